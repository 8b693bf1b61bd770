//! A run: validates the output folder, writes run.json, opens the GPU, and measures every scene block x method
//! (`crate::measure`), writing frames.csv as blocks finish and summary.csv at the end.

use crate::cli::run_config::RunConfig;
use crate::cli::RunArgs;
use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::measure::records::{
    pair_records, round_records, set_visible_pops, BlockInfo, Clock, FrameRecord, PairRecord,
    RoundRecord, SummaryRecord, SwitchRecord, TransitionRecord, Visibility,
};
use crate::measure::{BlockOutput, BlockRunner, FrameImages, MethodSetup, QualityOptions};
use crate::methods::{is_reference, Registry};
use crate::results::answer::AnswerFile;
use crate::results::csv::{
    write_events, write_pairs, write_rounds, write_summary, write_transitions, FramesWriter,
};
use crate::results::files::{stale_run_files, WRITE_PROBE};
use crate::results::manifest::{now_rfc3339, peak_resident_bytes, RunManifest, RunStatus};
use crate::results::png::{DumpImages, FrameDumper, FrameId};
use crate::scene::{Scene, SceneDef};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;

pub use crate::measure::INTERRUPTED;

/// `lodbench run`: checks the flags, runs, prints the summary table and the results folder.
pub fn execute(args: &RunArgs) -> Result<()> {
    let cfg = RunConfig::from_args(args)?;
    stop_on_signal();
    let summary = run(&cfg)?;
    out!("{}", summary_table(&summary));
    outln!("{}", calibration_line(&cfg, &summary.summaries));
    outln!("results in {}", summary.out_dir.display());
    Ok(())
}

/// What the pops are measured in, and the visible pops per minute of each method: in JNDs of a calibration, or
/// not calibrated (lodpop, over the budget).
fn calibration_line(cfg: &RunConfig, summaries: &[SummaryRecord]) -> String {
    let per_min: Vec<String> = summaries
        .iter()
        .filter_map(|s| {
            let v = s.visible_pops_per_min?;
            Some(format!(
                "{} {} (n={})",
                s.method,
                crate::numbers::sig3(Some(v)),
                s.count
            ))
        })
        .collect();
    let unit = match &cfg.calibration {
        Some(j) => format!("pops in JNDs (summary.csv's lodpop_max_jnd): {}", j.describe()),
        None => "not calibrated: pops are lodpop, visible ones those over the budget (lodbench calibrate and \
                 --calibration give JNDs a person measured)"
            .to_string(),
    };
    format!(
        "{unit}\nvisible pops per minute of the path at {} fps: {}",
        cfg.path_fps,
        match per_min.is_empty() {
            true => "- (no quality pass)".to_string(),
            false => per_min.join(", "),
        }
    )
}

/// On Ctrl-C, the run stops after the frame in progress (run.json says interrupted); a second signal while
/// the first is being handled ends the process at once.
pub fn stop_on_signal() {
    let _ = ctrlc::set_handler(|| {
        if INTERRUPTED.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
    });
}

/// What a finished run produced.
#[derive(Clone)]
pub struct RunSummary {
    pub out_dir: PathBuf,
    pub summaries: Vec<SummaryRecord>,
    /// pairs.csv's rows.
    pub pairs: Vec<PairRecord>,
    pub blocks: Vec<BlockInfo>,
    /// The answer the table ends with, as answer.json holds it.
    pub answer: AnswerFile,
    /// The adapter is a CPU rasteriser (lavapipe): no GPU clock to drop, and its triangle rate read around a block
    /// varies by up to 40 % from reading to reading, so the blocks' clock notes are not printed.
    pub cpu_adapter: bool,
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
    let probe = dir.join(WRITE_PROBE);
    std::fs::write(&probe, b"").map_err(|e| out_err(format!("is not writable ({e})")))?;
    let _ = std::fs::remove_file(&probe);
    for stale in stale_run_files() {
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
    for note in defs.iter().filter(|_| !cfg.quiet).flat_map(|d| d.notes()) {
        eprintln!("note: {note}");
    }
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
    manifest.peak_resident_bytes = peak_resident_bytes();
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
    let (summaries, pairs) = result?;
    let answer = crate::results::answer::write(&out_dir)?;
    Ok(RunSummary {
        out_dir,
        summaries,
        pairs,
        blocks: manifest.blocks.clone(),
        answer,
        cpu_adapter: manifest
            .adapter
            .as_ref()
            .is_some_and(|a| a.device_type == "Cpu"),
    })
}

/// What the blocks of a run add up to, written at the end (frames.csv as each block finishes).
struct RunOutput {
    frames_csv: FramesWriter,
    summaries: Vec<SummaryRecord>,
    transitions: Vec<TransitionRecord>,
    switches: Vec<SwitchRecord>,
    rounds: Vec<RoundRecord>,
    pairs: Vec<PairRecord>,
}

/// What every block of a run shares.
struct RunJob<'a> {
    cfg: &'a RunConfig,
    registry: &'a Registry,
    ctx: GpuContext,
    dumper: Option<FrameDumper>,
    progress: ProgressBar,
    out_dir: &'a Path,
}

/// One method's quality pass over a block: its frame rows and its extra targets' size.
struct MeasuredMethod {
    rows: Vec<FrameRecord>,
    extra_target_bytes: u64,
}

fn run_blocks(
    cfg: &RunConfig,
    registry: &Registry,
    defs: &[SceneDef],
    out_dir: &Path,
    manifest: &mut RunManifest,
) -> Result<(Vec<SummaryRecord>, Vec<PairRecord>)> {
    let (ctx, clock, warm_on) = open_adapter(cfg, manifest)?;
    let warm = clock.as_ref().filter(|_| warm_on);
    manifest.write(out_dir)?;

    let dumper = if cfg.dump_frames {
        Some(FrameDumper::create(out_dir)?)
    } else {
        None
    };
    let mut output = RunOutput {
        frames_csv: FramesWriter::create(out_dir)?,
        summaries: Vec::new(),
        transitions: Vec::new(),
        switches: Vec::new(),
        rounds: Vec::new(),
        pairs: Vec::new(),
    };
    let job = RunJob {
        cfg,
        registry,
        ctx,
        dumper,
        progress: progress_bar(total_frames(cfg, defs)),
        out_dir,
    };
    let mut block_index = 0u64;
    for def in defs {
        for &count in &def.counts {
            block_index += 1;
            let first = manifest.blocks.len();
            let before = clock
                .as_ref()
                .map(|c| c.triangle_rate(&job.ctx))
                .transpose()?;
            job.run_block((def, count, block_index), warm, manifest, &mut output)?;
            let after = clock
                .as_ref()
                .map(|c| c.triangle_rate(&job.ctx))
                .transpose()?;
            for b in &mut manifest.blocks[first..] {
                b.triangle_rate_before = before;
                b.triangle_rate_after = after;
            }
        }
    }
    let ceiling = run_triangle_ceiling(manifest);
    manifest.triangle_ceiling = ceiling;
    manifest.write(out_dir)?;
    job.progress.finish_and_clear();
    output.frames_csv.finish()?;
    for s in &mut output.summaries {
        s.set_ceiling(ceiling, manifest.fragment_ceiling);
    }
    let RunOutput {
        mut summaries,
        mut transitions,
        switches,
        rounds,
        pairs,
        ..
    } = output;
    write_run_csvs(cfg, out_dir, (&mut summaries, &mut transitions, &switches))?;
    write_rounds(out_dir, &rounds)?;
    write_pairs(out_dir, &pairs)?;
    Ok((summaries, pairs))
}

/// The visible pops (over 1 JND with a calibration, whatever the budget, else over the budget), then
/// summary.csv, transitions.csv and events.csv, each whole.
fn write_run_csvs(
    cfg: &RunConfig,
    out_dir: &Path,
    (summaries, transitions, switches): (
        &mut [SummaryRecord],
        &mut [TransitionRecord],
        &[SwitchRecord],
    ),
) -> Result<()> {
    let visibility = Visibility {
        threshold: match &cfg.calibration {
            Some(j) => Some(j.value_of(1.0)),
            None => cfg.budget_lodpop,
        },
        fps: cfg.path_fps,
        jnd: cfg.calibration.as_ref().map(|j| j.threshold),
    };
    let events = set_visible_pops(summaries, transitions, switches, visibility);
    write_summary(out_dir, summaries)?;
    write_transitions(out_dir, transitions)?;
    write_events(out_dir, &events)?;
    Ok(())
}

/// The adapter the run draws on, recorded in the manifest with its ceilings (`--ceilings on`: measured now, and
/// the probe that reads the triangle rate around each block), and whether that probe warms the GPU's clock
/// before each timed segment (`--clock-warmup`; auto: not on a CPU adapter, which has no GPU clock).
fn open_adapter(
    cfg: &RunConfig,
    manifest: &mut RunManifest,
) -> Result<(
    GpuContext,
    Option<crate::measure::probe_rounds::ClockCheck>,
    bool,
)> {
    let ctx = GpuContext::new(cfg.adapter.as_deref())?;
    manifest.adapter = Some(ctx.info.clone());
    manifest.timing_source = Some(ctx.timing);
    manifest.timestamp_period_ns = Some(ctx.timestamp_period_ns);
    let clock = match cfg.ceilings {
        crate::effects::OnOff::On => Some(crate::measure::probe_rounds::ClockCheck::new(&ctx)?),
        crate::effects::OnOff::Off => None,
    };
    if let Some(c) = &clock {
        let rows = crate::measure::probe_rounds::ceilings(&ctx, c, cfg.seed)?;
        c.note_ceilings(&rows);
        let fill = crate::measure::probe_rounds::fill_ceilings(&ctx, cfg.seed)?;
        manifest.fragment_ceiling =
            crate::measure::probe_rounds::fragment_ceiling(rows.iter().chain(&fill));
        manifest.ceilings = Some(rows);
        manifest.fill_ceilings = Some(fill);
    }
    let warm_on = clock.is_some()
        && match cfg.clock_warmup {
            crate::cli::ClockWarmup::On => true,
            crate::cli::ClockWarmup::Auto => ctx.info.device_type != "Cpu",
            crate::cli::ClockWarmup::Off => false,
        };
    manifest.clock_warmup = Some(warm_on);
    Ok((ctx, clock, warm_on))
}

/// The run's triangle ceiling (run.json's `triangle_ceiling`): the highest triangle rate of its start's probes and
/// of the readings around its blocks; None with `--ceilings off`.
fn run_triangle_ceiling(manifest: &RunManifest) -> Option<f64> {
    manifest.ceilings.as_deref().and_then(|rows| {
        let readings = manifest.blocks.iter().flat_map(|b| {
            [b.triangle_rate_before, b.triangle_rate_after]
                .into_iter()
                .flatten()
        });
        crate::measure::probe_rounds::run_triangle_ceiling(rows, readings)
    })
}

/// The frames the progress bar counts: per block, every method's warm-up, timed and quality frames (with the
/// quality pass's own warm-up), and the reference's warm-up and timed frames when it is timed without being
/// reported (with the quality pass only).
fn total_frames(cfg: &RunConfig, defs: &[SceneDef]) -> u64 {
    let quality = cfg.quality_pass() as u64;
    defs.iter()
        .map(|d| {
            let pv = cfg.resolved(d.kind);
            let methods = cfg.methods_for(d.kind);
            let timed_only = quality * !methods.iter().any(|m| is_reference(m)) as u64;
            let (warmup, frames) = (pv.warmup as u64, pv.frames as u64);
            d.counts.len() as u64
                * (methods.len() as u64 * (1 + quality) * (warmup + frames)
                    + timed_only * (warmup + frames))
        })
        .sum()
}

fn progress_bar(total: u64) -> ProgressBar {
    let progress = ProgressBar::new(total);
    progress.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} frames {msg}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    progress
}

/// The quality pass's options for a block of `methods` methods.
fn quality_options(cfg: &RunConfig, methods: usize) -> QualityOptions {
    QualityOptions {
        metrics: cfg.metrics.clone(),
        reduction: cfg.metric_reduction,
        region: cfg.metric_region,
        timing_only: !cfg.quality_pass(),
        schedule: cfg.quality_schedule,
        // Kept only for a block whose quality pass runs more than one method.
        reference_cache_bytes: if methods > 1 {
            cfg.reference_cache_mib << 20
        } else {
            0
        },
    }
}

/// Writes each method's rows to frames.csv and its transitions and block info to the run's, returning the
/// measured methods in the order they were listed (pairs.csv's a before b).
fn record_outputs(
    outputs: Vec<BlockOutput>,
    methods: &[String],
    manifest: &mut RunManifest,
    output: &mut RunOutput,
) -> Result<Vec<MeasuredMethod>> {
    let mut measured = Vec::new();
    for out in outputs {
        output.frames_csv.write_block(&out.rows)?;
        output.transitions.extend(out.transitions);
        output.switches.extend(out.switches);
        measured.push(MeasuredMethod {
            extra_target_bytes: out.info.extra_target_bytes,
            rows: out.rows,
        });
        manifest.blocks.push(out.info);
    }
    // The reported methods in the order they were listed (pairs.csv's a before b).
    measured.sort_by_key(|m| {
        m.rows
            .first()
            .and_then(|r| methods.iter().position(|l| *l == r.method))
    });
    Ok(measured)
}

impl RunJob<'_> {
    /// Scene block `def` with `count` instances, the `block_index`-th of the run: its methods' rounds (timing,
    /// then quality pass, round by round), their summaries and rounds.
    fn run_block(
        &self,
        (def, count, block_index): (&SceneDef, u32, u64),
        warm: Option<&crate::measure::probe_rounds::ClockCheck>,
        manifest: &mut RunManifest,
        output: &mut RunOutput,
    ) -> Result<()> {
        let cfg = self.cfg;
        let warmup = cfg.resolved(def.kind).warmup;
        let methods = cfg.methods_for(def.kind);
        let baseline = cfg.baseline_for(&methods);
        let scene = def.instantiate(count);
        let setup = MethodSetup {
            registry: self.registry.clone(),
            options: cfg.method_options,
            seed: cfg.seed,
        };
        let quality = quality_options(cfg, methods.len());
        let mut block =
            BlockRunner::new(&self.ctx, &scene, setup, self.dumper.is_some(), &quality)?;
        block.dump_transitions_only(cfg.dump_transitions);
        block.warm_clock_with(warm);
        let stage = match cfg.quality_pass() {
            true => "timing and quality rounds",
            false => "timing rounds",
        };
        self.progress
            .set_message(format!("{} n={} {stage}", def.name(), count));
        // Each block's shuffles have their own seed, derived from --seed and the block's position.
        let rounds_seed = crate::rng::SplitMix64::new(cfg.seed ^ 0x524F_554E_4453)
            .next_u64()
            .wrapping_add(block_index);
        let (outputs, block_rounds) = block.measure_block(
            &methods,
            (warmup, cfg.rounds, rounds_seed),
            cfg.dump_every,
            &self.progress,
            |method, f, images| self.dump(&scene, method, f, images),
        )?;
        let measured = record_outputs(outputs, &methods, manifest, output)?;
        // The block's one clock.
        let clock = Clock::of(measured.iter().flat_map(|m| &m.rows));
        summarise(
            cfg,
            (baseline.as_deref(), clock),
            &measured,
            crate::measure::shortest_transition(&scene),
            &mut output.summaries,
        );
        let block_rows: Vec<Vec<FrameRecord>> = measured.into_iter().map(|m| m.rows).collect();
        output.rounds.extend(round_records(
            &block_rows,
            &block_rounds,
            baseline.as_deref(),
            clock,
        ));
        output.pairs.extend(pair_records(&block_rows, clock));
        manifest.timing_rounds.push(block_rounds);
        manifest.write(self.out_dir)
    }

    /// Writes one frame's dumps (with `--dump-frames`).
    fn dump(
        &self,
        scene: &Scene,
        method: &str,
        frame: u32,
        frame_images: FrameImages<'_>,
    ) -> Result<()> {
        let Some(d) = &self.dumper else {
            return Ok(());
        };
        let id = FrameId {
            scene: scene.name(),
            method,
            count: scene.count,
            frame,
        };
        let images = DumpImages {
            width: scene.width,
            height: scene.height,
            method: frame_images.method,
            reference: frame_images.reference,
            extras: frame_images.extras,
        };
        d.write(&id, &images)
    }
}

/// Each measured method's summary row, with its ratios to the baseline where the baseline was measured too, on
/// the block's `clock`, and the block's shortest transition (`room`, [`crate::measure::shortest_transition`]).
fn summarise(
    cfg: &RunConfig,
    (baseline, clock): (Option<&str>, Clock),
    measured: &[MeasuredMethod],
    room: Option<u32>,
    summaries: &mut Vec<SummaryRecord>,
) {
    let baseline_rows = baseline.and_then(|b| {
        measured
            .iter()
            .map(|m| &m.rows)
            .find(|r| r.first().is_some_and(|r| r.method == b))
    });
    for m in measured {
        // Each block's bootstrap has its own seed, derived from --seed and the block's position.
        let block_seed = cfg.seed.wrapping_add(summaries.len() as u64 + 1);
        if let Some(mut s) =
            SummaryRecord::from_frames(&m.rows, m.extra_target_bytes, block_seed, clock)
        {
            if let (Some(b), Some(base)) = (baseline, baseline_rows) {
                s.set_ratios(b, &m.rows, base);
            }
            s.transition_frames_min = room;
            summaries.push(s);
        }
    }
}

/// The table printed at the end of a run: columns sized to their contents, numbers by unit (milliseconds to 3
/// significant figures, triangles with thousands separators, ratios with their interval; full precision in the
/// CSVs), then the answer (answer.json's sentences, `results::answer`) and what the columns mean.
pub fn summary_table(s: &RunSummary) -> String {
    let right = [
        false, false, true, true, true, true, true, true, true, true, true, true, false,
    ];
    let mut out = crate::numbers::aligned(&summary_rows(s), &right);
    out.push_str(&crate::results::answer::sentences_text(&s.answer));
    let baseline = s.summaries.iter().find_map(|r| r.baseline.clone());
    out.push_str(&format!(
        "lodpop max is the popping: the largest change LOD switching alone makes to a frame, the pose held \
         (root mean square over the frame of the sRGB values, 0 to 1); rmse is the error against the \
         high-poly reference in the same unit, pop max its largest change from one frame to the next. \
         Per frame: gpu ms and cpu ms are medians, triangles a mean. q/r = quality-pass time per frame / the \
         timing-pass time of the renders it makes (method, reference where drawn, lodpop's counterfactual where \
         drawn), paired by round (geometric mean; its interval in run.json); time / baseline = time over {}'s, \
         paired by timing round, geometric mean and 95 % t interval over rounds (every other pair: pairs.csv, \
         lodbench compare DIR A B); '-' = not measured (no timestamps; --quality off: no image figures); figures \
         rounded to 3 significant figures, full precision in summary.csv\n",
        baseline.as_deref().unwrap_or("the baseline (none run)")
    ));
    push_notes(&mut out, s);
    out
}

/// The summary table's header and one row of cells per summary.
fn summary_rows(s: &RunSummary) -> Vec<Vec<String>> {
    use crate::numbers::{ratio, sig3, thousands};
    let mut rows = vec![[
        "scene",
        "method",
        "count",
        "frames",
        "gpu ms median",
        "cpu ms median",
        "triangles mean",
        "rmse mean",
        "rmse max",
        "pop max",
        "lodpop max",
        "q/r",
        "time / baseline [95 % CI]",
    ]
    .map(String::from)
    .to_vec()];
    for r in &s.summaries {
        let q = s
            .blocks
            .iter()
            .find(|b| b.scene == r.scene && b.method == r.method && b.count == r.count)
            .and_then(|b| b.quality_to_renders_ratio);
        rows.push(vec![
            r.scene.clone(),
            r.method.clone(),
            r.count.to_string(),
            r.frames.to_string(),
            sig3(r.gpu_ms_median),
            sig3(Some(r.cpu_ms_median)),
            thousands(Some(r.triangles_mean)),
            sig3(r.rmse_mean),
            sig3(r.rmse_max),
            sig3(r.pop_max),
            sig3(r.lodpop_max),
            q.map_or("-".into(), |q| format!("{q:.2}")),
            ratio(
                r.ratio_to_baseline,
                r.ratio_to_baseline_ci95_lo,
                r.ratio_to_baseline_ci95_hi,
            ),
        ]);
    }
    rows
}

/// The notes under the table: each block whose adapter changed speed during it (not on a CPU adapter), and
/// each block's material limits.
fn push_notes(out: &mut String, s: &RunSummary) {
    let mut said = Vec::new();
    for b in &s.blocks {
        if s.cpu_adapter {
            break;
        }
        if let (Some(x), Some(y)) = (b.triangle_rate_before, b.triangle_rate_after) {
            if crate::measure::probe_rounds::clock_changed(x, y)
                && !said.contains(&(&b.scene, b.count))
            {
                said.push((&b.scene, b.count));
                out.push_str(&format!(
                    "note: {} n={}: the adapter's triangle rate was {:.3} M/s before the block and {:.3} M/s \
                     after it: the adapter changed speed during the block, and its times are suspect\n",
                    b.scene,
                    b.count,
                    x / 1e6,
                    y / 1e6
                ));
            }
        }
    }
    for b in &s.blocks {
        if let Some(limit) = &b.material_limits {
            out.push_str(&format!("note: {} {}: {limit}\n", b.scene, b.method));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(scene: &str, method: &str, gpu_ms: f64, triangles: f64) -> SummaryRecord {
        SummaryRecord {
            scene: scene.into(),
            method: method.into(),
            count: 1,
            frames: 600,
            gpu_ms_median: Some(gpu_ms),
            cpu_ms_median: gpu_ms * 1.1,
            triangles_mean: triangles,
            lodpop_max: Some(0.004 * gpu_ms),
            baseline: Some("discrete".into()),
            ratio_to_baseline: Some(gpu_ms),
            ratio_to_baseline_ci95_lo: Some(gpu_ms * 0.9),
            ratio_to_baseline_ci95_hi: Some(gpu_ms * 1.1),
            ..SummaryRecord::default()
        }
    }

    #[test]
    fn a_block_the_adapter_slowed_in_is_noted_once() {
        let block = |method: &str, before: f64, after: f64| BlockInfo {
            scene: "terrain".into(),
            method: method.into(),
            count: 1,
            triangle_rate_before: Some(before),
            triangle_rate_after: Some(after),
            ..BlockInfo::default()
        };
        let s = RunSummary {
            out_dir: PathBuf::from("out"),
            summaries: vec![record("terrain", "blocks", 1.0, 1000.0)],
            pairs: Vec::new(),
            blocks: vec![block("blocks", 10e6, 2.5e6), block("roam", 10e6, 2.5e6)],
            answer: answer_of(&[record("terrain", "blocks", 1.0, 1000.0)]),
            cpu_adapter: false,
        };
        let text = summary_table(&s);
        assert_eq!(
            text.matches("changed speed during the block").count(),
            1,
            "{text}"
        );
        assert!(
            text.contains("note: terrain n=1: the adapter's triangle rate was 10.000 M/s before")
        );
        let on_a_cpu = RunSummary {
            cpu_adapter: true,
            ..s.clone()
        };
        assert!(!summary_table(&on_a_cpu).contains("changed speed"));
        let steady = RunSummary {
            blocks: vec![block("blocks", 10e6, 9e6)],
            ..s
        };
        assert!(!summary_table(&steady).contains("changed speed"));
    }

    fn answer_of(summaries: &[SummaryRecord]) -> AnswerFile {
        crate::results::answer::from_records(summaries, &[], &[], None).expect("rows")
    }

    #[test]
    fn the_table_stays_aligned_for_a_long_scene_name() {
        let long = "a-forty-character-user-scene-name-01.glb";
        assert_eq!(long.len(), 40);
        let summaries = vec![
            record("bunny-sweep", "discrete", 1.0, 1183.0),
            record("bunny-sweep", "alpha-2pass", 1.234_567, 1556.4),
            record(long, "discrete", 1.0, 557_500.0),
            record(long, "fsi-noreproject", 12.345_67, 3674.0),
        ];
        let s = RunSummary {
            out_dir: PathBuf::from("out"),
            answer: answer_of(&summaries),
            summaries,
            pairs: Vec::new(),
            blocks: Vec::new(),
            cpu_adapter: false,
        };
        let text = summary_table(&s);
        let lines: Vec<&str> = text.lines().take(5).collect();
        // Each column's cells start (text) or end (numbers) at the same place on every line.
        let method_at = lines[0].find("method").expect("the header");
        for (line, method) in
            lines[1..]
                .iter()
                .zip(["discrete", "alpha-2pass", "discrete", "fsi-noreproject"])
        {
            assert_eq!(line.find(method), Some(method_at), "{text}");
        }
        let gpu_end = lines[0].find("gpu ms median").expect("the header") + "gpu ms median".len();
        for (line, ms) in lines[1..].iter().zip(["1.00", "1.23", "1.00", "12.3"]) {
            assert!(line[..gpu_end].ends_with(ms), "{text}");
        }
        let ratio_at = lines[0].find("time / baseline").expect("the header");
        for (line, r) in
            lines[1..]
                .iter()
                .zip(["1.00 [0.90", "1.23 [1.11", "1.00 [0.90", "12.35 [11.11"])
        {
            assert_eq!(line.find(r), Some(ratio_at), "{text}");
        }
        assert!(text.contains("557,500"), "{text}");
        // The answer follows the table, one per scene.
        assert!(
            text.contains(&format!("{long}: discrete pops least")),
            "{text}"
        );
    }
}
