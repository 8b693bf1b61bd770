//! run.json (what was run, on what, by which build, and whether it finished) and experiment.json (an
//! experiment's planned runs): written as [`RunManifest`] and [`ExperimentRecord`], read back as
//! [`RunManifestRecord`] and [`ExperimentRecord`].

use super::files::{partial, EXPERIMENT_JSON};
use crate::cli::config::RunConfig;
use crate::cli::experiment_file::{Experiment, PlannedRun, Shard};
use crate::error::{Error, Result};
use crate::gpu::{AdapterSummary, TimingSource};
use crate::measure::records::{BlockInfo, BlockRounds};
use crate::scene::SceneDescription;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

pub use super::files::RUN_JSON;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RunStatus {
    /// Written when the run starts; a run.json still saying this with no lodbench running was killed.
    Running,
    Complete,
    Interrupted,
    Failed,
}

#[derive(Debug, Clone, Serialize)]
pub struct RunManifest {
    pub status: RunStatus,
    pub error: Option<String>,
    pub lodbench_version: &'static str,
    pub git_commit: Option<&'static str>,
    pub seed: u64,
    pub start_time: String,
    pub end_time: Option<String>,
    pub adapter: Option<AdapterSummary>,
    pub timing_source: Option<TimingSource>,
    pub timestamp_period_ns: Option<f32>,
    /// Frames the timing pass keeps in flight (docs/measurement.md, "Timing pass").
    pub frames_in_flight_timing: u32,
    pub config: RunConfig,
    pub scenes: Vec<SceneDescription>,
    pub blocks: Vec<BlockInfo>,
    /// Per scene block: the timing rounds' frames and method orders (`--rounds`, shuffled from `--seed`).
    pub timing_rounds: Vec<BlockRounds>,
}

pub fn now_rfc3339() -> String {
    humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string()
}

impl RunManifest {
    pub fn new(config: RunConfig) -> Self {
        RunManifest {
            status: RunStatus::Running,
            error: None,
            lodbench_version: env!("CARGO_PKG_VERSION"),
            git_commit: option_env!("LODBENCH_GIT_COMMIT").filter(|s| !s.is_empty()),
            seed: config.seed,
            start_time: now_rfc3339(),
            end_time: None,
            adapter: None,
            timing_source: None,
            timestamp_period_ns: None,
            frames_in_flight_timing: 1,
            config,
            scenes: Vec::new(),
            blocks: Vec::new(),
            timing_rounds: Vec::new(),
        }
    }

    /// Writes run.json through a temporary file, so a reader never sees half of it.
    pub fn write(&self, dir: &Path) -> Result<()> {
        let path = dir.join(RUN_JSON);
        let tmp = dir.join(partial(RUN_JSON));
        let text = serde_json::to_string_pretty(self)?;
        std::fs::write(&tmp, text + "\n").map_err(|e| Error::io(&tmp, e))?;
        std::fs::rename(&tmp, &path).map_err(|e| Error::io(&path, e))
    }
}

impl RunStatus {
    /// As run.json writes it.
    pub fn name(self) -> &'static str {
        match self {
            RunStatus::Running => "running",
            RunStatus::Complete => "complete",
            RunStatus::Interrupted => "interrupted",
            RunStatus::Failed => "failed",
        }
    }
}

/// run.json read back: what resuming an experiment and merging its folders check. The configuration stays as
/// written (compared as JSON: an f32 flag reads back from its text as another f64 than it converts to).
#[derive(Debug, Clone, Deserialize)]
pub struct RunManifestRecord {
    #[serde(default)]
    pub status: Option<RunStatus>,
    #[serde(default)]
    pub lodbench_version: Option<String>,
    #[serde(default)]
    pub git_commit: Option<String>,
    #[serde(default)]
    pub adapter: Option<AdapterRecord>,
    #[serde(default)]
    pub config: serde_json::Value,
}

/// The adapter of a run.json read back: its name.
#[derive(Debug, Clone, Deserialize)]
pub struct AdapterRecord {
    #[serde(default)]
    pub name: Option<String>,
}

/// The build that made a run or an experiment folder: `lodbench merge` merges folders of one build only.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BuildVersion {
    pub lodbench_version: Option<String>,
    pub git_commit: Option<String>,
}

impl RunManifestRecord {
    pub fn version(&self) -> BuildVersion {
        BuildVersion {
            lodbench_version: self.lodbench_version.clone(),
            git_commit: self.git_commit.clone(),
        }
    }
}

/// `value` as JSON text (a string quoted, None as `null`), as the messages that quote run.json write it.
pub fn json_text<T: Serialize>(value: &T) -> String {
    serde_json::to_string(value).unwrap_or_default()
}

/// Reads a JSON file as `T`: Err when it cannot be read, Ok(Err) when it is no `T`.
pub fn read_json<T: DeserializeOwned>(path: &Path) -> Result<serde_json::Result<T>> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    Ok(serde_json::from_str(&text))
}

/// One planned run as experiment.json records it: the swept value and the configuration as written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlannedRunRecord {
    #[serde(default)]
    pub value: Option<String>,
    #[serde(default)]
    pub config: serde_json::Value,
}

/// experiment.json: the experiment (every planned run), the shard this folder holds, and the version that made
/// it (`lodbench merge` checks all three); a merged folder's adds the folders merged and the runs left out.
/// Written with `R` = `&PlannedRun` (the configuration in its own order), read back with [`PlannedRunRecord`].
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ExperimentRecord<R> {
    pub name: String,
    #[serde(default)]
    pub description: String,
    #[serde(default)]
    pub file: PathBuf,
    #[serde(default)]
    pub variable: Option<String>,
    pub runs: Vec<R>,
    #[serde(default)]
    pub shard: Option<Shard>,
    #[serde(default)]
    pub lodbench_version: Option<String>,
    #[serde(default)]
    pub git_commit: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub merged_from: Option<Vec<String>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub left_out: Option<Vec<String>>,
}

impl<'e> ExperimentRecord<&'e PlannedRun> {
    /// The record of `experiment` run as `shard`, made by this build.
    pub fn of(experiment: &'e Experiment, shard: Option<Shard>) -> Self {
        ExperimentRecord {
            name: experiment.name.clone(),
            description: experiment.description.clone(),
            file: experiment.file.clone(),
            variable: experiment.variable.clone(),
            runs: experiment.runs.iter().collect(),
            shard,
            lodbench_version: Some(env!("CARGO_PKG_VERSION").to_string()),
            git_commit: option_env!("LODBENCH_GIT_COMMIT")
                .filter(|s| !s.is_empty())
                .map(str::to_string),
            merged_from: None,
            left_out: None,
        }
    }
}

impl<R: Serialize> ExperimentRecord<R> {
    /// Writes `dir/experiment.json`, its keys in the record's order.
    pub fn write(&self, dir: &Path) -> Result<()> {
        write_experiment_json(dir, self)
    }
}

impl ExperimentRecord<PlannedRunRecord> {
    /// Reads `dir/experiment.json`: Err when it cannot be read, Ok(Err) when it is no experiment record.
    pub fn read(dir: &Path) -> Result<serde_json::Result<Self>> {
        read_json(&dir.join(EXPERIMENT_JSON))
    }
}

/// Writes `value` as `dir/experiment.json`.
pub fn write_experiment_json<T: Serialize + ?Sized>(dir: &Path, value: &T) -> Result<()> {
    let path = dir.join(EXPERIMENT_JSON);
    std::fs::write(&path, serde_json::to_string_pretty(value)? + "\n")
        .map_err(|e| Error::io(&path, e))
}
