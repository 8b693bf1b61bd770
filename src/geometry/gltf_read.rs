//! A glTF 2.0 reader (`.gltf` JSON or `.glb`) for the files real tools write: the JSON is read with serde_json
//! and the geometry decoded here, so that the extensions optimised assets carry are read rather than refused.
//!
//! Read: KHR_mesh_quantization (integer and normalised positions and normals, dequantised as glTF 2.0 section
//! 3.11 says), EXT_meshopt_compression and KHR_meshopt_compression (decoded with meshoptimizer, the `meshopt`
//! crate, filters included), EXT_mesh_gpu_instancing (each instance of a node is placed, whether the file
//! marks the extension required or not), and the authored LOD chains a file can hold (MSFT_lod on a node, or
//! sibling nodes named `NAME_LOD0`, `NAME_LOD1`, ... as Unity, Unreal and Godot importers name them), reported
//! as chains so that no caller merges their levels. Textures and images are never decoded, so extensions that
//! only change them (KHR_texture_transform, KHR_texture_basisu, EXT_texture_webp, ...) and the material
//! extensions are accepted even when required. Any other required extension is refused with its name and a
//! remedy (for Draco: the glTF-Transform command that rewrites the file with meshopt compression).

use glam::{Mat4, Quat, Vec3};
use serde_json::Value;
use std::borrow::Cow;
use std::path::Path;

/// The largest buffer view a meshopt-compressed view may decode to (1 GiB).
const MAX_VIEW_BYTES: usize = 1 << 30;

/// Extensions that change geometry or placement and that this reader decodes.
const READ: [&str; 5] = [
    "KHR_mesh_quantization",
    "EXT_meshopt_compression",
    "KHR_meshopt_compression",
    "EXT_mesh_gpu_instancing",
    "MSFT_lod",
];

/// Prefixes of extensions that only change materials, textures, lights or cameras: accepted unread.
const APPEARANCE: [&str; 5] = [
    "KHR_materials_",
    "KHR_texture_",
    "EXT_texture_",
    "KHR_lights_",
    "KHR_xmp",
];

/// One placement of a glTF mesh: the node (and, with EXT_mesh_gpu_instancing, the instance) that places it.
#[derive(Debug, Clone)]
pub struct Placement {
    pub node: usize,
    /// The node's name ("" when it has none).
    pub name: String,
    /// The instance within the node's EXT_mesh_gpu_instancing (None: the node itself).
    pub instance: Option<usize>,
    pub mesh: usize,
    /// Mesh space to world.
    pub world: Mat4,
}

/// Where an authored LOD chain was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChainSource {
    /// MSFT_lod on the LOD0 node (`ids`: the coarser levels' nodes).
    MsftLod,
    /// Sibling nodes named `NAME_LOD0`, `NAME_LOD1`, ...
    LodNames,
}

/// An authored LOD chain: one node per level, finest first.
#[derive(Debug, Clone)]
pub struct AuthoredChain {
    pub source: ChainSource,
    /// The LOD0 node's name, or the names' common stem.
    pub name: String,
    pub nodes: Vec<usize>,
    /// MSFT_lod's `extras.MSFT_screencoverage` on the LOD0 node, when present.
    pub screen_coverage: Option<Vec<f64>>,
    /// `extras.lodbench_switch_distances` on the LOD0 node (what `lodbench export` writes): exact switch
    /// distances, preferred to the screen coverage.
    pub switch_distances: Option<Vec<f32>>,
    /// `extras.lodbench_spin_per_frame` (windmill blades' turn per frame, radians), 0 without it.
    pub spin_per_frame: f32,
}

/// What a glTF file places in its scene.
pub struct Content<'a> {
    doc: Doc<'a>,
    /// Every mesh placement of the scene's node trees in document order, then MSFT_lod's coarser levels that
    /// are not in the scene (placed where their LOD0 node's parent is).
    pub placements: Vec<Placement>,
    pub chains: Vec<AuthoredChain>,
    /// The scene read (None: the file has no scenes and every mesh is placed untransformed).
    pub scene: Option<usize>,
    /// The scene's nodes: (node, parent's world matrix, world matrix).
    nodes: SceneNodes,
}

/// A camera node's animation (the first animated camera of the scene): keys in world space.
#[derive(Debug, Clone)]
pub struct AnimatedCamera {
    pub node: usize,
    /// The camera's vertical field of view, radians, and its clip planes (perspective cameras).
    pub yfov: Option<f32>,
    pub znear: Option<f32>,
    pub zfar: Option<f32>,
    /// (time s, eye, orientation): the camera looks along its local -z.
    pub keys: Vec<(f64, Vec3, Quat)>,
}

/// A primitive's triangles in mesh space, with its normals when the file has usable ones.
pub struct Triangles {
    pub positions: Vec<[f32; 3]>,
    pub normals: Option<Vec<[f32; 3]>>,
    pub indices: Vec<u32>,
    /// lodbench's own per-vertex shading extras (`_LODBENCH_AUX`, written by `lodbench export`).
    pub aux: Option<Vec<[f32; 4]>>,
}

/// The scene's nodes, depth first: (node, parent's world matrix, the node's world matrix).
type SceneNodes = Vec<(usize, Mat4, Mat4)>;

/// `NAME_LODn` nodes grouped by (parent, stem): their (level, node) pairs.
type NameGroups = Vec<((usize, String), Vec<(u32, usize)>)>;

/// Triangle primitives merged into one vertex and index list, each added under a transform: positions by it,
/// normals by its inverse transpose (kept while every primitive has normals and every transform is invertible),
/// the winding reversed under a mirroring transform (negative determinant, as glTF specifies), and lodbench's
/// shading extras (`_LODBENCH_AUX`, zeros for primitives without them) with the blades' hub height scaled by the
/// transform's scale along y.
#[derive(Debug)]
pub struct Merged {
    pub positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    all_normals: bool,
    aux: Option<Vec<[f32; 4]>>,
    pub indices: Vec<u32>,
}

impl Default for Merged {
    fn default() -> Self {
        Merged {
            positions: Vec::new(),
            normals: Vec::new(),
            all_normals: true,
            aux: None,
            indices: Vec::new(),
        }
    }
}

impl Merged {
    /// Adds `prims` placed by `transform`.
    pub fn add(&mut self, prims: &[Triangles], transform: Mat4) -> Result<(), String> {
        let linear = glam::Mat3::from_mat4(transform);
        let det = linear.determinant();
        let normal_matrix = linear.inverse().transpose();
        let y_scale = transform.transform_vector3(Vec3::Y).length();
        for prim in prims {
            let base = u32::try_from(self.positions.len())
                .ok()
                .zip(u32::try_from(prim.positions.len()).ok())
                .filter(|(b, n)| b.checked_add(*n).is_some())
                .map(|(b, _)| b)
                .ok_or_else(|| "has more vertices than 32-bit indices can address".to_string())?;
            self.positions.extend(
                prim.positions
                    .iter()
                    .map(|&v| transform.transform_point3(Vec3::from(v)).to_array()),
            );
            for t in prim.indices.chunks_exact(3) {
                let t = if det < 0.0 {
                    [t[0], t[2], t[1]]
                } else {
                    [t[0], t[1], t[2]]
                };
                self.indices.extend(t.iter().map(|&ix| base + ix));
            }
            match &prim.normals {
                Some(n) if self.all_normals && det != 0.0 && normal_matrix.is_finite() => {
                    self.normals.extend(n.iter().map(|&n| {
                        let n = normal_matrix * Vec3::from(n);
                        n.try_normalize().unwrap_or(n).to_array()
                    }));
                }
                _ => self.all_normals = false,
            }
            let scaled = |a: &[[f32; 4]]| -> Vec<[f32; 4]> {
                a.iter()
                    .map(|&[u, v, kind, hub]| [u, v, kind, hub * y_scale])
                    .collect()
            };
            match (&prim.aux, &mut self.aux) {
                (Some(a), Some(all)) => all.extend(scaled(a)),
                (Some(a), None) => {
                    let mut all = vec![[0.0; 4]; base as usize];
                    all.extend(scaled(a));
                    self.aux = Some(all);
                }
                (None, Some(all)) => {
                    all.extend(std::iter::repeat_n([0.0; 4], prim.positions.len()))
                }
                (None, None) => {}
            }
        }
        Ok(())
    }

    /// The normals, when every primitive had them under an invertible transform.
    pub fn normals(&mut self) -> Option<Vec<[f32; 3]>> {
        self.all_normals.then(|| std::mem::take(&mut self.normals))
    }

    /// The shading extras, when some primitive had them.
    pub fn aux(&mut self) -> Option<Vec<[f32; 4]>> {
        self.aux.take()
    }
}

/// The parsed document and its buffers.
struct Doc<'a> {
    json: Value,
    blob: Option<&'a [u8]>,
    dir: &'a Path,
    buffers: Vec<Option<Vec<u8>>>,
    /// Decoded meshopt-compressed buffer views, by view index.
    views: Vec<Option<Vec<u8>>>,
}

/// Reads the glTF (JSON or GLB) in `bytes`; external buffers are looked up in `dir`. Errors are problem texts
/// (the caller names the file).
pub fn read<'a>(bytes: &'a [u8], dir: &'a Path) -> Result<Content<'a>, String> {
    let (json, blob) = container(bytes).map_err(|e| format!("not a readable glTF file ({e})"))?;
    check_required(&json)?;
    let mut doc = Doc {
        buffers: vec![None; array(&json, "buffers").len()],
        views: vec![None; array(&json, "bufferViews").len()],
        json,
        blob,
        dir,
    };
    let (nodes, scene) = scene_nodes(&doc.json)?;
    let chains = chains(&doc.json, &nodes)?;
    let mut placements = Vec::new();
    match &nodes {
        None => {
            for mesh in 0..array(&doc.json, "meshes").len() {
                placements.push(Placement {
                    node: usize::MAX,
                    name: String::new(),
                    instance: None,
                    mesh,
                    world: Mat4::IDENTITY,
                });
            }
        }
        Some(nodes) => {
            for &(node, _, world) in nodes {
                doc.place(node, world, &mut placements)?;
            }
            // MSFT_lod's coarser levels need not be in the scene: a level outside it is placed under its LOD0
            // node's parent (the spec's LOD nodes replace the LOD0 node where it stands).
            for c in chains.iter().filter(|c| c.source == ChainSource::MsftLod) {
                let Some(&(_, parent, _)) = nodes.iter().find(|(n, _, _)| *n == c.nodes[0]) else {
                    continue;
                };
                for &n in &c.nodes[1..] {
                    if !nodes.iter().any(|(m, _, _)| *m == n) {
                        let local = node_matrix(&doc.json["nodes"][n])
                            .map_err(|e| format!("node {n}: {e}"))?;
                        doc.place(n, parent * local, &mut placements)?;
                    }
                }
            }
        }
    }
    Ok(Content {
        doc,
        placements,
        chains,
        scene,
        nodes: nodes.unwrap_or_default(),
    })
}

impl Content<'_> {
    /// The base colour factor (linear RGB) of the material of mesh `mesh`'s first primitive, if it has one.
    pub fn mesh_color(&self, mesh: usize) -> Option<[f32; 3]> {
        let json = &self.doc.json;
        let material = json["meshes"][mesh]["primitives"][0]["material"].as_u64()? as usize;
        let f = floats::<4>(
            &json["materials"][material]["pbrMetallicRoughness"]["baseColorFactor"],
            "baseColorFactor",
        )
        .ok()??;
        Some([f[0], f[1], f[2]].map(|c| c.clamp(0.0, 1.0)))
    }

    /// Mesh `mesh`'s name ("" when it has none).
    pub fn mesh_name(&self, mesh: usize) -> &str {
        self.doc.json["meshes"][mesh]["name"].as_str().unwrap_or("")
    }

    /// The first camera node of the scene whose translation or rotation is animated (its channels from the first
    /// animation that moves it), its keys resampled at the union of its channels' key times: LINEAR as glTF
    /// defines it; a STEP channel takes its held value at each key time and a CUBICSPLINE its values at its keys,
    /// and the path then joins the keys linearly (a stepped camera glides between its keys). The node's parents
    /// are taken at rest. None when no camera is animated.
    pub fn animated_camera(&mut self) -> Result<Option<AnimatedCamera>, String> {
        let json = self.doc.json.clone();
        let Some(&(node, parent, _)) = self
            .nodes
            .iter()
            .find(|(n, _, _)| json["nodes"][*n].get("camera").is_some() && animated(&json, *n))
        else {
            return Ok(None);
        };
        let what = format!("the animation of camera node {node}");
        let rest = &json["nodes"][node];
        let t0 = floats::<3>(&rest["translation"], "translation")?.unwrap_or([0.0; 3]);
        let r0 = floats::<4>(&rest["rotation"], "rotation")?.unwrap_or([0.0, 0.0, 0.0, 1.0]);
        let mut translation: Option<Track> = None;
        let mut rotation: Option<Track> = None;
        // The first animation that moves the camera (a file with several clips, as Blender writes one per
        // action, would otherwise mix their channels).
        let first = array(&json, "animations").iter().find(|a| {
            array(a, "channels")
                .iter()
                .any(|c| c["target"]["node"].as_u64() == Some(node as u64))
        });
        if let Some(anim) = first {
            for ch in array(anim, "channels") {
                if ch["target"]["node"].as_u64() != Some(node as u64) {
                    continue;
                }
                let (slot, width) = match ch["target"]["path"].as_str() {
                    Some("translation") => (&mut translation, 3),
                    Some("rotation") => (&mut rotation, 4),
                    _ => continue,
                };
                let sampler = ch["sampler"]
                    .as_u64()
                    .and_then(|i| array(anim, "samplers").get(i as usize));
                let sampler =
                    sampler.ok_or_else(|| format!("{what}: a channel names no sampler"))?;
                let input = sampler["input"]
                    .as_u64()
                    .ok_or_else(|| format!("{what}: a sampler has no input"))?;
                let output = sampler["output"]
                    .as_u64()
                    .ok_or_else(|| format!("{what}: a sampler has no output"))?;
                let (times, _) = self.doc.read_floats(input as usize)?;
                let (values, c) = self.doc.read_floats(output as usize)?;
                let mode = sampler["interpolation"].as_str().unwrap_or("LINEAR");
                let per_key = if mode == "CUBICSPLINE" { 3 } else { 1 };
                if c != width || values.len() != times.len() * width * per_key {
                    return Err(format!(
                        "{what}: a sampler's output does not match its {} keys",
                        times.len()
                    ));
                }
                if times.is_empty()
                    || times.iter().any(|t| !t.is_finite())
                    || times.windows(2).any(|w| w[1] <= w[0])
                {
                    return Err(format!("{what}: key times must be given and increase"));
                }
                let values: Vec<f32> = values
                    .chunks_exact(width * per_key)
                    .flat_map(|k| k[(per_key / 2) * width..(per_key / 2 + 1) * width].to_vec())
                    .collect();
                *slot = Some(Track {
                    times,
                    values,
                    width,
                    step: mode == "STEP",
                });
            }
        }
        let mut times: Vec<f32> = translation
            .iter()
            .chain(rotation.iter())
            .flat_map(|t| t.times.iter().copied())
            .collect();
        times.sort_by(f32::total_cmp);
        times.dedup();
        if times.len() < 2 {
            return Err(format!(
                "{what} has {} key time(s); a path needs at least two",
                times.len()
            ));
        }
        let (_, parent_rotation, _) = parent.to_scale_rotation_translation();
        let keys = times
            .iter()
            .map(|&t| {
                let tr = translation
                    .as_ref()
                    .map_or(Vec3::from(t0), |k| Vec3::from_slice(&k.at(t)));
                let ro = rotation
                    .as_ref()
                    .map_or(Quat::from_array(r0), |k| Quat::from_slice(&k.at(t)))
                    .normalize();
                (
                    f64::from(t),
                    parent.transform_point3(tr),
                    (parent_rotation * ro).normalize(),
                )
            })
            .collect();
        let perspective = |key: &str| {
            rest["camera"]
                .as_u64()
                .and_then(|c| json["cameras"][c as usize]["perspective"][key].as_f64())
                .filter(|v| v.is_finite() && *v > 0.0)
                .map(|f| f as f32)
        };
        Ok(Some(AnimatedCamera {
            node,
            yfov: perspective("yfov"),
            znear: perspective("znear"),
            zfar: perspective("zfar"),
            keys,
        }))
    }

    /// Whether `node` is a level of an authored chain.
    pub fn in_chain(&self, node: usize) -> bool {
        self.chains.iter().any(|c| c.nodes.contains(&node))
    }

    /// The triangle primitives of mesh `mesh` (TRIANGLES as they are, strips and fans triangulated, points and
    /// lines skipped), each in mesh space. Empty when the mesh has none.
    pub fn mesh_triangles(&mut self, mesh: usize) -> Result<Vec<Triangles>, String> {
        let prims = self.doc.json["meshes"][mesh]["primitives"].clone();
        let mut out = Vec::new();
        for (p, prim) in prims.as_array().into_iter().flatten().enumerate() {
            let mode = prim.get("mode").and_then(Value::as_u64).unwrap_or(4);
            if !(4..=6).contains(&mode) {
                continue;
            }
            let what = format!("mesh {mesh} primitive {p}");
            if prim
                .pointer("/extensions/KHR_draco_mesh_compression")
                .is_some()
            {
                return Err(format!("{what} is Draco-compressed; {}", DRACO_REMEDY));
            }
            let attrs = &prim["attributes"];
            let pos = attrs["POSITION"]
                .as_u64()
                .ok_or_else(|| format!("{what} has no POSITION attribute"))?
                as usize;
            let positions = self.doc.read_vec3(pos, &what, "positions")?;
            let normals = match attrs.get("NORMAL").and_then(Value::as_u64) {
                Some(n) => {
                    let n = self.doc.read_vec3(n as usize, &what, "normals")?;
                    if n.len() != positions.len() {
                        return Err(format!(
                            "{what} has {} normals for {} positions",
                            n.len(),
                            positions.len()
                        ));
                    }
                    Some(n)
                }
                None => None,
            };
            let aux = match attrs.get("_LODBENCH_AUX").and_then(Value::as_u64) {
                Some(a) => {
                    let (v, c) = self.doc.read_floats(a as usize)?;
                    if c != 4 || v.len() != positions.len() * 4 {
                        return Err(format!("{what}: _LODBENCH_AUX is not one VEC4 per vertex"));
                    }
                    Some(
                        v.chunks_exact(4)
                            .map(|a| [a[0], a[1], a[2], a[3]])
                            .collect(),
                    )
                }
                None => None,
            };
            let count = u32::try_from(positions.len())
                .map_err(|_| format!("{what} has too many vertices"))?;
            let order: Vec<u32> = match prim.get("indices").and_then(Value::as_u64) {
                Some(ix) => self.doc.read_indices(ix as usize, &what)?,
                None => (0..count).collect(),
            };
            if let Some(&bad) = order.iter().find(|&&ix| ix >= count) {
                return Err(format!(
                    "{what} uses vertex index {bad} but has {count} vertices"
                ));
            }
            let indices = triangulate(mode, &order).ok_or_else(|| {
                format!("{what} has {} indices, not a multiple of 3", order.len())
            })?;
            out.push(Triangles {
                positions,
                normals,
                indices,
                aux,
            });
        }
        Ok(out)
    }
}

/// Whether some animation channel moves `node` (translation or rotation).
fn animated(json: &Value, node: usize) -> bool {
    array(json, "animations").iter().any(|a| {
        array(a, "channels").iter().any(|c| {
            c["target"]["node"].as_u64() == Some(node as u64)
                && matches!(
                    c["target"]["path"].as_str(),
                    Some("translation" | "rotation")
                )
        })
    })
}

/// One animation channel's keys (values `width` wide).
struct Track {
    times: Vec<f32>,
    values: Vec<f32>,
    width: usize,
    step: bool,
}

impl Track {
    /// The value at time `t`: held before the first key and after the last, linear between keys (slerp for
    /// rotations, `width` 4), the earlier key's with STEP.
    fn at(&self, t: f32) -> Vec<f32> {
        let w = self.width;
        let key = |i: usize| &self.values[i * w..(i + 1) * w];
        let n = self.times.len();
        if t <= self.times[0] {
            return key(0).to_vec();
        }
        if t >= self.times[n - 1] {
            return key(n - 1).to_vec();
        }
        let i = self
            .times
            .windows(2)
            .position(|p| t < p[1])
            .unwrap_or(n - 2);
        if self.step {
            return key(i).to_vec();
        }
        let s = (t - self.times[i]) / (self.times[i + 1] - self.times[i]);
        if w == 4 {
            let (a, b) = (Quat::from_slice(key(i)), Quat::from_slice(key(i + 1)));
            return a.normalize().slerp(b.normalize(), s).to_array().to_vec();
        }
        key(i)
            .iter()
            .zip(key(i + 1))
            .map(|(a, b)| a + (b - a) * s)
            .collect()
    }
}

/// What a user can do with a Draco-compressed file.
const DRACO_REMEDY: &str = "lodbench does not decode Draco (KHR_draco_mesh_compression): rewrite the file with \
     meshopt compression, which it reads: `npx @gltf-transform/cli meshopt IN.glb OUT.glb` (gltfpack cannot read \
     Draco input)";

/// The JSON and the GLB binary chunk of `bytes`.
fn container(bytes: &[u8]) -> Result<(Value, Option<&[u8]>), String> {
    let json_of = |b: &[u8]| -> Result<Value, String> {
        let v: Value = serde_json::from_slice(b).map_err(|e| format!("invalid JSON: {e}"))?;
        match v.pointer("/asset/version").and_then(Value::as_str) {
            Some(ver) if ver.starts_with("2.") => Ok(v),
            Some(ver) => Err(format!("glTF version {ver}; lodbench reads glTF 2.0")),
            None => Err("no asset.version: not a glTF 2.0 document".into()),
        }
    };
    if !bytes.starts_with(b"glTF") {
        return Ok((json_of(bytes)?, None));
    }
    let word = |at: usize| -> Option<u32> {
        bytes
            .get(at..at + 4)
            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
    };
    let version = word(4).ok_or("GLB header truncated")?;
    if version != 2 {
        return Err(format!("GLB version {version}; lodbench reads version 2"));
    }
    let length = word(8).ok_or("GLB header truncated")? as usize;
    if length != bytes.len() {
        return Err(format!(
            "the GLB header says {length} bytes but the file has {}",
            bytes.len()
        ));
    }
    let (mut at, mut json, mut blob) = (12usize, None, None);
    while at < length {
        let (len, kind) = match (word(at), word(at + 4)) {
            (Some(l), Some(k)) => (l as usize, k),
            _ => return Err(format!("GLB chunk header at byte {at} truncated")),
        };
        let data = bytes
            .get(at + 8..at + 8 + len)
            .ok_or_else(|| format!("GLB chunk at byte {at} runs past the end of the file"))?;
        match (kind, json.is_none()) {
            (0x4E4F_534A, true) => json = Some(json_of(data)?),
            (_, true) => return Err("the first GLB chunk is not JSON".into()),
            (0x004E_4942, false) if blob.is_none() => blob = Some(data),
            _ => {}
        }
        at += 8 + len;
    }
    Ok((json.ok_or("GLB without a JSON chunk")?, blob))
}

/// Refuses a file that requires an extension this reader does not read.
fn check_required(json: &Value) -> Result<(), String> {
    for ext in array(json, "extensionsRequired") {
        let Some(name) = ext.as_str() else {
            continue;
        };
        if READ.contains(&name) || APPEARANCE.iter().any(|p| name.starts_with(p)) {
            continue;
        }
        if name == "KHR_draco_mesh_compression" {
            return Err(format!("requires {name}; {DRACO_REMEDY}"));
        }
        return Err(format!(
            "requires extension {name}, which lodbench does not read (it reads {} and ignores texture and \
             material extensions); export the file again without it, or rewrite it with `npx gltfpack -i IN.glb -o \
             OUT.glb -noq` where gltfpack reads the extension",
            READ.join(", ")
        ));
    }
    Ok(())
}

fn array<'v>(json: &'v Value, key: &str) -> &'v [Value] {
    json.get(key)
        .and_then(Value::as_array)
        .map_or(&[], Vec::as_slice)
}

fn index(v: &Value, what: impl FnOnce() -> String, len: usize) -> Result<usize, String> {
    match v.as_u64() {
        Some(i) if (i as usize) < len => Ok(i as usize),
        _ => Err(format!("{} is {v}, not an index below {len}", what())),
    }
}

fn floats<const N: usize>(v: &Value, what: &str) -> Result<Option<[f32; N]>, String> {
    let Some(a) = v.as_array() else {
        return match v {
            Value::Null => Ok(None),
            _ => Err(format!("{what} is not an array")),
        };
    };
    if a.len() != N {
        return Err(format!("{what} has {} numbers, not {N}", a.len()));
    }
    let mut out = [0.0f32; N];
    for (o, x) in out.iter_mut().zip(a) {
        *o = x
            .as_f64()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("{what} holds {x}, not a finite number"))? as f32;
    }
    Ok(Some(out))
}

/// A node's local matrix (its `matrix`, or translation x rotation x scale).
fn node_matrix(node: &Value) -> Result<Mat4, String> {
    if let Some(m) = floats::<16>(&node["matrix"], "a node's matrix")? {
        return Ok(Mat4::from_cols_array(&m));
    }
    let t = floats::<3>(&node["translation"], "a node's translation")?.unwrap_or([0.0; 3]);
    let r = floats::<4>(&node["rotation"], "a node's rotation")?.unwrap_or([0.0, 0.0, 0.0, 1.0]);
    let s = floats::<3>(&node["scale"], "a node's scale")?.unwrap_or([1.0; 3]);
    Ok(Mat4::from_scale_rotation_translation(
        Vec3::from(s),
        Quat::from_array(r).normalize(),
        Vec3::from(t),
    ))
}

/// The scene's nodes with their world matrices, depth first in document order, and the scene's index; None
/// when the file has no scenes.
fn scene_nodes(json: &Value) -> Result<(Option<SceneNodes>, Option<usize>), String> {
    let scenes = array(json, "scenes");
    if scenes.is_empty() {
        return Ok((None, None));
    }
    let s = match json.get("scene") {
        Some(v) => index(v, || "scene".into(), scenes.len())?,
        None => 0,
    };
    let nodes = array(json, "nodes");
    let mut seen = vec![false; nodes.len()];
    let mut stack: Vec<(usize, Mat4)> = Vec::new();
    for v in array(&scenes[s], "nodes").iter().rev() {
        stack.push((
            index(v, || format!("a node of scene {s}"), nodes.len())?,
            Mat4::IDENTITY,
        ));
    }
    let mut out = Vec::new();
    while let Some((n, parent)) = stack.pop() {
        if std::mem::replace(&mut seen[n], true) {
            return Err(format!(
                "node {n} is reached twice from scene {s} (glTF node hierarchies must be trees)"
            ));
        }
        let world = parent * node_matrix(&nodes[n]).map_err(|e| format!("node {n}: {e}"))?;
        out.push((n, parent, world));
        for c in array(&nodes[n], "children").iter().rev() {
            stack.push((
                index(c, || format!("a child of node {n}"), nodes.len())?,
                world,
            ));
        }
    }
    Ok((Some(out), Some(s)))
}

/// The authored LOD chains among the scene's nodes.
fn chains(json: &Value, nodes: &Option<SceneNodes>) -> Result<Vec<AuthoredChain>, String> {
    let all = array(json, "nodes");
    let mut out = Vec::new();
    // Without scenes every mesh is placed untransformed and no node is read; otherwise only the scene's nodes
    // can hold a chain.
    let Some(nodes) = nodes else {
        return Ok(out);
    };
    for (n, node) in all.iter().enumerate() {
        let Some(ids) = node.pointer("/extensions/MSFT_lod/ids") else {
            continue;
        };
        if !nodes.iter().any(|(m, _, _)| *m == n) {
            continue;
        }
        let mut chain = vec![n];
        for id in ids.as_array().map_or(&[][..], Vec::as_slice) {
            let id = index(id, || format!("an MSFT_lod id of node {n}"), all.len())?;
            if chain.contains(&id) || all[id].pointer("/extensions/MSFT_lod").is_some() {
                return Err(format!(
                    "node {n}'s MSFT_lod lists node {id}, which is already a level of the chain or has a chain \
                     of its own (a cycle)"
                ));
            }
            chain.push(id);
        }
        let numbers = |key: &str| -> Result<Option<Vec<f64>>, String> {
            let Some(v) = node.pointer(&format!("/extras/{key}")) else {
                return Ok(None);
            };
            v.as_array()
                .and_then(|a| a.iter().map(Value::as_f64).collect::<Option<Vec<f64>>>())
                .filter(|a| a.iter().all(|x| x.is_finite()))
                .map(Some)
                .ok_or_else(|| format!("node {n}'s extras.{key} is not an array of numbers"))
        };
        let screen_coverage = numbers("MSFT_screencoverage")?;
        let switch_distances =
            numbers("lodbench_switch_distances")?.map(|a| a.iter().map(|&d| d as f32).collect());
        out.push(AuthoredChain {
            source: ChainSource::MsftLod,
            name: node["name"].as_str().unwrap_or("").to_string(),
            nodes: chain,
            screen_coverage,
            switch_distances,
            spin_per_frame: node
                .pointer("/extras/lodbench_spin_per_frame")
                .and_then(Value::as_f64)
                .unwrap_or(0.0) as f32,
        });
    }
    refuse_level_children(all, &out)?;
    // `NAME_LODn` siblings: group the scene's nodes by parent and stem.
    let mut parent = vec![usize::MAX; all.len()];
    for (p, node) in all.iter().enumerate() {
        for c in array(node, "children") {
            if let Some(c) = c.as_u64().filter(|&c| (c as usize) < all.len()) {
                parent[c as usize] = p;
            }
        }
    }
    let mut groups: NameGroups = Vec::new();
    let in_msft: Vec<usize> = out.iter().flat_map(|c| c.nodes.iter().copied()).collect();
    for &(n, _, _) in nodes {
        if in_msft.contains(&n) {
            continue;
        }
        let Some(name) = all[n]["name"].as_str() else {
            continue;
        };
        let Some((stem, level)) = lod_name(name) else {
            continue;
        };
        let key = (parent[n], stem.to_string());
        match groups.iter_mut().find(|(k, _)| *k == key) {
            Some((_, levels)) => levels.push((level, n)),
            None => groups.push((key, vec![(level, n)])),
        }
    }
    for ((_, stem), mut levels) in groups {
        if levels.len() < 2 {
            continue;
        }
        levels.sort();
        if levels.windows(2).any(|w| w[0].0 == w[1].0) || levels[0].0 != 0 {
            return Err(format!(
                "the nodes named {stem}_LODn have levels {:?}: an authored chain needs LOD0 and each level once",
                levels.iter().map(|l| l.0).collect::<Vec<_>>()
            ));
        }
        out.push(AuthoredChain {
            source: ChainSource::LodNames,
            name: stem,
            nodes: levels.into_iter().map(|l| l.1).collect(),
            screen_coverage: None,
            switch_distances: None,
            spin_per_frame: 0.0,
        });
    }
    refuse_level_children(all, &out)?;
    Ok(out)
}

/// A chain's level is its node's own mesh: a level node with children is refused (their meshes would be drawn
/// at every distance, or lost with the level).
fn refuse_level_children(all: &[Value], chains: &[AuthoredChain]) -> Result<(), String> {
    for c in chains {
        if let Some(&n) = c
            .nodes
            .iter()
            .find(|&&n| !array(&all[n], "children").is_empty())
        {
            return Err(format!(
                "LOD chain '{}': level node {n} has child nodes; lodbench takes each level's own mesh, so put \
                 each level's geometry in its node's mesh",
                c.name
            ));
        }
    }
    Ok(())
}

/// `NAME_LOD3` (also `_lod3`, `-LOD3`): the stem and the level.
fn lod_name(name: &str) -> Option<(&str, u32)> {
    let lower = name.to_ascii_lowercase();
    let at = lower.rfind("lod")?;
    let level: u32 = lower[at + 3..].parse().ok()?;
    let stem = name[..at].strip_suffix(['_', '-'])?;
    (!stem.is_empty()).then_some((stem, level))
}

/// The triangle list of a TRIANGLES (4), TRIANGLE_STRIP (5) or TRIANGLE_FAN (6) primitive's vertex order (glTF
/// 2.0 section 3.7.2.1); `None` for a TRIANGLES list whose length is not a multiple of 3.
pub fn triangulate(mode: u64, order: &[u32]) -> Option<Vec<u32>> {
    let n = order.len();
    match mode {
        5 => Some(
            (0..n.saturating_sub(2))
                .flat_map(|i| {
                    let odd = i % 2;
                    [order[i], order[i + 1 + odd], order[i + 2 - odd]]
                })
                .collect(),
        ),
        6 => Some(
            (1..n.saturating_sub(1))
                .flat_map(|i| [order[i], order[i + 1], order[0]])
                .collect(),
        ),
        _ => n.is_multiple_of(3).then(|| order.to_vec()),
    }
}

/// An accessor's layout.
struct Layout {
    view: usize,
    offset: usize,
    count: usize,
    component: u64,
    components: usize,
    normalized: bool,
}

fn component_size(c: u64) -> Option<usize> {
    match c {
        5120 | 5121 => Some(1),
        5122 | 5123 => Some(2),
        5125 | 5126 => Some(4),
        _ => None,
    }
}

fn component_name(c: u64) -> &'static str {
    match c {
        5120 => "byte",
        5121 => "unsigned byte",
        5122 => "short",
        5123 => "unsigned short",
        5125 => "unsigned int",
        5126 => "float",
        _ => "unknown",
    }
}

impl Doc<'_> {
    /// The placements of node `n` at `world` (the node alone: its children are in the scene's list): its mesh,
    /// once, or once per EXT_mesh_gpu_instancing instance (instance transform applied before the node's).
    fn place(&mut self, n: usize, world: Mat4, out: &mut Vec<Placement>) -> Result<(), String> {
        let node = self.json["nodes"][n].clone();
        let Some(m) = node.get("mesh") else {
            return Ok(());
        };
        let mesh = index(
            m,
            || format!("node {n}'s mesh"),
            array(&self.json, "meshes").len(),
        )?;
        let name = node["name"].as_str().unwrap_or("").to_string();
        let Some(attrs) = node.pointer("/extensions/EXT_mesh_gpu_instancing/attributes") else {
            out.push(Placement {
                node: n,
                name,
                instance: None,
                mesh,
                world,
            });
            return Ok(());
        };
        let what = format!("node {n}'s EXT_mesh_gpu_instancing");
        let mut read = |key: &str, components: usize| -> Result<Option<Vec<f32>>, String> {
            let Some(a) = attrs.get(key) else {
                return Ok(None);
            };
            let a = a
                .as_u64()
                .ok_or_else(|| format!("{what}: {key} is not an accessor index"))?
                as usize;
            let (v, c) = self.read_floats(a)?;
            if c != components {
                return Err(format!(
                    "{what}: {key} has {c} components, not {components}"
                ));
            }
            Ok(Some(v))
        };
        let t = read("TRANSLATION", 3)?;
        let r = read("ROTATION", 4)?;
        let s = read("SCALE", 3)?;
        let counts: Vec<usize> = [(&t, 3), (&r, 4), (&s, 3)]
            .iter()
            .filter_map(|(v, c)| v.as_ref().map(|v| v.len() / c))
            .collect();
        let Some(&count) = counts.first() else {
            return Err(format!("{what} has none of TRANSLATION, ROTATION, SCALE"));
        };
        if counts.iter().any(|&c| c != count) {
            return Err(format!(
                "{what}'s attributes have different instance counts {counts:?}"
            ));
        }
        for i in 0..count {
            let tr = t
                .as_ref()
                .map_or(Vec3::ZERO, |v| Vec3::from_slice(&v[3 * i..]));
            let ro = r.as_ref().map_or(Quat::IDENTITY, |v| {
                Quat::from_slice(&v[4 * i..]).normalize()
            });
            let sc = s
                .as_ref()
                .map_or(Vec3::ONE, |v| Vec3::from_slice(&v[3 * i..]));
            if !(tr.is_finite() && ro.is_finite() && sc.is_finite()) {
                return Err(format!("{what}: instance {i} has a non-finite transform"));
            }
            out.push(Placement {
                node: n,
                name: name.clone(),
                instance: Some(i),
                mesh,
                world: world * Mat4::from_scale_rotation_translation(sc, ro, tr),
            });
        }
        Ok(())
    }

    fn layout(&self, i: usize) -> Result<Layout, String> {
        let accessors = array(&self.json, "accessors");
        let a = accessors.get(i).ok_or_else(|| {
            format!(
                "accessor {i} does not exist ({} accessors)",
                accessors.len()
            )
        })?;
        if a.get("sparse").is_some() {
            return Err(format!(
                "accessor {i} is sparse, which lodbench does not read"
            ));
        }
        let view = match a.get("bufferView") {
            Some(v) => index(v, || format!("accessor {i}'s bufferView"), self.views.len())?,
            None => return Err(format!("accessor {i} has no buffer view")),
        };
        let component = a["componentType"].as_u64().unwrap_or(0);
        if component_size(component).is_none() {
            return Err(format!(
                "accessor {i} has componentType {component}, which glTF does not define"
            ));
        }
        let components = match a["type"].as_str() {
            Some("SCALAR") => 1,
            Some("VEC2") => 2,
            Some("VEC3") => 3,
            Some("VEC4") => 4,
            other => {
                return Err(format!(
                    "accessor {i} has type {}, where lodbench reads SCALAR and VEC2-4",
                    other.unwrap_or("(none)")
                ))
            }
        };
        Ok(Layout {
            view,
            offset: a["byteOffset"].as_u64().unwrap_or(0) as usize,
            count: a["count"].as_u64().unwrap_or(0) as usize,
            component,
            components,
            normalized: a["normalized"].as_bool().unwrap_or(false),
        })
    }

    /// The bytes of buffer `b`.
    fn buffer(&mut self, b: usize) -> Result<&[u8], String> {
        let n = self.buffers.len();
        if b >= n {
            return Err(format!("buffer {b} does not exist ({n} buffers)"));
        }
        if self.buffers[b].is_none() {
            let desc = &self.json["buffers"][b];
            let declared = desc["byteLength"].as_u64().unwrap_or(0) as usize;
            let data: Vec<u8> = match desc["uri"].as_str() {
                Some(uri) => read_buffer_uri(b, uri, self.dir)?,
                None if b == 0 => self
                    .blob
                    .ok_or_else(|| {
                        format!("buffer {b} refers to the GLB binary chunk, which the file does not have")
                    })?
                    .to_vec(),
                None if desc.pointer("/extensions/EXT_meshopt_compression/fallback").is_some()
                    || desc.pointer("/extensions/KHR_meshopt_compression/fallback").is_some() =>
                {
                    return Err(format!(
                        "buffer {b} is a meshopt fallback buffer without data, read by a buffer view that is not \
                         compressed"
                    ))
                }
                None => return Err(format!("buffer {b} has no uri and is not the GLB binary chunk")),
            };
            if data.len() < declared {
                return Err(format!(
                    "buffer {b} holds {} bytes but declares byteLength {declared}",
                    data.len()
                ));
            }
            self.buffers[b] = Some(data);
        }
        Ok(self.buffers[b].as_deref().unwrap_or(&[]))
    }

    /// Buffer view `v`'s bytes (decoded when meshopt-compressed) and its stride.
    fn view(&mut self, v: usize) -> Result<(Cow<'_, [u8]>, Option<usize>), String> {
        let desc = self.json["bufferViews"][v].clone();
        let stride = desc["byteStride"].as_u64().map(|s| s as usize);
        let compressed = desc
            .pointer("/extensions/EXT_meshopt_compression")
            .or_else(|| desc.pointer("/extensions/KHR_meshopt_compression"))
            .cloned();
        if let Some(ext) = compressed {
            if self.views[v].is_none() {
                let view_length = desc["byteLength"].as_u64().unwrap_or(0) as usize;
                let decoded = self.decode_meshopt(v, &ext, view_length)?;
                self.views[v] = Some(decoded);
            }
            return Ok((
                Cow::Borrowed(self.views[v].as_deref().unwrap_or(&[])),
                stride,
            ));
        }
        let b = index(
            &desc["buffer"],
            || format!("buffer view {v}'s buffer"),
            self.buffers.len(),
        )?;
        let offset = desc["byteOffset"].as_u64().unwrap_or(0) as usize;
        let length = desc["byteLength"].as_u64().unwrap_or(0) as usize;
        let data = self.buffer(b)?;
        let have = data.len();
        let bytes = offset
            .checked_add(length)
            .and_then(|end| data.get(offset..end))
            .ok_or_else(|| {
                format!("buffer view {v} reaches past the end of buffer {b} ({have} bytes)")
            })?;
        Ok((Cow::Borrowed(bytes), stride))
    }

    /// EXT_ or KHR_meshopt_compression: the view's decoded bytes (count x byteStride).
    fn decode_meshopt(
        &mut self,
        v: usize,
        ext: &Value,
        view_length: usize,
    ) -> Result<Vec<u8>, String> {
        let what = format!("buffer view {v} (meshopt-compressed)");
        let b = index(
            &ext["buffer"],
            || format!("{what}: buffer"),
            self.buffers.len(),
        )?;
        let offset = ext["byteOffset"].as_u64().unwrap_or(0) as usize;
        let length = ext["byteLength"].as_u64().unwrap_or(0) as usize;
        let stride = ext["byteStride"].as_u64().unwrap_or(0) as usize;
        let count = ext["count"].as_u64().unwrap_or(0) as usize;
        let mode = ext["mode"].as_str().unwrap_or("");
        let filter = ext["filter"].as_str().unwrap_or("NONE");
        let data = self.buffer(b)?;
        let src = offset
            .checked_add(length)
            .and_then(|end| data.get(offset..end))
            .ok_or_else(|| format!("{what} reaches past the end of buffer {b}"))?;
        // The decoders allocate count x stride before they look at the data: the size must be the view's
        // (as the extension requires), and the compressed stream long enough for the count it claims.
        if count.checked_mul(stride) != Some(view_length) || view_length > MAX_VIEW_BYTES {
            return Err(format!(
                "{what}: count {count} x byteStride {stride} is not the view's byteLength {view_length} (or over \
                 {MAX_VIEW_BYTES} bytes)"
            ));
        }
        let index_mode = matches!(mode, "TRIANGLES" | "INDICES");
        if index_mode && filter != "NONE" {
            return Err(format!("{what}: mode {mode} takes no filter ({filter})"));
        }
        if mode == "TRIANGLES" && !count.is_multiple_of(3) {
            return Err(format!(
                "{what}: TRIANGLES with count {count}, not a multiple of 3"
            ));
        }
        let least = match mode {
            "TRIANGLES" => 17 + count / 3,
            "INDICES" => 5 + count,
            _ => 1,
        };
        if src.len() < least {
            return Err(format!(
                "{what}: {} compressed bytes cannot hold {count} elements",
                src.len()
            ));
        }
        let fail = |e: meshopt::Error| format!("{what} does not decode ({e})");
        let mut out = match (mode, stride) {
            ("ATTRIBUTES", s) if s > 0 && s % 4 == 0 && s <= 256 => decode_vertices(src, count, s)?,
            ("TRIANGLES", 2) => bytemuck::cast_slice(&meshopt::decode_index_buffer::<u16>(src, count).map_err(fail)?).to_vec(),
            ("TRIANGLES", 4) => bytemuck::cast_slice(&meshopt::decode_index_buffer::<u32>(src, count).map_err(fail)?).to_vec(),
            ("INDICES", 2) => bytemuck::cast_slice(&meshopt::decode_index_sequence::<u16>(src, count).map_err(fail)?).to_vec(),
            ("INDICES", 4) => bytemuck::cast_slice(&meshopt::decode_index_sequence::<u32>(src, count).map_err(fail)?).to_vec(),
            _ => return Err(format!("{what} has mode {mode:?} with byteStride {stride}, which the extension does not allow")),
        };
        unfilter(&mut out, filter, stride).map_err(|e| format!("{what}: {e}"))?;
        Ok(out)
    }

    /// The bytes of accessor `i`'s buffer view (laid out as `l`) and its stride, checked to hold every element:
    /// a stride that holds an element, and the last element inside the view.
    fn elements(&mut self, i: usize, l: &Layout) -> Result<(Cow<'_, [u8]>, usize), String> {
        let elem = component_size(l.component).unwrap_or(4) * l.components;
        let (bytes, stride) = self.view(l.view)?;
        let stride = stride.unwrap_or(elem);
        if stride < elem {
            return Err(format!(
                "buffer view {} has stride {stride}, less than accessor {i}'s {elem}-byte elements",
                l.view
            ));
        }
        let end = l
            .count
            .checked_sub(1)
            .and_then(|n| n.checked_mul(stride))
            .and_then(|n| n.checked_add(elem))
            .and_then(|n| n.checked_add(l.offset));
        if l.count > 0 && end.is_none_or(|end| end > bytes.len()) {
            return Err(format!(
                "accessor {i} ({} elements) does not fit in buffer view {}",
                l.count, l.view
            ));
        }
        Ok((bytes, stride))
    }

    /// Accessor `i`'s elements as floats (integers dequantised: normalised ones to [-1, 1] or [0, 1], others
    /// as their value).
    fn read_floats(&mut self, i: usize) -> Result<(Vec<f32>, usize), String> {
        let l = self.layout(i)?;
        let size = component_size(l.component).unwrap_or(4);
        let (bytes, stride) = self.elements(i, &l)?;
        let mut out = Vec::with_capacity(l.count * l.components);
        for e in 0..l.count {
            let at = l.offset + e * stride;
            for c in 0..l.components {
                let b = &bytes[at + c * size..at + (c + 1) * size];
                out.push(component(b, l.component, l.normalized));
            }
        }
        Ok((out, l.components))
    }

    /// A VEC3 attribute (`kind`: "positions", "normals") of `what`.
    fn read_vec3(&mut self, i: usize, what: &str, kind: &str) -> Result<Vec<[f32; 3]>, String> {
        let l = self.layout(i)?;
        if l.components != 3 {
            return Err(format!(
                "{what} has {}-component {kind}; glTF {kind} are VEC3",
                l.components
            ));
        }
        let (v, _) = self.read_floats(i)?;
        Ok(v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
    }

    fn read_indices(&mut self, i: usize, what: &str) -> Result<Vec<u32>, String> {
        let l = self.layout(i)?;
        if !matches!(l.component, 5121 | 5123 | 5125) || l.components != 1 || l.normalized {
            return Err(format!(
                "{what} has {} indices of {} components; glTF indices are unsigned integer scalars",
                component_name(l.component),
                l.components
            ));
        }
        let size = component_size(l.component).unwrap_or(4);
        let (bytes, stride) = self.elements(i, &l)?;
        // Read as integers: through f32 an index above 2^24 would round.
        Ok((0..l.count)
            .map(|e| {
                let b = &bytes[l.offset + e * stride..];
                match size {
                    1 => u32::from(b[0]),
                    2 => u32::from(u16::from_le_bytes([b[0], b[1]])),
                    _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                }
            })
            .collect())
    }
}

/// One component of an accessor element as f32 (glTF 2.0 section 3.11 for normalised integers).
fn component(b: &[u8], kind: u64, normalized: bool) -> f32 {
    match (kind, normalized) {
        (5126, _) => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        (5125, _) => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
        (5120, false) => b[0] as i8 as f32,
        (5120, true) => (b[0] as i8 as f32 / 127.0).max(-1.0),
        (5121, false) => b[0] as f32,
        (5121, true) => b[0] as f32 / 255.0,
        (5122, false) => i16::from_le_bytes([b[0], b[1]]) as f32,
        (5122, true) => (i16::from_le_bytes([b[0], b[1]]) as f32 / 32767.0).max(-1.0),
        (5123, false) => u16::from_le_bytes([b[0], b[1]]) as f32,
        _ => u16::from_le_bytes([b[0], b[1]]) as f32 / 65535.0,
    }
}

/// `count` vertices of `stride` bytes from meshoptimizer's vertex codec.
fn decode_vertices(src: &[u8], count: usize, stride: usize) -> Result<Vec<u8>, String> {
    #[derive(Clone, Copy)]
    #[repr(transparent)]
    struct Bytes<const N: usize>([u8; N]);
    impl<const N: usize> Default for Bytes<N> {
        fn default() -> Self {
            Bytes([0; N])
        }
    }
    fn run<const N: usize>(src: &[u8], count: usize) -> Result<Vec<u8>, String> {
        let v: Vec<Bytes<N>> = meshopt::decode_vertex_buffer(src, count)
            .map_err(|e| format!("the vertex stream does not decode ({e})"))?;
        Ok(v.into_iter().flat_map(|b| b.0).collect())
    }
    macro_rules! by_stride {
        ($($n:literal)*) => {
            match stride {
                $($n => run::<$n>(src, count),)*
                _ => Err(format!("byteStride {stride} is not a multiple of 4 up to 256")),
            }
        };
    }
    by_stride!(4 8 12 16 20 24 28 32 36 40 44 48 52 56 60 64 68 72 76 80 84 88 92 96 100 104 108 112 116 120 124 128
        132 136 140 144 148 152 156 160 164 168 172 176 180 184 188 192 196 200 204 208 212 216 220 224 228 232
        236 240 244 248 252 256)
}

/// Undoes a meshopt filter in place (EXT_meshopt_compression's filters, and KHR's COLOR).
fn unfilter(data: &mut [u8], filter: &str, stride: usize) -> Result<(), String> {
    fn apply<T: bytemuck::Pod>(data: &mut [u8], f: impl FnOnce(&mut [T])) {
        let mut v: Vec<T> = data
            .chunks_exact(std::mem::size_of::<T>())
            .map(bytemuck::pod_read_unaligned)
            .collect();
        f(&mut v);
        data.copy_from_slice(bytemuck::cast_slice(&v));
    }
    match (filter, stride) {
        ("NONE", _) => {}
        ("OCTAHEDRAL", 4) => apply::<[i8; 4]>(data, meshopt::decode_filter_oct),
        ("OCTAHEDRAL", 8) => apply::<[i16; 4]>(data, meshopt::decode_filter_oct),
        ("QUATERNION", 8) => apply::<[i16; 4]>(data, meshopt::decode_filter_quat),
        ("EXPONENTIAL", 4) => apply::<[u32; 1]>(data, meshopt::decode_filter_exp),
        ("EXPONENTIAL", 8) => apply::<[u32; 2]>(data, meshopt::decode_filter_exp),
        ("EXPONENTIAL", 12) => apply::<[u32; 3]>(data, meshopt::decode_filter_exp),
        ("EXPONENTIAL", 16) => apply::<[u32; 4]>(data, meshopt::decode_filter_exp),
        ("COLOR", 4) => apply::<[u8; 4]>(data, meshopt::decode_filter_color),
        ("COLOR", 8) => apply::<[u16; 4]>(data, meshopt::decode_filter_color),
        _ => {
            return Err(format!(
                "filter {filter} with byteStride {stride} is not one lodbench decodes"
            ))
        }
    }
    Ok(())
}

/// A buffer's bytes from a `data:` URI or a file relative to `dir`.
pub fn read_buffer_uri(i: usize, uri: &str, dir: &Path) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (header, payload) = rest
            .split_once(',')
            .ok_or_else(|| format!("buffer {i} has a data: URI without a ','"))?;
        let bytes = if header.ends_with(";base64") {
            decode_base64(payload)
        } else {
            percent_decode(payload)
        };
        return bytes.ok_or_else(|| format!("buffer {i} has a data: URI that does not decode"));
    }
    let scheme = uri.split_once(':').map(|(s, _)| s);
    if scheme.is_some_and(|s| {
        s.len() > 1
            && s.starts_with(|c: char| c.is_ascii_alphabetic())
            && s.chars()
                .all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'))
    }) {
        return Err(format!(
            "buffer {i} has URI '{uri}': lodbench reads only data: URIs and relative file paths"
        ));
    }
    let relative = percent_decode(uri)
        .and_then(|b| String::from_utf8(b).ok())
        .ok_or_else(|| format!("buffer {i} has URI '{uri}', which is not a valid file path"))?;
    let file = dir.join(relative);
    std::fs::read(&file).map_err(|e| {
        if e.kind() == std::io::ErrorKind::NotFound {
            format!("buffer {i} file {} not found", file.display())
        } else {
            format!("buffer {i} file {} cannot be read ({e})", file.display())
        }
    })
}

/// Standard or URL-safe base64 (the two alphabets may mix), padding optional; `None` for any other character
/// or a length no base64 text has. Bits left over after the last whole byte are ignored.
pub fn decode_base64(text: &str) -> Option<Vec<u8>> {
    use base64::engine::{general_purpose, DecodePaddingMode, Engine, GeneralPurpose};
    const ENGINE: GeneralPurpose = GeneralPurpose::new(
        &base64::alphabet::STANDARD,
        general_purpose::NO_PAD
            .with_decode_padding_mode(DecodePaddingMode::RequireNone)
            .with_decode_allow_trailing_bits(true),
    );
    let standard: String = text
        .trim_end_matches('=')
        .chars()
        .map(|c| match c {
            '-' => '+',
            '_' => '/',
            c => c,
        })
        .collect();
    ENGINE.decode(standard).ok()
}

/// Decodes `%XX` escapes; `None` for a `%` not followed by two hex digits.
pub fn percent_decode(text: &str) -> Option<Vec<u8>> {
    // The crate leaves a malformed escape as it is; a URI with one is refused instead.
    let b = text.as_bytes();
    let malformed = b.iter().enumerate().any(|(i, &c)| {
        c == b'%'
            && !b
                .get(i + 1..i + 3)
                .is_some_and(|hex| hex.iter().all(u8::is_ascii_hexdigit))
    });
    (!malformed).then(|| percent_encoding::percent_decode(b).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::mesh::Mesh;

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
                    c.mesh_triangles(p[0])
                        .unwrap()
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

    /// glTF 2.0 section 3.11: f = max(c / 127, -1) for bytes, c / 255 for unsigned bytes, max(c / 32767, -1)
    /// for shorts, c / 65535 for unsigned shorts; integers that are not normalised keep their value.
    #[test]
    fn normalised_integers_dequantise_as_the_spec_says() {
        let short = |v: i16| v.to_le_bytes();
        assert_eq!(component(&short(32767), 5122, true), 1.0);
        assert_eq!(component(&short(-32767), 5122, true), -1.0);
        assert_eq!(component(&short(-32768), 5122, true), -1.0);
        assert_eq!(component(&short(16384), 5122, true), 16384.0 / 32767.0);
        assert_eq!(component(&short(-7), 5122, false), -7.0);
        assert_eq!(component(&65535u16.to_le_bytes(), 5123, true), 1.0);
        assert_eq!(component(&1000u16.to_le_bytes(), 5123, false), 1000.0);
        assert_eq!(component(&[127], 5120, true), 1.0);
        assert_eq!(component(&[0x80], 5120, true), -1.0);
        assert_eq!(component(&[0x81], 5120, false), -127.0);
        assert_eq!(component(&[255], 5121, true), 1.0);
        assert_eq!(component(&[51], 5121, true), 0.2);
        assert_eq!(component(&1.5f32.to_le_bytes(), 5126, true), 1.5);
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
            c.mesh_triangles(0).err().unwrap_or_default()
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

    #[test]
    fn lod_names() {
        assert_eq!(lod_name("Rock_LOD0"), Some(("Rock", 0)));
        assert_eq!(lod_name("SM_Rock_lod12"), Some(("SM_Rock", 12)));
        assert_eq!(lod_name("tree-LOD2"), Some(("tree", 2)));
        assert_eq!(lod_name("LOD1"), None);
        assert_eq!(lod_name("Rock_LODx"), None);
        assert_eq!(lod_name("Melody"), None);
    }

    /// A required extension lodbench does not read is refused by name; texture-only ones are not.
    #[test]
    fn required_extensions() {
        let doc = |ext: &str| serde_json::json!({"asset": {"version": "2.0"}, "extensionsRequired": [ext]});
        let msg = check_required(&doc("EXT_mesh_features_x")).unwrap_err();
        assert!(
            msg.contains("EXT_mesh_features_x") && msg.contains("gltfpack"),
            "{msg}"
        );
        assert!(check_required(&doc("KHR_texture_basisu")).is_ok());
        assert!(check_required(&doc("KHR_mesh_quantization")).is_ok());
    }
}
