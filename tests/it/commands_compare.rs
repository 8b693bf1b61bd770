//! `lodbench compare DIR A B` through the binary, on a tiny run on the software adapter: what it prints is
//! pairs.csv's row and summary.csv's `ratio_to_baseline`, and bad input is one `error:` line.

use crate::common::{fails_with, lodbench, read_csv, run_into, Row};
use std::path::Path;
use std::process::Output;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn stdout(out: &Output) -> String {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).to_string()
}

/// The ratio and interval compare prints on the line starting with `what` (`all frames`, `transition`,
/// `steady`): None where it prints `-` for the ratio, the bounds None where it prints `-` for them.
fn printed(text: &str, what: &str) -> Option<(f64, Option<(f64, f64)>)> {
    let line = text
        .lines()
        .find(|l| l.trim_start().starts_with(what))
        .unwrap_or_else(|| panic!("no {what} line in: {text}"));
    let rest = line.trim_start()[what.len()..].trim_start();
    let mut parts = rest.split_whitespace();
    let ratio = parts.next().unwrap();
    if ratio == "-" {
        return None;
    }
    let ratio: f64 = ratio.parse().unwrap();
    let interval = parts.next().unwrap();
    let ci = if interval == "-" {
        None
    } else {
        let second = parts.next().unwrap();
        let lo: f64 = interval
            .trim_matches(|c| c == '[' || c == ',')
            .parse()
            .unwrap();
        let hi: f64 = second.trim_end_matches(']').parse().unwrap();
        Some((lo, hi))
    };
    Some((ratio, ci))
}

/// `value` as printed with 6 decimals equals the CSV cell `cell` (both absent: an empty cell).
fn same(value: Option<f64>, cell: &str, what: &str) {
    let Some(value) = value else {
        assert_eq!(cell, "", "{what}: printed none, CSV {cell:?}");
        return;
    };
    let expected: f64 = cell.parse().unwrap_or_else(|_| panic!("{what}: {cell:?}"));
    assert!(
        (value - expected).abs() <= 5.1e-7,
        "{what}: printed {value}, CSV {expected}"
    );
}

/// The printed ratio of `what` with its interval equals the row's columns `prefix`, `prefix_ci95_lo/hi`.
fn same_ratio(text: &str, what: &str, row: &Row, prefix: &str) {
    let p = printed(text, what);
    same(p.map(|p| p.0), &row[prefix], prefix);
    let ci = p.and_then(|p| p.1);
    same(ci.map(|c| c.0), &row[&format!("{prefix}_ci95_lo")], prefix);
    same(ci.map(|c| c.1), &row[&format!("{prefix}_ci95_hi")], prefix);
}

#[test]
fn compare_prints_the_paired_ratios_of_pairs_csv_and_summary_csv() {
    let dir = tempfile::tempdir().unwrap();
    #[rustfmt::skip]
    let out = run_into(
        &dir.path().join("run"),
        &[
            "--scene", "bunny-sweep", "--profile", "quick", "--frames", "40", "--rounds", "4",
            "--method", "discrete,alpha,dither",
        ],
    );
    let pairs = read_csv(&out.join("pairs.csv"));
    let listed: Vec<(&str, &str)> = pairs
        .iter()
        .map(|r| (r["method_a"].as_str(), r["method_b"].as_str()))
        .collect();
    assert_eq!(
        listed,
        [
            ("discrete", "alpha"),
            ("discrete", "dither"),
            ("alpha", "dither")
        ]
    );
    let summary = read_csv(&out.join("summary.csv"));
    let clock = &summary[0]["clock"];
    assert!(clock == "gpu_ms" || clock == "cpu_ms", "{clock}");
    assert!(summary.iter().all(|r| &r["clock"] == clock));
    assert!(pairs
        .iter()
        .all(|r| &r["clock"] == clock && r["rounds"] == "4"));
    assert!(read_csv(&out.join("rounds.csv"))
        .iter()
        .all(|r| &r["time"] == clock));

    // discrete over alpha: pairs.csv's first row, for all frames, those in transition and the steady ones.
    let text = stdout(&lodbench(&["compare", s(&out), "discrete", "alpha"], &[]));
    assert!(
        text.starts_with(&format!(
            "bunny-sweep, count 1: discrete over alpha ({clock}, 4 rounds)"
        )),
        "{text}"
    );
    assert!(
        printed(&text, "all frames").and_then(|p| p.1).is_some(),
        "{text}"
    );
    same_ratio(&text, "all frames", &pairs[0], "ratio");
    same_ratio(&text, "transition", &pairs[0], "ratio_transition");
    same_ratio(&text, "steady", &pairs[0], "ratio_steady");
    let verdict = if pairs[0]["different"] == "true" {
        "different: discrete costs"
    } else {
        "not different"
    };
    let all = text.lines().find(|l| l.contains("all frames")).unwrap();
    assert!(all.contains(verdict), "{all} / {:?}", pairs[0]);

    // alpha over discrete: summary.csv's ratio_to_baseline for alpha (discrete is the default baseline).
    let alpha = summary.iter().find(|r| r["method"] == "alpha").unwrap();
    assert_eq!(alpha["baseline"], "discrete");
    let text = stdout(&lodbench(
        &[
            "compare",
            s(&out),
            "alpha",
            "discrete",
            "--scene",
            "bunny-sweep",
            "--count",
            "1",
        ],
        &[],
    ));
    same_ratio(&text, "all frames", alpha, "ratio_to_baseline");
    same_ratio(&text, "transition", alpha, "ratio_to_baseline_transition");
    same_ratio(&text, "steady", alpha, "ratio_to_baseline_steady");

    // Bad input: one error line each.
    fails_with(
        &lodbench(&["compare", s(&out), "alpha", "fsi"], &[]),
        &["has no method 'fsi'", "discrete, alpha, dither"],
    );
    fails_with(
        &lodbench(
            &["compare", s(&dir.path().join("nowhere")), "alpha", "dither"],
            &[],
        ),
        &["nowhere", "does not exist"],
    );
    fails_with(
        &lodbench(
            &["compare", s(&out), "alpha", "dither", "--count", "7"],
            &[],
        ),
        &["no block of count 7 with both alpha and dither"],
    );
    // A run without timing rounds: frames.csv without its round column (as before lodbench timed in rounds).
    let old = dir.path().join("old");
    std::fs::create_dir_all(&old).unwrap();
    let mut r = csv::Reader::from_path(out.join("frames.csv")).unwrap();
    let header = r.headers().unwrap().clone();
    let keep: Vec<usize> = (0..header.len())
        .filter(|&i| &header[i] != "round")
        .collect();
    let mut w = csv::Writer::from_path(old.join("frames.csv")).unwrap();
    w.write_record(keep.iter().map(|&i| &header[i])).unwrap();
    for rec in r.records() {
        let rec = rec.unwrap();
        w.write_record(keep.iter().map(|&i| &rec[i])).unwrap();
    }
    w.flush().unwrap();
    fails_with(
        &lodbench(&["compare", s(&old), "alpha", "discrete"], &[]),
        &["no timing rounds"],
    );
}
