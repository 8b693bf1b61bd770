//! Meshes and what is computed from them on the CPU: loading (OBJ, glTF), LOD chains, morph targets, the
//! procedural models and terrain, Blow's blocks with seams, and meshoptimizer's cluster DAG.

pub mod attributes;
pub mod block_tree;
pub mod blocks;
pub mod cluster_dag;
pub mod deform;
pub mod gltf;
pub mod impostor;
pub mod lod;
pub mod material;
pub mod mesh;
pub mod morph;
pub mod procgen;
pub mod projection;
pub mod roam_mesh;
pub mod tangents;
pub mod terrain;
