//! The deformed models' pose on the GPU: each frame's skinned and morphed vertices written over their ranges
//! of the vertex buffers.

use crate::gpu::pipelines::{SurfaceVertex, Vertex};
use crate::scene::animated::Posed;
use crate::scene::{Motion, Scene};

/// The models a scene deforms per frame.
/// The deformed models' LODs as the last [`SceneGpu::write_pose`] posed them (empty when nothing deforms), and
/// the scratch their vertices and surface vertices (their tangents turn with the pose) are written from, reused
/// every frame.
#[derive(Default)]
pub struct PoseState {
    pub(super) posed: Posed,
    pub(super) vertices: Vec<Vertex>,
    pub(super) surface: Vec<SurfaceVertex>,
}

pub(super) fn deformed_models(scene: &Scene) -> Vec<u32> {
    match &scene.motion {
        Motion::Animated(a) => a.deformers.iter().map(|d| d.model).collect(),
        _ => Vec::new(),
    }
}

/// A deformed vertex: its position and normal on the frame, its rest position in `aux` (kind
/// [`crate::geometry::mesh::AUX_DEFORMED`]) for FSI's visibility texture.
pub(super) fn deformed_vertex(position: [f32; 3], normal: [f32; 3], rest: [f32; 3]) -> Vertex {
    Vertex {
        position,
        normal,
        aux: [
            rest[0],
            rest[1],
            crate::geometry::mesh::AUX_DEFORMED,
            rest[2],
        ],
    }
}
