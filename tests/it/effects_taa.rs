//! `--taa on` on the software adapter: the resolve against a CPU model of it, and a static frame's convergence
//! to the frame without TAA.

use crate::common::{col, linear_to_srgb8, read_csv, run_into, srgb_to_linear};
use std::path::Path;

const W: u32 = 96;
const H: u32 = 72;
const FRAMES: u32 = 48;

/// One static bunny (bunny-grid of 1: no motion, fixed camera), `reference,discrete`, every frame dumped.
fn static_run(out: &Path, extra: &[&str]) -> std::path::PathBuf {
    let (w, h, f) = (W.to_string(), H.to_string(), FRAMES.to_string());
    let mut args = vec![
        "--scene",
        "bunny-grid",
        "--count",
        "1",
        "--method",
        "reference,discrete",
        "--width",
        &w,
        "--height",
        &h,
        "--frames",
        &f,
        "--warmup",
        "0",
        "--rounds",
        "1",
        "--dump-frames",
    ];
    args.extend_from_slice(extra);
    run_into(out, &args)
}

fn frame(dir: &Path, f: u32) -> Vec<u8> {
    let p = dir
        .join("frames")
        .join(format!("bunny-grid_discrete_c1_f{f:05}_reference.png"));
    lodbench::raster::read(&p)
        .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
        .into_raw()
}

/// The resolve of shaders/taa.wgsl in f64: the history clamped to the current frame's 3x3 min/max, then
/// h + alpha (c - h), in linear values; the first frame's history is the frame.
fn resolve(history: &mut Option<Vec<f64>>, current: &[u8], alpha: f64) -> Vec<u8> {
    let c: Vec<f64> = current.iter().map(|&v| srgb_to_linear(v)).collect();
    let h = history.get_or_insert_with(|| c.clone());
    let (w, hgt) = (W as i64, H as i64);
    for y in 0..hgt {
        for x in 0..w {
            for ch in 0..3 {
                let at = |x: i64, y: i64| {
                    c[((y.clamp(0, hgt - 1) * w + x.clamp(0, w - 1)) * 4 + ch) as usize]
                };
                let (mut lo, mut hi) = (f64::MAX, f64::MIN);
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        lo = lo.min(at(x + dx, y + dy));
                        hi = hi.max(at(x + dx, y + dy));
                    }
                }
                let i = ((y * w + x) * 4 + ch) as usize;
                let clamped = h[i].clamp(lo, hi);
                h[i] = clamped + alpha * (c[i] - clamped);
            }
        }
    }
    h.chunks(4)
        .flat_map(|p| {
            [
                linear_to_srgb8(p[0]),
                linear_to_srgb8(p[1]),
                linear_to_srgb8(p[2]),
                255,
            ]
        })
        .collect()
}

/// Largest and mean absolute difference over R, G, B, in 8-bit levels.
fn difference(a: &[u8], b: &[u8]) -> (u8, f64) {
    let d: Vec<u8> = a
        .chunks(4)
        .zip(b.chunks(4))
        .flat_map(|(p, q)| (0..3).map(move |c| p[c].abs_diff(q[c])))
        .collect();
    (
        *d.iter().max().unwrap(),
        d.iter().map(|&x| x as f64).sum::<f64>() / d.len() as f64,
    )
}

/// (1) `--taa-alpha 1` dumps the jittered frames unblended (h' = c); the default resolve (alpha 0.1, 3x3 clamp)
/// of the same frames, recomputed on the CPU from them, matches the GPU's dumps within 1 level on every pixel
/// (the GPU keeps its history in Rgba16Float: 11 significant bits, under half a level after sRGB encoding), and
/// the jitter is there (consecutive raw frames differ). (2) Convergence: after 48 frames (6 cycles of the 8
/// jitter points) the static frame under TAA equals the frame without TAA within 2 levels wherever the frame
/// without TAA is flat over the pixel's 3x3 neighbourhood (within 2 levels: inside the bunny and the background,
/// where jitter moves nothing; the rest is the silhouette, which TAA anti-aliases), and within 1 level on
/// average over the whole frame (measured: 0.65; the silhouette's pixels, a quarter of this frame, differ by
/// about 3 levels on average, their anti-aliasing). Both runs' reference and discrete match each other as without TAA (no LOD
/// change on a static bunny at LOD0: rmse 0).
#[test]
fn taa_resolve_matches_its_cpu_model_and_converges() {
    let tmp = tempfile::tempdir().unwrap();
    let raw = static_run(
        &tmp.path().join("raw"),
        &["--taa", "on", "--taa-alpha", "1"],
    );
    let taa = static_run(&tmp.path().join("taa"), &["--taa", "on"]);
    let plain = static_run(&tmp.path().join("plain"), &[]);
    assert_ne!(frame(&raw, 0), frame(&raw, 1), "the jitter moves the frame");
    let mut history = None;
    let mut worst = 0u8;
    for f in 0..FRAMES {
        let expected = resolve(&mut history, &frame(&raw, f), 0.1);
        let (max, _) = difference(&expected, &frame(&taa, f));
        worst = worst.max(max);
        assert!(
            max <= 1,
            "frame {f}: the GPU resolve differs from its CPU model by {max} levels"
        );
    }
    eprintln!("resolve against the CPU model: at most {worst} level(s)");

    let converged = frame(&taa, FRAMES - 1);
    let without = frame(&plain, FRAMES - 1);
    let (w, h) = (W as i64, H as i64);
    let px = |x: i64, y: i64, c: usize| {
        without[((y.clamp(0, h - 1) * w + x.clamp(0, w - 1)) * 4) as usize + c]
    };
    let mut flat = 0;
    for y in 0..h {
        for x in 0..w {
            let is_flat = (0..3).all(|c| {
                let v: Vec<u8> = (-1..=1)
                    .flat_map(|dy| (-1..=1).map(move |dx| (dx, dy)))
                    .map(|(dx, dy)| px(x + dx, y + dy, c))
                    .collect();
                v.iter().max().unwrap() - v.iter().min().unwrap() <= 2
            });
            if is_flat {
                flat += 1;
                for c in 0..3 {
                    let i = ((y * w + x) * 4) as usize + c;
                    let d = converged[i].abs_diff(without[i]);
                    assert!(
                        d <= 2,
                        "pixel ({x}, {y}) channel {c}: {} under TAA, {} without",
                        converged[i],
                        without[i]
                    );
                }
            }
        }
    }
    assert!(
        flat > (W * H / 2) as usize,
        "only {flat} flat pixels: the test frame shows too little"
    );
    let (max, mean) = difference(&converged, &without);
    eprintln!(
        "converged against no TAA: max {max} levels, mean {mean:.4} levels, {flat} flat pixels"
    );
    assert!(mean <= 1.0, "mean difference {mean} levels");
    for dir in [&taa, &plain] {
        let rows = read_csv(&dir.join("frames.csv"));
        assert!(col(&rows, "discrete", "rmse").iter().all(|&r| r == 0.0));
    }
}

/// A bad TAA setting is one error naming the flag.
#[test]
fn bad_taa_flags_are_refused() {
    use clap::Parser;
    use lodbench::cli::{Cli, Command};
    for (flag, value) in [
        ("--taa-alpha", "0"),
        ("--taa-alpha", "1.5"),
        ("--taa-samples", "0"),
    ] {
        let cli = Cli::try_parse_from(["lodbench", "run", "--taa", "on", flag, value]).unwrap();
        let Command::Run(args) = cli.command else {
            unreachable!()
        };
        let err = lodbench::cli::run_config::RunConfig::from_args(&args)
            .unwrap_err()
            .to_string();
        assert!(err.contains(flag), "{err}");
    }
}

/// bunny-sweep close up at 128x96 over `frames` frames, `methods` and the reference, with `extra` flags; the
/// frames and the transitions of the run.
fn sweep_run(
    out: &Path,
    methods: &str,
    frames: u32,
    extra: &[&str],
) -> (crate::common::Rows, crate::common::Rows) {
    let f = frames.to_string();
    let mut args = vec![
        "--scene",
        "bunny-sweep",
        "--frames",
        &f,
        "--width",
        "128",
        "--height",
        "96",
        "--sweep-start",
        "close-up",
        "--method",
        methods,
        "--warmup",
        "0",
        "--rounds",
        "1",
    ];
    args.extend_from_slice(extra);
    let dir = run_into(out, &args);
    (
        read_csv(&dir.join("frames.csv")),
        read_csv(&dir.join("transitions.csv")),
    )
}

/// lodpop under TAA is the difference of two TAA streams, each with its own history (the method's, and its
/// counterfactual fed every frame with the frame of the previous schedule): (1) discrete's hard switch scores
/// about alpha x Delta on its frame and a decaying tail after it, on at least 5 frames, while the same path
/// without TAA scores on the switch frame alone; (2) alpha's ramp keeps its per-frame slope through the
/// history, so its largest lodpop per transition under TAA is at least half of what it is without TAA (a
/// counterfactual resolved against the method's own history would report about alpha = 0.1 of it). (2) holds on
/// this short path; on the ci path alpha's largest lodpop without TAA is its k = 0.5 swap of the opaque LOD, a
/// step that TAA spreads like discrete's switch (docs/findings/engine-effects.md).
#[test]
fn lodpop_under_taa_is_the_difference_of_two_streams() {
    let tmp = tempfile::tempdir().unwrap();
    let (plain, plain_t) = sweep_run(&tmp.path().join("plain"), "discrete,alpha", 200, &[]);
    let (taa, taa_t) = sweep_run(
        &tmp.path().join("taa"),
        "discrete,alpha",
        200,
        &["--taa", "on"],
    );

    let switches: Vec<usize> = col(&plain, "discrete", "lodpop")
        .iter()
        .enumerate()
        .filter(|(_, &x)| x > 0.0)
        .map(|(f, _)| f)
        .collect();
    let lodpop = col(&taa, "discrete", "lodpop");
    // Every switch with 5 frames after it on the path (the last one, back at LOD0, may lie nearer the end).
    let switches: Vec<usize> = switches
        .into_iter()
        .filter(|&s| s + 6 <= lodpop.len())
        .collect();
    assert!(switches.len() >= 4, "discrete switches: {switches:?}");
    for &s in &switches {
        let tail = &lodpop[s..s + 6];
        eprintln!("discrete under TAA from switch frame {s}: {tail:.5?}");
        assert!(tail.iter().all(|&x| x > 0.0), "frame {s}: {tail:?}");
        for w in tail.windows(2) {
            assert!(
                w[1] < w[0],
                "switch {s}: the tail does not decrease: {tail:?}"
            );
        }
    }

    let max_of = |rows: &crate::common::Rows, t: &str| -> f64 {
        rows.iter()
            .find(|r| r["method"] == "alpha" && r["transition"] == t)
            .unwrap_or_else(|| panic!("alpha transition {t}"))["lodpop_max"]
            .parse()
            .unwrap()
    };
    let n = plain_t.iter().filter(|r| r["method"] == "alpha").count();
    assert!(n >= 2);
    for t in 0..n {
        let t = t.to_string();
        let (without, with) = (max_of(&plain_t, &t), max_of(&taa_t, &t));
        eprintln!("alpha transition {t}: lodpop_max {without:.5} without TAA, {with:.5} with");
        assert!(
            with >= 0.5 * without,
            "transition {t}: alpha's lodpop_max {with} under TAA, {without} without"
        );
    }
}
