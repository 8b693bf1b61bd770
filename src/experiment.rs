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
//! The `[run]` table is turned into `lodbench run` arguments and validated exactly as on the command line.
//! Unknown keys are errors naming the key and the line.

use crate::cli::{Cli, Command};
use crate::config::RunConfig;
use crate::error::{Error, Result};
use clap::Parser;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The file's schema (checked first, so a typo is reported with its line).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ExperimentSchema {
    #[allow(dead_code)]
    name: String,
    #[allow(dead_code)]
    #[serde(default)]
    description: String,
    #[allow(dead_code)]
    run: RunKeys,
    #[allow(dead_code)]
    sweep: Option<SweepKeys>,
}

#[allow(dead_code)]
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
struct RunKeys {
    scene: Option<Vec<String>>,
    method: Option<Vec<String>>,
    profile: Option<String>,
    width: Option<u32>,
    height: Option<u32>,
    frames: Option<u32>,
    warmup: Option<u32>,
    seed: Option<u64>,
    count: Option<Vec<u32>>,
    mesh: Option<String>,
    pixel_error: Option<f64>,
    switch_distances: Option<Vec<f64>>,
    fov: Option<f64>,
    fade: Option<String>,
    band: Option<f64>,
    fade_frames: Option<u32>,
    hysteresis: Option<f64>,
    noise: Option<String>,
    correspondence: Option<String>,
    vis_texture: Option<String>,
    fsi_check: Option<String>,
    camera: Option<String>,
    metrics: Option<Vec<String>>,
    adapter: Option<String>,
    dump_frames: Option<bool>,
    dump_every: Option<u32>,
    dump_transitions: Option<bool>,
}

#[allow(dead_code)]
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SweepKeys {
    variable: String,
    values: Vec<toml::Value>,
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

fn args_of(run: &toml::Table) -> Vec<String> {
    let mut argv = vec!["lodbench".to_string(), "run".to_string()];
    for (k, v) in run {
        match v {
            toml::Value::Boolean(true) => argv.push(format!("--{k}")),
            toml::Value::Boolean(false) => {}
            _ => {
                argv.push(format!("--{k}"));
                argv.push(value_text(v));
            }
        }
    }
    argv
}

impl Experiment {
    /// Reads and validates an experiment file: schema, then every run's flags as `lodbench run` would.
    pub fn load(path: &Path) -> Result<Experiment> {
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
        toml::from_str::<ExperimentSchema>(&text).map_err(|e| bad(at(&e)))?;
        let doc: toml::Table = toml::from_str(&text).map_err(|e| bad(at(&e)))?;
        let get_str = |k: &str| {
            doc.get(k)
                .and_then(|v| v.as_str())
                .unwrap_or("")
                .to_string()
        };
        let run = doc
            .get("run")
            .and_then(|v| v.as_table())
            .cloned()
            .unwrap_or_default();
        let sweep = doc.get("sweep").and_then(|v| v.as_table());
        let mut variants: Vec<(Option<String>, toml::Table)> = Vec::new();
        let variable = match sweep {
            None => {
                variants.push((None, run.clone()));
                None
            }
            Some(s) => {
                let var = s
                    .get("variable")
                    .and_then(|v| v.as_str())
                    .unwrap_or("")
                    .to_string();
                let values = s
                    .get("values")
                    .and_then(|v| v.as_array())
                    .cloned()
                    .unwrap_or_default();
                if values.is_empty() {
                    return Err(bad("[sweep] values is empty".into()));
                }
                for v in &values {
                    let mut t = run.clone();
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
                        // Reuse the schema to check the variable is a [run] key.
                        let probe = format!("[run]\n{var} = {v}\n");
                        #[derive(Deserialize)]
                        #[serde(deny_unknown_fields)]
                        struct Probe {
                            #[allow(dead_code)]
                            run: RunKeys,
                        }
                        toml::from_str::<Probe>(&probe).map_err(|e| {
                            bad(format!(
                                "[sweep] variable '{var}' with value {v}: {}",
                                e.message()
                            ))
                        })?;
                        t.insert(var.clone(), v.clone());
                    }
                    variants.push((Some(value_text(v)), t));
                }
                Some(var)
            }
        };
        let mut runs = Vec::new();
        for (value, table) in variants {
            let args = match Cli::try_parse_from(args_of(&table)) {
                Ok(Cli {
                    command: Command::Run(r),
                }) => r,
                Ok(_) => unreachable!("args_of always builds a run command"),
                Err(e) => {
                    let msg = e.to_string();
                    let first = msg
                        .lines()
                        .next()
                        .unwrap_or("")
                        .trim_start_matches("error: ");
                    return Err(bad(format!("[run] {first}")));
                }
            };
            let config = RunConfig::from_args(&args).map_err(|e| bad(e.to_string()))?;
            runs.push(PlannedRun { value, config });
        }
        Ok(Experiment {
            name: get_str("name"),
            description: get_str("description"),
            file: path.to_path_buf(),
            variable,
            runs,
        })
    }

    /// Runs every planned run into `out/runs/<variable>=<value>/` (or `out/` without a sweep), then writes
    /// `out/frames.csv` and `out/summary.csv` with the swept variable as the first column, and
    /// `out/experiment.json`.
    pub fn run(&self, out: &Path) -> Result<Vec<PathBuf>> {
        crate::runner::prepare_output(out)?;
        std::fs::write(
            out.join("experiment.json"),
            serde_json::to_string_pretty(self)? + "\n",
        )
        .map_err(|e| Error::io(out.join("experiment.json"), e))?;
        let mut folders = Vec::new();
        for r in &self.runs {
            let folder = match (&self.variable, &r.value) {
                (Some(var), Some(v)) => out
                    .join("runs")
                    .join(format!("{var}={}", v.replace(',', "x"))),
                _ => out.to_path_buf(),
            };
            let mut cfg = r.config.clone();
            cfg.out = Some(folder.clone());
            crate::runner::run(&cfg)?;
            folders.push(folder);
        }
        if let Some(var) = &self.variable {
            for file in ["frames.csv", "summary.csv"] {
                merge(out, file, var, &self.runs, &folders)?;
            }
        }
        Ok(folders)
    }
}

/// Concatenates `file` of each run folder with the swept value as a first column.
fn merge(
    out: &Path,
    file: &str,
    var: &str,
    runs: &[PlannedRun],
    folders: &[PathBuf],
) -> Result<()> {
    let path = out.join(file);
    let mut w = csv::Writer::from_path(&path)?;
    for (i, (run, folder)) in runs.iter().zip(folders).enumerate() {
        let mut r = csv::Reader::from_path(folder.join(file))?;
        if i == 0 {
            let mut header = csv::StringRecord::from(vec![var]);
            header.extend(r.headers()?.iter());
            w.write_record(&header)?;
        }
        for rec in r.records() {
            let mut row = csv::StringRecord::from(vec![run.value.clone().unwrap_or_default()]);
            row.extend(rec?.iter());
            w.write_record(&row)?;
        }
    }
    w.flush().map_err(|e| Error::io(&path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, text: &str) -> PathBuf {
        let p = dir.join("e.toml");
        std::fs::write(&p, text).unwrap();
        p
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
