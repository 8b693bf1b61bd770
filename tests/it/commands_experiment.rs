//! `lodbench experiment --shard i/n`, `lodbench merge` and `lodbench experiment --resume`, through the binary
//! on the software adapter: a small bunny-sweep experiment of four runs (a `band` sweep).

use crate::common::{deterministic, experiment_file, fails_with, lodbench, ok, read_csv, Rows};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn failure(out: Output) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(!out.status.success(), "expected failure: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    stderr
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Three shards of four runs (2, 1 and 1 of them), merged, give the unsharded experiment's frames: the same
/// rows in the same order, the deterministic columns identical, plus an `adapter` column; `--list` shows the
/// split.
#[test]
fn three_shards_merged_equal_one_unsharded_run() {
    let dir = tempfile::tempdir().unwrap();
    let file = experiment_file(dir.path(), 24);
    let list = ok(lodbench(
        &["experiment", s(&file), "--list", "--shard", "1/3"],
        &[],
    ));
    let text = String::from_utf8_lossy(&list.stdout);
    for (value, shard) in [("0.02", 1), ("0.05", 2), ("0.1", 3), ("0.15", 1)] {
        assert!(
            text.contains(&format!("  band={value} shard {shard}/3 ")),
            "{text}"
        );
    }
    let whole = dir.path().join("whole");
    ok(lodbench(&["experiment", s(&file), "--out", s(&whole)], &[]));
    let mut shards = Vec::new();
    for i in 1..=3 {
        let out = dir.path().join(format!("shard-{i}"));
        ok(lodbench(
            &[
                "experiment",
                s(&file),
                "--shard",
                &format!("{i}/3"),
                "--out",
                s(&out),
            ],
            &[],
        ));
        shards.push(out);
    }
    assert!(shards[0].join("runs/band=0.15/run.json").is_file());
    assert!(!shards[1].join("runs/band=0.15").exists());
    let merged = dir.path().join("merged");
    let mut args = vec!["merge"];
    args.extend(shards.iter().map(|p| s(p)));
    args.extend(["--out", s(&merged)]);
    ok(lodbench(&args, &[]));
    for file in ["frames.csv", "summary.csv"] {
        let (a, b) = (read_csv(&whole.join(file)), read_csv(&merged.join(file)));
        assert_eq!(a.len(), b.len(), "{file}");
        if file == "frames.csv" {
            assert_eq!(deterministic(&a), deterministic(&b));
        }
        assert!(
            b.iter().all(|r| !r["adapter"].is_empty()),
            "{file}: adapter column"
        );
    }
    let e: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(merged.join("experiment.json")).unwrap())
            .unwrap();
    assert_eq!(e["merged_from"].as_array().unwrap().len(), 3);
    assert!(merged.join("runs/band=0.05/run.json").is_file());
}

/// Merge refuses duplicates, missing runs, runs of another lodbench version, failed runs and another
/// experiment, each with a message naming the runs or folders; `--allow-partial` merges the complete runs and
/// lists the rest.
#[test]
fn merge_refuses_what_does_not_fit() {
    let dir = tempfile::tempdir().unwrap();
    let file = experiment_file(dir.path(), 12);
    let shard = |i: u32| {
        let out = dir.path().join(format!("shard-{i}"));
        ok(lodbench(
            &[
                "experiment",
                s(&file),
                "--shard",
                &format!("{i}/2"),
                "--out",
                s(&out),
            ],
            &[],
        ));
        out
    };
    let (a, b) = (shard(1), shard(2));
    let out = dir.path().join("merged");
    let e = failure(lodbench(
        &["merge", s(&a), s(&a), s(&b), "--out", s(&out)],
        &[],
    ));
    assert!(e.contains("band=0.02") && e.contains("duplicate"), "{e}");
    let e = failure(lodbench(&["merge", s(&a), "--out", s(&out)], &[]));
    assert!(e.contains("missing: band=0.05, band=0.15"), "{e}");
    let partial = ok(lodbench(
        &["merge", s(&a), "--out", s(&out), "--allow-partial"],
        &[],
    ));
    let note = String::from_utf8_lossy(&partial.stderr);
    assert!(note.contains("left out band=0.05: missing"), "{note}");
    assert_eq!(
        read_csv(&out.join("summary.csv"))
            .iter()
            .filter(|r| r["method"] == "discrete")
            .count(),
        2
    );

    // Another version: a copy of shard 2 whose run of band=0.05 claims another lodbench.
    let edit = |from: &Path, name: &str, run: &str, key: &str, value: &str| {
        let to = dir.path().join(name);
        copy_dir(from, &to);
        let p = to.join("runs").join(run).join("run.json");
        let mut j: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
        j[key] = serde_json::Value::from(value);
        std::fs::write(&p, serde_json::to_string(&j).unwrap()).unwrap();
        to
    };
    let other = edit(
        &b,
        "other-version",
        "band=0.05",
        "lodbench_version",
        "9.9.9",
    );
    let e = failure(lodbench(
        &["merge", s(&a), s(&other), "--out", s(&out)],
        &[],
    ));
    assert!(e.contains("9.9.9") && e.contains("one version"), "{e}");
    let failed = edit(&b, "failed", "band=0.15", "status", "failed");
    let e = failure(lodbench(
        &["merge", s(&a), s(&failed), "--out", s(&out)],
        &[],
    ));
    assert!(
        e.contains("not complete: band=0.15") && e.contains("failed"),
        "{e}"
    );
    let renamed = dir.path().join("renamed");
    copy_dir(&b, &renamed);
    let p = renamed.join("experiment.json");
    let text = std::fs::read_to_string(&p)
        .unwrap()
        .replace("\"shards\"", "\"other\"");
    std::fs::write(&p, text).unwrap();
    let e = failure(lodbench(
        &["merge", s(&a), s(&renamed), "--out", s(&out)],
        &[],
    ));
    assert!(
        e.contains("another experiment") && e.contains("name"),
        "{e}"
    );
}

/// A copy of experiment folder `from` at `to` with `edit` applied to the run.json of every run named in `runs`
/// (`band=0.05`; all its runs when empty).
fn edited(from: &Path, to: &Path, runs: &[&str], edit: impl Fn(&mut serde_json::Value)) -> PathBuf {
    copy_dir(from, to);
    for entry in std::fs::read_dir(to.join("runs")).unwrap() {
        let entry = entry.unwrap();
        let name = entry.file_name().to_string_lossy().to_string();
        if !runs.is_empty() && !runs.contains(&name.as_str()) {
            continue;
        }
        let p = entry.path().join("run.json");
        let mut j: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
        edit(&mut j);
        std::fs::write(&p, serde_json::to_string_pretty(&j).unwrap()).unwrap();
    }
    to.to_path_buf()
}

/// Merge refuses runs made on other adapters (name, driver; allowed with --allow-adapters, which keeps them
/// apart by the adapter column of every merged CSV), on another timing clock, by builds from different dirty
/// trees (allowed with --allow-dirty; the same changes pass), with other flags than their plan, and CSVs whose
/// headers differ: each with one error line naming the runs (or the file) and the field. Only one adapter
/// enumerates here, so the other adapter is an edited run.json.
#[test]
fn merge_refuses_other_adapters_clocks_builds_flags_and_headers() {
    let dir = tempfile::tempdir().unwrap();
    let file = experiment_file(dir.path(), 12);
    let shard = |i: u32| {
        let out = dir.path().join(format!("shard-{i}"));
        ok(lodbench(
            &[
                "experiment",
                s(&file),
                "--shard",
                &format!("{i}/2"),
                "--out",
                s(&out),
            ],
            &[],
        ));
        out
    };
    let (a, b) = (shard(1), shard(2));
    let out = dir.path().join("merged");
    let merge = |b: &Path, extra: &[&str]| {
        let mut args = vec!["merge", s(&a), s(b), "--out", s(&out)];
        args.extend_from_slice(extra);
        lodbench(&args, &[])
    };
    let set = |key: &'static str, value: serde_json::Value| {
        move |j: &mut serde_json::Value| j[key] = value.clone()
    };
    let set_adapter = |key: &'static str, value: &'static str| {
        move |j: &mut serde_json::Value| j["adapter"][key] = value.into()
    };

    let gpu = edited(
        &b,
        &dir.path().join("gpu"),
        &[],
        set_adapter("name", "Other GPU"),
    );
    fails_with(
        &merge(&gpu, &[]),
        &[
            "band=0.05 in",
            "band=0.02 in",
            "adapter name",
            "\"Other GPU\"",
            "--allow-adapters",
        ],
    );
    ok(merge(&gpu, &["--allow-adapters"]));
    let name = |rows: &Rows| {
        let mut names: Vec<String> = rows.iter().map(|r| r["adapter"].clone()).collect();
        names.sort();
        names.dedup();
        names
    };
    let frames = read_csv(&out.join("frames.csv"));
    let names = name(&frames);
    assert_eq!(names.len(), 2, "{names:?}");
    assert!(names.contains(&"Other GPU".to_string()), "{names:?}");
    for f in ["summary.csv", "transitions.csv", "rounds.csv", "pairs.csv"] {
        assert_eq!(name(&read_csv(&out.join(f))), names, "{f}");
    }
    // The other GPU's runs are their own blocks: compare keeps them apart.
    let text = String::from_utf8_lossy(
        &ok(lodbench(&["compare", s(&out), "dither", "discrete"], &[])).stdout,
    )
    .to_string();
    assert!(
        text.contains("band=0.05, adapter=Other GPU, bunny-sweep, count 1: dither over discrete"),
        "{text}"
    );
    assert_eq!(text.matches(": dither over discrete").count(), 4, "{text}");

    let driver = edited(
        &b,
        &dir.path().join("driver"),
        &["band=0.15"],
        set_adapter("driver", "other 2.0"),
    );
    fails_with(
        &merge(&driver, &[]),
        &["band=0.15 in", "adapter driver", "other 2.0"],
    );
    ok(merge(&driver, &["--allow-adapters"]));
    // The other clock than this adapter's, which --allow-adapters does not allow.
    let ours: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(a.join("runs/band=0.02/run.json")).unwrap())
            .unwrap();
    let other = if ours["timing_source"] == "cpu-clock" {
        "gpu-timestamps"
    } else {
        "cpu-clock"
    };
    let clock = edited(
        &b,
        &dir.path().join("clock"),
        &["band=0.15"],
        set("timing_source", other.into()),
    );
    fails_with(
        &merge(&clock, &["--allow-adapters"]),
        &["band=0.15 in", "timing_source", other, "one clock"],
    );

    // Other flags than the plan's: a run whose resolved frame count is not the one planned.
    let flags = edited(&b, &dir.path().join("flags"), &["band=0.05"], |j| {
        j["config"]["resolved"][0]["frames"] = 99.into()
    });
    fails_with(
        &merge(&flags, &[]),
        &[
            "band=0.05 in",
            "other flags",
            "config.resolved[0].frames: 99 against 12",
        ],
    );

    // Dirty trees: the same changes merge, other or unknown changes only with --allow-dirty.
    let dirty = |name: &str, hash: serde_json::Value| {
        let to = dir.path().join(name);
        edited(&b, &to, &[], |j| {
            j["git_commit"] = "0123456789ab-dirty".into();
            j["source_diff_hash"] = hash.clone();
        })
    };
    let a_dirty = edited(&a, &dir.path().join("a-dirty"), &[], |j| {
        j["git_commit"] = "0123456789ab-dirty".into();
        j["source_diff_hash"] = "00000000000000aa".into();
    });
    let merge_dirty = |b: &Path, extra: &[&str]| {
        let mut args = vec!["merge", s(&a_dirty), s(b), "--out", s(&out)];
        args.extend_from_slice(extra);
        lodbench(&args, &[])
    };
    ok(merge_dirty(&dirty("same", "00000000000000aa".into()), &[]));
    let other = dirty("other", "00000000000000bb".into());
    fails_with(
        &merge_dirty(&other, &[]),
        &[
            "band=0.05 in",
            "band=0.02 in",
            "dirty tree",
            "0123456789ab-dirty",
            "00000000000000bb",
            "commit",
            "--allow-dirty",
        ],
    );
    ok(merge_dirty(&other, &["--allow-dirty"]));
    fails_with(
        &merge_dirty(&dirty("unknown", serde_json::Value::Null), &[]),
        &["dirty tree", "no source_diff_hash", "--allow-dirty"],
    );

    // A CSV whose header differs from the other runs': refused, naming the file, before anything is written.
    let header = dir.path().join("header");
    copy_dir(&b, &header);
    let summary = header.join("runs/band=0.15/summary.csv");
    let text = std::fs::read_to_string(&summary)
        .unwrap()
        .replacen("rmse_mean", "rmse_average", 1);
    std::fs::write(&summary, text).unwrap();
    let fresh = dir.path().join("fresh");
    fails_with(
        &lodbench(&["merge", s(&a), s(&header), "--out", s(&fresh)], &[]),
        &[
            "band=0.15",
            "summary.csv has another header than",
            "rmse_average against rmse_mean",
        ],
    );
    assert!(!fresh.exists(), "a refused merge writes nothing");
}

/// run.json's `status`, None while there is no run.json (it is written whole, through a temporary file).
fn run_status(path: &Path) -> Option<String> {
    let text = std::fs::read_to_string(path).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    v["status"].as_str().map(str::to_string)
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let path = entry.path();
        if path.is_dir() {
            copy_dir(&path, &to.join(entry.file_name()));
        } else {
            std::fs::copy(&path, to.join(entry.file_name())).unwrap();
        }
    }
}

/// An experiment killed by SIGTERM after its first run, then rerun with `--resume`, skips the complete run and
/// ends with the frames of an uninterrupted experiment (deterministic columns identical).
#[test]
fn resume_after_sigterm_ends_like_an_uninterrupted_run() {
    let dir = tempfile::tempdir().unwrap();
    let file = experiment_file(dir.path(), 120);
    let out = dir.path().join("resumed");
    let mut child = Command::new(env!("CARGO_BIN_EXE_lodbench"))
        .args(["experiment", s(&file), "--out", s(&out)])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let first = out.join("runs/band=0.02/run.json");
    // Wait for the first run to complete, without a clock: an experiment that ends first fails the test.
    loop {
        if run_status(&first).as_deref() == Some("complete") {
            break;
        }
        if let Some(status) = child.try_wait().unwrap() {
            let mut err = String::new();
            std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
            panic!("the experiment ended ({status}) before its first run completed: {err}");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let pid = child.id().to_string();
    assert!(Command::new("kill")
        .args(["-TERM", &pid])
        .status()
        .unwrap()
        .success());
    let status = child.wait().unwrap();
    assert!(!status.success(), "the experiment ended before the signal");
    let second = run_status(&out.join("runs/band=0.05/run.json"));
    assert_ne!(second.as_deref(), Some("complete"));
    assert!(!out.join("frames.csv").exists());

    let resumed = ok(lodbench(
        &["experiment", s(&file), "--out", s(&out), "--resume"],
        &[],
    ));
    let note = String::from_utf8_lossy(&resumed.stderr);
    assert!(
        note.contains("band=0.02: complete, skipped (--resume)"),
        "{note}"
    );
    assert!(!note.contains("band=0.05: complete"), "{note}");
    let whole = dir.path().join("whole");
    ok(lodbench(&["experiment", s(&file), "--out", s(&whole)], &[]));
    assert_eq!(
        deterministic(&read_csv(&out.join("frames.csv"))),
        deterministic(&read_csv(&whole.join("frames.csv")))
    );
}

/// `--resume` keeps a complete run only when this build made it with the planned flags: a run whose run.json
/// names another lodbench version, or other resolved flags, is rerun, with a line saying why; run.json records
/// the resolved values (the sweep's start, which the flags leave to the profile).
#[test]
fn resume_reruns_runs_of_another_build_or_other_flags() {
    let dir = tempfile::tempdir().unwrap();
    let file = experiment_file(dir.path(), 12);
    let out = dir.path().join("exp");
    ok(lodbench(&["experiment", s(&file), "--out", s(&out)], &[]));
    let run_json = |run: &str| -> serde_json::Value {
        serde_json::from_str(
            &std::fs::read_to_string(out.join("runs").join(run).join("run.json")).unwrap(),
        )
        .unwrap()
    };
    let first = run_json("band=0.02");
    assert_eq!(
        first["config"]["scene"]["sweep_start"],
        serde_json::Value::Null
    );
    assert_eq!(first["config"]["resolved"][0]["sweep_start"], "fit");
    assert_eq!(first["config"]["resolved"][0]["frames"], 12);
    let edit = |run: &str, f: &dyn Fn(&mut serde_json::Value)| {
        let p = out.join("runs").join(run).join("run.json");
        let mut j: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
        f(&mut j);
        std::fs::write(&p, serde_json::to_string_pretty(&j).unwrap()).unwrap();
    };
    edit("band=0.05", &|j| j["lodbench_version"] = "9.9.9".into());
    edit("band=0.1", &|j| {
        j["config"]["resolved"][0]["sweep_start"] = "close-up".into()
    });
    let resumed = ok(lodbench(
        &["experiment", s(&file), "--out", s(&out), "--resume"],
        &[],
    ));
    let note = String::from_utf8_lossy(&resumed.stderr);
    assert!(
        note.contains("band=0.02: complete, skipped (--resume)"),
        "{note}"
    );
    assert!(
        note.contains("band=0.15: complete, skipped (--resume)"),
        "{note}"
    );
    assert!(
        note.contains("band=0.05: rerun (--resume): it was made by lodbench 9.9.9"),
        "{note}"
    );
    assert!(
        note.contains("band=0.1: rerun (--resume): its flags differ from the plan's (config.resolved[0].sweep_start: \"close-up\" against \"fit\")"),
        "{note}"
    );
    assert!(!note.contains("band=0.05: complete"), "{note}");
    assert_eq!(
        run_json("band=0.05")["lodbench_version"],
        env!("CARGO_PKG_VERSION")
    );
    assert_eq!(
        run_json("band=0.1")["config"]["resolved"][0]["sweep_start"],
        "fit"
    );
}

/// The GPU suite stops at once, before any experiment, when the best adapter is a software one (as here).
#[test]
fn the_gpu_suite_refuses_a_software_adapter() {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/gpu-suite.sh");
    let run = Command::new("bash")
        .arg(&script)
        .arg("5")
        .env("LODBENCH", env!("CARGO_BIN_EXE_lodbench"))
        .output()
        .expect("bash runs");
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("software") && stderr.contains("llvmpipe"),
        "{stderr}"
    );
    let e = Command::new("bash")
        .arg(&script)
        .arg("many")
        .env("LODBENCH", env!("CARGO_BIN_EXE_lodbench"))
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&e.stderr).contains("whole number"));
    // An experiment named that the suite does not have is refused by name, before any run.
    let e = Command::new("bash")
        .arg(&script)
        .args(["5", "frontier", "fsi-fig9"])
        .env("LODBENCH", env!("CARGO_BIN_EXE_lodbench"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&e.stderr);
    assert_eq!(e.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("no experiment 'fsi-fig9'"), "{stderr}");
}

/// Two `[[sweep]]` tables cross into four runs, each in `runs/pixel-error=P+band=B/`, with a column per swept
/// variable (pixel-error, then band) in the joined CSVs; two shards merged give the unsharded rows.
#[test]
fn two_variable_sweep_shards_merge_to_the_unsharded_run() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("two.toml");
    std::fs::write(
        &file,
        "name = \"two\"\n[run]\nscene = [\"bunny-sweep\"]\nmethod = [\"discrete\", \"dither\"]\n\
         width = 160\nheight = 120\nframes = 12\nwarmup = 0\nrounds = 2\n\
         [[sweep]]\nvariable = \"pixel-error\"\nvalues = [0.25, 2]\n\
         [[sweep]]\nvariable = \"band\"\nvalues = [0.05, 0.15]\n",
    )
    .unwrap();
    let whole = dir.path().join("whole");
    ok(lodbench(&["experiment", s(&file), "--out", s(&whole)], &[]));
    assert!(whole
        .join("runs/pixel-error=2+band=0.05/run.json")
        .is_file());
    let header = |p: &Path| -> Vec<String> {
        let text = std::fs::read_to_string(p).unwrap();
        let first = text.lines().next().unwrap_or("");
        first.split(',').take(3).map(str::to_string).collect()
    };
    assert_eq!(
        header(&whole.join("summary.csv")),
        ["pixel-error", "band", "scene"]
    );
    let rows = read_csv(&whole.join("summary.csv"));
    let runs: Vec<(String, String)> = rows
        .iter()
        .filter(|r| r["method"] == "discrete")
        .map(|r| (r["pixel-error"].clone(), r["band"].clone()))
        .collect();
    let want = [
        ("0.25", "0.05"),
        ("0.25", "0.15"),
        ("2", "0.05"),
        ("2", "0.15"),
    ];
    assert_eq!(
        runs,
        want.map(|(a, b)| (a.to_string(), b.to_string())).to_vec()
    );
    // Each variable reaches its runs: the pixel error moves the switches (fewer triangles at 2), the band
    // widens the transitions (an instance in transition only at the wider band, in these 12 frames).
    let figure = |pe: &str, band: &str, column: &str| -> f64 {
        rows.iter()
            .find(|r| r["method"] == "discrete" && r["pixel-error"] == pe && r["band"] == band)
            .unwrap()[column]
            .parse()
            .unwrap()
    };
    assert!(figure("2", "0.05", "triangles_mean") < figure("0.25", "0.05", "triangles_mean"));
    assert!(
        figure("0.25", "0.15", "t_instances_mean") > figure("0.25", "0.05", "t_instances_mean")
    );
    let mut shards = Vec::new();
    for i in 1..=2 {
        let out = dir.path().join(format!("shard-{i}"));
        let shard = format!("{i}/2");
        ok(lodbench(
            &["experiment", s(&file), "--shard", &shard, "--out", s(&out)],
            &[],
        ));
        shards.push(out);
    }
    let merged = dir.path().join("merged");
    ok(lodbench(
        &["merge", s(&shards[0]), s(&shards[1]), "--out", s(&merged)],
        &[],
    ));
    let (a, b) = (
        read_csv(&whole.join("frames.csv")),
        read_csv(&merged.join("frames.csv")),
    );
    assert_eq!(a.len(), b.len());
    let key = |rows: &Rows| -> Vec<Vec<String>> {
        rows.iter()
            .map(|r| {
                [
                    "pixel-error",
                    "band",
                    "method",
                    "frame",
                    "triangles",
                    "lod_mean",
                    "rmse",
                    "lodpop",
                ]
                .iter()
                .map(|c| r[*c].clone())
                .collect()
            })
            .collect()
    };
    assert_eq!(key(&a), key(&b));
    assert_eq!(
        header(&merged.join("summary.csv")),
        ["pixel-error", "band", "adapter"]
    );
}
