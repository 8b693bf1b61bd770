//! A camera that draws a scene's models one at a time, alone, at the origin, from any direction and distance,
//! and the change a switch makes to its frame.

use crate::error::Result;
use crate::gpu::scene_gpu::ShadowMap;
use crate::gpu::{
    DrawList, GpuContext, InstanceRaw, RenderTarget, SceneGpu, TextureReadback, View,
};
use crate::measure::metrics::rms_difference_parts;
use crate::scene::{Camera, Scene};
use glam::{Mat4, Quat, Vec3};

/// What a switch does to a model's frame: lodpop between the two LODs' frames and its coverage and shading
/// parts, and the two frames (RGBA8).
pub struct Switched {
    pub lodpop: f64,
    pub coverage: f64,
    pub shading: f64,
    pub frames: [Vec<u8>; 2],
}

/// Scores two frames (RGBA8): ColorVideoVDP's JOD under a JOD budget.
pub type FrameScore<'f> = &'f mut dyn FnMut(&[u8], &[u8]) -> Result<f64>;

/// Draws a scene's models one at a time, alone, at the origin, from any direction and distance.
pub struct ModelCamera<'a> {
    pub(super) ctx: &'a GpuContext,
    pub scene: &'a Scene,
    pub(super) gpu: SceneGpu,
    pub(super) target: RenderTarget,
    pub(super) readback: TextureReadback,
    pub(super) list: DrawList,
    pub(super) buffer: crate::gpu::InstanceBuffer,
    pub(super) background: [u8; 3],
}

impl<'a> ModelCamera<'a> {
    pub fn new(ctx: &'a GpuContext, scene: &'a Scene) -> Result<ModelCamera<'a>> {
        ctx.check_viewport(scene.width, scene.height)?;
        let gpu = SceneGpu::new(ctx, scene)?;
        let (w, h) = (scene.width, scene.height);
        Ok(ModelCamera {
            ctx,
            scene,
            target: RenderTarget::new(&ctx.device, "tune target", w, h),
            readback: TextureReadback::color(&ctx.device, "tune read-back", w, h),
            list: DrawList::default(),
            buffer: gpu.create_instance_buffer("tune instance", 1),
            background: gpu.background_bytes(ctx)?,
            gpu,
        })
    }

    /// The device's bytes of the clear colour.
    pub fn background(&self) -> [u8; 3] {
        self.background
    }

    /// Model `model` at LOD `lod`, its bounding-sphere centre at the origin turned by `rotation` (its first
    /// instance's), seen from `direction` at `distance`: the frame's RGBA bytes.
    pub fn draw(
        &mut self,
        model: u32,
        lod: u32,
        rotation: Quat,
        direction: Vec3,
        distance: f32,
    ) -> Result<Vec<u8>> {
        let m = &self.scene.models[model as usize];
        let eye = direction * distance;
        let up = if direction.y.abs() > 0.99 {
            Vec3::Z
        } else {
            Vec3::Y
        };
        let aspect = self.scene.width as f32 / self.scene.height as f32;
        let near = (distance - 1.5 * m.radius).max(distance * 1e-3);
        let camera = Camera {
            eye,
            view: Mat4::look_at_rh(eye, Vec3::ZERO, up),
            proj: Mat4::perspective_rh(self.scene.fov_y, aspect, near, distance + 1.5 * m.radius),
        };
        self.gpu.write_camera(&camera);
        let matrix = Mat4::from_quat(rotation)
            * Mat4::from_scale(Vec3::splat(m.scale))
            * Mat4::from_translation(-m.center);
        let [r, g, b] = m.color_of(lod);
        self.list.clear();
        self.list.push(
            0,
            model,
            lod,
            InstanceRaw::new(&matrix, [r, g, b, 0.0], [0.0, 1.0, lod as f32, 0.0]),
        );
        self.list.build();
        self.gpu.upload(&self.buffer, &self.list);
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = self.gpu.begin_clear_pass(
                &mut encoder,
                &self.target,
                View::lit_by(ShadowMap::NONE),
                "tune pass",
            );
            self.gpu.draw(
                &mut pass,
                &self.buffer,
                0,
                &self.list,
                &[&self.gpu.opaque_pipeline],
            );
        }
        self.readback.encode_copy(&mut encoder, &self.target);
        self.gpu.queue.submit([encoder.finish()]);
        let px = self.readback.read(self.ctx)?;
        self.ctx.check_errors()?;
        Ok(px)
    }

    /// What switching from LOD `lod` to LOD `lod + 1` of `model` does to its frame from `direction` at
    /// `distance`.
    pub fn switch_at(
        &mut self,
        model: u32,
        lod: u32,
        rotation: Quat,
        direction: Vec3,
        distance: f32,
    ) -> Result<Switched> {
        let a = self.draw(model, lod, rotation, direction, distance)?;
        let b = self.draw(model, lod + 1, rotation, direction, distance)?;
        let (lodpop, coverage, shading) = rms_difference_parts(&a, &b, self.background);
        Ok(Switched {
            lodpop,
            coverage,
            shading,
            frames: [a, b],
        })
    }
}
