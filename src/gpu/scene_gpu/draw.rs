//! Instanced draws of a draw list, part by part where a mesh has materials (one pipeline variant and bind group
//! per material class and material).

use crate::gpu::draw_list::{DrawList, DrawStats, PipelineIndex};
use crate::gpu::instances::InstanceBuffer;
use crate::gpu::pipelines::{MaterialClass, MeshPipelines, Surface, MATERIAL_GROUP};
use crate::gpu::scene_gpu::build::SceneGpu;

impl SceneGpu {
    /// Draws `count` instances from absolute instance `first` of `buffer` at (model, LOD) with `pipeline`;
    /// for methods that need a pass per instance.
    #[allow(
        clippy::too_many_arguments,
        reason = "one draw's parameters, as wgpu's own draw_indexed takes them"
    )]
    pub fn draw_instances(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        buffer: &InstanceBuffer,
        first: u32,
        count: u32,
        model: u32,
        lod: u32,
        pipeline: &MeshPipelines,
    ) -> DrawStats {
        let draw = crate::gpu::draw_list::Draw {
            pipeline: 0,
            model,
            lod,
            first_instance: 0,
            instance_count: count,
        };
        let list = crate::gpu::draw_list::DrawList::of_draws(vec![draw]);
        self.draw(pass, buffer, first, &list, &[pipeline])
    }

    /// Records the draws of `list` (uploaded to `buffer` at instance `first`, see [`SceneGpu::upload_at`])
    /// into `pass`, with `pipelines[d.pipeline]` for each draw. The camera's bind group (group 0) is the pass's
    /// ([`SceneGpu::begin_pass`]); the others are the caller's to set.
    pub fn draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        buffer: &InstanceBuffer,
        first: u32,
        list: &DrawList,
        pipelines: &[&MeshPipelines],
    ) -> DrawStats {
        let mut stats = DrawStats::default();
        if list.draws.is_empty() {
            return stats;
        }
        pass.set_vertex_buffer(0, self.vertex_buffer.slice(..));
        pass.set_vertex_buffer(1, buffer.buffer.slice(..));
        pass.set_index_buffer(self.index_buffer.slice(..), wgpu::IndexFormat::Uint32);
        let flat = pipelines
            .first()
            .is_some_and(|p| p.surface == Surface::Flat);
        let Some(materials) = self.materials.as_ref().filter(|_| !flat) else {
            let mut bound: Option<PipelineIndex> = None;
            for d in &list.draws {
                if bound != Some(d.pipeline) {
                    pass.set_pipeline(pipelines[d.pipeline as usize].base());
                    bound = Some(d.pipeline);
                }
                let r = self.lods[d.model as usize][d.lod as usize];
                pass.draw_indexed(
                    r.first_index..r.first_index + r.index_count,
                    r.base_vertex,
                    first + d.first_instance..first + d.first_instance + d.instance_count,
                );
                stats.triangles += r.triangles() * d.instance_count as u64;
                stats.draw_calls += 1;
            }
            return stats;
        };
        // Part by part, the opaque and cut-out parts of every draw first, then the blended ones (in the list's
        // order, over what the opaque ones left), as an engine draws its transparent queue after its opaque one.
        pass.set_vertex_buffer(3, materials.vertices.slice(..));
        let mut bound: Option<(PipelineIndex, MaterialClass)> = None;
        let mut bound_material: Option<u32> = None;
        for blended in [false, true] {
            for d in &list.draws {
                let r = self.lods[d.model as usize][d.lod as usize];
                let (p0, n) = r.parts;
                for part in &self.parts[p0 as usize..(p0 + n) as usize] {
                    if part.class.blends() != blended {
                        continue;
                    }
                    let Some(pipeline) = pipelines[d.pipeline as usize].get(part.class) else {
                        continue;
                    };
                    if bound != Some((d.pipeline, part.class)) {
                        pass.set_pipeline(pipeline);
                        bound = Some((d.pipeline, part.class));
                    }
                    if bound_material != Some(part.material) {
                        pass.set_bind_group(
                            MATERIAL_GROUP,
                            &materials.groups[part.material as usize],
                            &[],
                        );
                        bound_material = Some(part.material);
                    }
                    pass.draw_indexed(
                        part.first_index..part.first_index + part.index_count,
                        r.base_vertex,
                        first + d.first_instance..first + d.first_instance + d.instance_count,
                    );
                    stats.triangles += part.index_count as u64 / 3 * d.instance_count as u64;
                    stats.draw_calls += 1;
                }
            }
        }
        stats
    }
}
