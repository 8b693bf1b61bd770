//! The records lodbench writes: a row per frame (frames.csv) and a row per block (summary.csv). A frame record
//! is built once, by the runner, when every figure of its frame is known; a summary record is computed here
//! from a block's frame records with `crate::measure::stats`. The exporters only serialise them.
//!
//! - `rows.rs`: the frame rows and the block's sizes and rounds;
//! - `summaries.rs`: the statistics (summary.csv, the clock, the paired ratios, rounds.csv, pairs.csv);
//! - `transitions.rs`: transition detection (transitions.csv, the frames `--dump-transitions` dumps);
//! - `events.rs`: each instance's switches grouped into the waves a person sees (events.csv, summary.csv's
//!   visible pops).
//!
//! Every figure of the quality pass is an `Option`: empty (never 0) in a run without it (`--quality off`).

mod events;
mod rows;
mod summaries;
mod transitions;

pub use events::*;
pub use rows::*;
pub use summaries::*;
pub use transitions::*;

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
            view_pop: None,
            splits: None,
            merges: None,
            select_cpu_ms: None,
            round: 0,
            fragments: None,
        }
    }

    #[test]
    fn the_ceiling_columns_name_what_bounds_a_block() {
        // 4 frames of 100-103 triangles and 1,000-4,000 fragments, 2 ms each on the GPU's clock.
        let rows: Vec<FrameRecord> = (0..4)
            .map(|f| FrameRecord {
                fragments: Some(1000 * (f as u64 + 1)),
                ..row(f, Some(2.0), 0.0, 0.0)
            })
            .collect();
        let s = |rows: &[FrameRecord], t: Option<f64>, fr: Option<f64>| {
            let mut s = SummaryRecord::from_frames(rows, 0, 1, Clock::GpuMs).unwrap();
            s.set_ceiling(t, fr);
            s
        };
        let a = s(&rows, Some(101_500.0 / 0.8), Some(1_250_000.0 / 0.5));
        assert_eq!(a.fragments_mean, Some(2500.0));
        assert_eq!(a.triangles_per_s, Some(50_750.0));
        assert_eq!(a.fragments_per_s, Some(1_250_000.0));
        assert!((a.triangle_ceiling_share.unwrap() - 0.4).abs() < 1e-12);
        assert!((a.fragment_ceiling_share.unwrap() - 0.5).abs() < 1e-12);
        assert_eq!(a.bound, None, "neither share reaches {BOUND_SHARE}");
        let b = s(&rows, Some(100_000.0), Some(1_300_000.0));
        assert_eq!(b.bound.as_deref(), Some("fragments"));
        let c = s(&rows, Some(55_000.0), Some(1_300_000.0));
        assert_eq!(c.bound.as_deref(), Some("triangles+fragments"));
        // A frame not counted: the block's fragments are not known, nor their share.
        let mut gap = rows.clone();
        gap[2].fragments = None;
        let d = s(&gap, Some(55_000.0), Some(1_300_000.0));
        assert_eq!((d.fragments_mean, d.fragments_per_s), (None, None));
        assert_eq!(d.bound.as_deref(), Some("triangles"));
        // No ceiling read (--ceilings off): rates, but no share and no bound.
        let e = s(&rows, None, None);
        assert!(
            e.fragments_per_s.is_some() && e.fragment_ceiling_share.is_none() && e.bound.is_none()
        );
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
