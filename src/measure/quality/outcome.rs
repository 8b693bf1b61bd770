//! What the quality pass measures: per frame, per segment, and the images a dumped frame hands on.

use crate::measure::metrics::FrameMetrics;
use crate::methods::common::DumpKind;

/// The shadow's own share of the error per frame (`--shadows on`).
pub struct ShadowFigures {
    pub rmse: Vec<f64>,
    pub lodpop: Vec<f64>,
}

/// What the quality pass measured, per frame.
pub struct QualityPass {
    pub metrics: Vec<FrameMetrics>,
    /// `--metrics flip`: mean FLIP per frame.
    pub flip: Vec<Option<f64>>,
    /// lodpop per frame, with its coverage and shading parts.
    pub lodpop: Vec<crate::measure::diff_kernel::DiffFigure>,
    /// Methods with a lag (FSI): lag_rmse per frame.
    pub lag: Option<Vec<f64>>,
    /// `--impostor`: view_pop per frame (None without impostors, under TAA, for a method with a lag).
    pub view_pop: Option<Vec<f64>>,
    pub shadow: Option<ShadowFigures>,
    /// The method's own stage per frame (FSI's combination pass), when it has one: timed in the quality pass,
    /// so that its timestamps are never inside a timing-pass frame.
    pub stage_ms: Option<Vec<Option<f64>>>,
    /// The fragment shader invocations of the method's frame, per frame (None on every frame where the device
    /// has no pipeline statistics queries).
    pub fragments: Vec<Option<u64>>,
    pub ms_per_frame: f64,
    pub metric_gpu_ms_median: Option<f64>,
    /// Mean share of the frame's 16 x 16 tiles the metric kernel read.
    pub metric_tile_share: f64,
    /// Mean share of the frame's pixels lodpop's counterfactual was drawn in, over the frames it was drawn.
    pub counterfactual_pixel_share: Option<f64>,
    /// Frames on which lodpop's counterfactual was drawn (a render of the method's frame with the earlier
    /// states, inside the changed instances' rectangle).
    pub counterfactual_frames: u32,
    /// Frames whose reference frame was copied instead of drawn: from the block's [`ReferenceCache`], or in
    /// the reference's own pass from its frame.
    pub reference_frames_copied: u32,
    /// The pass's segments (one per timing round), each timed on its own.
    pub segments: Vec<SegmentCost>,
    /// Per frame, the units whose image changed on it, with their weights (`records::events`).
    pub changes: Vec<crate::measure::records::FrameChanges>,
}

/// The images of one dumped quality-pass frame, RGBA8.
#[derive(Debug, Clone, Copy)]
pub struct FrameImages<'i> {
    pub method: &'i [u8],
    pub reference: &'i [u8],
    /// The intermediate images: the method's (FSI's LOD buffers) and lodpop's counterfactual frames.
    pub extras: &'i [(DumpKind, Vec<u8>)],
}

/// One segment of a quality pass: its frames, its wall time and what it rendered besides the method's frames.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentCost {
    pub frames: [u32; 2],
    pub ms: f64,
    /// Frames on which lodpop's counterfactual was drawn.
    pub counterfactual_frames: u32,
    /// Frames whose reference frame was copied, not drawn.
    pub reference_copied: u32,
    /// Frames on which view_pop's counterfactual was drawn (`--impostor`).
    pub view_frames: u32,
}
