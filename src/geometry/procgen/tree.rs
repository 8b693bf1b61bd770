//! TREES: one seeded skeleton of generalised cylinders and leaf cards, 4 LODs from coarser parameters and
//! billboard-cloud cards (the module docs of `procgen` give the table), and the cards' alpha masks.

use super::mesh_builder::{tube, AuxKind, Builder, Caps};
use super::model_chain::{measure_errors, ModelChain};
use crate::error::Result;
use crate::geometry::lod::LodChain;
use crate::geometry::mesh::{Mesh, AUX_LEAF, AUX_LEAF_CLUSTER, AUX_SOLID};
use crate::rng::SplitMix64;
use glam::{Quat, Vec3};
use std::f32::consts::TAU;

/// Height of a tree's LOD0 (the skeleton is scaled to it).
pub const TREE_HEIGHT: f32 = 8.0;
/// Every tree LOD stays within this distance of the y axis in x and in z.
pub const TREE_MAX_HALF_WIDTH: f32 = 4.0;

/// The single-leaf alpha mask over a card's (u, v) in [0, 1]^2: a pointed leaf along v. Must match
/// `leaf_mask` in shaders/mesh.wgsl (the mask of [`AUX_LEAF`] cards).
pub fn leaf_mask(u: f32, v: f32) -> bool {
    let x = u * 2.0 - 1.0;
    let y = v * 2.0 - 1.0;
    x.abs() <= 0.8 * (1.0 - y * y)
}

/// The leaf-cluster mask: a 3x3 grid of leaves, each cell's leaf tilted by a fixed per-cell amount, with two
/// cells left empty so the card does not read as a square. Must match `leaf_cluster_mask` in the
/// shader (the mask of [`AUX_LEAF_CLUSTER`] cards).
pub fn leaf_cluster_mask(u: f32, v: f32) -> bool {
    let cu = (u * 3.0).floor().clamp(0.0, 2.0);
    let cv = (v * 3.0).floor().clamp(0.0, 2.0);
    let cell = cu + 3.0 * cv;
    if cell == 2.0 || cell == 6.0 {
        return false;
    }
    let fu = u * 3.0 - cu;
    let fv = v * 3.0 - cv;
    leaf_mask(fu, fv)
}

/// Per-LOD tree parameters: (sides, segments) per branch level (trunk, main, branch, twig; `None` = not
/// drawn), leaf cards per twig, the card kind and the card size relative to a LOD0 leaf.
#[derive(Debug, Clone, Copy)]
struct TreeParams {
    levels: [Option<(usize, usize)>; 4],
    cards_per_twig: usize,
    kind: f32,
    scale: f32,
}

const LEAVES_PER_TWIG: usize = 133;

const TREE_LODS: [TreeParams; 4] = [
    TreeParams {
        levels: [Some((20, 20)), Some((12, 12)), Some((8, 8)), Some((5, 4))],
        cards_per_twig: LEAVES_PER_TWIG,
        kind: AUX_LEAF,
        scale: 1.0,
    },
    TreeParams {
        levels: [Some((12, 10)), Some((8, 6)), Some((5, 4)), Some((3, 2))],
        cards_per_twig: 62,
        kind: AUX_LEAF,
        scale: 1.46,
    },
    TreeParams {
        levels: [Some((8, 6)), Some((6, 4)), Some((4, 3)), None],
        cards_per_twig: 24,
        kind: AUX_LEAF_CLUSTER,
        scale: 2.7,
    },
    TreeParams {
        levels: [Some((6, 4)), Some((4, 2)), Some((3, 1)), None],
        cards_per_twig: 8,
        kind: AUX_LEAF_CLUSTER,
        scale: 4.7,
    },
];

/// TREES: 4 LODs of 92,924 / 39,984 / 14,784 / 4,836 triangles (the same for every seed), [`TREE_HEIGHT`]
/// tall; `seed` picks the skeleton and the leaves.
pub fn tree_chain(seed: u64) -> Result<ModelChain> {
    let skeleton = TreeSkeleton::generate(seed);
    let meshes = TREE_LODS
        .iter()
        .enumerate()
        .map(|(k, p)| skeleton.mesh(&format!("tree{seed}/lod{k}"), p))
        .collect::<Result<Vec<_>>>()?;
    let errors = measure_errors(&meshes)?;
    Ok(ModelChain {
        chain: LodChain::from_meshes(&format!("tree{seed}"), meshes, &errors)?,
        lod_colors: vec![[0.16, 0.36, 0.08]; TREE_LODS.len()],
    })
}

// ---------------------------------------------------------------------------------------------------------
// Trees

struct Branch {
    level: usize,
    points: Vec<Vec3>,
    radii: Vec<f32>,
}

/// A leaf card: its stem point, width and length directions (unit, orthogonal) and length.
struct Leaf {
    base: Vec3,
    across: Vec3,
    along: Vec3,
    length: f32,
}

struct TreeSkeleton {
    branches: Vec<Branch>,
    /// `leaves[t]`: the leaves of twig t, in generation order (coarser LODs use the first ones).
    leaves: Vec<Vec<Leaf>>,
}

/// Finest segments per branch level; coarser LODs resample these polylines.
const FINE_SEGMENTS: [usize; 4] = [20, 12, 8, 4];
/// Children per branch of each level (main branches on the trunk, branches on mains, twigs on branches).
const CHILDREN: [usize; 3] = [9, 6, 5];

struct Rng(SplitMix64);

impl Rng {
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.0.next_f32()
    }

    fn unit(&mut self) -> Vec3 {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, TAU);
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    fn in_ball(&mut self) -> Vec3 {
        self.unit() * self.0.next_f32().cbrt()
    }
}

impl TreeSkeleton {
    fn generate(seed: u64) -> TreeSkeleton {
        let mut rng = Rng(SplitMix64::new(seed));
        let mut branches = vec![Self::trunk(&mut rng)];
        // Children, level by level.
        let mut parents = vec![0usize];
        for level in 1..4 {
            let mut next = Vec::new();
            for &pi in &parents {
                let count = CHILDREN[level - 1];
                let (ppoints, pradii) = (branches[pi].points.clone(), branches[pi].radii.clone());
                let plen: f32 = ppoints.windows(2).map(|w| w[0].distance(w[1])).sum();
                let azimuth0 = rng.range(0.0, TAU);
                for c in 0..count {
                    let (t_lo, t_hi) = match level {
                        1 => (0.38, 0.95),
                        2 => (0.25, 1.0),
                        _ => (0.3, 1.0),
                    };
                    let t = t_lo + (t_hi - t_lo) * (c as f32 + rng.range(0.2, 0.8)) / count as f32;
                    let (at, pdir, prad) = sample_polyline(&ppoints, &pradii, t);
                    let dir = if level == 1 {
                        // Golden-angle azimuths, rising more steeply higher up.
                        let az = azimuth0 + c as f32 * 2.399_963 + rng.range(-0.3, 0.3);
                        let elev = (25.0 + 30.0 * t + rng.range(-5.0, 5.0)).to_radians();
                        Vec3::new(az.cos() * elev.cos(), elev.sin(), az.sin() * elev.cos())
                    } else {
                        let side = pdir.any_orthonormal_vector();
                        let spin = Quat::from_axis_angle(pdir, rng.range(0.0, TAU));
                        let axis = spin * side;
                        let angle = rng.range(35.0, 60.0).to_radians();
                        (Quat::from_axis_angle(axis, angle) * pdir + Vec3::Y * 0.25)
                            .normalize_or(pdir)
                    };
                    let len = match level {
                        1 => 3.0 * (1.15 - 0.6 * t),
                        2 => 0.5 * plen * (1.0 - 0.4 * t),
                        _ => 0.5 * plen * (1.0 - 0.3 * t),
                    } * rng.range(0.85, 1.15);
                    let r0 = prad * 0.6;
                    let (points, radii) = grow(
                        &mut rng,
                        at,
                        dir,
                        len,
                        (r0, r0 * 0.35),
                        FINE_SEGMENTS[level],
                        0.08,
                    );
                    next.push(branches.len());
                    branches.push(Branch {
                        level,
                        points,
                        radii,
                    });
                }
            }
            parents = next;
        }
        // Leaves around every twig.
        let mut leaves = Vec::with_capacity(parents.len());
        for &ti in &parents {
            leaves.push(Self::twig_leaves(&mut rng, &branches[ti]));
        }
        let mut sk = TreeSkeleton { branches, leaves };
        sk.normalise_height();
        sk
    }

    /// The trunk: 5.6 units, leaning a little off the vertical.
    fn trunk(rng: &mut Rng) -> Branch {
        let trunk_len = 5.6;
        let lean = Vec3::new(rng.range(-0.04, 0.04), 1.0, rng.range(-0.04, 0.04));
        let trunk = grow(
            rng,
            Vec3::ZERO,
            lean.normalize_or(Vec3::Y),
            trunk_len,
            (0.28, 0.05),
            FINE_SEGMENTS[0],
            0.03,
        );
        Branch {
            level: 0,
            points: trunk.0,
            radii: trunk.1,
        }
    }

    /// [`LEAVES_PER_TWIG`] leaves scattered around twig `tw`, each at a random point along it and turned at
    /// random.
    fn twig_leaves(rng: &mut Rng, tw: &Branch) -> Vec<Leaf> {
        let len: f32 = tw.points.windows(2).map(|w| w[0].distance(w[1])).sum();
        let spread = 0.55 * len;
        let mut list = Vec::with_capacity(LEAVES_PER_TWIG);
        for _ in 0..LEAVES_PER_TWIG {
            let t = rng.range(0.15, 1.0);
            let (at, _, _) = sample_polyline(&tw.points, &tw.radii, t);
            let base = at + rng.in_ball() * spread;
            let along = rng.unit();
            let across = along.any_orthonormal_vector();
            let spin = Quat::from_axis_angle(along, rng.range(0.0, TAU));
            list.push(Leaf {
                base,
                across: spin * across,
                along,
                length: rng.range(0.13, 0.19),
            });
        }
        list
    }

    /// Scales everything about the origin so that LOD0's highest point is at [`TREE_HEIGHT`].
    fn normalise_height(&mut self) {
        let mut top = 0.0f32;
        for b in &self.branches {
            for (p, r) in b.points.iter().zip(&b.radii) {
                top = top.max(p.y + r);
            }
        }
        for l in self.leaves.iter().flatten() {
            for c in card_corners(l, 1.0, AUX_LEAF) {
                top = top.max(c.y);
            }
        }
        if !(top > 0.0 && top.is_finite()) {
            return;
        }
        let s = TREE_HEIGHT / top;
        for b in &mut self.branches {
            b.points.iter_mut().for_each(|p| *p *= s);
            b.radii.iter_mut().for_each(|r| *r *= s);
        }
        for l in self.leaves.iter_mut().flatten() {
            l.base *= s;
            l.length *= s;
        }
    }

    fn mesh(&self, name: &str, p: &TreeParams) -> Result<Mesh> {
        let mut b = Builder::default();
        let solid = AuxKind::new(AUX_SOLID, 0.0);
        for br in &self.branches {
            let Some((sides, segs)) = p.levels.get(br.level).copied().flatten() else {
                continue;
            };
            let (points, radii) = resample(&br.points, &br.radii, segs);
            // The trunk's bottom ring lies flat on the ground.
            let flat = br.level == 0;
            tube(&mut b, &points, &radii, sides, solid, Caps::None, flat)?;
        }
        for twig in &self.leaves {
            for leaf in twig.iter().take(p.cards_per_twig) {
                card(&mut b, leaf, p.scale, p.kind);
            }
        }
        b.finish(name)
    }
}

/// A gently bending polyline of `segs` segments from `start` along `dir`, radius tapering `r.0` -> `r.1`.
fn grow(
    rng: &mut Rng,
    start: Vec3,
    dir: Vec3,
    len: f32,
    r: (f32, f32),
    segs: usize,
    wobble: f32,
) -> (Vec<Vec3>, Vec<f32>) {
    let step = len / segs as f32;
    let mut p = start;
    let mut d = dir;
    let mut points = vec![p];
    let mut radii = vec![r.0];
    for i in 1..=segs {
        d = (d + rng.unit() * wobble + Vec3::Y * 0.02).normalize_or(d);
        p += d * step;
        points.push(p);
        radii.push(r.0 + (r.1 - r.0) * i as f32 / segs as f32);
    }
    (points, radii)
}

/// Point, direction and radius at arc-length fraction `t` along a polyline.
fn sample_polyline(points: &[Vec3], radii: &[f32], t: f32) -> (Vec3, Vec3, f32) {
    let total: f32 = points.windows(2).map(|w| w[0].distance(w[1])).sum();
    let mut left = t.clamp(0.0, 1.0) * total;
    for (i, w) in points.windows(2).enumerate() {
        let l = w[0].distance(w[1]);
        if left <= l || i + 2 == points.len() {
            let f = if l > 0.0 {
                (left / l).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let r0 = radii.get(i).copied().unwrap_or(0.0);
            let r1 = radii.get(i + 1).copied().unwrap_or(r0);
            return (
                w[0].lerp(w[1], f),
                (w[1] - w[0]).normalize_or(Vec3::Y),
                r0 + (r1 - r0) * f,
            );
        }
        left -= l;
    }
    let p = points.first().copied().unwrap_or(Vec3::ZERO);
    (p, Vec3::Y, radii.first().copied().unwrap_or(0.0))
}

/// `segs + 1` of the polyline's points (evenly by index, ends kept).
fn resample(points: &[Vec3], radii: &[f32], segs: usize) -> (Vec<Vec3>, Vec<f32>) {
    let n = points.len().min(radii.len());
    if n == 0 {
        return (Vec::new(), Vec::new());
    }
    (0..=segs)
        .map(|i| {
            let j = ((i * (n - 1)) as f32 / segs.max(1) as f32).round() as usize;
            let j = j.min(n - 1);
            (points[j], radii[j])
        })
        .unzip()
}

/// Card corners in (u, v) order (0,0), (1,0), (1,1), (0,1). Single leaves are 0.6:1 cards with the stem at
/// v = 0, `scale` leaf lengths long; cluster cards are squares of side `scale` leaf lengths centred on the
/// leaf's middle.
fn card_corners(l: &Leaf, scale: f32, kind: f32) -> [Vec3; 4] {
    let (w, h, start) = if kind == AUX_LEAF_CLUSTER {
        let side = l.length * scale;
        (side, side, l.base + l.along * (0.5 * l.length - 0.5 * side))
    } else {
        let h = l.length * scale;
        (0.6 * h, h, l.base)
    };
    let a = l.across * (0.5 * w);
    let b = l.along * h;
    [start - a, start + a, start + a + b, start - a + b]
}

fn card(b: &mut Builder, l: &Leaf, scale: f32, kind: f32) {
    let c = card_corners(l, scale, kind);
    let n = l.across.cross(l.along).normalize_or(Vec3::Z);
    let uv = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    let ids: Vec<u32> = c
        .iter()
        .zip(uv)
        .map(|(p, [u, v])| b.vertex(*p, Some(n), [u, v, kind, 0.0]))
        .collect();
    b.quad(ids[0], ids[1], ids[2], ids[3]);
}
