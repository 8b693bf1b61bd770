//! What a frame writes to the scene on the GPU before its draws: the camera (and its shadow map's matrix and
//! bias), the light, `--shader-work`'s constants, the deformed models' pose; and the camera bind group a pass binds.

use crate::gpu::pipelines::{SurfaceVertex, Vertex};
use crate::gpu::scene_gpu::build::SceneGpu;
use crate::gpu::scene_gpu::camera::{CameraRaw, IMPOSTOR_EYE_OFFSET, LIGHT_OFFSET, WORK_OFFSET};
use crate::gpu::scene_gpu::geometry::surface_vertex;
use crate::gpu::scene_gpu::pose::{deformed_vertex, PoseState};
use crate::gpu::scene_gpu::view::ShadowMap;
use crate::gpu::targets::texture_2d;
use crate::scene::animated::Posed;
use crate::scene::model::{AMBIENT, LIGHT_DIR};
use crate::scene::{Camera, Motion, Scene};
use glam::Vec3;

impl SceneGpu {
    pub fn write_camera(&self, camera: &Camera) {
        let l = Vec3::from(LIGHT_DIR).normalize();
        let raw = CameraRaw {
            view_proj: camera.view_proj().to_cols_array_2d(),
            eye: camera.eye.extend(1.0).to_array(),
            light: [l.x, l.y, l.z, AMBIENT],
            light_view_proj: [[0.0; 4]; 4],
            shadow: [0.0; 4],
            work: [0.0; 4],
            impostor_eye: [0.0; 4],
        };
        let bytes = bytemuck::bytes_of(&raw);
        self.queue
            .write_buffer(&self.camera.buffer, 0, &bytes[..LIGHT_OFFSET as usize]);
        self.write_impostor_eye(camera.eye);
    }

    /// `--impostor`: the eye the impostors select their frames by (the camera's, written by
    /// [`SceneGpu::write_camera`]; view_pop's counterfactual writes the previous frame's).
    pub fn write_impostor_eye(&self, eye: Vec3) {
        self.queue.write_buffer(
            &self.camera.buffer,
            IMPOSTOR_EYE_OFFSET,
            bytemuck::cast_slice(&eye.extend(1.0).to_array()),
        );
    }

    /// `--shader-work`: every shaded fragment runs `iterations` dependent ALU iterations and adds their result
    /// (in [0, 1)) with `weight`. Runs always give weight 0 (the image unchanged); a test gives 1 to see that the
    /// loop runs.
    pub fn write_work(&self, iterations: u32, weight: f32) {
        self.queue.write_buffer(
            &self.camera.buffer,
            WORK_OFFSET,
            bytemuck::cast_slice(&[iterations as f32, weight, 0.0, 0.0]),
        );
    }

    /// `--shadows on`: this frame's light matrix (every shadow map of the frame shares it); shading reads the
    /// shadow map from then on.
    pub fn write_light(&self, light_view_proj: &glam::Mat4, depth_bias: f32) {
        let mut words = [0f32; 20];
        words[..16].copy_from_slice(&light_view_proj.to_cols_array());
        words[16..].copy_from_slice(&[1.0, self.shadows.size as f32, depth_bias, 0.0]);
        self.queue.write_buffer(
            &self.camera.buffer,
            LIGHT_OFFSET,
            bytemuck::cast_slice(&words),
        );
    }

    /// The camera bind group with shadow map `map` (the placeholder's when the scene has no such map: shadows
    /// off).
    pub fn camera_group(&self, map: ShadowMap) -> &wgpu::BindGroup {
        &self.camera.groups[map.index().min(self.camera.groups.len().saturating_sub(1))]
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
}

impl SceneGpu {
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
        let mut state = self.pose.borrow_mut();
        let PoseState {
            posed,
            vertices: scratch,
            surface,
        } = &mut *state;
        let chains: Vec<&crate::geometry::lod::LodChain> =
            scene.models.iter().map(|m| &m.chain).collect();
        a.pose(&chains, frame, &|i| scene.instance_matrix(i, frame), posed);
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
                .write_buffer(&self.vertex_buffer, at, bytemuck::cast_slice(scratch));
            if let (Some(mg), false) = (&self.materials, p.tangents.is_empty()) {
                let mesh = &scene.models[m].chain.lods[l].mesh;
                surface.clear();
                surface.extend((0..mesh.vertex_count()).map(|v| SurfaceVertex {
                    tangent: p.tangents[v],
                    ..surface_vertex(mesh, v)
                }));
                let at = self.lods[m][l].base_vertex as u64
                    * std::mem::size_of::<SurfaceVertex>() as u64;
                self.queue
                    .write_buffer(&mg.vertices, at, bytemuck::cast_slice(surface));
            }
        }
    }

    /// The posed vertices (positions, normals) of `model`'s LOD `lod` on the frame last written by
    /// [`SceneGpu::write_pose`], when the model deforms.
    pub fn posed(&self, model: u32, lod: u32) -> Option<std::cell::Ref<'_, Posed>> {
        let state = self.pose.borrow();
        state.posed.of(model, lod)?;
        Some(std::cell::Ref::map(state, |s| &s.posed))
    }
}
