//! The quality pass of one method on a block, frame by frame in stages:
//!
//! 1. **render**: the reference and the method into two targets, each lit by its own shadow map;
//! 2. **shadow maps** (`--shadows on`): what the reference, the method and the method's counterfactual cast,
//!    asked once the method has decided its frame, submitted before the frame's commands;
//! 3. **effects**: `--taa on` resolves both frames in place; `--shadows on` renders the shadow's own share;
//! 4. **metrics**: the metric kernel reduces the difference of the two targets to scalars on the GPU;
//! 5. **read-back requests**: the frames (for FLIP and dumps) and the method's intermediate images;
//! 6. **counterfactuals**: lodpop's and the lag's frames at this pose, in a submission of their own;
//! 7. **collect**: FLIP and the dump callback on the read-back images, or a bound on the frames in flight.
//!
//! The scalars of all frames are read back once at the end. FSI's combination pass is timed here.
//!
//! A method's pass is made in segments, one after each timing round over the same frames
//! ([`super::block::BlockRunner::measure_block`]), by an instance of the method of its own, warmed up as the
//! timed one: so its frames are the timed frames, and each segment's time is paired with the round's timing
//! segments for `quality_to_renders_ratio`.

use super::block_gpu::BlockGpu;
use super::coverage::{Coverage, PixelRect};
use super::diff_kernel::DiffKernel;
use super::driver::check_interrupt;
use super::driver::FrameDriver;
use super::effects::{Casters, ShadowRole, ShadowShare, Stream, TaaStreams};
use super::metric_kernel::MetricKernel;
use super::reference_cache::ReferenceCache;
use crate::error::{Error, Result};
use crate::gpu::fragments::FragmentRows;
use crate::gpu::timestamps::GpuTimer;
use crate::gpu::{GpuContext, RenderTarget, SceneGpu, TextureReadback};
use crate::measure::metrics::{FrameMetrics, Metric, MetricReduction, MetricRegion};
use crate::methods::common::{ask_counterfactual, Counterfactual, DumpKind};
use crate::methods::{FrameInput, Method, Registry};
use crate::scene::schedule::InstanceState;
use crate::scene::Scene;
use glam::Mat4;
use indicatif::ProgressBar;
use std::collections::VecDeque;
use std::time::Instant;

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
        Ok(QualityKernels {
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

/// The shadow's own share of the error per frame (`--shadows on`).
pub struct ShadowFigures {
    pub rmse: Vec<f64>,
    pub lodpop: Vec<f64>,
}

/// What the quality pass measured, per frame.
pub struct QualityPass {
    pub metrics: Vec<FrameMetrics>,
    /// `--metrics flip`: mean FLIP per frame.
    pub flip: Vec<Option<f64>>,
    /// lodpop per frame, with its coverage and shading parts.
    pub lodpop: Vec<super::diff_kernel::DiffFigure>,
    /// Methods with a lag (FSI): lag_rmse per frame.
    pub lag: Option<Vec<f64>>,
    pub shadow: Option<ShadowFigures>,
    /// The method's own stage per frame (FSI's combination pass), when it has one: timed in the quality pass,
    /// so that its timestamps are never inside a timing-pass frame.
    pub stage_ms: Option<Vec<Option<f64>>>,
    /// The fragment shader invocations of the method's frame, per frame (None on every frame where the device
    /// has no pipeline statistics queries).
    pub fragments: Vec<Option<u64>>,
    pub ms_per_frame: f64,
    pub metric_gpu_ms_median: Option<f64>,
    /// Mean share of the frame's 16 x 16 tiles the metric kernel read.
    pub metric_tile_share: f64,
    /// Mean share of the frame's pixels lodpop's counterfactual was drawn in, over the frames it was drawn.
    pub counterfactual_pixel_share: Option<f64>,
    /// Frames on which lodpop's counterfactual was drawn (a render of the method's frame with the earlier
    /// states, inside the changed instances' rectangle).
    pub counterfactual_frames: u32,
    /// Frames whose reference frame was copied instead of drawn: from the block's [`ReferenceCache`], or in
    /// the reference's own pass from its frame.
    pub reference_frames_copied: u32,
    /// The pass's segments (one per timing round), each timed on its own.
    pub segments: Vec<SegmentCost>,
}

/// The images of one dumped quality-pass frame, RGBA8.
#[derive(Debug, Clone, Copy)]
pub struct FrameImages<'i> {
    pub method: &'i [u8],
    pub reference: &'i [u8],
    /// The intermediate images: the method's (FSI's LOD buffers) and lodpop's counterfactual frames.
    pub extras: &'i [(DumpKind, Vec<u8>)],
}

/// The quality pass's own GPU objects for one method on a block: its targets, kernels (a slot per frame), TAA
/// streams and shadow share, which carry from one segment of its pass to the next while other methods' passes
/// run in between (the block's reference cache is the one thing the stages share).
pub struct QualityStage {
    targets: QualityTargets,
    kernels: QualityKernels,
    reference: Box<dyn Method>,
    /// Read back every quality-pass frame and compute FLIP on it.
    flip: bool,
    /// The method's and the reference's read-back, with `--metrics flip` or dumps.
    readback: Option<[TextureReadback; 2]>,
    /// `--taa on`: the resolve and the two image streams.
    taa: Option<TaaStreams>,
    /// `--shadows on`: the shadow's own share of the error.
    shadow_share: Option<ShadowShare>,
    /// `--metric-region`.
    region: MetricRegion,
}

/// Keep at most this many quality-pass frames queued on the GPU.
const QUALITY_IN_FLIGHT: usize = 2;

/// The metric kernel is timed on frames 0, n, 2n, ... only: each timed frame adds two timestamp passes and a
/// resolve, fixed costs as large as a small frame's kernel on a CPU rasteriser, and `metric_gpu_ms_median` is a
/// median, which a sample of a block's frames estimates.
pub const METRIC_TIMED_EVERY: u32 = 8;

/// The schedule states of the last frames, newest first: lodpop's history.
struct StateHistory {
    /// How many earlier frames the method's counterfactual reads (`Counterfactual::lodpop_history`, at least 1).
    depth: usize,
    frames: VecDeque<Vec<InstanceState>>,
}

impl StateHistory {
    fn new(depth: usize) -> StateHistory {
        StateHistory {
            depth,
            frames: VecDeque::with_capacity(depth + 1),
        }
    }

    /// The previous frame's states (before [`StateHistory::push`] of this frame's).
    fn previous(&self) -> Option<&[InstanceState]> {
        self.frames.front().map(Vec::as_slice)
    }

    fn push(&mut self, states: &[InstanceState]) {
        self.frames.push_front(states.to_vec());
        self.frames.truncate(self.depth + 1);
    }

    /// Whether the frame after `push` can differ from its counterfactual: the states changed within the
    /// history (an instance's state is not `same` as before), a transition is under way with a history
    /// deeper than one frame, or the method says its selection changed (asked last).
    fn changed(
        &self,
        same: impl Fn(&InstanceState, &InstanceState) -> bool,
        selection_changed: impl FnOnce() -> bool,
    ) -> bool {
        let h = &self.frames;
        let same_frame = |a: &[InstanceState], b: &[InstanceState]| {
            a.len() == b.len() && a.iter().zip(b).all(|(x, y)| same(x, y))
        };
        h.len() > 1
            && (h.iter().skip(1).any(|s| !same_frame(s, &h[0]))
                || (self.depth > 1 && h.iter().flatten().any(|s| s.in_transition()))
                || selection_changed())
    }

    /// The earlier frames' states, newest first.
    fn earlier(&self) -> Vec<&[InstanceState]> {
        self.frames.iter().skip(1).map(Vec::as_slice).collect()
    }
}

/// Whether two states of an instance draw the same image of it (`Counterfactual::same_image_state`).
type SameImage<'m> = dyn Fn(&InstanceState, &InstanceState) -> bool + 'm;

/// Which counterfactual frames were drawn this frame.
#[derive(Debug, Clone, Copy)]
struct Counterfactuals {
    /// The frame without the method's lag (`now`): the method has one.
    unlagged: bool,
    /// The frame with the previous schedule (`before`), drawn inside this rectangle: it can differ from the
    /// frame there.
    changed: Option<PixelRect>,
    /// lodpop compared the frame with `before` (drawn, or under TAA the counterfactual stream's frame).
    compared: bool,
}

/// The read-backs one frame asked for.
struct FrameReads {
    /// The method's and the reference's frames were copied for read-back.
    frames: bool,
    /// The frame goes to the dump callback.
    dump: bool,
    /// The method's intermediate images and the counterfactual frames (dumped frames only).
    extras: Vec<(DumpKind, TextureReadback)>,
}

/// One segment of a quality pass: its frames, its wall time and what it rendered besides the method's frames.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentCost {
    pub frames: [u32; 2],
    pub ms: f64,
    /// Frames on which lodpop's counterfactual was drawn.
    pub counterfactual_frames: u32,
    /// Frames whose reference frame was copied, not drawn.
    pub reference_copied: u32,
}

/// What the pass carries from frame to frame, and from one segment to the next.
pub struct Walk {
    /// Per frame, whether it goes to the dump callback.
    dump_frames: Vec<bool>,
    history: StateHistory,
    in_flight: VecDeque<wgpu::SubmissionIndex>,
    flip: Vec<Option<f64>>,
    has_lag: bool,
    /// Where the frames can differ from the background (the kernels' tiles, the counterfactual's scissor).
    coverage: Coverage,
    /// Tiles the metric kernel read, summed over the frames.
    tiles_read: u64,
    /// Pixels lodpop's counterfactual was drawn in, summed, and the frames it was drawn on.
    counterfactual_pixels: (u64, u32),
    /// The method is the reference and its frame is made by the frame alone: the reference frame is a copy
    /// of the method's.
    reference_is_method_frame: bool,
    /// Frames whose reference frame was copied, not drawn.
    reference_copied: u32,
    /// The metric timer's slots written in this pass.
    metric_timed: Vec<u32>,
    /// The method frames' fragment counts, resolved ([`crate::gpu::fragments`]; no frame counted where the
    /// device has no pipeline statistics queries).
    fragments: FragmentRows,
    /// The pass's segments so far.
    segments: Vec<SegmentCost>,
}

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
    fn reference_copyable(taa: &Option<TaaStreams>, shadow_share: &Option<ShadowShare>) -> bool {
        taa.is_none() && shadow_share.is_none()
    }

    /// The start of the quality pass of `method` (`is_reference`: the reference itself): what it carries from
    /// frame to frame. `dump_frames`: per frame, whether it goes to the dump callback. The pass is then made in
    /// segments ([`QualityStage::segment`]) and read at the end ([`QualityStage::finish`]).
    pub fn begin(
        &mut self,
        base: &BlockGpu<'_>,
        (method, is_reference): (&mut dyn Method, bool),
        dump_frames: Vec<bool>,
    ) -> Walk {
        if let Some(taa) = &mut self.taa {
            taa.reset();
        }
        let history = ask_counterfactual(method, |m| m.lodpop_history().max(1));
        let confined = ask_counterfactual(method, |m| m.image_confined_to_instances())
            && ask_counterfactual(self.reference.as_mut(), |m| m.image_confined_to_instances());
        let mut walk = Walk {
            dump_frames,
            history: StateHistory::new(history),
            in_flight: VecDeque::new(),
            flip: vec![None; base.scene.frames as usize],
            has_lag: false,
            coverage: Coverage::new(base.scene, self.region == MetricRegion::Covered && confined),
            tiles_read: 0,
            counterfactual_pixels: (0, 0),
            reference_is_method_frame: is_reference
                && Self::reference_copyable(&self.taa, &self.shadow_share),
            reference_copied: 0,
            metric_timed: Vec::new(),
            fragments: FragmentRows::new(base.scene.frames),
            segments: Vec::new(),
        };
        walk.coverage.reset();
        walk
    }

    /// The quality pass of `method` over `frames`, the next frames of its walk `driver` (reset before the
    /// first segment), timed by the wall clock from its first command to the GPU's last; `cache`: the block's
    /// reference frames (kept by whichever pass drew them first).
    pub fn segment(
        &mut self,
        base: &BlockGpu<'_>,
        (method, driver): (&mut dyn Method, &mut FrameDriver<'_>),
        (walk, frames): (&mut Walk, std::ops::Range<u32>),
        cache: Option<&ReferenceCache>,
        progress: &ProgressBar,
        on_frames: &mut dyn FnMut(u32, FrameImages<'_>) -> Result<()>,
    ) -> Result<()> {
        let start = Instant::now();
        let before = (walk.counterfactual_pixels.1, walk.reference_copied);
        let first = frames.start;
        for f in frames.clone() {
            check_interrupt()?;
            driver.advance(f);
            self.quality_frame(base, (method, cache), driver, f, walk, on_frames)?;
            progress.inc(1);
        }
        base.ctx.wait_idle()?;
        walk.in_flight.clear();
        walk.segments.push(SegmentCost {
            frames: [first, frames.end],
            ms: start.elapsed().as_secs_f64() * 1e3,
            counterfactual_frames: walk.counterfactual_pixels.1 - before.0,
            reference_copied: walk.reference_copied - before.1,
        });
        Ok(())
    }

    /// One frame of the quality pass, through every stage.
    fn quality_frame(
        &mut self,
        base: &BlockGpu<'_>,
        (method, cache): (&mut dyn Method, Option<&ReferenceCache>),
        driver: &FrameDriver<'_>,
        f: u32,
        walk: &mut Walk,
        on_frames: &mut dyn FnMut(u32, FrameImages<'_>) -> Result<()>,
    ) -> Result<()> {
        let (ctx, dump) = (base.ctx, walk.dump_frames[f as usize]);
        base.write_frame(f);
        if let Some(taa) = &self.taa {
            taa.begin_frame(ctx);
        }
        let input = driver.input(f);
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        if f == 0 {
            self.clear_kernels(&mut encoder);
        }
        let copy_method = walk.reference_is_method_frame;
        let read_back = dump || self.flip;
        if self.render_frames(
            base,
            (method, cache),
            (&input, f, copy_method),
            (&mut encoder, &mut walk.fragments),
            read_back,
        ) {
            walk.reference_copied += 1;
        }
        let previous = walk.history.previous();
        let shadows = self.shadow_maps(base, method, &input, previous);
        self.apply_effects(base, &input, &mut encoder, (f, previous.is_some()));
        let view_proj = base.scene.camera(f).view_proj();
        let mut tiles = walk
            .coverage
            .frame_tiles(base.scene, &driver.matrices, view_proj);
        if copy_method {
            // The reference's frame compared with itself (the same draw, copied): every figure of the kernel
            // is 0 by construction, so no tile is read (frame 0 still zeroes the block's sums).
            tiles.clear();
        }
        walk.tiles_read += tiles.len() as u64;
        if self.encode_metrics(base, &mut encoder, f, &tiles) {
            walk.metric_timed.push(f / METRIC_TIMED_EVERY);
        }
        let mut reads = self.request_reads(base, method, &mut encoder, dump);
        let mut index = ctx
            .queue
            .submit(shadows.into_iter().chain([encoder.finish()]));
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        walk.history.push(&driver.states);
        let drawn = ask_counterfactual(method, |method| {
            self.counterfactuals(
                base,
                method,
                (&input, &walk.history),
                (&walk.coverage, dump),
                &mut encoder,
            )
        });
        walk.has_lag |= drawn.unlagged;
        if let Some(rect) = drawn.changed {
            walk.counterfactual_pixels.0 += rect.pixels();
            walk.counterfactual_pixels.1 += 1;
        }
        if reads.dump {
            self.request_counterfactual_reads(base, drawn, &mut encoder, &mut reads);
        }
        if drawn.unlagged || drawn.changed.is_some() || self.taa.is_some() {
            index = ctx.queue.submit([encoder.finish()]);
        }
        if let Some(taa) = &mut self.taa {
            taa.advance();
        }
        self.collect_frame(base, f, reads, index, walk, on_frames)
    }

    /// lodpop's, the lag's and the shadow share's accumulators, before the first frame.
    fn clear_kernels(&self, encoder: &mut wgpu::CommandEncoder) {
        self.kernels.lodpop.clear(encoder);
        self.kernels.lag.clear(encoder);
        if let Some(share) = &self.shadow_share {
            share.rmse.clear(encoder);
            share.lodpop.clear(encoder);
        }
    }

    /// Stage 1: the reference and the method, each lit by its own shadow map. The reference frame is not drawn
    /// (returns true) where an earlier pass kept frame `f` in the cache, or where `copy_method` says the
    /// method's frame is the same draw (copied); a drawn or copied reference frame is kept for the next pass
    /// where the cache has room. The method's frame is copied into the reference target only where something
    /// reads that target this frame (a dump or FLIP: the metric kernel skips a frame compared with itself); the
    /// cache then keeps it from the method's target. The method's frame alone has its fragments counted into
    /// `fragments`, where the device can ([`crate::gpu::fragments`]).
    fn render_frames(
        &mut self,
        base: &BlockGpu<'_>,
        (method, cache): (&mut dyn Method, Option<&ReferenceCache>),
        (input, f, copy_method): (&FrameInput<'_>, u32, bool),
        (encoder, fragments): (&mut wgpu::CommandEncoder, &mut FragmentRows),
        read_back: bool,
    ) -> bool {
        let (gpu, t, reference) = (&base.gpu, &self.targets, &mut self.reference);
        let from_cache = cache.is_some_and(|c| c.restore(encoder, f, &t.reference));
        let from_method = !from_cache && copy_method;
        if !from_cache && !from_method {
            let input = input.lit_by(ShadowRole::Reference.map());
            reference.encode(gpu, &input, encoder, &t.reference);
        }
        if let Some(queries) = &gpu.fragments {
            queries.start();
        }
        method.encode(
            gpu,
            &input.lit_by(ShadowRole::Method.map()),
            encoder,
            &t.method,
        );
        if let Some(queries) = &gpu.fragments {
            queries.resolve(encoder, fragments, f);
        }
        if from_method && read_back {
            t.method.copy_color_to(encoder, &t.reference);
        }
        if let (false, Some(c)) = (from_cache, cache) {
            c.store(
                encoder,
                f,
                if from_method { &t.method } else { &t.reference },
            );
        }
        from_cache || from_method
    }

    /// Stage 2 (`--shadows on`): the frame's shadow maps: the reference's LOD0, the method's casters, and, for
    /// lodpop's counterfactual, what the method cast with the `previous` frame's states.
    fn shadow_maps(
        &self,
        base: &BlockGpu<'_>,
        method: &dyn Method,
        input: &FrameInput<'_>,
        previous: Option<&[InstanceState]>,
    ) -> Vec<wgpu::CommandBuffer> {
        let Some(shadows) = &base.shadows else {
            return Vec::new();
        };
        let gpu = &base.gpu;
        let mut out = vec![
            shadows.commands(
                gpu,
                self.reference.as_ref(),
                input,
                input.states,
                (ShadowRole::Reference, Casters::Reference),
            ),
            shadows.commands(
                gpu,
                method,
                input,
                input.states,
                (ShadowRole::Method, Casters::Method),
            ),
        ];
        if let Some(previous) = previous {
            out.push(shadows.commands(
                gpu,
                method,
                input,
                previous,
                (ShadowRole::Before, Casters::Method),
            ));
        }
        out
    }

    /// Stage 3: TAA resolves both frames in place (each against its own history) before anything reads them,
    /// after the method's frame is copied into lodpop's `before` target (the counterfactual stream's frame
    /// unless stage 6 draws one); the shadow's own share: LOD0 objects lit by the method's shadow map now and
    /// by its counterfactual's (on the first frame, which has no earlier schedule, the same frame), each its
    /// own stream under TAA. `has_previous`: the frame has an earlier one.
    fn apply_effects(
        &mut self,
        base: &BlockGpu<'_>,
        input: &FrameInput<'_>,
        encoder: &mut wgpu::CommandEncoder,
        (f, has_previous): (u32, bool),
    ) {
        let (ctx, gpu, t, reference) = (base.ctx, &base.gpu, &self.targets, &mut self.reference);
        if let Some(taa) = &self.taa {
            t.method.copy_color_to(encoder, &t.before);
            taa.resolve(ctx, encoder, Stream::Method, &t.method);
            taa.resolve(ctx, encoder, Stream::Reference, &t.reference);
        }
        let Some(share) = &self.shadow_share else {
            return;
        };
        let now = input.lit_by(ShadowRole::Method.map());
        reference.encode(gpu, &now, encoder, &share.now);
        if has_previous {
            let before = input.lit_by(ShadowRole::Before.map());
            reference.encode(gpu, &before, encoder, &share.before);
        } else {
            share.now.copy_color_to(encoder, &share.before);
        }
        if let Some(taa) = &self.taa {
            taa.resolve(ctx, encoder, Stream::ShadowNow, &share.now);
            taa.resolve(ctx, encoder, Stream::ShadowBefore, &share.before);
        }
        share.rmse.encode(&ctx.queue, encoder, f, 0);
        if f > 0 {
            share.lodpop.encode(&ctx.queue, encoder, f, 0);
        }
    }

    /// Stage 4: the metric kernel on (method, reference) over `tiles`, timed on its own every
    /// [`METRIC_TIMED_EVERY`]th frame where it reads a tile (returns whether this frame was timed).
    fn encode_metrics(
        &self,
        base: &BlockGpu<'_>,
        encoder: &mut wgpu::CommandEncoder,
        f: u32,
        tiles: &[u32],
    ) -> bool {
        let k = &self.kernels;
        let timer = match &k.metric_timer {
            Some(t) if f.is_multiple_of(METRIC_TIMED_EVERY) && !tiles.is_empty() => Some(t),
            _ => None,
        };
        if let Some(t) = timer {
            t.begin(encoder, f / METRIC_TIMED_EVERY);
        }
        k.metric.encode(&base.ctx.queue, encoder, f, tiles);
        if let Some(t) = timer {
            t.end(encoder, f / METRIC_TIMED_EVERY);
        }
        timer.is_some()
    }

    /// Stage 5: copies of the frames for FLIP or a dump, and of the method's intermediate images (FSI's LOD
    /// buffers) for a dump.
    fn request_reads(
        &self,
        base: &BlockGpu<'_>,
        method: &dyn Method,
        encoder: &mut wgpu::CommandEncoder,
        dump: bool,
    ) -> FrameReads {
        let frames = match &self.readback {
            Some([m, r]) if dump || self.flip => {
                m.encode_copy(encoder, &self.targets.method);
                r.encode_copy(encoder, &self.targets.reference);
                true
            }
            _ => false,
        };
        let extras = if dump {
            method
                .debug_targets()
                .into_iter()
                .map(|(kind, t)| (kind, self.copy_of(base, encoder, kind, t)))
                .collect()
        } else {
            Vec::new()
        };
        FrameReads {
            frames,
            dump,
            extras,
        }
    }

    fn copy_of(
        &self,
        base: &BlockGpu<'_>,
        encoder: &mut wgpu::CommandEncoder,
        kind: DumpKind,
        t: &RenderTarget,
    ) -> TextureReadback {
        let rb = TextureReadback::color(&base.ctx.device, kind.name(), t.width, t.height);
        rb.encode_copy(encoder, t);
        rb
    }

    /// Stage 6: lodpop's and the lag's counterfactual frames at this pose, and their kernels (the method
    /// writes its instance data again through the queue, so this goes in a submission of its own). Where the
    /// coverage is bounded and the frame is not dumped, lodpop's counterfactual is drawn and compared only
    /// inside [`QualityStage::changed_rect`] (outside it the two frames are equal), and not at all when that
    /// is empty. Under TAA each counterfactual is a stream of its own: `before` is fed every frame (the
    /// method's own frame, or the unlagged one, where the counterfactual is not drawn: the two are equal
    /// there) and compared on every frame but the first, since the histories differ for some frames after any
    /// difference.
    fn counterfactuals(
        &self,
        base: &BlockGpu<'_>,
        method: &mut dyn Counterfactual,
        (input, history): (&FrameInput<'_>, &StateHistory),
        (coverage, dump): (&Coverage, bool),
        encoder: &mut wgpu::CommandEncoder,
    ) -> Counterfactuals {
        let (ctx, gpu, t, k) = (base.ctx, &base.gpu, &self.targets, &self.kernels);
        let f = input.frame;
        let taa = self.taa.as_ref();
        let full = PixelRect::full(base.scene.width, base.scene.height);
        let covered = self.region == MetricRegion::Covered;
        // A transition's moving pattern (dither --noise-temporal) changes an instance in transition every frame.
        let moving = method.transition_pattern_moves();
        let same = |a: &InstanceState, b: &InstanceState| {
            !(moving && (a.in_transition() || b.in_transition()))
                && match covered {
                    true => method.same_image_state(a, b),
                    false => a == b,
                }
        };
        let mut changed = history.changed(same, || method.selection_changed());
        let rect = match (changed, dump) {
            (true, false) => Self::changed_rect(base, input, history, (coverage, &same)),
            _ => full,
        };
        changed &= !rect.is_empty();
        let unlagged = self.encode_unlagged(base, method, (input, changed), encoder);
        if changed {
            let earlier = history.earlier();
            // Inside a scissor, an instance whose rectangle misses it is drawn nowhere: its matrix is zeroed
            // (every vertex at the clip-space origin, w = 0, so the clipper drops its triangles).
            let culled: Vec<Mat4>;
            let lit = input.lit_by(ShadowRole::Before.map());
            let input = if rect == full {
                lit
            } else {
                culled = Self::culled_matrices(base, input, coverage, rect);
                let [x, y] = [rect.x0, rect.y0];
                FrameInput {
                    matrices: &culled,
                    view: lit.view.scissored([x, y, rect.x1 - x, rect.y1 - y]),
                    ..lit
                }
            };
            method.encode_before(gpu, &input, &earlier, encoder, &t.before);
        }
        if let Some(taa) = taa {
            taa.resolve(ctx, encoder, Stream::Before, &t.before);
        }
        let compared = changed || (taa.is_some() && f > 0);
        if compared {
            k.lodpop.encode_in(
                &ctx.queue,
                encoder,
                (f, unlagged as usize),
                if changed { rect } else { full },
            );
        }
        Counterfactuals {
            unlagged,
            changed: changed.then_some(rect),
            compared,
        }
    }

    /// The method's unlagged frame into `now` where it draws one (resolved by TAA, after `now` is copied to
    /// `before` when nothing `changed`), and the lag kernel on it; whether it drew one.
    fn encode_unlagged(
        &self,
        base: &BlockGpu<'_>,
        method: &mut dyn Counterfactual,
        (input, changed): (&FrameInput<'_>, bool),
        encoder: &mut wgpu::CommandEncoder,
    ) -> bool {
        let (ctx, gpu, t, k) = (base.ctx, &base.gpu, &self.targets, &self.kernels);
        let unlagged = method.encode_unlagged(gpu, input, encoder, &t.now);
        if unlagged {
            if let Some(taa) = self.taa.as_ref() {
                if !changed {
                    t.now.copy_color_to(encoder, &t.before);
                }
                taa.resolve(ctx, encoder, Stream::Unlagged, &t.now);
            }
            k.lag.encode(&ctx.queue, encoder, input.frame, 0);
        }
        unlagged
    }

    /// The frame's instance matrices with those whose rectangle misses `rect` zeroed (every vertex at the
    /// clip-space origin, w = 0, so the clipper drops its triangles).
    fn culled_matrices(
        base: &BlockGpu<'_>,
        input: &FrameInput<'_>,
        coverage: &Coverage,
        rect: PixelRect,
    ) -> Vec<Mat4> {
        let view_proj = base.scene.camera(input.frame).view_proj();
        input
            .matrices
            .iter()
            .enumerate()
            .map(|(i, m)| {
                match coverage
                    .instance_rect(base.scene, i, *m, view_proj)
                    .overlaps(&rect)
                {
                    true => *m,
                    false => Mat4::ZERO,
                }
            })
            .collect()
    }

    /// Where this frame and its counterfactual can differ: the union of the rectangles of the instances whose
    /// state differs from the previous frame's, when the coverage is bounded and the method's frame depends on
    /// one earlier frame only (else the whole frame). Outside it both frames draw the same fragments of the
    /// same instances in the same order.
    fn changed_rect(
        base: &BlockGpu<'_>,
        input: &FrameInput<'_>,
        history: &StateHistory,
        (coverage, same): (&Coverage, &SameImage<'_>),
    ) -> PixelRect {
        let full = PixelRect::full(base.scene.width, base.scene.height);
        let earlier = history.earlier();
        if !coverage.bounded || history.depth != 1 || earlier.len() != 1 {
            return full;
        }
        let (now, before) = (input.states, earlier[0]);
        if now.len() != before.len() {
            return full;
        }
        let view_proj = base.scene.camera(input.frame).view_proj();
        coverage.rect_of(base.scene, input.matrices, view_proj, |i| {
            !same(&now[i], &before[i])
        })
    }

    /// With a dump: the counterfactual frames drawn this frame, for read-back.
    fn request_counterfactual_reads(
        &self,
        base: &BlockGpu<'_>,
        drawn: Counterfactuals,
        encoder: &mut wgpu::CommandEncoder,
        reads: &mut FrameReads,
    ) {
        for (kind, show, target) in [
            (DumpKind::LodpopNow, drawn.unlagged, &self.targets.now),
            (DumpKind::LodpopBefore, drawn.compared, &self.targets.before),
        ] {
            if show {
                let rb = self.copy_of(base, encoder, kind, target);
                reads.extras.push((kind, rb));
            }
        }
    }

    /// Stage 7: FLIP and the dump callback on the frame's read-back images, or, when nothing is read back, a
    /// bound on the frames queued on the GPU.
    fn collect_frame(
        &self,
        base: &BlockGpu<'_>,
        f: u32,
        reads: FrameReads,
        index: wgpu::SubmissionIndex,
        walk: &mut Walk,
        on_frames: &mut dyn FnMut(u32, FrameImages<'_>) -> Result<()>,
    ) -> Result<()> {
        let ctx = base.ctx;
        if let (true, Some([m, r])) = (reads.frames, &self.readback) {
            let method_rgba = m.read(ctx)?;
            let reference_rgba = r.read(ctx)?;
            if self.flip {
                walk.flip[f as usize] = Some(crate::measure::metrics::flip_mean(
                    &method_rgba,
                    &reference_rgba,
                    base.scene.width,
                    base.scene.height,
                ));
            }
            if reads.dump {
                let extras = reads
                    .extras
                    .iter()
                    .map(|(kind, rb)| Ok((*kind, rb.read(ctx)?)))
                    .collect::<Result<Vec<_>>>()?;
                let images = FrameImages {
                    method: &method_rgba,
                    reference: &reference_rgba,
                    extras: &extras,
                };
                on_frames(f, images)?;
            }
            return Ok(());
        }
        walk.in_flight.push_back(index);
        if walk.in_flight.len() > QUALITY_IN_FLIGHT {
            if let Some(oldest) = walk.in_flight.pop_front() {
                ctx.device
                    .poll(wgpu::PollType::Wait {
                        submission_index: Some(oldest),
                        timeout: None,
                    })
                    .map_err(|e| Error::Gpu(format!("waiting for the GPU: {e}")))?;
            }
        }
        Ok(())
    }

    /// After the last segment: every kernel's per-frame figures, read back once.
    pub fn finish(
        &self,
        base: &BlockGpu<'_>,
        method: &dyn Method,
        walk: Walk,
    ) -> Result<QualityPass> {
        let (ctx, k, frames) = (base.ctx, &self.kernels, base.scene.frames);
        let pixels = base.scene.width as f64 * base.scene.height as f64;
        let metric_tile_share =
            walk.tiles_read as f64 / (walk.coverage.tile_count() as f64 * frames.max(1) as f64);
        let (drawn_pixels, drawn_frames) = walk.counterfactual_pixels;
        let counterfactual_pixel_share =
            (drawn_frames > 0).then(|| drawn_pixels as f64 / (pixels * drawn_frames as f64));
        let shadow = match &self.shadow_share {
            Some(share) => Some(ShadowFigures {
                rmse: share.rmse.read(ctx, frames)?,
                lodpop: share.lodpop.read(ctx, frames)?,
            }),
            None => None,
        };
        let metric_gpu_ms_median = match &k.metric_timer {
            Some(t) => {
                let slots = t.read(ctx)?;
                let ms: Vec<f64> = walk
                    .metric_timed
                    .iter()
                    .filter_map(|&i| slots.get(i as usize).copied().flatten())
                    .collect();
                crate::measure::stats::percentile(&ms, 50.0)
            }
            None => None,
        };
        Ok(QualityPass {
            fragments: walk.fragments.read(ctx)?,
            metrics: k.metric.read(ctx, frames)?,
            flip: walk.flip,
            lodpop: k.lodpop.read_parts(ctx, frames)?,
            lag: if walk.has_lag {
                Some(k.lag.read(ctx, frames)?)
            } else {
                None
            },
            shadow,
            stage_ms: method.stage_gpu_ms(ctx)?,
            metric_gpu_ms_median,
            metric_tile_share,
            counterfactual_pixel_share,
            counterfactual_frames: drawn_frames,
            reference_frames_copied: walk.reference_copied,
            ms_per_frame: walk.segments.iter().map(|s| s.ms).sum::<f64>() / frames.max(1) as f64,
            segments: walk.segments,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn states(lods: &[(u32, u32, f32)]) -> Vec<InstanceState> {
        lods.iter()
            .map(|&(lod_from, lod_to, k)| InstanceState {
                lod_from,
                lod_to,
                k,
            })
            .collect()
    }

    #[test]
    fn the_counterfactual_is_drawn_only_when_the_frame_can_differ() {
        let steady = states(&[(1, 1, 0.0), (2, 2, 0.0)]);
        let switched = states(&[(1, 1, 0.0), (3, 3, 0.0)]);
        let mut h = StateHistory::new(1);
        h.push(&steady);
        assert!(
            !h.changed(|a, b| a == b, || true),
            "the first frame has no earlier frame"
        );
        assert_eq!(h.previous(), Some(steady.as_slice()));
        h.push(&steady);
        assert!(!h.changed(|a, b| a == b, || false), "the same states twice");
        assert!(
            h.changed(|a, b| a == b, || true),
            "the method's own selection changed"
        );
        h.push(&switched);
        assert!(h.changed(|a, b| a == b, || false), "an instance switched");
        assert_eq!(
            h.earlier(),
            vec![steady.as_slice()],
            "depth 1 keeps one earlier frame"
        );
    }

    #[test]
    fn a_deeper_history_counts_a_transition_under_way() {
        let blending = states(&[(1, 2, 0.5)]);
        let mut shallow = StateHistory::new(1);
        let mut deep = StateHistory::new(2);
        for _ in 0..3 {
            shallow.push(&blending);
            deep.push(&blending);
        }
        assert!(
            !shallow.changed(|a, b| a == b, || false),
            "one frame back, the same blend state"
        );
        assert!(
            deep.changed(|a, b| a == b, || false),
            "two frames back, a transition under way"
        );
        assert_eq!(deep.earlier().len(), 2);
    }
}
