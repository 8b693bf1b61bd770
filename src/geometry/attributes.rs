//! Per-vertex data a mesh carries besides its positions and normals: texture coordinates, tangents and colours
//! (what a user scene's materials sample, `shaders/surface_pbr.wgsl`), and what deforms it: skin influences and morph
//! targets. Every simplified vertex is an original vertex, so each LOD gathers all of it by index
//! ([`VertexData::gather`]) and indexes the same joints and targets.

/// Skin influences: `per_vertex` (4 per glTF JOINTS_n/WEIGHTS_n set: 4, 8, 12, ...) joint indices and weights
/// per vertex, into the skin's joint list.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SkinInfluences {
    pub per_vertex: usize,
    pub joints: Vec<u16>,
    pub weights: Vec<f32>,
}

impl SkinInfluences {
    /// Vertex `v`'s influences as (joint, weight) pairs, zero weights included.
    pub fn of(&self, v: usize) -> impl Iterator<Item = (u16, f32)> + '_ {
        let at = v * self.per_vertex;
        self.joints[at..at + self.per_vertex]
            .iter()
            .copied()
            .zip(self.weights[at..at + self.per_vertex].iter().copied())
    }

    pub fn vertex_count(&self) -> usize {
        self.joints.len() / self.per_vertex.max(1)
    }
}

/// One morph target: displacements of positions (and normals, when the file has them) at weight 1.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MorphTarget {
    pub positions: Vec<[f32; 3]>,
    pub normals: Option<Vec<[f32; 3]>>,
}

/// What deforms a mesh per frame, in the mesh's own space: the undeformed (bind-pose, no morph) positions and
/// normals, the skin influences and the morph targets.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Deformable {
    pub base_positions: Vec<[f32; 3]>,
    pub base_normals: Vec<[f32; 3]>,
    /// The undeformed tangents, when the mesh has them (turned with the skin; morph targets do not move them).
    pub base_tangents: Option<Vec<[f32; 4]>>,
    pub skin: Option<SkinInfluences>,
    pub targets: Vec<MorphTarget>,
}

/// The optional per-vertex channels of a mesh (one entry per vertex where present).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct VertexData {
    /// TEXCOORD_0.
    pub uv0: Option<Vec<[f32; 2]>>,
    /// TEXCOORD_1.
    pub uv1: Option<Vec<[f32; 2]>>,
    /// TANGENT: xyz, and w the bitangent's sign.
    pub tangents: Option<Vec<[f32; 4]>>,
    /// COLOR_0, linear RGBA.
    pub colors: Option<Vec<[f32; 4]>>,
    /// Present when the mesh is skinned or has morph targets.
    pub deform: Option<Box<Deformable>>,
}

fn gather<T: Copy>(v: &[T], order: &[u32]) -> Vec<T> {
    order.iter().map(|&i| v[i as usize]).collect()
}

impl VertexData {
    /// The data of the vertices `order` names, in that order.
    pub fn gather(&self, order: &[u32]) -> VertexData {
        VertexData {
            uv0: self.uv0.as_deref().map(|v| gather(v, order)),
            uv1: self.uv1.as_deref().map(|v| gather(v, order)),
            tangents: self.tangents.as_deref().map(|v| gather(v, order)),
            colors: self.colors.as_deref().map(|v| gather(v, order)),
            deform: self.deform.as_ref().map(|d| {
                Box::new(Deformable {
                    base_positions: gather(&d.base_positions, order),
                    base_normals: gather(&d.base_normals, order),
                    base_tangents: d.base_tangents.as_deref().map(|t| gather(t, order)),
                    skin: d.skin.as_ref().map(|s| {
                        let n = s.per_vertex;
                        let mut joints = Vec::with_capacity(order.len() * n);
                        let mut weights = Vec::with_capacity(order.len() * n);
                        for &i in order {
                            let at = i as usize * n;
                            joints.extend_from_slice(&s.joints[at..at + n]);
                            weights.extend_from_slice(&s.weights[at..at + n]);
                        }
                        SkinInfluences {
                            per_vertex: n,
                            joints,
                            weights,
                        }
                    }),
                    targets: d
                        .targets
                        .iter()
                        .map(|t| MorphTarget {
                            positions: gather(&t.positions, order),
                            normals: t.normals.as_deref().map(|n| gather(n, order)),
                        })
                        .collect(),
                })
            }),
        }
    }

    /// A problem text when a channel has not `n` entries or holds a non-finite value.
    pub fn check(&self, n: usize) -> Result<(), String> {
        fn each<const K: usize>(
            name: &str,
            v: &Option<Vec<[f32; K]>>,
            n: usize,
        ) -> Result<(), String> {
            let Some(v) = v else { return Ok(()) };
            if v.len() != n {
                return Err(format!("{} {name} for {n} vertices", v.len()));
            }
            if v.iter().flatten().any(|c| !c.is_finite()) {
                return Err(format!("has a non-finite {name} value"));
            }
            Ok(())
        }
        each("texture coordinates", &self.uv0, n)?;
        each("second texture coordinates", &self.uv1, n)?;
        each("tangents", &self.tangents, n)?;
        each("colours", &self.colors, n)?;
        let Some(d) = &self.deform else { return Ok(()) };
        each("bind-pose positions", &Some(d.base_positions.clone()), n)?;
        each("bind-pose normals", &Some(d.base_normals.clone()), n)?;
        each("bind-pose tangents", &d.base_tangents, n)?;
        if let Some(s) = &d.skin {
            if s.per_vertex == 0
                || s.joints.len() != n * s.per_vertex
                || s.weights.len() != n * s.per_vertex
            {
                return Err(format!("skin influences do not cover its {n} vertices"));
            }
            if s.weights.iter().any(|w| !w.is_finite()) {
                return Err("has a non-finite skin weight".into());
            }
        }
        for (k, t) in d.targets.iter().enumerate() {
            each(
                &format!("morph target {k} displacements"),
                &Some(t.positions.clone()),
                n,
            )?;
            each(
                &format!("morph target {k} normal displacements"),
                &t.normals,
                n,
            )?;
        }
        Ok(())
    }
}

/// Area-weighted vertex normals; a vertex with no non-degenerate face gets +Y.
pub fn vertex_normals(positions: &[[f32; 3]], indices: &[u32]) -> Vec<[f32; 3]> {
    let mut acc = vec![glam::Vec3::ZERO; positions.len()];
    for t in indices.chunks_exact(3) {
        let (a, b, c) = (t[0] as usize, t[1] as usize, t[2] as usize);
        let (pa, pb, pc) = (
            glam::Vec3::from(positions[a]),
            glam::Vec3::from(positions[b]),
            glam::Vec3::from(positions[c]),
        );
        let n = (pb - pa).cross(pc - pa); // length = 2 * area
        acc[a] += n;
        acc[b] += n;
        acc[c] += n;
    }
    acc.into_iter()
        .map(|n| n.try_normalize().unwrap_or(glam::Vec3::Y).to_array())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn data() -> VertexData {
        VertexData {
            uv0: Some(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
            uv1: None,
            tangents: None,
            colors: Some(vec![[1.0; 4], [0.5; 4], [0.25; 4]]),
            deform: Some(Box::new(Deformable {
                base_positions: vec![[0.0; 3], [1.0; 3], [2.0; 3]],
                base_normals: vec![[0.0, 1.0, 0.0]; 3],
                base_tangents: None,
                skin: Some(SkinInfluences {
                    per_vertex: 4,
                    joints: vec![0, 1, 0, 0, 1, 0, 0, 0, 2, 1, 0, 0],
                    weights: vec![0.5, 0.5, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.25, 0.75, 0.0, 0.0],
                }),
                targets: vec![MorphTarget {
                    positions: vec![[0.1; 3], [0.2; 3], [0.3; 3]],
                    normals: None,
                }],
            })),
        }
    }

    /// A vertex keeps every channel it had: gathering vertices 2 and 0 gives their entries, skin included.
    #[test]
    fn gather_keeps_each_vertex_whole() {
        let g = data().gather(&[2, 0]);
        assert_eq!(g.uv0, Some(vec![[0.0, 1.0], [0.0, 0.0]]));
        assert_eq!(g.colors, Some(vec![[0.25; 4], [1.0; 4]]));
        let d = g.deform.unwrap();
        assert_eq!(d.base_positions, vec![[2.0; 3], [0.0; 3]]);
        let s = d.skin.unwrap();
        assert_eq!(s.of(0).collect::<Vec<_>>()[..2], [(2, 0.25), (1, 0.75)]);
        assert_eq!(s.of(1).collect::<Vec<_>>()[..2], [(0, 0.5), (1, 0.5)]);
        assert_eq!(d.targets[0].positions, vec![[0.3; 3], [0.1; 3]]);
        assert!(g.tangents.is_none());
        assert!(data().check(3).is_ok());
        let e = data().check(4).unwrap_err();
        assert!(e.contains("3 texture coordinates for 4 vertices"), "{e}");
    }
}
