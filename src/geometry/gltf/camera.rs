//! The file's animated camera: the first camera node of the scene whose translation or rotation an animation
//! drives, as keys in world space (its parents at rest).

use super::content::Content;
use super::json::{array, opt_index};
use glam::{Quat, Vec3};

/// A camera node's animation: keys in world space.
#[derive(Debug, Clone)]
pub struct AnimatedCamera {
    pub node: usize,
    /// The camera's vertical field of view, radians, and its clip planes (perspective cameras).
    pub yfov: Option<f32>,
    pub znear: Option<f32>,
    pub zfar: Option<f32>,
    /// (time s, eye, orientation): the camera looks along its local -z.
    pub keys: Vec<(f64, Vec3, Quat)>,
}

impl Content<'_> {
    /// The first camera node of the scene whose translation or rotation is animated (its channels from the first
    /// animation that moves it), sampled at the union of its channels' key times as each channel's sampler gives
    /// it (LINEAR, STEP or CUBICSPLINE); the path then joins the keys linearly. The node's parents are taken at
    /// rest. None when no camera is animated.
    pub fn animated_camera(&mut self) -> Result<Option<AnimatedCamera>, String> {
        let json = self.doc.json.clone();
        let cameras = array(&json, "cameras").len();
        let Some((node, anim)) = self.first_moved_camera(&json) else {
            return Ok(None);
        };
        let what = format!("the animation of camera node {node}");
        let animation = self
            .doc
            .animation(anim)
            .map_err(|e| format!("{what}: {e}"))?;
        let (t0, r0) = self.rest_translation_rotation(node);
        let channels: Vec<_> = animation
            .channels
            .iter()
            .filter(|c| {
                c.node == node
                    && matches!(
                        c.path,
                        super::animation::Path::Translation | super::animation::Path::Rotation
                    )
            })
            .collect();
        let mut times: Vec<f32> = channels
            .iter()
            .flat_map(|c| animation.samplers[c.sampler].times.iter().copied())
            .collect();
        times.sort_by(f32::total_cmp);
        times.dedup();
        if times.len() < 2 {
            return Err(format!(
                "{what} has {} key time(s); a path needs at least two",
                times.len()
            ));
        }
        let parent = match self.nodes.parent[node] {
            Some(p) => self.rest_worlds[p],
            None => glam::Mat4::IDENTITY,
        };
        let (_, parent_rotation, _) = parent.to_scale_rotation_translation();
        let mut buf = [0.0f32; 4];
        let keys = times
            .iter()
            .map(|&t| {
                let (mut tr, mut ro) = (t0, r0);
                for c in &channels {
                    let s = &animation.samplers[c.sampler];
                    match c.path {
                        super::animation::Path::Translation => {
                            s.sample(t, false, &mut buf[..3]);
                            tr = Vec3::from_slice(&buf[..3]);
                        }
                        _ => {
                            s.sample(t, true, &mut buf);
                            ro = Quat::from_slice(&buf);
                        }
                    }
                }
                (
                    f64::from(t),
                    parent.transform_point3(tr),
                    (parent_rotation * ro.normalize()).normalize(),
                )
            })
            .collect();
        let camera = opt_index(
            &json["nodes"][node]["camera"],
            || format!("node {node}'s camera"),
            cameras,
        )?;
        let perspective = |key: &str| {
            camera
                .and_then(|c| json["cameras"][c]["perspective"][key].as_f64())
                .filter(|v| v.is_finite() && *v > 0.0)
                .map(|f| f as f32)
        };
        Ok(Some(AnimatedCamera {
            node,
            yfov: perspective("yfov"),
            znear: perspective("znear"),
            zfar: perspective("zfar"),
            keys,
        }))
    }

    /// The first camera node in scene order whose translation or rotation an animation drives, and the first
    /// such animation.
    fn first_moved_camera(&self, json: &serde_json::Value) -> Option<(usize, usize)> {
        let moved = |n: usize| {
            array(json, "animations").iter().position(|a| {
                array(a, "channels").iter().any(|c| {
                    super::json::uint(&c["target"]["node"]) == Some(n as u64)
                        && matches!(
                            c["target"]["path"].as_str(),
                            Some("translation" | "rotation")
                        )
                })
            })
        };
        let mut found = None;
        for &n in &self.nodes.scene_order {
            if json["nodes"][n].get("camera").is_none() {
                continue;
            }
            if let Some(a) = moved(n) {
                found = Some((n, a));
                break;
            }
        }
        found
    }

    /// Node `node`'s local translation and rotation at rest.
    fn rest_translation_rotation(&self, node: usize) -> (Vec3, Quat) {
        match self.nodes.local[node] {
            super::nodes::Local::Trs { t, r, .. } => (t, r),
            super::nodes::Local::Matrix(m) => {
                let (_, r, t) = m.to_scale_rotation_translation();
                (t, r)
            }
        }
    }
}
