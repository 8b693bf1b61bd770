//! [`SceneDef`]: what a scene name and the flags make, once per scene, and the scene of each instance count
//! built from it by the family's builder (`procedural.rs`, `bunny.rs`, `unified.rs`).

use crate::error::Result;
use crate::scene::bunny::{self, BunnyParts, BunnyPath};
use crate::scene::config::SceneConfig;
use crate::scene::kind::{CameraMode, SceneKind};
use crate::scene::model::{CameraTrack, Layout, Model, Scene};
use crate::scene::procedural;
use crate::scene::schedule::ScheduleParams;
use crate::scene::unified::{self, UnifiedParts};
use crate::scene::user::{self, UserParts};
use std::sync::Arc;

/// Scene-level facts that do not depend on the instance count: built once per scene name.
#[derive(Debug, Clone)]
pub struct SceneDef {
    pub kind: SceneKind,
    pub models: Arc<[Model]>,
    pub frames: u32,
    pub width: u32,
    pub height: u32,
    pub fov_y: f32,
    pub schedule: ScheduleParams,
    /// Instance counts to build (one block each).
    pub counts: Vec<u32>,
    pub camera_mode: CameraMode,
    pub mesh_source: String,
    /// Milliseconds spent building the models' LOD chains (once per scene, never per instance).
    pub lod_generation_ms: f64,
    /// What the scene's family adds to its models.
    pub family: Family,
    pub taa: Option<crate::effects::taa::Taa>,
    pub shadows: Option<crate::effects::shadow::Shadows>,
    /// `--impostor`: the impostor every model's chain ends in.
    pub impostor: Option<crate::geometry::impostor::Impostor>,
    /// `--shader-work`: extra ALU iterations per shaded fragment.
    pub shader_work: u32,
    /// `--camera-path`: replaces the family's camera.
    pub camera_path: Option<Arc<crate::scene::camera_path::CameraPath>>,
    /// What the family's builder noticed about its models.
    pub model_notes: Vec<String>,
}

/// The scene families and what each has beyond its models.
#[derive(Debug, Clone)]
pub enum Family {
    /// simple, windmills, trees (`procedural.rs`).
    Procedural,
    /// bunny-sweep, bunny-grid: the path and the ground (`bunny.rs`).
    Bunny(BunnyParts),
    /// bunny-halves, terrain: the blocks, camera and frustum (`unified.rs`).
    Unified(Arc<UnifiedParts>),
    /// A user's glTF scene: its instances and camera flight (`user.rs`).
    User(Arc<UserParts>),
}

impl SceneDef {
    pub fn new(kind: SceneKind, cfg: &SceneConfig) -> Result<SceneDef> {
        let pv = cfg.resolved(kind);
        let mut fov_y = cfg.fov_deg.to_radians();
        let (mut set, family) = if kind.is_unified() {
            let (set, parts) = unified::def(kind, cfg, &pv, fov_y)?;
            (set, Family::Unified(Arc::new(parts)))
        } else if kind.is_user() {
            let (set, parts) = user::def(kind, cfg, &pv, fov_y)?;
            fov_y = parts.fov_y.unwrap_or(fov_y);
            (set, Family::User(Arc::new(parts)))
        } else if kind.is_bunny() {
            let (set, parts) = bunny::def(kind, cfg, &pv, fov_y)?;
            (set, Family::Bunny(parts))
        } else {
            (
                procedural::def(kind, cfg, pv.height, fov_y)?,
                Family::Procedural,
            )
        };
        let schedule = cfg.schedule(kind)?;
        if let Some(imp) = &cfg.impostor {
            if kind.is_unified() {
                return Err(crate::error::Error::Config(format!(
                    "--impostor: scene {} is one large mesh in blocks, whose blocks have no impostor; run it on \
                     another scene",
                    kind.name()
                )));
            }
            let view = crate::scene::impostors::SwitchView {
                pixel_error: cfg.pixel_error(kind, pv.height),
                height: pv.height,
                fov_y,
            };
            let notes = crate::scene::impostors::append(&mut set.models, imp, &view, &schedule)?;
            set.notes.extend(notes);
        }
        Ok(SceneDef {
            kind,
            models: Arc::from(set.models),
            frames: pv.frames,
            width: pv.width,
            height: pv.height,
            fov_y,
            schedule,
            counts: cfg.counts(kind),
            camera_mode: cfg.camera,
            mesh_source: set.mesh_source,
            lod_generation_ms: set.lod_generation_ms,
            family,
            taa: cfg.taa,
            shadows: cfg.shadows,
            impostor: cfg.impostor,
            shader_work: cfg.shader_work,
            camera_path: cfg.camera_path.clone().map(Arc::new),
            model_notes: set.notes,
        })
    }

    /// The scene's name (the CSVs' `scene` column).
    pub fn name(&self) -> &'static str {
        self.kind.name()
    }

    /// The bunny scenes' path (sweep or grid); None for the others.
    pub fn path(&self) -> Option<BunnyPath> {
        match &self.family {
            Family::Bunny(b) => Some(b.path),
            _ => None,
        }
    }

    /// A user scene's instances and flight; None for the built-in scenes.
    pub fn user(&self) -> Option<&UserParts> {
        match &self.family {
            Family::User(u) => Some(u),
            _ => None,
        }
    }

    /// The unified scenes' blocks, camera and frustum; None for the others.
    pub fn unified(&self) -> Option<&UnifiedParts> {
        match &self.family {
            Family::Unified(u) => Some(u),
            _ => None,
        }
    }

    /// What a user should know before trusting the scene: switches the path never reaches; for a user scene,
    /// what its file holds that is not drawn as written. One line each (empty when there is nothing to say).
    pub fn notes(&self) -> Vec<String> {
        let mut notes = self.model_notes.clone();
        if let Family::User(u) = &self.family {
            notes.extend(u.notes.iter().cloned());
            notes.extend(self.unreached_on_the_path());
        } else if self.camera_path.is_some() {
            notes.extend(self.unreached_on_the_path());
        } else if let (Family::Bunny(b), Some(m)) = (&self.family, self.models.first()) {
            notes.extend(b.path.notes(self.kind, m));
        }
        notes
    }

    /// A camera path's switches never crossed: per model, the switches that no instance of it crosses on the
    /// path (its camera distances stay on one side of the switch on every frame), at the first instance count.
    fn unreached_on_the_path(&self) -> Vec<String> {
        let scene = self.instantiate(self.counts[0]);
        let mut range = vec![(f32::INFINITY, f32::NEG_INFINITY); self.models.len()];
        for (i, inst) in scene.instances.iter().enumerate() {
            if scene.ground == Some(i) {
                continue;
            }
            let r = &mut range[inst.model as usize];
            for f in 0..scene.frames {
                let d = scene.lod_distance(i, f);
                *r = (r.0.min(d), r.1.max(d));
            }
        }
        let mut notes = Vec::new();
        for (m, &(lo, hi)) in self.models.iter().zip(&range) {
            let missed: Vec<String> = m
                .switches
                .iter()
                .enumerate()
                .filter(|(_, &s)| lo.is_finite() && !(lo <= s && s <= hi))
                .map(|(j, s)| format!("LOD{} at {s:.4}", j + 1))
                .collect();
            if !missed.is_empty() {
                notes.push(format!(
                    "{}: on this camera path no instance of model {} crosses the switch to {} (its distances \
                     stay between {lo:.4} and {hi:.4}): not reached",
                    self.kind.name(),
                    m.name,
                    missed.join(", ")
                ));
            }
        }
        notes
    }

    /// The scene of `count` instances (the bunny scenes' ground with `--shadows on` comes last).
    pub fn instantiate(&self, count: u32) -> Scene {
        let layout = match &self.family {
            Family::Procedural => procedural::layout(&self.models[0], count),
            Family::Bunny(b) => bunny::layout(self.kind, &self.models[0], &b.path, count),
            Family::Unified(u) => unified::layout(u),
            Family::User(u) => user::layout(u),
        };
        let mut layout = layout;
        if let Some(path) = &self.camera_path {
            // Far enough for every instance seen from every key.
            let reach = layout
                .instances
                .iter()
                .map(|i| {
                    let r = self.models[i.model as usize].radius * i.size();
                    path.eyes()
                        .map(|e| e.distance(i.position) + r)
                        .fold(0.0f32, f32::max)
                })
                .fold(0.0f32, f32::max);
            layout.far = layout.far.max(reach * 1.5);
            layout.near = layout.near.min(
                self.models
                    .iter()
                    .map(|m| m.radius * 0.02)
                    .fold(f32::INFINITY, f32::min),
            );
            layout.track = Some(CameraTrack::Path(path.clone()));
        }
        let mut scene = self.scene(count, layout);
        if let Family::Bunny(BunnyParts {
            ground: Some(ground),
            ..
        }) = self.family
        {
            scene.ground = Some(scene.instances.len());
            scene.instances.push(ground);
        }
        scene
    }

    /// The scene of `count` instances placed as `layout` says.
    fn scene(&self, count: u32, layout: Layout) -> Scene {
        Scene {
            kind: self.kind,
            count,
            models: self.models.clone(),
            instances: layout.instances,
            motion: layout.motion,
            frames: self.frames,
            width: self.width,
            height: self.height,
            fov_y: self.fov_y,
            near: layout.near,
            far: layout.far,
            eye: layout.eye,
            forward: layout.forward,
            camera_mode: self.camera_mode,
            track: layout.track,
            schedule: self.schedule,
            unified: layout.unified,
            taa: self.taa,
            shadows: self.shadows,
            impostor: self.impostor,
            shader_work: self.shader_work,
            shader_work_weight: 0.0,
            ground: None,
            materials: match &self.family {
                Family::User(u) => u.materials.clone(),
                _ => Default::default(),
            },
        }
    }
}
