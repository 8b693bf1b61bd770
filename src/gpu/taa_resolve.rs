//! The TAA resolve of `shaders/taa.wgsl` (`--taa on`, src/effects/taa.rs): per image stream (the method's
//! frames, the reference's, and each counterfactual stream of the quality pass, measure/effects.rs), two history
//! textures used in turn: a frame's resolve reads the previous history and writes the next one.

use crate::effects::taa::Taa;
use crate::formats::COLOR_FORMAT;
use crate::gpu::context::GpuContext;
use crate::gpu::targets::{texture_2d, RenderTarget, ATTACHMENT_READ};

pub const TAA_WGSL: &str = include_str!("../../shaders/taa.wgsl");
const HISTORY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The resolve pipeline, shared by the streams.
pub struct TaaResolve {
    pipeline: wgpu::RenderPipeline,
    settings: Taa,
}

/// One image stream's history.
pub struct TaaStream {
    history: [wgpu::Texture; 2],
    /// The resolved frame before it is copied back into the target.
    resolved: wgpu::Texture,
    params: wgpu::Buffer,
    /// Which of `history` holds the previous frame's.
    previous: usize,
    first: bool,
    width: u32,
    height: u32,
}

impl TaaResolve {
    pub fn new(ctx: &GpuContext, settings: Taa) -> TaaResolve {
        let device = &ctx.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("taa.wgsl"),
            source: wgpu::ShaderSource::Wgsl(TAA_WGSL.into()),
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("taa resolve"),
            layout: None,
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_fullscreen"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_resolve"),
                compilation_options: Default::default(),
                targets: &[Some(HISTORY_FORMAT.into()), Some(COLOR_FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        TaaResolve { pipeline, settings }
    }

    pub fn stream(&self, ctx: &GpuContext, label: &str, width: u32, height: u32) -> TaaStream {
        let d = &ctx.device;
        let texture = |name: &str, format| {
            texture_2d(
                d,
                &format!("{label} taa {name}"),
                (width, height),
                format,
                ATTACHMENT_READ,
            )
        };
        TaaStream {
            history: [
                texture("history 0", HISTORY_FORMAT),
                texture("history 1", HISTORY_FORMAT),
            ],
            resolved: texture("resolved", COLOR_FORMAT),
            params: d.create_buffer(&wgpu::BufferDescriptor {
                label: Some(&format!("{label} taa params")),
                size: 16,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            previous: 0,
            first: true,
            width,
            height,
        }
    }

    /// Writes `stream`'s parameters for the coming frame (before its submission).
    pub fn begin_frame(&self, ctx: &GpuContext, stream: &TaaStream) {
        let words: [u32; 4] = [
            self.settings.alpha.to_bits(),
            self.settings.clamp as u32,
            stream.first as u32,
            0,
        ];
        ctx.queue
            .write_buffer(&stream.params, 0, bytemuck::cast_slice(&words));
    }

    /// Resolves `target` in place against `stream`'s previous history, writing the stream's next history (the
    /// stream's frame of this frame; [`TaaStream::advance`] after the frame's submissions).
    pub fn encode(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        stream: &TaaStream,
        target: &RenderTarget,
    ) {
        let device = &ctx.device;
        let previous = stream.history[stream.previous].create_view(&Default::default());
        let next = stream.history[1 - stream.previous].create_view(&Default::default());
        let resolved = stream.resolved.create_view(&Default::default());
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("taa resolve"),
            layout: &self.pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&target.color_view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&previous),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: stream.params.as_entire_binding(),
                },
            ],
        });
        {
            let attachment = |view| {
                Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })
            };
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("taa resolve"),
                color_attachments: &[attachment(&next), attachment(&resolved)],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.draw(0..3, 0..1);
        }
        encoder.copy_texture_to_texture(
            stream.resolved.as_image_copy(),
            target.color.as_image_copy(),
            wgpu::Extent3d {
                width: stream.width,
                height: stream.height,
                depth_or_array_layers: 1,
            },
        );
    }
}

impl TaaStream {
    /// After the frame's submissions: its history becomes the previous one.
    pub fn advance(&mut self) {
        self.previous = 1 - self.previous;
        self.first = false;
    }

    /// A new sequence (the quality pass's frame 0): the next frame's history is itself.
    pub fn reset(&mut self) {
        self.first = true;
    }
}
