//! Experiment files: `lodbench experiment FILE.toml` reads a sweep described in a file into the validated
//! configurations of its runs (`commands::experiment` runs them).
//!
//! ```toml
//! name = "sheliemietiev-fig5"
//! description = "..."
//! [run]                     # any `lodbench run` flag, same name without the dashes
//! scene = ["bunny-grid"]
//! profile = "paper"
//! [sweep]                   # optional: one run per value
//! variable = "viewport"     # a [run] key, or "viewport" for [width, height] pairs
//! values = [[256, 256], [512, 512]]
//! ```
//! Several variables are crossed with `[[sweep]]` tables instead of the one `[sweep]`: one run per combination
//! of their values, the first table's variable varying slowest.
//! The `[run]` table deserialises straight into `RunArgs` (the same struct clap fills from the command line,
//! so a key takes exactly the values its flag takes, and a key left out takes the flag's default), and is then
//! validated by `RunConfig::from_args` as on the command line. An unknown key, or a value of the wrong type, is
//! an error naming the key and its line.

use crate::cli::run_config::RunConfig;
use crate::cli::RunArgs;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The file's shape (checked first, so a typo outside `[run]` is reported with its line).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ExperimentFile {
    name: String,
    #[serde(default)]
    description: String,
    run: toml::Table,
    /// `[sweep]` (a table) or `[[sweep]]` (tables, crossed): read by [`sweeps`].
    sweep: Option<toml::Value>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SweepKeys {
    variable: String,
    values: Vec<toml::Value>,
}

/// The swept variable that stands for the `width` and `height` keys together.
const VIEWPORT: &str = "viewport";

impl SweepKeys {
    /// Whether the sweep sets `key` in every run.
    fn varies(&self, key: &str) -> bool {
        self.sets().contains(&key)
    }

    /// The `[run]` keys the sweep sets.
    fn sets(&self) -> Vec<&str> {
        match self.variable.as_str() {
            VIEWPORT => vec!["width", "height"],
            v => vec![v],
        }
    }
}

/// The file's sweeps: none, the one `[sweep]` table, or the `[[sweep]]` tables in their order. Two sweeps of
/// one key (the viewport counting as width and height) are an error.
fn sweeps(source: &Source, file: &ExperimentFile) -> Result<Vec<SweepKeys>> {
    let tables = match &file.sweep {
        None => return Ok(Vec::new()),
        Some(t @ toml::Value::Table(_)) => vec![t.clone()],
        Some(toml::Value::Array(a)) => a.clone(),
        Some(other) => {
            return Err(source.bad(format!(
                "sweep = {other}: expected a [sweep] table or [[sweep]] tables"
            )))
        }
    };
    let many = tables.len() > 1;
    let mut out: Vec<SweepKeys> = Vec::new();
    for (i, t) in tables.into_iter().enumerate() {
        let at = if many {
            format!("[[sweep]] {}", i + 1)
        } else {
            "[sweep]".to_string()
        };
        let keys = SweepKeys::deserialize(t)
            .map_err(|e| source.bad(format!("{at}: {}", e.message().trim())))?;
        if let Some(earlier) = out.iter().find(|o| keys.sets().iter().any(|k| o.varies(k))) {
            return Err(source.bad(format!(
                "{at}: variable '{}' is swept already (as '{}')",
                keys.variable, earlier.variable
            )));
        }
        out.push(keys);
    }
    if out.is_empty() {
        return Err(source.bad("[[sweep]] has no table".into()));
    }
    Ok(out)
}

/// The keys `[run]` takes: every `lodbench run` flag without its dashes, except `out` (the experiment decides
/// where each run writes).
pub fn run_keys() -> Vec<String> {
    use clap::Args;
    RunArgs::augment_args(clap::Command::new("run"))
        .get_arguments()
        .filter_map(|a| a.get_long().map(str::to_string))
        .filter(|k| k != "out")
        .collect()
}

/// Where a key stands in the file: its line number (1-based) and the line's text.
struct KeyLine<'t> {
    line: usize,
    source: &'t str,
}

/// `key = ...` inside the `[run]` table of `text`, if it is there.
fn key_line<'t>(text: &'t str, key: &str) -> Option<KeyLine<'t>> {
    let mut in_run = false;
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.starts_with('[') {
            in_run = t.trim_start_matches('[').trim_end_matches(']').trim() == "run";
        } else if in_run {
            let k = t.split('=').next().unwrap_or("").trim().trim_matches('"');
            if k == key {
                return Some(KeyLine {
                    line: i + 1,
                    source: t,
                });
            }
        }
    }
    None
}

/// A `[run]` value that does not fit its flag: the key (empty when no key alone is at fault) and serde's message.
#[derive(Debug)]
struct KeyError {
    key: String,
    message: String,
}

/// `table` as `RunArgs`. On a bad value, the key at fault is found by reading each key alone (serde's message
/// for a flattened struct does not name it).
fn run_args(table: &toml::Table) -> std::result::Result<RunArgs, KeyError> {
    RunArgs::deserialize(toml::Value::Table(table.clone())).map_err(|whole| {
        for (k, v) in table {
            let alone = toml::Table::from_iter([(k.clone(), v.clone())]);
            if let Err(e) = RunArgs::deserialize(toml::Value::Table(alone)) {
                return KeyError {
                    key: k.clone(),
                    message: e.message().trim().to_string(),
                };
            }
        }
        KeyError {
            key: String::new(),
            message: whole.message().trim().to_string(),
        }
    })
}

/// `--shard i/n`: the i-th (1-based) of n parts of an experiment's planned runs, by index: run k belongs to
/// shard `k % n + 1` (the way `cargo nextest --partition slice:i/n` deals tests out), so the n shards partition
/// the runs whatever their count.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct Shard {
    pub index: u32,
    pub count: u32,
}

impl Shard {
    /// Parses `i/n` with 1 <= i <= n.
    pub fn parse(text: &str) -> Result<Shard> {
        let bad = || {
            Error::Config(format!(
                "--shard {text}: expected i/n with 1 <= i <= n (for example 2/4)"
            ))
        };
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        let (index, count) = (
            i.trim().parse::<u32>().map_err(|_| bad())?,
            n.trim().parse::<u32>().map_err(|_| bad())?,
        );
        if index == 0 || index > count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }

    /// Whether planned run `k` (0-based) belongs to this shard.
    pub fn owns(&self, k: usize) -> bool {
        k % self.count as usize + 1 == self.index as usize
    }
}

/// One run of the experiment: the swept values, one per sweep (as written in their columns), and its validated
/// configuration.
#[derive(Debug, Clone, Serialize)]
pub struct PlannedRun {
    pub values: Vec<String>,
    pub config: RunConfig,
}

/// `variable=value` of each sweep, joined by `+` (how messages and run folders name a planned run).
pub fn sweep_label(variables: &[String], values: &[String]) -> String {
    variables
        .iter()
        .zip(values)
        .map(|(var, v)| format!("{var}={v}"))
        .collect::<Vec<_>>()
        .join("+")
}

#[derive(Debug, Clone, Serialize)]
pub struct Experiment {
    pub name: String,
    pub description: String,
    pub file: PathBuf,
    /// The swept variables (an extra CSV column each, in this order), none without a sweep.
    pub variables: Vec<String>,
    pub runs: Vec<PlannedRun>,
}

fn value_text(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => s.clone(),
        toml::Value::Array(a) => a.iter().map(value_text).collect::<Vec<_>>().join(","),
        other => other.to_string(),
    }
}

/// The file being read, for its errors: each names the file, and the line where it can.
struct Source {
    name: String,
    text: String,
}

impl Source {
    fn bad(&self, problem: String) -> Error {
        Error::Config(format!("experiment {}: {problem}", self.name))
    }

    /// "line N (`the line`): what is wrong", so the key is named whatever the error.
    fn at(&self, e: &toml::de::Error) -> String {
        let text = &self.text;
        match e.span() {
            Some(span) => {
                let line = text[..span.start.min(text.len())].matches('\n').count() + 1;
                let source = text.lines().nth(line - 1).unwrap_or("").trim();
                format!("line {line} (`{source}`): {}", e.message())
            }
            None => e.message().to_string(),
        }
    }

    /// "line N (`the line`): " of `key` in `[run]`, or nothing when the file does not set it.
    fn where_is(&self, key: &str) -> String {
        match key_line(&self.text, key) {
            Some(k) => format!("line {} (`{}`): ", k.line, k.source),
            None => String::new(),
        }
    }
}

/// One run's `[run]` table, before it is checked: the swept values (one per sweep, none without) and the keys.
struct Variant {
    values: Vec<String>,
    table: toml::Table,
}

impl Experiment {
    /// Reads and validates an experiment file: its shape, then every run's flags as `lodbench run` would.
    pub fn load(path: &Path) -> Result<Experiment> {
        Self::load_with(path, &[])
    }

    /// [`Experiment::load`] with `--set KEY=VALUE` overrides of `[run]` keys (VALUE in TOML syntax, or a bare
    /// word taken as a string), applied before the sweep, so they hold in every run; a key the sweep varies
    /// cannot be set.
    pub fn load_with(path: &Path, overrides: &[String]) -> Result<Experiment> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        Self::parse(path, text, overrides)
    }

    /// [`Experiment::load_with`] of the text of the file at `path` (named in errors, and the experiment's
    /// `file`).
    pub fn parse(path: &Path, text: String, overrides: &[String]) -> Result<Experiment> {
        let source = Source {
            name: path.display().to_string(),
            text,
        };
        let mut file: ExperimentFile =
            toml::from_str(&source.text).map_err(|e| source.bad(source.at(&e)))?;
        let keys = run_keys();
        let sweeps = sweeps(&source, &file)?;
        for o in overrides {
            apply_override(&source, &mut file, (&keys, &sweeps), o)?;
        }
        check_run_keys(&source, &file, &keys)?;
        let variants = variants(&source, &file, &keys, &sweeps)?;
        let variables: Vec<String> = sweeps.iter().map(|s| s.variable.clone()).collect();
        let runs = variants
            .into_iter()
            .map(|v| plan_run(&source, (&sweeps, &variables), v))
            .collect::<Result<Vec<_>>>()?;
        Ok(Experiment {
            name: file.name,
            description: file.description,
            file: path.to_path_buf(),
            variables,
            runs,
        })
    }
}

/// Applies `--set KEY=VALUE` (`o`) to the file's `[run]` table.
fn apply_override(
    source: &Source,
    file: &mut ExperimentFile,
    (keys, sweeps): (&[String], &[SweepKeys]),
    o: &str,
) -> Result<()> {
    let Some((key, value)) = o.split_once('=') else {
        return Err(source.bad(format!("--set {o}: expected KEY=VALUE")));
    };
    let key = key.trim();
    if !keys.iter().any(|k| k == key) {
        return Err(source.bad(format!(
            "--set {o}: '{key}' is not a [run] key (the keys: {})",
            keys.join(", ")
        )));
    }
    if sweeps.iter().any(|sw| sw.varies(key)) {
        return Err(source.bad(format!("--set {o}: '{key}' is the swept variable")));
    }
    let value = value.trim();
    let parsed = toml::from_str::<toml::Table>(&format!("v = {value}"))
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(value.to_string()));
    file.run.insert(key.to_string(), parsed);
    Ok(())
}

/// Every key of `[run]` is a flag of `lodbench run`.
fn check_run_keys(source: &Source, file: &ExperimentFile, keys: &[String]) -> Result<()> {
    match file.run.keys().find(|key| !keys.contains(key)) {
        Some(key) => Err(source.bad(format!(
            "{}[run] has no key '{key}' (the keys are `lodbench run`'s flags without dashes, \
             except out: {})",
            source.where_is(key),
            keys.join(", ")
        ))),
        None => Ok(()),
    }
}

/// The `[run]` table of each planned run: one without a sweep, else one per combination of the sweeps' values
/// (the first sweep's varying slowest).
fn variants(
    source: &Source,
    file: &ExperimentFile,
    keys: &[String],
    sweeps: &[SweepKeys],
) -> Result<Vec<Variant>> {
    let mut variants = vec![Variant {
        values: Vec::new(),
        table: file.run.clone(),
    }];
    for sweep in sweeps {
        let var = sweep.variable.as_str();
        if var != VIEWPORT && !keys.iter().any(|k| k == var) {
            return Err(source.bad(format!(
                "[sweep] variable '{var}' is not a [run] key or viewport (the keys: {})",
                keys.join(", ")
            )));
        }
        if sweep.values.is_empty() {
            return Err(source.bad(format!("[sweep] {var}: values is empty")));
        }
        let mut crossed = Vec::new();
        for base in &variants {
            for v in &sweep.values {
                let mut table = base.table.clone();
                if var == VIEWPORT {
                    let pair = v.as_array().filter(|a| a.len() == 2);
                    let Some(pair) = pair else {
                        return Err(source
                            .bad(format!("[sweep] viewport value {v} is not [width, height]")));
                    };
                    table.insert("width".into(), pair[0].clone());
                    table.insert("height".into(), pair[1].clone());
                } else {
                    table.insert(var.to_string(), v.clone());
                }
                let mut values = base.values.clone();
                values.push(value_text(v));
                crossed.push(Variant { values, table });
            }
        }
        variants = crossed;
    }
    Ok(variants)
}

/// One planned run: its table read as `lodbench run`'s flags and validated as on the command line.
fn plan_run(
    source: &Source,
    (sweeps, variables): (&[SweepKeys], &[String]),
    v: Variant,
) -> Result<PlannedRun> {
    let swept = |key: &str| sweeps.iter().zip(&v.values).find(|(s, _)| s.varies(key));
    let args = run_args(&v.table).map_err(|e| match swept(&e.key) {
        Some((s, value)) => source.bad(format!(
            "[sweep] variable '{}' with value {value}: {}",
            s.variable, e.message
        )),
        None if e.key.is_empty() && !v.values.is_empty() => source.bad(format!(
            "[sweep] values {}: {}",
            sweep_label(variables, &v.values),
            e.message
        )),
        None => source.bad(format!(
            "{}[run] {}: {}",
            source.where_is(&e.key),
            e.key,
            e.message
        )),
    })?;
    let config = RunConfig::from_args(&args).map_err(|e| source.bad(e.to_string()))?;
    Ok(PlannedRun {
        values: v.values,
        config,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    fn write(dir: &Path, text: &str) -> PathBuf {
        let p = dir.join("e.toml");
        std::fs::write(&p, text).unwrap();
        p
    }

    /// Every run is in exactly one shard, for 1 to 7 shards and 0 to 20 runs, and the shards are as even as
    /// dealing makes them.
    #[test]
    fn shards_partition_the_runs() {
        for runs in 0..=20usize {
            for n in 1..=7u32 {
                let shards: Vec<Shard> = (1..=n).map(|index| Shard { index, count: n }).collect();
                for k in 0..runs {
                    assert_eq!(
                        shards.iter().filter(|s| s.owns(k)).count(),
                        1,
                        "{k} of {runs}, n {n}"
                    );
                }
                let sizes: Vec<usize> = shards
                    .iter()
                    .map(|s| (0..runs).filter(|&k| s.owns(k)).count())
                    .collect();
                let (lo, hi) = (sizes.iter().min().unwrap(), sizes.iter().max().unwrap());
                assert!(hi - lo <= 1, "{sizes:?}");
            }
        }
        assert_eq!(Shard::parse("2/4").unwrap(), Shard { index: 2, count: 4 });
        for bad in ["0/3", "4/3", "3", "a/b", "1/0", "-1/2"] {
            let e = Shard::parse(bad).unwrap_err().to_string();
            assert!(e.contains("--shard") && e.contains(bad), "{e}");
        }
    }

    /// `--set` overrides a [run] key in every run, takes TOML values or bare words, and refuses unknown keys and
    /// the swept variable.
    #[test]
    fn set_overrides_run_keys() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(
            dir.path(),
            "name = \"x\"\n[run]\nscene = [\"bunny-sweep\"]\nframes = 50\n[sweep]\nvariable = \"band\"\nvalues = [0.02, 0.05]\n",
        );
        let e = Experiment::load_with(&p, &["frames=7".into(), "fade=time".into()]).unwrap();
        assert!(e.runs.iter().all(|r| r.config.scene.frames == Some(7)));
        assert!(e
            .runs
            .iter()
            .all(|r| r.config.scene.schedule.fade == crate::scene::schedule::FadeMode::Time));
        for (bad, needle) in [
            ("framez=7", "framez"),
            ("band=0.1", "swept"),
            ("frames", "KEY=VALUE"),
        ] {
            let msg = Experiment::load_with(&p, &[bad.into()])
                .unwrap_err()
                .to_string();
            assert!(msg.contains(needle), "{bad}: {msg}");
        }
    }

    #[test]
    fn shipped_experiments_validate() {
        // The paper-scale files and their CPU-scale companions in cpu/.
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/experiments");
        let mut n = 0;
        for dir in [root.clone(), root.join("cpu")] {
            for entry in std::fs::read_dir(dir).unwrap() {
                let p = entry.unwrap().path();
                if p.extension().is_some_and(|e| e == "toml") {
                    let e = Experiment::load(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
                    assert!(!e.runs.is_empty());
                    n += 1;
                }
            }
        }
        assert!(n >= 8, "{n} experiment files");
    }

    #[test]
    fn typos_name_the_key_and_the_line() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(
            dir.path(),
            "name = \"x\"\n[run]\nscene = [\"bunny-sweep\"]\nwidht = 64\n",
        );
        let msg = Experiment::load(&p).unwrap_err().to_string();
        assert!(msg.contains("widht") && msg.contains("line 4"), "{msg}");
        let p = write(
            dir.path(),
            "name = \"x\"\n[run]\nscene = [\"bunny-swep\"]\n",
        );
        let msg = Experiment::load(&p).unwrap_err().to_string();
        assert!(
            msg.contains("bunny-swep") && msg.contains("bunny-sweep"),
            "{msg}"
        );
        let p = write(
            dir.path(),
            "name = \"x\"\n[run]\n[sweep]\nvariable = \"widht\"\nvalues = [1]\n",
        );
        let msg = Experiment::load(&p).unwrap_err().to_string();
        assert!(msg.contains("widht"), "{msg}");
        let p = write(dir.path(), "name = \"x\"\n[run]\nwidth = \"wide\"\n");
        let msg = Experiment::load(&p).unwrap_err().to_string();
        assert!(msg.contains("width") && msg.contains("line 3"), "{msg}");
        let p = write(dir.path(), "name = \"x\"\n[run\n");
        assert!(Experiment::load(&p)
            .unwrap_err()
            .to_string()
            .contains("line 2"));
    }

    #[test]
    fn every_run_key_is_read() {
        // A key clap knows but serde named differently would be ignored silently: each key with a value of no
        // flag's type (a table) must fail, naming that key.
        for key in run_keys() {
            let t = toml::Table::from_iter([(key.clone(), toml::Value::Table(toml::Table::new()))]);
            let e = run_args(&t).expect_err(&key);
            assert_eq!(e.key, key);
        }
        // And a key set in a file equals the flag on the command line.
        let t: toml::Table = toml::from_str(
            "scene = [\"bunny-grid\"]\ncount = [5, 7]\nfov = 50\ncamera = \"orbit\"\nvis-texture = \"radial\"\n\
             correspondence = \"surface\"\ndump-frames = true\nmetrics = [\"rmse\", \"flip\"]\nseed = 9",
        )
        .unwrap();
        let from_file = run_args(&t).unwrap();
        let from_flags = match crate::cli::Cli::try_parse_from([
            "lodbench",
            "run",
            "--scene",
            "bunny-grid",
            "--count",
            "5,7",
            "--fov",
            "50",
            "--camera",
            "orbit",
            "--vis-texture",
            "radial",
            "--correspondence",
            "surface",
            "--dump-frames",
            "--metrics",
            "rmse,flip",
            "--seed",
            "9",
        ])
        .unwrap()
        .command
        {
            crate::cli::Command::Run(r) => r,
            _ => unreachable!(),
        };
        assert_eq!(format!("{from_file:?}"), format!("{from_flags:?}"));
    }

    #[test]
    fn sweep_plans_one_run_per_value() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(
            dir.path(),
            "name = \"v\"\n[run]\nscene = [\"bunny-sweep\"]\nmethod = [\"discrete\"]\nframes = 4\n\
             [sweep]\nvariable = \"viewport\"\nvalues = [[64, 48], [96, 72]]\n",
        );
        let e = Experiment::load(&p).unwrap();
        assert_eq!(e.variables, ["viewport"]);
        let sizes: Vec<_> = e
            .runs
            .iter()
            .map(|r| (r.config.scene.width, r.config.scene.height))
            .collect();
        assert_eq!(sizes, vec![(Some(64), Some(48)), (Some(96), Some(72))]);
        assert_eq!(e.runs[1].values, ["96,72"]);
    }

    /// `[[sweep]]` tables cross: one run per combination, the first table's variable varying slowest, each run
    /// with both values; a variable swept twice, or set with `--set`, is refused.
    #[test]
    fn two_sweeps_cross() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(
            dir.path(),
            "name = \"x\"\n[run]\nscene = [\"bunny-sweep\"]\nframes = 4\n\
             [[sweep]]\nvariable = \"pixel-error\"\nvalues = [1, 2]\n\
             [[sweep]]\nvariable = \"band\"\nvalues = [0.02, 0.05, 0.1]\n",
        );
        let e = Experiment::load(&p).unwrap();
        assert_eq!(e.variables, ["pixel-error", "band"]);
        let planned: Vec<(Vec<String>, Option<f32>, f32)> = e
            .runs
            .iter()
            .map(|r| {
                (
                    r.values.clone(),
                    r.config.scene.pixel_error,
                    r.config.scene.schedule.band,
                )
            })
            .collect();
        let want = [
            (1.0, 0.02),
            (1.0, 0.05),
            (1.0, 0.1),
            (2.0, 0.02),
            (2.0, 0.05),
            (2.0, 0.1),
        ];
        assert_eq!(planned.len(), want.len());
        for ((values, pe, band), (want_pe, want_band)) in planned.iter().zip(want) {
            assert_eq!(*pe, Some(want_pe), "{values:?}");
            assert_eq!(*band, want_band, "{values:?}");
            assert_eq!(values, &[format!("{want_pe}"), format!("{want_band}")]);
        }
        assert_eq!(
            sweep_label(&e.variables, &e.runs[4].values),
            "pixel-error=2+band=0.05"
        );
        let msg = Experiment::load_with(&p, &["band=0.3".into()])
            .unwrap_err()
            .to_string();
        assert!(msg.contains("swept"), "{msg}");
        for (text, needle) in [
            ("[[sweep]]\nvariable = \"band\"\nvalues = [0.1]\n[[sweep]]\nvariable = \"band\"\nvalues = [0.2]\n", "swept already"),
            ("[[sweep]]\nvariable = \"viewport\"\nvalues = [[64, 48]]\n[[sweep]]\nvariable = \"width\"\nvalues = [32]\n", "swept already"),
            ("[[sweep]]\nvariable = \"band\"\nvalues = []\n", "empty"),
            ("[[sweep]]\nvariable = \"band\"\nvalus = [1]\n", "valus"),
            ("[[sweep]]\nvariable = \"band\"\nvalues = [0.1]\n[[sweep]]\nvariable = \"pixel-error\"\nvalues = [\"big\"]\n", "pixel-error"),
        ] {
            let p = write(
                dir.path(),
                &format!("name = \"x\"\n[run]\nscene = [\"bunny-sweep\"]\n{text}"),
            );
            let msg = Experiment::load(&p).unwrap_err().to_string();
            assert!(msg.contains(needle), "{text}: {msg}");
        }
    }
}
