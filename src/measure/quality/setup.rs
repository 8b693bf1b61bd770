//! The quality pass's set-up: its options, targets and kernels, and the stage that holds them for one method
//! on a block (its reference's frames from the block's cache where they can be copied).

use crate::error::Result;
use crate::gpu::timestamps::GpuTimer;
use crate::gpu::{GpuContext, RenderTarget, SceneGpu, TextureReadback};
use crate::measure::block_gpu::BlockGpu;
use crate::measure::diff_kernel::DiffKernel;
use crate::measure::effects::{ShadowShare, TaaStreams};
use crate::measure::metric_kernel::MetricKernel;
use crate::measure::metrics::{Metric, MetricReduction, MetricRegion};
use crate::measure::reference_cache::ReferenceCache;
use crate::methods::{Method, Registry};
use crate::scene::Scene;

/// When a block's quality segments are made (`--quality-schedule`).
#[derive(
    Debug,
    Clone,
    Copy,
    Default,
    PartialEq,
    Eq,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum QualitySchedule {
    /// In every round, right after its timing segments: `quality_to_renders_ratio` pairs each quality segment
    /// with the timing segments seconds before it; the timing rounds run between quality segments.
    #[default]
    Rounds,
    /// After the last timing round, round by round: the timing rounds run back to back, as in a `--quality
    /// off` run, and each quality segment is divided by timing segments minutes before it.
    After,
}

/// What the quality pass computes besides rmse, pop and lodpop, and how.
#[derive(Debug, Clone, Default)]
pub struct QualityOptions {
    /// `--metrics`: `Metric::Flip` and `Metric::De2000` switch those metrics on.
    pub metrics: Vec<Metric>,
    /// `--metric-reduction`.
    pub reduction: MetricReduction,
    /// `--metric-region`.
    pub region: MetricRegion,
    /// `--quality off`: no quality pass at all (the block builds no stage; its figures are empty).
    pub timing_only: bool,
    /// `--quality-schedule`.
    pub schedule: QualitySchedule,
    /// Bytes the block may keep of the reference's frames for its next methods (`--reference-cache-mib`;
    /// 0: draw the reference in every method's pass). [`ReferenceCache`] says where it is not used.
    pub reference_cache_bytes: u64,
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

/// The quality pass's render targets.
pub struct QualityTargets {
    pub method: RenderTarget,
    pub reference: RenderTarget,
    /// lodpop's counterfactual frames at the current pose: without the method's lag (`now`) and with the
    /// previous schedule (`before`).
    pub now: RenderTarget,
    pub before: RenderTarget,
}

impl QualityTargets {
    pub fn new(ctx: &GpuContext, w: u32, h: u32) -> QualityTargets {
        QualityTargets {
            method: RenderTarget::new(&ctx.device, "method target", w, h),
            reference: RenderTarget::new(&ctx.device, "reference target", w, h),
            now: RenderTarget::new(&ctx.device, "lodpop now target", w, h),
            before: RenderTarget::new(&ctx.device, "lodpop before target", w, h),
        }
    }
}

/// The quality pass's GPU reductions, one slot per frame each.
pub struct QualityKernels {
    /// rmse, pop, de2000, uncovered and crack pixels of (method, reference).
    pub metric: MetricKernel,
    /// Times the metric kernel alone on every [`METRIC_TIMED_EVERY`]th frame (its own cost, reported in
    /// run.json).
    pub metric_timer: Option<GpuTimer>,
    /// lodpop: pair 0 = (method, before), pair 1 = (now, before).
    pub lodpop: DiffKernel,
    /// lag_rmse: (method, now).
    pub lag: DiffKernel,
    /// `--impostor`: view_pop's counterfactual frame and its kernel (method, view).
    pub view: Option<ViewPop>,
}

/// view_pop's frame (the method's frame with the impostors' frames selected from the previous frame's eye) and
/// its difference from the method's.
pub struct ViewPop {
    pub target: RenderTarget,
    pub kernel: DiffKernel,
}

impl QualityKernels {
    pub fn new(
        ctx: &GpuContext,
        gpu: &SceneGpu,
        scene: &Scene,
        t: &QualityTargets,
        quality: &QualityOptions,
    ) -> Result<QualityKernels> {
        let frames = scene.frames;
        let pairs = [(&t.method, &t.before), (&t.now, &t.before)];
        let background = gpu.background_bytes(ctx)?;
        let view = match scene.impostor {
            Some(_) if scene.taa.is_none() => {
                let target = RenderTarget::new(
                    &ctx.device,
                    "view_pop target",
                    t.method.width,
                    t.method.height,
                );
                let kernel =
                    DiffKernel::new(ctx, "view_pop", &[(&t.method, &target)], frames, background)?;
                Some(ViewPop { target, kernel })
            }
            _ => None,
        };
        Ok(QualityKernels {
            view,
            lodpop: DiffKernel::new(ctx, "lodpop", &pairs, frames, background)?,
            lag: DiffKernel::new(ctx, "lag", &[(&t.method, &t.now)], frames, background)?,
            metric: MetricKernel::new(
                ctx,
                (&t.method, &t.reference),
                frames,
                (quality.metrics.contains(&Metric::De2000), quality.reduction),
                background,
            )?,
            metric_timer: GpuTimer::new(ctx, frames.div_ceil(METRIC_TIMED_EVERY)),
        })
    }
}

/// The quality pass's own GPU objects for one method on a block: its targets, kernels (a slot per frame), TAA
/// streams and shadow share, which carry from one segment of its pass to the next while other methods' passes
/// run in between (the block's reference cache is the one thing the stages share).
pub struct QualityStage {
    pub(super) targets: QualityTargets,
    pub(super) kernels: QualityKernels,
    pub(super) reference: Box<dyn Method>,
    /// Read back every quality-pass frame and compute FLIP on it.
    pub(super) flip: bool,
    /// The method's and the reference's read-back, with `--metrics flip` or dumps.
    pub(super) readback: Option<[TextureReadback; 2]>,
    /// `--taa on`: the resolve and the two image streams.
    pub(super) taa: Option<TaaStreams>,
    /// `--shadows on`: the shadow's own share of the error.
    pub(super) shadow_share: Option<ShadowShare>,
    /// `--metric-region`.
    pub(super) region: MetricRegion,
}

/// Keep at most this many quality-pass frames queued on the GPU.
pub(super) const QUALITY_IN_FLIGHT: usize = 2;

/// The metric kernel is timed on frames 0, n, 2n, ... only: each timed frame adds two timestamp passes and a
/// resolve, fixed costs as large as a small frame's kernel on a CPU rasteriser, and `metric_gpu_ms_median` is a
/// median, which a sample of a block's frames estimates.
pub const METRIC_TIMED_EVERY: u32 = 8;

impl QualityStage {
    /// `dump`: hand frames to the pass's callback.
    pub fn new(base: &BlockGpu<'_>, dump: bool, quality: &QualityOptions) -> Result<QualityStage> {
        let (ctx, scene) = (base.ctx, base.scene);
        let flip = quality.metrics.contains(&Metric::Flip);
        let (w, h) = (scene.width, scene.height);
        let targets = QualityTargets::new(ctx, w, h);
        let kernels = QualityKernels::new(ctx, &base.gpu, scene, &targets, quality)?;
        let reference = Registry::builtin().create("reference", &base.build())?;
        let readback = (dump || flip).then(|| {
            [
                TextureReadback::color(&ctx.device, "method read-back", w, h),
                TextureReadback::color(&ctx.device, "reference read-back", w, h),
            ]
        });
        let shadow_share = match scene.shadows {
            None => None,
            Some(_) => Some(ShadowShare::new(
                ctx,
                scene,
                &targets.reference,
                base.gpu.background_bytes(ctx)?,
            )?),
        };
        let taa = TaaStreams::new(ctx, scene);
        Ok(QualityStage {
            taa,
            shadow_share,
            targets,
            kernels,
            reference,
            region: quality.region,
            flip,
            readback,
        })
    }

    /// The block's reference cache for rounds of at most `round_frames` frames (`quality.reference_cache_bytes`),
    /// where a copy of the reference frame can stand in for a draw in this stage's passes (None: drawn in every
    /// pass).
    pub fn reference_cache(
        &self,
        base: &BlockGpu<'_>,
        quality: &QualityOptions,
        round_frames: u32,
    ) -> Option<ReferenceCache> {
        let scene = base.scene;
        match Self::reference_copyable(&self.taa, &self.shadow_share) {
            true => ReferenceCache::new(
                base.ctx,
                (scene.width, scene.height),
                round_frames,
                quality.reference_cache_bytes,
            ),
            false => None,
        }
    }

    /// Whether the reference frame is made by the frame alone, so that a copy of it can stand in for a draw: not
    /// under TAA (its stream carries a history) nor with shadows (its shadow map is drawn in the same pass).
    pub(super) fn reference_copyable(
        taa: &Option<TaaStreams>,
        shadow_share: &Option<ShadowShare>,
    ) -> bool {
        taa.is_none() && shadow_share.is_none()
    }
}
