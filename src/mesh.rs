//! Validated triangle meshes and OBJ loading (tobj).

use crate::error::{Error, Result};
use glam::Vec3;
use std::path::Path;

/// An indexed triangle mesh with per-vertex normals. Construct it with [`Mesh::new`] (or the loaders), which
/// checks what the GPU and the LOD generator rely on: indices in range, finite coordinates, whole triangles,
/// at least one triangle.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub indices: Vec<u32>,
    /// Per-vertex shading extras, one per vertex (zeros unless set with [`Mesh::with_aux`]):
    /// `[u, v, kind, hub_y]`. kind ([`AUX_SOLID`], [`AUX_LEAF`], [`AUX_LEAF_CLUSTER`], [`AUX_BLADE`]) selects the
    /// alpha-test mask over (u, v) or the blade rotation about the object-space axis parallel to +z through
    /// (0, hub_y, z); see shaders/mesh.wgsl.
    pub aux: Vec<[f32; 4]>,
}

/// `aux` kinds (the shader reads them as floats).
pub const AUX_SOLID: f32 = 0.0;
/// An alpha-tested card showing one leaf (mask: [`leaf_mask`] at (u, v)).
pub const AUX_LEAF: f32 = 1.0;
/// An alpha-tested card showing a cluster of leaves (mask: [`leaf_cluster_mask`]), for billboard clouds.
pub const AUX_LEAF_CLUSTER: f32 = 2.0;
/// A windmill blade vertex: rotated about the hub by the instance's animation angle after the object-space
/// position FSI's visibility texture reads (seed 000 section 3.3).
pub const AUX_BLADE: f32 = 3.0;

/// The single-leaf alpha mask over a card's (u, v) in [0, 1]^2: a pointed leaf along v. Must match
/// `leaf_mask` in shaders/mesh.wgsl.
pub fn leaf_mask(u: f32, v: f32) -> bool {
    let x = u * 2.0 - 1.0;
    let y = v * 2.0 - 1.0;
    x.abs() <= 0.8 * (1.0 - y * y)
}

/// The leaf-cluster mask: a 3x3 grid of leaves, each cell's leaf tilted by a fixed per-cell amount, with two
/// cells left empty so the card does not read as a square. Must match `leaf_cluster_mask` in the shader.
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

impl Mesh {
    /// Builds and validates a mesh. `name` is used in error messages (a file path or a generator's name).
    /// Missing normals (`None`) are computed as area-weighted vertex normals.
    pub fn new(
        name: &str,
        positions: Vec<[f32; 3]>,
        normals: Option<Vec<[f32; 3]>>,
        indices: Vec<u32>,
    ) -> Result<Mesh> {
        let bad = |problem: String| Error::Mesh {
            path: name.to_string(),
            problem,
        };
        if indices.is_empty() {
            return Err(bad("has no triangles".into()));
        }
        if !indices.len().is_multiple_of(3) {
            return Err(bad(format!(
                "index count {} is not a multiple of 3",
                indices.len()
            )));
        }
        if let Some((i, p)) = positions
            .iter()
            .enumerate()
            .find(|(_, p)| !p.iter().all(|c| c.is_finite()))
        {
            return Err(bad(format!(
                "vertex {} has a non-finite coordinate {:?}",
                i + 1,
                p
            )));
        }
        if let Some((i, &ix)) = indices
            .iter()
            .enumerate()
            .find(|(_, &ix)| ix as usize >= positions.len())
        {
            return Err(bad(format!(
                "triangle {} uses vertex index {} but the mesh has {} vertices",
                i / 3 + 1,
                ix as u64 + 1,
                positions.len()
            )));
        }
        let normals = match normals {
            Some(n) => {
                if n.len() != positions.len() {
                    return Err(bad(format!(
                        "{} normals for {} vertices",
                        n.len(),
                        positions.len()
                    )));
                }
                if n.iter().any(|v| !v.iter().all(|c| c.is_finite())) {
                    return Err(bad("has a non-finite normal".into()));
                }
                n
            }
            None => vertex_normals(&positions, &indices),
        };
        let aux = vec![[0.0; 4]; positions.len()];
        Ok(Mesh {
            positions,
            normals,
            indices,
            aux,
        })
    }

    /// Sets the per-vertex `aux` data (one entry per vertex, finite).
    pub fn with_aux(mut self, name: &str, aux: Vec<[f32; 4]>) -> Result<Mesh> {
        let bad = |problem: String| Error::Mesh {
            path: name.to_string(),
            problem,
        };
        if aux.len() != self.positions.len() {
            return Err(bad(format!(
                "{} aux entries for {} vertices",
                aux.len(),
                self.positions.len()
            )));
        }
        if aux.iter().any(|a| !a.iter().all(|c| c.is_finite())) {
            return Err(bad("has a non-finite aux value".into()));
        }
        self.aux = aux;
        Ok(self)
    }

    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Axis-aligned bounds (min, max).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for p in &self.positions {
            let p = Vec3::from(*p);
            lo = lo.min(p);
            hi = hi.max(p);
        }
        (lo, hi)
    }

    /// Centre of the bounding box and the radius of the sphere around it that holds every vertex.
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        let (lo, hi) = self.bounds();
        let c = (lo + hi) * 0.5;
        let r = self
            .positions
            .iter()
            .map(|p| Vec3::from(*p).distance(c))
            .fold(0.0f32, f32::max);
        (c, r)
    }

    /// Loads an OBJ file (all its objects, faces triangulated); normals are taken from the file when every
    /// vertex has one, computed otherwise.
    pub fn load_obj(path: &Path) -> Result<Mesh> {
        let name = path.display().to_string();
        if !path.is_file() {
            return Err(Error::Mesh {
                path: name,
                problem: "file not found".into(),
            });
        }
        let bytes = std::fs::read(path).map_err(|e| Error::Mesh {
            path: name.clone(),
            problem: format!("cannot be read ({e})"),
        })?;
        Mesh::parse_obj(&name, &bytes)
    }

    /// Parses OBJ text held in memory; `name` is used in error messages.
    pub fn parse_obj(name: &str, bytes: &[u8]) -> Result<Mesh> {
        let opts = tobj::LoadOptions {
            triangulate: true,
            single_index: true,
            ..Default::default()
        };
        let mut reader = std::io::BufReader::new(bytes);
        let (models, _materials) =
            tobj::load_obj_buf(&mut reader, &opts, |_| Err(tobj::LoadError::OpenFileFailed))
                .map_err(|e| Error::Mesh {
                    path: name.to_string(),
                    problem: format!("not a readable OBJ file ({e})"),
                })?;
        let mut positions = Vec::new();
        let mut normals = Vec::new();
        let mut indices = Vec::new();
        let mut all_have_normals = true;
        for m in &models {
            let mesh = &m.mesh;
            let base = positions.len() as u64;
            let count = mesh.positions.len() / 3;
            positions.extend(mesh.positions.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
            if mesh.normals.len() == mesh.positions.len() {
                normals.extend(mesh.normals.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
            } else {
                all_have_normals = false;
            }
            for &ix in &mesh.indices {
                // An index past this object's vertices must stay out of range after the offset, not alias a
                // vertex of the next object.
                let global = if (ix as usize) < count {
                    base + ix as u64
                } else {
                    u32::MAX as u64
                };
                indices.push(global.min(u32::MAX as u64) as u32);
            }
        }
        let normals = if all_have_normals && !normals.is_empty() {
            Some(normals)
        } else {
            None
        };
        Mesh::new(name, positions, normals, indices)
    }
}

/// Area-weighted vertex normals; a vertex with no non-degenerate face gets +Y.
pub fn vertex_normals(positions: &[[f32; 3]], indices: &[u32]) -> Vec<[f32; 3]> {
    let mut acc = vec![Vec3::ZERO; positions.len()];
    for t in indices.chunks_exact(3) {
        let (a, b, c) = (t[0] as usize, t[1] as usize, t[2] as usize);
        let (pa, pb, pc) = (
            Vec3::from(positions[a]),
            Vec3::from(positions[b]),
            Vec3::from(positions[c]),
        );
        let n = (pb - pa).cross(pc - pa); // length = 2 * area
        acc[a] += n;
        acc[b] += n;
        acc[c] += n;
    }
    acc.into_iter()
        .map(|n| n.try_normalize().unwrap_or(Vec3::Y).to_array())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> (Vec<[f32; 3]>, Vec<u32>) {
        (
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            vec![0, 1, 2],
        )
    }

    #[test]
    fn valid_triangle_gets_normals() {
        let (p, i) = tri();
        let m = Mesh::new("t", p, None, i).unwrap();
        assert_eq!(m.triangle_count(), 1);
        for n in &m.normals {
            assert!((Vec3::from(*n) - Vec3::Z).length() < 1e-6);
        }
    }

    #[test]
    fn rejects_out_of_range_index() {
        let (p, _) = tri();
        let e = Mesh::new("t.obj", p, None, vec![0, 1, 3]).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains("t.obj") && msg.contains("vertex index 4"),
            "{msg}"
        );
    }

    #[test]
    fn rejects_nan() {
        let (mut p, i) = tri();
        p[1][2] = f32::NAN;
        let msg = Mesh::new("t.obj", p, None, i).unwrap_err().to_string();
        assert!(
            msg.contains("non-finite") && msg.contains("vertex 2"),
            "{msg}"
        );
    }

    #[test]
    fn rejects_empty_and_partial() {
        let (p, _) = tri();
        assert!(Mesh::new("t", p.clone(), None, vec![]).is_err());
        assert!(Mesh::new("t", p, None, vec![0, 1]).is_err());
    }

    #[test]
    fn obj_errors_name_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("missing.obj");
        let msg = Mesh::load_obj(&missing).unwrap_err().to_string();
        assert!(
            msg.contains("missing.obj") && msg.contains("not found"),
            "{msg}"
        );

        let bad = dir.path().join("bad.obj");
        std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n").unwrap();
        let msg = Mesh::load_obj(&bad).unwrap_err().to_string();
        assert!(msg.contains("bad.obj"), "{msg}");

        let nan = dir.path().join("nan.obj");
        std::fs::write(&nan, "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        let msg = Mesh::load_obj(&nan).unwrap_err().to_string();
        assert!(msg.contains("nan.obj"), "{msg}");
    }

    #[test]
    fn loads_committed_bunny() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/bunny.obj");
        let m = Mesh::load_obj(&path).unwrap();
        assert_eq!(m.vertex_count(), 1839);
        assert_eq!(m.triangle_count(), 3674);
    }
}
