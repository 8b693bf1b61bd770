//! What an answer's sentences and table cells are made of: text, and numbers that say which CSV cells they show
//! (report.html writes them as `data-` attributes, and scripts/tests check each against its file).

use crate::numbers::{ratio, sig3, thousands};
use crate::results::csv::CsvRow;
use crate::results::files::{PAIRS_CSV, RUN_JSON, SUMMARY_CSV};
use serde::Serialize;

/// How a number is formatted (`crate::numbers`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Fmt {
    /// [`sig3`]: at least 3 significant figures.
    Sig3,
    /// [`thousands`]: a count with separators.
    Thousands,
    /// [`ratio`]: a ratio and its 95 % interval, from three columns.
    Ratio,
}

/// What is done to the cells before they are formatted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Op {
    /// Shown as they are.
    #[serde(rename = "")]
    AsIs,
    /// Halved: the default budget, half the hard switch's largest lodpop.
    #[serde(rename = "half")]
    Half,
    /// Inverted (and the interval's ends swapped): a paired ratio read the other way round.
    #[serde(rename = "inv")]
    Inv,
}

/// A number as shown, and the cells it comes from: `file`'s row whose cells are `row`, its columns `cols` (one,
/// or a ratio's three).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Value {
    pub text: String,
    pub file: &'static str,
    pub row: CsvRow,
    pub cols: Vec<String>,
    pub fmt: Fmt,
    pub op: Op,
}

/// A piece of a sentence or a table cell: text, or a [`Value`].
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Part {
    Text(String),
    Value(Value),
}

impl Part {
    pub fn text(&self) -> &str {
        match self {
            Part::Text(t) => t,
            Part::Value(v) => &v.text,
        }
    }
}

impl From<String> for Part {
    fn from(t: String) -> Part {
        Part::Text(t)
    }
}

impl From<&str> for Part {
    fn from(t: &str) -> Part {
        Part::Text(t.to_string())
    }
}

impl From<Value> for Part {
    fn from(v: Value) -> Part {
        Part::Value(v)
    }
}

/// A sentence's text: its parts joined.
pub fn text_of(parts: &[Part]) -> String {
    parts.iter().map(Part::text).collect()
}

/// summary.csv's columns that name a row besides the swept variables.
pub const SUMMARY_KEY: [&str; 3] = ["scene", "method", "count"];

/// pairs.csv's columns that name a row besides the swept variables.
pub const PAIRS_KEY: [&str; 4] = ["scene", "count", "method_a", "method_b"];

/// `key` after the swept `variables`: the columns that find a row.
fn key_columns<'a>(variables: &'a [String], key: &[&'a str]) -> Vec<&'a str> {
    variables
        .iter()
        .map(String::as_str)
        .chain(key.iter().copied())
        .collect()
}

/// A ratio's three columns: `col`, `col_ci95_lo`, `col_ci95_hi`.
pub fn ratio_columns(col: &str) -> Vec<String> {
    vec![
        col.to_string(),
        format!("{col}_ci95_lo"),
        format!("{col}_ci95_hi"),
    ]
}

/// Summary row `r`'s column `col` (a ratio's three with [`Fmt::Ratio`]) as shown.
pub fn summary_value(r: &CsvRow, variables: &[String], col: &str, fmt: Fmt, op: Op) -> Value {
    let row = r.pick(&key_columns(variables, &SUMMARY_KEY));
    if fmt == Fmt::Ratio {
        let cols = ratio_columns(col);
        let text = ratio(r.num(&cols[0]), r.num(&cols[1]), r.num(&cols[2]));
        return Value {
            text,
            file: SUMMARY_CSV,
            row,
            cols,
            fmt,
            op,
        };
    }
    let x = r.num(col).map(|x| if op == Op::Half { x / 2.0 } else { x });
    let text = match fmt {
        Fmt::Thousands => thousands(x),
        _ => sig3(x),
    };
    Value {
        text,
        file: SUMMARY_CSV,
        row,
        cols: vec![col.to_string()],
        fmt,
        op,
    }
}

/// Pairs row `p`'s ratio as shown: as written, or inverted (`Op::Inv`).
pub fn pair_value(p: &CsvRow, variables: &[String], op: Op) -> Value {
    let cols = ratio_columns("ratio");
    let (r, lo, hi) = (p.num(&cols[0]), p.num(&cols[1]), p.num(&cols[2]));
    let text = match (op, r, lo, hi) {
        (Op::Inv, Some(r), Some(lo), Some(hi)) => {
            ratio(Some(1.0 / r), Some(1.0 / hi), Some(1.0 / lo))
        }
        _ => ratio(r, lo, hi),
    };
    Value {
        text,
        file: PAIRS_CSV,
        row: p.pick(&key_columns(variables, &PAIRS_KEY)),
        cols,
        fmt: Fmt::Ratio,
        op,
    }
}

/// The run's `--budget-lodpop` as shown (run.json's config).
pub fn budget_value(b: f64) -> Value {
    Value {
        text: sig3(Some(b)),
        file: RUN_JSON,
        row: CsvRow::default(),
        cols: vec!["budget_lodpop".to_string()],
        fmt: Fmt::Sig3,
        op: Op::AsIs,
    }
}
