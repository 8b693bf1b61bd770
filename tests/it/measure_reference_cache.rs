//! The reference cache (src/measure/reference_cache.rs): in each round, the methods' quality segments after the
//! first copy the reference frame kept by the first, and the reference's own pass (first where it is listed)
//! copies its frame, instead of drawing the reference again. Every figure must be the one of a run that draws it
//! every time (`--reference-cache-mib 0`), with the whole round kept, with a budget that keeps only its first
//! frames, and over several rounds.

use crate::common::{read_csv, run_into};
use std::path::Path;

/// Every column of frames.csv but the timings (they differ run to run).
fn figures(dir: &Path) -> Vec<Vec<String>> {
    const TIMINGS: [&str; 4] = ["gpu_ms", "cpu_ms", "combine_gpu_ms", "round"];
    read_csv(&dir.join("frames.csv"))
        .iter()
        .map(|r| {
            let mut cells: Vec<String> = r
                .iter()
                .filter(|(k, _)| !TIMINGS.contains(&k.as_str()))
                .map(|(k, v)| format!("{k}={v}"))
                .collect();
            cells.sort();
            cells
        })
        .collect()
}

/// Per block of run.json: (method, reference_frames_copied).
fn copied(dir: &Path) -> Vec<(String, u64)> {
    let text = std::fs::read_to_string(dir.join("run.json")).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    json["blocks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| {
            (
                b["method"].as_str().unwrap().to_string(),
                b["reference_frames_copied"].as_u64().unwrap(),
            )
        })
        .collect()
}

/// simple (moving objects, so every frame's reference differs) at 128x96: a frame takes 512 x 96 bytes in the
/// cache, so 1 MiB keeps 21 of the 30 frames.
#[test]
fn copied_reference_frames_give_the_drawn_ones_figures() {
    let dir = tempfile::tempdir().unwrap();
    let run = |mib: &str| {
        let out = dir.path().join(format!("cache-{mib}"));
        #[rustfmt::skip]
        run_into(&out, &[
            "--scene", "simple", "--count", "16", "--method", "discrete,reference,alpha,geomorph", "--frames", "30",
            "--width", "128", "--height", "96", "--rounds", "1", "--warmup", "1", "--metrics", "rmse,pop,de2000",
            "--reference-cache-mib", mib,
        ]);
        (figures(&out), copied(&out))
    };
    let (drawn, none) = run("0");
    let (whole, all) = run("1024");
    let (part, some) = run("1");
    assert!(drawn.iter().any(|r| r
        .iter()
        .any(|c| c.starts_with("lodpop=") && c != "lodpop=0")));
    assert_eq!(
        whole, drawn,
        "the whole path kept: the figures of drawn references"
    );
    assert_eq!(
        part, drawn,
        "21 frames kept: the figures of drawn references"
    );
    // Without the cache only the reference's own pass copies (its frame is the reference frame).
    let want = |first: u64, later: u64, own: u64| {
        vec![
            ("discrete".to_string(), first),
            ("reference".to_string(), own),
            ("alpha".to_string(), later),
            ("geomorph".to_string(), later),
        ]
    };
    // The reference's own segment comes first in a round, so every method listed copies what it kept.
    assert_eq!(none, want(0, 0, 30));
    assert_eq!(all, want(30, 30, 30));
    assert_eq!(some, want(21, 21, 30));
}

/// Over 3 rounds without the reference listed: the cache holds one round's frames, kept by that round's first
/// segment (whichever method the round's shuffle put first) and copied by the two after it, so of each frame's
/// three passes one draws and two copy; the figures are those of drawn references.
#[test]
fn the_cache_holds_a_round_and_is_reused_by_the_next() {
    let dir = tempfile::tempdir().unwrap();
    let run = |mib: &str| {
        let out = dir.path().join(format!("rounds-{mib}"));
        #[rustfmt::skip]
        run_into(&out, &[
            "--scene", "simple", "--count", "16", "--method", "discrete,alpha,geomorph", "--frames", "30",
            "--width", "128", "--height", "96", "--rounds", "3", "--warmup", "1",
            "--reference-cache-mib", mib,
        ]);
        (figures(&out), copied(&out), out)
    };
    let (drawn, none, _) = run("0");
    // 1 MiB keeps 21 frames, more than a round's 10.
    let (kept, some, out) = run("1");
    assert_eq!(kept, drawn);
    assert!(none.iter().all(|(_, n)| *n == 0), "{none:?}");
    // The first reported method of each round's order (the reference is timed there, for q/r, and has no
    // quality segment) draws the round's 10 frames; the others copy them.
    let text = std::fs::read_to_string(out.join("run.json")).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    let firsts: Vec<&str> = json["timing_rounds"][0]["rounds"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            let order = r["order"].as_array().unwrap().iter();
            order
                .map(|m| m.as_str().unwrap())
                .find(|m| *m != "reference")
                .unwrap()
        })
        .collect();
    assert_eq!(firsts.len(), 3);
    for (method, n) in &some {
        let first_in = firsts.iter().filter(|f| **f == method.as_str()).count() as u64;
        assert_eq!(
            *n,
            10 * (3 - first_in),
            "{method}: {some:?}, firsts {firsts:?}"
        );
    }
}
