//! The decision table beside the answer's sentences: a row per method of a block, each cell a summary.csv cell
//! as shown, with the parts of its largest pop (transitions.csv) and its lowest JOD (perceptual.csv, where
//! `lodbench perceptual` ran).

use super::parts::{summary_value, Fmt, Op, Part};
use crate::numbers::sig3;
use crate::results::csv::CsvRow;

/// The table's header.
pub const DECISION_COLUMNS: [&str; 10] = [
    "method",
    "frame time, ms",
    "time / baseline [95 %]",
    "on transition frames",
    "triangles",
    "largest lodpop",
    "its coverage part",
    "its shading part",
    "lowest JOD",
    "mean rmse",
];

/// Whether `r` is of the block (`values` of the swept `variables`, `scene`, `count`) and method `method`.
fn of(r: &CsvRow, block: &CsvRow, variables: &[String], method: &str) -> bool {
    r.text("scene") == block.text("scene")
        && r.text("count") == block.text("count")
        && r.text("method") == method
        && variables.iter().all(|v| r.text(v) == block.text(v))
}

/// (coverage, shading) of `method`'s transition of largest lodpop in `transitions` (the first of equals).
fn largest_parts(
    transitions: &[CsvRow],
    block: &CsvRow,
    method: &str,
    variables: &[String],
) -> (Option<f64>, Option<f64>) {
    let mut best: Option<&CsvRow> = None;
    for r in transitions
        .iter()
        .filter(|r| of(r, block, variables, method))
    {
        let nan = |x: &CsvRow| x.num("lodpop_max").unwrap_or(f64::NAN);
        if best.is_none_or(|b| nan(r) > nan(b)) {
            best = Some(r);
        }
    }
    best.map_or((None, None), |b| {
        (b.num("lodpop_coverage"), b.num("lodpop_shading"))
    })
}

/// The lowest `jod_popping` of `method`'s transitions in the run's perceptual.csv rows; None without one.
fn lowest_jod(perceptual: &[CsvRow], r: &CsvRow) -> Option<f64> {
    let mut low: Option<f64> = None;
    for p in perceptual
        .iter()
        .filter(|p| of(p, r, &[], r.text("method")))
    {
        let cur = low.unwrap_or(f64::INFINITY);
        // As min(cur, x): a missing figure leaves it where it was.
        low = Some(match p.num("jod_popping") {
            Some(x) if x < cur => x,
            _ => cur,
        });
    }
    low.filter(|x| x.is_finite())
}

/// The decision table of one block: a row per summary row.
pub fn decision_rows(
    rows: &[&CsvRow],
    transitions: &[CsvRow],
    perceptual: &[CsvRow],
    variables: &[String],
) -> Vec<Vec<Part>> {
    let value = |r: &CsvRow, col: &str, fmt: Fmt| -> Part {
        summary_value(r, variables, col, fmt, Op::AsIs).into()
    };
    rows.iter()
        .map(|&r| {
            let (cov, shade) = largest_parts(transitions, r, r.text("method"), variables);
            let ms = if r.text("gpu_ms_median").is_empty() {
                "cpu_ms_median"
            } else {
                "gpu_ms_median"
            };
            vec![
                r.text("method").into(),
                value(r, ms, Fmt::Sig3),
                value(r, "ratio_to_baseline", Fmt::Ratio),
                value(r, "ratio_to_baseline_transition", Fmt::Ratio),
                value(r, "triangles_mean", Fmt::Thousands),
                value(r, "lodpop_max", Fmt::Sig3),
                sig3(cov).into(),
                sig3(shade).into(),
                sig3(lowest_jod(perceptual, r)).into(),
                value(r, "rmse_mean", Fmt::Sig3),
            ]
        })
        .collect()
}
