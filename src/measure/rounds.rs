//! The warm-up and the timing rounds of a block's methods.
//!
//! - Warm-up ([`WarmUpPlan`]): `warmup` untimed frames, then the first frames of each distinct transition on
//!   each side of its midpoint, so every pipeline a method uses has run once before timing, then the first
//!   timed frame's pose as the frame before it (`Method::replay_as_previous`), so the first timed frame finds
//!   the state every later one finds.
//! - Timing rounds ([`BlockGpu::time_round`], driven by `BlockRunner::measure_block`): the path is cut into `rounds` consecutive segments; round r
//!   times every method over segment r in a seeded shuffled order, each method continuing its own walk, so drift
//!   of the machine's speed falls on all methods alike and each round pairs the methods on the same frames.
//!   Nothing but the method's own work is in a timed frame (no metric, no read-back, no stage timestamps). Each
//!   frame is submitted and waited for, so `cpu_ms` is a true encode-to-completion time and frames never
//!   overlap; GPU timestamps are resolved into one buffer per method and read once after the rounds. With
//!   `--clock-warmup`, the GPU is kept busy before each segment until its clock is up
//!   (`probe_rounds::ClockCheck::warm`), outside the segment's time.

use super::block_gpu::BlockGpu;
use super::driver::check_interrupt;
use super::driver::{FrameDriver, FrameFacts};
use super::effects::{Casters, ShadowRole};
use crate::error::Result;
use crate::gpu::timestamps::GpuTimer;
use crate::gpu::DrawStats;
use crate::measure::records::{BlockRounds, Round, TransitionPair};
use crate::methods::is_reference;
use crate::methods::{FrameInput, Method, MethodEntry};
use crate::rng::SplitMix64;
use crate::scene::Scene;
use indicatif::ProgressBar;
use std::time::Instant;

/// Instance bytes a method moved over its timed frames.
#[derive(Debug, Clone, Copy, Default)]
pub struct Uploads {
    /// Bytes of the instance lists it built.
    pub listed: u64,
    /// Bytes it wrote to the GPU.
    pub written: u64,
}

/// One method of a block from its creation through the timing rounds: the method (kept for its quality pass),
/// its own walk along the path, and what its timed frames measured.
pub struct TimedMethod<'s> {
    pub label: String,
    pub(super) entry: MethodEntry,
    pub(super) method: Box<dyn Method>,
    pub(super) driver: FrameDriver<'s>,
    timer: Option<GpuTimer>,
    pub(super) facts: Vec<FrameFacts>,
    pub(super) cpu_ms: Vec<f64>,
    pub(super) stats: Vec<DrawStats>,
    /// The round each frame was timed in.
    pub(super) round: Vec<u32>,
    /// GPU time per frame, read after the last round (None without timestamp queries).
    pub(super) gpu_ms: Vec<Option<f64>>,
    /// Wall time of each timed segment (one per round, in round order), ms.
    pub(super) segment_ms: Vec<f64>,
    pub(super) uploads: Uploads,
    /// `--warmup` (the frames of the path rendered untimed first; [`WarmUpPlan`] adds transition frames).
    pub(super) warmup: u32,
    /// `--clock-warmup`: the GPU clock's warm-up before each of its timed segments.
    pub(super) clock_warmups: Vec<crate::measure::probe_rounds::WarmUp>,
}

impl TimedMethod<'_> {
    /// Wall time per timed frame (render + wait), ms.
    pub fn ms_per_frame(&self) -> f64 {
        self.segment_ms.iter().sum::<f64>() / self.cpu_ms.len().max(1) as f64
    }
}

/// The frames every method renders untimed before the rounds: the first `warmup` frames of the path (wrapping),
/// then the first frame of each distinct transition of the path on each side of its midpoint (`lod_from ->
/// lod_to` pair, and k below or from 0.5: a transition walked back has the same pair and starts from the other
/// side) and the two frames after it, so that every pipeline and buffer a method uses in a transition is used
/// once before timing (`alpha-zwrite` switches pipelines at k = 0.5). The warm-up then ends on frame 0 (see
/// [`BlockGpu::time_methods`]).
#[derive(Debug, Clone, PartialEq)]
pub struct WarmUpPlan {
    pub warmup: u32,
    pub transition_frames: Vec<u32>,
}

impl WarmUpPlan {
    /// Walks the path once on the CPU to find the transitions.
    pub fn new(scene: &Scene, warmup: u32) -> WarmUpPlan {
        let mut driver = FrameDriver::new(scene);
        let mut seen: Vec<(TransitionPair, bool)> = Vec::new();
        let mut frames: Vec<u32> = Vec::new();
        for f in 0..scene.frames {
            let facts = driver.advance(f);
            let key = (facts.pair, facts.k_mean.is_some_and(|k| k >= 0.5));
            if facts.pair != TransitionPair::None && !seen.contains(&key) {
                seen.push(key);
                frames.extend((f..f + 3).filter(|&g| g < scene.frames));
            }
        }
        frames.sort_unstable();
        frames.dedup();
        WarmUpPlan {
            warmup,
            transition_frames: frames,
        }
    }
}

/// The frames of round `r` of `rounds` over `frames` frames: consecutive segments of (nearly) equal length.
pub fn round_frames(r: u32, rounds: u32, frames: u32) -> (u32, u32) {
    let at = |i: u32| (i as u64 * frames as u64 / rounds.max(1) as u64) as u32;
    (at(r), at(r + 1))
}

/// Round `r`'s order of `n` methods: a Fisher-Yates shuffle drawn from `rng`.
pub fn shuffled_order(n: usize, rng: &mut SplitMix64) -> Vec<usize> {
    let mut order: Vec<usize> = (0..n).collect();
    for i in (1..n).rev() {
        let j = (rng.next_u64() % (i as u64 + 1)) as usize;
        order.swap(i, j);
    }
    order
}

/// The methods of a block, created and warmed up, before their rounds.
pub struct Prepared<'s> {
    pub methods: Vec<TimedMethod<'s>>,
    /// The block's rounds as run.json records them (its `rounds` still empty).
    pub info: BlockRounds,
    pub plan: WarmUpPlan,
}

impl<'a> BlockGpu<'a> {
    /// Creates the methods `labels` (a label `NAME#k` is another instance of NAME) and warms each up
    /// ([`WarmUpPlan`]). When no label is the reference and `time_reference` (the quality pass runs), the
    /// reference is created too (its time per frame is the denominator of run.json's `quality_to_renders_ratio`),
    /// last, labelled `reference`. Each round is then [`BlockGpu::time_round`].
    pub fn prepare_methods(
        &self,
        labels: &[String],
        warmup: u32,
        seed: u64,
        time_reference: bool,
        progress: &ProgressBar,
    ) -> Result<Prepared<'a>> {
        let scene = self.scene;
        let mut labels = labels.to_vec();
        let timed_only: Vec<String> = if !time_reference || labels.iter().any(|l| is_reference(l)) {
            Vec::new()
        } else {
            labels.push("reference".into());
            vec!["reference".into()]
        };
        let plan = WarmUpPlan::new(scene, warmup);
        let mut methods = Vec::with_capacity(labels.len());
        for label in &labels {
            let mut m = self.create_timed(label, warmup)?;
            self.warm_up(
                (&m.label, m.method.as_mut(), &mut m.driver),
                &plan,
                progress,
            )?;
            methods.push(m);
        }
        Ok(Prepared {
            methods,
            info: BlockRounds {
                scene: scene.name().to_string(),
                count: scene.count,
                seed,
                warmup_transition_frames: plan.transition_frames.clone(),
                timed_only,
                rounds: Vec::new(),
            },
            plan,
        })
    }

    /// Round `r` of `rounds`: every method timed over the frames [`round_frames`]`(r)`, in an order shuffled
    /// from `rng`, each continuing its own walk along the path; returns the order (indices into `methods`).
    pub fn time_round(
        &self,
        p: &mut Prepared<'a>,
        (r, rounds): (u32, u32),
        rng: &mut SplitMix64,
        progress: &ProgressBar,
    ) -> Result<Vec<usize>> {
        let (lo, hi) = round_frames(r, rounds, self.scene.frames);
        let order = shuffled_order(p.methods.len(), rng);
        for &i in &order {
            if let Some(clock) = self.clock {
                let warm = clock.warm(self.ctx)?;
                p.methods[i].clock_warmups.push(warm);
            }
            self.time_segment(&mut p.methods[i], r, lo..hi, progress)?;
        }
        p.info.rounds.push(Round {
            round: r,
            frames: [lo, hi],
            order: order.iter().map(|&i| p.methods[i].label.clone()).collect(),
        });
        Ok(order)
    }

    /// After the last round: every method's GPU timestamps, read once.
    pub fn read_timers(&self, methods: &mut [TimedMethod<'a>]) -> Result<()> {
        for m in methods.iter_mut() {
            m.gpu_ms = match &m.timer {
                Some(t) => t.read(self.ctx)?,
                None => Vec::new(),
            };
        }
        self.ctx.check_errors()
    }

    /// The method `label`, created, with an empty record of its timed frames.
    fn create_timed(&self, label: &str, warmup: u32) -> Result<TimedMethod<'a>> {
        let (scene, frames) = (self.scene, self.scene.frames as usize);
        let entry = *self.setup.registry.get(label)?;
        Ok(TimedMethod {
            label: label.to_string(),
            entry,
            method: (entry.create)(&self.build())?,
            driver: FrameDriver::new(scene),
            timer: GpuTimer::new(self.ctx, scene.frames),
            facts: Vec::with_capacity(frames),
            cpu_ms: Vec::with_capacity(frames),
            stats: Vec::with_capacity(frames),
            round: Vec::with_capacity(frames),
            gpu_ms: Vec::new(),
            segment_ms: Vec::new(),
            uploads: Uploads::default(),
            warmup,
            clock_warmups: Vec::new(),
        })
    }

    /// `plan`'s warm-up frames, untimed, then frame 0 as the frame before the first timed frame (frame 0 of
    /// round 0): drawn, then handed to `Method::replay_as_previous`, so that the first timed frame follows a
    /// frame as every other does (FSI renders one LOD buffer there, not both). The walk `driver` is left reset,
    /// at the start of the path. The quality pass's own instance of a method is warmed up the same way, so that
    /// its frames are the timed frames (the method's state included).
    pub(super) fn warm_up(
        &self,
        (label, method, driver): (&str, &mut dyn Method, &mut FrameDriver<'_>),
        plan: &WarmUpPlan,
        progress: &ProgressBar,
    ) -> Result<()> {
        let scene = self.scene;
        for w in 0..plan.warmup {
            let f = w % scene.frames;
            if f == 0 {
                driver.reset();
            }
            driver.advance(f);
            self.render_untimed((label, &mut *method), driver, f)?;
            progress.inc(1);
        }
        driver.reset();
        let last = plan.transition_frames.last().copied();
        for f in 0..last.map_or(0, |l| l + 1) {
            driver.advance(f);
            if plan.transition_frames.binary_search(&f).is_ok() {
                self.render_untimed((label, &mut *method), driver, f)?;
            }
        }
        driver.reset();
        if scene.frames > 0 {
            driver.advance(0);
            self.render_untimed((label, &mut *method), driver, 0)?;
            method.replay_as_previous();
        }
        driver.reset();
        Ok(())
    }

    /// `--shadows on`, outside the quality pass: what `m` casts this frame, into the method's shadow map.
    fn own_shadow(
        &self,
        (label, method): (&str, &dyn Method),
        input: &FrameInput<'_>,
    ) -> Option<wgpu::CommandBuffer> {
        let casters = if is_reference(label) {
            Casters::Reference
        } else {
            Casters::Method
        };
        let shadows = self.shadows.as_ref()?;
        Some(shadows.commands(
            &self.gpu,
            method,
            input,
            input.states,
            (ShadowRole::Method, casters),
        ))
    }

    fn render_untimed(
        &self,
        (label, method): (&str, &mut dyn Method),
        driver: &FrameDriver<'_>,
        f: u32,
    ) -> Result<()> {
        check_interrupt()?;
        let ctx = self.ctx;
        self.write_frame(f);
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let input = driver.input(f);
        method.encode(&self.gpu, &input, &mut encoder, &self.timing_target);
        let shadow = self.own_shadow((label, &*method), &input);
        ctx.queue
            .submit(shadow.into_iter().chain([encoder.finish()]));
        ctx.wait_idle()
    }

    /// Times `m` over `frames` (the next frames of its walk) in round `round`: each frame submitted and waited
    /// for, bracketed by the method's own timestamps, nothing else in its command buffer.
    pub(super) fn time_segment(
        &self,
        m: &mut TimedMethod<'_>,
        round: u32,
        frames: std::ops::Range<u32>,
        progress: &ProgressBar,
    ) -> Result<()> {
        let ctx = self.ctx;
        let uploads_before = self.gpu.uploads.get();
        let start = Instant::now();
        for f in frames {
            check_interrupt()?;
            m.facts.push(m.driver.advance(f));
            let t0 = Instant::now();
            self.write_frame(f);
            // With --shadows on the shadow pass goes in a command buffer of its own, before the frame's (it
            // draws what the method decided in `encode`); the method's timestamps open it.
            let mut first = ctx.device.create_command_encoder(&Default::default());
            if let Some(t) = &m.timer {
                t.begin(&mut first, f);
            }
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            let input = FrameInput {
                timed: true,
                ..m.driver.input(f)
            };
            let stats = m
                .method
                .encode(&self.gpu, &input, &mut encoder, &self.timing_target);
            m.stats.push(stats);
            if let Some(t) = &m.timer {
                t.end(&mut encoder, f);
            }
            let shadow = self.own_shadow((&m.label, m.method.as_ref()), &input);
            ctx.queue.submit(
                [first.finish()]
                    .into_iter()
                    .chain(shadow)
                    .chain([encoder.finish()]),
            );
            ctx.wait_idle()?;
            m.cpu_ms.push(t0.elapsed().as_secs_f64() * 1e3);
            m.round.push(round);
            progress.inc(1);
        }
        m.segment_ms.push(start.elapsed().as_secs_f64() * 1e3);
        let after = self.gpu.uploads.get();
        m.uploads.listed += after.0 - uploads_before.0;
        m.uploads.written += after.1 - uploads_before.1;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounds_partition_the_path() {
        for (rounds, frames) in [(1, 10), (3, 10), (20, 300), (7, 7), (4, 3)] {
            let segments: Vec<(u32, u32)> = (0..rounds)
                .map(|r| round_frames(r, rounds, frames))
                .collect();
            assert_eq!(segments[0].0, 0);
            assert_eq!(segments[rounds as usize - 1].1, frames);
            for w in segments.windows(2) {
                assert_eq!(w[0].1, w[1].0, "{rounds} rounds over {frames} frames");
            }
            let lengths: Vec<u32> = segments.iter().map(|(lo, hi)| hi - lo).collect();
            let (min, max) = (lengths.iter().min(), lengths.iter().max());
            assert!(max.zip(min).is_some_and(|(a, b)| a - b <= 1), "{lengths:?}");
        }
    }

    #[test]
    fn round_orders_are_seeded_permutations() {
        let draw = |seed| {
            let mut rng = SplitMix64::new(seed);
            (0..20)
                .map(|_| shuffled_order(5, &mut rng))
                .collect::<Vec<_>>()
        };
        let orders = draw(3);
        assert_eq!(orders, draw(3), "the same seed gives the same orders");
        assert_ne!(orders, draw(4), "another seed gives other orders");
        for o in &orders {
            let mut sorted = o.clone();
            sorted.sort_unstable();
            assert_eq!(sorted, vec![0, 1, 2, 3, 4]);
        }
        assert!(
            orders.iter().any(|o| o[0] != 0),
            "the first method is not always first"
        );
    }
}
