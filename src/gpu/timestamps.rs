//! GPU frame timing with timestamp queries, after wgpu's `timestamp_queries` example and wgpu-profiler: one
//! struct owns the query set, the resolve buffer and the read-back buffer, and converts units in one place.
//!
//! Each timed frame is bracketed by two empty compute passes that write a timestamp at their beginning, so the
//! interval covers all of the frame's passes whatever the method records in between. Every frame's pair is
//! resolved into its own 256-byte slot of one resolve buffer, and the whole run is read back once at the end:
//! reading timings never waits on the GPU during the timed frames.

use crate::error::Result;
use crate::gpu::context::GpuContext;

/// Query-set pairs reused round-robin (a pair is resolved in the same submission that wrote it).
const RING: u32 = 256;
const SLOT: u64 = wgpu::QUERY_RESOLVE_BUFFER_ALIGNMENT;

pub struct GpuTimer {
    query_set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    frames: u32,
    period_ns: f64,
}

impl GpuTimer {
    /// None when the device has no timestamp queries (then frames are timed with the CPU clock only).
    pub fn new(ctx: &GpuContext, frames: u32) -> Option<GpuTimer> {
        Self::on_device(&ctx.device, ctx.timestamp_period_ns, frames)
    }

    /// [`GpuTimer::new`] for code that holds only the device (methods timing one of their own passes);
    /// `period_ns` is the queue's timestamp period.
    pub fn on_device(device: &wgpu::Device, period_ns: f32, frames: u32) -> Option<GpuTimer> {
        if !device.features().contains(wgpu::Features::TIMESTAMP_QUERY) {
            return None;
        }
        let frames = frames.max(1);
        let size = frames as u64 * SLOT;
        Some(GpuTimer {
            query_set: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("frame timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: RING * 2,
            }),
            resolve: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp resolve"),
                size,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            readback: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp read-back"),
                size,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            frames,
            period_ns: period_ns as f64,
        })
    }

    fn stamp(&self, encoder: &mut wgpu::CommandEncoder, index: u32, label: &str) {
        encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(label),
            timestamp_writes: Some(wgpu::ComputePassTimestampWrites {
                query_set: &self.query_set,
                beginning_of_pass_write_index: Some(index),
                end_of_pass_write_index: None,
            }),
        });
    }

    /// First thing in frame `frame`'s encoder.
    pub fn begin(&self, encoder: &mut wgpu::CommandEncoder, frame: u32) {
        self.stamp(encoder, (frame % RING) * 2, "frame begin timestamp");
    }

    /// Last thing in frame `frame`'s encoder: writes the end stamp and resolves the pair into the frame's slot.
    pub fn end(&self, encoder: &mut wgpu::CommandEncoder, frame: u32) {
        let q = (frame % RING) * 2;
        self.stamp(encoder, q + 1, "frame end timestamp");
        if frame < self.frames {
            encoder.resolve_query_set(
                &self.query_set,
                q..q + 2,
                &self.resolve,
                frame as u64 * SLOT,
            );
        }
    }

    /// GPU milliseconds of each frame (None where the counter went backwards).
    pub fn read(&self, ctx: &GpuContext) -> Result<Vec<Option<f64>>> {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.readback, 0, None);
        ctx.queue.submit([encoder.finish()]);
        let period = self.period_ns;
        let frames = self.frames as usize;
        ctx.read_buffer(&self.readback, |bytes| {
            (0..frames)
                .map(|f| {
                    let at = f * SLOT as usize;
                    let t0 = u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap_or([0; 8]));
                    let t1 =
                        u64::from_le_bytes(bytes[at + 8..at + 16].try_into().unwrap_or([0; 8]));
                    (t1 >= t0).then(|| (t1 - t0) as f64 * period / 1e6)
                })
                .collect()
        })
    }
}
