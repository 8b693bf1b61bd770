//! The reference's frames of a block's current round, kept on the GPU by the round's first quality segment so
//! that the next methods' segments of the round copy them instead of drawing the reference again.
//!
//! The reference frame of frame `f` is the same picture whatever method is measured: every instance at LOD0
//! under frame `f`'s camera and animation (src/methods/reference.rs). So a run of n methods on a block draws the
//! high-poly reference once per frame instead of n times; with 8 methods on trees (regress profile) that is most
//! of the quality pass (docs/measurement.md, "The reference cache").
//!
//! Not used where the reference frame depends on more than the frame: under TAA (its stream carries a history)
//! and with shadows (its shadow map is drawn in the same pass). Every method's quality segment of round r covers
//! the same frames within round r (src/measure/block.rs), so the cache holds one round's frames and is
//! reused from round to round: its memory is a round's, not the path's, and it does not grow while the rounds
//! are timed. The budget (`--reference-cache-mib`) bounds it: the first frames of a round that fit are kept,
//! the rest drawn as before. Every figure is the same with the
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
    /// Frames `first..first + capacity` have a slot.
    capacity: u32,
    /// The first frame of the current round.
    first: u32,
    /// Frames `first..filled` hold the reference (set when a segment that stored them has ended).
    filled: u32,
}

impl ReferenceCache {
    /// A cache of the first frames of a round of `frames` frames (the longest round) at `width` x `height` that
    /// fit in `budget` bytes; None when not one fits.
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
            first: 0,
            filled: 0,
        })
    }

    /// Frame `f`'s slot (`first <= f < first + capacity`).
    fn slot(&self, f: u32) -> wgpu::TexelCopyBufferInfo<'_> {
        let f = f - self.first;
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
        if f < self.first || f >= self.filled {
            return false;
        }
        encoder.copy_buffer_to_texture(self.slot(f), target.color.as_image_copy(), self.extent());
        true
    }

    /// Records the copy of `target`'s colour (frame `f`'s reference, just drawn) into the cache, where it has a
    /// slot and does not hold it yet.
    pub fn store(&self, encoder: &mut wgpu::CommandEncoder, f: u32, target: &RenderTarget) {
        if f >= self.filled && f < self.first + self.capacity {
            encoder.copy_texture_to_buffer(
                target.color.as_image_copy(),
                self.slot(f),
                self.extent(),
            );
        }
    }

    /// A round starts at frame `first`: the slots are free for its frames.
    pub fn begin_round(&mut self, first: u32) {
        self.first = first;
        self.filled = first;
    }

    /// A segment stored the round's frames up to `end` and ended: later segments of the round copy them.
    pub fn stored(&mut self, end: u32) {
        self.filled = self.filled.max(end.min(self.first + self.capacity));
    }
}
