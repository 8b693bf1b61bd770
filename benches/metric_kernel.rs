//! The metric kernel's own cost per frame, measured paired in one run (the quality pass's `q/r` divides two wall
//! times measured minutes apart, and on a shared or virtual machine those move by as much as the kernel costs:
//! docs/findings/timing.md).
//!
//! `cargo bench --bench metric_kernel [-- --rounds 20 --frames 100 --width 320 --height 240 --share 0.11 --seed 1]`
//!
//! Two synthetic frames (a method's disc a hair smaller than the reference's and shaded a little differently,
//! so a few pixels on its edge are uncovered and every figure is non-zero) are compared by the metric kernel of the quality pass. Each round times
//! `--frames` frames of every variant, in an order shuffled per round with `--seed`; a frame is its commands
//! encoded, submitted and waited for, as in the timing rounds. Variants:
//! - `submit`: an empty submission, the floor every frame pays;
//! - `kernel-no-tiles`: the kernel's per-frame set-up (its parameters written, its counter cleared) with no tile;
//! - `kernel`: the kernel over a centred square of tiles, `--share` of the frame's tiles (bunny-sweep at the ci
//!   profile reads 0.11 of them, run.json's `metric_tile_share`);
//! - `kernel-full`: over every tile (the first frame of a pass, or a scene without a bound);
//! - `kernel-64`, `kernel-64-full`: the same with 64 invocations a tile, a GPU's (the adapter's own count is
//!   `kernel_lanes`: 8 on a CPU adapter, so on a GPU these repeat `kernel` and `kernel-full`, an A/A pair);
//! - `kernel-equal`: `kernel` with the method's frame the reference's (nothing uncovered: the crack test finds
//!   an empty list).
//!
//! Printed per variant: the median over rounds of the round's mean time per frame, and against `submit` the
//! paired difference per frame (mean over rounds and 95 % t interval) and the paired ratio (geometric mean and
//! 95 % t interval), the rule of docs/measurement.md; then the same for `kernel-64` against `kernel`,
//! `kernel-64-full` against `kernel-full` and `kernel-equal` against `kernel`.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    reason = "a bench fails by panicking"
)]

use lodbench::gpu::compute::kernel_lanes;
use lodbench::gpu::context::GpuContext;
use lodbench::gpu::targets::RenderTarget;
use lodbench::measure::coverage::TILE;
use lodbench::measure::metric_kernel::MetricKernel;
use lodbench::measure::metrics::MetricReduction;
use lodbench::measure::rounds::shuffled_order;
use lodbench::measure::stats::{paired_log_ratio, percentile};
use lodbench::rng::SplitMix64;
use std::time::Instant;

const BACKGROUND: [u8; 3] = [60, 63, 69];
const VARIANTS: [&str; 7] = [
    "submit",
    "kernel-no-tiles",
    "kernel",
    "kernel-full",
    "kernel-64",
    "kernel-64-full",
    "kernel-equal",
];
/// (variant, against): the pairs printed after the table against `submit`.
const PAIRS: [(usize, usize); 3] = [(4, 2), (5, 3), (6, 2)];

struct Args {
    rounds: usize,
    frames: usize,
    width: u32,
    height: u32,
    share: f64,
    seed: u64,
}

fn args() -> Args {
    let mut a = Args {
        rounds: 20,
        frames: 100,
        width: 320,
        height: 240,
        share: 0.11,
        seed: 1,
    };
    let argv: Vec<String> = std::env::args().skip(1).collect();
    let mut i = 0;
    while i < argv.len() {
        let value = || argv.get(i + 1).expect("a value after the flag").clone();
        match argv[i].as_str() {
            "--rounds" => a.rounds = value().parse().expect("--rounds N"),
            "--frames" => a.frames = value().parse().expect("--frames N"),
            "--width" => a.width = value().parse().expect("--width N"),
            "--height" => a.height = value().parse().expect("--height N"),
            "--share" => a.share = value().parse().expect("--share X"),
            "--seed" => a.seed = value().parse().expect("--seed N"),
            // `cargo bench` passes `--bench`; anything else is a typo.
            "--bench" => {
                i += 1;
                continue;
            }
            other => panic!("unknown flag {other}"),
        }
        i += 2;
    }
    assert!(
        a.rounds >= 2 && a.frames >= 1,
        "at least 2 rounds of 1 frame"
    );
    a
}

/// A frame of the background with a shaded disc of `radius` (pixels) in its centre.
fn disc(width: u32, height: u32, radius: f64, tint: u8) -> Vec<u8> {
    let (cx, cy) = (width as f64 / 2.0, height as f64 / 2.0);
    let mut rgba = Vec::with_capacity((width * height * 4) as usize);
    for y in 0..height {
        for x in 0..width {
            let (dx, dy) = (x as f64 + 0.5 - cx, y as f64 + 0.5 - cy);
            let px = if dx * dx + dy * dy <= radius * radius {
                let shade = (120.0 + 100.0 * (dx / radius)) as u8;
                [shade, shade.wrapping_add(tint), 90, 255]
            } else {
                [BACKGROUND[0], BACKGROUND[1], BACKGROUND[2], 255]
            };
            rgba.extend_from_slice(&px);
        }
    }
    rgba
}

/// The tiles of a centred square holding `share` of the frame's tiles (at least one).
fn centred_tiles(width: u32, height: u32, share: f64) -> Vec<u32> {
    let (tx, ty) = (width.div_ceil(TILE), height.div_ceil(TILE));
    let side = (((tx * ty) as f64 * share).sqrt().round() as u32).clamp(1, tx.min(ty));
    let (x0, y0) = ((tx - side) / 2, (ty - side) / 2);
    (y0..y0 + side)
        .flat_map(|y| (x0..x0 + side).map(move |x| y * tx + x))
        .collect()
}

fn main() {
    let a = args();
    let ctx = GpuContext::new(None).expect("a GPU adapter (or Mesa lavapipe)");
    let (w, h) = (a.width, a.height);
    let method = RenderTarget::new(&ctx.device, "method", w, h);
    let reference = RenderTarget::new(&ctx.device, "reference", w, h);
    let radius = w.min(h) as f64 * 0.2;
    // A hair smaller: a few uncovered pixels on its edge (bunny-sweep at ci: a median of 6 a frame).
    method.write_color(&ctx.queue, &disc(w, h, radius - 0.05, 0));
    reference.write_color(&ctx.queue, &disc(w, h, radius, 3));
    // Two frame slots (frame 0 fills the previous-error image, frame 1 is timed), the default figures.
    let kernel_of = |method, lanes| {
        MetricKernel::with_lanes(
            &ctx,
            (method, &reference),
            2,
            (false, MetricReduction::Atomics),
            BACKGROUND,
            lanes,
        )
        .expect("the metric kernel")
    };
    let lanes = kernel_lanes(&ctx);
    let kernel = kernel_of(&method, lanes);
    let kernel_64 = kernel_of(&method, 64);
    let equal = kernel_of(&reference, lanes);
    let all: Vec<u32> = (0..w.div_ceil(TILE) * h.div_ceil(TILE)).collect();
    let some = centred_tiles(w, h, a.share);
    // Frame 0 fills the previous-error image over every tile; every timed frame is frame 1 (pop against it).
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    for k in [&kernel, &kernel_64, &equal] {
        k.encode(&ctx.queue, &mut encoder, 0, &all);
    }
    ctx.queue.submit([encoder.finish()]);
    let frame = |variant: usize| {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        match variant {
            0 => {}
            1 => kernel.encode(&ctx.queue, &mut encoder, 1, &[]),
            2 => kernel.encode(&ctx.queue, &mut encoder, 1, &some),
            3 => kernel.encode(&ctx.queue, &mut encoder, 1, &all),
            4 => kernel_64.encode(&ctx.queue, &mut encoder, 1, &some),
            5 => kernel_64.encode(&ctx.queue, &mut encoder, 1, &all),
            _ => equal.encode(&ctx.queue, &mut encoder, 1, &some),
        }
        let index = ctx.queue.submit([encoder.finish()]);
        ctx.device
            .poll(wgpu::PollType::Wait {
                submission_index: Some(index),
                timeout: None,
            })
            .expect("waiting for the GPU");
    };
    // Warm-up: every variant's pipelines and buffers used once.
    for v in 0..VARIANTS.len() {
        for _ in 0..10 {
            frame(v);
        }
    }
    let mut rng = SplitMix64::new(a.seed);
    let mut ms = vec![Vec::with_capacity(a.rounds); VARIANTS.len()];
    for _ in 0..a.rounds {
        for v in shuffled_order(VARIANTS.len(), &mut rng) {
            let start = Instant::now();
            for _ in 0..a.frames {
                frame(v);
            }
            ms[v].push(start.elapsed().as_secs_f64() * 1e3 / a.frames as f64);
        }
    }
    let info = ctx.adapter.get_info();
    println!(
        "metric kernel, {w}x{h}, {} of {} tiles ({TILE}x{TILE}) for `kernel`; {} rounds of {} frames, seed {}; {} ({})",
        some.len(),
        all.len(),
        a.rounds,
        a.frames,
        a.seed,
        info.name,
        info.driver_info
    );
    println!(
        "{:<16} {:>10} {:>28} {:>26}",
        "variant", "median ms", "minus submit, ms [95% CI]", "over submit [95% CI]"
    );
    for (v, name) in VARIANTS.iter().enumerate() {
        let median = percentile(&ms[v], 50.0).unwrap_or(f64::NAN);
        let (diff, ratio) = paired(&ms[v], &ms[0]);
        println!("{name:<16} {median:>10.4} {diff:>28} {ratio:>26}");
    }
    println!(
        "{:<32} {:>28} {:>26}",
        "pair (variant against)", "difference, ms [95% CI]", "ratio [95% CI]"
    );
    for (v, base) in PAIRS {
        let (diff, ratio) = paired(&ms[v], &ms[base]);
        let name = format!("{} against {}", VARIANTS[v], VARIANTS[base]);
        println!("{name:<32} {diff:>28} {ratio:>26}");
    }
}

/// The paired difference per frame and the paired ratio of `x` against `base`, round by round (mean and
/// geometric mean over rounds, 95 % t intervals), printed.
fn paired(x: &[f64], base: &[f64]) -> (String, String) {
    let diffs: Vec<f64> = x.iter().zip(base).map(|(x, b)| x - b).collect();
    let logs: Vec<f64> = x.iter().zip(base).map(|(x, b)| (x / b).ln()).collect();
    let show = |m: Option<(f64, Option<(f64, f64)>)>, f: &dyn Fn(f64) -> f64| match m {
        Some((m, Some((lo, hi)))) => format!("{:.4} [{:.4}, {:.4}]", f(m), f(lo), f(hi)),
        _ => "-".into(),
    };
    (
        show(paired_log_ratio(&diffs), &|x| x),
        show(paired_log_ratio(&logs), &f64::exp),
    )
}
