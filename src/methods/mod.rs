//! Transition methods behind one trait and one registry. A method only decides how to draw the shared
//! schedule's `(lod_from, lod_to, k)` per instance; it never selects LODs itself.
//!
//! Adding a method: a new file with a type implementing [`Method`] (and, if it has flags, an options struct
//! flattened into [`MethodOptions`]), plus its line in [`BUILTIN`]. docs/ARCHITECTURE.md walks through it;
//! `tests/it/methods_registry.rs` does it with a throwaway method. The methods' files import `common`, never this file, so
//! the registry can name them without an import circle.

pub mod alpha;
pub mod alpha_2pass;
pub mod alpha_sorted;
pub mod alpha_zwrite;
pub mod blocks_tree;
pub mod clusterlod;
pub mod common;
pub mod discrete;
pub mod dither;
pub mod fsi;
pub mod geomorph;
pub mod noise;
pub mod reference;
pub mod roam;
pub mod traits;

pub use common::{instance_raw, instance_raw_with, FrameInput, Method, OpaqueInstances};

use crate::error::{Error, Result};
use crate::gpu::SceneGpu;
use crate::scene::Scene;

/// The flags of every method, each method's declared once in its own file and flattened here: `lodbench run`
/// takes them as flags, experiment files as `[run]` keys, and run.json records them (its `config`, and each
/// block's `method_options`, the ones its method reads).
#[derive(
    Debug, Clone, Copy, PartialEq, Default, clap::Args, serde::Serialize, serde::Deserialize,
)]
#[serde(default)]
pub struct MethodOptions {
    #[command(flatten)]
    #[serde(flatten)]
    pub dither: dither::DitherOptions,
    #[command(flatten)]
    #[serde(flatten)]
    pub geomorph: geomorph::GeomorphOptions,
    #[command(flatten)]
    #[serde(flatten)]
    pub fsi: fsi::FsiOptions,
    #[command(flatten)]
    #[serde(flatten)]
    pub clusterlod: clusterlod::ClusterLodOptions,
    #[command(flatten)]
    #[serde(flatten)]
    pub roam: roam::RoamOptions,
}

/// What a method's constructor gets; GPU objects are created there, once per scene block.
pub struct Build<'a> {
    pub gpu: &'a SceneGpu,
    pub scene: &'a Scene,
    pub options: &'a MethodOptions,
    /// `--seed` (noise patterns, visibility textures).
    pub seed: u64,
}

/// One method of the registry.
#[derive(Clone, Copy)]
pub struct MethodEntry {
    /// The name `--method` takes and the CSVs' `method` column holds.
    pub name: &'static str,
    /// One line for `lodbench list`.
    pub about: &'static str,
    pub create: fn(&Build<'_>) -> Result<Box<dyn Method>>,
    /// The options this method reads, as run.json records them per block (None: it reads none).
    pub options: fn(&MethodOptions) -> Option<serde_json::Value>,
}

fn no_options(_: &MethodOptions) -> Option<serde_json::Value> {
    None
}

fn json(v: impl serde::Serialize) -> Option<serde_json::Value> {
    serde_json::to_value(v).ok()
}

/// The options FSI's ablations read: the visibility texture and where it is looked up (not `--fsi-check`).
fn fsi_ablation_options(o: &MethodOptions) -> Option<serde_json::Value> {
    json(serde_json::json!({ "vis_texture": o.fsi.vis_texture, "vis_space": o.fsi.vis_space }))
}

/// Every built-in method, in the order runs use when `--method` is absent. One line a method (rustfmt would
/// spread each over eight).
#[rustfmt::skip]
pub const BUILTIN: &[MethodEntry] = &[
    MethodEntry { name: "reference", about: "LOD0 everywhere: the high-poly reference", create: |b| Ok(Box::new(reference::Reference::new(b.gpu, b.scene))), options: no_options },
    MethodEntry { name: "reference-flat", about: "the reference drawn flat (one colour per model, no texture): paired with reference, the cost of a user scene's materials (not run by default)", create: |b| Ok(Box::new(reference::Reference::flat(b.gpu, b.scene))), options: no_options },
    MethodEntry { name: "discrete", about: "discrete LOD switching: a hard switch at k = 0.5", create: |b| Ok(Box::new(discrete::Discrete::new(b.gpu, b.scene))), options: no_options },
    MethodEntry { name: "discrete-mesh", about: "discrete, drawing the last mesh LOD where --impostor's card would be (its cost)", create: |b| Ok(Box::new(discrete::Discrete::without_impostors(b.gpu, b.scene))), options: no_options },
    MethodEntry { name: "alpha", about: "Giegl's unpopping: one LOD opaque, the other blended over it", create: |b| Ok(Box::new(alpha::Alpha::new(b.gpu, b.scene))), options: no_options },
    MethodEntry { name: "alpha-2pass", about: "unpopping, double pass: each translucent LOD shows only its nearest surface", create: |b| Ok(Box::new(alpha_2pass::AlphaTwoPass::new(b.gpu, b.scene, alpha_2pass::Weights::Unpop))), options: no_options },
    MethodEntry { name: "alpha-linear", about: "Sheliemietiev et al. 2023's alpha blending: both LODs translucent, 1 - k and k, double pass each", create: |b| Ok(Box::new(alpha_2pass::AlphaTwoPass::new(b.gpu, b.scene, alpha_2pass::Weights::Linear))), options: no_options },
    MethodEntry { name: "alpha-sorted", about: "alpha's blend composited in exact depth order per pixel (depth peeling): the order-independent reference of its sorting error (not run by default)", create: |b| Ok(Box::new(alpha_sorted::AlphaSorted::new(b.gpu, b.scene))), options: no_options },
    MethodEntry { name: "alpha-zwrite", about: "Blow's unpopping: translucent with Z-writes, the compare switch", create: |b| Ok(Box::new(alpha_zwrite::AlphaZWrite::new(b.gpu, b.scene))), options: no_options },
    MethodEntry { name: "dither", about: "noise blending: complementary screen-space discard", create: |b| Ok(Box::new(dither::Dither::new(b.gpu, b.scene, &b.options.dither, b.seed, false))), options: |o| json(o.dither) },
    MethodEntry { name: "dither-skip", about: "dither, a LOD the pattern gives no pixel at this k not drawn (not run by default)", create: |b| Ok(Box::new(dither::Dither::new(b.gpu, b.scene, &b.options.dither, b.seed, true))), options: |o| json(o.dither) },
    MethodEntry { name: "geomorph", about: "geomorphing: the finer LOD's vertices move to their targets on the coarser", create: |b| Ok(Box::new(geomorph::Geomorph::new(b.gpu, b.scene, &b.options.geomorph))), options: |o| json(o.geomorph) },
    MethodEntry { name: "fsi", about: "Frame Sequential Interpolation (Scherzer & Wimmer 2008)", create: |b| Ok(Box::new(fsi::Fsi::new(b.gpu, b.scene, &b.options.fsi, b.seed, fsi::Variant::Sequential))), options: |o| json(o.fsi) },
    MethodEntry { name: "fsi-noreproject", about: "FSI ablation: the older buffer read at the same pixel", create: |b| Ok(Box::new(fsi::Fsi::new(b.gpu, b.scene, &b.options.fsi, b.seed, fsi::Variant::NoReproject))), options: fsi_ablation_options },
    MethodEntry { name: "fsi-sameframe", about: "FSI ablation: both LOD buffers rendered every frame", create: |b| Ok(Box::new(fsi::Fsi::new(b.gpu, b.scene, &b.options.fsi, b.seed, fsi::Variant::SameFrame))), options: fsi_ablation_options },
    MethodEntry { name: "fsi-blend", about: "FSI ablation: frame-sequential blending, the two LOD buffers alpha-blended by k, no visibility texture (not run by default)", create: |b| Ok(Box::new(fsi::Fsi::new(b.gpu, b.scene, &b.options.fsi, b.seed, fsi::Variant::Blend))), options: no_options },
    MethodEntry { name: "blocks", about: "unified LOD (Blow 2003a, 2003b): per-block alpha-zwrite blending, seams between the blocks", create: |b| Ok(Box::new(alpha_zwrite::AlphaZWrite::with_seams(b.gpu, b.scene))), options: no_options },
    MethodEntry { name: "blocks-noseams", about: "blocks without the seams (the ablation: cracks show where neighbours differ)", create: |b| Ok(Box::new(alpha_zwrite::AlphaZWrite::new(b.gpu, b.scene))), options: no_options },
    MethodEntry { name: "blocks-discrete", about: "blocks with seams, hard switches per block", create: |b| Ok(Box::new(discrete::Discrete::with_seams(b.gpu, b.scene))), options: no_options },
    MethodEntry { name: "blocks-tree", about: "Blow's hierarchy of blocks on the terrain: 2 x 2 blocks combined and reduced, a parent faded into its children, seams across levels", create: |b| Ok(Box::new(blocks_tree::BlocksTree::new(b.gpu, b.scene)?)), options: no_options },
    MethodEntry { name: "clusterlod", about: "meshoptimizer's cluster DAG (Nanite-style), the per-frame cut at --pixel-error", create: |b| Ok(Box::new(clusterlod::ClusterLod::new(b.gpu, b.scene, &b.options.clusterlod)?)), options: |o| json(o.clusterlod) },
    MethodEntry { name: "roam", about: "ROAM (Duchaineau et al. 1997): the terrain's bintree split and merged each frame at --pixel-error", create: |b| Ok(Box::new(roam::Roam::new(b.gpu, b.scene, None)?)), options: no_options },
    MethodEntry { name: "roam-morph", about: "ROAM, each vertex a split adds moved in from its edge's midpoint over --roam-morph-frames", create: |b| Ok(Box::new(roam::Roam::new(b.gpu, b.scene, Some(b.options.roam.roam_morph_frames))?)), options: |o| json(o.roam) },
];

/// The methods a run can name: the built-in ones, plus any a caller (a test, a downstream crate) adds.
#[derive(Clone)]
pub struct Registry {
    entries: Vec<MethodEntry>,
}

impl Default for Registry {
    fn default() -> Self {
        Registry {
            entries: BUILTIN.to_vec(),
        }
    }
}

impl Registry {
    /// The built-in methods.
    pub fn builtin() -> Registry {
        Registry::default()
    }

    /// This registry plus `entry`; a name already taken is an error.
    pub fn with(mut self, entry: MethodEntry) -> Result<Registry> {
        if self.entries.iter().any(|e| e.name == entry.name) {
            return Err(Error::Config(format!(
                "method {} is registered twice",
                entry.name
            )));
        }
        self.entries.push(entry);
        Ok(self)
    }

    pub fn entries(&self) -> &[MethodEntry] {
        &self.entries
    }

    /// Every name, in registry order.
    pub fn names(&self) -> Vec<&'static str> {
        self.entries.iter().map(|e| e.name).collect()
    }

    /// The method called `name` (a run's label `NAME#k` names NAME), or an error listing the valid names.
    pub fn get(&self, name: &str) -> Result<&MethodEntry> {
        let base = base_name(name);
        self.entries
            .iter()
            .find(|e| e.name == base)
            .ok_or_else(|| Error::unknown("method", name, &self.names()))
    }

    /// Builds the method called `name`.
    pub fn create(&self, name: &str, build: &Build<'_>) -> Result<Box<dyn Method>> {
        (self.get(name)?.create)(build)
    }
}

/// The method a run's label names: `discrete#2` (the second `discrete` of `--method discrete,discrete`) is
/// `discrete`; any other label is itself.
pub fn base_name(label: &str) -> &str {
    match label.rsplit_once('#') {
        Some((base, k)) if !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()) => base,
        _ => label,
    }
}

/// Whether a run's label names the reference (`reference`, `reference#2`, ...).
pub fn is_reference(label: &str) -> bool {
    base_name(label) == "reference"
}

/// The methods that need a scene of one large mesh in blocks (`SceneKind::is_unified`): they draw its seams or
/// its cluster DAG.
pub const UNIFIED_ONLY: [&str; 7] = [
    "blocks",
    "blocks-noseams",
    "blocks-discrete",
    "blocks-tree",
    "clusterlod",
    "roam",
    "roam-morph",
];

/// The methods that need the procedural terrain's height field and its grid (scene terrain without `--mesh`).
pub const TERRAIN_ONLY: [&str; 3] = ["blocks-tree", "roam", "roam-morph"];

/// Whether the method of `label` needs the terrain's height field.
pub fn needs_height_field(label: &str) -> bool {
    TERRAIN_ONLY.contains(&base_name(label))
}

/// What a unified scene runs when `--method` is absent: the reference and the four unified methods of blocks
/// and clusters (blocks-tree, roam and roam-morph need the terrain's height field and run when named).
pub const UNIFIED_DEFAULT: [&str; 5] = [
    "reference",
    "blocks",
    "blocks-noseams",
    "blocks-discrete",
    "clusterlod",
];

/// Built-in methods a run draws only when `--method` names them: variants that test a claim (their image is
/// another method's, or they ablate one).
pub const NOT_DEFAULT: [&str; 5] = [
    "reference-flat",
    "alpha-sorted",
    "dither-skip",
    "fsi-blend",
    "discrete-mesh",
];

/// Built-in methods that cannot draw a transition into an impostor (`--impostor`): geomorph moves the finer
/// LOD's vertices onto the coarser LOD's surface, and a card has no surface to move them onto. A run with
/// `--impostor` leaves them out of its defaults and refuses them by name.
pub const NOT_WITH_IMPOSTOR: [&str; 1] = ["geomorph"];

/// Whether the method of `label` cannot draw a transition into an impostor.
pub fn not_with_impostor(label: &str) -> bool {
    NOT_WITH_IMPOSTOR.contains(&base_name(label))
}

/// Whether the method of `label` needs a unified scene.
pub fn needs_unified(label: &str) -> bool {
    UNIFIED_ONLY.contains(&base_name(label))
}

/// The built-in methods a scene runs when `--method` is absent, in [`BUILTIN`]'s order.
pub fn defaults_for(unified: bool) -> Vec<&'static str> {
    names()
        .into_iter()
        .filter(|n| match unified {
            true => UNIFIED_DEFAULT.contains(n),
            false => !needs_unified(n) && !NOT_DEFAULT.contains(n),
        })
        .collect()
}

/// Every built-in method name, in [`BUILTIN`]'s order.
pub fn names() -> Vec<&'static str> {
    BUILTIN.iter().map(|e| e.name).collect()
}
