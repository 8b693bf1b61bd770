//! The scene on the GPU, built: its struct, the constructor in named steps (geometry, camera, shadow maps,
//! shaders, pipelines), the pipelines' context and the instance uploads.

use crate::error::Result;
use crate::gpu::context::GpuContext;
use crate::gpu::draw_list::DrawList;
use crate::gpu::impostor_atlas::{Baker, ImpostorAtlas};
use crate::gpu::instances::{InstanceBuffer, UploadCounters};
use crate::gpu::pipelines::{
    mesh_pipelines, mesh_wgsl, MaterialClass, MeshPipeline, MeshPipelines, PipelineContext, Surface,
};
use crate::gpu::scene_gpu::camera::{
    camera_buffer, camera_groups, camera_layout, shadow_maps, shadow_sampler, CameraGpu,
    ShadowMapsGpu,
};
use crate::gpu::scene_gpu::geometry::{material_classes, LodRange, PartRange, SceneGeometry};
use crate::gpu::scene_gpu::pose::{deformed_models, PoseState};
use crate::gpu::scene_gpu::view::{ShadowMap, View};
use crate::gpu::surface::MaterialsGpu;
use crate::gpu::targets::RenderTarget;
use crate::scene::Scene;

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
    /// The camera uniform and its bind groups.
    pub camera: CameraGpu,
    /// The shadow maps (`--shadows on`; only the placeholder otherwise).
    pub shadows: ShadowMapsGpu,
    /// The mesh shader and what every mesh pipeline of the scene is built with.
    pub shading: Shading,
    /// The material parts of every LOD ([`LodRange::parts`]).
    pub parts: Vec<PartRange>,
    /// The materials' textures, samplers and bind groups, and the surface vertex buffer (PBR surface).
    pub materials: Option<MaterialsGpu>,
    pub opaque_pipeline: MeshPipelines,
    pub uploads: UploadCounters,
    /// The deformed models' pose as [`SceneGpu::write_pose`] last wrote it, with its scratch.
    pub(super) pose: std::cell::RefCell<PoseState>,
    /// Counts the fragments of the passes begun while the quality pass counts a method's frame (None where the
    /// device has no pipeline statistics queries).
    pub fragments: Option<crate::gpu::fragments::FragmentQueries>,
    /// `--impostor`'s atlases, baked (placeholders without impostors).
    pub impostors: ImpostorAtlas,
}

/// The mesh shader and what every mesh pipeline of a scene is built with.
pub struct Shading {
    pub shader: wgpu::ShaderModule,
    /// The flat surface's shader in a scene of materials ([`SceneGpu::flat_pipeline`]).
    pub flat_shader: Option<wgpu::ShaderModule>,
    /// What the mesh shader's surface is: flat, or the scene's materials.
    pub surface: Surface,
    /// The classes of the parts (the plain class alone with the flat surface), each mesh pipeline's variants.
    pub classes: Vec<MaterialClass>,
    /// The scene has alpha-tested geometry: every mesh pipeline is built with `ALPHA_TEST` on.
    pub alpha_test: bool,
    /// Faces every mesh pipeline culls where its own descriptor says None: back faces in the unified scenes
    /// (closed meshes and heightfields wound outwards, their seams wound with them), so a crack between blocks
    /// shows what lies behind the surface, as in an engine that culls a model's inside, and `crack_px` sees it;
    /// none elsewhere.
    pub cull: Option<wgpu::Face>,
}

/// The mesh shader with the scene's `surface`, and (with the PBR surface) the flat one besides, built first.
pub(super) fn mesh_shaders(
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

/// Whether the scene has alpha-tested geometry: masked materials, leaf cards, or impostors' cards.
pub(super) fn needs_alpha_test(scene: &Scene) -> bool {
    scene.impostor.is_some()
        || scene.materials.any_mask()
        || scene.models.iter().any(|m| {
            m.chain.lods.iter().any(|l| {
                l.mesh.aux.iter().any(|a| {
                    a[2] == crate::geometry::mesh::AUX_LEAF
                        || a[2] == crate::geometry::mesh::AUX_LEAF_CLUSTER
                })
            })
        })
}

impl SceneGpu {
    /// What every mesh pipeline of the scene is built over.
    pub fn pipeline_context(&self) -> PipelineContext<'_> {
        PipelineContext {
            device: &self.device,
            shader: &self.shading.shader,
            camera_layout: &self.camera.layout,
            alpha_test: self.shading.alpha_test,
            impostors: self.impostors.impostor.is_some(),
            surface: self.shading.surface,
            material_layout: self.materials.as_ref().map(|m| &m.layout),
            classes: &self.shading.classes,
            cull: self.shading.cull,
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
                shader: self
                    .shading
                    .flat_shader
                    .as_ref()
                    .unwrap_or(&self.shading.shader),
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
        let impostors = ImpostorAtlas::new(device, &ctx.queue, scene)?;
        let shadows = (&shadow_views[..], &shadow_sampler);
        let camera_groups =
            camera_groups(device, &camera_layout, &camera_buffer, shadows, &impostors);
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
                impostors: impostors.impostor.is_some(),
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
            camera: CameraGpu {
                buffer: camera_buffer,
                layout: camera_layout,
                groups: camera_groups,
            },
            shadows: ShadowMapsGpu {
                views: shadow_views,
                maps: shadow_maps,
                size: shadow_size,
            },
            shading: Shading {
                shader,
                flat_shader,
                surface,
                classes,
                alpha_test,
                cull,
            },
            parts: geometry.parts,
            materials,
            opaque_pipeline,
            uploads: UploadCounters::default(),
            pose: Default::default(),
            fragments: crate::gpu::fragments::FragmentQueries::new(device),
            impostors,
        };
        gpu.write_work(scene.shader_work, scene.shader_work_weight);
        gpu.bake_impostors(ctx)?;
        Ok(gpu)
    }

    /// `--impostor`: bakes the atlases (none without), through a camera group of its own over placeholders.
    fn bake_impostors(&self, ctx: &GpuContext) -> Result<()> {
        if self.impostors.impostor.is_none() {
            return Ok(());
        }
        let device = &self.device;
        let empty = ImpostorAtlas::empty(device, &self.queue);
        let buffer = camera_buffer(device);
        let views = [self.shadows.views[0].clone()];
        let sampler = shadow_sampler(device);
        let groups = camera_groups(
            device,
            &self.camera.layout,
            &buffer,
            (&views, &sampler),
            &empty,
        );
        let pipelines = crate::gpu::pipelines::bake_pipelines(&self.pipeline_context());
        let instance = self.create_instance_buffer("impostor bake instance", 1);
        let baker = Baker {
            device,
            queue: &self.queue,
            pipelines: &pipelines,
            camera_group: &groups[0],
            camera_buffer: &buffer,
            instance: &instance,
        };
        self.impostors.bake(&baker, &|pass, list| {
            self.draw(pass, &instance, 0, list, &[&pipelines]);
        })?;
        ctx.wait_idle()
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
}
