//! The camera uniform (view-projection, eye, light, the shadow map's matrix, `--shader-work`), its bind groups
//! (one per shadow map) and the shadow maps themselves.

use crate::gpu::impostor_atlas::ImpostorAtlas;
use crate::gpu::scene_gpu::view::ShadowMap;
use crate::gpu::targets::{texture_2d, ATTACHMENT_READ};
pub use crate::scene::model::{AMBIENT, LIGHT_DIR};
use crate::scene::Scene;
use bytemuck::{Pod, Zeroable};

/// The camera uniform, its layout and its bind group (group 0) with each shadow map ([`ShadowMap`]); a pass
/// binds its view's.
pub struct CameraGpu {
    pub buffer: wgpu::Buffer,
    pub layout: wgpu::BindGroupLayout,
    pub groups: Vec<wgpu::BindGroup>,
}

/// The shadow maps, indexed by [`ShadowMap::index`] like the camera's bind groups: their textures, depth views
/// and side in texels.
pub struct ShadowMapsGpu {
    pub views: Vec<wgpu::TextureView>,
    pub maps: Vec<wgpu::Texture>,
    pub size: u32,
}

#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub(super) struct CameraRaw {
    pub(super) view_proj: [[f32; 4]; 4],
    pub(super) eye: [f32; 4],
    pub(super) light: [f32; 4],
    /// `--shadows on`: world to the shadow map's clip space, and (on, side in texels, depth bias, 0).
    pub(super) light_view_proj: [[f32; 4]; 4],
    pub(super) shadow: [f32; 4],
    /// `--shader-work`: (iterations, weight of their result, 0, 0); written once, by [`SceneGpu::write_work`].
    pub(super) work: [f32; 4],
    /// `--impostor`: the eye the impostors select their frames by ([`SceneGpu::write_impostor_eye`]).
    pub(super) impostor_eye: [f32; 4],
}

/// Byte offset of `light_view_proj` in the camera uniform (what [`SceneGpu::write_camera`] leaves alone).
pub(super) const LIGHT_OFFSET: u64 = 64 + 16 + 16;

/// Byte offset of `work` in the camera uniform.
pub(super) const WORK_OFFSET: u64 = LIGHT_OFFSET + 64 + 16;

/// Byte offset of `impostor_eye` in the camera uniform.
pub(super) const IMPOSTOR_EYE_OFFSET: u64 = WORK_OFFSET + 16;

/// The camera uniform buffer ([`CameraRaw`]).
pub(super) fn camera_buffer(device: &wgpu::Device) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("camera uniform"),
        size: std::mem::size_of::<CameraRaw>() as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// Group 0's layout: the camera uniform, a shadow map and its comparison sampler, the impostors' atlases, their
/// sampler and table (`gpu/impostor_atlas.rs`).
pub(super) fn camera_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("camera layout"),
        entries: &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 1,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Depth,
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 2,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
                count: None,
            },
            atlas_entry(3),
            atlas_entry(4),
            wgpu::BindGroupLayoutEntry {
                binding: 5,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 6,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
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

fn atlas_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: true },
            view_dimension: wgpu::TextureViewDimension::D2Array,
            multisampled: false,
        },
        count: None,
    }
}

/// The shadow maps: the 1x1 placeholder, then `lit` maps of `shadow_size` texels a side under `--shadows on`.
pub(super) fn shadow_maps(
    device: &wgpu::Device,
    scene: &Scene,
    lit: usize,
    shadow_size: u32,
) -> Vec<wgpu::Texture> {
    let maps = if scene.shadows.is_some() { 1 + lit } else { 1 };
    (0..maps)
        .map(|i| {
            let side = if i == ShadowMap::NONE.index() {
                1
            } else {
                shadow_size
            };
            texture_2d(
                device,
                &format!("shadow map {i}"),
                (side, side),
                crate::formats::DEPTH_FORMAT,
                ATTACHMENT_READ,
            )
        })
        .collect()
}

/// The comparison sampler the shadow maps are read with.
pub(super) fn shadow_sampler(device: &wgpu::Device) -> wgpu::Sampler {
    device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("shadow sampler"),
        address_mode_u: wgpu::AddressMode::ClampToEdge,
        address_mode_v: wgpu::AddressMode::ClampToEdge,
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        compare: Some(wgpu::CompareFunction::LessEqual),
        ..Default::default()
    })
}

/// The camera's bind group with each shadow map's view.
pub(super) fn camera_groups(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    camera_buffer: &wgpu::Buffer,
    (shadow_views, shadow_sampler): (&[wgpu::TextureView], &wgpu::Sampler),
    atlas: &ImpostorAtlas,
) -> Vec<wgpu::BindGroup> {
    shadow_views
        .iter()
        .map(|view| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("camera bind group"),
                layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: camera_buffer.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::TextureView(view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: wgpu::BindingResource::Sampler(shadow_sampler),
                    },
                    wgpu::BindGroupEntry {
                        binding: 3,
                        resource: wgpu::BindingResource::TextureView(&atlas.srgb_view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 4,
                        resource: wgpu::BindingResource::TextureView(&atlas.linear_view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 5,
                        resource: wgpu::BindingResource::Sampler(&atlas.sampler),
                    },
                    wgpu::BindGroupEntry {
                        binding: 6,
                        resource: atlas.table.as_entire_binding(),
                    },
                ],
            })
        })
        .collect()
}
