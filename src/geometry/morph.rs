//! Geomorph correspondences (Sheliemietiev et al. 2023 sections 10-11): for every vertex of a finer LOD, the point of the next
//! coarser LOD it moves to during a transition, with the normal it takes there.
//!
//! - `nearest` (the paper's): the nearest coarse vertex, with the normal difference in the distance:
//!   `|p - q|^2 + (lambda |n_p - n_q|)^2`, lambda the coarse mesh's mean edge length, so a vertex is not pulled to
//!   a close vertex on the far side of a thin part (an ear) when one a little farther faces the same way.
//!   Found with a k-d tree over the coarse vertices (the position term alone bounds the search).
//! - `nearest-position`: the same with lambda = 0, the ablation of the normal term.
//! - `surface`: the closest point on the coarse surface, the normal interpolated there (barycentric, normalised).
//!   Found with a bounding-volume hierarchy over the coarse triangles.
//!
//! Each LOD pair is computed once per process and cached (keyed by both meshes' contents).

use crate::geometry::mesh::Mesh;
use glam::Vec3;
use serde::Serialize;
use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::sync::{Arc, Mutex, OnceLock};

/// `--correspondence`: how geomorph pairs fine vertices with the coarse LOD.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, serde::Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum Correspondence {
    /// `surface` on a user's glTF file, `nearest` (the paper's) on the built-in scenes.
    Auto,
    /// Nearest coarse vertex, normals in the distance (Sheliemietiev et al. 2023 section 11).
    Nearest,
    /// Nearest coarse vertex by position alone (lambda = 0): the ablation of the normal term, which section 11
    /// says the metric must have.
    NearestPosition,
    /// Closest point on the coarse surface.
    Surface,
}

impl Correspondence {
    /// `auto` resolved for a scene: `surface` on a user's file (`user_file`), whose textured, hard-edged models
    /// the nearest vertex folds (on Avocado, DamagedHelmet and Fox `surface` pops least: docs/methods.md,
    /// "geomorph"), else `nearest`, the paper's, which the bunny experiments reproduce.
    pub fn resolve(self, user_file: bool) -> Correspondence {
        match self {
            Correspondence::Auto if user_file => Correspondence::Surface,
            Correspondence::Auto => Correspondence::Nearest,
            other => other,
        }
    }
}

/// Per fine vertex: where it goes on the coarse LOD, and the normal it has there.
#[derive(Debug, Clone, PartialEq)]
pub struct MorphTargets {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    /// Per fine vertex, the coarse vertices its target is made of and their weights (a nearest vertex: itself
    /// with weight 1; a surface point: its triangle's corners with barycentric weights), so that a target
    /// follows the coarse mesh when it deforms ([`MorphTargets::follow`]).
    pub sources: Vec<[(u32, f32); 3]>,
    /// Per fine vertex, the coarse vertices its texture coordinates, tangent and colour go to, and their
    /// weights: from the fine vertex's own texture chart ([`surface_sources`]); `sources` where the meshes have
    /// no texture coordinates.
    pub surface: Vec<[(u32, f32); 3]>,
}

impl MorphTargets {
    /// The targets on the coarse mesh posed at `positions` and `normals` (normals interpolated and
    /// normalised, the undeformed target's normal where they cancel), into `out_positions`, `out_normals`.
    pub fn follow(
        &self,
        positions: &[[f32; 3]],
        normals: &[[f32; 3]],
        out_positions: &mut Vec<[f32; 3]>,
        out_normals: &mut Vec<[f32; 3]>,
    ) {
        out_positions.clear();
        out_normals.clear();
        for (k, src) in self.sources.iter().enumerate() {
            let (mut p, mut n) = (Vec3::ZERO, Vec3::ZERO);
            for &(i, w) in src {
                if w != 0.0 {
                    p += v(&positions[i as usize]) * w;
                    n += v(&normals[i as usize]) * w;
                }
            }
            out_positions.push(p.to_array());
            out_normals.push(n.try_normalize().map_or(self.normals[k], |n| n.to_array()));
        }
    }
}

type MorphCache = Mutex<HashMap<(u64, u64, Correspondence), Arc<MorphTargets>>>;

/// The targets of `fine`'s vertices on `coarse`, from the process-wide cache or computed now.
pub fn morph_targets(fine: &Mesh, coarse: &Mesh, how: Correspondence) -> Arc<MorphTargets> {
    static CACHE: OnceLock<MorphCache> = OnceLock::new();
    let key = (mesh_hash(fine), mesh_hash(coarse), how);
    let cache = CACHE.get_or_init(Default::default);
    if let Some(t) = cache.lock().ok().and_then(|c| c.get(&key).cloned()) {
        return t;
    }
    let mut t = match how {
        Correspondence::Nearest | Correspondence::Auto => nearest_vertex(fine, coarse),
        Correspondence::NearestPosition => nearest_vertex_weighted(fine, coarse, 0.0),
        Correspondence::Surface => closest_surface(fine, coarse),
    };
    t.surface = surface_sources(fine, coarse, &t);
    let t = Arc::new(t);
    if let Ok(mut c) = cache.lock() {
        c.insert(key, t.clone());
    }
    t
}

/// [`morph_targets`] within each material: a fine vertex of a material's triangles targets the coarse LOD's
/// triangles of the same material (a target on another material's surface would take its texture coordinates
/// from another texture's layout), or the whole coarse mesh where the coarse LOD lost that material. The same as
/// [`morph_targets`] for a mesh of one material or none.
pub fn morph_targets_by_material(
    fine: &Mesh,
    coarse: &Mesh,
    how: Correspondence,
) -> Arc<MorphTargets> {
    if fine.parts.len() < 2 {
        return morph_targets(fine, coarse, how);
    }
    let mut out = MorphTargets {
        positions: fine.positions.clone(),
        normals: fine.normals.clone(),
        sources: vec![[(0, 0.0); 3]; fine.positions.len()],
        surface: vec![[(0, 0.0); 3]; fine.positions.len()],
    };
    for part in &fine.parts {
        let (sub_fine, fine_order) = sub_mesh(fine, part.material);
        let (sub_coarse, coarse_order) =
            match coarse.parts.iter().any(|p| p.material == part.material) {
                true => sub_mesh(coarse, part.material),
                false => (coarse.clone(), (0..coarse.vertex_count() as u32).collect()),
            };
        let t = morph_targets(&sub_fine, &sub_coarse, how);
        for (k, &v) in fine_order.iter().enumerate() {
            let v = v as usize;
            out.positions[v] = t.positions[k];
            out.normals[v] = t.normals[k];
            out.sources[v] = t.sources[k].map(|(i, w)| (coarse_order[i as usize], w));
            out.surface[v] = t.surface[k].map(|(i, w)| (coarse_order[i as usize], w));
        }
    }
    Arc::new(out)
}

/// The triangles of `mesh`'s parts of `material` as a mesh of their own, and each of its vertices' index in
/// `mesh`.
fn sub_mesh(mesh: &Mesh, material: u32) -> (Mesh, Vec<u32>) {
    let mut remap = vec![u32::MAX; mesh.vertex_count()];
    let mut order = Vec::new();
    let mut indices = Vec::new();
    for p in mesh.parts.iter().filter(|p| p.material == material) {
        let a = p.first_index as usize;
        for &i in &mesh.indices[a..a + p.index_count as usize] {
            let slot = &mut remap[i as usize];
            if *slot == u32::MAX {
                *slot = order.len() as u32;
                order.push(i);
            }
            indices.push(*slot);
        }
    }
    let pick = |v: &[[f32; 3]]| order.iter().map(|&i| v[i as usize]).collect::<Vec<_>>();
    let sub = Mesh {
        positions: pick(&mesh.positions),
        normals: pick(&mesh.normals),
        indices,
        aux: order.iter().map(|&i| mesh.aux[i as usize]).collect(),
        data: crate::geometry::attributes::VertexData {
            deform: None,
            ..mesh.data.gather(&order)
        },
        parts: Vec::new(),
    };
    (sub, order)
}

fn mesh_hash(m: &Mesh) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    bytemuck::cast_slice::<_, u8>(&m.positions).hash(&mut h);
    bytemuck::cast_slice::<_, u8>(&m.normals).hash(&mut h);
    m.indices.hash(&mut h);
    for uv in [&m.data.uv0, &m.data.uv1] {
        uv.as_deref()
            .map(bytemuck::cast_slice::<_, u8>)
            .hash(&mut h);
    }
    h.finish()
}

fn v(p: &[f32; 3]) -> Vec3 {
    Vec3::from(*p)
}

/// Mean edge length of a mesh (the lambda of the nearest-vertex metric).
pub fn mean_edge_length(m: &Mesh) -> f32 {
    let mut sum = 0.0f64;
    for t in m.indices.chunks_exact(3) {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            sum += v(&m.positions[a as usize]).distance(v(&m.positions[b as usize])) as f64;
        }
    }
    (sum / m.indices.len().max(1) as f64) as f32
}

/// The paper's correspondence: nearest coarse vertex under `|p - q|^2 + (lambda |n_p - n_q|)^2`.
pub fn nearest_vertex(fine: &Mesh, coarse: &Mesh) -> MorphTargets {
    nearest_vertex_weighted(fine, coarse, mean_edge_length(coarse))
}

/// Nearest coarse vertex under `|p - q|^2 + (lambda |n_p - n_q|)^2` for a given `lambda` (0: position alone).
///
/// The search is over positions, not vertices: where a mesh splits a position into several vertices (its
/// wedges: a texture seam, a hard edge), the wedges of a fine position all take one target position, the
/// coarse position nearest under the metric with each side's normal the mean of its wedges', so the morph opens
/// no crack along a seam. Which coarse wedge at that position each fine wedge takes its normal (and texture
/// coordinates) from is then [`nearest_wedge`]'s choice.
pub fn nearest_vertex_weighted(fine: &Mesh, coarse: &Mesh, lambda: f32) -> MorphTargets {
    let coarse_points = Points::of(coarse);
    let fine_points = Points::of(fine);
    let pts = &coarse_points.positions;
    let nrm = &coarse_points.normals;
    let mut idx: Vec<u32> = (0..pts.len() as u32).collect();
    kd_build(pts, &mut idx, 0);
    // Per fine position, the coarse position it goes to.
    let goes_to: Vec<u32> = fine_points
        .positions
        .iter()
        .zip(&fine_points.normals)
        .map(|(&p, &n)| {
            let metric = |j: u32| {
                let j = j as usize;
                pts[j].distance_squared(p) + lambda * lambda * nrm[j].distance_squared(n)
            };
            let mut best = (f32::INFINITY, u32::MAX);
            kd_search(pts, &idx, 0, p, &metric, &mut best);
            best.1
        })
        .collect();
    let mut positions = Vec::with_capacity(fine.positions.len());
    let mut normals = Vec::with_capacity(fine.positions.len());
    let mut sources = Vec::with_capacity(fine.positions.len());
    for k in 0..fine.vertex_count() {
        let point = goes_to[fine_points.of_vertex[k] as usize] as usize;
        let j = nearest_wedge(fine, k, coarse, &coarse_points.wedges[point]);
        positions.push(coarse.positions[j as usize]);
        normals.push(coarse.normals[j as usize]);
        sources.push([(j, 1.0), (j, 0.0), (j, 0.0)]);
    }
    MorphTargets {
        positions,
        normals,
        sources,
        surface: Vec::new(),
    }
}

/// Per fine vertex, the coarse vertices its texture coordinates, tangent and colour go to (with weights), from
/// the fine vertex's own texture chart.
///
/// A chart ([`charts`]) is a part of the surface whose texture coordinates are continuous. The attribute-aware
/// simplifier keeps charts apart, so each chart of the fine mesh has one on the coarse mesh: the coarse chart
/// holding the most of its vertices that the coarse mesh kept with the same texture coordinates (or, for a chart
/// with none kept, the charts of the wedges nearest in attributes at its vertices' targets). A target's source
/// at a position where its chart has a wedge is that wedge (the nearest in attributes of the chart's); where the
/// target position lies in another chart (across a seam: its chart ends short of it on the coarse mesh), the
/// attributes are those of the closest point to the target on the chart's own coarse triangles. Either way the
/// texture coordinates stay in the vertex's part of the texture, so the morph does not sweep them across the
/// atlas; the price at such a vertex is that its position and texture coordinates come from points up to a
/// seam's width apart. Meshes without texture coordinates keep the targets' own sources.
pub fn surface_sources(fine: &Mesh, coarse: &Mesh, t: &MorphTargets) -> Vec<[(u32, f32); 3]> {
    if fine.data.uv0.is_none() || coarse.data.uv0.is_none() {
        return t.sources.clone();
    }
    let (fine_chart, fine_charts) = charts(fine);
    let (coarse_chart, _) = charts(coarse);
    let points = Points::of(coarse);
    let at = |p: &[f32; 3]| {
        let key = p.map(f32::to_bits);
        points.index.get(&key).copied()
    };
    // The coarse chart of each fine chart: kept vertices' votes first, the targets' nearest wedges otherwise.
    let mut kept: HashMap<(u32, u32), u32> = HashMap::new();
    let mut near: HashMap<(u32, u32), u32> = HashMap::new();
    for (k, &fc) in fine_chart.iter().enumerate() {
        if let Some(pt) = at(&fine.positions[k]) {
            let j = nearest_wedge(fine, k, coarse, &points.wedges[pt as usize]);
            if attribute_distance(fine, k, coarse, j as usize) < 1e-10 {
                *kept.entry((fc, coarse_chart[j as usize])).or_default() += 1;
            }
        }
        let (i, _) = main_source(&t.sources[k]);
        let pt = points.of_vertex[i as usize] as usize;
        let j = nearest_wedge(fine, k, coarse, &points.wedges[pt]);
        *near.entry((fc, coarse_chart[j as usize])).or_default() += 1;
    }
    let vote = |votes: &HashMap<(u32, u32), u32>| {
        let mut best: Vec<Option<(u32, u32)>> = vec![None; fine_charts];
        let mut keys: Vec<_> = votes.iter().collect();
        keys.sort();
        for (&(fc, cc), &n) in keys {
            let b = &mut best[fc as usize];
            if b.is_none_or(|(_, m)| n > m) {
                *b = Some((cc, n));
            }
        }
        best
    };
    let (by_kept, by_near) = (vote(&kept), vote(&near));
    let chart_of = |fc: u32| by_kept[fc as usize].or(by_near[fc as usize]).map(|b| b.0);
    let mut bvhs: HashMap<u32, (Mesh, Bvh)> = HashMap::new();
    (0..fine.vertex_count())
        .map(|k| {
            let Some(chart) = chart_of(fine_chart[k]) else {
                return t.sources[k];
            };
            let own = |i: u32| -> Option<u32> {
                let pt = points.of_vertex[i as usize] as usize;
                let mine: Vec<u32> = points.wedges[pt]
                    .iter()
                    .copied()
                    .filter(|&j| coarse_chart[j as usize] == chart)
                    .collect();
                (!mine.is_empty()).then(|| nearest_wedge(fine, k, coarse, &mine))
            };
            let within: Option<Vec<(u32, f32)>> = t.sources[k]
                .iter()
                .map(|&(i, w)| {
                    if w == 0.0 {
                        Some((i, w))
                    } else {
                        own(i).map(|j| (j, w))
                    }
                })
                .collect();
            if let Some(w) = within {
                return [w[0], w[1], w[2]];
            }
            let (mesh, bvh) = bvhs.entry(chart).or_insert_with(|| {
                let mut m = Mesh {
                    positions: coarse.positions.clone(),
                    normals: coarse.normals.clone(),
                    indices: Vec::new(),
                    aux: Vec::new(),
                    data: Default::default(),
                    parts: Vec::new(),
                };
                for tri in coarse.indices.chunks_exact(3) {
                    if coarse_chart[tri[0] as usize] == chart {
                        m.indices.extend_from_slice(tri);
                    }
                }
                let bvh = Bvh::new(&m);
                (m, bvh)
            });
            let (tri, _, bary) = bvh.closest(mesh, v(&t.positions[k]));
            [0, 1, 2].map(|c| (mesh.indices[tri * 3 + c], bary[c]))
        })
        .collect()
}

/// The source of largest weight.
fn main_source(src: &[(u32, f32); 3]) -> (u32, f32) {
    src.iter()
        .copied()
        .fold(src[0], |a, b| if b.1 > a.1 { b } else { a })
}

/// Per vertex, its texture chart, and the number of charts: vertices joined by a triangle, or sharing a
/// position and both sets of texture coordinates (a hard edge splits the normals, not the chart), are in one
/// chart.
pub fn charts(m: &Mesh) -> (Vec<u32>, usize) {
    let n = m.vertex_count();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn root(parent: &mut [u32], mut i: u32) -> u32 {
        while parent[i as usize] != i {
            parent[i as usize] = parent[parent[i as usize] as usize];
            i = parent[i as usize];
        }
        i
    }
    let join = |parent: &mut Vec<u32>, a: u32, b: u32| {
        let (ra, rb) = (root(parent, a), root(parent, b));
        if ra != rb {
            parent[ra.max(rb) as usize] = ra.min(rb);
        }
    };
    for tri in m.indices.chunks_exact(3) {
        join(&mut parent, tri[0], tri[1]);
        join(&mut parent, tri[1], tri[2]);
    }
    let uv = |set: &Option<Vec<[f32; 2]>>, i: usize| {
        set.as_ref().map_or([0; 2], |u| u[i].map(f32::to_bits))
    };
    // A vertex's position and texture coordinates (both sets), as bits.
    type Wedge = ([u32; 3], [u32; 2], [u32; 2]);
    let mut same: HashMap<Wedge, u32> = HashMap::new();
    for i in 0..n {
        let key = (
            m.positions[i].map(f32::to_bits),
            uv(&m.data.uv0, i),
            uv(&m.data.uv1, i),
        );
        let first = *same.entry(key).or_insert(i as u32);
        join(&mut parent, first, i as u32);
    }
    let mut ids: HashMap<u32, u32> = HashMap::new();
    let chart = (0..n as u32)
        .map(|i| {
            let r = root(&mut parent, i);
            let next = ids.len() as u32;
            *ids.entry(r).or_insert(next)
        })
        .collect();
    (chart, ids.len())
}

/// A mesh's distinct positions: each with the mean of its vertices' normals (normalised; the first vertex's
/// where they cancel) and its vertices (its wedges), and per vertex its position's index.
struct Points {
    index: HashMap<[u32; 3], u32>,
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    wedges: Vec<Vec<u32>>,
    of_vertex: Vec<u32>,
}

impl Points {
    fn of(m: &Mesh) -> Points {
        let mut at: HashMap<[u32; 3], u32> = HashMap::new();
        let mut points = Points {
            index: HashMap::new(),
            positions: Vec::new(),
            normals: Vec::new(),
            wedges: Vec::new(),
            of_vertex: Vec::with_capacity(m.vertex_count()),
        };
        for (i, p) in m.positions.iter().enumerate() {
            let slot = *at.entry(p.map(f32::to_bits)).or_insert_with(|| {
                points.positions.push(v(p));
                points.normals.push(Vec3::ZERO);
                points.wedges.push(Vec::new());
                points.positions.len() as u32 - 1
            });
            points.normals[slot as usize] += v(&m.normals[i]);
            points.wedges[slot as usize].push(i as u32);
            points.of_vertex.push(slot);
        }
        for (n, w) in points.normals.iter_mut().zip(&points.wedges) {
            *n = n.try_normalize().unwrap_or(v(&m.normals[w[0] as usize]));
        }
        points.index = at;
        points
    }
}

/// Of the coarse vertices `wedges` (one position's), the one whose attributes are nearest fine vertex `k`'s:
/// the squared distance between the normals plus that between the texture coordinates (both sets, where the
/// meshes have them); the lowest index of a tie.
fn nearest_wedge(fine: &Mesh, k: usize, coarse: &Mesh, wedges: &[u32]) -> u32 {
    let cost = |j: u32| attribute_distance(fine, k, coarse, j as usize);
    wedges
        .iter()
        .copied()
        .min_by(|&a, &b| cost(a).total_cmp(&cost(b)).then(a.cmp(&b)))
        .unwrap_or(wedges[0])
}

/// The squared distance between fine vertex `k`'s normal and coarse vertex `j`'s plus that between their
/// texture coordinates (both sets, where the meshes have them).
fn attribute_distance(fine: &Mesh, k: usize, coarse: &Mesh, j: usize) -> f32 {
    let tex = |m: &Mesh, i: usize| {
        let a = m.data.uv0.as_ref().map_or([0.0; 2], |u| u[i]);
        let b = m.data.uv1.as_ref().map_or([0.0; 2], |u| u[i]);
        glam::Vec4::new(a[0], a[1], b[0], b[1])
    };
    v(&coarse.normals[j]).distance_squared(v(&fine.normals[k]))
        + tex(coarse, j).distance_squared(tex(fine, k))
}

fn kd_build(pts: &[Vec3], idx: &mut [u32], depth: usize) {
    if idx.len() <= 1 {
        return;
    }
    let axis = depth % 3;
    let mid = idx.len() / 2;
    idx.select_nth_unstable_by(mid, |&a, &b| {
        pts[a as usize][axis]
            .total_cmp(&pts[b as usize][axis])
            .then(a.cmp(&b))
    });
    let (left, right) = idx.split_at_mut(mid);
    kd_build(pts, left, depth + 1);
    kd_build(pts, &mut right[1..], depth + 1);
}

/// Best = smallest (metric, index). The metric is at least the squared position distance, which bounds the
/// far side of each split.
fn kd_search(
    pts: &[Vec3],
    idx: &[u32],
    depth: usize,
    q: Vec3,
    metric: &impl Fn(u32) -> f32,
    best: &mut (f32, u32),
) {
    if idx.is_empty() {
        return;
    }
    let mid = idx.len() / 2;
    let j = idx[mid];
    let m = metric(j);
    if m < best.0 || (m == best.0 && j < best.1) {
        *best = (m, j);
    }
    let axis = depth % 3;
    let diff = q[axis] - pts[j as usize][axis];
    let (near, far) = if diff < 0.0 {
        (&idx[..mid], &idx[mid + 1..])
    } else {
        (&idx[mid + 1..], &idx[..mid])
    };
    kd_search(pts, near, depth + 1, q, metric, best);
    if diff * diff <= best.0 {
        kd_search(pts, far, depth + 1, q, metric, best);
    }
}

/// Closest point on the coarse surface, normal interpolated there. The point is found by position alone, so the
/// wedges of a fine position (a seam, a hard edge) all take it; each corner of its triangle is then the coarse
/// wedge at that corner's position nearest the fine vertex's attributes ([`nearest_wedge`]), so a vertex of one
/// texture chart takes its normal and texture coordinates from its own chart's side of a seam.
pub fn closest_surface(fine: &Mesh, coarse: &Mesh) -> MorphTargets {
    let bvh = Bvh::new(coarse);
    let coarse_points = Points::of(coarse);
    let mut positions = Vec::with_capacity(fine.positions.len());
    let mut normals = Vec::with_capacity(fine.positions.len());
    let mut sources = Vec::with_capacity(fine.positions.len());
    for (k, p) in fine.positions.iter().enumerate() {
        let (tri, point, bary) = bvh.closest(coarse, v(p));
        let t = [0, 1, 2].map(|c| {
            let corner = coarse.indices[tri * 3 + c] as usize;
            let wedges = &coarse_points.wedges[coarse_points.of_vertex[corner] as usize];
            nearest_wedge(fine, k, coarse, wedges)
        });
        let n = v(&coarse.normals[t[0] as usize]) * bary[0]
            + v(&coarse.normals[t[1] as usize]) * bary[1]
            + v(&coarse.normals[t[2] as usize]) * bary[2];
        let face = (v(&coarse.positions[t[1] as usize]) - v(&coarse.positions[t[0] as usize]))
            .cross(v(&coarse.positions[t[2] as usize]) - v(&coarse.positions[t[0] as usize]));
        let n = n
            .try_normalize()
            .or(face.try_normalize())
            .unwrap_or(Vec3::Y);
        positions.push(point.to_array());
        normals.push(n.to_array());
        sources.push([0, 1, 2].map(|k| (t[k], bary[k])));
    }
    MorphTargets {
        positions,
        normals,
        sources,
        surface: Vec::new(),
    }
}

struct BvhNode {
    lo: Vec3,
    hi: Vec3,
    /// Leaf: triangles `start..start + count` of `order`; inner: children at `start` and `start + 1`.
    start: u32,
    count: u32,
}

struct Bvh {
    nodes: Vec<BvhNode>,
    order: Vec<u32>,
}

const LEAF: usize = 4;

impl Bvh {
    fn new(m: &Mesh) -> Bvh {
        let tris = m.triangle_count();
        let corners = |t: u32| {
            let t = t as usize * 3;
            [0, 1, 2].map(|k| v(&m.positions[m.indices[t + k] as usize]))
        };
        let centroid: Vec<Vec3> = (0..tris as u32)
            .map(|t| corners(t).iter().copied().sum::<Vec3>() / 3.0)
            .collect();
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(2 * tris / LEAF + 1),
            order: (0..tris as u32).collect(),
        };
        bvh.nodes.push(BvhNode {
            lo: Vec3::ZERO,
            hi: Vec3::ZERO,
            start: 0,
            count: 0,
        });
        let mut stack = vec![(0usize, 0usize, tris)];
        while let Some((node, begin, end)) = stack.pop() {
            let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
            for &t in &bvh.order[begin..end] {
                for c in corners(t) {
                    lo = lo.min(c);
                    hi = hi.max(c);
                }
            }
            bvh.nodes[node].lo = lo;
            bvh.nodes[node].hi = hi;
            if end - begin <= LEAF {
                bvh.nodes[node].start = begin as u32;
                bvh.nodes[node].count = (end - begin) as u32;
                continue;
            }
            let ext = hi - lo;
            let axis = if ext.x >= ext.y && ext.x >= ext.z {
                0
            } else if ext.y >= ext.z {
                1
            } else {
                2
            };
            let mid = (begin + end) / 2;
            bvh.order[begin..end].select_nth_unstable_by(mid - begin, |&a, &b| {
                centroid[a as usize][axis]
                    .total_cmp(&centroid[b as usize][axis])
                    .then(a.cmp(&b))
            });
            let left = bvh.nodes.len();
            for _ in 0..2 {
                bvh.nodes.push(BvhNode {
                    lo: Vec3::ZERO,
                    hi: Vec3::ZERO,
                    start: 0,
                    count: 0,
                });
            }
            bvh.nodes[node].start = left as u32;
            stack.push((left, begin, mid));
            stack.push((left + 1, mid, end));
        }
        bvh
    }

    fn box_distance_squared(n: &BvhNode, q: Vec3) -> f32 {
        let d = (n.lo - q).max(q - n.hi).max(Vec3::ZERO);
        d.length_squared()
    }

    /// (triangle, closest point, barycentric weights); ties go to the lowest triangle index.
    fn closest(&self, m: &Mesh, q: Vec3) -> (usize, Vec3, [f32; 3]) {
        let mut best = (f32::INFINITY, usize::MAX, Vec3::ZERO, [1.0, 0.0, 0.0]);
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            let n = &self.nodes[i];
            if Self::box_distance_squared(n, q) > best.0 {
                continue;
            }
            if n.count > 0 {
                for &t in &self.order[n.start as usize..(n.start + n.count) as usize] {
                    let t = t as usize;
                    let c = [0, 1, 2].map(|k| v(&m.positions[m.indices[t * 3 + k] as usize]));
                    let (p, bary) = closest_point_on_triangle(q, c[0], c[1], c[2]);
                    let d = p.distance_squared(q);
                    if d < best.0 || (d == best.0 && t < best.1) {
                        best = (d, t, p, bary);
                    }
                }
            } else {
                let (a, b) = (n.start as usize, n.start as usize + 1);
                let (da, db) = (
                    Self::box_distance_squared(&self.nodes[a], q),
                    Self::box_distance_squared(&self.nodes[b], q),
                );
                // Visit the nearer child first (pushed last).
                if da <= db {
                    stack.push(b);
                    stack.push(a);
                } else {
                    stack.push(a);
                    stack.push(b);
                }
            }
        }
        (best.1, best.2, best.3)
    }
}

/// Closest point to `p` on triangle abc and its barycentric weights (Ericson, Real-Time Collision Detection,
/// 5.1.5).
pub fn closest_point_on_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> (Vec3, [f32; 3]) {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, [1.0, 0.0, 0.0]);
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let w = d1 / (d1 - d3);
        return (a + ab * w, [1.0 - w, w, 0.0]);
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + ac * w, [1.0 - w, 0.0, w]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * w, [0.0, 1.0 - w, w]);
    }
    let denom = 1.0 / (va + vb + vc);
    let vv = vb * denom;
    let ww = vc * denom;
    (a + ab * vv + ac * ww, [1.0 - vv - ww, vv, ww])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::lod::{LodChain, DEFAULT_TARGETS};
    use crate::scene::BUNNY_OBJ;

    fn chain() -> LodChain {
        let m = Mesh::parse_obj("bunny", BUNNY_OBJ).unwrap();
        LodChain::build("bunny", &m, &DEFAULT_TARGETS).unwrap()
    }

    /// A flat strip in z = 0, y in [0, 1], with a texture seam at x = 1: chart A (x <= 1) maps u = x / 2 (the
    /// atlas's left half), chart B (x >= 1) u = 1 - (x - 1) / 4 (its right edge, mirrored). A column at each of
    /// `xs` (the seam's column twice, once per chart), a quad between neighbours of one chart.
    fn seamed_strip(xs: &[f32]) -> Mesh {
        let (mut positions, mut uv, mut indices) = (Vec::new(), Vec::new(), Vec::new());
        // Chart B first: a tie between the seam's wedges that went to the lowest index would take B's.
        for (chart, range) in [(1, (1.0, 2.0)), (0, (0.0, 1.0))] {
            let cols: Vec<f32> = xs
                .iter()
                .copied()
                .filter(|&x| x >= range.0 && x <= range.1)
                .collect();
            let first = positions.len() as u32;
            for &x in &cols {
                let u = if chart == 0 {
                    x / 2.0
                } else {
                    1.0 - (x - 1.0) / 4.0
                };
                for y in [0.0, 1.0] {
                    positions.push([x, y, 0.0]);
                    uv.push([u, y]);
                }
            }
            for c in 0..cols.len() as u32 - 1 {
                let (a, b) = (first + 2 * c, first + 2 * c + 2);
                indices.extend_from_slice(&[a, b, a + 1, b, b + 1, a + 1]);
            }
        }
        Mesh {
            normals: vec![[0.0, 0.0, 1.0]; positions.len()],
            aux: vec![[0.0; 4]; positions.len()],
            positions,
            indices,
            data: crate::geometry::attributes::VertexData {
                uv0: Some(uv),
                ..Default::default()
            },
            parts: Vec::new(),
        }
    }

    /// Across a texture seam, the wedges of one fine position take one target position (no crack opens), and
    /// each fine vertex takes its texture coordinates from its own chart's coarse vertices, under every
    /// correspondence: a vertex of chart A near the seam, whose nearest coarse position is the seam's, takes the
    /// seam's chart-A wedge, not chart B's at the other end of the atlas.
    #[test]
    fn seams_keep_one_position_and_each_charts_coordinates() {
        let fine = seamed_strip(&[0.0, 0.4, 0.8, 1.0, 1.2, 1.6, 2.0]);
        let coarse = seamed_strip(&[0.0, 1.0, 2.0]);
        let (fc, n) = charts(&fine);
        assert_eq!(n, 2, "{fc:?}");
        assert_eq!(charts(&coarse).1, 2);
        let uv = |m: &Mesh, src: &[(u32, f32); 3]| {
            src.iter().fold(glam::Vec2::ZERO, |a, &(i, w)| {
                a + glam::Vec2::from(m.data.uv0.as_ref().unwrap()[i as usize]) * w
            })
        };
        for how in [
            Correspondence::Nearest,
            Correspondence::NearestPosition,
            Correspondence::Surface,
        ] {
            let t = morph_targets(&fine, &coarse, how);
            for k in 0..fine.vertex_count() {
                for j in 0..fine.vertex_count() {
                    if fine.positions[k] == fine.positions[j] {
                        assert_eq!(t.positions[k], t.positions[j], "{how:?}: {k} and {j}");
                    }
                }
                // Chart A's coordinates are in [0, 0.5], chart B's in [0.75, 1].
                let u = uv(&coarse, &t.surface[k]).x;
                let mine = fine.data.uv0.as_ref().unwrap()[k][0];
                assert_eq!(
                    u <= 0.5,
                    mine <= 0.5,
                    "{how:?}: vertex {k} (u {mine}) goes to u {u}"
                );
            }
            // The chart-A vertex at x = 0.8 goes to the seam's position (the nearest vertex) or stays where it
            // is (the surface under it), at chart A's u there either way.
            let k = fine.positions.iter().position(|p| p[0] == 0.8).unwrap();
            let x = t.positions[k][0];
            assert_eq!(
                x,
                if how == Correspondence::Surface {
                    0.8
                } else {
                    1.0
                }
            );
            assert!(
                (uv(&coarse, &t.surface[k]).x - x / 2.0).abs() < 1e-6,
                "{how:?}"
            );
        }
    }

    /// A target follows its coarse mesh: posed as it is, every correspondence gives back its own targets;
    /// moved and turned, the targets move and turn with it (a deformed model's LODs each frame).
    #[test]
    fn targets_follow_the_coarse_mesh() {
        let c = chain();
        let (fine, coarse) = (&c.lods[1].mesh, &c.lods[2].mesh);
        let turn = glam::Mat4::from_rotation_y(0.7)
            * glam::Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0));
        let moved: Vec<[f32; 3]> = coarse
            .positions
            .iter()
            .map(|p| turn.transform_point3(v(p)).to_array())
            .collect();
        let turned: Vec<[f32; 3]> = coarse
            .normals
            .iter()
            .map(|n| turn.transform_vector3(v(n)).to_array())
            .collect();
        for how in [
            Correspondence::Nearest,
            Correspondence::NearestPosition,
            Correspondence::Surface,
        ] {
            let t = morph_targets(fine, coarse, how);
            let (mut p, mut n) = (Vec::new(), Vec::new());
            t.follow(&coarse.positions, &coarse.normals, &mut p, &mut n);
            for (a, b) in p.iter().zip(&t.positions) {
                assert!(v(a).abs_diff_eq(v(b), 1e-5), "{how:?}: {a:?} vs {b:?}");
            }
            t.follow(&moved, &turned, &mut p, &mut n);
            for k in 0..p.len() {
                let want = turn.transform_point3(v(&t.positions[k]));
                assert!(
                    v(&p[k]).abs_diff_eq(want, 1e-4),
                    "{how:?}: {:?} vs {want}",
                    p[k]
                );
                let want_n = turn.transform_vector3(v(&t.normals[k]));
                assert!(
                    v(&n[k]).abs_diff_eq(want_n, 1e-4),
                    "{how:?}: normal {:?} vs {want_n}",
                    n[k]
                );
            }
        }
    }

    #[test]
    fn vertices_on_the_coarse_mesh_map_to_themselves() {
        let c = chain();
        for pair in c.lods.windows(2) {
            let (fine, coarse) = (&pair[0].mesh, &pair[1].mesh);
            let shared: Vec<usize> = (0..fine.positions.len())
                .filter(|&i| {
                    coarse
                        .positions
                        .iter()
                        .zip(&coarse.normals)
                        .any(|(p, n)| *p == fine.positions[i] && *n == fine.normals[i])
                })
                .collect();
            assert!(
                shared.len() >= coarse.positions.len() / 2,
                "meshopt keeps original vertices"
            );
            for how in [Correspondence::Nearest, Correspondence::Surface] {
                let t = morph_targets(fine, coarse, how);
                for &i in &shared {
                    assert_eq!(t.positions[i], fine.positions[i], "{how:?} vertex {i}");
                }
            }
        }
    }

    fn brute_nearest(fine: &Mesh, coarse: &Mesh, i: usize) -> [f32; 3] {
        brute_nearest_weighted(fine, coarse, i, mean_edge_length(coarse))
    }

    fn brute_nearest_weighted(fine: &Mesh, coarse: &Mesh, i: usize, lambda: f32) -> [f32; 3] {
        let (p, n) = (v(&fine.positions[i]), v(&fine.normals[i]));
        let j = (0..coarse.positions.len())
            .min_by(|&a, &b| {
                let m = |j: usize| {
                    v(&coarse.positions[j]).distance_squared(p)
                        + lambda * lambda * v(&coarse.normals[j]).distance_squared(n)
                };
                m(a).total_cmp(&m(b)).then(a.cmp(&b))
            })
            .unwrap();
        coarse.positions[j]
    }

    #[test]
    fn kd_tree_finds_the_brute_force_nearest() {
        let c = chain();
        let (fine, coarse) = (&c.lods[0].mesh, &c.lods[3].mesh);
        let t = nearest_vertex(fine, coarse);
        for i in (0..fine.positions.len()).step_by(7) {
            assert_eq!(t.positions[i], brute_nearest(fine, coarse, i), "vertex {i}");
        }
    }

    /// `nearest-position` is the nearest vertex by position alone (lambda = 0), and on the bunny's coarsest
    /// LOD it pairs some vertices differently from the paper's metric (the normal term moves them).
    #[test]
    fn nearest_position_drops_the_normal_term() {
        let c = chain();
        let (fine, coarse) = (&c.lods[0].mesh, &c.lods[3].mesh);
        let t = morph_targets(fine, coarse, Correspondence::NearestPosition);
        for i in (0..fine.positions.len()).step_by(7) {
            assert_eq!(
                t.positions[i],
                brute_nearest_weighted(fine, coarse, i, 0.0),
                "vertex {i}"
            );
        }
        let paper = morph_targets(fine, coarse, Correspondence::Nearest);
        let moved = (0..fine.positions.len())
            .filter(|&i| t.positions[i] != paper.positions[i])
            .count();
        assert!(moved > 0, "the normal term changes no pairing");
    }

    #[test]
    fn surface_targets_lie_on_the_coarse_surface_and_are_closest() {
        let c = chain();
        let (fine, coarse) = (&c.lods[1].mesh, &c.lods[2].mesh);
        let t = closest_surface(fine, coarse);
        for i in (0..fine.positions.len()).step_by(5) {
            let p = v(&fine.positions[i]);
            let target = v(&t.positions[i]);
            let mut best = f32::INFINITY;
            let mut on_surface = f32::INFINITY;
            for tri in coarse.indices.chunks_exact(3) {
                let [a, b, cc] = [0, 1, 2].map(|k| v(&coarse.positions[tri[k] as usize]));
                best = best.min(closest_point_on_triangle(p, a, b, cc).0.distance(p));
                on_surface = on_surface.min(
                    closest_point_on_triangle(target, a, b, cc)
                        .0
                        .distance(target),
                );
            }
            assert!(
                on_surface < 1e-4,
                "vertex {i}: target {on_surface} off the surface"
            );
            assert!(
                (target.distance(p) - best).abs() < 1e-4,
                "vertex {i}: not the closest point"
            );
            let n = v(&t.normals[i]);
            assert!((n.length() - 1.0).abs() < 1e-4);
        }
    }

    #[test]
    fn closest_point_regions() {
        let (a, b, c) = (Vec3::ZERO, Vec3::X, Vec3::Y);
        assert_eq!(
            closest_point_on_triangle(Vec3::new(-1.0, -1.0, 0.0), a, b, c).0,
            a
        );
        let (p, w) = closest_point_on_triangle(Vec3::new(0.25, 0.25, 3.0), a, b, c);
        assert!((p - Vec3::new(0.25, 0.25, 0.0)).length() < 1e-6);
        assert!((w[0] - 0.5).abs() < 1e-6 && (w[1] - 0.25).abs() < 1e-6);
        let (p, _) = closest_point_on_triangle(Vec3::new(1.0, 1.0, 0.0), a, b, c);
        assert!((p - Vec3::new(0.5, 0.5, 0.0)).length() < 1e-6);
    }
}
