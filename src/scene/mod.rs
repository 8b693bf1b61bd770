//! Scenes: models with LOD chains, instances, the camera and how things move. Pure CPU, no device.
//!
//! - `config.rs`: [`SceneConfig`], the scene-defining flags after the profile; `kind.rs`: the scene names,
//!   profiles and camera modes.
//! - `def.rs`: [`SceneDef`], a scene built once from its name and the flags, and the [`Scene`] of each
//!   instance count, from one builder per scene family: `procedural.rs` (simple, windmills, trees),
//!   `bunny.rs` (bunny-sweep, bunny-grid) and `unified.rs` (bunny-halves, terrain).
//!   A glTF file's path is a user scene (`user.rs`).
//! - `model.rs`: the data model (models, instances, motion, the camera, the unified scenes' seams and DAG).
//! - `description.rs`: what `lodbench describe` prints; `schedule.rs`: the LOD schedule every method shares.

pub mod animated;
pub mod bunny;
pub mod camera_path;
pub mod config;
pub mod def;
pub mod description;
pub mod export_glb;
pub mod export_obj;
pub mod impostors;
pub mod kind;
pub mod model;
pub mod procedural;
pub mod schedule;
pub mod unified;
pub mod user;

pub use bunny::{BunnyPath, BUNNY_OBJ, BUNNY_YAW};
pub use config::{SceneConfig, PAPER_HEIGHT};
pub use def::{Family, SceneDef};
pub use description::{LodDescription, ModelDescription, SceneDescription, NOT_REACHED};
pub use kind::{CameraMode, Profile, ProfileValues, SceneKind, SweepStart, PAPER_COUNTS};
pub use model::{
    sweep_distance, Camera, CameraTrack, Instance, Model, Motion, Scene, BACKGROUND,
    ORBIT_AMPLITUDE_DEG, ORBIT_PERIOD_FRAMES, SCENE_SEED,
};
pub use procedural::WINDMILL_SPIN_PER_FRAME;
pub use unified::UnifiedParts;
