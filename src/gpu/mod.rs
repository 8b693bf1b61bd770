//! Everything that talks to wgpu.

pub mod context;
pub mod metrics;
pub mod renderer;
pub mod timing;

pub use context::{AdapterSummary, GpuContext, TimingSource};
pub use renderer::{DrawList, DrawStats, InstanceRaw, RenderTarget, SceneGpu};
