//! The measurement: for each scene block and method, a timing pass and a quality pass over the same frames.
//!
//! - Timing pass: `warmup` untimed frames, then `frames` timed frames; nothing but the method's own work is in
//!   a timed frame (no metric, no read-back). Each frame is submitted and waited for, so `cpu_ms` is a true
//!   encode-to-completion time and frames never overlap; GPU timestamps are resolved into one buffer and read
//!   once after the pass, so reading them never stalls the timed frames.
//! - Quality pass: per frame the reference and the method are rendered into two targets and the metric kernel
//!   reduces their difference to scalars on the GPU; the scalars of all frames are read back once at the end.

use crate::config::RunConfig;
use crate::error::{Error, Result};
use crate::export::csv::{FrameRecord, FramesWriter, SummaryRecord};
use crate::export::manifest::{now_rfc3339, BlockInfo, RunManifest, RunStatus};
use crate::export::png::FrameDumper;
use crate::gpu::metrics::MetricKernel;
use crate::gpu::renderer::{ColorReadback, RenderTarget, SceneGpu};
use crate::gpu::timing::GpuTimer;
use crate::gpu::GpuContext;
use crate::methods::{self, FrameInput, Method, MethodOptions};
use crate::scene::{Scene, SceneDef};
use crate::schedule::{InstanceState, LodSchedule};
use glam::Mat4;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
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
        let eye = self.scene.camera(frame).eye;
        for (i, inst) in self.scene.instances.iter().enumerate() {
            let d = self.scene.instance_position(i, frame).distance(eye);
            let switches = &self.scene.models[inst.model as usize].switches;
            let s = self.schedule.update(i, d, switches);
            lod_sum += s.lod_value() as f64;
            t += s.in_transition() as u32;
            self.states.push(s);
            self.distances.push(d);
            self.matrices.push(self.scene.instance_matrix(i, frame));
        }
        FrameFacts {
            lod_mean: lod_sum / self.scene.instances.len().max(1) as f64,
            t_instances: t,
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
    pub info: BlockInfo,
}

/// The GPU objects of one scene block, shared by all methods run on it.
pub struct BlockRunner<'a> {
    ctx: &'a GpuContext,
    scene: &'a Scene,
    gpu: SceneGpu,
    timing_target: RenderTarget,
    method_target: RenderTarget,
    reference_target: RenderTarget,
    reference: Box<dyn Method>,
    options: MethodOptions,
    kernel: MetricKernel,
    timer: Option<GpuTimer>,
    /// Times the metric kernel alone in the quality pass (its own cost, reported in run.json).
    metric_timer: Option<GpuTimer>,
    readback: Option<(ColorReadback, ColorReadback)>,
    /// Read back every quality-pass frame and compute FLIP on it.
    flip: bool,
    /// Hand every `dump_every`-th frame's images to the caller.
    dump: bool,
    /// With `dump`: only frames with an instance in transition (`--dump-transitions`).
    dump_transitions_only: bool,
}

/// Keep at most this many quality-pass frames queued on the GPU.
const QUALITY_IN_FLIGHT: u32 = 2;

impl<'a> BlockRunner<'a> {
    /// `dump`: hand frames to `run_method`'s callback; `flip`: compute FLIP on every quality-pass frame.
    pub fn new(
        ctx: &'a GpuContext,
        scene: &'a Scene,
        options: MethodOptions,
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
        let reference = methods::create("reference", &gpu, scene, &options)?;
        let kernel = MetricKernel::new(ctx, &method_target, &reference_target, scene.frames)?;
        let timer = GpuTimer::new(ctx, scene.frames);
        let metric_timer = GpuTimer::new(ctx, scene.frames);
        let readback = with_readback.then(|| {
            (
                ColorReadback::new(&ctx.device, "method read-back", w, h),
                ColorReadback::new(&ctx.device, "reference read-back", w, h),
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
            reference,
            options,
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

    /// Timing pass then quality pass of `method_name`. `on_frames` is called with the quality-pass images of
    /// every `dump_every`-th frame when the runner was built with read-back.
    pub fn run_method(
        &mut self,
        method_name: &str,
        warmup: u32,
        dump_every: u32,
        progress: &ProgressBar,
        mut on_frames: impl FnMut(u32, &[u8], &[u8], &[(&str, Vec<u8>)]) -> Result<()>,
    ) -> Result<BlockOutput> {
        let scene = self.scene;
        let ctx = self.ctx;
        let frames = scene.frames;
        let mut method = methods::create(method_name, &self.gpu, scene, &self.options)?;
        let mut driver = FrameDriver::new(scene);

        // Warm-up: the first frames of the path (wrapping), untimed.
        for w in 0..warmup {
            check_interrupt()?;
            let f = w % frames;
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

        // Timing pass.
        driver.reset();
        let mut rows = Vec::with_capacity(frames as usize);
        let uploads_before = self.gpu.uploads.get();
        let pass_start = Instant::now();
        for f in 0..frames {
            check_interrupt()?;
            let facts = driver.advance(f);
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
            let stats = method.encode(&self.gpu, &input, &mut encoder, &self.timing_target);
            if let Some(t) = &self.timer {
                t.end(&mut encoder, f);
            }
            ctx.queue.submit([encoder.finish()]);
            ctx.wait_idle()?;
            let cpu_ms = t0.elapsed().as_secs_f64() * 1e3;
            rows.push(FrameRecord {
                scene: scene.name.clone(),
                method: method_name.to_string(),
                count: scene.count,
                frame: f,
                gpu_ms: None,
                cpu_ms,
                triangles: stats.triangles,
                draw_calls: stats.draw_calls,
                t_instances: facts.t_instances,
                lod_mean: facts.lod_mean,
                rmse: 0.0,
                pop: 0.0,
                de2000_mean: 0.0,
                flip_mean: None,
                combine_gpu_ms: None,
            });
            progress.inc(1);
        }
        let timing_ms = pass_start.elapsed().as_secs_f64() * 1e3 / frames as f64;
        let uploads_after = self.gpu.uploads.get();
        let per_frame = |after: u64, before: u64| (after - before) as f64 / frames as f64;
        let instance_bytes_listed_per_frame = per_frame(uploads_after.0, uploads_before.0);
        let instance_bytes_written_per_frame = per_frame(uploads_after.1, uploads_before.1);
        if let Some(t) = &self.timer {
            for (row, ms) in rows.iter_mut().zip(t.read(ctx)?) {
                row.gpu_ms = ms;
            }
        }
        if let Some(stage) = method.stage_gpu_ms(ctx)? {
            for (row, ms) in rows.iter_mut().zip(stage) {
                row.combine_gpu_ms = ms;
            }
        }

        // Quality pass.
        driver.reset();
        let pass_start = Instant::now();
        let mut in_flight = std::collections::VecDeque::new();
        for f in 0..frames {
            check_interrupt()?;
            let facts = driver.advance(f);
            self.gpu.write_camera(&scene.camera(f));
            let input = driver.input(f);
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
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
                && (!self.dump_transitions_only || facts.t_instances > 0);
            let read = match &self.readback {
                Some((m, r)) if dump || self.flip => {
                    m.encode_copy(&mut encoder, &self.method_target);
                    r.encode_copy(&mut encoder, &self.reference_target);
                    true
                }
                _ => false,
            };
            // The method's intermediate images (FSI's LOD buffers), only for dumped frames.
            let extras: Vec<(&str, ColorReadback)> = if dump {
                method
                    .debug_targets()
                    .into_iter()
                    .map(|(name, t)| {
                        let rb = ColorReadback::new(&ctx.device, name, t.width, t.height);
                        rb.encode_copy(&mut encoder, t);
                        (name, rb)
                    })
                    .collect()
            } else {
                Vec::new()
            };
            let index = ctx.queue.submit([encoder.finish()]);
            if let (true, Some((m, r))) = (read, &self.readback) {
                let method_rgba = m.read(ctx)?;
                let reference_rgba = r.read(ctx)?;
                if self.flip {
                    rows[f as usize].flip_mean = Some(crate::metrics::flip_mean(
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
                    on_frames(f, &method_rgba, &reference_rgba, &extras)?;
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
        let quality_ms = pass_start.elapsed().as_secs_f64() * 1e3 / frames as f64;
        let metrics = self.kernel.read(ctx, frames)?;
        let metric_gpu_ms_median = match &self.metric_timer {
            Some(t) => {
                let ms: Vec<f64> = t.read(ctx)?.into_iter().flatten().collect();
                crate::export::csv::percentile(&ms, 50.0)
            }
            None => None,
        };
        for (row, m) in rows.iter_mut().zip(metrics) {
            row.rmse = m.rmse;
            row.pop = m.pop;
            row.de2000_mean = m.de2000;
        }
        ctx.check_errors()?;
        Ok(BlockOutput {
            rows,
            info: BlockInfo {
                scene: scene.name.clone(),
                method: method_name.to_string(),
                count: scene.count,
                width: scene.width,
                height: scene.height,
                frames,
                warmup,
                timing_pass_ms_per_frame: timing_ms,
                quality_pass_ms_per_frame: quality_ms,
                quality_to_timing_ratio: quality_ms / timing_ms,
                metric_gpu_ms_median,
                extra_target_bytes: method.extra_target_bytes(),
                instance_bytes_listed_per_frame,
                instance_bytes_written_per_frame,
            },
        })
    }
}

/// What a finished run produced.
pub struct RunSummary {
    pub out_dir: PathBuf,
    pub summaries: Vec<SummaryRecord>,
    pub blocks: Vec<BlockInfo>,
}

/// The default output folder: results/<scenes>-<UTC time>/.
pub fn default_out_dir(scenes: &[String]) -> PathBuf {
    let stamp: String = now_rfc3339()
        .chars()
        .filter(|c| c.is_ascii_digit() || *c == 'T')
        .collect::<String>()
        .replace('T', "-");
    PathBuf::from("results").join(format!("{}-{stamp}", scenes.join("+")))
}

/// Creates the output folder and checks it is writable before any GPU work; removes result files of an
/// earlier run there so nothing stale looks complete.
pub fn prepare_output(dir: &Path) -> Result<()> {
    let out_err = |problem: String| Error::Output {
        path: dir.to_path_buf(),
        problem,
    };
    if dir.exists() && !dir.is_dir() {
        return Err(out_err("exists and is not a folder".into()));
    }
    std::fs::create_dir_all(dir).map_err(|e| out_err(format!("cannot be created ({e})")))?;
    let probe = dir.join(".lodbench-write-test");
    std::fs::write(&probe, b"").map_err(|e| out_err(format!("is not writable ({e})")))?;
    let _ = std::fs::remove_file(&probe);
    for stale in ["frames.csv", "summary.csv", "frames.csv.partial"] {
        let p = dir.join(stale);
        if p.exists() {
            std::fs::remove_file(&p).map_err(|e| Error::io(&p, e))?;
        }
    }
    Ok(())
}

/// Runs everything `cfg` asks for. run.json is written at the start (status running) and at the end with
/// the outcome, also when the run fails or is interrupted.
pub fn run(cfg: &RunConfig) -> Result<RunSummary> {
    // Everything that can be checked without a device is checked first.
    let defs = cfg
        .scenes
        .iter()
        .map(|s| SceneDef::new(s, &cfg.scene))
        .collect::<Result<Vec<_>>>()?;
    let out_dir = cfg
        .out
        .clone()
        .unwrap_or_else(|| default_out_dir(&cfg.scenes));
    prepare_output(&out_dir)?;
    let mut manifest = RunManifest::new(cfg.clone());
    manifest.scenes = defs.iter().map(|d| d.describe(&cfg.scene)).collect();
    manifest.write(&out_dir).map_err(|e| Error::Output {
        path: out_dir.clone(),
        problem: format!("run.json cannot be written ({e})"),
    })?;

    let result = run_blocks(cfg, &defs, &out_dir, &mut manifest);
    manifest.end_time = Some(now_rfc3339());
    match &result {
        Ok(_) => manifest.status = RunStatus::Complete,
        Err(Error::Interrupted) => {
            manifest.status = RunStatus::Interrupted;
            manifest.error = Some("interrupted by signal".into());
        }
        Err(e) => {
            manifest.status = RunStatus::Failed;
            manifest.error = Some(e.to_string());
        }
    }
    manifest.write(&out_dir)?;
    let summaries = result?;
    Ok(RunSummary {
        out_dir,
        summaries,
        blocks: manifest.blocks.clone(),
    })
}

fn run_blocks(
    cfg: &RunConfig,
    defs: &[SceneDef],
    out_dir: &Path,
    manifest: &mut RunManifest,
) -> Result<Vec<SummaryRecord>> {
    let ctx = GpuContext::new(cfg.adapter.as_deref())?;
    manifest.adapter = Some(ctx.info.clone());
    manifest.timing_source = Some(ctx.timing);
    manifest.timestamp_period_ns = Some(ctx.timestamp_period_ns);
    manifest.write(out_dir)?;

    let dumper = if cfg.dump_frames {
        Some(FrameDumper::create(out_dir)?)
    } else {
        None
    };
    let mut frames_csv = FramesWriter::create(out_dir)?;
    let mut summaries = Vec::new();

    let total: u64 = defs
        .iter()
        .map(|d| {
            let pv = cfg.resolved(&d.name);
            d.counts.len() as u64
                * cfg.methods.len() as u64
                * (pv.warmup as u64 + 2 * pv.frames as u64)
        })
        .sum();
    let progress = ProgressBar::new(total);
    progress.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} frames {msg}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );

    for def in defs {
        let warmup = cfg.resolved(&def.name).warmup;
        for &count in &def.counts {
            let scene = def.instantiate(count);
            let options = MethodOptions {
                noise: cfg.noise,
                correspondence: cfg.correspondence,
                vis_texture: cfg.vis_texture,
                fsi_check: cfg.fsi_check,
                seed: cfg.seed,
            };
            let flip = cfg.metrics.contains(&crate::metrics::Metric::Flip);
            let mut block = BlockRunner::new(&ctx, &scene, options, dumper.is_some(), flip)?;
            block.dump_transitions_only(cfg.dump_transitions);
            for method in &cfg.methods {
                progress.set_message(format!("{} n={} {}", def.name, count, method));
                let out =
                    block.run_method(method, warmup, cfg.dump_every, &progress, |f, m, r, x| {
                        match &dumper {
                            Some(d) => d.write(
                                &scene.name,
                                method,
                                count,
                                f,
                                scene.width,
                                scene.height,
                                m,
                                r,
                                x,
                            ),
                            None => Ok(()),
                        }
                    })?;
                frames_csv.write_block(&out.rows)?;
                // Each block's bootstrap has its own seed, derived from --seed and the block's position.
                let block_seed = cfg.seed.wrapping_add(summaries.len() as u64 + 1);
                let extra = out.info.extra_target_bytes;
                if let Some(s) = SummaryRecord::from_frames(&out.rows, extra, block_seed) {
                    summaries.push(s);
                }
                manifest.blocks.push(out.info);
                manifest.write(out_dir)?;
            }
        }
    }
    progress.finish_and_clear();
    frames_csv.finish()?;
    crate::export::csv::write_summary(out_dir, &summaries)?;
    Ok(summaries)
}

/// The table printed at the end of a run.
pub fn summary_table(s: &RunSummary) -> String {
    let mut out = format!(
        "{:<12} {:<13} {:>5} {:>6} {:>9} {:>9} {:>10} {:>9} {:>9} {:>9} {:>7}\n",
        "scene",
        "method",
        "count",
        "frames",
        "gpu_ms",
        "cpu_ms",
        "triangles",
        "rmse",
        "rmse_max",
        "pop_max",
        "q/t"
    );
    let fmt_opt = |v: Option<f64>| v.map_or("-".to_string(), |x| format!("{x:.3}"));
    for r in &s.summaries {
        let ratio = s
            .blocks
            .iter()
            .find(|b| b.scene == r.scene && b.method == r.method && b.count == r.count)
            .map_or(f64::NAN, |b| b.quality_to_timing_ratio);
        out.push_str(&format!(
            "{:<12} {:<13} {:>5} {:>6} {:>9} {:>9.3} {:>10.0} {:>9.5} {:>9.5} {:>9.5} {:>7.2}\n",
            r.scene,
            r.method,
            r.count,
            r.frames,
            fmt_opt(r.gpu_ms_median),
            r.cpu_ms_median,
            r.triangles_mean,
            r.rmse_mean,
            r.rmse_max,
            r.pop_max,
            ratio
        ));
    }
    out.push_str("gpu_ms and cpu_ms are medians; q/t = quality-pass time per frame / timing-pass time per frame\n");
    out
}
