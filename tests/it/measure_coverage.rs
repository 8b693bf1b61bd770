//! `--metric-region covered` (the default) reads only the pixels the instances can cover and draws lodpop's
//! counterfactual only where the instances whose state changed reach (src/measure/coverage.rs): every figure
//! must equal `--metric-region full`'s, frame by frame, on scenes with moving instances (simple in 30 frames moves
//! its objects across the screen by more than a tile a frame, so a pixel an object leaves must still be read for
//! its pop),
//! many instances, turning blades and alpha-tested leaves, and the bound must really have left pixels out.

use crate::common::{read_csv, run_into};
use std::path::Path;

/// The quality pass's figures of frames.csv (timings left out: they differ run to run).
const FIGURES: [&str; 8] = [
    "rmse",
    "pop",
    "lodpop",
    "de2000_mean",
    "uncovered_px",
    "crack_px",
    "triangles",
    "t_instances",
];

const METHODS: &str =
    "reference,discrete,alpha,alpha-2pass,alpha-linear,alpha-zwrite,dither,geomorph";

/// A run's run.json.
fn run_json(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("run.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// Per block of run.json: (method, metric_tile_share, counterfactual_pixel_share).
fn shares(json: &serde_json::Value) -> Vec<(String, f64, Option<f64>)> {
    json["blocks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| {
            (
                format!(
                    "{} {}",
                    b["scene"].as_str().unwrap(),
                    b["method"].as_str().unwrap()
                ),
                b["metric_tile_share"].as_f64().unwrap(),
                b["counterfactual_pixel_share"].as_f64(),
            )
        })
        .collect()
}

#[test]
fn the_covered_region_gives_the_full_frames_figures_on_bunny_sweep() {
    covered_equals_full("bunny-sweep", "120", "1");
}

#[test]
fn the_covered_region_gives_the_full_frames_figures_on_simple() {
    covered_equals_full("simple", "30", "36");
}

#[test]
fn the_covered_region_gives_the_full_frames_figures_on_windmills() {
    covered_equals_full("windmills", "40", "16");
}

#[test]
fn the_covered_region_gives_the_full_frames_figures_on_trees() {
    covered_equals_full("trees", "12", "3");
}

/// The metric kernel's own time per frame (`metric_gpu_ms_median`, from a sample of the frames where the kernel
/// ran): none for the reference, whose frame is compared with itself and never read, a positive time for every
/// other block (lavapipe has timestamps).
fn metric_times(json: &serde_json::Value) {
    if json["timing_source"] != "gpu-timestamps" {
        return;
    }
    for b in json["blocks"].as_array().unwrap() {
        let ms = b["metric_gpu_ms_median"].as_f64();
        let method = b["method"].as_str().unwrap();
        match method {
            "reference" => assert_eq!(ms, None, "{method}: the kernel never ran"),
            _ => assert!(ms.is_some_and(|ms| ms > 0.0), "{method}: {ms:?}"),
        }
    }
}

/// Runs `scene` for `frames` frames with `count` instances under both regions and compares them (one test per
/// scene, so the harness spreads them over its threads).
fn covered_equals_full(scene: &str, frames: &str, count: &str) {
    let dir = tempfile::tempdir().unwrap();
    {
        let mut figures = Vec::new();
        for region in ["covered", "full"] {
            let out = dir.path().join(format!("{scene}-{frames}-{region}"));
            #[rustfmt::skip]
            run_into(&out, &[
                "--scene", scene, "--method", METHODS, "--frames", frames, "--count", count, "--width", "96",
                "--height", "72", "--rounds", "1", "--warmup", "1", "--metrics", "rmse,pop,de2000", "--metric-region", region,
            ]);
            let rows = read_csv(&out.join("frames.csv"));
            let cells: Vec<Vec<String>> = rows
                .iter()
                .map(|r| {
                    let mut c = vec![r["method"].clone(), r["frame"].clone()];
                    c.extend(FIGURES.iter().map(|f| r[*f].clone()));
                    c
                })
                .collect();
            let json = run_json(&out);
            metric_times(&json);
            figures.push((cells, shares(&json)));
        }
        let (covered, full) = (&figures[0], &figures[1]);
        assert_eq!(covered.0.len(), full.0.len(), "{scene}: rows");
        for (a, b) in covered.0.iter().zip(&full.0) {
            assert_eq!(
                a, b,
                "{scene}: [method, frame, {FIGURES:?}] covered vs full"
            );
        }
        assert!(
            covered.0.iter().any(|c| c[4] != "0"),
            "{scene}: some frame has lodpop > 0 (the counterfactual was compared)"
        );
        for (block, tiles, drawn) in &full.1 {
            // The reference's frame compared with itself (its own draw, copied) is not read at all: every
            // figure is 0 by construction (src/measure/quality/frame.rs, `quality_frame`).
            let expected = if block.ends_with(" reference") {
                0.0
            } else {
                1.0
            };
            assert_eq!(*tiles, expected, "{block}: full reads every tile");
            assert!(
                drawn.is_none_or(|d| d == 1.0),
                "{block}: full draws whole counterfactuals"
            );
        }
        if scene == "bunny-sweep" {
            // One bunny, most of the path far away: most tiles left out, and the counterfactual of a blend drawn
            // around the bunny only.
            for (block, tiles, drawn) in &covered.1 {
                assert!(*tiles < 0.8, "{block}: tile share {tiles}");
                assert!(
                    drawn.is_none_or(|d| d < 0.8),
                    "{block}: counterfactual share {drawn:?}"
                );
            }
        }
    }
}

/// The metric kernel's tiles on a frame are those covered now and those covered on the last frame (a pixel
/// left out must have had error 0 then): checked against each frame's own tiles on bunny-sweep in 12 frames,
/// where the bunny shrinks by more than a tile a frame, so some tile covered on a frame is not covered on the
/// next.
#[test]
fn the_tiles_are_this_frames_and_the_last_frames() {
    use lodbench::measure::coverage::Coverage;
    use lodbench::measure::FrameDriver;
    use std::collections::BTreeSet;
    let scene = crate::common::sweep_scene(&["--frames", "12", "--width", "96", "--height", "72"]);
    let own = |matrices: &[glam::Mat4], f: u32| -> BTreeSet<u32> {
        // A fresh coverage lists every tile on its first frame; the second call with the same frame lists
        // this frame's own tiles.
        let mut c = Coverage::new(&scene, true);
        let vp = scene.camera(f).view_proj();
        c.frame_tiles(&scene, matrices, vp);
        c.frame_tiles(&scene, matrices, vp).into_iter().collect()
    };
    let mut coverage = Coverage::new(&scene, true);
    assert!(coverage.bounded);
    let mut driver = FrameDriver::new(&scene);
    let mut last: Option<BTreeSet<u32>> = None;
    let mut left_behind = 0;
    for f in 0..scene.frames {
        driver.advance(f);
        let tiles: BTreeSet<u32> = coverage
            .frame_tiles(&scene, &driver.matrices, scene.camera(f).view_proj())
            .into_iter()
            .collect();
        let now = own(&driver.matrices, f);
        match &last {
            None => assert_eq!(
                tiles.len() as u32,
                coverage.tile_count(),
                "frame 0: every tile"
            ),
            Some(before) => {
                let union: BTreeSet<u32> = now.union(before).copied().collect();
                assert_eq!(
                    tiles, union,
                    "frame {f}: this frame's tiles and the last frame's"
                );
                left_behind += before.difference(&now).count();
            }
        }
        last = Some(now);
    }
    assert!(left_behind > 0, "the bunny left some tile behind");
}
