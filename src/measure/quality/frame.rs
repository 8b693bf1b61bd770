//! One quality-pass frame in stages: render, shadow maps, effects, metrics, read-back requests (the
//! counterfactuals and the collection in their own files).

use crate::error::Result;
use crate::gpu::fragments::FragmentRows;
use crate::measure::block_gpu::BlockGpu;
use crate::measure::driver::FrameDriver;
use crate::measure::effects::{Casters, ShadowRole, Stream};
use crate::measure::quality::collect::FrameReads;
use crate::measure::quality::outcome::FrameImages;
use crate::measure::quality::setup::{QualityStage, METRIC_TIMED_EVERY};
use crate::measure::quality::walk::Walk;
use crate::measure::reference_cache::ReferenceCache;
use crate::methods::common::ask_counterfactual;
use crate::methods::{FrameInput, Method};
use crate::scene::schedule::InstanceState;

impl QualityStage {
    /// One frame of the quality pass, through every stage.
    pub(super) fn quality_frame(
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
        walk.push_states(base, method, &input);
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
        if let Some(i) = self.view_counterfactual(base, method, (&input, &walk.history)) {
            (index, walk.view_frames) = (i, walk.view_frames + 1);
        }
        if let Some(taa) = &mut self.taa {
            taa.advance();
        }
        self.collect_frame(base, f, reads, index, walk, on_frames)
    }

    /// lodpop's, the lag's, view_pop's and the shadow share's accumulators, before the first frame.
    pub(super) fn clear_kernels(&self, encoder: &mut wgpu::CommandEncoder) {
        if let Some(v) = &self.kernels.view {
            v.kernel.clear(encoder);
        }
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
    pub(super) fn render_frames(
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
        let mut counted = input.lit_by(ShadowRole::Method.map());
        counted.view = counted.view.counting_fragments();
        method.encode(gpu, &counted, encoder, &t.method);
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
    pub(super) fn shadow_maps(
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
    pub(super) fn apply_effects(
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
    pub(super) fn encode_metrics(
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
    pub(super) fn request_reads(
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
}
