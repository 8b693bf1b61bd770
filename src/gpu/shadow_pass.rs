//! The shadow pass of `--shadows on` (src/shadow.rs): the casters' depth from the light into one of the
//! scene's shadow maps (`SceneGpu::shadows`), drawn with the placeholder's camera bind group so the map
//! being written is never the one bound.

use crate::gpu::draw_list::{DrawList, DrawStats, PipelineIndex};
use crate::gpu::instances::InstanceBuffer;
use crate::gpu::pipelines::{shadow_pipelines, MeshPipelines};
use crate::gpu::scene_gpu::{SceneGpu, ShadowMap};

/// Pipeline indices of a shadow draw list: a caster drawn whole, and one LOD of a dithered caster.
pub const CAST_WHOLE: PipelineIndex = 0;
pub const CAST_DITHERED: PipelineIndex = 1;

pub struct ShadowPass {
    whole: MeshPipelines,
    dithered: MeshPipelines,
    /// One instance buffer per shadow map, so maps drawn in one submission keep their own instances.
    buffers: Vec<InstanceBuffer>,
}

impl ShadowPass {
    pub fn new(gpu: &SceneGpu, instances: u32) -> ShadowPass {
        let p = |label, fragment| shadow_pipelines(&gpu.pipeline_context(), label, fragment);
        ShadowPass {
            whole: p("shadow caster", None),
            dithered: p("shadow caster, dithered", Some("fs_shadow_dither")),
            buffers: (0..gpu.shadows.views.len())
                .map(|i| {
                    gpu.create_instance_buffer(
                        &format!("shadow map {i} casters"),
                        2 * instances.max(1),
                    )
                })
                .collect(),
        }
    }

    /// Uploads `list` (built, pipelines [`CAST_WHOLE`] / [`CAST_DITHERED`]) and records the depth of its
    /// casters into shadow map `map`.
    pub fn encode(
        &self,
        gpu: &SceneGpu,
        encoder: &mut wgpu::CommandEncoder,
        map: ShadowMap,
        list: &DrawList,
    ) -> DrawStats {
        let buffer = &self.buffers[map.index()];
        gpu.upload(buffer, list);
        // Lit by the placeholder, so that the map being written is never the one bound.
        let view = &gpu.shadows.views[map.index()];
        let mut pass = gpu.begin_depth_pass(
            encoder,
            view,
            crate::gpu::scene_gpu::View::lit_by(ShadowMap::NONE),
            "shadow pass",
        );
        gpu.draw(&mut pass, buffer, 0, list, &[&self.whole, &self.dithered])
    }
}
