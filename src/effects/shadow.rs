//! `--shadows on`: one directional shadow map, so LOD transitions are measured with the shadows engines draw
//! (Godot issue 59538: during a fade the coarse LOD shadows the fine one; Godot issue 39530: directional shadows
//! break with dithered fades).
//!
//! The CPU half: the settings, what each instance casts ([`Caster`]) and the light's matrix. The light is the
//! scene's own (`gpu::LIGHT_DIR`), orthographic, fitted every frame to the bounding spheres of the instances
//! that cast (every instance but the bunny scenes' ground, which only receives). The GPU half
//! (`gpu/shadow.rs`, `shaders/mesh.wgsl`) renders the casters' depth from the light and shades every
//! fragment of every method with a 3x3 percentage-closer filter of 2x2 bilinear depth comparisons (16 texels),
//! a constant depth bias of [`DEPTH_BIAS`].
//!
//! What casts (`--shadow-lod`):
//! - `follow` (default): what the method draws. An instance out of transition casts its LOD; a t-instance of a
//!   blending method (alpha, alpha-2pass, alpha-zwrite, alpha-linear, dither, geomorph) casts both LODs with
//!   complementary dither (the incoming LOD where k exceeds interleaved gradient noise at the shadow-map
//!   texel), engines' usual choice, since a shadow map cannot blend; discrete casts the LOD it shows; FSI
//!   casts, each frame, the LODs of the LOD buffer it renders that frame (so each of its two buffers is lit by
//!   the shadow of its own LODs). geomorph's casters are not morphed (said in docs/methods.md).
//! - `lod-from`, `lod-to`: every t-instance casts that one LOD, whatever the method draws.
//!
//! The reference always casts LOD0.

use crate::error::{Error, Result};
use crate::geometry::projection::Sphere;
use glam::{Mat4, Vec3};
use serde::{Deserialize, Serialize};

/// Depth bias of the shadow test as a fraction of the largest caster's bounding radius (the shader gets it in
/// the light's normalised depth, divided by the fitted box's depth).
pub const BIAS_OF_RADIUS: f32 = 0.02;

/// The shadow flags of `lodbench run` (a part of `SceneArgs`).
#[derive(Debug, Clone, Copy, PartialEq, clap::Args, Deserialize, Serialize)]
#[serde(default, rename_all = "kebab-case")]
pub struct ShadowArgs {
    /// One directional shadow map in every scene but the unified ones.
    #[arg(long, value_enum, default_value_t = crate::effects::OnOff::Off,
          help_heading = crate::defaults::heading::EFFECTS)]
    pub shadows: crate::effects::OnOff,
    /// With --shadows on: the shadow map's side in texels.
    #[arg(long, default_value_t = 1024, help_heading = crate::defaults::heading::EFFECTS)]
    pub shadow_size: u32,
    /// With --shadows on: what a t-instance casts (follow: what the method draws).
    #[arg(long, value_enum, default_value_t = ShadowLod::Follow, help_heading = crate::defaults::heading::EFFECTS)]
    pub shadow_lod: ShadowLod,
}

impl Default for ShadowArgs {
    fn default() -> Self {
        crate::defaults::clap_defaults()
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ShadowLod {
    Follow,
    LodFrom,
    LodTo,
}

/// A validated shadow setting (present only with `--shadows on`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Shadows {
    pub size: u32,
    pub lod: ShadowLod,
}

impl ShadowArgs {
    pub fn resolve(&self) -> Result<Option<Shadows>> {
        if self.shadows == crate::effects::OnOff::Off {
            return Ok(None);
        }
        if !(16..=8192).contains(&self.shadow_size) {
            return Err(Error::Config(format!(
                "--shadow-size {}: must be 16 to 8192",
                self.shadow_size
            )));
        }
        Ok(Some(Shadows {
            size: self.shadow_size,
            lod: self.shadow_lod,
        }))
    }
}

/// What one instance casts into the shadow map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Caster {
    Lod(u32),
    /// Both LODs, complementary dither at k (`to` where k > the texel's threshold).
    Dither {
        from: u32,
        to: u32,
        k: f32,
    },
}

/// The light's view-projection: orthographic along `-to_light`, its square side and depth fitted to the
/// `spheres` (the depth widened by `receiver_depth` behind them, where the shadows land);
/// with the box's depth in world units.
pub fn light_matrix(to_light: Vec3, spheres: &[Sphere], receiver_depth: f32) -> (Mat4, f32) {
    let dir = to_light.normalize_or(Vec3::Y);
    let up = if dir.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
    let view = Mat4::look_at_rh(Vec3::ZERO, -dir, up);
    let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
    for &Sphere {
        centre: c,
        radius: r,
    } in spheres
    {
        let p = view.transform_point3(c);
        lo = lo.min(p - Vec3::splat(r));
        hi = hi.max(p + Vec3::splat(r));
    }
    if spheres.is_empty() {
        lo = Vec3::splat(-1.0);
        hi = Vec3::splat(1.0);
    }
    // Square, so a texel is as wide as it is high.
    let half = ((hi.x - lo.x).max(hi.y - lo.y) * 0.5).max(1e-3);
    let (cx, cy) = ((lo.x + hi.x) * 0.5, (lo.y + hi.y) * 0.5);
    // View space looks down -z: near is the largest z.
    let near = -hi.z;
    let far = -lo.z + receiver_depth;
    (
        Mat4::orthographic_rh(cx - half, cx + half, cy - half, cy + half, near, far) * view,
        far - near,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn light_box_holds_the_spheres() {
        let spheres = [
            Sphere::new(Vec3::new(0.0, 1.0, 0.0), 0.5),
            Sphere::new(Vec3::new(4.0, 1.0, 2.0), 1.0),
        ];
        let (m, depth) = light_matrix(Vec3::new(-0.45, 0.8, 0.4), &spheres, 10.0);
        assert!(depth > 10.0);
        for s in spheres {
            let p = m.project_point3(s.centre);
            assert!(p.x.abs() <= 1.0 && p.y.abs() <= 1.0, "{p}");
            assert!((0.0..=1.0).contains(&p.z), "{p}");
        }
        // Farther along the light's direction is deeper.
        let d = Vec3::new(-0.45, 0.8, 0.4).normalize();
        let a = m.project_point3(Vec3::new(0.0, 1.0, 0.0));
        let b = m.project_point3(Vec3::new(0.0, 1.0, 0.0) - d * 0.3);
        assert!(b.z > a.z);
    }
}
