//! The command-line contract (clap derive). Scripts, CI and later issues rely on these exact names.

use crate::schedule::FadeMode;
use clap::{Args, Parser, Subcommand, ValueEnum};
use serde::Serialize;
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
    /// Run a sweep described in a TOML file (scenes/experiments/) into one results folder.
    Experiment(ExperimentArgs),
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
}

/// Size and length presets; explicit flags override them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Profile {
    /// A minute's look at everything: small viewport, few frames.
    Quick,
    /// What CI runs on a software adapter.
    Ci,
    /// The papers' sizes: 800x600, 3,600 timed frames, the full instance counts.
    Paper,
}

/// Flags that change what a scene is (shared by `run` and `describe`).
#[derive(Debug, Clone, Args)]
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
    /// OBJ file that replaces the Stanford bunny in the bunny scenes.
    #[arg(long)]
    pub mesh: Option<PathBuf>,
    /// Screen-space error, in pixels, at which each LOD is switched in.
    #[arg(long, default_value_t = 1.0)]
    pub pixel_error: f32,
    /// Explicit switch distances for LOD1, LOD2, ... (world units), overriding --pixel-error.
    #[arg(long, value_delimiter = ',')]
    pub switch_distances: Option<Vec<f32>>,
    /// bunny-grid instance counts; each count is its own block of rows.
    #[arg(long, value_delimiter = ',')]
    pub count: Vec<u32>,
    /// Vertical field of view in degrees.
    #[arg(long, default_value_t = 60.0)]
    pub fov: f32,
    /// How k advances through a transition.
    #[arg(long, value_enum, default_value_t = FadeMode::Distance)]
    pub fade: FadeMode,
    /// Half-width of the transition band as a fraction of the switch distance (seed 003 section 8).
    #[arg(long, default_value_t = 0.05)]
    pub band: f32,
    /// Length of a time-based fade in frames (--fade time).
    #[arg(long, default_value_t = 30)]
    pub fade_frames: u32,
    /// Hysteresis margin as a fraction of the switch distance.
    #[arg(long, default_value_t = 0.0)]
    pub hysteresis: f32,
    /// Camera motion: `fixed` (the scene's own path) or `orbit` (the camera swings around what it looks at,
    /// +-30 degrees over 240 frames, keeping its distance: every pixel moves, which exercises FSI's
    /// reprojection).
    #[arg(long, value_enum, default_value_t = crate::scene::CameraMode::Fixed)]
    pub camera: crate::scene::CameraMode,
}

#[derive(Debug, Clone, Args)]
pub struct RunArgs {
    /// Scenes to run (comma-separated or repeated); all when absent.
    #[arg(long, value_delimiter = ',')]
    pub scene: Vec<String>,
    /// Methods to run (comma-separated or repeated); all when absent.
    #[arg(long, value_delimiter = ',')]
    pub method: Vec<String>,
    #[command(flatten)]
    pub scene_args: SceneArgs,
    /// Untimed frames rendered before the timed ones.
    #[arg(long)]
    pub warmup: Option<u32>,
    /// Seed of every random choice (recorded in run.json).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Threshold pattern of noise blending (`dither`).
    #[arg(long, value_enum, default_value_t = crate::noise::NoisePattern::White16)]
    pub noise: crate::noise::NoisePattern,
    /// Vertex correspondence of geomorphing (`geomorph`).
    #[arg(long, value_enum, default_value_t = crate::morph::Correspondence::Nearest)]
    pub correspondence: crate::morph::Correspondence,
    /// Visibility texture of Frame Sequential Interpolation (`fsi*`, seed 000 section 3.3).
    #[arg(long, value_enum, default_value_t = crate::noise::VisTexture::Noise)]
    pub vis_texture: crate::noise::VisTexture,
    /// `fsi` only, not in the paper: `forward` uses an older fragment only if, reprojected with its own depth,
    /// it lands within a pixel of the pixel (rejects the disocclusion ghosts of seed 000 section 4.2).
    #[arg(long, value_enum, default_value_t = crate::methods::fsi::FsiCheck::None)]
    pub fsi_check: crate::methods::fsi::FsiCheck,
    /// Image metrics per frame (rmse, pop and de2000 are always computed; flip adds NVIDIA FLIP, on the CPU).
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [crate::metrics::Metric::Rmse, crate::metrics::Metric::Pop, crate::metrics::Metric::De2000])]
    pub metrics: Vec<crate::metrics::Metric>,
    /// Output folder (default results/<scene>-<time>/).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Use the adapter whose name contains this (case-insensitive).
    #[arg(long)]
    pub adapter: Option<String>,
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
