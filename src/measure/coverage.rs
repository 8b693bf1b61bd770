//! Where on screen a frame can differ from the background: a conservative bound of every instance's pixels,
//! so that the quality pass's kernels read only those pixels and lodpop's counterfactual draws only where it
//! can differ, with every figure unchanged (exact integer sums over the same nonzero terms).
//!
//! An instance's pixels lie inside the projection of its model's **reach box**: the object-space box holding
//! every vertex of every LOD of its chain (geomorph's targets are on coarse triangles, so inside it too), grown
//! to the cylinder a windmill blade sweeps about its hub. The box's eight corners are projected with the
//! frame's instance matrix and camera; when all lie in front of the camera, the convex hull of their images
//! holds the image of the box (a perspective map keeps convex sets convex where w > 0), and the pixel rectangle
//! around them, grown by [`MARGIN_PX`], holds every pixel centre a triangle of the instance can cover. A corner
//! at or behind the camera plane makes the instance's bound the whole frame.
//!
//! The bound holds only for a frame that shows nothing but the instances' meshes over the background: a method
//! says so with [`crate::methods::common::Counterfactual::image_confined_to_instances`], and a scene with TAA (the history
//! shows earlier frames), shadows (a shadow falls outside its caster) or unified blocks (one mesh in world
//! space) always uses the whole frame.

use crate::geometry::lod::LodChain;
use crate::geometry::mesh::AUX_BLADE;
use crate::scene::Scene;
use glam::{Mat4, Vec3, Vec4};

/// Side of a metric tile in pixels (`TILE` in shaders/metrics.wgsl).
pub const TILE: u32 = 16;

/// Pixels added on every side of a projected bound: pixel centres are covered at most half a pixel outside
/// the exact projection; one more pixel absorbs f32 rounding of the projection.
pub const MARGIN_PX: f32 = 2.0;

/// A half-open pixel rectangle `x0..x1` by `y0..y1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PixelRect {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl PixelRect {
    pub fn full(width: u32, height: u32) -> PixelRect {
        PixelRect {
            x0: 0,
            y0: 0,
            x1: width,
            y1: height,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.x0 >= self.x1 || self.y0 >= self.y1
    }

    /// The smallest rectangle holding both (an empty one adds nothing).
    pub fn union(self, other: PixelRect) -> PixelRect {
        if self.is_empty() {
            return other;
        }
        if other.is_empty() {
            return self;
        }
        PixelRect {
            x0: self.x0.min(other.x0),
            y0: self.y0.min(other.y0),
            x1: self.x1.max(other.x1),
            y1: self.y1.max(other.y1),
        }
    }

    /// The two share a pixel.
    pub fn overlaps(&self, other: &PixelRect) -> bool {
        !self.is_empty()
            && !other.is_empty()
            && self.x0 < other.x1
            && other.x0 < self.x1
            && self.y0 < other.y1
            && other.y0 < self.y1
    }

    pub fn pixels(&self) -> u64 {
        if self.is_empty() {
            0
        } else {
            (self.x1 - self.x0) as u64 * (self.y1 - self.y0) as u64
        }
    }
}

/// The object-space box holding every position a vertex of `chain` can take: every LOD's vertices and, for
/// windmill blades, the cylinder about the hub axis (parallel to +z through (0, hub_y)) of radius the farthest
/// vertex from that axis (a mix of two vertices inside the cylinder stays inside, and the rotation keeps it).
pub fn reach_box(chain: &LodChain) -> (Vec3, Vec3) {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    let mut hubs: Vec<f32> = Vec::new();
    for lod in &chain.lods {
        for (i, p) in lod.mesh.positions.iter().enumerate() {
            let p = Vec3::from(*p);
            lo = lo.min(p);
            hi = hi.max(p);
            if let Some(aux) = lod.mesh.aux.get(i) {
                if aux[2] == AUX_BLADE && !hubs.contains(&aux[3]) {
                    hubs.push(aux[3]);
                }
            }
        }
    }
    for hub in hubs {
        let mut rho = 0.0f32;
        for lod in &chain.lods {
            for p in &lod.mesh.positions {
                rho = rho.max((p[0] * p[0] + (p[1] - hub) * (p[1] - hub)).sqrt());
            }
        }
        lo = lo.min(Vec3::new(-rho, hub - rho, lo.z));
        hi = hi.max(Vec3::new(rho, hub + rho, hi.z));
    }
    (lo, hi)
}

/// The pixel rectangle holding every pixel the box `(lo, hi)` covers through `clip_from_object`, clamped to
/// the frame (empty when off screen), or the whole frame when a corner lies at or behind the camera plane.
pub fn project_box(
    (lo, hi): (Vec3, Vec3),
    clip_from_object: Mat4,
    width: u32,
    height: u32,
) -> PixelRect {
    if !(lo.is_finite() && hi.is_finite()) {
        return PixelRect::full(width, height);
    }
    let (mut min_x, mut min_y) = (f32::INFINITY, f32::INFINITY);
    let (mut max_x, mut max_y) = (f32::NEG_INFINITY, f32::NEG_INFINITY);
    for c in 0..8 {
        let corner = Vec3::new(
            if c & 1 == 0 { lo.x } else { hi.x },
            if c & 2 == 0 { lo.y } else { hi.y },
            if c & 4 == 0 { lo.z } else { hi.z },
        );
        let clip: Vec4 = clip_from_object * corner.extend(1.0);
        if !clip.is_finite() || clip.w <= 1e-6 {
            return PixelRect::full(width, height);
        }
        // NDC x right, y up; pixel rows go down.
        let x = (clip.x / clip.w * 0.5 + 0.5) * width as f32;
        let y = (0.5 - clip.y / clip.w * 0.5) * height as f32;
        min_x = min_x.min(x);
        max_x = max_x.max(x);
        min_y = min_y.min(y);
        max_y = max_y.max(y);
    }
    let clamp = |v: f32, n: u32| v.clamp(0.0, n as f32) as u32;
    PixelRect {
        x0: clamp((min_x - MARGIN_PX).floor(), width),
        y0: clamp((min_y - MARGIN_PX).floor(), height),
        x1: clamp((max_x + MARGIN_PX).ceil(), width),
        y1: clamp((max_y + MARGIN_PX).ceil(), height),
    }
}

/// Per frame, the pixels that can differ from the background, as instance rectangles and metric tiles.
pub struct Coverage {
    /// The bound is usable (the method's image is confined to its instances and the scene has no effect
    /// that reaches beyond them); otherwise every query answers the whole frame.
    pub bounded: bool,
    width: u32,
    height: u32,
    tiles_x: u32,
    tiles_y: u32,
    /// Each model's reach box (used for the bound only when `bounded`).
    boxes: Vec<(Vec3, Vec3)>,
    /// The tiles the previous frame covered (None before the first frame).
    previous: Option<Vec<bool>>,
}

impl Coverage {
    /// `confined`: the method (and the reference it is compared with) draws only its instances' meshes over
    /// the background.
    pub fn new(scene: &Scene, confined: bool) -> Coverage {
        let bounded =
            confined && scene.taa.is_none() && scene.shadows.is_none() && scene.unified.is_none();
        Coverage {
            bounded,
            width: scene.width,
            height: scene.height,
            tiles_x: scene.width.div_ceil(TILE),
            tiles_y: scene.height.div_ceil(TILE),
            boxes: scene
                .models
                .iter()
                .map(|m| m.deformed_reach.unwrap_or_else(|| reach_box(&m.chain)))
                .collect(),
            previous: None,
        }
    }

    /// Forgets the previous frame (at the start of a pass).
    pub fn reset(&mut self) {
        self.previous = None;
    }

    pub fn tile_count(&self) -> u32 {
        self.tiles_x * self.tiles_y
    }

    /// Instance `i`'s pixel rectangle on this frame (the whole frame where the bound is not usable).
    pub fn instance_rect(
        &self,
        scene: &Scene,
        i: usize,
        matrix: Mat4,
        view_proj: Mat4,
    ) -> PixelRect {
        if !self.bounded {
            return PixelRect::full(self.width, self.height);
        }
        self.projected(scene, i, matrix, view_proj)
    }

    /// The pixels of instance `i`'s rectangle on this frame, bounded or not: its weight among the instances
    /// that switch on one frame (`records::events`).
    pub fn instance_pixels(&self, scene: &Scene, i: usize, matrix: Mat4, view_proj: Mat4) -> u64 {
        self.projected(scene, i, matrix, view_proj).pixels()
    }

    /// The projection of instance `i`'s reach box on this frame.
    fn projected(&self, scene: &Scene, i: usize, matrix: Mat4, view_proj: Mat4) -> PixelRect {
        let model = scene.instances[i].model as usize;
        project_box(
            self.boxes[model],
            view_proj * matrix,
            self.width,
            self.height,
        )
    }

    /// The union of the rectangles of the instances `which` picks (empty when it picks none).
    pub fn rect_of(
        &self,
        scene: &Scene,
        matrices: &[Mat4],
        view_proj: Mat4,
        which: impl Fn(usize) -> bool,
    ) -> PixelRect {
        let mut r = PixelRect {
            x0: 0,
            y0: 0,
            x1: 0,
            y1: 0,
        };
        for (i, m) in matrices.iter().enumerate() {
            if which(i) {
                r = r.union(self.instance_rect(scene, i, *m, view_proj));
                if r == PixelRect::full(self.width, self.height) {
                    break;
                }
            }
        }
        r
    }

    /// The metric tiles (indices `ty * tiles_x + tx`) the metric kernel reads this frame: those any
    /// instance's rectangle touches now or touched on the previous frame (the kernel keeps each pixel's error
    /// for the next frame's pop, so a pixel left out must have had a zero error then and have one now); every
    /// tile on a pass's first frame and whenever the bound is not usable.
    pub fn frame_tiles(&mut self, scene: &Scene, matrices: &[Mat4], view_proj: Mat4) -> Vec<u32> {
        let all: Vec<u32> = (0..self.tile_count()).collect();
        if !self.bounded {
            return all;
        }
        let mut now = vec![false; self.tile_count() as usize];
        for (i, m) in matrices.iter().enumerate() {
            let r = self.instance_rect(scene, i, *m, view_proj);
            if r.is_empty() {
                continue;
            }
            for ty in r.y0 / TILE..r.y1.div_ceil(TILE) {
                for tx in r.x0 / TILE..r.x1.div_ceil(TILE) {
                    now[(ty * self.tiles_x + tx) as usize] = true;
                }
            }
        }
        let tiles = match &self.previous {
            None => all,
            Some(before) => (0..self.tile_count())
                .filter(|&t| now[t as usize] || before[t as usize])
                .collect(),
        };
        self.previous = Some(now);
        tiles
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_box_in_front_projects_inside_its_margin() {
        let view = Mat4::look_at_rh(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y);
        let proj = Mat4::perspective_rh(60f32.to_radians(), 1.0, 0.1, 100.0);
        let r = project_box((Vec3::splat(-0.5), Vec3::splat(0.5)), proj * view, 100, 100);
        // The nearest face (z = 0.5, 4.5 from the eye) spans 0.5 / (4.5 tan 30 deg) = 0.192 of the half-width.
        let half = 0.5 / (4.5 * 30f32.to_radians().tan()) * 50.0;
        assert_eq!(r.x0, (50.0 - half - MARGIN_PX).floor() as u32);
        assert_eq!(r.x1, (50.0 + half + MARGIN_PX).ceil() as u32);
        assert_eq!((r.y0, r.y1), (r.x0, r.x1), "square and centred");
    }

    #[test]
    fn a_box_behind_the_eye_is_the_whole_frame_and_one_aside_is_empty() {
        let view = Mat4::look_at_rh(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y);
        let proj = Mat4::perspective_rh(60f32.to_radians(), 1.0, 0.1, 100.0);
        let around_eye = (Vec3::new(-1.0, -1.0, 4.0), Vec3::new(1.0, 1.0, 6.0));
        assert_eq!(
            project_box(around_eye, proj * view, 64, 48),
            PixelRect::full(64, 48)
        );
        let aside = (Vec3::new(40.0, -1.0, -1.0), Vec3::new(42.0, 1.0, 1.0));
        assert!(project_box(aside, proj * view, 64, 48).is_empty());
    }

    #[test]
    fn the_reach_box_holds_a_turning_blade() {
        use crate::geometry::lod::{Lod, LodChain};
        use crate::geometry::mesh::Mesh;
        let mesh = Mesh {
            positions: vec![[0.0, 1.0, 0.0], [0.2, 3.0, 0.1], [-0.2, 3.0, -0.1]],
            normals: vec![[0.0, 0.0, 1.0]; 3],
            indices: vec![0, 1, 2],
            aux: vec![[0.0, 0.0, AUX_BLADE, 1.0]; 3],
            data: Default::default(),
            parts: Vec::new(),
        };
        let chain = LodChain {
            lods: vec![Lod {
                mesh,
                target_fraction: 1.0,
                error_abs: 0.0,
            }],
        };
        let (lo, hi) = reach_box(&chain);
        let rho = (0.2f32 * 0.2 + 4.0).sqrt();
        assert!((lo.x + rho).abs() < 1e-6 && (hi.x - rho).abs() < 1e-6);
        assert!((lo.y - (1.0 - rho)).abs() < 1e-6 && (hi.y - (1.0 + rho)).abs() < 1e-6);
        assert_eq!((lo.z, hi.z), (-0.1, 0.1));
    }

    #[test]
    fn a_union_ignores_the_empty_rectangle() {
        let r = PixelRect {
            x0: 3,
            y0: 0,
            x1: 17,
            y1: 5,
        };
        assert_eq!(r.union(PixelRect::full(0, 0)), r, "empty adds nothing");
        assert_eq!(r.pixels(), 14 * 5);
        let right = PixelRect { x0: 17, ..r };
        assert!(!r.overlaps(&right), "half-open: x 17 is not in r");
        assert!(r.overlaps(&PixelRect { x0: 16, ..r }));
    }
}
