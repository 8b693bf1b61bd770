//! What `lodbench describe` prints (and run.json's scene descriptions): a scene's settings, models, LODs and
//! path, from its [`SceneDef`].

use crate::geometry::block_tree::BlockTree;
use crate::geometry::cluster_dag::{CutBound, CutDiagnosis};
use crate::geometry::lod::LodInfo;
use crate::scene::bunny::BunnyPath;
use crate::scene::config::SceneConfig;
use crate::scene::def::SceneDef;
use crate::scene::kind::CameraMode;
use crate::scene::model::{Motion, Preprocessing, Scene, Unified};
use crate::scene::schedule::ScheduleParams;
use serde::Serialize;

/// What `lodbench describe` prints.
#[derive(Debug, Clone, Serialize)]
pub struct SceneDescription {
    pub scene: String,
    pub profile: String,
    pub width: u32,
    pub height: u32,
    pub fov_y_deg: f32,
    pub frames: u32,
    pub instance_counts: Vec<u32>,
    pub mesh: String,
    pub pixel_error: f32,
    pub schedule: ScheduleParams,
    pub models: Vec<ModelDescription>,
    pub motion: Motion,
    pub camera: CameraMode,
    /// Milliseconds to build the models' LOD chains (once per scene).
    pub lod_generation_ms: f64,
    /// Milliseconds to place the instances of the first count (once per block).
    pub instance_build_ms: f64,
    /// The bunny scenes' path (None for the procedural scenes).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub path: Option<BunnyPath>,
    /// [`SceneDef::notes`]: what the run warns about this scene.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
    /// The unified scenes' preprocessing: blocks, seams, cluster DAG, with times and sizes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unified: Option<Preprocessing>,
    /// A unified scene's clusterlod cut along the path at the run's pixel error (means over the frames, and the
    /// frame with the most groups over the threshold because of their sphere).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cut: Option<CutAlongPath>,
    /// The terrain's `blocks-tree` hierarchy: nodes and triangles per level (None without the height field's
    /// grid).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hierarchy: Option<HierarchyDescription>,
    /// A user scene's instances, authored chains and camera flight.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub user: Option<crate::scene::user::UserParts>,
    /// How the scene's triangles are shaded, and the light.
    pub surface: SurfaceDescription,
    /// `--impostor`: the atlas every model's impostor is baked into.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub impostor: Option<ImpostorDescription>,
}

/// An impostor's atlas as `describe` shows it (`geometry/impostor.rs`, `gpu/impostor_atlas.rs`).
#[derive(Debug, Clone, Serialize)]
pub struct ImpostorDescription {
    #[serde(flatten)]
    pub settings: crate::geometry::impostor::Impostor,
    /// Frames per atlas (N x N) and texels along a frame's side.
    pub frames_total: u32,
    pub frame_texels: u32,
    /// Models with an impostor, and the bytes of each one's atlas and of them all.
    pub models: usize,
    pub bytes_per_model: u64,
    pub bytes: u64,
    /// The largest angle between a view and the frame(s) drawn for it, degrees.
    pub max_view_angle_deg: f32,
    /// The whole description in a line.
    pub line: String,
}

/// How a scene is shaded (docs/methods.md, "Materials as engines draw them").
#[derive(Debug, Clone, Serialize)]
pub struct SurfaceDescription {
    /// `flat` (one colour per instance, Lambert and ambient: the built-in scenes, `--materials flat`) or `pbr`
    /// (glTF's metallic-roughness materials, glTF 2.0 Appendix B's BRDF).
    pub kind: &'static str,
    /// Towards the directional light (normalised).
    pub light_direction: [f32; 3],
    /// flat: the ambient share of the colour; pbr: the uniform environment's radiance (the light's irradiance at
    /// normal incidence is pi x (1 - ambient)).
    pub ambient: f32,
    pub materials: usize,
    pub images: usize,
    /// Texels of every image at full size.
    pub texels: u64,
}

/// Blow's hierarchy of the terrain as `blocks-tree` builds it.
#[derive(Debug, Clone, Serialize)]
pub struct HierarchyDescription {
    /// Leaves along a side.
    pub leaves: u32,
    /// Level 0 (the leaves) up to the root: its nodes, their triangles together, their largest error.
    pub levels: Vec<HierarchyLevel>,
    pub build_ms: f64,
}

#[derive(Debug, Clone, Serialize)]
pub struct HierarchyLevel {
    pub level: u32,
    pub nodes: u32,
    pub triangles: u64,
    pub error_max: f32,
}

#[derive(Debug, Clone, Serialize)]
pub struct ModelDescription {
    pub name: String,
    pub radius: f32,
    /// Its instances at the first instance count.
    pub instances: usize,
    /// The smallest and largest of its instances' sizes (`Instance::size`) where any differs from 1: an instance
    /// `s` times its model's size switches at `s` times the model's switch distances.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sizes: Option<[f32; 2]>,
    pub switch_source: crate::scene::model::SwitchSource,
    pub lods: Vec<LodDescription>,
}

#[derive(Debug, Clone, Serialize)]
pub struct LodDescription {
    #[serde(flatten)]
    pub info: LodInfo,
    /// Distance beyond which this LOD is selected (None for LOD0).
    pub switch_distance: Option<f32>,
    /// "not reached by the sweep" for a bunny-scene switch nearer than the path's start ([`BunnyPath`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<&'static str>,
    /// `lodbench describe --deviation`: the largest and the mean distance from LOD0's vertices to this LOD's
    /// surface ([`crate::geometry::lod::surface_deviation`]), object-space units.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub deviation_max: Option<f32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub deviation_mean: Option<f32>,
}

/// The terrain's hierarchy, per level (None without the height field's grid, or where it does not build).
fn hierarchy(u: &Unified) -> Option<HierarchyDescription> {
    let field = u.terrain?;
    let tree = BlockTree::build(&u.mesh, field.quads, field.blocks).ok()?;
    let top = tree.nodes[tree.root as usize].level;
    let levels = (0..=top)
        .map(|level| {
            let nodes = tree.nodes.iter().filter(|n| n.level == level);
            HierarchyLevel {
                level,
                nodes: nodes.clone().count() as u32,
                triangles: nodes.clone().map(|n| n.index_count as u64 / 3).sum(),
                error_max: nodes.map(|n| n.error).fold(0.0, f32::max),
            }
        })
        .collect();
    Some(HierarchyDescription {
        leaves: field.blocks.clamp(1, field.quads),
        levels,
        build_ms: tree.build_ms,
    })
}

/// [`CutDiagnosis`] along a unified scene's path: the means over its frames, and the frame where the most
/// groups were over the threshold with the camera inside their sphere.
#[derive(Debug, Clone, Serialize)]
pub struct CutAlongPath {
    pub frames: u32,
    pub groups: f64,
    pub over: f64,
    pub over_inside_sphere: f64,
    pub over_only_by_sphere: f64,
    pub triangles: f64,
    pub worst_frame: u32,
    pub worst: CutDiagnosis,
}

fn cut_along_path(scene: &Scene, u: &Unified) -> CutAlongPath {
    let per_frame: Vec<CutDiagnosis> = (0..scene.frames)
        .map(|f| {
            u.dag
                .diagnose(&scene.cut_camera(f, u.pixel_error, CutBound::Sphere))
        })
        .collect();
    let n = per_frame.len().max(1) as f64;
    let mean = |v: fn(&CutDiagnosis) -> f64| per_frame.iter().map(v).sum::<f64>() / n;
    let (worst_frame, worst) = per_frame
        .iter()
        .enumerate()
        .max_by_key(|(_, d)| d.over_only_by_sphere)
        .map(|(f, d)| (f as u32, *d))
        .unwrap_or_default();
    CutAlongPath {
        frames: scene.frames,
        groups: mean(|d| d.groups as f64),
        over: mean(|d| d.over as f64),
        over_inside_sphere: mean(|d| d.over_inside_sphere as f64),
        over_only_by_sphere: mean(|d| d.over_only_by_sphere as f64),
        triangles: mean(|d| d.triangles as f64),
        worst_frame,
        worst,
    }
}

/// [`LodDescription::note`] of a switch the bunny path never reaches.
pub const NOT_REACHED: &str = "not reached by the sweep";

impl SceneDef {
    pub fn describe(&self, cfg: &SceneConfig) -> SceneDescription {
        let started = std::time::Instant::now();
        let first = self.instantiate(self.counts[0]);
        let instance_build_ms = started.elapsed().as_secs_f64() * 1e3;
        SceneDescription {
            scene: self.name().to_string(),
            profile: format!("{:?}", cfg.profile).to_lowercase(),
            width: self.width,
            height: self.height,
            fov_y_deg: self.fov_y.to_degrees(),
            frames: self.frames,
            instance_counts: self.counts.clone(),
            mesh: self.mesh_source.clone(),
            pixel_error: cfg.pixel_error(self.kind, self.height),
            schedule: self.schedule,
            models: (0..self.models.len())
                .map(|m| self.describe_model(m, &first))
                .collect(),
            motion: first.motion.clone(),
            camera: self.camera_mode,
            lod_generation_ms: self.lod_generation_ms,
            instance_build_ms,
            path: self.path(),
            notes: self.notes(),
            unified: self.unified().map(|u| u.data.preprocessing.clone()),
            cut: self.unified().map(|u| cut_along_path(&first, &u.data)),
            hierarchy: self.unified().and_then(|u| hierarchy(&u.data)),
            user: self.user().cloned(),
            impostor: self.impostor.map(|imp| {
                let models = self
                    .models
                    .iter()
                    .filter(|m| crate::geometry::impostor::ends_in_card(&m.chain))
                    .count();
                ImpostorDescription {
                    settings: imp,
                    frames_total: imp.frames * imp.frames,
                    frame_texels: imp.frame_texels(),
                    models,
                    bytes_per_model: imp.atlas_bytes(),
                    bytes: imp.atlas_bytes() * models as u64,
                    max_view_angle_deg: imp.max_view_angle().to_degrees(),
                    line: imp.describe(),
                }
            }),
            surface: SurfaceDescription {
                kind: if first.materials.is_empty() {
                    "flat"
                } else {
                    "pbr"
                },
                light_direction: glam::Vec3::from(crate::scene::model::LIGHT_DIR)
                    .normalize()
                    .to_array(),
                ambient: crate::scene::model::AMBIENT,
                materials: first.materials.materials.len(),
                images: first.materials.images.len(),
                texels: first
                    .materials
                    .images
                    .iter()
                    .map(|i| u64::from(i.width) * u64::from(i.height))
                    .sum(),
            },
        }
    }

    /// [`SceneDef::describe`] with every LOD's measured deviation from LOD0 ([`LodDescription::deviation_max`]).
    pub fn describe_with_deviation(&self, cfg: &SceneConfig) -> SceneDescription {
        let mut d = self.describe(cfg);
        for (model, desc) in self.models.iter().zip(&mut d.models) {
            let lod0 = &model.chain.lods[0].mesh;
            for (lod, l) in model.chain.lods.iter().zip(&mut desc.lods) {
                let (max, mean) = crate::geometry::lod::surface_deviation(lod0, &lod.mesh);
                (l.deviation_max, l.deviation_mean) = (Some(max), Some(mean));
            }
        }
        d
    }

    fn describe_model(&self, index: usize, first: &Scene) -> ModelDescription {
        let (path, m) = (self.path(), &self.models[index]);
        let sizes: Vec<f32> = (first.instances.iter())
            .filter(|i| i.model as usize == index)
            .map(|i| i.size())
            .collect();
        let range = sizes
            .iter()
            .fold([f32::INFINITY, f32::NEG_INFINITY], |[a, b], &s| {
                [a.min(s), b.max(s)]
            });
        ModelDescription {
            name: m.name.clone(),
            radius: m.radius,
            instances: sizes.len(),
            sizes: sizes.iter().any(|&s| s != 1.0).then_some(range),
            switch_source: m.switch_source,
            lods: m
                .chain
                .info()
                .into_iter()
                .map(|info| LodDescription {
                    switch_distance: info.lod.checked_sub(1).map(|j| m.switches[j]),
                    note: match (info.lod, path) {
                        (1.., Some(p)) if info.lod <= p.unreached => Some(NOT_REACHED),
                        _ => None,
                    },
                    deviation_max: None,
                    deviation_mean: None,
                    info,
                })
                .collect(),
        }
    }
}
