//! The counterfactual frames of a quality-pass frame: lodpop's (the earlier schedule at this pose, inside the
//! changed instances' rectangle) and the lag's (the method's frame without its lag).

use crate::gpu::{RenderTarget, TextureReadback};
use crate::measure::block_gpu::BlockGpu;
use crate::measure::coverage::{Coverage, PixelRect};
use crate::measure::effects::{ShadowRole, Stream};
use crate::measure::metrics::MetricRegion;
use crate::measure::quality::collect::FrameReads;
use crate::measure::quality::history::{SameImage, StateHistory};
use crate::measure::quality::setup::QualityStage;
use crate::measure::records::FrameChanges;
use crate::methods::common::{Counterfactual, DumpKind};
use crate::methods::FrameInput;
use crate::scene::schedule::InstanceState;
use glam::Mat4;

/// Which counterfactual frames were drawn this frame.
#[derive(Debug, Clone, Copy)]
pub(super) struct Counterfactuals {
    /// The frame without the method's lag (`now`): the method has one.
    pub(super) unlagged: bool,
    /// The frame with the previous schedule (`before`), drawn inside this rectangle: it can differ from the
    /// frame there.
    pub(super) changed: Option<PixelRect>,
    /// lodpop compared the frame with `before` (drawn, or under TAA the counterfactual stream's frame).
    pub(super) compared: bool,
}

/// Whether two states of an instance draw the same image of it, by the method's own test
/// (`Counterfactual::same_image_state`) where `by_method`, else only when they are equal. A transition's moving
/// pattern (dither --noise-temporal) changes an instance in transition every frame.
fn same_image(
    method: &dyn Counterfactual,
    by_method: bool,
) -> impl Fn(&InstanceState, &InstanceState) -> bool + '_ {
    let moving = method.transition_pattern_moves();
    move |a: &InstanceState, b: &InstanceState| {
        !(moving && (a.in_transition() || b.in_transition()))
            && match by_method {
                true => method.same_image_state(a, b),
                false => a == b,
            }
    }
}

impl QualityStage {
    /// The units whose image changed on this frame (after `history`'s push), for the pop events
    /// (`records::events`): each instance whose state draws differently from an earlier frame's in the history
    /// by the method's own test (or is in transition, with a history deeper than one frame), weighted by its
    /// screen rectangle's pixels (one off screen changes no pixel and is left out); and, where the method's own
    /// selection changed (`selection_changed`), the whole frame as one unit past the instances.
    pub(super) fn switched_units(
        base: &BlockGpu<'_>,
        method: &dyn Counterfactual,
        (input, history): (&FrameInput<'_>, &StateHistory),
        coverage: &Coverage,
    ) -> FrameChanges {
        let same = same_image(method, true);
        let view_proj = base.scene.camera(input.frame).view_proj();
        let mut out: FrameChanges = history
            .changed_instances(same)
            .into_iter()
            .map(|i| {
                let px = coverage.instance_pixels(base.scene, i, input.matrices[i], view_proj);
                (i as u32, px as f64)
            })
            .filter(|&(_, px)| px > 0.0)
            .collect();
        if method.selection_changed() {
            let whole = base.scene.width as f64 * base.scene.height as f64;
            out.push((input.states.len() as u32, whole));
        }
        out
    }

    pub(super) fn copy_of(
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
    pub(super) fn counterfactuals(
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
        let (changed, rect) = {
            let same = same_image(&*method, self.region == MetricRegion::Covered);
            let changed = history.changed(&same, || method.selection_changed());
            let rect = match (changed, dump) {
                (true, false) => Self::changed_rect(base, input, history, (coverage, &same)),
                _ => full,
            };
            (changed && !rect.is_empty(), rect)
        };
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
    pub(super) fn encode_unlagged(
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
    pub(super) fn culled_matrices(
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
    pub(super) fn changed_rect(
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

    /// `--impostor`: view_pop's counterfactual, in a submission of its own: the method's frame (this frame's
    /// schedule, through its counterfactual with the whole history as this frame's) drawn with the impostors'
    /// frames selected from the previous frame's eye, and its difference from the method's frame. Not drawn
    /// where the eye and every instance held still (the frame is then the same: view_pop 0). The selecting eye
    /// is the previous frame's, in the instance's current placement (docs/measurement.md, "view_pop").
    pub(super) fn view_counterfactual(
        &self,
        base: &BlockGpu<'_>,
        method: &mut dyn crate::methods::Method,
        (input, history): (&FrameInput<'_>, &StateHistory),
    ) -> Option<wgpu::SubmissionIndex> {
        let view = self.kernels.view.as_ref()?;
        let f = input.frame;
        let scene = base.scene;
        let (ctx, gpu) = (base.ctx, &base.gpu);
        let (before, now) = (scene.camera(f.checked_sub(1)?).eye, scene.camera(f).eye);
        let still = matches!(scene.motion, crate::scene::Motion::Static);
        if before == now && still {
            return None;
        }
        gpu.write_impostor_eye(before);
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let states = history.all();
        crate::methods::common::ask_counterfactual(method, |m| {
            m.encode_before(gpu, input, &states, &mut encoder, &view.target)
        });
        view.kernel.encode(&ctx.queue, &mut encoder, f, 0);
        let index = ctx.queue.submit([encoder.finish()]);
        gpu.write_impostor_eye(now);
        Some(index)
    }

    /// With a dump: the counterfactual frames drawn this frame, for read-back.
    pub(super) fn request_counterfactual_reads(
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
}
