//! Procedural stand-ins for the three test scenes of Scherzer & Wimmer (2008, "Frame Sequential
//! Interpolation"), section 4: SIMPLE (a red sphere and a blue box), WINDMILLS ("LODs ranging from 100 -
//! 18,000 triangles") and TREES ("LODs ranging from 5,000 - 93,000 triangles"). The paper's models are not
//! published, so they are generated here, on the CPU, deterministically (trees from a seed, with the in-house
//! [`SplitMix64`]).
//!
//! Every chain is "artist-style": each LOD is generated again from coarser generation parameters (fewer
//! segments, sides, branches, leaves; billboard-cloud cards instead of leaves), never by simplifying LOD0.
//! The chain goes through [`LodChain::from_meshes`] with a *measured* `error_abs` per LOD (0 for LOD0): a
//! sampled symmetric Hausdorff distance, the larger of
//! - the largest distance from a deterministic sample of LOD0's vertices (every k-th vertex, at most
//!   [`ERROR_SAMPLES`]) to the closest point on LOD k's surface ([`crate::geometry::morph::closest_surface`]), and
//! - the same from LOD k's vertices to LOD0's surface ([`measure_error`] gives either direction).
//!
//! The second direction matters for foliage: LOD0's leaves lie within about 0.15-0.2 of *any* coarser
//! LOD's cards, so the first direction alone is nearly the same for LOD1, 2 and 3 of a tree (0.144, 0.142,
//! 0.151 for seed 1) and would give them the same switch distance; the ever larger billboard-cloud cards
//! stick out of LOD0's foliage by 0.03 / 0.27 / 0.54. For the windmill and the sphere the first direction
//! decides (a coarse LOD's vertices lie on or near LOD0's surface), except SIMPLE's box corners (0.39).
//!
//! Object space: y up, the model's base (ground contact) at y = 0, centred on x = z = 0. Per-vertex `aux` is
//! `[u, v, kind, hub_y]` (kinds in [`crate::geometry::mesh`]); `hub_y` is only set on [`AUX_BLADE`] vertices (0
//! elsewhere).
//!
//! ## Colours: `lod_colors`
//!
//! Colour is per instance in the renderer, so [`ModelChain::lod_colors`] holds one linear-RGB base colour per
//! LOD: an instance drawn at LOD k takes `lod_colors[k]`. SIMPLE's two LODs differ in colour (Scherzer & Wimmer 2008: the
//! objects "match neither in color nor in silhouettes"): LOD0 red, LOD1 blue. WINDMILLS and TREES use one
//! colour for every LOD.
//!
//! ## SIMPLE ([`simple_chain`]), 2 LODs, centre (0, 1, 0)
//!
//! | LOD | shape | parameters | triangles | colour |
//! |-----|-------|------------|-----------|--------|
//! | 0 | UV sphere, smooth normals | radius 1, 32 slices x 24 stacks | 1,472 | red |
//! | 1 | box, flat normals (4 vertices per face) | side 1.6 | 12 | blue |
//!
//! Bounds: LOD0 y in [0, 2], x, z in [-1, 1]; LOD1 y in [0.2, 1.8], x, z in [-0.8, 0.8].
//!
//! ## WINDMILLS ([`windmill_chain`]), 4 LODs
//!
//! A tapered tower (frustum, y 0..6.9, radius 0.35 -> 0.18, top cap), a nacelle (a capsule-like lathe along
//! z, z -0.9..0.6, radius 0.3, axis at y = [`WINDMILL_HUB_Y`] = 7), a pointed spinner (z 0.6..1.1) and four
//! twisted blades (NACA-00xx-like lofted sections, chord 0.25 -> 0.5 -> 0.12, thickness 24 % -> 12 %, twist
//! 20 deg -> 2 deg, span to radius [`WINDMILL_ROTOR_RADIUS`] = 3) in the plane z = [`WINDMILL_BLADE_Z`] = 0.8,
//! in front of the nacelle. Spinner and blades are [`AUX_BLADE`] with hub_y = 7: the rotor turns about the
//! axis parallel to +z through (0, 7). The tower and nacelle are [`AUX_SOLID`]. Bounds: y in [0, 10],
//! x in [-3, 3], z in about [-0.9, 1.1].
//!
//! | LOD | tower sides x rings | nacelle sides x rings | spinner sides x rings | blade section points x sections | triangles |
//! |-----|------|------|------|------|--------|
//! | 0 | 64 x 41 | 32 x 20 | 32 x 10 | 32 x 43 | 18,086 |
//! | 1 | 32 x 17 | 16 x 10 | 16 x 6 | 16 x 23 | 4,486 |
//! | 2 | 12 x 6 | 8 x 5 | 8 x 3 | 8 x 12 | 1,002 |
//! | 3 | 8 x 2 | 4 x 3 | 3 x 2 | 4 x 2 | 98 |
//!
//! ## TREES ([`tree_chain`]), 4 LODs
//!
//! One seeded skeleton per seed: a trunk, 9 main branches, 6 branches on each, 5 twigs on each of those
//! (334 generalised cylinders, parallel-transport frames), and 133 leaves around each twig (35,910 leaves,
//! random position within the twig's puff, random orientation, so cards intersect each other and the
//! branches). The skeleton is scaled so that LOD0 is exactly [`TREE_HEIGHT`] = 8 tall (coarser LODs' larger
//! cards reach up to about 8.4); the crown is about 5-6 units across (x, z within +-[`TREE_MAX_HALF_WIDTH`]
//! = 4); the trunk's bottom ring lies flat at y = 0. Each LOD draws the same skeleton with coarser
//! parameters; cards are [`AUX_LEAF`] (single leaf, 0.6:1 card) or [`AUX_LEAF_CLUSTER`] (a square card with a
//! 3x3 leaf cluster, billboard cloud) with uv over [0, 1]^2, 2 triangles each. Coarser cards sit where the
//! first leaves of each twig were, larger, so cards of different LODs intersect.
//!
//! | LOD | trunk / main / branch / twig (sides x segments) | cards per twig | card kind, length (LOD0 leaf = 1) | triangles |
//! |-----|------|------|------|--------|
//! | 0 | 20x20 / 12x12 / 8x8 / 5x4 | 133 | leaf, 1x | 92,924 |
//! | 1 | 12x10 / 8x6 / 5x4 / 3x2 | 62 | leaf, 1.46x | 39,984 |
//! | 2 | 8x6 / 6x4 / 4x3 / - | 24 | cluster, 2.7x | 14,784 |
//! | 3 | 6x4 / 4x2 / 3x1 / - | 8 | cluster, 4.7x | 4,836 |
//!
//! Cluster cards are squares of that side; single-leaf cards are 0.6 as wide as long.
//!
//! Build time (release, including the error measurement): the caller times it; `lodbench describe` prints it
//! as `lod_generation_ms`.

mod mesh_builder;
mod model_chain;
mod simple;
mod tree;
mod windmill;

pub use model_chain::{measure_error, ModelChain, ERROR_SAMPLES};
pub use simple::simple_chain;
pub use tree::{leaf_cluster_mask, leaf_mask, tree_chain, TREE_HEIGHT, TREE_MAX_HALF_WIDTH};
pub use windmill::{windmill_chain, WINDMILL_BLADE_Z, WINDMILL_HUB_Y, WINDMILL_ROTOR_RADIUS};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::mesh::{AUX_BLADE, AUX_LEAF, AUX_LEAF_CLUSTER, AUX_SOLID};
    use glam::Vec3;

    fn tris(m: &ModelChain) -> Vec<usize> {
        m.chain
            .lods
            .iter()
            .map(|l| l.mesh.triangle_count())
            .collect()
    }

    fn within(got: usize, want: usize, tol: f32) -> bool {
        (got as f32 - want as f32).abs() <= want as f32 * tol
    }

    fn check_common(m: &ModelChain) {
        assert_eq!(m.lod_colors.len(), m.chain.lods.len());
        for w in m.chain.lods.windows(2) {
            assert!(w[1].mesh.triangle_count() < w[0].mesh.triangle_count());
        }
        assert_eq!(m.chain.lods[0].error_abs, 0.0);
        for (k, lod) in m.chain.lods.iter().enumerate() {
            if k > 0 {
                assert!(
                    lod.error_abs.is_finite() && lod.error_abs > 0.0,
                    "LOD{k}: {}",
                    lod.error_abs
                );
            }
            for n in &lod.mesh.normals {
                let n = Vec3::from(*n);
                assert!(n.is_finite() && (n.length() - 1.0).abs() < 1e-3, "{n}");
            }
            let (lo, _) = lod.mesh.bounds();
            assert!(lo.y > -1e-4, "LOD{k} reaches below the ground: {lo}");
            // Winding agrees with the normals (outward faces): every face within 120 degrees of its smoothed
            // vertex normals (sharp, twisted blade trailing edges at low LODs smooth over a wide angle), 99 %
            // within 90 degrees.
            let mesh = &lod.mesh;
            let mut agree = 0;
            for t in mesh.indices.chunks_exact(3) {
                let p = [0, 1, 2].map(|k| Vec3::from(mesh.positions[t[k] as usize]));
                let face = (p[1] - p[0]).cross(p[2] - p[0]);
                if face.length() < 1e-9 {
                    continue;
                }
                let n: Vec3 = t
                    .iter()
                    .map(|&i| Vec3::from(mesh.normals[i as usize]))
                    .sum();
                let cos = face.normalize().dot(n.normalize_or_zero());
                assert!(cos > -0.5, "LOD{k}: triangle {t:?} faces inward ({cos})");
                agree += usize::from(cos > 0.0);
            }
            assert!(agree * 100 >= mesh.triangle_count() * 99, "LOD{k}: {agree}");
        }
    }

    #[test]
    fn simple_is_a_red_sphere_and_a_blue_box() {
        let m = simple_chain().unwrap();
        check_common(&m);
        assert_eq!(tris(&m), vec![1472, 12]);
        let (s, c) = (&m.chain.lods[0].mesh, &m.chain.lods[1].mesh);
        for p in &s.positions {
            assert!((Vec3::from(*p).distance(Vec3::Y) - 1.0).abs() < 1e-5);
        }
        let (lo, hi) = s.bounds();
        assert!((lo - Vec3::new(-1.0, 0.0, -1.0)).abs().max_element() < 1e-5);
        assert!((hi - Vec3::new(1.0, 2.0, 1.0)).abs().max_element() < 1e-5);
        let (lo, hi) = c.bounds();
        assert!((lo - Vec3::new(-0.8, 0.2, -0.8)).abs().max_element() < 1e-5);
        assert!((hi - Vec3::new(0.8, 1.8, 0.8)).abs().max_element() < 1e-5);
        // Flat shading: each triangle's vertices share its face normal.
        for t in c.indices.chunks_exact(3) {
            let p = [0, 1, 2].map(|k| Vec3::from(c.positions[t[k] as usize]));
            let face = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
            for &i in t {
                assert!(Vec3::from(c.normals[i as usize]).dot(face) > 0.9999);
            }
        }
        let [r0, g0, b0] = m.color(0);
        let [r1, g1, b1] = m.color(1);
        assert!(r0 > 0.5 && g0 < 0.2 && b0 < 0.2, "LOD0 red");
        assert!(b1 > 0.5 && r1 < 0.2 && g1 < 0.2, "LOD1 blue");
        // Sphere vs box: the box corners stick out of the (tessellated) sphere by about 0.8 sqrt(3) - 1.
        let e = m.chain.lods[1].error_abs;
        assert!((e - (0.8 * 3f32.sqrt() - 1.0)).abs() < 0.005, "{e}");
        // The sphere's vertices are at most 0.2 inside or outside the box.
        let forward = measure_error(s, c, ERROR_SAMPLES).unwrap();
        assert!((forward - 0.2).abs() < 0.03, "{forward}");
    }

    #[test]
    fn windmill_counts_aux_and_bounds() {
        let m = windmill_chain().unwrap();
        check_common(&m);
        let want = [18000, 4500, 1000, 100];
        let got = tris(&m);
        for (g, w) in got.iter().zip(want) {
            assert!(within(*g, w, 0.15), "{got:?}");
        }
        for (k, lod) in m.chain.lods.iter().enumerate() {
            let mesh = &lod.mesh;
            let (lo, hi) = mesh.bounds();
            assert!(
                lo.y.abs() < 1e-4 && (hi.y - 10.0).abs() < 0.05,
                "LOD{k}: {lo} {hi}"
            );
            assert!(
                lo.x > -3.1 && hi.x < 3.1 && lo.z > -1.0 && hi.z < 1.2,
                "{lo} {hi}"
            );
            let mut blades = 0;
            for (p, a) in mesh.positions.iter().zip(&mesh.aux) {
                let p = Vec3::from(*p);
                if a[2] == AUX_BLADE {
                    blades += 1;
                    assert_eq!(a[3], WINDMILL_HUB_Y);
                    let r = (p - Vec3::new(0.0, WINDMILL_HUB_Y, p.z)).length();
                    assert!(r <= WINDMILL_ROTOR_RADIUS + 0.01, "{p}");
                    assert!(p.z > 0.55, "rotor part behind the nacelle front: {p}");
                } else {
                    assert_eq!(a[2], AUX_SOLID);
                    assert_eq!(a[3], 0.0);
                }
            }
            // Blade tips reach the rotor radius; the rotor is a good share of the vertices.
            assert!(blades > mesh.vertex_count() / 4, "LOD{k}: {blades}");
            assert!(mesh.positions.iter().any(|p| (p[1] - 10.0).abs() < 0.05));
        }
    }

    #[test]
    fn tree_counts_aux_and_bounds() {
        let m = tree_chain(1).unwrap();
        check_common(&m);
        let want = [93000, 40000, 15000, 5000];
        let got = tris(&m);
        for (g, w) in got.iter().zip(want) {
            assert!(within(*g, w, 0.15), "{got:?}");
        }
        let kinds = [AUX_LEAF, AUX_LEAF, AUX_LEAF_CLUSTER, AUX_LEAF_CLUSTER];
        for (k, lod) in m.chain.lods.iter().enumerate() {
            let mesh = &lod.mesh;
            let mut cards = 0;
            for a in &mesh.aux {
                assert!(a[2] == AUX_SOLID || a[2] == kinds[k], "LOD{k}: {a:?}");
                if a[2] == kinds[k] {
                    cards += 1;
                    assert!((0.0..=1.0).contains(&a[0]) && (0.0..=1.0).contains(&a[1]));
                }
            }
            assert_eq!(cards % 4, 0);
            assert!(cards / 4 * 2 > mesh.triangle_count() / 2, "LOD{k}");
            let (lo, hi) = mesh.bounds();
            assert!(lo.y.abs() < 1e-4, "LOD{k}: {lo}");
            if k == 0 {
                assert!((hi.y - TREE_HEIGHT).abs() < 1e-3, "{hi}");
            } else {
                assert!(
                    hi.y > TREE_HEIGHT - 1.0 && hi.y < TREE_HEIGHT + 1.0,
                    "LOD{k}: {hi}"
                );
            }
            let w = lo.abs().max(hi.abs());
            assert!(
                w.x < TREE_MAX_HALF_WIDTH && w.z < TREE_MAX_HALF_WIDTH,
                "LOD{k}: {lo} {hi}"
            );
            assert!(w.x > 1.5 && w.z > 1.5, "crown too narrow: {lo} {hi}");
        }
    }

    #[test]
    fn trees_are_deterministic_per_seed() {
        let a = tree_chain(7).unwrap();
        let b = tree_chain(7).unwrap();
        let c = tree_chain(8).unwrap();
        for (x, y) in a.chain.lods.iter().zip(&b.chain.lods) {
            assert_eq!(x.mesh, y.mesh);
            assert_eq!(x.error_abs, y.error_abs);
        }
        assert_ne!(
            a.chain.lods[0].mesh.positions,
            c.chain.lods[0].mesh.positions
        );
        assert_eq!(tris(&a), tris(&c), "counts do not depend on the seed");
        // Coarser tree LODs deviate more; other seeds keep the documented bounds.
        for m in [&a, &c] {
            for l in &m.chain.lods {
                let (lo, hi) = l.mesh.bounds();
                assert!(lo.y.abs() < 1e-4 && hi.y > 7.9 && hi.y < 9.0, "{lo} {hi}");
                let w = lo.abs().max(hi.abs());
                assert!(
                    w.x < TREE_MAX_HALF_WIDTH && w.z < TREE_MAX_HALF_WIDTH,
                    "{lo} {hi}"
                );
            }
            for w in m.chain.lods.windows(2) {
                assert!(w[1].error_abs > w[0].error_abs);
            }
        }
    }

    #[test]
    fn error_of_a_mesh_against_itself_is_zero() {
        let m = simple_chain().unwrap();
        let s = &m.chain.lods[0].mesh;
        assert!(measure_error(s, s, 100).unwrap() < 1e-5);
        assert!(measure_error(s, s, 0).unwrap() < 1e-5);
    }

    #[test]
    fn leaf_masks_cut_a_pointed_leaf_and_leave_two_cluster_cells_empty() {
        assert!(leaf_mask(0.5, 0.5), "the leaf's centre");
        assert!(
            !leaf_mask(0.95, 0.9) && !leaf_mask(0.05, 0.1),
            "the card's corners"
        );
        let centre = |cell: u32| {
            (
                (cell % 3) as f32 / 3.0 + 1.0 / 6.0,
                (cell / 3) as f32 / 3.0 + 1.0 / 6.0,
            )
        };
        for cell in 0..9 {
            let (u, v) = centre(cell);
            assert_eq!(
                leaf_cluster_mask(u, v),
                cell != 2 && cell != 6,
                "cell {cell}"
            );
        }
    }
}
