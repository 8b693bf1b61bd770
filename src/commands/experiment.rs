//! `lodbench experiment FILE.toml`: a sweep described in a file, written to one results folder with a column
//! per swept variable.
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
//! The `[run]` table deserialises straight into `RunArgs` (the same struct clap fills from the command line,
//! so a key takes exactly the values its flag takes, and a key left out takes the flag's default), and is then
//! validated by `RunConfig::from_args` as on the command line. An unknown key, or a value of the wrong type, is
//! an error naming the key and its line.

use crate::cli::config::RunConfig;
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
    sweep: Option<SweepKeys>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SweepKeys {
    variable: String,
    values: Vec<toml::Value>,
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

/// Line number (1-based) and text of `key = ...` inside the `[run]` table of `text`, if it is there.
fn key_line<'t>(text: &'t str, key: &str) -> Option<(usize, &'t str)> {
    let mut in_run = false;
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.starts_with('[') {
            in_run = t.trim_start_matches('[').trim_end_matches(']').trim() == "run";
        } else if in_run {
            let k = t.split('=').next().unwrap_or("").trim().trim_matches('"');
            if k == key {
                return Some((i + 1, t));
            }
        }
    }
    None
}

/// `table` as `RunArgs`. On a bad value, the key at fault is found by reading each key alone (serde's message
/// for a flattened struct does not name it).
fn run_args(table: &toml::Table) -> std::result::Result<RunArgs, (String, String)> {
    RunArgs::deserialize(toml::Value::Table(table.clone())).map_err(|whole| {
        for (k, v) in table {
            let alone = toml::Table::from_iter([(k.clone(), v.clone())]);
            if let Err(e) = RunArgs::deserialize(toml::Value::Table(alone)) {
                return (k.clone(), e.message().trim().to_string());
            }
        }
        (String::new(), whole.message().trim().to_string())
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

/// How `Experiment::run_with` runs the plan.
#[derive(Debug, Clone, Copy, Default)]
pub struct RunOptions {
    /// Only this shard's runs.
    pub shard: Option<Shard>,
    /// Skip the runs whose run.json says complete with the planned configuration.
    pub resume: bool,
}

/// What `experiment.json` records: the experiment (every planned run), the shard this folder holds, and the
/// version that made it (`lodbench merge` checks all three).
#[derive(Debug, Serialize)]
struct ExperimentRecord<'a> {
    #[serde(flatten)]
    experiment: &'a Experiment,
    shard: Option<Shard>,
    lodbench_version: &'static str,
    git_commit: Option<&'static str>,
}

/// One run of the experiment: the swept value (as written in the column) and its validated configuration.
#[derive(Debug, Clone, Serialize)]
pub struct PlannedRun {
    pub value: Option<String>,
    pub config: RunConfig,
}

#[derive(Debug, Clone, Serialize)]
pub struct Experiment {
    pub name: String,
    pub description: String,
    pub file: PathBuf,
    /// The swept variable (the extra CSV column), if any.
    pub variable: Option<String>,
    pub runs: Vec<PlannedRun>,
}

fn value_text(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => s.clone(),
        toml::Value::Array(a) => a.iter().map(value_text).collect::<Vec<_>>().join(","),
        other => other.to_string(),
    }
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
        let name = path.display().to_string();
        let bad = |problem: String| Error::Config(format!("experiment {name}: {problem}"));
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        // "line N (`the line`): what is wrong", so the key is named whatever the error.
        let at = |e: &toml::de::Error| match e.span() {
            Some(span) => {
                let line = text[..span.start.min(text.len())].matches('\n').count() + 1;
                let source = text.lines().nth(line - 1).unwrap_or("").trim();
                format!("line {line} (`{source}`): {}", e.message())
            }
            None => e.message().to_string(),
        };
        let mut file: ExperimentFile = toml::from_str(&text).map_err(|e| bad(at(&e)))?;
        let keys = run_keys();
        for o in overrides {
            let Some((key, value)) = o.split_once('=') else {
                return Err(bad(format!("--set {o}: expected KEY=VALUE")));
            };
            let key = key.trim();
            if !keys.iter().any(|k| k == key) {
                return Err(bad(format!(
                    "--set {o}: '{key}' is not a [run] key (the keys: {})",
                    keys.join(", ")
                )));
            }
            if file.sweep.as_ref().is_some_and(|sw| {
                sw.variable == key
                    || (sw.variable == "viewport" && (key == "width" || key == "height"))
            }) {
                return Err(bad(format!("--set {o}: '{key}' is the swept variable")));
            }
            let value = value.trim();
            let parsed = toml::from_str::<toml::Table>(&format!("v = {value}"))
                .ok()
                .and_then(|mut t| t.remove("v"))
                .unwrap_or_else(|| toml::Value::String(value.to_string()));
            file.run.insert(key.to_string(), parsed);
        }
        let where_is = |key: &str| match key_line(&text, key) {
            Some((line, source)) => format!("line {line} (`{source}`): "),
            None => String::new(),
        };
        for key in file.run.keys() {
            if !keys.contains(key) {
                return Err(bad(format!(
                    "{}[run] has no key '{key}' (the keys are `lodbench run`'s flags without dashes, \
                     except out: {})",
                    where_is(key),
                    keys.join(", ")
                )));
            }
        }
        let mut variants: Vec<(Option<String>, toml::Table)> = Vec::new();
        let variable = match &file.sweep {
            None => {
                variants.push((None, file.run.clone()));
                None
            }
            Some(sweep) => {
                let var = sweep.variable.as_str();
                if var != "viewport" && !keys.iter().any(|k| k == var) {
                    return Err(bad(format!(
                        "[sweep] variable '{var}' is not a [run] key or viewport (the keys: {})",
                        keys.join(", ")
                    )));
                }
                if sweep.values.is_empty() {
                    return Err(bad("[sweep] values is empty".into()));
                }
                for v in &sweep.values {
                    let mut t = file.run.clone();
                    if var == "viewport" {
                        let pair = v.as_array().filter(|a| a.len() == 2);
                        let Some(pair) = pair else {
                            return Err(bad(format!(
                                "[sweep] viewport value {v} is not [width, height]"
                            )));
                        };
                        t.insert("width".into(), pair[0].clone());
                        t.insert("height".into(), pair[1].clone());
                    } else {
                        t.insert(var.to_string(), v.clone());
                    }
                    variants.push((Some(value_text(v)), t));
                }
                Some(var.to_string())
            }
        };
        let mut runs = Vec::new();
        for (value, table) in variants {
            let args = run_args(&table).map_err(|(key, message)| match &value {
                Some(v) if Some(key.as_str()) == variable.as_deref() || key.is_empty() => bad(
                    format!("[sweep] variable '{key}' with value {v}: {message}"),
                ),
                _ => bad(format!("{}[run] {key}: {message}", where_is(&key))),
            })?;
            let config = RunConfig::from_args(&args).map_err(|e| bad(e.to_string()))?;
            runs.push(PlannedRun { value, config });
        }
        Ok(Experiment {
            name: file.name,
            description: file.description,
            file: path.to_path_buf(),
            variable,
            runs,
        })
    }

    /// Runs every planned run into `out/runs/<variable>=<value>/` (or `out/` without a sweep), then writes
    /// `out/frames.csv` and `out/summary.csv` with the swept variable as the first column, and
    /// `out/experiment.json`.
    pub fn run(&self, out: &Path) -> Result<Vec<PathBuf>> {
        self.run_with(out, &RunOptions::default())
    }

    /// The folder planned run `k` writes to under `out`.
    pub fn run_folder(&self, out: &Path, k: usize) -> PathBuf {
        run_folder_of(out, self.variable.as_deref(), self.runs[k].value.as_deref())
    }

    /// The planned runs' indices `shard` holds (all without one).
    pub fn indices(&self, shard: Option<Shard>) -> Vec<usize> {
        (0..self.runs.len())
            .filter(|&k| shard.is_none_or(|s| s.owns(k)))
            .collect()
    }

    /// [`Experiment::run`] with `options`: only the shard's runs, and with `resume` none whose run.json says
    /// complete with the same configuration. The merged CSVs cover the runs this folder holds. Returns the run
    /// folders of this shard (the skipped ones too).
    pub fn run_with(&self, out: &Path, options: &RunOptions) -> Result<Vec<PathBuf>> {
        crate::commands::run::prepare_output(out)?;
        let record = ExperimentRecord {
            experiment: self,
            shard: options.shard,
            lodbench_version: env!("CARGO_PKG_VERSION"),
            git_commit: option_env!("LODBENCH_GIT_COMMIT").filter(|s| !s.is_empty()),
        };
        std::fs::write(
            out.join("experiment.json"),
            serde_json::to_string_pretty(&record)? + "\n",
        )
        .map_err(|e| Error::io(out.join("experiment.json"), e))?;
        let mine = self.indices(options.shard);
        let mut folders = Vec::new();
        for &k in &mine {
            let folder = self.run_folder(out, k);
            let mut cfg = self.runs[k].config.clone();
            cfg.out = Some(folder.clone());
            if options.resume && completed(&folder, &cfg) {
                eprintln!("{}: complete, skipped (--resume)", folder.display());
            } else {
                crate::commands::run::run(&cfg)?;
            }
            folders.push(folder);
        }
        if let Some(var) = &self.variable {
            for file in RUN_CSVS {
                let parts: Vec<(Vec<String>, PathBuf)> = mine
                    .iter()
                    .zip(&folders)
                    .map(|(&k, f)| {
                        (
                            vec![self.runs[k].value.clone().unwrap_or_default()],
                            f.join(file),
                        )
                    })
                    .collect();
                concat_csv(&out.join(file), &[var.as_str()], &parts)?;
            }
        }
        Ok(folders)
    }
}

/// Whether `folder` holds a complete run of `cfg`: its run.json says `complete` and records the same
/// configuration.
fn completed(folder: &Path, cfg: &RunConfig) -> bool {
    let Ok(text) = std::fs::read_to_string(folder.join("run.json")) else {
        return false;
    };
    let Ok(run) = serde_json::from_str::<serde_json::Value>(&text) else {
        return false;
    };
    // Compared as written: an f32 flag reads back from its text as another f64 than it converts to.
    let planned = serde_json::to_string(cfg)
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok());
    run["status"] == "complete"
        && planned.is_some_and(|c| c == run["config"])
        && ["frames.csv", "summary.csv"]
            .iter()
            .all(|f| folder.join(f).is_file())
}

/// The CSV files of a run folder that an experiment, and `lodbench merge`, join across runs.
pub const RUN_CSVS: [&str; 4] = ["frames.csv", "summary.csv", "transitions.csv", "rounds.csv"];

/// The folder of the run with swept `value` of `variable` under `out`: `runs/<variable>=<value>/` (a comma of a
/// value as `x`), or `out` itself without a sweep.
pub fn run_folder_of(out: &Path, variable: Option<&str>, value: Option<&str>) -> PathBuf {
    match (variable, value) {
        (Some(var), Some(v)) => out
            .join("runs")
            .join(format!("{var}={}", v.replace(',', "x"))),
        _ => out.to_path_buf(),
    }
}

/// Writes `path`: under `lead_header` and the parts' own header, each part's CSV rows after its lead values. A
/// part whose file is empty (a run without rows of it, e.g. no transition on its path, writes no header) adds
/// nothing.
pub(crate) fn concat_csv(
    path: &Path,
    lead_header: &[&str],
    parts: &[(Vec<String>, PathBuf)],
) -> Result<()> {
    let mut w = csv::Writer::from_path(path)?;
    let mut header_written = false;
    for (lead, source) in parts {
        let mut r = csv::Reader::from_path(source)?;
        if r.headers()?.is_empty() {
            continue;
        }
        if !header_written {
            let mut header = csv::StringRecord::from(lead_header.to_vec());
            header.extend(r.headers()?.iter());
            w.write_record(&header)?;
            header_written = true;
        }
        for rec in r.records() {
            let mut row = csv::StringRecord::from(lead.clone());
            row.extend(rec?.iter());
            w.write_record(&row)?;
        }
    }
    w.flush().map_err(|e| Error::io(path, e))
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
            let (k, _) = run_args(&t).expect_err(&key);
            assert_eq!(k, key);
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
        assert_eq!(e.variable.as_deref(), Some("viewport"));
        let sizes: Vec<_> = e
            .runs
            .iter()
            .map(|r| (r.config.scene.width, r.config.scene.height))
            .collect();
        assert_eq!(sizes, vec![(Some(64), Some(48)), (Some(96), Some(72))]);
        assert_eq!(e.runs[1].value.as_deref(), Some("96,72"));
    }
}
