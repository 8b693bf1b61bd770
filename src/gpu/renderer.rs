//! What every method draws with: the scene's geometry on the GPU, the camera uniform, the shared pipelines,
//! render targets, and instanced draws bucketed by (model, LOD, shader variant).

use crate::config::{COLOR_FORMAT, DEPTH_FORMAT};
use crate::error::{Error, Result};
use crate::gpu::context::GpuContext;
use crate::scene::{Camera, Scene, BACKGROUND};
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
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
    /// (u, v, kind, hub_y), see [`crate::mesh::Mesh::aux`].
    pub aux: [f32; 4],
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
    /// `color` is linear RGB plus the instance's animation angle in radians (windmill blades).
    pub fn new(model: &Mat4, color: [f32; 4], params: [f32; 4]) -> Self {
        InstanceRaw {
            model: model.to_cols_array_2d(),
            color,
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

/// Index of a pipeline in the slice a method passes to [`SceneGpu::draw`] (its shader variant).
pub type PipelineIndex = u8;

/// One instanced draw call.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Draw {
    pub pipeline: PipelineIndex,
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

/// A frame's draws: items added in any order, then sorted into buckets by (pipeline, model, LOD) so that each
/// bucket is one instanced draw ([`DrawList::build`]), or kept in the order given, merging only neighbours of
/// the same bucket ([`DrawList::build_in_order`], for back-to-front translucent draws). The vectors are kept
/// between frames, so nothing is allocated per frame once they have grown.
#[derive(Debug, Default)]
pub struct DrawList {
    items: Vec<((PipelineIndex, u32, u32), u32, InstanceRaw)>,
    pub instances: Vec<InstanceRaw>,
    pub draws: Vec<Draw>,
}

impl DrawList {
    pub fn clear(&mut self) {
        self.items.clear();
        self.instances.clear();
        self.draws.clear();
    }

    pub fn push(&mut self, pipeline: PipelineIndex, model: u32, lod: u32, raw: InstanceRaw) {
        let order = self.items.len() as u32;
        self.items.push(((pipeline, model, lod), order, raw));
    }

    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// Sorts into buckets (stable: instances keep their order inside a bucket) and fills `instances` and
    /// `draws`.
    pub fn build(&mut self) {
        self.items
            .sort_unstable_by_key(|(key, order, _)| (*key, *order));
        self.build_in_order();
    }

    /// Keeps the order of `push`; neighbours of the same bucket share a draw (instances of one draw are
    /// rasterised in order, so the order is kept).
    pub fn build_in_order(&mut self) {
        self.instances.clear();
        self.draws.clear();
        for (i, ((pipeline, model, lod), _, raw)) in self.items.iter().enumerate() {
            self.instances.push(*raw);
            match self.draws.last_mut() {
                Some(d) if d.pipeline == *pipeline && d.model == *model && d.lod == *lod => {
                    d.instance_count += 1
                }
                _ => self.draws.push(Draw {
                    pipeline: *pipeline,
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
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::COPY_DST,
            view_formats: &[wgpu::TextureFormat::Rgba8Unorm],
        });
        let depth = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(&format!("{label} depth")),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
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
    /// What the buffer holds (zeros at creation, as wgpu initialises buffers), so that an upload writes only
    /// the entries that differ.
    shadow: Mutex<Vec<InstanceRaw>>,
}

/// Unchanged entries between two changed ones that are written anyway to make one write of them (each
/// `write_buffer` has a fixed cost).
const UPLOAD_MERGE_GAP: usize = 8;

/// Instance data written per frame: what the draw lists held and what was actually written.
#[derive(Debug, Default)]
pub struct UploadCounters {
    listed: AtomicU64,
    written: AtomicU64,
}

impl UploadCounters {
    /// (bytes the draw lists held, bytes written) since the SceneGpu was built.
    pub fn get(&self) -> (u64, u64) {
        (
            self.listed.load(Ordering::Relaxed),
            self.written.load(Ordering::Relaxed),
        )
    }
}

/// The runs `[start, end)` where `new` differs from `old` (same length), runs closer than `gap` merged.
pub fn changed_runs<T: Pod>(old: &[T], new: &[T], gap: usize) -> Vec<(usize, usize)> {
    let differs = |i: usize| bytemuck::bytes_of(&old[i]) != bytemuck::bytes_of(&new[i]);
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for i in (0..new.len().min(old.len())).filter(|&i| differs(i)) {
        match runs.last_mut() {
            Some((_, end)) if i - *end <= gap => *end = i + 1,
            _ => runs.push((i, i + 1)),
        }
    }
    runs
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
    /// The scene has alpha-tested geometry: every mesh pipeline is built with `ALPHA_TEST` on.
    pub alpha_test: bool,
    pub uploads: UploadCounters,
}

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
    /// seen).
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

impl SceneGpu {
    /// Builds a pipeline over the shared vertex layout and shader (methods call this in their constructors).
    pub fn mesh_pipeline(&self, d: &MeshPipeline<'_>) -> wgpu::RenderPipeline {
        mesh_pipeline(
            &self.device,
            &self.shader,
            &self.camera_layout,
            self.alpha_test,
            d,
        )
    }

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
                vertices.extend(m.positions.iter().zip(&m.normals).zip(&m.aux).map(
                    |((p, n), a)| Vertex {
                        position: *p,
                        normal: *n,
                        aux: *a,
                    },
                ));
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
        let alpha_test = scene.models.iter().any(|m| {
            m.chain.lods.iter().any(|l| {
                l.mesh
                    .aux
                    .iter()
                    .any(|a| a[2] == crate::mesh::AUX_LEAF || a[2] == crate::mesh::AUX_LEAF_CLUSTER)
            })
        });
        let opaque_pipeline = mesh_pipeline(
            device,
            &shader,
            &camera_layout,
            alpha_test,
            &MeshPipeline::opaque("opaque pipeline"),
        );
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
            alpha_test,
            uploads: UploadCounters::default(),
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

    /// A `side` x `side` R32Float texture holding `values` (row-major): the screen-space thresholds of
    /// `dither`, the visibility texture of FSI. Read with `textureLoad` (no sampler).
    pub fn create_value_texture(&self, label: &str, side: u32, values: &[f32]) -> wgpu::Texture {
        debug_assert_eq!(values.len(), (side * side) as usize);
        let texture = self.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: side,
                height: side,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::R32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        self.queue.write_texture(
            texture.as_image_copy(),
            bytemuck::cast_slice(values),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(side * 4),
                rows_per_image: Some(side),
            },
            texture.size(),
        );
        texture
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
            shadow: Mutex::new(vec![InstanceRaw::zeroed(); capacity as usize]),
        }
    }

    /// Uploads a built draw list into `buffer` (before the submission that uses it).
    pub fn upload(&self, buffer: &InstanceBuffer, list: &DrawList) {
        self.upload_at(buffer, 0, list);
    }

    /// Uploads a built draw list into `buffer` from instance `first` on (several lists can share one buffer
    /// in one submission when they use disjoint ranges).
    /// Only the entries that differ from what the buffer already holds are written (see [`changed_runs`]).
    pub fn upload_at(&self, buffer: &InstanceBuffer, first: u32, list: &DrawList) {
        let new = &list.instances;
        let first = first as usize;
        debug_assert!(first + new.len() <= buffer.capacity as usize);
        let size = std::mem::size_of::<InstanceRaw>();
        let mut shadow = buffer
            .shadow
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let Some(old) = shadow.get_mut(first..first + new.len()) else {
            // Past the buffer's capacity: a bug, which wgpu's validation reports (ctx.check_errors).
            self.queue.write_buffer(
                &buffer.buffer,
                (first * size) as u64,
                bytemuck::cast_slice(new),
            );
            return;
        };
        let mut written = 0;
        for (start, end) in changed_runs(old, new, UPLOAD_MERGE_GAP) {
            self.queue.write_buffer(
                &buffer.buffer,
                ((first + start) * size) as u64,
                bytemuck::cast_slice(&new[start..end]),
            );
            old[start..end].copy_from_slice(&new[start..end]);
            written += (end - start) * size;
        }
        self.uploads
            .listed
            .fetch_add((new.len() * size) as u64, Ordering::Relaxed);
        self.uploads
            .written
            .fetch_add(written as u64, Ordering::Relaxed);
    }

    /// Begins a pass that clears `target` to the background and its depth to 1.
    pub fn begin_clear_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        target: &RenderTarget,
        label: &str,
    ) -> wgpu::RenderPass<'e> {
        self.begin_pass(encoder, &target.color_view, &target.depth_view, label, true)
    }

    /// Begins a pass on a colour and a depth view, clearing both (`clear`) or keeping what they hold.
    pub fn begin_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        color: &wgpu::TextureView,
        depth: &wgpu::TextureView,
        label: &str,
        clear: bool,
    ) -> wgpu::RenderPass<'e> {
        let [r, g, b] = BACKGROUND;
        let color_load = if clear {
            wgpu::LoadOp::Clear(wgpu::Color {
                r: r as f64,
                g: g as f64,
                b: b as f64,
                a: 1.0,
            })
        } else {
            wgpu::LoadOp::Load
        };
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: color,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: color_load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations {
                    load: if clear {
                        wgpu::LoadOp::Clear(1.0)
                    } else {
                        wgpu::LoadOp::Load
                    },
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        })
    }

    /// Draws `count` instances from absolute instance `first` of `buffer` at (model, LOD) with `pipeline`;
    /// for methods that need a pass per instance.
    #[allow(clippy::too_many_arguments)]
    pub fn draw_instances(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        buffer: &InstanceBuffer,
        first: u32,
        count: u32,
        model: u32,
        lod: u32,
        pipeline: &wgpu::RenderPipeline,
    ) -> DrawStats {
        pass.set_bind_group(0, &self.camera_bind_group, &[]);
        pass.set_vertex_buffer(0, self.vertex_buffer.slice(..));
        pass.set_vertex_buffer(1, buffer.buffer.slice(..));
        pass.set_index_buffer(self.index_buffer.slice(..), wgpu::IndexFormat::Uint32);
        pass.set_pipeline(pipeline);
        let r = self.lods[model as usize][lod as usize];
        pass.draw_indexed(
            r.first_index..r.first_index + r.index_count,
            r.base_vertex,
            first..first + count,
        );
        DrawStats {
            triangles: r.triangles() * count as u64,
            draw_calls: 1,
        }
    }

    /// Records the draws of `list` (uploaded to `buffer` at instance `first`, see [`SceneGpu::upload_at`])
    /// into `pass`, with `pipelines[d.pipeline]` for each draw. Bind groups other than the camera's (group 0)
    /// are the caller's to set.
    pub fn draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        buffer: &InstanceBuffer,
        first: u32,
        list: &DrawList,
        pipelines: &[&wgpu::RenderPipeline],
    ) -> DrawStats {
        let mut stats = DrawStats::default();
        if list.draws.is_empty() {
            return stats;
        }
        pass.set_bind_group(0, &self.camera_bind_group, &[]);
        pass.set_vertex_buffer(0, self.vertex_buffer.slice(..));
        pass.set_vertex_buffer(1, buffer.buffer.slice(..));
        pass.set_index_buffer(self.index_buffer.slice(..), wgpu::IndexFormat::Uint32);
        let mut bound: Option<PipelineIndex> = None;
        for d in &list.draws {
            if bound != Some(d.pipeline) {
                pass.set_pipeline(pipelines[d.pipeline as usize]);
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
        stats
    }
}

fn mesh_pipeline(
    device: &wgpu::Device,
    shader: &wgpu::ShaderModule,
    camera_layout: &wgpu::BindGroupLayout,
    alpha_test: bool,
    d: &MeshPipeline<'_>,
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
            (Some(f), _) => (Some(f), &targets),
            (None, true) => (Some("fs_depth_masked"), &[]),
            (None, false) => (None, &[]),
        };
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(d.label),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module: shader,
            entry_point: Some(if d.morph { "vs_morph" } else { "vs_main" }),
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

impl std::ops::Add for DrawStats {
    type Output = DrawStats;
    fn add(self, o: DrawStats) -> DrawStats {
        DrawStats {
            triangles: self.triangles + o.triangles,
            draw_calls: self.draw_calls + o.draw_calls,
        }
    }
}

impl std::ops::AddAssign for DrawStats {
    fn add_assign(&mut self, o: DrawStats) {
        *self = *self + o;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn raw(id: f32) -> InstanceRaw {
        InstanceRaw::new(&Mat4::IDENTITY, [1.0, 1.0, 1.0, 0.0], [0.0, 0.0, 0.0, id])
    }

    #[test]
    fn draw_list_buckets_by_variant_model_lod() {
        let mut l = DrawList::default();
        l.push(0, 0, 2, raw(0.0));
        l.push(0, 0, 0, raw(1.0));
        l.push(0, 0, 2, raw(2.0));
        l.push(0, 1, 0, raw(3.0));
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

    #[test]
    fn uploads_write_only_changed_runs() {
        let old = [0u32, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15];
        assert!(changed_runs(&old, &old, 8).is_empty());
        let mut new = old;
        new[3] = 99;
        assert_eq!(changed_runs(&old, &new, 8), vec![(3, 4)]);
        // Two changes 2 apart merge into one write with gap 2, stay apart with gap 1.
        new[6] = 99;
        assert_eq!(changed_runs(&old, &new, 2), vec![(3, 7)]);
        assert_eq!(changed_runs(&old, &new, 1), vec![(3, 4), (6, 7)]);
        new[15] = 0;
        assert_eq!(changed_runs(&old, &new, 1), vec![(3, 4), (6, 7), (15, 16)]);
    }
}
