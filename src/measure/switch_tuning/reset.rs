//! A rectangle of a render target put back as a clear leaves it: its colour the clear's bytes, its depth 1. The
//! tune camera draws each crop within one ([`super::ModelCamera::draw_rect`]) instead of clearing the whole
//! target for every draw.

use crate::formats::DEPTH_FORMAT;
use crate::gpu::RenderTarget;

/// The reset's shader: a triangle over the viewport writing the clear's bytes (to the target's unorm view, so the
/// bytes are written as they are, no sRGB encoding; a quarter above each byte, which rounding to the nearest byte
/// and truncation both take to the byte) and a depth; `CLEAR` is replaced by the bytes, `DEPTH` by the depth.
const RESET_WGSL: &str = "
struct Out {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

@vertex
fn vs_reset(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let x = f32(i & 1u) * 4.0 - 1.0;
    let y = f32(i >> 1u) * 4.0 - 1.0;
    return vec4<f32>(x, y, 0.5, 1.0);
}

@fragment
fn fs_reset() -> Out {
    return Out((vec4<f32>(CLEAR) + 0.25) / 255.0, DEPTH);
}
";

/// The WGSL of the reset writing the RGBA bytes `clear` and the depth `depth` (in [0, 1]).
pub fn reset_wgsl(clear: [u8; 4], depth: f32) -> String {
    let [r, g, b, a] = clear.map(|c| format!("{c}.0"));
    RESET_WGSL
        .replace("CLEAR", &format!("{r}, {g}, {b}, {a}"))
        .replace("DEPTH", &format!("{depth:?}"))
}

/// Writes fixed RGBA bytes and a fixed depth over rectangles of a render target: put back as a clear to the bytes
/// and depth 1 leaves them.
pub struct RectReset {
    pipeline: wgpu::RenderPipeline,
}

impl RectReset {
    /// A reset to the bytes `clear` (what a clear of the target to its clear colour leaves, read back) and the
    /// depth `depth` (1, as the clear leaves it).
    pub fn new(device: &wgpu::Device, clear: [u8; 4], depth: f32) -> RectReset {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("tune reset"),
            source: wgpu::ShaderSource::Wgsl(reset_wgsl(clear, depth).into()),
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("tune reset"),
            layout: None,
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_reset"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Always),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_reset"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::TextureFormat::Rgba8Unorm.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        RectReset { pipeline }
    }

    /// Records the writing of `rect`, `[x, y, width, height]`, of `target`'s colour and depth.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
        [x, y, w, h]: [u32; 4],
    ) {
        let keep = wgpu::Operations {
            load: wgpu::LoadOp::Load,
            store: wgpu::StoreOp::Store,
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("tune reset"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &target.color_bytes_view,
                depth_slice: None,
                resolve_target: None,
                ops: keep,
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &target.depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_scissor_rect(x, y, w, h);
        pass.set_pipeline(&self.pipeline);
        pass.draw(0..3, 0..1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reset's shader parses and validates, the bytes written in.
    #[test]
    fn the_reset_shader_is_valid_wgsl() {
        let src = reset_wgsl([1, 2, 255, 0], 1.0);
        assert!(src.contains("vec4<f32>(1.0, 2.0, 255.0, 0.0)"), "{src}");
        assert!(src.contains("255.0, 1.0)"), "{src}");
        let module = naga::front::wgsl::parse_str(&src).unwrap();
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&module)
        .unwrap();
    }
}
