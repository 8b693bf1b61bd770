//! What a user scene has beyond its models: the instances, the camera, the animation, and what `describe` and
//! the run report about them.

use crate::scene::animated::Animated;
use crate::scene::camera_path::CameraPath;
use crate::scene::model::Instance;
use serde::Serialize;
use std::sync::Arc;

/// A user scene's instances, camera flight, animation and notes.
#[derive(Debug, Clone, Serialize)]
pub struct UserParts {
    #[serde(skip)]
    pub instances: Vec<Instance>,
    /// The materials the models' parts name (empty with `--materials flat`).
    #[serde(skip)]
    pub materials: Arc<crate::geometry::material::Materials>,
    /// The default camera flight: from, to, and the direction it looks in.
    pub from: [f32; 3],
    pub to: [f32; 3],
    pub forward: [f32; 3],
    #[serde(skip)]
    pub near: f32,
    #[serde(skip)]
    pub far: f32,
    /// The scene's bounding sphere on frame 0 (centre, radius), which the default flight's first frame shows.
    pub scene_sphere: ([f32; 3], f32),
    /// The flight's start, from the sphere's centre.
    pub start: f32,
    pub instance_count: usize,
    /// The authored chains: model name, where the chain came from, levels.
    pub chains: Vec<ChainDescription>,
    /// The file's animated camera, when it has one and no `--camera-path` is given: it replaces the flight.
    #[serde(skip)]
    pub camera: Option<Arc<CameraPath>>,
    /// What the camera does, in words.
    pub camera_source: String,
    /// The animated camera's vertical field of view (radians), which replaces `--fov`.
    #[serde(skip)]
    pub fov_y: Option<f32>,
    /// The animation played over the frames (None: the scene at rest).
    pub animation: Option<Arc<Animated>>,
    /// The file's animations by name, in order ("" where unnamed).
    pub animations: Vec<String>,
    /// What was not drawn, or drawn other than the file says, and why.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
    /// Per instance, the glTF node it is (what `lodbench export --out FILE.obj` names its groups by).
    #[serde(skip)]
    pub sources: Vec<InstanceSource>,
    /// The nodes with a mesh that are no instance, and why (a coarser level of a chain, no triangles).
    #[serde(skip)]
    pub skipped: Vec<(usize, String)>,
}

/// The glTF node an instance is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InstanceSource {
    pub node: usize,
    /// Its EXT_mesh_gpu_instancing instance.
    pub instance: Option<usize>,
    /// The other nodes whose meshes its model holds, in order (an authored chain's LOD0 hierarchy).
    pub holds: Vec<usize>,
}

#[derive(Debug, Clone, Serialize)]
pub struct ChainDescription {
    pub model: String,
    pub source: &'static str,
    pub levels: usize,
    /// Where the switch distances came from.
    pub thresholds: String,
}
