//! `lodbench experiment FILE.toml`: runs the planned runs of an experiment file (`cli::experiment_file` reads
//! and validates it) into one results folder, with a column per swept variable.

use crate::cli::run_config::RunConfig;
use crate::cli::ExperimentArgs;
use crate::error::{Error, Result};
use crate::results::files::{FRAMES_CSV, RUN_JSON, SUMMARY_CSV};
use crate::results::manifest::{
    first_difference, read_json, BuildVersion, ExperimentRecord, RunManifestRecord, RunStatus,
};
use std::path::{Path, PathBuf};

pub use crate::cli::experiment_file::{run_keys, Experiment, PlannedRun, Shard};
pub use crate::results::files::{run_folder_of, RUN_CSVS};

/// How `Experiment::run_with` runs the plan.
#[derive(Debug, Clone, Copy, Default)]
pub struct RunOptions {
    /// Only this shard's runs.
    pub shard: Option<Shard>,
    /// Skip the runs whose run.json says complete, made by this build, with the planned configuration
    /// ([`reusable`]); rerun the others, saying why.
    pub resume: bool,
}

/// `lodbench experiment`: loads the file with its `--set`s, prints the plan, and with `--check` or `--list`
/// stops there, else runs this shard's runs into the folder.
pub fn execute(args: &ExperimentArgs) -> Result<()> {
    let mut e = Experiment::load_with(&args.file, &args.set)?;
    if let Some(a) = &args.adapter {
        for r in &mut e.runs {
            r.config.adapter = Some(a.clone());
        }
    }
    outln!(
        "experiment {} ({} run{}{}): {}",
        e.name,
        e.runs.len(),
        if e.runs.len() == 1 { "" } else { "s" },
        match e.variables.is_empty() {
            true => String::new(),
            false => format!(", sweeping {}", e.variables.join(" x ")),
        },
        e.description
    );
    let shard = args.shard.as_deref().map(Shard::parse).transpose()?;
    if args.check || args.list {
        print_plan(&e, shard, args.list);
        return Ok(());
    }
    crate::commands::run::stop_on_signal();
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| crate::commands::run::default_out_dir(&[e.name.as_str()]));
    let options = RunOptions {
        shard,
        resume: args.resume,
    };
    let folders = e.run_with(&out, &options)?;
    outln!("{} run(s) in {}", folders.len(), out.display());
    Ok(())
}

/// `--check` and `--list`: a line per planned run (with `list`, its shard among `shard`'s count) with each
/// scene's methods.
fn print_plan(e: &Experiment, shard: Option<Shard>, list: bool) {
    let n = shard.map_or(1, |s| s.count);
    for (k, r) in e.runs.iter().enumerate() {
        let part = if list {
            format!(" shard {}/{n}", k % n as usize + 1)
        } else {
            String::new()
        };
        let per_scene: Vec<String> = r
            .config
            .scenes
            .iter()
            .map(|&k| format!("{}: {}", k.name(), r.config.methods_for(k).join(", ")))
            .collect();
        let label = match r.values.is_empty() {
            true => "-".to_string(),
            false => crate::cli::experiment_file::sweep_label(&e.variables, &r.values),
        };
        outln!("  {label}{part} {}", per_scene.join("; "));
    }
}

impl Experiment {
    /// Runs every planned run into `out/runs/<variable>=<value>/` (or `out/` without a sweep), then writes
    /// `out/frames.csv` and `out/summary.csv` with the swept variables as the first columns, and
    /// `out/experiment.json`.
    pub fn run(&self, out: &Path) -> Result<Vec<PathBuf>> {
        self.run_with(out, &RunOptions::default())
    }

    /// The folder planned run `k` writes to under `out`.
    pub fn run_folder(&self, out: &Path, k: usize) -> PathBuf {
        run_folder_of(out, &self.variables, &self.runs[k].values)
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
        ExperimentRecord::of(self, options.shard).write(out)?;
        let mine = self.indices(options.shard);
        let mut folders = Vec::new();
        for &k in &mine {
            let folder = self.run_folder(out, k);
            let mut cfg = self.runs[k].config.clone();
            cfg.out = Some(folder.clone());
            let reuse = if options.resume {
                match reusable(&folder, &cfg) {
                    Ok(()) => true,
                    Err(Some(why)) => {
                        eprintln!("{}: rerun (--resume): {why}", folder.display());
                        false
                    }
                    Err(None) => false,
                }
            } else {
                false
            };
            if reuse {
                eprintln!("{}: complete, skipped (--resume)", folder.display());
            } else {
                crate::commands::run::run(&cfg)?;
            }
            folders.push(folder);
        }
        if !self.variables.is_empty() {
            let header: Vec<&str> = self.variables.iter().map(String::as_str).collect();
            for file in RUN_CSVS {
                let parts: Vec<CsvPart> = mine
                    .iter()
                    .zip(&folders)
                    .map(|(&k, f)| CsvPart {
                        lead: self.runs[k].values.clone(),
                        source: f.join(file),
                    })
                    .collect();
                concat_csv(&out.join(file), &header, &parts)?;
            }
            crate::results::answer::write(out)?;
        }
        Ok(folders)
    }
}

/// Whether `folder` holds a complete run of `cfg` that `--resume` may keep: its run.json says `complete`, was
/// written by this build (lodbench version, git commit and, for a `-dirty` commit, the hash of the
/// uncommitted changes), and records the same configuration, resolved values included; its frames.csv and
/// summary.csv are there. Err(Some(why)) when a run is there but cannot be kept, Err(None) when none was
/// started.
fn reusable(folder: &Path, cfg: &RunConfig) -> std::result::Result<(), Option<String>> {
    let path = folder.join(RUN_JSON);
    if !path.is_file() {
        return Err(None);
    }
    let run = match read_json::<RunManifestRecord>(&path) {
        Ok(Ok(run)) => run,
        Ok(Err(e)) => return Err(Some(format!("its run.json is not valid ({e})"))),
        Err(e) => return Err(Some(format!("its run.json cannot be read ({e})"))),
    };
    if run.status != Some(RunStatus::Complete) {
        return Err(Some(format!(
            "its run.json says {}",
            run.status.map_or("no status", RunStatus::name)
        )));
    }
    let (made_by, this) = (run.version(), BuildVersion::this());
    if made_by != this {
        return Err(Some(format!(
            "it was made by {}, this is {}",
            made_by.text(),
            this.text()
        )));
    }
    // Compared as written: an f32 flag reads back from its text as another f64 than it converts to.
    let planned = serde_json::to_string(cfg)
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .unwrap_or_default();
    if let Some(d) = first_difference(&run.config, &planned) {
        return Err(Some(format!(
            "its flags differ from the plan's (config.{d})"
        )));
    }
    match [FRAMES_CSV, SUMMARY_CSV]
        .iter()
        .find(|f| !folder.join(f).is_file())
    {
        Some(f) => Err(Some(format!("it has no {f}"))),
        None => Ok(()),
    }
}

/// One run's CSV in a joined CSV: the values of the leading columns for its rows, and the file.
pub(crate) struct CsvPart {
    pub lead: Vec<String>,
    pub source: PathBuf,
}

/// Every part's header is the same (parts with an empty file, which have none, aside): a part with another one
/// (a run of another lodbench, an edited file) is an error naming it and the part it differs from.
pub(crate) fn check_headers(parts: &[CsvPart]) -> Result<()> {
    let mut first: Option<(&Path, csv::StringRecord)> = None;
    for part in parts {
        let header = csv::Reader::from_path(&part.source)?.headers()?.clone();
        if header.is_empty() {
            continue;
        }
        let Some((from, h)) = &first else {
            first = Some((&part.source, header));
            continue;
        };
        if *h != header {
            let detail = match h.iter().zip(header.iter()).position(|(a, b)| a != b) {
                Some(i) => format!("column {}: {} against {}", i + 1, &header[i], &h[i]),
                None => format!("{} columns against {}", header.len(), h.len()),
            };
            return Err(Error::results(
                part.source.parent().unwrap_or(Path::new(".")),
                format!(
                    "its {} has another header than {} ({detail}): made by another lodbench, or edited?",
                    part.source
                        .file_name()
                        .map_or(String::new(), |n| n.to_string_lossy().to_string()),
                    from.display()
                ),
            ));
        }
    }
    Ok(())
}

/// Writes `path`: under `lead_header` and the parts' own header, each part's CSV rows after its lead values. A
/// part whose file is empty (a run without rows of it, e.g. no transition on its path, writes no header) adds
/// nothing. The parts' headers must agree ([`check_headers`]; nothing is written otherwise).
pub(crate) fn concat_csv(path: &Path, lead_header: &[&str], parts: &[CsvPart]) -> Result<()> {
    check_headers(parts)?;
    let mut w = csv::Writer::from_path(path)?;
    let mut header_written = false;
    for part in parts {
        let mut r = csv::Reader::from_path(&part.source)?;
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
            let mut row = csv::StringRecord::from(part.lead.clone());
            row.extend(rec?.iter());
            w.write_record(&row)?;
        }
    }
    w.flush().map_err(|e| Error::io(path, e))
}
