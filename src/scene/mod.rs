//! Scenes: models with LOD chains, instances, the camera and how things move. Pure CPU, no device.
//!
//! - `bunny-sweep`: the popping experiment of seed 003 section 6 (steps 1-4): one bunny starts at the nearest
//!   distance that shows all of it at LOD0 and moves at constant speed along the line of sight until past the
//!   last switch band, then back the same way. The camera is fixed.
//! - `bunny-grid`: the performance experiment of seed 003 section 6, eq. 1: n bunnies on the +x axis, evenly
//!   spaced by dx = (w - camera_x) / n, the camera looking along +x; nothing is culled, so bunnies behind
//!   others are still drawn (the paper turns occlusion culling off).

use crate::error::{Error, Result};
use crate::geometry::lod::{self, LodChain, LodInfo, DEFAULT_TARGETS};
use crate::geometry::mesh::Mesh;
use crate::scene::schedule::ScheduleParams;
use glam::{Mat4, Vec3};
use serde::Serialize;
use std::sync::Arc;

pub mod kind;
pub mod schedule;
pub mod unified;

pub use kind::{CameraMode, Profile, ProfileValues, SceneKind, SweepStart, PAPER_COUNTS};

/// Scene-defining settings after the profile is applied (built from the flags by `crate::cli::config`).
#[derive(Debug, Clone, Serialize)]
pub struct SceneConfig {
    pub profile: Profile,
    pub camera: CameraMode,
    /// Explicit overrides; None = the profile's value for each scene.
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub frames: Option<u32>,
    pub mesh: Option<std::path::PathBuf>,
    /// `--pixel-error`; None = the scene's default ([`SceneConfig::pixel_error`]).
    pub pixel_error: Option<f32>,
    /// `--sweep-start`; None = the profile's.
    pub sweep_start: Option<SweepStart>,
    pub switch_distances: Option<Vec<f32>>,
    /// `--partition` (bunny-halves, terrain).
    pub partition: crate::geometry::blocks::PartitionMode,
    /// `--blocks`; None = the profile's.
    pub blocks: Option<u32>,
    pub counts: Option<Vec<u32>>,
    pub fov_deg: f32,
    pub schedule: ScheduleParams,
    /// `--taa on`: the jitter of every frame's camera and the resolve after it.
    pub taa: Option<crate::effects::taa::Taa>,
    /// `--shadows on`: the shadow map (and a ground under the bunny scenes).
    pub shadows: Option<crate::effects::shadow::Shadows>,
}

impl SceneConfig {
    /// The profile's values for `kind` with the explicit flags applied.
    pub fn resolved(&self, kind: SceneKind) -> ProfileValues {
        let p = kind.profile(self.profile);
        ProfileValues {
            width: self.width.unwrap_or(p.width),
            height: self.height.unwrap_or(p.height),
            frames: self.frames.unwrap_or(p.frames),
            warmup: p.warmup,
            sweep_start: self.sweep_start.unwrap_or(p.sweep_start),
        }
    }

    /// The screen-space error (pixels) the switch distances of `kind` are made for, at viewport height `height`:
    /// `--pixel-error`, or by default one pixel at [`PAPER_HEIGHT`] for the bunny scenes (seed 003 ran them at
    /// 800x600; this keeps their switch distances and path the same at every viewport size, so a smaller
    /// profile is the same experiment at a lower resolution), except for a close-up path (1 pixel at this
    /// viewport), and 1 for the procedural scenes (whose camera flights start beyond the last switch at any
    /// size).
    pub fn pixel_error(&self, kind: SceneKind, height: u32) -> f32 {
        let close_up = self.resolved(kind).sweep_start == SweepStart::CloseUp;
        match self.pixel_error {
            Some(p) => p,
            None if kind.is_bunny() && !close_up => height as f32 / PAPER_HEIGHT as f32,
            None => 1.0,
        }
    }

    /// The instance counts of `kind`: `--count`, or the profile's (bunny-sweep is always one bunny).
    pub fn counts(&self, kind: SceneKind) -> Vec<u32> {
        match &self.counts {
            Some(c) if !kind.single_count() => c.clone(),
            _ => kind.profile_counts(self.profile),
        }
    }
}

/// Viewport height of seed 003's experiments (800x600): the bunny scenes' default `--pixel-error` is one pixel
/// at this height.
pub const PAPER_HEIGHT: u32 = 600;

/// Seed of the procedural scenes' models and layouts (tree shapes, instance jitter and yaw): fixed, so a
/// scene is the same picture whatever `--seed` drives (the methods' noise).
pub const SCENE_SEED: u64 = 2008;

/// Rotation of the windmill blades per frame, radians (one turn in 5 s at 60 fps).
pub const WINDMILL_SPIN_PER_FRAME: f32 = std::f32::consts::TAU / 300.0;

/// The Stanford bunny, npm `bunny@1.0.1` (see scenes/README.md), compiled in so the binary needs no files.
pub const BUNNY_OBJ: &[u8] = include_bytes!("../../scenes/bunny.obj");

/// Background colour (linear RGB) behind every scene.
pub const BACKGROUND: [f32; 3] = [0.045, 0.05, 0.06];

/// A model: its LOD chain, colour and switch distances.
#[derive(Debug, Clone)]
pub struct Model {
    pub name: String,
    /// Base colour, linear RGB.
    pub color: [f32; 3],
    /// Colour per LOD (SIMPLE's LODs differ in colour); empty = `color` for every LOD.
    pub lod_colors: Vec<[f32; 3]>,
    /// Rotation of the animated parts (windmill blades) per frame, radians; 0 = not animated.
    pub spin_per_frame: f32,
    pub chain: LodChain,
    /// Switch distance of LOD1, LOD2, ... in world units.
    pub switches: Vec<f32>,
    /// Where the switch distances came from: "pixel-error" or "override".
    pub switch_source: &'static str,
    /// Bounding-sphere centre (object space) and radius (world units, after scale).
    pub center: Vec3,
    pub radius: f32,
    pub scale: f32,
}

#[derive(Debug, Clone, Copy)]
pub struct Instance {
    pub model: u32,
    /// Position of the model's bounding-sphere centre at frame 0 (world).
    pub position: Vec3,
    /// Rotation about +y, radians.
    pub yaw: f32,
}

/// How instances move over the frames.
#[derive(Debug, Clone, Copy, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Motion {
    Static,
    /// Every instance moves along +x from `near` to `far` (distance from the camera) in the first half of the
    /// frames and back in the second, at constant speed.
    SweepX {
        near: f32,
        far: f32,
    },
}

pub const ORBIT_AMPLITUDE_DEG: f32 = 30.0;
pub const ORBIT_PERIOD_FRAMES: f32 = 240.0;

#[derive(Debug, Clone, Copy)]
pub struct Camera {
    pub eye: Vec3,
    pub view: Mat4,
    pub proj: Mat4,
}

impl Camera {
    pub fn view_proj(&self) -> Mat4 {
        self.proj * self.view
    }
}

/// A scene ready to render: everything a frame needs is a function of the frame number.
#[derive(Debug, Clone)]
pub struct Scene {
    pub kind: SceneKind,
    /// The `count` column of the CSVs: the instance count this block was built for.
    pub count: u32,
    pub models: Arc<[Model]>,
    pub instances: Vec<Instance>,
    pub motion: Motion,
    pub frames: u32,
    pub width: u32,
    pub height: u32,
    pub fov_y: f32,
    pub near: f32,
    pub far: f32,
    pub eye: Vec3,
    pub forward: Vec3,
    pub camera_mode: CameraMode,
    /// Camera flight of the procedural scenes: the eye moves from `.0` to `.1` at constant speed over the
    /// frames, looking along `forward`; None = the eye stays at `eye`.
    pub flight: Option<(Vec3, Vec3)>,
    /// bunny-halves' camera: once around `center` at `distance`, `elevation` radians above it (looking at it).
    pub turntable: Option<(Vec3, f32, f32)>,
    pub schedule: ScheduleParams,
    /// The unified-LOD scenes' blocks' mesh, seams and cluster DAG (every instance is a block at the identity
    /// transform); None elsewhere.
    pub unified: Option<Arc<unified::Unified>>,
    /// `--taa on`: every frame's projection is jittered ([`Scene::camera`]) and resolved (`gpu/taa.rs`).
    pub taa: Option<crate::effects::taa::Taa>,
    /// `--shadows on`: the shadow map's settings (src/shadow.rs).
    pub shadows: Option<crate::effects::shadow::Shadows>,
    /// The instance that is the bunny scenes' ground with `--shadows on`: static, always LOD0, receives
    /// shadows and casts none, left out of `lod_mean`.
    pub ground: Option<usize>,
}

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
    /// The bunny scenes' path (sweep or grid); None for the procedural scenes.
    pub path: Option<BunnyPath>,
    /// The unified scenes' blocks, camera and frustum.
    pub unified: Option<Arc<UnifiedParts>>,
    pub taa: Option<crate::effects::taa::Taa>,
    pub shadows: Option<crate::effects::shadow::Shadows>,
    /// `--shadows on` in the bunny scenes: the ground's model and position.
    pub ground: Option<(u32, Vec3)>,
}

/// What a unified scene's blocks are built from, once per scene.
#[derive(Debug)]
pub struct UnifiedParts {
    pub instances: Vec<Instance>,
    pub data: Arc<unified::Unified>,
    pub camera: unified::UnifiedCamera,
    pub forward: Vec3,
    pub near: f32,
    pub far: f32,
}

/// Where the bunny scenes' bunnies are: bunny-sweep's bunny moves from `near` to `far` and back, bunny-grid's
/// bunnies stand between them (eq. 1 of seed 003). Distances from the camera to the bounding-sphere centre.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BunnyPath {
    pub near: f32,
    pub far: f32,
    /// Nearest distance at which the model's bounding sphere fits the view (the narrower of the two fovs):
    /// `near` is never less, so the camera is never inside the model.
    pub fit: f32,
    /// How many switches, from LOD1 on, lie nearer than `near` (their band starts nearer): the path never
    /// reaches them, and every frame shows LOD `unreached` or coarser.
    pub unreached: usize,
    pub start: SweepStart,
}

impl BunnyPath {
    /// The path for `m` at this viewport: it starts at `fit`, or, when `fit` lies inside a switch's transition
    /// band, just past that band (so frame 0 is never in a transition), and ends past the last band with a
    /// margin so the coarsest LOD is seen for a while (at least a quarter beyond the start).
    ///
    /// A close-up (`SweepStart::CloseUp`) starts at `fit` when the first band lies beyond it, else at 0.9 of
    /// the first band's near edge, and reaches every switch.
    pub fn new(
        m: &Model,
        schedule: &ScheduleParams,
        start: SweepStart,
        width: u32,
        height: u32,
        fov_y: f32,
    ) -> Self {
        let (b, h) = (schedule.band, schedule.hysteresis);
        let aspect = width as f32 / height as f32;
        let half_fov = (fov_y * 0.5).min(((fov_y * 0.5).tan() * aspect).atan());
        let fit = m.radius / half_fov.sin();
        let first_band = m.switches.first().map(|s| s * (1.0 - h) * (1.0 - b));
        let (near, unreached) = match (start, first_band) {
            (SweepStart::CloseUp, Some(fb)) if fit >= fb * 0.95 => (fb * 0.9, 0),
            (SweepStart::CloseUp, _) => (fit, 0),
            (SweepStart::Fit, _) => {
                let unreached = m
                    .switches
                    .iter()
                    .take_while(|&&s| s * (1.0 - h) * (1.0 - b) < fit)
                    .count();
                let near = match unreached {
                    0 => fit,
                    n => fit.max(m.switches[n - 1] * (1.0 + h) * (1.0 + b) * 1.01),
                };
                (near, unreached)
            }
        };
        let last = m.switches.last().copied().unwrap_or(m.radius);
        let far = (last * (1.0 + h) * (1.0 + b) * 1.15).max(near * 1.25);
        BunnyPath {
            near,
            far,
            fit,
            unreached,
            start,
        }
    }
}

impl SceneDef {
    pub fn new(kind: SceneKind, cfg: &SceneConfig) -> Result<SceneDef> {
        let pv = cfg.resolved(kind);
        let fov_y = cfg.fov_deg.to_radians();
        if kind.is_unified() {
            return unified_def(kind, cfg, &pv, fov_y);
        }
        if !kind.is_bunny() {
            return procedural_def(kind, cfg, pv.frames, pv.width, pv.height, fov_y);
        }
        let started = std::time::Instant::now();
        const BUILT_IN: &str = "scenes/bunny.obj (built in)";
        let (mesh, mesh_source, file) = match &cfg.mesh {
            Some(p) => (
                Mesh::load(p)?,
                p.display().to_string(),
                p.display().to_string(),
            ),
            None => (
                Mesh::parse_obj(BUILT_IN, BUNNY_OBJ)?,
                "scenes/bunny.obj (npm bunny@1.0.1, built in)".to_string(),
                BUILT_IN.to_string(),
            ),
        };
        let model = bunny_model(kind, &file, &mesh, cfg, pv.height, fov_y)?;
        let path = BunnyPath::new(
            &model,
            &cfg.schedule,
            pv.sweep_start,
            pv.width,
            pv.height,
            fov_y,
        );
        let lod_generation_ms = started.elapsed().as_secs_f64() * 1e3;
        let mut models = vec![model];
        let ground =
            cfg.shadows
                .map(|_| ground_model(&models[0], path.far))
                .map(|(m, position)| {
                    models.push(m);
                    (1, position)
                });
        Ok(SceneDef {
            kind,
            models: Arc::from(models),
            frames: pv.frames,
            width: pv.width,
            height: pv.height,
            fov_y,
            schedule: cfg.schedule,
            counts: cfg.counts(kind),
            camera_mode: cfg.camera,
            mesh_source,
            lod_generation_ms,
            path: Some(path),
            unified: None,
            taa: cfg.taa,
            shadows: cfg.shadows,
            ground,
        })
    }

    /// What a user should know before trusting the scene: switches the bunny path never reaches. One line each
    /// scene (empty when there is nothing to say).
    pub fn notes(&self) -> Vec<String> {
        let (Some(path), Some(m)) = (self.path, self.models.first()) else {
            return Vec::new();
        };
        if path.near < m.radius {
            return vec![format!(
                "{}: a close-up (--sweep-start close-up): the path starts at {:.4}, inside the model's bounding \
                 sphere (radius {:.4}), so the camera may be inside the model",
                self.name(),
                path.near,
                m.radius
            )];
        }
        if path.unreached == 0 {
            return Vec::new();
        }
        let lods: Vec<String> = m.switches[..path.unreached]
            .iter()
            .enumerate()
            .map(|(j, s)| format!("LOD{} at {s:.4}", j + 1))
            .collect();
        let start = match self.kind {
            SceneKind::BunnyGrid => "the first bunny",
            _ => "the sweep's start",
        };
        vec![format!(
            "{}: the switch to {} lies nearer than {start} ({:.4}, where the model's bounding sphere fits the \
             view): not reached by the sweep; a smaller --pixel-error moves the switches farther",
            self.name(),
            lods.join(", "),
            path.near
        )]
    }

    pub fn instantiate(&self, count: u32) -> Scene {
        let mut scene = Scene {
            taa: self.taa,
            shadows: self.shadows,
            ..self.instantiate_without_taa(count)
        };
        if let Some((model, position)) = self.ground {
            scene.ground = Some(scene.instances.len());
            scene.instances.push(Instance {
                model,
                position,
                yaw: 0.0,
            });
        }
        scene
    }

    fn instantiate_without_taa(&self, count: u32) -> Scene {
        if let Some(u) = &self.unified {
            return self.instantiate_unified(count, u);
        }
        // The bunny scenes, and only they, have a path (SceneDef::new).
        let Some(path) = self.path else {
            return self.instantiate_field(count);
        };
        let m = &self.models[0];
        let (near_d, far_d) = (path.near, path.far);
        let yaw = BUNNY_YAW;
        let (instances, motion, far_plane) = match self.kind {
            SceneKind::BunnyGrid => {
                // eq. 1: dx = (w - camera_x) / n, objects from the nearest fully visible distance on.
                let camera_x = 0.0;
                let w = camera_x + far_d;
                let dx = (w - camera_x) / count as f32;
                let inst = (0..count)
                    .map(|i| Instance {
                        model: 0,
                        position: Vec3::new(camera_x + near_d + i as f32 * dx, 0.0, 0.0),
                        yaw,
                    })
                    .collect();
                (inst, Motion::Static, near_d + w + 2.0 * m.radius)
            }
            _ => (
                vec![Instance {
                    model: 0,
                    position: Vec3::new(near_d, 0.0, 0.0),
                    yaw,
                }],
                Motion::SweepX {
                    near: near_d,
                    far: far_d,
                },
                far_d + 2.0 * m.radius,
            ),
        };
        Scene {
            kind: self.kind,
            count,
            models: self.models.clone(),
            instances,
            motion,
            frames: self.frames,
            width: self.width,
            height: self.height,
            fov_y: self.fov_y,
            near: m.radius * 0.02,
            far: far_plane,
            eye: Vec3::ZERO,
            forward: Vec3::X,
            camera_mode: self.camera_mode,
            flight: None,
            turntable: None,
            schedule: self.schedule,
            unified: None,
            taa: None,
            shadows: None,
            ground: None,
        }
    }

    /// A unified scene: one instance per block, at the identity transform.
    fn instantiate_unified(&self, count: u32, u: &UnifiedParts) -> Scene {
        let (eye, flight, turntable) = match u.camera {
            unified::UnifiedCamera::Flight(from, to) => (from, Some((from, to)), None),
            unified::UnifiedCamera::Turntable {
                center,
                distance,
                elevation,
            } => (
                center + Vec3::new(0.0, elevation.sin(), elevation.cos()) * distance,
                None,
                Some((center, distance, elevation)),
            ),
        };
        Scene {
            kind: self.kind,
            count,
            models: self.models.clone(),
            instances: u.instances.clone(),
            motion: Motion::Static,
            frames: self.frames,
            width: self.width,
            height: self.height,
            fov_y: self.fov_y,
            near: u.near,
            far: u.far,
            eye,
            forward: u.forward,
            camera_mode: self.camera_mode,
            flight,
            turntable,
            schedule: self.schedule,
            unified: Some(u.data.clone()),
            taa: None,
            shadows: None,
            ground: None,
        }
    }

    /// The procedural scenes (seed 000 section 4): `count` instances on a jittered square grid on the ground
    /// plane (spacing 2.5 model radii, jitter +-0.3 spacing, random yaw; SCENE_SEED), and a camera flight
    /// along +z at a fixed height over the middle of the field, looking 12 degrees down: it starts back from
    /// the field's near edge by 1.1 times the last switch distance (so the nearest instances start at the
    /// coarsest LOD) and ends over the far edge, so instances keep entering and leaving transitions.
    fn instantiate_field(&self, count: u32) -> Scene {
        let m = &self.models[0];
        let spacing = 2.5 * m.radius;
        let side = (count as f32).sqrt().ceil().max(1.0) as u32;
        let half = (side as f32 - 1.0) * spacing * 0.5;
        let mut rng = crate::rng::SplitMix64::new(SCENE_SEED ^ count as u64);
        let instances: Vec<Instance> = (0..count)
            .map(|i| {
                let (gx, gz) = ((i % side) as f32, (i / side) as f32);
                let jx = (rng.next_f32() - 0.5) * 0.6 * spacing;
                let jz = (rng.next_f32() - 0.5) * 0.6 * spacing;
                Instance {
                    model: 0,
                    // The bounding-sphere centre's height above the ground (the model's base sits at y = 0).
                    position: Vec3::new(
                        gx * spacing - half + jx,
                        m.center.y,
                        gz * spacing - half + jz,
                    ),
                    yaw: rng.next_f32() * std::f32::consts::TAU,
                }
            })
            .collect();
        let last = m.switches.last().copied().unwrap_or(10.0 * m.radius);
        let height = 2.0 * m.radius + m.center.y;
        let rows = count.div_ceil(side) as f32;
        let z_far = (rows - 1.0) * spacing - half;
        let from = Vec3::new(0.0, height, -half - 1.1 * last);
        let to = Vec3::new(0.0, height, z_far);
        let pitch = 12f32.to_radians();
        let forward = Vec3::new(0.0, -pitch.sin(), pitch.cos());
        let extent = (to - from).length() + 2.0 * half + 4.0 * m.radius + last;
        Scene {
            kind: self.kind,
            count,
            models: self.models.clone(),
            instances,
            motion: Motion::Static,
            frames: self.frames,
            width: self.width,
            height: self.height,
            fov_y: self.fov_y,
            near: m.radius * 0.02,
            far: extent * 1.5,
            eye: from,
            forward,
            camera_mode: self.camera_mode,
            flight: Some((from, to)),
            turntable: None,
            schedule: self.schedule,
            unified: None,
            taa: None,
            shadows: None,
            ground: None,
        }
    }
}

/// A unified scene (`scene/unified.rs`): its mesh (`--mesh`, the built-in bunny, or the terrain), its blocks as
/// models with one instance each, and its seams and cluster DAG.
fn unified_def(
    kind: SceneKind,
    cfg: &SceneConfig,
    pv: &ProfileValues,
    fov_y: f32,
) -> Result<SceneDef> {
    if cfg.switch_distances.is_some() {
        return Err(Error::Config(format!(
            "--switch-distances does not apply to {}: each of its blocks has switch distances of its own (set \
             --pixel-error)",
            kind.name()
        )));
    }
    let started = std::time::Instant::now();
    let quads = SceneKind::terrain_quads(cfg.profile);
    let (mesh, mesh_source) = match (&cfg.mesh, kind) {
        (Some(p), _) => (Mesh::load(p)?, p.display().to_string()),
        (None, SceneKind::BunnyHalves) => (
            Mesh::parse_obj("scenes/bunny.obj (built in)", BUNNY_OBJ)?,
            "scenes/bunny.obj (npm bunny@1.0.1, built in)".to_string(),
        ),
        (None, _) => (
            crate::geometry::terrain::terrain_mesh(SCENE_SEED, quads)?,
            format!("procedural (src/terrain.rs, seed SCENE_SEED = 2008, {quads} x {quads} cells)"),
        ),
    };
    let u = unified::build(unified::UnifiedInput {
        kind,
        mesh,
        mesh_source: &mesh_source,
        partition: cfg.partition,
        blocks: cfg
            .blocks
            .unwrap_or_else(|| SceneKind::terrain_blocks(cfg.profile)),
        pixel_error: cfg.pixel_error(kind, pv.height),
        schedule: &cfg.schedule,
        width: pv.width,
        height: pv.height,
        fov_y,
    })?;
    let instances = (0..u.blocks.len())
        .map(|i| Instance {
            model: i as u32,
            position: u.blocks[i].center,
            yaw: 0.0,
        })
        .collect();
    let models: Vec<Model> = u
        .blocks
        .into_iter()
        .map(|b| Model {
            name: b.name,
            color: b.color,
            lod_colors: Vec::new(),
            spin_per_frame: 0.0,
            chain: b.chain,
            switches: b.switches,
            switch_source: b.switch_source,
            center: b.center,
            radius: b.radius,
            scale: 1.0,
        })
        .collect();
    Ok(SceneDef {
        kind,
        models: Arc::from(models),
        frames: pv.frames,
        width: pv.width,
        height: pv.height,
        fov_y,
        schedule: cfg.schedule,
        counts: cfg.counts(kind),
        camera_mode: cfg.camera,
        mesh_source,
        lod_generation_ms: started.elapsed().as_secs_f64() * 1e3,
        path: None,
        taa: cfg.taa,
        shadows: cfg.shadows,
        ground: None,
        unified: Some(Arc::new(UnifiedParts {
            instances,
            data: u.unified,
            camera: u.camera,
            forward: u.forward,
            near: u.near,
            far: u.far,
        })),
    })
}

/// The models of a procedural scene, built once: SIMPLE's sphere and box, the windmill, the tree
/// (`crate::geometry::procgen`). Switch distances: from the measured LOD errors and `--pixel-error` like the bunny's,
/// except SIMPLE, whose box is no approximation of the sphere at any distance: it switches at 12 sphere
/// radii (at 320x240 and 60 degrees the sphere is then about 17 pixels across), or at `--switch-distances`.
fn procedural_def(
    kind: SceneKind,
    cfg: &SceneConfig,
    frames: u32,
    width: u32,
    height: u32,
    fov_y: f32,
) -> Result<SceneDef> {
    let started = std::time::Instant::now();
    let name = kind.name();
    let (chain, spin, source) = match kind {
        SceneKind::Simple => (
            crate::geometry::procgen::simple_chain()?,
            0.0,
            "procedural (src/procgen.rs: sphere and box)",
        ),
        SceneKind::Windmills => (
            crate::geometry::procgen::windmill_chain()?,
            WINDMILL_SPIN_PER_FRAME,
            "procedural (src/procgen.rs: windmill)",
        ),
        _ => (
            crate::geometry::procgen::tree_chain(SCENE_SEED)?,
            0.0,
            "procedural (src/procgen.rs: tree, seed SCENE_SEED = 2008)",
        ),
    };
    let lod_generation_ms = started.elapsed().as_secs_f64() * 1e3;
    let lod_colors = chain.lod_colors.clone();
    let chain = chain.chain;
    let (center, radius) = chain.lods[0].mesh.bounding_sphere();
    let scale = 1.0;
    let (switches, switch_source) = match (&cfg.switch_distances, kind) {
        (Some(s), _) => {
            if s.len() != chain.lods.len() - 1 {
                return Err(Error::Config(format!(
                    "--switch-distances has {} values but {name} has {} LODs after LOD0",
                    s.len(),
                    chain.lods.len() - 1
                )));
            }
            (s.clone(), "override")
        }
        (None, SceneKind::Simple) => (vec![12.0 * radius], "scene"),
        (None, _) => (
            lod::switch_distances(&chain, scale, cfg.pixel_error(kind, height), height, fov_y),
            "pixel-error",
        ),
    };
    cfg.schedule.check_switches(name, &switches)?;
    let model = Model {
        name: name.trim_end_matches('s').to_string(),
        color: lod_colors.first().copied().unwrap_or([0.7; 3]),
        lod_colors,
        spin_per_frame: spin,
        chain,
        switches,
        switch_source,
        center,
        radius: radius * scale,
        scale,
    };
    Ok(SceneDef {
        kind,
        models: Arc::from(vec![model]),
        frames,
        width,
        height,
        fov_y,
        schedule: cfg.schedule,
        counts: cfg.counts(kind),
        camera_mode: cfg.camera,
        mesh_source: source.to_string(),
        lod_generation_ms,
        path: None,
        unified: None,
        taa: cfg.taa,
        shadows: cfg.shadows,
        ground: None,
    })
}

/// Yaw of the bunny instances: the classic three-quarter view, face to the right.
pub const BUNNY_YAW: f32 = 1.0;

/// The model of bunny scene `kind` from `mesh`, read from `file` (named in error messages).
fn bunny_model(
    kind: SceneKind,
    file: &str,
    mesh: &Mesh,
    cfg: &SceneConfig,
    height: u32,
    fov_y: f32,
) -> Result<Model> {
    let bad = |problem: String| Error::Mesh {
        path: file.to_string(),
        problem,
    };
    mesh.check_area(file)?;
    let chain = LodChain::build(file, mesh, &DEFAULT_TARGETS)?;
    let (center, radius) = chain.lods[0].mesh.bounding_sphere();
    if !(radius.is_finite() && radius > 0.0) {
        return Err(bad("has zero extent".into()));
    }
    let scale = 1.0;
    let (switches, switch_source) = match &cfg.switch_distances {
        Some(s) => {
            if s.len() != chain.lods.len() - 1 {
                return Err(Error::Config(format!(
                    "--switch-distances has {} values but the bunny has {} LODs after LOD0",
                    s.len(),
                    chain.lods.len() - 1
                )));
            }
            (s.clone(), "override")
        }
        None => (
            lod::switch_distances(&chain, scale, cfg.pixel_error(kind, height), height, fov_y),
            "pixel-error",
        ),
    };
    cfg.schedule.check_switches("bunny", &switches)?;
    Ok(Model {
        name: "bunny".into(),
        color: [0.72, 0.45, 0.28],
        lod_colors: Vec::new(),
        spin_per_frame: 0.0,
        chain,
        switches,
        switch_source,
        center,
        radius: radius * scale,
        scale,
    })
}

/// The bunny scenes' ground with `--shadows on`: a grey quad under the bunny's lowest point, from behind the
/// camera (at the origin, looking along +x) to past the path's far end, as wide as half its length; one LOD,
/// no switches. Returns the model and its position.
fn ground_model(bunny: &Model, far: f32) -> (Model, Vec3) {
    let r = bunny.radius;
    let lowest = bunny.chain.lods[0]
        .mesh
        .positions
        .iter()
        .map(|p| (p[1] - bunny.center.y) * bunny.scale)
        .fold(0.0f32, f32::min);
    let (hx, x_mid) = ((far + 3.0 * r) * 0.5, (far + r) * 0.5);
    let hz = (hx * 0.5).max(3.0 * r);
    let positions = vec![
        [-hx, 0.0, -hz],
        [hx, 0.0, -hz],
        [hx, 0.0, hz],
        [-hx, 0.0, hz],
    ];
    let mesh = Mesh {
        normals: vec![[0.0, 1.0, 0.0]; 4],
        aux: vec![[0.0; 4]; 4],
        indices: vec![0, 2, 1, 0, 3, 2],
        positions,
    };
    let model = Model {
        name: "ground".into(),
        color: [0.45, 0.45, 0.45],
        lod_colors: Vec::new(),
        spin_per_frame: 0.0,
        chain: LodChain {
            lods: vec![crate::geometry::lod::Lod {
                mesh,
                target_fraction: 1.0,
                error_abs: 0.0,
            }],
        },
        switches: Vec::new(),
        switch_source: "none (the ground)",
        center: Vec3::ZERO,
        radius: (hx * hx + hz * hz).sqrt(),
        scale: 1.0,
    };
    (model, Vec3::new(x_mid, lowest, 0.0))
}

impl SceneDef {
    /// The scene's name (the CSVs' `scene` column).
    pub fn name(&self) -> &'static str {
        self.kind.name()
    }
}

impl Model {
    /// Base colour of LOD `lod`, linear RGB.
    pub fn color_of(&self, lod: u32) -> [f32; 3] {
        self.lod_colors
            .get(lod as usize)
            .copied()
            .unwrap_or(self.color)
    }
}

impl Scene {
    /// The scene's name (the CSVs' `scene` column).
    pub fn name(&self) -> &'static str {
        self.kind.name()
    }

    /// Animation angle of instance `i` on `frame` (radians; windmill blades), with a fixed per-instance phase
    /// so that neighbours do not turn in step.
    pub fn animation_angle(&self, i: usize, frame: u32) -> f32 {
        let m = &self.models[self.instances[i].model as usize];
        if m.spin_per_frame == 0.0 {
            return 0.0;
        }
        let phase = (i as f32 * 2.399_963).rem_euclid(std::f32::consts::TAU);
        (phase + m.spin_per_frame * frame as f32).rem_euclid(std::f32::consts::TAU)
    }

    /// Where instance `i`'s centre is on `frame`.
    pub fn instance_position(&self, i: usize, frame: u32) -> Vec3 {
        let inst = &self.instances[i];
        if self.ground == Some(i) {
            return inst.position;
        }
        match self.motion {
            Motion::Static => inst.position,
            Motion::SweepX { near, far } => {
                let d = match self.camera_mode {
                    CameraMode::Dolly => near,
                    _ => sweep_distance(near, far, self.frames, frame),
                };
                Vec3::new(self.eye.x + d, inst.position.y, inst.position.z)
            }
        }
    }

    /// Object-to-world matrix of instance `i` on `frame`: the model's bounding-sphere centre goes to the
    /// instance position.
    pub fn instance_matrix(&self, i: usize, frame: u32) -> Mat4 {
        if self.unified.is_some() {
            // Blocks and seams are in world space: every block shares one exact transform with its seams.
            return Mat4::IDENTITY;
        }
        let inst = &self.instances[i];
        let m = &self.models[inst.model as usize];
        Mat4::from_translation(self.instance_position(i, frame))
            * Mat4::from_rotation_y(inst.yaw)
            * Mat4::from_scale(Vec3::splat(m.scale))
            * Mat4::from_translation(-m.center)
    }

    /// Distance from the camera to instance `i`'s centre on `frame` (what LOD selection uses).
    pub fn instance_distance(&self, i: usize, frame: u32) -> f32 {
        self.instance_position(i, frame)
            .distance(self.camera(frame).eye)
    }

    pub fn camera(&self, frame: u32) -> Camera {
        let (eye, view) = match (self.camera_mode, self.flight, self.turntable) {
            (_, _, Some((center, distance, elevation))) => {
                let theta = std::f32::consts::TAU * frame as f32 / self.frames.max(1) as f32;
                let dir = Vec3::new(
                    elevation.cos() * theta.sin(),
                    elevation.sin(),
                    elevation.cos() * theta.cos(),
                );
                let eye = center + dir * distance;
                (eye, Mat4::look_at_rh(eye, center, Vec3::Y))
            }
            (_, Some((from, to)), None) => {
                let t = if self.frames > 1 {
                    frame as f32 / (self.frames - 1) as f32
                } else {
                    0.0
                };
                let eye = from.lerp(to, t);
                (eye, Mat4::look_at_rh(eye, eye + self.forward, Vec3::Y))
            }
            (CameraMode::Fixed, None, None) => (
                self.eye,
                Mat4::look_at_rh(self.eye, self.eye + self.forward, Vec3::Y),
            ),
            (CameraMode::Dolly, None, None) => {
                let eye = match self.motion {
                    // Back from the bunny by as much as the fixed camera's bunny has moved away from it.
                    Motion::SweepX { near, far } => {
                        self.eye - Vec3::X * (sweep_distance(near, far, self.frames, frame) - near)
                    }
                    Motion::Static => self.eye,
                };
                (eye, Mat4::look_at_rh(eye, eye + self.forward, Vec3::Y))
            }
            (CameraMode::Orbit, None, None) => {
                let target = match self.instances.first() {
                    Some(_) => self.instance_position(0, frame),
                    None => self.eye + self.forward,
                };
                let d = target.distance(self.eye);
                let phase = std::f32::consts::TAU * frame as f32 / ORBIT_PERIOD_FRAMES;
                let phi = ORBIT_AMPLITUDE_DEG.to_radians() * phase.sin();
                let dir = glam::Quat::from_rotation_y(phi) * self.forward;
                let eye = target - dir * d;
                (eye, Mat4::look_at_rh(eye, target, Vec3::Y))
            }
        };
        let mut proj = Mat4::perspective_rh(
            self.fov_y,
            self.width as f32 / self.height as f32,
            self.near,
            self.far,
        );
        if let Some(taa) = &self.taa {
            let (x, y) = taa.jitter_ndc(frame, self.width, self.height);
            proj = Mat4::from_translation(Vec3::new(x, y, 0.0)) * proj;
        }
        Camera { eye, view, proj }
    }

    pub fn triangles_lod0(&self) -> u64 {
        self.instances
            .iter()
            .map(|i| {
                self.models[i.model as usize].chain.lods[0]
                    .mesh
                    .triangle_count() as u64
            })
            .sum()
    }
}

/// Constant-speed distance along the sweep: out from `near` to `far` over the first half of the frames, back
/// over the second; frame f and frame N-1-f are at the same distance.
pub fn sweep_distance(near: f32, far: f32, frames: u32, frame: u32) -> f32 {
    if frames < 2 {
        return near;
    }
    let half = (frames - 1) as f32 / 2.0;
    let u = frame as f32 / half;
    let u = if u <= 1.0 { u } else { 2.0 - u };
    near + (far - near) * u
}

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
    pub unified: Option<unified::Preprocessing>,
}

#[derive(Debug, Clone, Serialize)]
pub struct ModelDescription {
    pub name: String,
    pub radius: f32,
    pub switch_source: &'static str,
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
            fov_y_deg: cfg.fov_deg,
            frames: self.frames,
            instance_counts: self.counts.clone(),
            mesh: self.mesh_source.clone(),
            pixel_error: cfg.pixel_error(self.kind, self.height),
            schedule: self.schedule,
            models: self
                .models
                .iter()
                .map(|m| ModelDescription {
                    name: m.name.clone(),
                    radius: m.radius,
                    switch_source: m.switch_source,
                    lods: m
                        .chain
                        .info()
                        .into_iter()
                        .map(|info| LodDescription {
                            switch_distance: info.lod.checked_sub(1).map(|j| m.switches[j]),
                            note: match (info.lod, self.path) {
                                (1.., Some(p)) if info.lod <= p.unreached => Some(NOT_REACHED),
                                _ => None,
                            },
                            info,
                        })
                        .collect(),
                })
                .collect(),
            motion: first.motion,
            camera: self.camera_mode,
            lod_generation_ms: self.lod_generation_ms,
            instance_build_ms,
            path: self.path,
            notes: self.notes(),
            unified: self.unified.as_ref().map(|u| u.data.preprocessing.clone()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::{Cli, Command};
    use clap::Parser;

    fn cfg(extra: &[&str]) -> SceneConfig {
        let mut argv = vec!["lodbench", "describe", "--scene", "bunny-sweep"];
        argv.extend_from_slice(extra);
        match Cli::try_parse_from(argv).unwrap().command {
            Command::Describe(d) => SceneConfig::from_args(&d.scene_args).unwrap(),
            _ => unreachable!(),
        }
    }

    #[test]
    fn sweep_goes_out_and_back_at_constant_speed() {
        let n = 11;
        let d: Vec<f32> = (0..n).map(|f| sweep_distance(1.0, 6.0, n, f)).collect();
        assert_eq!(d[0], 1.0);
        assert_eq!(d[5], 6.0);
        assert_eq!(d[10], 1.0);
        for f in 0..n as usize {
            assert!((d[f] - d[n as usize - 1 - f]).abs() < 1e-6);
        }
        for w in d[..6].windows(2) {
            assert!((w[1] - w[0] - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn sweep_passes_every_switch_starting_at_lod0() {
        let def = SceneDef::new(SceneKind::BunnySweep, &cfg(&[])).unwrap();
        let s = def.instantiate(1);
        let m = &s.models[0];
        let d0 = s.instance_distance(0, 0);
        let dmax = (0..s.frames)
            .map(|f| s.instance_distance(0, f))
            .fold(0.0, f32::max);
        assert!(d0 < m.switches[0] * 0.95);
        assert!(dmax > m.switches.last().unwrap() * 1.05);
    }

    #[test]
    fn grid_follows_equation_1() {
        let c = cfg(&["--count", "50,7"]);
        let def = SceneDef::new(SceneKind::BunnyGrid, &c).unwrap();
        assert_eq!(def.counts, vec![50, 7]);
        let s = def.instantiate(7);
        assert_eq!(s.instances.len(), 7);
        let xs: Vec<f32> = s.instances.iter().map(|i| i.position.x).collect();
        let dx = xs[1] - xs[0];
        for w in xs.windows(2) {
            assert!((w[1] - w[0] - dx).abs() < 1e-3);
        }
        let last = *s.models[0].switches.last().unwrap();
        // w - camera_x = n dx reaches past the last switch band.
        assert!(7.0 * dx > last * 1.05);
        assert!(s
            .instances
            .iter()
            .all(|i| i.position.y == 0.0 && i.position.z == 0.0));
        assert_eq!(s.forward, Vec3::X);
    }

    #[test]
    fn dolly_moves_the_camera_through_the_same_relative_geometry() {
        let fixed = SceneDef::new(SceneKind::BunnySweep, &cfg(&[]))
            .unwrap()
            .instantiate(1);
        let dolly = SceneDef::new(SceneKind::BunnySweep, &cfg(&["--camera", "dolly"]))
            .unwrap()
            .instantiate(1);
        let mut eyes = Vec::new();
        for f in [0, 1, fixed.frames / 4, fixed.frames / 2, fixed.frames - 1] {
            // The bunny stays put; the eye moves.
            assert_eq!(dolly.instance_position(0, f), dolly.instance_position(0, 0));
            eyes.push(dolly.camera(f).eye);
            let d = (fixed.instance_distance(0, f), dolly.instance_distance(0, f));
            assert!((d.0 - d.1).abs() <= 1e-4 * d.0, "frame {f}: {d:?}");
            // Object space to clip space is the same transform.
            let (a, b) = (
                fixed.camera(f).view_proj() * fixed.instance_matrix(0, f),
                dolly.camera(f).view_proj() * dolly.instance_matrix(0, f),
            );
            let scale = a.to_cols_array().iter().fold(0f32, |m, x| m.max(x.abs()));
            for (x, y) in a.to_cols_array().iter().zip(b.to_cols_array()) {
                assert!((x - y).abs() <= 1e-4 * scale, "frame {f}: {a} vs {b}");
            }
        }
        assert!(eyes[2].distance(eyes[0]) > 1.0, "{eyes:?}");
    }

    #[test]
    fn orbit_keeps_the_distance_and_moves_the_eye() {
        let def = SceneDef::new(SceneKind::BunnySweep, &cfg(&["--camera", "orbit"])).unwrap();
        let s = def.instantiate(1);
        let fixed = SceneDef::new(SceneKind::BunnySweep, &cfg(&[]))
            .unwrap()
            .instantiate(1);
        for f in [0, 30, 60, 90, 500] {
            let (a, b) = (s.instance_distance(0, f), fixed.instance_distance(0, f));
            assert!((a - b).abs() < 1e-3 * b, "frame {f}: {a} vs {b}");
        }
        assert_eq!(s.camera(0).eye, fixed.camera(0).eye);
        assert!(
            s.camera(60).eye.distance(fixed.camera(60).eye) > 0.1 * fixed.instance_distance(0, 60)
        );
    }

    #[test]
    fn switch_override_must_match_lod_count() {
        let c = cfg(&["--switch-distances", "10,20"]);
        assert!(SceneDef::new(SceneKind::BunnySweep, &c).is_err());
        let c = cfg(&["--switch-distances", "10,20,40"]);
        let def = SceneDef::new(SceneKind::BunnySweep, &c).unwrap();
        assert_eq!(def.models[0].switches, vec![10.0, 20.0, 40.0]);
    }

    #[test]
    fn switch_distance_halves_with_double_pixel_error() {
        let a = SceneDef::new(SceneKind::BunnySweep, &cfg(&["--pixel-error", "1"])).unwrap();
        let b = SceneDef::new(SceneKind::BunnySweep, &cfg(&["--pixel-error", "2"])).unwrap();
        for (x, y) in a.models[0].switches.iter().zip(&b.models[0].switches) {
            assert!((x / y - 2.0).abs() < 1e-3);
        }
    }

    /// The bunny scenes' default pixel error is one pixel at 800x600, so the switch distances are the same at
    /// every viewport height; a close-up keeps one pixel of its own viewport.
    #[test]
    fn bunny_switches_are_the_papers_at_every_profile() {
        let at = |extra: &[&str]| {
            SceneDef::new(SceneKind::BunnySweep, &cfg(extra))
                .unwrap()
                .models[0]
                .switches
                .clone()
        };
        let paper = at(&["--profile", "paper"]);
        for profile in ["quick", "ci", "regress"] {
            let s = at(&["--profile", profile, "--sweep-start", "fit"]);
            for (x, y) in s.iter().zip(&paper) {
                assert!(
                    (x / y - 1.0).abs() < 1e-5,
                    "{profile}: {s:?} against {paper:?}"
                );
            }
        }
        // The regress profile's close-up: 1 pixel at 72 pixels, so 600 / 72 times nearer.
        let close = at(&["--profile", "regress"]);
        assert!((paper[0] / close[0] - 600.0 / 72.0).abs() < 1e-3);
    }

    /// The fit path never starts nearer than where the bounding sphere fits the view, and says which switches
    /// it does not reach; the close-up starts before the first switch.
    #[test]
    fn the_fit_path_starts_outside_the_bounding_sphere() {
        let def = SceneDef::new(SceneKind::BunnySweep, &cfg(&["--pixel-error", "5"])).unwrap();
        let p = def.path.unwrap();
        let m = &def.models[0];
        assert!(p.near >= p.fit && p.fit > m.radius);
        assert!(p.unreached > 0 && m.switches[p.unreached - 1] < p.near);
        assert_eq!(def.notes().len(), 1);
        let d = def.describe(&cfg(&["--pixel-error", "5"]));
        assert_eq!(d.models[0].lods[1].note, Some(NOT_REACHED));
        let close = SceneDef::new(
            SceneKind::BunnySweep,
            &cfg(&["--pixel-error", "5", "--sweep-start", "close-up"]),
        )
        .unwrap();
        let c = close.path.unwrap();
        assert!(c.near < m.switches[0] && c.unreached == 0);
    }
}
