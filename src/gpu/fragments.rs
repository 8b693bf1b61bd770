//! Counting a frame's fragments: the fragment shader invocations of every render pass a method begins through
//! [`SceneGpu`](super::SceneGpu) for a view that counts them (`View::count_fragments`), read with pipeline
//! statistics queries (`wgpu::Features::PIPELINE_STATISTICS_QUERY`, `FRAGMENT_SHADER_INVOCATIONS`).
//!
//! The quality pass hands the method's own frame a counting view and resolves its queries after it
//! ([`FragmentQueries::resolve`]); no other frame's view counts, timed frames included, so the timing rounds hold
//! no query. A pass begun for a counting view gets a query of its own, ended when the pass ends ([`Pass`]). The queries live in query sets of
//! [`SET_QUERIES`] each, reused every frame (like the timer's ring) and added as a frame needs more (alpha-2pass
//! begins two passes per instance in transition: hundreds on a grid of bunnies); at the frame's end each set's
//! used range is resolved into the pass's [`FragmentRows`], and the rows are summed per frame when read. Passes a
//! method begins without [`SceneGpu::begin_pass`](super::SceneGpu::begin_pass) and its siblings are counted by
//! [`SceneGpu::counted`](super::SceneGpu::counted). Not counted: shadow maps, TAA's resolve and compute passes
//! (not the method's frame, or not fragments).

use crate::error::Result;
use crate::gpu::context::GpuContext;
use std::cell::{Cell, RefCell};
use std::ops::{Deref, DerefMut};

/// Queries in one query set.
pub const SET_QUERIES: u32 = 32;
/// Bytes of one chunk of a [`FragmentRows`] resolve buffer.
const CHUNK_BYTES: u64 = 1 << 20;
const ALIGN: u64 = wgpu::QUERY_RESOLVE_BUFFER_ALIGNMENT;

/// The query sets, and how many of their queries the frame being counted has begun. Whether a pass is counted is
/// its view's (`View::count_fragments`); the sets grow and their slots are handed out behind `&self`, since passes
/// are begun through a shared `SceneGpu`.
pub struct FragmentQueries {
    device: wgpu::Device,
    sets: RefCell<Vec<wgpu::QuerySet>>,
    used: Cell<u32>,
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
            device: device.clone(),
            sets: RefCell::new(Vec::new()),
            used: Cell::new(0),
        })
    }

    /// Resolves the queries of the passes counted since the last resolve into `rows` as frame `frame`'s, and
    /// frees their slots for the next frame.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder, rows: &mut FragmentRows, frame: u32) {
        let used = self.used.replace(0);
        let sets = self.sets.borrow();
        let mut spans = Vec::new();
        for (k, set) in sets.iter().enumerate() {
            let first = k as u32 * SET_QUERIES;
            if first >= used {
                break;
            }
            let n = (used - first).min(SET_QUERIES);
            let (chunk, offset) = rows.place(&self.device, n);
            encoder.resolve_query_set(set, 0..n, &rows.chunks[chunk], offset);
            spans.push(Span { chunk, offset, n });
        }
        rows.set_frame(frame, spans);
    }

    /// `pass` with a query begun in it.
    pub fn wrap<'e>(&self, mut pass: wgpu::RenderPass<'e>) -> Pass<'e> {
        let slot = self.used.get();
        let k = (slot / SET_QUERIES) as usize;
        let mut sets = self.sets.borrow_mut();
        while sets.len() <= k {
            sets.push(self.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("fragment counts"),
                ty: wgpu::QueryType::PipelineStatistics(
                    wgpu::PipelineStatisticsTypes::FRAGMENT_SHADER_INVOCATIONS,
                ),
                count: SET_QUERIES,
            }));
        }
        pass.begin_pipeline_statistics_query(&sets[k], slot % SET_QUERIES);
        self.used.set(slot + 1);
        Pass {
            pass,
            counted: true,
        }
    }
}

/// One resolved range of a frame's queries: `n` counts at `offset` of chunk `chunk`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Span {
    pub chunk: usize,
    pub offset: u64,
    pub n: u32,
}

/// Where one quality pass resolves its frames' queries: chunks of resolve buffer (added as they fill) and each
/// frame's spans in them (None: the frame was not counted).
pub struct FragmentRows {
    chunks: Vec<wgpu::Buffer>,
    /// The next free byte of the last chunk.
    at: u64,
    frames: Vec<Option<Vec<Span>>>,
}

impl FragmentRows {
    pub fn new(frames: u32) -> FragmentRows {
        FragmentRows {
            chunks: Vec::new(),
            at: 0,
            frames: vec![None; frames as usize],
        }
    }

    /// Room for `n` counts, aligned for a resolve: (chunk, offset).
    fn place(&mut self, device: &wgpu::Device, n: u32) -> (usize, u64) {
        let bytes = n as u64 * 8;
        if self.chunks.is_empty() || self.at + bytes > CHUNK_BYTES {
            self.chunks
                .push(device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("fragment counts"),
                    size: CHUNK_BYTES,
                    usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                }));
            self.at = 0;
        }
        let at = self.at;
        self.at = (at + bytes).div_ceil(ALIGN) * ALIGN;
        (self.chunks.len() - 1, at)
    }

    fn set_frame(&mut self, frame: u32, spans: Vec<Span>) {
        if let Some(f) = self.frames.get_mut(frame as usize) {
            *f = Some(spans);
        }
    }

    /// Each frame's fragments (None where it was not counted), read back once.
    pub fn read(&self, ctx: &GpuContext) -> Result<Vec<Option<u64>>> {
        let mut chunks = Vec::with_capacity(self.chunks.len());
        for chunk in &self.chunks {
            let readback = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("fragment counts read-back"),
                size: CHUNK_BYTES,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            encoder.copy_buffer_to_buffer(chunk, 0, &readback, 0, None);
            ctx.queue.submit([encoder.finish()]);
            chunks.push(ctx.read_buffer(&readback, |bytes| bytes.to_vec())?);
        }
        Ok(frame_sums(&chunks, &self.frames))
    }
}

/// Each frame's fragments: the sum of the counts of its spans in `chunks` (the chunks' bytes read back).
pub fn frame_sums(chunks: &[Vec<u8>], frames: &[Option<Vec<Span>>]) -> Vec<Option<u64>> {
    let count = |s: &Span, q: usize| {
        let at = s.offset as usize + q * 8;
        let b = chunks.get(s.chunk)?.get(at..at + 8)?;
        Some(u64::from_le_bytes(b.try_into().ok()?))
    };
    frames
        .iter()
        .map(|spans| {
            spans
                .as_ref()?
                .iter()
                .flat_map(|s| (0..s.n as usize).map(move |q| (s, q)))
                .map(|(s, q)| count(s, q))
                .sum::<Option<u64>>()
        })
        .collect()
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_frames_spans_are_summed_from_their_chunks() {
        let mut chunks = vec![vec![0u8; 1024], vec![0u8; 512]];
        let mut put = |c: usize, at: usize, v: u64| {
            chunks[c][at..at + 8].copy_from_slice(&v.to_le_bytes());
        };
        put(0, 0, 100);
        put(0, 8, 20);
        put(0, 256, 7);
        put(0, 264, 1000); // beyond frame 1's one count: not its own
        put(1, 0, 5);
        put(1, 8, 6);
        let span = |chunk, offset, n| Span { chunk, offset, n };
        let frames = vec![
            Some(vec![span(0, 0, 2)]),
            Some(vec![span(0, 256, 1)]),
            // A frame over two query sets: two spans, here in two chunks.
            Some(vec![span(0, 0, 1), span(1, 0, 2)]),
            Some(vec![]),
            None,
        ];
        assert_eq!(
            frame_sums(&chunks, &frames),
            vec![Some(120), Some(7), Some(111), Some(0), None]
        );
        // A span beyond what was read back is no count.
        assert_eq!(
            frame_sums(&chunks, &[Some(vec![span(2, 0, 1)])]),
            vec![None]
        );
    }
}
