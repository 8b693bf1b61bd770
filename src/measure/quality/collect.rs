//! The collection of a quality-pass frame: FLIP and the dump callback on its read-back images.

use crate::error::{Error, Result};
use crate::gpu::TextureReadback;
use crate::measure::block_gpu::BlockGpu;
use crate::measure::quality::outcome::FrameImages;
use crate::measure::quality::setup::{QualityStage, QUALITY_IN_FLIGHT};
use crate::measure::quality::walk::Walk;
use crate::methods::common::DumpKind;

/// The read-backs one frame asked for.
pub(super) struct FrameReads {
    /// The method's and the reference's frames were copied for read-back.
    pub(super) frames: bool,
    /// The frame goes to the dump callback.
    pub(super) dump: bool,
    /// The method's intermediate images and the counterfactual frames (dumped frames only).
    pub(super) extras: Vec<(DumpKind, TextureReadback)>,
}

impl QualityStage {
    /// Stage 7: FLIP and the dump callback on the frame's read-back images, or, when nothing is read back, a
    /// bound on the frames queued on the GPU.
    pub(super) fn collect_frame(
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
}
