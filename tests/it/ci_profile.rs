//! The full `ci` profile over every scene and method (about 25 minutes on a 2-core machine without a GPU), every
//! summary row's rmse and pop against `results/baseline/summary.csv`. Ignored by `cargo test`: the test suite's
//! regression is the `regress` module (the regression set); this one is for a change that needs the ci profile's
//! long sweep, run with `cargo test --release --test it ci_profile:: -- --ignored`, and re-blessed with
//! `LODBENCH_BLESS=1 cargo test --release --test it ci_profile:: -- --ignored`.

use crate::common::{read_csv, Row};

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// Columns under regression, and their tolerance: |current - baseline| <= ABS + REL * |baseline|. On the same
/// adapter the numbers are bit-identical; the tolerance leaves room for another Mesa or LLVM version's
/// rasterisation while a change of shading, geometry, schedule or metric moves them by far more.
const COLUMNS: [&str; 4] = ["rmse_mean", "rmse_max", "pop_max", "pop_p95"];
const REL: f64 = 0.01;
const ABS: f64 = 2e-6;

/// The run's output folder, made once per test binary.
fn ci_run() -> &'static PathBuf {
    static OUT: OnceLock<PathBuf> = OnceLock::new();
    OUT.get_or_init(|| {
        let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("ci-profile");
        crate::common::run_into(&out, &["--profile", "ci"])
    })
}

fn key(r: &Row) -> (String, String, String) {
    (r["scene"].clone(), r["method"].clone(), r["count"].clone())
}

fn num(r: &Row, c: &str) -> f64 {
    r[c].parse().unwrap_or_else(|_| panic!("{c}={}", r[c]))
}

#[test]
#[ignore = "the full ci profile, about 25 minutes on lavapipe: cargo test --release --test it ci_profile:: -- --ignored"]
fn rmse_and_pop_match_the_baseline() {
    let current = read_csv(&ci_run().join("summary.csv"));
    let baseline_path = Path::new(env!("CARGO_MANIFEST_DIR")).join("results/baseline/summary.csv");
    if std::env::var_os("LODBENCH_BLESS").is_some() {
        let mut w = csv::Writer::from_path(&baseline_path).unwrap();
        let mut header = vec!["scene", "method", "count", "frames"];
        header.extend(COLUMNS);
        w.write_record(&header).unwrap();
        for r in &current {
            w.write_record(header.iter().map(|h| r[*h].as_str()))
                .unwrap();
        }
        w.flush().unwrap();
        eprintln!("blessed {}", baseline_path.display());
        return;
    }
    let baseline = read_csv(&baseline_path);
    let by_key: HashMap<_, _> = current.iter().map(|r| (key(r), r)).collect();
    let mut problems = Vec::new();
    for b in &baseline {
        let Some(c) = by_key.get(&key(b)) else {
            problems.push(format!("{:?}: in the baseline, not in this run", key(b)));
            continue;
        };
        if b["frames"] != c["frames"] {
            problems.push(format!(
                "{:?}: frames {} -> {}",
                key(b),
                b["frames"],
                c["frames"]
            ));
        }
        for col in COLUMNS {
            let (was, now) = (num(b, col), num(c, col));
            if (now - was).abs() > ABS + REL * was.abs() {
                problems.push(format!("{:?}: {col} {was} -> {now}", key(b)));
            }
        }
    }
    let known: Vec<_> = baseline.iter().map(key).collect();
    for c in &current {
        if !known.contains(&key(c)) {
            problems.push(format!(
                "{:?}: new row, not in the baseline (re-bless)",
                key(c)
            ));
        }
    }
    assert!(
        problems.is_empty(),
        "rows moved against results/baseline/summary.csv (tolerance {ABS} + {REL} x baseline; re-bless with \
         LODBENCH_BLESS=1 cargo test --release --test it ci_profile:: -- --ignored):\n{}",
        problems.join("\n")
    );
}
