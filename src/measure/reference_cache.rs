//! The reference's frames of a block, kept on the GPU by the first method's quality pass so that the next
//! methods' quality passes copy them instead of drawing the reference again.
//!
//! The reference frame of frame `f` is the same picture whatever method is measured: every instance at LOD0
//! under frame `f`'s camera and animation (src/methods/reference.rs). So a run of n methods on a block draws the
//! high-poly reference once per frame instead of n times; with 8 methods on trees (regress profile) that is most
//! of the quality pass (docs/measurement.md, "The reference cache").
//!
//! Not used where the reference frame depends on more than the frame: under TAA (its stream carries a history)
//! and with shadows (its shadow map is drawn in the same pass). The budget (`--reference-cache-mib`) bounds
//! the memory: the first frames that fit are kept, the rest drawn as before. Every figure is the same with the
//! cache as without it: the copy is the reference's colour, byte for byte, and nothing reads its depth (test
//! `measure_reference_cache`).

use crate::gpu::{GpuContext, RenderTarget};

/// Frames of one buffer: at most this many bytes each (under wgpu's default `max_buffer_size`, 256 MiB).
const CHUNK_BYTES: u64 = 128 << 20;

pub struct ReferenceCache {
    width: u32,
    height: u32,
    /// One row of a frame in the buffers (`COPY_BYTES_PER_ROW_ALIGNMENT`).
    bytes_per_row: u32,
    /// One frame in the buffers (`bytes_per_row` x `height`).
    frame_bytes: u64,
    frames_per_chunk: u32,
    chunks: Vec<wgpu::Buffer>,
    /// Frames `0..capacity` have a slot.
    capacity: u32,
    /// Frames `0..filled` hold the reference (set when a pass that stored them has ended).
    filled: u32,
}

impl ReferenceCache {
    /// A cache of the first frames of `frames` at `width` x `height` that fit in `budget` bytes; None when not
    /// one fits.
    pub fn new(
        ctx: &GpuContext,
        (width, height): (u32, u32),
        frames: u32,
        budget: u64,
    ) -> Option<ReferenceCache> {
        let align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let bytes_per_row = (width * 4).div_ceil(align) * align;
        let frame_bytes = bytes_per_row as u64 * height as u64;
        let chunk_limit = CHUNK_BYTES.min(ctx.device.limits().max_buffer_size);
        let frames_per_chunk = (chunk_limit / frame_bytes).min(u32::MAX as u64) as u32;
        let capacity = (budget / frame_bytes).min(frames as u64) as u32;
        if frames_per_chunk == 0 || capacity == 0 {
            return None;
        }
        let chunks = (0..capacity.div_ceil(frames_per_chunk))
            .map(|c| {
                let n = frames_per_chunk.min(capacity - c * frames_per_chunk);
                ctx.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("reference cache"),
                    size: n as u64 * frame_bytes,
                    usage: wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                })
            })
            .collect();
        Some(ReferenceCache {
            width,
            height,
            bytes_per_row,
            frame_bytes,
            frames_per_chunk,
            chunks,
            capacity,
            filled: 0,
        })
    }

    /// Frame `f`'s slot.
    fn slot(&self, f: u32) -> wgpu::TexelCopyBufferInfo<'_> {
        wgpu::TexelCopyBufferInfo {
            buffer: &self.chunks[(f / self.frames_per_chunk) as usize],
            layout: wgpu::TexelCopyBufferLayout {
                offset: (f % self.frames_per_chunk) as u64 * self.frame_bytes,
                bytes_per_row: Some(self.bytes_per_row),
                rows_per_image: Some(self.height),
            },
        }
    }

    fn extent(&self) -> wgpu::Extent3d {
        wgpu::Extent3d {
            width: self.width,
            height: self.height,
            depth_or_array_layers: 1,
        }
    }

    /// Records the copy of frame `f`'s reference into `target`'s colour; false (nothing recorded) when the
    /// cache does not hold it.
    pub fn restore(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        f: u32,
        target: &RenderTarget,
    ) -> bool {
        if f >= self.filled {
            return false;
        }
        encoder.copy_buffer_to_texture(self.slot(f), target.color.as_image_copy(), self.extent());
        true
    }

    /// Records the copy of `target`'s colour (frame `f`'s reference, just drawn) into the cache, where it has a
    /// slot and does not hold it yet.
    pub fn store(&self, encoder: &mut wgpu::CommandEncoder, f: u32, target: &RenderTarget) {
        if f >= self.filled && f < self.capacity {
            encoder.copy_texture_to_buffer(
                target.color.as_image_copy(),
                self.slot(f),
                self.extent(),
            );
        }
    }

    /// A pass stored frames `0..frames` and ended: later passes copy them.
    pub fn stored(&mut self, frames: u32) {
        self.filled = self.filled.max(frames.min(self.capacity));
    }
}
