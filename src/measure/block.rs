//! One scene block: the GPU objects every method's measurement shares ([`BlockGpu`]), and what a method's
//! measurement on it returns: one frame record per frame, built once every figure of the frame is known
//! (without the quality pass, from the timing rounds alone, its figures empty).
//!
//! A block is measured in rounds ([`BlockRunner::measure_block`]): round r times every method over the r-th
//! segment of the path in a shuffled order (src/measure/rounds.rs), then makes every reported method's quality
//! pass over the same segment, in the same order, each by its own instance of the method and its own
//! [`QualityStage`]. A quality segment is thus seconds, not minutes, from the timing segments of its own round,
//! and `quality_to_renders_ratio` is paired round by round as the timing ratios are.

use super::block_gpu::{BlockGpu, MethodSetup};
use super::driver::FrameDriver;
use super::quality::{
    FrameImages, QualityOptions, QualityPass, QualitySchedule, QualityStage, SegmentCost, Walk,
};
use super::reference_cache::ReferenceCache;
use super::rounds::{round_frames, Prepared, TimedMethod};
use super::stats::paired_log_ratio;
use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::measure::metrics::Metric;
use crate::measure::records::{
    near_transitions, switches, transitions, BlockInfo, BlockRounds, FrameRecord, SwitchRecord,
    TransitionPair, TransitionRecord,
};
use crate::methods::{is_reference, Method};
use crate::rng::SplitMix64;
use crate::scene::Scene;
use indicatif::ProgressBar;

/// One method's measurement on one scene block.
pub struct BlockOutput {
    pub rows: Vec<FrameRecord>,
    pub transitions: Vec<TransitionRecord>,
    /// Each instance's switches (`records::events`; none without a quality pass).
    pub switches: Vec<SwitchRecord>,
    pub info: BlockInfo,
}

/// Which quality-pass frames are handed to the caller's dump callback.
#[derive(Debug, Clone, Copy)]
pub struct DumpPolicy {
    /// Dump at all (the block was built with read-back for it).
    pub dump: bool,
    /// Only frames with an instance in transition (`--dump-transitions`).
    pub transitions_only: bool,
}

/// The GPU objects of one scene block, shared by all methods run on it.
pub struct BlockRunner<'a> {
    base: BlockGpu<'a>,
    quality: QualityOptions,
    dumps: DumpPolicy,
}

/// One method's quality pass while it is made: its own instance of the method and walk along the path, its
/// stage, and what the stage carries between segments.
struct QualityRun<'s> {
    method: Box<dyn Method>,
    driver: FrameDriver<'s>,
    stage: QualityStage,
    walk: Walk,
}

impl<'a> BlockRunner<'a> {
    /// `dump`: hand frames to the quality pass's callback; `quality.timing_only`: no quality pass.
    pub fn new(
        ctx: &'a GpuContext,
        scene: &'a Scene,
        setup: MethodSetup,
        dump: bool,
        quality: &QualityOptions,
    ) -> Result<Self> {
        let base = BlockGpu::new(ctx, scene, setup)?;
        ctx.check_errors()?;
        Ok(BlockRunner {
            base,
            quality: quality.clone(),
            dumps: DumpPolicy {
                dump,
                transitions_only: false,
            },
        })
    }

    /// Warm the GPU's clock with `clock` before each timed segment (`--clock-warmup`; None: not).
    pub fn warm_clock_with(&mut self, clock: Option<&'a crate::measure::probe_rounds::ClockCheck>) {
        self.base.clock = clock;
    }

    /// Dump only frames with an instance in transition (of those, still every `dump_every`-th frame).
    pub fn dump_transitions_only(&mut self, on: bool) {
        self.dumps.transitions_only = on;
    }

    /// Warm-up, timing and quality pass of one method alone (one round): what a run of `--method NAME
    /// --rounds 1` measures. `on_frames` is called with the quality-pass images of every `dump_every`-th frame
    /// when the runner was built with read-back.
    pub fn run_method(
        &mut self,
        label: &str,
        warmup: u32,
        dump_every: u32,
        progress: &ProgressBar,
        mut on_frames: impl FnMut(u32, FrameImages<'_>) -> Result<()>,
    ) -> Result<BlockOutput> {
        let (mut outputs, _) = self.measure_block(
            &[label.to_string()],
            (warmup, 1, 0),
            dump_every,
            progress,
            |_, f, images| on_frames(f, images),
        )?;
        let found = outputs.drain(..).find(|o| o.info.method == label);
        found.ok_or_else(|| Error::Gpu(format!("method {label} was not measured")))
    }

    /// The methods `labels` on the block, in `rounds` rounds (`(warmup, rounds, seed)`; the rounds' order is
    /// shuffled from `seed`): round r times every method over the frames [`round_frames`]`(r)`, then makes the
    /// quality pass of every method over the same frames (none with `--quality off`). Where the quality pass
    /// runs and no label is the reference, the reference is timed too, for `quality_to_renders_ratio`, and not
    /// reported. `on_frames(label, frame, images)` gets every dumped frame. Returns each reported method's
    /// output, in the order of `labels`, and the rounds.
    pub fn measure_block(
        &mut self,
        labels: &[String],
        (warmup, rounds, seed): (u32, u32, u64),
        dump_every: u32,
        progress: &ProgressBar,
        mut on_frames: impl FnMut(&str, u32, FrameImages<'_>) -> Result<()>,
    ) -> Result<(Vec<BlockOutput>, BlockRounds)> {
        let base = &self.base;
        let frames = base.scene.frames;
        let quality_on = !self.quality.timing_only;
        let mut p = base.prepare_methods(labels, warmup, seed, quality_on, progress)?;
        let dump_frames = self.dump_frames(dump_every);
        let mut runs = Vec::with_capacity(p.methods.len());
        for m in &p.methods {
            runs.push(match quality_on && !p.info.timed_only.contains(&m.label) {
                true => Some(self.quality_run(m, &p, dump_frames.clone(), progress)?),
                false => None,
            });
        }
        let rounds = rounds.clamp(1, frames.max(1));
        let longest_round = frames.div_ceil(rounds);
        let mut cache: Option<ReferenceCache> = match runs.iter().flatten().count() > 1 {
            true => runs
                .iter()
                .flatten()
                .next()
                .and_then(|q| q.stage.reference_cache(base, &self.quality, longest_round)),
            false => None,
        };
        base.ctx.check_errors()?;
        let mut rng = SplitMix64::new(seed);
        let mut orders = Vec::with_capacity(rounds as usize);
        for r in 0..rounds {
            orders.push(base.time_round(&mut p, (r, rounds), &mut rng, progress)?);
            // The quality rounds due once timing round r is done: round r itself, or with `after` every round
            // once the last is timed.
            let due = match self.quality.schedule {
                QualitySchedule::Rounds => r..r + 1,
                QualitySchedule::After if r + 1 == rounds => 0..rounds,
                QualitySchedule::After => 0..0,
            };
            for q in due {
                self.quality_round(
                    &p,
                    (&mut runs, cache.as_mut()),
                    (q, rounds),
                    &orders[q as usize],
                    progress,
                    &mut on_frames,
                )?;
            }
        }
        base.read_timers(&mut p.methods)?;
        let reference = p.methods.iter().find(|m| is_reference(&m.label));
        let reference_ms = reference.map(|m| segment_ms_per_frame(m, frames));
        let mut outputs = Vec::new();
        for (m, q) in p.methods.iter().zip(runs) {
            if p.info.timed_only.contains(&m.label) {
                continue;
            }
            let quality = match q {
                Some(q) => Some(q.stage.finish(base, q.method.as_ref(), q.walk)?),
                None => None,
            };
            base.ctx.check_errors()?;
            let rows = self.frame_records(m, quality.as_ref());
            let pairs: Vec<TransitionPair> = m.facts.iter().map(|f| f.pair).collect();
            let changes = quality.as_ref().map_or(&[][..], |q| &q.changes);
            outputs.push(BlockOutput {
                transitions: transitions(&rows, &pairs),
                switches: switches(&rows, changes),
                rows,
                info: self.block_info(m, quality.as_ref(), reference_ms.as_deref()),
            });
        }
        Ok((outputs, p.info))
    }

    /// Round `r`'s quality segments: every reported method's pass over the round's frames, in the round's
    /// timing `order` with a listed reference first.
    fn quality_round(
        &self,
        p: &Prepared<'a>,
        (runs, mut cache): (&mut [Option<QualityRun<'a>>], Option<&mut ReferenceCache>),
        (r, rounds): (u32, u32),
        order: &[usize],
        progress: &ProgressBar,
        on_frames: &mut impl FnMut(&str, u32, FrameImages<'_>) -> Result<()>,
    ) -> Result<()> {
        let base = &self.base;
        let (lo, hi) = round_frames(r, rounds, base.scene.frames);
        // A listed reference first: its pass keeps the reference frames that every later pass of the round
        // copies (drawn by another method's pass first, they would be drawn twice).
        let mut order = order.to_vec();
        order.sort_by_key(|&i| !is_reference(&p.methods[i].label));
        if let Some(c) = cache.as_deref_mut() {
            c.begin_round(lo);
        }
        for &i in &order {
            let Some(q) = runs[i].as_mut() else { continue };
            let label = &p.methods[i].label;
            q.stage.segment(
                base,
                (q.method.as_mut(), &mut q.driver),
                (&mut q.walk, lo..hi),
                cache.as_deref(),
                progress,
                &mut |f, images| on_frames(label, f, images),
            )?;
            if let Some(c) = cache.as_deref_mut() {
                c.stored(hi);
            }
        }
        Ok(())
    }

    /// The quality pass of the timed method `m` about to start: a second instance of the method, warmed up as
    /// `m` was (its frames are `m`'s timed frames, state and all), and a stage of its own.
    fn quality_run(
        &self,
        m: &TimedMethod<'a>,
        p: &Prepared<'a>,
        dump_frames: Vec<bool>,
        progress: &ProgressBar,
    ) -> Result<QualityRun<'a>> {
        let base = &self.base;
        let mut method = (m.entry.create)(&base.build())?;
        let mut driver = FrameDriver::new(base.scene);
        base.warm_up((&m.label, method.as_mut(), &mut driver), &p.plan, progress)?;
        let mut stage = QualityStage::new(base, self.dumps.dump, &self.quality)?;
        let walk = stage.begin(base, (method.as_mut(), is_reference(&m.label)), dump_frames);
        Ok(QualityRun {
            method,
            driver,
            stage,
            walk,
        })
    }

    /// Per frame, whether the quality pass hands it to the dump callback: every `dump_every`-th frame, of those
    /// only the ones near a transition with `--dump-transitions` (from the block's LOD schedule, the same for
    /// every method).
    fn dump_frames(&self, dump_every: u32) -> Vec<bool> {
        let scene = self.base.scene;
        if !self.dumps.dump || self.quality.timing_only {
            return vec![false; scene.frames as usize];
        }
        let mut driver = FrameDriver::new(scene);
        let t_instances: Vec<u32> = (0..scene.frames)
            .map(|f| driver.advance(f).t_instances)
            .collect();
        let near = near_transitions(&t_instances);
        (0..scene.frames)
            .map(|f| {
                f % dump_every.max(1) == 0 && (!self.dumps.transitions_only || near[f as usize])
            })
            .collect()
    }

    /// One record per frame from the method's timed frames and its quality pass (None: every figure of the
    /// quality pass empty).
    fn frame_records(
        &self,
        timed: &TimedMethod<'_>,
        quality: Option<&QualityPass>,
    ) -> Vec<FrameRecord> {
        let scene = self.base.scene;
        let de2000 = quality.is_some() && self.quality.metrics.contains(&Metric::De2000);
        (0..scene.frames as usize)
            .map(|f| FrameRecord {
                scene: scene.name().to_string(),
                method: timed.label.clone(),
                count: scene.count,
                frame: f as u32,
                gpu_ms: timed.gpu_ms.get(f).copied().flatten(),
                cpu_ms: timed.cpu_ms[f],
                triangles: timed.stats[f].triangles,
                draw_calls: timed.stats[f].draw_calls,
                units_drawn: timed.stats[f]
                    .clusters
                    .unwrap_or(scene.instances.len() as u64),
                t_instances: timed.facts[f].t_instances,
                lod_mean: timed.facts[f].lod_mean,
                k_mean: timed.facts[f].k_mean,
                rmse: quality.map(|q| q.metrics[f].rmse),
                pop: quality.map(|q| q.metrics[f].pop),
                lodpop: quality.map(|q| q.lodpop[f].rms),
                lodpop_coverage: quality.map(|q| q.lodpop[f].coverage),
                lodpop_shading: quality.map(|q| q.lodpop[f].shading),
                de2000_mean: quality.and_then(|q| de2000.then_some(q.metrics[f].de2000)),
                uncovered_px: quality.map(|q| q.metrics[f].uncovered_px),
                crack_px: quality.map(|q| q.metrics[f].crack_px),
                flip_mean: quality.and_then(|q| q.flip[f]),
                combine_gpu_ms: quality
                    .and_then(|q| q.stage_ms.as_ref())
                    .and_then(|s| s.get(f).copied().flatten()),
                lag_rmse: quality.and_then(|q| q.lag.as_ref().map(|l| l[f])),
                shadow_rmse: quality.and_then(|q| q.shadow.as_ref().map(|s| s.rmse[f])),
                shadow_lodpop: quality.and_then(|q| q.shadow.as_ref().map(|s| s.lodpop[f])),
                splits: timed.stats[f].selection.map(|s| s.splits),
                merges: timed.stats[f].selection.map(|s| s.merges),
                select_cpu_ms: timed.stats[f].selection.map(|s| s.cpu_ns as f64 * 1e-6),
                round: timed.round[f],
                fragments: quality.and_then(|q| q.fragments.get(f).copied().flatten()),
                view_pop: quality.and_then(|q| q.view_pop.as_ref().map(|v| v[f])),
            })
            .collect()
    }

    /// The block's facts for run.json. `reference_ms`: the reference's timing time per frame in each round.
    fn block_info(
        &self,
        timed: &TimedMethod<'_>,
        quality: Option<&QualityPass>,
        reference_ms: Option<&[f64]>,
    ) -> BlockInfo {
        let scene = self.base.scene;
        let frames = scene.frames as f64;
        let timing_ms = timed.ms_per_frame();
        let renders = quality.zip(reference_ms).and_then(|(q, r)| {
            quality_to_renders(&q.segments, &segment_ms_per_frame(timed, scene.frames), r)
        });
        BlockInfo {
            scene: scene.name().to_string(),
            method: timed.label.clone(),
            method_options: (timed.entry.options)(&self.base.setup.options),
            material_limits: timed.method.material_limits(&scene.materials),
            count: scene.count,
            width: scene.width,
            height: scene.height,
            frames: scene.frames,
            warmup: timed.warmup,
            timing_pass_ms_per_frame: timing_ms,
            quality_pass_ms_per_frame: quality.map(|q| q.ms_per_frame),
            quality_to_timing_ratio: quality.map(|q| q.ms_per_frame / timing_ms),
            quality_to_renders_ratio: renders.as_ref().map(|r| r.ratio),
            quality_to_renders_ratio_ci95_lo: renders.as_ref().and_then(|r| r.ci95).map(|ci| ci.0),
            quality_to_renders_ratio_ci95_hi: renders.as_ref().and_then(|r| r.ci95).map(|ci| ci.1),
            quality_to_renders_by_round: renders.map(|r| r.by_round),
            counterfactual_frame_share: quality.map(|q| q.counterfactual_frames as f64 / frames),
            reference_frames_copied: quality.map(|q| q.reference_frames_copied),
            wait_instance_frames: timed.facts.iter().map(|f| f.t_waiting as u64).sum(),
            waiting_max: timed.facts.iter().map(|f| f.t_waiting).max().unwrap_or(0),
            metric_gpu_ms_median: quality.and_then(|q| q.metric_gpu_ms_median),
            metric_tile_share: quality.map(|q| q.metric_tile_share),
            counterfactual_pixel_share: quality.and_then(|q| q.counterfactual_pixel_share),
            extra_target_bytes: timed.method.extra_target_bytes(),
            instance_bytes_listed_per_frame: timed.uploads.listed as f64 / frames,
            instance_bytes_written_per_frame: timed.uploads.written as f64 / frames,
            triangle_rate_before: None,
            triangle_rate_after: None,
            clock_warmup_ms: (!timed.clock_warmups.is_empty())
                .then(|| timed.clock_warmups.iter().map(|w| w.ms).sum()),
            clock_warmups_short: (!timed.clock_warmups.is_empty())
                .then(|| timed.clock_warmups.iter().filter(|w| !w.reached).count() as u32),
        }
    }
}

/// A timed method's wall time per frame in each round's segment, in round order.
fn segment_ms_per_frame(m: &TimedMethod<'_>, frames: u32) -> Vec<f64> {
    let rounds = m.segment_ms.len() as u32;
    m.segment_ms
        .iter()
        .enumerate()
        .map(|(r, ms)| {
            let (lo, hi) = round_frames(r as u32, rounds, frames);
            ms / (hi - lo).max(1) as f64
        })
        .collect()
}

/// `quality_to_renders_ratio`, round by round and over the rounds.
#[derive(Debug, Clone, PartialEq)]
pub struct QualityToRenders {
    /// Geometric mean of the rounds' ratios.
    pub ratio: f64,
    /// Its Student-t 95 % interval over rounds (None with fewer than 2 rounds).
    pub ci95: Option<(f64, f64)>,
    pub by_round: Vec<f64>,
}

/// `quality_to_renders_ratio` and its 95 % interval: per round, the quality segment's time per frame over the
/// renders it made, each at the same round's timing time per frame (`method_ms`, `reference_ms`): the method's
/// frame, the reference's on the frames it was drawn (not copied), lodpop's and view_pop's counterfactuals on the
/// frames they were drawn; then the geometric mean of the rounds' ratios and its Student-t interval. None where a round lacks a
/// time.
pub fn quality_to_renders(
    segments: &[SegmentCost],
    method_ms: &[f64],
    reference_ms: &[f64],
) -> Option<QualityToRenders> {
    let by_round = segments
        .iter()
        .enumerate()
        .map(|(r, s)| {
            let n = (s.frames[1] - s.frames[0]).max(1) as f64;
            let drawn = 1.0 - s.reference_copied as f64 / n;
            let counterfactual = (s.counterfactual_frames + s.view_frames) as f64 / n;
            let renders = method_ms.get(r)? * (1.0 + counterfactual) + reference_ms.get(r)? * drawn;
            (renders > 0.0).then(|| s.ms / n / renders)
        })
        .collect::<Option<Vec<f64>>>()?;
    let logs: Vec<f64> = by_round.iter().map(|x| x.ln()).collect();
    let (m, ci) = paired_log_ratio(&logs)?;
    Some(QualityToRenders {
        ratio: m.exp(),
        ci95: ci.map(|(lo, hi)| (lo.exp(), hi.exp())),
        by_round,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn segment(
        frames: [u32; 2],
        ms: f64,
        counterfactual_frames: u32,
        reference_copied: u32,
    ) -> SegmentCost {
        SegmentCost {
            frames,
            ms,
            counterfactual_frames,
            reference_copied,
            view_frames: 0,
        }
    }

    #[test]
    fn each_round_is_divided_by_its_own_renders() {
        // Round 0: 10 frames, 30 ms: method 1 ms + reference 2 ms a frame, all drawn, no counterfactual: 1.0.
        // Round 1: the machine twice as slow in both passes; half the counterfactual drawn, the reference copied
        // on every frame: 10 frames, 45 ms over 10 x (3 ms x 1.5): 1.0 again.
        let segments = [segment([0, 10], 30.0, 0, 0), segment([10, 20], 45.0, 5, 10)];
        let q = quality_to_renders(&segments, &[1.0, 3.0], &[2.0, 4.0]).unwrap();
        assert_eq!(q.by_round.len(), 2);
        for r in &q.by_round {
            assert!((r - 1.0).abs() < 1e-12, "{:?}", q.by_round);
        }
        assert!((q.ratio - 1.0).abs() < 1e-12);
        let (lo, hi) = q.ci95.unwrap();
        assert!((lo - 1.0).abs() < 1e-12 && (hi - 1.0).abs() < 1e-12);
    }

    #[test]
    fn the_ratio_is_the_geometric_mean_of_the_rounds() {
        let segments = [segment([0, 4], 8.0, 0, 4), segment([4, 8], 32.0, 0, 4)];
        // Per frame 2 and 8 ms over a 1 ms method (reference copied): 2 and 8, geometric mean 4.
        let q = quality_to_renders(&segments, &[1.0, 1.0], &[5.0, 5.0]).unwrap();
        assert_eq!(q.by_round, vec![2.0, 8.0]);
        assert!((q.ratio - 4.0).abs() < 1e-12);
        let (lo, hi) = q.ci95.unwrap();
        assert!(lo < 4.0 && 4.0 < hi);
        let one = quality_to_renders(&segments[..1], &[1.0], &[5.0]).unwrap();
        assert_eq!(one.ci95, None, "one round has no interval");
        assert!(
            quality_to_renders(&segments, &[1.0], &[5.0]).is_none(),
            "a round without a timing time has no ratio"
        );
    }
}
