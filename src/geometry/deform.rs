//! Deforming a mesh on the CPU: its morph targets at given weights, then its skin at given joint matrices, the
//! order glTF 2.0 gives (section 3.7.2.2: "morph targets ... then skinning"). lodbench deforms each frame's
//! vertices here and uploads them (`gpu/scene_gpu/pose.rs`), so that every method draws the same deformed geometry
//! through its own pipelines unchanged.

use crate::geometry::attributes::Deformable;
use glam::{Mat3, Mat4, Vec3};

/// How a deformed mesh's vertices reach the model's space.
#[derive(Debug, Clone, Copy)]
pub enum Placing<'a> {
    /// Skinned: one matrix per joint of the skin (the model's space from the joint's bind space: the model's frame
    /// x the joint's world matrix x its inverse bind matrix).
    Skin(&'a [Mat4]),
    /// Not skinned: one matrix for every vertex (mesh to model space).
    Rigid(Mat4),
}

/// The normal matrix of `m`'s linear part up to a positive factor: its cofactor matrix (det(A) A^-T), made to
/// keep the normal's side where `m` mirrors. Normals are normalised after it, so the factor does not matter.
fn normal_matrix(m: Mat3) -> Mat3 {
    let [c0, c1, c2] = [m.x_axis, m.y_axis, m.z_axis];
    let cof = Mat3::from_cols(c1.cross(c2), c2.cross(c0), c0.cross(c1));
    if m.determinant() < 0.0 {
        -cof
    } else {
        cof
    }
}

/// Writes the deformed positions and normals of `d`'s vertices into `positions` and `normals` (as long as its
/// vertex count): morph targets at `weights` (missing weights are 0), then `placing`. A normal the transform
/// makes zero keeps its undeformed direction.
pub fn deform(
    d: &Deformable,
    weights: &[f32],
    placing: Placing<'_>,
    positions: &mut [[f32; 3]],
    normals: &mut [[f32; 3]],
) {
    deform_with_tangents(d, weights, placing, positions, normals, None);
}

/// [`deform`], and the tangents turned by the same matrices into `tangents` when `d` has them (their
/// handedness flipped where a matrix mirrors).
pub fn deform_with_tangents(
    d: &Deformable,
    weights: &[f32],
    placing: Placing<'_>,
    positions: &mut [[f32; 3]],
    normals: &mut [[f32; 3]],
    mut tangents: Option<&mut [[f32; 4]]>,
) {
    let active: Vec<(usize, f32)> = weights
        .iter()
        .copied()
        .enumerate()
        .filter(|&(k, w)| w != 0.0 && k < d.targets.len())
        .collect();
    let rigid = match placing {
        Placing::Rigid(m) => Some((m, normal_matrix(Mat3::from_mat4(m)))),
        Placing::Skin(_) => None,
    };
    for v in 0..d.base_positions.len() {
        let mut p = Vec3::from(d.base_positions[v]);
        let mut n = Vec3::from(d.base_normals[v]);
        for &(k, w) in &active {
            let t = &d.targets[k];
            p += Vec3::from(t.positions[v]) * w;
            if let Some(tn) = &t.normals {
                n += Vec3::from(tn[v]) * w;
            }
        }
        let (m, nm) = match (rigid, placing, &d.skin) {
            (Some(r), _, _) => r,
            (None, Placing::Skin(joints), Some(skin)) => {
                let mut m = Mat4::ZERO;
                for (j, w) in skin.of(v) {
                    if w != 0.0 {
                        if let Some(jm) = joints.get(j as usize) {
                            m += *jm * w;
                        }
                    }
                }
                (m, normal_matrix(Mat3::from_mat4(m)))
            }
            _ => (Mat4::IDENTITY, Mat3::IDENTITY),
        };
        positions[v] = m.transform_point3(p).to_array();
        normals[v] = (nm * n).try_normalize().unwrap_or(n).to_array();
        if let (Some(out), Some(base)) = (tangents.as_deref_mut(), &d.base_tangents) {
            let [x, y, z, w] = base[v];
            let t = Vec3::new(x, y, z);
            let linear = Mat3::from_mat4(m);
            let turned = (linear * t).try_normalize().unwrap_or(t);
            let sign = if linear.determinant() < 0.0 { -w } else { w };
            out[v] = [turned.x, turned.y, turned.z, sign];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::attributes::{MorphTarget, SkinInfluences};

    fn two_vertices() -> Deformable {
        Deformable {
            base_positions: vec![[1.0, 0.0, 0.0], [0.0, 2.0, 0.0]],
            base_normals: vec![[0.0, 1.0, 0.0], [1.0, 0.0, 0.0]],
            base_tangents: Some(vec![[1.0, 0.0, 0.0, 1.0], [1.0, 0.0, 0.0, 1.0]]),
            skin: Some(SkinInfluences {
                per_vertex: 4,
                joints: vec![0, 1, 0, 0, 1, 0, 0, 0],
                weights: vec![0.5, 0.5, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
            }),
            targets: vec![MorphTarget {
                positions: vec![[0.0, 0.0, 1.0], [0.0, 0.0, 0.0]],
                normals: None,
            }],
        }
    }

    /// Morph first (vertex 0 moves +z by the weight), then the blend of the joint matrices: vertex 0 half at
    /// joint 0 (identity), half at joint 1 (a translation by (0, 0, 4)); vertex 1 all at joint 1, a rotation of
    /// 90 degrees about z taking its normal +x to +y.
    #[test]
    fn morph_then_skin() {
        let d = two_vertices();
        let joints = [
            Mat4::IDENTITY,
            Mat4::from_translation(Vec3::new(0.0, 0.0, 4.0)),
        ];
        let (mut p, mut n) = (vec![[0.0; 3]; 2], vec![[0.0; 3]; 2]);
        deform(&d, &[0.5], Placing::Skin(&joints), &mut p, &mut n);
        assert_eq!(p[0], [1.0, 0.0, 2.5]);
        assert_eq!(p[1], [0.0, 2.0, 4.0]);
        let rot = [
            Mat4::IDENTITY,
            Mat4::from_rotation_z(std::f32::consts::FRAC_PI_2),
        ];
        let mut t = vec![[0.0; 4]; 2];
        deform_with_tangents(&d, &[], Placing::Skin(&rot), &mut p, &mut n, Some(&mut t));
        assert!(Vec3::from(p[1]).abs_diff_eq(Vec3::new(-2.0, 0.0, 0.0), 1e-6));
        assert!(Vec3::from(n[1]).abs_diff_eq(Vec3::Y, 1e-6));
        // The tangent turns with the joint: +x to +y, its sign kept.
        assert!(Vec3::from_slice(&t[1][..3]).abs_diff_eq(Vec3::Y, 1e-6));
        assert_eq!(t[1][3], 1.0);
    }

    /// A rigid placing applies one matrix; normals follow the inverse transpose, and a mirror keeps a normal on
    /// the mirrored surface's outside.
    #[test]
    fn rigid_placing_transforms_normals_by_the_inverse_transpose() {
        let d = Deformable {
            skin: None,
            ..two_vertices()
        };
        let (mut p, mut n) = (vec![[0.0; 3]; 2], vec![[0.0; 3]; 2]);
        let shear_free = Mat4::from_scale(Vec3::new(2.0, 1.0, 1.0));
        deform(&d, &[1.0], Placing::Rigid(shear_free), &mut p, &mut n);
        assert_eq!(p[0], [2.0, 0.0, 1.0]);
        assert_eq!(n[1], [1.0, 0.0, 0.0]);
        let mirror = Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0));
        deform(&d, &[], Placing::Rigid(mirror), &mut p, &mut n);
        assert_eq!(p[0], [-1.0, 0.0, 0.0]);
        assert_eq!(n[1], [-1.0, 0.0, 0.0]);
    }
}
