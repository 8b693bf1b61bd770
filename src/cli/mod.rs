//! The command-line contract (clap derive). Scripts, CI and later issues rely on these exact names.
//!
//! `RunArgs` and `SceneArgs` are also what an experiment file's `[run]` table deserialises into (kebab-case
//! keys, the flags' names without dashes); a key it leaves out takes the flag's default
//! (`crate::defaults::clap_defaults`), so a file and a command line with the same settings are the same run.
//!
//! Help texts: `-h` and `--help` print the same summary, one line a flag, grouped under `help_heading`s
//! (`crate::defaults::heading`). A doc comment on a flag is therefore one paragraph of one line or two, for
//! users: no source path, no rustdoc link (clap prints it verbatim); the details go to docs/flags.md, and notes
//! for developers to `//` comments. An enum flag takes `value_parser = names_only::<E>()`, so that its values'
//! doc comments stay out of the help. The tests below check all three.

pub mod calibration;
pub mod experiment_file;
pub mod run_config;

use crate::defaults::{heading, names_only};
use crate::effects::OnOff;
use crate::geometry::blocks::PartitionMode;
use crate::measure::metrics::{Metric, MetricReduction, MetricRegion};
use crate::measure::QualitySchedule;
use crate::methods::MethodOptions;
use crate::scene::schedule::FadeMode;
use crate::scene::{CameraMode, Profile, SweepStart};
use clap::{Args, CommandFactory, FromArgMatches, Parser, Subcommand};
use serde::Deserialize;
use std::path::PathBuf;

#[derive(Debug, Parser)]
#[command(
    name = "lodbench",
    version,
    about = "Measures what smooth LOD-transition methods cost and how much they pop",
    long_about = None,
    mut_subcommands = numbers_may_be_negative,
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

/// Every flag that takes a value takes a negative number as its value (`--budget-lodpop -1`, read as -1 and
/// refused with its range by the command's validation, not as an unknown flag `-1`).
fn numbers_may_be_negative(cmd: clap::Command) -> clap::Command {
    cmd.mut_args(|a| {
        if a.get_action().takes_values() {
            a.allow_negative_numbers(true)
        } else {
            a
        }
    })
}

impl Cli {
    /// The command line of this process, parsed as [`Cli::try_parse_checked_from`] does; on an error, clap's
    /// message and exit code 2.
    pub fn parse_checked() -> Cli {
        Self::try_parse_checked_from(std::env::args_os()).unwrap_or_else(|e| e.exit())
    }

    /// `args` parsed, with the flags a subcommand hides refused: `tune` takes `SceneArgs` whole, and the flags
    /// of it that change nothing for tune are hidden from `tune -h` and refused here, naming the flag
    /// ([`NOT_FOR_TUNE`]).
    pub fn try_parse_checked_from<I, T>(args: I) -> Result<Cli, clap::Error>
    where
        I: IntoIterator<Item = T>,
        T: Into<std::ffi::OsString> + Clone,
    {
        let mut cmd = Cli::command();
        let matches = cmd.try_get_matches_from_mut(args)?;
        if let Some(("tune", m)) = matches.subcommand() {
            let given = NOT_FOR_TUNE
                .iter()
                .find(|id| m.value_source(id) == Some(clap::parser::ValueSource::CommandLine));
            if let (Some(id), Some(tune)) = (given, cmd.find_subcommand_mut("tune")) {
                let flag = tune
                    .get_arguments()
                    .find(|a| a.get_id() == *id)
                    .and_then(|a| a.get_long())
                    .unwrap_or(id)
                    .to_string();
                return Err(tune.error(
                    clap::error::ErrorKind::ArgumentConflict,
                    format!(
                        "--{flag} changes nothing for tune, which draws each model alone, at rest, from its own \
                         views; `lodbench tune -h` lists the flags it reads"
                    ),
                ));
            }
        }
        Cli::from_arg_matches(&matches).map_err(|e| e.format(&mut cmd))
    }
}

/// The scene flags (`SceneArgs`, by clap id) that change nothing for `tune`: it refuses the unified scenes
/// (blocks), draws each model's first instance alone and at rest from its own views at its own distances
/// (instance counts, switches, the fade, the camera), without TAA or shadow maps, and compares images (the
/// shader work leaves them unchanged). Hidden from `tune -h`, refused by [`Cli::try_parse_checked_from`].
pub const NOT_FOR_TUNE: &[&str] = &[
    "partition",
    "blocks",
    "count",
    "switch_distances",
    "switch_screen_sizes",
    "fade",
    "fade_frames",
    "hysteresis",
    "max_transitions",
    "camera",
    "shader_work",
    "taa",
    "taa_alpha",
    "taa_samples",
    "taa_clamp",
    "shadows",
    "shadow_size",
    "shadow_lod",
];

fn hide_if_not_for_tune(a: clap::Arg) -> clap::Arg {
    let hide = NOT_FOR_TUNE.contains(&a.get_id().as_str());
    a.hide(hide)
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
    /// Write a results folder's answer (answer.json: which method pops least, the cheapest within the budget,
    /// the decision table) from its CSVs, and print its sentences; for a folder made before answer.json was.
    Answer(AnswerArgs),
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
    /// Build a browser experiment that measures when a person sees an LOD switch (2AFC, one switch against the
    /// same frames without it, over a ladder of pops): DIR/index.html beside its stimuli; `scripts/calibration.py
    /// fit` turns the responses into calibration.json, which `tune --calibration` and `run --calibration` read.
    Calibrate(CalibrateArgs),
    /// Score another renderer's frames: from a folder of its frames, their counterfactuals (each pose drawn with
    /// the previous frame's LOD selection), optionally the high-poly reference and a CSV of the levels drawn,
    /// the figures a run computes (rmse, pop, lodpop and its parts, FLIP, transitions), in frames.csv,
    /// transitions.csv, summary.csv and run.json (docs/measurement.md, "Scoring another renderer's frames").
    Score(ScoreArgs),
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
    #[arg(long, help_heading = heading::MEASUREMENT)]
    pub warmup: Option<u32>,
    /// Timing rounds: each times every method and the bare draw, in an order shuffled from --seed.
    #[arg(long, default_value_t = 20, help_heading = heading::MEASUREMENT)]
    pub rounds: u32,
    /// Seed of the rounds' order (recorded in overhead.json).
    #[arg(long, default_value_t = 1, help_heading = heading::MEASUREMENT)]
    pub seed: u64,
    /// GPU adapter, by index or name substring (`lodbench list`).
    #[arg(long, help_heading = heading::MEASUREMENT)]
    pub adapter: Option<String>,
    /// Output folder (default results/overhead-<time>/).
    #[arg(long, help_heading = heading::OUTPUT)]
    pub out: Option<PathBuf>,
}

#[derive(Debug, Clone, Args)]
pub struct ProbeArgs {
    /// The target's width in pixels (the geometry probes' control draws into twice the width).
    #[arg(long, default_value_t = 512)]
    pub width: u32,
    /// The target's height in pixels.
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
#[command(mut_args = hide_if_not_for_tune)]
pub struct TuneArgs {
    /// The scene whose models to tune: a built-in scene's name or a glTF file.
    #[arg(long)]
    pub scene: String,
    #[command(flatten)]
    pub scene_args: SceneArgs,
    /// The budget as lodpop: the largest RMS change over the frame (sRGB, in (0, 1)) a switch may cause.
    #[arg(long, conflicts_with = "budget_jod", help_heading = TUNING)]
    pub budget_lodpop: Option<f64>,
    /// The budget as ColorVideoVDP's JOD between the two frames: the least a switch may score (10: invisible).
    #[arg(long, help_heading = TUNING)]
    pub budget_jod: Option<f64>,
    /// A calibration (calibration.json, `scripts/calibration.py fit`): the budget in JNDs of its lodpop
    /// threshold (--budget-jnd), drawn at its display's size.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["budget_lodpop", "budget_jod"], help_heading = TUNING)]
    pub calibration: Option<PathBuf>,
    /// With --calibration: the budget in JNDs (1: the observer's 75 % threshold).
    #[arg(long, value_name = "K", requires = "calibration", help_heading = TUNING)]
    pub budget_jnd: Option<f64>,
    /// View directions per LOD pair: the scene's own (+z) and the rest from a seeded Fibonacci sphere.
    #[arg(long, default_value_t = 32, help_heading = TUNING)]
    pub views: u32,
    /// Distances per view, log-spaced from where the model fits the view to where it is two pixels across.
    #[arg(long, default_value_t = 24, help_heading = TUNING)]
    pub distances: u32,
    /// Measure every view at every grid distance (tune.csv then holds whole curves); by default each view's
    /// curve stops at the nearest distance that breaks the budget, which gives the same switches with fewer draws.
    #[arg(long, help_heading = TUNING)]
    pub full_grid: bool,
    /// The camera's speed (world units a second): with it, the narrowest --band blending methods need.
    #[arg(long, help_heading = TUNING)]
    pub speed: Option<f32>,
    /// Frames per second the speed is measured at.
    #[arg(long, default_value_t = 60.0, help_heading = TUNING)]
    pub fps: f32,
    /// Seed of the view directions (recorded in tune.json).
    #[arg(long, default_value_t = 1, help_heading = TUNING)]
    pub seed: u64,
    /// ColorVideoVDP display model of --budget-jod.
    #[arg(long, default_value = "standard_fhd", help_heading = TUNING)]
    pub display: String,
    /// GPU adapter, by index or name substring (`lodbench list`).
    #[arg(long, help_heading = heading::MEASUREMENT)]
    pub adapter: Option<String>,
    /// Output folder (default results/tune-<scene>-<time>/).
    #[arg(long, help_heading = heading::OUTPUT)]
    pub out: Option<PathBuf>,
}

/// `tune`'s own heading: the budget and the search.
const TUNING: &str = "Budget and search";

#[derive(Debug, Clone, Args)]
pub struct ScoreArgs {
    /// The score folder: score.json, lods.csv, frame/, counterfactual/, and optionally reference/ and stats.csv.
    pub dir: PathBuf,
    /// Where frames.csv, transitions.csv, summary.csv, run.json and frames/ (the pictures under a run's dump
    /// names, for `clips` and `perceptual`) go (default: DIR itself).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Image metrics per frame, as `run --metrics` (rmse, pop and lodpop always; de2000: the CPU's CIEDE2000;
    /// flip: NVIDIA FLIP); those against the reference are empty without reference/.
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [Metric::Rmse, Metric::Pop])]
    pub metrics: Vec<Metric>,
    /// The popping budget: a transition over it counts as a visible pop, and the answer is stated within it.
    #[arg(long)]
    pub budget_lodpop: Option<f64>,
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
    /// Nearest-neighbour upscaling factor (default: the smallest that shows at least 200 pixels high).
    #[arg(long)]
    pub scale: Option<u32>,
    /// Show the whole frame (default: the box around what the clip's pictures draw, with 8 pixels around).
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
    /// MP4s with ffmpeg: auto (when ffmpeg is on the PATH), on (an error without it), off; only: the MP4 alone,
    /// no frame images and no animated PNG, report.html's player plays it (a third of the bytes or less; needs
    /// ffmpeg).
    #[arg(long, value_enum, value_parser = names_only::<Mp4>(), default_value = "auto")]
    pub mp4: Mp4,
}

/// The display a calibration is made for and holds on (`lodbench calibrate`): each flag defaults to a common
/// desktop monitor, ColorVideoVDP's `standard_fhd` (24-inch 1920x1080 at 60 Hz, seen from 60 cm, 200 cd/m2).
#[derive(Debug, Clone, Args)]
pub struct DisplayArgs {
    /// The display's width in pixels.
    #[arg(long, default_value_t = 1920, help_heading = DISPLAY)]
    pub display_width: u32,
    /// The display's height in pixels.
    #[arg(long, default_value_t = 1080, help_heading = DISPLAY)]
    pub display_height: u32,
    /// The display's refresh rate in Hz: the stimuli play one frame per refresh, and the page refuses a display
    /// that refreshes at another rate.
    #[arg(long, default_value_t = 60.0, help_heading = DISPLAY)]
    pub refresh_hz: f64,
    /// The display's diagonal in inches.
    #[arg(long, default_value_t = 24.0, value_name = "INCHES", help_heading = DISPLAY)]
    pub diagonal_in: f64,
    /// The observer's distance from the screen in centimetres.
    #[arg(long, default_value_t = 60.0, value_name = "CM", help_heading = DISPLAY)]
    pub viewing_distance_cm: f64,
    /// The display's peak luminance in cd/m2 (ColorVideoVDP's display model).
    #[arg(long, default_value_t = 200.0, value_name = "CD_M2", help_heading = DISPLAY)]
    pub peak_luminance: f64,
}

/// `calibrate`'s heading for the display flags.
const DISPLAY: &str = "Display";

#[derive(Debug, Clone, Args)]
pub struct CalibrateArgs {
    /// Scenes whose models make the stimuli (comma-separated): built-in names or glTF files; each scene's first
    /// model with two LODs or more, alone, at rest, the camera dollying away from it through one switch.
    #[arg(long, value_delimiter = ',', required = true)]
    pub scene: Vec<String>,
    /// Transition methods of the stimuli (comma-separated): each scene and method is one staircase.
    #[arg(long, value_delimiter = ',', default_value = "discrete,dither,alpha")]
    pub method: Vec<String>,
    #[command(flatten)]
    pub display: DisplayArgs,
    /// The stimulus's side in pixels: a square window of the display, drawn one image pixel per display pixel,
    /// with the display's projection (its vertical field of view --fov over --display-height).
    #[arg(long, default_value_t = 512)]
    pub stimulus_size: u32,
    /// Vertical field of view of the display's full frame in degrees.
    #[arg(long, default_value_t = 60.0)]
    pub fov: f32,
    /// Length of each interval in milliseconds (frames: this times --refresh-hz).
    #[arg(long, default_value_t = 500.0)]
    pub interval_ms: f64,
    /// Length of dither's and alpha's fade in milliseconds.
    #[arg(long, default_value_t = 200.0)]
    pub fade_ms: f64,
    /// The ladder's switch distances, as multiples of the distance where the pair's error projects to one pixel
    /// (comma-separated): nearer is a larger pop.
    #[arg(long, value_delimiter = ',', default_value = "0.2,0.32,0.5,0.8,1.25,2")]
    pub scales: Vec<f32>,
    /// At most this many LOD pairs per model (0->1, 1->2, ...; 0: all).
    #[arg(long, default_value_t = 0)]
    pub pairs: u32,
    /// Valid trials per staircase (scene and method).
    #[arg(long, default_value_t = 40)]
    pub trials_per_track: u32,
    /// Seed of the page's random choices (which interval switches, which staircase goes next).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// GPU adapter, by index or name substring (`lodbench list`).
    #[arg(long)]
    pub adapter: Option<String>,
    /// Output folder (default results/calibrate-<time>/).
    #[arg(long)]
    pub out: Option<PathBuf>,
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
    /// Print the planned runs with the shard each belongs to under `--shard i/N`, without rendering.
    #[arg(long)]
    pub list: bool,
    /// Run only part i of n of the planned runs (run k goes to shard k mod n + 1); `lodbench merge` joins them.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,
    /// Skip the runs whose run.json in the output folder says complete with the same flags; run the rest.
    #[arg(long)]
    pub resume: bool,
    /// Run every run on this adapter (overrides the file's `adapter`): an index or a part of its name.
    #[arg(long, value_name = "INDEX|NAME")]
    pub adapter: Option<String>,
    /// Override a key of the file's run table in every run: `--set frames=300` (TOML syntax; repeatable).
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
    /// Merge runs made on different adapters (shards on different GPUs); no figure is averaged across them.
    #[arg(long)]
    pub allow_adapters: bool,
    /// Merge runs built from uncommitted changes even where their changes differ or cannot be told apart.
    #[arg(long)]
    pub allow_dirty: bool,
}

#[derive(Debug, Clone, Args)]
pub struct AnswerArgs {
    /// A results folder: a run's, an experiment's or a merged one (its summary.csv).
    pub dir: PathBuf,
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

/// Flags that change what a scene is (shared by `run`, `describe`, `export`, `tune` and `overhead`).
// The fields are in the order `-h` lists them, a heading's flags together (clap orders the headings by their
// first flag); docs/flags.md has each flag's whole text.
#[derive(Debug, Clone, Args, Deserialize)]
#[serde(default, rename_all = "kebab-case")]
pub struct SceneArgs {
    /// Size preset (viewport, frames, counts, warm-up); explicit flags override it.
    #[arg(long, value_enum, value_parser = names_only::<Profile>(), default_value_t = Profile::Quick)]
    pub profile: Profile,
    /// Viewport width in pixels (default: the profile's).
    #[arg(long, help_heading = heading::SCENE)]
    pub width: Option<u32>,
    /// Viewport height in pixels (default: the profile's).
    #[arg(long, help_heading = heading::SCENE)]
    pub height: Option<u32>,
    /// Timed frames (also the length of the quality pass; for bunny-sweep the whole path out and back).
    #[arg(long, help_heading = heading::SCENE)]
    pub frames: Option<u32>,
    /// Vertical field of view in degrees.
    #[arg(long, default_value_t = 60.0, help_heading = heading::SCENE)]
    pub fov: f32,
    /// Camera motion: the scene's own path, an orbit around what it looks at, or bunny-sweep's dolly.
    #[arg(long, value_enum, value_parser = names_only::<CameraMode>(), default_value_t = CameraMode::Fixed,
          help_heading = heading::SCENE)]
    pub camera: CameraMode,
    /// A camera path (CSV) that replaces every scene's own camera, resampled to --frames.
    #[arg(long, value_name = "CSV", help_heading = heading::SCENE)]
    pub camera_path: Option<PathBuf>,
    /// Mesh file (.obj, .gltf or .glb) that replaces the Stanford bunny in the bunny scenes.
    #[arg(long, value_name = "FILE", help_heading = heading::BUILT_IN)]
    pub mesh: Option<PathBuf>,
    /// Where the bunny scenes' path starts (default: the profile's: close-up for regress, else fit).
    #[arg(long, value_enum, value_parser = names_only::<SweepStart>(), help_heading = heading::BUILT_IN)]
    pub sweep_start: Option<SweepStart>,
    /// How bunny-halves and terrain divide their mesh into blocks.
    #[arg(long, value_enum, value_parser = names_only::<PartitionMode>(), default_value_t = PartitionMode::Clip,
          help_heading = heading::BUILT_IN)]
    pub partition: PartitionMode,
    /// terrain: blocks along the mesh's longest side (default: 4 at regress, 16 at paper, 8 otherwise).
    #[arg(long, help_heading = heading::BUILT_IN)]
    pub blocks: Option<u32>,
    /// bunny-grid instance counts; each count is its own block of rows.
    #[arg(long, value_delimiter = ',', help_heading = heading::BUILT_IN)]
    #[serde(deserialize_with = "one_or_many")]
    pub count: Vec<u32>,
    /// How a user's mesh (--scene FILE.glb, --mesh) is simplified into its LOD chain.
    #[arg(long, value_enum, value_parser = names_only::<crate::geometry::lod::Simplify>(),
          default_value_t = crate::geometry::lod::Simplify::Attributes, help_heading = heading::FILE)]
    pub simplify: crate::geometry::lod::Simplify,
    /// The file's materials (full), or one colour per model as the built-in scenes draw (flat).
    #[arg(long, value_enum, value_parser = names_only::<crate::geometry::material::MaterialMode>(),
          default_value_t = crate::geometry::material::MaterialMode::Full, help_heading = heading::FILE)]
    pub materials: crate::geometry::material::MaterialMode,
    /// The animation played over the frames, by index or name, or none (default: the file's first).
    #[arg(long, help_heading = heading::FILE)]
    pub animation: Option<String>,
    /// Screen-space error in pixels (at the viewport's height) at which each LOD is switched in.
    #[arg(long, value_name = "PIXELS", help_heading = heading::SWITCHES)]
    pub pixel_error: Option<f32>,
    /// Explicit switch distances for LOD1, LOD2, ... (world units), overriding --pixel-error.
    #[arg(long, value_delimiter = ',', value_name = "D1,D2,..", help_heading = heading::SWITCHES)]
    pub switch_distances: Option<Vec<f32>>,
    /// Switches as engines' screen sizes for LOD1, LOD2, ... (decreasing), overriding --pixel-error.
    #[arg(long, value_delimiter = ',', value_name = "S1,S2,..", conflicts_with = "switch_distances",
          help_heading = heading::SWITCHES)]
    pub switch_screen_sizes: Option<Vec<f32>>,
    /// How k advances through a transition (default: distance on the built-in scenes, time on a glTF file).
    #[arg(long, value_enum, value_parser = names_only::<FadeMode>(), help_heading = heading::SWITCHES)]
    pub fade: Option<FadeMode>,
    /// Half-width of the transition band as a fraction of the switch distance.
    #[arg(long, default_value_t = 0.05, help_heading = heading::SWITCHES)]
    pub band: f32,
    /// Length of a time-based fade in frames (default: 30 on the built-in scenes, 8 on a glTF file).
    #[arg(long, help_heading = heading::SWITCHES)]
    pub fade_frames: Option<u32>,
    /// Hysteresis margin as a fraction of the switch distance.
    #[arg(long, default_value_t = 0.0, help_heading = heading::SWITCHES)]
    pub hysteresis: f32,
    /// At most this many instances in transition at once (0: no cap; needs --fade time).
    #[arg(long, default_value_t = 0, help_heading = heading::SWITCHES)]
    pub max_transitions: u32,
    /// Extra ALU work per shaded fragment that leaves the image unchanged: an expensive material's cost.
    #[arg(long, default_value_t = 0, value_name = "N", help_heading = heading::EFFECTS)]
    pub shader_work: u32,
    #[command(flatten)]
    #[serde(flatten)]
    pub taa: crate::effects::taa::TaaArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub shadow: crate::effects::shadow::ShadowArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub impostor: crate::geometry::impostor::ImpostorArgs,
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
    // The methods' flags before the measurement's, so that `-h` lists them in that order.
    /// The method every method's time is divided by, round by round (default: discrete when it is run).
    #[arg(long, value_name = "METHOD", help_heading = heading::METHODS)]
    pub baseline: Option<String>,
    #[command(flatten)]
    #[serde(flatten)]
    pub method_options: MethodOptions,
    /// Untimed frames rendered before the timed ones (default: the profile's).
    #[arg(long, help_heading = heading::MEASUREMENT)]
    pub warmup: Option<u32>,
    /// Seed of every random choice (recorded in run.json).
    #[arg(long, default_value_t = 1, help_heading = heading::MEASUREMENT)]
    pub seed: u64,
    /// Timing rounds: consecutive segments of the timed frames, each timing every method in a shuffled order.
    #[arg(long, default_value_t = 20, help_heading = heading::MEASUREMENT)]
    pub rounds: u32,
    /// The popping budget the printed answer is stated within (default: half discrete's largest lodpop).
    #[arg(long, help_heading = heading::MEASUREMENT)]
    pub budget_lodpop: Option<f64>,
    /// A calibration (calibration.json, `scripts/calibration.py fit`): pops in JNDs of its lodpop threshold
    /// (summary.csv's and transitions.csv's lodpop_max_jnd), the budget --budget-jnd JNDs, visible pops over
    /// 1 JND. It holds for its display: a run at another --width/--height is refused.
    #[arg(long, value_name = "FILE", conflicts_with = "budget_lodpop", help_heading = heading::MEASUREMENT)]
    pub calibration: Option<PathBuf>,
    /// With --calibration: the answer's budget in JNDs [default: 1].
    #[arg(long, value_name = "K", requires = "calibration", conflicts_with = "budget_lodpop",
          help_heading = heading::MEASUREMENT)]
    pub budget_jnd: Option<f64>,
    /// The path's frame rate, for visible_pops_per_min (default: the calibration's refresh rate, else 60).
    #[arg(long, value_name = "FPS", help_heading = heading::MEASUREMENT)]
    pub path_fps: Option<f64>,
    /// Measure the adapter's ceilings (`lodbench probe`'s rates) before the blocks, for summary.csv's bound.
    #[arg(long, value_enum, default_value_t = OnOff::On, help_heading = heading::MEASUREMENT)]
    pub ceilings: OnOff,
    /// Before each method's timed segment, bring a GPU's clock back up with the triangle probe.
    #[arg(long, value_enum, value_parser = names_only::<ClockWarmup>(), default_value_t = ClockWarmup::Auto,
          help_heading = heading::MEASUREMENT)]
    pub clock_warmup: ClockWarmup,
    /// Image metrics per frame (rmse, pop and lodpop always; de2000: CIEDE2000; flip: NVIDIA FLIP, on the CPU).
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [Metric::Rmse, Metric::Pop],
          help_heading = heading::MEASUREMENT)]
    #[serde(deserialize_with = "one_or_many")]
    pub metrics: Vec<Metric>,
    /// How the metric kernel sums a row: per-invocation atomics or a workgroup-memory reduction.
    #[arg(long, value_enum, value_parser = names_only::<MetricReduction>(),
          default_value_t = MetricReduction::Atomics, help_heading = heading::MEASUREMENT)]
    pub metric_reduction: MetricReduction,
    /// Which pixels the quality pass reads: those the instances can cover, or every one (same figures).
    #[arg(long, value_enum, value_parser = names_only::<MetricRegion>(), default_value_t = MetricRegion::Covered,
          help_heading = heading::MEASUREMENT)]
    pub metric_region: MetricRegion,
    /// The quality pass; off: the warm-up and the timing rounds only, every image figure left empty.
    #[arg(long, value_enum, default_value_t = OnOff::On, help_heading = heading::MEASUREMENT)]
    pub quality: OnOff,
    /// When the quality pass is made: a segment after each timing round, or after every round.
    #[arg(long, value_enum, value_parser = names_only::<QualitySchedule>(),
          default_value_t = QualitySchedule::Rounds, help_heading = heading::MEASUREMENT)]
    pub quality_schedule: QualitySchedule,
    /// GPU memory a scene block may keep of the reference's frames, copied instead of drawn again (0: none).
    #[arg(long, default_value_t = 1024, value_name = "MIB", help_heading = heading::MEASUREMENT)]
    pub reference_cache_mib: u64,
    /// The adapter: an index as `lodbench list` prints them (0-based) or a part of its name (default: the best).
    #[arg(long, value_name = "INDEX|NAME", help_heading = heading::MEASUREMENT)]
    #[serde(deserialize_with = "name_or_index")]
    pub adapter: Option<String>,
    /// Output folder (default results/<scene>-<time>/).
    #[arg(long, help_heading = heading::OUTPUT)]
    pub out: Option<PathBuf>,
    /// Write PNGs of the method frame, the reference frame and an error heat-map.
    #[arg(long, help_heading = heading::OUTPUT)]
    pub dump_frames: bool,
    /// With --dump-frames: every k-th frame only.
    #[arg(long, default_value_t = 1, value_name = "K", help_heading = heading::OUTPUT)]
    pub dump_every: u32,
    /// With --dump-frames: only frames with an instance in transition (of those, every --dump-every-th).
    #[arg(long, help_heading = heading::OUTPUT)]
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
    #[arg(long, help_heading = heading::OUTPUT)]
    pub json: bool,
    /// Also measure each LOD against LOD0: the largest and the mean distance from LOD0's vertices to its surface.
    #[arg(long, help_heading = heading::OUTPUT)]
    pub deviation: bool,
    /// Print instead the camera of frame F as JSON: eye, view matrix, field of view, clip planes, viewport.
    #[arg(long, value_name = "F", help_heading = heading::OUTPUT)]
    pub camera_json: Option<u32>,
    /// Print instead every frame's camera as one JSON object: the field of view, clip planes, viewport, light and
    /// ambient once, then per frame its eye, view and projection matrices (what a renderer needs to fly the
    /// run's camera path, `scripts/three_lod.py`).
    #[arg(long, conflicts_with = "camera_json", help_heading = heading::OUTPUT)]
    pub cameras_json: bool,
}

#[derive(Debug, Clone, Args)]
pub struct ExportArgs {
    /// The scene to export (the unified scenes are not exported; a glTF scene only as .obj).
    #[arg(long)]
    pub scene: String,
    #[command(flatten)]
    pub scene_args: SceneArgs,
    /// The file to write: .glb (a built-in scene, its LOD chains and camera) or .obj (the geometry of --frame).
    #[arg(long, value_name = "FILE", help_heading = heading::OUTPUT)]
    pub out: PathBuf,
    /// The frame `--out FILE.obj` shows (its animation's pose, its camera ignored).
    #[arg(long, default_value_t = 0, help_heading = heading::OUTPUT)]
    pub frame: u32,
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
    /// The MP4 alone: no per-frame images and no animated PNG (report.html's player plays the MP4); an error
    /// when `ffmpeg` is missing.
    Only,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cli_is_consistent() {
        Cli::command().debug_assert();
    }

    /// `lodbench` and every subcommand, built (the help flags and the `help` subcommand added).
    fn every_command() -> Vec<clap::Command> {
        let mut cmd = Cli::command();
        cmd.build();
        let mut all: Vec<clap::Command> = cmd.get_subcommands().cloned().collect();
        all.push(cmd);
        all
    }

    /// clap prints `--help` as the long listing (a flag's whole doc comment, each value of an enum on a line
    /// of its own) when anything has a long text; nothing has, so `--help` is `-h`'s summary.
    #[test]
    fn help_has_one_paragraph_a_flag_and_no_value_texts() {
        for cmd in every_command() {
            let name = cmd.get_name().to_string();
            assert!(
                cmd.get_long_about().is_none(),
                "{name}: a doc comment of more than one paragraph"
            );
            for a in cmd.get_arguments() {
                let flag = a.get_long().unwrap_or(a.get_id().as_str());
                assert!(
                    a.get_long_help().is_none(),
                    "{name} --{flag}: a doc comment of more than one paragraph (the rest goes to docs/flags.md)"
                );
                for v in a.get_possible_values() {
                    assert!(
                        v.get_help().is_none(),
                        "{name} --{flag} {}: a value with a help text (value_parser = names_only::<E>())",
                        v.get_name()
                    );
                }
            }
        }
    }

    #[test]
    fn every_flag_with_a_value_takes_a_negative_number() {
        for cmd in every_command() {
            for a in cmd.get_arguments() {
                if a.get_action().takes_values() {
                    assert!(
                        a.is_allow_negative_numbers_set(),
                        "{} --{:?}",
                        cmd.get_name(),
                        a.get_long()
                    );
                }
            }
        }
        let parse = |args: &[&str]| Cli::try_parse_checked_from(args).map(|c| c.command);
        let Ok(Command::Tune(t)) =
            parse(&["lodbench", "tune", "--scene", "x", "--budget-lodpop", "-1"])
        else {
            panic!("tune --budget-lodpop -1 does not parse")
        };
        assert_eq!(t.budget_lodpop, Some(-1.0));
        let Ok(Command::Run(r)) = parse(&["lodbench", "run", "--hysteresis", "-0.1"]) else {
            panic!("run --hysteresis -0.1 does not parse")
        };
        assert_eq!(r.scene_args.hysteresis, -0.1);
    }

    #[test]
    fn tune_hides_and_refuses_the_scene_flags_it_does_not_read() {
        let cmd = Cli::command();
        let tune = cmd.find_subcommand("tune").unwrap();
        for id in NOT_FOR_TUNE {
            let a = tune
                .get_arguments()
                .find(|a| a.get_id() == *id)
                .unwrap_or_else(|| panic!("{id} is not a flag of tune"));
            assert!(a.is_hide_set(), "{id} shows in tune -h");
            let flag = format!("--{}", a.get_long().unwrap());
            // A value the flag takes: its default, else its first value, else a number.
            let value = a
                .get_default_values()
                .first()
                .map(|v| v.to_string_lossy().into_owned())
                .or_else(|| {
                    a.get_possible_values()
                        .first()
                        .map(|v| v.get_name().to_string())
                })
                .unwrap_or_else(|| "1".to_string());
            let mut args = vec!["lodbench", "tune", "--scene", "x", flag.as_str()];
            if a.get_action().takes_values() {
                args.push(&value);
            }
            let err = Cli::try_parse_checked_from(&args)
                .err()
                .unwrap_or_else(|| panic!("{args:?} parses"));
            assert_eq!(err.kind(), clap::error::ErrorKind::ArgumentConflict);
            assert!(
                err.to_string()
                    .contains(&format!("{flag} changes nothing for tune")),
                "{err}"
            );
        }
        // The rest of tune's flags show and parse; every flag of run shows.
        assert!(tune
            .get_arguments()
            .filter(|a| !NOT_FOR_TUNE.contains(&a.get_id().as_str()))
            .all(|a| !a.is_hide_set()));
        let run = cmd.find_subcommand("run").unwrap();
        assert!(run.get_arguments().all(|a| !a.is_hide_set()));
        let args = [
            "lodbench",
            "tune",
            "--scene",
            "x",
            "--band",
            "0.1",
            "--pixel-error",
            "2",
        ];
        assert!(Cli::try_parse_checked_from(args).is_ok());
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
