//! Counting a frame's fragments: the fragment shader invocations of every render pass a method begins through
//! [`SceneGpu`](super::SceneGpu) while counting is on, read with pipeline statistics queries
//! (`wgpu::Features::PIPELINE_STATISTICS_QUERY`, `FRAGMENT_SHADER_INVOCATIONS`).
//!
//! The quality pass turns counting on around the method's own frame ([`FragmentQueries::start`] ..
//! [`FragmentQueries::resolve`]) and never in a timed frame, so the timing rounds hold no query. A pass begun while
//! counting gets a query of its own (one slot of a query set reused every frame, like the timer's ring), ended
//! when the pass ends ([`Pass`]); the frame's slots are resolved into the frame's row of a buffer and summed when
//! read. Passes a method begins without [`SceneGpu::begin_pass`](super::SceneGpu::begin_pass) and its
//! siblings are counted by [`SceneGpu::counted`](super::SceneGpu::counted). Not counted: shadow maps, TAA's
//! resolve and compute passes (not the method's frame, or not fragments).

use std::cell::Cell;
use std::ops::{Deref, DerefMut};

/// Queries a frame may use: more passes than this and the frame's count is unknown.
pub const SLOTS: u32 = 64;
/// Bytes of a frame's row in a resolve buffer (a multiple of the resolve alignment).
pub const ROW: u64 = {
    let bytes = SLOTS as u64 * 8;
    bytes.div_ceil(wgpu::QUERY_RESOLVE_BUFFER_ALIGNMENT) * wgpu::QUERY_RESOLVE_BUFFER_ALIGNMENT
};

/// The query set and the state of the frame being counted.
pub struct FragmentQueries {
    set: wgpu::QuerySet,
    counting: Cell<bool>,
    used: Cell<u32>,
    overflow: Cell<bool>,
}

impl FragmentQueries {
    /// None where the device has no pipeline statistics queries.
    pub fn new(device: &wgpu::Device) -> Option<FragmentQueries> {
        if !device
            .features()
            .contains(wgpu::Features::PIPELINE_STATISTICS_QUERY)
        {
            return None;
        }
        Some(FragmentQueries {
            set: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("fragment counts"),
                ty: wgpu::QueryType::PipelineStatistics(
                    wgpu::PipelineStatisticsTypes::FRAGMENT_SHADER_INVOCATIONS,
                ),
                count: SLOTS,
            }),
            counting: Cell::new(false),
            used: Cell::new(0),
            overflow: Cell::new(false),
        })
    }

    /// Counts every pass begun from now until [`FragmentQueries::resolve`].
    pub fn start(&self) {
        self.counting.set(true);
        self.used.set(0);
        self.overflow.set(false);
    }

    /// Ends counting: resolves the frame's queries into row `row` of `buffer` (`ROW` bytes a row) and returns how
    /// many it used (None where the frame began more passes than [`SLOTS`]).
    pub fn resolve(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        buffer: &wgpu::Buffer,
        row: u32,
    ) -> Option<u32> {
        self.counting.set(false);
        let used = self.used.get();
        if used > 0 {
            encoder.resolve_query_set(&self.set, 0..used, buffer, row as u64 * ROW);
        }
        (!self.overflow.get()).then_some(used)
    }

    /// `pass` with a query begun in it when counting is on.
    pub fn wrap<'e>(&self, mut pass: wgpu::RenderPass<'e>) -> Pass<'e> {
        let mut counted = false;
        if self.counting.get() {
            let slot = self.used.get();
            if slot < SLOTS {
                pass.begin_pipeline_statistics_query(&self.set, slot);
                self.used.set(slot + 1);
                counted = true;
            } else {
                self.overflow.set(true);
            }
        }
        Pass { pass, counted }
    }
}

/// A render pass that ends its fragment query, if it has one, when it ends.
pub struct Pass<'e> {
    pass: wgpu::RenderPass<'e>,
    counted: bool,
}

impl<'e> Pass<'e> {
    /// A pass with no query.
    pub fn plain(pass: wgpu::RenderPass<'e>) -> Pass<'e> {
        Pass {
            pass,
            counted: false,
        }
    }
}

impl<'e> Deref for Pass<'e> {
    type Target = wgpu::RenderPass<'e>;
    fn deref(&self) -> &Self::Target {
        &self.pass
    }
}

impl DerefMut for Pass<'_> {
    fn deref_mut(&mut self) -> &mut Self::Target {
        &mut self.pass
    }
}

impl Drop for Pass<'_> {
    fn drop(&mut self) {
        // Before the pass itself ends (a field is dropped after its owner's drop).
        if self.counted {
            self.pass.end_pipeline_statistics_query();
        }
    }
}

/// The fragments of each frame from a resolve buffer read back (`bytes`, [`ROW`] bytes a frame) and each
/// frame's query count (None: unknown).
pub fn frame_sums(bytes: &[u8], used: &[Option<u32>]) -> Vec<Option<u64>> {
    used.iter()
        .enumerate()
        .map(|(f, n)| {
            let n = (*n)?;
            let at = f * ROW as usize;
            (0..n as usize)
                .map(|q| {
                    let b = bytes.get(at + q * 8..at + q * 8 + 8)?;
                    Some(u64::from_le_bytes(b.try_into().ok()?))
                })
                .sum::<Option<u64>>()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_frames_queries_are_summed_from_its_own_row() {
        let mut bytes = vec![0u8; 3 * ROW as usize];
        let put = |bytes: &mut Vec<u8>, f: usize, q: usize, v: u64| {
            let at = f * ROW as usize + q * 8;
            bytes[at..at + 8].copy_from_slice(&v.to_le_bytes());
        };
        put(&mut bytes, 0, 0, 100);
        put(&mut bytes, 0, 1, 20);
        put(&mut bytes, 1, 0, 7);
        put(&mut bytes, 1, 1, 1000); // beyond frame 1's one query: not its own
        put(&mut bytes, 2, 0, 5);
        let sums = frame_sums(&bytes, &[Some(2), Some(1), None]);
        assert_eq!(sums, vec![Some(120), Some(7), None]);
        assert_eq!(
            frame_sums(&bytes, &[Some(0)]),
            vec![Some(0)],
            "no pass, no fragment"
        );
        assert_eq!(ROW % wgpu::QUERY_RESOLVE_BUFFER_ALIGNMENT, 0);
    }
}
