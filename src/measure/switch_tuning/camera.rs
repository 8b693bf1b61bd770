//! A camera that draws a scene's models one at a time, alone, at the origin, from any direction and distance,
//! and the change a switch makes to its frame.

use crate::error::Result;
use crate::gpu::scene_gpu::ShadowMap;
use crate::gpu::{
    DrawList, GpuContext, InstanceRaw, RenderTarget, SceneGpu, TextureReadback, View,
};
use crate::measure::metrics::rms_difference_parts_over;
use crate::measure::switch_tuning::reset::RectReset;
use crate::scene::{Camera, Model, Scene};
use glam::{Mat4, Quat, Vec3};

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
    /// Per model, the radius around its bounding sphere's centre (world units) that holds every vertex of
    /// every LOD of it: what [`ModelCamera::crop`] bounds.
    pub(super) reach: Vec<f32>,
    /// What puts a crop back as a clear leaves it before each [`ModelCamera::draw_rect`], instead of clearing
    /// the whole target; None where it was found not to write the clear's bytes (the whole target is cleared).
    pub(super) reset: Option<RectReset>,
}

/// Pixels the crop adds on every side of the projected sphere (beyond its relative margin).
const CROP_PAD: f64 = 2.0;

impl<'a> ModelCamera<'a> {
    pub fn new(ctx: &'a GpuContext, scene: &'a Scene) -> Result<ModelCamera<'a>> {
        ctx.check_viewport(scene.width, scene.height)?;
        let gpu = SceneGpu::new(ctx, scene)?;
        let (w, h) = (scene.width, scene.height);
        let mut camera = ModelCamera {
            ctx,
            scene,
            target: RenderTarget::new(&ctx.device, "tune target", w, h),
            readback: TextureReadback::color(&ctx.device, "tune read-back", w, h),
            list: DrawList::default(),
            buffer: gpu.create_instance_buffer("tune instance", 1),
            background: gpu.background_bytes(ctx)?,
            reach: scene.models.iter().map(reach).collect(),
            reset: None,
            gpu,
        };
        camera.reset = camera.rect_reset()?;
        Ok(camera)
    }

    /// A [`RectReset`] to the bytes and depth a clear of a target leaves, if it writes them: checked on a
    /// one-pixel target (the reset's pipeline is the target's size's), written over first with other bytes and
    /// depth.
    fn rect_reset(&self) -> Result<Option<RectReset>> {
        let device = &self.gpu.device;
        let probe = RenderTarget::new(device, "tune reset probe", 1, 1);
        let (clear, depth) = self.probe_pixel(&probe, |encoder, target| {
            let view = View::lit_by(ShadowMap::NONE);
            drop(
                self.gpu
                    .begin_clear_pass(encoder, target, view, "tune clear probe"),
            );
        })?;
        let (Ok([r, g, b, a]), Ok(d)) = (<[u8; 4]>::try_from(&clear[..]), depth[..].try_into())
        else {
            return Ok(None);
        };
        if f32::from_le_bytes(d) != 1.0 {
            return Ok(None);
        }
        let pixel = [0, 0, 1, 1];
        let other = RectReset::new(device, [!r, !g, !b, !a], 0.25);
        let reset = RectReset::new(device, [r, g, b, a], 1.0);
        let painted = self.probe_pixel(&probe, |encoder, t| other.encode(encoder, t, pixel))?;
        let written = self.probe_pixel(&probe, |encoder, t| reset.encode(encoder, t, pixel))?;
        self.ctx.check_errors()?;
        let works = painted.0 != clear && painted.1 != depth && written == (clear, depth);
        Ok(works.then_some(reset))
    }

    /// The colour (RGBA bytes) and the depth (an f32's bytes) of a one-pixel target after `encode`.
    fn probe_pixel(
        &self,
        target: &RenderTarget,
        encode: impl FnOnce(&mut wgpu::CommandEncoder, &RenderTarget),
    ) -> Result<(Vec<u8>, Vec<u8>)> {
        let device = &self.gpu.device;
        let color = TextureReadback::color(device, "tune colour probe", 1, 1);
        let depth = TextureReadback::new(device, "tune depth probe", 1, 1, 4);
        let mut encoder = device.create_command_encoder(&Default::default());
        encode(&mut encoder, target);
        color.encode_copy(&mut encoder, target);
        let aspect = wgpu::TextureAspect::DepthOnly;
        depth.encode_copy_plane(&mut encoder, &target.depth, aspect);
        self.gpu.queue.submit([encoder.finish()]);
        Ok((color.read(self.ctx)?, depth.read(self.ctx)?))
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
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        let view = View::lit_by(ShadowMap::NONE);
        self.encode_draw(
            &mut encoder,
            (model, lod),
            rotation,
            direction,
            distance,
            view,
            true,
        );
        self.readback.encode_copy(&mut encoder, &self.target);
        self.gpu.queue.submit([encoder.finish()]);
        let px = self.readback.read(self.ctx)?;
        self.ctx.check_errors()?;
        Ok(px)
    }

    /// [`ModelCamera::draw`] within `rect`, `[x, y, width, height]` (drawn within it, the frame's clear
    /// colour elsewhere): the rectangle's RGBA bytes, as the whole frame's are there. The rectangle is put back
    /// as a clear leaves it ([`RectReset`]) and drawn within; the rest of the target is neither cleared nor read.
    #[allow(
        clippy::too_many_arguments,
        reason = "draw's parameters and the rectangle"
    )]
    pub fn draw_rect(
        &mut self,
        model: u32,
        lod: u32,
        rotation: Quat,
        direction: Vec3,
        distance: f32,
        rect: [u32; 4],
    ) -> Result<Vec<u8>> {
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        if let Some(reset) = &self.reset {
            reset.encode(&mut encoder, &self.target, rect);
        }
        let view = View::lit_by(ShadowMap::NONE).scissored(rect);
        let clear = self.reset.is_none();
        self.encode_draw(
            &mut encoder,
            (model, lod),
            rotation,
            direction,
            distance,
            view,
            clear,
        );
        self.readback
            .encode_copy_rect(&mut encoder, &self.target, rect);
        self.gpu.queue.submit([encoder.finish()]);
        let px = self.readback.read_rect(self.ctx, rect)?;
        self.ctx.check_errors()?;
        Ok(px)
    }

    /// The pixels, `[x, y, width, height]`, outside which model `model` drawn at `distance` (from any direction,
    /// at any LOD) leaves the frame its clear colour: the bounding rectangle of its reach's projection (a sphere
    /// on the view axis projects to a disc about the frame's centre), a margin added; the whole frame when the
    /// camera is within its reach.
    pub fn crop(&self, model: u32, distance: f32) -> [u32; 4] {
        let (w, h) = (self.scene.width, self.scene.height);
        let r = f64::from(self.reach[model as usize]) * 1.001;
        let d = f64::from(distance);
        if d <= r * 1.001 {
            return [0, 0, w, h];
        }
        // Tangent of the angle the sphere subtends at the camera, over the frame's half-height's.
        let tan = r / (d * d - r * r).sqrt() / (f64::from(self.scene.fov_y) * 0.5).tan();
        let half = tan * f64::from(h) * 0.5 * 1.001 + CROP_PAD;
        // The disc's centre is the frame's: lo < n / 2 < hi.
        let span = |n: u32| {
            let c = f64::from(n) * 0.5;
            let lo = (c - half).floor().max(0.0) as u32;
            let hi = ((c + half).ceil() as u32).min(n);
            (lo, hi)
        };
        let ((x0, x1), (y0, y1)) = (span(w), span(h));
        [x0, y0, x1 - x0, y1 - y0]
    }

    /// Records the draw of [`ModelCamera::draw`] into `encoder`, its pass of `view`, the target cleared first
    /// (`clear`) or as it is.
    #[allow(
        clippy::too_many_arguments,
        reason = "draw's parameters, the encoder and the pass's view"
    )]
    fn encode_draw(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        (model, lod): (u32, u32),
        rotation: Quat,
        direction: Vec3,
        distance: f32,
        view: View,
        clear: bool,
    ) {
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
        let views = (&self.target.color_view, &self.target.depth_view);
        let mut pass = self
            .gpu
            .begin_pass(encoder, views, view, "tune pass", clear);
        self.gpu.draw(
            &mut pass,
            &self.buffer,
            0,
            &self.list,
            &[&self.gpu.opaque_pipeline],
        );
    }

    /// lodpop and its coverage and shading parts between two crops (both [`ModelCamera::crop`]'s rectangle,
    /// [`ModelCamera::draw_rect`]) of this camera's frames: the whole frames' figures.
    pub fn pop_of(&self, a: &[u8], b: &[u8]) -> (f64, f64, f64) {
        let pixels = self.scene.width as usize * self.scene.height as usize;
        rms_difference_parts_over(a, b, self.background, pixels)
    }
}

/// The radius around `m`'s bounding sphere's centre (world units) that holds its bounding sphere and every
/// vertex of every LOD of it, as [`ModelCamera`] places it (scaled by its scale about its centre).
fn reach(m: &Model) -> f32 {
    let c = m.center.as_dvec3();
    let farthest = m
        .chain
        .lods
        .iter()
        .flat_map(|l| &l.mesh.positions)
        .map(|&p| (Vec3::from(p).as_dvec3() - c).length())
        .fold(0.0f64, f64::max);
    (farthest * f64::from(m.scale)).max(f64::from(m.radius)) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::{Cli, Command};
    use crate::measure::metrics::rms_difference_parts;
    use crate::scene::{SceneConfig, SceneDef, SceneKind};
    use clap::Parser;

    /// The rectangle `[x, y, w, h]` of a frame `width` pixels wide, and the frame with it cut out.
    fn split(frame: &[u8], width: u32, [x, y, w, h]: [u32; 4]) -> (Vec<u8>, Vec<u8>) {
        let (mut inside, mut outside) = (Vec::new(), Vec::new());
        for (i, px) in frame.chunks_exact(4).enumerate() {
            let (px_x, px_y) = (i as u32 % width, i as u32 / width);
            let within = (x..x + w).contains(&px_x) && (y..y + h).contains(&px_y);
            if within { &mut inside } else { &mut outside }.extend_from_slice(px);
        }
        (inside, outside)
    }

    /// A crop is the whole frame there and the whole frame is the clear colour elsewhere, whatever the target
    /// held before (the rectangle is put back as a clear leaves it), and lodpop and its parts over two crops are
    /// the whole frames', bit for bit: with the camera within the model's reach (the crop the whole frame), near
    /// and far, from several directions.
    #[test]
    fn a_crop_is_the_whole_frame_there() {
        let argv = ["lodbench", "describe", "--scene", "bunny-sweep"];
        let Command::Describe(d) = Cli::try_parse_from(argv).unwrap().command else {
            unreachable!()
        };
        let mut cfg = SceneConfig::from_args(&d.scene_args).unwrap();
        (cfg.width, cfg.height) = (Some(160), Some(120));
        let scene = SceneDef::new(SceneKind::BunnySweep, &cfg)
            .unwrap()
            .instantiate(1);
        let ctx = GpuContext::new(None).unwrap();
        let mut camera = ModelCamera::new(&ctx, &scene).unwrap();
        assert!(camera.reset.is_some(), "the reset writes the clear's bytes");
        let (r, rot) = (camera.reach[0], Quat::from_rotation_y(0.3));
        let bg = camera.background();
        let aside = Vec3::new(0.6, 0.0, 0.8);
        for (dir, d) in [
            (Vec3::Z, r * 0.8),
            (aside, r * 2.5),
            (Vec3::Y, r * 9.0),
            (aside, r * 30.0),
        ] {
            let rect = camera.crop(0, d);
            let full = [0, 1].map(|l| camera.draw(0, l, rot, dir, d).unwrap());
            let crops = [1, 0].map(|l| camera.draw_rect(0, l, rot, dir, d, rect).unwrap());
            for (frame, crop) in full.iter().zip(crops.iter().rev()) {
                let (inside, outside) = split(frame, 160, rect);
                assert_eq!(&inside, crop, "{dir} {d} {rect:?}");
                assert!(
                    outside.chunks_exact(4).all(|p| p[..3] == bg),
                    "{dir} {d} {rect:?}"
                );
            }
            assert!(crops[0] != crops[1] || d > r * 20.0, "the LODs differ: {d}");
            let parts = rms_difference_parts(&full[0], &full[1], bg);
            assert_eq!(camera.pop_of(&crops[1], &crops[0]), parts, "{d}");
        }
        assert_eq!(camera.crop(0, r * 0.8), [0, 0, 160, 120]);
        assert!(camera.crop(0, r * 30.0)[2] < 20);
    }
}
