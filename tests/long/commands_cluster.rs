//! The cluster recipes of docs/cluster.md through their scripts, on the software adapter (long suite: each runs a
//! whole sharded experiment, and Slurm's a local one-node cluster): GNU parallel's shards and a Slurm array job,
//! each merged, give the unsharded experiment's frames.

use crate::common::{deterministic, experiment_file, lodbench, ok, read_csv};
use std::path::{Path, PathBuf};
use std::process::Command;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The GNU parallel recipe of docs/cluster.md (`scripts/cluster/parallel-shards.sh`) with 3 shards on the
/// software adapter: its merged folder has the unsharded experiment's frames (deterministic columns identical).
#[test]
fn the_parallel_recipe_merges_to_the_unsharded_run() {
    let dir = tempfile::tempdir().unwrap();
    let file = experiment_file(dir.path(), 12);
    let out = dir.path().join("parallel");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/cluster/parallel-shards.sh");
    let run = Command::new("bash")
        .arg(&script)
        .args([s(&file), s(&out), "llvmpipe", "llvmpipe", "llvmpipe"])
        .env("LODBENCH", env!("CARGO_BIN_EXE_lodbench"))
        .output()
        .expect("bash runs");
    assert!(
        run.status.success(),
        "the recipe failed (GNU parallel comes with bash .ci/setup): {}",
        String::from_utf8_lossy(&run.stderr)
    );
    let whole = dir.path().join("whole");
    ok(lodbench(&["experiment", s(&file), "--out", s(&whole)], &[]));
    assert_eq!(
        deterministic(&read_csv(&out.join("merged/frames.csv"))),
        deterministic(&read_csv(&whole.join("frames.csv")))
    );
    assert!(out.join("shard-3/runs/band=0.1/run.json").is_file());
}

/// The programs the Slurm test needs (slurm-wlm and munge, from `bash .ci/setup-tests`), searched on PATH and in
/// /usr/sbin; the missing ones.
fn missing_slurm() -> Vec<&'static str> {
    let path = std::env::var_os("PATH").unwrap_or_default();
    let mut dirs: Vec<PathBuf> = std::env::split_paths(&path).collect();
    dirs.extend([PathBuf::from("/usr/sbin"), PathBuf::from("/sbin")]);
    [
        "sbatch",
        "scontrol",
        "squeue",
        "sinfo",
        "slurmctld",
        "slurmd",
        "munged",
    ]
    .into_iter()
    .filter(|p| !dirs.iter().any(|d| d.join(p).is_file()))
    .collect()
}

/// A line on the test's real stderr: `cargo test` shows it even when the test passes (the harness captures
/// `println!` and `eprintln!`, not writes to the handle).
fn say(line: &str) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "{line}");
}

/// The local cluster of `scripts/cluster/local-slurm.sh`, stopped when dropped (also when the test panics).
struct LocalSlurm {
    script: PathBuf,
    state: PathBuf,
}

impl LocalSlurm {
    fn start(state: PathBuf) -> Self {
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/cluster/local-slurm.sh");
        let cluster = Self { script, state };
        let out = cluster.command("start").output().expect("bash runs");
        assert!(
            out.status.success(),
            "the local Slurm cluster did not start: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        cluster
    }

    fn command(&self, action: &str) -> Command {
        let mut c = Command::new("bash");
        c.arg(&self.script).arg(action).arg(&self.state);
        c
    }

    /// A Slurm client command (sbatch, scontrol) talking to this cluster.
    fn client(&self, program: &str) -> Command {
        let mut c = Command::new(program);
        c.env("SLURM_CONF", self.state.join("slurm.conf"));
        c
    }

    /// `sbatch --parsable ARGS` with ENV added; the job id.
    fn sbatch(&self, args: &[&str], env: &[(&str, &str)]) -> String {
        let mut c = self.client("sbatch");
        c.arg("--parsable").args(args);
        for (k, v) in env {
            c.env(k, v);
        }
        let out = ok(c.output().expect("sbatch runs"));
        let id = String::from_utf8_lossy(&out.stdout).trim().to_string();
        id.split(';').next().unwrap().to_string()
    }

    /// `JOB=STATE` for every job of JOB_ID (one per array task), from `scontrol -o show job`; a job whose
    /// dependency can no longer be met (a merge after a failed task) is `JOB=PENDING(DependencyNeverSatisfied)`.
    fn states(&self, job_id: &str) -> Vec<String> {
        let out = self
            .client("scontrol")
            .args(["-o", "show", "job", job_id])
            .output()
            .expect("scontrol runs");
        String::from_utf8_lossy(&out.stdout)
            .lines()
            .map(|line| {
                let field = |name: &str| {
                    line.split_whitespace()
                        .find_map(|f| f.strip_prefix(name))
                        .unwrap_or("?")
                        .to_string()
                };
                let task = field("ArrayTaskId=");
                let name = if task == "?" {
                    field("JobId=")
                } else {
                    format!("{}_{task}", field("ArrayJobId="))
                };
                let (state, reason) = (field("JobState="), field("Reason="));
                if reason == "DependencyNeverSatisfied" {
                    format!("{name}={state}({reason})")
                } else {
                    format!("{name}={state}")
                }
            })
            .collect()
    }
}

impl Drop for LocalSlurm {
    fn drop(&mut self) {
        match self.command("stop").output() {
            Ok(out) if out.status.success() => {}
            Ok(out) => say(&format!(
                "local Slurm cluster: stop failed: {}",
                String::from_utf8_lossy(&out.stderr)
            )),
            Err(e) => say(&format!("local Slurm cluster: stop failed: {e}")),
        }
    }
}

/// The Slurm recipe of docs/cluster.md on a local one-node cluster (`scripts/cluster/local-slurm.sh`): the
/// array job `scripts/cluster/slurm-array.sbatch` with 3 tasks, then the merge job with
/// `--dependency=afterok:<array job id>`; the merged frames are the unsharded experiment's (deterministic columns
/// identical, row for row). Skipped, with one line, where Slurm or munge is not installed or not run as root.
#[test]
fn the_slurm_recipe_merges_to_the_unsharded_run() {
    let missing = missing_slurm();
    if !missing.is_empty() {
        say(&format!(
            "SKIPPED the_slurm_recipe_merges_to_the_unsharded_run: {} not installed (bash .ci/setup-tests installs slurm-wlm and munge)",
            missing.join(", ")
        ));
        return;
    }
    let uid = Command::new("id").arg("-u").output().expect("id runs");
    if String::from_utf8_lossy(&uid.stdout).trim() != "0" {
        say("SKIPPED the_slurm_recipe_merges_to_the_unsharded_run: the local Slurm cluster runs as root");
        return;
    }
    let started = std::time::Instant::now();
    let dir = tempfile::tempdir().unwrap();
    let file = experiment_file(dir.path(), 12);
    let out = dir.path().join("slurm");
    std::fs::create_dir_all(&out).unwrap();
    let cluster = LocalSlurm::start(dir.path().join("cluster"));
    let lodbench = env!("CARGO_BIN_EXE_lodbench");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/cluster/slurm-array.sbatch");
    let log = format!("--output={}/slurm-%A_%a.out", s(&out));
    // As documented: EXPERIMENT=... OUT=... sbatch --array=1-N scripts/cluster/slurm-array.sbatch.
    let array = cluster.sbatch(
        &[
            "--array=1-3",
            &log,
            &format!("--chdir={}", s(dir.path())),
            s(&script),
        ],
        &[
            ("EXPERIMENT", s(&file)),
            ("OUT", s(&out)),
            ("LODBENCH", lodbench),
        ],
    );
    let merge = cluster.sbatch(
        &[
            &format!("--dependency=afterok:{array}"),
            "--job-name=lodbench-merge",
            &format!("--output={}/slurm-merge-%j.out", s(&out)),
            "--wrap",
            &format!("{lodbench} merge {0}/shard-* --out {0}/merged", s(&out)),
        ],
        &[],
    );
    say(&format!(
        "slurm: array job {array} (3 tasks), merge job {merge} (afterok:{array})"
    ));
    // The unsharded run while the cluster works.
    let whole = dir.path().join("whole");
    let unsharded = std::process::Command::new(lodbench)
        .args(["experiment", s(&file), "--out", s(&whole)])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("lodbench runs");
    const ENDED: [&str; 9] = [
        "COMPLETED",
        "FAILED",
        "CANCELLED",
        "TIMEOUT",
        "NODE_FAIL",
        "OUT_OF_MEMORY",
        "DEADLINE",
        "PREEMPTED",
        "BOOT_FAIL",
    ];
    let bound = std::time::Duration::from_secs(300);
    let states = loop {
        let states: Vec<String> = [&array, &merge]
            .iter()
            .flat_map(|id| cluster.states(id))
            .collect();
        let ended = states.len() == 4
            && states.iter().all(|st| {
                st.ends_with(')') || ENDED.iter().any(|e| st.ends_with(&format!("={e}")))
            });
        if ended || started.elapsed() > bound {
            break states;
        }
        std::thread::sleep(std::time::Duration::from_secs(2));
    };
    let unsharded = unsharded.wait_with_output().unwrap();
    say(&format!(
        "slurm: final states after {:.0} s: {}",
        started.elapsed().as_secs_f64(),
        states.join(" ")
    ));
    let job_logs = || {
        let mut text = String::new();
        for entry in std::fs::read_dir(&out).unwrap().flatten() {
            let name = entry.file_name().to_string_lossy().to_string();
            if name.starts_with("slurm-") {
                let body = std::fs::read_to_string(entry.path()).unwrap_or_default();
                text += &format!("--- {name}\n{body}\n");
            }
        }
        text
    };
    assert!(
        states.len() == 4 && states.iter().all(|st| st.ends_with("=COMPLETED")),
        "jobs not all COMPLETED within {bound:?}: {states:?}\n{}",
        job_logs()
    );
    drop(cluster);
    ok(unsharded);
    assert_eq!(
        deterministic(&read_csv(&out.join("merged/frames.csv"))),
        deterministic(&read_csv(&whole.join("frames.csv")))
    );
    assert_eq!(
        read_csv(&out.join("merged/summary.csv")).len(),
        read_csv(&whole.join("summary.csv")).len()
    );
    assert!(out.join("shard-3/runs/band=0.1/run.json").is_file());
}
