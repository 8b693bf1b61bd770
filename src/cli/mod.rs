//! The command-line contract (clap derive). Scripts, CI and later issues rely on these exact names.
//!
//! `RunArgs` and `SceneArgs` are also what an experiment file's `[run]` table deserialises into (kebab-case
//! keys, the flags' names without dashes); a key it leaves out takes the flag's default
//! (`crate::defaults::clap_defaults`), so a file and a command line with the same settings are the same run.

pub mod experiment_file;
pub mod run_config;

use crate::effects::OnOff;
use crate::geometry::blocks::PartitionMode;
use crate::measure::metrics::{Metric, MetricReduction, MetricRegion};
use crate::measure::QualitySchedule;
use crate::methods::MethodOptions;
use crate::scene::schedule::FadeMode;
use crate::scene::{CameraMode, Profile, SweepStart};
use clap::{Args, Parser, Subcommand};
use serde::Deserialize;
use std::path::PathBuf;

#[derive(Debug, Parser)]
#[command(
    name = "lodbench",
    version,
    about = "Measures what smooth LOD-transition methods cost and how much they pop",
    long_about = None
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Render scenes with transition methods; write frames.csv, summary.csv and run.json.
    Run(RunArgs),
    /// List scenes, methods and the GPU adapters found.
    List,
    /// Show a scene's models, LOD chains, switch distances, instance and frame counts.
    Describe(DescribeArgs),
    /// Write a built-in scene as glTF 2.0 (.glb): its LOD chains (MSFT_lod, with the exact switch distances),
    /// its instances and its camera path as a camera animation; `run --scene FILE.glb` reads it back.
    Export(ExportArgs),
    /// Run a sweep described in a TOML file (scenes/experiments/) into one results folder.
    Experiment(ExperimentArgs),
    /// Merge the folders of an experiment's shards (`experiment --shard`) into one results folder.
    Merge(MergeArgs),
    /// Compare two methods' frame times in a results folder: A's time over B's per block, paired round by
    /// round, with its 95 % interval and whether the two differ (all frames, in transition, steady).
    Compare(CompareArgs),
    /// Score each method's clip of each transition of a run (made with --dump-frames --dump-transitions)
    /// against the reference's with ColorVideoVDP; writes perceptual.csv and compares with lodpop.
    Perceptual(PerceptualArgs),
    /// Animated side-by-side clips of every transition of a run (made with --dump-frames
    /// --dump-transitions): the reference, each method and its error heat-map; animated PNG, GIF, and MP4
    /// with ffmpeg.
    Clips(ClipsArgs),
    /// Choose each model's LOD switch distances from a popping budget, by measurement: every LOD pair drawn
    /// alone from N directions at a range of distances; writes tune.csv, tune.json, the settings in each
    /// engine's units (engines/) and the scene rewritten with them (tuned.glb).
    Tune(TuneArgs),
    /// Measure the adapter's ceilings: triangle, vertex, fill, depth and compute-read rates, each with a check
    /// that doubling what it names doubles its time and changing anything else does not; writes probe.csv.
    Probe(ProbeArgs),
    /// The harness's own overhead: methods as the timing rounds draw them against a bare instanced draw of the
    /// same meshes and instances, paired round by round; writes overhead.csv and overhead.json.
    Overhead(OverheadArgs),
}

#[derive(Debug, Clone, Args)]
pub struct OverheadArgs {
    /// Scenes to measure (comma-separated): built-in scenes of instanced models in one colour.
    #[arg(long, value_delimiter = ',', default_value = "bunny-grid,trees")]
    pub scene: Vec<String>,
    /// Methods drawn by the harness (comma-separated); the bare draw draws every instance at LOD0, as
    /// `reference` does.
    #[arg(long, value_delimiter = ',', default_value = "reference")]
    pub method: Vec<String>,
    #[command(flatten)]
    pub scene_args: SceneArgs,
    /// Untimed frames rendered before the timed ones (default: the profile's).
    #[arg(long)]
    pub warmup: Option<u32>,
    /// Timing rounds: each round times every method and bare draw over the round's frames, in an order shuffled
    /// from --seed.
    #[arg(long, default_value_t = 20)]
    pub rounds: u32,
    /// Seed of the rounds' order (recorded in overhead.json).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output folder (default results/overhead-<time>/).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// GPU adapter, by index or name substring (`lodbench list`).
    #[arg(long)]
    pub adapter: Option<String>,
}

#[derive(Debug, Clone, Args)]
pub struct ProbeArgs {
    /// The target's width and height in pixels (the geometry probes' control draws into twice the width).
    #[arg(long, default_value_t = 512)]
    pub width: u32,
    #[arg(long, default_value_t = 512)]
    pub height: u32,
    /// Timing rounds: each round times every variant of every probe once, in an order shuffled from --seed.
    #[arg(long, default_value_t = 10)]
    pub rounds: u32,
    /// Seed of the rounds' order (recorded in probe.json).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The amount of work of every probe, relative to the default (about a millisecond each on a GPU).
    #[arg(long, default_value_t = 1.0)]
    pub scale: f64,
    /// Output folder (default results/probe-<time>/).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// GPU adapter, by index or name substring (`lodbench list`).
    #[arg(long)]
    pub adapter: Option<String>,
}

#[derive(Debug, Clone, Args)]
pub struct TuneArgs {
    /// The scene whose models to tune: a built-in scene's name or a glTF file.
    #[arg(long)]
    pub scene: String,
    #[command(flatten)]
    pub scene_args: SceneArgs,
    /// The budget as lodpop: the largest RMS change over the frame (sRGB-encoded, in [0, 1]) a switch may
    /// cause, at the run's viewport.
    #[arg(long, conflicts_with = "budget_jod")]
    pub budget_lodpop: Option<f64>,
    /// The budget as ColorVideoVDP's JOD between the two frames (10: no visible difference): the least a switch
    /// may score.
    #[arg(long)]
    pub budget_jod: Option<f64>,
    /// View directions per LOD pair: the scene's own (+z) and the rest from a seeded Fibonacci sphere (32: with
    /// 8, a direction between them broke the budget by 12 % on a scan, docs/findings/tune.md).
    #[arg(long, default_value_t = 32)]
    pub views: u32,
    /// Distances per view, evenly spaced in log distance from where the model fits the view to where it is two
    /// pixels across.
    #[arg(long, default_value_t = 24)]
    pub distances: u32,
    /// The camera's speed in world units per second: with it, the narrowest band (`--band`) alpha, dither and
    /// geomorph need for every frame's change to stay within a lodpop budget.
    #[arg(long)]
    pub speed: Option<f32>,
    /// Frames per second the speed is measured at.
    #[arg(long, default_value_t = 60.0)]
    pub fps: f32,
    /// Seed of the view directions (recorded in tune.json).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// ColorVideoVDP display model of --budget-jod.
    #[arg(long, default_value = "standard_fhd")]
    pub display: String,
    /// Output folder (default results/tune-<scene>-<time>/).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// GPU adapter, by index or name substring (`lodbench list`).
    #[arg(long)]
    pub adapter: Option<String>,
}

#[derive(Debug, Clone, Args)]
pub struct ClipsArgs {
    /// A results folder of `lodbench run ... --dump-frames --dump-transitions`.
    pub dir: PathBuf,
    /// Methods to show, in this order (default: every method of the run).
    #[arg(long, value_delimiter = ',')]
    pub methods: Option<Vec<String>>,
    /// Tiles per row.
    #[arg(long, default_value_t = 4)]
    pub columns: u32,
    /// Nearest-neighbour upscaling factor (default: the smallest that makes the shown part at least 200
    /// pixels high, and no wider than 480 or the run's width).
    #[arg(long)]
    pub scale: Option<u32>,
    /// Show the whole frame (default: the box around everything the clip's pictures draw, with 8 pixels
    /// around it, or the whole frame when that box covers more than half of it).
    #[arg(long)]
    pub full_frame: bool,
    /// Frames per second of the GIF and MP4.
    #[arg(long, default_value_t = 10)]
    pub fps: u32,
    /// At most this many frames per clip, spread evenly over the transition's dumped frames (0: all).
    #[arg(long, default_value_t = 0)]
    pub max_frames: u32,
    /// Only these transitions, by their index along the path (transitions.csv's `transition`; default: all).
    #[arg(long, value_delimiter = ',')]
    pub transitions: Option<Vec<u32>>,
    /// Also a GIF of each clip (beside its animated PNG).
    #[arg(long)]
    pub gif: bool,
    /// MP4s with ffmpeg: auto (when ffmpeg is on the PATH), on (an error without it), off.
    #[arg(long, value_enum, default_value = "auto")]
    pub mp4: Mp4,
}

#[derive(Debug, Clone, Args)]
pub struct PerceptualArgs {
    /// A results folder of `lodbench run ... --dump-frames --dump-transitions`.
    pub dir: PathBuf,
    /// ColorVideoVDP display model (standard_fhd: 24-inch 1920x1080 at 60 cm, 200 cd/m2; standard_4k, ...).
    #[arg(long, default_value = "standard_fhd")]
    pub display: String,
    /// Frames per second the clips are shown at.
    #[arg(long, default_value_t = 60.0)]
    pub fps: f32,
}

#[derive(Debug, Clone, Args)]
pub struct ExperimentArgs {
    /// The experiment file.
    pub file: PathBuf,
    /// Output folder (default results/<experiment name>-<time>/).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Validate the file and print the planned runs without rendering.
    #[arg(long)]
    pub check: bool,
    /// Print the planned runs with the shard each belongs to under `--shard i/N` (N from --shard, else 1),
    /// without rendering.
    #[arg(long)]
    pub list: bool,
    /// Run only part i of n of the planned runs (run k goes to shard k mod n + 1), e.g. a Slurm array task's
    /// `--shard $((SLURM_ARRAY_TASK_ID + 1))/$SLURM_ARRAY_TASK_COUNT`; merge the shards' folders with
    /// `lodbench merge`.
    #[arg(long)]
    pub shard: Option<String>,
    /// Skip the runs whose run.json in the output folder says complete with the same flags, and run the rest
    /// (an interrupted or failed experiment, rerun).
    #[arg(long)]
    pub resume: bool,
    /// Run every run on this adapter (overrides the file's `adapter`): an index, 0-based in the order `lodbench
    /// list` prints, or a part of its name (case-insensitive); one GPU per shard on a machine with several.
    #[arg(long, value_name = "INDEX|NAME")]
    pub adapter: Option<String>,
    /// Override a `[run]` key of the file in every run: `--set frames=300` (VALUE in TOML syntax; repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

#[derive(Debug, Clone, Args)]
pub struct MergeArgs {
    /// Experiment folders to merge (shards, or runs made on different machines).
    #[arg(required = true)]
    pub dirs: Vec<PathBuf>,
    /// The merged folder.
    #[arg(long)]
    pub out: PathBuf,
    /// Merge the complete runs when some are missing, failed or were interrupted (listed either way).
    #[arg(long)]
    pub allow_partial: bool,
    /// Merge runs made on different adapters (name, driver): shards on different GPUs. Every merged CSV has
    /// the `adapter` column, which keeps their rows apart; nothing is averaged across adapters.
    #[arg(long)]
    pub allow_adapters: bool,
    /// Merge runs built from uncommitted changes (git_commit ending in -dirty) even where their changes differ
    /// or cannot be told apart (no `source_diff_hash` in run.json). Better: commit, rebuild and rerun.
    #[arg(long)]
    pub allow_dirty: bool,
}

#[derive(Debug, Clone, Args)]
pub struct CompareArgs {
    /// A results folder: a run's, an experiment's or a merged one (its frames.csv).
    pub dir: PathBuf,
    /// The method whose time is the numerator.
    pub a: String,
    /// The method whose time is the denominator.
    pub b: String,
    /// Only the blocks of this scene.
    #[arg(long)]
    pub scene: Option<String>,
    /// Only the blocks of this instance count.
    #[arg(long)]
    pub count: Option<u32>,
}

/// Flags that change what a scene is (shared by `run` and `describe`).
#[derive(Debug, Clone, Args, Deserialize)]
#[serde(default, rename_all = "kebab-case")]
pub struct SceneArgs {
    /// Size preset; explicit flags override it.
    #[arg(long, value_enum, default_value_t = Profile::Quick)]
    pub profile: Profile,
    /// Viewport width in pixels.
    #[arg(long)]
    pub width: Option<u32>,
    /// Viewport height in pixels.
    #[arg(long)]
    pub height: Option<u32>,
    /// Timed frames (also the length of the quality pass; for bunny-sweep the whole path out and back).
    #[arg(long)]
    pub frames: Option<u32>,
    /// Mesh file (.obj, .gltf or .glb) that replaces the Stanford bunny in the bunny scenes.
    #[arg(long)]
    pub mesh: Option<PathBuf>,
    /// A camera path, CSV (time or frame; x, y, z; target_x, target_y, target_z or qx, qy, qz, qw; optional
    /// fov_deg), resampled to --frames: it replaces every scene's own camera (docs/methods.md, "Camera paths").
    #[arg(long)]
    pub camera_path: Option<PathBuf>,
    /// Screen-space error, in pixels at the viewport's height, at which each LOD is switched in. A smaller value
    /// moves every switch farther from the camera, a larger one nearer. Default: for the bunny scenes one pixel
    /// at the paper's 600-pixel height (height / 600), so every profile has the paper's switch distances and
    /// path; 1 for the other scenes.
    #[arg(long)]
    pub pixel_error: Option<f32>,
    /// Where the bunny scenes' path starts: `fit` (where the model's bounding sphere fits the view, so the camera
    /// is never inside the model; switches nearer than that are not reached) or `close-up` (just before the
    /// first switch, even inside the bounding sphere; `--pixel-error` 1 by default). Default: the profile's
    /// (`close-up` for regress, `fit` otherwise).
    #[arg(long, value_enum)]
    pub sweep_start: Option<SweepStart>,
    /// Explicit switch distances for LOD1, LOD2, ... (world units), overriding --pixel-error.
    #[arg(long, value_delimiter = ',')]
    pub switch_distances: Option<Vec<f32>>,
    /// Switches in engine terms: LOD1, LOD2, ... come in where the model's bounding sphere's projected diameter
    /// over the viewport's height falls below each value (Unreal's screen size, Unity's screen-relative
    /// transition height, MSFT_screencoverage), decreasing; converted per model to d = radius / (size *
    /// tan(fov_y / 2)). Overrides --pixel-error; not with --switch-distances.
    #[arg(long, value_delimiter = ',', conflicts_with = "switch_distances")]
    pub switch_screen_sizes: Option<Vec<f32>>,
    /// How bunny-halves and terrain divide their mesh into blocks: `clip` (triangles clipped at the block
    /// faces) or `bin` (each triangle whole into the block of its barycentre).
    #[arg(long, value_enum, default_value_t = PartitionMode::Clip)]
    pub partition: PartitionMode,
    /// terrain: blocks along the mesh's longest side (cubic blocks). Default: the profile's (4 at regress, 16 at
    /// paper, 8 otherwise).
    #[arg(long)]
    pub blocks: Option<u32>,
    /// bunny-grid instance counts; each count is its own block of rows.
    #[arg(long, value_delimiter = ',')]
    #[serde(deserialize_with = "one_or_many")]
    pub count: Vec<u32>,
    /// How a user's mesh (`--scene FILE.glb`, `--mesh`) is simplified into its LOD chain: `attributes`
    /// (meshoptimizer's attribute-aware simplifier, normals and texture coordinates weighted, hard edges
    /// collapsible, texture seams protected) or `positions` (positions alone: split vertices keep their seams).
    #[arg(long, value_enum, default_value_t = crate::geometry::lod::Simplify::Attributes)]
    pub simplify: crate::geometry::lod::Simplify,
    /// glTF scenes (`--scene FILE.glb`): `full` draws the file's materials (metallic-roughness, textures, normal
    /// maps, alpha modes, vertex colours); `flat` draws each model in one colour, Lambert and ambient, reading no
    /// texture (the built-in scenes' look: the silhouette's popping alone).
    #[arg(long, value_enum, default_value_t = crate::geometry::material::MaterialMode::Full)]
    pub materials: crate::geometry::material::MaterialMode,
    /// glTF scenes (`--scene FILE.glb`): the animation that plays over the frames, by index or name, or `none`
    /// (the scene at rest). Default: the file's first animation, 60 frames a second of clip time, looped.
    #[arg(long)]
    pub animation: Option<String>,
    /// Vertical field of view in degrees.
    #[arg(long, default_value_t = 60.0)]
    pub fov: f32,
    /// Extra work per shaded fragment, for every method and the reference: N dependent ALU iterations (a
    /// multiply-add and a fract each) whose result is added with a weight of 0, so the image is unchanged while
    /// no shader compiler can drop the loop (the weight is a uniform). A stand-in for an expensive material: what
    /// drawing both LODs of a blend costs when fragments are dear (Scherzer & Wimmer 2008 section 2).
    #[arg(long, default_value_t = 0)]
    pub shader_work: u32,
    /// How k advances through a transition.
    #[arg(long, value_enum, default_value_t = FadeMode::Distance)]
    pub fade: FadeMode,
    /// Half-width of the transition band as a fraction of the switch distance (Sheliemietiev et al. 2023 section 8).
    #[arg(long, default_value_t = 0.05)]
    pub band: f32,
    /// Length of a time-based fade in frames (--fade time).
    #[arg(long, default_value_t = 30)]
    pub fade_frames: u32,
    /// Hysteresis margin as a fraction of the switch distance.
    #[arg(long, default_value_t = 0.0)]
    pub hysteresis: f32,
    /// At most this many instances in transition at once (0: no cap; needs --fade time): an instance whose LOD
    /// should change waits, keeping its LOD, until a fade ends (run.json: wait_instance_frames).
    #[arg(long, default_value_t = 0)]
    pub max_transitions: u32,
    /// Camera motion: `fixed` (the scene's own path) or `orbit` (the camera swings around what it looks at,
    /// +-30 degrees over 240 frames, keeping its distance: every pixel moves, which exercises FSI's
    /// reprojection).
    #[arg(long, value_enum, default_value_t = CameraMode::Fixed)]
    pub camera: CameraMode,
    #[command(flatten)]
    #[serde(flatten)]
    pub taa: crate::effects::taa::TaaArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub shadow: crate::effects::shadow::ShadowArgs,
}

impl Default for SceneArgs {
    fn default() -> Self {
        crate::defaults::clap_defaults()
    }
}

#[derive(Debug, Clone, Args, Deserialize)]
#[serde(default, rename_all = "kebab-case")]
pub struct RunArgs {
    /// Scenes to run (comma-separated or repeated); all when absent.
    #[arg(long, value_delimiter = ',')]
    #[serde(deserialize_with = "one_or_many")]
    pub scene: Vec<String>,
    /// Methods to run (comma-separated or repeated); all when absent.
    #[arg(long, value_delimiter = ',')]
    #[serde(deserialize_with = "one_or_many")]
    pub method: Vec<String>,
    #[command(flatten)]
    #[serde(flatten)]
    pub scene_args: SceneArgs,
    /// Untimed frames rendered before the timed ones.
    #[arg(long)]
    pub warmup: Option<u32>,
    /// Seed of every random choice (recorded in run.json).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Timing rounds: the timed frames are cut into this many consecutive segments, and round r times every
    /// method of the block over segment r, in an order shuffled from --seed (recorded in run.json), so drift
    /// of the machine falls on every method alike. The paired ratios and their intervals are over rounds.
    #[arg(long, default_value_t = 20)]
    pub rounds: u32,
    /// The method every method's time is divided by, round by round (summary.csv `ratio_to_baseline`);
    /// default `discrete` when it is run. A name repeated in --method is `NAME#2`, `NAME#3`, ...
    #[arg(long)]
    pub baseline: Option<String>,
    /// The popping budget the answer under the summary table (and at the top of report.html) is stated within:
    /// the largest lodpop a method may show to count (`lodbench tune --budget-lodpop`'s budget, say). Default:
    /// half the hard switch's (discrete's) largest lodpop. Changes no measurement.
    #[arg(long)]
    pub budget_lodpop: Option<f64>,
    /// Measure the adapter's ceilings before the blocks (`lodbench probe`'s rates, each probe's base alone, a
    /// fraction of a second on a CPU adapter) into run.json, and fill summary.csv's triangles_per_s,
    /// triangle_ceiling_share, fragments_per_s, fragment_ceiling_share and bound.
    #[arg(long, value_enum, default_value_t = OnOff::On)]
    pub ceilings: OnOff,
    /// Before each method's timed segment of a round, keep the GPU busy with the triangle probe until it reads
    /// nine tenths of the highest triangle rate the run has read (at most a quarter of a second), so that a GPU
    /// clock dropped while the GPU idled (a CPU-heavy method's selection) is back up before the next method is
    /// timed. `auto`: on, but on a CPU adapter (no GPU clock). Needs `--ceilings on`. Recorded per method in
    /// run.json (`clock_warmup_*`).
    #[arg(long, value_enum, default_value_t = ClockWarmup::Auto)]
    pub clock_warmup: ClockWarmup,
    #[command(flatten)]
    #[serde(flatten)]
    pub method_options: MethodOptions,
    /// Image metrics per frame (rmse, pop and lodpop are always computed; de2000 adds CIEDE2000 to the metric
    /// kernel; flip adds NVIDIA FLIP, on the CPU).
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [Metric::Rmse, Metric::Pop])]
    #[serde(deserialize_with = "one_or_many")]
    pub metrics: Vec<Metric>,
    /// How the metric kernel sums a row: per-invocation atomics (default) or a workgroup-memory reduction.
    #[arg(long, value_enum, default_value_t = MetricReduction::Atomics)]
    pub metric_reduction: MetricReduction,
    /// Which pixels the quality pass reads: `covered` (default) only those the instances can cover, where a
    /// bound holds (no TAA, no shadows, methods that draw only their meshes), and lodpop's counterfactual only
    /// where the instances whose state changed reach; `full` every pixel. The figures are the same.
    #[arg(long, value_enum, default_value_t = MetricRegion::Covered)]
    pub metric_region: MetricRegion,
    /// Output folder (default results/<scene>-<time>/).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// The adapter to run on: an index (0-based, in the order `lodbench list` prints them, best first), which
    /// tells identical GPUs apart, or a part of its name (case-insensitive); the best one when absent.
    #[arg(long, value_name = "INDEX|NAME")]
    #[serde(deserialize_with = "name_or_index")]
    pub adapter: Option<String>,
    /// The quality pass: `off` runs the warm-up and the timing rounds only, for runs that only time (an A/A
    /// check, cost figures); every image figure of the CSVs (rmse, pop, lodpop, de2000, FLIP, uncovered and
    /// crack pixels, lag, shadow, FSI's combine time) is then empty, never 0, and run.json's quality-pass
    /// times null. Refused with --dump-frames and --metrics de2000/flip, which need the pass.
    #[arg(long, value_enum, default_value_t = OnOff::On)]
    pub quality: OnOff,
    /// When the quality pass is made: `rounds` (default) a segment of every method's pass right after each
    /// timing round, over the same frames, so that quality_to_renders_ratio is paired round by round; `after`
    /// every timing round first, back to back as with --quality off, then the quality segments (the timing
    /// rounds then have no quality work between them; docs/measurement.md, "Quality pass").
    #[arg(long, value_enum, default_value_t = QualitySchedule::Rounds)]
    pub quality_schedule: QualitySchedule,
    /// GPU memory (MiB) a scene block may keep of the reference's frames, so that its second and later methods
    /// copy the reference frame instead of drawing it again (every figure is the same; the first frames that
    /// fit are kept). 0 draws it in every method's pass. Not used under TAA or with shadows.
    #[arg(long, default_value_t = 1024, value_name = "MIB")]
    pub reference_cache_mib: u64,
    /// Write PNGs of the method frame, the reference frame and an error heat-map.
    #[arg(long)]
    pub dump_frames: bool,
    /// With --dump-frames: every k-th frame only.
    #[arg(long, default_value_t = 1)]
    pub dump_every: u32,
    /// With --dump-frames: only frames with an instance in transition (of those, every k-th frame with
    /// --dump-every), so a long run's dumps land where methods differ.
    #[arg(long)]
    pub dump_transitions: bool,
}

impl Default for RunArgs {
    fn default() -> Self {
        crate::defaults::clap_defaults()
    }
}

/// `adapter` in a file: a name (`adapter = "H100"`) or an index (`adapter = 1`), as `--adapter` takes either.
fn name_or_index<'de, D>(d: D) -> Result<Option<String>, D::Error>
where
    D: serde::Deserializer<'de>,
{
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum NameOrIndex {
        Index(u64),
        Name(String),
    }
    Ok(Some(match NameOrIndex::deserialize(d)? {
        NameOrIndex::Index(i) => i.to_string(),
        NameOrIndex::Name(n) => n,
    }))
}

/// A list flag in a file: a single value or an array (`count = 50` or `count = [50, 250]`), as on the command
/// line, where `--count 50` and `--count 50,250` both work.
fn one_or_many<'de, D, T>(d: D) -> Result<Vec<T>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: Deserialize<'de>,
{
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum OneOrMany<T> {
        Many(Vec<T>),
        One(T),
    }
    Ok(match OneOrMany::deserialize(d)? {
        OneOrMany::Many(v) => v,
        OneOrMany::One(x) => vec![x],
    })
}

#[derive(Debug, Clone, Args)]
pub struct DescribeArgs {
    /// The scene to describe.
    #[arg(long)]
    pub scene: String,
    #[command(flatten)]
    pub scene_args: SceneArgs,
    /// Machine-readable output.
    #[arg(long)]
    pub json: bool,
    /// Also measure each LOD against LOD0: the largest and the mean distance from LOD0's vertices to the LOD's
    /// surface (object-space units), a measure independent of the simplifier's own error.
    #[arg(long)]
    pub deviation: bool,
    /// Print instead the camera of frame F as JSON: eye, the view matrix (world to camera, column-major),
    /// the vertical field of view, near and far planes and the viewport (what another renderer needs to draw
    /// lodbench's view; the projection is glam's right-handed one with depth in 0..1).
    #[arg(long, value_name = "F")]
    pub camera_json: Option<u32>,
}

#[derive(Debug, Clone, Args)]
pub struct ExportArgs {
    /// The scene to export (the unified scenes are not exported; a glTF scene only as .obj).
    #[arg(long)]
    pub scene: String,
    /// The file to write: `.glb`, a built-in scene with its LOD chains and camera; `.obj`, the geometry
    /// lodbench draws on `--frame`, every instance at LOD0 in world space, a group per instance (for a glTF scene
    /// named by its node: `node<N>`, `node<N>.<I>`).
    #[arg(long)]
    pub out: PathBuf,
    /// The frame `--out FILE.obj` shows (its animation's pose, its camera ignored).
    #[arg(long, default_value_t = 0)]
    pub frame: u32,
    #[command(flatten)]
    pub scene_args: SceneArgs,
}

/// `--clock-warmup`.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    Default,
    clap::ValueEnum,
    serde::Serialize,
    serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum ClockWarmup {
    /// On where the adapter is a GPU, off on a CPU rasteriser.
    #[default]
    Auto,
    On,
    Off,
}

/// Whether to write MP4s with ffmpeg.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, serde::Deserialize)]
pub enum Mp4 {
    /// When `ffmpeg` is on the PATH.
    Auto,
    /// Always; an error when `ffmpeg` is missing.
    On,
    Off,
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn cli_is_consistent() {
        Cli::command().debug_assert();
    }

    #[test]
    fn file_defaults_are_the_flag_defaults() {
        let from_flags = match Cli::try_parse_from(["lodbench", "run"]).unwrap().command {
            Command::Run(r) => r,
            _ => unreachable!(),
        };
        let from_file: RunArgs = toml::from_str("").unwrap();
        assert_eq!(format!("{from_flags:?}"), format!("{from_file:?}"));
        let set: RunArgs = toml::from_str(
            "count = 50\npixel-error = 2\nnoise = \"bayer4\"\nfsi-check = \"forward\"",
        )
        .unwrap();
        assert_eq!(set.scene_args.count, vec![50]);
        assert_eq!(set.scene_args.pixel_error, Some(2.0));
        assert_eq!(
            set.method_options.dither.noise,
            crate::methods::noise::NoisePattern::Bayer4
        );
        assert_eq!(
            set.method_options.fsi.fsi_check,
            crate::methods::fsi::FsiCheck::Forward
        );
        // `adapter` takes an index or a name, as --adapter does; `quality` is on or off.
        let set: RunArgs = toml::from_str("adapter = 1\nquality = \"off\"").unwrap();
        assert_eq!(
            (set.adapter.as_deref(), set.quality),
            (Some("1"), OnOff::Off)
        );
        let set: RunArgs = toml::from_str("adapter = \"H100\"").unwrap();
        assert_eq!(
            (set.adapter.as_deref(), set.quality),
            (Some("H100"), OnOff::On)
        );
    }

    #[test]
    fn lists_accept_commas_and_repetition() {
        let cli = Cli::try_parse_from([
            "lodbench",
            "run",
            "--scene",
            "bunny-sweep,bunny-grid",
            "--method",
            "reference",
            "--method",
            "discrete",
            "--count",
            "5,7",
        ])
        .unwrap();
        let Command::Run(r) = cli.command else {
            panic!("not run")
        };
        assert_eq!(r.scene, vec!["bunny-sweep", "bunny-grid"]);
        assert_eq!(r.method, vec!["reference", "discrete"]);
        assert_eq!(r.scene_args.count, vec![5, 7]);
    }
}
