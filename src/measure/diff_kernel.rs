//! The difference kernel of `shaders/diff.wgsl`: the RMS difference between two frames, per frame, as exact
//! integer sums in one slot per frame, read back once at the end of a pass, split into its coverage part (pixels
//! that are the background in one frame only) and its shading part (the rest). It compares fixed pairs of
//! targets (bound once); `encode` picks the pair.

use crate::error::Result;
use crate::gpu::compute::{bind_group, kernel_lanes, results_buffers, uniform_buffer};
use crate::gpu::context::GpuContext;
use crate::gpu::targets::RenderTarget;
use crate::measure::coverage::PixelRect;
use crate::measure::metrics::rms_of_sum;

pub const DIFF_WGSL: &str = include_str!("../../shaders/diff.wgsl");

/// One frame's difference: its RMS over every pixel, and the RMS of its two parts over every pixel (coverage:
/// the pixels that are the background in one frame only; shading: the others), `coverage^2 + shading^2 =
/// rms^2` exactly in the integer sums.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DiffFigure {
    pub rms: f64,
    pub coverage: f64,
    pub shading: f64,
}

pub struct DiffKernel {
    pipeline: wgpu::ComputePipeline,
    bind_groups: Vec<wgpu::BindGroup>,
    params: wgpu::Buffer,
    sums: wgpu::Buffer,
    readback: wgpu::Buffer,
    width: u32,
    height: u32,
    frames: u32,
    /// The background's bytes on this device (`SceneGpu::background_bytes`).
    background: [u8; 3],
}

impl DiffKernel {
    /// Compares each pair `(a, b)` of `pairs` (all of one size), with a slot for each of up to `frames` frames;
    /// `background` is the device's bytes of the clear colour.
    pub fn new(
        ctx: &GpuContext,
        label: &str,
        pairs: &[(&RenderTarget, &RenderTarget)],
        frames: u32,
        background: [u8; 3],
    ) -> Result<DiffKernel> {
        let device = &ctx.device;
        let (width, height) = pairs.first().map_or((1, 1), |(a, _)| (a.width, a.height));
        let frames = frames.max(1);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("diff.wgsl"),
            source: wgpu::ShaderSource::Wgsl(DIFF_WGSL.into()),
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(label),
            layout: None,
            module: &module,
            entry_point: Some("main"),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants: &[("LANES", kernel_lanes(ctx) as f64)],
                ..Default::default()
            },
            cache: None,
        });
        let [sums, readback] = results_buffers(device, [label, label], frames as u64 * 16);
        let params = uniform_buffer(device, label, 48);
        let layout = pipeline.get_bind_group_layout(0);
        let bind_groups = pairs
            .iter()
            .map(|(a, b)| {
                let resources = vec![
                    wgpu::BindingResource::TextureView(&a.color_bytes_view),
                    wgpu::BindingResource::TextureView(&b.color_bytes_view),
                    sums.as_entire_binding(),
                    params.as_entire_binding(),
                ];
                bind_group(device, label, &layout, resources)
            })
            .collect();
        ctx.check_errors()?;
        Ok(DiffKernel {
            pipeline,
            bind_groups,
            params,
            sums,
            readback,
            width,
            height,
            frames,
            background,
        })
    }

    /// Zeroes every slot (at the start of a pass): a frame whose slot is never written reads 0.
    pub fn clear(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.clear_buffer(&self.sums, 0, None);
    }

    /// Records the difference of pair `pair` into `frame`'s slot. One call per submission: the slot travels
    /// in a uniform written through the queue.
    pub fn encode(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        frame: u32,
        pair: usize,
    ) {
        let all = PixelRect::full(self.width, self.height);
        self.encode_in(queue, encoder, (frame, pair), all);
    }

    /// [`DiffKernel::encode`] reading only `rect`, for two frames known to be equal outside it (the RMS is
    /// still over every pixel of the frame).
    pub fn encode_in(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        (frame, pair): (u32, usize),
        rect: PixelRect,
    ) {
        let slot = frame.min(self.frames - 1);
        let [r, g, b] = self.background.map(u32::from);
        let params = [
            self.width,
            self.height,
            slot,
            0,
            rect.x0,
            rect.y0,
            rect.x1.min(self.width),
            rect.y1.min(self.height),
            r,
            g,
            b,
            0,
        ];
        queue.write_buffer(&self.params, 0, bytemuck::cast_slice(&params));
        if rect.is_empty() {
            return;
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("diff pass"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bind_groups[pair], &[]);
        pass.dispatch_workgroups(1, rect.y1 - rect.y0, 1);
    }

    /// The RMS difference of frames `0..frames` (0 for a frame never encoded), after their submissions.
    pub fn read(&self, ctx: &GpuContext, frames: u32) -> Result<Vec<f64>> {
        Ok(self
            .read_parts(ctx, frames)?
            .into_iter()
            .map(|d| d.rms)
            .collect())
    }

    /// The difference of frames `0..frames` with its coverage and shading parts.
    pub fn read_parts(&self, ctx: &GpuContext, frames: u32) -> Result<Vec<DiffFigure>> {
        let pixels = self.width as f64 * self.height as f64;
        let n = frames.min(self.frames) as usize;
        let sums = ctx.read_u64_sums(&self.sums, &self.readback, 2 * n)?;
        Ok(sums
            .chunks_exact(2)
            .map(|s| {
                let (all, coverage) = (s[0], s[1].min(s[0]));
                DiffFigure {
                    rms: rms_of_sum(all, pixels),
                    coverage: rms_of_sum(coverage, pixels),
                    shading: rms_of_sum(all - coverage, pixels),
                }
            })
            .collect())
    }
}
