//! `--quality off` on the software adapter: the timing rounds run as usual and the quality pass not at all, so
//! every image figure of frames.csv, summary.csv and transitions.csv is empty (never 0), the timing columns are
//! filled, and run.json's quality-pass times are null.

use crate::common::{read_csv, run_into, Rows};

/// Every column of `rows` named in `columns` is empty on every row, and there are rows.
fn all_empty(rows: &Rows, columns: &[&str], file: &str) {
    assert!(!rows.is_empty(), "{file}: no rows");
    for c in columns {
        let filled: Vec<&String> = rows
            .iter()
            .map(|r| &r[*c])
            .filter(|v| !v.is_empty())
            .collect();
        assert!(filled.is_empty(), "{file} {c}: {filled:?}, expected empty");
    }
}

/// Every column named is filled on every row.
fn all_filled(rows: &Rows, columns: &[&str], file: &str) {
    for c in columns {
        assert!(
            rows.iter().all(|r| !r[*c].is_empty()),
            "{file} {c}: an empty cell"
        );
    }
}

#[rustfmt::skip]
#[test]
fn quality_off_leaves_the_image_figures_empty_and_times() {
    let dir = tempfile::tempdir().unwrap();
    // FSI for lag_rmse and combine_gpu_ms, --shadows on for the shadow columns: all filled by the quality pass.
    let out = run_into(
        dir.path(),
        &[
            "--scene", "bunny-sweep", "--method", "discrete,fsi", "--frames", "24", "--width", "64",
            "--height", "48", "--rounds", "4", "--shadows", "on", "--quality", "off",
        ],
    );
    let frames = read_csv(&out.join("frames.csv"));
    assert_eq!(frames.len(), 2 * 24);
    all_empty(
        &frames,
        &[
            "rmse", "pop", "lodpop", "de2000_mean", "uncovered_px", "crack_px", "flip_mean", "combine_gpu_ms",
            "lag_rmse", "shadow_rmse", "shadow_lodpop",
        ],
        "frames.csv",
    );
    all_filled(&frames, &["cpu_ms", "triangles", "draw_calls", "t_instances", "lod_mean", "round"], "frames.csv");
    assert!(frames.iter().any(|r| r["t_instances"] != "0"), "the path has transitions");

    let summary = read_csv(&out.join("summary.csv"));
    assert_eq!(summary.len(), 2);
    all_empty(
        &summary,
        &[
            "rmse_mean", "rmse_mean_ci95_lo", "rmse_mean_ci95_hi", "rmse_max", "pop_max", "pop_p95", "lodpop_max",
            "lodpop_p95", "lodpop_sum", "de2000_mean", "de2000_max", "flip_mean", "uncovered_px_mean",
            "crack_px_mean", "crack_px_max", "combine_gpu_ms_median", "lag_rmse_mean", "lag_rmse_max",
            "shadow_rmse_mean", "shadow_lodpop_max",
        ],
        "summary.csv",
    );
    all_filled(&summary, &["cpu_ms_median", "triangles_mean", "ratio_to_baseline", "rounds"], "summary.csv");

    let transitions = read_csv(&out.join("transitions.csv"));
    all_empty(
        &transitions,
        &["lodpop_max", "lodpop_max_frame", "pop_max", "pop_max_frame", "rmse_max", "shadow_lodpop_max"],
        "transitions.csv",
    );
    all_filled(&transitions, &["first_frame", "last_frame", "lods"], "transitions.csv");
    all_filled(&read_csv(&out.join("rounds.csv")), &["median_ms", "ratio_to_baseline"], "rounds.csv");
    // The pairs need only the timing rounds: written as with the pass.
    let pairs = read_csv(&out.join("pairs.csv"));
    assert_eq!(pairs.len(), 1);
    all_filled(&pairs, &["method_a", "method_b", "clock", "ratio", "ratio_ci95_lo", "different"], "pairs.csv");

    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    assert_eq!(run["config"]["quality"], "off");
    for b in run["blocks"].as_array().unwrap() {
        for k in ["quality_pass_ms_per_frame", "quality_to_timing_ratio", "quality_to_renders_ratio",
                  "quality_to_renders_ratio_ci95_lo", "quality_to_renders_ratio_ci95_hi",
                  "quality_to_renders_by_round", "metric_gpu_ms_median"] {
            assert!(b[k].is_null(), "run.json {k}: {}", b[k]);
        }
        assert!(b["timing_pass_ms_per_frame"].as_f64().unwrap() > 0.0);
    }
    // Nothing needs the reference's time without the quality pass: it is not timed.
    assert_eq!(run["timing_rounds"][0]["timed_only"], serde_json::json!([]));
}
