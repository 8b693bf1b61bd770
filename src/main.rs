//! The `lodbench` binary: parse flags, dispatch, print one line on error.

use clap::Parser;
use lodbench::cli::config::RunConfig;
use lodbench::cli::{Cli, Command, DescribeArgs};
use lodbench::commands::run as runner;
use lodbench::scene::{SceneConfig, SceneDef, SceneKind};
use lodbench::{gpu, methods, Error};
use std::process::ExitCode;
use std::sync::atomic::Ordering;

/// `print!` / `println!` to stdout that give up quietly when stdout is gone (`lodbench describe ... | head`):
/// a closed pipe is no error of lodbench's, and `print!` would panic on it.
macro_rules! out {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = write!(std::io::stdout(), $($t)*);
    }};
}
macro_rules! outln {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($t)*);
    }};
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    quiet_wayland_probe();
    let result = match cli.command {
        Command::Run(args) => run(&args),
        Command::List => list(),
        Command::Describe(args) => describe(&args),
        Command::Experiment(args) => experiment(&args),
        Command::Merge(args) => merge(&args),
        Command::Perceptual(args) => perceptual(&args),
        Command::Clips(args) => clips(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Error::Interrupted) => {
            eprintln!("error: interrupted; run.json says so and frames.csv.partial keeps the finished blocks");
            ExitCode::from(130)
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Mesa's Vulkan loader probes for a Wayland display and prints `error: XDG_RUNTIME_DIR is invalid...` when
/// the variable is unset (headless machines, CI), which reads like one of our errors. Point it at the temp
/// folder for this process only; nothing is created there.
fn quiet_wayland_probe() {
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir());
    }
}

fn run(args: &lodbench::cli::RunArgs) -> lodbench::Result<()> {
    let cfg = RunConfig::from_args(args)?;
    // A second signal while the first is being handled ends the process at once.
    let _ = ctrlc::set_handler(|| {
        if runner::INTERRUPTED.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
    });
    let summary = runner::run(&cfg)?;
    out!("{}", runner::summary_table(&summary));
    outln!("results in {}", summary.out_dir.display());
    Ok(())
}

fn experiment(args: &lodbench::cli::ExperimentArgs) -> lodbench::Result<()> {
    let mut e = lodbench::commands::experiment::Experiment::load_with(&args.file, &args.set)?;
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
        e.variable
            .as_deref()
            .map_or(String::new(), |v| format!(", sweeping {v}")),
        e.description
    );
    let shard = args
        .shard
        .as_deref()
        .map(lodbench::commands::experiment::Shard::parse)
        .transpose()?;
    if args.check || args.list {
        let n = shard.map_or(1, |s| s.count);
        for (k, r) in e.runs.iter().enumerate() {
            let part = if args.list {
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
            outln!(
                "  {}{part} {}",
                r.value.as_deref().unwrap_or("-"),
                per_scene.join("; ")
            );
        }
        return Ok(());
    }
    let _ = ctrlc::set_handler(|| {
        if runner::INTERRUPTED.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
    });
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| runner::default_out_dir(&[e.name.as_str()]));
    let options = lodbench::commands::experiment::RunOptions {
        shard,
        resume: args.resume,
    };
    let folders = e.run_with(&out, &options)?;
    outln!("{} run(s) in {}", folders.len(), out.display());
    Ok(())
}

fn merge(args: &lodbench::cli::MergeArgs) -> lodbench::Result<()> {
    let m = lodbench::commands::merge::merge(&args.dirs, &args.out, args.allow_partial)?;
    for l in &m.left_out {
        eprintln!("note: left out {l}");
    }
    outln!("{} run(s) merged into {}", m.runs, args.out.display());
    Ok(())
}

fn clips(args: &lodbench::cli::ClipsArgs) -> lodbench::Result<()> {
    let settings = lodbench::commands::clips::ClipSettings {
        methods: args.methods.clone(),
        columns: args.columns,
        scale: args.scale,
        fps: args.fps,
        max_frames: args.max_frames,
        transitions: args.transitions.clone(),
        full_frame: args.full_frame,
        gif: args.gif,
        mp4: args.mp4,
    };
    let index = lodbench::commands::clips::make(&args.dir, &settings)?;
    for c in &index.clips {
        outln!(
            "{}: {} frames ({}-{}), {}{}",
            c.name,
            c.frames.len(),
            c.frames.first().copied().unwrap_or_default(),
            c.frames.last().copied().unwrap_or_default(),
            c.apng,
            [&c.gif, &c.mp4]
                .iter()
                .filter_map(|f| f.as_ref().map(|f| format!(", {f}")))
                .collect::<String>()
        );
    }
    outln!(
        "{} clips in {}",
        index.clips.len(),
        args.dir
            .join(lodbench::commands::clips::CLIPS_DIR)
            .display()
    );
    Ok(())
}

fn perceptual(args: &lodbench::cli::PerceptualArgs) -> lodbench::Result<()> {
    let settings = lodbench::commands::perceptual::PerceptualSettings {
        display: args.display.clone(),
        fps: args.fps,
    };
    let records = lodbench::commands::perceptual::check(&args.dir, &settings)?;
    out!("{}", lodbench::commands::perceptual::table(&records));
    outln!(
        "{} clips scored; {}",
        records.len(),
        args.dir
            .join(lodbench::commands::perceptual::PERCEPTUAL_CSV)
            .display()
    );
    Ok(())
}

fn list() -> lodbench::Result<()> {
    outln!("scenes:  {}", SceneKind::names().join(", "));
    outln!("methods:");
    for m in methods::BUILTIN {
        outln!("  {:<16} {}", m.name, m.about);
    }
    let adapters = gpu::context::enumerate_adapters();
    if adapters.is_empty() {
        outln!("adapters: none found");
        outln!("  {}", gpu::context::NO_ADAPTER_HELP);
    } else {
        outln!("adapters (best first; `--adapter SUBSTRING` picks one):");
        for a in adapters {
            let i = a.get_info();
            let ts = a.features().contains(wgpu::Features::TIMESTAMP_QUERY);
            outln!(
                "  {}  [{:?}, {:?}, driver {} {}{}]",
                i.name,
                i.backend,
                i.device_type,
                i.driver,
                i.driver_info,
                if ts { ", timestamps" } else { "" }
            );
        }
    }
    Ok(())
}

fn describe(args: &DescribeArgs) -> lodbench::Result<()> {
    let cfg = SceneConfig::from_args(&args.scene_args)?;
    let def = SceneDef::new(SceneKind::from_name(&args.scene)?, &cfg)?;
    let d = def.describe(&cfg);
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&d)?);
        return Ok(());
    }
    outln!(
        "{}: profile {}, {}x{}, fov {} deg, {} frames, instance counts {:?}",
        d.scene,
        d.profile,
        d.width,
        d.height,
        d.fov_y_deg,
        d.frames,
        d.instance_counts
    );
    outln!("mesh: {}", d.mesh);
    if let Some(u) = &d.unified {
        let lods = d.models.iter().map(|m| m.lods.len()).max().unwrap_or(0);
        let per_lod: Vec<String> = (0..lods)
            .map(|l| {
                let t: usize = d
                    .models
                    .iter()
                    .filter_map(|m| m.lods.get(l))
                    .map(|x| x.info.triangles)
                    .sum();
                format!("LOD{l} {t}")
            })
            .collect();
        outln!(
            "blocks: {} ({:?} grid of {:.3}-unit cubes, --partition {}), {} input triangles, {} in blocks; \
             triangles of all blocks per LOD: {}",
            u.blocks,
            u.grid,
            u.block_size,
            format!("{:?}", u.partition).to_lowercase(),
            u.input_triangles,
            u.block_triangles,
            per_lod.join(", ")
        );
        outln!(
            "seams: {} block pairs, {} edges, {} triangles over all LOD pairs",
            u.seam_pairs,
            u.seam_edges,
            u.seam_triangles_all_lod_pairs
        );
        outln!(
            "preprocessing: blocks {:.0} ms (partition {:.0}, LOD chains {:.0}, seams {:.0}), {:.1} MiB; \
             clusterlod {:.0} ms, {} clusters in {} groups, {} levels, {:.1} MiB",
            u.blocks_ms,
            u.partition_ms,
            u.lod_chains_ms,
            u.seams_ms,
            (u.blocks_bytes + u.seams_bytes) as f64 / (1 << 20) as f64,
            u.clusterlod_ms,
            u.clusters,
            u.cluster_groups,
            u.cluster_levels,
            u.clusterlod_bytes as f64 / (1 << 20) as f64
        );
        outln!("(every block's LODs and switch distances: --json)");
    }
    for m in d.models.iter().filter(|_| d.unified.is_none()) {
        outln!(
            "model {} (radius {:.3}, switch distances from {}):",
            m.name,
            m.radius,
            m.switch_source
        );
        outln!(
            "  {:>4} {:>10} {:>9} {:>14} {:>16}",
            "lod",
            "triangles",
            "vertices",
            "error_abs",
            "switch_distance"
        );
        for l in &m.lods {
            outln!(
                "  {:>4} {:>10} {:>9} {:>14.6} {:>16}{}",
                l.info.lod,
                l.info.triangles,
                l.info.vertices,
                l.info.error_abs,
                l.switch_distance
                    .map_or("-".to_string(), |s| format!("{s:.3}")),
                l.note.map_or(String::new(), |n| format!("  ({n})"))
            );
        }
    }
    outln!("pixel error: {}", d.pixel_error);
    if let Some(p) = &d.path {
        outln!(
            "path: from {:.3} to {:.3} (the bounding sphere fits the view from {:.3})",
            p.near,
            p.far,
            p.fit
        );
    }
    outln!("motion: {}", serde_json::to_string(&d.motion)?);
    for n in &d.notes {
        outln!("note: {n}");
    }
    Ok(())
}
