//! What every method draws with: the scene's geometry on the GPU, the camera uniform, the shared pipelines,
//! render targets, and instanced draws bucketed by (model, LOD, shader variant).

use crate::config::{COLOR_FORMAT, DEPTH_FORMAT};
use crate::error::{Error, Result};
use crate::gpu::context::GpuContext;
use crate::scene::{Camera, Scene, BACKGROUND};
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};
use wgpu::util::DeviceExt;

pub const MESH_WGSL: &str = include_str!("../../shaders/mesh.wgsl");

/// Direction towards the light (world) and the ambient term of the Lambert shading.
pub const LIGHT_DIR: [f32; 3] = [-0.45, 0.8, 0.4];
pub const AMBIENT: f32 = 0.22;

#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
}

/// Per-instance vertex data (96 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct InstanceRaw {
    pub model: [[f32; 4]; 4],
    pub color: [f32; 4],
    /// x = k, y = alpha, z = LOD, w = instance id.
    pub params: [f32; 4],
}

impl InstanceRaw {
    pub fn new(model: &Mat4, color: [f32; 3], params: [f32; 4]) -> Self {
        InstanceRaw {
            model: model.to_cols_array_2d(),
            color: [color[0], color[1], color[2], 1.0],
            params,
        }
    }
}

#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct CameraRaw {
    view_proj: [[f32; 4]; 4],
    eye: [f32; 4],
    light: [f32; 4],
}

/// Where one LOD of one model lives in the shared vertex and index buffers.
#[derive(Debug, Clone, Copy)]
pub struct LodRange {
    pub base_vertex: i32,
    pub first_index: u32,
    pub index_count: u32,
}

impl LodRange {
    pub fn triangles(&self) -> u64 {
        self.index_count as u64 / 3
    }
}

/// Shader variants: one pipeline each. Later methods add theirs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Variant {
    Opaque,
}

/// One instanced draw call.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Draw {
    pub variant: Variant,
    pub model: u32,
    pub lod: u32,
    pub first_instance: u32,
    pub instance_count: u32,
}

/// Triangles and draw calls a method really submitted in a frame.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DrawStats {
    pub triangles: u64,
    pub draw_calls: u32,
}

/// A frame's draws: items added in any order, then sorted into buckets by (variant, model, LOD) so that each
/// bucket is one instanced draw. The vectors are kept between frames, so nothing is allocated per frame once
/// they have grown.
#[derive(Debug, Default)]
pub struct DrawList {
    items: Vec<((Variant, u32, u32), u32, InstanceRaw)>,
    pub instances: Vec<InstanceRaw>,
    pub draws: Vec<Draw>,
}

impl DrawList {
    pub fn clear(&mut self) {
        self.items.clear();
        self.instances.clear();
        self.draws.clear();
    }

    pub fn push(&mut self, variant: Variant, model: u32, lod: u32, raw: InstanceRaw) {
        let order = self.items.len() as u32;
        self.items.push(((variant, model, lod), order, raw));
    }

    /// Sorts into buckets (stable: instances keep their order inside a bucket) and fills `instances` and
    /// `draws`.
    pub fn build(&mut self) {
        self.items
            .sort_unstable_by_key(|(key, order, _)| (*key, *order));
        self.instances.clear();
        self.draws.clear();
        for (i, ((variant, model, lod), _, raw)) in self.items.iter().enumerate() {
            self.instances.push(*raw);
            match self.draws.last_mut() {
                Some(d) if d.variant == *variant && d.model == *model && d.lod == *lod => {
                    d.instance_count += 1
                }
                _ => self.draws.push(Draw {
                    variant: *variant,
                    model: *model,
                    lod: *lod,
                    first_instance: i as u32,
                    instance_count: 1,
                }),
            }
        }
    }
}

/// Colour (sRGB) and depth attachments of one viewport. The colour texture can also be viewed as plain
/// Rgba8Unorm, which is how the metric kernels read the stored sRGB-encoded bytes.
pub struct RenderTarget {
    pub width: u32,
    pub height: u32,
    pub color: wgpu::Texture,
    pub color_view: wgpu::TextureView,
    pub color_bytes_view: wgpu::TextureView,
    pub depth: wgpu::Texture,
    pub depth_view: wgpu::TextureView,
}

impl RenderTarget {
    pub fn new(device: &wgpu::Device, label: &str, width: u32, height: u32) -> RenderTarget {
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let color = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(&format!("{label} colour")),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: COLOR_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[wgpu::TextureFormat::Rgba8Unorm],
        });
        let depth = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(&format!("{label} depth")),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        RenderTarget {
            width,
            height,
            color_view: color.create_view(&Default::default()),
            color_bytes_view: color.create_view(&wgpu::TextureViewDescriptor {
                label: Some(&format!("{label} colour bytes")),
                format: Some(wgpu::TextureFormat::Rgba8Unorm),
                ..Default::default()
            }),
            depth_view: depth.create_view(&Default::default()),
            color,
            depth,
        }
    }

    /// Bytes of colour and depth this target holds.
    pub fn bytes(&self) -> u64 {
        self.width as u64 * self.height as u64 * 8
    }
}

/// A method's own instance buffer (each method has one, so the reference and the method drawn in the same
/// submission never overwrite each other's data).
pub struct InstanceBuffer {
    pub buffer: wgpu::Buffer,
    pub capacity: u32,
}

/// The scene on the GPU: geometry, camera uniform, shared pipelines. Built once per scene block.
pub struct SceneGpu {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub vertex_buffer: wgpu::Buffer,
    pub index_buffer: wgpu::Buffer,
    /// `lods[model][lod]`.
    pub lods: Vec<Vec<LodRange>>,
    pub camera_buffer: wgpu::Buffer,
    pub camera_layout: wgpu::BindGroupLayout,
    pub camera_bind_group: wgpu::BindGroup,
    pub shader: wgpu::ShaderModule,
    pub opaque_pipeline: wgpu::RenderPipeline,
}

pub fn vertex_layouts() -> [wgpu::VertexBufferLayout<'static>; 2] {
    const VERTEX: [wgpu::VertexAttribute; 2] =
        wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3];
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

impl SceneGpu {
    pub fn new(ctx: &GpuContext, scene: &Scene) -> Result<SceneGpu> {
        let device = &ctx.device;
        let mut vertices: Vec<Vertex> = Vec::new();
        let mut indices: Vec<u32> = Vec::new();
        let mut lods = Vec::new();
        for model in scene.models.iter() {
            let mut ranges = Vec::new();
            for lod in &model.chain.lods {
                let m = &lod.mesh;
                ranges.push(LodRange {
                    base_vertex: i32::try_from(vertices.len())
                        .map_err(|_| Error::Gpu("scene has too many vertices".into()))?,
                    first_index: indices.len() as u32,
                    index_count: m.indices.len() as u32,
                });
                vertices.extend(m.positions.iter().zip(&m.normals).map(|(p, n)| Vertex {
                    position: *p,
                    normal: *n,
                }));
                indices.extend_from_slice(&m.indices);
            }
            lods.push(ranges);
        }
        let vertex_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("scene vertices"),
            contents: bytemuck::cast_slice(&vertices),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let index_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("scene indices"),
            contents: bytemuck::cast_slice(&indices),
            usage: wgpu::BufferUsages::INDEX,
        });
        let camera_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("camera uniform"),
            size: std::mem::size_of::<CameraRaw>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let camera_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("camera layout"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let camera_bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("camera bind group"),
            layout: &camera_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: camera_buffer.as_entire_binding(),
            }],
        });
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("mesh.wgsl"),
            source: wgpu::ShaderSource::Wgsl(MESH_WGSL.into()),
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("mesh pipeline layout"),
            bind_group_layouts: &[Some(&camera_layout)],
            immediate_size: 0,
        });
        let buffers = vertex_layouts();
        let opaque_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("opaque pipeline"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &shader,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &buffers.clone().map(Some),
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &shader,
                entry_point: Some("fs_opaque"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: COLOR_FORMAT,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        ctx.check_errors()?;
        Ok(SceneGpu {
            device: device.clone(),
            queue: ctx.queue.clone(),
            vertex_buffer,
            index_buffer,
            lods,
            camera_buffer,
            camera_layout,
            camera_bind_group,
            shader,
            opaque_pipeline,
        })
    }

    pub fn write_camera(&self, camera: &Camera) {
        let l = Vec3::from(LIGHT_DIR).normalize();
        let raw = CameraRaw {
            view_proj: camera.view_proj().to_cols_array_2d(),
            eye: camera.eye.extend(1.0).to_array(),
            light: [l.x, l.y, l.z, AMBIENT],
        };
        self.queue
            .write_buffer(&self.camera_buffer, 0, bytemuck::bytes_of(&raw));
    }

    pub fn create_instance_buffer(&self, label: &str, capacity: u32) -> InstanceBuffer {
        let capacity = capacity.max(1);
        InstanceBuffer {
            buffer: self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: capacity as u64 * std::mem::size_of::<InstanceRaw>() as u64,
                usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            capacity,
        }
    }

    /// Uploads a built draw list into `buffer` (before the submission that uses it).
    pub fn upload(&self, buffer: &InstanceBuffer, list: &DrawList) {
        debug_assert!(list.instances.len() <= buffer.capacity as usize);
        if !list.instances.is_empty() {
            self.queue
                .write_buffer(&buffer.buffer, 0, bytemuck::cast_slice(&list.instances));
        }
    }

    pub fn pipeline(&self, variant: Variant) -> &wgpu::RenderPipeline {
        match variant {
            Variant::Opaque => &self.opaque_pipeline,
        }
    }

    /// Begins a pass that clears `target` to the background and its depth to 1.
    pub fn begin_clear_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        target: &RenderTarget,
        label: &str,
    ) -> wgpu::RenderPass<'e> {
        let [r, g, b] = BACKGROUND;
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &target.color_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color {
                        r: r as f64,
                        g: g as f64,
                        b: b as f64,
                        a: 1.0,
                    }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &target.depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        })
    }

    /// Records the draws of `list` (already uploaded to `buffer`) into `pass`.
    pub fn draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        buffer: &InstanceBuffer,
        list: &DrawList,
    ) -> DrawStats {
        let mut stats = DrawStats::default();
        if list.draws.is_empty() {
            return stats;
        }
        pass.set_bind_group(0, &self.camera_bind_group, &[]);
        pass.set_vertex_buffer(0, self.vertex_buffer.slice(..));
        pass.set_vertex_buffer(1, buffer.buffer.slice(..));
        pass.set_index_buffer(self.index_buffer.slice(..), wgpu::IndexFormat::Uint32);
        let mut bound: Option<Variant> = None;
        for d in &list.draws {
            if bound != Some(d.variant) {
                pass.set_pipeline(self.pipeline(d.variant));
                bound = Some(d.variant);
            }
            let r = self.lods[d.model as usize][d.lod as usize];
            pass.draw_indexed(
                r.first_index..r.first_index + r.index_count,
                r.base_vertex,
                d.first_instance..d.first_instance + d.instance_count,
            );
            stats.triangles += r.triangles() * d.instance_count as u64;
            stats.draw_calls += 1;
        }
        stats
    }
}

/// Copies a target's colour into a mappable buffer (rows padded to 256 bytes).
pub struct ColorReadback {
    pub buffer: wgpu::Buffer,
    pub padded_row: u32,
    pub width: u32,
    pub height: u32,
}

impl ColorReadback {
    pub fn new(device: &wgpu::Device, label: &str, width: u32, height: u32) -> Self {
        let padded_row = (width * 4).div_ceil(256) * 256;
        ColorReadback {
            buffer: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: padded_row as u64 * height as u64,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            padded_row,
            width,
            height,
        }
    }

    pub fn encode_copy(&self, encoder: &mut wgpu::CommandEncoder, target: &RenderTarget) {
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: &target.color,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &self.buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.padded_row),
                    rows_per_image: Some(self.height),
                },
            },
            wgpu::Extent3d {
                width: self.width,
                height: self.height,
                depth_or_array_layers: 1,
            },
        );
    }

    /// Tightly packed RGBA8 (sRGB-encoded) after the copy's submission.
    pub fn read(&self, ctx: &GpuContext) -> Result<Vec<u8>> {
        let (w, h, row) = (
            self.width as usize,
            self.height as usize,
            self.padded_row as usize,
        );
        ctx.read_buffer(&self.buffer, |bytes| {
            let mut out = Vec::with_capacity(w * h * 4);
            for y in 0..h {
                out.extend_from_slice(&bytes[y * row..y * row + w * 4]);
            }
            out
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn raw(id: f32) -> InstanceRaw {
        InstanceRaw::new(&Mat4::IDENTITY, [1.0, 1.0, 1.0], [0.0, 0.0, 0.0, id])
    }

    #[test]
    fn draw_list_buckets_by_variant_model_lod() {
        let mut l = DrawList::default();
        l.push(Variant::Opaque, 0, 2, raw(0.0));
        l.push(Variant::Opaque, 0, 0, raw(1.0));
        l.push(Variant::Opaque, 0, 2, raw(2.0));
        l.push(Variant::Opaque, 1, 0, raw(3.0));
        l.build();
        assert_eq!(l.draws.len(), 3);
        assert_eq!((l.draws[0].lod, l.draws[0].instance_count), (0, 1));
        assert_eq!((l.draws[1].lod, l.draws[1].instance_count), (2, 2));
        assert_eq!((l.draws[2].model, l.draws[2].first_instance), (1, 3));
        // Stable inside a bucket.
        assert_eq!(l.instances[1].params[3], 0.0);
        assert_eq!(l.instances[2].params[3], 2.0);
        l.clear();
        l.build();
        assert!(l.draws.is_empty());
    }
}
