//! The metric kernels of `shaders/metrics.wgsl`: rmse and pop per frame, computed on the GPU and read back as
//! scalars. Results of every frame of a block go to their own slot of one buffer, read once at the end. Each
//! frame reads the tiles it is given (all of them, or those [`crate::measure::coverage::Coverage`] says can
//! differ from the background).

use crate::error::{Error, Result};
use crate::gpu::compute::{
    bind_group, buffer, kernel_lanes, read_only_storage_entry, results_buffers, storage_entry,
    texture_entry, uniform_buffer, uniform_entry,
};
use crate::gpu::context::GpuContext;
use crate::gpu::targets::RenderTarget;
use crate::measure::coverage::TILE;
use crate::measure::metrics::{FrameMetrics, MetricReduction};
use wgpu::BufferUsages as U;

pub const METRICS_WGSL: &str = include_str!("../../shaders/metrics.wgsl");

pub struct MetricKernel {
    pipeline: wgpu::ComputePipeline,
    /// `crack_main`: the crack test of the uncovered pixels `main` listed.
    crack_pipeline: wgpu::ComputePipeline,
    /// Workgroups of `crack_main` ([`crack_groups`]).
    crack_groups: u32,
    uncovered_count: wgpu::Buffer,
    _uncovered_list: wgpu::Buffer,
    /// The frame's tile list (`tiles` in the shader), each as `tx | ty << 16`.
    tiles: wgpu::Buffer,
    tiles_x: u32,
    bind_group: wgpu::BindGroup,
    params: wgpu::Buffer,
    sums: wgpu::Buffer,
    readback: wgpu::Buffer,
    width: u32,
    height: u32,
    frames: u32,
    background: u32,
}

/// One layout for both entry points, so one bind group serves the two dispatches of a frame.
fn metric_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("metric layout"),
        entries: &[
            texture_entry(0),
            texture_entry(1),
            storage_entry(2),
            storage_entry(3),
            uniform_entry(4),
            storage_entry(5),
            storage_entry(6),
            read_only_storage_entry(7),
        ],
    })
}

/// The pipelines of `main` (the per-pixel figures) and `crack_main` (the crack test of the uncovered pixels),
/// with the shader's DE2000, WORKGROUP_REDUCE and LANES constants.
fn metric_pipelines(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    layout: &wgpu::BindGroupLayout,
    (de2000, reduction): (bool, MetricReduction),
    lanes: u32,
) -> [wgpu::ComputePipeline; 2] {
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("metric pipeline layout"),
        bind_group_layouts: &[Some(layout)],
        immediate_size: 0,
    });
    let constants = [
        ("DE2000", de2000 as u32 as f64),
        (
            "WORKGROUP_REDUCE",
            (reduction == MetricReduction::Workgroup) as u32 as f64,
        ),
        ("LANES", lanes as f64),
    ];
    let compute = |label, entry_point| {
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(label),
            layout: Some(&pipeline_layout),
            module,
            entry_point: Some(entry_point),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants: &constants,
                ..Default::default()
            },
            cache: None,
        })
    };
    [
        compute("metric kernel", "main"),
        compute("crack kernel", "crack_main"),
    ]
}

/// Workgroups of `crack_main` (8 invocations each) for a frame of `pixels` pixels (the most its list can hold)
/// and a metric kernel of `lanes` invocations a tile: enough that no invocation tests more than 1,024 listed
/// pixels on a CPU adapter (8 lanes) or 64 on a GPU. On lavapipe the bound is a limit, not a choice: gallivm
/// ends a vector of invocations after 65,535 loop iterations in all (LP_MAX_TGSI_LOOP_ITERATIONS), about 1,400
/// crack tests of some 45 iterations each, and a longer list was undercounted without a word (test
/// `measure_metric_kernel`). A fixed count rather than an indirect dispatch sized by the list: lavapipe reads
/// indirect arguments at a cost larger than the test's (docs/findings/timing.md).
pub fn crack_groups(lanes: u32, pixels: u64) -> u32 {
    let per_invocation: u64 = if lanes == 8 { 1024 } else { 64 };
    pixels.div_ceil(8 * per_invocation).clamp(1, MAX_ROW as u64) as u32
}

/// Workgroups per row of the tile dispatch (MAX_ROW in the shader: a dispatch's limit per dimension).
const MAX_ROW: u32 = 65535;

/// 32-bit words of a frame's slot in the sums buffer: three 64-bit sums, then uncovered_px and crack_px.
const SLOT_WORDS: u32 = 8;

impl MetricKernel {
    /// Compares `method` against `reference` (both the same size) over up to `frames` frames; `de2000`: also
    /// the mean CIEDE2000 (else it reads 0); `reduction`: how a tile's partial sums are added; `background`:
    /// the bytes a target cleared to the background holds (for uncovered_px and crack_px). A tile is read by
    /// [`kernel_lanes`] invocations.
    pub fn new(
        ctx: &GpuContext,
        targets: (&RenderTarget, &RenderTarget),
        frames: u32,
        options: (bool, MetricReduction),
        background: [u8; 3],
    ) -> Result<MetricKernel> {
        Self::with_lanes(ctx, targets, frames, options, background, kernel_lanes(ctx))
    }

    /// [`MetricKernel::new`] with `lanes` invocations a tile (8, 16, 32 or 64) and [`crack_groups`] of them,
    /// whatever the adapter: the figures are the same (test `measure_metric_kernel`).
    pub fn with_lanes(
        ctx: &GpuContext,
        (method, reference): (&RenderTarget, &RenderTarget),
        frames: u32,
        (de2000, reduction): (bool, MetricReduction),
        background: [u8; 3],
        lanes: u32,
    ) -> Result<MetricKernel> {
        if !matches!(lanes, 8 | 16 | 32 | 64) {
            return Err(Error::Gpu(format!(
                "the metric kernel takes 8, 16, 32 or 64 invocations a tile, not {lanes}"
            )));
        }
        let device = &ctx.device;
        let (width, height) = (method.width, method.height);
        let frames = frames.max(1);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("metrics.wgsl"),
            source: wgpu::ShaderSource::Wgsl(METRICS_WGSL.into()),
        });
        let layout = metric_layout(device);
        let [pipeline, crack_pipeline] =
            metric_pipelines(device, &module, &layout, (de2000, reduction), lanes);
        let pixels = width as u64 * height as u64;
        let uncovered_list = buffer(device, "uncovered pixels", pixels.max(1) * 4, U::STORAGE);
        let uncovered_count = buffer(device, "uncovered pixel count", 4, U::STORAGE | U::COPY_DST);
        let prev_error = buffer(device, "previous error image", pixels * 4, U::STORAGE);
        let (tiles_x, tiles_y) = (width.div_ceil(TILE), height.div_ceil(TILE));
        let tiles = buffer(
            device,
            "metric tiles",
            (tiles_x as u64 * tiles_y as u64).max(1) * 4,
            U::STORAGE | U::COPY_DST,
        );
        let [sums, readback] = results_buffers(
            device,
            ["metric sums", "metric read-back"],
            frames as u64 * 4 * SLOT_WORDS as u64,
        );
        let params = uniform_buffer(device, "metric params", 32);
        let resources = vec![
            wgpu::BindingResource::TextureView(&method.color_bytes_view),
            wgpu::BindingResource::TextureView(&reference.color_bytes_view),
            prev_error.as_entire_binding(),
            sums.as_entire_binding(),
            params.as_entire_binding(),
            uncovered_list.as_entire_binding(),
            uncovered_count.as_entire_binding(),
            tiles.as_entire_binding(),
        ];
        let bind_group = bind_group(device, "metric bind group", &layout, resources);
        ctx.check_errors()?;
        Ok(MetricKernel {
            pipeline,
            crack_pipeline,
            crack_groups: crack_groups(lanes, pixels),
            uncovered_count,
            _uncovered_list: uncovered_list,
            tiles,
            tiles_x,
            bind_group,
            params,
            sums,
            readback,
            width,
            height,
            frames,
            background: background[0] as u32
                | (background[1] as u32) << 8
                | (background[2] as u32) << 16,
        })
    }

    /// Records the metric pass for `frame` (0-based within the block; frame 0 has pop 0) over `tiles`
    /// (indices `ty * tiles_x + tx`; frame 0 must list every tile, since it fills the previous error image).
    /// The sums of the block are zeroed when frame 0 is recorded.
    pub fn encode(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        frame: u32,
        tiles: &[u32],
    ) {
        let slot = frame.min(self.frames - 1);
        if frame == 0 {
            encoder.clear_buffer(&self.sums, 0, None);
        }
        encoder.clear_buffer(&self.uncovered_count, 0, None);
        let count = tiles.len() as u32;
        let params = [
            self.width,
            self.height,
            slot,
            (frame > 0) as u32,
            self.background,
            count,
            0,
            0,
        ];
        queue.write_buffer(&self.params, 0, bytemuck::cast_slice(&params));
        if count == 0 {
            return;
        }
        let packed: Vec<u32> = tiles
            .iter()
            .map(|t| (t % self.tiles_x) | (t / self.tiles_x) << 16)
            .collect();
        queue.write_buffer(&self.tiles, 0, bytemuck::cast_slice(&packed));
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("metric pass"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.dispatch_workgroups(count.min(MAX_ROW), count.div_ceil(MAX_ROW), 1);
        pass.set_pipeline(&self.crack_pipeline);
        pass.dispatch_workgroups(self.crack_groups, 1, 1);
    }

    /// rmse, pop, de2000, uncovered_px and crack_px of frames `0..frames`, after their submissions.
    pub fn read(&self, ctx: &GpuContext, frames: u32) -> Result<Vec<FrameMetrics>> {
        let pixels = self.width as f64 * self.height as f64;
        let n = frames.min(self.frames) as usize;
        // Read as 64-bit words: the last one of a slot holds uncovered_px (low) and crack_px (high).
        let sums = ctx.read_u64_sums(&self.sums, &self.readback, 4 * n)?;
        Ok(sums
            .chunks_exact(4)
            .map(|s| FrameMetrics {
                rmse: super::metrics::rmse_of_sum(s[0], pixels),
                pop: super::metrics::rms_of_sum(s[1], pixels),
                de2000: s[2] as f64 / (65536.0 * pixels),
                uncovered_px: s[3] & 0xffff_ffff,
                crack_px: s[3] >> 32,
            })
            .collect())
    }
}
