//! Integration tests that render on a real adapter (Mesa lavapipe in CI) at small sizes.

use crate::common::{col, read_csv, run_config, snapshot_problem};

use indicatif::ProgressBar;
use lodbench::commands::run;
use lodbench::measure::metrics::SequenceMetrics;
use lodbench::measure::{BlockRunner, QualityOptions};
use lodbench::scene::SceneKind;
use std::path::Path;

/// The acceptance check of a run, on the ci profile (the README's main job at a quarter of its frames, 600: the
/// sweep goes through every LOD the same way, four times faster): the three files; reference rows score 0; discrete
/// scores 0 while LOD0 is shown and > 0 after the first switch; its pop peaks on switch frames.
#[test]
fn ci_sweep_reference_and_discrete() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let out_s = out.to_str().unwrap();
    let cfg = run_config(&[
        "--scene",
        "bunny-sweep",
        "--method",
        "reference,discrete",
        "--profile",
        "ci",
        "--frames",
        "600",
        "--out",
        out_s,
    ]);
    run::run(&cfg).expect("run completes");
    for f in ["frames.csv", "summary.csv", "run.json"] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    assert_eq!(manifest["status"], "complete");
    assert_eq!(manifest["config"]["msaa_samples"], 1);
    assert!(manifest["adapter"]["name"].is_string());

    let rows = read_csv(&out.join("frames.csv"));
    assert!(col(&rows, "reference", "rmse").iter().all(|&x| x == 0.0));
    assert!(col(&rows, "reference", "pop").iter().all(|&x| x == 0.0));

    let tri = col(&rows, "discrete", "triangles");
    let rmse = col(&rows, "discrete", "rmse");
    let pop = col(&rows, "discrete", "pop");
    let lod0 = tri[0];
    let first_switch = tri
        .iter()
        .position(|&t| t != lod0)
        .expect("the sweep switches LOD");
    assert!(first_switch > 0);
    assert!(
        rmse[..first_switch].iter().all(|&x| x == 0.0),
        "rmse must be 0 while LOD0 is shown"
    );
    let back_to_lod0 = tri.iter().rposition(|&t| t != lod0).unwrap() + 1;
    assert!(
        rmse[first_switch..back_to_lod0].iter().all(|&x| x > 0.0),
        "rmse must be > 0 past the first switch"
    );

    let switches: Vec<usize> = (1..tri.len()).filter(|&f| tri[f] != tri[f - 1]).collect();
    assert_eq!(
        switches.len(),
        6,
        "three switches out, three back: {switches:?}"
    );
    for &f in &switches {
        assert!(
            pop[f] > pop[f - 1],
            "frame {f}: pop {} not above the previous {}",
            pop[f],
            pop[f - 1]
        );
        if f + 1 < pop.len() {
            assert!(
                pop[f] > pop[f + 1],
                "frame {f}: pop {} not above the next {}",
                pop[f],
                pop[f + 1]
            );
        }
    }
    let argmax = (0..pop.len())
        .max_by(|&a, &b| pop[a].total_cmp(&pop[b]))
        .unwrap();
    assert!(
        switches.contains(&argmax),
        "largest pop on frame {argmax}, switches {switches:?}"
    );

    // Timestamps: lavapipe offers them; every timed frame then has a GPU time.
    if manifest["timing_source"] == "gpu-timestamps" {
        assert!(col(&rows, "discrete", "gpu_ms").iter().all(|&x| x >= 0.0));
    }
    let summary = read_csv(&out.join("summary.csv"));
    assert_eq!(summary.len(), 2);
    let d = summary.iter().find(|r| r["method"] == "discrete").unwrap();
    assert_eq!(d["frames"], "600");
    let pop_max: f64 = d["pop_max"].parse().unwrap();
    assert_eq!(pop_max, pop[argmax]);
}

/// The reference's own quality pass reads its frame as the reference only where a dump or FLIP needs it: there
/// its dumped reference image is its dumped frame, byte for byte, and its FLIP error is 0 on every frame (a stale
/// reference target, one not refreshed from the method's frame, scores about 0.6 here); discrete's pass, which
/// copies the reference from the cache the reference's pass filled, dumps the same reference images.
#[test]
fn the_references_own_pass_dumps_and_flips_its_own_frame() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    #[rustfmt::skip]
    let cfg = run_config(&[
        "--scene", "bunny-sweep", "--method", "reference,discrete", "--width", "64", "--height", "48",
        "--frames", "12", "--warmup", "0", "--dump-frames", "--dump-every", "4", "--metrics", "rmse,pop,flip",
        "--out", out.to_str().unwrap(),
    ]);
    run::run(&cfg).unwrap();
    let rows = read_csv(&out.join("frames.csv"));
    let flip = col(&rows, "reference", "flip_mean");
    assert_eq!(flip.len(), 12);
    assert!(
        flip.iter().all(|&x| x == 0.0),
        "reference flip_mean {flip:?}"
    );
    let png = |method: &str, f: u32, kind: &str| {
        let name = format!("bunny-sweep_{method}_c1_f{f:05}_{kind}.png");
        lodbench::raster::read(out.join("frames").join(&name))
            .unwrap_or_else(|e| panic!("{name}: {e}"))
    };
    for f in [0, 4, 8] {
        let frame = png("reference", f, "method");
        assert!(frame == png("reference", f, "reference"), "frame {f}");
        assert!(
            frame == png("discrete", f, "reference"),
            "frame {f}: cached"
        );
    }
}

/// The same flags twice give identical quality columns (and everything else that is not a time), for every
/// method: the frame-sequential ones (fsi*) and the noise-driven one (dither) included.
#[test]
fn same_flags_same_metrics() {
    let dir = tempfile::tempdir().unwrap();
    let run_once = |name: &str| {
        let out = dir.path().join(name);
        let cfg = run_config(&[
            "--scene",
            "bunny-sweep",
            "--width",
            "160",
            "--height",
            "120",
            "--frames",
            "60",
            "--metrics",
            "rmse,pop,de2000",
            "--out",
            out.to_str().unwrap(),
        ]);
        run::run(&cfg).unwrap();
        read_csv(&out.join("frames.csv"))
    };
    let a = run_once("a");
    let b = run_once("b");
    for method in lodbench::methods::defaults_for(false) {
        for name in [
            "rmse",
            "pop",
            "lodpop",
            "de2000_mean",
            "triangles",
            "draw_calls",
            "t_instances",
            "lod_mean",
        ] {
            let (x, y) = (col(&a, method, name), col(&b, method, name));
            assert_eq!(x.len(), 60, "{method}");
            assert_eq!(
                x, y,
                "{method}: column {name} differs between identical runs"
            );
        }
        if method.starts_with("fsi") {
            let lag = |rows: &Vec<crate::common::Row>| -> Vec<String> {
                rows.iter()
                    .filter(|r| r["method"] == method)
                    .map(|r| r["lag_rmse"].clone())
                    .collect()
            };
            assert_eq!(lag(&a), lag(&b), "{method}: lag_rmse differs");
        }
    }
    assert!(col(&a, "discrete", "rmse").iter().any(|&x| x > 0.0));
}

/// See `gpu_metrics_match_cpu_oracle`.
const DE2000_TOLERANCE: f64 = 1e-5;

/// The GPU metric kernel agrees with the CPU oracle on read-back frames: rmse and pop to 1e-5, de2000_mean to
/// `DE2000_TOLERANCE`.
#[test]
fn gpu_metrics_match_cpu_oracle() {
    let scene = crate::common::sweep_scene(&[
        "--width",
        "160",
        "--height",
        "120",
        "--frames",
        "90",
        "--switch-distances",
        "12,16,20",
    ]);
    let ctx = crate::common::gpu();
    let mut block = BlockRunner::new(
        &ctx,
        &scene,
        Default::default(),
        true,
        &QualityOptions::with_de2000(),
    )
    .unwrap();
    let mut oracle = SequenceMetrics::new();
    let mut cpu = Vec::new();
    let out = block
        .run_method("discrete", 0, 1, &ProgressBar::hidden(), |_, img| {
            cpu.push(oracle.frame(img.method, img.reference));
            Ok(())
        })
        .unwrap();
    assert_eq!(cpu.len(), out.rows.len());
    for (row, c) in out.rows.iter().zip(&cpu) {
        let (rmse, pop) = (row.rmse.unwrap(), row.pop.unwrap());
        assert!(
            (rmse - c.rmse).abs() < 1e-5,
            "frame {}: gpu rmse {rmse} cpu {}",
            row.frame,
            c.rmse
        );
        assert!(
            (pop - c.pop).abs() < 1e-5,
            "frame {}: gpu pop {pop} cpu {}",
            row.frame,
            c.pop
        );
    }
    // de2000: the GPU evaluates CIEDE2000 per pixel in f32 and rounds it to 1/65536, the CPU in f64. The largest
    // difference of the frame means on this sequence was 6.5e-7 on lavapipe (Mesa 22.3.6); the bound leaves a
    // factor of 15 for other drivers' f32 pow and atan2, and a wrong formula, matrix or white point moves the
    // mean by far more.
    let de_diff = out
        .rows
        .iter()
        .zip(&cpu)
        .map(|(row, c)| (row.de2000_mean.unwrap() - c.de2000).abs())
        .fold(0.0, f64::max);
    println!("largest |gpu - cpu| de2000_mean: {de_diff:e}");
    assert!(
        de_diff < DE2000_TOLERANCE,
        "de2000: gpu and cpu differ by {de_diff}"
    );
    // Not vacuous: the sequence has real errors and real pops.
    assert!(cpu.iter().any(|m| m.rmse > 1e-3));
    assert!(cpu.iter().any(|m| m.pop > 1e-3));
    assert!(cpu.iter().any(|m| m.de2000 > 1e-2));
}

/// A rendered frame against a blessed PNG, with the snapshots' tolerance (`common::snapshot_problem`: a
/// different LLVM or Mesa version's rasterisation may differ on edge pixels, a changed shading, colour or camera
/// fails).
#[test]
fn snapshot_reference_frame() {
    let scene = crate::common::sweep_scene(&[
        "--width",
        "160",
        "--height",
        "120",
        "--frames",
        "2",
        "--switch-distances",
        "20,30,40",
    ]);
    let ctx = crate::common::gpu();
    let mut block =
        BlockRunner::new(&ctx, &scene, Default::default(), true, &Default::default()).unwrap();
    let mut frame0 = None;
    block
        .run_method("reference", 0, 1, &ProgressBar::hidden(), |f, img| {
            if f == 0 {
                frame0 = Some(img.method.to_vec());
            }
            Ok(())
        })
        .unwrap();
    let actual = lodbench::raster::RgbaImage::from_raw(scene.width, scene.height, frame0.unwrap())
        .expect("a frame of the viewport's size");
    let snap =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/snapshots/bunny-sweep_reference_f0.png");
    if let Some(problem) = snapshot_problem(&actual, &snap) {
        panic!("snapshot differs: {problem}");
    }
}

/// `--metrics flip` adds a flip_mean column: 0 exactly where the method frame equals the reference, above 0
/// where it differs; without it the column is empty.
#[test]
fn flip_metric_on_request() {
    let dir = tempfile::tempdir().unwrap();
    let run_with = |name: &str, metrics: &str| {
        let out = dir.path().join(name);
        let cfg = run_config(&[
            "--scene",
            "bunny-sweep",
            "--method",
            "discrete",
            "--width",
            "160",
            "--height",
            "120",
            "--frames",
            "40",
            "--warmup",
            "0",
            "--switch-distances",
            "14,16,18",
            "--metrics",
            metrics,
            "--out",
            out.to_str().unwrap(),
        ]);
        run::run(&cfg).unwrap();
        read_csv(&out.join("frames.csv"))
    };
    let rows = run_with("flip", "rmse,pop,de2000,flip");
    let mut differing = 0;
    for r in &rows {
        let rmse: f64 = r["rmse"].parse().unwrap();
        let flip: f64 = r["flip_mean"].parse().expect("flip_mean filled");
        if rmse == 0.0 {
            assert_eq!(flip, 0.0, "frame {}", r["frame"]);
        } else {
            assert!(flip > 0.0, "frame {}", r["frame"]);
            differing += 1;
        }
    }
    assert!(differing > 0);
    let rows = run_with("default", "rmse,pop");
    assert!(rows.iter().all(|r| r["flip_mean"].is_empty()));
    assert!(
        rows.iter().all(|r| r["de2000_mean"].is_empty()),
        "de2000 only when asked"
    );
}

/// An experiment file with a viewport sweep: one run per value, merged CSVs with a `viewport` column.
#[test]
fn experiment_sweep_runs_and_merges() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("sweep.toml");
    std::fs::write(
        &file,
        "name = \"tiny\"\n[run]\nscene = [\"bunny-sweep\"]\nmethod = [\"reference\", \"discrete\"]\n\
         frames = 4\nwarmup = 0\n[sweep]\nvariable = \"viewport\"\nvalues = [[64, 48], [96, 72]]\n",
    )
    .unwrap();
    let e = lodbench::commands::experiment::Experiment::load(&file).unwrap();
    let out = dir.path().join("out");
    let folders = e.run(&out).unwrap();
    assert_eq!(folders.len(), 2);
    let rows = read_csv(&out.join("summary.csv"));
    assert_eq!(rows.len(), 4);
    let viewports: Vec<&str> = rows.iter().map(|r| r["viewport"].as_str()).collect();
    assert_eq!(viewports, vec!["64,48", "64,48", "96,72", "96,72"]);
    assert_eq!(read_csv(&out.join("frames.csv")).len(), 2 * 2 * 4);
    assert!(out.join("experiment.json").is_file());
}

/// One frame of every scene at 96x72 per method against a blessed PNG (tests/snapshots/scenes/), with the
/// tolerance of `snapshot_reference_frame`: mean absolute difference at most 0.5 of 255 and at most 0.5 % of
/// pixels off by more than 16. Frame 2 of a 4-frame run: the procedural scenes' camera is then two thirds of
/// the way through its flight, inside the field. Re-bless with `LODBENCH_BLESS=1 cargo test --release --test it
/// snapshot`.
#[test]
fn snapshot_scenes_every_method() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let cfg = run_config(&[
        "--width",
        "96",
        "--height",
        "72",
        "--frames",
        "4",
        "--warmup",
        "0",
        "--count",
        "4",
        "--dump-frames",
        "--dump-every",
        "2",
        "--out",
        out.to_str().unwrap(),
    ]);
    run::run(&cfg).expect("every scene and method renders");
    let snaps = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/snapshots/scenes");
    let bless = std::env::var_os("LODBENCH_BLESS").is_some();
    let mut problems = Vec::new();
    let mut checked = 0;
    let mut expected = 0;
    for kind in SceneKind::ALL {
        let scene = kind.name();
        let count = if kind.single_count() { 1 } else { 4 };
        let methods = lodbench::methods::defaults_for(kind.is_unified());
        expected += methods.len();
        for method in methods {
            let stem = format!("{scene}_{method}_c{count}_f00002_method.png");
            let frame = out.join("frames").join(&stem);
            let actual = lodbench::raster::read(&frame)
                .unwrap_or_else(|e| panic!("{}: {e}", frame.display()));
            let snap = snaps.join(format!("{scene}_{method}.png"));
            if let Some(p) = snapshot_problem(&actual, &snap) {
                problems.push(format!("{scene} {method}: {p}"));
            }
            checked += 1;
        }
    }
    assert!(
        problems.is_empty(),
        "scene snapshots differ:\n{}",
        problems.join("\n")
    );
    assert!(bless || checked == expected);
}

/// A run of `methods` on a short bunny-sweep with `rounds` timing rounds and `seed`: its folder.
fn timing_run(
    dir: &Path,
    name: &str,
    methods: &str,
    rounds: &str,
    seed: &str,
) -> std::path::PathBuf {
    let out = dir.join(name);
    let cfg = run_config(&[
        "--scene",
        "bunny-sweep",
        "--method",
        methods,
        "--width",
        "64",
        "--height",
        "48",
        "--frames",
        "24",
        "--warmup",
        "1",
        "--switch-distances",
        "14,16,18",
        "--rounds",
        rounds,
        "--seed",
        seed,
        "--out",
        out.to_str().unwrap(),
    ]);
    run::run(&cfg).unwrap();
    out
}

fn timing_rounds(out: &Path) -> serde_json::Value {
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    run["timing_rounds"].clone()
}

/// The timing rounds are recorded in run.json, cover the path in order, hold every method once each (plus the
/// reference, timed for quality_to_renders_ratio), and their order is drawn from --seed: the same seed gives the
/// same orders, another seed other orders. frames.csv's `round` column agrees with run.json.
#[test]
fn timing_rounds_are_seeded_and_recorded() {
    let dir = tempfile::tempdir().unwrap();
    let methods = "discrete,alpha,dither";
    let a = timing_run(dir.path(), "a", methods, "6", "1");
    let b = timing_run(dir.path(), "b", methods, "6", "1");
    let c = timing_run(dir.path(), "c", methods, "6", "2");
    let (ra, rb, rc) = (timing_rounds(&a), timing_rounds(&b), timing_rounds(&c));
    assert_eq!(ra, rb, "same seed, same rounds");
    let orders = |r: &serde_json::Value| -> Vec<Vec<String>> {
        r[0]["rounds"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| serde_json::from_value(x["order"].clone()).unwrap())
            .collect()
    };
    assert_ne!(orders(&ra), orders(&rc), "another seed, other orders");
    let rounds = ra[0]["rounds"].as_array().unwrap();
    assert_eq!(rounds.len(), 6);
    assert_eq!(ra[0]["timed_only"], serde_json::json!(["reference"]));
    // The warm-up rendered the first frames of the path's transitions, which are frames in transition.
    let warm: Vec<u32> = serde_json::from_value(ra[0]["warmup_transition_frames"].clone()).unwrap();
    let t_frames: Vec<u32> = read_csv(&a.join("frames.csv"))
        .iter()
        .filter(|r| r["method"] == "discrete" && r["t_instances"] != "0")
        .map(|r| r["frame"].parse().unwrap())
        .collect();
    assert!(
        !warm.is_empty() && t_frames.contains(&warm[0]),
        "{warm:?} {t_frames:?}"
    );
    let mut next = 0;
    for r in rounds {
        let frames: [u32; 2] = serde_json::from_value(r["frames"].clone()).unwrap();
        assert_eq!(frames[0], next, "rounds cover the path in order");
        next = frames[1];
        let mut order: Vec<String> = serde_json::from_value(r["order"].clone()).unwrap();
        order.sort();
        assert_eq!(order, ["alpha", "discrete", "dither", "reference"]);
    }
    assert_eq!(next, 24);
    // Not every round in the same order.
    assert!(orders(&ra).windows(2).any(|w| w[0] != w[1]));
    let frames = read_csv(&a.join("frames.csv"));
    for row in frames.iter().filter(|r| r["method"] == "alpha") {
        let (f, round): (u32, usize) =
            (row["frame"].parse().unwrap(), row["round"].parse().unwrap());
        let span: [u32; 2] = serde_json::from_value(rounds[round]["frames"].clone()).unwrap();
        assert!(span[0] <= f && f < span[1], "frame {f} in round {round}");
    }
    // rounds.csv: a row per method and round, paired with the baseline (discrete, the default).
    let per_round = read_csv(&a.join("rounds.csv"));
    assert_eq!(per_round.len(), 3 * 6);
    assert!(per_round.iter().all(|r| r["baseline"] == "discrete"));
    let d: Vec<&crate::common::Row> = per_round
        .iter()
        .filter(|r| r["method"] == "discrete")
        .collect();
    assert!(d.iter().all(|r| r["ratio_to_baseline"] == "1.0"));
}

/// `--method discrete,discrete` runs discrete twice, as `discrete` and `discrete#2`: two blocks everywhere, the
/// same images (an A/A comparison differs only in time), and a paired ratio of the second over the first.
#[test]
fn a_method_listed_twice_runs_twice() {
    let dir = tempfile::tempdir().unwrap();
    let out = timing_run(dir.path(), "aa", "discrete,discrete", "4", "1");
    let summary = read_csv(&out.join("summary.csv"));
    let methods: Vec<&str> = summary.iter().map(|r| r["method"].as_str()).collect();
    assert_eq!(methods, ["discrete", "discrete#2"]);
    let frames = read_csv(&out.join("frames.csv"));
    for name in ["rmse", "pop", "lodpop", "triangles"] {
        assert_eq!(
            col(&frames, "discrete", name),
            col(&frames, "discrete#2", name),
            "{name}"
        );
    }
    assert_eq!(col(&frames, "discrete#2", "rmse").len(), 24);
    let second = &summary[1];
    assert_eq!(second["baseline"], "discrete");
    assert_eq!(second["rounds"], "4");
    let ratio: f64 = second["ratio_to_baseline"].parse().unwrap();
    let lo: f64 = second["ratio_to_baseline_ci95_lo"].parse().unwrap();
    let hi: f64 = second["ratio_to_baseline_ci95_hi"].parse().unwrap();
    assert!(lo <= ratio && ratio <= hi && ratio > 0.0);
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    let blocks: Vec<&str> = run["blocks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b["method"].as_str().unwrap())
        .collect();
    assert_eq!(blocks, ["discrete", "discrete#2"]);
    // q/r is paired round by round: a ratio per round, their geometric mean inside its interval.
    for b in run["blocks"].as_array().unwrap() {
        let q = b["quality_to_renders_ratio"].as_f64().unwrap();
        let lo = b["quality_to_renders_ratio_ci95_lo"].as_f64().unwrap();
        let hi = b["quality_to_renders_ratio_ci95_hi"].as_f64().unwrap();
        assert!(q > 0.0 && lo <= q && q <= hi, "{q} [{lo}, {hi}]");
        let by_round: Vec<f64> = b["quality_to_renders_by_round"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        assert_eq!(by_round.len(), 4);
        let geomean = (by_round.iter().map(|x| x.ln()).sum::<f64>() / 4.0).exp();
        assert!((geomean - q).abs() < 1e-9 * q, "{geomean} against {q}");
    }
}

/// `--max-transitions` reaches the run: on windmills (ci, timing only) with time fades a cap of 1 holds instances back (run.json's
/// wait_instance_frames and waiting_max above 0, t_instances never above 1), and without it nothing waits.
#[test]
fn max_transitions_caps_t_instances_and_records_the_wait() {
    let dir = tempfile::tempdir().unwrap();
    let run = |cap: &str| {
        let out = dir.path().join(format!("cap{cap}"));
        crate::common::run_into(
            &out,
            &[
                "--scene",
                "windmills",
                "--profile",
                "ci",
                "--fade",
                "time",
                "--fade-frames",
                "8",
                "--max-transitions",
                cap,
                "--method",
                "discrete",
                "--quality",
                "off",
                "--rounds",
                "1",
                "--warmup",
                "0",
            ],
        );
        let run: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
        let b = &run["blocks"][0];
        let t_max = crate::common::read_csv(&out.join("frames.csv"))
            .iter()
            .map(|r| r["t_instances"].parse::<u32>().unwrap())
            .max()
            .unwrap();
        (
            b["wait_instance_frames"].as_u64().unwrap(),
            b["waiting_max"].as_u64().unwrap(),
            t_max,
        )
    };
    let (free_wait, _, free_t) = run("0");
    let (wait, waiting_max, t) = run("1");
    assert_eq!(free_wait, 0);
    assert!(
        free_t > 1,
        "without a cap several windmills fade at once ({free_t})"
    );
    assert_eq!(t, 1);
    assert!(wait > 0 && waiting_max > 0, "{wait} {waiting_max}");
}

/// `--shader-work N`: the loop runs (with the result's weight set to 1, the frame changes with N) and leaves
/// every frame of a run as it is (weight 0: frames.csv's quality columns equal those without it). Removing the
/// loop from `shade` (tried) makes the first half fail.
#[test]
fn shader_work_runs_and_leaves_the_image_alone() {
    let frame0 = |work: &str, weight: f32| {
        let mut scene = crate::common::sweep_scene(&[
            "--width",
            "96",
            "--height",
            "72",
            "--frames",
            "2",
            "--shader-work",
            work,
        ]);
        scene.shader_work_weight = weight;
        let ctx = crate::common::gpu();
        let mut block =
            BlockRunner::new(&ctx, &scene, Default::default(), true, &Default::default()).unwrap();
        let mut out = None;
        block
            .run_method("reference", 0, 1, &ProgressBar::hidden(), |f, img| {
                if f == 0 {
                    out = Some(img.method.to_vec());
                }
                Ok(())
            })
            .unwrap();
        out.unwrap()
    };
    let plain = frame0("0", 0.0);
    assert_eq!(frame0("64", 0.0), plain);
    let (w0, w64) = (frame0("0", 1.0), frame0("64", 1.0));
    assert_ne!(w0, plain);
    assert_ne!(w64, w0, "64 iterations give the same colour as none");

    let dir = tempfile::tempdir().unwrap();
    let run = |work: &str| {
        let out = crate::common::run_into(
            &dir.path().join(work),
            &[
                "--scene",
                "bunny-sweep",
                "--profile",
                "regress",
                "--frames",
                "24",
                "--method",
                "discrete,alpha",
                "--shader-work",
                work,
            ],
        );
        crate::common::read_csv(&out.join("frames.csv"))
            .into_iter()
            .map(|r| {
                (
                    r["method"].clone(),
                    r["frame"].clone(),
                    r["rmse"].clone(),
                    r["lodpop"].clone(),
                )
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(run("0"), run("32"));
}

/// The quality pass is made round by round, each method's by an instance of its own with its own stage (targets,
/// kernels, TAA streams) while the other methods' segments run in between: every image figure is the same in 1
/// round as in 4, and with `--quality-schedule after` (every timing round first), for methods whose frame
/// carries state (FSI's buffers, TAA's history, ROAM's triangulation).
#[test]
fn the_quality_pass_does_not_depend_on_the_rounds() {
    let dir = tempfile::tempdir().unwrap();
    let figures = [
        "rmse",
        "pop",
        "lodpop",
        "lag_rmse",
        "uncovered_px",
        "crack_px",
        "triangles",
    ];
    for (name, args) in [
        (
            "simple",
            &[
                "--scene",
                "simple",
                "--profile",
                "regress",
                "--frames",
                "24",
                "--taa",
                "on",
                "--method",
                "alpha,fsi,dither",
            ][..],
        ),
        (
            "terrain",
            &[
                "--scene",
                "terrain",
                "--profile",
                "regress",
                "--frames",
                "16",
                "--method",
                "roam,blocks",
            ][..],
        ),
    ] {
        let run = |rounds: &str, schedule: &str| {
            let out = dir.path().join(format!("{name}-{rounds}-{schedule}"));
            let mut argv = args.to_vec();
            argv.extend_from_slice(&["--rounds", rounds, "--quality-schedule", schedule]);
            read_csv(&crate::common::run_into(&out, &argv).join("frames.csv"))
        };
        let (one, four) = (run("1", "rounds"), run("4", "rounds"));
        let after = run("4", "after");
        assert_eq!(one.len(), four.len());
        let rounds: Vec<&str> = four.iter().map(|r| r["round"].as_str()).collect();
        assert!(rounds.contains(&"3"), "{name}: four rounds ran");
        for ((a, b), c) in one.iter().zip(&four).zip(&after) {
            for f in figures {
                let at = format!("{name} {} frame {} {f}", a["method"], a["frame"]);
                assert_eq!(a[f], b[f], "{at}");
                assert_eq!(a[f], c[f], "{at} (after)");
            }
        }
    }
}
