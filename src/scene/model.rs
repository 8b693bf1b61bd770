//! The data model of a scene ready to render: models with LOD chains, their instances, how they move, the
//! camera, and the unified scenes' blocks, seams and cluster DAG. Everything a frame needs is a function of the
//! frame number.

use crate::geometry::blocks::PartitionMode;
use crate::geometry::cluster_dag::{ClusterDag, CutBound, CutCamera};
use crate::geometry::lod::LodChain;
use crate::geometry::mesh::Mesh;
use crate::geometry::terrain::TerrainField;
use crate::scene::kind::{CameraMode, SceneKind};
use crate::scene::schedule::ScheduleParams;
use glam::{Mat4, Vec3};
use serde::Serialize;
use std::sync::Arc;

/// Where a model's switch distances came from (`describe` and run.json write its [`SwitchSource::name`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SwitchSource {
    /// `--pixel-error`, from each level's error.
    PixelError,
    /// `--pixel-error`, from meshopt's estimate of an authored level's error.
    PixelErrorEstimated,
    /// `--switch-distances` or `--switch-screen-sizes`.
    Override,
    /// The scene's own (SIMPLE's 12 radii, the unified scenes').
    Scene,
    /// Never switched (the ground).
    Ground,
    /// `lodbench tune`'s.
    Tune,
    /// An authored chain's exact distances (`extras.lodbench_switch_distances`, lodbench export's).
    ExportedDistances,
    /// An authored chain's MSFT_screencoverage.
    ScreenCoverage,
}

impl SwitchSource {
    pub fn name(self) -> &'static str {
        match self {
            SwitchSource::PixelError => "pixel-error",
            SwitchSource::PixelErrorEstimated => "pixel-error (estimated)",
            SwitchSource::Override => "override",
            SwitchSource::Scene => "scene",
            SwitchSource::Ground => "none (the ground)",
            SwitchSource::Tune => "tune",
            SwitchSource::ExportedDistances => "lodbench_switch_distances",
            SwitchSource::ScreenCoverage => "MSFT_screencoverage",
        }
    }
}

impl std::fmt::Display for SwitchSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl Serialize for SwitchSource {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

/// Seed of the procedural scenes' models and layouts (tree shapes, instance jitter and yaw, the terrain):
/// fixed, so a scene is the same picture whatever `--seed` drives (the methods' noise).
pub const SCENE_SEED: u64 = 2008;

/// Background colour (linear RGB) behind every scene.
pub const BACKGROUND: [f32; 3] = [0.045, 0.05, 0.06];

/// Direction towards the one directional light (world, not normalised; the shaders normalise it) and the ambient
/// term, the same for every scene and method: the flat surface's Lambert mixes the two, the PBR surface reads the
/// ambient as a uniform environment's radiance and gives the light an irradiance of pi x (1 - ambient).
pub const LIGHT_DIR: [f32; 3] = [-0.45, 0.8, 0.4];
pub const AMBIENT: f32 = 0.22;

pub const ORBIT_AMPLITUDE_DEG: f32 = 30.0;
pub const ORBIT_PERIOD_FRAMES: f32 = 240.0;

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
    /// Where the switch distances came from.
    pub switch_source: SwitchSource,
    /// Bounding-sphere centre (object space) and radius (world units, after scale).
    pub center: Vec3,
    pub radius: f32,
    pub scale: f32,
    /// A deformed model's reach: the model-space box holding every vertex on every frame (None: its LODs'
    /// vertices are where they are drawn).
    pub deformed_reach: Option<(Vec3, Vec3)>,
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

/// What a scene family's builder makes once per scene: its models, where their mesh came from, and how long
/// their LOD chains took to build.
#[derive(Debug)]
pub struct ModelSet {
    pub models: Vec<Model>,
    pub mesh_source: String,
    /// Milliseconds spent building the models' LOD chains (once per scene, never per instance).
    pub lod_generation_ms: f64,
    /// What the builder noticed about the models (a mesh that cannot be simplified, ...), one line each.
    pub notes: Vec<String>,
}

#[derive(Debug, Clone, Copy)]
pub struct Instance {
    pub model: u32,
    /// Position of the model's bounding-sphere centre at frame 0 (world).
    pub position: Vec3,
    /// Rotation about +y, radians.
    pub yaw: f32,
    /// A rotation applied before the yaw (a user scene's node rotation; identity elsewhere).
    pub rotation: glam::Quat,
    /// A scale applied before the rotation, over the model's own (a user scene's placement whose scale differs
    /// from the one its model bakes in; one elsewhere). Its largest magnitude is the instance's `size`.
    pub scale: Vec3,
}

impl Instance {
    /// How much larger than its model the instance is drawn ([`size_of`] its scale).
    pub fn size(&self) -> f32 {
        size_of(self.scale)
    }
}

/// An instance's size under `scale` (over its model's): the largest magnitude of the scale, the factor by which
/// its model's errors, radius and switch distances grow (a bound along the most stretched axis).
pub fn size_of(scale: Vec3) -> f32 {
    scale.abs().max_element()
}

/// How instances move over the frames.
#[derive(Debug, Clone, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Motion {
    Static,
    /// Every instance moves along +x from `near` to `far` (distance from the camera) in the first half of the
    /// frames and back in the second, at constant speed.
    SweepX {
        near: f32,
        far: f32,
    },
    /// A user scene's animation: its moving instances' matrices and deformed models per frame
    /// (`scene/animated.rs`).
    Animated(Arc<crate::scene::animated::Animated>),
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

/// A camera that follows a track of its own whatever `--camera` says (the procedural, unified and user scenes,
/// and every scene with `--camera-path`).
#[derive(Debug, Clone)]
pub enum CameraTrack {
    /// `--camera-path`: the user's keys resampled to the frames.
    Path(Arc<crate::scene::camera_path::CameraPath>),
    /// A flight from `.0` to `.1` at constant speed over the frames, looking along the scene's `forward`.
    Flight(Vec3, Vec3),
    /// Once around `center` at `distance` over the frames, `elevation` radians above it, looking at it.
    Turntable {
        center: Vec3,
        distance: f32,
        elevation: f32,
    },
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
    /// The camera's own track (a flight or a turntable); None = `camera_mode` from `eye` along `forward`.
    pub track: Option<CameraTrack>,
    pub schedule: ScheduleParams,
    /// The unified-LOD scenes' blocks' mesh, seams and cluster DAG (every instance is a block at the identity
    /// transform); None elsewhere.
    pub unified: Option<Arc<Unified>>,
    /// `--taa on`: every frame's projection is jittered ([`Scene::camera`]) and resolved (`gpu/taa_resolve.rs`).
    pub taa: Option<crate::effects::taa::Taa>,
    /// `--shadows on`: the shadow map's settings (`effects/shadow.rs`).
    pub shadows: Option<crate::effects::shadow::Shadows>,
    /// `--impostor`: the impostor the models' chains end in (their last level's card, `geometry/impostor.rs`).
    pub impostor: Option<crate::geometry::impostor::Impostor>,
    /// `--shader-work`: extra ALU iterations per shaded fragment (`shade` in shaders/mesh.wgsl; 0: none).
    pub shader_work: u32,
    /// The weight the shader work's result is added to the colour with: 0 in every run (the image unchanged);
    /// a test sets 1 to see that the loop runs ([`crate::gpu::SceneGpu::write_work`]).
    pub shader_work_weight: f32,
    /// The instance that is the bunny scenes' ground with `--shadows on`: static, always LOD0, receives
    /// shadows and casts none, left out of `lod_mean`.
    pub ground: Option<usize>,
    /// A user scene's materials, which its meshes' parts name; empty for the built-in scenes and with
    /// `--materials flat` (one colour per instance, `shaders/surface_flat.wgsl`).
    pub materials: Arc<crate::geometry::material::Materials>,
}

/// What a scene family's builder places for one instance count: the parts of [`Scene`] that differ between
/// the families.
#[derive(Debug)]
pub struct Layout {
    pub instances: Vec<Instance>,
    pub motion: Motion,
    pub near: f32,
    pub far: f32,
    pub eye: Vec3,
    pub forward: Vec3,
    pub track: Option<CameraTrack>,
    pub unified: Option<Arc<Unified>>,
}

impl Scene {
    /// The scene's name (the CSVs' `scene` column).
    pub fn name(&self) -> &'static str {
        self.kind.name()
    }

    /// How a cluster cut sees `frame`: its camera, this viewport's pixels per unit at distance 1, the near plane,
    /// the threshold `pixel_error` and the `bound` distances are measured to (clusterlod and describe's cut).
    pub fn cut_camera(&self, frame: u32, pixel_error: f32, bound: CutBound) -> CutCamera {
        CutCamera {
            eye: self.camera(frame).eye,
            pixels_per_unit: crate::geometry::projection::pixels_per_unit(self.height, self.fov_y),
            znear: self.near,
            pixel_error,
            bound,
        }
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
            Motion::Animated(ref a) => match a.instance_matrix(i, frame) {
                Some(m) => m.transform_point3(self.models[inst.model as usize].center),
                None => inst.position,
            },
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
        if let Motion::Animated(a) = &self.motion {
            if let Some(m) = a.instance_matrix(i, frame) {
                return m;
            }
        }
        let inst = &self.instances[i];
        let m = &self.models[inst.model as usize];
        Mat4::from_translation(self.instance_position(i, frame))
            * Mat4::from_rotation_y(inst.yaw)
            * Mat4::from_quat(inst.rotation)
            * Mat4::from_scale(inst.scale * m.scale)
            * Mat4::from_translation(-m.center)
    }

    /// Distance from the camera to instance `i`'s centre on `frame`.
    pub fn instance_distance(&self, i: usize, frame: u32) -> f32 {
        self.instance_position(i, frame)
            .distance(self.camera(frame).eye)
    }

    /// The distance LOD selection compares with instance `i`'s model's switch distances on `frame`: its camera
    /// distance over its size (an instance twice its model's size shows its model's errors as the model does
    /// at half the distance).
    pub fn lod_distance(&self, i: usize, frame: u32) -> f32 {
        self.instance_distance(i, frame) / self.instances[i].size()
    }

    /// Instance `i`'s bounding radius (world units): its model's, times its size.
    pub fn instance_radius(&self, i: usize) -> f32 {
        let inst = &self.instances[i];
        self.models[inst.model as usize].radius * inst.size()
    }

    pub fn camera(&self, frame: u32) -> Camera {
        let (eye, view) = match &self.track {
            Some(track) => self.track_view(track, frame),
            None => self.mode_view(frame),
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

    /// The eye and view matrix on `frame` of a camera on `track`.
    fn track_view(&self, track: &CameraTrack, frame: u32) -> (Vec3, Mat4) {
        match *track {
            CameraTrack::Path(ref p) => p.view(frame, self.frames),
            CameraTrack::Turntable {
                center,
                distance,
                elevation,
            } => {
                let theta = std::f32::consts::TAU * frame as f32 / self.frames.max(1) as f32;
                let dir = Vec3::new(
                    elevation.cos() * theta.sin(),
                    elevation.sin(),
                    elevation.cos() * theta.cos(),
                );
                let eye = center + dir * distance;
                (eye, Mat4::look_at_rh(eye, center, Vec3::Y))
            }
            CameraTrack::Flight(from, to) => {
                let t = if self.frames > 1 {
                    frame as f32 / (self.frames - 1) as f32
                } else {
                    0.0
                };
                let eye = from.lerp(to, t);
                (eye, Mat4::look_at_rh(eye, eye + self.forward, Vec3::Y))
            }
        }
    }

    /// The eye and view matrix on `frame` of the `--camera` mode's camera.
    fn mode_view(&self, frame: u32) -> (Vec3, Mat4) {
        match self.camera_mode {
            CameraMode::Fixed => (
                self.eye,
                Mat4::look_at_rh(self.eye, self.eye + self.forward, Vec3::Y),
            ),
            CameraMode::Dolly => {
                let eye = match self.motion {
                    // Back from the bunny by as much as the fixed camera's bunny has moved away from it.
                    Motion::SweepX { near, far } => {
                        self.eye - Vec3::X * (sweep_distance(near, far, self.frames, frame) - near)
                    }
                    Motion::Static | Motion::Animated(_) => self.eye,
                };
                (eye, Mat4::look_at_rh(eye, eye + self.forward, Vec3::Y))
            }
            CameraMode::Orbit => {
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
        }
    }
}

/// One seam mesh: the seam between two blocks at one pair of their LODs (empty where every quad is
/// degenerate). Positions and normals are copies of the blocks' own, bit for bit, so the seam's edges are the
/// blocks' edges exactly.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SeamMesh {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub indices: Vec<u32>,
}

/// The seams between blocks (models) `blocks.0` and `blocks.1`: `meshes[a * lods.1 + b]` joins the first at
/// LOD a to the second at LOD b.
#[derive(Debug, Clone)]
pub struct Seam {
    pub blocks: (u32, u32),
    pub lods: (u32, u32),
    pub meshes: Vec<SeamMesh>,
}

impl Seam {
    pub fn mesh_index(&self, a: u32, b: u32) -> u32 {
        a.min(self.lods.0 - 1) * self.lods.1 + b.min(self.lods.1 - 1)
    }
}

/// What the preprocessing took and made (describe and run.json's scene descriptions).
#[derive(Debug, Clone, Serialize)]
pub struct Preprocessing {
    pub partition: PartitionMode,
    pub grid: [u32; 3],
    pub block_size: f64,
    pub blocks: usize,
    pub input_triangles: usize,
    /// Triangles of all blocks at full resolution (clipping adds some).
    pub block_triangles: usize,
    pub lod_targets: Vec<f32>,
    pub seam_pairs: usize,
    pub seam_edges: usize,
    /// Seam triangles over every pair of LODs of every pair of blocks.
    pub seam_triangles_all_lod_pairs: usize,
    pub partition_ms: f64,
    pub lod_chains_ms: f64,
    pub seams_ms: f64,
    /// Partition + LOD chains + seams: the blocks' whole preprocessing.
    pub blocks_ms: f64,
    /// Bytes of the blocks' LOD meshes and the seams as the GPU holds them (40-byte vertices, 4-byte indices).
    pub blocks_bytes: u64,
    pub seams_bytes: u64,
    pub clusterlod_ms: f64,
    pub clusterlod_bytes: u64,
    pub clusters: usize,
    pub cluster_groups: usize,
    pub cluster_levels: u32,
}

/// A unified scene's mesh, seams and cluster DAG (shared by every block of the scene).
#[derive(Debug)]
pub struct Unified {
    /// The whole mesh (clusterlod draws it).
    pub mesh: Mesh,
    pub dag: ClusterDag,
    pub seams: Vec<Seam>,
    /// `--pixel-error` as the blocks' switch distances and clusterlod's cut use it.
    pub pixel_error: f32,
    pub preprocessing: Preprocessing,
    /// The procedural terrain's height field (scene terrain without `--mesh`), for `roam`; None otherwise.
    pub terrain: Option<TerrainField>,
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
