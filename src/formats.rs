//! Constants every layer shares: the render-target formats and the largest viewport side. They sit at the
//! bottom of the module graph (docs/ARCHITECTURE.md), so the GPU layer, the methods and the configuration
//! read them without importing each other.

/// Colour format of every render target (recorded in run.json). The metrics read its sRGB-encoded bytes.
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// Depth format of every render target (recorded in run.json).
/// `--impostor`'s atlas layers (src/gpu/impostor_atlas.rs): base colour with coverage and emissive in sRGB,
/// normal with depth and occlusion-roughness-metallic linear.
pub const IMPOSTOR_SRGB_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
pub const IMPOSTOR_LINEAR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// MSAA samples of every render target (recorded in run.json).
pub const MSAA_SAMPLES: u32 = 1;

/// Largest viewport side accepted before asking the device (wgpu's default max_texture_dimension_2d).
pub const MAX_SIDE: u32 = 8192;
