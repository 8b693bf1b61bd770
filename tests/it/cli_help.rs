//! `-h` and `--help` through the binary: every subcommand's is the same summary, a line or two a flag under
//! headings, written for users (no source path, no rustdoc link); `tune`'s lists only the flags tune reads and
//! refuses the others; and a negative number after a flag is read as a number, then refused with its range.

use crate::common::{fails_with, lodbench};
use clap::CommandFactory;
use lodbench::cli::{Cli, NOT_FOR_TUNE};

/// The standard output of a successful `lodbench ARGS`.
fn stdout_of(args: &[&str]) -> String {
    let out = lodbench(args, &[]);
    assert!(
        out.status.success(),
        "lodbench {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// The standard error of a failed `lodbench ARGS`.
fn stderr_of_failure(args: &[&str]) -> String {
    let out = lodbench(args, &[]);
    assert!(!out.status.success(), "lodbench {args:?} succeeded");
    String::from_utf8(out.stderr).unwrap()
}

/// Every subcommand's name.
fn subcommands() -> Vec<String> {
    Cli::command()
        .get_subcommands()
        .map(|c| c.get_name().to_string())
        .collect()
}

/// The argument lists that print help: `lodbench -h`, `lodbench --help`, and for every subcommand `-h`,
/// `--help` and `lodbench help SUBCOMMAND`.
fn help_invocations() -> Vec<Vec<String>> {
    let mut all = vec![vec!["-h".to_string()], vec!["--help".to_string()]];
    for c in subcommands() {
        all.push(vec![c.clone(), "-h".into()]);
        all.push(vec![c.clone(), "--help".into()]);
        all.push(vec!["help".into(), c]);
    }
    all
}

/// What a help text must not show: a source path (`src/...`, a `.rs` or `.wgsl` file, `crate::`) or rustdoc's
/// link syntax (`[Name]`, `[`name`]`, `[text](path)`, `[text][Name]`). Clap's own brackets pass: `[OPTIONS]`
/// and `[COMMAND]` of the usage, `[default: 8]`, `[possible values: on, off]`, and an interval such as `[0, 1]`.
fn developer_syntax(help: &str) -> Vec<String> {
    let mut found = Vec::new();
    for line in help.lines().filter(|l| !l.starts_with("Usage:")) {
        for needle in ["src/", "crate::", "shaders/", "[`", "](", "]["] {
            if line.contains(needle) {
                found.push(format!("{needle:?} in: {line}"));
            }
        }
        for ext in [".rs", ".wgsl"] {
            let ends_a_name = line.match_indices(ext).any(|(i, _)| {
                !line[i + ext.len()..]
                    .chars()
                    .next()
                    .is_some_and(|c| c.is_alphanumeric())
            });
            if ends_a_name {
                found.push(format!("a {ext} file in: {line}"));
            }
        }
        // `[Name]`, `[path::Name]`: a word in brackets, other than clap's placeholders.
        let mut rest = line;
        while let Some(open) = rest.find('[') {
            let after = &rest[open + 1..];
            let Some(close) = after.find(']') else { break };
            let inside = &after[..close];
            let a_word = !inside.is_empty()
                && inside
                    .chars()
                    .all(|c| c.is_alphanumeric() || c == '_' || c == ':');
            if a_word && !["OPTIONS", "COMMAND"].contains(&inside) {
                found.push(format!("[{inside}] in: {line}"));
            }
            rest = after;
        }
    }
    found
}

#[test]
fn the_checker_finds_source_paths_and_rustdoc_links_and_passes_clap_s_brackets() {
    for bad in [
        "  --x  unioned up the DAG ([`GroupBounds`]): over",
        "  --x  see [GroupBounds] for it",
        "  --x  see [crate::scene::Scene]",
        "  --x  Only the pixels (src/measure/coverage.rs) where",
        "  --x  in morph.rs, computed once",
        "  --x  (shaders/surface_pbr.wgsl)",
        "  --x  a [link](crate::x) here",
    ] {
        assert!(!developer_syntax(bad).is_empty(), "not found in {bad:?}");
    }
    for good in [
        "Usage: lodbench run [OPTIONS] --scene <SCENE>",
        "Usage: lodbench [COMMAND]",
        "  --fov <FOV>  Vertical field of view in degrees [default: 60]",
        "  --taa <TAA>  Temporal anti-aliasing [default: off] [possible values: on, off]",
        "  --x  the largest RMS change (sRGB-encoded, in [0, 1]) or (0, 1), results/<scene>-<time>/",
        "  --x  summary.csv's bound, run.json, --metrics rs, runs",
    ] {
        assert_eq!(developer_syntax(good), Vec::<String>::new(), "{good:?}");
    }
}

/// The lines of each flag's entry in a help text (its name's line and any more before the next flag, heading
/// or blank line).
fn entry_lengths(help: &str) -> Vec<(String, usize)> {
    let mut entries: Vec<(String, usize)> = Vec::new();
    let mut open = false;
    for line in help.lines() {
        let trimmed = line.trim_start();
        if line.starts_with("  ") && trimmed.starts_with('-') {
            entries.push((trimmed.to_string(), 1));
            open = true;
        } else if open && line.starts_with(' ') && !trimmed.is_empty() {
            if let Some(last) = entries.last_mut() {
                last.1 += 1;
            }
        } else {
            open = false;
        }
    }
    entries
}

#[test]
fn run_help_is_a_summary_under_150_lines() {
    let long = stdout_of(&["run", "--help"]);
    let lines = long.lines().count();
    assert!(lines < 150, "run --help has {lines} lines:\n{long}");
    assert!(
        long.contains("--budget-lodpop") && long.contains("--fsi-check"),
        "{long}"
    );
    for heading in [
        "Scene:",
        "Built-in scenes:",
        "Your file (--scene FILE.glb):",
        "Methods:",
        "Measurement:",
        "Output:",
    ] {
        assert!(
            long.lines().any(|l| l == heading),
            "no heading {heading:?} in run --help:\n{long}"
        );
    }
}

#[test]
fn every_help_is_the_summary_a_line_or_two_a_flag() {
    for c in subcommands() {
        let short = stdout_of(&[&c, "-h"]);
        let long = stdout_of(&[&c, "--help"]);
        assert_eq!(short, long, "{c}: --help prints more than -h's summary");
        for (flag, n) in entry_lengths(&long) {
            assert!(
                n <= 2,
                "{c} --help: {flag} takes {n} lines (the details go to docs/flags.md)"
            );
        }
    }
}

#[test]
fn no_help_shows_source_paths_or_rustdoc_links() {
    for args in help_invocations() {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let help = stdout_of(&args);
        let found = developer_syntax(&help);
        assert!(
            found.is_empty(),
            "lodbench {}:\n{}",
            args.join(" "),
            found.join("\n")
        );
    }
}

#[test]
fn tune_lists_only_the_flags_it_reads_and_refuses_the_others() {
    let tune = stdout_of(&["tune", "--help"]);
    let run = stdout_of(&["run", "--help"]);
    let cmd = Cli::command();
    let tune_cmd = cmd.find_subcommand("tune").unwrap();
    let mut flags: Vec<String> = NOT_FOR_TUNE
        .iter()
        .map(|id| {
            let arg = tune_cmd.get_arguments().find(|a| a.get_id() == *id);
            format!("--{}", arg.unwrap().get_long().unwrap())
        })
        .collect();
    // The ones the report named, whatever the list says.
    for named in ["--partition", "--blocks", "--taa"] {
        assert!(flags.iter().any(|f| f == named), "{named} not refused");
    }
    flags.sort();
    for flag in &flags {
        let listed = |help: &str| {
            help.lines()
                .any(|l| l.trim_start().starts_with(&format!("{flag} ")))
        };
        assert!(!listed(&tune), "tune --help lists {flag}:\n{tune}");
        assert!(listed(&run), "run --help does not list {flag}");
    }
    // The scene flags tune reads are still listed.
    for flag in [
        "--width",
        "--mesh",
        "--pixel-error",
        "--band",
        "--materials",
    ] {
        assert!(
            tune.contains(&format!("{flag} ")),
            "{flag} missing:\n{tune}"
        );
    }

    let err = stderr_of_failure(&[
        "tune",
        "--scene",
        "bunny-sweep",
        "--budget-lodpop",
        "0.01",
        "--partition",
        "bin",
    ]);
    assert!(
        err.starts_with("error: --partition changes nothing for tune"),
        "{err}"
    );
    let err = stderr_of_failure(&["tune", "--scene", "bunny-sweep", "--taa", "on"]);
    assert!(
        err.starts_with("error: --taa changes nothing for tune"),
        "{err}"
    );
}

#[test]
fn a_negative_number_is_a_number_refused_with_its_range() {
    fails_with(
        &lodbench(
            &["tune", "--scene", "bunny-sweep", "--budget-lodpop", "-1"],
            &[],
        ),
        &["--budget-lodpop -1: a lodpop budget is a change in (0, 1)"],
    );
    fails_with(
        &lodbench(
            &["run", "--scene", "bunny-sweep", "--budget-lodpop", "-1"],
            &[],
        ),
        &["--budget-lodpop -1: a lodpop budget is a change in (0, 1)"],
    );
    fails_with(
        &lodbench(
            &["run", "--scene", "bunny-sweep", "--hysteresis", "-0.1"],
            &[],
        ),
        &["--hysteresis -0.1", "[0, 0.5)"],
    );
    fails_with(
        &lodbench(&["describe", "--scene", "bunny-sweep", "--fov", "-5"], &[]),
        &["--fov -5 must be between 1 and 170"],
    );
    // A count: clap's own message for a value out of its type's range, not an unknown flag `-1`.
    for (args, flag) in [
        (&["run", "--frames", "-1"][..], "--frames"),
        (
            &["describe", "--scene", "bunny-sweep", "--blocks", "-1"],
            "--blocks",
        ),
        (
            &["export", "--scene", "bunny-sweep", "--frame", "-1"],
            "--frame",
        ),
        (
            &["tune", "--scene", "bunny-sweep", "--views", "-1"],
            "--views",
        ),
        (&["probe", "--rounds", "-1"], "--rounds"),
        (&["overhead", "--warmup", "-1"], "--warmup"),
        (&["clips", "dir", "--columns", "-1"], "--columns"),
        (&["compare", "dir", "a", "b", "--count", "-1"], "--count"),
    ] {
        let err = stderr_of_failure(args);
        assert!(
            err.starts_with(&format!("error: invalid value '-1' for '{flag}")),
            "lodbench {}: {err}",
            args.join(" ")
        );
    }
}
