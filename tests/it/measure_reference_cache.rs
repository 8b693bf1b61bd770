//! The reference cache (src/measure/reference_cache.rs): a block's second and later methods copy the reference
//! frame kept by the first method's pass, and the reference's own pass copies its frame, instead of drawing
//! the reference again. Every figure must be the one of a run that draws it every time (`--reference-cache-mib
//! 0`), with the whole path kept, and with a budget that keeps only its first frames.

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
    assert_eq!(none, want(0, 0, 30));
    assert_eq!(all, want(0, 30, 30));
    assert_eq!(some, want(0, 21, 30));
}
