//! The statistics of a block's frame records: a row per block (summary.csv, [`SummaryRecord`]), the clock its
//! times are on ([`Clock`]), the paired ratios round by round ([`PairedRatios`]), a row per round (rounds.csv)
//! and per pair of methods (pairs.csv).

use super::rows::{BlockRounds, FrameRecord};
use crate::measure::stats::{bootstrap_ci, mean, percentile};
use serde::Serialize;

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
    /// The fewest frames any instance spent in one transition along the path (of those that begin and end on
    /// it), the same for every method of the block: 1 means the camera crossed a switch's band within a frame,
    /// where no blending method can act ([`crate::measure::shortest_transition`]); empty without transitions.
    pub transition_frames_min: Option<u32>,
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
    /// Pop events (transitions within a few frames of each other joined, `events.rs`) and how many a minute of
    /// the path (at its frame rate) exceed `visible_pop_threshold`: 1 JND of `--calibration`, else the lodpop
    /// budget (`--budget-lodpop`, else half of discrete's lodpop_max, the answer's default).
    pub pop_events: Option<u32>,
    pub visible_pop_threshold: Option<f64>,
    pub visible_pops_per_min: Option<f64>,
    /// With `--calibration`: lodpop_max in JNDs of the calibration's lodpop threshold.
    pub lodpop_max_jnd: Option<f64>,
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
    /// `--impostor`: the largest view_pop (the impostors' own popping under motion).
    pub view_pop_max: Option<f64>,
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
    /// Mean over the frames the quality pass counted of `fragments` (fragment shader invocations of the
    /// method's frame; empty with `--quality off`, on an adapter without pipeline statistics queries, or where a
    /// frame was not counted).
    pub fragments_mean: Option<f64>,
    /// `fragments_mean` over the median frame time (the block's clock), a second.
    pub fragments_per_s: Option<f64>,
    /// `fragments_per_s` over the run's fragment ceiling (run.json's `fragment_ceiling`: the fastest of the fill
    /// probes read at the run's start, whose full-screen quads shade every fragment they count).
    pub fragment_ceiling_share: Option<f64>,
    /// What the block draws near the adapter's rate of: `triangles` and/or `fragments`, where that share is
    /// 0.8 or more (joined by `+`).
    pub bound: Option<String>,
}

/// A share of a ceiling at or above which the block is said to be bound by it (`bound`).
pub const BOUND_SHARE: f64 = 0.8;

impl SummaryRecord {
    /// Fills the ceiling columns from the run's triangle and fragment ceilings (a second each).
    pub fn set_ceiling(&mut self, triangle_ceiling: Option<f64>, fragment_ceiling: Option<f64>) {
        let ms = match self.clock {
            Clock::GpuMs => self.gpu_ms_median,
            Clock::CpuMs => Some(self.cpu_ms_median),
        };
        let per_s = |amount: f64| ms.filter(|ms| *ms > 0.0).map(|ms| amount / (ms / 1e3));
        let share = |rate: Option<f64>, ceiling: Option<f64>| {
            rate.zip(ceiling.filter(|c| *c > 0.0)).map(|(r, c)| r / c)
        };
        self.triangles_per_s = per_s(self.triangles_mean);
        self.triangle_ceiling_share = share(self.triangles_per_s, triangle_ceiling);
        self.fragments_per_s = self.fragments_mean.and_then(per_s);
        self.fragment_ceiling_share = share(self.fragments_per_s, fragment_ceiling);
        let bound: Vec<&str> = [
            ("triangles", self.triangle_ceiling_share),
            ("fragments", self.fragment_ceiling_share),
        ]
        .into_iter()
        .filter(|(_, s)| s.is_some_and(|s| s >= BOUND_SHARE))
        .map(|(name, _)| name)
        .collect();
        self.bound = (!bound.is_empty()).then(|| bound.join("+"));
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
        let mut s = SummaryRecord {
            scene: first.scene.clone(),
            method: first.method.clone(),
            count: first.count,
            frames: rows.len() as u32,
            extra_target_bytes,
            tri_alternation_max: tri_alternation_max(rows),
            clock,
            rounds: rows.iter().map(|r| r.round + 1).max().unwrap_or(0),
            // The baseline, the ratios and the ceiling's columns: set_ratios and set_ceiling fill them.
            ..SummaryRecord::default()
        };
        s.set_timing_figures(rows);
        s.set_image_figures(rows, seed);
        Some(s)
    }

    /// The timing pass's figures of the block's rows: times (the GPU's also in and out of transition), and
    /// what was drawn.
    fn set_timing_figures(&mut self, rows: &[FrameRecord]) {
        let gpu: Vec<f64> = rows.iter().filter_map(|r| r.gpu_ms).collect();
        let cpu: Vec<f64> = rows.iter().map(|r| r.cpu_ms).collect();
        let gpu_where = |transition: bool| {
            rows.iter()
                .filter(|r| (r.t_instances > 0) == transition)
                .filter_map(|r| r.gpu_ms)
                .collect::<Vec<_>>()
        };
        self.gpu_ms_median = percentile(&gpu, 50.0);
        self.gpu_ms_median_transition = percentile(&gpu_where(true), 50.0);
        self.gpu_ms_median_steady = percentile(&gpu_where(false), 50.0);
        self.gpu_ms_p5 = percentile(&gpu, 5.0);
        self.gpu_ms_p95 = percentile(&gpu, 95.0);
        self.cpu_ms_median = percentile(&cpu, 50.0).unwrap_or(f64::NAN);
        self.triangles_mean = mean(rows.iter().map(|r| r.triangles as f64));
        // Counted on every frame, or not known.
        let fragments: Option<Vec<f64>> =
            rows.iter().map(|r| r.fragments.map(|n| n as f64)).collect();
        self.fragments_mean = fragments
            .filter(|v| !v.is_empty())
            .map(|v| mean(v.into_iter()));
        self.draw_calls_mean = mean(rows.iter().map(|r| r.draw_calls as f64));
        self.t_instances_mean = mean(rows.iter().map(|r| r.t_instances as f64));
        self.units_drawn_mean = mean(rows.iter().map(|r| r.units_drawn as f64));
        self.combine_gpu_ms_median = percentile(
            &rows
                .iter()
                .filter_map(|r| r.combine_gpu_ms)
                .collect::<Vec<_>>(),
            50.0,
        );
    }

    /// The quality pass's figures of the block's rows (`seed` drives the RMSE's bootstrap): each None when a
    /// frame has none (`--quality off`).
    fn set_image_figures(&mut self, rows: &[FrameRecord], seed: u64) {
        let lag: Option<Vec<f64>> = rows.iter().map(|r| r.lag_rmse).collect();
        let shadow_rmse: Option<Vec<f64>> = rows.iter().map(|r| r.shadow_rmse).collect();
        let shadow_lodpop: Option<Vec<f64>> = rows.iter().map(|r| r.shadow_lodpop).collect();
        let pop: Option<Vec<f64>> = rows.iter().map(|r| r.pop).collect();
        let rmse: Option<Vec<f64>> = rows.iter().map(|r| r.rmse).collect();
        let lodpop: Option<Vec<f64>> = rows.iter().map(|r| r.lodpop).collect();
        let uncovered: Option<Vec<u64>> = rows.iter().map(|r| r.uncovered_px).collect();
        let crack: Option<Vec<u64>> = rows.iter().map(|r| r.crack_px).collect();
        let max = |v: &Vec<f64>| v.iter().copied().fold(0.0, f64::max);
        let mean_of = |v: &Vec<u64>| mean(v.iter().map(|&x| x as f64));
        let de2000: Option<Vec<f64>> = rows.iter().map(|r| r.de2000_mean).collect();
        let rmse_ci = rmse.as_ref().map(|rmse| {
            bootstrap_ci(rmse, seed ^ 0x524D_5345, |v| Some(mean(v.iter().copied())))
                .unwrap_or((0.0, 0.0))
        });
        self.rmse_mean = rmse.as_ref().map(|v| mean(v.iter().copied()));
        self.rmse_mean_ci95_lo = rmse_ci.map(|c| c.0);
        self.rmse_mean_ci95_hi = rmse_ci.map(|c| c.1);
        self.rmse_max = rmse.as_ref().map(max);
        self.pop_max = pop.as_ref().map(max);
        self.pop_p95 = pop.as_ref().map(|v| percentile(v, 95.0).unwrap_or(0.0));
        self.lodpop_max = lodpop.as_ref().map(max);
        self.lodpop_p95 = lodpop.as_ref().map(|v| percentile(v, 95.0).unwrap_or(0.0));
        self.lodpop_sum = lodpop.as_ref().map(|v| v.iter().sum());
        self.de2000_mean = de2000.as_ref().map(|v| mean(v.iter().copied()));
        self.de2000_max = de2000.map(|v| v.into_iter().fold(0.0, f64::max));
        self.flip_mean = rows
            .iter()
            .map(|r| r.flip_mean)
            .collect::<Option<Vec<f64>>>()
            .map(|v| mean(v.into_iter()));
        self.uncovered_px_mean = uncovered.as_ref().map(mean_of);
        self.crack_px_mean = crack.as_ref().map(mean_of);
        self.crack_px_max = crack.map(|v| v.into_iter().max().unwrap_or(0));
        self.lag_rmse_mean = lag.as_ref().map(|v| mean(v.iter().copied()));
        self.lag_rmse_max = lag.map(|v| v.into_iter().fold(0.0, f64::max));
        self.shadow_rmse_mean = shadow_rmse.as_ref().map(|v| mean(v.iter().copied()));
        self.shadow_lodpop_max = shadow_lodpop.map(|v| v.into_iter().fold(0.0, f64::max));
        let view_pop: Option<Vec<f64>> = rows.iter().map(|r| r.view_pop).collect();
        self.view_pop_max = view_pop.map(|v| v.into_iter().fold(0.0, f64::max));
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
