//! Frames drawn for one pair kept for the next: the pair (`k`, `k + 1`) draws LOD `k + 1` where the pair
//! (`k + 1`, `k + 2`) may draw it again (the dense check's distances subdivide the same grid steps), so its frames
//! are kept, within a budget of bytes, the oldest dropped first.

use std::collections::{HashMap, VecDeque};

/// A frame's key: LOD, view, the distance's bits.
pub type FrameKey = (u32, u32, u32);

/// The bytes of frames [`FrameCache`] keeps at most by default (crops are small; whole frames under a JOD
/// budget are kept fewer).
pub const FRAME_CACHE_BYTES: usize = 256 << 20;

/// Frames (RGBA bytes) by [`FrameKey`], at most `limit` bytes of them, the oldest dropped first.
#[derive(Debug, Default)]
pub struct FrameCache {
    frames: HashMap<FrameKey, Vec<u8>>,
    order: VecDeque<FrameKey>,
    bytes: usize,
    limit: usize,
}

impl FrameCache {
    /// An empty cache of at most `limit` bytes.
    pub fn new(limit: usize) -> FrameCache {
        FrameCache {
            limit,
            ..FrameCache::default()
        }
    }

    /// The frame of `key`, taken out of the cache (each is drawn again at most once).
    pub fn take(&mut self, key: FrameKey) -> Option<Vec<u8>> {
        let frame = self.frames.remove(&key)?;
        self.bytes -= frame.len();
        self.order.retain(|k| *k != key);
        Some(frame)
    }

    /// Keeps `frame` under `key` (replacing any), dropping the oldest frames beyond the limit; a frame larger
    /// than the limit is not kept.
    pub fn put(&mut self, key: FrameKey, frame: Vec<u8>) {
        self.take(key);
        if frame.len() > self.limit {
            return;
        }
        while self.bytes + frame.len() > self.limit {
            let Some(old) = self.order.pop_front() else {
                break;
            };
            if let Some(f) = self.frames.remove(&old) {
                self.bytes -= f.len();
            }
        }
        self.bytes += frame.len();
        self.order.push_back(key);
        self.frames.insert(key, frame);
    }

    /// Drops every frame of a LOD below `lod` (no pair from `lod` on draws them).
    pub fn drop_below(&mut self, lod: u32) {
        self.frames.retain(|k, _| k.0 >= lod);
        self.order.retain(|k| k.0 >= lod);
        self.bytes = self.frames.values().map(Vec::len).sum();
    }

    /// The bytes of the frames kept.
    pub fn bytes(&self) -> usize {
        self.bytes
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Frames come back once, the oldest go first beyond the limit, a frame beyond the limit is not kept and the
    /// LODs no pair draws any more are dropped.
    #[test]
    fn the_cache_keeps_the_newest_frames_within_its_bytes() {
        let mut c = FrameCache::new(10);
        c.put((1, 0, 5), vec![1; 4]);
        c.put((1, 1, 5), vec![2; 4]);
        assert_eq!(c.bytes(), 8);
        c.put((2, 0, 5), vec![3; 4]);
        assert_eq!(c.bytes(), 8);
        assert_eq!(c.take((1, 0, 5)), None);
        assert_eq!(c.take((1, 1, 5)), Some(vec![2; 4]));
        assert_eq!(c.take((1, 1, 5)), None);
        c.put((3, 0, 5), vec![4; 11]);
        assert_eq!(c.take((3, 0, 5)), None);
        c.put((1, 2, 5), vec![5; 2]);
        c.drop_below(2);
        assert_eq!(c.bytes(), 4);
        assert_eq!(c.take((2, 0, 5)), Some(vec![3; 4]));
        assert_eq!(c.bytes(), 0);
    }
}
