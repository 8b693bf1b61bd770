//! run.json: what was run, on what, by which build, and whether it finished.

use crate::cli::config::RunConfig;
use crate::error::{Error, Result};
use crate::gpu::{AdapterSummary, TimingSource};
use crate::measure::records::{BlockInfo, BlockRounds};
use crate::scene::SceneDescription;
use serde::Serialize;
use std::path::Path;

pub const RUN_JSON: &str = "run.json";

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
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
        let tmp = dir.join("run.json.partial");
        let text = serde_json::to_string_pretty(self)?;
        std::fs::write(&tmp, text + "\n").map_err(|e| Error::io(&tmp, e))?;
        std::fs::rename(&tmp, &path).map_err(|e| Error::io(&path, e))
    }
}
