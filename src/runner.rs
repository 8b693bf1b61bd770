//! A run: validates the output folder, writes run.json, opens the GPU, and measures every scene block x method
//! (`crate::measure`), writing frames.csv as blocks finish and summary.csv at the end.

use crate::config::RunConfig;
use crate::error::{Error, Result};
use crate::export::csv::{write_summary, write_transitions, FramesWriter};
use crate::export::manifest::{now_rfc3339, RunManifest, RunStatus};
use crate::export::png::FrameDumper;
use crate::gpu::GpuContext;
use crate::measure::{BlockRunner, MethodSetup};
use crate::methods::Registry;
use crate::records::{BlockInfo, SummaryRecord};
use crate::scene::SceneDef;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};

pub use crate::measure::INTERRUPTED;

/// What a finished run produced.
pub struct RunSummary {
    pub out_dir: PathBuf,
    pub summaries: Vec<SummaryRecord>,
    pub blocks: Vec<BlockInfo>,
}

/// The default output folder: results/<scenes>-<UTC time>/.
pub fn default_out_dir(scenes: &[&str]) -> PathBuf {
    let stamp: String = now_rfc3339()
        .chars()
        .filter(|c| c.is_ascii_digit() || *c == 'T')
        .collect::<String>()
        .replace('T', "-");
    PathBuf::from("results").join(format!("{}-{stamp}", scenes.join("+")))
}

/// Creates the output folder and checks it is writable before any GPU work; removes result files of an
/// earlier run there so nothing stale looks complete.
pub fn prepare_output(dir: &Path) -> Result<()> {
    let out_err = |problem: String| Error::Output {
        path: dir.to_path_buf(),
        problem,
    };
    if dir.exists() && !dir.is_dir() {
        return Err(out_err("exists and is not a folder".into()));
    }
    std::fs::create_dir_all(dir).map_err(|e| out_err(format!("cannot be created ({e})")))?;
    let probe = dir.join(".lodbench-write-test");
    std::fs::write(&probe, b"").map_err(|e| out_err(format!("is not writable ({e})")))?;
    let _ = std::fs::remove_file(&probe);
    for stale in [
        "frames.csv",
        "summary.csv",
        "transitions.csv",
        "frames.csv.partial",
    ] {
        let p = dir.join(stale);
        if p.exists() {
            std::fs::remove_file(&p).map_err(|e| Error::io(&p, e))?;
        }
    }
    Ok(())
}

/// Runs everything `cfg` asks for with the built-in methods.
pub fn run(cfg: &RunConfig) -> Result<RunSummary> {
    run_with(cfg, &Registry::builtin())
}

/// Runs everything `cfg` asks for, its methods taken from `registry`. run.json is written at the start (status
/// running) and at the end with the outcome, also when the run fails or is interrupted.
pub fn run_with(cfg: &RunConfig, registry: &Registry) -> Result<RunSummary> {
    // Everything that can be checked without a device is checked first.
    let defs = cfg
        .scenes
        .iter()
        .map(|&s| SceneDef::new(s, &cfg.scene))
        .collect::<Result<Vec<_>>>()?;
    let out_dir = cfg.out.clone().unwrap_or_else(|| {
        default_out_dir(&cfg.scenes.iter().map(|s| s.name()).collect::<Vec<_>>())
    });
    prepare_output(&out_dir)?;
    let mut manifest = RunManifest::new(cfg.clone());
    manifest.scenes = defs.iter().map(|d| d.describe(&cfg.scene)).collect();
    manifest.write(&out_dir).map_err(|e| Error::Output {
        path: out_dir.clone(),
        problem: format!("run.json cannot be written ({e})"),
    })?;

    let result = run_blocks(cfg, registry, &defs, &out_dir, &mut manifest);
    manifest.end_time = Some(now_rfc3339());
    match &result {
        Ok(_) => manifest.status = RunStatus::Complete,
        Err(Error::Interrupted) => {
            manifest.status = RunStatus::Interrupted;
            manifest.error = Some("interrupted by signal".into());
        }
        Err(e) => {
            manifest.status = RunStatus::Failed;
            manifest.error = Some(e.to_string());
        }
    }
    manifest.write(&out_dir)?;
    let summaries = result?;
    Ok(RunSummary {
        out_dir,
        summaries,
        blocks: manifest.blocks.clone(),
    })
}

fn run_blocks(
    cfg: &RunConfig,
    registry: &Registry,
    defs: &[SceneDef],
    out_dir: &Path,
    manifest: &mut RunManifest,
) -> Result<Vec<SummaryRecord>> {
    let ctx = GpuContext::new(cfg.adapter.as_deref())?;
    manifest.adapter = Some(ctx.info.clone());
    manifest.timing_source = Some(ctx.timing);
    manifest.timestamp_period_ns = Some(ctx.timestamp_period_ns);
    manifest.write(out_dir)?;

    let dumper = if cfg.dump_frames {
        Some(FrameDumper::create(out_dir)?)
    } else {
        None
    };
    let mut frames_csv = FramesWriter::create(out_dir)?;
    let mut summaries = Vec::new();
    let mut transitions = Vec::new();

    let total: u64 = defs
        .iter()
        .map(|d| {
            let pv = cfg.resolved(d.kind);
            d.counts.len() as u64
                * cfg.methods.len() as u64
                * (pv.warmup as u64 + 2 * pv.frames as u64)
        })
        .sum();
    let progress = ProgressBar::new(total);
    progress.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} frames {msg}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );

    for def in defs {
        let warmup = cfg.resolved(def.kind).warmup;
        for &count in &def.counts {
            let scene = def.instantiate(count);
            let setup = MethodSetup {
                registry: registry.clone(),
                options: cfg.method_options,
                seed: cfg.seed,
            };
            let flip = cfg.metrics.contains(&crate::metrics::Metric::Flip);
            let mut block = BlockRunner::new(&ctx, &scene, setup, dumper.is_some(), flip)?;
            block.dump_transitions_only(cfg.dump_transitions);
            for method in &cfg.methods {
                progress.set_message(format!("{} n={} {}", def.name(), count, method));
                let out = block.run_method(
                    method,
                    warmup,
                    cfg.dump_every,
                    &progress,
                    |f, (m, r, x)| match &dumper {
                        Some(d) => d.write(
                            scene.name(),
                            method,
                            count,
                            f,
                            scene.width,
                            scene.height,
                            m,
                            r,
                            x,
                        ),
                        None => Ok(()),
                    },
                )?;
                frames_csv.write_block(&out.rows)?;
                transitions.extend(out.transitions);
                // Each block's bootstrap has its own seed, derived from --seed and the block's position.
                let block_seed = cfg.seed.wrapping_add(summaries.len() as u64 + 1);
                let extra = out.info.extra_target_bytes;
                if let Some(s) = SummaryRecord::from_frames(&out.rows, extra, block_seed) {
                    summaries.push(s);
                }
                manifest.blocks.push(out.info);
                manifest.write(out_dir)?;
            }
        }
    }
    progress.finish_and_clear();
    frames_csv.finish()?;
    write_summary(out_dir, &summaries)?;
    write_transitions(out_dir, &transitions)?;
    Ok(summaries)
}

/// The table printed at the end of a run.
pub fn summary_table(s: &RunSummary) -> String {
    let mut out = format!(
        "{:<12} {:<15} {:>5} {:>6} {:>9} {:>9} {:>10} {:>9} {:>9} {:>9} {:>10} {:>7}\n",
        "scene",
        "method",
        "count",
        "frames",
        "gpu_ms",
        "cpu_ms",
        "triangles",
        "rmse",
        "rmse_max",
        "pop_max",
        "lodpop_max",
        "q/t"
    );
    let fmt_opt = |v: Option<f64>| v.map_or("-".to_string(), |x| format!("{x:.3}"));
    for r in &s.summaries {
        let ratio = s
            .blocks
            .iter()
            .find(|b| b.scene == r.scene && b.method == r.method && b.count == r.count)
            .map_or(f64::NAN, |b| b.quality_to_timing_ratio);
        out.push_str(&format!(
            "{:<12} {:<15} {:>5} {:>6} {:>9} {:>9.3} {:>10.0} {:>9.5} {:>9.5} {:>9.5} {:>10.5} {:>7.2}\n",
            r.scene,
            r.method,
            r.count,
            r.frames,
            fmt_opt(r.gpu_ms_median),
            r.cpu_ms_median,
            r.triangles_mean,
            r.rmse_mean,
            r.rmse_max,
            r.pop_max,
            r.lodpop_max,
            ratio
        ));
    }
    out.push_str("gpu_ms and cpu_ms are medians; q/t = quality-pass time per frame / timing-pass time per frame\n");
    out
}
