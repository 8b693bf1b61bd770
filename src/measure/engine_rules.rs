//! The rules engines place LOD switches by when nobody measures (`lodbench tune` measures the image change at
//! each rule's distance beside its own; docs/methods.md, "The engines' rules"), from the LOD's simplifier error
//! and the model's bounding sphere.

use crate::geometry::projection::{distance_of, switch_distance};
use serde::{Deserialize, Serialize};

/// An engine's rule: an error bound on the LOD's simplifier error
/// `e` (object-space units at scale 1, the chain's `error_abs` times the model's scale), giving the distance from
/// the bounding sphere's centre (radius `r`) at which LOD k may come in. docs/methods.md, "The engines' rules".
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Rule {
    /// Unreal's auto LOD screen size (`FStaticMeshRenderData::ResolveSectionInfo`): `ViewDistance = e x 960 /
    /// PixelError` (PixelError 8 by default: `FMeshReductionSettings`), the sphere's centre a radius beyond it, its
    /// screen size on a 1920x1080 view of 90 degrees across; 0.75^k where a LOD has no error; a size not below the
    /// previous LOD's becomes half of it. Screen sizes, so the distance scales with the field of view and not with
    /// the viewport's pixels.
    Unreal,
    /// Godot's `mesh_lod_threshold` of 1 pixel: LOD k while `e` projects to at most 1 pixel at the distance from
    /// the camera plane to the nearest side of the mesh's bounds (`mesh_surface_get_lod`): taken here as a
    /// radius nearer than the centre.
    Godot,
    /// meshoptimizer's projection (lodbench's default for a user's mesh, gltfpack's and the clusterlod example's
    /// rule): `e` projects to 1 pixel at the distance from the centre.
    Meshopt,
}

/// Every rule, in the order tables list them.
pub const RULES: [Rule; 3] = [Rule::Unreal, Rule::Godot, Rule::Meshopt];

/// Unreal's auto LOD view: 1920x1080, 90 degrees across (`HalfFOV = PI / 4`), so its `ComputeBoundsScreenSize`
/// multiplies by `P11 = (1920 / 1080) / tan(45 degrees)`.
pub const UNREAL_P11: f32 = 1920.0 / 1080.0;
/// Unreal's `FMeshReductionSettings::PixelError` default.
pub const UNREAL_PIXEL_ERROR: f32 = 8.0;
/// Unreal's fallback `AutoComputeLODPowerBase`.
pub const UNREAL_POWER_BASE: f32 = 0.75;
/// Godot's default `rendering/mesh_lod/lod_change/threshold_pixels`.
pub const GODOT_THRESHOLD_PX: f32 = 1.0;

impl Rule {
    pub fn name(self) -> &'static str {
        match self {
            Rule::Unreal => "unreal",
            Rule::Godot => "godot",
            Rule::Meshopt => "meshopt",
        }
    }

    /// Where LOD 1, 2, ... come in under the rule, for their errors `errors` (LOD1 first), the sphere's radius
    /// `r`, and the run's viewport height and vertical field of view: strictly increasing, as a schedule needs
    /// (a switch not beyond the previous one moves just past it).
    pub fn distances(self, errors: &[f32], r: f32, height_px: u32, fov_y: f32) -> Vec<f32> {
        // Where error e projects to px pixels.
        let project = |e: f32, px: f32| switch_distance(e, 1.0, px, height_px, fov_y);
        let mut previous_size = 1.0f32;
        let mut out: Vec<f32> = Vec::with_capacity(errors.len());
        for (i, &e) in errors.iter().enumerate() {
            let d = match self {
                Rule::Unreal => {
                    let mut size = if e > 0.0 {
                        let view = e * 960.0 / UNREAL_PIXEL_ERROR;
                        UNREAL_P11 * r / (view + r)
                    } else {
                        UNREAL_POWER_BASE.powi(i as i32 + 1)
                    };
                    if size > previous_size {
                        size = previous_size / 2.0;
                    }
                    previous_size = size;
                    distance_of(r, size, fov_y)
                }
                Rule::Godot => project(e, GODOT_THRESHOLD_PX) + r,
                Rule::Meshopt => project(e, 1.0),
            };
            let d = match out.last() {
                Some(&p) if d <= p * 1.0001 => p * 1.0001,
                _ => d,
            };
            out.push(d);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::projection::screen_size;

    /// The rules' closed forms: Unreal's 8 pixels at 960 pixels of focal length and a radius beyond, as a screen
    /// size; Godot's 1 pixel from the near side; meshopt's 1 pixel from the centre; the fallbacks.
    #[test]
    fn the_engines_rules_place_switches_by_their_formulas() {
        let fov = 60f32.to_radians();
        let tan = (fov * 0.5).tan();
        let (r, h) = (0.5f32, 480u32);
        let errors = [0.01f32, 0.04, 0.2];
        let m = Rule::Meshopt.distances(&errors, r, h, fov);
        for (d, e) in m.iter().zip(errors) {
            // 1 pixel: e / (2 d tan) of the height is one of its 480 pixels.
            assert!((e * h as f32 / (2.0 * d * tan) - 1.0).abs() < 1e-5, "{d}");
        }
        let g = Rule::Godot.distances(&errors, r, h, fov);
        assert!(g.iter().zip(&m).all(|(g, m)| (g - m - r).abs() < 1e-5));
        let u = Rule::Unreal.distances(&errors, r, h, fov);
        for (d, e) in u.iter().zip(errors) {
            // At 1920x1080 and 90 degrees across (focal length 960 px) the error is 8 px a radius nearer.
            let size = screen_size(r, *d, fov);
            let view = UNREAL_P11 * r / size - r;
            assert!((e * 960.0 / view - 8.0).abs() < 1e-3, "{d} {view}");
        }
        // No error: 0.75^k; a LOD whose size would not fall halves the previous one's; always increasing.
        let u = Rule::Unreal.distances(&[0.0, 0.0], r, h, fov);
        assert!((screen_size(r, u[0], fov) - 0.75).abs() < 1e-5);
        assert!((screen_size(r, u[1], fov) - 0.5625).abs() < 1e-5);
        let big = Rule::Unreal.distances(&[1e-7], r, h, fov);
        assert!((screen_size(r, big[0], fov) - 0.5).abs() < 1e-5);
        let flat = Rule::Meshopt.distances(&[0.01, 0.01], r, h, fov);
        assert!(flat[1] > flat[0]);
    }
}
