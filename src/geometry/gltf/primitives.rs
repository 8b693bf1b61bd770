//! Mesh primitives (glTF 2.0 section 3.7.2): their triangles (TRIANGLES as they are, strips and fans
//! triangulated, points and lines skipped and counted) with every vertex attribute lodbench keeps, and
//! [`Merged`], which joins a mesh's primitives (or several meshes) into one vertex and index list under
//! transforms.

use super::accessors::Doc;
use super::container::DRACO_REMEDY;
use super::json::{array, opt_index, uint_or};
use crate::geometry::attributes::{
    vertex_normals, Deformable, MorphTarget, SkinInfluences, VertexData,
};
use glam::{Mat3, Mat4, Vec3};
use serde_json::Value;

/// A primitive's triangles in mesh space with its attributes.
#[derive(Debug, Clone, Default)]
pub struct Triangles {
    pub positions: Vec<[f32; 3]>,
    pub normals: Option<Vec<[f32; 3]>>,
    pub indices: Vec<u32>,
    /// lodbench's own per-vertex shading extras (`_LODBENCH_AUX`, written by `lodbench export`).
    pub aux: Option<Vec<[f32; 4]>>,
    pub uv0: Option<Vec<[f32; 2]>>,
    pub uv1: Option<Vec<[f32; 2]>>,
    /// TANGENT, or MikkTSpace's when the primitive's material has a normal texture and the file gives none.
    pub tangents: Option<Vec<[f32; 4]>>,
    pub colors: Option<Vec<[f32; 4]>>,
    /// Every JOINTS_n/WEIGHTS_n set.
    pub skin: Option<SkinInfluences>,
    /// Morph targets' POSITION (zeros where a target has none) and NORMAL displacements.
    pub targets: Vec<MorphTarget>,
    pub material: Option<usize>,
}

impl Triangles {
    /// MikkTSpace tangents from texture coordinate set `set` (normals computed first when the primitive has
    /// none); a vertex whose corners get different tangents is split, each copy keeping every other channel.
    /// Nothing when the primitive lacks that set (the normal texture then has nothing to be oriented by, and
    /// the shader draws without it).
    fn generate_tangents(&mut self, set: u64) {
        let uv = match set {
            0 => self.uv0.clone(),
            1 => self.uv1.clone(),
            _ => None,
        };
        let Some(uv) = uv else { return };
        let normals = self
            .normals
            .get_or_insert_with(|| vertex_normals(&self.positions, &self.indices))
            .clone();
        let Some(corners) = crate::geometry::tangents::mikktspace_corners(
            &self.positions,
            &normals,
            &uv,
            &self.indices,
        ) else {
            return;
        };
        let n = self.positions.len();
        let mut tangents: Vec<Option<[f32; 4]>> = vec![None; n];
        // Copies made of a vertex for a tangent its first corner did not have: (source, tangent) -> copy.
        let mut copies: Vec<(u32, [f32; 4], u32)> = Vec::new();
        let mut order: Vec<u32> = (0..n as u32).collect();
        for (c, ix) in self.indices.iter_mut().enumerate() {
            let v = *ix as usize;
            let t = corners[c];
            match tangents[v] {
                None => tangents[v] = Some(t),
                Some(have) if crate::geometry::tangents::same_tangent(have, t) => {}
                Some(_) => {
                    let found = copies.iter().find(|(src, ct, _)| {
                        *src as usize == v && crate::geometry::tangents::same_tangent(*ct, t)
                    });
                    *ix = match found {
                        Some(&(_, _, copy)) => copy,
                        None => {
                            let copy = order.len() as u32;
                            order.push(v as u32);
                            tangents.push(Some(t));
                            copies.push((v as u32, t, copy));
                            copy
                        }
                    };
                }
            }
        }
        if order.len() > n {
            self.gather(&order);
        }
        self.tangents = Some(
            tangents
                .into_iter()
                .map(|t| t.unwrap_or([1.0, 0.0, 0.0, 1.0]))
                .collect(),
        );
    }

    /// Keeps the vertices `order` names, in that order (indices untouched: the caller renumbers them).
    fn gather(&mut self, order: &[u32]) {
        fn pick<T: Copy>(v: &mut Option<Vec<T>>, order: &[u32]) {
            if let Some(all) = v {
                *all = order.iter().map(|&i| all[i as usize]).collect();
            }
        }
        let mut positions = Some(std::mem::take(&mut self.positions));
        pick(&mut positions, order);
        self.positions = positions.unwrap_or_default();
        pick(&mut self.normals, order);
        pick(&mut self.aux, order);
        pick(&mut self.uv0, order);
        pick(&mut self.uv1, order);
        pick(&mut self.tangents, order);
        pick(&mut self.colors, order);
        if let Some(s) = &mut self.skin {
            let k = s.per_vertex;
            let (j, w) = (
                std::mem::take(&mut s.joints),
                std::mem::take(&mut s.weights),
            );
            for &i in order {
                let at = i as usize * k;
                s.joints.extend_from_slice(&j[at..at + k]);
                s.weights.extend_from_slice(&w[at..at + k]);
            }
        }
        for t in &mut self.targets {
            let mut p = Some(std::mem::take(&mut t.positions));
            pick(&mut p, order);
            t.positions = p.unwrap_or_default();
            pick(&mut t.normals, order);
        }
    }
}

/// A mesh's triangle primitives and the primitives it has that are not triangles.
#[derive(Debug, Clone, Default)]
pub struct MeshPrimitives {
    pub triangles: Vec<Triangles>,
    /// (primitive index, mode) of the points and lines primitives, which are not read.
    pub skipped: Vec<(usize, u64)>,
    /// The mesh's default morph weights (`weights`), when it gives them.
    pub weights: Option<Vec<f32>>,
}

impl MeshPrimitives {
    /// How many morph targets the mesh has (its primitives' largest count).
    pub fn target_count(&self) -> usize {
        self.triangles
            .iter()
            .map(|t| t.targets.len())
            .max()
            .unwrap_or(0)
    }

    pub fn is_skinned(&self) -> bool {
        self.triangles.iter().any(|t| t.skin.is_some())
    }
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

/// A primitive's attribute or target accessor named `key` in `attrs`, when present.
fn attribute(
    attrs: &Value,
    key: &str,
    what: &str,
    accessors: usize,
) -> Result<Option<usize>, String> {
    opt_index(&attrs[key], || format!("{what}'s {key}"), accessors)
}

impl Doc<'_> {
    /// The primitives of mesh `mesh`, each in mesh space.
    pub fn mesh_primitives(&mut self, mesh: usize) -> Result<MeshPrimitives, String> {
        let meshes = array(&self.json, "meshes");
        let m = meshes
            .get(mesh)
            .ok_or_else(|| format!("mesh {mesh} does not exist ({} meshes)", meshes.len()))?
            .clone();
        let mut out = MeshPrimitives {
            weights: super::json::float_list(&m["weights"], &format!("mesh {mesh}'s weights"))?,
            ..Default::default()
        };
        for (p, prim) in array(&m, "primitives").iter().enumerate() {
            let what = format!("mesh {mesh} primitive {p}");
            let mode = uint_or(&prim["mode"], 4, || format!("{what}'s mode"))?;
            if mode > 6 {
                return Err(format!(
                    "{what} has mode {mode}, which glTF does not define"
                ));
            }
            if mode < 4 {
                out.skipped.push((p, mode));
                continue;
            }
            out.triangles.push(self.primitive(prim, mode, &what)?);
        }
        Ok(out)
    }

    fn primitive(&mut self, prim: &Value, mode: u64, what: &str) -> Result<Triangles, String> {
        if prim
            .pointer("/extensions/KHR_draco_mesh_compression")
            .is_some()
        {
            return Err(format!("{what} is Draco-compressed; {DRACO_REMEDY}"));
        }
        let accessors = array(&self.json, "accessors").len();
        let attrs = &prim["attributes"];
        let pos = attribute(attrs, "POSITION", what, accessors)?
            .ok_or_else(|| format!("{what} has no POSITION attribute"))?;
        let positions = self.read_vecs::<3>(pos, what, "positions")?;
        let n = positions.len();
        let count_of = |len: usize, kind: &str| -> Result<(), String> {
            if len != n {
                return Err(format!("{what} has {len} {kind} for {n} positions"));
            }
            Ok(())
        };
        let normals = match attribute(attrs, "NORMAL", what, accessors)? {
            Some(a) => {
                let v = self.read_vecs::<3>(a, what, "normals")?;
                count_of(v.len(), "normals")?;
                Some(v)
            }
            None => None,
        };
        let mut uvs = [None, None];
        for (set, uv) in uvs.iter_mut().enumerate() {
            let key = format!("TEXCOORD_{set}");
            if let Some(a) = attribute(attrs, &key, what, accessors)? {
                let v = self.read_vecs::<2>(a, what, "texture coordinates")?;
                count_of(v.len(), "texture coordinates")?;
                *uv = Some(v);
            }
        }
        let [uv0, uv1] = uvs;
        let tangents = match attribute(attrs, "TANGENT", what, accessors)? {
            Some(a) => {
                let v = self.read_vecs::<4>(a, what, "tangents")?;
                count_of(v.len(), "tangents")?;
                Some(v)
            }
            None => None,
        };
        let colors = match attribute(attrs, "COLOR_0", what, accessors)? {
            Some(a) => {
                let v = self.read_rgba(a, what)?;
                count_of(v.len(), "colours")?;
                Some(v)
            }
            None => None,
        };
        let aux = self.lodbench_aux(attrs, what, n)?;
        let skin = self.skin_influences(attrs, what, n)?;
        let targets = self.morph_targets(prim, what, n)?;
        let indices = self.triangle_indices(prim, mode, what, n)?;
        let materials = array(&self.json, "materials").len();
        let material = opt_index(
            &prim["material"],
            || format!("{what}'s material"),
            materials,
        )?;
        let mut t = Triangles {
            positions,
            normals,
            indices,
            aux,
            uv0,
            uv1,
            tangents,
            colors,
            skin,
            targets,
            material,
        };
        if t.tangents.is_none() {
            if let Some(set) = material.and_then(|m| self.normal_texcoord(m)) {
                t.generate_tangents(set);
            }
        }
        Ok(t)
    }

    /// The `_LODBENCH_AUX` attribute (lodbench's own export: one VEC4 per vertex of the `n`), where present.
    fn lodbench_aux(
        &mut self,
        attrs: &Value,
        what: &str,
        n: usize,
    ) -> Result<Option<Vec<[f32; 4]>>, String> {
        let accessors = array(&self.json, "accessors").len();
        Ok(match attribute(attrs, "_LODBENCH_AUX", what, accessors)? {
            Some(a) => {
                let (v, c) = self.read_floats(a)?;
                if c != 4 || v.len() != n * 4 {
                    return Err(format!("{what}: _LODBENCH_AUX is not one VEC4 per vertex"));
                }
                Some(
                    v.chunks_exact(4)
                        .map(|a| [a[0], a[1], a[2], a[3]])
                        .collect(),
                )
            }
            None => None,
        })
    }

    /// The primitive's morph targets over its `n` vertices: POSITION displacements (zeros where a target has
    /// none) and NORMAL ones.
    fn morph_targets(
        &mut self,
        prim: &Value,
        what: &str,
        n: usize,
    ) -> Result<Vec<MorphTarget>, String> {
        let accessors = array(&self.json, "accessors").len();
        let mut targets = Vec::new();
        for (k, t) in array(prim, "targets").iter().enumerate() {
            let twhat = format!("{what} morph target {k}");
            let read3 = |doc: &mut Self,
                         key: &str,
                         kind: &str|
             -> Result<Option<Vec<[f32; 3]>>, String> {
                match attribute(t, key, &twhat, accessors)? {
                    Some(a) => {
                        let v = doc.read_vecs::<3>(a, &twhat, kind)?;
                        if v.len() != n {
                            return Err(format!("{twhat} has {} {kind} for {n} vertices", v.len()));
                        }
                        Ok(Some(v))
                    }
                    None => Ok(None),
                }
            };
            let positions = read3(self, "POSITION", "position displacements")?;
            let normals = read3(self, "NORMAL", "normal displacements")?;
            targets.push(MorphTarget {
                positions: positions.unwrap_or_else(|| vec![[0.0; 3]; n]),
                normals,
            });
        }
        Ok(targets)
    }

    /// The primitive's triangles (`mode`'s strips and fans triangulated) as indices into its `n` vertices:
    /// its index accessor, or the vertices in order.
    fn triangle_indices(
        &mut self,
        prim: &Value,
        mode: u64,
        what: &str,
        n: usize,
    ) -> Result<Vec<u32>, String> {
        let accessors = array(&self.json, "accessors").len();
        let count = u32::try_from(n).map_err(|_| format!("{what} has too many vertices"))?;
        let order: Vec<u32> =
            match opt_index(&prim["indices"], || format!("{what}'s indices"), accessors)? {
                Some(ix) => self.read_indices(ix, what)?,
                None => (0..count).collect(),
            };
        if let Some(&bad) = order.iter().find(|&&ix| ix >= count) {
            return Err(format!(
                "{what} uses vertex index {bad} but has {count} vertices"
            ));
        }
        let indices = triangulate(mode, &order)
            .ok_or_else(|| format!("{what} has {} indices, not a multiple of 3", order.len()))?;
        Ok(indices)
    }

    /// The texture coordinate set of material `m`'s normal texture, when it has one.
    fn normal_texcoord(&self, m: usize) -> Option<u64> {
        let info = &self.json["materials"][m]["normalTexture"];
        if info.is_null() {
            return None;
        }
        let set = uint_or(&info["texCoord"], 0, String::new).unwrap_or(0);
        Some(
            info.pointer("/extensions/KHR_texture_transform/texCoord")
                .and_then(super::json::uint)
                .unwrap_or(set),
        )
    }

    /// Every set of JOINTS_n/WEIGHTS_n, from 0 up to the first set absent (glTF 2.0 section 3.7.3.3: all of them
    /// skin the vertex): four influences a set, both of a set or neither.
    fn skin_influences(
        &mut self,
        attrs: &Value,
        what: &str,
        n: usize,
    ) -> Result<Option<SkinInfluences>, String> {
        let accessors = array(&self.json, "accessors").len();
        let mut joints = Vec::new();
        let mut weights = Vec::new();
        let mut sets = 0;
        for set in 0.. {
            let j = attribute(attrs, &format!("JOINTS_{set}"), what, accessors)?;
            let w = attribute(attrs, &format!("WEIGHTS_{set}"), what, accessors)?;
            let (j, w) = match (j, w) {
                (None, None) => break,
                (Some(j), Some(w)) => (j, w),
                _ => {
                    return Err(format!(
                        "{what} has one of JOINTS_{set} and WEIGHTS_{set} without the other"
                    ))
                }
            };
            let (jv, jc) = self.read_uints(j, &format!("{what}'s JOINTS_{set}"))?;
            let (wv, wc) = self.read_floats(w)?;
            if jc != 4 || wc != 4 || jv.len() != n * 4 || wv.len() != n * 4 {
                return Err(format!(
                    "{what}'s JOINTS_{set} and WEIGHTS_{set} are not one VEC4 each per vertex"
                ));
            }
            if let Some(big) = jv.iter().find(|&&j| j > u32::from(u16::MAX)) {
                return Err(format!("{what}'s JOINTS_{set} names joint {big}"));
            }
            joints.push(jv);
            weights.push(wv);
            sets += 1;
        }
        if sets == 0 {
            return Ok(None);
        }
        let per_vertex = 4 * sets;
        let mut out = SkinInfluences {
            per_vertex,
            joints: Vec::with_capacity(n * per_vertex),
            weights: Vec::with_capacity(n * per_vertex),
        };
        for v in 0..n {
            for s in 0..sets {
                out.joints
                    .extend(joints[s][v * 4..v * 4 + 4].iter().map(|&j| j as u16));
                out.weights.extend_from_slice(&weights[s][v * 4..v * 4 + 4]);
            }
        }
        Ok(Some(out))
    }
}

/// Triangle primitives merged into one vertex and index list, each added under a transform and with morph
/// weights: positions (morphed by the weights) by the transform, normals by its inverse transpose (kept while
/// every primitive has normals and every transform is invertible), tangents by its linear part (their
/// handedness flipped with it), the winding reversed under a mirroring transform (negative determinant, as glTF
/// specifies), lodbench's shading extras (`_LODBENCH_AUX`, zeros for primitives without them) with the blades'
/// hub height scaled by the transform's scale along y. Texture coordinates, tangents and colours are kept when
/// some primitive has them (defaults elsewhere: (0, 0), +x, white); skins and morph targets as a
/// [`Deformable`] (undeformed positions, the transform applied).
#[derive(Debug)]
pub struct Merged {
    pub positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    all_normals: bool,
    aux: Option<Vec<[f32; 4]>>,
    pub indices: Vec<u32>,
    /// Per primitive added: its glTF material (None: the default material) and its index count, in order.
    parts: Vec<(Option<usize>, usize)>,
    uv0: Option<Vec<[f32; 2]>>,
    uv1: Option<Vec<[f32; 2]>>,
    tangents: Option<Vec<[f32; 4]>>,
    colors: Option<Vec<[f32; 4]>>,
    base_positions: Vec<[f32; 3]>,
    base_normals: Vec<[f32; 3]>,
    skin: Option<SkinInfluences>,
    skinned_vertices: usize,
    targets: Vec<MorphTarget>,
}

impl Default for Merged {
    fn default() -> Self {
        Merged {
            positions: Vec::new(),
            normals: Vec::new(),
            all_normals: true,
            aux: None,
            indices: Vec::new(),
            parts: Vec::new(),
            uv0: None,
            uv1: None,
            tangents: None,
            colors: None,
            base_positions: Vec::new(),
            base_normals: Vec::new(),
            skin: None,
            skinned_vertices: 0,
            targets: Vec::new(),
        }
    }
}

/// What [`Merged::finish`] gives: one mesh's data.
#[derive(Debug)]
pub struct MergedParts {
    pub positions: Vec<[f32; 3]>,
    /// None when some primitive had none (the caller computes them all).
    pub normals: Option<Vec<[f32; 3]>>,
    pub indices: Vec<u32>,
    /// The triangles by material, in runs: (glTF material, None for the default one; index count), the runs
    /// covering `indices` in order, one run per material.
    pub parts: Vec<(Option<usize>, u32)>,
    pub aux: Option<Vec<[f32; 4]>>,
    pub data: VertexData,
}

impl MergedParts {
    /// Appends `other` (its indices moved past this mesh's vertices). Channels one side lacks get defaults
    /// ((0, 0), +x, white, zeros); the deformable parts are dropped (a mesh joined from several is drawn at rest).
    pub fn append(&mut self, other: MergedParts) -> Result<(), String> {
        let (base, n) = (self.positions.len(), other.positions.len());
        let offset = u32::try_from(base)
            .ok()
            .filter(|b| b.checked_add(n as u32).is_some())
            .ok_or_else(|| "has more vertices than 32-bit indices can address".to_string())?;
        self.indices
            .extend(other.indices.iter().map(|&i| offset + i));
        self.parts.extend(other.parts);
        self.positions.extend(other.positions);
        self.normals = match (self.normals.take(), other.normals) {
            (Some(mut a), Some(b)) => {
                a.extend(b);
                Some(a)
            }
            _ => None,
        };
        fn join<T: Copy>(a: &mut Option<Vec<T>>, b: Option<Vec<T>>, base: usize, n: usize, d: T) {
            if a.is_none() && b.is_none() {
                return;
            }
            let mut all = a.take().unwrap_or_else(|| vec![d; base]);
            all.extend(b.unwrap_or_else(|| vec![d; n]));
            *a = Some(all);
        }
        join(&mut self.aux, other.aux, base, n, [0.0; 4]);
        join(&mut self.data.uv0, other.data.uv0, base, n, [0.0; 2]);
        join(&mut self.data.uv1, other.data.uv1, base, n, [0.0; 2]);
        join(
            &mut self.data.tangents,
            other.data.tangents,
            base,
            n,
            [1.0, 0.0, 0.0, 1.0],
        );
        join(&mut self.data.colors, other.data.colors, base, n, [1.0; 4]);
        self.data.deform = None;
        Ok(())
    }
}

/// Extends an optional channel with `n` entries of `prim` (or `default`), filling earlier vertices with
/// `default` the first time a primitive has it.
fn extend<T: Copy>(
    all: &mut Option<Vec<T>>,
    prim: Option<Vec<T>>,
    base: usize,
    n: usize,
    default: T,
) {
    match (prim, all.as_mut()) {
        (Some(p), Some(a)) => a.extend(p),
        (Some(p), None) => {
            let mut a = vec![default; base];
            a.extend(p);
            *all = Some(a);
        }
        (None, Some(a)) => a.extend(std::iter::repeat_n(default, n)),
        (None, None) => {}
    }
}

impl Merged {
    /// Adds `prims` placed by `transform`, morphed by `weights` (missing weights are 0).
    pub fn add(
        &mut self,
        prims: &[Triangles],
        transform: Mat4,
        weights: &[f32],
    ) -> Result<(), String> {
        let linear = Mat3::from_mat4(transform);
        let det = linear.determinant();
        let normal_matrix = linear.inverse().transpose();
        let y_scale = transform.transform_vector3(Vec3::Y).length();
        for prim in prims {
            let n = prim.positions.len();
            let base = u32::try_from(self.positions.len())
                .ok()
                .zip(u32::try_from(n).ok())
                .filter(|(b, n)| b.checked_add(*n).is_some())
                .map(|(b, _)| b)
                .ok_or_else(|| "has more vertices than 32-bit indices can address".to_string())?;
            let w = |k: usize| weights.get(k).copied().unwrap_or(0.0);
            for (v, &p) in prim.positions.iter().enumerate() {
                let raw = Vec3::from(p);
                let morphed = prim
                    .targets
                    .iter()
                    .enumerate()
                    .fold(raw, |acc, (k, t)| acc + Vec3::from(t.positions[v]) * w(k));
                self.base_positions
                    .push(transform.transform_point3(raw).to_array());
                self.positions
                    .push(transform.transform_point3(morphed).to_array());
            }
            self.parts.push((prim.material, prim.indices.len()));
            for t in prim.indices.chunks_exact(3) {
                let t = if det < 0.0 {
                    [t[0], t[2], t[1]]
                } else {
                    [t[0], t[1], t[2]]
                };
                self.indices.extend(t.iter().map(|&ix| base + ix));
            }
            match &prim.normals {
                Some(normals) if self.all_normals && det != 0.0 && normal_matrix.is_finite() => {
                    self.base_normals.extend(normals.iter().map(|&nv| {
                        let nv = normal_matrix * Vec3::from(nv);
                        nv.try_normalize().unwrap_or(nv).to_array()
                    }));
                    self.normals
                        .extend(normals.iter().enumerate().map(|(v, &nv)| {
                            let nv = prim.targets.iter().enumerate().fold(
                                Vec3::from(nv),
                                |acc, (k, t)| {
                                    acc + t
                                        .normals
                                        .as_ref()
                                        .map_or(Vec3::ZERO, |tn| Vec3::from(tn[v]))
                                        * w(k)
                                },
                            );
                            let nv = normal_matrix * nv;
                            nv.try_normalize().unwrap_or(nv).to_array()
                        }));
                }
                _ => self.all_normals = false,
            }
            let hub = |a: &[[f32; 4]]| -> Vec<[f32; 4]> {
                a.iter()
                    .map(|&[u, v, kind, hub]| [u, v, kind, hub * y_scale])
                    .collect()
            };
            let base = base as usize;
            extend(
                &mut self.aux,
                prim.aux.as_deref().map(hub),
                base,
                n,
                [0.0; 4],
            );
            extend(&mut self.uv0, prim.uv0.clone(), base, n, [0.0; 2]);
            extend(&mut self.uv1, prim.uv1.clone(), base, n, [0.0; 2]);
            let flip = if det < 0.0 { -1.0 } else { 1.0 };
            let tangents = prim.tangents.as_ref().map(|t| {
                t.iter()
                    .map(|&[x, y, z, s]| {
                        let d = linear * Vec3::new(x, y, z);
                        let d = d.try_normalize().unwrap_or(d);
                        [d.x, d.y, d.z, s * flip]
                    })
                    .collect()
            });
            extend(&mut self.tangents, tangents, base, n, [1.0, 0.0, 0.0, 1.0]);
            extend(&mut self.colors, prim.colors.clone(), base, n, [1.0; 4]);
            self.add_skin(prim, base)?;
            self.add_targets(prim, base, linear, normal_matrix);
        }
        Ok(())
    }

    fn add_skin(&mut self, prim: &Triangles, base: usize) -> Result<(), String> {
        let n = prim.positions.len();
        match (&prim.skin, &mut self.skin) {
            (None, None) => return Ok(()),
            (Some(s), Some(all)) if s.per_vertex == all.per_vertex => {
                all.joints.extend_from_slice(&s.joints);
                all.weights.extend_from_slice(&s.weights);
            }
            (Some(s), None) if self.skinned_vertices == base => self.skin = Some(s.clone()),
            _ => {
                return Err(
                    "mixes primitives with and without skin influences (JOINTS_0, WEIGHTS_0), or with different \
                     numbers of JOINTS_n/WEIGHTS_n sets; skin every primitive of a skinned mesh alike"
                        .into(),
                )
            }
        }
        self.skinned_vertices += n;
        Ok(())
    }

    fn add_targets(&mut self, prim: &Triangles, base: usize, linear: Mat3, normal_matrix: Mat3) {
        let n = prim.positions.len();
        while self.targets.len() < prim.targets.len() {
            self.targets.push(MorphTarget {
                positions: vec![[0.0; 3]; base],
                normals: None,
            });
        }
        for (k, all) in self.targets.iter_mut().enumerate() {
            match prim.targets.get(k) {
                Some(t) => {
                    all.positions.extend(
                        t.positions
                            .iter()
                            .map(|&d| (linear * Vec3::from(d)).to_array()),
                    );
                    let normals = t.normals.as_ref().map(|tn| {
                        tn.iter()
                            .map(|&d| (normal_matrix * Vec3::from(d)).to_array())
                            .collect()
                    });
                    extend(&mut all.normals, normals, base, n, [0.0; 3]);
                }
                None => {
                    all.positions.extend(std::iter::repeat_n([0.0; 3], n));
                    extend(&mut all.normals, None, base, n, [0.0; 3]);
                }
            }
        }
    }

    /// The merged mesh; its deformable part (when a primitive was skinned or had morph targets) holds the
    /// undeformed positions and normals (computed from them where the primitives had none).
    pub fn finish(mut self) -> MergedParts {
        let (indices, parts) = by_material(&self.indices, &self.parts);
        self.indices = indices;
        let normals = self.all_normals.then_some(self.normals);
        let deform = (self.skin.is_some() || !self.targets.is_empty()).then(|| {
            let base_normals = match normals {
                Some(_) => self.base_normals,
                None => vertex_normals(&self.base_positions, &self.indices),
            };
            Box::new(Deformable {
                base_positions: self.base_positions,
                base_normals,
                base_tangents: self.tangents.clone(),
                skin: self.skin,
                targets: self.targets,
            })
        });
        MergedParts {
            positions: self.positions,
            normals,
            indices: self.indices,
            parts,
            aux: self.aux,
            data: VertexData {
                uv0: self.uv0,
                uv1: self.uv1,
                tangents: self.tangents,
                colors: self.colors,
                deform,
            },
        }
    }
}

/// The triangles of `indices`, whose primitives `parts` lists in order (material, index count), regrouped so that
/// each material's triangles are one run (materials in order of first use, triangles in their order within a
/// material), and the runs.
fn by_material(
    indices: &[u32],
    parts: &[(Option<usize>, usize)],
) -> (Vec<u32>, Vec<(Option<usize>, u32)>) {
    let mut order: Vec<Option<usize>> = Vec::new();
    for (m, _) in parts {
        if !order.contains(m) {
            order.push(*m);
        }
    }
    let mut out = Vec::with_capacity(indices.len());
    let mut runs = Vec::with_capacity(order.len());
    for m in order {
        let before = out.len();
        let mut at = 0;
        for &(pm, count) in parts {
            if pm == m {
                out.extend_from_slice(&indices[at..at + count]);
            }
            at += count;
        }
        if out.len() > before {
            runs.push((m, (out.len() - before) as u32));
        }
    }
    (out, runs)
}
