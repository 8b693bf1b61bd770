//! `lodbench merge DIR... --out DIR`: one results folder from the folders of an experiment's shards (or of its
//! runs made on different machines), refusing what does not fit.
//!
//! Every input is an experiment folder (`lodbench experiment ... --out DIR`, with or without `--shard`): its
//! `experiment.json` names the experiment and every planned run; its runs lie in `runs/<variable>=<value>/` (or
//! the folder itself without a sweep). The merge checks, before writing anything:
//! - every input is the same experiment: the same name, swept variable and planned runs (flags included, but
//!   `--adapter`, which may point each shard at its own GPU);
//! - every run was made by the same lodbench (`lodbench_version` and `git_commit` of its run.json);
//! - no run is in two inputs (a duplicate), and every planned run is in one (a missing run);
//! - every run is complete: a failed or interrupted one is refused, or with `--allow-partial` left out (as are
//!   missing runs), and listed either way.
//!
//! The output holds a copy of each run folder under `runs/`, `frames.csv`, `summary.csv`, `transitions.csv` and
//! `rounds.csv` with the swept variable (if any) and `adapter` (the run's adapter name) as the first columns,
//! and `experiment.json` with `merged_from`. Nothing is averaged: runs on different adapters stay apart by the
//! `adapter` column.

use crate::error::{Error, Result};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// What a merge did.
#[derive(Debug, Clone)]
pub struct MergeSummary {
    pub runs: usize,
    /// Planned runs left out (`--allow-partial`): `value: why`.
    pub left_out: Vec<String>,
}

fn bad(problem: String) -> Error {
    Error::Config(format!("merge: {problem}"))
}

fn read_json(path: &Path) -> Result<Value> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    serde_json::from_str(&text)
        .map_err(|e| bad(format!("{} is not valid JSON ({e})", path.display())))
}

/// One planned run found in an input.
struct Found {
    input: PathBuf,
    folder: PathBuf,
    run: Value,
}

/// The folder planned run `value` of `variable` has under `dir` (as `Experiment::run_folder` names it).
fn run_folder(dir: &Path, variable: &Value, value: &Value) -> PathBuf {
    crate::commands::experiment::run_folder_of(dir, variable.as_str(), value.as_str())
}

/// Merges the experiment folders `inputs` into `out`; see the module docs.
pub fn merge(inputs: &[PathBuf], out: &Path, allow_partial: bool) -> Result<MergeSummary> {
    if inputs.is_empty() {
        return Err(bad("no input folders".into()));
    }
    let mut experiments = Vec::new();
    for dir in inputs {
        let path = dir.join("experiment.json");
        if !path.is_file() {
            return Err(bad(format!(
                "{} has no experiment.json (not a folder of `lodbench experiment`)",
                dir.display()
            )));
        }
        experiments.push(read_json(&path)?);
    }
    // The adapter a shard was pointed at (`--adapter`) may differ between shards: it is not the experiment.
    let comparable = |e: &Value| -> Value {
        let mut e = e.clone();
        for r in e["runs"].as_array_mut().into_iter().flatten() {
            if let Some(c) = r["config"].as_object_mut() {
                c.remove("adapter");
                c.remove("out");
            }
        }
        e
    };
    let first = &experiments[0];
    let first_cmp = comparable(first);
    for (dir, e) in inputs.iter().zip(&experiments).skip(1) {
        let e = comparable(e);
        for key in ["name", "variable", "runs"] {
            if e[key] != first_cmp[key] {
                return Err(bad(format!(
                    "{} is another experiment than {}: its {key} differs{}",
                    dir.display(),
                    inputs[0].display(),
                    if key == "name" {
                        format!(" ({} against {})", e[key], first_cmp[key])
                    } else {
                        String::new()
                    }
                )));
            }
        }
    }
    let variable = &first["variable"];
    let planned = first["runs"].as_array().ok_or_else(|| {
        bad(format!(
            "{}: experiment.json has no runs",
            inputs[0].display()
        ))
    })?;
    let label = |k: usize| -> String {
        match (variable.as_str(), planned[k]["value"].as_str()) {
            (Some(var), Some(v)) => format!("{var}={v}"),
            _ => "the experiment's run".to_string(),
        }
    };

    // Which input holds each planned run, and in what state.
    let mut found: Vec<Option<Found>> = (0..planned.len()).map(|_| None).collect();
    let mut not_complete = Vec::new();
    for dir in inputs {
        for (k, p) in planned.iter().enumerate() {
            let folder = run_folder(dir, variable, &p["value"]);
            let run_json = folder.join("run.json");
            if !run_json.is_file() {
                continue;
            }
            let run = read_json(&run_json)?;
            if run["status"] != "complete" {
                not_complete.push(format!(
                    "{} in {}: {}",
                    label(k),
                    dir.display(),
                    run["status"].as_str().unwrap_or("unknown status")
                ));
                continue;
            }
            if let Some(other) = &found[k] {
                return Err(bad(format!(
                    "{} is in both {} and {} (a duplicate run)",
                    label(k),
                    other.input.display(),
                    dir.display()
                )));
            }
            found[k] = Some(Found {
                input: dir.clone(),
                folder,
                run,
            });
        }
    }
    let missing: Vec<String> = (0..planned.len())
        .filter(|&k| found[k].is_none())
        .map(label)
        .collect();
    if !allow_partial && (!missing.is_empty() || !not_complete.is_empty()) {
        let mut why = Vec::new();
        if !not_complete.is_empty() {
            why.push(format!("not complete: {}", not_complete.join("; ")));
        }
        if !missing.is_empty() {
            why.push(format!("missing: {}", missing.join(", ")));
        }
        return Err(bad(format!(
            "{} (--allow-partial merges the complete runs and lists the others)",
            why.join("; ")
        )));
    }
    let runs: Vec<(usize, &Found)> = found
        .iter()
        .enumerate()
        .filter_map(|(k, f)| f.as_ref().map(|f| (k, f)))
        .collect();
    if runs.is_empty() {
        return Err(bad("no complete run in the inputs".into()));
    }
    let version = |r: &Value| (r["lodbench_version"].clone(), r["git_commit"].clone());
    let v0 = version(&runs[0].1.run);
    for (k, f) in &runs[1..] {
        if version(&f.run) != v0 {
            return Err(bad(format!(
                "{} in {} was made by lodbench {} ({}), {} in {} by {} ({}): merge runs of one version",
                label(*k),
                f.input.display(),
                f.run["lodbench_version"],
                f.run["git_commit"],
                label(runs[0].0),
                runs[0].1.input.display(),
                v0.0,
                v0.1
            )));
        }
    }

    crate::commands::run::prepare_output(out)?;
    for (_, f) in &runs {
        copy_run(&f.folder, &destination(out, f))?;
    }
    let mut lead_header: Vec<&str> = variable.as_str().into_iter().collect();
    lead_header.push("adapter");
    for file in crate::commands::experiment::RUN_CSVS {
        let parts: Vec<(Vec<String>, PathBuf)> = runs
            .iter()
            .filter(|(_, f)| f.folder.join(file).is_file())
            .map(|(k, f)| {
                let adapter = f.run["adapter"]["name"].as_str().unwrap_or("unknown");
                let lead = variable
                    .as_str()
                    .map(|_| value_of(&planned[*k]))
                    .into_iter()
                    .chain([adapter.to_string()])
                    .collect();
                (lead, f.folder.join(file))
            })
            .collect();
        crate::commands::experiment::concat_csv(&out.join(file), &lead_header, &parts)?;
    }
    let mut record = first.clone();
    record["shard"] = Value::Null;
    record["merged_from"] = Value::from(
        inputs
            .iter()
            .map(|d| d.display().to_string())
            .collect::<Vec<_>>(),
    );
    let left_out: Vec<String> = missing
        .iter()
        .map(|m| format!("{m}: missing"))
        .chain(not_complete.iter().cloned())
        .collect();
    record["left_out"] = Value::from(left_out.clone());
    std::fs::write(
        out.join("experiment.json"),
        serde_json::to_string_pretty(&record)? + "\n",
    )
    .map_err(|e| Error::io(out.join("experiment.json"), e))?;
    Ok(MergeSummary {
        runs: runs.len(),
        left_out,
    })
}

/// The swept value of a planned run as its CSV column writes it.
fn value_of(planned: &Value) -> String {
    planned["value"].as_str().unwrap_or_default().to_string()
}

/// Where run `f` goes under `out`: the place it had in its input (`runs/run/` for an experiment without a
/// sweep, whose run is its folder itself).
fn destination(out: &Path, f: &Found) -> PathBuf {
    match f.folder.strip_prefix(&f.input) {
        Ok(rel) if !rel.as_os_str().is_empty() => out.join(rel),
        _ => out.join("runs").join("run"),
    }
}

/// Copies the files of run folder `from` (not its subfolders) into `to`.
fn copy_run(from: &Path, to: &Path) -> Result<()> {
    std::fs::create_dir_all(to).map_err(|e| Error::io(to, e))?;
    for entry in std::fs::read_dir(from).map_err(|e| Error::io(from, e))? {
        let entry = entry.map_err(|e| Error::io(from, e))?;
        let path = entry.path();
        if path.is_file() {
            std::fs::copy(&path, to.join(entry.file_name())).map_err(|e| Error::io(&path, e))?;
        }
    }
    Ok(())
}
