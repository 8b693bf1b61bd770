//! `alpha-zwrite`: Blow's variant of unpopping blending (Blow 2003a, "Unified Rendering LOD, Part 2"). The
//! translucent LOD is drawn after the opaque one with depth writes on, so its own far surfaces are hidden
//! consistently from frame to frame. When the roles swap at k = 0.5 the draw order swaps with them, and the depth
//! compare of the translucent draw switches from less-equal (before) to less (after): pixels where the two LODs
//! meet at equal depth are filled by the same LOD on both sides of the swap, so the swap does not pop. Opaque
//! draws first, translucent ones back to front.

use super::alpha::OVER;
use super::common::{unpop, BlendLists, Counterfactual, FrameInput, Method, SeamDraws};
use crate::gpu::{DrawStats, InstanceBuffer, MeshPipeline, RenderTarget, SceneGpu};
use crate::scene::Scene;

/// Pipeline indices of the translucent draws.
const BEFORE_SWAP: u8 = 0;
const AFTER_SWAP: u8 = 1;

pub struct AlphaZWrite {
    lists: BlendLists,
    buffer: InstanceBuffer,
    less_equal: crate::gpu::MeshPipelines,
    less: crate::gpu::MeshPipelines,
    /// `blocks`: a unified scene's seams, between the blocks' opaque LODs, drawn with the opaque blocks.
    seams: Option<SeamDraws>,
}

impl AlphaZWrite {
    pub fn new(gpu: &SceneGpu, scene: &Scene) -> Self {
        let translucent = |label, depth_compare| {
            gpu.mesh_pipeline(&MeshPipeline {
                label,
                morph: false,
                fragment: Some("fs_translucent"),
                id_target: None,
                cull: None,
                depth_compare,
                depth_write: true,
                blend: Some(OVER),
                extra_layouts: &[],
            })
        };
        AlphaZWrite {
            lists: BlendLists::default(),
            buffer: gpu
                .create_instance_buffer("alpha-zwrite instances", 2 * scene.instances.len() as u32),
            less_equal: translucent(
                "alpha-zwrite translucent <=",
                wgpu::CompareFunction::LessEqual,
            ),
            less: translucent("alpha-zwrite translucent <", wgpu::CompareFunction::Less),
            seams: None,
        }
    }

    /// `blocks` (Blow 2003a and 2003b): these rules per block of a unified scene, opaque blocks and the seams
    /// between their opaque LODs first, then the translucent blocks back to front.
    pub fn with_seams(gpu: &SceneGpu, scene: &Scene) -> Self {
        AlphaZWrite {
            seams: SeamDraws::new(gpu, scene),
            ..Self::new(gpu, scene)
        }
    }
}

impl Method for AlphaZWrite {
    fn encode(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
    ) -> DrawStats {
        let n_opaque = self.lists.prepare(gpu, input, &self.buffer, |u| {
            if u.swapped {
                AFTER_SWAP
            } else {
                BEFORE_SWAP
            }
        });
        if let Some(seams) = &mut self.seams {
            seams.prepare(gpu, input, |s| unpop(s).opaque);
        }
        let mut pass = gpu.begin_clear_pass(encoder, target, input.view, "alpha-zwrite pass");
        let mut a = gpu.draw(
            &mut pass,
            &self.buffer,
            0,
            &self.lists.opaque,
            &[&gpu.opaque_pipeline],
        );
        if let Some(seams) = &self.seams {
            a += seams.draw(gpu, &mut pass);
        }
        let b = gpu.draw(
            &mut pass,
            &self.buffer,
            n_opaque,
            &self.lists.translucent,
            &[&self.less_equal, &self.less],
        );
        a + b
    }

    fn counterfactual(&mut self) -> Option<&mut dyn Counterfactual> {
        Some(self)
    }
}

impl Counterfactual for AlphaZWrite {
    fn image_confined_to_instances(&self) -> bool {
        true
    }
}
