//! `lodbench calibrate` through the binary (a small ladder on the software adapter: the page beside its stimuli,
//! the switch interval differing from the still one exactly from the switch on, nearer switches popping more),
//! and `--calibration` in `run` and `tune`: pops in JNDs, visible pops over 1 JND, a calibration of another
//! display or a broken file refused in one line.

use crate::common::{fails_with, lodbench};
use lodbench::cli::calibration::Display;
use std::path::Path;

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// A calibration.json of lodpop with `threshold`, for a `w` x `h` display.
fn calibration(path: &Path, threshold: f64, (w, h): (u32, u32)) {
    let display = Display::new((w, h), 60.0, 24.0, 60.0, 200.0).unwrap();
    let file = serde_json::json!({
        "format": "lodbench-calibration", "version": 1, "simulated": true,
        "label": "SIMULATED observer (planted on lodpop): not human data",
        "display": display, "best_metric": "lodpop",
        "metrics": {"lodpop": {"threshold": threshold, "ci95": [threshold * 0.8, threshold * 1.25]}}
    });
    std::fs::write(path, file.to_string()).unwrap();
}

/// The ladder of two steps (1.5 and 4 times the one-pixel distance of LOD0 -> LOD1) for discrete and dither,
/// 9 frames an interval (150 ms at 60 Hz), a 3-frame fade, on a 160x120 display (so that the 96-pixel window holds
/// the bunny: at 4 times it fits, at 1.5 times it overflows the window, a close-up).
#[test]
fn calibrate_writes_the_page_beside_stimuli_whose_switch_shows_from_its_frame_on() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cal");
    #[rustfmt::skip]
    let r = lodbench(&[
        "calibrate", "--scene", "bunny-sweep", "--method", "discrete,dither", "--display-width", "160",
        "--display-height", "120", "--stimulus-size", "96", "--scales", "1.5,4", "--pairs", "1", "--interval-ms", "150", "--fade-ms", "50",
        "--out", out.to_str().unwrap(),
    ], &[]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let stderr = String::from_utf8_lossy(&r.stderr);
    assert!(
        !stderr.contains("note:"),
        "the stimulus runs' notes are not printed: {stderr}"
    );
    let s = json(&out.join("stimuli.json"));
    let page = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(!page.contains("__LODBENCH_STIMULI__"));
    assert!(
        page.contains(s["id"].as_str().unwrap()),
        "the page holds the stimuli"
    );
    assert_eq!(s["stimulus"]["frames_per_interval"], 9);
    let tracks = s["tracks"].as_array().unwrap();
    assert_eq!(tracks.len(), 2);
    let stimuli = s["stimuli"].as_array().unwrap();
    assert_eq!(stimuli.len(), 4);
    let by = |method: &str, scale: f64| {
        stimuli
            .iter()
            .find(|x| x["method"] == method && (x["scale"].as_f64().unwrap() - scale).abs() < 1e-6)
            .unwrap()
    };
    for x in stimuli {
        let (sw, st) = (
            x["switch_frames"].as_array().unwrap(),
            x["still_frames"].as_array().unwrap(),
        );
        assert_eq!((sw.len(), st.len()), (9, 9));
        for f in sw.iter().chain(st) {
            assert!(out.join(f.as_str().unwrap()).is_file(), "{f}");
        }
        // The two intervals share their frames up to the crossing (0.4 of the way: frame 3), and the switch's
        // frame differs (the dumped frames are named by their bytes: equal names, equal frames).
        assert_eq!(sw[..3], st[..3], "{}", x["id"]);
        let at = x["switch_frame"].as_u64().unwrap() as usize;
        assert_ne!(sw[at], st[at], "{}", x["id"]);
        let jod = x["jod_popping"].as_f64().unwrap();
        assert!(x["lodpop"].as_f64().unwrap() > 0.0 && x["flip"].as_f64().unwrap() > 0.0);
        assert!(jod > 0.0 && jod < 10.0, "{jod}");
    }
    // Nearer is a larger pop, by every figure.
    for m in ["discrete", "dither"] {
        let (near, far) = (by(m, 1.5), by(m, 4.0));
        for figure in ["lodpop", "flip"] {
            assert!(near[figure].as_f64() > far[figure].as_f64(), "{m} {figure}");
        }
        assert!(
            near["jod_popping"].as_f64() < far["jod_popping"].as_f64(),
            "{m}"
        );
        // The track climbs in lodpop: the staircase starts at its top.
        let t = tracks.iter().find(|t| t["method"] == m).unwrap();
        assert_eq!(t["stimuli"][1], near["id"]);
    }
}

#[test]
fn calibrate_refuses_a_bad_display_in_one_line_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cal");
    let o = out.to_str().unwrap();
    let r = lodbench(
        &[
            "calibrate",
            "--scene",
            "bunny-sweep",
            "--refresh-hz",
            "0",
            "--out",
            o,
        ],
        &[],
    );
    fails_with(&r, &["--refresh-hz 0"]);
    let r = lodbench(
        &[
            "calibrate",
            "--scene",
            "bunny-sweep",
            "--stimulus-size",
            "4000",
            "--out",
            o,
        ],
        &[],
    );
    fails_with(&r, &["--stimulus-size 4000", "1920x1080"]);
    let r = lodbench(&["calibrate", "--scene", "terrain", "--out", o], &[]);
    fails_with(&r, &["terrain", "unified"]);
    #[rustfmt::skip]
    let r = lodbench(&["calibrate", "--scene", "bunny-sweep", "--scales", "0.5,1,0.5", "--out", o], &[]);
    fails_with(&r, &["--scales: 0.5 is given twice"]);
    #[rustfmt::skip]
    let r = lodbench(&["calibrate", "--scene", "bunny-sweep", "--trials-per-track", "0", "--out", o], &[]);
    fails_with(&r, &["--trials-per-track 0"]);
    assert!(!out.join("index.html").exists() && !out.join("stimuli.json").exists());
    // A size that is not a number: clap's error, exit code 2, naming the flag.
    let r = lodbench(
        &[
            "calibrate",
            "--scene",
            "bunny-sweep",
            "--diagonal-in",
            "big",
            "--out",
            o,
        ],
        &[],
    );
    let stderr = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.starts_with("error:") && stderr.contains("--diagonal-in"),
        "{stderr}"
    );
}

#[test]
fn run_and_tune_refuse_a_calibration_of_another_display_or_a_broken_file() {
    let dir = tempfile::tempdir().unwrap();
    let cal = dir.path().join("calibration.json");
    calibration(&cal, 0.004, (1920, 1080));
    let c = cal.to_str().unwrap();
    let out = dir.path().join("out");
    let o = out.to_str().unwrap();
    let r = lodbench(
        &[
            "run",
            "--scene",
            "bunny-sweep",
            "--calibration",
            c,
            "--out",
            o,
        ],
        &[],
    );
    fails_with(&r, &["calibration", "1920x1080 display", "320x240"]);
    let r = lodbench(
        &[
            "tune",
            "--scene",
            "bunny-sweep",
            "--calibration",
            c,
            "--width",
            "320",
            "--out",
            o,
        ],
        &[],
    );
    fails_with(&r, &["1920x1080 display", "320x1080"]);
    std::fs::write(&cal, "").unwrap();
    let r = lodbench(
        &[
            "tune",
            "--scene",
            "bunny-sweep",
            "--calibration",
            c,
            "--out",
            o,
        ],
        &[],
    );
    fails_with(&r, &["calibration.json", "is not a calibration.json"]);
    let r = lodbench(
        &[
            "run",
            "--scene",
            "bunny-sweep",
            "--budget-jnd",
            "1",
            "--out",
            o,
        ],
        &[],
    );
    assert_eq!(r.status.code(), Some(2), "--budget-jnd needs --calibration");
    #[rustfmt::skip]
    let r = lodbench(&["run", "--scene", "bunny-sweep", "--calibration", c, "--budget-lodpop", "0.01", "--out", o], &[]);
    assert_eq!(
        r.status.code(),
        Some(2),
        "--calibration's budget is in JNDs, not --budget-lodpop"
    );
    assert!(!out.join("summary.csv").exists());
}

/// A run with a calibration of its display: lodpop_max_jnd is lodpop_max over the threshold, an event is visible
/// over 1 JND (visible_pop_threshold), and the answer's budget says where it comes from.
#[test]
fn a_calibrated_run_counts_pops_in_jnds() {
    let dir = tempfile::tempdir().unwrap();
    let cal = dir.path().join("calibration.json");
    let threshold = 0.002;
    calibration(&cal, threshold, (160, 120));
    let out = dir.path().join("run");
    #[rustfmt::skip]
    let r = lodbench(&[
        "run", "--scene", "bunny-sweep", "--method", "discrete,dither", "--width", "160", "--height", "120",
        "--frames", "60", "--rounds", "1", "--warmup", "0", "--fade", "time", "--fade-frames", "8", "--calibration", cal.to_str().unwrap(),
        "--budget-jnd", "2", "--out", out.to_str().unwrap(),
    ], &[]);
    let stdout = String::from_utf8_lossy(&r.stdout);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(
        stdout.contains("pops in JNDs") && stdout.contains("simulated"),
        "{stdout}"
    );
    let rows = crate::common::read_csv(&out.join("summary.csv"));
    for row in &rows {
        let num = |c: &str| row[c].parse::<f64>().unwrap();
        assert!((num("lodpop_max_jnd") - num("lodpop_max") / threshold).abs() < 1e-9);
        assert_eq!(
            num("visible_pop_threshold"),
            threshold,
            "1 JND, not the 2-JND budget"
        );
        // 60 frames at 60 fps: a minute is 60 paths; each event over 1 JND counts 60 a minute.
        assert!(num("pop_events") >= 1.0);
        if num("lodpop_max_jnd") > 1.0 {
            assert!(
                num("visible_pops_per_min") >= 60.0,
                "an event over 1 JND is visible"
            );
        }
    }
    let answer = json(&out.join("answer.json")).to_string();
    assert!(
        answer.contains("2.00 JND of a simulated observer"),
        "{answer}"
    );
    let run = json(&out.join("run.json"));
    assert_eq!(
        run["config"]["budget_lodpop"].as_f64(),
        Some(2.0 * threshold)
    );
    assert_eq!(
        run["config"]["calibration"]["threshold"].as_f64(),
        Some(threshold)
    );
}
