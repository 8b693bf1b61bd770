//! [`read`]: a glTF file's scene as lodbench takes it: every mesh placement, the authored LOD chains, the node
//! hierarchy, and access to meshes, skins and animations.

use super::accessors::Doc;
use super::animation::{animation_names, Animation, Rig};
use super::authored_chains::{chains, AuthoredChain};
use super::container::{check_required, container};
use super::json::{array, floats, uint};
use super::nodes::{Nodes, Placement};
use super::primitives::{Merged, MergedParts, MeshPrimitives};
use super::skins::Skin;
use glam::Mat4;
use std::path::Path;

/// What a glTF file places in its scene.
pub struct Content<'a> {
    pub(super) doc: Doc<'a>,
    pub nodes: Nodes,
    /// Every node's world matrix at rest.
    pub rest_worlds: Vec<Mat4>,
    /// Every mesh placement of the scene's node trees in document order, then MSFT_lod's coarser levels that
    /// are not in the scene (placed where their LOD0 node's parent is).
    pub placements: Vec<Placement>,
    pub chains: Vec<AuthoredChain>,
    /// The scene read (None: the file has no scenes and every mesh is placed untransformed).
    pub scene: Option<usize>,
}

/// Reads the glTF (JSON or GLB) in `bytes`; external buffers are looked up in `dir`. Errors are problem texts
/// (the caller names the file).
pub fn read<'a>(bytes: &'a [u8], dir: &'a Path) -> Result<Content<'a>, String> {
    let (json, blob) = container(bytes).map_err(|e| format!("not a readable glTF file ({e})"))?;
    check_required(&json)?;
    let mut doc = Doc::new(json, blob, dir);
    let nodes = Nodes::read(&doc.json)?;
    let rest_worlds = nodes.worlds(&nodes.rest_locals());
    let chains = chains(&doc.json, &nodes)?;
    let mut placements = Vec::new();
    if nodes.scene.is_none() {
        for mesh in 0..array(&doc.json, "meshes").len() {
            placements.push(Placement {
                node: usize::MAX,
                name: String::new(),
                instance: None,
                mesh,
                world: Mat4::IDENTITY,
                instance_local: Mat4::IDENTITY,
                skin: None,
                weights: None,
            });
        }
    } else {
        for &n in &nodes.scene_order {
            doc.place(n, rest_worlds[n], &mut placements)?;
        }
        // MSFT_lod's coarser levels need not be in the scene: a level outside it is placed under its LOD0
        // node's parent (the spec's LOD nodes replace the LOD0 node where it stands), its descendants with it.
        for c in chains
            .iter()
            .filter(|c| c.source == super::authored_chains::ChainSource::MsftLod)
        {
            let parent = nodes.parent[c.nodes[0]].map_or(Mat4::IDENTITY, |p| rest_worlds[p]);
            for &level in &c.nodes[1..] {
                if nodes.scene_order.contains(&level) {
                    continue;
                }
                let root = parent * nodes.local[level].matrix();
                for (m, rel) in nodes.subtree(level) {
                    doc.place(m, root * rel, &mut placements)?;
                }
            }
        }
    }
    Ok(Content {
        doc,
        rest_worlds,
        placements,
        chains,
        scene: nodes.scene,
        nodes,
    })
}

impl Content<'_> {
    /// The base colour factor (linear RGB) of the material of mesh `mesh`'s first primitive, if it has one.
    pub fn mesh_color(&self, mesh: usize) -> Option<[f32; 3]> {
        let json = &self.doc.json;
        let material = uint(&json["meshes"][mesh]["primitives"][0]["material"])? as usize;
        let f = floats::<4>(
            &json["materials"][material]["pbrMetallicRoughness"]["baseColorFactor"],
            "baseColorFactor",
        )
        .ok()??;
        Some([f[0], f[1], f[2]].map(|c| c.clamp(0.0, 1.0)))
    }

    /// lodbench's index of glTF material `gltf` (None: glTF's default material) in `table`, read with its
    /// images the first time.
    pub fn material(
        &mut self,
        table: &mut super::materials::MaterialTable,
        gltf: Option<usize>,
    ) -> Result<u32, String> {
        self.doc.material(table, gltf)
    }

    /// Mesh `mesh`'s name ("" when it has none).
    pub fn mesh_name(&self, mesh: usize) -> &str {
        self.doc.json["meshes"][mesh]["name"].as_str().unwrap_or("")
    }

    /// The chain and level whose node hierarchy holds `node`, if any.
    pub fn chain_level(&self, node: usize) -> Option<(usize, usize)> {
        if node == usize::MAX {
            return None;
        }
        self.chains.iter().enumerate().find_map(|(c, chain)| {
            chain
                .nodes
                .iter()
                .position(|&level| self.nodes.is_under(node, level))
                .map(|l| (c, l))
        })
    }

    /// Whether `node` belongs to a level of an authored chain.
    pub fn in_chain(&self, node: usize) -> bool {
        self.chain_level(node).is_some()
    }

    /// The primitives of mesh `mesh` in mesh space (points and lines counted, not read).
    pub fn mesh_primitives(&mut self, mesh: usize) -> Result<MeshPrimitives, String> {
        self.doc.mesh_primitives(mesh)
    }

    /// Skin `i`.
    pub fn skin(&mut self, i: usize) -> Result<Skin, String> {
        self.doc.skin(i)
    }

    /// Skin `i`, checked against the joints mesh `prims` names: every joint index within the skin's joints.
    pub fn skin_of(
        &mut self,
        i: usize,
        mesh: usize,
        prims: &MeshPrimitives,
    ) -> Result<Skin, String> {
        let skin = self.doc.skin(i)?;
        let most = prims
            .triangles
            .iter()
            .filter_map(|t| t.skin.as_ref())
            .flat_map(|s| s.joints.iter().zip(&s.weights))
            .filter(|(_, &w)| w != 0.0)
            .map(|(&j, _)| j as usize)
            .max();
        if let Some(j) = most.filter(|&j| j >= skin.joints.len()) {
            return Err(format!(
                "mesh {mesh}'s JOINTS name joint {j}, but skin {i} has {} joints",
                skin.joints.len()
            ));
        }
        Ok(skin)
    }

    /// The morph weights placement `p` gives mesh `prims` at rest: the node's, else the mesh's, else none (0).
    pub fn rest_weights(p: &Placement, prims: &MeshPrimitives) -> Vec<f32> {
        p.weights
            .clone()
            .or_else(|| prims.weights.clone())
            .unwrap_or_default()
    }

    /// Whether placement `p` of mesh `prims` is skinned: its node has a skin and its primitives joints.
    pub fn is_skinned(p: &Placement, prims: &MeshPrimitives) -> bool {
        p.skin.is_some() && prims.is_skinned()
    }

    /// Mesh `p.mesh` (its primitives `prims`) as placement `p` shows it at rest, in the frame `to_frame` maps
    /// world space to. Not skinned: merged under `mesh_to_frame` (`to_frame` x the placement's world matrix, or
    /// the caller's own product of it), morphed by its rest weights ([`Content::rest_weights`]). Skinned: merged
    /// in mesh space (its deformable part stays there), then posed by its joints at rest, `to_frame` x each
    /// joint's world matrix x its inverse bind matrix: the node's own transform is ignored, as glTF 2.0 section
    /// 3.7.3.3 specifies. Skin influences on an unskinned node are dropped.
    pub fn placed(
        &mut self,
        p: &Placement,
        prims: &MeshPrimitives,
        to_frame: Mat4,
    ) -> Result<MergedParts, String> {
        self.placed_as(p, prims, to_frame * p.world, to_frame)
    }

    /// [`Content::placed`] with the unskinned mesh's transform given (`mesh_to_frame`).
    pub fn placed_as(
        &mut self,
        p: &Placement,
        prims: &MeshPrimitives,
        mesh_to_frame: Mat4,
        to_frame: Mat4,
    ) -> Result<MergedParts, String> {
        let weights = Content::rest_weights(p, prims);
        let mut merged = Merged::default();
        let skin = match (Content::is_skinned(p, prims), p.skin) {
            (true, Some(s)) => Some(self.skin_of(s, p.mesh, prims)?),
            _ => None,
        };
        let Some(skin) = skin else {
            merged.add(&prims.triangles, mesh_to_frame, &weights)?;
            let mut parts = merged.finish();
            if let Some(d) = &mut parts.data.deform {
                d.skin = None;
                if d.targets.is_empty() {
                    parts.data.deform = None;
                }
            }
            return Ok(parts);
        };
        merged.add(&prims.triangles, Mat4::IDENTITY, &weights)?;
        let mut parts = merged.finish();
        let joints: Vec<Mat4> = skin
            .joints
            .iter()
            .zip(&skin.inverse_bind)
            .map(|(&j, ibm)| to_frame * self.rest_worlds[j] * *ibm)
            .collect();
        if let Some(d) = &parts.data.deform {
            let mut normals = vec![[0.0; 3]; d.base_positions.len()];
            crate::geometry::deform::deform_with_tangents(
                d,
                &weights,
                crate::geometry::deform::Placing::Skin(&joints),
                &mut parts.positions,
                &mut normals,
                parts.data.tangents.as_deref_mut(),
            );
            parts.normals = Some(normals);
        }
        Ok(parts)
    }

    /// The names of the file's animations ("" where unnamed), in order.
    pub fn animation_names(&self) -> Vec<String> {
        animation_names(&self.doc.json)
    }

    /// Animation `i`.
    pub fn animation(&mut self, i: usize) -> Result<Animation, String> {
        self.doc.animation(i)
    }

    /// The node hierarchy with animation `i` (None: at rest).
    pub fn rig(&mut self, i: Option<usize>) -> Result<Rig, String> {
        let animation = i.map(|i| self.doc.animation(i)).transpose()?;
        Ok(Rig::new(self.nodes.clone(), animation))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::gltf::ChainSource;
    use crate::geometry::mesh::Mesh;
    use glam::Vec3;

    fn tools(file: &str) -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data/tools")
            .join(file)
    }

    fn source() -> Mesh {
        Mesh::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/bunny.obj")).unwrap()
    }

    /// Signed volume of a closed-enough mesh (its sign is the winding's).
    fn volume(m: &Mesh) -> f64 {
        m.indices
            .chunks_exact(3)
            .map(|t| {
                let [a, b, c] =
                    [0, 1, 2].map(|k| Vec3::from(m.positions[t[k] as usize]).as_dvec3());
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    /// `got` holds `copies` copies of the source bunny, the k-th moved by `k * spacing` along x: the triangle
    /// count, every vertex within `tol` of a source vertex so moved, the bounds within `tol`, and the signed
    /// volume (the winding) within 1 %.
    fn assert_copies(file: &str, got: &Mesh, copies: usize, spacing: f32, tol: f32) {
        let src = source();
        assert_eq!(
            got.triangle_count(),
            copies * src.triangle_count(),
            "{file}: triangles"
        );
        for (i, p) in got.positions.iter().enumerate() {
            let p = Vec3::from(*p);
            let k = (p.x / spacing).round().clamp(0.0, copies as f32 - 1.0);
            let q = p - Vec3::new(k * spacing, 0.0, 0.0);
            let near = src
                .positions
                .iter()
                .any(|s| Vec3::from(*s).abs_diff_eq(q, tol));
            assert!(near, "{file}: vertex {i} {p} is no source vertex");
        }
        let ((lo, hi), (slo, shi)) = (got.bounds(), src.bounds());
        let shi = shi + Vec3::new((copies as f32 - 1.0) * spacing, 0.0, 0.0);
        assert!(
            lo.abs_diff_eq(slo, tol) && hi.abs_diff_eq(shi, tol),
            "{file}: bounds {lo} {hi} against {slo} {shi}"
        );
        let (v, sv) = (volume(got), volume(&src) * copies as f64);
        assert!(
            (v / sv - 1.0).abs() < 0.01,
            "{file}: volume {v} against {sv}"
        );
    }

    /// The bunny as the tools write it (tests/data/README.md): float files give its vertices to 1e-6 a
    /// coordinate; quantised ones within one step of their 14-bit grid (both tools' default position precision:
    /// gltfpack stores unsigned shorts, glTF-Transform normalised shorts rounded to 14 bits) over the largest
    /// extent, 9.907 / 16383 = 6.05e-4 (the largest error measured is 4.1e-4, glTF-Transform's). The
    /// dequantisation's exact values are checked by `normalised_integers_dequantise_as_the_spec_says`.
    #[test]
    fn files_real_tools_write_give_the_source() {
        let q = 6.1e-4;
        for (file, tol) in [
            ("bunny-obj2gltf.glb", 1e-6),
            ("bunny-gltfpack-noq.glb", 1e-6),
            ("bunny-gltfpack.glb", q),
            ("bunny-gltfpack-c.glb", q),
            ("bunny-gltfpack-c-khr.glb", q),
            ("bunny-gt-quantize.glb", q),
            ("bunny-gt-meshopt.glb", q),
        ] {
            let m = Mesh::load(&tools(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
            assert_copies(file, &m, 1, 15.0, tol);
        }
    }

    /// Six bunnies 15 units apart: six nodes sharing a mesh, and one node with EXT_mesh_gpu_instancing, marked
    /// required or not (glTF-Transform's `instance` leaves it optional): all six are placed.
    #[test]
    fn instanced_files_place_every_instance() {
        for file in [
            "bunny-six-nodes.glb",
            "bunny-six-instanced-optional.glb",
            "bunny-six-instanced-required.glb",
        ] {
            let m = Mesh::load(&tools(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
            assert_copies(file, &m, 6, 15.0, 1e-5);
        }
        let bytes = std::fs::read(tools("bunny-six-instanced-required.glb")).unwrap();
        let c = read(&bytes, Path::new("")).unwrap();
        let instances: Vec<Option<usize>> = c.placements.iter().map(|p| p.instance).collect();
        assert_eq!(instances, (0..6).map(Some).collect::<Vec<_>>());
    }

    #[test]
    fn draco_is_refused_with_the_command_that_rewrites_it() {
        let msg = Mesh::load(&tools("bunny-gt-draco.glb"))
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("bunny-gt-draco.glb")
                && msg.contains("KHR_draco_mesh_compression")
                && msg.contains("gltf-transform/cli meshopt"),
            "{msg}"
        );
    }

    /// MSFT_lod (levels out of the scene, and in it as UnityGLTF writes them) and `_LODn` names are chains of
    /// three levels, never merged: `--mesh` refuses them, naming the chain.
    #[test]
    fn authored_chains_are_found_and_never_merged() {
        for (file, source, name, coverage) in [
            (
                "bunny-msft-lod.glb",
                ChainSource::MsftLod,
                "Bunny_LOD0",
                Some(vec![0.5, 0.2, 0.01]),
            ),
            (
                "bunny-msft-lod-in-scene.glb",
                ChainSource::MsftLod,
                "Bunny_LOD0",
                Some(vec![0.5, 0.2, 0.01]),
            ),
            ("bunny-lod-names.glb", ChainSource::LodNames, "Bunny", None),
        ] {
            let bytes = std::fs::read(tools(file)).unwrap();
            let mut c = read(&bytes, Path::new("")).unwrap();
            assert_eq!(c.chains.len(), 1, "{file}");
            let chain = &c.chains[0];
            assert_eq!(
                (chain.source, chain.name.as_str()),
                (source, name),
                "{file}"
            );
            assert_eq!(chain.screen_coverage, coverage, "{file}");
            assert_eq!(chain.nodes.len(), 3, "{file}");
            // Each level placed once, with its own mesh: 3674, 1836 and 918 triangles.
            let mut tris = Vec::new();
            for &n in &chain.nodes.clone() {
                let p: Vec<usize> = c
                    .placements
                    .iter()
                    .filter(|p| p.node == n)
                    .map(|p| p.mesh)
                    .collect();
                assert_eq!(p.len(), 1, "{file}: node {n}");
                tris.push(
                    c.mesh_primitives(p[0])
                        .unwrap()
                        .triangles
                        .iter()
                        .map(|t| t.indices.len() / 3)
                        .sum::<usize>(),
                );
            }
            assert_eq!(tris, [3674, 1836, 918], "{file}");
            let msg = Mesh::load(&tools(file)).unwrap_err().to_string();
            assert!(
                msg.contains(file) && msg.contains("authored LOD chain") && msg.contains(name),
                "{msg}"
            );
        }
    }

    /// An MSFT_lod id out of range, and one that loops back into the chain, are refused by node.
    #[test]
    fn bad_lod_ids_are_refused() {
        let doc = |ids: serde_json::Value| {
            serde_json::json!({
                "asset": {"version": "2.0"},
                "scenes": [{"nodes": [0]}],
                "nodes": [{"extensions": {"MSFT_lod": {"ids": ids}}}, {}],
            })
            .to_string()
        };
        let err = |ids| {
            read(doc(ids).as_bytes(), Path::new(""))
                .err()
                .unwrap_or_default()
        };
        let e = err(serde_json::json!([7]));
        assert!(
            e.contains("MSFT_lod id of node 0") && e.contains("not an index below 2"),
            "{e}"
        );
        let e = err(serde_json::json!([1, 0]));
        assert!(e.contains("cycle"), "{e}");
        let e = err(serde_json::json!([1, 1]));
        assert!(e.contains("cycle"), "{e}");
        assert!(read(doc(serde_json::json!([1])).as_bytes(), Path::new("")).is_ok());
    }

    /// A document with one mesh whose indices (and POSITION, unless `positions` is null: then 36 zero bytes
    /// uncompressed) come from meshopt-compressed views described by `positions` and `indices`
    /// (EXT_meshopt_compression objects over a 48-byte buffer of zeros).
    fn meshopt_doc(positions: serde_json::Value, indices: serde_json::Value) -> String {
        let position_view = match positions.is_null() {
            true => serde_json::json!({"buffer": 0, "byteLength": 36}),
            false => {
                serde_json::json!({"buffer": 0, "byteLength": positions["count"].as_u64().unwrap_or(0) * 12,
                "extensions": {"EXT_meshopt_compression": positions}})
            }
        };
        serde_json::json!({
            "asset": {"version": "2.0"},
            "extensionsUsed": ["EXT_meshopt_compression"],
            "buffers": [{"byteLength": 48, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA"}],
            "bufferViews": [
                position_view,
                {"buffer": 0, "byteLength": indices["count"].as_u64().unwrap_or(0) * 2,
                 "extensions": {"EXT_meshopt_compression": indices}},
            ],
            "accessors": [
                {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
                {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"},
            ],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
            "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0}],
        })
        .to_string()
    }

    /// What the meshopt decoders would allocate or assert on is refused first: a count that does not fit the
    /// view or the compressed bytes, TRIANGLES not in threes, a filter on indices.
    #[test]
    fn meshopt_streams_that_cannot_hold_their_count_are_refused() {
        let err = |p: serde_json::Value, i: serde_json::Value| {
            let doc = meshopt_doc(p, i);
            let mut c = read(doc.as_bytes(), Path::new("")).unwrap_or_else(|e| panic!("{e}"));
            c.mesh_primitives(0).err().unwrap_or_default()
        };
        let ok_pos = serde_json::Value::Null;
        let tri = |count: u64, filter: &str| {
            serde_json::json!({"buffer": 0, "byteLength": 8, "byteStride": 2, "mode": "TRIANGLES", "count": count,
                "filter": filter})
        };
        let huge = serde_json::json!({"buffer": 0, "byteLength": 8, "byteStride": 4, "mode": "ATTRIBUTES",
            "count": 1_000_000_000_000u64});
        let e = err(huge, tri(3, "NONE"));
        assert!(e.contains("is not the view's byteLength"), "{e}");
        let e = err(ok_pos.clone(), tri(4, "NONE"));
        assert!(e.contains("not a multiple of 3"), "{e}");
        let e = err(ok_pos.clone(), tri(3, "EXPONENTIAL"));
        assert!(e.contains("takes no filter"), "{e}");
        let e = err(ok_pos, tri(300, "NONE"));
        assert!(e.contains("cannot hold 300 elements"), "{e}");
    }

    /// A camera channel whose sampler has no keys is refused, not indexed.
    #[test]
    fn an_empty_camera_channel_is_refused() {
        let doc = serde_json::json!({
            "asset": {"version": "2.0"},
            "buffers": [{"byteLength": 8, "uri": "data:application/octet-stream;base64,AAAAAAAAAAA="}],
            "bufferViews": [{"buffer": 0, "byteLength": 8}],
            "accessors": [
                {"bufferView": 0, "componentType": 5126, "count": 0, "type": "SCALAR"},
                {"bufferView": 0, "componentType": 5126, "count": 0, "type": "VEC4"},
            ],
            "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}],
            "scenes": [{"nodes": [0]}],
            "nodes": [{"camera": 0}],
            "animations": [{"samplers": [{"input": 0, "output": 1}],
                "channels": [{"sampler": 0, "target": {"node": 0, "path": "rotation"}}]}],
        })
        .to_string();
        let mut c = read(doc.as_bytes(), Path::new("")).unwrap_or_else(|e| panic!("{e}"));
        let e = c.animated_camera().err().unwrap_or_default();
        assert!(e.contains("key times must be given"), "{e}");
    }
}
