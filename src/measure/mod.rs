//! The measurement of the methods of one scene block: warm-up, timing rounds and a quality pass over the same
//! frames, then one frame record per frame, built once every figure of the frame is known.
//!
//! - Warm-up ([`WarmUpPlan`]): `warmup` untimed frames, then the first frames of each distinct transition, so
//!   every pipeline a method uses has run once before timing.
//! - Timing rounds ([`BlockRunner::time_methods`]): the path is cut into `rounds` consecutive segments; round r
//!   times every method over segment r in a seeded shuffled order, each method continuing its own walk, so drift
//!   of the machine's speed falls on all methods alike and each round pairs the methods on the same frames.
//!   Nothing but the method's own work is in a timed frame (no metric, no read-back, no stage timestamps). Each
//!   frame is submitted and waited for, so `cpu_ms` is a true encode-to-completion time and frames never
//!   overlap; GPU timestamps are resolved into one buffer per method and read once after the rounds.
//! - Quality pass ([`BlockRunner::measure_quality`]): per frame the reference and the method are rendered into
//!   two targets and the metric kernel reduces their difference to scalars on the GPU; the scalars of all
//!   frames are read back once at the end. FSI's combination pass is timed here.

pub mod diff_kernel;
pub mod metric_kernel;
pub mod metrics;
pub mod records;
pub mod stats;

use crate::error::{Error, Result};
use crate::gpu::scene_gpu::{SHADOW_BEFORE, SHADOW_METHOD, SHADOW_REFERENCE};
use crate::gpu::shadow_pass::ShadowPass;
use crate::gpu::taa_resolve::{TaaResolve, TaaStream};
use crate::gpu::timing::GpuTimer;
use crate::gpu::{DrawStats, GpuContext, RenderTarget, SceneGpu, TextureReadback};
use crate::measure::diff_kernel::DiffKernel;
use crate::measure::metric_kernel::MetricKernel;
use crate::measure::metrics::{FrameMetrics, Metric, MetricReduction};
use crate::measure::records::{
    near_transitions, transitions, BlockInfo, FrameRecord, TransitionPair, TransitionRecord,
};
use crate::methods::{Build, FrameInput, Method, MethodEntry, MethodOptions, Registry};
use crate::scene::schedule::{InstanceState, LodSchedule};
use crate::scene::Scene;
use glam::Mat4;
use indicatif::ProgressBar;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Set by the binary's signal handler; checked once per frame.
pub static INTERRUPTED: AtomicBool = AtomicBool::new(false);

fn check_interrupt() -> Result<()> {
    if INTERRUPTED.load(Ordering::Relaxed) {
        Err(Error::Interrupted)
    } else {
        Ok(())
    }
}

/// Walks a scene's frames in order: the shared LOD schedule and the instance matrices of each frame.
pub struct FrameDriver<'s> {
    scene: &'s Scene,
    schedule: LodSchedule,
    pub states: Vec<InstanceState>,
    pub matrices: Vec<Mat4>,
    pub distances: Vec<f32>,
}

/// Method-independent facts of one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameFacts {
    pub lod_mean: f64,
    pub t_instances: u32,
    /// Mean k over the instances in transition (None when none is).
    pub k_mean: Option<f64>,
    /// The LODs the t-instances go between.
    pub pair: TransitionPair,
}

impl<'s> FrameDriver<'s> {
    pub fn new(scene: &'s Scene) -> Self {
        let n = scene.instances.len();
        FrameDriver {
            scene,
            schedule: LodSchedule::new(scene.schedule, n),
            states: Vec::with_capacity(n),
            matrices: Vec::with_capacity(n),
            distances: Vec::with_capacity(n),
        }
    }

    pub fn reset(&mut self) {
        self.schedule.reset();
    }

    /// Advances to `frame` (frames must come in order after a reset).
    pub fn advance(&mut self, frame: u32) -> FrameFacts {
        self.states.clear();
        self.matrices.clear();
        self.distances.clear();
        let mut lod_sum = 0.0f64;
        let mut t = 0u32;
        let mut k_sum = 0.0f64;
        let mut pair = TransitionPair::None;
        let eye = self.scene.camera(frame).eye;
        for (i, inst) in self.scene.instances.iter().enumerate() {
            let d = self.scene.instance_position(i, frame).distance(eye);
            let switches = &self.scene.models[inst.model as usize].switches;
            let s = self.schedule.update(i, d, switches);
            if self.scene.ground != Some(i) {
                lod_sum += s.lod_value() as f64;
            }
            if s.in_transition() {
                t += 1;
                k_sum += s.k as f64;
                pair = pair.with(s.lod_from, s.lod_to);
            }
            self.states.push(s);
            self.distances.push(d);
            self.matrices.push(self.scene.instance_matrix(i, frame));
        }
        FrameFacts {
            lod_mean: lod_sum
                / (self.scene.instances.len() - self.scene.ground.is_some() as usize).max(1) as f64,
            t_instances: t,
            k_mean: (t > 0).then(|| k_sum / t as f64),
            pair,
        }
    }

    pub fn input(&self, frame: u32) -> FrameInput<'_> {
        FrameInput {
            frame,
            scene: self.scene,
            states: &self.states,
            matrices: &self.matrices,
            distances: &self.distances,
            timed: false,
        }
    }
}

/// One method's measurement on one scene block.
pub struct BlockOutput {
    pub rows: Vec<FrameRecord>,
    pub transitions: Vec<TransitionRecord>,
    pub info: BlockInfo,
}

/// Which methods a block can run and what they are built with.
#[derive(Clone)]
pub struct MethodSetup {
    pub registry: Registry,
    pub options: MethodOptions,
    /// `--seed`.
    pub seed: u64,
}

impl Default for MethodSetup {
    /// The built-in methods with every flag at its default (`--seed 1`).
    fn default() -> Self {
        MethodSetup {
            registry: Registry::builtin(),
            options: MethodOptions::default(),
            seed: 1,
        }
    }
}

/// The order of one timing round: which frames it covers and the order the methods were timed in.
pub use crate::measure::records::{BlockRounds, Round};

/// One method of a block from its creation through the timing rounds: the method (kept for its quality pass),
/// its own walk along the path, and what its timed frames measured.
pub struct TimedMethod<'s> {
    pub label: String,
    entry: MethodEntry,
    method: Box<dyn Method>,
    driver: FrameDriver<'s>,
    timer: Option<GpuTimer>,
    facts: Vec<FrameFacts>,
    cpu_ms: Vec<f64>,
    stats: Vec<DrawStats>,
    /// The round each frame was timed in.
    round: Vec<u32>,
    /// GPU time per frame, read after the last round (None without timestamp queries).
    gpu_ms: Vec<Option<f64>>,
    /// Wall time of the method's timed segments, ms.
    wall_ms: f64,
    /// Instance bytes (listed, written) over its timed frames.
    uploads: (u64, u64),
    /// `--warmup` (the frames of the path rendered untimed first; [`WarmUpPlan`] adds transition frames).
    warmup: u32,
}

impl TimedMethod<'_> {
    /// Wall time per timed frame (render + wait), ms.
    pub fn ms_per_frame(&self) -> f64 {
        self.wall_ms / self.cpu_ms.len().max(1) as f64
    }
}

/// The timing-round time per frame of the (first) reference among `timed`, listed or timed only: the denominator
/// of `quality_to_renders_ratio`.
pub fn reference_ms_per_frame(timed: &[TimedMethod<'_>]) -> Option<f64> {
    timed
        .iter()
        .find(|t| is_reference(&t.label))
        .map(TimedMethod::ms_per_frame)
}

pub use crate::methods::is_reference;

/// The frames every method renders untimed before the rounds: the first `warmup` frames of the path (wrapping),
/// then the first frame of each distinct transition of the path (`lod_from -> lod_to` pair) and the two frames
/// after it, so that every pipeline and buffer a method uses in a transition is used once before timing.
#[derive(Debug, Clone, PartialEq)]
pub struct WarmUpPlan {
    pub warmup: u32,
    pub transition_frames: Vec<u32>,
}

impl WarmUpPlan {
    /// Walks the path once on the CPU to find the transitions.
    pub fn new(scene: &Scene, warmup: u32) -> WarmUpPlan {
        let mut driver = FrameDriver::new(scene);
        let mut seen: Vec<TransitionPair> = Vec::new();
        let mut frames: Vec<u32> = Vec::new();
        for f in 0..scene.frames {
            let pair = driver.advance(f).pair;
            if pair != TransitionPair::None && !seen.contains(&pair) {
                seen.push(pair);
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
pub fn shuffled_order(n: usize, rng: &mut crate::rng::SplitMix64) -> Vec<usize> {
    let mut order: Vec<usize> = (0..n).collect();
    for i in (1..n).rev() {
        let j = (rng.next_u64() % (i as u64 + 1)) as usize;
        order.swap(i, j);
    }
    order
}

/// What the quality pass computes besides rmse, pop and lodpop, and how.
#[derive(Debug, Clone, Default)]
pub struct QualityOptions {
    /// `--metrics`: `Metric::Flip` and `Metric::De2000` switch those metrics on.
    pub metrics: Vec<Metric>,
    /// `--metric-reduction`.
    pub reduction: MetricReduction,
}

impl QualityOptions {
    /// With de2000 (the GPU-oracle tests).
    pub fn with_de2000() -> QualityOptions {
        QualityOptions {
            metrics: vec![Metric::De2000],
            ..Default::default()
        }
    }
}

/// What the quality pass measured, per frame.
struct QualityPass {
    metrics: Vec<FrameMetrics>,
    /// `--metrics flip`: mean FLIP per frame.
    flip: Vec<Option<f64>>,
    lodpop: Vec<f64>,
    /// Methods with a lag (FSI): lag_rmse per frame.
    lag: Option<Vec<f64>>,
    /// `--shadows on`: (shadow_rmse, shadow_lodpop) per frame.
    shadow: Option<(Vec<f64>, Vec<f64>)>,
    /// The method's own stage per frame (FSI's combination pass), when it has one: timed in the quality pass,
    /// so that its timestamps are never inside a timing-pass frame.
    stage_ms: Option<Vec<Option<f64>>>,
    ms_per_frame: f64,
    metric_gpu_ms_median: Option<f64>,
}

/// The GPU objects of one scene block, shared by all methods run on it.
pub struct BlockRunner<'a> {
    ctx: &'a GpuContext,
    scene: &'a Scene,
    gpu: SceneGpu,
    timing_target: RenderTarget,
    method_target: RenderTarget,
    reference_target: RenderTarget,
    /// lodpop's counterfactual frames: the frame without the method's lag (`now`) and with the previous
    /// schedule (`before`), both at the current pose.
    now_target: RenderTarget,
    before_target: RenderTarget,
    /// lodpop: pair 0 = (method, before), pair 1 = (now, before); lag: (method, now).
    lodpop_kernel: DiffKernel,
    lag_kernel: DiffKernel,
    reference: Box<dyn Method>,
    setup: MethodSetup,
    kernel: MetricKernel,
    /// `--metrics de2000`: the kernel computes CIEDE2000 (else de2000_mean is empty).
    de2000: bool,
    /// Times the metric kernel alone in the quality pass (its own cost, reported in run.json).
    metric_timer: Option<GpuTimer>,
    readback: Option<(TextureReadback, TextureReadback)>,
    /// Read back every quality-pass frame and compute FLIP on it.
    flip: bool,
    /// Hand every `dump_every`-th frame's images to the caller.
    dump: bool,
    /// With `dump`: only frames with an instance in transition (`--dump-transitions`).
    dump_transitions_only: bool,
    /// `--taa on`: the resolve, the method's image stream and the reference's.
    taa: Option<(TaaResolve, TaaStream, TaaStream)>,
    /// `--shadows on`: the shadow pass, and the shadow's own share of the error: the reference's LOD0 objects
    /// lit by the method's shadow map (`now`) and by its counterfactual's (`before`), with their kernels
    /// against the reference (shadow_rmse) and against each other (shadow_lodpop).
    shadow: Option<ShadowPass>,
    shadow_share: Option<ShadowShare>,
    /// `--shadows on`: each frame's light matrix and depth bias ([`frame_lights`]).
    lights: Vec<(Mat4, f32)>,
}

struct ShadowShare {
    now: RenderTarget,
    before: RenderTarget,
    rmse: DiffKernel,
    lodpop: DiffKernel,
}

/// Keep at most this many quality-pass frames queued on the GPU.
const QUALITY_IN_FLIGHT: u32 = 2;

/// The images of one dumped quality-pass frame: the method's, the reference's, and the method's intermediate
/// images (name, RGBA8).
pub type FrameImages<'i> = (&'i [u8], &'i [u8], &'i [(&'i str, Vec<u8>)]);

impl<'a> BlockRunner<'a> {
    /// `dump`: hand frames to the quality pass's callback.
    pub fn new(
        ctx: &'a GpuContext,
        scene: &'a Scene,
        setup: MethodSetup,
        dump: bool,
        quality: &QualityOptions,
    ) -> Result<Self> {
        let flip = quality.metrics.contains(&Metric::Flip);
        let with_readback = dump || flip;
        ctx.check_viewport(scene.width, scene.height)?;
        let gpu = SceneGpu::new(ctx, scene)?;
        let (w, h) = (scene.width, scene.height);
        let timing_target = RenderTarget::new(&ctx.device, "timing target", w, h);
        let method_target = RenderTarget::new(&ctx.device, "method target", w, h);
        let reference_target = RenderTarget::new(&ctx.device, "reference target", w, h);
        let now_target = RenderTarget::new(&ctx.device, "lodpop now target", w, h);
        let before_target = RenderTarget::new(&ctx.device, "lodpop before target", w, h);
        let lodpop_kernel = DiffKernel::new(
            ctx,
            "lodpop",
            &[
                (&method_target, &before_target),
                (&now_target, &before_target),
            ],
            scene.frames,
        )?;
        let lag_kernel =
            DiffKernel::new(ctx, "lag", &[(&method_target, &now_target)], scene.frames)?;
        let reference = Registry::builtin().create("reference", &build(&gpu, scene, &setup))?;
        let kernel = MetricKernel::new(
            ctx,
            (&method_target, &reference_target),
            scene.frames,
            (quality.metrics.contains(&Metric::De2000), quality.reduction),
            gpu.background_bytes(ctx)?,
        )?;
        let metric_timer = GpuTimer::new(ctx, scene.frames);
        let readback = with_readback.then(|| {
            (
                TextureReadback::color(&ctx.device, "method read-back", w, h),
                TextureReadback::color(&ctx.device, "reference read-back", w, h),
            )
        });
        let taa = scene.taa.map(|settings| {
            let resolve = TaaResolve::new(ctx, settings);
            let method = resolve.stream(ctx, "method", w, h);
            let reference = resolve.stream(ctx, "reference", w, h);
            (resolve, method, reference)
        });
        let shadow = scene
            .shadows
            .map(|_| ShadowPass::new(&gpu, scene.instances.len() as u32));
        let shadow_share = match scene.shadows {
            None => None,
            Some(_) => {
                let now = RenderTarget::new(&ctx.device, "shadow share now", w, h);
                let before = RenderTarget::new(&ctx.device, "shadow share before", w, h);
                let rmse = DiffKernel::new(
                    ctx,
                    "shadow rmse",
                    &[(&now, &reference_target)],
                    scene.frames,
                )?;
                let lodpop =
                    DiffKernel::new(ctx, "shadow lodpop", &[(&now, &before)], scene.frames)?;
                Some(ShadowShare {
                    now,
                    before,
                    rmse,
                    lodpop,
                })
            }
        };
        ctx.check_errors()?;
        Ok(BlockRunner {
            lights: frame_lights(scene),
            shadow,
            shadow_share,
            taa,
            ctx,
            scene,
            gpu,
            timing_target,
            method_target,
            reference_target,
            now_target,
            before_target,
            lodpop_kernel,
            lag_kernel,
            reference,
            setup,
            kernel,
            de2000: quality.metrics.contains(&Metric::De2000),
            metric_timer,
            readback,
            flip,
            dump,
            dump_transitions_only: false,
        })
    }

    /// Dump only frames with an instance in transition (of those, still every `dump_every`-th frame).
    pub fn dump_transitions_only(&mut self, on: bool) {
        self.dump_transitions_only = on;
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
        on_frames: impl FnMut(u32, FrameImages<'_>) -> Result<()>,
    ) -> Result<BlockOutput> {
        let (mut timed, _) = self.time_methods(&[label.to_string()], warmup, 1, 0, progress)?;
        let reference_ms = reference_ms_per_frame(&timed);
        let method = timed
            .drain(..)
            .find(|t| t.label == label)
            .ok_or_else(|| Error::Gpu(format!("method {label} was not timed")))?;
        self.measure_quality(method, reference_ms, dump_every, progress, on_frames)
    }

    /// Creates the methods `labels` (a label `NAME#k` is another instance of NAME), warms each up
    /// ([`WarmUpPlan`]), then times them in `rounds` interleaved rounds: round r times every method over the
    /// frames [`round_frames`]`(r)`, in an order shuffled from `seed`, each method continuing its own walk along
    /// the path. When no label is the reference, the reference is timed too (its time per frame is the
    /// denominator of run.json's `quality_to_renders_ratio`) and returned last, labelled `reference`.
    pub fn time_methods(
        &self,
        labels: &[String],
        warmup: u32,
        rounds: u32,
        seed: u64,
        progress: &ProgressBar,
    ) -> Result<(Vec<TimedMethod<'a>>, BlockRounds)> {
        let (scene, ctx) = (self.scene, self.ctx);
        let frames = scene.frames;
        let mut labels = labels.to_vec();
        let timed_only: Vec<String> = if labels.iter().any(|l| is_reference(l)) {
            Vec::new()
        } else {
            labels.push("reference".into());
            vec!["reference".into()]
        };
        let mut methods = labels
            .iter()
            .map(|label| {
                let entry = *self.setup.registry.get(label)?;
                Ok(TimedMethod {
                    label: label.clone(),
                    entry,
                    method: (entry.create)(&build(&self.gpu, scene, &self.setup))?,
                    driver: FrameDriver::new(scene),
                    timer: GpuTimer::new(ctx, frames),
                    facts: Vec::with_capacity(frames as usize),
                    cpu_ms: Vec::with_capacity(frames as usize),
                    stats: Vec::with_capacity(frames as usize),
                    round: Vec::with_capacity(frames as usize),
                    gpu_ms: Vec::new(),
                    wall_ms: 0.0,
                    uploads: (0, 0),
                    warmup,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let plan = WarmUpPlan::new(scene, warmup);
        for m in methods.iter_mut() {
            self.warm_up(m, &plan, progress)?;
            m.driver.reset();
        }
        let rounds = rounds.clamp(1, frames.max(1));
        let mut rng = crate::rng::SplitMix64::new(seed);
        let mut info = BlockRounds {
            scene: scene.name().to_string(),
            count: scene.count,
            seed,
            warmup_transition_frames: plan.transition_frames.clone(),
            timed_only,
            rounds: Vec::with_capacity(rounds as usize),
        };
        for r in 0..rounds {
            let (lo, hi) = round_frames(r, rounds, frames);
            let order = shuffled_order(methods.len(), &mut rng);
            for &i in &order {
                self.time_segment(&mut methods[i], r, lo..hi, progress)?;
            }
            info.rounds.push(Round {
                round: r,
                frames: [lo, hi],
                order: order.iter().map(|&i| methods[i].label.clone()).collect(),
            });
        }
        for m in methods.iter_mut() {
            m.gpu_ms = match &m.timer {
                Some(t) => t.read(ctx)?,
                None => Vec::new(),
            };
        }
        ctx.check_errors()?;
        Ok((methods, info))
    }

    /// The quality pass of a timed method, then its frame records. `reference_ms`: the reference's timing-pass
    /// time per frame (for `quality_to_renders_ratio`).
    pub fn measure_quality(
        &mut self,
        mut timed: TimedMethod<'a>,
        reference_ms: Option<f64>,
        dump_every: u32,
        progress: &ProgressBar,
        mut on_frames: impl FnMut(u32, FrameImages<'_>) -> Result<()>,
    ) -> Result<BlockOutput> {
        let scene = self.scene;
        let t_instances: Vec<u32> = timed.facts.iter().map(|f| f.t_instances).collect();
        let near = near_transitions(&t_instances);
        let quality = self.quality_pass(
            timed.method.as_mut(),
            &mut timed.driver,
            (dump_every, &near),
            progress,
            &mut on_frames,
        )?;
        self.ctx.check_errors()?;
        let label = timed.label.as_str();
        let de2000 = self.de2000;
        let rows = (0..scene.frames as usize)
            .map(|f| FrameRecord {
                scene: scene.name().to_string(),
                method: label.to_string(),
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
                rmse: quality.metrics[f].rmse,
                pop: quality.metrics[f].pop,
                lodpop: quality.lodpop[f],
                de2000_mean: de2000.then_some(quality.metrics[f].de2000),
                uncovered_px: quality.metrics[f].uncovered_px,
                crack_px: quality.metrics[f].crack_px,
                flip_mean: quality.flip[f],
                combine_gpu_ms: quality
                    .stage_ms
                    .as_ref()
                    .and_then(|s| s.get(f).copied().flatten()),
                lag_rmse: quality.lag.as_ref().map(|l| l[f]),
                shadow_rmse: quality.shadow.as_ref().map(|s| s.0[f]),
                shadow_lodpop: quality.shadow.as_ref().map(|s| s.1[f]),
                round: timed.round[f],
            })
            .collect::<Vec<_>>();
        let pairs: Vec<TransitionPair> = timed.facts.iter().map(|f| f.pair).collect();
        let frames = scene.frames as f64;
        let timing_ms = timed.ms_per_frame();
        Ok(BlockOutput {
            transitions: transitions(&rows, &pairs),
            rows,
            info: BlockInfo {
                scene: scene.name().to_string(),
                method: label.to_string(),
                method_options: (timed.entry.options)(&self.setup.options),
                count: scene.count,
                width: scene.width,
                height: scene.height,
                frames: scene.frames,
                warmup: timed.warmup,
                timing_pass_ms_per_frame: timing_ms,
                quality_pass_ms_per_frame: quality.ms_per_frame,
                quality_to_timing_ratio: quality.ms_per_frame / timing_ms,
                quality_to_renders_ratio: reference_ms
                    .map(|r| quality.ms_per_frame / (timing_ms + r)),
                metric_gpu_ms_median: quality.metric_gpu_ms_median,
                extra_target_bytes: timed.method.extra_target_bytes(),
                instance_bytes_listed_per_frame: timed.uploads.0 as f64 / frames,
                instance_bytes_written_per_frame: timed.uploads.1 as f64 / frames,
            },
        })
    }

    /// `plan`'s warm-up frames, untimed.
    fn warm_up(
        &self,
        m: &mut TimedMethod<'_>,
        plan: &WarmUpPlan,
        progress: &ProgressBar,
    ) -> Result<()> {
        let scene = self.scene;
        for w in 0..plan.warmup {
            let f = w % scene.frames;
            if f == 0 {
                m.driver.reset();
            }
            m.driver.advance(f);
            self.render_untimed(m, f)?;
            progress.inc(1);
        }
        m.driver.reset();
        let last = plan.transition_frames.last().copied();
        for f in 0..last.map_or(0, |l| l + 1) {
            m.driver.advance(f);
            if plan.transition_frames.binary_search(&f).is_ok() {
                self.render_untimed(m, f)?;
            }
        }
        Ok(())
    }

    /// `--shadows on`, outside the quality pass: what `m` casts this frame, into its shadow map.
    fn own_shadow(
        &self,
        m: &TimedMethod<'_>,
        input: &FrameInput<'_>,
    ) -> Option<wgpu::CommandBuffer> {
        let reference = is_reference(&m.label);
        self.shadow_commands(
            m.method.as_ref(),
            input,
            input.states,
            (SHADOW_METHOD, false, reference),
        )
    }

    fn render_untimed(&self, m: &mut TimedMethod<'_>, f: u32) -> Result<()> {
        check_interrupt()?;
        let ctx = self.ctx;
        self.write_frame(f);
        self.gpu.use_shadow_map(SHADOW_METHOD);
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let input = m.driver.input(f);
        m.method
            .encode(&self.gpu, &input, &mut encoder, &self.timing_target);
        let shadow = self.own_shadow(m, &input);
        ctx.queue
            .submit(shadow.into_iter().chain([encoder.finish()]));
        ctx.wait_idle()
    }

    /// Times `m` over `frames` (the next frames of its walk) in round `round`: each frame submitted and waited
    /// for, bracketed by the method's own timestamps, nothing else in its command buffer.
    fn time_segment(
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
            self.gpu.use_shadow_map(SHADOW_METHOD);
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
            let shadow = self.own_shadow(m, &input);
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
        m.wall_ms += start.elapsed().as_secs_f64() * 1e3;
        let after = self.gpu.uploads.get();
        m.uploads.0 += after.0 - uploads_before.0;
        m.uploads.1 += after.1 - uploads_before.1;
        Ok(())
    }

    /// The frame's camera, and with `--shadows on` its light (`lights`), into the camera uniform.
    fn write_frame(&self, f: u32) {
        self.gpu.write_camera(&self.scene.camera(f));
        if let Some((light, bias)) = self.lights.get(f as usize) {
            self.gpu.write_light(light, *bias);
        }
    }

    /// `--shadows on`: a command buffer, to be submitted before the frame's, that draws into shadow map `map`
    /// what `method` casts (asked after its `encode` of the frame; `states` this frame's, or the earlier
    /// frame's for lodpop's counterfactual with `before`), under `--shadow-lod` unless `reference`.
    fn shadow_commands(
        &self,
        method: &dyn Method,
        input: &FrameInput<'_>,
        states: &[InstanceState],
        (map, before, reference): (usize, bool, bool),
    ) -> Option<wgpu::CommandBuffer> {
        let (pass, settings) = (self.shadow.as_ref()?, self.scene.shadows?);
        let mut list = crate::gpu::DrawList::default();
        let input = FrameInput { states, ..*input };
        crate::methods::common::shadow_list(
            &input,
            |i| {
                let own = method.shadow_caster(states, i, before);
                if reference {
                    own
                } else {
                    states[i].caster_under(own, settings.lod)
                }
            },
            &mut list,
        );
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        pass.encode(&self.gpu, &mut encoder, map, &list);
        Some(encoder.finish())
    }

    fn quality_pass(
        &mut self,
        method: &mut dyn Method,
        driver: &mut FrameDriver<'_>,
        (dump_every, near_transition): (u32, &[bool]),
        progress: &ProgressBar,
        on_frames: &mut impl FnMut(u32, FrameImages<'_>) -> Result<()>,
    ) -> Result<QualityPass> {
        let (scene, ctx) = (self.scene, self.ctx);
        let frames = scene.frames;
        driver.reset();
        let mut flip = vec![None; frames as usize];
        let mut has_lag = false;
        // The states of the last frames, newest first (lodpop's schedule history).
        let depth = method.lodpop_history().max(1);
        let mut history: std::collections::VecDeque<Vec<InstanceState>> =
            std::collections::VecDeque::with_capacity(depth + 1);
        let pass_start = Instant::now();
        let mut in_flight = std::collections::VecDeque::new();
        if let Some((_, m, r)) = &mut self.taa {
            m.reset();
            r.reset();
        }
        for f in 0..frames {
            check_interrupt()?;
            driver.advance(f);
            self.write_frame(f);
            if let Some((resolve, m, r)) = &self.taa {
                resolve.begin_frame(ctx, m);
                resolve.begin_frame(ctx, r);
            }
            let input = driver.input(f);
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            if f == 0 {
                self.lodpop_kernel.clear(&mut encoder);
                self.lag_kernel.clear(&mut encoder);
                if let Some(share) = &self.shadow_share {
                    share.rmse.clear(&mut encoder);
                    share.lodpop.clear(&mut encoder);
                }
            }
            self.gpu.use_shadow_map(SHADOW_REFERENCE);
            self.reference
                .encode(&self.gpu, &input, &mut encoder, &self.reference_target);
            self.gpu.use_shadow_map(SHADOW_METHOD);
            method.encode(&self.gpu, &input, &mut encoder, &self.method_target);
            // --shadows on: the frame's shadow maps (the reference's LOD0, the method's casters, and, for
            // lodpop's counterfactual, what the method cast with the previous states), asked now that the
            // method has decided its frame, submitted before the frame's commands.
            let mut shadows: Vec<wgpu::CommandBuffer> = Vec::new();
            shadows.extend(self.shadow_commands(
                self.reference.as_ref(),
                &input,
                input.states,
                (SHADOW_REFERENCE, false, true),
            ));
            shadows.extend(self.shadow_commands(
                method,
                &input,
                input.states,
                (SHADOW_METHOD, false, false),
            ));
            if let Some(previous) = history.front() {
                shadows.extend(self.shadow_commands(
                    method,
                    &input,
                    previous,
                    (SHADOW_BEFORE, true, false),
                ));
            }
            // TAA: both frames resolved in place (each against its own history) before anything reads them.
            if let Some((resolve, m, r)) = &self.taa {
                resolve.encode(ctx, &mut encoder, m, &self.method_target, true);
                resolve.encode(ctx, &mut encoder, r, &self.reference_target, true);
            }
            // The shadow's own share: LOD0 objects lit by the method's shadow map now and by its
            // counterfactual's (resolved against the reference's history under TAA, which they leave as it is).
            if let Some(share) = &self.shadow_share {
                for (map, target) in [(SHADOW_METHOD, &share.now), (SHADOW_BEFORE, &share.before)] {
                    self.gpu.use_shadow_map(map);
                    self.reference
                        .encode(&self.gpu, &input, &mut encoder, target);
                    if let Some((resolve, _, r)) = &self.taa {
                        resolve.encode(ctx, &mut encoder, r, target, false);
                    }
                }
                self.gpu.use_shadow_map(SHADOW_METHOD);
                share.rmse.encode(&ctx.queue, &mut encoder, f, 0);
                if f > 0 {
                    share.lodpop.encode(&ctx.queue, &mut encoder, f, 0);
                }
            }
            if let Some(t) = &self.metric_timer {
                t.begin(&mut encoder, f);
            }
            self.kernel.encode(&ctx.queue, &mut encoder, f);
            if let Some(t) = &self.metric_timer {
                t.end(&mut encoder, f);
            }
            let dump = self.dump
                && f % dump_every == 0
                && (!self.dump_transitions_only || near_transition[f as usize]);
            let read = match &self.readback {
                Some((m, r)) if dump || self.flip => {
                    m.encode_copy(&mut encoder, &self.method_target);
                    r.encode_copy(&mut encoder, &self.reference_target);
                    true
                }
                _ => false,
            };
            // The method's intermediate images (FSI's LOD buffers), only for dumped frames.
            let mut extras: Vec<(&str, TextureReadback)> = if dump {
                method
                    .debug_targets()
                    .into_iter()
                    .map(|(name, t)| {
                        let rb = TextureReadback::color(&ctx.device, name, t.width, t.height);
                        rb.encode_copy(&mut encoder, t);
                        (name, rb)
                    })
                    .collect()
            } else {
                Vec::new()
            };
            let mut index = ctx
                .queue
                .submit(shadows.into_iter().chain([encoder.finish()]));

            // lodpop and lag: the counterfactual frames at this pose, in a submission of their own (the method
            // writes its instance data again through the queue, which must not reach the frame above).
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            let unlagged =
                method.encode_unlagged(&self.gpu, &input, &mut encoder, &self.now_target);
            if let (true, Some((resolve, m, _))) = (unlagged, &self.taa) {
                resolve.encode(ctx, &mut encoder, m, &self.now_target, false);
            }
            has_lag |= unlagged;
            if unlagged {
                self.lag_kernel.encode(&ctx.queue, &mut encoder, f, 0);
            }
            history.push_front(driver.states.clone());
            history.truncate(depth + 1);
            let changed = history.len() > 1
                && (history.iter().skip(1).any(|h| *h != history[0])
                    || (depth > 1 && history.iter().flatten().any(|s| s.in_transition()))
                    || method.selection_changed());
            if changed {
                let earlier: Vec<&[InstanceState]> =
                    history.iter().skip(1).map(Vec::as_slice).collect();
                self.gpu.use_shadow_map(SHADOW_BEFORE);
                method.encode_before(
                    &self.gpu,
                    &input,
                    &earlier,
                    &mut encoder,
                    &self.before_target,
                );
                self.gpu.use_shadow_map(SHADOW_METHOD);
                if let Some((resolve, m, _)) = &self.taa {
                    resolve.encode(ctx, &mut encoder, m, &self.before_target, false);
                }
                self.lodpop_kernel
                    .encode(&ctx.queue, &mut encoder, f, unlagged as usize);
            }
            if dump {
                for (name, show, target) in [
                    ("lodpop-now", unlagged, &self.now_target),
                    ("lodpop-before", changed, &self.before_target),
                ] {
                    if show {
                        let rb =
                            TextureReadback::color(&ctx.device, name, target.width, target.height);
                        rb.encode_copy(&mut encoder, target);
                        extras.push((name, rb));
                    }
                }
            }
            if unlagged || changed {
                index = ctx.queue.submit([encoder.finish()]);
            }
            if let Some((_, m, r)) = &mut self.taa {
                m.advance();
                r.advance();
            }

            if let (true, Some((m, r))) = (read, &self.readback) {
                let method_rgba = m.read(ctx)?;
                let reference_rgba = r.read(ctx)?;
                if self.flip {
                    flip[f as usize] = Some(crate::measure::metrics::flip_mean(
                        &method_rgba,
                        &reference_rgba,
                        scene.width,
                        scene.height,
                    ));
                }
                if dump {
                    let extras = extras
                        .iter()
                        .map(|(name, rb)| Ok((*name, rb.read(ctx)?)))
                        .collect::<Result<Vec<_>>>()?;
                    on_frames(f, (&method_rgba, &reference_rgba, &extras))?;
                }
            } else {
                in_flight.push_back(index);
                if in_flight.len() > QUALITY_IN_FLIGHT as usize {
                    if let Some(oldest) = in_flight.pop_front() {
                        ctx.device
                            .poll(wgpu::PollType::Wait {
                                submission_index: Some(oldest),
                                timeout: None,
                            })
                            .map_err(|e| Error::Gpu(format!("waiting for the GPU: {e}")))?;
                    }
                }
            }
            progress.inc(1);
        }
        ctx.wait_idle()?;
        let ms_per_frame = pass_start.elapsed().as_secs_f64() * 1e3 / frames as f64;
        let metrics = self.kernel.read(ctx, frames)?;
        let lodpop = self.lodpop_kernel.read(ctx, frames)?;
        let lag = if has_lag {
            Some(self.lag_kernel.read(ctx, frames)?)
        } else {
            None
        };
        let shadow = match &self.shadow_share {
            Some(share) => Some((
                share.rmse.read(ctx, frames)?,
                share.lodpop.read(ctx, frames)?,
            )),
            None => None,
        };
        let metric_gpu_ms_median = match &self.metric_timer {
            Some(t) => {
                let ms: Vec<f64> = t.read(ctx)?.into_iter().flatten().collect();
                crate::measure::stats::percentile(&ms, 50.0)
            }
            None => None,
        };
        Ok(QualityPass {
            metrics,
            flip,
            lodpop,
            lag,
            shadow,
            stage_ms: method.stage_gpu_ms(ctx)?,
            ms_per_frame,
            metric_gpu_ms_median,
        })
    }
}

/// `--shadows on`: every frame's light and depth bias, fitted to the casters' bounding spheres (every instance
/// but the ground) with room behind them for the receivers; the same for every method, so computed once per
/// block. Empty without shadows.
fn frame_lights(scene: &Scene) -> Vec<(Mat4, f32)> {
    if scene.shadows.is_none() {
        return Vec::new();
    }
    (0..scene.frames)
        .map(|f| {
            let spheres: Vec<(glam::Vec3, f32)> = scene
                .instances
                .iter()
                .enumerate()
                .filter(|(i, _)| scene.ground != Some(*i))
                .map(|(i, inst)| {
                    (
                        scene.instance_position(i, f),
                        scene.models[inst.model as usize].radius,
                    )
                })
                .collect();
            let r = spheres.iter().map(|s| s.1).fold(0.0f32, f32::max);
            let (light, depth) = crate::effects::shadow::light_matrix(
                glam::Vec3::from(crate::gpu::LIGHT_DIR),
                &spheres,
                3.0 * r,
            );
            (
                light,
                crate::effects::shadow::BIAS_OF_RADIUS * r / depth.max(1e-6),
            )
        })
        .collect()
}

fn build<'b>(gpu: &'b SceneGpu, scene: &'b Scene, setup: &'b MethodSetup) -> Build<'b> {
    Build {
        gpu,
        scene,
        options: &setup.options,
        seed: setup.seed,
    }
}
