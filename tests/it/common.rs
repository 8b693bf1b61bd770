//! Helpers every integration test shares: one way to build a run's or a scene's configuration from the flags a
//! user would type, one way to run it (in-process or through the binary), one GPU context, one CSV reader, the
//! sRGB transfer functions. The long suite (tests/long/) shares this file.

use clap::Parser;
use glam::Vec3;
use lodbench::cli::run_config::RunConfig;
use lodbench::cli::{Cli, Command, RunArgs};
use lodbench::scene::{Motion, Scene, SceneConfig, SceneDef, SceneKind};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::Arc;

/// Runs the lodbench binary with ARGS and the environment variables ENV added; its output.
pub fn lodbench(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_lodbench"));
    c.args(args);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("lodbench runs")
}

/// Asserts failure with exactly one `error:` line mentioning every needle.
pub fn fails_with(out: &Output, needles: &[&str]) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "expected failure, stderr: {stderr}");
    assert!(!stderr.contains("panicked"), "panic: {stderr}");
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "expected one line, got: {stderr}");
    assert!(lines[0].starts_with("error:"), "{stderr}");
    for n in needles {
        assert!(lines[0].contains(n), "'{n}' not in: {stderr}");
    }
}

/// The GPU context of the tests (lavapipe on a machine without a GPU).
pub fn gpu() -> lodbench::gpu::GpuContext {
    lodbench::gpu::GpuContext::new(None).expect("an adapter (install mesa-vulkan-drivers)")
}

/// An sRGB-encoded 8-bit channel as linear light in [0, 1] (IEC 61966-2-1).
pub fn srgb_to_linear(c: u8) -> f64 {
    let c = f64::from(c) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear light as an sRGB-encoded 8-bit channel, clamped to [0, 1] and rounded.
pub fn linear_to_srgb8(l: f64) -> u8 {
    let l = l.clamp(0.0, 1.0);
    let c = if l <= 0.003_130_8 {
        l * 12.92
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    };
    (c * 255.0).round() as u8
}

/// The flags of `lodbench run ARGS`, parsed as the binary parses them.
pub fn run_args(args: &[&str]) -> RunArgs {
    let mut argv = vec!["lodbench", "run"];
    argv.extend_from_slice(args);
    match Cli::try_parse_from(argv).expect("flags parse").command {
        Command::Run(r) => r,
        _ => unreachable!(),
    }
}

/// The validated configuration of `lodbench run ARGS`.
pub fn run_config(args: &[&str]) -> RunConfig {
    RunConfig::from_args(&run_args(args)).expect("valid config")
}

/// Runs `lodbench run ARGS --out OUT` in-process; returns OUT.
pub fn run_into(out: &Path, args: &[&str]) -> PathBuf {
    let mut argv = args.to_vec();
    argv.extend_from_slice(&["--out", out.to_str().expect("a UTF-8 path")]);
    lodbench::commands::run::run(&run_config(&argv)).expect("the run completes");
    out.to_path_buf()
}

/// The scene configuration of `lodbench describe --scene SCENE ARGS` (the scene flags `run` shares).
pub fn scene_config(scene: &str, args: &[&str]) -> SceneConfig {
    let mut argv = vec!["lodbench", "describe", "--scene", scene];
    argv.extend_from_slice(args);
    match Cli::try_parse_from(argv).expect("flags parse").command {
        Command::Describe(d) => SceneConfig::from_args(&d.scene_args).expect("valid scene flags"),
        _ => unreachable!(),
    }
}

/// bunny-sweep built from scene flags.
pub fn sweep_scene(args: &[&str]) -> Scene {
    SceneDef::new(SceneKind::BunnySweep, &scene_config("bunny-sweep", args))
        .expect("the scene builds")
        .instantiate(1)
}

/// One CSV row, by column name.
pub type Row = HashMap<String, String>;
pub type Rows = Vec<Row>;

/// Every row of a CSV file written by lodbench.
pub fn read_csv(path: &Path) -> Rows {
    let mut r = csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let headers = r.headers().expect("a header row").clone();
    r.records()
        .map(|rec| {
            let rec = rec.expect("a CSV record");
            headers
                .iter()
                .zip(rec.iter())
                .map(|(h, v)| (h.to_string(), v.to_string()))
                .collect()
        })
        .collect()
}

/// Column `name` of `method`'s rows, as numbers.
pub fn col(rows: &Rows, method: &str, name: &str) -> Vec<f64> {
    rows.iter()
        .filter(|r| r["method"] == method)
        .map(|r| {
            r[name]
                .parse::<f64>()
                .unwrap_or_else(|_| panic!("{name}={}", r[name]))
        })
        .collect()
}

/// Mean absolute difference (of 255, over R, G, B) and the fraction of pixels off by more than 16 in any
/// channel, between two RGBA8 images of the same size.
pub fn image_difference(a: &[u8], b: &[u8]) -> (f64, f64) {
    let mut sum = 0u64;
    let mut bad = 0usize;
    for (p, q) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        let worst = (0..3).map(|c| p[c].abs_diff(q[c])).max().unwrap_or(0);
        sum += (0..3).map(|c| p[c].abs_diff(q[c]) as u64).sum::<u64>();
        bad += (worst > 16) as usize;
    }
    let pixels = a.len() / 4;
    (sum as f64 / (pixels * 3) as f64, bad as f64 / pixels as f64)
}

pub const W: u32 = 160;
pub const H: u32 = 120;
pub const RED: [f32; 3] = [0.8, 0.04, 0.04];
pub const GREEN: [f32; 3] = [0.04, 0.8, 0.04];
pub const BLUE: [f32; 3] = [0.04, 0.04, 0.8];
pub const YELLOW: [f32; 3] = [0.8, 0.8, 0.04];

/// Static bunnies at the given distances along the camera's axis, LOD j+1 beyond `switches[j]`, each LOD in
/// its own colour (red, green, blue, yellow) so that the LODs can be told apart in the images.
pub fn static_scene(distances: &[f32], switches: [f32; 3], frames: u32, camera: &str) -> Scene {
    let s = format!("{},{},{}", switches[0], switches[1], switches[2]);
    let (w, h, f) = (W.to_string(), H.to_string(), frames.to_string());
    let cfg = scene_config(
        "bunny-grid",
        &[
            "--width",
            &w,
            "--height",
            &h,
            "--frames",
            &f,
            "--switch-distances",
            &s,
            "--count",
            "1",
            "--camera",
            camera,
        ],
    );
    let def = SceneDef::new(SceneKind::BunnyGrid, &cfg).unwrap();
    let mut scene = def.instantiate(distances.len() as u32);
    for (inst, &d) in scene.instances.iter_mut().zip(distances) {
        inst.position = Vec3::new(d, 0.0, 0.0);
    }
    scene.motion = Motion::Static;
    scene.far = distances.iter().fold(0.0f32, |a, &b| a.max(b)) * 2.0;
    let mut models = scene.models.to_vec();
    models[0].lod_colors = vec![RED, GREEN, BLUE, YELLOW];
    scene.models = Arc::from(models);
    scene
}

/// A distance that fits the whole bunny in view (the grid's first position with default switches).
pub fn near_distance() -> f32 {
    let cfg = scene_config("bunny-grid", &["--count", "1"]);
    let d = SceneDef::new(SceneKind::BunnyGrid, &cfg)
        .unwrap()
        .instantiate(1);
    d.instances[0].position.x
}

/// `actual` against the blessed PNG `snap` with the snapshots' tolerance (mean absolute difference at most 0.5 of
/// 255 over R, G, B; at most 0.5 % of pixels off by more than 16 in a channel: another rasteriser's edge pixels
/// pass, a changed shading, blend, pattern or LOD does not). With `LODBENCH_BLESS` set it writes `snap` instead.
/// Returns what is wrong (a uniform frame fails too), or None; on a difference the frame and a map of each
/// pixel's largest channel difference (times 8, in red) go to `target/snapshots/<name>-actual.png` and
/// `-difference.png`. The one comparison of every snapshot test; re-bless with
/// `LODBENCH_BLESS=1 cargo test --release --test it snapshot`.
pub fn snapshot_problem(actual: &lodbench::raster::RgbaImage, snap: &Path) -> Option<String> {
    if std::env::var_os("LODBENCH_BLESS").is_some() {
        std::fs::create_dir_all(snap.parent().expect("a folder")).expect("snapshot folder");
        actual.save(snap).expect("snapshot written");
        return None;
    }
    let expected = lodbench::raster::read(snap)
        .unwrap_or_else(|e| panic!("{}: {e} (bless with LODBENCH_BLESS=1)", snap.display()));
    if expected.dimensions() != actual.dimensions() {
        return Some(format!(
            "{}: {:?}, the frame {:?}",
            snap.display(),
            expected.dimensions(),
            actual.dimensions()
        ));
    }
    let uniform = actual.pixels().all(|p| p == actual.get_pixel(0, 0));
    let (mean, bad) = image_difference(actual.as_raw(), expected.as_raw());
    if !(uniform || mean > 0.5 || bad > 0.005) {
        return None;
    }
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/snapshots");
    let name = snap
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("snapshot");
    let difference =
        lodbench::raster::RgbaImage::from_fn(actual.width(), actual.height(), |x, y| {
            let (a, b) = (actual.get_pixel(x, y), expected.get_pixel(x, y));
            let worst = (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap_or(0);
            lodbench::raster::Rgba([worst.saturating_mul(8), 0, 0, 255])
        });
    let saved = std::fs::create_dir_all(&dir).is_ok()
        && actual.save(dir.join(format!("{name}-actual.png"))).is_ok()
        && difference
            .save(dir.join(format!("{name}-difference.png")))
            .is_ok();
    Some(format!(
        "mean {mean:.3}, {:.3} % off by > 16{}{}",
        bad * 100.0,
        if uniform { ", uniform frame" } else { "" },
        if saved {
            format!("; see {}", dir.display())
        } else {
            String::new()
        }
    ))
}

/// Frame `frame` of `method` on `scene`, from its quality pass (RGBA8, sRGB-encoded bytes).
pub fn render_frame(
    ctx: &lodbench::gpu::GpuContext,
    scene: &Scene,
    method: &str,
    frame: u32,
) -> Vec<u8> {
    let mut block = lodbench::measure::BlockRunner::new(
        ctx,
        scene,
        Default::default(),
        true,
        &Default::default(),
    )
    .unwrap();
    let mut out = None;
    block
        .run_method(method, 0, 1, &indicatif::ProgressBar::hidden(), |f, img| {
            if f == frame {
                out = Some(img.method.to_vec());
            }
            Ok(())
        })
        .unwrap();
    out.expect("the frame was rendered")
}

/// `out` of a command that must succeed (its stderr shown otherwise).
pub fn ok(out: Output) -> Output {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// A small bunny-sweep experiment of four runs (a `band` sweep at 64x48, discrete and dither), written into `dir`: what
/// the shard, merge, resume and cluster-recipe tests run.
pub fn experiment_file(dir: &Path, frames: u32) -> PathBuf {
    let p = dir.join("shards.toml");
    std::fs::write(
        &p,
        format!(
            "name = \"shards\"\n[run]\nscene = [\"bunny-sweep\"]\nmethod = [\"discrete\", \"dither\"]\n\
             width = 64\nheight = 48\nframes = {frames}\nwarmup = 0\nrounds = 2\n\
             [sweep]\nvariable = \"band\"\nvalues = [0.02, 0.05, 0.1, 0.15]\n"
        ),
    )
    .unwrap();
    p
}

/// The columns that are the same on every run of the same flags on the same adapter (not the timings).
pub const SAME: [&str; 10] = [
    "band",
    "scene",
    "method",
    "frame",
    "triangles",
    "t_instances",
    "lod_mean",
    "rmse",
    "pop",
    "lodpop",
];

pub fn deterministic(rows: &Rows) -> Vec<Vec<String>> {
    rows.iter()
        .map(|r| SAME.iter().map(|c| r[*c].clone()).collect())
        .collect()
}

/// The index of column `name` of a CSV header.
pub fn column(header: &csv::StringRecord, name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name}"))
}
