//! The rows a block's frames are recorded in: a row per frame (frames.csv, [`FrameRecord`]) and its timing read
//! back ([`FrameTimes`]), the block's sizes ([`BlockInfo`]) and its timing rounds ([`BlockRounds`], [`Round`]).

use serde::Serialize;

/// One row of frames.csv: one frame of one method on one scene block.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct FrameRecord {
    pub scene: String,
    pub method: String,
    /// Instance count of the block (bunny-grid's n; 1 for bunny-sweep).
    pub count: u32,
    pub frame: u32,
    /// GPU time between timestamps around all of the frame's passes (empty without timestamp queries).
    pub gpu_ms: Option<f64>,
    /// CPU wall time from the start of encoding to the GPU's completion of the frame.
    pub cpu_ms: f64,
    pub triangles: u64,
    pub draw_calls: u32,
    /// What the method drew this frame in its own units: clusters for `clusterlod`, instances (blocks, in the
    /// unified scenes) for every other method.
    pub units_drawn: u64,
    /// Instances in transition (lod_from != lod_to) this frame.
    pub t_instances: u32,
    /// Mean over instances of lod_from + k (lod_to - lod_from), the same for every method.
    pub lod_mean: f64,
    /// Mean over the instances in transition of their blend factor k in [0, 1] (empty when none is).
    pub k_mean: Option<f64>,
    /// RMS over pixels and channels of the method's frame minus the reference's (empty with `--quality off`,
    /// as every figure of the quality pass below).
    pub rmse: Option<f64>,
    pub pop: Option<f64>,
    /// RMS over pixels and channels of the method's frame minus the same frame rendered with the previous
    /// frame's LOD schedule at this frame's pose (docs/measurement.md, "lodpop"); 0 where the schedule did not
    /// change.
    pub lodpop: Option<f64>,
    /// lodpop's two parts, each an RMS over every pixel of the frame (`lodpop_coverage^2 + lodpop_shading^2 =
    /// lodpop^2`, exactly in the integer sums): coverage, the pixels that are the background in one of the two
    /// frames only (the silhouette moved); shading, the pixels covered in both whose colour changed
    /// (docs/measurement.md, "lodpop in parts").
    pub lodpop_coverage: Option<f64>,
    pub lodpop_shading: Option<f64>,
    /// Mean CIEDE2000 over pixels between method and reference frame (sRGB D65 -> XYZ -> CIELAB), with
    /// `--metrics de2000` (empty otherwise).
    pub de2000_mean: Option<f64>,
    /// Pixels where the method shows the background and the reference shows surface.
    pub uncovered_px: Option<u64>,
    /// The uncovered pixels with the method's own surface within 4 pixels on both sides along the row or the
    /// column: cracks and holes (`metrics::crack_pixels`).
    pub crack_px: Option<u64>,
    /// Mean FLIP error, with `--metrics ...,flip` (empty otherwise).
    pub flip_mean: Option<f64>,
    /// GPU time of FSI's combination pass and its copy into the frame's target, measured in the quality pass
    /// (empty for other methods or without timestamps).
    pub combine_gpu_ms: Option<f64>,
    /// `fsi*` only: RMS of the method's frame minus the same combination with every LOD buffer drawn at this
    /// frame's pose (its one-frame lag; 0 for fsi-sameframe).
    pub lag_rmse: Option<f64>,
    /// `--shadows on`: RMS of the reference's LOD0 objects lit by the method's shadow map minus the reference
    /// frame: the error the method's shadow alone makes (empty without shadows).
    pub shadow_rmse: Option<f64>,
    /// `--shadows on`: RMS of those objects lit by the method's shadow map minus the same lit by what the
    /// method cast with the previous frame's schedule: the shadow's own popping (0 on frame 0).
    pub shadow_lodpop: Option<f64>,
    /// `roam*`: bintree nodes split and merged this frame (a forced split counts; a diamond is two nodes), and
    /// the CPU time of the frame's update, walk and morphs, in the timed frame (empty for other methods).
    pub splits: Option<u32>,
    pub merges: Option<u32>,
    pub select_cpu_ms: Option<f64>,
    /// The timing round the frame was timed in (0-based; `--rounds`).
    pub round: u32,
    /// Fragment shader invocations of the method's frame, counted in the quality pass with pipeline statistics
    /// queries (its own passes: not the shadow maps, TAA's resolve or compute passes; empty with `--quality
    /// off` or where the adapter has no such queries).
    pub fragments: Option<u64>,
    /// `--impostor`: RMS of the method's frame minus the same frame with the impostors' frames and blend weights
    /// selected from the previous frame's eye: the impostors' own popping under motion, LOD switches aside (0
    /// where the eye holds still; empty without impostors, under TAA and for FSI).
    pub view_pop: Option<f64>,
}

/// Per (scene, count, method) block: sizes and the cost of the two passes.
#[derive(Debug, Clone, Default, Serialize)]
pub struct BlockInfo {
    pub scene: String,
    pub method: String,
    /// The options the method reads (`MethodEntry::options`; absent for methods without options).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub method_options: Option<serde_json::Value>,
    /// What of the scene's materials the method does not draw as the reference does (`Method::material_limits`;
    /// absent when it draws them all).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub material_limits: Option<String>,
    pub count: u32,
    pub width: u32,
    pub height: u32,
    pub frames: u32,
    pub warmup: u32,
    /// Wall time per frame of the timing pass (render + wait), milliseconds.
    pub timing_pass_ms_per_frame: f64,
    /// Wall time per frame of the quality pass (reference + method + metric kernel), milliseconds (null with
    /// `--quality off`, as the two ratios).
    pub quality_pass_ms_per_frame: Option<f64>,
    /// quality_pass_ms_per_frame / timing_pass_ms_per_frame (2.0 is the floor: the reference doubles the work).
    pub quality_to_timing_ratio: Option<f64>,
    /// quality_pass_ms_per_frame over the timing-pass time of the renders the quality pass makes: the method's
    /// frame, the reference's (only on the frames where it was drawn, `reference_frames_copied`) and lodpop's
    /// counterfactual (one more render of the method, on the share of frames it was drawn,
    /// `counterfactual_frame_share`). What the pass costs beyond its renders: 1.0 would be free kernels,
    /// copies and read-backs. The counterfactual counts as a whole render though it is drawn inside a scissor,
    /// so where it is drawn often this is a lower bound of that overhead; `quality_to_timing_ratio` is the plain
    /// ratio. Made round by round (each quality segment over the renders timed in its own round; the geometric
    /// mean of the rounds' ratios), with its Student-t 95 % interval over rounds (null with one round).
    pub quality_to_renders_ratio: Option<f64>,
    pub quality_to_renders_ratio_ci95_lo: Option<f64>,
    pub quality_to_renders_ratio_ci95_hi: Option<f64>,
    /// The ratio of each round, in round order.
    pub quality_to_renders_by_round: Option<Vec<f64>>,
    /// The share of the quality pass's frames on which lodpop's counterfactual was drawn (some instance's
    /// image-state changed; None: no quality pass).
    pub counterfactual_frame_share: Option<f64>,
    /// Frames of the quality pass whose reference frame was copied instead of drawn: from the block's
    /// reference cache, kept by an earlier method's pass, or in the reference's own pass from its own frame
    /// (0: all drawn; None: no quality pass).
    pub reference_frames_copied: Option<u32>,
    /// The frames instances waited for a slot under `--max-transitions`, summed over instances (0 without a
    /// cap): the delay the cap costs.
    pub wait_instance_frames: u64,
    /// The most instances waiting on one frame.
    pub waiting_max: u32,
    /// Median GPU time of the metric kernel alone per quality-pass frame (None without timestamps).
    pub metric_gpu_ms_median: Option<f64>,
    /// The share of the frame's 16 x 16 pixel tiles the metric kernel read, mean over the quality pass's frames (1.0 with
    /// `--metric-region full` or where no bound holds; docs/measurement.md, "Cost of the quality pass").
    pub metric_tile_share: Option<f64>,
    /// The share of the frame's pixels lodpop's counterfactual was drawn in, mean over the frames it was
    /// drawn on (None when it never was).
    pub counterfactual_pixel_share: Option<f64>,
    pub extra_target_bytes: u64,
    /// Instance data per timing-pass frame: what the method's draw lists held, and what was written to the
    /// GPU (only the entries that changed since the previous upload into the same buffer range).
    pub instance_bytes_listed_per_frame: f64,
    pub instance_bytes_written_per_frame: f64,
    /// The adapter's triangle rate (a second) just before and just after the block
    /// (`measure::probe_rounds::ClockCheck`; null with `--ceilings off`): where the two differ by more than a fifth,
    /// the adapter changed speed during the block (a GPU's clock), and its times are suspect.
    pub triangle_rate_before: Option<f64>,
    pub triangle_rate_after: Option<f64>,
    /// `--clock-warmup`: the warm-ups before the method's timed segments (one per round): their total wall
    /// time, ms, and how many ended at the cap short of the target (the clock did not come up; null without
    /// warm-ups).
    pub clock_warmup_ms: Option<f64>,
    pub clock_warmups_short: Option<u32>,
}

/// The timing rounds of one scene block, as run.json records them (`timing_rounds`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct BlockRounds {
    pub scene: String,
    pub count: u32,
    /// Seed of the rounds' shuffles (derived from `--seed` and the block's position).
    pub seed: u64,
    /// Frames rendered untimed after the `warmup` frames: each distinct transition's first frames.
    pub warmup_transition_frames: Vec<u32>,
    /// Methods timed in the rounds but not reported (the reference, timed for `quality_to_renders_ratio`).
    pub timed_only: Vec<String>,
    pub rounds: Vec<Round>,
}

/// A frame's timing as frames.csv holds it, read back (`lodbench compare`): the columns the paired ratios need,
/// of any version of frames.csv that has them (`round` is empty in a run made before the timing rounds).
#[derive(Debug, Clone, serde::Deserialize, PartialEq)]
pub struct FrameTimes {
    pub scene: String,
    pub method: String,
    pub count: u32,
    pub frame: u32,
    pub gpu_ms: Option<f64>,
    pub cpu_ms: f64,
    pub t_instances: u32,
    #[serde(default)]
    pub round: Option<u32>,
}

impl FrameTimes {
    /// The frame record of these times, every other figure empty or 0; None without a round.
    pub fn record(self) -> Option<FrameRecord> {
        Some(FrameRecord {
            round: self.round?,
            scene: self.scene,
            method: self.method,
            count: self.count,
            frame: self.frame,
            gpu_ms: self.gpu_ms,
            cpu_ms: self.cpu_ms,
            triangles: 0,
            draw_calls: 0,
            units_drawn: 0,
            t_instances: self.t_instances,
            lod_mean: 0.0,
            k_mean: None,
            rmse: None,
            pop: None,
            lodpop: None,
            lodpop_coverage: None,
            lodpop_shading: None,
            de2000_mean: None,
            uncovered_px: None,
            crack_px: None,
            flip_mean: None,
            combine_gpu_ms: None,
            lag_rmse: None,
            shadow_rmse: None,
            shadow_lodpop: None,
            splits: None,
            merges: None,
            select_cpu_ms: None,
            fragments: None,
            view_pop: None,
        })
    }
}

/// One timing round: its frames `[first, end)` and the order the methods were timed in.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Round {
    pub round: u32,
    pub frames: [u32; 2],
    pub order: Vec<String>,
}
