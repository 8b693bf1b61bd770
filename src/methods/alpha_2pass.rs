//! `alpha-2pass`: the double-pass variant of unpopping blending (seed 003 section 11). Each translucent LOD
//! contributes only its nearest surface, so its own back faces never show through: a depth-only pass writes the
//! object's nearest depth, then a colour pass draws it again with a depth-equal test and blending.
//!
//! The paper clears the whole depth buffer before each translucent model, which would let it draw over nearer
//! objects that should hide it. Here the object's depth passes go to a depth buffer of the method's own
//! (`object_depth`, cleared per t-instance), and the colour pass reads the scene's depth buffer (the opaque
//! pass's) as a texture and drops fragments behind it: occlusion by the rest of the scene stays intact, and,
//! as in `alpha`, the object's own opaque LOD hides the parts of the translucent one that lie behind it. Cost: two
//! render passes per t-instance.

use super::alpha::OVER;
use super::common::{FrameInput, Method, UnpopLists};
use crate::formats::DEPTH_FORMAT;
use crate::gpu::{DrawStats, InstanceBuffer, MeshPipeline, RenderTarget, SceneGpu};
use crate::scene::Scene;

pub struct AlphaTwoPass {
    lists: UnpopLists,
    buffer: InstanceBuffer,
    depth_only: wgpu::RenderPipeline,
    colour: wgpu::RenderPipeline,
    scene_depth_layout: wgpu::BindGroupLayout,
    /// Bind groups of the scene-depth textures seen so far (one per render target: timing, quality).
    scene_depth_groups: Vec<(wgpu::Texture, wgpu::BindGroup)>,
    object_depth: wgpu::Texture,
    object_depth_view: wgpu::TextureView,
}

impl AlphaTwoPass {
    pub fn new(gpu: &SceneGpu, scene: &Scene) -> Self {
        let scene_depth_layout =
            gpu.device
                .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some("alpha-2pass scene depth layout"),
                    entries: &[wgpu::BindGroupLayoutEntry {
                        binding: 2,
                        visibility: wgpu::ShaderStages::FRAGMENT,
                        ty: wgpu::BindingType::Texture {
                            sample_type: wgpu::TextureSampleType::Depth,
                            view_dimension: wgpu::TextureViewDimension::D2,
                            multisampled: false,
                        },
                        count: None,
                    }],
                });
        let object_depth = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("alpha-2pass object depth"),
            size: wgpu::Extent3d {
                width: scene.width,
                height: scene.height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        AlphaTwoPass {
            lists: UnpopLists::default(),
            buffer: gpu
                .create_instance_buffer("alpha-2pass instances", 2 * scene.instances.len() as u32),
            depth_only: gpu.mesh_pipeline(&MeshPipeline {
                label: "alpha-2pass depth only",
                morph: false,
                fragment: None,
                id_target: None,
                cull: None,
                depth_compare: wgpu::CompareFunction::Less,
                depth_write: true,
                blend: None,
                extra_layouts: &[],
            }),
            colour: gpu.mesh_pipeline(&MeshPipeline {
                label: "alpha-2pass colour",
                morph: false,
                fragment: Some("fs_translucent_occluded"),
                id_target: None,
                cull: None,
                depth_compare: wgpu::CompareFunction::Equal,
                depth_write: false,
                blend: Some(OVER),
                extra_layouts: &[&scene_depth_layout],
            }),
            scene_depth_layout,
            scene_depth_groups: Vec::new(),
            object_depth_view: object_depth.create_view(&Default::default()),
            object_depth,
        }
    }

    fn scene_depth_group(&mut self, gpu: &SceneGpu, target: &RenderTarget) -> usize {
        if let Some(i) = self
            .scene_depth_groups
            .iter()
            .position(|(t, _)| *t == target.depth)
        {
            return i;
        }
        let group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("alpha-2pass scene depth"),
            layout: &self.scene_depth_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 2,
                resource: wgpu::BindingResource::TextureView(&target.depth_view),
            }],
        });
        self.scene_depth_groups.push((target.depth.clone(), group));
        self.scene_depth_groups.len() - 1
    }
}

impl Method for AlphaTwoPass {
    fn extra_target_bytes(&self) -> u64 {
        let s = self.object_depth.size();
        s.width as u64 * s.height as u64 * 4
    }

    fn encode(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
    ) -> DrawStats {
        let group = self.scene_depth_group(gpu, target);
        // Translucent neighbours of one bucket share a draw; each of its instances gets its own pair of passes.
        let n_opaque = self.lists.prepare(gpu, input, &self.buffer, |_| 0);
        let mut stats = {
            let mut pass = gpu.begin_clear_pass(encoder, target, "alpha-2pass opaque");
            gpu.draw(
                &mut pass,
                &self.buffer,
                0,
                &self.lists.opaque,
                &[&gpu.opaque_pipeline],
            )
        };
        for d in &self.lists.translucent.draws {
            for j in 0..d.instance_count {
                let at = n_opaque + d.first_instance + j;
                {
                    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                        label: Some("alpha-2pass nearest surface"),
                        color_attachments: &[],
                        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                            view: &self.object_depth_view,
                            depth_ops: Some(wgpu::Operations {
                                load: wgpu::LoadOp::Clear(1.0),
                                store: wgpu::StoreOp::Store,
                            }),
                            stencil_ops: None,
                        }),
                        timestamp_writes: None,
                        occlusion_query_set: None,
                        multiview_mask: None,
                    });
                    stats += gpu.draw_instances(
                        &mut pass,
                        &self.buffer,
                        at,
                        1,
                        d.model,
                        d.lod,
                        &self.depth_only,
                    );
                }
                let mut pass = gpu.begin_pass(
                    encoder,
                    &target.color_view,
                    &self.object_depth_view,
                    "alpha-2pass colour",
                    false,
                );
                pass.set_bind_group(1, &self.scene_depth_groups[group].1, &[]);
                stats += gpu.draw_instances(
                    &mut pass,
                    &self.buffer,
                    at,
                    1,
                    d.model,
                    d.lod,
                    &self.colour,
                );
            }
        }
        stats
    }
}
