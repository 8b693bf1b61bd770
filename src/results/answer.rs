//! The answer a run leads with, and the numbers a person reads at a glance.
//!
//! Per scene and count of a run: which method pops least, and which is the cheapest within a popping budget, each
//! in one sentence whose numbers are summary.csv's and pairs.csv's (docs/measurement.md, "The answer first").
//! `lodbench run` prints them under its table; scripts/answer.py writes the same sentences, word for word, at the
//! top of report.html (scripts/tests/test_answer.py checks that the two agree).
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

use crate::measure::records::{PairRecord, SummaryRecord};
use crate::methods::base_name;

/// A figure to at least 3 significant figures, never in exponent form: `1.52`, `15.2`, `152`, `1523`, `0.00287`;
/// `-` where there is none. scripts/answer.py's `sig3` is the same rule.
pub fn sig3(x: Option<f64>) -> String {
    match x {
        Some(x) if x.is_finite() => {
            if x == 0.0 {
                return "0".into();
            }
            let decimals = (2 - x.abs().log10().floor() as i32).max(0) as usize;
            format!("{x:.decimals$}")
        }
        _ => "-".into(),
    }
}

/// A count with thousands separators, rounded: `3,674`; `-` where there is none.
pub fn thousands(x: Option<f64>) -> String {
    let Some(x) = x.filter(|x| x.is_finite()) else {
        return "-".into();
    };
    let digits = format!("{:.0}", x.abs());
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    if x.round() < 0.0 {
        out.insert(0, '-');
    }
    out
}

/// A ratio with its 95 % interval, 2 decimals: `1.23 [1.10, 1.37]`; the ratio alone without an interval.
pub fn ratio(r: Option<f64>, lo: Option<f64>, hi: Option<f64>) -> String {
    match (r, lo, hi) {
        (Some(r), Some(lo), Some(hi)) => format!("{r:.2} [{lo:.2}, {hi:.2}]"),
        (Some(r), _, _) => format!("{r:.2}"),
        _ => "-".into(),
    }
}

/// The sentences of one scene and count.
#[derive(Debug, Clone, PartialEq)]
pub struct Answer {
    pub scene: String,
    pub count: u32,
    pub sentences: Vec<String>,
}

/// The answers of a run's summary rows (in their order, one per scene and count) and its pairs; `budget` is
/// `--budget-lodpop`.
pub fn answers(
    summaries: &[SummaryRecord],
    pairs: &[PairRecord],
    budget: Option<f64>,
) -> Vec<Answer> {
    let mut blocks: Vec<(&str, u32)> = Vec::new();
    for r in summaries {
        if !blocks.contains(&(r.scene.as_str(), r.count)) {
            blocks.push((&r.scene, r.count));
        }
    }
    blocks
        .iter()
        .map(|&(scene, count)| {
            let rows: Vec<&SummaryRecord> = summaries
                .iter()
                .filter(|r| r.scene == scene && r.count == count)
                .collect();
            let counts = blocks.iter().filter(|b| b.0 == scene).count();
            let name = if counts > 1 {
                format!("{scene} (count {count})")
            } else {
                scene.to_string()
            };
            Answer {
                scene: scene.to_string(),
                count,
                sentences: block_sentences(&name, &rows, pairs, budget),
            }
        })
        .collect()
}

/// Whether a method shows LOD transitions (not a reference of any kind).
pub fn is_candidate(method: &str) -> bool {
    !base_name(method).starts_with("reference")
}

/// The answer for block `name`: which method pops least, and the cheapest within the lodpop budget (given,
/// or half the hard switch's largest lodpop).
fn block_sentences(
    name: &str,
    rows: &[&SummaryRecord],
    pairs: &[PairRecord],
    budget: Option<f64>,
) -> Vec<String> {
    let Some(baseline) = rows.iter().find_map(|r| r.baseline.clone()) else {
        return vec![format!(
            "{name}: no baseline ran, so no paired costs (--baseline names one)."
        )];
    };
    let candidates: Vec<&SummaryRecord> = rows
        .iter()
        .copied()
        .filter(|r| is_candidate(&r.method) && r.lodpop_max.is_some())
        .collect();
    if candidates.is_empty() {
        return vec![format!(
            "{name}: no popping measured (--quality off, or no method with LOD transitions ran)."
        )];
    }
    let hard = candidates
        .iter()
        .find(|r| r.method == "discrete")
        .or_else(|| candidates.iter().find(|r| r.method == baseline))
        .copied();
    if let Some(sentence) = no_room(name, rows, &candidates, hard) {
        return vec![sentence];
    }
    let mut out = Vec::new();
    // Least lodpop as the sentence shows it (3 figures), the cheaper of a tie.
    let shown = |r: &SummaryRecord| sig3(r.lodpop_max).parse::<f64>().unwrap_or(f64::INFINITY);
    let Some(least) = candidates.iter().copied().min_by(|a, b| {
        shown(a)
            .total_cmp(&shown(b))
            .then(by_cost(a, b))
            .then(lodpop_or_inf(a).total_cmp(&lodpop_or_inf(b)))
    }) else {
        return Vec::new();
    };
    let against = match hard {
        Some(h) if h.method != least.method => {
            format!(" against {}'s {}", h.method, sig3(h.lodpop_max))
        }
        _ => String::new(),
    };
    let ties = ties_clause(&candidates, least);
    if candidates.len() == 1 {
        // Nothing to compare its popping with: say what it is, and a budget's verdict only where one was given.
        out.push(format!(
            "{name}: {} is the only method with LOD transitions in the run, a largest lodpop of {}; {}.",
            least.method,
            sig3(least.lodpop_max),
            cost_clause(least, &baseline)
        ));
        if budget.is_none() {
            return out;
        }
    } else {
        out.push(format!(
            "{name}: {} pops least, a largest lodpop of {}{ties}{against}; {}.",
            least.method,
            sig3(least.lodpop_max),
            cost_clause(least, &baseline)
        ));
    }
    let budget = match (budget, hard) {
        (Some(b), _) => Some((b, "--budget-lodpop".to_string())),
        (None, Some(h)) => h
            .lodpop_max
            .map(|x| (x / 2.0, format!("half of {}'s", h.method))),
        (None, None) => None,
    };
    let Some((b, source)) = budget else {
        return out;
    };
    out.push(budget_sentence(
        &candidates,
        least,
        (b, &source),
        &baseline,
        pairs,
    ));
    out
}

/// The fewest frames a transition must span for a blending method to act on it: over one frame a blend shows
/// one of its two LODs whole, as the hard switch does.
pub const MIN_TRANSITION_FRAMES: u32 = 2;

/// Where some transition of the block spans fewer than [`MIN_TRANSITION_FRAMES`] frames (summary.csv's
/// `transition_frames_min`) and a method other than the hard switch ran: the one sentence that says so, in
/// place of a winner the run could not have found.
fn no_room(
    name: &str,
    rows: &[&SummaryRecord],
    candidates: &[&SummaryRecord],
    hard: Option<&SummaryRecord>,
) -> Option<String> {
    let n = rows
        .iter()
        .find_map(|r| r.transition_frames_min)
        .filter(|&n| n < MIN_TRANSITION_FRAMES)?;
    let smooth = candidates
        .iter()
        .any(|r| hard.is_none_or(|h| h.method != r.method));
    smooth.then(|| {
        format!(
            "{name}: a transition here lasts {n} frame (the camera crosses a switch's band within it), too few \
             for a blending method to act, so this run cannot say which method pops least; give the transitions \
             room with --fade time --fade-frames 8, or a slower path."
        )
    })
}

/// A block's cost order: ratio to the baseline, unmeasured last.
fn by_cost(a: &&SummaryRecord, b: &&SummaryRecord) -> std::cmp::Ordering {
    let c = |r: &SummaryRecord| r.ratio_to_baseline.unwrap_or(f64::INFINITY);
    c(a).total_cmp(&c(b))
}

/// A method's largest lodpop, infinite where unmeasured.
fn lodpop_or_inf(r: &SummaryRecord) -> f64 {
    r.lodpop_max.unwrap_or(f64::INFINITY)
}

/// The other `candidates` whose largest lodpop reads as `least`'s to 3 figures (they pop as little as far as
/// the sentence can say): " (a and b too, to 3 figures)", or nothing.
fn ties_clause(candidates: &[&SummaryRecord], least: &SummaryRecord) -> String {
    let ties: Vec<&str> = candidates
        .iter()
        .filter(|r| r.method != least.method && sig3(r.lodpop_max) == sig3(least.lodpop_max))
        .map(|r| r.method.as_str())
        .collect();
    if ties.is_empty() {
        String::new()
    } else {
        format!(" ({} too, to 3 figures)", and_list(&ties))
    }
}

/// The cheapest of the `candidates` within the lodpop budget `b` (from `source`) and how it compares with the
/// next, or that none is within it and `least` comes nearest.
fn budget_sentence(
    candidates: &[&SummaryRecord],
    least: &SummaryRecord,
    (b, source): (f64, &str),
    baseline: &str,
    pairs: &[PairRecord],
) -> String {
    let mut within: Vec<&SummaryRecord> = candidates
        .iter()
        .copied()
        .filter(|r| lodpop_or_inf(r) <= b && r.ratio_to_baseline.is_some())
        .collect();
    within.sort_by(by_cost);
    let Some(best) = within.first() else {
        return format!(
            "No method keeps its largest lodpop within {} ({source}); {} comes nearest.",
            sig3(Some(b)),
            least.method
        );
    };
    let mut s = format!(
        "Within a largest lodpop of {} ({source}), {} is the cheapest: {}.",
        sig3(Some(b)),
        best.method,
        cost_clause(best, baseline)
    );
    match within.get(1) {
        None => s.push_str(" No other method is within it."),
        Some(next) => s.push_str(&versus(best, next, pairs)),
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
fn cost_clause(r: &SummaryRecord, baseline: &str) -> String {
    if r.method == baseline {
        return format!("it is the baseline ({baseline})");
    }
    let (x, lo, hi) = (
        r.ratio_to_baseline,
        r.ratio_to_baseline_ci95_lo,
        r.ratio_to_baseline_ci95_hi,
    );
    match (x, lo, hi) {
        (Some(_), Some(l), Some(h)) if l > 1.0 || h < 1.0 => {
            format!(
                "it takes {} times {baseline}'s frame time",
                ratio(x, lo, hi)
            )
        }
        (Some(_), Some(_), Some(_)) => format!(
            "its frame time is not measurably different from {baseline}'s ({} times)",
            ratio(x, lo, hi)
        ),
        (Some(_), _, _) => format!(
            "it takes {} times {baseline}'s frame time (too few rounds for an interval)",
            ratio(x, lo, hi)
        ),
        _ => "its cost was not measured".into(),
    }
}

/// The cheapest against the next within the budget, paired directly (pairs.csv), in hyperfine's words where
/// they differ.
fn versus(best: &SummaryRecord, next: &SummaryRecord, pairs: &[PairRecord]) -> String {
    let pair = pairs.iter().find_map(|p| {
        if p.scene != best.scene || p.count != best.count {
            return None;
        }
        let (r, lo, hi) = (p.ratio?, p.ratio_ci95_lo?, p.ratio_ci95_hi?);
        if p.method_a == best.method && p.method_b == next.method {
            Some((r, lo, hi))
        } else if p.method_a == next.method && p.method_b == best.method {
            Some((1.0 / r, 1.0 / hi, 1.0 / lo))
        } else {
            None
        }
    });
    match pair {
        None => format!(
            " {} is the next within it (no paired ratio of the two).",
            next.method
        ),
        // best's time over next's.
        Some((r, lo, hi)) if hi < 1.0 => format!(
            " {} ran {} times faster than {}, the next within it.",
            best.method,
            ratio(Some(1.0 / r), Some(1.0 / hi), Some(1.0 / lo)),
            next.method
        ),
        Some((r, lo, hi)) if lo > 1.0 => format!(
            " Paired directly, {} ran {} times faster than {}.",
            next.method,
            ratio(Some(r), Some(lo), Some(hi)),
            best.method
        ),
        Some((r, lo, hi)) => format!(
            " It is not measurably different from {}, the next within it ({} times its frame time).",
            next.method,
            ratio(Some(r), Some(lo), Some(hi))
        ),
    }
}

/// Rows of cells as columns sized to their contents (two spaces apart), numbers right-aligned: `right[i]` says
/// whether column i is. The first row is the header.
pub fn aligned(rows: &[Vec<String>], right: &[bool]) -> String {
    let columns = rows.iter().map(Vec::len).max().unwrap_or(0);
    let widths: Vec<usize> = (0..columns)
        .map(|c| {
            rows.iter()
                .filter_map(|r| r.get(c))
                .map(|s| s.chars().count())
                .max()
                .unwrap_or(0)
        })
        .collect();
    let mut out = String::new();
    for row in rows {
        let mut line = String::new();
        for (c, width) in widths.iter().enumerate() {
            let cell = row.get(c).map_or("", String::as_str);
            let pad = width - cell.chars().count();
            if c > 0 {
                line.push_str("  ");
            }
            if right.get(c).copied().unwrap_or(false) {
                line.push_str(&" ".repeat(pad));
                line.push_str(cell);
            } else {
                line.push_str(cell);
                line.push_str(&" ".repeat(pad));
            }
        }
        out.push_str(line.trim_end());
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::records::Clock;

    pub fn row(scene: &str, method: &str, lodpop: f64, r: (f64, f64, f64)) -> SummaryRecord {
        let mut s = SummaryRecord {
            scene: scene.into(),
            method: method.into(),
            count: 1,
            ..SummaryRecord::default()
        };
        s.lodpop_max = Some(lodpop);
        s.baseline = Some("discrete".into());
        s.ratio_to_baseline = Some(r.0);
        s.ratio_to_baseline_ci95_lo = Some(r.1);
        s.ratio_to_baseline_ci95_hi = Some(r.2);
        s
    }

    fn pair(a: &str, b: &str, r: (f64, f64, f64)) -> PairRecord {
        PairRecord {
            scene: "s".into(),
            count: 1,
            method_a: a.into(),
            method_b: b.into(),
            clock: Clock::GpuMs,
            rounds: 20,
            ratio: Some(r.0),
            ratio_ci95_lo: Some(r.1),
            ratio_ci95_hi: Some(r.2),
            ratio_transition: None,
            ratio_transition_ci95_lo: None,
            ratio_transition_ci95_hi: None,
            ratio_steady: None,
            ratio_steady_ci95_lo: None,
            ratio_steady_ci95_hi: None,
            different: Some(r.1 > 1.0 || r.2 < 1.0),
        }
    }

    #[test]
    fn numbers_by_unit() {
        assert_eq!(sig3(Some(1.5203795)), "1.52");
        assert_eq!(sig3(Some(15.2049)), "15.2");
        assert_eq!(sig3(Some(152.49)), "152");
        assert_eq!(sig3(Some(1523.4)), "1523");
        assert_eq!(sig3(Some(0.0028712)), "0.00287");
        assert_eq!(sig3(Some(0.0)), "0");
        assert_eq!(sig3(None), "-");
        assert_eq!(thousands(Some(3674.0)), "3,674");
        assert_eq!(thousands(Some(557_500.4)), "557,500");
        assert_eq!(thousands(Some(999.6)), "1,000");
        assert_eq!(thousands(Some(12.0)), "12");
        assert_eq!(
            ratio(Some(1.2345), Some(1.1), Some(1.37)),
            "1.23 [1.10, 1.37]"
        );
        assert_eq!(ratio(Some(0.5), None, None), "0.50");
    }

    #[test]
    fn least_popping_and_cheapest_within_the_default_budget() {
        let rows = vec![
            row("s", "reference", 0.0, (2.0, 1.8, 2.2)),
            row("s", "discrete", 0.004, (1.0, 1.0, 1.0)),
            row("s", "alpha", 0.0015, (1.3, 1.2, 1.4)),
            row("s", "dither", 0.0018, (1.1, 1.05, 1.15)),
            row("s", "geomorph", 0.003, (1.01, 0.98, 1.04)),
        ];
        let pairs = vec![pair("alpha", "dither", (1.18, 1.1, 1.27))];
        let a = answers(&rows, &pairs, None);
        assert_eq!(a.len(), 1);
        assert_eq!(
            a[0].sentences,
            [
                "s: alpha pops least, a largest lodpop of 0.00150 against discrete's 0.00400; it takes \
                 1.30 [1.20, 1.40] times discrete's frame time.",
                "Within a largest lodpop of 0.00200 (half of discrete's), dither is the cheapest: it takes \
                 1.10 [1.05, 1.15] times discrete's frame time. dither ran 1.18 [1.10, 1.27] times faster than \
                 alpha, the next within it."
            ]
        );
    }

    /// A transition of one frame leaves a blend no room: the answer says so and names no method; with two frames
    /// (or a hard switch alone in the run) it answers as usual.
    #[test]
    fn a_transition_of_one_frame_names_no_method() {
        let rows = |frames: u32| {
            ["discrete", "alpha", "dither"].map(|m| {
                let mut r = row("s", m, 0.004, (1.0, 1.0, 1.0));
                r.transition_frames_min = Some(frames);
                r
            })
        };
        let a = answers(&rows(1), &[], None);
        assert_eq!(
            a[0].sentences,
            ["s: a transition here lasts 1 frame (the camera crosses a switch's band within it), too few for a \
              blending method to act, so this run cannot say which method pops least; give the transitions room \
              with --fade time --fade-frames 8, or a slower path."]
        );
        assert!(
            answers(&rows(MIN_TRANSITION_FRAMES), &[], None)[0].sentences[0].contains("pops least")
        );
        let alone = answers(&rows(1)[..1], &[], None);
        assert!(
            alone[0].sentences[0].contains("the only method"),
            "{alone:?}"
        );
    }

    #[test]
    fn no_difference_is_stated_as_none() {
        let rows = vec![
            row("s", "discrete", 0.004, (1.0, 1.0, 1.0)),
            row("s", "alpha", 0.001, (1.02, 0.97, 1.07)),
            row("s", "dither", 0.0011, (1.03, 0.99, 1.08)),
        ];
        let pairs = vec![pair("alpha", "dither", (0.99, 0.95, 1.03))];
        let a = &answers(&rows, &pairs, Some(0.0012))[0].sentences;
        assert!(
            a[0].contains("not measurably different from discrete's (1.02 [0.97, 1.07] times)"),
            "{a:?}"
        );
        assert!(a[1].starts_with("Within a largest lodpop of 0.00120 (--budget-lodpop), alpha"));
        assert!(
            a[1].ends_with(
                "It is not measurably different from dither, the next within it (0.99 [0.95, 1.03] times its \
                 frame time)."
            ),
            "{a:?}"
        );
    }

    #[test]
    fn a_pair_written_the_other_way_round_is_inverted() {
        let rows = vec![
            row("s", "discrete", 0.004, (1.0, 1.0, 1.0)),
            row("s", "alpha", 0.001, (1.3, 1.2, 1.4)),
            row("s", "dither", 0.0011, (1.1, 1.05, 1.15)),
        ];
        // alpha's time over dither's is 1.25: dither (the cheapest) ran 1.25 times faster.
        let pairs = vec![pair("alpha", "dither", (1.25, 1.2, 1.3))];
        let a = &answers(&rows, &pairs, Some(0.002))[0].sentences;
        assert!(
            a[1].ends_with(
                "dither ran 1.25 [1.20, 1.30] times faster than alpha, the next within it."
            ),
            "{a:?}"
        );
    }

    #[test]
    fn ties_to_the_shown_figures_are_named() {
        let rows = vec![
            row("s", "discrete", 0.004, (1.0, 1.0, 1.0)),
            row("s", "alpha", 0.0015901, (1.3, 1.2, 1.4)),
            row("s", "alpha-2pass", 0.0015899, (1.4, 1.3, 1.5)),
            row("s", "alpha-zwrite", 0.00159, (1.2, 1.1, 1.3)),
            row("s", "dither", 0.0016, (1.1, 1.05, 1.15)),
        ];
        let a = &answers(&rows, &[], None)[0].sentences;
        assert!(
            a[0].starts_with(
                "s: alpha-zwrite pops least, a largest lodpop of 0.00159 (alpha and alpha-2pass too, to 3 \
                 figures) against discrete's 0.00400; it takes 1.20 [1.10, 1.30] times"
            ),
            "{a:?}"
        );
    }

    #[test]
    fn a_lone_method_is_not_said_to_pop_least() {
        let rows = vec![
            row("s", "reference", 0.0, (2.0, 1.8, 2.2)),
            row("s", "discrete", 0.004, (1.0, 1.0, 1.0)),
        ];
        let a = &answers(&rows, &[], None)[0].sentences;
        assert_eq!(
            a,
            &["s: discrete is the only method with LOD transitions in the run, a largest lodpop of 0.00400; it \
               is the baseline (discrete)."]
        );
        assert_eq!(answers(&rows, &[], Some(0.005))[0].sentences.len(), 2);
    }

    #[test]
    fn nothing_within_the_budget_says_who_comes_nearest() {
        let rows = vec![
            row("s", "discrete", 0.004, (1.0, 1.0, 1.0)),
            row("s", "alpha", 0.003, (1.3, 1.2, 1.4)),
        ];
        let a = &answers(&rows, &[], None)[0].sentences;
        assert_eq!(
            a[1],
            "No method keeps its largest lodpop within 0.00200 (half of discrete's); alpha comes nearest."
        );
    }

    #[test]
    fn aligned_columns_fit_their_longest_cell() {
        let name = "a-user-scene-name-of-forty-characters.glb";
        assert_eq!(name.len(), 41);
        let rows = vec![
            vec!["scene".to_string(), "method".into(), "ms".into()],
            vec![name[..40].to_string(), "discrete".into(), "1.52".into()],
            vec!["bunny".into(), "alpha-2pass".into(), "15.2".into()],
        ];
        let text = aligned(&rows, &[false, false, true]);
        let lines: Vec<&str> = text.lines().collect();
        // Every column starts at the same place on every line, and numbers end together.
        let starts = |l: &str, word: &str| l.find(word).expect("a cell");
        assert_eq!(starts(lines[0], "method"), starts(lines[1], "discrete"));
        assert_eq!(
            starts(lines[1], "discrete"),
            starts(lines[2], "alpha-2pass")
        );
        assert_eq!(lines[0].len(), lines[1].len());
        assert_eq!(lines[1].len(), lines[2].len());
        assert_eq!(starts(lines[1], "discrete"), 42);
    }
}
