//! The perspective projection, written once: how big a sphere or an error looks at a distance, and the distance
//! at which it looks a given size. Every scene builder, the engines' conversions (`results::engines`), `tune`
//! and the engines' own rules (`measure::engine_rules`) compute with these.
//!
//! A viewport `height` pixels high with vertical field of view `fov_y` (radians) shows, at distance `d`, a
//! length `e` (perpendicular to the view) as `e * height / (2 d tan(fov_y / 2))` pixels; a sphere of radius `r`
//! has screen size `r / (d tan(fov_y / 2))`, its projected diameter over the viewport's height (Unreal's screen
//! size, Unity's screen-relative transition height for a sphere).

use glam::Vec3;

/// A bounding sphere.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Sphere {
    pub centre: Vec3,
    pub radius: f32,
}

impl Sphere {
    pub fn new(centre: Vec3, radius: f32) -> Sphere {
        Sphere { centre, radius }
    }

    /// The centre of the box of `points` and the radius around it that holds them all.
    pub fn around(points: &[[f32; 3]]) -> Sphere {
        let (lo, hi) = points.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(Vec3::from(*p)), hi.max(Vec3::from(*p))),
        );
        let centre = (lo + hi) * 0.5;
        let radius = points
            .iter()
            .map(|p| Vec3::from(*p).distance(centre))
            .fold(0.0f32, f32::max);
        Sphere { centre, radius }
    }

    /// The smallest sphere around the box of `spheres`.
    pub fn holding(spheres: &[Sphere]) -> Sphere {
        let (lo, hi) = spheres.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), s| {
                let r = Vec3::splat(s.radius);
                (lo.min(s.centre - r), hi.max(s.centre + r))
            },
        );
        let centre = (lo + hi) * 0.5;
        let radius = spheres
            .iter()
            .map(|s| s.centre.distance(centre) + s.radius)
            .fold(0.0f32, f32::max);
        Sphere { centre, radius }
    }
}

/// `tan(fov_y / 2)`.
pub fn tan_half(fov_y: f32) -> f32 {
    (fov_y * 0.5).tan()
}

/// The screen size of a sphere of radius `r` at distance `d`: its projected diameter over the viewport's height.
pub fn screen_size(r: f32, d: f32, fov_y: f32) -> f32 {
    r / (d * tan_half(fov_y))
}

/// The distance at which a sphere of radius `r` has screen size `s` (the inverse of [`screen_size`]).
pub fn distance_of(r: f32, s: f32, fov_y: f32) -> f32 {
    r / (s * tan_half(fov_y))
}

/// Pixels per world unit at distance 1 on a viewport `height` pixels high: `height / (2 tan(fov_y / 2))`.
pub fn pixels_per_unit(height: u32, fov_y: f32) -> f32 {
    height as f32 / (2.0 * tan_half(fov_y))
}

/// Distance at which an object-space error `error_abs` (at instance scale `scale`) projects to `pixel_error`
/// pixels on a viewport `height_px` pixels high: `pixels = error * height / (2 d tan(fov/2))`, solved for d.
pub fn switch_distance(
    error_abs: f32,
    scale: f32,
    pixel_error: f32,
    height_px: u32,
    fov_y: f32,
) -> f32 {
    error_abs * scale * height_px as f32 / (2.0 * pixel_error * tan_half(fov_y))
}

/// The object-space error (at instance scale `scale`) that projects to `pixel_error` pixels at distance
/// `distance`: the inverse of [`switch_distance`].
pub fn error_at_distance(
    distance: f32,
    scale: f32,
    pixel_error: f32,
    height_px: u32,
    fov_y: f32,
) -> f32 {
    distance * 2.0 * pixel_error * tan_half(fov_y) / (height_px as f32 * scale)
}

/// The narrower of the two half fields of view of a `width` x `height` viewport (radians).
pub fn half_fov_fit(width: u32, height: u32, fov_y: f32) -> f32 {
    let aspect = width as f32 / height as f32;
    (fov_y * 0.5).min((tan_half(fov_y) * aspect).atan())
}

/// Nearest distance from the camera at which a bounding sphere of `radius` fits the view (the narrower of the
/// two fields of view).
pub fn fit_distance(radius: f32, width: u32, height: u32, fov_y: f32) -> f32 {
    radius / half_fov_fit(width, height, fov_y).sin()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The inverses undo each other, and a sphere at its fit distance touches the narrower edge of the view.
    #[test]
    fn the_projection_and_its_inverses_agree() {
        let fov = 60f32.to_radians();
        let (r, d) = (0.5f32, 7.0f32);
        let s = screen_size(r, d, fov);
        assert!((distance_of(r, s, fov) - d).abs() < 1e-5);
        let e = 0.01f32;
        let dist = switch_distance(e, 2.0, 1.5, 600, fov);
        assert!((error_at_distance(dist, 2.0, 1.5, 600, fov) - e).abs() < 1e-8);
        // e * scale at `dist` is 1.5 pixels.
        assert!((e * 2.0 * pixels_per_unit(600, fov) / dist - 1.5).abs() < 1e-5);
        // A square viewport: the sphere's edge is seen at half the field of view.
        let fit = fit_distance(r, 600, 600, fov);
        assert!(((r / fit).asin() - fov * 0.5).abs() < 1e-6);
        // A tall viewport is limited by its width.
        assert!(fit_distance(r, 300, 600, fov) > fit);
    }
}
