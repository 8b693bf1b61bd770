//! Octahedral impostors (docs/methods.md, "Impostors"): a model baked from N x N view directions into an atlas,
//! drawn as a camera-facing card. This file is the CPU half: the flags, the octahedral maps, the frames a view
//! selects and their weights, the card mesh, the atlas's size and the impostor's error. The shader half is
//! `shaders/mesh.wgsl` (`impostor_*`, which mirrors [`select`], [`decode`] and [`frame_basis`]); the baking is
//! `src/gpu/impostor_atlas.rs`.
//!
//! Frames sit on the vertices of an N x N grid over the unit square, frame (i, j) at (i, j) / (N - 1), mapped to
//! a direction by the octahedral map (`full`: the whole sphere, the centre looking down from +y, the corners
//! from below; `hemi`: the upper hemisphere, the centre from +y, the edges on the horizon). A view direction
//! selects the nearest frame, or the 3 frames of the grid triangle it falls in with its barycentric weights
//! (Unreal's Impostor Baker's "3-frame blend"): the weights sum to 1 and change continuously with the direction.
//! The hemi layout shows a view from below the horizon as its horizon frames (the direction's y clamped to 0).

use crate::error::{Error, Result};
use crate::geometry::mesh::Mesh;
use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};

/// `aux` kind of an impostor card's vertex (the shader builds the card facing the camera).
pub const AUX_IMPOSTOR: f32 = 5.0;

/// At most this many models of a scene carry an impostor (the shader's table of them is a uniform array).
pub const MAX_IMPOSTORS: usize = 64;

/// Layers of each colour and data array per impostor: base colour and coverage, emissive (sRGB); normal and
/// depth, occlusion-roughness-metallic (linear).
pub const LAYERS_PER_IMPOSTOR: u32 = 2;

/// Bytes per atlas texel over the four layers (four RGBA8 textures).
pub const BYTES_PER_TEXEL: u64 = 16;

/// Which part of the sphere of view directions the frames cover.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Deserialize, Serialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Layout {
    /// Every direction (octahedron).
    #[default]
    Full,
    /// The upper hemisphere (hemi-octahedron): twice the frames' density; below the horizon the horizon frames.
    Hemi,
}

impl Layout {
    pub fn name(self) -> &'static str {
        match self {
            Layout::Full => "full",
            Layout::Hemi => "hemi",
        }
    }
}

/// The impostor flags (a part of `SceneArgs`): `--impostor` makes an octahedral impostor the last level of
/// every model's chain.
#[derive(Debug, Clone, Copy, PartialEq, clap::Args, Deserialize, Serialize)]
#[serde(default, rename_all = "kebab-case")]
pub struct ImpostorArgs {
    /// End every model's LOD chain with an octahedral impostor baked from its LOD0.
    #[arg(long, help_heading = crate::defaults::heading::IMPOSTORS)]
    pub impostor: bool,
    /// With --impostor: frames along each side of the atlas (N x N view directions, N from 2).
    #[arg(long, default_value_t = 16, value_name = "N", help_heading = crate::defaults::heading::IMPOSTORS)]
    pub impostor_frames: u32,
    /// With --impostor: the views the frames cover.
    #[arg(long, value_enum, value_parser = crate::defaults::names_only::<Layout>(), default_value_t = Layout::Full,
          help_heading = crate::defaults::heading::IMPOSTORS)]
    pub impostor_layout: Layout,
    /// With --impostor: frames a pixel blends (1: the nearest; 3: the grid triangle's, weighted).
    #[arg(long, default_value_t = 3, value_name = "1|3", help_heading = crate::defaults::heading::IMPOSTORS)]
    pub impostor_blend: u32,
    /// With --impostor: shift each frame's lookup by its baked depth (one parallax step).
    #[arg(long, help_heading = crate::defaults::heading::IMPOSTORS)]
    pub impostor_parallax: bool,
    /// With --impostor: the atlas's side in texels.
    #[arg(long, default_value_t = 1024, value_name = "TEXELS", help_heading = crate::defaults::heading::IMPOSTORS)]
    pub impostor_resolution: u32,
    /// With --impostor: the impostor's switch distance (world units; default: where its error reaches
    /// --pixel-error).
    #[arg(long, value_name = "D", help_heading = crate::defaults::heading::IMPOSTORS)]
    pub impostor_distance: Option<f32>,
}

impl Default for ImpostorArgs {
    fn default() -> Self {
        crate::defaults::clap_defaults()
    }
}

impl ImpostorArgs {
    /// The checked settings, None without `--impostor`.
    pub fn params(&self) -> Result<Option<Impostor>> {
        if !self.impostor {
            return Ok(None);
        }
        let bad = |m: String| Err(Error::Config(m));
        if self.impostor_frames < 2 {
            return bad(format!(
                "--impostor-frames {}: an impostor needs at least 2 frames a side (2 x 2 views); engines use 8 \
                 to 16",
                self.impostor_frames
            ));
        }
        if self.impostor_blend != 1 && self.impostor_blend != 3 {
            return bad(format!(
                "--impostor-blend {}: a pixel blends 1 frame (the nearest) or 3 (its grid triangle's)",
                self.impostor_blend
            ));
        }
        if self.impostor_resolution < 2 * self.impostor_frames {
            return bad(format!(
                "--impostor-resolution {} is under 2 texels per frame for {} frames a side",
                self.impostor_resolution, self.impostor_frames
            ));
        }
        if let Some(d) = self.impostor_distance {
            if !(d.is_finite() && d > 0.0) {
                return bad(format!(
                    "--impostor-distance {d}: a distance is a positive number"
                ));
            }
        }
        Ok(Some(Impostor {
            frames: self.impostor_frames,
            layout: self.impostor_layout,
            blend: self.impostor_blend,
            parallax: self.impostor_parallax,
            resolution: self.impostor_resolution,
            distance: self.impostor_distance,
        }))
    }
}

/// An impostor's settings (every model of a scene has the same).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Impostor {
    pub frames: u32,
    pub layout: Layout,
    pub blend: u32,
    pub parallax: bool,
    pub resolution: u32,
    pub distance: Option<f32>,
}

impl Impostor {
    /// Texels along a frame's side (the atlas's side divided among the frames, rounded down).
    pub fn frame_texels(&self) -> u32 {
        self.resolution / self.frames
    }

    /// Bytes of one model's atlas: four RGBA8 layers of the atlas's side squared.
    pub fn atlas_bytes(&self) -> u64 {
        u64::from(self.resolution).pow(2) * BYTES_PER_TEXEL
    }

    /// One line for `describe` and the run's notes.
    pub fn describe(&self) -> String {
        format!(
            "octahedral impostor: {n} x {n} frames ({layout}{below}), {r} x {r} texels ({f} a frame), colour with \
             coverage, normal with depth, occlusion-roughness-metallic and emissive (4 RGBA8 layers, {mib:.1} MiB \
             a model), {blend} frame{s} a pixel, parallax {p}",
            n = self.frames,
            layout = self.layout.name(),
            below = match self.layout {
                Layout::Hemi => ": views from below show the horizon frames",
                Layout::Full => "",
            },
            r = self.resolution,
            f = self.frame_texels(),
            mib = self.atlas_bytes() as f64 / (1024.0 * 1024.0),
            blend = self.blend,
            s = if self.blend == 1 { "" } else { "s" },
            p = if self.parallax { "on" } else { "off" },
        )
    }

    /// The largest angle in radians between a direction and the nearest frame (1 frame) or between neighbouring
    /// frames (3 frames blend them), measured over the grid: the view error the impostor makes.
    pub fn max_view_angle(&self) -> f32 {
        let n = self.frames;
        let mut worst = 0.0f32;
        let angle = |a: Vec3, b: Vec3| a.dot(b).clamp(-1.0, 1.0).acos();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let d = frame_direction(self.layout, n, i, j);
                let right = frame_direction(self.layout, n, i + 1, j);
                let below = frame_direction(self.layout, n, i, j + 1);
                // The edges of the grid's triangles ([`select`]'s): across, down and the shared diagonal.
                worst = worst
                    .max(angle(d, right))
                    .max(angle(d, below))
                    .max(angle(right, below));
            }
        }
        if self.blend == 1 {
            worst * 0.5
        } else {
            worst
        }
    }

    /// The impostor's object-space error for a model of bounding radius `radius` (object space): the larger of
    /// a point on the sphere moving by the view error ([`Impostor::max_view_angle`], parallax halving it), and
    /// one atlas texel.
    pub fn error_abs(&self, radius: f32) -> f32 {
        let angle = self.max_view_angle() * if self.parallax { 0.5 } else { 1.0 };
        let view = radius * (angle * 0.5).sin() * 2.0;
        let texel = 2.0 * radius / self.frame_texels() as f32;
        view.max(texel)
    }
}

/// The octahedral map of `layout`: a unit direction to the unit square.
pub fn encode(layout: Layout, d: Vec3) -> Vec2 {
    let s = d.x.abs() + d.y.abs() + d.z.abs();
    let p = if s > 0.0 { d / s } else { Vec3::Y };
    let q = match layout {
        Layout::Full => {
            if p.y >= 0.0 {
                Vec2::new(p.x, p.z)
            } else {
                Vec2::new((1.0 - p.z.abs()) * sign(p.x), (1.0 - p.x.abs()) * sign(p.z))
            }
        }
        Layout::Hemi => Vec2::new(p.x + p.z, p.x - p.z),
    };
    q * 0.5 + Vec2::splat(0.5)
}

/// The inverse of [`encode`]: a point of the unit square to a unit direction.
pub fn decode(layout: Layout, uv: Vec2) -> Vec3 {
    let a = uv * 2.0 - Vec2::ONE;
    let d = match layout {
        Layout::Full => {
            let y = 1.0 - a.x.abs() - a.y.abs();
            if y >= 0.0 {
                Vec3::new(a.x, y, a.y)
            } else {
                Vec3::new(
                    (1.0 - a.y.abs()) * sign(a.x),
                    y,
                    (1.0 - a.x.abs()) * sign(a.y),
                )
            }
        }
        Layout::Hemi => {
            let x = (a.x + a.y) * 0.5;
            let z = (a.x - a.y) * 0.5;
            Vec3::new(x, (1.0 - x.abs() - z.abs()).max(0.0), z)
        }
    };
    d.normalize()
}

fn sign(x: f32) -> f32 {
    if x >= 0.0 {
        1.0
    } else {
        -1.0
    }
}

/// Frame (i, j)'s view direction (from the model's centre towards the camera that baked it).
pub fn frame_direction(layout: Layout, n: u32, i: u32, j: u32) -> Vec3 {
    let step = 1.0 / (n - 1) as f32;
    decode(layout, Vec2::new(i as f32 * step, j as f32 * step))
}

/// A frame's image axes (right, up) for view direction `f`: up is +y's part across `f`, or -z looking straight
/// down or up.
pub fn frame_basis(f: Vec3) -> (Vec3, Vec3) {
    let up_ref = if f.y.abs() > 0.999 {
        Vec3::NEG_Z
    } else {
        Vec3::Y
    };
    let right = up_ref.cross(f).normalize();
    (right, f.cross(right))
}

/// The direction a view from `d` is drawn from: `d` itself, or under the hemi layout with y clamped to 0 (a view
/// from below shows the horizon frames). Returns whether it was clamped.
pub fn shown_direction(layout: Layout, d: Vec3) -> (Vec3, bool) {
    match layout {
        Layout::Hemi if d.y < 0.0 => {
            let h = Vec3::new(d.x, 0.0, d.z);
            let h = if h.length_squared() > 0.0 {
                h.normalize()
            } else {
                Vec3::X
            };
            (h, true)
        }
        _ => (d, false),
    }
}

/// The frames a view from direction `d` draws: (i, j, weight), 1 or 3 of them, the weights summing to 1.
pub fn select(layout: Layout, n: u32, blend: u32, d: Vec3) -> Vec<(u32, u32, f32)> {
    let (d, _) = shown_direction(layout, d);
    let top = (n - 1) as f32;
    let g = encode(layout, d) * top;
    if blend == 1 {
        let r = g.round().clamp(Vec2::ZERO, Vec2::splat(top));
        return vec![(r.x as u32, r.y as u32, 1.0)];
    }
    let cell = g.floor().clamp(Vec2::ZERO, Vec2::splat(top - 1.0));
    let f = g - cell;
    let (i, j) = (cell.x as u32, cell.y as u32);
    if f.x + f.y < 1.0 {
        vec![(i, j, 1.0 - f.x - f.y), (i + 1, j, f.x), (i, j + 1, f.y)]
    } else {
        vec![
            (i + 1, j + 1, f.x + f.y - 1.0),
            (i, j + 1, 1.0 - f.x),
            (i + 1, j, 1.0 - f.y),
        ]
    }
}

/// The card an impostor level draws: four vertices at the model's centre `centre` (object space) whose `aux`
/// is (corner x, corner y, [`AUX_IMPOSTOR`], slot), the shader spreading them across the view; two triangles,
/// in material `material` where the model has materials.
pub fn card_mesh(name: &str, centre: Vec3, slot: u32, material: Option<u32>) -> Result<Mesh> {
    let c = centre.to_array();
    let mesh = Mesh::new(
        name,
        vec![c; 4],
        Some(vec![[0.0, 0.0, 1.0]; 4]),
        vec![0, 1, 2, 0, 2, 3],
    )?;
    let s = slot as f32;
    let aux = vec![
        [-1.0, -1.0, AUX_IMPOSTOR, s],
        [1.0, -1.0, AUX_IMPOSTOR, s],
        [1.0, 1.0, AUX_IMPOSTOR, s],
        [-1.0, 1.0, AUX_IMPOSTOR, s],
    ];
    let mesh = mesh.with_aux(name, aux)?;
    match material {
        Some(m) => mesh.with_parts(name, &[(m, 6)]),
        None => Ok(mesh),
    }
}

/// Whether `mesh` is an impostor's card.
pub fn is_card(mesh: &Mesh) -> bool {
    mesh.aux.first().is_some_and(|a| a[2] == AUX_IMPOSTOR)
}

/// Whether `chain` ends in an impostor's card (`--impostor` appends it as the last level, and only there).
pub fn ends_in_card(chain: &crate::geometry::lod::LodChain) -> bool {
    chain.lods.last().is_some_and(|l| is_card(&l.mesh))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dirs() -> Vec<Vec3> {
        // A deterministic spread over the sphere (a Fibonacci lattice), poles included.
        let n = 2000;
        let mut out = vec![Vec3::Y, Vec3::NEG_Y, Vec3::X, Vec3::Z];
        for k in 0..n {
            let y = 1.0 - 2.0 * (k as f32 + 0.5) / n as f32;
            let r = (1.0 - y * y).sqrt();
            let a = k as f32 * 2.399_963;
            out.push(Vec3::new(r * a.cos(), y, r * a.sin()));
        }
        out
    }

    #[test]
    fn the_maps_invert_each_other() {
        for d in dirs() {
            let back = decode(Layout::Full, encode(Layout::Full, d));
            assert!(back.distance(d) < 1e-4, "{d} -> {back}");
            if d.y >= 0.0 {
                let back = decode(Layout::Hemi, encode(Layout::Hemi, d));
                assert!(back.distance(d) < 1e-4, "hemi {d} -> {back}");
            }
        }
    }

    #[test]
    fn frame_axes_are_orthonormal_and_face_the_view() {
        for d in dirs() {
            let (r, u) = frame_basis(d);
            assert!((r.length() - 1.0).abs() < 1e-4 && (u.length() - 1.0).abs() < 1e-4);
            assert!(r.dot(u).abs() < 1e-4 && r.dot(d).abs() < 1e-4);
            // right x up = towards the viewer: the card is wound counter-clockwise as seen.
            assert!(r.cross(u).dot(d) > 0.999);
        }
    }

    /// The weights sum to 1 and lie in [0, 1], for both layouts, every N tried and both modes.
    #[test]
    fn weights_sum_to_one() {
        for layout in [Layout::Full, Layout::Hemi] {
            for n in [2, 8, 12, 16] {
                for blend in [1, 3] {
                    for d in dirs() {
                        let s = select(layout, n, blend, d);
                        let sum: f32 = s.iter().map(|f| f.2).sum();
                        assert!(
                            (sum - 1.0).abs() < 1e-5,
                            "{layout:?} {n} {blend} {d}: {s:?}"
                        );
                        assert!(s.iter().all(|f| (-1e-6..=1.0 + 1e-6).contains(&f.2)));
                        assert!(s.iter().all(|f| f.0 < n && f.1 < n));
                    }
                }
            }
        }
    }

    /// The blend as a function of the view direction: each frame's weight, frames of the same direction (the
    /// full octahedron's mirrored border frames) counted as one.
    fn weight_map(layout: Layout, n: u32, d: Vec3) -> Vec<(Vec3, f32)> {
        let mut out: Vec<(Vec3, f32)> = Vec::new();
        for (i, j, w) in select(layout, n, 3, d) {
            let f = frame_direction(layout, n, i, j);
            match out.iter_mut().find(|(g, _)| g.distance(f) < 1e-4) {
                Some(e) => e.1 += w,
                None => out.push((f, w)),
            }
        }
        out
    }

    fn map_distance(a: &[(Vec3, f32)], b: &[(Vec3, f32)]) -> f32 {
        let weight_in = |m: &[(Vec3, f32)], f: Vec3| {
            m.iter()
                .filter(|(g, _)| g.distance(f) < 1e-4)
                .map(|e| e.1)
                .sum::<f32>()
        };
        let mut sum = 0.0;
        for (f, w) in a {
            sum += (w - weight_in(b, *f)).abs();
        }
        for (f, w) in b {
            if a.iter().all(|(g, _)| g.distance(*f) >= 1e-4) {
                sum += w;
            }
        }
        sum
    }

    /// The 3-frame weights change continuously with the direction, across cell and triangle borders and the
    /// full octahedron's folds: two directions 1e-4 rad apart have weights within 0.01 of each other (a
    /// step across a border without continuity moves some weight by up to 1).
    #[test]
    fn blend_weights_are_continuous_across_frame_borders() {
        for layout in [Layout::Full, Layout::Hemi] {
            for n in [8, 16] {
                for d in dirs() {
                    if layout == Layout::Hemi && d.y < 0.0 {
                        continue;
                    }
                    let axis = d.any_orthonormal_vector();
                    let e = glam::Quat::from_axis_angle(axis, 1e-4) * d;
                    let dist = map_distance(&weight_map(layout, n, d), &weight_map(layout, n, e));
                    assert!(dist < 0.01, "{layout:?} N {n}: {d} -> {e}: {dist}");
                }
                // Along a meridian through the borders, in fine steps.
                for k in 0..4000 {
                    let a = k as f32 / 4000.0 * std::f32::consts::PI;
                    let d = Vec3::new(a.sin() * 0.6, a.cos(), a.sin() * 0.8);
                    let e = Vec3::new(
                        (a + 1e-4).sin() * 0.6,
                        (a + 1e-4).cos(),
                        (a + 1e-4).sin() * 0.8,
                    );
                    if layout == Layout::Hemi && (d.y < 0.0 || e.y < 0.0) {
                        continue;
                    }
                    let dist = map_distance(&weight_map(layout, n, d), &weight_map(layout, n, e));
                    assert!(dist < 0.01, "{layout:?} N {n} at {a}: {dist}");
                }
            }
        }
    }

    /// The nearest frame is one of the 3 frames the blend draws (so 1 and 3 frames show the same view on a
    /// frame's own direction).
    #[test]
    fn the_nearest_frame_is_among_the_blended_ones() {
        for layout in [Layout::Full, Layout::Hemi] {
            for d in dirs() {
                let one = select(layout, 12, 1, d)[0];
                let three = select(layout, 12, 3, d);
                assert!(
                    three.iter().any(|f| (f.0, f.1) == (one.0, one.1)),
                    "{d}: {one:?} vs {three:?}"
                );
            }
        }
    }

    /// The hemi layout says what it shows below the horizon: the horizon frames, never a frame of its upper
    /// half, and the view is flagged as clamped.
    #[test]
    fn hemi_shows_the_horizon_frames_from_below() {
        for d in dirs().into_iter().filter(|d| d.y < -0.01) {
            let (shown, clamped) = shown_direction(Layout::Hemi, d);
            assert!(clamped && shown.y == 0.0);
            for (i, j, w) in select(Layout::Hemi, 16, 3, d) {
                if w > 1e-4 {
                    assert!(
                        frame_direction(Layout::Hemi, 16, i, j).y < 0.2,
                        "{d}: frame {i},{j}"
                    );
                }
            }
        }
        assert!(!shown_direction(Layout::Full, Vec3::NEG_Y).1);
    }

    #[test]
    fn bad_settings_are_refused() {
        let args = |f: &dyn Fn(&mut ImpostorArgs)| {
            let mut a = ImpostorArgs {
                impostor: true,
                ..Default::default()
            };
            f(&mut a);
            a.params()
        };
        for n in [0, 1] {
            let e = args(&|a| a.impostor_frames = n).unwrap_err().to_string();
            assert!(e.contains("--impostor-frames"), "{e}");
        }
        assert!(args(&|a| a.impostor_blend = 2).is_err());
        assert!(args(&|a| a.impostor_resolution = 16).is_err());
        assert!(args(&|a| a.impostor_distance = Some(-1.0)).is_err());
        assert!(args(&|_| ()).unwrap().is_some());
        assert!(ImpostorArgs::default().params().unwrap().is_none());
    }

    /// More frames, a smaller view error; 3 frames blend neighbours twice the nearest frame's half-gap apart.
    #[test]
    fn the_error_shrinks_with_more_frames() {
        let p = |frames, blend| Impostor {
            frames,
            layout: Layout::Full,
            blend,
            parallax: false,
            resolution: 4096,
            distance: None,
        };
        assert!(p(16, 3).error_abs(1.0) < p(8, 3).error_abs(1.0));
        assert!((p(12, 3).max_view_angle() - 2.0 * p(12, 1).max_view_angle()).abs() < 1e-6);
    }
}
