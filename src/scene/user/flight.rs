//! A user scene's camera: the file's animated camera (its first, keys resampled to the frames, its vertical fov
//! replacing `--fov`) when it has one and no `--camera-path` is given; otherwise a flight that shows the whole
//! scene on its first frame and moves out until every model has passed its last switch.

use crate::error::{Error, Result};
use crate::geometry::gltf::{AnimatedCamera, Content};
use crate::geometry::projection::{fit_distance, Sphere};
use crate::scene::camera_path::CameraPath;
use crate::scene::config::SceneConfig;
use crate::scene::kind::ProfileValues;
use crate::scene::schedule::FadeMode;
use glam::Vec3;
use std::sync::Arc;

/// The file's animated camera, checked, and the path made of it (None with `--camera-path`, or when the file
/// animates no camera).
pub fn file_camera(
    file: &str,
    content: &mut Content<'_>,
    cfg: &SceneConfig,
) -> Result<Option<(AnimatedCamera, Arc<CameraPath>)>> {
    let bad = |problem: String| Error::Mesh {
        path: file.to_string(),
        problem,
    };
    if cfg.camera_path.is_some() {
        return Ok(None);
    }
    let Some(a) = content.animated_camera().map_err(bad)? else {
        return Ok(None);
    };
    if let Some(f) = a.yfov {
        if !(1.0..170.0).contains(&f.to_degrees()) {
            return Err(bad(format!(
                "the animated camera's yfov {f} rad ({:.1} deg) is not between 1 and 170 degrees",
                f.to_degrees()
            )));
        }
    }
    if let (Some(n), Some(f)) = (a.znear, a.zfar) {
        if n >= f {
            return Err(bad(format!(
                "the animated camera's znear {n} is not below its zfar {f}"
            )));
        }
    }
    let path = Arc::new(CameraPath::from_orientations(
        file,
        &a.keys,
        a.yfov.map(f32::to_degrees),
    )?);
    Ok(Some((a, path)))
}

/// The default flight's first eye: on +z (glTF's front) of the scene sphere's centre, looking along -z, where
/// the sphere fits the view.
pub fn start(sphere: Sphere, pv: &ProfileValues, fov_y: f32) -> (Vec3, f32) {
    let d = fit_distance(
        sphere.radius.max(f32::MIN_POSITIVE),
        pv.width,
        pv.height,
        fov_y,
    );
    (sphere.centre + Vec3::Z * d, d)
}

/// How far out the flight goes: every instance (`(position on the last frame, the last switch of its model)`)
/// beyond its model's last switch by the band, the hysteresis and 15 %, and at least 1.25 times the start. With
/// a time fade, also far enough that the flight, moving evenly over `frames`, crosses the last switch more than
/// the fade's frames and one before its end (`room` = fade + 2 frames, scaled by (frames - 1) / frames since the
/// flight's last frame is at frames - 1), so the last fade ends on the path, its steady frame after it too.
pub fn end(
    cfg: &SceneConfig,
    centre: Vec3,
    start: f32,
    frames: u32,
    instances: &[(Vec3, Option<f32>)],
) -> f32 {
    let s = cfg.user_schedule;
    let (b, h) = (s.band, s.hysteresis);
    let room = s.fade_frames + 2;
    instances
        .iter()
        .filter_map(|&(p, last)| {
            let last = last?;
            let beyond = last * (1.0 + h) * (1.0 + b) * 1.15 + p.distance(centre);
            let crossed = last * (1.0 + h) + p.distance(centre);
            let fade_room = match s.fade {
                FadeMode::Time if frames > room && crossed > start => {
                    start + (crossed - start) * frames as f32 / (frames - room) as f32
                }
                _ => 0.0,
            };
            Some(beyond.max(fade_room))
        })
        .fold(start * 1.25, f32::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sphere_holds_every_sphere() {
        let spheres = [
            Sphere::new(Vec3::ZERO, 1.0),
            Sphere::new(Vec3::new(10.0, 0.0, 0.0), 2.0),
        ];
        let all = Sphere::holding(&spheres);
        assert_eq!(all.centre, Vec3::new(5.5, 0.0, 0.0));
        assert_eq!(all.radius, 6.5);
        for s in spheres {
            assert!(s.centre.distance(all.centre) + s.radius <= all.radius + 1e-6);
        }
    }
}
