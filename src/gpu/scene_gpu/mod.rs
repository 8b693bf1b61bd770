//! The scene on the GPU: the models' LOD meshes in one vertex and one index buffer, the camera uniform, the
//! scene's surface (flat, or its materials: textures, samplers and a bind group each), the shared opaque
//! pipeline, render passes and instanced draws, part by part where a mesh has materials.
//!
//! One file per job: [`build`] (the struct and its constructor), [`geometry`] (the meshes' buffers and ranges),
//! [`camera`] (the camera uniform, its bind groups, the shadow maps), [`pose`] (the deformed models' vertices per
//! frame), [`view`] (what a pass sees: shadow map, scissor, fragment counting), [`writes`] (what a frame writes
//! before its draws: camera, light, pose), [`passes`] and [`draw`]. The struct's methods live beside their job;
//! only [`build`] defines it, and no file it imports defines one of its methods.

pub mod build;
pub mod camera;
pub mod draw;
pub mod geometry;
pub mod passes;
pub mod pose;
pub mod view;
pub mod writes;

pub use crate::scene::model::{AMBIENT, LIGHT_DIR};
pub use build::SceneGpu;
pub use geometry::{surface_vertex, LodRange, PartRange};
pub use view::{ShadowMap, View};
