//! ROAM, Real-time Optimally Adapting Meshes (Duchaineau et al. 1997, the terrain algorithm of seed 002): a
//! binary triangle tree over a height field, split and merged from frame to frame so that every leaf's
//! projected distortion is at or under a threshold in pixels. Pure CPU, deterministic.
//!
//! - **Height field** ([`HeightField`]): `n` x `n` cells, `n` a power of two, over the square `[0, size]^2`
//!   of the x-z plane, heights in y. The `terrain` scene's field samples the same function as its mesh
//!   (`geometry::terrain::height`) on the power-of-two grid nearest its cell count.
//! - **Bintree**: the square is two right isosceles root triangles sharing the diagonal from (n, 0) to (0, n);
//!   a triangle (left, right, apex) splits at the midpoint c of its hypotenuse (left-right) into its left child
//!   (apex, left, c) and its right child (right, apex, c), which keep its winding (counter-clockwise seen from
//!   +y). Each triangle knows its left, right and base neighbours (across the edges apex-left, right-apex and
//!   the hypotenuse); the leaves are the triangulation. Depth `2 log2 n` gives triangles with legs of one cell.
//! - **Forced splits**: a triangle splits only together with its base neighbour (a diamond); a base neighbour
//!   one level coarser is split first, recursively. Every leaf's neighbours are then within one level of it
//!   and no vertex lies inside another leaf's edge: the mesh has no cracks.
//! - **Wedgies** (nested, Duchaineau §5): a triangle's thickness is
//!   `e = max(e_left, e_right) + |z(c) - (z(left) + z(right)) / 2|`, 0 at the finest level: every point of the
//!   field over the triangle lies within `e` above or below the triangle's surface (vertically).
//! - **Priority**: the thickness projected to pixels at the camera's distance to the triangle's box (its x-z
//!   bounding rectangle, the height range of the field under it), clamped to the near plane: the isotropic
//!   bound lodbench's block switches and clusterlod's box bound use (`CutCamera::projected_to_box`), an upper
//!   bound of Duchaineau's view-dependent one. A child's box lies in its parent's and its thickness is no larger,
//!   so a child's priority never exceeds its parent's: splitting only lowers the priorities of the leaves.
//! - **Per frame** ([`Bintree::update`]): the triangulation carries over from the frame before. The split
//!   queue (leaves over the threshold, highest priority first) splits, forced splits included, until no leaf is
//!   over it; then the merge queue (mergeable diamonds, both triangles at or under the threshold, lowest
//!   priority first) merges, pushing each merged diamond's parents when they become mergeable. A diamond is
//!   mergeable when its (one or two) triangles are split into leaves, so merging removes exactly one vertex.
//!   The queues are refilled from the carried triangulation every frame with this frame's priorities (the
//!   camera moves every frame, so every priority changes; Duchaineau's deferred recomputation is not built).
//!   With a threshold (no triangle budget) the order does not change the result: each frame ends on the
//!   coarsest crack-free triangulation with every leaf at or under the threshold, whatever it started from
//!   (test `coherent_update_equals_update_from_the_roots`).

use crate::geometry::cluster_dag::CutCamera;
use glam::Vec3;
use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;

/// No node (a missing neighbour or child).
pub const NONE: u32 = u32::MAX;
const LEFT: usize = 0;
const RIGHT: usize = 1;
const BASE: usize = 2;

/// A height field of `n` x `n` square cells over `[0, size]^2`, heights row by row (`j * (n + 1) + i` at
/// x = i size / n, z = j size / n).
#[derive(Debug, Clone, PartialEq)]
pub struct HeightField {
    pub n: u32,
    pub size: f32,
    pub heights: Vec<f32>,
}

impl HeightField {
    /// `n` (a power of two, at least 2) cells a side, heights `f(x, z)`.
    pub fn from_fn(n: u32, size: f32, f: impl Fn(f32, f32) -> f32) -> HeightField {
        let n = n.max(2).next_power_of_two();
        let step = size / n as f32;
        let heights = (0..=n)
            .flat_map(|j| (0..=n).map(move |i| (i as f32 * step, j as f32 * step)))
            .map(|(x, z)| f(x, z))
            .collect();
        HeightField { n, size, heights }
    }

    /// The power of two nearest `cells` by ratio (at least 2): the ROAM grid for a mesh of `cells` x `cells`.
    pub fn grid_for(cells: u32) -> u32 {
        let cells = cells.max(2) as u64;
        let hi = cells.next_power_of_two();
        let lo = (hi / 2).max(2);
        (if cells * cells < lo * hi { lo } else { hi }) as u32
    }

    pub fn vertex_count(&self) -> usize {
        ((self.n + 1) * (self.n + 1)) as usize
    }

    pub fn index(&self, i: u32, j: u32) -> u32 {
        j * (self.n + 1) + i
    }

    fn grid(&self, v: u32) -> (u32, u32) {
        (v % (self.n + 1), v / (self.n + 1))
    }

    pub fn position(&self, v: u32) -> Vec3 {
        let (i, j) = self.grid(v);
        let step = self.size / self.n as f32;
        Vec3::new(i as f32 * step, self.heights[v as usize], j as f32 * step)
    }

    /// Vertex normals from central differences of the heights (one-sided at the border).
    pub fn normals(&self) -> Vec<[f32; 3]> {
        let n = self.n;
        let step = self.size / n as f32;
        let h = |i: u32, j: u32| self.heights[self.index(i, j) as usize];
        (0..=n)
            .flat_map(|j| (0..=n).map(move |i| (i, j)))
            .map(|(i, j)| {
                let (i0, i1) = (i.saturating_sub(1), (i + 1).min(n));
                let (j0, j1) = (j.saturating_sub(1), (j + 1).min(n));
                let dx = (h(i1, j) - h(i0, j)) / ((i1 - i0) as f32 * step);
                let dz = (h(i, j1) - h(i, j0)) / ((j1 - j0) as f32 * step);
                Vec3::new(-dx, 1.0, -dz).normalize().to_array()
            })
            .collect()
    }
}

/// One triangle of the bintree.
#[derive(Debug, Clone, Copy)]
struct Node {
    /// Index into the static arrays: root * stride + heap index (root 1, children 2h and 2h + 1).
    id: u32,
    level: u8,
    /// Grid vertices: left, right, apex (hypotenuse left-right).
    v: [u32; 3],
    child: [u32; 2],
    parent: u32,
    /// Neighbours across apex-left, right-apex and the hypotenuse.
    nb: [u32; 3],
}

/// Splits and merges of one update, in bintree nodes (a diamond of two triangles counts 2).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct UpdateCounts {
    pub splits: u32,
    pub merges: u32,
}

/// A priority in a queue: ordered by value, then by node for a total, deterministic order.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Queued(f32, u32);

impl Eq for Queued {}

impl PartialOrd for Queued {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Queued {
    fn cmp(&self, other: &Self) -> Ordering {
        self.0.total_cmp(&other.0).then(self.1.cmp(&other.1))
    }
}

/// The bintree of a height field: the static per-node thickness and height range, and the current
/// triangulation.
#[derive(Debug, Clone)]
pub struct Bintree {
    field: HeightField,
    /// Deepest level (`2 log2 n`).
    depth: u8,
    /// Static entries per root (`2^(depth + 1)`).
    stride: u32,
    /// Nested wedgie thickness, and the lowest and highest height under each node, by static index.
    thickness: Vec<f32>,
    y_min: Vec<f32>,
    y_max: Vec<f32>,
    nodes: Vec<Node>,
    free: Vec<u32>,
    roots: [u32; 2],
    split_queue: BinaryHeap<Queued>,
    merge_queue: BinaryHeap<Reverse<Queued>>,
    scratch: Vec<u32>,
}

impl Bintree {
    /// The bintree of `field`, its triangulation the two roots.
    pub fn new(field: HeightField) -> Bintree {
        let depth = (2 * field.n.trailing_zeros()) as u8;
        let stride = 1u32 << (depth + 1);
        let len = 2 * stride as usize;
        let mut tree = Bintree {
            depth,
            stride,
            thickness: vec![0.0; len],
            y_min: vec![0.0; len],
            y_max: vec![0.0; len],
            nodes: Vec::new(),
            free: Vec::new(),
            roots: [NONE; 2],
            split_queue: BinaryHeap::new(),
            merge_queue: BinaryHeap::new(),
            scratch: Vec::new(),
            field,
        };
        for (r, v) in tree.root_vertices().into_iter().enumerate() {
            tree.fill_static(r as u32 * stride + 1, 0, v);
        }
        tree.reset();
        tree
    }

    pub fn field(&self) -> &HeightField {
        &self.field
    }

    /// The deepest level: triangles with legs of one cell.
    pub fn depth(&self) -> u8 {
        self.depth
    }

    /// The two roots (left, right, apex), counter-clockwise from +y: apex (0, 0) and apex (n, n) on the
    /// diagonal from (n, 0) to (0, n).
    fn root_vertices(&self) -> [[u32; 3]; 2] {
        let f = &self.field;
        let n = f.n;
        let (a, b, c, d) = (f.index(0, 0), f.index(n, 0), f.index(n, n), f.index(0, n));
        [[d, b, a], [b, d, c]]
    }

    fn midpoint(&self, a: u32, b: u32) -> u32 {
        let ((ai, aj), (bi, bj)) = (self.field.grid(a), self.field.grid(b));
        self.field.index((ai + bi) / 2, (aj + bj) / 2)
    }

    fn height(&self, v: u32) -> f32 {
        self.field.heights[v as usize]
    }

    /// Fills the static entries of node `id` at `level` with vertices (left, right, apex) and its subtree.
    fn fill_static(&mut self, id: u32, level: u8, [l, r, a]: [u32; 3]) {
        let i = id as usize;
        if level == self.depth {
            let hs = [self.height(l), self.height(r), self.height(a)];
            self.thickness[i] = 0.0;
            self.y_min[i] = hs.iter().copied().fold(f32::INFINITY, f32::min);
            self.y_max[i] = hs.iter().copied().fold(f32::NEG_INFINITY, f32::max);
            return;
        }
        let c = self.midpoint(l, r);
        let root_base = id - id % self.stride;
        let heap = id - root_base;
        let (lc, rc) = (root_base + 2 * heap, root_base + 2 * heap + 1);
        self.fill_static(lc, level + 1, [a, l, c]);
        self.fill_static(rc, level + 1, [r, a, c]);
        let (lc, rc) = (lc as usize, rc as usize);
        let bend = (self.height(c) - (self.height(l) + self.height(r)) * 0.5).abs();
        self.thickness[i] = self.thickness[lc].max(self.thickness[rc]) + bend;
        self.y_min[i] = self.y_min[lc].min(self.y_min[rc]);
        self.y_max[i] = self.y_max[lc].max(self.y_max[rc]);
    }

    /// Back to the two roots.
    pub fn reset(&mut self) {
        self.nodes.clear();
        self.free.clear();
        let vs = self.root_vertices();
        for (r, v) in vs.into_iter().enumerate() {
            self.nodes.push(Node {
                id: r as u32 * self.stride + 1,
                level: 0,
                v,
                child: [NONE; 2],
                parent: NONE,
                nb: [NONE, NONE, 1 - r as u32],
            });
            self.roots[r] = r as u32;
        }
    }

    fn alloc(&mut self, node: Node) -> u32 {
        match self.free.pop() {
            Some(i) => {
                self.nodes[i as usize] = node;
                i
            }
            None => {
                self.nodes.push(node);
                self.nodes.len() as u32 - 1
            }
        }
    }

    fn node(&self, t: u32) -> &Node {
        &self.nodes[t as usize]
    }

    fn is_leaf(&self, t: u32) -> bool {
        self.node(t).child[0] == NONE
    }

    /// Replaces `x`'s neighbour pointer to `old` with `new`.
    fn relink(&mut self, x: u32, old: u32, new: u32) {
        let nb = &mut self.nodes[x as usize].nb;
        if let Some(k) = nb.iter().position(|&y| y == old) {
            nb[k] = new;
        } else {
            debug_assert!(false, "node {x} is not a neighbour of {old}");
        }
    }

    /// Splits leaf `t` with its base neighbour, forcing splits of coarser base neighbours first; every node
    /// split is pushed onto `split` (Duchaineau's forced split; the linking follows Turner's "ROAM Simplistic").
    fn split(&mut self, t: u32, split: &mut Vec<u32>) {
        if !self.is_leaf(t) || self.node(t).level == self.depth {
            return;
        }
        let b = self.node(t).nb[BASE];
        if b != NONE && self.node(b).nb[BASE] != t {
            self.split(b, split);
        }
        let n = *self.node(t);
        let [l, r, a] = n.v;
        let c = self.midpoint(l, r);
        let root_base = n.id - n.id % self.stride;
        let heap = n.id - root_base;
        let child = |id, v| Node {
            id,
            level: n.level + 1,
            v,
            child: [NONE; 2],
            parent: t,
            nb: [NONE; 3],
        };
        let lc = self.alloc(child(root_base + 2 * heap, [a, l, c]));
        let rc = self.alloc(child(root_base + 2 * heap + 1, [r, a, c]));
        self.nodes[t as usize].child = [lc, rc];
        split.push(t);
        self.nodes[lc as usize].nb[BASE] = n.nb[LEFT];
        self.nodes[lc as usize].nb[LEFT] = rc;
        self.nodes[rc as usize].nb[BASE] = n.nb[RIGHT];
        self.nodes[rc as usize].nb[RIGHT] = lc;
        if n.nb[LEFT] != NONE {
            self.relink(n.nb[LEFT], t, lc);
        }
        if n.nb[RIGHT] != NONE {
            self.relink(n.nb[RIGHT], t, rc);
        }
        let b = self.node(t).nb[BASE];
        if b == NONE {
            return;
        }
        if self.is_leaf(b) {
            // The partner splits now and links its children to ours (the branch below, from its side).
            self.split(b, split);
        } else {
            let [bl, br] = self.node(b).child;
            self.nodes[bl as usize].nb[RIGHT] = rc;
            self.nodes[br as usize].nb[LEFT] = lc;
            self.nodes[lc as usize].nb[RIGHT] = br;
            self.nodes[rc as usize].nb[LEFT] = bl;
        }
    }

    /// Whether `t`'s diamond (it and its base neighbour) is split exactly once: both its triangles have two
    /// leaf children.
    fn mergeable(&self, t: u32) -> bool {
        let split_once = |x: u32| {
            let c = self.node(x).child;
            c[0] != NONE && self.is_leaf(c[0]) && self.is_leaf(c[1])
        };
        let b = self.node(t).nb[BASE];
        split_once(t) && (b == NONE || (self.node(b).nb[BASE] == t && split_once(b)))
    }

    /// Undoes the split of `t` alone (its children are leaves).
    fn unsplit(&mut self, t: u32) {
        let [lc, rc] = self.node(t).child;
        let (outer_l, outer_r) = (self.node(lc).nb[BASE], self.node(rc).nb[BASE]);
        self.nodes[t as usize].nb[LEFT] = outer_l;
        self.nodes[t as usize].nb[RIGHT] = outer_r;
        if outer_l != NONE {
            self.relink(outer_l, lc, t);
        }
        if outer_r != NONE {
            self.relink(outer_r, rc, t);
        }
        self.nodes[t as usize].child = [NONE; 2];
        self.free.extend([lc, rc]);
    }

    /// Merges `t`'s diamond (mergeable); returns the nodes merged (1 or 2).
    fn merge(&mut self, t: u32) -> u32 {
        let b = self.node(t).nb[BASE];
        self.unsplit(t);
        if b != NONE {
            self.unsplit(b);
            2
        } else {
            1
        }
    }

    /// The diamond's name in the merge queue: the lower of its nodes' static ids' pool indices.
    fn diamond(&self, t: u32) -> u32 {
        let b = self.node(t).nb[BASE];
        if b == NONE {
            t
        } else {
            t.min(b)
        }
    }

    /// Node `t`'s projected distortion in pixels (its thickness at the camera's distance to its box).
    pub fn priority(&self, t: u32, camera: &CutCamera) -> f32 {
        let n = self.node(t);
        let id = n.id as usize;
        if self.thickness[id] == 0.0 {
            return 0.0;
        }
        let ps = n.v.map(|v| self.field.position(v));
        let min = ps[0].min(ps[1]).min(ps[2]).with_y(self.y_min[id]);
        let max = ps[0].max(ps[1]).max(ps[2]).with_y(self.y_max[id]);
        camera.projected_to_box(self.thickness[id], min, max)
    }

    fn diamond_priority(&self, t: u32, camera: &CutCamera) -> f32 {
        let b = self.node(t).nb[BASE];
        let p = self.priority(t, camera);
        if b == NONE {
            p
        } else {
            p.max(self.priority(b, camera))
        }
    }

    /// Every leaf, depth first from root 0, left child first.
    fn leaves(&self, out: &mut Vec<u32>) {
        out.clear();
        let mut stack: Vec<u32> = self.roots.iter().rev().copied().collect();
        while let Some(t) = stack.pop() {
            let c = self.node(t).child;
            if c[0] == NONE {
                out.push(t);
            } else {
                stack.extend([c[1], c[0]]);
            }
        }
    }

    /// Every split node's diamond name, for the merge queue's refill.
    fn mergeable_diamonds(&self, out: &mut Vec<u32>) {
        out.clear();
        let mut stack: Vec<u32> = self.roots.to_vec();
        while let Some(t) = stack.pop() {
            let c = self.node(t).child;
            if c[0] != NONE {
                if self.mergeable(t) && self.diamond(t) == t {
                    out.push(t);
                }
                stack.extend(c);
            }
        }
    }

    /// One frame's update at `camera` (its `pixel_error` the threshold): splits, then merges.
    pub fn update(&mut self, camera: &CutCamera) -> UpdateCounts {
        let tau = camera.pixel_error;
        let mut counts = UpdateCounts::default();
        let mut nodes = std::mem::take(&mut self.scratch);
        self.leaves(&mut nodes);
        self.split_queue.clear();
        for &t in &nodes {
            let p = self.priority(t, camera);
            if p > tau {
                self.split_queue.push(Queued(p, t));
            }
        }
        while let Some(Queued(_, t)) = self.split_queue.pop() {
            if !self.is_leaf(t) {
                continue;
            }
            nodes.clear();
            self.split(t, &mut nodes);
            counts.splits += nodes.len() as u32;
            for &s in &nodes {
                for c in self.node(s).child {
                    let p = self.priority(c, camera);
                    if p > tau {
                        self.split_queue.push(Queued(p, c));
                    }
                }
            }
        }
        self.mergeable_diamonds(&mut nodes);
        self.merge_queue.clear();
        for &t in &nodes {
            let p = self.diamond_priority(t, camera);
            if p <= tau {
                self.merge_queue.push(Reverse(Queued(p, t)));
            }
        }
        while let Some(Reverse(Queued(_, t))) = self.merge_queue.pop() {
            if self.is_leaf(t) || !self.mergeable(t) {
                continue;
            }
            let b = self.node(t).nb[BASE];
            counts.merges += self.merge(t);
            for x in [t, b] {
                if x == NONE {
                    continue;
                }
                let parent = self.node(x).parent;
                if parent != NONE && self.mergeable(parent) {
                    let d = self.diamond(parent);
                    let p = self.diamond_priority(d, camera);
                    if p <= tau {
                        self.merge_queue.push(Reverse(Queued(p, d)));
                    }
                }
            }
        }
        self.scratch = nodes;
        counts
    }

    /// The triangulation as grid-vertex indices, three per leaf (left, right, apex: counter-clockwise from
    /// +y), leaves in depth-first order.
    pub fn triangles_into(&mut self, out: &mut Vec<u32>) {
        let mut leaves = std::mem::take(&mut self.scratch);
        self.leaves(&mut leaves);
        out.clear();
        out.extend(leaves.iter().flat_map(|&t| self.node(t).v));
        self.scratch = leaves;
    }

    /// Leaves of the triangulation.
    pub fn triangle_count(&self) -> usize {
        let mut leaves = Vec::new();
        self.leaves(&mut leaves);
        leaves.len()
    }

    /// The vertex each split node adds (the midpoint of its hypotenuse) and the two it lies between, for every
    /// split node: what `roam-morph` moves in from the edge's midpoint height.
    pub fn split_vertices(&self, out: &mut Vec<[u32; 3]>) {
        out.clear();
        let mut stack: Vec<u32> = self.roots.to_vec();
        while let Some(t) = stack.pop() {
            let n = self.node(t);
            if n.child[0] != NONE {
                out.push([self.midpoint(n.v[0], n.v[1]), n.v[0], n.v[1]]);
                stack.extend(n.child);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::cluster_dag::CutBound;
    use crate::rng::SplitMix64;
    use std::collections::HashMap;

    fn field(n: u32) -> HeightField {
        HeightField::from_fn(n, 16.0, |x, z| {
            (x * 0.7).sin() * 1.5 + (z * 1.3).cos() * 0.8 + (x * z * 0.05).sin()
        })
    }

    fn camera(eye: Vec3, pixel_error: f32) -> CutCamera {
        CutCamera {
            eye,
            pixels_per_unit: 200.0,
            znear: 0.01,
            pixel_error,
            bound: CutBound::Box,
        }
    }

    /// Crack-free: every leaf edge is shared by exactly two leaves with the same two vertices, or lies on the
    /// square's border and belongs to one; and every neighbour pointer names a leaf across that edge, within
    /// one level.
    fn assert_conforming(tree: &Bintree) {
        let mut leaves = Vec::new();
        tree.leaves(&mut leaves);
        let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
        for &t in &leaves {
            let [l, r, a] = tree.node(t).v;
            for (p, q) in [(l, r), (r, a), (a, l)] {
                *edges.entry((p.min(q), p.max(q))).or_default() += 1;
            }
        }
        let n = tree.field.n;
        let on_border = |v: u32| {
            let (i, j) = tree.field.grid(v);
            (i == 0 || i == n, j == 0 || j == n)
        };
        for (&(p, q), &count) in &edges {
            let ((pi, pj), (qi, qj)) = (tree.field.grid(p), tree.field.grid(q));
            let border = (pi == qi && on_border(p).0) || (pj == qj && on_border(p).1);
            assert_eq!(count, if border { 1 } else { 2 }, "edge {p}-{q}");
        }
        for &t in &leaves {
            let node = tree.node(t);
            let [l, r, a] = node.v;
            for (k, (p, q)) in [(LEFT, (a, l)), (RIGHT, (r, a)), (BASE, (l, r))] {
                let x = node.nb[k];
                if x == NONE {
                    continue;
                }
                let other = tree.node(x);
                assert!(other.level.abs_diff(node.level) <= 1, "levels {t} {x}");
                if tree.is_leaf(x) && other.level == node.level {
                    assert!(other.v.contains(&p) && other.v.contains(&q), "{t} -> {x}");
                }
            }
        }
    }

    fn sorted_triangles(tree: &mut Bintree) -> Vec<[u32; 3]> {
        let mut idx = Vec::new();
        tree.triangles_into(&mut idx);
        let mut tris: Vec<[u32; 3]> = idx.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
        tris.sort();
        tris
    }

    #[test]
    fn heightfield_grid_is_the_nearest_power_of_two() {
        assert_eq!(HeightField::grid_for(280), 256);
        assert_eq!(HeightField::grid_for(48), 64);
        assert_eq!(HeightField::grid_for(160), 128);
        assert_eq!(HeightField::grid_for(1000), 1024);
        assert_eq!(HeightField::grid_for(1), 2);
        let f = field(8);
        assert_eq!(f.heights.len(), 81);
        assert_eq!(
            f.position(f.index(8, 4)),
            Vec3::new(16.0, f.heights[44], 8.0)
        );
    }

    #[test]
    fn thickness_bounds_the_field_and_nests() {
        let tree = Bintree::new(field(16));
        for r in 0..2u32 {
            for h in 1..tree.stride / 2 {
                let (p, c0, c1) = (
                    r * tree.stride + h,
                    r * tree.stride + 2 * h,
                    r * tree.stride + 2 * h + 1,
                );
                let [p, c0, c1] = [p, c0, c1].map(|i| i as usize);
                assert!(tree.thickness[p] >= tree.thickness[c0].max(tree.thickness[c1]));
                assert!(tree.y_min[p] <= tree.y_min[c0] && tree.y_max[p] >= tree.y_max[c1]);
            }
        }
        let root = 1usize;
        assert!(tree.thickness[root] > 0.0);
        // The finest level is exact.
        let leaf = (tree.stride / 2) as usize;
        assert_eq!(tree.thickness[leaf], 0.0);
    }

    #[test]
    fn forced_split_keeps_neighbours_within_one_level() {
        let mut tree = Bintree::new(field(16));
        // Split down to the finest level along one corner, which forces splits across the square.
        let mut split = Vec::new();
        for _ in 0..tree.depth {
            let mut leaves = Vec::new();
            tree.leaves(&mut leaves);
            let t = *leaves
                .iter()
                .max_by_key(|&&t| {
                    tree.node(t).v.contains(&0) as u32 * 100 + tree.node(t).level as u32
                })
                .unwrap();
            let before = split.len();
            tree.split(t, &mut split);
            assert!(split.len() > before, "split of {t} did nothing");
            assert_conforming(&tree);
        }
        // Forced splits happened: more nodes were split than the splits asked for (one per level).
        assert!(split.len() > tree.depth as usize, "{}", split.len());
        let mut leaves = Vec::new();
        tree.leaves(&mut leaves);
        let levels = leaves.iter().map(|&t| tree.node(t).level);
        assert_eq!(levels.clone().max(), Some(tree.depth));
        assert!(levels.min() < Some(tree.depth / 2));
        assert!(tree.triangle_count() > 2 * tree.depth as usize);
    }

    #[test]
    fn merge_undoes_split() {
        let mut tree = Bintree::new(field(16));
        let start = sorted_triangles(&mut tree);
        let mut split = Vec::new();
        let mut leaves = Vec::new();
        for step in 0..40 {
            tree.leaves(&mut leaves);
            let t = leaves[(step * 7919) % leaves.len()];
            tree.split(t, &mut split);
        }
        assert_conforming(&tree);
        assert!(tree.triangle_count() > 40);
        // Merge every mergeable diamond until none is left: back to the roots.
        let mut diamonds = Vec::new();
        loop {
            tree.mergeable_diamonds(&mut diamonds);
            let Some(&t) = diamonds.first() else { break };
            tree.merge(t);
            assert_conforming(&tree);
        }
        assert_eq!(sorted_triangles(&mut tree), start);
        // Every node split was given back to the pool.
        assert_eq!(tree.nodes.len() - tree.free.len(), 2);
    }

    #[test]
    fn merge_of_a_diamond_restores_the_triangulation_before_its_split() {
        let mut tree = Bintree::new(field(8));
        let mut split = Vec::new();
        tree.split(0, &mut split);
        let mut leaves = Vec::new();
        tree.leaves(&mut leaves);
        tree.split(leaves[1], &mut split);
        let before = sorted_triangles(&mut tree);
        tree.leaves(&mut leaves);
        let t = leaves[2];
        split.clear();
        tree.split(t, &mut split);
        assert_ne!(sorted_triangles(&mut tree), before);
        // Merging the split node's diamonds, finest first, restores the triangulation.
        for &s in split.iter().rev() {
            if !tree.is_leaf(s) && tree.mergeable(s) {
                tree.merge(s);
            }
        }
        assert_eq!(sorted_triangles(&mut tree), before);
        assert_conforming(&tree);
    }

    /// The update's invariants at `camera`: no leaf over the threshold (unless at the finest level), no
    /// mergeable diamond at or under it, no crack.
    fn assert_settled(tree: &Bintree, camera: &CutCamera) {
        let mut nodes = Vec::new();
        tree.leaves(&mut nodes);
        for &t in &nodes {
            assert!(
                tree.priority(t, camera) <= camera.pixel_error || tree.node(t).level == tree.depth,
                "leaf {t} over the threshold"
            );
        }
        tree.mergeable_diamonds(&mut nodes);
        for &t in &nodes {
            assert!(
                tree.diamond_priority(t, camera) > camera.pixel_error,
                "diamond {t} left"
            );
        }
        assert_conforming(tree);
    }

    #[test]
    fn coherent_update_equals_update_from_the_roots() {
        let mut coherent = Bintree::new(field(32));
        let mut fresh = coherent.clone();
        let mut rng = SplitMix64::new(34);
        let mut eye = Vec3::new(2.0, 4.0, 2.0);
        let (mut splits, mut merges) = (0, 0);
        for frame in 0..60 {
            // A seeded flight: a random walk over the square, now and then a jump.
            let jump = frame % 20 == 19;
            let step = if jump { 8.0 } else { 0.6 };
            eye += Vec3::new(rng.next_f32() - 0.3, 0.0, rng.next_f32() - 0.3) * step;
            eye = eye.clamp(Vec3::new(-2.0, 3.0, -2.0), Vec3::new(18.0, 5.0, 18.0));
            let cam = camera(eye, 1.0 + 2.0 * rng.next_f32());
            let c = coherent.update(&cam);
            splits += c.splits;
            merges += c.merges;
            assert_settled(&coherent, &cam);
            fresh.reset();
            fresh.update(&cam);
            assert_eq!(
                sorted_triangles(&mut coherent),
                sorted_triangles(&mut fresh),
                "frame {frame}"
            );
            // Nothing left to do: a second update at the same camera changes nothing.
            assert_eq!(coherent.update(&cam), UpdateCounts::default());
        }
        assert!(splits > 0 && merges > 0, "{splits} {merges}");
    }

    #[test]
    fn triangles_fall_as_the_threshold_rises() {
        let mut tree = Bintree::new(field(32));
        let eye = Vec3::new(1.0, 4.0, 1.0);
        let counts: Vec<usize> = [0.5, 1.0, 2.0, 4.0]
            .map(|p| {
                tree.update(&camera(eye, p));
                tree.triangle_count()
            })
            .into();
        assert!(counts.windows(2).all(|w| w[0] > w[1]), "{counts:?}");
    }

    #[test]
    fn triangles_wind_counter_clockwise_from_above() {
        let mut tree = Bintree::new(field(8));
        tree.update(&camera(Vec3::new(0.0, 3.0, 0.0), 0.5));
        let mut idx = Vec::new();
        tree.triangles_into(&mut idx);
        assert!(idx.len() > 6);
        for c in idx.chunks(3) {
            let [p, q, r] = [c[0], c[1], c[2]].map(|v| tree.field.position(v).with_y(0.0));
            assert!((q - p).cross(r - p).y > 0.0, "{c:?}");
        }
    }
}
