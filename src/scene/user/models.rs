//! A user scene's models and instances at rest: every placement of the scene drawn as glTF places it, placements
//! of the same mesh and weights sharing one model (drawn instanced) whatever their scale, an authored LOD chain
//! one model whose levels are its node hierarchies, a skinned or morph-animated placement a model of its own.
//!
//! A shared model bakes in the scale of its first placement; every other placement carries its scale over that
//! one as its instance's own (`Instance::scale`), so instances at other scales, stretched or not, draw the same
//! mesh and LOD chain. Mirrored placements (a negative determinant) share a model of their own: the mirror is
//! baked in with the winding reversed, as glTF specifies, and the pipelines cull one winding. With `--impostor`,
//! placements share a model only when their scales differ by a uniform factor: an impostor is lit in its
//! model's space, which keeps angles only under a uniform scale.

use crate::error::{Error, Result};
use crate::geometry::gltf::{self, Content, MeshPrimitives, Placement};
use crate::geometry::mesh::Mesh;
use crate::scene::animated::SkinBinding;
use crate::scene::user::parts::InstanceSource;
use glam::{Mat4, Quat, Vec3};
use std::collections::HashMap;

/// Colours of models whose material has no base colour factor, in turn.
const PALETTE: [[f32; 3]; 6] = [
    [0.72, 0.45, 0.28],
    [0.30, 0.55, 0.75],
    [0.45, 0.70, 0.35],
    [0.80, 0.70, 0.30],
    [0.65, 0.40, 0.70],
    [0.55, 0.55, 0.55],
];

/// What makes two placements one model.
#[derive(Debug, Clone, PartialEq)]
enum ModelKey {
    /// Meshes (one per level), what the placements' scales must share (`scale_class`) and rest weights.
    Rigid(Vec<Vec<usize>>, [i64; 3], Vec<u32>),
    /// A skinned mesh posed at rest by its skin (its node's transform ignored), and its weights.
    Skinned(usize, usize, Vec<u32>),
    /// A placement deformed per frame: a model of its own.
    Own(usize),
}

/// An authored chain's thresholds and extras, as the file gives them.
#[derive(Debug, Clone)]
pub struct ChainInfo {
    pub chain: gltf::AuthoredChain,
}

/// How a deformed model is driven.
#[derive(Debug, Clone)]
pub struct DeformSpec {
    pub node: usize,
    pub rest_weights: Vec<f32>,
    pub targets: usize,
    pub skin: Option<SkinBinding>,
}

/// A model before its LOD chain: its LOD0 mesh (or an authored chain's level meshes), in model space.
#[derive(Debug)]
pub struct PendingModel {
    key: ModelKey,
    pub name: String,
    pub color: [f32; 3],
    /// Per level, when an authored chain's levels differ in colour.
    pub lod_colors: Vec<[f32; 3]>,
    /// LOD0 alone (lodbench builds the chain), or an authored chain's levels.
    pub levels: Vec<Mesh>,
    pub authored: Option<ChainInfo>,
    pub deform: Option<DeformSpec>,
    /// The scale baked into `levels` (its first placement's; one for skinned and deformed models).
    baked: Vec3,
}

/// How an instance moves when the animation moves it.
#[derive(Debug, Clone, Copy)]
pub enum Anchor {
    /// By its node: model-to-world = the node's world matrix x `local` (the instance's own transform, then
    /// the inverse of the scale baked into the model).
    Node { node: usize, local: Mat4 },
    /// A skinned model: by the rigid part of its skeleton root's motion since rest.
    Skeleton { root: usize },
}

/// An instance at rest: its model, the rotation, translation and scale (over its model's) of its model space,
/// what moves it, and the node it is.
#[derive(Debug, Clone)]
pub struct PendingInstance {
    pub model: usize,
    pub rotation: Quat,
    pub translation: Vec3,
    pub scale: Vec3,
    pub anchor: Anchor,
    pub source: InstanceSource,
}

/// The models and instances of a file, and what the reader noticed.
#[derive(Debug, Default)]
pub struct Collected {
    /// The materials the models' parts name (empty with `--materials flat`: no model has parts).
    pub materials: crate::geometry::material::Materials,
    pub models: Vec<PendingModel>,
    pub instances: Vec<PendingInstance>,
    pub notes: Vec<String>,
    /// Nodes with a mesh that are no instance, and why.
    pub skipped: Vec<(usize, String)>,
}

/// A scale as a model's key: to 1e-6, so the same scale decomposed from differently rotated placements (which
/// differ in the last bits) shares one model.
fn scale_key(scale: Vec3) -> [i64; 3] {
    scale
        .to_array()
        .map(|s| (f64::from(s) * 1e6).round() as i64)
}

/// What the scales of placements sharing a model must have in common: their handedness (a mirror is baked into
/// its model with the winding reversed), or with `uniform_only` their shape (the scale over its largest
/// magnitude, to 1e-6, signs kept), so that instances differ from their model by a uniform factor.
fn scale_class(scale: Vec3, uniform_only: bool) -> [i64; 3] {
    if uniform_only {
        return scale_key(scale / scale.abs().max_element());
    }
    [i64::from(scale.x * scale.y * scale.z < 0.0), 0, 0]
}

fn weights_key(w: &[f32]) -> Vec<u32> {
    w.iter().map(|x| x.to_bits()).collect()
}

/// A world transform as scale, rotation, translation; refused (naming `what`) when it shears or is singular (no
/// such decomposition reproduces it). A mirroring transform decomposes with a negative scale, which the model
/// bakes in (its winding reversed, as glTF specifies).
fn decompose(file: &str, what: &str, world: Mat4) -> Result<(Vec3, Quat, Vec3)> {
    let (s, r, t) = world.to_scale_rotation_translation();
    let again = Mat4::from_scale_rotation_translation(s, r, t);
    let tol = 1e-4
        * world
            .abs()
            .to_cols_array()
            .iter()
            .fold(1.0f32, |a, &b| a.max(b));
    if !again.abs_diff_eq(world, tol) || !s.is_finite() || s.abs().min_element() <= 0.0 {
        return Err(Error::Mesh {
            path: file.to_string(),
            problem: format!(
                "{what} has a transform that shears or is singular, which a user scene does not place; apply \
                 the transform to the mesh in the tool that wrote it (in Blender: Object > Apply > All \
                 Transforms, then export again)"
            ),
        });
    }
    Ok((s, r, t))
}

/// The joint at the top of a skin's joints (its `skeleton` when the file names one): what moves a skinned
/// model's frame.
fn skeleton_root(content: &Content<'_>, skin: &gltf::Skin) -> usize {
    if let Some(s) = skin.skeleton {
        return s;
    }
    let mut j = skin.joints[0];
    while let Some(p) = content.nodes.parent[j] {
        if !skin.joints.contains(&p) {
            break;
        }
        j = p;
    }
    j
}

/// Reads the models of a file: `rig` says what the chosen animation moves (a skinned placement whose joints
/// move, or whose weights the clip drives, is deformed per frame); `--materials` and `--impostor` what a model
/// holds and which placements share one.
pub struct Collector<'c, 'a> {
    file: &'c str,
    content: &'c mut Content<'a>,
    rig: &'c gltf::Rig,
    /// The materials read so far (None with `--materials flat`).
    table: Option<gltf::MaterialTable>,
    prims: HashMap<usize, MeshPrimitives>,
    out: Collected,
    noted: Vec<usize>,
    /// Placements share a model only when their scales differ by a uniform factor (`--impostor`).
    uniform_only: bool,
}

impl<'c, 'a> Collector<'c, 'a> {
    pub fn new(
        file: &'c str,
        content: &'c mut Content<'a>,
        rig: &'c gltf::Rig,
        cfg: &crate::scene::config::SceneConfig,
    ) -> Self {
        let materials = cfg.materials;
        Collector {
            uniform_only: cfg.impostor.is_some(),
            file,
            content,
            rig,
            table: (materials == crate::geometry::material::MaterialMode::Full)
                .then(gltf::MaterialTable::default),
            prims: HashMap::new(),
            out: Collected::default(),
            noted: Vec::new(),
        }
    }

    fn bad(&self, problem: String) -> Error {
        Error::Mesh {
            path: self.file.to_string(),
            problem,
        }
    }

    /// Mesh `mesh`'s primitives (read once), with a note the first time a mesh has points or lines.
    fn primitives(&mut self, mesh: usize) -> Result<MeshPrimitives> {
        if !self.prims.contains_key(&mesh) {
            let p = self
                .content
                .mesh_primitives(mesh)
                .map_err(|e| self.bad(e))?;
            if !p.skipped.is_empty() && !p.triangles.is_empty() && !self.noted.contains(&mesh) {
                self.noted.push(mesh);
                let name = self.content.mesh_name(mesh);
                self.out.notes.push(format!(
                    "{}: mesh {mesh}{} has {} primitive(s) of points or lines (modes {:?}), not drawn: lodbench \
                     draws triangles",
                    self.file,
                    if name.is_empty() { String::new() } else { format!(" ('{name}')") },
                    p.skipped.len(),
                    p.skipped.iter().map(|s| s.1).collect::<Vec<_>>()
                ));
            }
            self.prims.insert(mesh, p);
        }
        Ok(self.prims[&mesh].clone())
    }

    /// Whether the animation moves `node` or a node above it.
    fn moves(&self, node: usize) -> bool {
        let Some(a) = &self.rig.animation else {
            return false;
        };
        let mut n = Some(node);
        while let Some(i) = n {
            if a.moves(i) {
                return true;
            }
            n = self.content.nodes.parent[i];
        }
        false
    }

    fn weighs(&self, node: usize) -> bool {
        self.rig.animation.as_ref().is_some_and(|a| a.weighs(node))
    }

    /// Every model and instance: the authored chains first, then every other placement.
    pub fn collect(mut self) -> Result<Collected> {
        let chains = self.content.chains.clone();
        for chain in &chains {
            self.chain(chain)?;
        }
        let placements = std::mem::take(&mut self.content.placements);
        for (i, p) in placements.iter().enumerate() {
            if !self.content.in_chain(p.node) {
                self.placement(i, p)?;
            }
        }
        self.content.placements = placements;
        if let Some(t) = self.table.take() {
            self.out
                .notes
                .extend(t.notes.iter().map(|n| format!("{}: {n}", self.file)));
            self.out.materials = t.materials;
        }
        if self.content.scene.is_none() && !self.out.instances.is_empty() {
            self.out.notes.push(format!(
                "{}: the file has no scenes: every mesh is drawn once, untransformed, and no node's transform or \
                 animation moves it (glTF 2.0 leaves what to show to the client); add a scene to place them",
                self.file
            ));
        }
        if self.out.instances.is_empty() {
            let scene = match self.content.scene {
                Some(s) => format!(" in scene {s}"),
                None => String::new(),
            };
            return Err(self.bad(match self.out.skipped.is_empty() {
                true => format!("has no triangle primitives{scene}"),
                false => format!(
                    "has no triangle primitives{scene}: its meshes hold only points or lines, and lodbench draws \
                     triangles"
                ),
            }));
        }
        Ok(self.out)
    }

    /// The model of `key`, made by `make` the first time.
    fn model(
        &mut self,
        key: ModelKey,
        make: impl FnOnce(&mut Self) -> Result<Option<PendingModel>>,
    ) -> Result<Option<usize>> {
        if let Some(i) = self.out.models.iter().position(|m| m.key == key) {
            return Ok(Some(i));
        }
        match make(self)? {
            Some(mut m) => {
                m.key = key;
                self.out.models.push(m);
                Ok(Some(self.out.models.len() - 1))
            }
            None => Ok(None),
        }
    }

    fn color(&self, mesh: usize) -> [f32; 3] {
        self.content
            .mesh_color(mesh)
            .unwrap_or(PALETTE[self.out.models.len() % PALETTE.len()])
    }

    /// One placement outside the chains: a model shared by mesh, scale and weights (skinned: by mesh, skin and
    /// weights), or its own when deformed per frame.
    fn placement(&mut self, index: usize, p: &Placement) -> Result<()> {
        let prims = self.primitives(p.mesh)?;
        if prims.triangles.is_empty() {
            self.out.notes.push(format!(
                "{}: node {} ('{}') places mesh {}{}, which holds only points or lines (modes {:?}): not drawn, \
                 lodbench draws triangles",
                self.file,
                p.node,
                p.name,
                p.mesh,
                match self.content.mesh_name(p.mesh) {
                    "" => String::new(),
                    n => format!(" ('{n}')"),
                },
                prims.skipped.iter().map(|s| s.1).collect::<Vec<_>>()
            ));
            self.out
                .skipped
                .push((p.node, format!("mesh {} has no triangles", p.mesh)));
            return Ok(());
        }
        let source = InstanceSource {
            node: p.node,
            instance: p.instance,
            holds: Vec::new(),
        };
        let weights = Content::rest_weights(p, &prims);
        let animated_weights = self.weighs(p.node) && prims.target_count() > 0;
        let what = format!("node {} ('{}')", p.node, p.name);
        if let (true, Some(s)) = (Content::is_skinned(p, &prims), p.skin) {
            let skin = self
                .content
                .skin_of(s, p.mesh, &prims)
                .map_err(|e| self.bad(e))?;
            let root = skeleton_root(self.content, &skin);
            let deformed = animated_weights || skin.joints.iter().any(|&j| self.moves(j));
            let key = if deformed {
                ModelKey::Own(index)
            } else {
                ModelKey::Skinned(p.mesh, s, weights_key(&weights))
            };
            let spec = deformed.then(|| DeformSpec {
                node: p.node,
                rest_weights: weights.clone(),
                targets: prims.target_count(),
                skin: Some(SkinBinding {
                    joints: skin.joints.clone(),
                    inverse_bind: skin.inverse_bind.clone(),
                }),
            });
            // Posed at rest in world space: the model's space is the world's at rest.
            let model = self.model(key, |c| {
                let mesh = c.mesh_of(p, &prims, Mat4::IDENTITY, Mat4::IDENTITY, deformed)?;
                Ok(Some(c.pending(p.mesh, vec![mesh], spec)))
            })?;
            if let Some(model) = model {
                self.out.instances.push(PendingInstance {
                    model,
                    rotation: Quat::IDENTITY,
                    translation: Vec3::ZERO,
                    scale: Vec3::ONE,
                    anchor: Anchor::Skeleton { root },
                    source,
                });
            }
            return Ok(());
        }
        self.rigid(p, &prims, source, &what, (index, weights, animated_weights))
    }

    /// A placement that is no skin: a model shared by mesh, scale class and weights (one of its own when the
    /// clip drives its weights), placed at its rotation and translation, scaled over its model's.
    fn rigid(
        &mut self,
        p: &Placement,
        prims: &MeshPrimitives,
        source: InstanceSource,
        what: &str,
        (index, weights, animated_weights): (usize, Vec<f32>, bool),
    ) -> Result<()> {
        let (scale, rotation, translation) = decompose(self.file, what, p.world)?;
        let key = if animated_weights {
            ModelKey::Own(index)
        } else {
            let class = scale_class(scale, self.uniform_only);
            ModelKey::Rigid(vec![vec![p.mesh]], class, weights_key(&weights))
        };
        let spec = animated_weights.then(|| DeformSpec {
            node: p.node,
            rest_weights: weights.clone(),
            targets: prims.target_count(),
            skin: None,
        });
        let model = self.model(key, |c| {
            let mesh = c.mesh_of(
                p,
                prims,
                Mat4::from_scale(scale),
                Mat4::IDENTITY,
                animated_weights,
            )?;
            Ok(Some(PendingModel {
                baked: scale,
                ..c.pending(p.mesh, vec![mesh], spec)
            }))
        })?;
        if let Some(model) = model {
            // The model bakes its first placement's scale; this placement draws it at its own over that one.
            let baked = self.out.models[model].baked;
            self.out.instances.push(PendingInstance {
                model,
                rotation,
                translation,
                scale: scale / baked,
                anchor: Anchor::Node {
                    node: p.node,
                    local: p.instance_local * Mat4::from_scale(baked).inverse(),
                },
                source,
            });
        }
        Ok(())
    }

    fn pending(&self, mesh: usize, levels: Vec<Mesh>, deform: Option<DeformSpec>) -> PendingModel {
        PendingModel {
            key: ModelKey::Own(usize::MAX),
            name: match self.content.mesh_name(mesh) {
                "" => format!("mesh{mesh}"),
                n => n.to_string(),
            },
            color: self.color(mesh),
            lod_colors: Vec::new(),
            levels,
            authored: None,
            deform,
            baked: Vec3::ONE,
        }
    }

    /// Placement `p`'s mesh at rest ([`Content::placed_as`]): unskinned under `mesh_to_frame`, skinned by its
    /// joints into the frame `to_frame` maps world space to; its deformable part kept when `deformed`.
    fn mesh_of(
        &mut self,
        p: &Placement,
        prims: &MeshPrimitives,
        mesh_to_frame: Mat4,
        to_frame: Mat4,
        deformed: bool,
    ) -> Result<Mesh> {
        let mut parts = self
            .content
            .placed_as(p, prims, mesh_to_frame, to_frame)
            .map_err(|e| self.bad(e))?;
        if !deformed {
            parts.data.deform = None;
        }
        self.mesh_from(parts)
    }

    /// The mesh of merged primitives, its parts' materials read when materials are drawn.
    fn mesh_from(&mut self, parts: gltf::MergedParts) -> Result<Mesh> {
        let name = self.file;
        let runs = match &mut self.table {
            Some(table) => {
                let mut runs = Vec::with_capacity(parts.parts.len());
                for &(gltf_material, count) in &parts.parts {
                    let m =
                        self.content
                            .material(table, gltf_material)
                            .map_err(|e| Error::Mesh {
                                path: name.to_string(),
                                problem: e,
                            })?;
                    runs.push((m, count));
                }
                runs
            }
            None => Vec::new(),
        };
        let mut m = Mesh::new(name, parts.positions, parts.normals, parts.indices)?;
        if let Some(aux) = parts.aux {
            m = m.with_aux(name, aux)?;
        }
        m = m.with_data(name, parts.data)?;
        if !runs.is_empty() {
            m = m.with_parts(name, &runs)?;
        }
        m.check_area(name)?;
        Ok(m)
    }

    /// An authored chain: one model whose levels are its level nodes' hierarchies, placed by the LOD0 node.
    fn chain(&mut self, chain: &gltf::AuthoredChain) -> Result<()> {
        let root = chain.nodes[0];
        let what = format!("LOD chain '{}' (node {root})", chain.name);
        let root_world = self.level_world(chain, 0);
        let (scale, rotation, translation) = decompose(self.file, &what, root_world)?;
        let to_model = Mat4::from_rotation_translation(rotation, translation).inverse();
        let placements = self.content.placements.clone();
        let mut level_meshes = Vec::new();
        let mut level_placements = Vec::new();
        for (l, &level) in chain.nodes.iter().enumerate() {
            let mine: Vec<&Placement> = placements
                .iter()
                .filter(|p| p.node != usize::MAX && self.content.nodes.is_under(p.node, level))
                .collect();
            if mine.is_empty() {
                return Err(self.bad(format!(
                    "{what}: level {l} (node {level}) places no mesh; every level of a chain needs geometry"
                )));
            }
            level_meshes.push(mine.iter().map(|p| p.mesh).collect::<Vec<_>>());
            if l > 0 {
                for p in &mine {
                    self.out
                        .skipped
                        .push((p.node, format!("level {l} of LOD chain '{}'", chain.name)));
                }
            }
            level_placements.push(mine.into_iter().cloned().collect::<Vec<_>>());
        }
        let key = ModelKey::Rigid(level_meshes, scale_key(scale), Vec::new());
        let model = self.model(key, |c| {
            let mut levels = Vec::new();
            let mut colors = Vec::new();
            for (l, ps) in level_placements.iter().enumerate() {
                let parts = c.chain_level(&what, l, ps, to_model)?;
                levels.push(c.mesh_from(parts)?);
                colors.push(c.content.mesh_color(ps[0].mesh));
            }
            let color = colors[0].unwrap_or(PALETTE[c.out.models.len() % PALETTE.len()]);
            let lod_colors: Vec<[f32; 3]> = colors.iter().map(|k| k.unwrap_or(color)).collect();
            Ok(Some(PendingModel {
                key: ModelKey::Own(usize::MAX),
                name: if chain.name.is_empty() {
                    format!("chain{}", c.out.models.len())
                } else {
                    chain.name.clone()
                },
                color,
                lod_colors: if lod_colors.iter().any(|k| *k != color) {
                    lod_colors
                } else {
                    Vec::new()
                },
                levels,
                authored: Some(ChainInfo {
                    chain: chain.clone(),
                }),
                deform: None,
                baked: scale,
            }))
        })?;
        if let Some(model) = model {
            let mut holds: Vec<usize> = level_placements[0].iter().map(|p| p.node).collect();
            holds.dedup();
            holds.retain(|&n| n != root);
            self.out.instances.push(PendingInstance {
                model,
                rotation,
                translation,
                scale: Vec3::ONE,
                anchor: Anchor::Node {
                    node: root,
                    local: Mat4::from_scale(scale).inverse(),
                },
                source: InstanceSource {
                    node: root,
                    instance: None,
                    holds,
                },
            });
        }
        Ok(())
    }

    /// Level `l` of the authored chain `what`: its placements `ps` merged in the chain's model space (`to_model`),
    /// at rest (with a note where a mesh is skinned or has animated weights). Errors where it has no triangles.
    fn chain_level(
        &mut self,
        what: &str,
        l: usize,
        ps: &[Placement],
        to_model: Mat4,
    ) -> Result<gltf::MergedParts> {
        let mut merged: Option<gltf::MergedParts> = None;
        for p in ps {
            let prims = self.primitives(p.mesh)?;
            if Content::is_skinned(p, &prims) || self.weighs(p.node) {
                self.out.notes.push(format!(
                    "{}: {what}: level {l}'s mesh {} is skinned or has animated weights; drawn at rest \
                     (lodbench animates the skins and morph targets of meshes without authored chains)",
                    self.file, p.mesh
                ));
            }
            let part = self
                .content
                .placed_as(p, &prims, to_model * p.world, to_model)
                .map_err(|e| self.bad(e))?;
            match &mut merged {
                Some(m) => m.append(part).map_err(|e| self.bad(e))?,
                None => merged = Some(part),
            }
        }
        let mut parts = merged.ok_or_else(|| self.bad(format!("{what}: level {l} is empty")))?;
        parts.data.deform = None;
        if parts.indices.is_empty() {
            return Err(self.bad(format!("{what}: level {l} has no triangles")));
        }
        Ok(parts)
    }

    /// Where level `l` of `chain` stands at rest: its node's world matrix, or, for an MSFT_lod level outside the
    /// scene, where it replaces the LOD0 node (under the LOD0 node's parent).
    fn level_world(&self, chain: &gltf::AuthoredChain, l: usize) -> Mat4 {
        let n = chain.nodes[l];
        let nodes = &self.content.nodes;
        if nodes.scene_order.contains(&n) {
            return self.content.rest_worlds[n];
        }
        let parent =
            nodes.parent[chain.nodes[0]].map_or(Mat4::IDENTITY, |p| self.content.rest_worlds[p]);
        parent * nodes.local[n].matrix()
    }
}
