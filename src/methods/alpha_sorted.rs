//! `alpha-sorted`: `alpha`'s blend with every translucent fragment composited in exact depth order per pixel,
//! the order-independent reference of claim F9 (Scherzer & Wimmer 2008 section 1, drawback 5: blending needs
//! depth sorting, and billboard clouds need it per polygon). `alpha` sorts its translucent draws by instance
//! distance only, so where one translucent LOD's polygons overlap each other (a billboard cloud's), or two
//! translucent instances interleave in depth, they blend in draw order; `alpha-sorted` draws the same opaque and
//! translucent LODs with the same alphas and peels the translucent fragments nearest first ([`LAYERS`] layers,
//! Everitt's depth peeling), accumulating them front to back (shaders/peel.wgsl). The difference between the two
//! frames is `alpha`'s sorting error alone, apart from the LOD error both share (`scripts/sort_error.py` reads it
//! from the two methods' dumps). A pixel with more than [`LAYERS`] translucent fragments in front of the opaque
//! surface loses the farthest; fragments at exactly the depth of the previous layer are peeled once. Not run by
//! default; its frame time is that of a reference, not of a method anyone would ship.

use super::common::{BlendLists, Counterfactual, FrameInput, Method};
use crate::formats::{COLOR_FORMAT, DEPTH_FORMAT};
use crate::gpu::compute::{
    bind_group, storage_entry, texture_entry, uniform_buffer, uniform_entry,
};
use crate::gpu::{texture_2d, DrawStats, InstanceBuffer, MeshPipeline, RenderTarget, SceneGpu};
use crate::scene::Scene;

/// Translucent layers peeled per frame.
pub const LAYERS: usize = 16;

const PEEL_WGSL: &str = include_str!("../../shaders/peel.wgsl");

/// The composite bind group of one render target (timing and quality targets differ), made on first use: it
/// reads the target's opaque colour.
struct TargetState {
    depth: wgpu::Texture,
    composite: wgpu::BindGroup,
}

pub struct AlphaSorted {
    lists: BlendLists,
    buffer: InstanceBuffer,
    peel_pipeline: crate::gpu::MeshPipelines,
    /// Depth of each peel (two, alternating) and a depth of 0 everywhere (before the first layer).
    peel_depth: [wgpu::Texture; 2],
    peel_depth_views: [wgpu::TextureView; 2],
    /// [0] reads the zero depth (before the first layer), [1 + i] reads peel depth i.
    peel_groups: [wgpu::BindGroup; 3],
    layer_view: wgpu::TextureView,
    accumulate: wgpu::ComputePipeline,
    resolve: wgpu::ComputePipeline,
    compute_layout: wgpu::BindGroupLayout,
    acc: wgpu::Buffer,
    params: wgpu::Buffer,
    output: wgpu::Texture,
    output_view: wgpu::TextureView,
    targets: Vec<TargetState>,
    size: (u32, u32),
}

impl AlphaSorted {
    pub fn new(gpu: &SceneGpu, scene: &Scene) -> Self {
        let device = &gpu.device;
        let size = (scene.width, scene.height);
        let depth_usage = wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_DST;
        let peel_depth = [0, 1].map(|i| {
            texture_2d(
                device,
                &format!("alpha-sorted peel depth {i}"),
                size,
                DEPTH_FORMAT,
                depth_usage,
            )
        });
        let (_zero, zero_view) = zero_depth(gpu, size, depth_usage);
        let (peel_layout, peel_depth_views, peel_groups) =
            peel_groups(device, &zero_view, &peel_depth);
        let peel_pipeline = peel_pipeline(gpu, &peel_layout);
        let layer = texture_2d(
            device,
            "alpha-sorted layer",
            size,
            COLOR_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let layer_view = layer.create_view(&Default::default());
        let compute_layout = composite_layout(device);
        let (module, layout) = composite_program(device, &compute_layout);
        let (acc, params) = composite_buffers(gpu, size);
        let output = texture_2d(
            device,
            "alpha-sorted frame",
            size,
            wgpu::TextureFormat::Rgba8Unorm,
            wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
        );
        let compute = |entry: &str| compute_pipeline(device, &layout, &module, entry);
        AlphaSorted {
            lists: BlendLists::default(),
            buffer: gpu
                .create_instance_buffer("alpha-sorted instances", 2 * scene.instances.len() as u32),
            peel_pipeline,
            peel_depth,
            peel_depth_views,
            peel_groups,
            layer_view,
            accumulate: compute("cs_accumulate"),
            resolve: compute("cs_resolve"),
            compute_layout,
            acc,
            params,
            output_view: output.create_view(&Default::default()),
            output,
            targets: Vec::new(),
            size,
        }
    }

    /// The composite bind group of `target` (made on first use: it reads the target's opaque colour).
    fn target_state(&mut self, gpu: &SceneGpu, target: &RenderTarget) -> usize {
        if let Some(i) = self.targets.iter().position(|t| t.depth == target.depth) {
            return i;
        }
        let composite = bind_group(
            &gpu.device,
            "alpha-sorted composite",
            &self.compute_layout,
            vec![
                wgpu::BindingResource::TextureView(&self.layer_view),
                self.acc.as_entire_binding(),
                self.params.as_entire_binding(),
                wgpu::BindingResource::TextureView(&target.color_bytes_view),
                wgpu::BindingResource::TextureView(&self.output_view),
            ],
        );
        self.targets.push(TargetState {
            depth: target.depth.clone(),
            composite,
        });
        self.targets.len() - 1
    }

    fn dispatch(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        pipeline: &wgpu::ComputePipeline,
        group: &wgpu::BindGroup,
    ) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("alpha-sorted composite"),
            timestamp_writes: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, group, &[]);
        pass.dispatch_workgroups(self.size.0.div_ceil(8), self.size.1.div_ceil(8), 1);
    }
}

/// A depth texture of `size` cleared to 0 once (every fragment is behind it: what the first layer peels
/// against), and its view.
fn zero_depth(
    gpu: &SceneGpu,
    size: (u32, u32),
    usage: wgpu::TextureUsages,
) -> (wgpu::Texture, wgpu::TextureView) {
    let device = &gpu.device;
    let zero = texture_2d(device, "alpha-sorted zero depth", size, DEPTH_FORMAT, usage);
    let zero_view = zero.create_view(&Default::default());
    {
        // Cleared to 0 once: every fragment is behind it.
        let mut encoder = device.create_command_encoder(&Default::default());
        drop(encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("alpha-sorted zero depth"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &zero_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        }));
        gpu.queue.submit([encoder.finish()]);
    }
    (zero, zero_view)
}

/// The peel pass's layout (the previous peel's depth), the peel depths' views, and its three bind groups:
/// the zero depth, then each peel depth.
fn peel_groups(
    device: &wgpu::Device,
    zero_view: &wgpu::TextureView,
    peel_depth: &[wgpu::Texture; 2],
) -> (
    wgpu::BindGroupLayout,
    [wgpu::TextureView; 2],
    [wgpu::BindGroup; 3],
) {
    let peel_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("alpha-sorted peel layout"),
        entries: &[wgpu::BindGroupLayoutEntry {
            binding: 3,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Depth,
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        }],
    });
    let peel_depth_views = [0, 1].map(|i| peel_depth[i].create_view(&Default::default()));
    let group = |view: &wgpu::TextureView| {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("alpha-sorted previous peel"),
            layout: &peel_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 3,
                resource: wgpu::BindingResource::TextureView(view),
            }],
        })
    };
    let peel_groups = [
        group(zero_view),
        group(&peel_depth_views[0]),
        group(&peel_depth_views[1]),
    ];
    (peel_layout, peel_depth_views, peel_groups)
}

/// The pipeline that draws the translucent fragments behind the previous peel's depth.
fn peel_pipeline(gpu: &SceneGpu, peel_layout: &wgpu::BindGroupLayout) -> crate::gpu::MeshPipelines {
    gpu.mesh_pipeline(&MeshPipeline {
        label: "alpha-sorted peel",
        morph: false,
        fragment: Some("fs_translucent_peel"),
        id_target: None,
        cull: None,
        depth_compare: wgpu::CompareFunction::LessEqual,
        depth_write: true,
        blend: None,
        extra_layouts: &[peel_layout],
    })
}

/// The composite passes' layout: the layer, the accumulation, the parameters, the opaque colour, the frame.
fn composite_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("alpha-sorted composite layout"),
        entries: &[
            texture_entry(0),
            storage_entry(1),
            uniform_entry(2),
            texture_entry(3),
            wgpu::BindGroupLayoutEntry {
                binding: 4,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::StorageTexture {
                    access: wgpu::StorageTextureAccess::WriteOnly,
                    format: wgpu::TextureFormat::Rgba8Unorm,
                    view_dimension: wgpu::TextureViewDimension::D2,
                },
                count: None,
            },
        ],
    })
}

/// peel.wgsl's module and the composite pipeline layout.
fn composite_program(
    device: &wgpu::Device,
    compute_layout: &wgpu::BindGroupLayout,
) -> (wgpu::ShaderModule, wgpu::PipelineLayout) {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("peel.wgsl"),
        source: wgpu::ShaderSource::Wgsl(PEEL_WGSL.into()),
    });
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("alpha-sorted composite"),
        bind_group_layouts: &[Some(compute_layout)],
        immediate_size: 0,
    });
    (module, layout)
}

/// The composite compute pipeline of peel.wgsl's `entry`, labelled with it.
fn compute_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    entry: &str,
) -> wgpu::ComputePipeline {
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(entry),
        layout: Some(layout),
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// The accumulation buffer (16 bytes a pixel) and the parameters uniform, written with the frame's `size`.
fn composite_buffers(gpu: &SceneGpu, size: (u32, u32)) -> (wgpu::Buffer, wgpu::Buffer) {
    let device = &gpu.device;
    let acc = crate::gpu::compute::buffer(
        device,
        "alpha-sorted accumulation",
        size.0 as u64 * size.1 as u64 * 16,
        wgpu::BufferUsages::STORAGE,
    );
    let params = uniform_buffer(device, "alpha-sorted params", 16);
    gpu.queue
        .write_buffer(&params, 0, bytemuck::cast_slice(&[size.0, size.1, 0, 0]));
    (acc, params)
}

impl Method for AlphaSorted {
    fn material_limits(&self, materials: &crate::geometry::material::Materials) -> Option<String> {
        materials
            .materials
            .iter()
            .any(|m| m.alpha == crate::geometry::material::AlphaMode::Blend)
            .then(|| "BLEND materials' parts of an instance in transition are blended in draw order over the peeled layers, not peeled with them".to_string())
    }

    fn extra_target_bytes(&self) -> u64 {
        // Three depths, the layer, the accumulation (16 bytes a pixel) and the output.
        let (w, h) = (self.size.0 as u64, self.size.1 as u64);
        w * h * (3 * 4 + 4 + 16 + 4)
    }

    fn encode(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
    ) -> DrawStats {
        let t = self.target_state(gpu, target);
        let n_opaque = self.lists.prepare(gpu, input, &self.buffer, |_| 0);
        let mut stats = {
            let mut pass = gpu.begin_clear_pass(encoder, target, input.view, "alpha-sorted opaque");
            gpu.draw(
                &mut pass,
                &self.buffer,
                0,
                &self.lists.opaque,
                &[&gpu.opaque_pipeline],
            )
        };
        if !self.lists.translucent.draws.is_empty() {
            for layer in 0..LAYERS {
                let cur = layer % 2;
                // The opaque depth, so the less-equal test keeps the nearest fragment not behind it.
                encoder.copy_texture_to_texture(
                    target.depth.as_image_copy(),
                    self.peel_depth[cur].as_image_copy(),
                    self.peel_depth[cur].size(),
                );
                {
                    // The layer cleared to no colour and no alpha; the depth as copied.
                    let mut pass = gpu.counted(
                        input.view,
                        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                            label: Some("alpha-sorted peel"),
                            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                                view: &self.layer_view,
                                depth_slice: None,
                                resolve_target: None,
                                ops: wgpu::Operations {
                                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                                    store: wgpu::StoreOp::Store,
                                },
                            })],
                            depth_stencil_attachment: Some(
                                wgpu::RenderPassDepthStencilAttachment {
                                    view: &self.peel_depth_views[cur],
                                    depth_ops: Some(wgpu::Operations {
                                        load: wgpu::LoadOp::Load,
                                        store: wgpu::StoreOp::Store,
                                    }),
                                    stencil_ops: None,
                                },
                            ),
                            timestamp_writes: None,
                            occlusion_query_set: None,
                            multiview_mask: None,
                        }),
                    );
                    gpu.apply_view(&mut pass, input.view);
                    let previous = if layer == 0 { 0 } else { 1 + (1 - cur) };
                    pass.set_bind_group(1, &self.peel_groups[previous], &[]);
                    stats += gpu.draw(
                        &mut pass,
                        &self.buffer,
                        n_opaque,
                        &self.lists.translucent,
                        &[&self.peel_pipeline],
                    );
                }
                self.dispatch(encoder, &self.accumulate, &self.targets[t].composite);
            }
        }
        self.dispatch(encoder, &self.resolve, &self.targets[t].composite);
        // Same bytes, sRGB-tagged: copies between the two formats are plain copies.
        encoder.copy_texture_to_texture(
            self.output.as_image_copy(),
            target.color.as_image_copy(),
            self.output.size(),
        );
        stats
    }

    fn counterfactual(&mut self) -> Option<&mut dyn Counterfactual> {
        Some(self)
    }
}

impl Counterfactual for AlphaSorted {
    fn image_confined_to_instances(&self) -> bool {
        true
    }
}
