//! The adapter's ceilings: microbenchmarks that each load one stage of the pipeline (`shaders/probe.wgsl`,
//! `shaders/probe_read.wgsl`; timed and summarised by `measure::probe_rounds`, `lodbench probe`).
//!
//! Each probe has a quantity it names (triangles, vertices, fragments, bytes) and three variants: the base, the
//! same with that quantity doubled (its time should double), and a control that changes something else and
//! keeps the quantity (its time should not move). How each isolates its stage:
//!
//! - **triangles**: patches of 8 triangles over 9 shared vertices (indexed), each inside one pixel's top-left
//!   corner, so no triangle covers a pixel centre and nothing is rasterised; a vertex serves about 3 triangles.
//!   Culling off. Drawn as one indexed draw of every patch, and (`triangles-instanced`) as one patch instanced.
//!   Control: the same triangles over a target of twice the pixels.
//! - **vertices**: triangles whose three vertices are one point (zero area), dropped after assembly: the vertex
//!   shader and primitive assembly alone. Control: twice the pixels.
//! - **fill, opaque / blended**: full-screen layers, no depth test; the fragment shader writes a constant, so
//!   the time is the rasteriser's and the colour writes' (blended: and the reads of the blend). Control: each
//!   layer as 8 triangles instead of 2.
//! - **depth**: the same layers into a depth target alone (no colour, no fragment shader), compare always,
//!   write on. Control: 8 triangles a layer.
//! - **bandwidth**: a compute pass that reads a buffer once, 16 bytes an invocation, as the metric kernel reads
//!   frames; each workgroup adds one word to a small output. Control: half the invocations, each reading 32
//!   bytes.
//!
//! Positions come from the vertex and instance indices: no vertex buffer is fetched.

use crate::error::{Error, Result};
use crate::gpu::context::GpuContext;

pub const PROBE_WGSL: &str = include_str!("../../shaders/probe.wgsl");
pub const PROBE_READ_WGSL: &str = include_str!("../../shaders/probe_read.wgsl");

const COLOR: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
const DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Triangles and vertices of a patch (`vs_patches`).
const PATCH_TRIANGLES: u64 = 8;
const PATCH_VERTICES: u32 = 9;

/// The probes, in the order they are reported.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Probe {
    Triangles,
    TrianglesInstanced,
    Vertices,
    FillOpaque,
    FillBlended,
    Depth,
    Bandwidth,
}

pub const PROBES: [Probe; 7] = [
    Probe::Triangles,
    Probe::TrianglesInstanced,
    Probe::Vertices,
    Probe::FillOpaque,
    Probe::FillBlended,
    Probe::Depth,
    Probe::Bandwidth,
];

/// What a probe's quantity counts (probe.csv's `unit`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Unit {
    Triangles,
    Vertices,
    Fragments,
    Bytes,
}

impl Unit {
    pub fn name(self) -> &'static str {
        match self {
            Unit::Triangles => "triangles",
            Unit::Vertices => "vertices",
            Unit::Fragments => "fragments",
            Unit::Bytes => "bytes",
        }
    }
}

/// A probe's variants: the base, its quantity doubled, and a control that keeps the quantity.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Variant {
    Base,
    Doubled,
    Control,
}

pub const VARIANTS: [Variant; 3] = [Variant::Base, Variant::Doubled, Variant::Control];

impl Probe {
    pub fn name(self) -> &'static str {
        match self {
            Probe::Triangles => "triangles",
            Probe::TrianglesInstanced => "triangles-instanced",
            Probe::Vertices => "vertices",
            Probe::FillOpaque => "fill-opaque",
            Probe::FillBlended => "fill-blended",
            Probe::Depth => "depth",
            Probe::Bandwidth => "bandwidth",
        }
    }

    /// What the quantity counts.
    pub fn unit(self) -> Unit {
        match self {
            Probe::Triangles | Probe::TrianglesInstanced => Unit::Triangles,
            Probe::Vertices => Unit::Vertices,
            Probe::FillOpaque | Probe::FillBlended | Probe::Depth => Unit::Fragments,
            Probe::Bandwidth => Unit::Bytes,
        }
    }

    /// A fill probe: full-screen quads of shaded fragments, opaque or blended.
    pub fn is_fill(self) -> bool {
        matches!(self, Probe::FillOpaque | Probe::FillBlended)
    }

    /// What the control variant changes.
    pub fn control(self) -> &'static str {
        match self {
            Probe::Triangles | Probe::TrianglesInstanced | Probe::Vertices => {
                "twice the target's pixels"
            }
            Probe::FillOpaque | Probe::FillBlended | Probe::Depth => "8 triangles a layer, not 2",
            Probe::Bandwidth => "half the invocations, 32 bytes each",
        }
    }
}

/// The base amounts of work, scaled by `lodbench probe --scale`.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Amounts {
    /// Patches of 8 triangles.
    pub patches: u32,
    /// Vertices of the degenerate triangles (a multiple of 3).
    pub vertices: u32,
    /// Full-screen layers.
    pub layers: u32,
    /// Bytes read.
    pub bytes: u64,
}

impl Amounts {
    /// The defaults at `scale` (1: about a millisecond each on a GPU, tens on lavapipe).
    pub fn at(scale: f64) -> Amounts {
        let s = |x: f64| (x * scale).round().max(1.0);
        Amounts {
            patches: s(65_536.0) as u32,
            vertices: (s(1_048_576.0 / 3.0) * 3.0) as u32,
            layers: s(16.0) as u32,
            bytes: (s(1_048_576.0) as u64) * 16,
        }
    }
}

/// The pipelines, targets and buffers of every probe.
pub struct Probes {
    amounts: Amounts,
    size: (u32, u32),
    patches: wgpu::RenderPipeline,
    patches_instanced: wgpu::RenderPipeline,
    degenerate: wgpu::RenderPipeline,
    fill_opaque: wgpu::RenderPipeline,
    fill_blended: wgpu::RenderPipeline,
    depth: wgpu::RenderPipeline,
    read: wgpu::ComputePipeline,
    /// The target's colour and depth views, and the control's (twice the pixels).
    color: [wgpu::TextureView; 2],
    depth_view: wgpu::TextureView,
    /// Bind groups of the render probes: [target, control target] x grid [1, 2].
    params: [[wgpu::BindGroup; 2]; 2],
    /// Indices of every patch (the doubled count) and of one patch.
    patch_indices: wgpu::Buffer,
    one_patch: wgpu::Buffer,
    /// Bind groups of the bandwidth probe: base, doubled, control.
    reads: [wgpu::BindGroup; 3],
}

impl Probes {
    /// Every probe's resources for a `width` x `height` target.
    pub fn new(ctx: &GpuContext, (width, height): (u32, u32), amounts: Amounts) -> Result<Probes> {
        ctx.check_viewport(width * 2, height)?;
        let d = &ctx.device;
        let (module, read_module) = probe_modules(d);
        let params_layout = uniform_layout(d);
        let layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("probe"),
            bind_group_layouts: &[Some(&params_layout)],
            immediate_size: 0,
        });
        let (source, sink) = read_buffers(d, amounts.bytes * 2);
        let read = read_pipeline(d, &read_module);
        let vec4s = bandwidth_vec4s(amounts)?;
        let [patches, patches_instanced, degenerate, fill_opaque, fill_blended, depth] =
            render_pipelines(d, &layout, &module);
        let (color, depth_view) = targets(d, width, height);
        let params = param_groups(d, &params_layout, width, height);
        let (patch_indices, one_patch) = index_buffers(d, amounts.patches);
        let reads = read_groups(d, &read, (&source, &sink), vec4s);
        let probes = Probes {
            amounts,
            size: (width, height),
            patches,
            patches_instanced,
            degenerate,
            fill_opaque,
            fill_blended,
            depth,
            color,
            depth_view,
            params,
            patch_indices,
            one_patch,
            reads,
            read,
        };
        ctx.check_errors()?;
        Ok(probes)
    }

    pub fn amounts(&self) -> Amounts {
        self.amounts
    }

    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// The amount of `probe`'s quantity its `variant` does.
    pub fn quantity(&self, probe: Probe, variant: Variant) -> f64 {
        let a = self.amounts;
        let twice = if variant == Variant::Doubled {
            2.0
        } else {
            1.0
        };
        let pixels = self.size.0 as f64 * self.size.1 as f64;
        twice
            * match probe {
                Probe::Triangles | Probe::TrianglesInstanced => {
                    a.patches as f64 * PATCH_TRIANGLES as f64
                }
                Probe::Vertices => a.vertices as f64,
                Probe::FillOpaque | Probe::FillBlended | Probe::Depth => a.layers as f64 * pixels,
                Probe::Bandwidth => a.bytes as f64,
            }
    }

    /// Records `probe`'s `variant` into `encoder`.
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder, probe: Probe, variant: Variant) {
        let a = self.amounts;
        let twice = if variant == Variant::Doubled { 2 } else { 1 };
        let control = variant == Variant::Control;
        if probe == Probe::Bandwidth {
            let group = &self.reads[match variant {
                Variant::Base => 0,
                Variant::Doubled => 1,
                Variant::Control => 2,
            }];
            let reads_each = if control { 2 } else { 1 };
            let invocations = (a.bytes / 16) * twice / reads_each;
            let groups = invocations.div_ceil(64);
            let (x, y) = (groups.min(65_535) as u32, groups.div_ceil(65_535) as u32);
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("probe bandwidth"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.read);
            pass.set_bind_group(0, group, &[]);
            pass.dispatch_workgroups(x, y, 1);
            return;
        }
        let geometry = matches!(
            probe,
            Probe::Triangles | Probe::TrianglesInstanced | Probe::Vertices
        );
        // Geometry's control: the wider target; a layer's: the 2 x 2 grid.
        let target = usize::from(geometry && control);
        let grid = usize::from(!geometry && control);
        let depth_only = probe == Probe::Depth;
        let color = [Some(wgpu::RenderPassColorAttachment {
            view: &self.color[target],
            depth_slice: None,
            resolve_target: None,
            // Loaded, not cleared: a clear's cost is the target's pixels, which the geometry probes' control
            // doubles.
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Load,
                store: wgpu::StoreOp::Store,
            },
        })];
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(probe.name()),
            color_attachments: if depth_only { &[] } else { &color },
            depth_stencil_attachment: depth_only.then_some(
                wgpu::RenderPassDepthStencilAttachment {
                    view: &self.depth_view,
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
        });
        pass.set_bind_group(0, &self.params[target][grid], &[]);
        let layer_vertices = if control && !geometry { 24 } else { 6 };
        match probe {
            Probe::Triangles => {
                pass.set_pipeline(&self.patches);
                pass.set_index_buffer(self.patch_indices.slice(..), wgpu::IndexFormat::Uint32);
                let patches = a.patches * twice as u32;
                pass.draw_indexed(0..patches * PATCH.len() as u32, 0, 0..1);
            }
            Probe::TrianglesInstanced => {
                pass.set_pipeline(&self.patches_instanced);
                pass.set_index_buffer(self.one_patch.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..PATCH.len() as u32, 0, 0..a.patches * twice as u32);
            }
            Probe::Vertices => {
                pass.set_pipeline(&self.degenerate);
                pass.draw(0..a.vertices * twice as u32, 0..1);
            }
            Probe::FillOpaque | Probe::FillBlended | Probe::Depth => {
                pass.set_pipeline(match probe {
                    Probe::FillOpaque => &self.fill_opaque,
                    Probe::FillBlended => &self.fill_blended,
                    _ => &self.depth,
                });
                for _ in 0..a.layers * twice as u32 {
                    pass.draw(0..layer_vertices, 0..1);
                }
            }
            Probe::Bandwidth => {}
        }
    }
}

/// A patch's 8 triangles over its 3 x 3 vertices (`vs_patches`).
const PATCH: [u32; 24] = [
    0, 1, 3, 1, 4, 3, 1, 2, 4, 2, 5, 4, 3, 4, 6, 4, 7, 6, 4, 5, 7, 5, 8, 7,
];

/// probe.wgsl's module (the render probes) and probe_read.wgsl's (the bandwidth probe).
fn probe_modules(d: &wgpu::Device) -> (wgpu::ShaderModule, wgpu::ShaderModule) {
    let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("probe.wgsl"),
        source: wgpu::ShaderSource::Wgsl(PROBE_WGSL.into()),
    });
    let read_module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("probe_read.wgsl"),
        source: wgpu::ShaderSource::Wgsl(PROBE_READ_WGSL.into()),
    });
    (module, read_module)
}

/// The bandwidth probe's source (`bytes` long, at least 16) and its small sink.
fn read_buffers(d: &wgpu::Device, bytes: u64) -> (wgpu::Buffer, wgpu::Buffer) {
    let source = d.create_buffer(&wgpu::BufferDescriptor {
        label: Some("probe read source"),
        size: bytes.max(16),
        usage: wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    });
    let sink = d.create_buffer(&wgpu::BufferDescriptor {
        label: Some("probe read sink"),
        size: 16,
        usage: wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    });
    (source, sink)
}

/// The bandwidth probe's compute pipeline (its layout from the shader).
fn read_pipeline(d: &wgpu::Device, read_module: &wgpu::ShaderModule) -> wgpu::ComputePipeline {
    d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("probe bandwidth"),
        layout: None,
        module: read_module,
        entry_point: Some("cs_read"),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// The base bandwidth probe's 16-byte reads, or an error where the doubled count is beyond a u32.
fn bandwidth_vec4s(amounts: Amounts) -> Result<u64> {
    let vec4s = amounts.bytes / 16;
    if vec4s * 2 > u32::MAX as u64 {
        return Err(Error::Config(format!(
            "probe: {} bytes is more than the bandwidth probe addresses",
            amounts.bytes
        )));
    }
    Ok(vec4s)
}

/// The render probes' pipelines: patches, one patch instanced, degenerate triangles, opaque and blended fill,
/// depth alone.
fn render_pipelines(
    d: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
) -> [wgpu::RenderPipeline; 6] {
    let render = |label: &str, vs: &str, blend: Option<wgpu::BlendState>, depth_only: bool| {
        render_pipeline(d, layout, module, label, vs, blend, depth_only)
    };
    [
        render("probe triangles", "vs_patches", None, false),
        render(
            "probe triangles instanced",
            "vs_patches_instanced",
            None,
            false,
        ),
        render("probe vertices", "vs_degenerate", None, false),
        render("probe fill opaque", "vs_layer", None, false),
        render(
            "probe fill blended",
            "vs_layer",
            Some(wgpu::BlendState::ALPHA_BLENDING),
            false,
        ),
        render("probe depth", "vs_layer", None, true),
    ]
}

/// The colour targets' views (`width`, and the control's twice that) and the depth target's view.
fn targets(
    d: &wgpu::Device,
    width: u32,
    height: u32,
) -> ([wgpu::TextureView; 2], wgpu::TextureView) {
    let texture = |label: &str, w: u32, format| {
        d.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: w,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        })
        .create_view(&Default::default())
    };
    let color = [
        texture("probe target", width, COLOR),
        texture("probe control target", width * 2, COLOR),
    ];
    (color, texture("probe depth", width, DEPTH))
}

/// The render probes' parameter bind groups: [target, control target] x grid [1, 2].
fn param_groups(
    d: &wgpu::Device,
    params_layout: &wgpu::BindGroupLayout,
    width: u32,
    height: u32,
) -> [[wgpu::BindGroup; 2]; 2] {
    let param = |w: u32, grid: u32| {
        let words: [u32; 4] = [(w as f32).to_bits(), (height as f32).to_bits(), 0, grid];
        let buffer = buffer_with(
            d,
            "probe params",
            bytemuck::cast_slice(&words),
            wgpu::BufferUsages::UNIFORM,
        );
        d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("probe params"),
            layout: params_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: buffer.as_entire_binding(),
            }],
        })
    };
    [
        [param(width, 1), param(width, 2)],
        [param(width * 2, 1), param(width * 2, 2)],
    ]
}

/// The indices of twice `patches` patches, and of one patch.
fn index_buffers(d: &wgpu::Device, patches: u32) -> (wgpu::Buffer, wgpu::Buffer) {
    let max_patches = patches as u64 * 2;
    let indices: Vec<u32> = (0..max_patches as u32)
        .flat_map(|p| PATCH.iter().map(move |&i| p * PATCH_VERTICES + i))
        .collect();
    let patch_indices = buffer_with(
        d,
        "probe patch indices",
        bytemuck::cast_slice(&indices),
        wgpu::BufferUsages::INDEX,
    );
    let one_patch = buffer_with(
        d,
        "probe one patch",
        bytemuck::cast_slice(&PATCH),
        wgpu::BufferUsages::INDEX,
    );
    (patch_indices, one_patch)
}

/// The bandwidth probe's bind groups over `(source, sink)`: base, doubled (twice the reads), control (half
/// the invocations, each reading twice).
fn read_groups(
    d: &wgpu::Device,
    read: &wgpu::ComputePipeline,
    (source, sink): (&wgpu::Buffer, &wgpu::Buffer),
    vec4s: u64,
) -> [wgpu::BindGroup; 3] {
    let read_group = |vec4s: u64, reads: u32| {
        let words: [u32; 4] = [vec4s as u32, reads, 0, 0];
        let params = buffer_with(
            d,
            "probe read params",
            bytemuck::cast_slice(&words),
            wgpu::BufferUsages::UNIFORM,
        );
        d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("probe read"),
            layout: &read.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: source.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: sink.as_entire_binding(),
                },
            ],
        })
    };
    [
        read_group(vec4s, 1),
        read_group(vec4s * 2, 1),
        read_group(vec4s, 2),
    ]
}

fn uniform_layout(d: &wgpu::Device) -> wgpu::BindGroupLayout {
    d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("probe params"),
        entries: &[wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::VERTEX,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        }],
    })
}

fn buffer_with(
    d: &wgpu::Device,
    label: &str,
    bytes: &[u8],
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    use wgpu::util::DeviceExt;
    d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: bytes,
        usage,
    })
}

fn render_pipeline(
    d: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    label: &str,
    vs: &str,
    blend: Option<wgpu::BlendState>,
    depth_only: bool,
) -> wgpu::RenderPipeline {
    let targets = [Some(wgpu::ColorTargetState {
        format: COLOR,
        blend,
        write_mask: wgpu::ColorWrites::ALL,
    })];
    d.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some(vs),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState {
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil: depth_only.then(|| wgpu::DepthStencilState {
            format: DEPTH,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Always),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: wgpu::MultisampleState::default(),
        fragment: (!depth_only).then_some(wgpu::FragmentState {
            module,
            entry_point: Some("fs_colour"),
            compilation_options: Default::default(),
            targets: &targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}
