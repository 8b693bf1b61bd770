//! The GPU layer: device and adapter, the scene's geometry on the GPU, render targets, instance buffers,
//! pipelines, draw lists, read-back, timestamps and the metric kernel. It imports nothing above it except
//! the scene's data (`crate::scene`), never the methods, the configuration or the runner.

pub mod compute;
pub mod context;
pub mod draw_list;
pub mod fragments;
pub mod impostor_atlas;
pub mod instances;
pub mod pipelines;
pub mod probe_kernels;
pub mod readback;
pub mod scene_gpu;
pub mod shadow_pass;
pub mod surface;
pub mod taa_resolve;
pub mod targets;
pub mod timestamps;

pub use context::{AdapterSummary, GpuContext, TimingSource};
pub use draw_list::{Draw, DrawList, DrawStats, InstanceRaw, PipelineIndex, Selection};
pub use instances::{changed_runs, InstanceBuffer, UploadCounters};
pub use pipelines::{
    mesh_wgsl, MaterialClass, MeshPipeline, MeshPipelines, Surface, SurfaceTarget, SurfaceVertex,
    Vertex,
};
pub use readback::{read_texture, TextureReadback};
pub use scene_gpu::{surface_vertex, LodRange, PartRange, SceneGpu, View, AMBIENT, LIGHT_DIR};
pub use targets::{texture_2d, RenderTarget, ATTACHMENT_READ};
