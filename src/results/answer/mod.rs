//! The answer a results folder leads with, written once: `answer.json` ([`ANSWER_JSON`]).
//!
//! Per block of summary.csv (its swept values, scene and count): which method pops least and which is the
//! cheapest within a popping budget, in sentences whose every number is a cell of summary.csv or pairs.csv
//! ([`rule`]), and the decision table beside them ([`table`]). `lodbench run` writes it at the end of a run and
//! prints its sentences under its table; `lodbench experiment` and `lodbench merge` write it for the joined CSVs;
//! `lodbench perceptual` rewrites it with the JOD column; `lodbench answer DIR` makes it for any folder (one
//! written before it existed). scripts/plot.py puts it at the top of report.html as it stands: the terminal
//! and the report say the same because they read the same file.
//!
//! The rule reads the CSV rows as their files hold them ([`CsvRow`]), so the answer of a run in memory
//! ([`from_records`]) is the answer of its folder ([`from_folder`]).

pub mod parts;
pub mod rule;
pub mod table;

use crate::error::{Error, Result};
use crate::measure::records::{PairRecord, SummaryRecord, TransitionRecord};
use crate::results::csv::{read_rows, rows_of, CsvRow};
use crate::results::files::{
    run_folder_of, ANSWER_JSON, PAIRS_CSV, PERCEPTUAL_CSV, RUN_JSON, SUMMARY_CSV, TRANSITIONS_CSV,
};
use crate::results::manifest::{read_json, write_compact_json_file, BuildVersion};
use parts::{text_of, Part};
use rule::{Budget, Sentence};
use serde::Serialize;
use std::path::Path;

pub use rule::{is_candidate, MIN_TRANSITION_FRAMES};
pub use table::DECISION_COLUMNS;

/// answer.json's `schema`.
pub const SCHEMA: &str = "lodbench-answer/1";

/// answer.json.
#[derive(Debug, Clone, Serialize)]
pub struct AnswerFile {
    pub schema: &'static str,
    pub build: BuildVersion,
    /// summary.csv's columns before `scene`, `adapter` aside: the swept variables of an experiment folder.
    pub variables: Vec<String>,
    pub columns: [&'static str; 10],
    pub blocks: Vec<Block>,
}

/// The answer of one block of summary.csv.
#[derive(Debug, Clone, Serialize)]
pub struct Block {
    /// `bunny-sweep`, `bunny-sweep (pixel-error 2) (count 5)`: how its sentences name it.
    pub name: String,
    /// The swept variables' values, as the CSV writes them.
    pub values: Vec<String>,
    pub scene: String,
    pub count: String,
    /// `discrete` where it ran, else the baseline; None where neither shows transitions.
    pub hard_switch: Option<String>,
    /// The budget the cheapest is chosen within.
    pub budget: Option<Budget>,
    pub sentences: Vec<Sentence>,
    /// The decision table: a row per method, its cells under [`DECISION_COLUMNS`].
    pub rows: Vec<Vec<Part>>,
}

impl Block {
    /// Its sentences as text.
    pub fn texts(&self) -> Vec<String> {
        self.sentences.iter().map(|s| text_of(s)).collect()
    }
}

/// What the answer reads: the folder's CSV rows and, per run (its swept values), the run's `--budget-lodpop`
/// and perceptual.csv rows.
pub struct Tables<'a> {
    pub summary: Vec<CsvRow>,
    pub pairs: Vec<CsvRow>,
    pub transitions: Vec<CsvRow>,
    pub budget_of: &'a dyn Fn(&[String]) -> Option<rule::Given>,
    pub perceptual_of: &'a dyn Fn(&[String]) -> Result<Vec<CsvRow>>,
}

/// The answer of `t`; an error where a run's perceptual.csv cannot be read.
pub fn answer(t: &Tables<'_>) -> Result<AnswerFile> {
    let variables = variables_of(&t.summary);
    let keys = block_keys(&t.summary, &variables);
    let blocks = keys
        .iter()
        .map(|key| {
            let rows: Vec<&CsvRow> = t
                .summary
                .iter()
                .filter(|r| &key_of(r, &variables) == key)
                .collect();
            let name = block_name(key, &variables, &keys);
            let said = rule::sentences(&rule::BlockInput {
                name: &name,
                rows: &rows,
                pairs: &t.pairs,
                variables: &variables,
                budget: (t.budget_of)(&key.0),
            });
            let perceptual = (t.perceptual_of)(&key.0)?;
            Ok(Block {
                name,
                values: key.0.clone(),
                scene: key.1.clone(),
                count: key.2.clone(),
                hard_switch: said.hard_switch,
                budget: said.budget,
                sentences: said.sentences,
                rows: table::decision_rows(&rows, &t.transitions, &perceptual, &variables),
            })
        })
        .collect::<Result<Vec<Block>>>()?;
    Ok(AnswerFile {
        schema: SCHEMA,
        build: BuildVersion::this(),
        variables,
        columns: DECISION_COLUMNS,
        blocks,
    })
}

/// summary.csv's columns before `scene`, `adapter` aside: an experiment folder's swept variables.
fn variables_of(summary: &[CsvRow]) -> Vec<String> {
    summary.first().map_or_else(Vec::new, |r| {
        r.0.iter()
            .map(|(c, _)| c.clone())
            .take_while(|c| c != "scene")
            .filter(|c| c != "adapter")
            .collect()
    })
}

/// A block's key: its swept values, scene and count.
type Key = (Vec<String>, String, String);

fn key_of(r: &CsvRow, variables: &[String]) -> Key {
    (
        variables.iter().map(|v| r.text(v).to_string()).collect(),
        r.text("scene").to_string(),
        r.text("count").to_string(),
    )
}

/// The blocks of `summary`, in the order their first rows come.
fn block_keys(summary: &[CsvRow], variables: &[String]) -> Vec<Key> {
    let mut keys: Vec<Key> = Vec::new();
    for r in summary {
        let k = key_of(r, variables);
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    keys
}

/// `scene`, with the swept values where there are (`scene (pixel-error 2)`) and the count where the run has
/// several of the scene (`scene (count 5)`).
fn block_name(key: &Key, variables: &[String], keys: &[Key]) -> String {
    let (values, scene, _) = key;
    let counts = keys
        .iter()
        .filter(|k| &k.0 == values && &k.1 == scene)
        .count();
    let mut name = scene.clone();
    if !variables.is_empty() {
        let swept: Vec<String> = variables
            .iter()
            .zip(values)
            .map(|(v, x)| format!("{v} {x}"))
            .collect();
        name += &format!(" ({})", swept.join(", "));
    }
    if counts > 1 {
        name += &format!(" (count {})", key.2);
    }
    name
}

/// The answer of a run in memory: its records as their CSVs hold them, `budget` its `--budget-lodpop`.
pub fn from_records(
    summaries: &[SummaryRecord],
    pairs: &[PairRecord],
    transitions: &[TransitionRecord],
    budget: Option<f64>,
) -> Result<AnswerFile> {
    answer(&Tables {
        summary: rows_of(summaries)?,
        pairs: rows_of(pairs)?,
        transitions: rows_of(transitions)?,
        budget_of: &|_| {
            budget.map(|lodpop| rule::Given {
                lodpop,
                source: "--budget-lodpop".to_string(),
            })
        },
        perceptual_of: &|_| Ok(Vec::new()),
    })
}

/// The answer of results folder `dir` (a run's, an experiment's or a merged one): its summary.csv, pairs.csv
/// and transitions.csv, and each run's run.json (`--budget-lodpop`) and perceptual.csv.
pub fn from_folder(dir: &Path) -> Result<AnswerFile> {
    if !dir.join(SUMMARY_CSV).is_file() {
        return Err(Error::results(
            dir,
            "has no summary.csv (a complete lodbench run, experiment or merged folder?)",
        ));
    }
    let summary = read_rows(&dir.join(SUMMARY_CSV))?;
    let variables = variables_of(&summary);
    let run = |values: &[String]| run_folder_of(dir, &variables, values);
    answer(&Tables {
        summary,
        pairs: read_rows(&dir.join(PAIRS_CSV))?,
        transitions: read_rows(&dir.join(TRANSITIONS_CSV))?,
        budget_of: &|values| budget_lodpop(&run(values).join(RUN_JSON)),
        perceptual_of: &|values| {
            let path = run(values).join(PERCEPTUAL_CSV);
            read_rows(&path).map_err(|e| Error::results(&path, format!("cannot be read ({e})")))
        },
    })
}

/// run.json's `config.budget_lodpop` and where it came from (`--budget-lodpop`, or `--budget-jnd` of
/// `config.calibration`); None where it has none or cannot be read.
fn budget_lodpop(path: &Path) -> Option<rule::Given> {
    let json: serde_json::Value = read_json(path).ok()?.ok()?;
    let config = json.get("config")?;
    let lodpop = config.get("budget_lodpop")?.as_f64()?;
    let source = match config.get("calibration").filter(|c| !c.is_null()) {
        Some(c) => {
            let threshold = c.get("threshold")?.as_f64()?;
            let simulated = c
                .get("simulated")
                .and_then(|s| s.as_bool())
                .unwrap_or(false);
            format!(
                "{} JND of {}{}",
                crate::numbers::sig3(Some(lodpop / threshold)),
                if simulated {
                    "a simulated observer, "
                } else {
                    ""
                },
                c.get("path")?.as_str()?
            )
        }
        None => "--budget-lodpop".to_string(),
    };
    Some(rule::Given { lodpop, source })
}

/// Writes `dir/answer.json` from the folder's files, and returns it.
pub fn write(dir: &Path) -> Result<AnswerFile> {
    let answer = from_folder(dir)?;
    write_compact_json_file(dir, ANSWER_JSON, &answer)?;
    Ok(answer)
}

/// Its sentences as the terminal prints them: each on its line, a blank line after the last; nothing where none.
pub fn sentences_text(answer: &AnswerFile) -> String {
    let lines: Vec<String> = answer.blocks.iter().flat_map(Block::texts).collect();
    if lines.is_empty() {
        return String::new();
    }
    format!("\n{}\n\n", lines.join("\n"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::records::Clock;

    /// The sentences of the first block of a run's records.
    fn answers(
        rows: &[SummaryRecord],
        pairs: &[PairRecord],
        budget: Option<f64>,
    ) -> Vec<Vec<String>> {
        from_records(rows, pairs, &[], budget)
            .expect("rows")
            .blocks
            .iter()
            .map(Block::texts)
            .collect()
    }

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
            a[0],
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
            a[0],
            ["s: a transition here lasts 1 frame (the camera crosses a switch's band within it), too few for a \
              blending method to act, so this run cannot say which method pops least; give the transitions room \
              with --fade time --fade-frames 8, or a slower path."]
        );
        assert!(answers(&rows(MIN_TRANSITION_FRAMES), &[], None)[0][0].contains("pops least"));
        let alone = answers(&rows(1)[..1], &[], None);
        assert!(alone[0][0].contains("the only method"), "{alone:?}");
    }

    #[test]
    fn no_difference_is_stated_as_none() {
        let rows = vec![
            row("s", "discrete", 0.004, (1.0, 1.0, 1.0)),
            row("s", "alpha", 0.001, (1.02, 0.97, 1.07)),
            row("s", "dither", 0.0011, (1.03, 0.99, 1.08)),
        ];
        let pairs = vec![pair("alpha", "dither", (0.99, 0.95, 1.03))];
        let a = &answers(&rows, &pairs, Some(0.0012))[0];
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
        let a = &answers(&rows, &pairs, Some(0.002))[0];
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
        let a = &answers(&rows, &[], None)[0];
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
        let a = &answers(&rows, &[], None)[0];
        assert_eq!(
            a,
            &["s: discrete is the only method with LOD transitions in the run, a largest lodpop of 0.00400; it \
               is the baseline (discrete)."]
        );
        assert_eq!(answers(&rows, &[], Some(0.005))[0].len(), 2);
    }

    #[test]
    fn nothing_within_the_budget_says_who_comes_nearest() {
        let rows = vec![
            row("s", "discrete", 0.004, (1.0, 1.0, 1.0)),
            row("s", "alpha", 0.003, (1.3, 1.2, 1.4)),
        ];
        let a = &answers(&rows, &[], None)[0];
        assert_eq!(
            a[1],
            "No method keeps its largest lodpop within 0.00200 (half of discrete's); alpha comes nearest."
        );
    }

    /// Every number of a sentence names its cells: the default budget is half of discrete's lodpop_max, in the
    /// row of its scene, method and count; a folder's answer is that of its records in memory.
    #[test]
    fn numbers_name_their_cells_and_a_folder_reads_as_its_records() {
        let rows = vec![
            row("s", "discrete", 0.004, (1.0, 1.0, 1.0)),
            row("s", "alpha", 0.0015, (1.3, 1.2, 1.4)),
        ];
        let a = from_records(&rows, &[], &[], None).expect("rows");
        let budget = a.blocks[0].sentences[1]
            .iter()
            .find_map(|p| match p {
                Part::Value(v) => Some(v.clone()),
                Part::Text(_) => None,
            })
            .expect("a number");
        assert_eq!(budget.text, "0.00200");
        assert_eq!(budget.op, parts::Op::Half);
        assert_eq!(budget.cols, ["lodpop_max"]);
        assert_eq!(
            serde_json::to_string(&budget.row).expect("json"),
            r#"{"scene":"s","method":"discrete","count":"1"}"#
        );
        let dir = tempfile::tempdir().expect("a folder");
        crate::results::csv::write_summary(dir.path(), &rows).expect("summary.csv");
        let folder = write(dir.path()).expect("answer.json");
        assert_eq!(folder.blocks[0].texts(), a.blocks[0].texts());
        assert!(dir.path().join(ANSWER_JSON).is_file());
        assert!(from_folder(&dir.path().join("none")).is_err());
    }
}
