//! Helpers every integration test shares: one way to build a run's or a scene's configuration from the flags a
//! user would type, one way to run it, and one CSV reader.

use clap::Parser;
use lodbench::cli::{Cli, Command, RunArgs};
use lodbench::config::RunConfig;
use lodbench::scene::{Scene, SceneConfig, SceneDef, SceneKind};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The flags of `lodbench run ARGS`, parsed as the binary parses them.
pub fn run_args(args: &[&str]) -> RunArgs {
    let mut argv = vec!["lodbench", "run"];
    argv.extend_from_slice(args);
    match Cli::try_parse_from(argv).expect("flags parse").command {
        Command::Run(r) => r,
        _ => unreachable!(),
    }
}

/// The validated configuration of `lodbench run ARGS`.
pub fn run_config(args: &[&str]) -> RunConfig {
    RunConfig::from_args(&run_args(args)).expect("valid config")
}

/// Runs `lodbench run ARGS --out OUT` in-process; returns OUT.
pub fn run_into(out: &Path, args: &[&str]) -> PathBuf {
    let mut argv = args.to_vec();
    argv.extend_from_slice(&["--out", out.to_str().expect("a UTF-8 path")]);
    lodbench::runner::run(&run_config(&argv)).expect("the run completes");
    out.to_path_buf()
}

/// The scene configuration of `lodbench describe --scene SCENE ARGS` (the scene flags `run` shares).
pub fn scene_config(scene: &str, args: &[&str]) -> SceneConfig {
    let mut argv = vec!["lodbench", "describe", "--scene", scene];
    argv.extend_from_slice(args);
    match Cli::try_parse_from(argv).expect("flags parse").command {
        Command::Describe(d) => SceneConfig::from_args(&d.scene_args).expect("valid scene flags"),
        _ => unreachable!(),
    }
}

/// bunny-sweep built from scene flags.
pub fn sweep_scene(args: &[&str]) -> Scene {
    SceneDef::new(SceneKind::BunnySweep, &scene_config("bunny-sweep", args))
        .expect("the scene builds")
        .instantiate(1)
}

/// One CSV row, by column name.
pub type Row = HashMap<String, String>;
pub type Rows = Vec<Row>;

/// Every row of a CSV file written by lodbench.
pub fn read_csv(path: &Path) -> Rows {
    let mut r = csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let headers = r.headers().expect("a header row").clone();
    r.records()
        .map(|rec| {
            let rec = rec.expect("a CSV record");
            headers
                .iter()
                .zip(rec.iter())
                .map(|(h, v)| (h.to_string(), v.to_string()))
                .collect()
        })
        .collect()
}

/// Column `name` of `method`'s rows, as numbers.
pub fn col(rows: &Rows, method: &str, name: &str) -> Vec<f64> {
    rows.iter()
        .filter(|r| r["method"] == method)
        .map(|r| {
            r[name]
                .parse::<f64>()
                .unwrap_or_else(|_| panic!("{name}={}", r[name]))
        })
        .collect()
}
