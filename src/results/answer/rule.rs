//! The answer's rule: per block of summary.csv, which method pops least and which is the cheapest within a
//! popping budget, in sentences whose every number is a cell of summary.csv or pairs.csv (or run.json's budget).
//!
//! - The candidates are the methods that show LOD transitions: every method but the references (`reference`,
//!   `reference-flat`, ...), with a largest lodpop (none under `--quality off`).
//! - The hard switch is `discrete` where it ran, else the baseline.
//! - Where a transition of the block spans fewer than [`MIN_TRANSITION_FRAMES`] frames (summary.csv's
//!   `transition_frames_min`), no blending method can have acted on it: one sentence says so and names no
//!   method (a run of the hard switch alone is answered as usual).
//! - The budget is `--budget-lodpop` where given (`lodbench tune`'s budget, say), else half the hard switch's
//!   largest lodpop: a smooth method is there to take the hard switch's pop away, and one that does not halve it
//!   has not done so; a fixed default would mean something else at every resolution (lodpop is an RMS over the
//!   frame).
//! - Costs are the all-frames paired ratios (summary.csv's `ratio_to_baseline`, pairs.csv's `ratio`) and a cost is
//!   called different only where its 95 % interval excludes 1 (the paired rule of `measure::records::Ratio`).

use super::parts::{budget_value, pair_value, summary_value, Fmt, Op, Part, Value};
use crate::methods::base_name;
use crate::numbers::sig3;
use crate::results::csv::CsvRow;

/// The fewest frames a transition must span for a blending method to act on it: over one frame a blend shows
/// one of its two LODs whole, as the hard switch does.
pub const MIN_TRANSITION_FRAMES: u32 = 2;

/// A sentence: its parts.
pub type Sentence = Vec<Part>;

/// The budget a block's answer is stated within: `lodpop` and where it comes from (`--budget-lodpop`, or
/// `half of discrete's`).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Budget {
    pub lodpop: f64,
    pub source: String,
}

/// A block's sentences, with the hard switch and the budget they were stated against.
#[derive(Debug, Clone, PartialEq)]
pub struct Said {
    pub sentences: Vec<Sentence>,
    pub hard_switch: Option<String>,
    pub budget: Option<Budget>,
}

/// What the rule reads of one block: its summary rows, the run's pairs, the swept variables and the run's
/// `--budget-lodpop`.
pub struct BlockInput<'a> {
    pub name: &'a str,
    pub rows: &'a [&'a CsvRow],
    pub pairs: &'a [CsvRow],
    pub variables: &'a [String],
    pub budget: Option<Given>,
}

/// Whether a method shows LOD transitions (not a reference of any kind).
pub fn is_candidate(method: &str) -> bool {
    !base_name(method).starts_with("reference")
}

/// A row's time over the baseline's, all frames; infinite where unmeasured, so it sorts last.
fn cost(r: &CsvRow) -> f64 {
    r.num("ratio_to_baseline").unwrap_or(f64::INFINITY)
}

fn lodpop(r: &CsvRow) -> f64 {
    r.num("lodpop_max").unwrap_or(f64::INFINITY)
}

/// The hard switch among `rows`: discrete where it ran, else the baseline.
fn hard_switch<'a>(rows: &[&'a CsvRow], baseline: &str) -> Option<&'a CsvRow> {
    rows.iter()
        .find(|r| r.text("method") == "discrete")
        .or_else(|| rows.iter().find(|r| r.text("method") == baseline))
        .copied()
}

/// The answer for one block: which method pops least, and the cheapest within the lodpop budget.
pub fn sentences(b: &BlockInput<'_>) -> Said {
    let alone = |s: String| Said {
        sentences: vec![vec![Part::Text(s)]],
        hard_switch: None,
        budget: None,
    };
    let name = b.name;
    let Some(baseline) = b
        .rows
        .iter()
        .map(|r| r.text("baseline"))
        .find(|s| !s.is_empty())
    else {
        return alone(format!(
            "{name}: no baseline ran, so no paired costs (--baseline names one)."
        ));
    };
    let candidates: Vec<&CsvRow> = b
        .rows
        .iter()
        .copied()
        .filter(|r| is_candidate(r.text("method")) && r.num("lodpop_max").is_some())
        .collect();
    if candidates.is_empty() {
        return alone(format!(
            "{name}: no popping measured (--quality off, or no method with LOD transitions ran)."
        ));
    }
    let hard = hard_switch(&candidates, baseline);
    if let Some(sentence) = no_room(name, b.rows, &candidates, hard) {
        return alone(sentence);
    }
    // Least lodpop as the sentence shows it (3 figures), the cheaper of a tie.
    let shown = |r: &CsvRow| {
        sig3(r.num("lodpop_max"))
            .parse::<f64>()
            .unwrap_or(f64::INFINITY)
    };
    let Some(least) = candidates.iter().copied().min_by(|a, c| {
        shown(a)
            .total_cmp(&shown(c))
            .then(cost(a).total_cmp(&cost(c)))
            .then(lodpop(a).total_cmp(&lodpop(c)))
    }) else {
        return alone(String::new());
    };
    let lodpop_of = |r: &CsvRow, op: Op| summary_value(r, b.variables, "lodpop_max", Fmt::Sig3, op);
    let mut first: Sentence = vec![];
    let budget = budget_of(b.budget.as_ref(), hard, b.variables);
    if candidates.len() == 1 {
        // Nothing to compare its popping with: say what it is, and a budget's verdict only where one was given.
        first.push(
            format!(
                "{name}: {} is the only method with LOD transitions in the run, a largest lodpop of ",
                least.text("method")
            )
            .into(),
        );
        first.push(lodpop_of(least, Op::AsIs).into());
    } else {
        first.push(
            format!(
                "{name}: {} pops least, a largest lodpop of ",
                least.text("method")
            )
            .into(),
        );
        first.push(lodpop_of(least, Op::AsIs).into());
        let ties = ties_clause(&candidates, least);
        if !ties.is_empty() {
            first.push(ties.into());
        }
        if let Some(h) = hard.filter(|h| h.text("method") != least.text("method")) {
            first.push(format!(" against {}'s ", h.text("method")).into());
            first.push(lodpop_of(h, Op::AsIs).into());
        }
    }
    first.push("; ".into());
    first.extend(cost_clause(least, baseline, b.variables));
    first.push(".".into());
    let mut out = vec![first];
    if candidates.len() > 1 || b.budget.is_some() {
        if let Some(level) = &budget {
            out.push(within_budget(&candidates, least, level, baseline, b));
        }
    }
    Said {
        sentences: out,
        hard_switch: hard.map(|h| h.text("method").to_string()),
        budget: budget.map(|l| Budget {
            lodpop: l.lodpop,
            source: l.source,
        }),
    }
}

/// A block's budget: as the sentence shows it, its level and where it comes from.
struct Level {
    shown: Value,
    lodpop: f64,
    source: String,
}

/// A budget the run was given (run.json): its lodpop and where it comes from (`--budget-lodpop`, or a number of
/// JNDs of a calibration).
#[derive(Debug, Clone, PartialEq)]
pub struct Given {
    pub lodpop: f64,
    pub source: String,
}

/// The budget: the run's (run.json), else half the hard switch's largest lodpop.
fn budget_of(given: Option<&Given>, hard: Option<&CsvRow>, variables: &[String]) -> Option<Level> {
    match (given, hard) {
        (Some(g), _) => Some(Level {
            shown: budget_value(g.lodpop),
            lodpop: g.lodpop,
            source: g.source.clone(),
        }),
        (None, Some(h)) => Some(Level {
            lodpop: h.num("lodpop_max")? / 2.0,
            shown: summary_value(h, variables, "lodpop_max", Fmt::Sig3, Op::Half),
            source: format!("half of {}'s", h.text("method")),
        }),
        (None, None) => None,
    }
}

/// Where some transition of the block spans fewer than [`MIN_TRANSITION_FRAMES`] frames (summary.csv's
/// `transition_frames_min`) and a method other than the hard switch ran: the one sentence that says so, in
/// place of a winner the run could not have found.
fn no_room(
    name: &str,
    rows: &[&CsvRow],
    candidates: &[&CsvRow],
    hard: Option<&CsvRow>,
) -> Option<String> {
    let n = rows
        .iter()
        .find_map(|r| r.num("transition_frames_min"))
        .filter(|&n| n < MIN_TRANSITION_FRAMES as f64)?;
    let smooth = candidates
        .iter()
        .any(|r| hard.is_none_or(|h| h.text("method") != r.text("method")));
    smooth.then(|| {
        format!(
            "{name}: a transition here lasts {} frame (the camera crosses a switch's band within it), too few \
             for a blending method to act, so this run cannot say which method pops least; give the transitions \
             room with --fade time --fade-frames 8, or a slower path.",
            n as i64
        )
    })
}

/// The other `candidates` whose largest lodpop reads as `least`'s to 3 figures (they pop as little as far as
/// the sentence can say): " (a and b too, to 3 figures)", or nothing.
fn ties_clause(candidates: &[&CsvRow], least: &CsvRow) -> String {
    let shown = |r: &CsvRow| sig3(r.num("lodpop_max"));
    let ties: Vec<&str> = candidates
        .iter()
        .filter(|r| r.text("method") != least.text("method") && shown(r) == shown(least))
        .map(|r| r.text("method"))
        .collect();
    if ties.is_empty() {
        String::new()
    } else {
        format!(" ({} too, to 3 figures)", and_list(&ties))
    }
}

/// The cheapest of the `candidates` within the budget `level` and how it compares with the
/// next, or that none is within it and `least` comes nearest.
fn within_budget(
    candidates: &[&CsvRow],
    least: &CsvRow,
    level: &Level,
    baseline: &str,
    input: &BlockInput<'_>,
) -> Sentence {
    let (b, source) = (level.shown.clone(), &level.source);
    let mut within: Vec<&CsvRow> = candidates
        .iter()
        .copied()
        .filter(|r| lodpop(r) <= level.lodpop && r.num("ratio_to_baseline").is_some())
        .collect();
    within.sort_by(|a, c| cost(a).total_cmp(&cost(c)));
    let Some(best) = within.first() else {
        return vec![
            "No method keeps its largest lodpop within ".into(),
            b.into(),
            format!(" ({source}); {} comes nearest.", least.text("method")).into(),
        ];
    };
    let mut s: Sentence = vec![
        "Within a largest lodpop of ".into(),
        b.into(),
        format!(" ({source}), {} is the cheapest: ", best.text("method")).into(),
    ];
    s.extend(cost_clause(best, baseline, input.variables));
    s.push(".".into());
    match within.get(1) {
        None => s.push(" No other method is within it.".into()),
        Some(next) => s.extend(versus(best, next, input.pairs, input.variables)),
    }
    s
}

/// `a`, `a and b`, `a, b and c`.
fn and_list(names: &[&str]) -> String {
    match names {
        [] => String::new(),
        [one] => one.to_string(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}

/// What a method costs against the baseline, as a clause: a difference only where the interval excludes 1.
fn cost_clause(r: &CsvRow, baseline: &str, variables: &[String]) -> Vec<Part> {
    if r.text("method") == baseline {
        return vec![format!("it is the baseline ({baseline})").into()];
    }
    let v = || summary_value(r, variables, "ratio_to_baseline", Fmt::Ratio, Op::AsIs).into();
    let (x, lo, hi) = (
        r.num("ratio_to_baseline"),
        r.num("ratio_to_baseline_ci95_lo"),
        r.num("ratio_to_baseline_ci95_hi"),
    );
    match (x, lo, hi) {
        (None, _, _) => vec!["its cost was not measured".into()],
        (Some(_), Some(l), Some(h)) if l > 1.0 || h < 1.0 => vec![
            "it takes ".into(),
            v(),
            format!(" times {baseline}'s frame time").into(),
        ],
        (Some(_), Some(_), Some(_)) => vec![
            format!("its frame time is not measurably different from {baseline}'s (").into(),
            v(),
            " times)".into(),
        ],
        (Some(_), _, _) => vec![
            "it takes ".into(),
            v(),
            format!(" times {baseline}'s frame time (too few rounds for an interval)").into(),
        ],
    }
}

/// The cheapest against the next within the budget, paired directly (pairs.csv), in hyperfine's words where
/// they differ.
fn versus(best: &CsvRow, next: &CsvRow, pairs: &[CsvRow], variables: &[String]) -> Vec<Part> {
    let (bm, nm) = (best.text("method"), next.text("method"));
    let same_block = |p: &CsvRow| {
        p.text("scene") == best.text("scene")
            && p.text("count") == best.text("count")
            && variables.iter().all(|v| p.text(v) == best.text(v))
    };
    // (best's time over next's, its interval) and whether the row is written the other way round.
    let found = pairs.iter().filter(|p| same_block(p)).find_map(|p| {
        p.num("ratio")?;
        let (lo, hi) = (p.num("ratio_ci95_lo")?, p.num("ratio_ci95_hi")?);
        match (p.text("method_a"), p.text("method_b")) {
            (a, b) if a == bm && b == nm => Some((p, hi, lo, Op::AsIs)),
            (a, b) if a == nm && b == bm => Some((p, 1.0 / lo, 1.0 / hi, Op::Inv)),
            _ => None,
        }
    });
    let Some((p, hi, lo, op)) = found else {
        return vec![format!(" {nm} is the next within it (no paired ratio of the two).").into()];
    };
    if hi < 1.0 {
        // best ran faster: the ratio shown the other way round.
        let flipped = if op == Op::Inv { Op::AsIs } else { Op::Inv };
        return vec![
            format!(" {bm} ran ").into(),
            pair_value(p, variables, flipped).into(),
            format!(" times faster than {nm}, the next within it.").into(),
        ];
    }
    let v = pair_value(p, variables, op);
    if lo > 1.0 {
        return vec![
            format!(" Paired directly, {nm} ran ").into(),
            v.into(),
            format!(" times faster than {bm}.").into(),
        ];
    }
    vec![
        format!(" It is not measurably different from {nm}, the next within it (").into(),
        v.into(),
        " times its frame time).".into(),
    ]
}
