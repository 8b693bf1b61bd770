//! Dividing one large triangle mesh into a 3D grid of blocks (seed 004, "Clipping or Binning?" and "Building
//! Seams"), the first step of Blow's unified LOD: blocks change LOD independently, and degenerate quads (seams)
//! join neighbouring blocks so no crack opens where they differ.
//!
//! - [`Partition::clip`] clips every triangle at the block faces (Sutherland-Hodgman on the triangle, fan
//!   triangulation of the convex result). Every vertex is named by integers, never by its float position
//!   ([`VertexKey`]): an input vertex by its index, a point where clipping cut an input edge by that edge's two
//!   input vertices and the plane, a point where two planes cut a triangle's interior by the triangle and the two
//!   planes. Positions are computed once per key from the input in f64 (the same in every block that makes the
//!   point), and coordinates on a plane are set to the plane exactly, so the inside/outside tests of
//!   neighbouring blocks agree bit for bit.
//! - [`Partition::bin`] puts each triangle whole into the block of its barycentre (the blocks' bounds grow to
//!   hold their triangles).
//! - Seams: every edge a block has on one of its faces (made by clipping, or an input edge lying on a plane;
//!   for binning, every edge whose triangles went to different blocks) is a potential seam edge. Edges with the
//!   same two keys in different blocks are joined by one degenerate quad per neighbouring pair (blocks in index
//!   order, so an edge shared by three blocks gets two quads, not three). Input vertices that only share a
//!   position are different keys and are never joined: the mesh's own cracks stay cracks.
//!
//! Planes are numbered globally (`axis << 24 | i`, plane i of an axis at `origin + i * cell`), so the face two
//! neighbouring blocks share is one plane for both.

use crate::error::{Error, Result};
use glam::DVec3;
use std::collections::{BTreeMap, HashMap};

/// A regular grid of cubic blocks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    pub origin: DVec3,
    pub cell: f64,
    /// Blocks along x, y, z.
    pub dims: [u32; 3],
}

impl Grid {
    /// The grid of cubes of side `cell` that covers `positions` (at least one block per axis).
    pub fn covering(positions: &[[f32; 3]], cell: f64) -> Result<Grid> {
        if !(cell.is_finite() && cell > 0.0) {
            return Err(Error::Config(format!(
                "block size {cell} must be a positive number"
            )));
        }
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for p in positions {
            let p = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
            lo = lo.min(p);
            hi = hi.max(p);
        }
        if !(lo.is_finite() && hi.is_finite()) {
            return Err(Error::Config(
                "cannot build blocks for an empty mesh".into(),
            ));
        }
        let n = ((hi - lo) / cell).floor() + DVec3::ONE;
        if n.max_element() > 4096.0 {
            return Err(Error::Config(format!(
                "block size {cell} gives more than 4,096 blocks along an axis"
            )));
        }
        Ok(Grid {
            origin: lo,
            cell,
            dims: [n.x as u32, n.y as u32, n.z as u32],
        })
    }

    /// The global number of plane `i` of `axis` (0 = x, 1 = y, 2 = z).
    pub fn plane(axis: usize, i: u32) -> u32 {
        (axis as u32) << 24 | i
    }

    fn plane_axis(plane: u32) -> usize {
        (plane >> 24) as usize
    }

    fn plane_value(&self, plane: u32) -> f64 {
        let axis = Self::plane_axis(plane);
        self.origin[axis] + (plane & 0x00ff_ffff) as f64 * self.cell
    }

    pub fn block_count(&self) -> usize {
        self.dims.iter().map(|&d| d as usize).product()
    }

    /// Index of block `c` (x fastest).
    pub fn block_index(&self, c: [u32; 3]) -> usize {
        (c[0] + self.dims[0] * (c[1] + self.dims[1] * c[2])) as usize
    }

    /// The block holding point `p` (clamped to the grid).
    pub fn block_of(&self, p: DVec3) -> [u32; 3] {
        let mut c = [0; 3];
        for (axis, c) in c.iter_mut().enumerate() {
            let i = ((p[axis] - self.origin[axis]) / self.cell).floor();
            *c = (i.max(0.0) as u32).min(self.dims[axis] - 1);
        }
        c
    }
}

/// The integer name of a vertex of a block (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum VertexKey {
    Input(u32),
    /// Input edge (a, b), a < b, cut by a plane.
    Edge {
        a: u32,
        b: u32,
        plane: u32,
    },
    /// Input triangle `tri` cut by two planes, p1 < p2.
    Face {
        tri: u32,
        p1: u32,
        p2: u32,
    },
}

/// One block's mesh: its own vertices (with their keys) and triangles, and its potential seam edges.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Block {
    pub coord: [u32; 3],
    pub positions: Vec<[f32; 3]>,
    pub keys: Vec<VertexKey>,
    pub indices: Vec<u32>,
    /// Edges on the block's border (local vertex indices, as they run in the block's triangles).
    pub seam_edges: Vec<(u32, u32)>,
}

impl Block {
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }
}

/// A degenerate quad joining the same edge in two blocks: `(block, local a, local b)` of each side, with the
/// same two keys in the same order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SeamQuad {
    pub first: (usize, u32, u32),
    pub second: (usize, u32, u32),
}

/// How a mesh was divided.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PartitionMode {
    Clip,
    Bin,
}

/// The blocks (non-empty ones only, in grid order) and the seams between them.
#[derive(Debug, Clone)]
pub struct Partition {
    pub grid: Grid,
    pub mode: PartitionMode,
    pub blocks: Vec<Block>,
    pub seams: Vec<SeamQuad>,
}

/// A polygon vertex during clipping: its key, its position, and the input edge it lies on (if any).
#[derive(Debug, Clone, Copy)]
struct PolyVertex {
    key: VertexKey,
    p: DVec3,
    edge: Option<(u32, u32)>,
}

struct Clipper<'a> {
    grid: &'a Grid,
    input: Vec<DVec3>,
    indices: &'a [u32],
}

impl Clipper<'_> {
    fn input_vertex(&self, v: u32) -> PolyVertex {
        PolyVertex {
            key: VertexKey::Input(v),
            p: self.input[v as usize],
            edge: None,
        }
    }

    /// The point where input edge (a, b) meets `plane`, from the input alone.
    fn edge_point(&self, a: u32, b: u32, plane: u32) -> PolyVertex {
        let (a, b) = (a.min(b), a.max(b));
        let axis = Grid::plane_axis(plane);
        let value = self.grid.plane_value(plane);
        let (pa, pb) = (self.input[a as usize], self.input[b as usize]);
        let t = (value - pa[axis]) / (pb[axis] - pa[axis]);
        let mut p = pa + (pb - pa) * t;
        p[axis] = value;
        PolyVertex {
            key: VertexKey::Edge { a, b, plane },
            p,
            edge: Some((a, b)),
        }
    }

    /// The point where planes p1 and p2 cut triangle `tri`'s plane, from the input alone; `fallback` when the
    /// triangle is (nearly) parallel to the two planes' line.
    fn face_point(&self, tri: u32, p1: u32, p2: u32, fallback: DVec3) -> PolyVertex {
        let (p1, p2) = (p1.min(p2), p1.max(p2));
        let t = &self.indices[tri as usize * 3..tri as usize * 3 + 3];
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| self.input[i as usize]);
        let n = (b - a).cross(c - a);
        let (i, j) = (Grid::plane_axis(p1), Grid::plane_axis(p2));
        let k = 3 - i - j;
        let mut p = fallback;
        p[i] = self.grid.plane_value(p1);
        p[j] = self.grid.plane_value(p2);
        if n[k].abs() > 1e-12 * n.length() {
            p[k] = (n.dot(a) - n[i] * p[i] - n[j] * p[j]) / n[k];
        }
        PolyVertex {
            key: VertexKey::Face { tri, p1, p2 },
            p,
            edge: None,
        }
    }

    fn on_edge(v: &PolyVertex, edge: (u32, u32)) -> bool {
        match v.key {
            VertexKey::Input(x) => x == edge.0 || x == edge.1,
            _ => v.edge == Some(edge),
        }
    }

    /// Where segment (from, to) crosses `plane`, named by the input edge or the plane both lie on.
    fn crossing(&self, tri: u32, from: &PolyVertex, to: &PolyVertex, plane: u32) -> PolyVertex {
        let t = &self.indices[tri as usize * 3..tri as usize * 3 + 3];
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            let e = (a.min(b), a.max(b));
            if Self::on_edge(from, e) && Self::on_edge(to, e) {
                return self.edge_point(e.0, e.1, plane);
            }
        }
        // A segment inside the triangle lies on the plane that made it.
        let axis = Grid::plane_axis(plane);
        let s = (self.grid.plane_value(plane) - from.p[axis]) / (to.p[axis] - from.p[axis]);
        let fallback = from.p + (to.p - from.p) * s;
        let other = self
            .planes_through(from)
            .into_iter()
            .find(|q| Grid::plane_axis(*q) != axis && self.on_plane(to, *q));
        match other {
            Some(q) => self.face_point(tri, q, plane, fallback),
            None => self.face_point(tri, plane, plane, fallback),
        }
    }

    fn on_plane(&self, v: &PolyVertex, plane: u32) -> bool {
        v.p[Grid::plane_axis(plane)] == self.grid.plane_value(plane)
    }

    /// The grid planes `v` lies on exactly.
    fn planes_through(&self, v: &PolyVertex) -> Vec<u32> {
        let mut out = Vec::new();
        for axis in 0..3 {
            let i = (v.p[axis] - self.grid.origin[axis]) / self.grid.cell;
            if i >= 0.0 && i.fract() == 0.0 && i <= self.grid.dims[axis] as f64 {
                let plane = Grid::plane(axis, i as u32);
                if self.on_plane(v, plane) {
                    out.push(plane);
                }
            }
        }
        out
    }

    /// Triangle `tri` clipped to block `c`: the convex polygon (possibly empty or degenerate).
    fn clip(&self, tri: u32, c: [u32; 3]) -> Vec<PolyVertex> {
        let t = &self.indices[tri as usize * 3..tri as usize * 3 + 3];
        let mut poly: Vec<PolyVertex> = t.iter().map(|&v| self.input_vertex(v)).collect();
        for (axis, &ci) in c.iter().enumerate() {
            for (side, i) in [(1.0, ci), (-1.0, ci + 1)] {
                let plane = Grid::plane(axis, i);
                let value = self.grid.plane_value(plane);
                // Signed distance, positive inside the block.
                let d = |v: &PolyVertex| side * (v.p[axis] - value);
                if poly.iter().all(|v| d(v) >= 0.0) {
                    continue;
                }
                let mut out = Vec::with_capacity(poly.len() + 1);
                for (n, cur) in poly.iter().enumerate() {
                    let next = &poly[(n + 1) % poly.len()];
                    let (dc, dn) = (d(cur), d(next));
                    if dc >= 0.0 {
                        out.push(*cur);
                    }
                    if (dc > 0.0 && dn < 0.0) || (dc < 0.0 && dn > 0.0) {
                        out.push(self.crossing(tri, cur, next, plane));
                    }
                }
                poly = out;
                if poly.len() < 3 {
                    return Vec::new();
                }
            }
        }
        poly
    }
}

/// True when the polygon has no area (all its vertices on one line, or fewer than three distinct keys).
fn degenerate(poly: &[PolyVertex]) -> bool {
    let mut keys: Vec<VertexKey> = poly.iter().map(|v| v.key).collect();
    keys.sort();
    keys.dedup();
    if keys.len() < 3 {
        return true;
    }
    let a = poly[0].p;
    let area: f64 = (1..poly.len() - 1)
        .map(|i| (poly[i].p - a).cross(poly[i + 1].p - a).length())
        .sum();
    area == 0.0
}

#[derive(Default)]
struct BlockBuilder {
    block: Block,
    local: HashMap<VertexKey, u32>,
}

impl BlockBuilder {
    fn vertex(&mut self, key: VertexKey, p: DVec3) -> u32 {
        let b = &mut self.block;
        *self.local.entry(key).or_insert_with(|| {
            b.positions.push([p.x as f32, p.y as f32, p.z as f32]);
            b.keys.push(key);
            b.keys.len() as u32 - 1
        })
    }
}

impl Partition {
    /// Clips the mesh (`positions`, `indices`) at the faces of `grid`'s blocks.
    pub fn clip(positions: &[[f32; 3]], indices: &[u32], grid: Grid) -> Partition {
        let clipper = Clipper {
            grid: &grid,
            input: positions
                .iter()
                .map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64))
                .collect(),
            indices,
        };
        let mut builders: BTreeMap<usize, BlockBuilder> = BTreeMap::new();
        for tri in 0..(indices.len() / 3) as u32 {
            let t = &indices[tri as usize * 3..tri as usize * 3 + 3];
            let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
            for &v in t {
                lo = lo.min(clipper.input[v as usize]);
                hi = hi.max(clipper.input[v as usize]);
            }
            let (b0, b1) = (grid.block_of(lo), grid.block_of(hi));
            for z in b0[2]..=b1[2] {
                for y in b0[1]..=b1[1] {
                    for x in b0[0]..=b1[0] {
                        let c = [x, y, z];
                        let poly = clipper.clip(tri, c);
                        if poly.len() < 3 || degenerate(&poly) {
                            continue;
                        }
                        let builder = builders.entry(grid.block_index(c)).or_default();
                        builder.block.coord = c;
                        let local: Vec<u32> =
                            poly.iter().map(|v| builder.vertex(v.key, v.p)).collect();
                        for i in 1..local.len() - 1 {
                            builder.block.indices.extend_from_slice(&[
                                local[0],
                                local[i],
                                local[i + 1],
                            ]);
                        }
                        // Polygon edges on one of the block's inner faces (a face another block lies
                        // beyond) are potential seam edges.
                        for (n, v) in poly.iter().enumerate() {
                            let w = &poly[(n + 1) % poly.len()];
                            let on_face = (0..3).any(|axis| {
                                [c[axis], c[axis] + 1].into_iter().any(|i| {
                                    let inner = i > 0 && i < grid.dims[axis];
                                    let plane = Grid::plane(axis, i);
                                    inner
                                        && clipper.on_plane(v, plane)
                                        && clipper.on_plane(w, plane)
                                })
                            });
                            if on_face && local[n] != local[(n + 1) % local.len()] {
                                builder
                                    .block
                                    .seam_edges
                                    .push((local[n], local[(n + 1) % local.len()]));
                            }
                        }
                    }
                }
            }
        }
        let blocks: Vec<Block> = builders.into_values().map(|b| b.block).collect();
        let seams = match_seams(&blocks);
        Partition {
            grid,
            mode: PartitionMode::Clip,
            blocks,
            seams,
        }
    }

    /// Bins each triangle whole into the block of its barycentre.
    pub fn bin(positions: &[[f32; 3]], indices: &[u32], grid: Grid) -> Partition {
        let input: Vec<DVec3> = positions
            .iter()
            .map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64))
            .collect();
        let mut builders: BTreeMap<usize, BlockBuilder> = BTreeMap::new();
        // Which blocks hold each input edge.
        let mut edge_blocks: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
        for t in indices.chunks_exact(3) {
            let centre = (input[t[0] as usize] + input[t[1] as usize] + input[t[2] as usize]) / 3.0;
            let c = grid.block_of(centre);
            let index = grid.block_index(c);
            let builder = builders.entry(index).or_default();
            builder.block.coord = c;
            for &v in t {
                let local = builder.vertex(VertexKey::Input(v), input[v as usize]);
                builder.block.indices.push(local);
            }
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                let list = edge_blocks.entry((a.min(b), a.max(b))).or_default();
                if !list.contains(&index) {
                    list.push(index);
                }
            }
        }
        for ((a, b), list) in &edge_blocks {
            if list.len() < 2 {
                continue;
            }
            for index in list {
                let Some(builder) = builders.get_mut(index) else {
                    continue;
                };
                let (la, lb) = (
                    builder.local[&VertexKey::Input(*a)],
                    builder.local[&VertexKey::Input(*b)],
                );
                builder.block.seam_edges.push((la, lb));
            }
        }
        let mut blocks: Vec<Block> = builders.into_values().map(|b| b.block).collect();
        for b in &mut blocks {
            b.seam_edges.sort_unstable();
        }
        let seams = match_seams(&blocks);
        Partition {
            grid,
            mode: PartitionMode::Bin,
            blocks,
            seams,
        }
    }

    pub fn triangle_count(&self) -> usize {
        self.blocks.iter().map(Block::triangle_count).sum()
    }

    /// Every block simplified to each of `targets` (fractions of its triangles; the first must be 1.0) with
    /// meshopt, every vertex of a seam edge locked: the blocks' borders stay exactly as clipped, so a seam quad
    /// stays degenerate and valid whatever LODs its two blocks show. (The borders then never reduce; seed 004's
    /// answer, combining blocks into coarser ones and reducing their inner borders, is not built yet.)
    pub fn lod_chains(&self, targets: &[f32]) -> Result<Vec<Vec<BlockLod>>> {
        crate::lod::check_targets("the blocks", targets)?;
        self.blocks
            .iter()
            .map(|b| {
                let mut locked = vec![false; b.positions.len()];
                for &(u, v) in &b.seam_edges {
                    locked[u as usize] = true;
                    locked[v as usize] = true;
                }
                let bytes: &[u8] = bytemuck::cast_slice(&b.positions);
                let adapter = meshopt::VertexDataAdapter::new(bytes, 12, 0).map_err(|e| {
                    Error::Config(format!(
                        "block {:?}: meshopt rejected the vertices: {e}",
                        b.coord
                    ))
                })?;
                Ok(targets
                    .iter()
                    .map(|&fraction| {
                        if fraction == 1.0 {
                            return BlockLod {
                                indices: b.indices.clone(),
                                error_abs: 0.0,
                            };
                        }
                        let target = crate::lod::target_index_count(b.indices.len(), fraction);
                        let mut error = 0.0f32;
                        let indices = meshopt::simplify_with_locks(
                            &b.indices,
                            &adapter,
                            &locked,
                            target,
                            f32::MAX,
                            meshopt::SimplifyOptions::ErrorAbsolute,
                            Some(&mut error),
                        );
                        BlockLod {
                            indices,
                            error_abs: error,
                        }
                    })
                    .collect())
            })
            .collect()
    }
}

/// One LOD of a block: triangles into the block's own (full-resolution) vertices, and meshopt's error estimate
/// in the mesh's units.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockLod {
    pub indices: Vec<u32>,
    pub error_abs: f32,
}

/// One side of a seam edge: (block, local a, local b).
type EdgeSide = (usize, u32, u32);

/// Joins each seam edge present in several blocks: one quad per pair of consecutive blocks (block order).
fn match_seams(blocks: &[Block]) -> Vec<SeamQuad> {
    let mut by_edge: BTreeMap<(VertexKey, VertexKey), Vec<EdgeSide>> = BTreeMap::new();
    for (bi, b) in blocks.iter().enumerate() {
        for &(u, v) in &b.seam_edges {
            let (ku, kv) = (b.keys[u as usize], b.keys[v as usize]);
            // The same edge in the same order on every side: by key.
            let entry = if ku <= kv {
                (ku, kv, u, v)
            } else {
                (kv, ku, v, u)
            };
            let list = by_edge.entry((entry.0, entry.1)).or_default();
            if !list.iter().any(|(i, _, _)| *i == bi) {
                list.push((bi, entry.2, entry.3));
            }
        }
    }
    let mut seams = Vec::new();
    for list in by_edge.values() {
        for w in list.windows(2) {
            seams.push(SeamQuad {
                first: w[0],
                second: w[1],
            });
        }
    }
    seams
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(dims: [u32; 3]) -> Grid {
        Grid {
            origin: DVec3::ZERO,
            cell: 1.0,
            dims,
        }
    }

    fn keys_of(p: &Partition, seam: &SeamQuad) -> [(VertexKey, VertexKey); 2] {
        let k = |(b, u, v): (usize, u32, u32)| {
            (p.blocks[b].keys[u as usize], p.blocks[b].keys[v as usize])
        };
        [k(seam.first), k(seam.second)]
    }

    /// Area of a block's triangles.
    fn area(b: &Block) -> f64 {
        b.indices
            .chunks_exact(3)
            .map(|t| {
                let [a, b2, c] = [t[0], t[1], t[2]].map(|i| {
                    let p = b.positions[i as usize];
                    DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
                });
                (b2 - a).cross(c - a).length() / 2.0
            })
            .sum()
    }

    /// A 2 x 1 quad in z = 0.5 (triangles 0-1-2 and 0-2-3) clipped by the plane x = 1: each half gets the
    /// right area, the cut makes three points named by their input edges (the diagonal's midpoint once, shared
    /// by both triangles), and the two cut segments become two seam quads whose sides carry the same keys.
    #[test]
    fn a_quad_clipped_by_one_plane() {
        let pos = [
            [0.0, 0.0, 0.5],
            [2.0, 0.0, 0.5],
            [2.0, 1.0, 0.5],
            [0.0, 1.0, 0.5],
        ];
        let idx = [0, 1, 2, 0, 2, 3];
        let p = Partition::clip(&pos, &idx, grid([2, 1, 1]));
        assert_eq!(p.blocks.len(), 2);
        let (left, right) = (&p.blocks[0], &p.blocks[1]);
        assert_eq!((left.coord, right.coord), ([0, 0, 0], [1, 0, 0]));
        assert_eq!((left.triangle_count(), right.triangle_count()), (3, 3));
        assert!((area(left) - 1.0).abs() < 1e-6 && (area(right) - 1.0).abs() < 1e-6);
        let plane = Grid::plane(0, 1);
        let cut = [
            VertexKey::Edge { a: 0, b: 1, plane },
            VertexKey::Edge { a: 0, b: 2, plane },
            VertexKey::Edge { a: 2, b: 3, plane },
        ];
        for b in [left, right] {
            for k in cut {
                let n = b.keys.iter().filter(|&&x| x == k).count();
                assert_eq!(n, 1, "{k:?} in block {:?}", b.coord);
            }
            assert_eq!(b.positions.len(), 5);
            assert_eq!(b.seam_edges.len(), 2);
        }
        let mid = left.keys.iter().position(|k| *k == cut[1]).unwrap();
        assert_eq!(left.positions[mid], [1.0, 0.5, 0.5]);
        assert_eq!(p.seams.len(), 2);
        for s in &p.seams {
            let [a, b] = keys_of(&p, s);
            assert_eq!(a, b);
            assert_ne!(s.first.0, s.second.0);
        }
    }

    /// Seed 004 Fig. 3: two triangles share an edge that lies on the plane x = 1, one on each side. Nothing is
    /// clipped (no new vertex), but the shared edge is a seam: one quad.
    #[test]
    fn two_triangles_straddling_a_plane() {
        let pos = [
            [1.0, 0.0, 0.5],
            [1.0, 1.0, 0.5],
            [0.2, 0.5, 0.5],
            [1.8, 0.5, 0.5],
        ];
        let idx = [0, 1, 2, 1, 0, 3];
        let p = Partition::clip(&pos, &idx, grid([2, 1, 1]));
        assert_eq!(p.blocks.len(), 2);
        for b in &p.blocks {
            assert_eq!(b.triangle_count(), 1);
            assert!(b.keys.iter().all(|k| matches!(k, VertexKey::Input(_))));
        }
        assert_eq!(p.seams.len(), 1);
        let [a, _] = keys_of(&p, &p.seams[0]);
        assert_eq!(
            (a.0.min(a.1), a.0.max(a.1)),
            (VertexKey::Input(0), VertexKey::Input(1))
        );
    }

    /// An input edge along the line x = 1, y = 1 (where four blocks meet), shared by three triangles that lie
    /// in three different blocks: the edge is a seam edge of each of the three, and two quads join them (a
    /// chain), not three, and none reaches the fourth block.
    #[test]
    fn an_edge_on_the_border_of_three_blocks() {
        let pos = [
            [1.0, 1.0, 0.2],
            [1.0, 1.0, 0.8],
            [0.5, 0.5, 0.5], // block (0, 0)
            [1.5, 0.5, 0.5], // block (1, 0)
            [0.5, 1.5, 0.5], // block (0, 1)
        ];
        let idx = [0, 1, 2, 1, 0, 3, 0, 1, 4];
        let p = Partition::clip(&pos, &idx, grid([2, 2, 1]));
        let coords: Vec<[u32; 3]> = p.blocks.iter().map(|b| b.coord).collect();
        assert_eq!(coords, vec![[0, 0, 0], [1, 0, 0], [0, 1, 0]]);
        assert_eq!(p.seams.len(), 2);
        for s in &p.seams {
            let [a, b] = keys_of(&p, s);
            assert_eq!(a, b);
            assert_eq!(
                (a.0.min(a.1), a.0.max(a.1)),
                (VertexKey::Input(0), VertexKey::Input(1))
            );
        }
    }

    /// Two surfaces that touch along x = 1 with coincident but distinct vertices (0/4 and 1/5 share positions):
    /// a real crack of the input mesh, which a seam must not close. Matching by position would join them.
    #[test]
    fn coincident_vertices_are_not_joined() {
        let pos = [
            [1.0, 0.0, 0.5],
            [1.0, 1.0, 0.5],
            [0.2, 0.5, 0.5],
            [1.8, 0.5, 0.5],
            [1.0, 0.0, 0.5],
            [1.0, 1.0, 0.5],
        ];
        let idx = [0, 1, 2, 5, 4, 3];
        let p = Partition::clip(&pos, &idx, grid([2, 1, 1]));
        assert_eq!(p.blocks.len(), 2);
        assert!(p.blocks.iter().all(|b| b.seam_edges.len() == 1));
        assert!(p.seams.is_empty(), "{:?}", p.seams);
    }

    /// A triangle cut by two planes of different axes gets a vertex inside it named by the triangle and both
    /// planes, at the same position in all four blocks; the four pieces add up to the triangle.
    #[test]
    fn two_planes_meet_inside_a_triangle() {
        let pos = [[0.2, 0.2, 0.5], [1.9, 0.3, 0.5], [0.4, 1.8, 0.5]];
        let idx = [0, 1, 2];
        let p = Partition::clip(&pos, &idx, grid([2, 2, 1]));
        assert_eq!(p.blocks.len(), 4);
        let corner = VertexKey::Face {
            tri: 0,
            p1: Grid::plane(0, 1),
            p2: Grid::plane(1, 1),
        };
        for b in &p.blocks {
            let i = b
                .keys
                .iter()
                .position(|k| *k == corner)
                .expect("the corner");
            assert_eq!(b.positions[i], [1.0, 1.0, 0.5]);
        }
        let total: f64 = p.blocks.iter().map(area).sum();
        let whole = (DVec3::new(1.7, 0.1, 0.0))
            .cross(DVec3::new(0.2, 1.6, 0.0))
            .length()
            / 2.0;
        assert!((total - whole).abs() < 1e-6, "{total} against {whole}");
        // Four cut segments, each shared by two blocks.
        assert_eq!(p.seams.len(), 4);
    }

    /// Binning keeps triangles whole: the quad's two triangles go to the blocks of their barycentres and the
    /// diagonal they share is the one seam.
    #[test]
    fn binning_keeps_triangles_whole() {
        let pos = [
            [0.0, 0.0, 0.5],
            [2.0, 0.0, 0.5],
            [2.0, 1.0, 0.5],
            [0.0, 1.0, 0.5],
        ];
        let idx = [0, 1, 2, 0, 2, 3];
        let p = Partition::bin(&pos, &idx, grid([2, 1, 1]));
        assert_eq!(p.blocks.len(), 2);
        assert_eq!(p.triangle_count(), 2);
        assert_eq!(p.seams.len(), 1);
        let [a, b] = keys_of(&p, &p.seams[0]);
        assert_eq!(a, b);
        assert_eq!(
            (a.0.min(a.1), a.0.max(a.1)),
            (VertexKey::Input(0), VertexKey::Input(2))
        );
    }

    /// Seed 004 Fig. 1: the bunny clipped in half by the plane x = its centre, one half reduced to a quarter of
    /// its triangles. With the seam vertices locked, the reduced half keeps exactly the full half's edges on the
    /// cut (so the halves still meet without a crack, and every seam quad's vertices are still drawn), while its
    /// triangle count falls. Without the locks (tried: plain `simplify`), edges on the cut go.
    #[test]
    fn a_reduced_half_keeps_its_cut_edges() {
        let m = crate::mesh::Mesh::parse_obj("bunny", crate::scene::BUNNY_OBJ).unwrap();
        let (lo, hi) = m.bounds();
        let cell = ((hi - lo).max_element() * 1.01) as f64;
        let centre = ((lo.x + hi.x) * 0.5) as f64;
        let g = Grid {
            origin: DVec3::new(centre - cell, lo.y as f64, lo.z as f64),
            cell,
            dims: [2, 1, 1],
        };
        let p = Partition::clip(&m.positions, &m.indices, g);
        assert_eq!(p.blocks.len(), 2);
        let chains = p.lod_chains(&[1.0, 0.25]).unwrap();
        let plane = centre as f32;
        // The block's border on the cut: edges of one non-degenerate triangle only, both ends on the plane.
        let cut_edges = |b: &Block, indices: &[u32]| {
            let mut count: BTreeMap<(u32, u32), u32> = BTreeMap::new();
            for t in indices.chunks_exact(3) {
                let [a, b2, c] = [t[0], t[1], t[2]].map(|i| {
                    let p = b.positions[i as usize];
                    DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
                });
                if (b2 - a).cross(c - a).length() == 0.0 {
                    continue;
                }
                for (u, v) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                    *count.entry((u.min(v), u.max(v))).or_default() += 1;
                }
            }
            count
                .into_iter()
                .filter(|&((u, v), n)| {
                    n == 1
                        && b.positions[u as usize][0] == plane
                        && b.positions[v as usize][0] == plane
                })
                .map(|(e, _)| e)
                .collect::<Vec<_>>()
        };
        for (b, chain) in p.blocks.iter().zip(&chains) {
            let (full, reduced) = (&chain[0], &chain[1]);
            assert!(
                reduced.indices.len() * 10 < full.indices.len() * 4,
                "{} of {}",
                reduced.indices.len(),
                full.indices.len()
            );
            let edges = cut_edges(b, &full.indices);
            assert!(edges.len() > 20, "{} edges on the cut", edges.len());
            assert_eq!(cut_edges(b, &reduced.indices), edges);
            assert!(reduced.error_abs > 0.0);
        }
        for s in &p.seams {
            for (bi, u, v) in [s.first, s.second] {
                let used = |x: u32| chains[bi][1].indices.contains(&x);
                assert!(used(u) && used(v));
            }
        }
    }

    /// The committed bunny clipped into a 3 x 3 x 3 grid: no area is lost or gained, and every seam quad's
    /// two sides are at the same positions (degenerate at full resolution).
    #[test]
    fn the_bunny_clipped_keeps_its_area_and_its_seams_close() {
        let m = crate::mesh::Mesh::parse_obj("bunny", crate::scene::BUNNY_OBJ).unwrap();
        let (lo, hi) = m.bounds();
        let cell = ((hi - lo).max_element() / 2.9) as f64;
        let g = Grid::covering(&m.positions, cell).unwrap();
        assert_eq!(g.dims, [3, 3, 3]);
        let p = Partition::clip(&m.positions, &m.indices, g);
        let input = Block {
            positions: m.positions.clone(),
            indices: m.indices.clone(),
            ..Default::default()
        };
        let total: f64 = p.blocks.iter().map(area).sum();
        assert!((total - area(&input)).abs() < 1e-6 * area(&input));
        assert!(p.triangle_count() > m.triangle_count());
        assert!(p.seams.len() > 50, "{} seams", p.seams.len());
        for s in &p.seams {
            let pos = |(b, u, v): (usize, u32, u32)| {
                (
                    p.blocks[b].positions[u as usize],
                    p.blocks[b].positions[v as usize],
                )
            };
            assert_eq!(pos(s.first), pos(s.second));
        }
    }
}
