//! How a number is shown to a person: to 3 significant figures, a count with thousands separators, a ratio with
//! its interval, and cells in aligned columns. The terminal's tables (run, probe, overhead, tune, describe) and
//! the answer (`results::answer`, hence report.html) format with these, and with nothing else.

/// A figure to at least 3 significant figures, never in exponent form: `1.52`, `15.2`, `152`, `1523`, `0.00287`;
/// `-` where there is none. scripts/lodbench_results.py's `sig3` is the same rule, for the report's other tables.
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
