//! The scene on the GPU: the models' LOD meshes in one vertex and one index buffer, the camera uniform, the
//! scene's surface (flat, or its materials: textures, samplers and a bind group each), the shared opaque
//! pipeline, render passes and instanced draws, part by part where a mesh has materials.

use super::fragments::Pass;
use crate::error::{Error, Result};
use crate::gpu::context::GpuContext;
use crate::gpu::draw_list::{DrawList, DrawStats, PipelineIndex};
use crate::gpu::instances::{InstanceBuffer, UploadCounters};
use crate::gpu::pipelines::{
    mesh_pipelines, mesh_wgsl, MaterialClass, MeshPipeline, MeshPipelines, PipelineContext,
    Surface, SurfaceVertex, Vertex, MATERIAL_GROUP,
};
use crate::gpu::surface::MaterialsGpu;
use crate::gpu::targets::{texture_2d, RenderTarget, ATTACHMENT_READ};
use crate::scene::animated::Posed;
use crate::scene::{Camera, Motion, Scene, BACKGROUND};
use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use wgpu::util::DeviceExt;

pub use crate::scene::model::{AMBIENT, LIGHT_DIR};

#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct CameraRaw {
    view_proj: [[f32; 4]; 4],
    eye: [f32; 4],
    light: [f32; 4],
    /// `--shadows on`: world to the shadow map's clip space, and (on, side in texels, depth bias, 0).
    light_view_proj: [[f32; 4]; 4],
    shadow: [f32; 4],
    /// `--shader-work`: (iterations, weight of their result, 0, 0); written once, by [`SceneGpu::write_work`].
    work: [f32; 4],
}

/// Byte offset of `light_view_proj` in the camera uniform (what [`SceneGpu::write_camera`] leaves alone).
const LIGHT_OFFSET: u64 = 64 + 16 + 16;
/// Byte offset of `work` in the camera uniform.
const WORK_OFFSET: u64 = LIGHT_OFFSET + 64 + 16;

/// One of the scene's shadow maps: the one a shadow pass writes, and the one draws are lit by. The layer above
/// decides what each map stands for; the GPU layer only keeps them apart.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShadowMap(usize);

impl ShadowMap {
    /// The 1x1 placeholder: draws with shadows off, and the shadow passes themselves (so the map being written
    /// is never the one bound).
    pub const NONE: ShadowMap = ShadowMap(0);

    /// The `i`-th of the maps a scene with `--shadows on` has ([`SceneGpu::with_shadow_maps`]).
    pub const fn lit(i: usize) -> ShadowMap {
        ShadowMap(i + 1)
    }

    /// Index into [`SceneGpu::shadow_views`] and [`SceneGpu::shadow_maps`].
    pub fn index(self) -> usize {
        self.0
    }
}

/// What a pass sees of the frame beyond its instances: the shadow map its shading reads (the camera bind group
/// with that map, group 0) and the scissor rectangle `[x, y, width, height]` its colour passes draw within (None:
/// the whole target; clears still cover the whole target). The quality pass draws one frame under several views
/// (the method's, the reference's, lodpop's counterfactual inside the rectangle where it can differ); the view
/// travels with the frame's input (`FrameInput::view`) to every pass begun for it ([`SceneGpu::begin_pass`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct View {
    pub shadow: ShadowMap,
    pub scissor: Option<[u32; 4]>,
}

impl View {
    /// The whole target, lit by shadow map `shadow`.
    pub const fn lit_by(shadow: ShadowMap) -> View {
        View {
            shadow,
            scissor: None,
        }
    }

    /// This view with its colour passes limited to `rect`, `[x, y, width, height]`.
    pub fn scissored(self, rect: [u32; 4]) -> View {
        View {
            scissor: Some(rect),
            ..self
        }
    }
}

/// Where one LOD of one model lives in the shared vertex and index buffers.
#[derive(Debug, Clone, Copy)]
pub struct LodRange {
    pub base_vertex: i32,
    pub first_index: u32,
    pub index_count: u32,
    /// Its material parts: `SceneGpu::parts[parts.0..parts.0 + parts.1]` (none with the flat surface).
    pub parts: (u32, u32),
}

/// A run of one LOD's indices drawn with one material.
#[derive(Debug, Clone, Copy)]
pub struct PartRange {
    pub first_index: u32,
    pub index_count: u32,
    pub material: u32,
    pub class: MaterialClass,
}

impl LodRange {
    pub fn triangles(&self) -> u64 {
        self.index_count as u64 / 3
    }
}

/// The scene on the GPU: geometry, camera uniform, shared pipelines. Built once per scene block.
pub struct SceneGpu {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub vertex_buffer: wgpu::Buffer,
    pub index_buffer: wgpu::Buffer,
    /// `lods[model][lod]`; a unified scene's seams follow its models: `lods[seam_base + s][mesh]` is seam s's
    /// mesh `mesh` ([`crate::scene::unified::Seam::mesh_index`]).
    pub lods: Vec<Vec<LodRange>>,
    /// Index in `lods` of the first seam (the model count).
    pub seam_base: u32,
    pub camera_buffer: wgpu::Buffer,
    pub camera_layout: wgpu::BindGroupLayout,
    /// The camera's bind group (group 0) with each shadow map ([`ShadowMap`]); a pass binds its view's.
    pub camera_groups: Vec<wgpu::BindGroup>,
    /// The shadow maps' depth views, indexed like `camera_groups` (`--shadows on`; only the placeholder
    /// otherwise).
    pub shadow_views: Vec<wgpu::TextureView>,
    pub shadow_maps: Vec<wgpu::Texture>,
    pub shadow_size: u32,
    pub shader: wgpu::ShaderModule,
    /// The flat surface's shader in a scene of materials ([`SceneGpu::flat_pipeline`]).
    flat_shader: Option<wgpu::ShaderModule>,
    /// What the mesh shader's surface is: flat, or the scene's materials.
    pub surface: Surface,
    /// The material parts of every LOD ([`LodRange::parts`]).
    pub parts: Vec<PartRange>,
    /// The classes of the parts (the plain class alone with the flat surface), each mesh pipeline's variants.
    pub classes: Vec<MaterialClass>,
    /// The materials' textures, samplers and bind groups, and the surface vertex buffer (PBR surface).
    pub materials: Option<MaterialsGpu>,
    pub opaque_pipeline: MeshPipelines,
    /// The scene has alpha-tested geometry: every mesh pipeline is built with `ALPHA_TEST` on.
    pub alpha_test: bool,
    /// Faces every mesh pipeline culls where its own descriptor says None: back faces in the unified scenes
    /// (closed meshes and heightfields wound outwards, their seams wound with them), so a crack between blocks
    /// shows what lies behind the surface, as in an engine that culls a model's inside, and `crack_px` sees it;
    /// none elsewhere.
    pub cull: Option<wgpu::Face>,
    pub uploads: UploadCounters,
    /// The deformed models' LODs as the last [`SceneGpu::write_pose`] posed them (empty when nothing deforms).
    posed: std::cell::RefCell<Posed>,
    /// Counts the fragments of the passes begun while the quality pass counts a method's frame (None where the
    /// device has no pipeline statistics queries).
    pub fragments: Option<super::fragments::FragmentQueries>,
    /// Scratch for their vertices, reused every frame.
    pose_vertices: std::cell::RefCell<Vec<Vertex>>,
    /// Scratch for their surface vertices (their tangents turn with the pose), reused every frame.
    pose_surface: std::cell::RefCell<Vec<SurfaceVertex>>,
}

/// The models a scene deforms per frame.
fn deformed_models(scene: &Scene) -> Vec<u32> {
    match &scene.motion {
        Motion::Animated(a) => a.deformers.iter().map(|d| d.model).collect(),
        _ => Vec::new(),
    }
}

/// A deformed vertex: its position and normal on the frame, its rest position in `aux` (kind
/// [`crate::geometry::mesh::AUX_DEFORMED`]) for FSI's visibility texture.
fn deformed_vertex(position: [f32; 3], normal: [f32; 3], rest: [f32; 3]) -> Vertex {
    Vertex {
        position,
        normal,
        aux: [
            rest[0],
            rest[1],
            crate::geometry::mesh::AUX_DEFORMED,
            rest[2],
        ],
    }
}

/// The surface vertex of vertex `v` of `mesh`: its texture coordinates, tangent and colour, defaults where the
/// mesh has none ((0, 0), +x, white).
pub fn surface_vertex(mesh: &crate::geometry::mesh::Mesh, v: usize) -> SurfaceVertex {
    let d = &mesh.data;
    let uv0 = d.uv0.as_ref().map_or([0.0; 2], |t| t[v]);
    let uv1 = d.uv1.as_ref().map_or([0.0; 2], |t| t[v]);
    SurfaceVertex {
        tex: [uv0[0], uv0[1], uv1[0], uv1[1]],
        tangent: d.tangents.as_ref().map_or([1.0, 0.0, 0.0, 1.0], |t| t[v]),
        color: d.colors.as_ref().map_or([1.0; 4], |c| c[v]),
    }
}

impl SceneGpu {
    /// What every mesh pipeline of the scene is built over.
    pub fn pipeline_context(&self) -> PipelineContext<'_> {
        PipelineContext {
            device: &self.device,
            shader: &self.shader,
            camera_layout: &self.camera_layout,
            alpha_test: self.alpha_test,
            surface: self.surface,
            material_layout: self.materials.as_ref().map(|m| &m.layout),
            classes: &self.classes,
            cull: self.cull,
        }
    }

    /// Builds a pipeline over the shared vertex layout and shader, in each material class of the scene (methods
    /// call this in their constructors).
    pub fn mesh_pipeline(&self, d: &MeshPipeline<'_>) -> MeshPipelines {
        mesh_pipelines(&self.pipeline_context(), d)
    }

    /// A pipeline with the flat surface whatever the scene's (one colour per instance, Lambert and ambient, no
    /// material bound; every triangle of a LOD in one draw): what `reference-flat` draws, the same triangles as
    /// the reference without the materials' cost.
    pub fn flat_pipeline(&self, d: &MeshPipeline<'_>) -> MeshPipelines {
        mesh_pipelines(
            &PipelineContext {
                shader: self.flat_shader.as_ref().unwrap_or(&self.shader),
                surface: Surface::Flat,
                material_layout: None,
                classes: &[MaterialClass::PLAIN],
                ..self.pipeline_context()
            },
            d,
        )
    }

    /// An instance buffer for `capacity` instances.
    pub fn create_instance_buffer(&self, label: &str, capacity: u32) -> InstanceBuffer {
        InstanceBuffer::new(&self.device, label, capacity)
    }

    /// Uploads a built draw list into `buffer` (before the submission that uses it).
    pub fn upload(&self, buffer: &InstanceBuffer, list: &DrawList) {
        self.upload_at(buffer, 0, list);
    }

    /// Uploads a built draw list into `buffer` from instance `first` on ([`InstanceBuffer::write`]), counted
    /// in `uploads`.
    pub fn upload_at(&self, buffer: &InstanceBuffer, first: u32, list: &DrawList) {
        buffer.write(&self.queue, first, list, &self.uploads);
    }

    /// With one shadow map under `--shadows on`.
    pub fn new(ctx: &GpuContext, scene: &Scene) -> Result<SceneGpu> {
        SceneGpu::with_shadow_maps(ctx, scene, 1)
    }

    /// With `lit` shadow maps under `--shadows on` (`ShadowMap::lit(0)` ...), besides the placeholder; none
    /// without shadows.
    pub fn with_shadow_maps(ctx: &GpuContext, scene: &Scene, lit: usize) -> Result<SceneGpu> {
        let device = &ctx.device;
        let pbr = !scene.materials.is_empty();
        let deformed = deformed_models(scene);
        let geometry = SceneGeometry::gather(scene, pbr, &deformed)?;
        let (vertex_buffer, index_buffer) = geometry.buffers(device, !deformed.is_empty());
        let camera_buffer = camera_buffer(device);
        let camera_layout = camera_layout(device);
        let shadow_size = scene.shadows.map_or(1, |s| s.size);
        let shadow_maps = shadow_maps(device, scene, lit, shadow_size);
        let shadow_views: Vec<wgpu::TextureView> = shadow_maps
            .iter()
            .map(|t| t.create_view(&Default::default()))
            .collect();
        let shadow_sampler = shadow_sampler(device);
        let camera_groups = camera_groups(
            device,
            &camera_layout,
            &camera_buffer,
            &shadow_views,
            &shadow_sampler,
        );
        let surface = if pbr { Surface::Pbr } else { Surface::Flat };
        let (shader, flat_shader) = mesh_shaders(device, surface);
        let alpha_test = needs_alpha_test(scene);
        let cull = scene.unified.is_some().then_some(wgpu::Face::Back);
        let classes = material_classes(&geometry.parts);
        let materials = pbr
            .then(|| {
                MaterialsGpu::new(
                    ctx,
                    &scene.materials,
                    &geometry.surface_vertices,
                    !deformed.is_empty(),
                )
            })
            .transpose()?;
        let opaque_pipeline = mesh_pipelines(
            &PipelineContext {
                device,
                shader: &shader,
                camera_layout: &camera_layout,
                alpha_test,
                surface,
                material_layout: materials.as_ref().map(|m| &m.layout),
                classes: &classes,
                cull,
            },
            &MeshPipeline::opaque("opaque pipeline"),
        );
        ctx.check_errors()?;
        let gpu = SceneGpu {
            device: device.clone(),
            queue: ctx.queue.clone(),
            vertex_buffer,
            index_buffer,
            lods: geometry.lods,
            seam_base: geometry.seam_base,
            camera_buffer,
            camera_layout,
            camera_groups,
            shadow_views,
            shadow_maps,
            shadow_size,
            shader,
            flat_shader,
            surface,
            parts: geometry.parts,
            classes,
            materials,
            opaque_pipeline,
            alpha_test,
            cull,
            uploads: UploadCounters::default(),
            posed: Default::default(),
            fragments: super::fragments::FragmentQueries::new(device),
            pose_vertices: Default::default(),
            pose_surface: Default::default(),
        };
        gpu.write_work(scene.shader_work, scene.shader_work_weight);
        Ok(gpu)
    }

    /// The bytes (R, G, B) a target cleared to the background holds on this device: the sRGB encoding the
    /// device itself makes of [`BACKGROUND`], read back once, so uncovered_px and crack_px compare exactly.
    pub fn background_bytes(&self, ctx: &GpuContext) -> Result<[u8; 3]> {
        let target = RenderTarget::new(&self.device, "background probe", 1, 1);
        let readback =
            crate::gpu::readback::TextureReadback::color(&self.device, "background probe", 1, 1);
        let mut encoder = self.device.create_command_encoder(&Default::default());
        drop(self.begin_clear_pass(
            &mut encoder,
            &target,
            View::lit_by(ShadowMap::NONE),
            "background probe",
        ));
        readback.encode_copy(&mut encoder, &target);
        self.queue.submit([encoder.finish()]);
        let px = readback.read(ctx)?;
        Ok([px[0], px[1], px[2]])
    }

    pub fn write_camera(&self, camera: &Camera) {
        let l = Vec3::from(LIGHT_DIR).normalize();
        let raw = CameraRaw {
            view_proj: camera.view_proj().to_cols_array_2d(),
            eye: camera.eye.extend(1.0).to_array(),
            light: [l.x, l.y, l.z, AMBIENT],
            light_view_proj: [[0.0; 4]; 4],
            shadow: [0.0; 4],
            work: [0.0; 4],
        };
        let bytes = bytemuck::bytes_of(&raw);
        self.queue
            .write_buffer(&self.camera_buffer, 0, &bytes[..LIGHT_OFFSET as usize]);
    }

    /// The deformed models' vertices on `frame` (skins and morph weights of a user scene's animation, posed on
    /// the CPU), written over their LODs' ranges of the vertex buffer before the frame's draws; nothing when no
    /// model deforms.
    pub fn write_pose(&self, scene: &Scene, frame: u32) {
        let Motion::Animated(a) = &scene.motion else {
            return;
        };
        if a.deformers.is_empty() {
            return;
        }
        let mut posed = self.posed.borrow_mut();
        let chains: Vec<&crate::geometry::lod::LodChain> =
            scene.models.iter().map(|m| &m.chain).collect();
        a.pose(
            &chains,
            frame,
            &|i| scene.instance_matrix(i, frame),
            &mut posed,
        );
        let mut scratch = self.pose_vertices.borrow_mut();
        for p in &posed.lods {
            let (m, l) = (p.model as usize, p.lod as usize);
            let rest = &scene.models[m].chain.lods[l].mesh.positions;
            scratch.clear();
            scratch.extend(
                p.positions
                    .iter()
                    .zip(&p.normals)
                    .zip(rest)
                    .map(|((p, n), r)| deformed_vertex(*p, *n, *r)),
            );
            let at = self.lods[m][l].base_vertex as u64 * std::mem::size_of::<Vertex>() as u64;
            self.queue
                .write_buffer(&self.vertex_buffer, at, bytemuck::cast_slice(&scratch));
            if let (Some(mg), false) = (&self.materials, p.tangents.is_empty()) {
                let mesh = &scene.models[m].chain.lods[l].mesh;
                let mut surface = self.pose_surface.borrow_mut();
                surface.clear();
                surface.extend((0..mesh.vertex_count()).map(|v| SurfaceVertex {
                    tangent: p.tangents[v],
                    ..surface_vertex(mesh, v)
                }));
                let at = self.lods[m][l].base_vertex as u64
                    * std::mem::size_of::<SurfaceVertex>() as u64;
                self.queue
                    .write_buffer(&mg.vertices, at, bytemuck::cast_slice(&surface));
            }
        }
    }

    /// The posed vertices (positions, normals) of `model`'s LOD `lod` on the frame last written by
    /// [`SceneGpu::write_pose`], when the model deforms.
    pub fn posed(&self, model: u32, lod: u32) -> Option<std::cell::Ref<'_, Posed>> {
        let posed = self.posed.borrow();
        posed.of(model, lod)?;
        Some(posed)
    }

    /// `--shader-work`: every shaded fragment runs `iterations` dependent ALU iterations and adds their result
    /// (in [0, 1)) with `weight`. Runs always give weight 0 (the image unchanged); a test gives 1 to see that the
    /// loop runs.
    pub fn write_work(&self, iterations: u32, weight: f32) {
        self.queue.write_buffer(
            &self.camera_buffer,
            WORK_OFFSET,
            bytemuck::cast_slice(&[iterations as f32, weight, 0.0, 0.0]),
        );
    }

    /// `--shadows on`: this frame's light matrix (every shadow map of the frame shares it); shading reads the
    /// shadow map from then on.
    pub fn write_light(&self, light_view_proj: &glam::Mat4, depth_bias: f32) {
        let mut words = [0f32; 20];
        words[..16].copy_from_slice(&light_view_proj.to_cols_array());
        words[16..].copy_from_slice(&[1.0, self.shadow_size as f32, depth_bias, 0.0]);
        self.queue.write_buffer(
            &self.camera_buffer,
            LIGHT_OFFSET,
            bytemuck::cast_slice(&words),
        );
    }

    /// The camera bind group with shadow map `map` (the placeholder's when the scene has no such map: shadows
    /// off).
    pub fn camera_group(&self, map: ShadowMap) -> &wgpu::BindGroup {
        &self.camera_groups[map.index().min(self.camera_groups.len().saturating_sub(1))]
    }

    /// A `side` x `side` R32Float texture holding `values` (row-major): the screen-space thresholds of
    /// `dither`, the visibility texture of FSI. Read with `textureLoad` (no sampler).
    pub fn create_value_texture(&self, label: &str, side: u32, values: &[f32]) -> wgpu::Texture {
        debug_assert_eq!(values.len(), (side * side) as usize);
        let texture = texture_2d(
            &self.device,
            label,
            (side, side),
            wgpu::TextureFormat::R32Float,
            wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        );
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

    /// `pass` with a fragment query in it while the quality pass counts the method's frame
    /// ([`FragmentQueries`](super::fragments::FragmentQueries)): for a pass a method begins itself.
    pub fn counted<'e>(&self, pass: wgpu::RenderPass<'e>) -> Pass<'e> {
        match &self.fragments {
            Some(f) => f.wrap(pass),
            None => Pass::plain(pass),
        }
    }

    /// Begins a pass of `view` that clears `target` to the background and its depth to 1.
    pub fn begin_clear_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        target: &RenderTarget,
        view: View,
        label: &str,
    ) -> Pass<'e> {
        let views = (&target.color_view, &target.depth_view);
        self.begin_pass(encoder, views, view, label, true)
    }

    /// A depth-only pass into `depth`, cleared to 1 (alpha-2pass's nearest surface, the shadow pass), with the
    /// camera bind group of shadow map `map` bound (the scissor is for colour passes).
    pub fn begin_depth_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        depth: &wgpu::TextureView,
        map: ShadowMap,
        label: &str,
    ) -> Pass<'e> {
        let mut pass = self.counted(encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        }));
        pass.set_bind_group(0, self.camera_group(map), &[]);
        pass
    }

    /// Begins a pass of `view` on a colour and a depth view, clearing both (`clear`) or keeping what they hold:
    /// the camera bind group of the view's shadow map bound, the view's scissor set.
    pub fn begin_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        (color, depth): (&wgpu::TextureView, &wgpu::TextureView),
        view: View,
        label: &str,
        clear: bool,
    ) -> Pass<'e> {
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
        let mut pass = self.counted(encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
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
        }));
        self.apply_view(&mut pass, view);
        pass
    }

    /// Sets `view` on a colour pass begun elsewhere than [`SceneGpu::begin_pass`] (a method's own attachments):
    /// the camera bind group of its shadow map, and its scissor.
    pub fn apply_view(&self, pass: &mut wgpu::RenderPass<'_>, view: View) {
        pass.set_bind_group(0, self.camera_group(view.shadow), &[]);
        if let Some([x, y, w, h]) = view.scissor {
            pass.set_scissor_rect(x, y, w, h);
        }
    }

    /// Draws `count` instances from absolute instance `first` of `buffer` at (model, LOD) with `pipeline`;
    /// for methods that need a pass per instance.
    #[allow(
        clippy::too_many_arguments,
        reason = "one draw's parameters, as wgpu's own draw_indexed takes them"
    )]
    pub fn draw_instances(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        buffer: &InstanceBuffer,
        first: u32,
        count: u32,
        model: u32,
        lod: u32,
        pipeline: &MeshPipelines,
    ) -> DrawStats {
        let draw = crate::gpu::draw_list::Draw {
            pipeline: 0,
            model,
            lod,
            first_instance: 0,
            instance_count: count,
        };
        let list = crate::gpu::draw_list::DrawList::of_draws(vec![draw]);
        self.draw(pass, buffer, first, &list, &[pipeline])
    }

    /// Records the draws of `list` (uploaded to `buffer` at instance `first`, see [`SceneGpu::upload_at`])
    /// into `pass`, with `pipelines[d.pipeline]` for each draw. The camera's bind group (group 0) is the pass's
    /// ([`SceneGpu::begin_pass`]); the others are the caller's to set.
    pub fn draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        buffer: &InstanceBuffer,
        first: u32,
        list: &DrawList,
        pipelines: &[&MeshPipelines],
    ) -> DrawStats {
        let mut stats = DrawStats::default();
        if list.draws.is_empty() {
            return stats;
        }
        pass.set_vertex_buffer(0, self.vertex_buffer.slice(..));
        pass.set_vertex_buffer(1, buffer.buffer.slice(..));
        pass.set_index_buffer(self.index_buffer.slice(..), wgpu::IndexFormat::Uint32);
        let flat = pipelines
            .first()
            .is_some_and(|p| p.surface == Surface::Flat);
        let Some(materials) = self.materials.as_ref().filter(|_| !flat) else {
            let mut bound: Option<PipelineIndex> = None;
            for d in &list.draws {
                if bound != Some(d.pipeline) {
                    pass.set_pipeline(pipelines[d.pipeline as usize].base());
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
            return stats;
        };
        // Part by part, the opaque and cut-out parts of every draw first, then the blended ones (in the list's
        // order, over what the opaque ones left), as an engine draws its transparent queue after its opaque one.
        pass.set_vertex_buffer(3, materials.vertices.slice(..));
        let mut bound: Option<(PipelineIndex, MaterialClass)> = None;
        let mut bound_material: Option<u32> = None;
        for blended in [false, true] {
            for d in &list.draws {
                let r = self.lods[d.model as usize][d.lod as usize];
                let (p0, n) = r.parts;
                for part in &self.parts[p0 as usize..(p0 + n) as usize] {
                    if part.class.blends() != blended {
                        continue;
                    }
                    let Some(pipeline) = pipelines[d.pipeline as usize].get(part.class) else {
                        continue;
                    };
                    if bound != Some((d.pipeline, part.class)) {
                        pass.set_pipeline(pipeline);
                        bound = Some((d.pipeline, part.class));
                    }
                    if bound_material != Some(part.material) {
                        pass.set_bind_group(
                            MATERIAL_GROUP,
                            &materials.groups[part.material as usize],
                            &[],
                        );
                        bound_material = Some(part.material);
                    }
                    pass.draw_indexed(
                        part.first_index..part.first_index + part.index_count,
                        r.base_vertex,
                        first + d.first_instance..first + d.first_instance + d.instance_count,
                    );
                    stats.triangles += part.index_count as u64 / 3 * d.instance_count as u64;
                    stats.draw_calls += 1;
                }
            }
        }
        stats
    }
}

/// The scene's meshes laid end to end on the CPU, as [`SceneGpu`] uploads them: every model's LODs, then every
/// seam's meshes.
struct SceneGeometry {
    vertices: Vec<Vertex>,
    indices: Vec<u32>,
    lods: Vec<Vec<LodRange>>,
    seam_base: u32,
    parts: Vec<PartRange>,
    /// One per vertex of the models' LODs (PBR surface only).
    surface_vertices: Vec<SurfaceVertex>,
}

impl SceneGeometry {
    /// Gathers the models' LODs (with their material parts and surface vertices when `pbr`; the `deformed`
    /// models' rest positions in `aux`), then the unified scene's seams.
    fn gather(scene: &Scene, pbr: bool, deformed: &[u32]) -> Result<SceneGeometry> {
        let mut g = SceneGeometry {
            vertices: Vec::new(),
            indices: Vec::new(),
            lods: Vec::new(),
            seam_base: 0,
            parts: Vec::new(),
            surface_vertices: Vec::new(),
        };
        for (mi, model) in scene.models.iter().enumerate() {
            let mut ranges = Vec::new();
            for lod in &model.chain.lods {
                ranges.push(g.push_lod(scene, &lod.mesh, pbr, deformed.contains(&(mi as u32)))?);
            }
            g.lods.push(ranges);
        }
        g.seam_base = g.lods.len() as u32;
        for seam in scene.unified.iter().flat_map(|u| &u.seams) {
            let mut ranges = Vec::new();
            for m in &seam.meshes {
                ranges.push(g.push_seam_mesh(m)?);
            }
            g.lods.push(ranges);
        }
        Ok(g)
    }

    /// The base vertex of the next mesh appended.
    fn next_base_vertex(&self) -> Result<i32> {
        i32::try_from(self.vertices.len())
            .map_err(|_| Error::Gpu("scene has too many vertices".into()))
    }

    /// Appends one LOD mesh of a model (and its parts and surface vertices when `pbr`), returning its range.
    fn push_lod(
        &mut self,
        scene: &Scene,
        m: &crate::geometry::mesh::Mesh,
        pbr: bool,
        deformed: bool,
    ) -> Result<LodRange> {
        let first_part = self.parts.len() as u32;
        if pbr {
            for p in &m.parts {
                let material = &scene.materials.materials[p.material as usize];
                self.parts.push(PartRange {
                    first_index: self.indices.len() as u32 + p.first_index,
                    index_count: p.index_count,
                    material: p.material,
                    class: MaterialClass::new(
                        !material.double_sided,
                        material.alpha == crate::geometry::material::AlphaMode::Blend,
                    ),
                });
            }
            self.surface_vertices
                .extend((0..m.vertex_count()).map(|v| surface_vertex(m, v)));
        }
        let range = LodRange {
            base_vertex: self.next_base_vertex()?,
            first_index: self.indices.len() as u32,
            index_count: m.indices.len() as u32,
            parts: (first_part, self.parts.len() as u32 - first_part),
        };
        if deformed {
            self.vertices.extend(
                m.positions
                    .iter()
                    .zip(&m.normals)
                    .map(|(p, n)| deformed_vertex(*p, *n, *p)),
            );
        } else {
            self.vertices
                .extend(
                    m.positions
                        .iter()
                        .zip(&m.normals)
                        .zip(&m.aux)
                        .map(|((p, n), a)| Vertex {
                            position: *p,
                            normal: *n,
                            aux: *a,
                        }),
                );
        }
        self.indices.extend_from_slice(&m.indices);
        Ok(range)
    }

    /// Appends one mesh of a seam (no parts, `aux` zero), returning its range.
    fn push_seam_mesh(&mut self, m: &crate::scene::model::SeamMesh) -> Result<LodRange> {
        let range = LodRange {
            base_vertex: self.next_base_vertex()?,
            first_index: self.indices.len() as u32,
            index_count: m.indices.len() as u32,
            parts: (0, 0),
        };
        self.vertices
            .extend(m.positions.iter().zip(&m.normals).map(|(p, n)| Vertex {
                position: *p,
                normal: *n,
                aux: [0.0; 4],
            }));
        self.indices.extend_from_slice(&m.indices);
        Ok(range)
    }

    /// The vertex buffer (writable when some model deforms) and the index buffer.
    fn buffers(&self, device: &wgpu::Device, deforms: bool) -> (wgpu::Buffer, wgpu::Buffer) {
        let vertex_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("scene vertices"),
            contents: bytemuck::cast_slice(&self.vertices),
            usage: if deforms {
                wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST
            } else {
                wgpu::BufferUsages::VERTEX
            },
        });
        let index_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("scene indices"),
            contents: bytemuck::cast_slice(&self.indices),
            usage: wgpu::BufferUsages::INDEX,
        });
        (vertex_buffer, index_buffer)
    }
}

/// The camera uniform buffer ([`CameraRaw`]).
fn camera_buffer(device: &wgpu::Device) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("camera uniform"),
        size: std::mem::size_of::<CameraRaw>() as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// Group 0's layout: the camera uniform, a shadow map and its comparison sampler.
fn camera_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
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
        ],
    })
}

/// The shadow maps: the 1x1 placeholder, then `lit` maps of `shadow_size` texels a side under `--shadows on`.
fn shadow_maps(
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
fn shadow_sampler(device: &wgpu::Device) -> wgpu::Sampler {
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
fn camera_groups(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    camera_buffer: &wgpu::Buffer,
    shadow_views: &[wgpu::TextureView],
    shadow_sampler: &wgpu::Sampler,
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
                ],
            })
        })
        .collect()
}

/// The mesh shader with the scene's `surface`, and (with the PBR surface) the flat one besides, built first.
fn mesh_shaders(
    device: &wgpu::Device,
    surface: Surface,
) -> (wgpu::ShaderModule, Option<wgpu::ShaderModule>) {
    let flat_shader = (surface == Surface::Pbr).then(|| {
        device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("surface/flat.wgsl + mesh.wgsl"),
            source: wgpu::ShaderSource::Wgsl(mesh_wgsl(Surface::Flat).into()),
        })
    });
    let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(match surface {
            Surface::Flat => "surface/flat.wgsl + mesh.wgsl",
            Surface::Pbr => "surface/pbr.wgsl + mesh.wgsl",
        }),
        source: wgpu::ShaderSource::Wgsl(mesh_wgsl(surface).into()),
    });
    (shader, flat_shader)
}

/// Whether the scene has alpha-tested geometry: masked materials, or leaf cards.
fn needs_alpha_test(scene: &Scene) -> bool {
    scene.materials.any_mask()
        || scene.models.iter().any(|m| {
            m.chain.lods.iter().any(|l| {
                l.mesh.aux.iter().any(|a| {
                    a[2] == crate::geometry::mesh::AUX_LEAF
                        || a[2] == crate::geometry::mesh::AUX_LEAF_CLUSTER
                })
            })
        })
}

/// The distinct material classes of the parts, sorted; the plain class alone when there are none.
fn material_classes(parts: &[PartRange]) -> Vec<MaterialClass> {
    let mut classes: Vec<MaterialClass> = parts.iter().map(|p| p.class).collect();
    classes.sort();
    classes.dedup();
    if classes.is_empty() {
        classes.push(MaterialClass::PLAIN);
    }
    classes
}
