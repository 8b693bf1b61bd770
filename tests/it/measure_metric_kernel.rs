//! The metric kernel (src/measure/metric_kernel.rs, shaders/metrics.wgsl) on synthetic frames: its uncovered and
//! crack counts against the CPU oracle where many more pixels are uncovered than the crack test's dispatch has
//! invocations, and on a frame with none between two such frames, with 8 and 64 invocations a tile.

use lodbench::gpu::context::GpuContext;
use lodbench::gpu::targets::RenderTarget;
use lodbench::measure::coverage::TILE;
use lodbench::measure::metric_kernel::{crack_groups, MetricKernel};
use lodbench::measure::metrics::{crack_pixels, FrameMetrics, MetricReduction};

const BACKGROUND: [u8; 3] = [60, 63, 69];
const SURFACE: [u8; 3] = [200, 120, 90];

/// The crack test's invocations at 320x240 with `lanes` invocations a tile in the metric kernel: each tests
/// every `one_pass(lanes)`-th listed pixel.
fn one_pass(lanes: u32) -> u64 {
    crack_groups(lanes, 320 * 240) as u64 * 8
}

/// `width` x `height` RGBA8: the surface where `surface(x, y)`, the background elsewhere.
fn frame(width: u32, height: u32, surface: impl Fn(u32, u32) -> bool) -> Vec<u8> {
    (0..height)
        .flat_map(|y| (0..width).map(move |x| (x, y)))
        .flat_map(|(x, y)| {
            let [r, g, b] = if surface(x, y) { SURFACE } else { BACKGROUND };
            [r, g, b, 255]
        })
        .collect()
}

/// The metric kernel's figures of `frames` against `reference`, with `lanes` invocations a tile, every tile read.
fn run_kernel(
    ctx: &GpuContext,
    (w, h): (u32, u32),
    reference: &[u8],
    frames: &[&Vec<u8>],
    lanes: u32,
) -> Vec<FrameMetrics> {
    let method_target = RenderTarget::new(&ctx.device, "method", w, h);
    let reference_target = RenderTarget::new(&ctx.device, "reference", w, h);
    let kernel = MetricKernel::with_lanes(
        ctx,
        (&method_target, &reference_target),
        frames.len() as u32,
        (false, MetricReduction::Atomics),
        BACKGROUND,
        lanes,
    )
    .unwrap();
    let tiles: Vec<u32> = (0..w.div_ceil(TILE) * h.div_ceil(TILE)).collect();
    reference_target.write_color(&ctx.queue, reference);
    for (f, rgba) in frames.iter().enumerate() {
        method_target.write_color(&ctx.queue, rgba);
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        kernel.encode(&ctx.queue, &mut encoder, f as u32, &tiles);
        ctx.queue.submit([encoder.finish()]);
        ctx.wait_idle().unwrap();
    }
    kernel.read(ctx, frames.len() as u32).unwrap()
}

/// Three frames against a reference that is surface everywhere: the method shows a one-pixel column of surface
/// every 4 columns (3 of 4 pixels uncovered, 57,600 at 320x240; all but those within 2 pixels of the image's
/// border are cracks, many times the crack test's invocations), then the reference itself (nothing
/// uncovered), then the columns again. Each frame's counts equal `metrics::crack_pixels`, with 8 invocations a
/// tile (a CPU adapter's) and 64 (a GPU's), and every figure is the same with both. Testing only one listed
/// pixel per invocation (the shader's loop without its stride) fails on the first frame, and so do 4 workgroups
/// for the crack test on lavapipe (1,800 tests an invocation: gallivm's loop limit cuts them short, a different
/// count on every run); the count not cleared between frames fails on the second (the first frame's list tested
/// again); a tile's pixels not all read with 64 invocations fails (all four tried).
#[test]
fn crack_counts_equal_the_oracle_past_one_dispatch_and_after_an_empty_frame() {
    let ctx = crate::common::gpu();
    let (w, h) = (320, 240);
    // The reference a shade off the method's surface, so rmse and pop are not 0 where both show surface.
    let full = frame(w, h, |_, _| true);
    let reference: Vec<u8> = full
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1] + 3, p[2], p[3]])
        .collect();
    let columns = frame(w, h, |x, _| x % 4 == 0);
    let frames = [&columns, &full, &columns];
    let by_lanes: Vec<Vec<FrameMetrics>> = [8, 64]
        .iter()
        .map(|&lanes| run_kernel(&ctx, (w, h), &reference, &frames, lanes))
        .collect();
    for (lanes, got) in [8, 64].iter().zip(&by_lanes) {
        for (f, rgba) in frames.iter().enumerate() {
            let want = crack_pixels(rgba, &reference, w, h, BACKGROUND);
            assert_eq!(
                (got[f].uncovered_px, got[f].crack_px),
                want,
                "{lanes} invocations a tile, frame {f}: gpu against cpu"
            );
        }
        assert_eq!((got[1].uncovered_px, got[1].crack_px), (0, 0));
        assert!(got[1].rmse > 0.0 && got[2].pop > 0.0, "{:?}", got);
    }
    assert_eq!(by_lanes[0], by_lanes[1], "8 and 64 invocations a tile");
    let (uncovered, cracks) = crack_pixels(&columns, &reference, w, h, BACKGROUND);
    assert!(
        cracks > 10 * one_pass(64) && one_pass(64) > one_pass(8),
        "the columns leave {uncovered} uncovered, {cracks} cracks: too few to need several passes"
    );
}
