//! lodpop, the popping score that holds the pose fixed (docs/measurement.md, "lodpop"), on the software
//! adapter: (a) zero without transitions while pop is not; (b) discrete's only on its switch frames; (c) every
//! smooth method below discrete at every transition of a bunny sweep; (d) the GPU kernel against the CPU
//! oracle on dumped frames, for lodpop, its coverage and shading parts and FSI's lag_rmse; and fsi-sameframe,
//! which has no lag, at lag 0; (e) a switch that changes colours only is all shading, one that changes the
//! outline only all coverage; (f) instances switching together are one pop event (events.csv).

use crate::common::{col, read_csv, run_into, Rows};

use std::path::Path;

fn run(out: &Path, args: &[&str]) -> Rows {
    read_csv(&run_into(out, args).join("frames.csv"))
}

const METHODS: &str =
    "discrete,alpha,alpha-2pass,alpha-zwrite,dither,geomorph,fsi,fsi-noreproject,fsi-sameframe";

/// (a) Two bunnies that never change LOD (the near one at LOD0, the far one at LOD1) while the camera orbits
/// the near one: every method's lodpop is exactly 0 on every frame, while pop is not (the far bunny's LOD1
/// error moves on screen).
#[rustfmt::skip]
#[test]
fn no_schedule_change_no_lodpop() {
    let dir = tempfile::tempdir().unwrap();
    let rows = run(
        dir.path(),
        &[
            "--scene", "bunny-grid", "--count", "2", "--camera", "orbit", "--frames", "24", "--width",
            "96", "--height", "72", "--sweep-start", "close-up", "--method", METHODS,
        ],
    );
    for m in METHODS.split(',') {
        assert!(col(&rows, m, "t_instances").iter().all(|&t| t == 0.0), "{m}: a transition");
        assert!(col(&rows, m, "lodpop").iter().all(|&x| x == 0.0), "{m}: lodpop not 0");
        assert!(col(&rows, m, "pop").iter().any(|&x| x > 0.0), "{m}: pop all 0");
    }
}

/// A small bunny sweep of every method, run once for (b) and (c).
fn sweep(dir: &Path) -> Rows {
    run(
        dir,
        &[
            "--scene",
            "bunny-sweep",
            "--frames",
            "200",
            "--width",
            "160",
            "--height",
            "120",
            // Close up, where the bunny's LOD differences are visible at 160x120 (--sweep-start's help).
            "--sweep-start",
            "close-up",
            "--method",
            METHODS,
        ],
    )
}

#[test]
fn discrete_pops_only_at_its_switches_and_smooth_methods_pop_less() {
    let dir = tempfile::tempdir().unwrap();
    let rows = sweep(dir.path());

    // (b) discrete's picture changes with the schedule only where its LOD switches, which is where its
    // triangle count changes.
    let tri = col(&rows, "discrete", "triangles");
    let lodpop = col(&rows, "discrete", "lodpop");
    let switches: Vec<usize> = (1..tri.len()).filter(|&f| tri[f] != tri[f - 1]).collect();
    assert_eq!(
        switches.len(),
        6,
        "three switches out, three back: {switches:?}"
    );
    for (f, &x) in lodpop.iter().enumerate() {
        assert_eq!(x > 0.0, switches.contains(&f), "frame {f}: lodpop {x}");
    }

    // (c) Per transition, every smooth method's largest lodpop is below discrete's.
    let transitions = read_csv(&dir.path().join("transitions.csv"));
    let max_of = |m: &str, t: &str| -> f64 {
        transitions
            .iter()
            .find(|r| r["method"] == m && r["transition"] == t)
            .unwrap_or_else(|| panic!("{m} transition {t}"))["lodpop_max"]
            .parse()
            .unwrap()
    };
    let n = transitions
        .iter()
        .filter(|r| r["method"] == "discrete")
        .count();
    assert_eq!(n, 6, "six transitions on the path");
    for t in 0..n {
        let t = t.to_string();
        let d = max_of("discrete", &t);
        assert!(d > 0.0);
        for m in METHODS.split(',').skip(1) {
            let x = max_of(m, &t);
            assert!(
                x < d,
                "transition {t}: {m} lodpop {x} not below discrete's {d}"
            );
        }
    }
}

/// (d) The GPU's lodpop and lag_rmse against `metrics::rms_difference` on the dumped frames (the method's
/// frame, or FSI's lag-free frame, against the frame with the previous schedule), to 1e-5; fsi-sameframe's lag
/// is exactly 0, since its frame is its lag-free frame.
#[test]
fn gpu_lodpop_and_lag_match_the_cpu_oracle() {
    let dir = tempfile::tempdir().unwrap();
    let rows = run(
        dir.path(),
        &[
            "--scene",
            "bunny-sweep",
            "--frames",
            "120",
            "--width",
            "96",
            "--height",
            "72",
            "--method",
            "alpha,dither,fsi,fsi-sameframe",
            "--dump-frames",
            "--dump-transitions",
        ],
    );
    let frames = dir.path().join("frames");
    let load = |stem: &str, name: &str| -> Option<Vec<u8>> {
        let p = frames.join(format!("{stem}_{name}.png"));
        p.exists()
            .then(|| lodbench::raster::read(&p).unwrap().into_raw())
    };
    let (mut lodpop_checked, mut lag_checked) = (0, 0);
    for r in &rows {
        let stem = format!(
            "bunny-sweep_{}_c1_f{:05}",
            r["method"],
            r["frame"].parse::<u32>().unwrap()
        );
        let Some(method) = load(&stem, "method") else {
            continue;
        };
        let now = load(&stem, "lodpop-now");
        if let Some(before) = load(&stem, "lodpop-before") {
            // The background's bytes: a corner of the reference frame, which the bunny never reaches.
            let corner = load(&stem, "reference").unwrap();
            let bg = [corner[0], corner[1], corner[2]];
            let (cpu, coverage, shading) = lodbench::measure::metrics::rms_difference_parts(
                now.as_ref().unwrap_or(&method),
                &before,
                bg,
            );
            for (c, want) in [
                ("lodpop", cpu),
                ("lodpop_coverage", coverage),
                ("lodpop_shading", shading),
            ] {
                let gpu: f64 = r[c].parse().unwrap();
                assert!(
                    (want - gpu).abs() < 1e-5,
                    "{stem}: {c} gpu {gpu} cpu {want}"
                );
            }
            lodpop_checked += 1;
        }
        if let Some(now) = &now {
            let cpu = lodbench::measure::metrics::rms_difference(&method, now);
            let gpu: f64 = r["lag_rmse"].parse().unwrap();
            assert!((cpu - gpu).abs() < 1e-5, "{stem}: lag gpu {gpu} cpu {cpu}");
            lag_checked += 1;
        }
    }
    assert!(
        lodpop_checked >= 20,
        "{lodpop_checked} lodpop frames checked"
    );
    assert!(lag_checked >= 10, "{lag_checked} lag frames checked");
    assert!(col(&rows, "fsi-sameframe", "lag_rmse")
        .iter()
        .all(|&x| x == 0.0));
    assert!(
        col(&rows, "fsi", "lag_rmse").iter().any(|&x| x > 0.0),
        "fsi shows no lag"
    );
    assert!(rows
        .iter()
        .filter(|r| r["method"] == "alpha")
        .all(|r| r["lag_rmse"].is_empty()));
}

/// dither's moving pattern (`--noise-temporal`) moves only because an instance is in transition, so its
/// motion is part of the transition: a static bunny held at its first switch distance (k = 0.5 on every frame,
/// a fixed camera, no change of state; its LODs in two colours) scores lodpop > 0 on every frame but the first
/// with the moving pattern, and exactly 0 with the fixed one; `--metric-region full` (the check of the covered
/// region) agrees.
#[test]
fn a_moving_dither_pattern_pops_at_a_fixed_state() {
    use lodbench::measure::metrics::MetricRegion;
    use lodbench::measure::{BlockRunner, MethodSetup, QualityOptions};
    let ctx = crate::common::gpu();
    let d = crate::common::near_distance();
    let scene = crate::common::static_scene(&[d], [d, 1.5 * d, 2.0 * d], 12, "fixed");
    let lodpop_of = |moving: bool, region: MetricRegion| -> (Vec<f64>, Vec<f64>) {
        let mut setup = MethodSetup {
            registry: lodbench::methods::Registry::builtin(),
            options: Default::default(),
            seed: 1,
        };
        setup.options.dither.noise_temporal = moving;
        let quality = QualityOptions {
            region,
            ..Default::default()
        };
        let mut block = BlockRunner::new(&ctx, &scene, setup, false, &quality).unwrap();
        let out = block
            .run_method("dither", 0, 1, &indicatif::ProgressBar::hidden(), |_, _| {
                Ok(())
            })
            .unwrap();
        let k = out.rows.iter().map(|r| r.k_mean.unwrap_or(-1.0)).collect();
        (out.rows.iter().map(|r| r.lodpop.unwrap()).collect(), k)
    };
    let (lodpop, k) = lodpop_of(true, MetricRegion::Covered);
    assert!(k.iter().all(|&k| (k - 0.5).abs() < 1e-3), "k: {k:?}");
    assert_eq!(lodpop[0], 0.0);
    assert!(
        lodpop[1..].iter().all(|&x| x > 0.0),
        "moving pattern: {lodpop:?}"
    );
    let (full, _) = lodpop_of(true, MetricRegion::Full);
    assert_eq!(full, lodpop, "--metric-region full differs");
    let (fixed, _) = lodpop_of(false, MetricRegion::Covered);
    assert!(fixed.iter().all(|&x| x == 0.0), "fixed pattern: {fixed:?}");
}

/// (e) lodpop's parts on two authored chains (tests/data/gltf/make_materials.py), unlit so that a colour is its
/// material's whatever the light: pop-shading's levels share their outline and differ in colour, so its switch is
/// all shading (coverage exactly 0); pop-coverage's share their colour and differ in outline, so its switch is all
/// coverage (shading exactly 0). Each crosses its switch on the default flight within the 40 frames.
#[test]
fn a_switch_of_colour_is_shading_and_a_switch_of_outline_is_coverage() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/gltf");
    for (file, part, other) in [
        ("pop-shading.gltf", "lodpop_shading", "lodpop_coverage"),
        ("pop-coverage.gltf", "lodpop_coverage", "lodpop_shading"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let scene = data.join(file);
        #[rustfmt::skip]
        let rows = run(dir.path(), &[
            "--scene", scene.to_str().unwrap(), "--method", "discrete", "--frames", "40", "--width", "96",
            "--height", "72",
        ]);
        let lodpop = col(&rows, "discrete", "lodpop");
        let (mine, theirs) = (col(&rows, "discrete", part), col(&rows, "discrete", other));
        let switches: Vec<usize> = (0..lodpop.len()).filter(|&f| lodpop[f] > 0.0).collect();
        assert_eq!(switches.len(), 1, "{file}: one switch: {lodpop:?}");
        for f in 0..lodpop.len() {
            assert_eq!(theirs[f], 0.0, "{file} frame {f}: {other} {}", theirs[f]);
            assert!(
                (mine[f] - lodpop[f]).abs() <= 1e-12 * lodpop[f].max(1.0),
                "{file} frame {f}: {part} {} lodpop {}",
                mine[f],
                lodpop[f]
            );
        }
        let transitions = read_csv(&dir.path().join("transitions.csv"));
        assert_eq!(transitions.len(), 1, "{file}");
        assert_eq!(transitions[0][other].parse::<f64>().unwrap(), 0.0, "{file}");
        assert_eq!(transitions[0][part], transitions[0]["lodpop_max"], "{file}");
    }
}

/// (f) A planted wave: bunny-grid's two bunnies (x = 13.28 and 61.35) seen from a camera that backs away along
/// their perpendicular bisector, so both are at one distance on every frame and switch together at each of the
/// three switch distances. events.csv has a wave per switch distance, each of both bunnies' switches, scored by
/// the combined change of its frame (discrete: both switch on one frame, so the event's lodpop is that frame's;
/// dither: the fade's largest frame at least); every squared lodpop of discrete's frames is some event's.
#[rustfmt::skip]
#[test]
fn a_wave_of_instances_switching_together_is_one_event() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("path.csv");
    let mid = 0.5 * (13.278 + 61.35);
    std::fs::write(&path, format!("frame,x,y,z,target_x,target_y,target_z\n0,{mid},0,32,{mid},0,0\n1,{mid},0,100,{mid},0,0\n")).unwrap();
    let out = run_into(&dir.path().join("run"), &[
        "--scene", "bunny-grid", "--count", "2", "--camera-path", path.to_str().unwrap(), "--frames", "60",
        "--width", "128", "--height", "96", "--switch-distances", "45,60,80", "--rounds", "1", "--warmup", "0",
        "--method", "discrete,dither",
    ]);
    let frames = read_csv(&out.join("frames.csv"));
    let events = read_csv(&out.join("events.csv"));
    let num = |r: &std::collections::HashMap<String, String>, c: &str| r[c].parse::<f64>().unwrap();
    for method in ["discrete", "dither"] {
        let mine: Vec<_> = events.iter().filter(|e| e["method"] == method).collect();
        assert_eq!(mine.len(), 3, "{method}: a wave per switch distance: {mine:?}");
        assert!(mine.iter().all(|e| e["switches"] == "2"), "{method}: both bunnies in each wave: {mine:?}");
        let lodpop = col(&frames, method, "lodpop");
        for e in &mine {
            let (a, b) = (num(e, "first_frame") as usize, num(e, "last_frame") as usize);
            let largest = lodpop[a..=b + 2].iter().cloned().fold(0.0, f64::max);
            assert!(largest > 0.0, "{method}: the wave changes its frames");
            assert!(num(e, "lodpop") >= largest * (1.0 - 1e-9), "{method}: {e:?} against its frame's {largest}");
        }
    }
    let discrete: Vec<_> = events.iter().filter(|e| e["method"] == "discrete").collect();
    for e in &discrete {
        assert_eq!(e["first_frame"], e["last_frame"], "a discrete switch is one frame, both on the same");
        let f = num(e, "first_frame") as usize;
        let on_frame = col(&frames, "discrete", "lodpop")[f];
        assert!((num(e, "lodpop") - on_frame).abs() <= 1e-12, "{e:?}: the frame's {on_frame}");
    }
    let frames_sq: f64 = col(&frames, "discrete", "lodpop").iter().map(|l| l * l).sum();
    let events_sq: f64 = discrete.iter().map(|e| num(e, "lodpop").powi(2)).sum();
    assert!((frames_sq - events_sq).abs() <= 1e-12 * frames_sq.max(1e-12), "{frames_sq} against {events_sq}");
    let summary = read_csv(&out.join("summary.csv"));
    assert!(summary.iter().all(|s| s["pop_events"] == "3"), "{summary:?}");
}
