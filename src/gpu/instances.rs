//! Instance buffers: each method's per-instance data on the GPU, uploaded from a built draw list, writing only
//! the entries that changed since the last upload.

use crate::gpu::draw_list::{DrawList, InstanceRaw};
use bytemuck::{Pod, Zeroable};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

/// A method's own instance buffer (each method has one, so the reference and the method drawn in the same
/// submission never overwrite each other's data).
pub struct InstanceBuffer {
    pub buffer: wgpu::Buffer,
    pub capacity: u32,
    /// What the buffer holds (zeros at creation, as wgpu initialises buffers), so that an upload writes only
    /// the entries that differ.
    shadow: Mutex<Vec<InstanceRaw>>,
}

/// Unchanged entries between two changed ones that are written anyway to make one write of them (each
/// `write_buffer` has a fixed cost).
const UPLOAD_MERGE_GAP: usize = 8;

/// Instance data written per frame: what the draw lists held and what was actually written.
#[derive(Debug, Default)]
pub struct UploadCounters {
    listed: AtomicU64,
    written: AtomicU64,
}

impl UploadCounters {
    /// (bytes the draw lists held, bytes written) since the SceneGpu was built.
    pub fn get(&self) -> (u64, u64) {
        (
            self.listed.load(Ordering::Relaxed),
            self.written.load(Ordering::Relaxed),
        )
    }
}

/// The runs `[start, end)` where `new` differs from `old` (same length), runs closer than `gap` merged.
pub fn changed_runs<T: Pod>(old: &[T], new: &[T], gap: usize) -> Vec<(usize, usize)> {
    let differs = |i: usize| bytemuck::bytes_of(&old[i]) != bytemuck::bytes_of(&new[i]);
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for i in (0..new.len().min(old.len())).filter(|&i| differs(i)) {
        match runs.last_mut() {
            Some((_, end)) if i - *end <= gap => *end = i + 1,
            _ => runs.push((i, i + 1)),
        }
    }
    runs
}

impl InstanceBuffer {
    /// A buffer for `capacity` instances (at least one).
    pub fn new(device: &wgpu::Device, label: &str, capacity: u32) -> InstanceBuffer {
        let capacity = capacity.max(1);
        InstanceBuffer {
            buffer: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: capacity as u64 * std::mem::size_of::<InstanceRaw>() as u64,
                usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            capacity,
            shadow: Mutex::new(vec![InstanceRaw::zeroed(); capacity as usize]),
        }
    }

    /// Writes a built draw list from instance `first` on (several lists can share one buffer in one
    /// submission when they use disjoint ranges), before the submission that uses it. Only the entries that
    /// differ from what the buffer already holds are written (see [`changed_runs`]); `counters` adds what the
    /// list held and what was written.
    pub fn write(
        &self,
        queue: &wgpu::Queue,
        first: u32,
        list: &DrawList,
        counters: &UploadCounters,
    ) {
        let new = &list.instances;
        let first = first as usize;
        debug_assert!(first + new.len() <= self.capacity as usize);
        let size = std::mem::size_of::<InstanceRaw>();
        let mut shadow = self
            .shadow
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let Some(old) = shadow.get_mut(first..first + new.len()) else {
            // Past the buffer's capacity: a bug, which wgpu's validation reports (ctx.check_errors).
            queue.write_buffer(
                &self.buffer,
                (first * size) as u64,
                bytemuck::cast_slice(new),
            );
            return;
        };
        let mut written = 0;
        for (start, end) in changed_runs(old, new, UPLOAD_MERGE_GAP) {
            queue.write_buffer(
                &self.buffer,
                ((first + start) * size) as u64,
                bytemuck::cast_slice(&new[start..end]),
            );
            old[start..end].copy_from_slice(&new[start..end]);
            written += (end - start) * size;
        }
        counters
            .listed
            .fetch_add((new.len() * size) as u64, Ordering::Relaxed);
        counters
            .written
            .fetch_add(written as u64, Ordering::Relaxed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uploads_write_only_changed_runs() {
        let old = [0u32, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15];
        assert!(changed_runs(&old, &old, 8).is_empty());
        let mut new = old;
        new[3] = 99;
        assert_eq!(changed_runs(&old, &new, 8), vec![(3, 4)]);
        // Two changes 2 apart merge into one write with gap 2, stay apart with gap 1.
        new[6] = 99;
        assert_eq!(changed_runs(&old, &new, 2), vec![(3, 7)]);
        assert_eq!(changed_runs(&old, &new, 1), vec![(3, 4), (6, 7)]);
        new[15] = 0;
        assert_eq!(changed_runs(&old, &new, 1), vec![(3, 4), (6, 7), (15, 16)]);
    }
}
