//! A glTF 2.0 reader (`.gltf` JSON or `.glb`) for the files real tools write: the JSON is read with serde_json
//! and the geometry decoded here, so that the extensions optimised assets carry are read rather than refused.
//!
//! A typed document from a crate (`gltf-json`) was weighed and not taken: it refuses a whole file where one
//! property is off, and real files are off in ways the glTF Validator accepts: integers written as integral
//! floats (`"byteStride": 24.0`) and channels without a target node (the Asset-Generator's
//! `Animation_NodeMisc_08`). Here each property is checked where it is read, so an error names it.
//!
//! Read: KHR_mesh_quantization (integer and normalised attributes, dequantised as glTF 2.0 section 3.11 says),
//! EXT_meshopt_compression and KHR_meshopt_compression (decoded with meshoptimizer, filters included), sparse
//! accessors, EXT_mesh_gpu_instancing (each instance of a node placed, whether the file marks the extension
//! required or not), skins and morph targets, animations, and the authored LOD chains a file can hold (MSFT_lod
//! on a node, or sibling nodes named `NAME_LOD0`, `NAME_LOD1`, ...; a level is a node with its descendants),
//! reported as chains so that no caller merges their levels. Materials (`materials.rs`: the core
//! metallic-roughness model, KHR_texture_transform, PNG, JPEG and WebP images) are read when a scene asks for
//! them; extensions that only change appearance are accepted even when required, and a texture lodbench cannot
//! decode refuses the file when a scene draws it. Any other required extension is refused with its name and a
//! remedy (for Draco: the glTF-Transform command that rewrites the file with meshopt compression).
//!
//! The files: `container.rs` (GLB, JSON, buffer URIs, required extensions), `json.rs` (properties), `accessors.rs`
//! (buffer views and accessors), `nodes.rs` (hierarchy, placements), `authored_chains.rs` (authored LOD chains),
//! `materials.rs` (materials, textures, samplers, images),
//! `primitives.rs` (triangles and their attributes, merging), `skins.rs`, `animation.rs`, `camera.rs` (the
//! animated camera) and `content.rs` ([`read`] and what it gives).

mod accessors;
pub mod animation;
mod authored_chains;
mod camera;
pub mod container;
mod content;
mod json;
pub mod materials;
pub mod nodes;
pub mod primitives;
mod skins;

pub use animation::{Animation, Rig};
pub use authored_chains::{AuthoredChain, ChainSource};
pub use camera::AnimatedCamera;
pub use container::{decode_base64, percent_decode};
pub use content::{read, Content};
pub use materials::MaterialTable;
pub use nodes::Placement;
pub use primitives::{Merged, MergedParts, MeshPrimitives, Triangles};
pub use skins::Skin;
