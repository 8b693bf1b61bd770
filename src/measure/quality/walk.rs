//! The pass across its segments: what it carries from frame to frame and segment to segment, each segment's
//! frames in turn, and the collection at the end.

use crate::error::Result;
use crate::gpu::fragments::FragmentRows;
use crate::measure::block_gpu::BlockGpu;
use crate::measure::coverage::Coverage;
use crate::measure::driver::check_interrupt;
use crate::measure::driver::FrameDriver;
use crate::measure::metrics::MetricRegion;
use crate::measure::quality::history::StateHistory;
use crate::measure::quality::outcome::{FrameImages, QualityPass, SegmentCost, ShadowFigures};
use crate::measure::quality::setup::QualityStage;
use crate::measure::records::FrameChanges;
use crate::measure::reference_cache::ReferenceCache;
use crate::methods::common::ask_counterfactual;
use crate::methods::Method;
use indicatif::ProgressBar;
use std::collections::VecDeque;
use std::time::Instant;

/// What the pass carries from frame to frame, and from one segment to the next.
pub struct Walk {
    /// Per frame, whether it goes to the dump callback.
    pub(super) dump_frames: Vec<bool>,
    pub(super) history: StateHistory,
    pub(super) in_flight: VecDeque<wgpu::SubmissionIndex>,
    pub(super) flip: Vec<Option<f64>>,
    pub(super) has_lag: bool,
    /// Where the frames can differ from the background (the kernels' tiles, the counterfactual's scissor).
    pub(super) coverage: Coverage,
    /// Tiles the metric kernel read, summed over the frames.
    pub(super) tiles_read: u64,
    /// Pixels lodpop's counterfactual was drawn in, summed, and the frames it was drawn on.
    pub(super) counterfactual_pixels: (u64, u32),
    /// Frames on which view_pop's counterfactual was drawn (`--impostor`).
    pub(super) view_frames: u32,
    /// The method is the reference and its frame is made by the frame alone: the reference frame is a copy
    /// of the method's.
    pub(super) reference_is_method_frame: bool,
    /// Frames whose reference frame was copied, not drawn.
    pub(super) reference_copied: u32,
    /// The metric timer's slots written in this pass.
    pub(super) metric_timed: Vec<u32>,
    /// The method frames' fragment counts, resolved ([`crate::gpu::fragments`]; no frame counted where the
    /// device has no pipeline statistics queries).
    pub(super) fragments: FragmentRows,
    /// The pass's segments so far.
    pub(super) segments: Vec<SegmentCost>,
    /// Per frame, the units whose image changed on it (`QualityStage::switched_units`).
    pub(super) changes: Vec<FrameChanges>,
}

impl Walk {
    /// Pushes this frame's states onto lodpop's history and records which instances changed on it (the pop
    /// events' switches, `QualityStage::switched_units`).
    pub(super) fn push_states(
        &mut self,
        base: &BlockGpu<'_>,
        method: &mut dyn Method,
        input: &crate::methods::FrameInput<'_>,
    ) {
        self.history.push(input.states);
        let (history, coverage) = (&self.history, &self.coverage);
        self.changes[input.frame as usize] = ask_counterfactual(method, |m| {
            QualityStage::switched_units(base, m, (input, history), coverage)
        });
    }
}

impl QualityStage {
    /// The start of the quality pass of `method` (`is_reference`: the reference itself): what it carries from
    /// frame to frame. `dump_frames`: per frame, whether it goes to the dump callback. The pass is then made in
    /// segments ([`QualityStage::segment`]) and read at the end ([`QualityStage::finish`]).
    pub fn begin(
        &mut self,
        base: &BlockGpu<'_>,
        (method, is_reference): (&mut dyn Method, bool),
        dump_frames: Vec<bool>,
    ) -> Walk {
        if let Some(taa) = &mut self.taa {
            taa.reset();
        }
        let history = ask_counterfactual(method, |m| m.lodpop_history().max(1));
        let confined = ask_counterfactual(method, |m| m.image_confined_to_instances())
            && ask_counterfactual(self.reference.as_mut(), |m| m.image_confined_to_instances());
        let mut walk = Walk {
            dump_frames,
            history: StateHistory::new(history),
            in_flight: VecDeque::new(),
            flip: vec![None; base.scene.frames as usize],
            has_lag: false,
            coverage: Coverage::new(base.scene, self.region == MetricRegion::Covered && confined),
            tiles_read: 0,
            counterfactual_pixels: (0, 0),
            view_frames: 0,
            reference_is_method_frame: is_reference
                && Self::reference_copyable(&self.taa, &self.shadow_share),
            reference_copied: 0,
            metric_timed: Vec::new(),
            fragments: FragmentRows::new(base.scene.frames),
            segments: Vec::new(),
            changes: vec![Vec::new(); base.scene.frames as usize],
        };
        walk.coverage.reset();
        walk
    }

    /// The quality pass of `method` over `frames`, the next frames of its walk `driver` (reset before the
    /// first segment), timed by the wall clock from its first command to the GPU's last; `cache`: the block's
    /// reference frames (kept by whichever pass drew them first).
    pub fn segment(
        &mut self,
        base: &BlockGpu<'_>,
        (method, driver): (&mut dyn Method, &mut FrameDriver<'_>),
        (walk, frames): (&mut Walk, std::ops::Range<u32>),
        cache: Option<&ReferenceCache>,
        progress: &ProgressBar,
        on_frames: &mut dyn FnMut(u32, FrameImages<'_>) -> Result<()>,
    ) -> Result<()> {
        let start = Instant::now();
        let before = (
            walk.counterfactual_pixels.1,
            walk.reference_copied,
            walk.view_frames,
        );
        let first = frames.start;
        for f in frames.clone() {
            check_interrupt()?;
            driver.advance(f);
            self.quality_frame(base, (method, cache), driver, f, walk, on_frames)?;
            progress.inc(1);
        }
        base.ctx.wait_idle()?;
        walk.in_flight.clear();
        walk.segments.push(SegmentCost {
            frames: [first, frames.end],
            ms: start.elapsed().as_secs_f64() * 1e3,
            counterfactual_frames: walk.counterfactual_pixels.1 - before.0,
            reference_copied: walk.reference_copied - before.1,
            view_frames: walk.view_frames - before.2,
        });
        Ok(())
    }

    /// After the last segment: every kernel's per-frame figures, read back once.
    pub fn finish(
        &self,
        base: &BlockGpu<'_>,
        method: &dyn Method,
        walk: Walk,
    ) -> Result<QualityPass> {
        let (ctx, k, frames) = (base.ctx, &self.kernels, base.scene.frames);
        let pixels = base.scene.width as f64 * base.scene.height as f64;
        let metric_tile_share =
            walk.tiles_read as f64 / (walk.coverage.tile_count() as f64 * frames.max(1) as f64);
        let (drawn_pixels, drawn_frames) = walk.counterfactual_pixels;
        let counterfactual_pixel_share =
            (drawn_frames > 0).then(|| drawn_pixels as f64 / (pixels * drawn_frames as f64));
        let shadow = match &self.shadow_share {
            Some(share) => Some(ShadowFigures {
                rmse: share.rmse.read(ctx, frames)?,
                lodpop: share.lodpop.read(ctx, frames)?,
            }),
            None => None,
        };
        let metric_gpu_ms_median = match &k.metric_timer {
            Some(t) => {
                let slots = t.read(ctx)?;
                let ms: Vec<f64> = walk
                    .metric_timed
                    .iter()
                    .filter_map(|&i| slots.get(i as usize).copied().flatten())
                    .collect();
                crate::measure::stats::percentile(&ms, 50.0)
            }
            None => None,
        };
        Ok(QualityPass {
            fragments: walk.fragments.read(ctx)?,
            metrics: k.metric.read(ctx, frames)?,
            flip: walk.flip,
            lodpop: k.lodpop.read_parts(ctx, frames)?,
            lag: if walk.has_lag {
                Some(k.lag.read(ctx, frames)?)
            } else {
                None
            },
            view_pop: match &k.view {
                Some(v) if !walk.has_lag => Some(v.kernel.read(ctx, frames)?),
                _ => None,
            },
            shadow,
            stage_ms: method.stage_gpu_ms(ctx)?,
            metric_gpu_ms_median,
            metric_tile_share,
            counterfactual_pixel_share,
            counterfactual_frames: drawn_frames,
            reference_frames_copied: walk.reference_copied,
            ms_per_frame: walk.segments.iter().map(|s| s.ms).sum::<f64>() / frames.max(1) as f64,
            segments: walk.segments,
            changes: walk.changes,
        })
    }
}
