//! `lodbench overhead`: the harness's own overhead (`measure::overhead_rounds`) per scene and count, written as
//! overhead.csv (a row per method and bare draw) and overhead.json (the adapter, the flags, each round's order),
//! and printed as a table.

use crate::cli::run_config::resolve_methods;
use crate::cli::OverheadArgs;
use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::measure::overhead_rounds::{check_same_image, measure, OverheadRecord};
use crate::measure::{BlockGpu, MethodSetup};
use crate::methods::Registry;
use crate::numbers::{aligned, ratio, sig3};
use crate::results::csv::write_whole;
use crate::results::files::{OVERHEAD_CSV, OVERHEAD_JSON};
use crate::results::manifest::BuildVersion;
use crate::scene::{SceneConfig, SceneDef, SceneKind};
use serde::Serialize;

/// What overhead.json holds.
#[derive(Serialize)]
struct OverheadManifest<'a> {
    /// The build: lodbench_version, git_commit, source_diff_hash.
    #[serde(flatten)]
    build: BuildVersion,
    adapter: crate::gpu::AdapterSummary,
    scenes: Vec<&'static str>,
    methods: &'a [String],
    profile: String,
    rounds: u32,
    seed: u64,
    blocks: Vec<BlockOrders>,
    rows: &'a [OverheadRecord],
}

/// One block's rounds: what was timed in which order.
#[derive(Serialize)]
struct BlockOrders {
    scene: &'static str,
    count: u32,
    width: u32,
    height: u32,
    frames: u32,
    warmup: u32,
    orders: Vec<Vec<String>>,
}

/// `lodbench overhead`.
pub fn execute(args: &OverheadArgs) -> Result<()> {
    let kinds = SceneKind::resolve(&args.scene)?;
    let cfg = SceneConfig::from_args(&args.scene_args)?;
    if args.rounds < 2 {
        return Err(Error::Config(format!(
            "--rounds {}: a paired interval needs at least 2 rounds",
            args.rounds
        )));
    }
    let registry = Registry::builtin();
    let methods = resolve_methods(&args.method, &registry.names())?;
    let defs = kinds
        .iter()
        .map(|&k| refuse_unbare(k, &cfg).and_then(|_| SceneDef::new(k, &cfg)))
        .collect::<Result<Vec<_>>>()?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| super::run::default_out_dir(&["overhead"]));
    super::run::prepare_output(&out)?;
    let ctx = GpuContext::new(args.adapter.as_deref())?;
    let setup = MethodSetup {
        registry,
        options: Default::default(),
        seed: args.seed,
    };
    let (rows, blocks) = measure_blocks(&ctx, args, &cfg, &defs, &methods, setup)?;
    write_whole(&out, OVERHEAD_CSV, &rows)?;
    let manifest = OverheadManifest {
        build: BuildVersion::this(),
        adapter: ctx.info.clone(),
        scenes: defs.iter().map(|d| d.name()).collect(),
        methods: &methods,
        profile: format!("{:?}", args.scene_args.profile).to_lowercase(),
        rounds: args.rounds,
        seed: args.seed,
        blocks,
        rows: &rows,
    };
    crate::results::manifest::write_json_file(&out, OVERHEAD_JSON, &manifest)?;
    out!("{}", table(&rows));
    outln!(
        "adapter: {}; medians over {} rounds; throughput: triangles per second over the bare draw's, paired by \
         round, with the 95 % interval",
        ctx.info.name,
        args.rounds
    );
    outln!("results in {}", out.display());
    Ok(())
}

/// Every block of every scene (`defs`, each at each of its counts): the bare draw checked against the
/// reference, then `methods` and the bare draw timed in `args.rounds` rounds; the rows and each block's orders.
fn measure_blocks(
    ctx: &GpuContext,
    args: &OverheadArgs,
    cfg: &SceneConfig,
    defs: &[SceneDef],
    methods: &[String],
    setup: MethodSetup,
) -> Result<(Vec<OverheadRecord>, Vec<BlockOrders>)> {
    let progress = indicatif::ProgressBar::hidden();
    let (mut rows, mut blocks) = (Vec::new(), Vec::new());
    for def in defs {
        let warmup = args.warmup.unwrap_or_else(|| cfg.resolved(def.kind).warmup);
        for &count in &def.counts {
            let scene = def.instantiate(count);
            let block = BlockGpu::new(ctx, &scene, setup.clone())?;
            if block.gpu.materials.is_some() {
                return Err(Error::Config(format!(
                    "scene {}: the bare draw draws one colour per model, and this scene has materials; run it \
                     with --materials flat",
                    def.name()
                )));
            }
            check_same_image(&block, "reference")?;
            let mut prepared =
                block.prepare_methods(methods, warmup, args.seed, false, &progress)?;
            let block_seed = args.seed ^ ((blocks.len() as u64 + 1) << 32);
            let (r, orders) = measure(&block, &mut prepared, (args.rounds, block_seed), &progress)?;
            ctx.check_errors()?;
            outln!("{} n={count}: {} rounds", def.name(), args.rounds);
            rows.extend(r);
            blocks.push(BlockOrders {
                scene: def.name(),
                count,
                width: scene.width,
                height: scene.height,
                frames: scene.frames,
                warmup,
                orders,
            });
        }
    }
    Ok((rows, blocks))
}

/// Scenes the bare draw cannot stand beside: their draw is more than instances of one pipeline.
fn refuse_unbare(kind: SceneKind, cfg: &SceneConfig) -> Result<()> {
    let why = if kind.is_unified() {
        Some("its blocks are drawn with seams between them")
    } else if cfg.shadows.is_some() {
        Some("--shadows adds a shadow pass; run it without --shadows")
    } else {
        None
    };
    match why {
        Some(why) => Err(Error::Config(format!(
            "scene {}: the overhead comparison draws instances of the scene's models with one pipeline; {why}",
            kind.name()
        ))),
        None => Ok(()),
    }
}

/// The printed table: a row per scene, count and contender.
pub fn table(rows: &[OverheadRecord]) -> String {
    let mut cells = vec![[
        "scene",
        "count",
        "drawn by",
        "ms/frame",
        "triangles/s",
        "draws/frame",
        "throughput / bare",
    ]
    .map(String::from)
    .to_vec()];
    for r in rows {
        cells.push(vec![
            r.scene.clone(),
            r.count.to_string(),
            r.contender.clone(),
            sig3(Some(r.ms_per_frame_median)),
            format!("{} M", sig3(Some(r.triangles_per_s_median / 1e6))),
            sig3(Some(r.draw_calls_per_frame)),
            ratio(
                Some(r.throughput_to_bare),
                r.throughput_ci95_lo,
                r.throughput_ci95_hi,
            ),
        ]);
    }
    aligned(&cells, &[false, true, false, true, true, true, false])
}
