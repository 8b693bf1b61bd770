//! The records lodbench writes: a row per frame (frames.csv) and a row per block (summary.csv). A frame record
//! is built once, by the runner, when every figure of its frame is known; a summary record is computed here
//! from a block's frame records with `crate::measure::stats`. The exporters only serialise them.
//!
//! Every figure of the quality pass is an `Option`: empty (never 0) in a run without it (`--quality off`).

use crate::measure::stats::{bootstrap_ci, mean, percentile};
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
}

/// One row of summary.csv: one method on one scene block.
#[derive(Debug, Clone, Default, Serialize, PartialEq)]
pub struct SummaryRecord {
    pub scene: String,
    pub method: String,
    pub count: u32,
    pub frames: u32,
    pub gpu_ms_median: Option<f64>,
    /// Medians over the frames with an instance in transition and over the frames without.
    pub gpu_ms_median_transition: Option<f64>,
    pub gpu_ms_median_steady: Option<f64>,
    pub gpu_ms_p5: Option<f64>,
    pub gpu_ms_p95: Option<f64>,
    pub cpu_ms_median: f64,
    pub triangles_mean: f64,
    pub draw_calls_mean: f64,
    pub t_instances_mean: f64,
    /// The quality pass's figures, empty with `--quality off`: mean rmse with its bootstrap interval, largest
    /// rmse, largest and 95th percentile pop.
    pub rmse_mean: Option<f64>,
    pub rmse_mean_ci95_lo: Option<f64>,
    pub rmse_mean_ci95_hi: Option<f64>,
    pub rmse_max: Option<f64>,
    pub pop_max: Option<f64>,
    pub pop_p95: Option<f64>,
    /// Largest, 95th percentile and sum over frames of lodpop.
    pub lodpop_max: Option<f64>,
    pub lodpop_p95: Option<f64>,
    pub lodpop_sum: Option<f64>,
    /// Mean over frames of de2000_mean, and its largest frame (empty without `--metrics de2000`).
    pub de2000_mean: Option<f64>,
    pub de2000_max: Option<f64>,
    /// Mean over frames of flip_mean (empty without `--metrics flip`).
    pub flip_mean: Option<f64>,
    /// Mean over frames of units_drawn (clusters for clusterlod, instances otherwise).
    pub units_drawn_mean: f64,
    /// Mean over frames of uncovered_px; mean and largest crack_px.
    pub uncovered_px_mean: Option<f64>,
    pub crack_px_mean: Option<f64>,
    pub crack_px_max: Option<u64>,
    pub extra_target_bytes: u64,
    /// Largest relative change of the triangle count between consecutive frames,
    /// max |t_f - t_(f-1)| / t_(f-1) (Scherzer & Wimmer 2008 section 4 saw at most 2 % with FSI).
    pub tri_alternation_max: f64,
    /// Median GPU time of FSI's combination pass (empty for other methods).
    pub combine_gpu_ms_median: Option<f64>,
    /// `fsi*` only: mean and largest lag_rmse.
    pub lag_rmse_mean: Option<f64>,
    pub lag_rmse_max: Option<f64>,
    /// `--shadows on`: mean shadow_rmse and largest shadow_lodpop (the shadow's own error and popping).
    pub shadow_rmse_mean: Option<f64>,
    pub shadow_lodpop_max: Option<f64>,
    /// `--baseline`: this method's time over the baseline's, paired round by round ([`PairedRatios`]).
    pub baseline: Option<String>,
    /// The frame time every ratio of the block is of ([`Clock::of_block`]), the same on every row of a block.
    pub clock: Clock,
    pub rounds: u32,
    pub ratio_to_baseline: Option<f64>,
    pub ratio_to_baseline_ci95_lo: Option<f64>,
    pub ratio_to_baseline_ci95_hi: Option<f64>,
    pub ratio_to_baseline_transition: Option<f64>,
    pub ratio_to_baseline_transition_ci95_lo: Option<f64>,
    pub ratio_to_baseline_transition_ci95_hi: Option<f64>,
    pub ratio_to_baseline_steady: Option<f64>,
    pub ratio_to_baseline_steady_ci95_lo: Option<f64>,
    pub ratio_to_baseline_steady_ci95_hi: Option<f64>,
    /// Mean triangles drawn over the median frame time (the block's clock), a second.
    pub triangles_per_s: Option<f64>,
    /// `triangles_per_s` over the adapter's triangle ceiling measured at the start of the run (run.json's
    /// `ceilings`, `measure::probe_rounds::triangle_ceiling`).
    pub triangle_ceiling_share: Option<f64>,
    /// `triangles` where that share is 0.8 or more: the block draws near the adapter's triangle rate.
    pub bound: Option<String>,
}

impl SummaryRecord {
    /// Fills the ceiling columns from the run's triangle ceiling (triangles a second).
    pub fn set_ceiling(&mut self, triangle_ceiling: Option<f64>) {
        let ms = match self.clock {
            Clock::GpuMs => self.gpu_ms_median,
            Clock::CpuMs => Some(self.cpu_ms_median),
        };
        self.triangles_per_s = ms
            .filter(|ms| *ms > 0.0)
            .map(|ms| self.triangles_mean / (ms / 1e3));
        self.triangle_ceiling_share = self
            .triangles_per_s
            .zip(triangle_ceiling.filter(|c| *c > 0.0))
            .map(|(r, c)| r / c);
        self.bound = self
            .triangle_ceiling_share
            .filter(|s| *s >= 0.8)
            .map(|_| "triangles".to_string());
    }

    /// Summarises one block's rows (all of the same scene, method and count); `seed` drives the bootstrap,
    /// `clock` is the block's ([`Clock::of_block`], over every method of the block).
    pub fn from_frames(
        rows: &[FrameRecord],
        extra_target_bytes: u64,
        seed: u64,
        clock: Clock,
    ) -> Option<SummaryRecord> {
        let first = rows.first()?;
        let lag: Option<Vec<f64>> = rows.iter().map(|r| r.lag_rmse).collect();
        let shadow_rmse: Option<Vec<f64>> = rows.iter().map(|r| r.shadow_rmse).collect();
        let shadow_lodpop: Option<Vec<f64>> = rows.iter().map(|r| r.shadow_lodpop).collect();
        let gpu: Vec<f64> = rows.iter().filter_map(|r| r.gpu_ms).collect();
        let cpu: Vec<f64> = rows.iter().map(|r| r.cpu_ms).collect();
        // The quality pass's figures: None when a frame has none (`--quality off`).
        let pop: Option<Vec<f64>> = rows.iter().map(|r| r.pop).collect();
        let rmse: Option<Vec<f64>> = rows.iter().map(|r| r.rmse).collect();
        let lodpop: Option<Vec<f64>> = rows.iter().map(|r| r.lodpop).collect();
        let uncovered: Option<Vec<u64>> = rows.iter().map(|r| r.uncovered_px).collect();
        let crack: Option<Vec<u64>> = rows.iter().map(|r| r.crack_px).collect();
        let max = |v: &Vec<f64>| v.iter().copied().fold(0.0, f64::max);
        let mean_of = |v: &Vec<u64>| mean(v.iter().map(|&x| x as f64));
        let gpu_where = |transition: bool| {
            rows.iter()
                .filter(|r| (r.t_instances > 0) == transition)
                .filter_map(|r| r.gpu_ms)
                .collect::<Vec<_>>()
        };
        let de2000: Option<Vec<f64>> = rows.iter().map(|r| r.de2000_mean).collect();
        let rmse_ci = rmse.as_ref().map(|rmse| {
            bootstrap_ci(rmse, seed ^ 0x524D_5345, |v| Some(mean(v.iter().copied())))
                .unwrap_or((0.0, 0.0))
        });
        Some(SummaryRecord {
            scene: first.scene.clone(),
            method: first.method.clone(),
            count: first.count,
            frames: rows.len() as u32,
            gpu_ms_median: percentile(&gpu, 50.0),
            gpu_ms_median_transition: percentile(&gpu_where(true), 50.0),
            gpu_ms_median_steady: percentile(&gpu_where(false), 50.0),
            gpu_ms_p5: percentile(&gpu, 5.0),
            gpu_ms_p95: percentile(&gpu, 95.0),
            cpu_ms_median: percentile(&cpu, 50.0).unwrap_or(f64::NAN),
            triangles_mean: mean(rows.iter().map(|r| r.triangles as f64)),
            draw_calls_mean: mean(rows.iter().map(|r| r.draw_calls as f64)),
            t_instances_mean: mean(rows.iter().map(|r| r.t_instances as f64)),
            rmse_mean: rmse.as_ref().map(|v| mean(v.iter().copied())),
            rmse_mean_ci95_lo: rmse_ci.map(|c| c.0),
            rmse_mean_ci95_hi: rmse_ci.map(|c| c.1),
            rmse_max: rmse.as_ref().map(max),
            pop_max: pop.as_ref().map(max),
            pop_p95: pop.as_ref().map(|v| percentile(v, 95.0).unwrap_or(0.0)),
            lodpop_max: lodpop.as_ref().map(max),
            lodpop_p95: lodpop.as_ref().map(|v| percentile(v, 95.0).unwrap_or(0.0)),
            lodpop_sum: lodpop.as_ref().map(|v| v.iter().sum()),
            de2000_mean: de2000.as_ref().map(|v| mean(v.iter().copied())),
            de2000_max: de2000.map(|v| v.into_iter().fold(0.0, f64::max)),
            flip_mean: rows
                .iter()
                .map(|r| r.flip_mean)
                .collect::<Option<Vec<f64>>>()
                .map(|v| mean(v.into_iter())),
            units_drawn_mean: mean(rows.iter().map(|r| r.units_drawn as f64)),
            uncovered_px_mean: uncovered.as_ref().map(mean_of),
            crack_px_mean: crack.as_ref().map(mean_of),
            crack_px_max: crack.map(|v| v.into_iter().max().unwrap_or(0)),
            extra_target_bytes,
            tri_alternation_max: tri_alternation_max(rows),
            combine_gpu_ms_median: percentile(
                &rows
                    .iter()
                    .filter_map(|r| r.combine_gpu_ms)
                    .collect::<Vec<_>>(),
                50.0,
            ),
            lag_rmse_mean: lag.as_ref().map(|v| mean(v.iter().copied())),
            lag_rmse_max: lag.map(|v| v.into_iter().fold(0.0, f64::max)),
            shadow_rmse_mean: shadow_rmse.as_ref().map(|v| mean(v.iter().copied())),
            shadow_lodpop_max: shadow_lodpop.map(|v| v.into_iter().fold(0.0, f64::max)),
            baseline: None,
            clock,
            rounds: rows.iter().map(|r| r.round + 1).max().unwrap_or(0),
            ratio_to_baseline: None,
            ratio_to_baseline_ci95_lo: None,
            ratio_to_baseline_ci95_hi: None,
            ratio_to_baseline_transition: None,
            ratio_to_baseline_transition_ci95_lo: None,
            ratio_to_baseline_transition_ci95_hi: None,
            ratio_to_baseline_steady: None,
            ratio_to_baseline_steady_ci95_lo: None,
            ratio_to_baseline_steady_ci95_hi: None,
            triangles_per_s: None,
            triangle_ceiling_share: None,
            bound: None,
        })
    }

    /// Fills the ratio columns from this block's rows and the baseline's (same scene, count, frames, rounds),
    /// of the block's clock.
    pub fn set_ratios(
        &mut self,
        baseline: &str,
        rows: &[FrameRecord],
        baseline_rows: &[FrameRecord],
    ) {
        let r = PairedRatios::new(rows, baseline_rows, self.clock);
        self.baseline = Some(baseline.to_string());
        let split = Ratio::columns;
        (
            self.ratio_to_baseline,
            self.ratio_to_baseline_ci95_lo,
            self.ratio_to_baseline_ci95_hi,
        ) = split(r.all);
        (
            self.ratio_to_baseline_transition,
            self.ratio_to_baseline_transition_ci95_lo,
            self.ratio_to_baseline_transition_ci95_hi,
        ) = split(r.transition);
        (
            self.ratio_to_baseline_steady,
            self.ratio_to_baseline_steady_ci95_lo,
            self.ratio_to_baseline_steady_ci95_hi,
        ) = split(r.steady);
    }
}

/// Which frames of a round a per-round median is taken over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameSet {
    All,
    /// Frames with an instance in transition.
    Transition,
    /// Frames without.
    Steady,
}

impl FrameSet {
    fn holds(self, r: &FrameRecord) -> bool {
        match self {
            FrameSet::All => true,
            FrameSet::Transition => r.t_instances > 0,
            FrameSet::Steady => r.t_instances == 0,
        }
    }
}

/// The frame time the ratios of a block are of: `gpu_ms` when every timed frame of every method of the block
/// has one, else `cpu_ms`. Decided once per block ([`Clock::of_block`]) and passed to every ratio of it
/// (summary.csv's `ratio_to_baseline`, rounds.csv, pairs.csv), so one missing timestamp cannot switch some of
/// a block's ratios to another clock than the others.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Clock {
    #[default]
    GpuMs,
    CpuMs,
}

impl Clock {
    /// The clock of a block: `blocks` each method's frame records.
    pub fn of_block(blocks: &[Vec<FrameRecord>]) -> Clock {
        Clock::of(blocks.iter().flatten())
    }

    /// `gpu_ms` when every one of `rows` has it (and there is one), else `cpu_ms`.
    pub fn of<'a>(rows: impl IntoIterator<Item = &'a FrameRecord>) -> Clock {
        let mut any = false;
        for r in rows {
            if r.gpu_ms.is_none() {
                return Clock::CpuMs;
            }
            any = true;
        }
        if any {
            Clock::GpuMs
        } else {
            Clock::CpuMs
        }
    }

    /// The column name: `gpu_ms` or `cpu_ms`.
    pub fn name(self) -> &'static str {
        match self {
            Clock::GpuMs => "gpu_ms",
            Clock::CpuMs => "cpu_ms",
        }
    }

    /// A frame's time on this clock (NaN for a frame without it, which [`percentile`] leaves out).
    fn time(self, r: &FrameRecord) -> f64 {
        match self {
            Clock::GpuMs => r.gpu_ms.unwrap_or(f64::NAN),
            Clock::CpuMs => r.cpu_ms,
        }
    }
}

/// Per round, the median frame time on `clock` over the round's frames of `set` (None where the round has
/// none).
pub fn round_medians(rows: &[FrameRecord], set: FrameSet, clock: Clock) -> Vec<Option<f64>> {
    let rounds = rows.iter().map(|r| r.round + 1).max().unwrap_or(0) as usize;
    let mut per: Vec<Vec<f64>> = vec![Vec::new(); rounds];
    for r in rows.iter().filter(|r| set.holds(r)) {
        per[r.round as usize].push(clock.time(r));
    }
    per.iter().map(|v| percentile(v, 50.0)).collect()
}

/// A paired ratio: the geometric mean over rounds of (method's round median / baseline's round median), and
/// its Student-t 95 % interval over rounds ([`crate::measure::stats::paired_log_ratio`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ratio {
    pub ratio: f64,
    pub ci95: Option<(f64, f64)>,
    /// Rounds that held frames of the set in both blocks.
    pub rounds: usize,
}

impl Ratio {
    /// Whether the 95 % interval excludes 1.0 (the two costs differ); None without an interval.
    pub fn different(&self) -> Option<bool> {
        self.ci95.map(|(lo, hi)| lo > 1.0 || hi < 1.0)
    }

    /// The ratio and its interval's bounds as CSV columns (each empty where there is none).
    pub fn columns(x: Option<Ratio>) -> (Option<f64>, Option<f64>, Option<f64>) {
        (
            x.map(|x| x.ratio),
            x.and_then(|x| x.ci95.map(|c| c.0)),
            x.and_then(|x| x.ci95.map(|c| c.1)),
        )
    }
}

/// A method's time over the baseline's (or over any other method's of the same block): over all frames, over
/// frames in transition, over steady frames.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairedRatios {
    pub all: Option<Ratio>,
    pub transition: Option<Ratio>,
    pub steady: Option<Ratio>,
}

impl PairedRatios {
    /// `rows`' time over `baseline`'s, both of the same block, on the block's `clock`.
    pub fn new(rows: &[FrameRecord], baseline: &[FrameRecord], clock: Clock) -> PairedRatios {
        let ratio = |set| {
            let (m, b) = (
                round_medians(rows, set, clock),
                round_medians(baseline, set, clock),
            );
            let logs: Vec<f64> = m
                .iter()
                .zip(&b)
                .filter_map(|(m, b)| Some((m.as_ref()? / b.as_ref()?).ln()))
                .filter(|x| x.is_finite())
                .collect();
            let (mean, ci) = crate::measure::stats::paired_log_ratio(&logs)?;
            Some(Ratio {
                ratio: mean.exp(),
                ci95: ci.map(|(lo, hi)| (lo.exp(), hi.exp())),
                rounds: logs.len(),
            })
        };
        PairedRatios {
            all: ratio(FrameSet::All),
            transition: ratio(FrameSet::Transition),
            steady: ratio(FrameSet::Steady),
        }
    }
}

/// max over consecutive frames of |t_f - t_(f-1)| / t_(f-1), triangles t, over every frame of the block (0
/// for fewer than two frames). The warm-up ends by rendering the path's frame 0 and replaying it as the previous
/// frame ([`crate::methods::Method::replay_as_previous`]), so FSI's first timed frame reads a previous frame like
/// every other and draws one LOD buffer, as in the paper's steady state (section 4.1).
pub fn tri_alternation_max(rows: &[FrameRecord]) -> f64 {
    rows.windows(2)
        .map(|w| {
            let (a, b) = (w[0].triangles as f64, w[1].triangles as f64);
            if a > 0.0 {
                (b - a).abs() / a
            } else {
                0.0
            }
        })
        .fold(0.0, f64::max)
}

/// Which LODs the instances in transition on one frame go between.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TransitionPair {
    /// No instance in transition.
    #[default]
    None,
    /// Every t-instance goes from the first LOD to the second.
    One(u32, u32),
    /// t-instances between different pairs of LODs.
    Mixed,
}

impl TransitionPair {
    /// The pair of a frame whose t-instances include one going `from` -> `to`.
    pub fn with(self, from: u32, to: u32) -> TransitionPair {
        match self {
            TransitionPair::None => TransitionPair::One(from, to),
            TransitionPair::One(a, b) if (a, b) == (from, to) => self,
            _ => TransitionPair::Mixed,
        }
    }

    /// The pair of a run of frames: this one's joined with a later frame's.
    pub fn join(self, other: TransitionPair) -> TransitionPair {
        match other {
            TransitionPair::None => self,
            TransitionPair::One(a, b) => self.with(a, b),
            TransitionPair::Mixed => TransitionPair::Mixed,
        }
    }

    fn text(self) -> String {
        match self {
            TransitionPair::None => String::new(),
            TransitionPair::One(a, b) => format!("{a}->{b}"),
            TransitionPair::Mixed => "mixed".into(),
        }
    }
}

/// Frames after a transition's last frame that still count as its own in transitions.csv: the frame after it
/// shows the end state (a schedule change, so lodpop's) and, for FSI, the frame after that still combines a
/// buffer from inside the transition.
pub const TRANSITION_TAIL: u32 = 2;

/// Frames before a transition's first frame that `--dump-transitions` dumps too, so a clip of the transition
/// (`lodbench perceptual`) starts from the picture before it.
pub const TRANSITION_LEAD: u32 = 2;

/// Per frame: whether it lies within [`TRANSITION_LEAD`] frames before or [`TRANSITION_TAIL`] frames after a
/// frame with an instance in transition (the frames `--dump-transitions` dumps).
pub fn near_transitions(t_instances: &[u32]) -> Vec<bool> {
    let n = t_instances.len();
    let mut near = vec![false; n];
    for (f, _) in t_instances.iter().enumerate().filter(|(_, &t)| t > 0) {
        let lo = f.saturating_sub(TRANSITION_LEAD as usize);
        let hi = (f + TRANSITION_TAIL as usize).min(n.saturating_sub(1));
        near[lo..=hi].fill(true);
    }
    near
}

/// One row of transitions.csv: one transition of the path (a maximal run of frames with an instance in
/// transition) for one method on one scene block, with its largest figures over the transition's frames and
/// the [`TRANSITION_TAIL`] frames after it.
#[derive(Debug, Clone, Serialize, serde::Deserialize, PartialEq)]
pub struct TransitionRecord {
    pub scene: String,
    pub method: String,
    pub count: u32,
    /// 0-based index of the transition along the path.
    pub transition: u32,
    /// First and last frame with an instance in transition.
    pub first_frame: u32,
    pub last_frame: u32,
    /// `lod_from->lod_to` of the t-instances (of the first frame's), or `mixed`.
    pub lods: String,
    /// The largest lodpop, pop and rmse over the transition's frames and the frame of each (empty, as the
    /// frame, with `--quality off`).
    pub lodpop_max: Option<f64>,
    pub lodpop_max_frame: Option<u32>,
    /// lodpop_max's parts on its frame: coverage^2 + shading^2 = lodpop_max^2 (FrameRecord::lodpop_coverage).
    #[serde(default)]
    pub lodpop_coverage: Option<f64>,
    #[serde(default)]
    pub lodpop_shading: Option<f64>,
    pub pop_max: Option<f64>,
    pub pop_max_frame: Option<u32>,
    pub rmse_max: Option<f64>,
    /// `--shadows on`: the largest shadow_lodpop over the same frames (empty without shadows).
    #[serde(default)]
    pub shadow_lodpop_max: Option<f64>,
}

/// The transitions of one block: `rows` its frame records in frame order, `pairs` each frame's pair.
pub fn transitions(rows: &[FrameRecord], pairs: &[TransitionPair]) -> Vec<TransitionRecord> {
    let mut out = Vec::new();
    let mut f = 0;
    while f < rows.len() {
        if rows[f].t_instances == 0 {
            f += 1;
            continue;
        }
        let first = f;
        while f < rows.len() && rows[f].t_instances > 0 {
            f += 1;
        }
        let last = f - 1;
        let window = &rows[first..(last + 1 + TRANSITION_TAIL as usize).min(rows.len())];
        // The largest value over the window and its frame; None when a frame has no value.
        let argmax = |value: fn(&FrameRecord) -> Option<f64>| {
            window
                .iter()
                .try_fold((0.0f64, window[0].frame), |(best, at), r| {
                    let v = value(r)?;
                    Some(if v > best { (v, r.frame) } else { (best, at) })
                })
                .unzip()
        };
        let (lodpop_max, lodpop_max_frame) = argmax(|r| r.lodpop);
        let at_max = lodpop_max_frame.and_then(|f| window.iter().find(|r| r.frame == f));
        let (pop_max, pop_max_frame) = argmax(|r| r.pop);
        let r0 = &rows[first];
        out.push(TransitionRecord {
            scene: r0.scene.clone(),
            method: r0.method.clone(),
            count: r0.count,
            transition: out.len() as u32,
            first_frame: r0.frame,
            last_frame: rows[last].frame,
            // Over every frame of the transition: instances that start their transitions while others are
            // still in theirs make one run of frames.
            lods: pairs
                .get(first..=last)
                .unwrap_or_default()
                .iter()
                .fold(TransitionPair::None, |acc, &p| acc.join(p))
                .text(),
            lodpop_max,
            lodpop_max_frame,
            lodpop_coverage: at_max.and_then(|r| r.lodpop_coverage),
            lodpop_shading: at_max.and_then(|r| r.lodpop_shading),
            pop_max,
            pop_max_frame,
            rmse_max: argmax(|r| r.rmse).0,
            shadow_lodpop_max: window
                .iter()
                .map(|r| r.shadow_lodpop)
                .collect::<Option<Vec<f64>>>()
                .map(|v| v.into_iter().fold(0.0, f64::max)),
        });
    }
    out
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

/// One row of rounds.csv: one method's frames of one timing round, summarised, and paired with the baseline's
/// same round: the data `ratio_to_baseline` and its interval are computed from.
#[derive(Debug, Clone, Serialize, serde::Deserialize, PartialEq)]
pub struct RoundRecord {
    pub scene: String,
    pub method: String,
    pub count: u32,
    pub round: u32,
    /// 0-based place of the method in the round's order.
    pub position: u32,
    pub first_frame: u32,
    pub end_frame: u32,
    /// `gpu_ms` or `cpu_ms`: which frame time the medians are of (the block's clock).
    pub time: Clock,
    pub median_ms: Option<f64>,
    pub median_ms_transition: Option<f64>,
    pub median_ms_steady: Option<f64>,
    pub baseline: Option<String>,
    /// median_ms over the baseline's median_ms in the same round.
    pub ratio_to_baseline: Option<f64>,
}

/// The rows of rounds.csv for one block: `blocks` each method's frame records (in any order), `clock` the
/// block's.
pub fn round_records(
    blocks: &[Vec<FrameRecord>],
    info: &BlockRounds,
    baseline: Option<&str>,
    clock: Clock,
) -> Vec<RoundRecord> {
    let medians = |rows: &[FrameRecord], set| round_medians(rows, set, clock);
    let base = baseline.and_then(|b| {
        blocks
            .iter()
            .find(|rows| rows.first().is_some_and(|r| r.method == b))
            .map(|rows| medians(rows, FrameSet::All))
    });
    let mut out = Vec::new();
    for rows in blocks {
        let Some(first) = rows.first() else { continue };
        let (m, t, st) = (
            medians(rows, FrameSet::All),
            medians(rows, FrameSet::Transition),
            medians(rows, FrameSet::Steady),
        );
        for round in &info.rounds {
            let r = round.round as usize;
            let at = |v: &[Option<f64>]| v.get(r).copied().flatten();
            out.push(RoundRecord {
                scene: first.scene.clone(),
                method: first.method.clone(),
                count: first.count,
                round: round.round,
                position: round
                    .order
                    .iter()
                    .position(|l| *l == first.method)
                    .unwrap_or(0) as u32,
                first_frame: round.frames[0],
                end_frame: round.frames[1],
                time: clock,
                median_ms: at(&m),
                median_ms_transition: at(&t),
                median_ms_steady: at(&st),
                baseline: base.as_ref().and(baseline.map(str::to_string)),
                ratio_to_baseline: base.as_ref().and_then(|b| Some(at(&m)? / at(b)?)),
            });
        }
    }
    out
}

/// One row of pairs.csv: two methods of one block, method_a's time over method_b's, paired round by round
/// ([`PairedRatios`], on the block's clock): how to compare any two methods' costs.
#[derive(Debug, Clone, Serialize, serde::Deserialize, PartialEq)]
pub struct PairRecord {
    pub scene: String,
    pub count: u32,
    pub method_a: String,
    pub method_b: String,
    pub clock: Clock,
    /// Rounds the all-frames ratio is over (those holding frames of both methods).
    pub rounds: u32,
    pub ratio: Option<f64>,
    pub ratio_ci95_lo: Option<f64>,
    pub ratio_ci95_hi: Option<f64>,
    pub ratio_transition: Option<f64>,
    pub ratio_transition_ci95_lo: Option<f64>,
    pub ratio_transition_ci95_hi: Option<f64>,
    pub ratio_steady: Option<f64>,
    pub ratio_steady_ci95_lo: Option<f64>,
    pub ratio_steady_ci95_hi: Option<f64>,
    /// The all-frames interval excludes 1.0 (empty without an interval).
    pub different: Option<bool>,
}

impl PairRecord {
    /// `a`'s time over `b`'s (the frame records of two methods of one block) on the block's `clock`; None when
    /// either has no rows.
    pub fn new(a: &[FrameRecord], b: &[FrameRecord], clock: Clock) -> Option<PairRecord> {
        let (first_a, first_b) = (a.first()?, b.first()?);
        let r = PairedRatios::new(a, b, clock);
        let (ratio, ratio_ci95_lo, ratio_ci95_hi) = Ratio::columns(r.all);
        let (ratio_transition, ratio_transition_ci95_lo, ratio_transition_ci95_hi) =
            Ratio::columns(r.transition);
        let (ratio_steady, ratio_steady_ci95_lo, ratio_steady_ci95_hi) = Ratio::columns(r.steady);
        Some(PairRecord {
            scene: first_a.scene.clone(),
            count: first_a.count,
            method_a: first_a.method.clone(),
            method_b: first_b.method.clone(),
            clock,
            rounds: r.all.map_or(0, |x| x.rounds as u32),
            ratio,
            ratio_ci95_lo,
            ratio_ci95_hi,
            ratio_transition,
            ratio_transition_ci95_lo,
            ratio_transition_ci95_hi,
            ratio_steady,
            ratio_steady_ci95_lo,
            ratio_steady_ci95_hi,
            different: r.all.and_then(|x| x.different()),
        })
    }
}

/// The rows of pairs.csv for one block: `blocks` each reported method's frame records in the order the methods
/// were listed; a row per unordered pair (a before b in that order), on the block's `clock`.
pub fn pair_records(blocks: &[Vec<FrameRecord>], clock: Clock) -> Vec<PairRecord> {
    let mut out = Vec::new();
    for (i, a) in blocks.iter().enumerate() {
        for b in &blocks[i + 1..] {
            out.extend(PairRecord::new(a, b, clock));
        }
    }
    out
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

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub(crate) fn row(frame: u32, gpu: Option<f64>, rmse: f64, pop: f64) -> FrameRecord {
        FrameRecord {
            scene: "s".into(),
            method: "m".into(),
            count: 1,
            frame,
            gpu_ms: gpu,
            cpu_ms: 2.0,
            triangles: 100 + frame as u64,
            draw_calls: 1,
            units_drawn: 1,
            t_instances: 0,
            lod_mean: 0.0,
            k_mean: None,
            rmse: Some(rmse),
            pop: Some(pop),
            lodpop: Some(0.0),
            lodpop_coverage: None,
            lodpop_shading: None,
            de2000_mean: Some(rmse / 2.0),
            uncovered_px: Some(0),
            crack_px: Some(0),
            flip_mean: None,
            combine_gpu_ms: None,
            lag_rmse: None,
            shadow_rmse: None,
            shadow_lodpop: None,
            splits: None,
            merges: None,
            select_cpu_ms: None,
            round: 0,
        }
    }

    /// Rows of `rounds` rounds of `per_round` frames, frame f in transition when `transition(f)`, timed
    /// `time(round, f)`.
    fn timed_rows(
        rounds: u32,
        per_round: u32,
        transition: impl Fn(u32) -> bool,
        time: impl Fn(u32, u32) -> f64,
    ) -> Vec<FrameRecord> {
        (0..rounds * per_round)
            .map(|f| FrameRecord {
                t_instances: transition(f) as u32,
                round: f / per_round,
                ..row(f, Some(time(f / per_round, f)), 0.0, 0.0)
            })
            .collect()
    }

    #[test]
    fn paired_ratios_cancel_drift_between_rounds() {
        // The machine slows down round by round; the method costs 1.5x the baseline on transition frames and
        // the same elsewhere. Paired by round, the drift cancels exactly.
        let drift = |r: u32| 1.0 + 0.3 * r as f64;
        let tr = |f: u32| f.is_multiple_of(4);
        let base = timed_rows(6, 8, tr, |r, _| drift(r));
        let method = timed_rows(6, 8, tr, |r, f| drift(r) * if tr(f) { 1.5 } else { 1.0 });
        let p = PairedRatios::new(
            &method,
            &base,
            Clock::of([&method, &base].into_iter().flatten()),
        );
        let (all, t, s) = (p.all.unwrap(), p.transition.unwrap(), p.steady.unwrap());
        assert!((t.ratio - 1.5).abs() < 1e-12 && (s.ratio - 1.0).abs() < 1e-12);
        assert!(
            (all.ratio - 1.0).abs() < 1e-12,
            "the median frame is steady"
        );
        assert_eq!((all.rounds, t.rounds), (6, 6));
        // No spread between rounds: the interval is the point.
        let (lo, hi) = t.ci95.unwrap();
        assert!((lo - 1.5).abs() < 1e-9 && (hi - 1.5).abs() < 1e-9);
        // A method measured against itself is 1 with an interval around it.
        let noisy = timed_rows(6, 8, tr, |r, f| {
            drift(r) * (1.0 + 0.01 * ((f * 7) % 5) as f64)
        });
        let aa = PairedRatios::new(&noisy, &base, Clock::GpuMs).all.unwrap();
        let (lo, hi) = aa.ci95.unwrap();
        assert!(lo < aa.ratio && aa.ratio < hi, "{aa:?}");
    }

    #[test]
    fn ratios_fall_back_to_cpu_time_and_skip_rounds_without_the_frames() {
        // Only round 0 holds transition frames: a ratio but no interval.
        let base: Vec<FrameRecord> = timed_rows(3, 4, |f| f < 2, |_, _| 1.0)
            .into_iter()
            .map(|r| FrameRecord {
                gpu_ms: None,
                cpu_ms: 2.0,
                ..r
            })
            .collect();
        let method: Vec<FrameRecord> = base
            .iter()
            .map(|r| FrameRecord {
                cpu_ms: 3.0,
                ..r.clone()
            })
            .collect();
        let p = PairedRatios::new(
            &method,
            &base,
            Clock::of([&method, &base].into_iter().flatten()),
        );
        let t = p.transition.unwrap();
        assert_eq!((t.ratio, t.ci95, t.rounds), (1.5, None, 1));
        assert_eq!(p.all.unwrap().rounds, 3);
        let mut s = SummaryRecord::from_frames(&method, 0, 1, Clock::CpuMs).unwrap();
        s.set_ratios("discrete", &method, &base);
        assert_eq!(s.rounds, 3);
        assert_eq!(s.ratio_to_baseline, Some(1.5));
        assert_eq!(s.baseline.as_deref(), Some("discrete"));
    }

    #[test]
    fn one_missing_timestamp_puts_every_ratio_of_the_block_on_cpu_time() {
        // Three methods; on the GPU clock b and c cost 2x a, on the CPU clock 3x. One frame of c lacks its
        // gpu_ms: every ratio of the block, b over a included, is of cpu_ms.
        let method = |name: &str, gpu: f64, cpu: f64| -> Vec<FrameRecord> {
            timed_rows(4, 5, |f| f % 3 == 0, |r, _| 1.0 + 0.1 * r as f64)
                .into_iter()
                .map(|r| FrameRecord {
                    method: name.into(),
                    gpu_ms: r.gpu_ms.map(|t| t * gpu),
                    cpu_ms: r.gpu_ms.unwrap_or(1.0) * cpu,
                    ..r
                })
                .collect()
        };
        let (a, b, mut c) = (
            method("a", 1.0, 1.0),
            method("b", 2.0, 3.0),
            method("c", 2.0, 3.0),
        );
        c[7].gpu_ms = None;
        let blocks = vec![a.clone(), b.clone(), c.clone()];
        let clock = Clock::of_block(&blocks);
        assert_eq!(clock, Clock::CpuMs);
        assert_eq!(Clock::of_block(&blocks[..2]), Clock::GpuMs);
        let mut s = SummaryRecord::from_frames(&b, 0, 1, clock).unwrap();
        s.set_ratios("a", &b, &a);
        assert_eq!(s.clock, Clock::CpuMs);
        assert!((s.ratio_to_baseline.unwrap() - 3.0).abs() < 1e-12, "{s:?}");
        let pairs = pair_records(&blocks, clock);
        assert_eq!(
            pairs
                .iter()
                .map(|p| (p.method_a.as_str(), p.method_b.as_str(), p.clock))
                .collect::<Vec<_>>(),
            [
                ("a", "b", Clock::CpuMs),
                ("a", "c", Clock::CpuMs),
                ("b", "c", Clock::CpuMs)
            ]
        );
        assert!(
            (pairs[0].ratio.unwrap() - 1.0 / 3.0).abs() < 1e-12,
            "{:?}",
            pairs[0]
        );
        assert!((pairs[2].ratio.unwrap() - 1.0).abs() < 1e-12);
        // No spread between rounds: the interval is the point, which excludes 1 for a, b and holds it for b, c.
        assert_eq!(
            (pairs[0].different, pairs[2].different),
            (Some(true), Some(false))
        );
        assert_eq!(pairs[0].rounds, 4);
        let info = BlockRounds {
            scene: "s".into(),
            count: 1,
            seed: 0,
            warmup_transition_frames: vec![],
            timed_only: vec![],
            rounds: (0..4)
                .map(|r| Round {
                    round: r,
                    frames: [r * 5, r * 5 + 5],
                    order: vec!["a".into(), "b".into(), "c".into()],
                })
                .collect(),
        };
        let rounds = round_records(&blocks, &info, Some("a"), clock);
        assert!(rounds.iter().all(|r| r.time == Clock::CpuMs));
        let b0 = rounds.iter().find(|r| r.method == "b").unwrap();
        assert!((b0.ratio_to_baseline.unwrap() - 3.0).abs() < 1e-12);
    }

    #[test]
    fn tri_alternation_covers_every_frame() {
        let with = |tris: &[u64]| {
            let rows: Vec<FrameRecord> = tris
                .iter()
                .enumerate()
                .map(|(f, &t)| FrameRecord {
                    triangles: t,
                    ..row(f as u32, None, 0.0, 0.0)
                })
                .collect();
            tri_alternation_max(&rows)
        };
        // 200 -> 100 on the first pair of frames is 50 %; 100 -> 110 is 10 %.
        assert!((with(&[200, 100, 110, 100]) - 0.5).abs() < 1e-12);
        assert!((with(&[100, 110, 100]) - 0.1).abs() < 1e-12);
        assert_eq!(with(&[200]), 0.0);
        assert_eq!(with(&[]), 0.0);
    }

    #[test]
    fn summary_of_rows() {
        let rows = vec![
            row(0, Some(1.0), 0.0, 0.0),
            row(1, Some(3.0), 0.2, 0.5),
            row(2, Some(2.0), 0.1, 0.1),
        ];
        let s = SummaryRecord::from_frames(&rows, 0, 7, Clock::GpuMs).unwrap();
        assert_eq!(s.frames, 3);
        assert_eq!(s.gpu_ms_median, Some(2.0));
        assert!((s.rmse_mean.unwrap() - 0.1).abs() < 1e-12);
        assert_eq!(s.rmse_max, Some(0.2));
        assert_eq!(s.pop_max, Some(0.5));
        assert_eq!(s.triangles_mean, 101.0);
        let no_gpu: Vec<_> = rows
            .iter()
            .map(|r| FrameRecord {
                gpu_ms: None,
                ..r.clone()
            })
            .collect();
        let s_no_gpu = SummaryRecord::from_frames(&no_gpu, 0, 7, Clock::CpuMs).unwrap();
        assert_eq!(s_no_gpu.gpu_ms_median, None);
        assert_eq!(s_no_gpu.gpu_ms_median_steady, None);
        // The intervals hold the statistic, and are the same for the same seed.
        let (lo, m, hi) = (
            s.rmse_mean_ci95_lo.unwrap(),
            s.rmse_mean.unwrap(),
            s.rmse_mean_ci95_hi.unwrap(),
        );
        assert!(lo <= m && m <= hi);
        assert_eq!(
            s,
            SummaryRecord::from_frames(&rows, 0, 7, Clock::GpuMs).unwrap()
        );
    }

    #[test]
    fn transitions_are_runs_of_frames_in_transition_with_a_tail() {
        let t = [0u32, 1, 1, 0, 0, 0, 2, 0];
        let rows: Vec<FrameRecord> = t
            .iter()
            .enumerate()
            .map(|(f, &n)| FrameRecord {
                t_instances: n,
                lodpop: Some([0.0, 0.1, 0.3, 0.2, 0.0, 0.05, 0.4, 0.0][f]),
                lodpop_coverage: None,
                lodpop_shading: None,
                ..row(f as u32, None, 0.01 * f as f64, 0.0)
            })
            .collect();
        let pairs: Vec<TransitionPair> = t
            .iter()
            .map(|&n| match n {
                0 => TransitionPair::None,
                1 => TransitionPair::None.with(0, 1),
                _ => TransitionPair::None.with(0, 1).with(1, 2),
            })
            .collect();
        let tr = transitions(&rows, &pairs);
        assert_eq!(tr.len(), 2);
        assert_eq!((tr[0].first_frame, tr[0].last_frame), (1, 2));
        assert_eq!(tr[0].lods, "0->1");
        // Frames 1-4 (two after the last): the largest lodpop 0.3 at frame 2, rmse at frame 4.
        assert_eq!(
            (tr[0].lodpop_max, tr[0].lodpop_max_frame),
            (Some(0.3), Some(2))
        );
        assert!((tr[0].rmse_max.unwrap() - 0.04).abs() < 1e-12);
        assert_eq!((tr[1].first_frame, tr[1].lods.as_str()), (6, "mixed"));
        // The tail is cut at the end of the path.
        assert!((tr[1].rmse_max.unwrap() - 0.07).abs() < 1e-12);
        assert!(transitions(&rows[..1], &pairs[..1]).is_empty());
    }

    /// A run of transition frames whose first frames hold one pair and later frames another (one instance
    /// starts its transition while another is in its own) is `mixed`, not its first frame's pair.
    #[test]
    fn a_transition_is_labelled_by_all_its_frames() {
        let rows: Vec<FrameRecord> = (0..4)
            .map(|f| FrameRecord {
                t_instances: [0, 1, 1, 1][f],
                ..row(f as u32, None, 0.0, 0.0)
            })
            .collect();
        let none = TransitionPair::None;
        let pairs = [none, none.with(2, 3), none.with(2, 3), none.with(1, 2)];
        assert_eq!(transitions(&rows, &pairs)[0].lods, "mixed");
        let pairs = [none, none.with(2, 3), none.with(2, 3), none.with(2, 3)];
        assert_eq!(transitions(&rows, &pairs)[0].lods, "2->3");
    }

    #[test]
    fn without_the_quality_pass_its_figures_are_empty_not_zero() {
        let rows: Vec<FrameRecord> = (0..4)
            .map(|f| FrameRecord {
                t_instances: (f == 1) as u32,
                rmse: None,
                pop: None,
                lodpop: None,
                lodpop_coverage: None,
                lodpop_shading: None,
                de2000_mean: None,
                uncovered_px: None,
                crack_px: None,
                ..row(f, Some(1.0 + f as f64), 0.0, 0.0)
            })
            .collect();
        let s = SummaryRecord::from_frames(&rows, 0, 1, Clock::GpuMs).unwrap();
        assert_eq!(s.gpu_ms_median, Some(2.5));
        assert_eq!(
            (
                s.rmse_mean,
                s.rmse_mean_ci95_lo,
                s.rmse_max,
                s.pop_max,
                s.pop_p95
            ),
            (None, None, None, None, None)
        );
        assert_eq!(
            (s.lodpop_max, s.lodpop_p95, s.lodpop_sum),
            (None, None, None)
        );
        assert_eq!(
            (
                s.uncovered_px_mean,
                s.crack_px_mean,
                s.crack_px_max,
                s.de2000_mean
            ),
            (None, None, None, None)
        );
        let tr = transitions(&rows, &[TransitionPair::None.with(0, 1); 4]);
        assert_eq!(tr.len(), 1);
        assert_eq!(
            (
                tr[0].lodpop_max,
                tr[0].lodpop_max_frame,
                tr[0].pop_max,
                tr[0].rmse_max
            ),
            (None, None, None, None)
        );
    }

    #[test]
    fn near_transitions_adds_the_lead_and_the_tail() {
        let near = near_transitions(&[0, 0, 0, 1, 0, 0, 0, 0, 1]);
        assert_eq!(
            near,
            vec![false, true, true, true, true, true, true, true, true]
        );
        assert!(near_transitions(&[0, 0]).iter().all(|&x| !x));
    }
}
