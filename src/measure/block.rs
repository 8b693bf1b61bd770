//! The GPU objects of one scene block, shared by all methods run on it, and what a method's measurement on it
//! returns: one frame record per frame, built once every figure of the frame is known.

use super::effects::{ShadowRole, ShadowShare, Shadows, TaaStreams};
use super::quality::{QualityKernels, QualityOptions, QualityPass, QualityTargets};
use super::timing::{reference_ms_per_frame, TimedMethod};
use super::{BlockOutput, MethodSetup};
use crate::error::{Error, Result};
use crate::gpu::{GpuContext, RenderTarget, SceneGpu, TextureReadback};
use crate::measure::metrics::Metric;
use crate::measure::records::{
    near_transitions, transitions, BlockInfo, FrameRecord, TransitionPair,
};
use crate::methods::common::DumpKind;
use crate::methods::{Build, Method, Registry};
use crate::scene::Scene;
use indicatif::ProgressBar;

/// The images of one dumped quality-pass frame, RGBA8.
#[derive(Debug, Clone, Copy)]
pub struct FrameImages<'i> {
    pub method: &'i [u8],
    pub reference: &'i [u8],
    /// The intermediate images: the method's (FSI's LOD buffers) and lodpop's counterfactual frames.
    pub extras: &'i [(DumpKind, Vec<u8>)],
}

/// Which quality-pass frames are handed to the caller's dump callback.
#[derive(Debug, Clone, Copy)]
pub struct DumpPolicy {
    /// Dump at all (the runner was built with read-back for it).
    pub dump: bool,
    /// Only frames with an instance in transition (`--dump-transitions`).
    pub transitions_only: bool,
}

/// The engine effects of the block: `--shadows on` (the shadow pass and lights, the shadow's own share of the
/// error) and `--taa on` (the resolve and its two image streams).
pub struct BlockEffects {
    pub shadows: Option<Shadows>,
    pub shadow_share: Option<ShadowShare>,
    pub taa: Option<TaaStreams>,
}

/// The GPU objects of one scene block, shared by all methods run on it.
pub struct BlockRunner<'a> {
    pub(super) ctx: &'a GpuContext,
    pub(super) scene: &'a Scene,
    pub(super) gpu: SceneGpu,
    /// Where the timing pass draws.
    pub(super) timing_target: RenderTarget,
    pub(super) targets: QualityTargets,
    pub(super) kernels: QualityKernels,
    pub(super) reference: Box<dyn Method>,
    pub(super) setup: MethodSetup,
    /// `--metrics de2000`: the kernel computes CIEDE2000 (else de2000_mean is empty).
    pub(super) de2000: bool,
    /// Read back every quality-pass frame and compute FLIP on it.
    pub(super) flip: bool,
    /// The method's and the reference's read-back, with `--metrics flip` or dumps.
    pub(super) readback: Option<[TextureReadback; 2]>,
    pub(super) dumps: DumpPolicy,
    pub(super) effects: BlockEffects,
}

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
        ctx.check_viewport(scene.width, scene.height)?;
        let gpu = SceneGpu::with_shadow_maps(ctx, scene, ShadowRole::COUNT)?;
        let (w, h) = (scene.width, scene.height);
        let timing_target = RenderTarget::new(&ctx.device, "timing target", w, h);
        let targets = QualityTargets::new(ctx, w, h);
        let kernels = QualityKernels::new(ctx, &gpu, scene, &targets, quality)?;
        let reference = Registry::builtin().create("reference", &build(&gpu, scene, &setup))?;
        let readback = (dump || flip).then(|| {
            [
                TextureReadback::color(&ctx.device, "method read-back", w, h),
                TextureReadback::color(&ctx.device, "reference read-back", w, h),
            ]
        });
        let effects = BlockEffects {
            taa: TaaStreams::new(ctx, scene),
            shadows: Shadows::new(&gpu, scene),
            shadow_share: match scene.shadows {
                None => None,
                Some(_) => Some(ShadowShare::new(ctx, scene, &targets.reference)?),
            },
        };
        ctx.check_errors()?;
        Ok(BlockRunner {
            ctx,
            scene,
            gpu,
            timing_target,
            targets,
            kernels,
            reference,
            setup,
            de2000: quality.metrics.contains(&Metric::De2000),
            flip,
            readback,
            dumps: DumpPolicy {
                dump,
                transitions_only: false,
            },
            effects,
        })
    }

    /// Dump only frames with an instance in transition (of those, still every `dump_every`-th frame).
    pub fn dump_transitions_only(&mut self, on: bool) {
        self.dumps.transitions_only = on;
    }

    /// What a method's constructor is given.
    pub(super) fn build(&self) -> Build<'_> {
        build(&self.gpu, self.scene, &self.setup)
    }

    /// The frame's camera, and with `--shadows on` its light, into the camera uniform; draws are lit by the
    /// method's shadow map unless a stage says otherwise.
    pub(super) fn write_frame(&self, f: u32) {
        self.gpu.write_camera(&self.scene.camera(f));
        if let Some(s) = &self.effects.shadows {
            s.write_light(&self.gpu, f);
        }
        self.gpu.use_shadow_map(ShadowRole::Method.map());
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
        let t_instances: Vec<u32> = timed.facts.iter().map(|f| f.t_instances).collect();
        let dump_frames = self.dump_frames(dump_every, &near_transitions(&t_instances));
        let quality = self.quality_pass(
            timed.method.as_mut(),
            &mut timed.driver,
            &dump_frames,
            progress,
            &mut on_frames,
        )?;
        self.ctx.check_errors()?;
        let rows = self.frame_records(&timed, &quality);
        let pairs: Vec<TransitionPair> = timed.facts.iter().map(|f| f.pair).collect();
        Ok(BlockOutput {
            transitions: transitions(&rows, &pairs),
            rows,
            info: self.block_info(&timed, &quality, reference_ms),
        })
    }

    /// Per frame, whether the quality pass hands it to the dump callback: every `dump_every`-th frame, of those
    /// only the ones near a transition with `--dump-transitions`.
    fn dump_frames(&self, dump_every: u32, near_transition: &[bool]) -> Vec<bool> {
        (0..self.scene.frames)
            .map(|f| {
                self.dumps.dump
                    && f % dump_every == 0
                    && (!self.dumps.transitions_only || near_transition[f as usize])
            })
            .collect()
    }

    /// One record per frame from the method's timed frames and its quality pass.
    fn frame_records(&self, timed: &TimedMethod<'_>, quality: &QualityPass) -> Vec<FrameRecord> {
        let scene = self.scene;
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
                rmse: quality.metrics[f].rmse,
                pop: quality.metrics[f].pop,
                lodpop: quality.lodpop[f],
                de2000_mean: self.de2000.then_some(quality.metrics[f].de2000),
                uncovered_px: quality.metrics[f].uncovered_px,
                crack_px: quality.metrics[f].crack_px,
                flip_mean: quality.flip[f],
                combine_gpu_ms: quality
                    .stage_ms
                    .as_ref()
                    .and_then(|s| s.get(f).copied().flatten()),
                lag_rmse: quality.lag.as_ref().map(|l| l[f]),
                shadow_rmse: quality.shadow.as_ref().map(|s| s.rmse[f]),
                shadow_lodpop: quality.shadow.as_ref().map(|s| s.lodpop[f]),
                round: timed.round[f],
            })
            .collect()
    }

    /// The block's facts for run.json.
    fn block_info(
        &self,
        timed: &TimedMethod<'_>,
        quality: &QualityPass,
        reference_ms: Option<f64>,
    ) -> BlockInfo {
        let scene = self.scene;
        let frames = scene.frames as f64;
        let timing_ms = timed.ms_per_frame();
        BlockInfo {
            scene: scene.name().to_string(),
            method: timed.label.clone(),
            method_options: (timed.entry.options)(&self.setup.options),
            count: scene.count,
            width: scene.width,
            height: scene.height,
            frames: scene.frames,
            warmup: timed.warmup,
            timing_pass_ms_per_frame: timing_ms,
            quality_pass_ms_per_frame: quality.ms_per_frame,
            quality_to_timing_ratio: quality.ms_per_frame / timing_ms,
            quality_to_renders_ratio: reference_ms.map(|r| quality.ms_per_frame / (timing_ms + r)),
            metric_gpu_ms_median: quality.metric_gpu_ms_median,
            extra_target_bytes: timed.method.extra_target_bytes(),
            instance_bytes_listed_per_frame: timed.uploads.listed as f64 / frames,
            instance_bytes_written_per_frame: timed.uploads.written as f64 / frames,
        }
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
