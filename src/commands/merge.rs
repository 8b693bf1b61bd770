//! `lodbench merge DIR... --out DIR`: one results folder from the folders of an experiment's shards (or of its
//! runs made on different machines), refusing what does not belong together.
//!
//! Every input is an experiment folder (`lodbench experiment ... --out DIR`, with or without `--shard`): its
//! `experiment.json` names the experiment and every planned run; its runs lie in `runs/<variable>=<value>/` (or
//! the folder itself without a sweep). The merge checks, before writing anything:
//! - every input is the same experiment: the same name, swept variable and planned runs (flags included, but
//!   `--adapter`, which may point each shard at its own GPU, and the output folder);
//! - no run is in two inputs (a duplicate), and every planned run is in one (a missing run);
//! - every run is complete: a failed or interrupted one is refused, or with `--allow-partial` left out (as are
//!   missing runs), and listed either way;
//! - every run was made by the same lodbench: `lodbench_version` and `git_commit` of its run.json; for a
//!   `-dirty` commit also `source_diff_hash`, the hash of the uncommitted changes (two dirty trees of one commit
//!   can differ): refused where the hashes differ or one is missing, unless `--allow-dirty`;
//! - every run ran on the same adapter: its name, `driver` and `driver_info`, unless `--allow-adapters`
//!   (shards on different GPUs, kept apart by the `adapter` column); and on the same timing clock
//!   (`timing_source`: GPU timestamps or the CPU clock), always;
//! - every run was run with its plan's flags: run.json's `config` (the flags and the values they resolved to)
//!   equals the input's experiment.json's for that run, but for the output folder (and `--adapter` with
//!   `--allow-adapters`);
//! - every CSV to join has the same header in every run.
//!
//! Each refusal is one error naming the two runs (or the run and its plan, or the file) and the field.
//!
//! The output holds a copy of each run folder under `runs/`, the [`RUN_CSVS`] (frames.csv, summary.csv,
//! transitions.csv, rounds.csv, pairs.csv) with the swept variable (if any) and `adapter` (the run's adapter
//! name) as the first columns, and `experiment.json` with `merged_from`. Nothing is averaged: runs on different
//! adapters stay apart by the `adapter` column.

use crate::cli::MergeArgs;
use crate::commands::experiment::{check_headers, concat_csv, CsvPart};
use crate::error::{Error, Result};
use crate::results::files::{
    run_folder_of, EXPERIMENT_JSON, RUNS_DIR, RUN_CSVS, RUN_JSON, UNSWEPT_RUN_DIR,
};
use crate::results::manifest::{
    first_difference, json_text, read_json, write_experiment_json, ExperimentRecord,
    PlannedRunRecord, RunManifestRecord, RunStatus,
};
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

fn not_json(path: &Path, e: serde_json::Error) -> Error {
    bad(format!("{} is not valid JSON ({e})", path.display()))
}

/// An input's experiment.json.
type Record = ExperimentRecord<PlannedRunRecord>;

/// What `lodbench merge` may merge on purpose.
#[derive(Debug, Clone, Copy, Default)]
pub struct MergeOptions {
    /// Merge the complete runs when some are missing, failed or were interrupted.
    pub allow_partial: bool,
    /// Merge runs made on different adapters (name, driver, driver info).
    pub allow_adapters: bool,
    /// Merge runs built from a `-dirty` tree whose changes differ or cannot be compared.
    pub allow_dirty: bool,
}

/// One planned run found in an input.
struct Found {
    /// The input's index among the inputs.
    at: usize,
    input: PathBuf,
    folder: PathBuf,
    run: RunManifestRecord,
}

/// A complete run to merge: its index in the plan and where it was found.
struct MergedRun<'a> {
    k: usize,
    found: &'a Found,
}

/// The experiment's plan, as the first input records it.
struct Plan<'a> {
    variables: &'a [String],
    runs: &'a [PlannedRunRecord],
}

impl Plan<'_> {
    /// How messages name planned run `k`: `variable=value` (joined by `+` for several sweeps).
    fn label(&self, k: usize) -> String {
        match self.variables.is_empty() {
            true => "the experiment's run".to_string(),
            false => crate::cli::experiment_file::sweep_label(self.variables, &self.runs[k].values),
        }
    }
}

/// Which input holds each planned run, and which runs are there but not complete (`value in DIR: status`).
struct Census {
    found: Vec<Option<Found>>,
    not_complete: Vec<String>,
}

impl Census {
    /// The planned runs no input holds complete, by label.
    fn missing(&self, plan: &Plan<'_>) -> Vec<String> {
        (0..self.found.len())
            .filter(|&k| self.found[k].is_none())
            .map(|k| plan.label(k))
            .collect()
    }

    fn complete(&self) -> Vec<MergedRun<'_>> {
        self.found
            .iter()
            .enumerate()
            .filter_map(|(k, f)| f.as_ref().map(|found| MergedRun { k, found }))
            .collect()
    }
}

/// `lodbench merge`: merges, notes what was left out, prints how many runs went where.
pub fn execute(args: &MergeArgs) -> Result<()> {
    let options = MergeOptions {
        allow_partial: args.allow_partial,
        allow_adapters: args.allow_adapters,
        allow_dirty: args.allow_dirty,
    };
    let m = merge(&args.dirs, &args.out, &options)?;
    for l in &m.left_out {
        eprintln!("note: left out {l}");
    }
    outln!("{} run(s) merged into {}", m.runs, args.out.display());
    Ok(())
}

/// Merges the experiment folders `inputs` into `out`; see the module docs.
pub fn merge(inputs: &[PathBuf], out: &Path, options: &MergeOptions) -> Result<MergeSummary> {
    let allow_partial = options.allow_partial;
    if inputs.is_empty() {
        return Err(bad("no input folders".into()));
    }
    let experiments = read_experiments(inputs)?;
    check_one_experiment(inputs, &experiments)?;
    let first = &experiments[0];
    let plan = Plan {
        variables: &first.variables,
        runs: &first.runs,
    };
    let census = find_runs(inputs, &plan)?;
    let missing = census.missing(&plan);
    if !allow_partial && (!missing.is_empty() || !census.not_complete.is_empty()) {
        return Err(refuse_partial(&census.not_complete, &missing));
    }
    let runs = census.complete();
    if runs.is_empty() {
        return Err(bad("no complete run in the inputs".into()));
    }
    check_one_version(&plan, &runs, options)?;
    check_one_machine(&plan, &runs, options)?;
    check_planned_flags(&plan, &experiments, &runs, options)?;
    for file in RUN_CSVS {
        check_headers(&csv_parts(&plan, &runs, file))?;
    }
    let left_out: Vec<String> = missing
        .iter()
        .map(|m| format!("{m}: missing"))
        .chain(census.not_complete.iter().cloned())
        .collect();
    write_merged(out, inputs, first, &plan, &runs, &left_out)?;
    Ok(MergeSummary {
        runs: runs.len(),
        left_out,
    })
}

/// Every input's experiment.json.
fn read_experiments(inputs: &[PathBuf]) -> Result<Vec<Record>> {
    let mut experiments = Vec::new();
    for dir in inputs {
        let path = dir.join(EXPERIMENT_JSON);
        if !path.is_file() {
            return Err(bad(format!(
                "{} has no experiment.json (not a folder of `lodbench experiment`)",
                dir.display()
            )));
        }
        experiments.push(Record::read(dir)?.map_err(|e| not_json(&path, e))?);
    }
    Ok(experiments)
}

/// The planned runs as the inputs must agree on them: without the adapter a shard was pointed at
/// (`--adapter`, which may differ between shards: it is not the experiment) and the output folder.
fn comparable(runs: &[PlannedRunRecord]) -> Vec<PlannedRunRecord> {
    let mut runs = runs.to_vec();
    for r in &mut runs {
        if let Some(c) = r.config.as_object_mut() {
            c.remove("adapter");
            c.remove("out");
        }
    }
    runs
}

/// Every input is the same experiment as the first: the same name, swept variable and planned runs.
fn check_one_experiment(inputs: &[PathBuf], experiments: &[Record]) -> Result<()> {
    let first = &experiments[0];
    let first_runs = comparable(&first.runs);
    for (dir, e) in inputs.iter().zip(experiments).skip(1) {
        let differs = if e.name != first.name {
            Some((
                "name",
                format!(
                    " ({} against {})",
                    json_text(&e.name),
                    json_text(&first.name)
                ),
            ))
        } else if e.variables != first.variables {
            Some(("variables", String::new()))
        } else if comparable(&e.runs) != first_runs {
            Some(("runs", String::new()))
        } else {
            None
        };
        if let Some((key, detail)) = differs {
            return Err(bad(format!(
                "{} is another experiment than {}: its {key} differs{detail}",
                dir.display(),
                inputs[0].display(),
            )));
        }
    }
    Ok(())
}

/// Looks for every planned run in every input: a complete run in two inputs is an error (a duplicate).
fn find_runs(inputs: &[PathBuf], plan: &Plan<'_>) -> Result<Census> {
    let mut census = Census {
        found: (0..plan.runs.len()).map(|_| None).collect(),
        not_complete: Vec::new(),
    };
    for (at, dir) in inputs.iter().enumerate() {
        for (k, p) in plan.runs.iter().enumerate() {
            let folder = run_folder_of(dir, plan.variables, &p.values);
            let run_json = folder.join(RUN_JSON);
            if !run_json.is_file() {
                continue;
            }
            let run: RunManifestRecord =
                read_json(&run_json)?.map_err(|e| not_json(&run_json, e))?;
            if run.status != Some(RunStatus::Complete) {
                census.not_complete.push(format!(
                    "{} in {}: {}",
                    plan.label(k),
                    dir.display(),
                    run.status.map_or("unknown status", RunStatus::name)
                ));
                continue;
            }
            if let Some(other) = &census.found[k] {
                return Err(bad(format!(
                    "{} is in both {} and {} (a duplicate run)",
                    plan.label(k),
                    other.input.display(),
                    dir.display()
                )));
            }
            census.found[k] = Some(Found {
                at,
                input: dir.clone(),
                folder,
                run,
            });
        }
    }
    Ok(census)
}

/// The error of a merge without `--allow-partial` that misses runs or finds some not complete.
fn refuse_partial(not_complete: &[String], missing: &[String]) -> Error {
    let mut why = Vec::new();
    if !not_complete.is_empty() {
        why.push(format!("not complete: {}", not_complete.join("; ")));
    }
    if !missing.is_empty() {
        why.push(format!("missing: {}", missing.join(", ")));
    }
    bad(format!(
        "{} (--allow-partial merges the complete runs and lists the others)",
        why.join("; ")
    ))
}

/// How messages name run `r`: `band=0.05 in DIR`.
fn name(plan: &Plan<'_>, r: &MergedRun<'_>) -> String {
    format!("{} in {}", plan.label(r.k), r.found.input.display())
}

/// Every run was made by the same lodbench (`lodbench_version` and `git_commit` of its run.json), and, for a
/// `-dirty` commit, from the same uncommitted changes (`source_diff_hash`) unless `--allow-dirty`.
fn check_one_version(
    plan: &Plan<'_>,
    runs: &[MergedRun<'_>],
    options: &MergeOptions,
) -> Result<()> {
    let first = &runs[0];
    let v0 = first.found.run.version();
    for r in &runs[1..] {
        let v = r.found.run.version();
        if (&v.lodbench_version, &v.git_commit) != (&v0.lodbench_version, &v0.git_commit) {
            return Err(bad(format!(
                "{} was made by lodbench {} ({}), {} by {} ({}): merge runs of one version",
                name(plan, r),
                json_text(&v.lodbench_version),
                json_text(&v.git_commit),
                name(plan, first),
                json_text(&v0.lodbench_version),
                json_text(&v0.git_commit)
            )));
        }
        let same_changes =
            v.source_diff_hash.is_some() && v.source_diff_hash == v0.source_diff_hash;
        if v.dirty() && !same_changes && !options.allow_dirty {
            let why = if v.source_diff_hash.is_none() || v0.source_diff_hash.is_none() {
                "and one run.json has no source_diff_hash to tell the two trees' changes apart"
                    .to_string()
            } else {
                format!(
                    "whose uncommitted changes differ (source_diff_hash {} against {})",
                    json_text(&v.source_diff_hash),
                    json_text(&v0.source_diff_hash)
                )
            };
            return Err(bad(format!(
                "{} and {} were built from a dirty tree (git_commit {}) {why}: two dirty trees of one commit can \
                 build different binaries; commit, rebuild and rerun, or merge anyway with --allow-dirty",
                name(plan, r),
                name(plan, first),
                json_text(&v.git_commit)
            )));
        }
    }
    Ok(())
}

/// Every run ran on the same adapter (name, driver, driver info) unless `--allow-adapters`, and on the same
/// timing clock (`timing_source`) always.
fn check_one_machine(
    plan: &Plan<'_>,
    runs: &[MergedRun<'_>],
    options: &MergeOptions,
) -> Result<()> {
    type Field = fn(&RunManifestRecord) -> Option<String>;
    let adapter_fields: [(&str, Field); 3] = [
        ("adapter name", |r| {
            r.adapter.as_ref().and_then(|a| a.name.clone())
        }),
        ("adapter driver", |r| {
            r.adapter.as_ref().and_then(|a| a.driver.clone())
        }),
        ("adapter driver_info", |r| {
            r.adapter.as_ref().and_then(|a| a.driver_info.clone())
        }),
    ];
    let clock: (&str, Field) = ("timing_source", |r| r.timing_source.clone());
    let fields = adapter_fields
        .iter()
        .filter(|_| !options.allow_adapters)
        .chain([&clock]);
    let first = &runs[0];
    for (field, get) in fields {
        let f0 = get(&first.found.run);
        for r in &runs[1..] {
            let f = get(&r.found.run);
            if f != f0 {
                let remedy = if *field == "timing_source" {
                    "the times of one folder are all of one clock"
                } else {
                    "runs on different GPUs are merged only with --allow-adapters (the adapter column keeps \
                     their rows apart)"
                };
                return Err(bad(format!(
                    "{} and {} differ in {field} ({} against {}): {remedy}",
                    name(plan, r),
                    name(plan, first),
                    json_text(&f),
                    json_text(&f0)
                )));
            }
        }
    }
    Ok(())
}

/// `config` as compared with the plan: without the output folder (and `--adapter` when adapters may differ).
fn comparable_config(config: &serde_json::Value, allow_adapters: bool) -> serde_json::Value {
    let mut c = config.clone();
    if let Some(o) = c.as_object_mut() {
        o.remove("out");
        if allow_adapters {
            o.remove("adapter");
        }
    }
    c
}

/// Every run was run with the flags its input's experiment.json plans for it (the flags and what they
/// resolved to), the output folder aside.
fn check_planned_flags(
    plan: &Plan<'_>,
    experiments: &[Record],
    runs: &[MergedRun<'_>],
    options: &MergeOptions,
) -> Result<()> {
    for r in runs {
        let Some(planned) = experiments.get(r.found.at).and_then(|e| e.runs.get(r.k)) else {
            continue;
        };
        let (ran, planned) = (
            comparable_config(&r.found.run.config, options.allow_adapters),
            comparable_config(&planned.config, options.allow_adapters),
        );
        if let Some(d) = first_difference(&ran, &planned) {
            return Err(bad(format!(
                "{} was run with other flags than {}'s experiment.json plans for it (config.{d}): rerun it \
                 (lodbench experiment --resume reruns it)",
                name(plan, r),
                r.found.input.display()
            )));
        }
    }
    Ok(())
}

/// The parts of the joined `file`: each run's, after its swept value (if any) and its adapter's name.
fn csv_parts(plan: &Plan<'_>, runs: &[MergedRun<'_>], file: &str) -> Vec<CsvPart> {
    runs.iter()
        .filter(|r| r.found.folder.join(file).is_file())
        .map(|r| {
            let adapter = r.found.run.adapter.as_ref().and_then(|a| a.name.as_deref());
            CsvPart {
                lead: plan.runs[r.k]
                    .values
                    .iter()
                    .cloned()
                    .chain([adapter.unwrap_or("unknown").to_string()])
                    .collect(),
                source: r.found.folder.join(file),
            }
        })
        .collect()
}

/// Writes the merged folder: each run's folder under `runs/`, the joined CSVs, and experiment.json.
fn write_merged(
    out: &Path,
    inputs: &[PathBuf],
    first: &Record,
    plan: &Plan<'_>,
    runs: &[MergedRun<'_>],
    left_out: &[String],
) -> Result<()> {
    crate::commands::run::prepare_output(out)?;
    for r in runs {
        copy_run(&r.found.folder, &destination(out, r.found))?;
    }
    let mut lead_header: Vec<&str> = plan.variables.iter().map(String::as_str).collect();
    lead_header.push("adapter");
    for file in RUN_CSVS {
        concat_csv(&out.join(file), &lead_header, &csv_parts(plan, runs, file))?;
    }
    crate::results::answer::write(out)?;
    let mut record = first.clone();
    record.shard = None;
    record.merged_from = Some(inputs.iter().map(|d| d.display().to_string()).collect());
    record.left_out = Some(left_out.to_vec());
    // Through a JSON value, so the keys are in alphabetical order, as merge has always written them.
    write_experiment_json(out, &serde_json::to_value(&record)?)
}

/// Where run `f` goes under `out`: the place it had in its input (`runs/run/` for an experiment without a
/// sweep, whose run is its folder itself).
fn destination(out: &Path, f: &Found) -> PathBuf {
    match f.folder.strip_prefix(&f.input) {
        Ok(rel) if !rel.as_os_str().is_empty() => out.join(rel),
        _ => out.join(RUNS_DIR).join(UNSWEPT_RUN_DIR),
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
