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
use wgpu::util::DeviceExt;
use wgpu::BufferUsages as U;

pub const METRICS_WGSL: &str = include_str!("../../shaders/metrics.wgsl");

pub struct MetricKernel {
    pipeline: wgpu::ComputePipeline,
    /// `crack_main`: the crack test of the uncovered pixels `main` listed.
    crack_pipeline: wgpu::ComputePipeline,
    /// `crack_args` in the shader: the listed pixels' count, then `crack_main`'s indirect dispatch (x, 1, 1).
    crack_args: wgpu::Buffer,
    _uncovered_list: wgpu::Buffer,
    /// The frame's tile list (`tiles` in the shader), each as `tx | ty << 16`.
    tiles: wgpu::Buffer,
    tiles_x: u32,
    bind_group: wgpu::BindGroup,
    crack_bind_group: wgpu::BindGroup,
    params: wgpu::Buffer,
    sums: wgpu::Buffer,
    readback: wgpu::Buffer,
    width: u32,
    height: u32,
    frames: u32,
    background: u32,
}

/// The bindings of `main`.
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

/// The bindings of `crack_main`: `crack_args` read-only (binding 8), since the same dispatch reads it as its
/// indirect arguments, a use wgpu does not allow beside a writable binding.
fn crack_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("crack test layout"),
        entries: &[
            texture_entry(0),
            texture_entry(1),
            storage_entry(3),
            uniform_entry(4),
            storage_entry(5),
            read_only_storage_entry(8),
        ],
    })
}

/// The pipelines of `main` (the per-pixel figures) and `crack_main` (the crack test of the uncovered pixels),
/// with the shader's DE2000, WORKGROUP_REDUCE and LANES constants.
fn metric_pipelines(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    layouts: [&wgpu::BindGroupLayout; 2],
    (de2000, reduction): (bool, MetricReduction),
    lanes: u32,
) -> [wgpu::ComputePipeline; 2] {
    let constants = [
        ("DE2000", de2000 as u32 as f64),
        (
            "WORKGROUP_REDUCE",
            (reduction == MetricReduction::Workgroup) as u32 as f64,
        ),
        ("LANES", lanes as f64),
    ];
    let compute = |label, entry_point, layout| {
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &[Some(layout)],
            immediate_size: 0,
        });
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
        compute("metric kernel", "main", layouts[0]),
        compute("crack kernel", "crack_main", layouts[1]),
    ]
}

/// Bytes of `crack_args` zeroed before each frame: the count and the dispatch's x.
const CRACK_ARGS_CLEARED: u64 = 8;

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

    /// [`MetricKernel::new`] with `lanes` invocations a tile (8, 16, 32 or 64), whatever the adapter: the
    /// figures are the same (test `measure_metric_kernel`).
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
        let (layout, crack) = (metric_layout(device), crack_layout(device));
        let [pipeline, crack_pipeline] = metric_pipelines(
            device,
            &module,
            [&layout, &crack],
            (de2000, reduction),
            lanes,
        );
        let pixels = width as u64 * height as u64;
        let uncovered_list = buffer(device, "uncovered pixels", pixels.max(1) * 4, U::STORAGE);
        let crack_args = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("crack test arguments"),
            contents: bytemuck::cast_slice(&[0u32, 0, 1, 1]),
            usage: U::STORAGE | U::INDIRECT | U::COPY_DST,
        });
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
            crack_args.as_entire_binding(),
            tiles.as_entire_binding(),
        ];
        let bind_group = bind_group(device, "metric bind group", &layout, resources);
        let crack_entries = [
            (
                0,
                wgpu::BindingResource::TextureView(&method.color_bytes_view),
            ),
            (
                1,
                wgpu::BindingResource::TextureView(&reference.color_bytes_view),
            ),
            (3, sums.as_entire_binding()),
            (4, params.as_entire_binding()),
            (5, uncovered_list.as_entire_binding()),
            (8, crack_args.as_entire_binding()),
        ]
        .map(|(binding, resource)| wgpu::BindGroupEntry { binding, resource });
        let crack_bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("crack test bind group"),
            layout: &crack,
            entries: &crack_entries,
        });
        ctx.check_errors()?;
        Ok(MetricKernel {
            pipeline,
            crack_pipeline,
            crack_args,
            _uncovered_list: uncovered_list,
            tiles,
            tiles_x,
            bind_group,
            crack_bind_group,
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
        encoder.clear_buffer(&self.crack_args, 0, Some(CRACK_ARGS_CLEARED));
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
        pass.set_bind_group(0, &self.crack_bind_group, &[]);
        // x = 0 (nothing uncovered): no workgroup, and on lavapipe no thread woken.
        pass.dispatch_workgroups_indirect(&self.crack_args, 4);
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
                rmse: (s[0] as f64 / (9.0 * 255.0 * 255.0 * pixels)).sqrt(),
                pop: (s[1] as f64 / (3.0 * 255.0 * 255.0 * pixels)).sqrt(),
                de2000: s[2] as f64 / (65536.0 * pixels),
                uncovered_px: s[3] & 0xffff_ffff,
                crack_px: s[3] >> 32,
            })
            .collect())
    }
}
