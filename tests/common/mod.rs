//! Helpers the integration tests share (`mod common;` in each): reading lodbench's CSVs and columns.

#![allow(dead_code, reason = "each test binary uses a part of these")]

use std::collections::HashMap;
use std::path::Path;

/// One CSV row, by column name.
pub type Row = HashMap<String, String>;
pub type Rows = Vec<Row>;

/// Every row of a CSV file written by lodbench.
pub fn read_csv(path: &Path) -> Rows {
    let mut r = csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let headers = r.headers().expect("a header row").clone();
    r.records()
        .map(|rec| {
            let rec = rec.expect("a CSV record");
            headers
                .iter()
                .zip(rec.iter())
                .map(|(h, v)| (h.to_string(), v.to_string()))
                .collect()
        })
        .collect()
}

/// Column `name` of `method`'s rows, as numbers.
pub fn col(rows: &Rows, method: &str, name: &str) -> Vec<f64> {
    rows.iter()
        .filter(|r| r["method"] == method)
        .map(|r| {
            r[name]
                .parse::<f64>()
                .unwrap_or_else(|_| panic!("{name}={}", r[name]))
        })
        .collect()
}
