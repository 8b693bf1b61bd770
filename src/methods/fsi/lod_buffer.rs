//! FSI's LOD buffers (colour, depth, instance id), what a buffer drew per instance (`Choice`, to draw it again at
//! another pose), and the pipelines and visibility texture the buffers are drawn with.

use super::options::{FsiOptions, Variant, VisSpace};
use crate::gpu::{texture_2d, DrawList, MeshPipeline, RenderTarget, SceneGpu, ATTACHMENT_READ};
use crate::methods::common::{instance_raw_with, FrameInput};
use crate::methods::noise::VisTexture;
use crate::methods::noise::{visibility_texture, VIS_TEXTURE_SIZE};

pub(super) const N_PIPELINE: u8 = 0;

pub(super) const T_PIPELINE: u8 = 1;

/// The id format for `instances` instances: ids up to [`back_id`] of the last one.
pub fn id_format(instances: usize) -> wgpu::TextureFormat {
    if 2 * instances < u16::MAX as usize {
        wgpu::TextureFormat::R16Uint
    } else {
        wgpu::TextureFormat::R32Uint
    }
}

/// Bytes per texel of an id format of [`id_format`].
pub(super) fn id_bytes(format: wgpu::TextureFormat) -> u32 {
    match format {
        wgpu::TextureFormat::R16Uint => 2,
        _ => 4,
    }
}

/// Bytes per pixel of one LOD buffer (colour + depth + id).
pub fn lod_buffer_bytes_per_pixel(instances: usize) -> u64 {
    4 + 4 + id_bytes(id_format(instances)) as u64
}

/// One LOD buffer: colour and depth (a [`RenderTarget`]) and the instance-id target.
pub(super) struct LodBuffer {
    pub(super) target: RenderTarget,
    pub(super) id: wgpu::Texture,
    pub(super) id_view: wgpu::TextureView,
}

/// A LOD buffer read back to the CPU (for tests and inspection): row-major, `width` x `height`.
#[derive(Debug, Clone)]
pub struct LodBufferImage {
    pub width: u32,
    pub height: u32,
    /// RGBA8, sRGB-encoded.
    pub color: Vec<u8>,
    pub depth: Vec<f32>,
    pub id: Vec<u32>,
}

impl LodBuffer {
    pub(super) fn new(
        gpu: &SceneGpu,
        label: &str,
        w: u32,
        h: u32,
        format: wgpu::TextureFormat,
    ) -> Self {
        let target = RenderTarget::new(&gpu.device, label, w, h);
        let id = texture_2d(
            &gpu.device,
            &format!("{label} id"),
            (w, h),
            format,
            ATTACHMENT_READ,
        );
        LodBuffer {
            id_view: id.create_view(&Default::default()),
            id,
            target,
        }
    }
}

/// How one LOD buffer drew one instance: enough to draw it again at another pose (lodpop's counterfactual).
#[derive(Debug, Clone, Copy)]
pub(super) struct Choice {
    pub(super) pipeline: u8,
    pub(super) model: u32,
    pub(super) lod: u32,
    pub(super) params: [f32; 4],
}

/// Fills and builds `list` with instance i drawn as `choices[i]` at `input`'s pose.
pub(super) fn fill_list(list: &mut DrawList, input: &FrameInput<'_>, choices: &[Choice]) {
    list.clear();
    for (i, c) in choices.iter().enumerate() {
        list.push(
            c.pipeline,
            c.model,
            c.lod,
            instance_raw_with(input, i, c.lod, c.params),
        );
    }
    list.build();
}

/// The visibility texture (`vis`, from `seed`) and its layout and bind group, group 1 of the draw pipelines.
pub(super) fn visibility_group(
    gpu: &SceneGpu,
    vis: VisTexture,
    seed: u64,
) -> (wgpu::BindGroupLayout, wgpu::BindGroup) {
    let device = &gpu.device;
    let vis_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("fsi visibility texture layout"),
        entries: &[wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        }],
    });
    let vis = gpu.create_value_texture(
        "fsi visibility texture",
        VIS_TEXTURE_SIZE,
        &visibility_texture(vis, seed),
    );
    let vis_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("fsi visibility texture"),
        layout: &vis_layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: wgpu::BindingResource::TextureView(&vis.create_view(&Default::default())),
        }],
    });
    (vis_layout, vis_group)
}

/// The n-instance and t-instance pipelines into the LOD buffers (ids in `format`); the t-instances' fragment
/// shader follows the variant and the visibility space.
pub(super) fn draw_pipelines(
    gpu: &SceneGpu,
    options: &FsiOptions,
    variant: Variant,
    format: wgpu::TextureFormat,
    vis_layout: &wgpu::BindGroupLayout,
) -> (crate::gpu::MeshPipelines, crate::gpu::MeshPipelines) {
    let pipeline = |label, fragment, cull| {
        gpu.mesh_pipeline(&MeshPipeline {
            label,
            morph: false,
            fragment: Some(fragment),
            id_target: Some(format),
            cull,
            depth_compare: wgpu::CompareFunction::Less,
            depth_write: true,
            blend: None,
            extra_layouts: &[vis_layout],
        })
    };
    let n_pipeline = pipeline("fsi n-instances", "fs_fsi_n", None);
    let t_pipeline = pipeline(
        "fsi t-instances",
        match (variant, options.vis_space) {
            (Variant::Blend, _) => "fs_fsi_t_blend",
            (_, VisSpace::Object) => "fs_fsi_t",
            (_, VisSpace::World) => "fs_fsi_t_world",
        },
        None,
    );
    (n_pipeline, t_pipeline)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn buffer_bytes_against_the_paper() {
        assert_eq!(lod_buffer_bytes_per_pixel(4000), 10);
        assert_eq!(lod_buffer_bytes_per_pixel(70_000), 12);
    }
}
