//! The measurement of one method on one scene block: a warm-up, a timing pass and a quality pass over the same
//! frames, then one frame record per frame, built once every figure of the frame is known.
//!
//! - Timing pass: `warmup` untimed frames, then `frames` timed frames; nothing but the method's own work is in
//!   a timed frame (no metric, no read-back). Each frame is submitted and waited for, so `cpu_ms` is a true
//!   encode-to-completion time and frames never overlap; GPU timestamps are resolved into one buffer and read
//!   once after the pass, so reading them never stalls the timed frames.
//! - Quality pass: per frame the reference and the method are rendered into two targets and the metric kernel
//!   reduces their difference to scalars on the GPU; the scalars of all frames are read back once at the end.

use crate::error::{Error, Result};
use crate::gpu::diff::DiffKernel;
use crate::gpu::metrics::MetricKernel;
use crate::gpu::timing::GpuTimer;
use crate::gpu::{DrawStats, GpuContext, RenderTarget, SceneGpu, TextureReadback};
use crate::methods::{Build, FrameInput, Method, MethodOptions, Registry};
use crate::metrics::FrameMetrics;
use crate::records::{
    near_transitions, transitions, BlockInfo, FrameRecord, TransitionPair, TransitionRecord,
};
use crate::scene::Scene;
use crate::schedule::{InstanceState, LodSchedule};
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
        let mut pair = TransitionPair::None;
        let eye = self.scene.camera(frame).eye;
        for (i, inst) in self.scene.instances.iter().enumerate() {
            let d = self.scene.instance_position(i, frame).distance(eye);
            let switches = &self.scene.models[inst.model as usize].switches;
            let s = self.schedule.update(i, d, switches);
            lod_sum += s.lod_value() as f64;
            if s.in_transition() {
                t += 1;
                pair = pair.with(s.lod_from, s.lod_to);
            }
            self.states.push(s);
            self.distances.push(d);
            self.matrices.push(self.scene.instance_matrix(i, frame));
        }
        FrameFacts {
            lod_mean: lod_sum / self.scene.instances.len().max(1) as f64,
            t_instances: t,
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

/// What the timing pass measured, per frame.
struct TimingPass {
    facts: Vec<FrameFacts>,
    cpu_ms: Vec<f64>,
    stats: Vec<DrawStats>,
    /// GPU time per frame (None without timestamp queries).
    gpu_ms: Vec<Option<f64>>,
    /// The method's own stage per frame (FSI's combination pass), when it has one.
    stage_ms: Option<Vec<Option<f64>>>,
    ms_per_frame: f64,
    instance_bytes_listed_per_frame: f64,
    instance_bytes_written_per_frame: f64,
}

/// What the quality pass measured, per frame.
struct QualityPass {
    metrics: Vec<FrameMetrics>,
    /// `--metrics flip`: mean FLIP per frame.
    flip: Vec<Option<f64>>,
    lodpop: Vec<f64>,
    /// Methods with a lag (FSI): lag_rmse per frame.
    lag: Option<Vec<f64>>,
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
    timer: Option<GpuTimer>,
    /// Times the metric kernel alone in the quality pass (its own cost, reported in run.json).
    metric_timer: Option<GpuTimer>,
    readback: Option<(TextureReadback, TextureReadback)>,
    /// Read back every quality-pass frame and compute FLIP on it.
    flip: bool,
    /// Hand every `dump_every`-th frame's images to the caller.
    dump: bool,
    /// With `dump`: only frames with an instance in transition (`--dump-transitions`).
    dump_transitions_only: bool,
}

/// Keep at most this many quality-pass frames queued on the GPU.
const QUALITY_IN_FLIGHT: u32 = 2;

/// The images of one dumped quality-pass frame: the method's, the reference's, and the method's intermediate
/// images (name, RGBA8).
pub type FrameImages<'i> = (&'i [u8], &'i [u8], &'i [(&'i str, Vec<u8>)]);

impl<'a> BlockRunner<'a> {
    /// `dump`: hand frames to `run_method`'s callback; `flip`: compute FLIP on every quality-pass frame.
    pub fn new(
        ctx: &'a GpuContext,
        scene: &'a Scene,
        setup: MethodSetup,
        dump: bool,
        flip: bool,
    ) -> Result<Self> {
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
        let kernel = MetricKernel::new(ctx, &method_target, &reference_target, scene.frames)?;
        let timer = GpuTimer::new(ctx, scene.frames);
        let metric_timer = GpuTimer::new(ctx, scene.frames);
        let readback = with_readback.then(|| {
            (
                TextureReadback::color(&ctx.device, "method read-back", w, h),
                TextureReadback::color(&ctx.device, "reference read-back", w, h),
            )
        });
        ctx.check_errors()?;
        Ok(BlockRunner {
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
            timer,
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

    /// Warm-up, timing pass and quality pass of `method_name`, then its frame records. `on_frames` is called
    /// with the quality-pass images of every `dump_every`-th frame when the runner was built with read-back.
    pub fn run_method(
        &mut self,
        method_name: &str,
        warmup: u32,
        dump_every: u32,
        progress: &ProgressBar,
        mut on_frames: impl FnMut(u32, FrameImages<'_>) -> Result<()>,
    ) -> Result<BlockOutput> {
        let scene = self.scene;
        let entry = *self.setup.registry.get(method_name)?;
        let mut method = (entry.create)(&build(&self.gpu, scene, &self.setup))?;
        let mut driver = FrameDriver::new(scene);
        self.warm_up(method.as_mut(), &mut driver, warmup, progress)?;
        let timing = self.timing_pass(method.as_mut(), &mut driver, progress)?;
        let t_instances: Vec<u32> = timing.facts.iter().map(|f| f.t_instances).collect();
        let near = near_transitions(&t_instances);
        let quality = self.quality_pass(
            method.as_mut(),
            &mut driver,
            (dump_every, &near),
            progress,
            &mut on_frames,
        )?;
        self.ctx.check_errors()?;

        let rows = (0..scene.frames as usize)
            .map(|f| FrameRecord {
                scene: scene.name().to_string(),
                method: method_name.to_string(),
                count: scene.count,
                frame: f as u32,
                gpu_ms: timing.gpu_ms.get(f).copied().flatten(),
                cpu_ms: timing.cpu_ms[f],
                triangles: timing.stats[f].triangles,
                draw_calls: timing.stats[f].draw_calls,
                t_instances: timing.facts[f].t_instances,
                lod_mean: timing.facts[f].lod_mean,
                rmse: quality.metrics[f].rmse,
                pop: quality.metrics[f].pop,
                lodpop: quality.lodpop[f],
                de2000_mean: quality.metrics[f].de2000,
                flip_mean: quality.flip[f],
                combine_gpu_ms: timing
                    .stage_ms
                    .as_ref()
                    .and_then(|s| s.get(f).copied().flatten()),
                lag_rmse: quality.lag.as_ref().map(|l| l[f]),
            })
            .collect::<Vec<_>>();
        let pairs: Vec<TransitionPair> = timing.facts.iter().map(|f| f.pair).collect();
        Ok(BlockOutput {
            transitions: transitions(&rows, &pairs),
            rows,
            info: BlockInfo {
                scene: scene.name().to_string(),
                method: method_name.to_string(),
                method_options: (entry.options)(&self.setup.options),
                count: scene.count,
                width: scene.width,
                height: scene.height,
                frames: scene.frames,
                warmup,
                timing_pass_ms_per_frame: timing.ms_per_frame,
                quality_pass_ms_per_frame: quality.ms_per_frame,
                quality_to_timing_ratio: quality.ms_per_frame / timing.ms_per_frame,
                metric_gpu_ms_median: quality.metric_gpu_ms_median,
                extra_target_bytes: method.extra_target_bytes(),
                instance_bytes_listed_per_frame: timing.instance_bytes_listed_per_frame,
                instance_bytes_written_per_frame: timing.instance_bytes_written_per_frame,
            },
        })
    }

    /// The first `warmup` frames of the path (wrapping), untimed.
    fn warm_up(
        &self,
        method: &mut dyn Method,
        driver: &mut FrameDriver<'_>,
        warmup: u32,
        progress: &ProgressBar,
    ) -> Result<()> {
        let (scene, ctx) = (self.scene, self.ctx);
        for w in 0..warmup {
            check_interrupt()?;
            let f = w % scene.frames;
            if f == 0 {
                driver.reset();
            }
            driver.advance(f);
            self.gpu.write_camera(&scene.camera(f));
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            method.encode(
                &self.gpu,
                &driver.input(f),
                &mut encoder,
                &self.timing_target,
            );
            ctx.queue.submit([encoder.finish()]);
            ctx.wait_idle()?;
            progress.inc(1);
        }
        Ok(())
    }

    fn timing_pass(
        &self,
        method: &mut dyn Method,
        driver: &mut FrameDriver<'_>,
        progress: &ProgressBar,
    ) -> Result<TimingPass> {
        let (scene, ctx) = (self.scene, self.ctx);
        let frames = scene.frames;
        driver.reset();
        let n = frames as usize;
        let (mut facts, mut cpu_ms, mut stats) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        let uploads_before = self.gpu.uploads.get();
        let pass_start = Instant::now();
        for f in 0..frames {
            check_interrupt()?;
            facts.push(driver.advance(f));
            let t0 = Instant::now();
            self.gpu.write_camera(&scene.camera(f));
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            if let Some(t) = &self.timer {
                t.begin(&mut encoder, f);
            }
            let input = FrameInput {
                timed: true,
                ..driver.input(f)
            };
            stats.push(method.encode(&self.gpu, &input, &mut encoder, &self.timing_target));
            if let Some(t) = &self.timer {
                t.end(&mut encoder, f);
            }
            ctx.queue.submit([encoder.finish()]);
            ctx.wait_idle()?;
            cpu_ms.push(t0.elapsed().as_secs_f64() * 1e3);
            progress.inc(1);
        }
        let ms_per_frame = pass_start.elapsed().as_secs_f64() * 1e3 / frames as f64;
        let uploads_after = self.gpu.uploads.get();
        let per_frame = |after: u64, before: u64| (after - before) as f64 / frames as f64;
        let gpu_ms = match &self.timer {
            Some(t) => t.read(ctx)?,
            None => Vec::new(),
        };
        Ok(TimingPass {
            facts,
            cpu_ms,
            stats,
            gpu_ms,
            stage_ms: method.stage_gpu_ms(ctx)?,
            ms_per_frame,
            instance_bytes_listed_per_frame: per_frame(uploads_after.0, uploads_before.0),
            instance_bytes_written_per_frame: per_frame(uploads_after.1, uploads_before.1),
        })
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
        for f in 0..frames {
            check_interrupt()?;
            driver.advance(f);
            self.gpu.write_camera(&scene.camera(f));
            let input = driver.input(f);
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            if f == 0 {
                self.lodpop_kernel.clear(&mut encoder);
                self.lag_kernel.clear(&mut encoder);
            }
            self.reference
                .encode(&self.gpu, &input, &mut encoder, &self.reference_target);
            method.encode(&self.gpu, &input, &mut encoder, &self.method_target);
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
            let mut index = ctx.queue.submit([encoder.finish()]);

            // lodpop and lag: the counterfactual frames at this pose, in a submission of their own (the method
            // writes its instance data again through the queue, which must not reach the frame above).
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            let unlagged =
                method.encode_unlagged(&self.gpu, &input, &mut encoder, &self.now_target);
            has_lag |= unlagged;
            if unlagged {
                self.lag_kernel.encode(&ctx.queue, &mut encoder, f, 0);
            }
            history.push_front(driver.states.clone());
            history.truncate(depth + 1);
            let changed = history.len() > 1
                && (history.iter().skip(1).any(|h| *h != history[0])
                    || (depth > 1 && history.iter().flatten().any(|s| s.in_transition())));
            if changed {
                let earlier: Vec<&[InstanceState]> =
                    history.iter().skip(1).map(Vec::as_slice).collect();
                method.encode_before(
                    &self.gpu,
                    &input,
                    &earlier,
                    &mut encoder,
                    &self.before_target,
                );
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

            if let (true, Some((m, r))) = (read, &self.readback) {
                let method_rgba = m.read(ctx)?;
                let reference_rgba = r.read(ctx)?;
                if self.flip {
                    flip[f as usize] = Some(crate::metrics::flip_mean(
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
        let metric_gpu_ms_median = match &self.metric_timer {
            Some(t) => {
                let ms: Vec<f64> = t.read(ctx)?.into_iter().flatten().collect();
                crate::stats::percentile(&ms, 50.0)
            }
            None => None,
        };
        Ok(QualityPass {
            metrics,
            flip,
            lodpop,
            lag,
            ms_per_frame,
            metric_gpu_ms_median,
        })
    }
}

fn build<'b>(gpu: &'b SceneGpu, scene: &'b Scene, setup: &'b MethodSetup) -> Build<'b> {
    Build {
        gpu,
        scene,
        options: &setup.options,
        seed: setup.seed,
    }
}
