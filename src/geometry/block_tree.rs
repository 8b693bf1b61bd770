//! Blow's hierarchy of blocks on a height field (Blow 2003a and 2003b; seed 004: "dividing the input data
//! into spatially-localized blocks, then hierarchically combining those blocks"), the geometry of
//! `blocks-tree`. Pure CPU, deterministic.
//!
//! - **Leaves**: the grid of `cells` x `cells` quads (two triangles each, the terrain mesh's own triangles
//!   and vertex numbering `j * (cells + 1) + i`) cut into `blocks` x `blocks` rectangles of whole cells, each
//!   at full resolution (error 0).
//! - **Parents**: 2 x 2 nodes of one level make a node of the next (fewer where `blocks` is not a power of
//!   two), up to one root. A parent's mesh is its region's full-resolution triangles reduced by meshopt to a
//!   quarter of its children's triangles together, its four corners locked and every other vertex free, its
//!   children's inner borders included: the children combined and reduced with their inner borders unlocked, so
//!   a parent holds about as many triangles as one child and a node of level L a `4^-L` part of its region's
//!   triangles. meshopt collapses a border vertex only along a border edge, so a node's border stays on its
//!   region's four grid lines, each side a subsequence of the grid vertices on it, corners kept.
//! - **Seams** ([`zipper`]): between two nodes that share part of a side (any levels), the strip between their
//!   two border chains on that grid line, triangulated by merging the chains in order along the line. Both
//!   chains lie in the same vertical plane, so the strip closes the gap between the two surfaces. A chain is cut
//!   to the shared part, extended to the nearest vertex beyond each end it lacks (a larger node has no vertex
//!   where a smaller neighbour's corner is): the seams of a large node's side with each of its smaller
//!   neighbours then overlap around those corners instead of leaving a slit. Each seam triangle is listed in
//!   both windings, since which side of the wall faces the camera depends on which surface is higher there.
//! - **Selection** ([`BlockTree::cut`]): a node is replaced by its children where its reduction error projects
//!   over the threshold at the camera's distance to its box (`CutCamera::projected_to_box`), with a fade over
//!   the distance band `[d (1 - band), d (1 + band)]` around that distance `d`; each node's distance is kept
//!   below its parent's band (`d_child (1 + band) * 1.01 <= d_parent (1 - band)`), and a child's box lies in
//!   its parent's, so a node fades only while its parent is wholly replaced and its children are not.

use crate::error::{Error, Result};
use crate::geometry::cluster_dag::CutCamera;
use crate::geometry::mesh::Mesh;
use glam::Vec3;

/// One side of a node's region: which grid line and which part of it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// i = i0 (-x), i = i1 (+x), j = j0 (-z), j = j1 (+z).
    West,
    East,
    South,
    North,
}

/// One node of the hierarchy: its region of cells `[i0, i1) x [j0, j1)`, its mesh (a range of
/// [`BlockTree::indices`]), its reduction error and switch distance, its children.
#[derive(Debug, Clone, PartialEq)]
pub struct Node {
    pub level: u32,
    pub cells: [u32; 4],
    pub first_index: u32,
    pub index_count: u32,
    /// meshopt's absolute error of the reduction (0 for a leaf).
    pub error: f32,
    /// Where the error projects to the threshold, kept below the parent's band (set by
    /// [`BlockTree::set_switches`]; 0 for a leaf).
    pub switch_distance: f32,
    pub min: Vec3,
    pub max: Vec3,
    pub children: Vec<u32>,
    pub parent: Option<u32>,
    /// The border chain of each side (West, East, South, North): the mesh's vertices on that grid line,
    /// sorted along it.
    pub borders: [Vec<u32>; 4],
}

/// The hierarchy over one height-field mesh.
#[derive(Debug, Clone)]
pub struct BlockTree {
    pub cells: u32,
    pub nodes: Vec<Node>,
    /// Every node's triangles, node after node, into the mesh's vertices.
    pub indices: Vec<u32>,
    pub root: u32,
    /// Milliseconds the reductions took.
    pub build_ms: f64,
}

/// What a frame draws of the tree: the nodes drawn opaque (a partition of the terrain), and the nodes in a
/// fade drawn translucent with their alpha and whether the fade is past its middle (the children opaque).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Cut {
    pub opaque: Vec<u32>,
    pub translucent: Vec<(u32, f32, bool)>,
}

/// An error unless `mesh` is a grid of `cells` x `cells` quads (`geometry::terrain::terrain_mesh`'s).
fn check_grid(mesh: &Mesh, cells: u32) -> Result<()> {
    let row = cells + 1;
    if mesh.positions.len() != (row * row) as usize
        || mesh.indices.len() != (6 * cells * cells) as usize
    {
        return Err(Error::Config(format!(
            "blocks-tree needs the terrain's grid of {cells} x {cells} cells; the mesh has {} vertices and {} \
             triangles",
            mesh.positions.len(),
            mesh.indices.len() / 3
        )));
    }
    Ok(())
}

impl BlockTree {
    /// The hierarchy of `mesh`, a grid of `cells` x `cells` quads as `geometry::terrain::terrain_mesh` makes
    /// it, over `blocks` x `blocks` leaves.
    pub fn build(mesh: &Mesh, cells: u32, blocks: u32) -> Result<BlockTree> {
        let started = std::time::Instant::now();
        check_grid(mesh, cells)?;
        let blocks = blocks.clamp(1, cells);
        let bytes: &[u8] = bytemuck::cast_slice(&mesh.positions);
        let adapter = meshopt::VertexDataAdapter::new(bytes, 12, 0).map_err(|e| {
            Error::Config(format!("blocks-tree: meshopt rejected the vertices: {e}"))
        })?;
        let mut tree = BlockTree {
            cells,
            nodes: Vec::new(),
            indices: Vec::new(),
            root: 0,
            build_ms: 0.0,
        };
        // Leaves, then each level from the one below, 2 x 2 at a time.
        let mut level = tree.push_leaves(mesh, blocks);
        let mut locks = vec![false; mesh.positions.len()];
        let mut l = 0;
        while level.len() > 1 || level[0].len() > 1 {
            l += 1;
            let (rows, cols) = (level.len().div_ceil(2), level[0].len().div_ceil(2));
            let mut next = Vec::new();
            for pj in 0..rows {
                let mut r = Vec::new();
                for pi in 0..cols {
                    let children: Vec<u32> = (2 * pj..(2 * pj + 2).min(level.len()))
                        .flat_map(|j| {
                            (2 * pi..(2 * pi + 2).min(level[j].len())).map(move |i| (i, j))
                        })
                        .map(|(i, j)| level[j][i])
                        .collect();
                    let c = |k: u32| &tree.nodes[k as usize].cells;
                    let region = [
                        children.iter().map(|&k| c(k)[0]).min().unwrap_or(0),
                        children.iter().map(|&k| c(k)[1]).max().unwrap_or(0),
                        children.iter().map(|&k| c(k)[2]).min().unwrap_or(0),
                        children.iter().map(|&k| c(k)[3]).max().unwrap_or(0),
                    ];
                    let below: usize = children
                        .iter()
                        .map(|&k| tree.nodes[k as usize].index_count as usize)
                        .sum();
                    let full = region_indices(mesh, cells, region);
                    let corners = corner_vertices(cells, region);
                    for &v in &corners {
                        locks[v as usize] = true;
                    }
                    let target = crate::geometry::lod::target_index_count(below, 0.25);
                    let mut error = 0.0f32;
                    let reduced = meshopt::simplify_with_locks(
                        &full,
                        &adapter,
                        &locks,
                        target,
                        f32::MAX,
                        meshopt::SimplifyOptions::ErrorAbsolute,
                        Some(&mut error),
                    );
                    for &v in &corners {
                        locks[v as usize] = false;
                    }
                    r.push(tree.push_node(mesh, l, region, reduced, error, children));
                }
                next.push(r);
            }
            level = next;
        }
        tree.root = level[0][0];
        tree.link_parents();
        tree.build_ms = started.elapsed().as_secs_f64() * 1e3;
        Ok(tree)
    }

    /// The `blocks` x `blocks` leaves, each the mesh's full triangles over its cells: their nodes by row.
    fn push_leaves(&mut self, mesh: &Mesh, blocks: u32) -> Vec<Vec<u32>> {
        let cells = self.cells;
        let edge = |b: u32, n: u32| (b as u64 * cells as u64 / n as u64) as u32;
        let mut level: Vec<Vec<u32>> = Vec::new();
        for bj in 0..blocks {
            let mut r = Vec::new();
            for bi in 0..blocks {
                let region = [
                    edge(bi, blocks),
                    edge(bi + 1, blocks),
                    edge(bj, blocks),
                    edge(bj + 1, blocks),
                ];
                let indices = region_indices(mesh, cells, region);
                r.push(self.push_node(mesh, 0, region, indices, 0.0, Vec::new()));
            }
            level.push(r);
        }
        level
    }

    /// Sets every node's parent from its parent's children.
    fn link_parents(&mut self) {
        for k in 0..self.nodes.len() {
            for c in self.nodes[k].children.clone() {
                self.nodes[c as usize].parent = Some(k as u32);
            }
        }
    }

    fn push_node(
        &mut self,
        mesh: &Mesh,
        level: u32,
        cells: [u32; 4],
        indices: Vec<u32>,
        error: f32,
        children: Vec<u32>,
    ) -> u32 {
        let (mut min, mut max) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for &v in &indices {
            let p = Vec3::from(mesh.positions[v as usize]);
            min = min.min(p);
            max = max.max(p);
        }
        let row = self.cells + 1;
        let [i0, i1, j0, j1] = cells;
        let mut borders: [Vec<u32>; 4] = Default::default();
        let mut used: Vec<u32> = indices.clone();
        used.sort_unstable();
        used.dedup();
        for &v in &used {
            let (i, j) = (v % row, v / row);
            // Sorted along the line: by j on the x sides, by i on the z sides (the vertex order does it).
            for (k, on) in [i == i0, i == i1, j == j0, j == j1].into_iter().enumerate() {
                if on {
                    borders[k].push(v);
                }
            }
        }
        for (k, b) in borders.iter_mut().enumerate() {
            if k < 2 {
                b.sort_by_key(|&v| v / row);
            }
        }
        let node = Node {
            level,
            cells,
            first_index: self.indices.len() as u32,
            index_count: indices.len() as u32,
            error,
            switch_distance: 0.0,
            min,
            max,
            children,
            parent: None,
            borders,
        };
        self.indices.extend_from_slice(&indices);
        self.nodes.push(node);
        self.nodes.len() as u32 - 1
    }

    /// Each node's switch distance for `pixels_per_unit` and `pixel_error`: where its error projects to the
    /// threshold, kept below its parent's band of half-width `band` (parents first).
    pub fn set_switches(&mut self, pixels_per_unit: f32, pixel_error: f32, band: f32) {
        let ratio = (1.0 + band) / (1.0 - band) * 1.01;
        let mut stack = vec![self.root];
        while let Some(k) = stack.pop() {
            let node = &self.nodes[k as usize];
            let mut d = if node.children.is_empty() {
                0.0
            } else {
                node.error * pixels_per_unit / pixel_error
            };
            if let Some(p) = node.parent {
                d = d.min(self.nodes[p as usize].switch_distance / ratio);
            }
            self.nodes[k as usize].switch_distance = d;
            stack.extend(self.nodes[k as usize].children.iter().copied());
        }
    }

    /// Node `k`'s fade towards its children at the camera: 0 beyond its band (the node drawn), 1 inside it
    /// (its children drawn), linear in the distance to its box between.
    pub fn fade(&self, k: u32, camera: &CutCamera, band: f32) -> f32 {
        let n = &self.nodes[k as usize];
        if n.children.is_empty() || n.switch_distance <= 0.0 {
            return 0.0;
        }
        let d = (camera.eye - camera.eye.clamp(n.min, n.max)).length();
        let (near, far) = (
            n.switch_distance * (1.0 - band),
            n.switch_distance * (1.0 + band),
        );
        ((far - d) / (far - near)).clamp(0.0, 1.0)
    }

    /// The frame's cut at `camera` (Blow 2003a's fade rules, `alpha-zwrite`'s: before the middle of a fade the
    /// parent opaque and its children translucent at alpha 2k, after it the children opaque and the parent at
    /// 2(1 - k)).
    pub fn cut(&self, camera: &CutCamera, band: f32, out: &mut Cut) {
        out.opaque.clear();
        out.translucent.clear();
        let mut stack = vec![self.root];
        while let Some(k) = stack.pop() {
            let n = &self.nodes[k as usize];
            let f = self.fade(k, camera, band);
            if f <= 0.0 {
                out.opaque.push(k);
            } else if f >= 1.0 {
                stack.extend(n.children.iter().rev().copied());
            } else if f < 0.5 {
                out.opaque.push(k);
                out.translucent
                    .extend(n.children.iter().map(|&c| (c, 2.0 * f, false)));
            } else {
                out.opaque.extend(n.children.iter().copied());
                out.translucent.push((k, 2.0 * (1.0 - f), true));
            }
        }
    }

    /// The seams between the nodes of `opaque` (a partition of the terrain) that share part of a side, as
    /// triangles into the mesh's vertices (each in both windings).
    pub fn seams(&self, opaque: &[u32], out: &mut Vec<u32>) {
        out.clear();
        let row = self.cells + 1;
        for (a_pos, &a) in opaque.iter().enumerate() {
            let na = &self.nodes[a as usize];
            for &b in &opaque[a_pos + 1..] {
                let nb = &self.nodes[b as usize];
                let ([ai0, ai1, aj0, aj1], [bi0, bi1, bj0, bj1]) = (na.cells, nb.cells);
                // (side of a, side of b, the shared part along the line, the coordinate along it)
                let shared = if ai1 == bi0 || bi1 == ai0 {
                    let (sa, sb) = if ai1 == bi0 { (1, 0) } else { (0, 1) };
                    Some((sa, sb, aj0.max(bj0), aj1.min(bj1), true))
                } else if aj1 == bj0 || bj1 == aj0 {
                    let (sa, sb) = if aj1 == bj0 { (3, 2) } else { (2, 3) };
                    Some((sa, sb, ai0.max(bi0), ai1.min(bi1), false))
                } else {
                    None
                };
                let Some((sa, sb, t0, t1, along_j)) = shared else {
                    continue;
                };
                if t0 >= t1 {
                    continue;
                }
                let at = |v: u32| if along_j { v / row } else { v % row };
                let chain_a = clip_chain(&na.borders[sa], at, t0, t1);
                let chain_b = clip_chain(&nb.borders[sb], at, t0, t1);
                zipper(chain_a, chain_b, at, out);
            }
        }
    }
}

/// The triangles of cells `[i0, i1) x [j0, j1)` of the grid mesh.
fn region_indices(mesh: &Mesh, cells: u32, [i0, i1, j0, j1]: [u32; 4]) -> Vec<u32> {
    let mut out = Vec::with_capacity(((i1 - i0) * (j1 - j0) * 6) as usize);
    for j in j0..j1 {
        let start = ((j * cells + i0) * 6) as usize;
        let end = ((j * cells + i1) * 6) as usize;
        out.extend_from_slice(&mesh.indices[start..end]);
    }
    out
}

fn corner_vertices(cells: u32, [i0, i1, j0, j1]: [u32; 4]) -> [u32; 4] {
    let row = cells + 1;
    [j0 * row + i0, j0 * row + i1, j1 * row + i0, j1 * row + i1]
}

/// The part of `chain` (sorted by `at`) within `[t0, t1]`, with the nearest vertex beyond each end that has
/// no vertex exactly at it.
fn clip_chain(chain: &[u32], at: impl Fn(u32) -> u32, t0: u32, t1: u32) -> &[u32] {
    let first = chain.partition_point(|&v| at(v) < t0);
    let first = if first < chain.len() && at(chain[first]) == t0 {
        first
    } else {
        first.saturating_sub(1)
    };
    let end = chain.partition_point(|&v| at(v) <= t1);
    let end = if end > 0 && at(chain[end - 1]) == t1 {
        end
    } else {
        (end + 1).min(chain.len())
    };
    &chain[first..end.max(first)]
}

/// The strip between chains `a` and `b` (both sorted by `at` along one grid line), merged in order: each step
/// advances the chain whose next vertex comes first and makes a triangle of that chain's edge and the other
/// chain's current vertex, in both windings.
pub fn zipper(a: &[u32], b: &[u32], at: impl Fn(u32) -> u32, out: &mut Vec<u32>) {
    if a.is_empty() || b.is_empty() {
        return;
    }
    let (mut i, mut j) = (0, 0);
    while i + 1 < a.len() || j + 1 < b.len() {
        let advance_a = j + 1 >= b.len() || (i + 1 < a.len() && at(a[i + 1]) <= at(b[j + 1]));
        let tri = if advance_a {
            i += 1;
            [a[i - 1], a[i], b[j]]
        } else {
            j += 1;
            [b[j - 1], b[j], a[i]]
        };
        if tri[0] != tri[2] && tri[1] != tri[2] {
            out.extend_from_slice(&tri);
            out.extend_from_slice(&[tri[0], tri[2], tri[1]]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::cluster_dag::CutBound;

    fn terrain(cells: u32) -> Mesh {
        crate::geometry::terrain::terrain_mesh(2008, cells).unwrap()
    }

    fn camera(eye: Vec3, pixel_error: f32) -> CutCamera {
        CutCamera {
            eye,
            pixels_per_unit: 300.0,
            znear: 0.05,
            pixel_error,
            bound: CutBound::Box,
        }
    }

    #[test]
    fn levels_halve_and_parents_hold_about_a_childs_triangles() {
        let tree = BlockTree::build(&terrain(48), 48, 4).unwrap();
        // 16 leaves, 4 parents, 1 root.
        assert_eq!(tree.nodes.len(), 21);
        assert_eq!(tree.nodes[tree.root as usize].level, 2);
        assert_eq!(tree.nodes[tree.root as usize].cells, [0, 48, 0, 48]);
        let leaf_tris = 12 * 12 * 2;
        for n in &tree.nodes {
            let tris = n.index_count as usize / 3;
            match n.level {
                0 => assert_eq!((tris, n.error), (leaf_tris, 0.0)),
                _ => {
                    assert!(
                        tris <= leaf_tris && tris > leaf_tris / 2,
                        "level {} {tris}",
                        n.level
                    );
                    assert!(n.error > 0.0);
                    assert_eq!(n.children.len(), 4);
                }
            }
        }
        // Errors grow up the tree.
        let root = &tree.nodes[tree.root as usize];
        assert!(root
            .children
            .iter()
            .all(|&c| tree.nodes[c as usize].error < root.error));
    }

    #[test]
    fn borders_stay_on_their_lines_with_the_corners() {
        let mesh = terrain(48);
        let tree = BlockTree::build(&mesh, 48, 4).unwrap();
        let row = 49;
        for n in &tree.nodes {
            let [i0, i1, j0, j1] = n.cells;
            for (k, chain) in n.borders.iter().enumerate() {
                let (first, last) = (chain[0], chain[chain.len() - 1]);
                let ends = match k {
                    0 => (j0 * row + i0, j1 * row + i0),
                    1 => (j0 * row + i1, j1 * row + i1),
                    2 => (j0 * row + i0, j0 * row + i1),
                    _ => (j1 * row + i0, j1 * row + i1),
                };
                assert_eq!((first, last), ends, "node {:?} side {k}", n.cells);
            }
            // The reduced mesh's area in x-z is its region's: nothing cut off at the borders.
            let area: f32 = tree.indices
                [n.first_index as usize..(n.first_index + n.index_count) as usize]
                .chunks(3)
                .map(|t| {
                    let [p, q, r] = [t[0], t[1], t[2]]
                        .map(|v| Vec3::from(mesh.positions[v as usize]).with_y(0.0));
                    (q - p).cross(r - p).y * 0.5
                })
                .sum();
            let cell = 100.0 / 48.0;
            let region = (i1 - i0) as f32 * (j1 - j0) as f32 * cell * cell;
            assert!((area - region).abs() < 1e-3 * region, "{area} {region}");
        }
    }

    #[test]
    fn cut_is_a_partition_and_fades_one_level_at_a_time() {
        let mut tree = BlockTree::build(&terrain(48), 48, 4).unwrap();
        tree.set_switches(300.0, 1.0, 0.05);
        let mut cut = Cut::default();
        let mut fading = 0;
        for step in 0..200 {
            let t = step as f32 / 200.0;
            // From over the terrain out to where the root's error projects under a pixel.
            let eye = Vec3::new(50.0, 14.0, 50.0 + 350.0 * t);
            tree.cut(&camera(eye, 1.0), 0.05, &mut cut);
            // Every cell in exactly one opaque node.
            let mut cover = vec![0u32; 48 * 48];
            for &k in &cut.opaque {
                let [i0, i1, j0, j1] = tree.nodes[k as usize].cells;
                for j in j0..j1 {
                    for i in i0..i1 {
                        cover[(j * 48 + i) as usize] += 1;
                    }
                }
            }
            assert!(cover.iter().all(|&c| c == 1), "step {step}");
            // A translucent node is never opaque too, and its parent or its children are opaque.
            for &(k, alpha, swapped) in &cut.translucent {
                assert!(!cut.opaque.contains(&k) && alpha > 0.0 && alpha <= 1.0);
                let n = &tree.nodes[k as usize];
                match swapped {
                    true => assert!(n.children.iter().all(|c| cut.opaque.contains(c))),
                    false => assert!(cut.opaque.contains(&n.parent.unwrap())),
                }
                fading += 1;
            }
        }
        assert!(fading > 0);
    }

    #[test]
    fn zipper_covers_both_chains_in_order() {
        // Chains along one line, positions = vertex ids.
        let (a, b) = ([0u32, 3, 4, 8], [0u32, 1, 2, 6, 8]);
        let mut out = Vec::new();
        zipper(&a, &b, |v| v, &mut out);
        // 3 + 4 edges, one triangle each, both windings, less the two that close on a shared end (0, 8).
        assert_eq!(out.len(), 5 * 6);
        for w in a.windows(2).chain(b.windows(2)) {
            assert!(
                out.chunks(3)
                    .any(|t| t.contains(&w[0]) && t.contains(&w[1])),
                "{w:?}"
            );
        }
        // A chain without the end: the nearest vertex beyond it is kept.
        assert_eq!(clip_chain(&[0, 3, 5, 9], |v| v, 4, 6), &[3, 5, 9]);
        assert_eq!(clip_chain(&[0, 3, 5, 9], |v| v, 3, 9), &[3, 5, 9]);
    }
}
