//! `lodbench score DIR` (docs/measurement.md, "Scoring another renderer's frames"): (a) a score folder written
//! from a run's own dumps (its frames, counterfactuals and reference, and the levels its schedule drew) gives
//! back that run's frames.csv image columns exactly, and its events.csv, for a switching and two blending
//! methods; (b) a folder that breaks the protocol is refused with one error naming what is wrong, and nothing
//! is written.

use crate::common::{fails_with, lodbench, read_csv, run_into, sweep_scene};
use lodbench::measure::FrameDriver;
use std::path::Path;

const SIZE: [&str; 4] = ["--width", "96", "--height", "72"];
const PATH: [&str; 4] = ["--frames", "120", "--switch-distances", "14,16,18"];
const IMAGE_COLUMNS: [&str; 8] = [
    "rmse",
    "pop",
    "lodpop",
    "lodpop_coverage",
    "lodpop_shading",
    "uncovered_px",
    "crack_px",
    "flip_mean",
];

/// lods.csv of `method` along the run's path, from the run's own schedule: discrete draws `lod_from` below
/// k = 0.5 and `lod_to` from it (a switch); the blending methods blend while `lod_from != lod_to`.
fn lods_csv(method: &str) -> String {
    let args: Vec<&str> = SIZE.iter().chain(PATH.iter()).copied().collect();
    let scene = sweep_scene(&args);
    let mut driver = FrameDriver::new(&scene);
    let mut csv = String::from("frame,object,lod,lod_to,k\n");
    for f in 0..scene.frames {
        driver.advance(f);
        let s = driver.states[0];
        let row = match (method, s.lod_from == s.lod_to) {
            (_, true) => format!("{f},bunny,{},,\n", s.lod_from),
            ("discrete", false) => {
                format!(
                    "{f},bunny,{},,\n",
                    if s.k < 0.5 { s.lod_from } else { s.lod_to }
                )
            }
            _ => format!("{f},bunny,{},{},{}\n", s.lod_from, s.lod_to, s.k),
        };
        csv.push_str(&row);
    }
    csv
}

/// The score folder of `method` from the run folder `run`'s dumps.
fn folder_from_dumps(run: &Path, method: &str, out: &Path) {
    for sub in ["frame", "counterfactual", "reference"] {
        std::fs::create_dir_all(out.join(sub)).unwrap();
    }
    let lods = lods_csv(method);
    let frames = lods.lines().count() - 1;
    std::fs::write(out.join("lods.csv"), lods).unwrap();
    let corner = lodbench::raster::read(
        run.join(format!("frames/bunny-sweep_{method}_c1_f00000_method.png")),
    )
    .unwrap();
    let bg = corner.get_pixel(0, 0).0;
    std::fs::write(
        out.join("score.json"),
        format!(
            r#"{{"engine": "lodbench {method}", "fps": 60, "background": [{}, {}, {}],
                "scene": "bunny-sweep", "method": "{method}"}}"#,
            bg[0], bg[1], bg[2]
        ),
    )
    .unwrap();
    for f in 0..frames {
        let stem = run.join(format!("frames/bunny-sweep_{method}_c1_f{f:05}"));
        let dump = |kind: &str| std::path::PathBuf::from(format!("{}_{kind}.png", stem.display()));
        let name = format!("{f:05}.png");
        std::fs::copy(dump("method"), out.join("frame").join(&name)).unwrap();
        std::fs::copy(dump("reference"), out.join("reference").join(&name)).unwrap();
        if dump("lodpop-before").is_file() {
            std::fs::copy(
                dump("lodpop-before"),
                out.join("counterfactual").join(&name),
            )
            .unwrap();
        }
    }
}

/// (a) The run's image columns, cell for cell, from its own dumps: the sums are the kernels' exact integers and
/// FLIP the same CPU code on the same bytes. The test fails when a figure changes definition on either side.
#[test]
fn a_runs_own_dumps_score_to_its_frames_csv_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let mut args = vec![
        "--scene",
        "bunny-sweep",
        "--method",
        "reference,discrete,alpha,dither",
    ];
    args.extend(SIZE);
    args.extend(PATH);
    args.extend([
        "--warmup",
        "0",
        "--rounds",
        "2",
        "--metrics",
        "rmse,pop,flip",
        "--dump-frames",
    ]);
    let run = run_into(&dir.path().join("run"), &args);
    let ran = read_csv(&run.join("frames.csv"));
    for method in ["discrete", "alpha", "dither"] {
        let folder = dir.path().join(method);
        folder_from_dumps(&run, method, &folder);
        let out = lodbench(
            &[
                "score",
                folder.to_str().unwrap(),
                "--metrics",
                "rmse,pop,flip",
            ],
            &[],
        );
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let scored = read_csv(&folder.join("frames.csv"));
        let theirs: Vec<_> = ran.iter().filter(|r| r["method"] == method).collect();
        assert_eq!(scored.len(), theirs.len(), "{method}: frames");
        for (a, b) in theirs.iter().zip(&scored) {
            for c in IMAGE_COLUMNS {
                assert_eq!(a[c], b[c], "{method} frame {}: {c}", a["frame"]);
            }
        }
        let pops = scored
            .iter()
            .filter(|r| r["lodpop"].parse::<f64>().unwrap() > 0.0)
            .count();
        assert!(
            pops >= 3,
            "{method}: {pops} frames with a pop: the path crosses no switch"
        );
        let transitions = read_csv(&folder.join("transitions.csv"));
        assert!(
            transitions.len() >= 3,
            "{method}: {} transitions",
            transitions.len()
        );
        // The pop events: the run's instance switches (its schedule) and score's object switches (lods.csv) are
        // the same frames, and one object takes each frame's whole change, so the events are the run's.
        let events = |path: &Path| -> Vec<Vec<String>> {
            read_csv(path)
                .iter()
                .filter(|r| r["method"] == method)
                .map(|r| {
                    ["event", "first_frame", "last_frame", "switches", "lodpop"]
                        .map(|c| r[c].clone())
                        .to_vec()
                })
                .collect()
        };
        let (ours, scored_events) = (
            events(&run.join("events.csv")),
            events(&folder.join("events.csv")),
        );
        assert!(ours.len() >= 3, "{method}: {ours:?}");
        assert_eq!(ours, scored_events, "{method}: events.csv, run vs score");
        // clips and perceptual read the pictures under a run's dump names.
        let linked =
            folder.join("frames/bunny-sweep_".to_string() + method + "_c1_f00000_method.png");
        assert!(linked.is_file(), "{} missing", linked.display());
    }
}

/// A valid two-frame folder of 4x4 pictures whose selection changes on frame 1.
fn small_folder(dir: &Path) {
    for sub in ["frame", "counterfactual"] {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
    }
    std::fs::write(
        dir.join("score.json"),
        r#"{"engine": "test", "fps": 30, "background": [0, 0, 0]}"#,
    )
    .unwrap();
    std::fs::write(dir.join("lods.csv"), "frame,object,lod\n0,a,0\n1,a,1\n").unwrap();
    let picture = |v: u8| {
        lodbench::raster::RgbaImage::from_pixel(4, 4, lodbench::raster::Rgba([v, v, v, 255]))
    };
    picture(10).save(dir.join("frame/00000.png")).unwrap();
    picture(20).save(dir.join("frame/00001.png")).unwrap();
    picture(10)
        .save(dir.join("counterfactual/00001.png"))
        .unwrap();
}

/// (b) Each breach of the protocol: one error line naming the file and the problem, a non-zero exit, and no
/// frames.csv left behind.
#[test]
fn bad_score_folders_are_refused_each_with_its_reason() {
    let root = tempfile::tempdir().unwrap();
    let ok = root.path().join("ok");
    small_folder(&ok);
    let out = lodbench(&["score", ok.to_str().unwrap()], &[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows = read_csv(&ok.join("frames.csv"));
    // Frame 1 differs from its counterfactual by 10/255 on every channel of every pixel.
    assert_eq!(rows[1]["lodpop"].parse::<f64>().unwrap(), 10.0 / 255.0);
    assert_eq!(rows[1]["rmse"], "", "no reference: no rmse");
    type Breach = (&'static str, fn(&Path), &'static [&'static str]);
    let breaches: [Breach; 7] = [
        (
            "no counterfactual",
            |d| std::fs::remove_file(d.join("counterfactual/00001.png")).unwrap(),
            &["counterfactual", "00001.png", "changed on frame 1"],
        ),
        (
            "sizes differ",
            |d| {
                lodbench::raster::RgbaImage::new(5, 4)
                    .save(d.join("frame/00001.png"))
                    .unwrap();
            },
            &["00001.png", "is 5x4", "4x4"],
        ),
        (
            "a frame named that is not there",
            |d| {
                std::fs::write(
                    d.join("lods.csv"),
                    "frame,object,lod\n0,a,0\n1,a,1\n2,a,1\n",
                )
                .unwrap()
            },
            &["lods.csv", "names frame 2", "frame/00002.png"],
        ),
        (
            "a picture of a frame not named",
            |d| {
                std::fs::copy(d.join("frame/00000.png"), d.join("frame/00007.png"))
                    .map(|_| ())
                    .unwrap()
            },
            &["00007.png", "lods.csv names frames 0..2"],
        ),
        (
            "no manifest",
            |d| std::fs::remove_file(d.join("score.json")).unwrap(),
            &["score.json", "cannot be read"],
        ),
        (
            "a typo in a column",
            |d| {
                std::fs::write(
                    d.join("lods.csv"),
                    "frame,object,lod,kk\n0,a,0,1\n1,a,1,1\n",
                )
                .unwrap()
            },
            &["lods.csv", "unknown column \"kk\""],
        ),
        (
            "a reference of some frames",
            |d| {
                std::fs::create_dir_all(d.join("reference")).unwrap();
                std::fs::copy(d.join("frame/00000.png"), d.join("reference/00000.png")).unwrap();
            },
            &["reference", "not 00001.png"],
        ),
    ];
    for (what, breach, needles) in breaches {
        let d = root.path().join(what.replace(' ', "-"));
        small_folder(&d);
        breach(&d);
        let out = lodbench(&["score", d.to_str().unwrap()], &[]);
        fails_with(&out, needles);
        assert!(!d.join("frames.csv").exists(), "{what}: frames.csv written");
    }
}
