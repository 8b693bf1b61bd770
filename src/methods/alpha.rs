//! `alpha`: Giegl-Wimmer "unpopping" LOD blending (Scherzer & Wimmer 2008 section 3.1 and Fig. 2; Blow 2003a Fig. 1b; Sheliemietiev et al. 2023
//! section 8). One LOD of a t-instance is always opaque; the other is drawn translucent over it (alpha 2k before
//! the swap at k = 0.5, 2(1 - k) after). Opaque geometry first, then the translucent draws sorted back to front
//! by instance distance, depth test on (less-equal, so a translucent surface coinciding with the opaque one
//! still blends), depth writes off.

use super::common::{BlendLists, Counterfactual, FrameInput, Method};
use crate::gpu::{DrawStats, InstanceBuffer, MeshPipeline, RenderTarget, SceneGpu};
use crate::scene::Scene;

/// Standard "over" blending of a translucent surface.
pub const OVER: wgpu::BlendState = wgpu::BlendState::ALPHA_BLENDING;

pub struct Alpha {
    lists: BlendLists,
    buffer: InstanceBuffer,
    translucent_pipeline: crate::gpu::MeshPipelines,
}

impl Alpha {
    pub fn new(gpu: &SceneGpu, scene: &Scene) -> Self {
        Alpha {
            lists: BlendLists::default(),
            buffer: gpu.create_instance_buffer("alpha instances", 2 * scene.instances.len() as u32),
            translucent_pipeline: gpu.mesh_pipeline(&MeshPipeline {
                label: "alpha translucent",
                morph: false,
                fragment: Some("fs_translucent"),
                id_target: None,
                cull: None,
                depth_compare: wgpu::CompareFunction::LessEqual,
                depth_write: false,
                blend: Some(OVER),
                extra_layouts: &[],
            }),
        }
    }
}

impl Method for Alpha {
    fn encode(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
    ) -> DrawStats {
        let n_opaque = self.lists.prepare(gpu, input, &self.buffer, |_| 0);
        let mut pass = gpu.begin_clear_pass(encoder, target, input.view, "alpha pass");
        let a = gpu.draw(
            &mut pass,
            &self.buffer,
            0,
            &self.lists.opaque,
            &[&gpu.opaque_pipeline],
        );
        let b = gpu.draw(
            &mut pass,
            &self.buffer,
            n_opaque,
            &self.lists.translucent,
            &[&self.translucent_pipeline],
        );
        a + b
    }

    fn counterfactual(&mut self) -> Option<&mut dyn Counterfactual> {
        Some(self)
    }
}

impl Counterfactual for Alpha {
    fn image_confined_to_instances(&self) -> bool {
        true
    }
}
