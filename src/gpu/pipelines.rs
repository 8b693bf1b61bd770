//! The mesh pipeline factory: pipelines over the shared vertex layout and the scene's mesh shader
//! (shaders/mesh.wgsl after one of shaders/surface/*.wgsl) per depth, blend and entry-point setting a method
//! asks for, one variant per material class the scene draws (culling, blending).

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

/// A vertex's material attributes (the PBR surface's second vertex buffer, slot 3).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct SurfaceVertex {
    /// TEXCOORD_0 in xy, TEXCOORD_1 in zw.
    pub tex: [f32; 4],
    pub tangent: [f32; 4],
    /// COLOR_0, linear RGBA.
    pub color: [f32; 4],
}

/// geomorph's target of a vertex's material attributes on the coarser LOD (slot 4 with the PBR surface): its
/// texture coordinates, and its tangent and colour packed into one attribute (`packed`: the tangent's xyz as
/// 16-bit snorm in x and y's low half, the linear RGBA colour as 16-bit unorm in z and w), since a pipeline
/// with the PBR surface and morph targets already uses 15 of the 16 vertex attributes wgpu allows.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct SurfaceTarget {
    pub tex: [f32; 4],
    pub packed: [u32; 4],
}

impl SurfaceTarget {
    /// The target of texture coordinates `tex`, unit tangent `tangent` and linear colour `color` (clamped to
    /// [0, 1]); `shaders/surface/pbr.wgsl` unpacks it with unpack2x16snorm and unpack2x16unorm.
    pub fn new(tex: [f32; 4], tangent: [f32; 3], color: [f32; 4]) -> Self {
        let snorm = |v: f32| (v.clamp(-1.0, 1.0) * 32767.0).round() as i16 as u16 as u32;
        let unorm = |v: f32| (v.clamp(0.0, 1.0) * 65535.0).round() as u32;
        SurfaceTarget {
            tex,
            packed: [
                snorm(tangent[0]) | snorm(tangent[1]) << 16,
                snorm(tangent[2]),
                unorm(color[0]) | unorm(color[1]) << 16,
                unorm(color[2]) | unorm(color[3]) << 16,
            ],
        }
    }
}

/// The part of the mesh shader that is the scene's surface (shaders/surface/).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Surface {
    /// `surface/flat.wgsl`: Lambert and ambient in the instance's colour (the built-in scenes).
    Flat,
    /// `surface/pbr.wgsl`: glTF materials, with the surface vertex buffer and a material bind group (group 2).
    Pbr,
}

pub const MESH_WGSL: &str = include_str!("../../shaders/mesh.wgsl");
pub const SURFACE_FLAT_WGSL: &str = include_str!("../../shaders/surface/flat.wgsl");
pub const SURFACE_PBR_WGSL: &str = include_str!("../../shaders/surface/pbr.wgsl");

/// The mesh shader of `surface`: the surface's file, then shaders/mesh.wgsl (the entry points).
pub fn mesh_wgsl(surface: Surface) -> String {
    let s = match surface {
        Surface::Flat => SURFACE_FLAT_WGSL,
        Surface::Pbr => SURFACE_PBR_WGSL,
    };
    format!("{s}\n{MESH_WGSL}")
}

/// The bind group index of a material (the PBR surface); a method's own groups are 1.
pub const MATERIAL_GROUP: u32 = 2;

/// How a part's pipeline differs from its method's: its faces culled (a single-sided material), blended (a
/// BLEND material). The flat surface has class 0 alone.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MaterialClass(pub u8);

impl MaterialClass {
    pub const PLAIN: MaterialClass = MaterialClass(0);
    const CULL: u8 = 1;
    const BLEND: u8 = 2;

    pub fn new(single_sided: bool, blend: bool) -> MaterialClass {
        MaterialClass(
            if single_sided { Self::CULL } else { 0 } | if blend { Self::BLEND } else { 0 },
        )
    }

    pub fn culls(self) -> bool {
        self.0 & Self::CULL != 0
    }

    pub fn blends(self) -> bool {
        self.0 & Self::BLEND != 0
    }

    fn index(self) -> usize {
        self.0 as usize
    }
}

/// Blending of a BLEND material's fragment over what is behind it, the target's alpha kept.
const BLEND_OVER: wgpu::BlendState = wgpu::BlendState {
    color: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::SrcAlpha,
        dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
        operation: wgpu::BlendOperation::Add,
    },
    alpha: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::Zero,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    },
};

/// One method pipeline in each material class the scene draws; a class the pipeline does not draw (BLEND parts
/// in a depth-only pass) has none, and its parts are skipped.
pub struct MeshPipelines {
    variants: [Option<wgpu::RenderPipeline>; 4],
    /// The first class's variant (every set has one).
    first: wgpu::RenderPipeline,
    /// The surface the pipelines shade with (the flat one in a scene of materials: `reference-flat`).
    pub surface: Surface,
}

impl MeshPipelines {
    /// The pipeline of `class`, when the method draws it.
    pub fn get(&self, class: MaterialClass) -> Option<&wgpu::RenderPipeline> {
        self.variants.get(class.index()).and_then(Option::as_ref)
    }

    /// The pipeline of the first class the scene has: the plain class of the flat surface, which the unified
    /// scenes' methods draw with.
    pub fn base(&self) -> &wgpu::RenderPipeline {
        &self.first
    }
}

/// What the scene gives every mesh pipeline: its shader, camera layout, surface and material classes.
pub struct PipelineContext<'a> {
    pub device: &'a wgpu::Device,
    pub shader: &'a wgpu::ShaderModule,
    pub camera_layout: &'a wgpu::BindGroupLayout,
    pub alpha_test: bool,
    /// The scene's chains end in impostors: every mesh pipeline is built with `IMPOSTORS` on.
    pub impostors: bool,
    pub surface: Surface,
    /// The material bind group layout (the PBR surface).
    pub material_layout: Option<&'a wgpu::BindGroupLayout>,
    /// The classes the scene's parts have (the plain class alone for the flat surface).
    pub classes: &'a [MaterialClass],
    /// Faces culled where neither the descriptor nor the class says (back faces in the unified scenes).
    pub cull: Option<wgpu::Face>,
}

fn vertex_layouts() -> [wgpu::VertexBufferLayout<'static>; 2] {
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
    /// seen). The scene's own culling takes the place of None (back faces in the unified scenes), and a
    /// single-sided material's class culls back faces.
    pub cull: Option<wgpu::Face>,
    pub depth_compare: wgpu::CompareFunction,
    pub depth_write: bool,
    pub blend: Option<wgpu::BlendState>,
    /// Bind group layouts after the camera's (group 0): the method's own (group 1).
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

/// `d` in every class of `ctx`.
pub(crate) fn mesh_pipelines(ctx: &PipelineContext<'_>, d: &MeshPipeline<'_>) -> MeshPipelines {
    build(ctx, d, false)
}

/// The shadow pass's pipelines (src/gpu/shadow_pass.rs): `vs_shadow`, depth only; `fragment` (the dithered
/// caster's) discards without writing colour; None = plain depth (the mask's entry with alpha-tested
/// geometry). Both faces cast; BLEND parts cast nothing.
pub(crate) fn shadow_pipelines(
    ctx: &PipelineContext<'_>,
    label: &str,
    fragment: Option<&str>,
) -> MeshPipelines {
    let d = MeshPipeline {
        fragment,
        ..MeshPipeline::opaque(label)
    };
    build(ctx, &d, true)
}

fn build(ctx: &PipelineContext<'_>, d: &MeshPipeline<'_>, shadow: bool) -> MeshPipelines {
    let mut variants: [Option<wgpu::RenderPipeline>; 4] = Default::default();
    for &class in ctx.classes {
        if class.blends() && (shadow || d.fragment.is_none()) {
            continue;
        }
        let targets = mesh_color_targets(d, class);
        variants[class.index()] = Some(mesh_pipeline_from(ctx, d, shadow, class, &targets));
    }
    let first = match variants.iter().flatten().next() {
        Some(p) => p.clone(),
        None => {
            let targets = mesh_color_targets(d, MaterialClass::PLAIN);
            mesh_pipeline_from(ctx, d, shadow, MaterialClass::PLAIN, &targets)
        }
    };
    MeshPipelines {
        variants,
        first,
        surface: ctx.surface,
    }
}

/// The pipeline layout of `d`: the camera's group, the method's own, and the materials' at
/// [`MATERIAL_GROUP`] where the scene has them (empty groups between).
fn mesh_pipeline_layout(ctx: &PipelineContext<'_>, d: &MeshPipeline<'_>) -> wgpu::PipelineLayout {
    let mut layouts: Vec<Option<&wgpu::BindGroupLayout>> = vec![Some(ctx.camera_layout)];
    layouts.extend(d.extra_layouts.iter().map(|l| Some(*l)));
    if let Some(m) = ctx.material_layout {
        layouts.resize(MATERIAL_GROUP as usize, None);
        layouts.push(Some(m));
    }
    ctx.device
        .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(d.label),
            bind_group_layouts: &layouts,
            immediate_size: 0,
        })
}

/// The vertex buffer slots of `d`: vertices, instances, the morph targets (`d.morph`), and with the PBR
/// surface the surface vertices and their morph targets; trailing empty slots dropped.
fn mesh_vertex_buffers(
    ctx: &PipelineContext<'_>,
    d: &MeshPipeline<'_>,
) -> Vec<Option<wgpu::VertexBufferLayout<'static>>> {
    const MORPH: [wgpu::VertexAttribute; 2] =
        wgpu::vertex_attr_array![8 => Float32x3, 9 => Float32x3];
    const SURFACE: [wgpu::VertexAttribute; 3] =
        wgpu::vertex_attr_array![11 => Float32x4, 12 => Float32x4, 13 => Float32x4];
    const SURFACE_MORPH: [wgpu::VertexAttribute; 2] =
        wgpu::vertex_attr_array![14 => Float32x4, 15 => Uint32x4];
    let [vertex, instance] = vertex_layouts();
    let morph = wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &MORPH,
    };
    let mut buffers = vec![Some(vertex), Some(instance), d.morph.then_some(morph)];
    if ctx.surface == Surface::Pbr {
        buffers.push(Some(wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<SurfaceVertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &SURFACE,
        }));
        buffers.push(d.morph.then_some(wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<SurfaceTarget>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &SURFACE_MORPH,
        }));
    }
    while buffers.last().is_some_and(Option::is_none) {
        buffers.pop();
    }
    buffers
}

/// The colour targets of `d` in `class`: the colour (blended over where the class blends and `d` names no
/// blend), and `d`'s id target.
fn mesh_color_targets(
    d: &MeshPipeline<'_>,
    class: MaterialClass,
) -> Vec<Option<wgpu::ColorTargetState>> {
    let blend = match (class.blends(), d.blend) {
        (true, Some(b)) => Some(b),
        (true, None) => Some(BLEND_OVER),
        (false, b) => b,
    };
    let mut targets = vec![Some(wgpu::ColorTargetState {
        format: COLOR_FORMAT,
        blend,
        write_mask: wgpu::ColorWrites::ALL,
    })];
    if let Some(format) = d.id_target {
        targets.push(Some(wgpu::ColorTargetState {
            format,
            blend: None,
            // A blended surface leaves the id of what is behind it.
            write_mask: if class.blends() {
                wgpu::ColorWrites::empty()
            } else {
                wgpu::ColorWrites::ALL
            },
        }));
    }
    targets
}

/// The faces `d` culls in `class`: its own in a shadow pass, back faces for a single-sided class, else its own
/// or the scene's.
fn mesh_cull(
    ctx: &PipelineContext<'_>,
    d: &MeshPipeline<'_>,
    shadow: bool,
    class: MaterialClass,
) -> Option<wgpu::Face> {
    if shadow {
        d.cull
    } else if class.culls() {
        Some(wgpu::Face::Back)
    } else {
        d.cull.or(ctx.cull)
    }
}

/// `--impostor`'s bake (`fs_bake`, src/gpu/impostor_atlas.rs) in each class of `ctx`: four colour targets (base
/// colour and emissive in sRGB, normal-depth and occlusion-roughness-metallic linear), nothing blended.
pub(crate) fn bake_pipelines(ctx: &PipelineContext<'_>) -> MeshPipelines {
    let d = MeshPipeline {
        fragment: Some("fs_bake"),
        ..MeshPipeline::opaque("impostor bake")
    };
    let target = |format| {
        Some(wgpu::ColorTargetState {
            format,
            blend: None,
            write_mask: wgpu::ColorWrites::ALL,
        })
    };
    let (srgb, linear) = (
        crate::formats::IMPOSTOR_SRGB_FORMAT,
        crate::formats::IMPOSTOR_LINEAR_FORMAT,
    );
    let targets = [target(srgb), target(srgb), target(linear), target(linear)];
    let mut variants: [Option<wgpu::RenderPipeline>; 4] = Default::default();
    for &class in ctx.classes {
        variants[class.index()] = Some(mesh_pipeline_from(ctx, &d, false, class, &targets));
    }
    let first = mesh_pipeline_from(ctx, &d, false, MaterialClass::PLAIN, &targets);
    MeshPipelines {
        variants,
        first,
        surface: ctx.surface,
    }
}

fn mesh_pipeline_from(
    ctx: &PipelineContext<'_>,
    d: &MeshPipeline<'_>,
    shadow: bool,
    class: MaterialClass,
    targets: &[Option<wgpu::ColorTargetState>],
) -> wgpu::RenderPipeline {
    let device = ctx.device;
    let layout = mesh_pipeline_layout(ctx, d);
    let buffers = mesh_vertex_buffers(ctx, d);
    let constants: Vec<(&str, f64)> =
        [("ALPHA_TEST", ctx.alpha_test), ("IMPOSTORS", ctx.impostors)]
            .into_iter()
            .filter(|c| c.1)
            .map(|(name, _)| (name, 1.0))
            .collect();
    let compilation_options = wgpu::PipelineCompilationOptions {
        constants: &constants,
        ..Default::default()
    };
    // Depth-only passes need a fragment stage only to apply the alpha-test mask.
    let (fragment, targets): (Option<&str>, &[Option<wgpu::ColorTargetState>]) =
        match (d.fragment, ctx.alpha_test) {
            (Some(f), _) if shadow => (Some(f), &[]),
            (Some(f), _) => (Some(f), targets),
            (None, true) => (Some("fs_depth_masked"), &[]),
            (None, false) => (None, &[]),
        };
    let cull = mesh_cull(ctx, d, shadow, class);
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(d.label),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module: ctx.shader,
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
            cull_mode: cull,
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(d.depth_write && !class.blends()),
            depth_compare: Some(d.depth_compare),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: wgpu::MultisampleState::default(),
        fragment: fragment.map(|entry| wgpu::FragmentState {
            module: ctx.shader,
            entry_point: Some(entry),
            compilation_options,
            targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}
