//! Animations (glTF 2.0 section 3.11 and Appendix C): channels that drive a node's translation, rotation,
//! scale or morph weights through a sampler of keys, LINEAR (rotations by slerp), STEP or CUBICSPLINE
//! (Hermite splines over in-tangent, value, out-tangent triplets).

use super::accessors::Doc;
use super::json::{array, index};
use glam::{Mat4, Quat, Vec3};

/// What a channel drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Path {
    Translation,
    Rotation,
    Scale,
    Weights,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interpolation {
    Linear,
    Step,
    CubicSpline,
}

/// A sampler's keys: strictly increasing times and `width` values per key (three groups per key for
/// CUBICSPLINE: in-tangent, value, out-tangent).
#[derive(Debug, Clone, PartialEq)]
pub struct Sampler {
    pub times: Vec<f32>,
    pub values: Vec<f32>,
    pub width: usize,
    pub interpolation: Interpolation,
}

impl Sampler {
    /// The value at time `t` into `out` (`width` long): held before the first key and after the last; slerp
    /// between unit quaternions where `rotation` (the shorter way), and every rotation normalised.
    pub fn sample(&self, t: f32, rotation: bool, out: &mut [f32]) {
        let w = self.width;
        let per_key = if self.interpolation == Interpolation::CubicSpline {
            3
        } else {
            1
        };
        let value = |k: usize| {
            let at = (k * per_key + per_key / 2) * w;
            &self.values[at..at + w]
        };
        let n = self.times.len();
        let i = if t <= self.times[0] {
            None
        } else if t >= self.times[n - 1] {
            Some(n - 1)
        } else {
            Some(self.times.partition_point(|&k| k <= t) - 1)
        };
        let i = match i {
            None => {
                out.copy_from_slice(value(0));
                return self.finish(rotation, out);
            }
            Some(i) if i + 1 >= n => {
                out.copy_from_slice(value(n - 1));
                return self.finish(rotation, out);
            }
            Some(i) => i,
        };
        let dt = self.times[i + 1] - self.times[i];
        let s = (t - self.times[i]) / dt;
        match self.interpolation {
            Interpolation::Step => out.copy_from_slice(value(i)),
            Interpolation::Linear if rotation => {
                let a = Quat::from_slice(value(i)).normalize();
                let b = Quat::from_slice(value(i + 1)).normalize();
                out.copy_from_slice(&a.slerp(b, s).to_array());
            }
            Interpolation::Linear => {
                for (o, (a, b)) in out.iter_mut().zip(value(i).iter().zip(value(i + 1))) {
                    *o = a + (b - a) * s;
                }
            }
            Interpolation::CubicSpline => {
                let out_tangent = &self.values[(i * 3 + 2) * w..(i * 3 + 3) * w];
                let in_tangent = &self.values[((i + 1) * 3) * w..((i + 1) * 3 + 1) * w];
                let (s2, s3) = (s * s, s * s * s);
                let (h00, h10, h01, h11) = (
                    2.0 * s3 - 3.0 * s2 + 1.0,
                    s3 - 2.0 * s2 + s,
                    -2.0 * s3 + 3.0 * s2,
                    s3 - s2,
                );
                for c in 0..w {
                    out[c] = h00 * value(i)[c]
                        + h10 * dt * out_tangent[c]
                        + h01 * value(i + 1)[c]
                        + h11 * dt * in_tangent[c];
                }
            }
        }
        self.finish(rotation, out)
    }

    fn finish(&self, rotation: bool, out: &mut [f32]) {
        if rotation {
            let q = Quat::from_slice(out).normalize();
            out.copy_from_slice(&q.to_array());
        }
    }
}

/// A channel: which node, what of it, and its sampler (an index into [`Animation::samplers`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Channel {
    pub node: usize,
    pub path: Path,
    pub sampler: usize,
}

/// An animation: its channels and samplers, and the time range its keys cover.
#[derive(Debug, Clone, PartialEq)]
pub struct Animation {
    pub index: usize,
    pub name: String,
    pub channels: Vec<Channel>,
    pub samplers: Vec<Sampler>,
    /// The first and the last key time over all its samplers, seconds.
    pub start: f32,
    pub end: f32,
}

impl Animation {
    /// Whether a channel drives `node`'s transform (translation, rotation or scale).
    pub fn moves(&self, node: usize) -> bool {
        self.channels
            .iter()
            .any(|c| c.node == node && c.path != Path::Weights)
    }

    /// Whether a channel drives `node`'s morph weights.
    pub fn weighs(&self, node: usize) -> bool {
        self.channels
            .iter()
            .any(|c| c.node == node && c.path == Path::Weights)
    }

    /// Every node's local matrix at time `t`: `rest` with the animated nodes' TRS replaced channel by channel
    /// (`rest_trs` gives each node's rest translation, rotation and scale; an animated node has no matrix).
    pub fn locals_at(
        &self,
        t: f32,
        rest: &[Mat4],
        rest_trs: &dyn Fn(usize) -> (Vec3, Quat, Vec3),
    ) -> Vec<Mat4> {
        let mut out = rest.to_vec();
        let mut trs: Vec<(usize, (Vec3, Quat, Vec3))> = Vec::new();
        let mut buf = [0.0f32; 4];
        for c in &self.channels {
            if c.path == Path::Weights {
                continue;
            }
            let slot = match trs.iter().position(|(n, _)| *n == c.node) {
                Some(p) => p,
                None => {
                    trs.push((c.node, rest_trs(c.node)));
                    trs.len() - 1
                }
            };
            let s = &self.samplers[c.sampler];
            let v = &mut trs[slot].1;
            match c.path {
                Path::Translation => {
                    s.sample(t, false, &mut buf[..3]);
                    v.0 = Vec3::from_slice(&buf[..3]);
                }
                Path::Rotation => {
                    s.sample(t, true, &mut buf);
                    v.1 = Quat::from_slice(&buf);
                }
                Path::Scale => {
                    s.sample(t, false, &mut buf[..3]);
                    v.2 = Vec3::from_slice(&buf[..3]);
                }
                Path::Weights => {}
            }
        }
        for (n, (tr, ro, sc)) in trs {
            out[n] = Mat4::from_scale_rotation_translation(sc, ro, tr);
        }
        out
    }

    /// `node`'s morph weights at time `t` (`count` of them), when a channel drives them.
    pub fn weights_at(&self, node: usize, t: f32, count: usize) -> Option<Vec<f32>> {
        let c = self
            .channels
            .iter()
            .find(|c| c.node == node && c.path == Path::Weights)?;
        let s = &self.samplers[c.sampler];
        let mut out = vec![0.0; s.width];
        s.sample(t, false, &mut out);
        out.resize(count, 0.0);
        Some(out)
    }
}

/// A node hierarchy with (at most) one animation: every node's world matrix and a node's morph weights at a
/// time of the animation.
#[derive(Debug, Clone)]
pub struct Rig {
    pub nodes: super::nodes::Nodes,
    pub animation: Option<Animation>,
    rest: Vec<Mat4>,
}

impl Rig {
    pub fn new(nodes: super::nodes::Nodes, animation: Option<Animation>) -> Rig {
        Rig {
            rest: nodes.rest_locals(),
            nodes,
            animation,
        }
    }

    /// Every node's world matrix at time `t` of the animation (at rest without one).
    pub fn worlds_at(&self, t: f32) -> Vec<Mat4> {
        match &self.animation {
            Some(a) => {
                let locals = a.locals_at(t, &self.rest, &|n| self.nodes.local[n].trs());
                self.nodes.worlds(&locals)
            }
            None => self.nodes.worlds(&self.rest),
        }
    }

    /// Every node's world matrix at rest.
    pub fn rest_worlds(&self) -> Vec<Mat4> {
        self.nodes.worlds(&self.rest)
    }

    /// `node`'s animated morph weights at time `t` (`count` of them), when the animation drives them.
    pub fn weights_at(&self, node: usize, t: f32, count: usize) -> Option<Vec<f32>> {
        self.animation.as_ref()?.weights_at(node, t, count)
    }
}

/// The names of the file's animations ("" where unnamed), in order.
pub fn animation_names(json: &serde_json::Value) -> Vec<String> {
    array(json, "animations")
        .iter()
        .map(|a| a["name"].as_str().unwrap_or("").to_string())
        .collect()
}

impl Doc<'_> {
    /// Animation `i`: its channels (a channel without a target node is ignored, as glTF says) and their samplers,
    /// each checked: key times finite and strictly increasing, as many values as keys need.
    pub fn animation(&mut self, i: usize) -> Result<Animation, String> {
        let anims = array(&self.json, "animations");
        let a = anims
            .get(i)
            .ok_or_else(|| format!("animation {i} does not exist ({} animations)", anims.len()))?
            .clone();
        let what = format!("animation {i}");
        let nodes = array(&self.json, "nodes").len();
        let sampler_defs = array(&a, "samplers").to_vec();
        let mut samplers: Vec<Option<Sampler>> = vec![None; sampler_defs.len()];
        let mut channels = Vec::new();
        for (c, ch) in array(&a, "channels").iter().enumerate() {
            let target = &ch["target"];
            if target.get("node").is_none() {
                continue;
            }
            let node = index(
                &target["node"],
                || format!("{what} channel {c}'s node"),
                nodes,
            )?;
            let path = match target["path"].as_str() {
                Some("translation") => Path::Translation,
                Some("rotation") => Path::Rotation,
                Some("scale") => Path::Scale,
                Some("weights") => Path::Weights,
                // KHR_animation_pointer and other extensions' paths: not geometry lodbench places.
                _ => continue,
            };
            let sampler = index(
                &ch["sampler"],
                || format!("{what} channel {c}'s sampler"),
                sampler_defs.len(),
            )?;
            if samplers[sampler].is_none() {
                let width = match path {
                    Path::Translation | Path::Scale => Some(3),
                    Path::Rotation => Some(4),
                    Path::Weights => None,
                };
                samplers[sampler] = Some(self.sampler(
                    &sampler_defs[sampler],
                    width,
                    &format!("{what} sampler {sampler}"),
                )?);
            }
            let s = samplers[sampler].as_ref().map_or(0, |s| s.width);
            let expected = match path {
                Path::Translation | Path::Scale => 3,
                Path::Rotation => 4,
                Path::Weights => s,
            };
            if s != expected {
                return Err(format!(
                    "{what} channel {c} drives {path:?} with sampler {sampler}, whose keys have {s} values"
                ));
            }
            channels.push(Channel {
                node,
                path,
                sampler,
            });
        }
        let samplers: Vec<Sampler> = samplers
            .into_iter()
            .map(|s| {
                s.unwrap_or(Sampler {
                    times: vec![0.0],
                    values: Vec::new(),
                    width: 0,
                    interpolation: Interpolation::Step,
                })
            })
            .collect();
        let used = channels.iter().map(|c| &samplers[c.sampler]);
        let start = used
            .clone()
            .map(|s| s.times[0])
            .fold(f32::INFINITY, f32::min);
        let end = used
            .map(|s| s.times[s.times.len() - 1])
            .fold(f32::NEG_INFINITY, f32::max);
        Ok(Animation {
            index: i,
            name: a["name"].as_str().unwrap_or("").to_string(),
            channels,
            samplers,
            start: if start.is_finite() { start } else { 0.0 },
            end: if end.is_finite() { end } else { 0.0 },
        })
    }

    /// A sampler's keys: `width` values per key (None: as many as the output holds per key, for weights).
    fn sampler(
        &mut self,
        s: &serde_json::Value,
        width: Option<usize>,
        what: &str,
    ) -> Result<Sampler, String> {
        let accessors = array(&self.json, "accessors").len();
        let input = index(&s["input"], || format!("{what}'s input"), accessors)?;
        let output = index(&s["output"], || format!("{what}'s output"), accessors)?;
        let interpolation = match s["interpolation"].as_str() {
            None | Some("LINEAR") => Interpolation::Linear,
            Some("STEP") => Interpolation::Step,
            Some("CUBICSPLINE") => Interpolation::CubicSpline,
            Some(other) => {
                return Err(format!(
                    "{what} has interpolation {other}, which glTF does not define"
                ))
            }
        };
        let (times, c) = self.read_floats(input)?;
        if c != 1 {
            return Err(format!("{what}'s input is not scalar key times"));
        }
        if times.is_empty()
            || times.iter().any(|t| !t.is_finite())
            || times.windows(2).any(|w| w[1] <= w[0])
        {
            return Err(format!("{what}: key times must be given and increase"));
        }
        let (values, _) = self.read_floats(output)?;
        let per_key = if interpolation == Interpolation::CubicSpline {
            3
        } else {
            1
        };
        let groups = times.len() * per_key;
        let width = match width {
            Some(w) => w,
            None if values.len() % groups == 0 => values.len() / groups,
            None => 0,
        };
        if width == 0 || values.len() != groups * width {
            return Err(format!(
                "{what}'s output holds {} values, which do not divide into its {} keys",
                values.len(),
                times.len()
            ));
        }
        if values.iter().any(|v| !v.is_finite()) {
            return Err(format!("{what}'s output holds a non-finite value"));
        }
        Ok(Sampler {
            times,
            values,
            width,
            interpolation,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sampler(interpolation: Interpolation, values: Vec<f32>, width: usize) -> Sampler {
        Sampler {
            times: vec![1.0, 3.0],
            values,
            width,
            interpolation,
        }
    }

    /// LINEAR interpolates, STEP holds the earlier key, both hold the ends outside the keys.
    #[test]
    fn linear_and_step() {
        let s = sampler(Interpolation::Linear, vec![0.0, 10.0, 4.0, 20.0], 2);
        let mut out = [0.0; 2];
        s.sample(2.5, false, &mut out);
        assert_eq!(out, [3.0, 17.5]);
        s.sample(0.0, false, &mut out);
        assert_eq!(out, [0.0, 10.0]);
        s.sample(9.0, false, &mut out);
        assert_eq!(out, [4.0, 20.0]);
        let s = sampler(Interpolation::Step, vec![0.0, 10.0, 4.0, 20.0], 2);
        s.sample(2.9, false, &mut out);
        assert_eq!(out, [0.0, 10.0]);
        s.sample(3.0, false, &mut out);
        assert_eq!(out, [4.0, 20.0]);
    }

    /// glTF 2.0 Appendix C's Hermite spline: p(s) = (2s^3 - 3s^2 + 1) v0 + (s^3 - 2s^2 + s) dt b0 + (-2s^3 +
    /// 3s^2) v1 + (s^3 - s^2) dt a1. With v0 = 0, v1 = 1, out-tangent b0 = 1, in-tangent a1 = 0 and dt = 2, at
    /// s = 0.5: 0.5 + 0.125 * 2 = 0.75.
    #[test]
    fn cubic_spline_is_hermite() {
        // Per key: in-tangent, value, out-tangent.
        let s = sampler(
            Interpolation::CubicSpline,
            vec![9.0, 0.0, 1.0, 0.0, 1.0, 9.0],
            1,
        );
        let mut out = [0.0];
        s.sample(2.0, false, &mut out);
        assert!((out[0] - 0.75).abs() < 1e-6, "{out:?}");
        s.sample(1.0, false, &mut out);
        assert_eq!(out, [0.0]);
        s.sample(3.0, false, &mut out);
        assert_eq!(out, [1.0]);
    }

    /// Rotations: slerp the shorter way, unit length.
    #[test]
    fn rotations_slerp() {
        let a = Quat::IDENTITY;
        let b = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
        // The same rotation as -b: the shorter way still ends at 90 degrees about y.
        let nb = -b;
        let s = sampler(
            Interpolation::Linear,
            [a.to_array(), nb.to_array()].concat(),
            4,
        );
        let mut out = [0.0; 4];
        s.sample(2.0, true, &mut out);
        let q = Quat::from_array(out);
        let want = Quat::from_rotation_y(std::f32::consts::FRAC_PI_4);
        assert!(
            q.abs_diff_eq(want, 1e-5) || q.abs_diff_eq(-want, 1e-5),
            "{q}"
        );
        assert!((q.length() - 1.0).abs() < 1e-6);
    }
}
