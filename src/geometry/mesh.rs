//! Validated triangle meshes, and loading them from OBJ (tobj) and glTF 2.0 (.gltf / .glb, `gltf/`).

use crate::error::{Error, Result};
use crate::geometry::attributes::VertexData;
use crate::geometry::gltf;
use crate::geometry::projection::Sphere;
use glam::Vec3;
use std::path::Path;

/// The mesh file formats [`Mesh::load`] reads, as its error messages list them.
const MESH_FORMATS: &str = "lodbench reads .obj, .gltf and .glb";

/// An indexed triangle mesh with per-vertex normals. Construct it with [`Mesh::new`] (or the loaders), which
/// checks what the GPU and the LOD generator rely on: indices in range, finite coordinates, whole triangles,
/// at least one triangle.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub indices: Vec<u32>,
    /// Per-vertex shading extras, one per vertex (zeros unless set with [`Mesh::with_aux`]):
    /// `[u, v, kind, hub_y]`. kind ([`AUX_SOLID`], [`AUX_LEAF`], [`AUX_LEAF_CLUSTER`], [`AUX_BLADE`],
    /// [`AUX_DEFORMED`]) selects the
    /// alpha-test mask over (u, v) or the blade rotation about the object-space axis parallel to +z through
    /// (0, hub_y, z); see shaders/mesh.wgsl.
    pub aux: Vec<[f32; 4]>,
    /// Texture coordinates, tangents, colours, skin and morph targets, where the source has them
    /// ([`Mesh::with_data`]); simplification keeps them ([`VertexData::gather`]).
    pub data: VertexData,
    /// The triangles by material, in runs covering `indices` in order ([`Mesh::with_parts`]); empty: the whole
    /// mesh in the scene's one flat look (every built-in scene).
    pub parts: Vec<Part>,
}

/// A run of a mesh's triangles drawn with one material: `index_count` indices from `first_index`, material
/// `material` of the scene's [`crate::geometry::material::Materials`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Part {
    pub material: u32,
    pub first_index: u32,
    pub index_count: u32,
}

/// `aux` kinds (the shader reads them as floats).
pub const AUX_SOLID: f32 = 0.0;
/// An alpha-tested card showing one leaf (mask: [`crate::geometry::procgen::leaf_mask`] at (u, v)).
pub const AUX_LEAF: f32 = 1.0;
/// An alpha-tested card showing a cluster of leaves (mask: [`crate::geometry::procgen::leaf_cluster_mask`]), for billboard clouds.
pub const AUX_LEAF_CLUSTER: f32 = 2.0;
/// A windmill blade vertex: rotated about the hub by the instance's animation angle after the object-space
/// position FSI's visibility texture reads (Scherzer & Wimmer 2008 section 3.3).
pub const AUX_BLADE: f32 = 3.0;
/// A vertex of a mesh deformed per frame (a skin, animated morph weights): its position is the frame's, and
/// `aux` holds its rest position as `(x, y, kind, z)`, the object-space position before animation that FSI's
/// visibility texture reads (set by the GPU layer, `gpu/scene_gpu/pose.rs`).
pub const AUX_DEFORMED: f32 = 4.0;

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
            data: VertexData::default(),
            parts: Vec::new(),
        })
    }

    /// Sets the material runs: (material, index count) in order, covering every index, each a whole number of
    /// triangles (runs of no index are dropped).
    pub fn with_parts(mut self, name: &str, runs: &[(u32, u32)]) -> Result<Mesh> {
        let mut parts = Vec::with_capacity(runs.len());
        let mut at = 0u64;
        for &(material, count) in runs {
            if count % 3 != 0 {
                return Err(mesh_error(
                    name,
                    format!("a material run of {count} indices is not whole triangles"),
                ));
            }
            if count > 0 {
                parts.push(Part {
                    material,
                    first_index: at as u32,
                    index_count: count,
                });
            }
            at += u64::from(count);
        }
        if at != self.indices.len() as u64 {
            return Err(mesh_error(
                name,
                format!(
                    "material runs cover {at} of its {} indices",
                    self.indices.len()
                ),
            ));
        }
        self.parts = parts;
        Ok(self)
    }

    /// The material runs as (material, index range); one run of material None when the mesh has none.
    pub fn runs(&self) -> Vec<(Option<u32>, std::ops::Range<usize>)> {
        if self.parts.is_empty() {
            return vec![(None, 0..self.indices.len())];
        }
        self.parts
            .iter()
            .map(|p| {
                let a = p.first_index as usize;
                (Some(p.material), a..a + p.index_count as usize)
            })
            .collect()
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

    /// Sets the optional per-vertex channels (each one entry per vertex, finite).
    pub fn with_data(mut self, name: &str, data: VertexData) -> Result<Mesh> {
        data.check(self.positions.len())
            .map_err(|problem| Error::Mesh {
                path: name.to_string(),
                problem,
            })?;
        self.data = data;
        Ok(self)
    }

    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// An error naming `name` (the file) when every triangle has zero area.
    pub fn check_area(&self, name: &str) -> Result<()> {
        let area: f64 = self
            .indices
            .chunks_exact(3)
            .map(|t| {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| Vec3::from(self.positions[i as usize]));
                f64::from((b - a).cross(c - a).length())
            })
            .sum();
        if area.is_nan() || area <= 0.0 {
            return Err(Error::Mesh {
                path: name.to_string(),
                problem: format!(
                    "all {} triangles are degenerate (zero area)",
                    self.triangle_count()
                ),
            });
        }
        Ok(())
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
    pub fn bounding_sphere(&self) -> Sphere {
        Sphere::around(&self.positions)
    }

    /// Loads a mesh file, choosing the reader by the extension (any case): `.obj` [`Mesh::load_obj`],
    /// `.gltf` and `.glb` [`Mesh::load_gltf`]. A missing path, a directory and any other extension are errors
    /// that name the file.
    pub fn load(path: &Path) -> Result<Mesh> {
        let name = path.display().to_string();
        check_mesh_file(path, &name)?;
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ext.as_deref() {
            Some("obj") => Mesh::load_obj(path),
            Some("gltf" | "glb") => Mesh::load_gltf(path),
            Some(other) => Err(mesh_error(
                &name,
                format!("unsupported extension '.{other}' ({MESH_FORMATS})"),
            )),
            None => Err(mesh_error(
                &name,
                format!("has no file extension ({MESH_FORMATS})"),
            )),
        }
    }

    /// Loads an OBJ file (all its objects, faces triangulated); normals are taken from the file when every
    /// vertex has one, computed otherwise.
    pub fn load_obj(path: &Path) -> Result<Mesh> {
        let name = path.display().to_string();
        let bytes = read_mesh_file(path, &name)?;
        Mesh::parse_obj(&name, &bytes)
    }

    /// Loads a glTF 2.0 file, JSON (`.gltf`) or binary (`.glb`; the content decides, not the extension), read by
    /// [`gltf`].
    ///
    /// The geometry taken is every triangle primitive of every mesh placement in the default scene (scene 0
    /// when the file names no default; every mesh, untransformed, when the file has no scenes), merged into
    /// one mesh with each placement's world transform applied: positions by the matrix, normals by its inverse
    /// transpose and renormalised; a transform that mirrors (negative determinant) gets its triangles' winding
    /// reversed, as glTF specifies. A mesh used by two nodes is merged twice, and a node with
    /// EXT_mesh_gpu_instancing once per instance (whether or not the file marks the extension required).
    ///
    /// - Primitive modes: TRIANGLES is taken as is, TRIANGLE_STRIP and TRIANGLE_FAN are triangulated (the
    ///   spec's vertex orders), POINTS and the LINE modes are skipped. A primitive without indices uses its
    ///   vertices in order.
    /// - Attributes: float, or integer as KHR_mesh_quantization allows (normalised or not, dequantised; the
    ///   node's transform then scales them back), and meshopt-compressed buffer views (EXT_ and
    ///   KHR_meshopt_compression) are decoded.
    /// - Normals: the file's when every merged primitive has NORMALs (and no transform is singular), otherwise
    ///   all are computed as [`Mesh::new`] does, as for OBJ files.
    /// - Accessors: sparse ones are read (their values substituted into the base data or zeros).
    /// - Skins and morph targets: a skinned mesh is placed by its joints at rest (its node's own transform
    ///   ignored, as glTF specifies), morph targets at the node's weights, else the mesh's, else 0.
    /// - Refused with the reason: a file holding an authored LOD chain (MSFT_lod, or `NAME_LODn` siblings:
    ///   merging its levels would draw them over each other), Draco compression (with the command that rewrites
    ///   the file with meshopt compression), any other required extension that changes geometry. Not read:
    ///   animations (the scene at rest), materials, UVs and images (never decoded).
    /// - Buffers: the GLB binary chunk, base64 `data:` URIs, or files named by relative (percent-encoded)
    ///   URIs, read from the .gltf file's folder; only buffers the merged primitives use are read.
    pub fn load_gltf(path: &Path) -> Result<Mesh> {
        let name = path.display().to_string();
        let bytes = read_mesh_file(path, &name)?;
        let dir = path.parent().unwrap_or(Path::new(""));
        Mesh::parse_gltf(&name, &bytes, dir)
    }

    /// Parses a glTF (JSON or GLB) held in memory as [`Mesh::load_gltf`] does; external buffers are looked up in
    /// `dir`, `name` is used in error messages.
    pub fn parse_gltf(name: &str, bytes: &[u8], dir: &Path) -> Result<Mesh> {
        parse_gltf(bytes, dir).map_err(|problem| mesh_error(name, problem))
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

fn mesh_error(name: &str, problem: impl Into<String>) -> Error {
    Error::Mesh {
        path: name.to_string(),
        problem: problem.into(),
    }
}

/// `Ok` for a path that names a file: errors say "file not found" or "is a directory" otherwise.
fn check_mesh_file(path: &Path, name: &str) -> Result<()> {
    match std::fs::metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            Err(mesh_error(name, "file not found"))
        }
        Err(e) => Err(mesh_error(name, format!("cannot be read ({e})"))),
        Ok(m) if m.is_dir() => Err(mesh_error(name, "is a directory")),
        Ok(m) if !m.is_file() => Err(mesh_error(name, "is not a regular file")),
        Ok(_) => Ok(()),
    }
}

/// The bytes of the mesh or scene file at `path` (`name` in errors).
pub(crate) fn read_mesh_file(path: &Path, name: &str) -> Result<Vec<u8>> {
    check_mesh_file(path, name)?;
    std::fs::read(path).map_err(|e| mesh_error(name, format!("cannot be read ({e})")))
}

/// Reads the glTF (JSON or GLB) in `bytes` as one mesh (see [`Mesh::load_gltf`]); external buffers are looked up
/// in `dir`. Errors are the problem text of an [`Error::Mesh`].
fn parse_gltf(bytes: &[u8], dir: &Path) -> Result<Mesh, String> {
    let mut content = gltf::read(bytes, dir)?;
    if let Some(c) = content.chains.first() {
        let source = match c.source {
            gltf::ChainSource::MsftLod => "MSFT_lod",
            gltf::ChainSource::LodNames => "nodes named _LOD0, _LOD1, ...",
        };
        return Err(format!(
            "holds an authored LOD chain ('{}': {} levels, {source}); --mesh takes one mesh and builds its own LOD \
             chain, and merging the levels would draw them over each other: pass a file with LOD0 alone",
            c.name,
            c.nodes.len()
        ));
    }
    let mut meshes: std::collections::HashMap<usize, gltf::MeshPrimitives> =
        std::collections::HashMap::new();
    let (mut positions, mut normals, mut indices) = (Vec::new(), Vec::new(), Vec::new());
    let mut all_normals = true;
    let placements = std::mem::take(&mut content.placements);
    for p in &placements {
        if let std::collections::hash_map::Entry::Vacant(e) = meshes.entry(p.mesh) {
            e.insert(content.mesh_primitives(p.mesh)?);
        }
        let part = content.placed(p, &meshes[&p.mesh], glam::Mat4::IDENTITY)?;
        let base = u32::try_from(positions.len())
            .ok()
            .filter(|b| b.checked_add(part.positions.len() as u32).is_some())
            .ok_or("has more vertices than 32-bit indices can address")?;
        indices.extend(part.indices.iter().map(|&i| base + i));
        match part.normals {
            Some(n) if all_normals => normals.extend(n),
            _ => all_normals = false,
        }
        positions.extend(part.positions);
    }
    if indices.is_empty() {
        return Err(match content.scene {
            Some(s) => format!("has no triangle primitives in scene {s}"),
            None => "has no triangle primitives".to_string(),
        });
    }
    // lodbench's own shading extras and the other channels are not read here: --mesh takes the shape alone.
    Mesh::new("", positions, all_normals.then_some(normals), indices).map_err(|e| match e {
        Error::Mesh { problem, .. } => problem,
        other => other.to_string(),
    })
}

pub use crate::geometry::attributes::vertex_normals;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::gltf::{decode_base64, percent_decode};

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
    fn load_obj_reports_a_directory() {
        let dir = tempfile::tempdir().unwrap();
        let sub = dir.path().join("meshes.obj");
        std::fs::create_dir(&sub).unwrap();
        for msg in [
            Mesh::load_obj(&sub).unwrap_err().to_string(),
            Mesh::load(&sub).unwrap_err().to_string(),
            Mesh::load_gltf(&sub).unwrap_err().to_string(),
        ] {
            assert!(
                msg.contains("meshes.obj") && msg.contains("is a directory"),
                "{msg}"
            );
        }
    }

    // ---- glTF ----

    fn fixture(file: &str) -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(file)
    }

    /// tests/data/tetra.gltf as JSON, to edit and write back.
    fn fixture_json() -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(fixture("tetra.gltf")).unwrap()).unwrap()
    }

    /// The fixture's 120-byte buffer (4 positions, 4 normals, 12 u16 indices).
    fn fixture_buffer() -> Vec<u8> {
        let json = fixture_json();
        let uri = json["buffers"][0]["uri"].as_str().unwrap();
        decode_base64(uri.split_once(',').unwrap().1).unwrap()
    }

    fn encode_base64(bytes: &[u8]) -> String {
        use base64::Engine;
        base64::engine::general_purpose::STANDARD.encode(bytes)
    }

    fn with_buffer(mut json: serde_json::Value, bytes: &[u8]) -> serde_json::Value {
        json["buffers"][0]["uri"] = format!(
            "data:application/octet-stream;base64,{}",
            encode_base64(bytes)
        )
        .into();
        json
    }

    fn write_json(dir: &Path, file: &str, json: &serde_json::Value) -> std::path::PathBuf {
        let path = dir.join(file);
        std::fs::write(&path, serde_json::to_string(json).unwrap()).unwrap();
        path
    }

    fn load_json(json: &serde_json::Value) -> Result<Mesh> {
        let dir = tempfile::tempdir().unwrap();
        Mesh::load(&write_json(dir.path(), "edited.gltf", json))
    }

    fn assert_bounds(m: &Mesh, lo: [f32; 3], hi: [f32; 3]) {
        let (l, h) = m.bounds();
        assert!(
            l.abs_diff_eq(Vec3::from(lo), 1e-6) && h.abs_diff_eq(Vec3::from(hi), 1e-6),
            "bounds {l} {h}"
        );
    }

    fn assert_near(a: [f32; 3], b: Vec3) {
        assert!(Vec3::from(a).abs_diff_eq(b, 1e-6), "{a:?} vs {b}");
    }

    #[test]
    fn base64_and_percent_decoding() {
        assert_eq!(decode_base64("aGVsbG8=").unwrap(), b"hello");
        assert_eq!(decode_base64("aGVsbG8").unwrap(), b"hello");
        assert_eq!(decode_base64("aGk_-w").unwrap(), [b'h', b'i', 0x3f, 0xfb]);
        assert!(decode_base64("aGVs*G8=").is_none());
        assert!(decode_base64("aGVsb").is_none());
        let all: Vec<u8> = (0..=255).collect();
        assert_eq!(decode_base64(&encode_base64(&all)).unwrap(), all);
        assert_eq!(percent_decode("a%20b%2Fc").unwrap(), b"a b/c");
        assert!(percent_decode("a%2").is_none());
        assert!(percent_decode("a%zz").is_none());
    }

    #[test]
    fn gltf_fixture_merges_both_nodes_with_transforms() {
        let m = Mesh::load(&fixture("tetra.gltf")).unwrap();
        // Two instances of the 4-vertex tetrahedron (node "moved" at x + 2); the POINTS primitive is skipped.
        assert_eq!(m.vertex_count(), 8);
        assert_eq!(m.triangle_count(), 8);
        assert_bounds(&m, [0.0, 0.0, 0.0], [3.0, 1.0, 1.0]);
        for i in 0..4 {
            assert_near(
                m.positions[i + 4],
                Vec3::from(m.positions[i]) + Vec3::new(2.0, 0.0, 0.0),
            );
            assert_eq!(m.normals[i + 4], m.normals[i]);
        }
        assert_eq!(&m.indices[..3], &[0, 2, 1]);
        assert_eq!(&m.indices[12..15], &[4, 6, 5]);
        // The file's normals, not computed ones (those would be +x at vertex 2).
        assert_near(m.normals[1], Vec3::new(3.0, -1.0, -1.0).normalize());
    }

    #[test]
    fn glb_fixture_equals_gltf_fixture() {
        let glb = Mesh::load(&fixture("tetra.glb")).unwrap();
        assert_eq!(glb.vertex_count(), 8);
        assert_eq!(glb, Mesh::load(&fixture("tetra.gltf")).unwrap());
    }

    #[test]
    fn load_dispatches_on_extension_in_any_case() {
        let dir = tempfile::tempdir().unwrap();
        let upper = dir.path().join("TETRA.GLTF");
        std::fs::copy(fixture("tetra.gltf"), &upper).unwrap();
        let mixed = dir.path().join("tetra.Glb");
        std::fs::copy(fixture("tetra.glb"), &mixed).unwrap();
        let obj = dir.path().join("tri.OBJ");
        std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        assert_eq!(Mesh::load(&upper).unwrap().triangle_count(), 8);
        assert_eq!(Mesh::load(&mixed).unwrap().triangle_count(), 8);
        assert_eq!(Mesh::load(&obj).unwrap().triangle_count(), 1);
        // glTF content behind a .obj name goes to the OBJ reader.
        let wrong = dir.path().join("tetra.obj");
        std::fs::copy(fixture("tetra.gltf"), &wrong).unwrap();
        assert!(Mesh::load(&wrong).is_err());
    }

    #[test]
    fn load_reports_missing_file_and_unsupported_extension() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("missing.glb");
        let msg = Mesh::load(&missing).unwrap_err().to_string();
        assert!(
            msg.contains("missing.glb") && msg.contains("file not found"),
            "{msg}"
        );
        let msg = Mesh::load_gltf(&missing).unwrap_err().to_string();
        assert!(
            msg.contains("missing.glb") && msg.contains("file not found"),
            "{msg}"
        );

        let xyz = dir.path().join("cloud.XYZ");
        std::fs::write(&xyz, "1 2 3\n").unwrap();
        let msg = Mesh::load(&xyz).unwrap_err().to_string();
        assert!(
            msg.contains("cloud.XYZ")
                && msg
                    .contains("unsupported extension '.xyz' (lodbench reads .obj, .gltf and .glb)"),
            "{msg}"
        );
        let bare = dir.path().join("mesh");
        std::fs::write(&bare, "v 0 0 0\n").unwrap();
        let msg = Mesh::load(&bare).unwrap_err().to_string();
        assert!(msg.contains("has no file extension"), "{msg}");
    }

    #[test]
    fn truncated_glb_and_garbage_gltf_are_not_readable() {
        let dir = tempfile::tempdir().unwrap();
        let glb = std::fs::read(fixture("tetra.glb")).unwrap();
        let cut = dir.path().join("cut.glb");
        // Every truncation (the GLB header's length no longer matches) is refused by the glTF parser, none
        // panics, and each message names the file.
        for len in 0..glb.len() {
            std::fs::write(&cut, &glb[..len]).unwrap();
            let msg = Mesh::load(&cut).unwrap_err().to_string();
            assert!(
                msg.contains("cut.glb") && msg.contains("not a readable glTF file ("),
                "{len}: {msg}"
            );
        }
        for (file, text) in [("garbage.gltf", "solid cube\n"), ("empty.gltf", "{}")] {
            let path = dir.path().join(file);
            std::fs::write(&path, text).unwrap();
            let msg = Mesh::load(&path).unwrap_err().to_string();
            assert!(
                msg.contains(file) && msg.contains("not a readable glTF file ("),
                "{msg}"
            );
        }
    }

    #[test]
    fn gltf_nan_position_is_reported() {
        let mut bytes = fixture_buffer();
        bytes[12..16].copy_from_slice(&f32::NAN.to_le_bytes()); // x of vertex 2 (position 1)
        let dir = tempfile::tempdir().unwrap();
        let path = write_json(dir.path(), "nan.gltf", &with_buffer(fixture_json(), &bytes));
        let msg = Mesh::load(&path).unwrap_err().to_string();
        assert!(
            msg.contains("nan.gltf") && msg.contains("vertex 2 has a non-finite coordinate"),
            "{msg}"
        );
    }

    #[test]
    fn gltf_separate_bin_is_read_from_the_files_folder() {
        let dir = tempfile::tempdir().unwrap();
        let sub = dir.path().join("model");
        std::fs::create_dir(&sub).unwrap();
        let mut json = fixture_json();
        json["buffers"][0]["uri"] = "tetra%20data.bin".into();
        let path = write_json(&sub, "tetra.gltf", &json);
        std::fs::write(sub.join("tetra data.bin"), fixture_buffer()).unwrap();
        assert_eq!(
            Mesh::load(&path).unwrap(),
            Mesh::load(&fixture("tetra.gltf")).unwrap()
        );

        std::fs::remove_file(sub.join("tetra data.bin")).unwrap();
        let msg = Mesh::load(&path).unwrap_err().to_string();
        assert!(
            msg.contains("tetra.gltf")
                && msg.contains("buffer 0 file")
                && msg.contains("tetra data.bin not found"),
            "{msg}"
        );
        json["buffers"][0]["uri"] = "https://example.com/tetra.bin".into();
        let msg = load_json(&json).unwrap_err().to_string();
        assert!(
            msg.contains("reads only data: URIs and relative file paths"),
            "{msg}"
        );
    }

    #[test]
    fn gltf_takes_the_default_scene_else_scene_0_else_every_mesh() {
        let mut json = fixture_json();
        json["scenes"] = serde_json::json!([{"nodes": [0]}, {"nodes": [1]}]);
        json["scene"] = 1.into();
        let m = load_json(&json).unwrap();
        assert_eq!(m.vertex_count(), 4);
        assert_bounds(&m, [2.0, 0.0, 0.0], [3.0, 1.0, 1.0]);

        json["scenes"] = serde_json::json!([{"nodes": [1]}, {"nodes": [0]}]);
        json.as_object_mut().unwrap().remove("scene");
        let m = load_json(&json).unwrap();
        assert_eq!(m.vertex_count(), 4);
        assert_bounds(&m, [2.0, 0.0, 0.0], [3.0, 1.0, 1.0]);

        json.as_object_mut().unwrap().remove("scenes");
        let m = load_json(&json).unwrap();
        assert_eq!(m.vertex_count(), 4);
        assert_bounds(&m, [0.0, 0.0, 0.0], [1.0, 1.0, 1.0]);
    }

    #[test]
    fn gltf_without_triangle_primitives_is_an_error() {
        let mut json = fixture_json();
        json["meshes"][0]["primitives"][0]["mode"] = 1.into(); // LINES; primitive 1 is POINTS
        let dir = tempfile::tempdir().unwrap();
        let path = write_json(dir.path(), "lines.gltf", &json);
        let msg = Mesh::load(&path).unwrap_err().to_string();
        assert!(
            msg.contains("lines.gltf") && msg.contains("has no triangle primitives in scene 0"),
            "{msg}"
        );
    }

    #[test]
    fn gltf_strips_fans_and_unindexed_triangles() {
        let mut json = fixture_json();
        json["meshes"][0]["primitives"][0]
            .as_object_mut()
            .unwrap()
            .remove("indices");
        json["meshes"][0]["primitives"][0]["mode"] = 5.into();
        let m = load_json(&json).unwrap();
        assert_eq!(&m.indices[..6], &[0, 1, 2, 1, 3, 2]);
        assert_eq!(m.triangle_count(), 4);

        json["meshes"][0]["primitives"][0]["mode"] = 6.into();
        let m = load_json(&json).unwrap();
        assert_eq!(&m.indices[..6], &[1, 2, 0, 2, 3, 0]);

        json["meshes"][0]["primitives"][0]["mode"] = 4.into();
        json["accessors"][0]["count"] = 3.into();
        json["accessors"][1]["count"] = 3.into();
        let m = load_json(&json).unwrap();
        assert_eq!(m.indices, [0, 1, 2, 3, 4, 5]);
    }

    #[test]
    fn gltf_node_transform_maps_normals_by_inverse_transpose_and_mirrors_winding() {
        let mut json = fixture_json();
        json["nodes"][1]["scale"] = serde_json::json!([2.0, 1.0, -1.0]);
        let m = load_json(&json).unwrap();
        assert_bounds(&m, [0.0, 0.0, -1.0], [4.0, 1.0, 1.0]);
        assert_near(m.positions[5], Vec3::new(4.0, 0.0, 0.0));
        assert_near(m.normals[5], Vec3::new(1.5, -1.0, 1.0).normalize());
        // The mirrored copy's triangles still face outwards.
        let centre = Vec3::new(2.5, 0.25, -0.25);
        for t in m.indices[12..].chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| Vec3::from(m.positions[i as usize]));
            let outward = (b - a).cross(c - a).dot((a + b + c) / 3.0 - centre);
            assert!(outward > 0.0, "{t:?}");
        }
    }

    #[test]
    fn gltf_normals_are_computed_unless_every_primitive_has_them() {
        let mut json = fixture_json();
        let mut bare = json["meshes"][0].clone();
        bare["primitives"][0]["attributes"]
            .as_object_mut()
            .unwrap()
            .remove("NORMAL");
        json["meshes"] = serde_json::json!([json["meshes"][0], bare]);
        json["nodes"][1]["mesh"] = 1.into();
        let m = load_json(&json).unwrap();
        assert_eq!(m.vertex_count(), 8);
        assert_eq!(m.normals, vertex_normals(&m.positions, &m.indices));
        assert_near(m.normals[1], Vec3::X);
    }

    #[test]
    fn gltf_structural_problems_are_errors() {
        let mut bad_index = fixture_buffer();
        bad_index[96..98].copy_from_slice(&9u16.to_le_bytes());
        let cases: Vec<(serde_json::Value, &str)> = vec![
            (
                with_buffer(fixture_json(), &bad_index),
                "mesh 0 primitive 0 uses vertex index 9 but has 4 vertices",
            ),
            (
                {
                    let mut j = fixture_json();
                    j["accessors"][0]["count"] = 5.into();
                    j
                },
                "accessor 0 (5 elements) does not fit in buffer view 0",
            ),
            (
                {
                    let mut j = fixture_json();
                    j["nodes"][1]["children"] = serde_json::json!([0]);
                    j
                },
                "node 0 is its own ancestor",
            ),
            (
                {
                    let mut j = fixture_json();
                    j["buffers"][0]["byteLength"] = 200.into();
                    j
                },
                "buffer 0 holds 120 bytes but declares byteLength 200",
            ),
            (
                {
                    let mut j = fixture_json();
                    j["accessors"][0]["sparse"] = serde_json::json!({
                        "count": 1,
                        "indices": {"bufferView": 1, "componentType": 5123},
                        "values": {"bufferView": 0}
                    });
                    j
                },
                "accessor 0's sparse substitutes element",
            ),
        ];
        for (json, want) in cases {
            let msg = load_json(&json).unwrap_err().to_string();
            assert!(msg.contains("edited.gltf") && msg.contains(want), "{msg}");
        }
    }

    #[test]
    fn loads_committed_bunny() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/bunny.obj");
        let m = Mesh::load_obj(&path).unwrap();
        assert_eq!(m.vertex_count(), 1839);
        assert_eq!(m.triangle_count(), 3674);
    }
}
