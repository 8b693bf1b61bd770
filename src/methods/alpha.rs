//! `alpha`: Giegl-Wimmer "unpopping" LOD blending (seed 000 section 3.1 and Fig. 2; seed 001 Fig. 1b; seed 003
//! section 8). One LOD of a t-instance is always opaque; the other is drawn translucent over it (alpha 2k before
//! the swap at k = 0.5, 2(1 - k) after). Opaque geometry first, then the translucent draws sorted back to front
//! by instance distance, depth test on (less-equal, so a translucent surface coinciding with the opaque one
//! still blends), depth writes off.

use super::{back_to_front, instance_raw, unpop, FrameInput, Method};
use crate::gpu::renderer::{
    DrawList, DrawStats, InstanceBuffer, MeshPipeline, RenderTarget, SceneGpu,
};
use crate::scene::Scene;

/// Standard "over" blending of a translucent surface.
pub const OVER: wgpu::BlendState = wgpu::BlendState::ALPHA_BLENDING;

pub struct Alpha {
    opaque: DrawList,
    translucent: DrawList,
    order: Vec<usize>,
    buffer: InstanceBuffer,
    translucent_pipeline: wgpu::RenderPipeline,
}

impl Alpha {
    pub fn new(gpu: &SceneGpu, scene: &Scene) -> Self {
        Alpha {
            opaque: DrawList::default(),
            translucent: DrawList::default(),
            order: Vec::new(),
            buffer: gpu.create_instance_buffer("alpha instances", 2 * scene.instances.len() as u32),
            translucent_pipeline: gpu.mesh_pipeline(&MeshPipeline {
                label: "alpha translucent",
                morph: false,
                fragment: Some("fs_translucent"),
                depth_compare: wgpu::CompareFunction::LessEqual,
                depth_write: false,
                blend: Some(OVER),
                extra_layouts: &[],
            }),
        }
    }
}

impl Method for Alpha {
    fn name(&self) -> &'static str {
        "alpha"
    }

    fn encode(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
    ) -> DrawStats {
        self.opaque.clear();
        self.translucent.clear();
        for (i, (inst, s)) in input.scene.instances.iter().zip(input.states).enumerate() {
            let u = unpop(s);
            self.opaque.push(
                0,
                inst.model,
                u.opaque,
                instance_raw(input, i, s.k, 1.0, u.opaque),
            );
        }
        back_to_front(input.distances, &mut self.order, |i| {
            input.states[i].in_transition()
        });
        for &i in &self.order {
            let s = &input.states[i];
            if let Some((lod, alpha)) = unpop(s).translucent {
                let model = input.scene.instances[i].model;
                self.translucent
                    .push(0, model, lod, instance_raw(input, i, s.k, alpha, lod));
            }
        }
        self.opaque.build();
        self.translucent.build_in_order();
        let n_opaque = self.opaque.instances.len() as u32;
        gpu.upload_at(&self.buffer, 0, &self.opaque);
        gpu.upload_at(&self.buffer, n_opaque, &self.translucent);
        let mut pass = gpu.begin_clear_pass(encoder, target, "alpha pass");
        let a = gpu.draw(
            &mut pass,
            &self.buffer,
            0,
            &self.opaque,
            &[&gpu.opaque_pipeline],
        );
        let b = gpu.draw(
            &mut pass,
            &self.buffer,
            n_opaque,
            &self.translucent,
            &[&self.translucent_pipeline],
        );
        a + b
    }
}
