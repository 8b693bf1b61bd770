//! run.json (what was run, on what, by which build, and whether it finished) and experiment.json (an
//! experiment's planned runs): written as [`RunManifest`] and [`ExperimentRecord`], read back as
//! [`RunManifestRecord`] and [`ExperimentRecord`].

use super::files::{partial, EXPERIMENT_JSON};
use crate::cli::experiment_file::{Experiment, PlannedRun, Shard};
use crate::cli::run_config::RunConfig;
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
    /// With a `-dirty` git_commit: a hash of the uncommitted changes to the build's sources
    /// ([`BuildVersion::this`]).
    pub source_diff_hash: Option<&'static str>,
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
    /// The process's peak resident memory when the run ended, in bytes (`VmHWM` of /proc/self/status; null
    /// where the system does not say). On a CPU adapter such as lavapipe it includes what a GPU would hold.
    pub peak_resident_bytes: Option<u64>,
    /// The adapter's ceilings measured before the blocks (`measure::probe_rounds::ceilings`; null with
    /// `--ceilings off`): each probe's rate on its clock. summary.csv's ceiling columns divide by them.
    pub ceilings: Option<Vec<crate::measure::probe_rounds::ProbeRecord>>,
    /// The triangle ceiling summary.csv's `triangle_ceiling_share` divides by: the highest triangle rate the
    /// run read, at its start (`ceilings`) or around any block (`triangle_rate_before` / `_after`)
    /// (`measure::probe_rounds::run_triangle_ceiling`); null with `--ceilings off`.
    pub triangle_ceiling: Option<f64>,
    /// The two fill probes at `lodbench probe`'s default size and work, measured before the blocks
    /// (`measure::probe_rounds::fill_ceilings`; null with `--ceilings off`).
    pub fill_ceilings: Option<Vec<crate::measure::probe_rounds::ProbeRecord>>,
    /// The fragment ceiling summary.csv's `fragment_ceiling_share` divides by: the fastest fill probe of
    /// `ceilings` and `fill_ceilings`, read with them (`measure::probe_rounds::fragment_ceiling`); null with
    /// `--ceilings off`.
    pub fragment_ceiling: Option<f64>,
    /// Whether the GPU's clock was warmed before each timed segment (`--clock-warmup`, resolved: `auto` is off
    /// on a CPU adapter and with `--ceilings off`); null before the adapter was opened.
    pub clock_warmup: Option<bool>,
}

/// This build's `git describe --always --dirty` (None when not built from a checkout).
const GIT_COMMIT: Option<&str> = match option_env!("LODBENCH_GIT_COMMIT") {
    Some(c) if !c.is_empty() => Some(c),
    _ => None,
};

/// This build's hash of its uncommitted source changes (build.rs; None for a clean commit).
const SOURCE_DIFF_HASH: Option<&str> = match option_env!("LODBENCH_SOURCE_DIFF_HASH") {
    Some(h) if !h.is_empty() => Some(h),
    _ => None,
};

/// This process's peak resident memory so far, in bytes: `VmHWM` of /proc/self/status (None where there is
/// no such file, as on systems other than Linux).
pub fn peak_resident_bytes() -> Option<u64> {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| vm_hwm_bytes(&s))
}

/// The `VmHWM:` line of a /proc/PID/status text, in bytes (the kernel writes it in kB).
fn vm_hwm_bytes(status: &str) -> Option<u64> {
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let mut words = line.split_whitespace().skip(1);
    let kb: u64 = words.next()?.parse().ok()?;
    (words.next() == Some("kB")).then_some(kb * 1024)
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
            git_commit: GIT_COMMIT,
            source_diff_hash: SOURCE_DIFF_HASH,
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
            peak_resident_bytes: None,
            ceilings: None,
            triangle_ceiling: None,
            fill_ceilings: None,
            fragment_ceiling: None,
            clock_warmup: None,
        }
    }

    /// Writes run.json through a temporary file, so a reader never sees half of it. Compact JSON on one line
    /// (`jq .` or `python3 -m json.tool` indents it): indented, a run.json of a scene with hundreds of models is
    /// 40 % whitespace, and the committed results hold hundreds of them.
    pub fn write(&self, dir: &Path) -> Result<()> {
        let path = dir.join(RUN_JSON);
        let tmp = dir.join(partial(RUN_JSON));
        let text = serde_json::to_string(self)?;
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
    pub source_diff_hash: Option<String>,
    #[serde(default)]
    pub adapter: Option<AdapterRecord>,
    /// `gpu-timestamps` or `cpu-clock` (null before the adapter was opened).
    #[serde(default)]
    pub timing_source: Option<String>,
    #[serde(default)]
    pub config: serde_json::Value,
}

/// The adapter of a run.json read back: what `lodbench merge` compares.
#[derive(Debug, Clone, Deserialize)]
pub struct AdapterRecord {
    #[serde(default)]
    pub name: Option<String>,
    #[serde(default)]
    pub driver: Option<String>,
    #[serde(default)]
    pub driver_info: Option<String>,
}

/// The build that made a run or an experiment folder: `lodbench merge` merges folders of one build only, and
/// `lodbench experiment --resume` reuses only runs of this build. Every manifest (run.json, tune.json,
/// probe.json, overhead.json) and answer.json carry it, its fields at the manifest's top level.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct BuildVersion {
    pub lodbench_version: Option<String>,
    pub git_commit: Option<String>,
    /// With a `-dirty` git_commit: a hash of the uncommitted changes to the sources the binary is built from
    /// (build.rs: FNV-1a 64 of `git diff HEAD --binary` over src/, shaders/, scenes/, Cargo.toml, Cargo.lock
    /// and build.rs, and of their untracked files); None for a clean commit or a run.json from before it.
    pub source_diff_hash: Option<String>,
}

impl BuildVersion {
    /// This binary's.
    pub fn this() -> BuildVersion {
        BuildVersion {
            lodbench_version: Some(env!("CARGO_PKG_VERSION").to_string()),
            git_commit: GIT_COMMIT.map(str::to_string),
            source_diff_hash: SOURCE_DIFF_HASH.map(str::to_string),
        }
    }

    /// Whether the build had uncommitted changes (git_commit ends in `-dirty`).
    pub fn dirty(&self) -> bool {
        self.git_commit
            .as_deref()
            .is_some_and(|c| c.ends_with("-dirty"))
    }

    /// `lodbench 0.1.0 (abc123-dirty, changes 0123456789abcdef)`, as messages quote it.
    pub fn text(&self) -> String {
        let mut out = format!(
            "lodbench {} ({}",
            self.lodbench_version.as_deref().unwrap_or("unknown"),
            self.git_commit.as_deref().unwrap_or("no commit")
        );
        if self.dirty() {
            out += &format!(
                ", changes {}",
                self.source_diff_hash.as_deref().unwrap_or("unknown")
            );
        }
        out + ")"
    }
}

impl RunManifestRecord {
    pub fn version(&self) -> BuildVersion {
        BuildVersion {
            lodbench_version: self.lodbench_version.clone(),
            git_commit: self.git_commit.clone(),
            source_diff_hash: self.source_diff_hash.clone(),
        }
    }
}

/// The first place where two JSON values differ, as `path: a against b` (`resolved[0].frames: 12 against
/// 24`); None when they are equal.
pub fn first_difference(a: &serde_json::Value, b: &serde_json::Value) -> Option<String> {
    use serde_json::Value;
    fn walk(path: String, a: &Value, b: &Value) -> Option<String> {
        let join = |key: &str| {
            if path.is_empty() {
                key.to_string()
            } else {
                format!("{path}.{key}")
            }
        };
        match (a, b) {
            (Value::Object(x), Value::Object(y)) => {
                let mut keys: Vec<&String> = x.keys().chain(y.keys()).collect();
                keys.sort();
                keys.dedup();
                keys.into_iter().find_map(|k| {
                    walk(
                        join(k),
                        x.get(k).unwrap_or(&Value::Null),
                        y.get(k).unwrap_or(&Value::Null),
                    )
                })
            }
            (Value::Array(x), Value::Array(y)) if x.len() == y.len() => x
                .iter()
                .zip(y)
                .enumerate()
                .find_map(|(i, (p, q))| walk(format!("{path}[{i}]"), p, q)),
            _ if a == b => None,
            _ => Some(format!(
                "{}: {} against {}",
                if path.is_empty() { "(whole)" } else { &path },
                a,
                b
            )),
        }
    }
    walk(String::new(), a, b)
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

/// One planned run as experiment.json records it: the swept values (one per sweep) and the configuration as
/// written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlannedRunRecord {
    #[serde(default)]
    pub values: Vec<String>,
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
    pub variables: Vec<String>,
    pub runs: Vec<R>,
    #[serde(default)]
    pub shard: Option<Shard>,
    #[serde(default)]
    pub lodbench_version: Option<String>,
    #[serde(default)]
    pub git_commit: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source_diff_hash: Option<String>,
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
            variables: experiment.variables.clone(),
            runs: experiment.runs.iter().collect(),
            shard,
            lodbench_version: Some(env!("CARGO_PKG_VERSION").to_string()),
            git_commit: GIT_COMMIT.map(str::to_string),
            source_diff_hash: SOURCE_DIFF_HASH.map(str::to_string),
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

/// Writes `value` as pretty JSON to `dir/name` (probe.json, overhead.json), the path named when it cannot be.
pub fn write_json_file<T: Serialize + ?Sized>(dir: &Path, name: &str, value: &T) -> Result<()> {
    write_output(&dir.join(name), serde_json::to_string_pretty(value)?)
}

/// Writes `value` as compact JSON on one line to `dir/name` (answer.json, whose value objects are half whitespace
/// when indented; score's run.json), the path named when it cannot be.
pub fn write_compact_json_file<T: Serialize + ?Sized>(
    dir: &Path,
    name: &str,
    value: &T,
) -> Result<()> {
    write_output(&dir.join(name), serde_json::to_string(value)? + "\n")
}

fn write_output(path: &Path, text: String) -> Result<()> {
    std::fs::write(path, text).map_err(|e| Error::Output {
        path: path.to_path_buf(),
        problem: format!("cannot be written ({e})"),
    })
}

/// Writes `value` as `dir/experiment.json`.
pub fn write_experiment_json<T: Serialize + ?Sized>(dir: &Path, value: &T) -> Result<()> {
    let path = dir.join(EXPERIMENT_JSON);
    std::fs::write(&path, serde_json::to_string_pretty(value)? + "\n")
        .map_err(|e| Error::io(&path, e))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn first_difference_names_the_path() {
        let a = json!({"out": "x", "resolved": [{"frames": 12, "scene": "s"}]});
        let b = json!({"out": "x", "resolved": [{"frames": 24, "scene": "s"}]});
        assert_eq!(
            first_difference(&a, &b).as_deref(),
            Some("resolved[0].frames: 12 against 24")
        );
        assert_eq!(first_difference(&a, &a), None);
        let c = json!({"out": "x"});
        assert_eq!(
            first_difference(&c, &a).as_deref(),
            Some("resolved: null against [{\"frames\":12,\"scene\":\"s\"}]")
        );
    }

    #[test]
    fn peak_resident_memory_is_read_from_vm_hwm() {
        let status = "Name:\tlodbench\nVmPeak:\t  900 kB\nVmHWM:\t  123456 kB\nVmRSS:\t  100 kB\n";
        assert_eq!(vm_hwm_bytes(status), Some(123456 * 1024));
        assert_eq!(vm_hwm_bytes("VmRSS:\t100 kB\n"), None);
        assert_eq!(vm_hwm_bytes("VmHWM:\t12 MB\n"), None);
        assert_eq!(vm_hwm_bytes("VmHWM:\tmany kB\n"), None);
    }

    #[test]
    fn a_dirty_build_says_so() {
        let v = BuildVersion {
            lodbench_version: Some("0.1.0".into()),
            git_commit: Some("abc-dirty".into()),
            source_diff_hash: None,
        };
        assert!(v.dirty());
        assert_eq!(v.text(), "lodbench 0.1.0 (abc-dirty, changes unknown)");
        let clean = BuildVersion {
            git_commit: Some("abc".into()),
            ..v
        };
        assert!(!clean.dirty());
        assert_eq!(clean.text(), "lodbench 0.1.0 (abc)");
    }
}
