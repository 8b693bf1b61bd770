//! FSI's combination pass (shaders/fsi_combine.wgsl; Scherzer & Wimmer 2008 sections 3.4-3.5, eq. 2): its
//! layout, program, targets, pipeline and inputs.

use super::lod_buffer::LodBuffer;
use super::options::Variant;
use crate::gpu::texture_2d;

pub const COMBINE_WGSL: &str = include_str!("../../../shaders/fsi_combine.wgsl");

/// The combination pass's inputs: `buffers[newer]` as the newer LOD buffer, the other as the older.
pub(super) fn combine_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    buffers: &[LodBuffer; 2],
    newer: usize,
    uniform: &wgpu::Buffer,
    combined_view: &wgpu::TextureView,
) -> wgpu::BindGroup {
    let (n, o) = (&buffers[newer], &buffers[1 - newer]);
    let views = [
        &n.target.color_bytes_view,
        &n.target.depth_view,
        &n.id_view,
        &o.target.color_bytes_view,
        &o.target.depth_view,
        &o.id_view,
    ];
    let mut entries: Vec<wgpu::BindGroupEntry> = views
        .into_iter()
        .enumerate()
        .map(|(binding, view)| wgpu::BindGroupEntry {
            binding: binding as u32,
            resource: wgpu::BindingResource::TextureView(view),
        })
        .collect();
    entries.push(wgpu::BindGroupEntry {
        binding: 6,
        resource: uniform.as_entire_binding(),
    });
    entries.push(wgpu::BindGroupEntry {
        binding: 7,
        resource: wgpu::BindingResource::TextureView(combined_view),
    });
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("fsi combine inputs"),
        layout,
        entries: &entries,
    })
}

#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct CombineRaw {
    pub(super) reproject: [[f32; 4]; 4],
    pub(super) forward: [[f32; 4]; 4],
    /// Viewport size in pixels (x, y); z, w unused.
    pub(super) size: [f32; 4],
}

/// The combine pass's layout: both LOD buffers' colour, depth and ids, the uniform, the combined frame.
pub(super) fn combine_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let tex = |binding, sample_type| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    };
    let colour = wgpu::TextureSampleType::Float { filterable: false };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("fsi combine layout"),
        entries: &[
            tex(0, colour),
            tex(1, wgpu::TextureSampleType::Depth),
            tex(2, wgpu::TextureSampleType::Uint),
            tex(3, colour),
            tex(4, wgpu::TextureSampleType::Depth),
            tex(5, wgpu::TextureSampleType::Uint),
            wgpu::BindGroupLayoutEntry {
                binding: 7,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::StorageTexture {
                    access: wgpu::StorageTextureAccess::WriteOnly,
                    format: wgpu::TextureFormat::Rgba8Unorm,
                    view_dimension: wgpu::TextureViewDimension::D2,
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 6,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            },
        ],
    })
}

/// The combine shader module and its pipeline layout (the combine pipelines are built over both).
pub(super) fn combine_program(
    device: &wgpu::Device,
    combine_layout: &wgpu::BindGroupLayout,
) -> (wgpu::ShaderModule, wgpu::PipelineLayout) {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("fsi_combine.wgsl"),
        source: wgpu::ShaderSource::Wgsl(COMBINE_WGSL.into()),
    });
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("fsi combine"),
        bind_group_layouts: &[Some(combine_layout)],
        immediate_size: 0,
    });
    (module, layout)
}

/// The combined frame (`w` x `h`, written by the combine pass), its view, and the combine uniform.
pub(super) fn combine_targets(
    device: &wgpu::Device,
    w: u32,
    h: u32,
) -> (wgpu::Texture, wgpu::TextureView, wgpu::Buffer) {
    let combined = texture_2d(
        device,
        "fsi combined frame",
        (w, h),
        wgpu::TextureFormat::Rgba8Unorm,
        wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
    );
    let combined_view = combined.create_view(&Default::default());
    let combine_uniform = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("fsi combine uniform"),
        size: std::mem::size_of::<CombineRaw>() as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    (combined, combined_view, combine_uniform)
}

/// The combination the pass makes (fsi_combine.wgsl's COMBINATION): 0 the paper's, 1 with the forward check,
/// 2 frame-sequential blending.
pub(super) fn combination(variant: Variant, forward_check: bool) -> u32 {
    match (variant, forward_check) {
        (Variant::Blend, _) => 2,
        (_, true) => 1,
        _ => 0,
    }
}

/// The combination pass's pipeline for one variant: `same_pixel` reads the older buffer at the pixel (no
/// reprojection), `combination` as [`combination`]. Constants, not uniforms: each pipeline holds only its own
/// variant's code (fsi_combine.wgsl says why).
pub(super) fn combine_pipeline(
    device: &wgpu::Device,
    (module, layout): (&wgpu::ShaderModule, &wgpu::PipelineLayout),
    same_pixel: bool,
    combination: u32,
) -> wgpu::ComputePipeline {
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("fsi combine"),
        layout: Some(layout),
        module,
        entry_point: Some("cs_combine"),
        compilation_options: wgpu::PipelineCompilationOptions {
            constants: &[
                ("SAME_PIXEL", if same_pixel { 1.0 } else { 0.0 }),
                ("COMBINATION", combination as f64),
            ],
            ..Default::default()
        },
        cache: None,
    })
}
