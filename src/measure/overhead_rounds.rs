//! The harness's own overhead (`lodbench overhead`): a method as the timing rounds time it
//! (`BlockGpu::time_segment`: the walk along the path, the frame's uniforms, the method's draw list and
//! upload, its timestamps, submit and wait) against a bare instanced draw of the same meshes and instance data
//! in the same process, on the same target, over the same frames, paired round by round.
//!
//! The bare draw is what an engine's fastest path for these instances would be: the instance data uploaded once,
//! then per frame the camera written, one cleared pass, the scene's opaque pipeline and buffers bound once and
//! one `draw_indexed` per (model, LOD) bucket, submitted and waited for. Two variants add back one part of the
//! harness each, so a shortfall is found where it comes from:
//! - `bare+timestamps`: the harness's timestamp pair (its own command buffer before the frame's, as timed
//!   frames carry it);
//! - `bare+list`: the draw list rebuilt from the frame's walk (the LOD schedule and instance matrices) and its
//!   changed runs uploaded, as `reference` does every frame.
//!
//! - `bare#2`: the bare draw again, the A/A pair: a ratio of another contender's is a difference only where
//!   its interval excludes 1 and `bare#2`'s does not.
//!
//! Every instance is drawn at LOD0, the reference's draw; before timing, the bare draw's frame 0 is checked
//! to be the `reference` method's frame 0, byte for byte, so the two draw the same thing. A throughput ratio
//! is triangles per second over the bare draw's, paired round by round; for `reference` it is the bare
//! draw's time over the method's.

use super::block_gpu::BlockGpu;
use super::driver::FrameDriver;
use super::effects::ShadowRole;
use super::rounds::{round_frames, shuffled_order, Prepared};
use super::stats::{paired_log_ratio, percentile};
use crate::error::{Error, Result};
use crate::gpu::draw_list::DrawList;
use crate::gpu::instances::InstanceBuffer;
use crate::gpu::readback::TextureReadback;
use crate::gpu::timestamps::GpuTimer;
use crate::gpu::View;
use crate::methods::common::instance_raw;
use crate::rng::SplitMix64;
use indicatif::ProgressBar;
use serde::Serialize;
use std::time::Instant;

/// A variant of the bare draw.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Bare {
    /// Instance data uploaded once; per frame the camera, one pass, a draw per bucket.
    Plain,
    /// And the harness's timestamp pair.
    Timestamps,
    /// And the draw list rebuilt from the frame's walk and uploaded.
    List,
    /// [`Bare::Plain`] again, timed as a contender of its own: the A/A pair that says how far two identical
    /// draws' ratio strays in this run.
    Again,
}

impl Bare {
    pub const ALL: [Bare; 4] = [Bare::Plain, Bare::Again, Bare::Timestamps, Bare::List];

    pub fn name(self) -> &'static str {
        match self {
            Bare::Plain => "bare",
            Bare::Timestamps => "bare+timestamps",
            Bare::List => "bare+list",
            Bare::Again => "bare#2",
        }
    }
}

/// One bare draw: its instances (LOD0 for every instance), its buffer and, for [`Bare::List`], its own walk.
pub struct BareDraw<'s> {
    pub variant: Bare,
    list: DrawList,
    buffer: InstanceBuffer,
    driver: FrameDriver<'s>,
    timer: Option<GpuTimer>,
}

impl<'s> BareDraw<'s> {
    /// The bare draw of `block`'s scene, its instances at frame 0 uploaded.
    pub fn new(block: &BlockGpu<'s>, variant: Bare) -> BareDraw<'s> {
        let scene = block.scene;
        let mut bare = BareDraw {
            variant,
            list: DrawList::default(),
            buffer: block
                .gpu
                .create_instance_buffer("bare instances", scene.instances.len() as u32),
            driver: FrameDriver::new(scene),
            timer: match variant {
                Bare::Timestamps => GpuTimer::new(block.ctx, scene.frames.max(1)),
                _ => None,
            },
        };
        bare.list_frame(block, 0);
        bare.driver.reset();
        bare
    }

    /// The walk advanced to frame `f`, every instance listed at LOD0 and the list's changed runs uploaded.
    fn list_frame(&mut self, block: &BlockGpu<'_>, f: u32) {
        self.driver.advance(f);
        let input = self.driver.input(f);
        self.list.clear();
        for (i, (inst, state)) in block.scene.instances.iter().zip(input.states).enumerate() {
            self.list
                .push(0, inst.model, 0, instance_raw(&input, i, state.k, 1.0, 0));
        }
        self.list.build();
        block.gpu.upload(&self.buffer, &self.list);
    }

    /// Triangles a frame draws.
    pub fn triangles(&self, block: &BlockGpu<'_>) -> u64 {
        self.list
            .draws
            .iter()
            .map(|d| {
                block.gpu.lods[d.model as usize][d.lod as usize].triangles()
                    * d.instance_count as u64
            })
            .sum()
    }

    pub fn draw_calls(&self) -> usize {
        self.list.draws.len()
    }

    /// Frame `f` into the block's timing target: submitted and waited for.
    pub fn frame(&mut self, block: &BlockGpu<'_>, f: u32) -> Result<()> {
        let (ctx, gpu) = (block.ctx, &block.gpu);
        gpu.write_camera(&block.scene.camera(f));
        if self.variant == Bare::List {
            self.list_frame(block, f);
        }
        let mut first = None;
        if let Some(t) = &self.timer {
            let mut e = ctx.device.create_command_encoder(&Default::default());
            t.begin(&mut e, f);
            first = Some(e);
        }
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        {
            let view = View::lit_by(ShadowRole::Method.map());
            let target = &block.timing_target;
            let mut pass = gpu.begin_clear_pass(&mut encoder, target, view, "bare pass");
            pass.set_pipeline(gpu.opaque_pipeline.base());
            pass.set_vertex_buffer(0, gpu.vertex_buffer.slice(..));
            pass.set_vertex_buffer(1, self.buffer.buffer.slice(..));
            pass.set_index_buffer(gpu.index_buffer.slice(..), wgpu::IndexFormat::Uint32);
            for d in &self.list.draws {
                let r = gpu.lods[d.model as usize][d.lod as usize];
                pass.draw_indexed(
                    r.first_index..r.first_index + r.index_count,
                    r.base_vertex,
                    d.first_instance..d.first_instance + d.instance_count,
                );
            }
        }
        if let Some(t) = &self.timer {
            t.end(&mut encoder, f);
        }
        ctx.queue.submit(
            first
                .map(|e| e.finish())
                .into_iter()
                .chain([encoder.finish()]),
        );
        ctx.wait_idle()
    }

    /// `frames` frames from 0, untimed; the walk left at the start of the path.
    pub fn warm_up(&mut self, block: &BlockGpu<'_>, frames: u32) -> Result<()> {
        let n = block.scene.frames.max(1);
        for w in 0..frames.max(1) {
            if w % n == 0 {
                self.driver.reset();
            }
            self.frame(block, w % n)?;
        }
        self.driver.reset();
        Ok(())
    }
}

/// The timing target's colour after `draw` ran, as bytes.
fn target_bytes(
    block: &BlockGpu<'_>,
    draw: impl FnOnce(&mut wgpu::CommandEncoder),
) -> Result<Vec<u8>> {
    let (ctx, scene) = (block.ctx, block.scene);
    let readback = TextureReadback::color(&ctx.device, "overhead check", scene.width, scene.height);
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    draw(&mut encoder);
    readback.encode_copy(&mut encoder, &block.timing_target);
    ctx.queue.submit([encoder.finish()]);
    readback.read(ctx)
}

/// Checks that the bare draw's frame 0 is method `label`'s frame 0 (`reference`'s, by the command), byte for
/// byte, with an instance of the method of its own (the timed methods' state is not touched).
pub fn check_same_image(block: &BlockGpu<'_>, label: &str) -> Result<()> {
    let mut bare = BareDraw::new(block, Bare::Plain);
    bare.frame(block, 0)?;
    let bare_bytes = target_bytes(block, |_| {})?;
    let entry = *block.setup.registry.get(label)?;
    let mut method = (entry.create)(&block.build())?;
    let mut driver = FrameDriver::new(block.scene);
    driver.advance(0);
    block.write_frame(0);
    let method_bytes = target_bytes(block, |encoder| {
        method.encode(&block.gpu, &driver.input(0), encoder, &block.timing_target);
    })?;
    let differ = bare_bytes
        .chunks(4)
        .zip(method_bytes.chunks(4))
        .filter(|(a, b)| a != b)
        .count();
    if differ > 0 {
        return Err(Error::Gpu(format!(
            "scene {}: the bare draw's frame 0 differs from {label}'s in {differ} pixels, so it does not \
             draw the same meshes and instances; the overhead comparison would not be of the same work",
            block.scene.name()
        )));
    }
    Ok(())
}

/// One timed contender's figures over a block's rounds (a row of overhead.csv).
#[derive(Debug, Clone, Serialize)]
pub struct OverheadRecord {
    pub scene: String,
    pub count: u32,
    /// A method's label (drawn by the harness) or a bare draw's variant.
    pub contender: String,
    pub rounds: u32,
    pub frames: u32,
    pub triangles_per_frame: f64,
    pub draw_calls_per_frame: f64,
    /// Median over rounds of the wall time per frame (render, submit and wait), ms.
    pub ms_per_frame_median: f64,
    pub triangles_per_s_median: f64,
    /// Triangles per second over the bare draw's, the geometric mean of the rounds' ratios.
    pub throughput_to_bare: f64,
    pub throughput_ci95_lo: Option<f64>,
    pub throughput_ci95_hi: Option<f64>,
}

/// What one contender measured per round: wall ms and triangles.
#[derive(Default)]
struct PerRound {
    ms: Vec<f64>,
    triangles: Vec<f64>,
    frames: Vec<u32>,
    draw_calls: f64,
}

/// The methods of `prepared` (made by [`BlockGpu::prepare_methods`]) and the bare draws of [`Bare::ALL`] in
/// `rounds` rounds: round r times each over the frames [`round_frames`]`(r)` in an order shuffled from
/// `seed`. Returns a row per contender (the methods first) and each round's order.
pub fn measure(
    block: &BlockGpu<'_>,
    prepared: &mut Prepared<'_>,
    (rounds, seed): (u32, u64),
    progress: &ProgressBar,
) -> Result<(Vec<OverheadRecord>, Vec<Vec<String>>)> {
    let warmup = prepared.plan.warmup;
    let mut bares = Vec::new();
    for v in Bare::ALL {
        let mut b = BareDraw::new(block, v);
        b.warm_up(block, warmup)?;
        bares.push(b);
    }
    let n_methods = prepared.methods.len();
    let mut per: Vec<PerRound> = (0..n_methods + bares.len())
        .map(|_| PerRound::default())
        .collect();
    let mut rng = SplitMix64::new(seed);
    let mut orders = Vec::new();
    for r in 0..rounds {
        let (lo, hi) = round_frames(r, rounds, block.scene.frames);
        let order = shuffled_order(per.len(), &mut rng);
        for &c in &order {
            let (ms, triangles) = match c.checked_sub(n_methods) {
                None => time_method(block, prepared, c, (r, lo..hi), progress)?,
                Some(b) => time_bare(block, &mut bares[b], lo..hi)?,
            };
            per[c].ms.push(ms);
            per[c].triangles.push(triangles);
            per[c].frames.push(hi - lo);
        }
        orders.push(order.iter().map(|&c| label(prepared, &bares, c)).collect());
    }
    for (m, p) in prepared.methods.iter().zip(&mut per) {
        p.draw_calls =
            m.stats.iter().map(|s| s.draw_calls as f64).sum::<f64>() / m.stats.len().max(1) as f64;
    }
    for (b, p) in bares.iter().zip(&mut per[n_methods..]) {
        p.draw_calls = b.draw_calls() as f64;
    }
    let bare = n_methods; // Bare::Plain, the first of the bare draws
    let rows = (0..per.len())
        .map(|c| record(block, label(prepared, &bares, c), &per[c], &per[bare]))
        .collect();
    Ok((rows, orders))
}

fn label(prepared: &Prepared<'_>, bares: &[BareDraw<'_>], c: usize) -> String {
    match c.checked_sub(prepared.methods.len()) {
        None => prepared.methods[c].label.clone(),
        Some(b) => bares[b].variant.name().to_string(),
    }
}

/// Method `i` of `prepared` over `frames` in round `r`, as the timing rounds time it: (wall ms, triangles).
fn time_method(
    block: &BlockGpu<'_>,
    prepared: &mut Prepared<'_>,
    i: usize,
    (r, frames): (u32, std::ops::Range<u32>),
    progress: &ProgressBar,
) -> Result<(f64, f64)> {
    let m = &mut prepared.methods[i];
    let before = m.stats.len();
    block.time_segment(m, r, frames, progress)?;
    let ms = m.segment_ms.last().copied().unwrap_or(0.0);
    let triangles = m.stats[before..].iter().map(|s| s.triangles as f64).sum();
    Ok((ms, triangles))
}

/// A bare draw over `frames`: (wall ms, triangles).
fn time_bare(
    block: &BlockGpu<'_>,
    bare: &mut BareDraw<'_>,
    frames: std::ops::Range<u32>,
) -> Result<(f64, f64)> {
    let per_frame = bare.triangles(block) as f64;
    let n = frames.len() as f64;
    let start = Instant::now();
    for f in frames {
        super::driver::check_interrupt()?;
        bare.frame(block, f)?;
    }
    Ok((start.elapsed().as_secs_f64() * 1e3, per_frame * n))
}

/// A contender's row: its medians and its throughput over the bare draw's, paired by round.
fn record(
    block: &BlockGpu<'_>,
    contender: String,
    p: &PerRound,
    bare: &PerRound,
) -> OverheadRecord {
    let ms_per_frame: Vec<f64> =
        p.ms.iter()
            .zip(&p.frames)
            .map(|(ms, &n)| ms / n.max(1) as f64)
            .collect();
    let frames: u32 = p.frames.iter().sum();
    let rate = |q: &PerRound, r: usize| q.triangles[r] / (q.ms[r] / 1e3);
    let rates: Vec<f64> = (0..p.ms.len()).map(|r| rate(p, r)).collect();
    let logs: Vec<f64> = (0..p.ms.len())
        .map(|r| (rate(p, r) / rate(bare, r)).ln())
        .collect();
    let (m, ci) = paired_log_ratio(&logs).unwrap_or((0.0, None));
    OverheadRecord {
        scene: block.scene.name().to_string(),
        count: block.scene.count,
        contender,
        rounds: p.ms.len() as u32,
        frames,
        triangles_per_frame: p.triangles.iter().sum::<f64>() / frames.max(1) as f64,
        draw_calls_per_frame: p.draw_calls,
        ms_per_frame_median: percentile(&ms_per_frame, 50.0).unwrap_or(f64::NAN),
        triangles_per_s_median: percentile(&rates, 50.0).unwrap_or(f64::NAN),
        throughput_to_bare: m.exp(),
        throughput_ci95_lo: ci.map(|c| c.0.exp()),
        throughput_ci95_hi: ci.map(|c| c.1.exp()),
    }
}
