//! The mesh pipeline factory: one pipeline over the shared vertex layout and shaders/mesh.wgsl per depth,
//! blend and entry-point setting a method asks for.

use crate::formats::{COLOR_FORMAT, DEPTH_FORMAT};
use crate::gpu::draw_list::InstanceRaw;
use bytemuck::{Pod, Zeroable};

/// A vertex of the shared vertex buffer.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    /// (u, v, kind, hub_y), see [`crate::geometry::mesh::Mesh::aux`].
    pub aux: [f32; 4],
}

pub const MESH_WGSL: &str = include_str!("../../shaders/mesh.wgsl");

pub fn vertex_layouts() -> [wgpu::VertexBufferLayout<'static>; 2] {
    const VERTEX: [wgpu::VertexAttribute; 3] =
        wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 10 => Float32x4];
    const INSTANCE: [wgpu::VertexAttribute; 6] = wgpu::vertex_attr_array![
        2 => Float32x4, 3 => Float32x4, 4 => Float32x4, 5 => Float32x4, 6 => Float32x4, 7 => Float32x4
    ];
    [
        wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<Vertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &VERTEX,
        },
        wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<InstanceRaw>() as u64,
            step_mode: wgpu::VertexStepMode::Instance,
            attributes: &INSTANCE,
        },
    ]
}

/// How a mesh pipeline (shaders/mesh.wgsl) treats depth and colour.
#[derive(Clone, Copy)]
pub struct MeshPipeline<'a> {
    pub label: &'a str,
    /// Morphing vertex stage (`vs_morph`, with the morph-target buffer in slot 2) instead of `vs_main`.
    pub morph: bool,
    /// Fragment entry point; None = depth only (the pass then has no colour attachment; with alpha-tested
    /// geometry the masked depth-only entry is used).
    pub fragment: Option<&'a str>,
    /// A second colour target of this format (FSI's instance-id target).
    pub id_target: Option<wgpu::TextureFormat>,
    /// Faces culled (None for every shared pipeline: scanned meshes have holes through which their inside is
    /// seen). `SceneGpu::mesh_pipeline` puts the scene's own culling in place of None (back faces in the
    /// unified scenes).
    pub cull: Option<wgpu::Face>,
    pub depth_compare: wgpu::CompareFunction,
    pub depth_write: bool,
    pub blend: Option<wgpu::BlendState>,
    /// Bind group layouts after the camera's (group 0).
    pub extra_layouts: &'a [&'a wgpu::BindGroupLayout],
}

impl MeshPipeline<'_> {
    pub fn opaque(label: &str) -> MeshPipeline<'_> {
        MeshPipeline {
            label,
            morph: false,
            fragment: Some("fs_opaque"),
            id_target: None,
            cull: None,
            depth_compare: wgpu::CompareFunction::Less,
            depth_write: true,
            blend: None,
            extra_layouts: &[],
        }
    }
}

pub(crate) fn mesh_pipeline(
    device: &wgpu::Device,
    shader: &wgpu::ShaderModule,
    camera_layout: &wgpu::BindGroupLayout,
    alpha_test: bool,
    d: &MeshPipeline<'_>,
) -> wgpu::RenderPipeline {
    mesh_pipeline_from(device, shader, camera_layout, alpha_test, d, false)
}

/// The shadow pass's pipeline (src/gpu/shadow.rs): `vs_shadow`, depth only; `fragment` (the dithered
/// caster's) discards without writing colour; None = plain depth (the mask's entry with alpha-tested
/// geometry).
pub(crate) fn shadow_pipeline(
    device: &wgpu::Device,
    shader: &wgpu::ShaderModule,
    camera_layout: &wgpu::BindGroupLayout,
    alpha_test: bool,
    label: &str,
    fragment: Option<&str>,
) -> wgpu::RenderPipeline {
    let d = MeshPipeline {
        fragment,
        ..MeshPipeline::opaque(label)
    };
    mesh_pipeline_from(device, shader, camera_layout, alpha_test, &d, true)
}

fn mesh_pipeline_from(
    device: &wgpu::Device,
    shader: &wgpu::ShaderModule,
    camera_layout: &wgpu::BindGroupLayout,
    alpha_test: bool,
    d: &MeshPipeline<'_>,
    shadow: bool,
) -> wgpu::RenderPipeline {
    let mut layouts: Vec<Option<&wgpu::BindGroupLayout>> = vec![Some(camera_layout)];
    layouts.extend(d.extra_layouts.iter().map(|l| Some(*l)));
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(d.label),
        bind_group_layouts: &layouts,
        immediate_size: 0,
    });
    const MORPH: [wgpu::VertexAttribute; 2] =
        wgpu::vertex_attr_array![8 => Float32x3, 9 => Float32x3];
    let [vertex, instance] = vertex_layouts();
    let morph = wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &MORPH,
    };
    let buffers = if d.morph {
        vec![Some(vertex), Some(instance), Some(morph)]
    } else {
        vec![Some(vertex), Some(instance)]
    };
    let mut targets = vec![Some(wgpu::ColorTargetState {
        format: COLOR_FORMAT,
        blend: d.blend,
        write_mask: wgpu::ColorWrites::ALL,
    })];
    if let Some(format) = d.id_target {
        targets.push(Some(wgpu::ColorTargetState {
            format,
            blend: None,
            write_mask: wgpu::ColorWrites::ALL,
        }));
    }
    let constants: &[(&str, f64)] = if alpha_test {
        &[("ALPHA_TEST", 1.0)]
    } else {
        &[]
    };
    let compilation_options = wgpu::PipelineCompilationOptions {
        constants,
        ..Default::default()
    };
    // Depth-only passes need a fragment stage only to apply the alpha-test mask.
    let (fragment, targets): (Option<&str>, &[Option<wgpu::ColorTargetState>]) =
        match (d.fragment, alpha_test) {
            (Some(f), _) if shadow => (Some(f), &[]),
            (Some(f), _) => (Some(f), &targets),
            (None, true) => (Some("fs_depth_masked"), &[]),
            (None, false) => (None, &[]),
        };
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(d.label),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module: shader,
            entry_point: Some(match (shadow, d.morph) {
                (true, _) => "vs_shadow",
                (false, true) => "vs_morph",
                (false, false) => "vs_main",
            }),
            compilation_options: compilation_options.clone(),
            buffers: &buffers,
        },
        primitive: wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleList,
            cull_mode: d.cull,
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(d.depth_write),
            depth_compare: Some(d.depth_compare),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: wgpu::MultisampleState::default(),
        fragment: fragment.map(|entry| wgpu::FragmentState {
            module: shader,
            entry_point: Some(entry),
            compilation_options,
            targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}
