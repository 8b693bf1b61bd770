//! The results-folder format, written once: every file and folder name of a run folder and of an experiment
//! folder, the kinds of dumped image, and the frames of a transition's clip.
//!
//! A run folder (`lodbench run --out DIR`):
//! - [`RUN_JSON`]: what was run and whether it finished (`results::manifest::RunManifest`);
//! - [`FRAMES_CSV`] (written as `frames.csv.partial` until the run completes), [`SUMMARY_CSV`],
//!   [`TRANSITIONS_CSV`], [`EVENTS_CSV`], [`ROUNDS_CSV`], [`PAIRS_CSV`] (`results::csv`);
//! - [`FRAMES_DIR`]`/`: with `--dump-frames`, `<stem>_<kind>.png` per dumped frame ([`DumpKind`]);
//! - [`CLIPS_DIR`]`/`: `lodbench clips`, with [`INDEX_JSON`] (built as `clips.partial/`);
//! - [`PERCEPTUAL_CSV`]: `lodbench perceptual`;
//! - [`ANSWER_JSON`]: the answer the folder leads with (`results::answer`), also in an experiment folder.
//!
//! A tune folder (`lodbench tune --out DIR`): [`TUNE_JSON`], [`TUNE_CSV`], [`RULES_CSV`], [`TUNED_GLB`] and
//! [`ENGINES_DIR`]`/` (each engine's file, [`EngineFile`], and [`ENGINES_README`]).
//! A probe folder: [`PROBE_JSON`] and [`PROBE_CSV`]; an overhead folder: [`OVERHEAD_JSON`] and [`OVERHEAD_CSV`].
//!
//! An experiment folder (`lodbench experiment`, `lodbench merge`): [`EXPERIMENT_JSON`]
//! (`results::manifest::ExperimentRecord`), the [`RUN_CSVS`] of all its runs joined, and each run's folder under
//! [`RUNS_DIR`]`/<variable>=<value>/` ([`run_folder_of`]).

use crate::measure::records::{TransitionRecord, TRANSITION_LEAD, TRANSITION_TAIL};
use std::path::{Path, PathBuf};

pub const FRAMES_CSV: &str = "frames.csv";
pub const SUMMARY_CSV: &str = "summary.csv";
pub const TRANSITIONS_CSV: &str = "transitions.csv";
/// The pop events, waves of switches (`measure::records::events`).
pub const EVENTS_CSV: &str = "events.csv";
pub const ROUNDS_CSV: &str = "rounds.csv";
pub const PAIRS_CSV: &str = "pairs.csv";
pub const PERCEPTUAL_CSV: &str = "perceptual.csv";
pub const RUN_JSON: &str = "run.json";
pub const EXPERIMENT_JSON: &str = "experiment.json";
/// The answer of a run or experiment folder (`results::answer`).
pub const ANSWER_JSON: &str = "answer.json";
/// `lodbench tune`'s manifest: what was tuned, the switches per model, the build.
pub const TUNE_JSON: &str = "tune.json";
/// `lodbench tune`'s samples: each view's pop per LOD pair and distance.
pub const TUNE_CSV: &str = "tune.csv";
/// `lodbench tune`'s switch distances by rule (its own and the engines').
pub const RULES_CSV: &str = "rules.csv";
/// `lodbench tune`'s scene as glTF, with the tuned switches.
pub const TUNED_GLB: &str = "tuned.glb";
/// `lodbench tune`'s folder of engine settings.
pub const ENGINES_DIR: &str = "engines";
/// The page in [`ENGINES_DIR`] that says how to use each file.
pub const ENGINES_README: &str = "README.md";
/// `lodbench calibrate`'s page, its stimuli (the page holds them too) and their frames' folder.
pub const CALIBRATE_PAGE: &str = "index.html";
pub const STIMULI_JSON: &str = "stimuli.json";
pub const STIMULI_FRAMES_DIR: &str = "frames";
/// The fit of a calibration's responses (`scripts/calibration.py fit`), which `--calibration` reads.
pub const CALIBRATION_JSON: &str = "calibration.json";
/// `lodbench probe`'s manifest and rows.
pub const PROBE_JSON: &str = "probe.json";
pub const PROBE_CSV: &str = "probe.csv";
/// `lodbench overhead`'s manifest and rows.
pub const OVERHEAD_JSON: &str = "overhead.json";
pub const OVERHEAD_CSV: &str = "overhead.csv";

/// The files in [`ENGINES_DIR`], one per engine's setting.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EngineFile {
    UnityLodGroup,
    UnityLodGroupCrossfade,
    UnrealScreenSizes,
    GodotVisibilityRanges,
    GodotVisibilityRangesFade,
    BevyVisibilityRanges,
    BevyVisibilityRangesFade,
    ThreejsLod,
}

impl EngineFile {
    pub fn name(self) -> &'static str {
        match self {
            EngineFile::UnityLodGroup => "unity-lodgroup.json",
            EngineFile::UnityLodGroupCrossfade => "unity-lodgroup-crossfade.json",
            EngineFile::UnrealScreenSizes => "unreal-screen-sizes.json",
            EngineFile::GodotVisibilityRanges => "godot-visibility-ranges.json",
            EngineFile::GodotVisibilityRangesFade => "godot-visibility-ranges-fade.json",
            EngineFile::BevyVisibilityRanges => "bevy-visibility-ranges.json",
            EngineFile::BevyVisibilityRangesFade => "bevy-visibility-ranges-fade.json",
            EngineFile::ThreejsLod => "threejs-lod.js",
        }
    }
}
/// The frame dumps of a run folder.
pub const FRAMES_DIR: &str = "frames";
/// The transition clips of a run folder.
pub const CLIPS_DIR: &str = "clips";
/// The clips and their frames, in [`CLIPS_DIR`].
pub const INDEX_JSON: &str = "index.json";
/// The run folders of an experiment folder.
pub const RUNS_DIR: &str = "runs";
/// Under [`RUNS_DIR`] of a merged folder: the run of an experiment without a sweep.
pub const UNSWEPT_RUN_DIR: &str = "run";
/// What a file or folder is called while it is written; renamed to its name when whole.
pub const PARTIAL_SUFFIX: &str = ".partial";
/// The empty file that checks an output folder is writable (removed at once).
pub const WRITE_PROBE: &str = ".lodbench-write-test";

/// The CSV files of a run folder that an experiment, and `lodbench merge`, join across runs.
pub const RUN_CSVS: [&str; 6] = [
    FRAMES_CSV,
    SUMMARY_CSV,
    TRANSITIONS_CSV,
    EVENTS_CSV,
    ROUNDS_CSV,
    PAIRS_CSV,
];

/// `name` while it is written: `frames.csv.partial`, `clips.partial`.
pub fn partial(name: &str) -> String {
    format!("{name}{PARTIAL_SUFFIX}")
}

/// The result files of an earlier run that a new run in the same folder removes first, so nothing stale looks
/// complete.
pub fn stale_run_files() -> [String; 7] {
    [
        FRAMES_CSV.to_string(),
        SUMMARY_CSV.to_string(),
        TRANSITIONS_CSV.to_string(),
        EVENTS_CSV.to_string(),
        ROUNDS_CSV.to_string(),
        PAIRS_CSV.to_string(),
        partial(FRAMES_CSV),
    ]
}

/// The folder of the run with swept `values` of `variables` under `out`: `runs/<variable>=<value>/`, for several
/// sweeps `runs/<variable>=<value>+<variable>=<value>/` (a comma of a value as `x`), or `out` itself without a
/// sweep.
pub fn run_folder_of(out: &Path, variables: &[String], values: &[String]) -> PathBuf {
    if variables.is_empty() {
        return out.to_path_buf();
    }
    let values: Vec<String> = values.iter().map(|v| v.replace(',', "x")).collect();
    out.join(RUNS_DIR)
        .join(crate::cli::experiment_file::sweep_label(variables, &values))
}

/// The kinds of image `--dump-frames` writes per frame (defined where the images are made).
pub use crate::methods::common::DumpKind;

/// The frames of a transition's clip (`lodbench clips`, `lodbench perceptual`, and what `--dump-transitions`
/// dumps around it): from [`TRANSITION_LEAD`] before its first frame to [`TRANSITION_TAIL`] after its last.
/// scripts/plot.py mirrors it as CLIP_LEAD and CLIP_TAIL.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ClipWindow {
    pub first: u32,
    pub last: u32,
}

impl ClipWindow {
    pub fn of(t: &TransitionRecord) -> ClipWindow {
        ClipWindow {
            first: t.first_frame.saturating_sub(TRANSITION_LEAD),
            last: t.last_frame + TRANSITION_TAIL,
        }
    }

    pub fn frames(&self) -> std::ops::RangeInclusive<u32> {
        self.first..=self.last
    }
}

/// The files of one clip in [`CLIPS_DIR`], relative to it.
pub struct ClipFiles {
    pub name: String,
}

impl ClipFiles {
    /// The clip of transition `transition` of scene block `scene`, `count`: `bunny-sweep_c1_t03`.
    pub fn new(scene: &str, count: u32, transition: u32) -> ClipFiles {
        ClipFiles {
            name: format!("{scene}_c{count}_t{transition:02}"),
        }
    }

    /// The folder of its frames.
    pub fn folder(&self) -> &str {
        &self.name
    }

    /// Frame `f`'s grid of pictures.
    pub fn frame_image(&self, f: u32) -> String {
        format!("{}/frame_{f:05}.png", self.name)
    }

    /// Frame `f`'s grid of error heat-maps.
    pub fn error_image(&self, f: u32) -> String {
        format!("{}/error_{f:05}.png", self.name)
    }

    /// The animation, as `ext` (`png`, `gif`, `mp4`).
    pub fn animation(&self, ext: &str) -> String {
        format!("{}.{ext}", self.name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dump_kinds_have_distinct_names() {
        let mut names: Vec<&str> = DumpKind::ALL.iter().map(|k| k.name()).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), DumpKind::ALL.len());
    }

    #[test]
    fn folder_names() {
        assert_eq!(partial(FRAMES_CSV), "frames.csv.partial");
        assert_eq!(
            run_folder_of(Path::new("o"), &["viewport".into()], &["64,48".into()]),
            Path::new("o/runs/viewport=64x48")
        );
        assert_eq!(
            run_folder_of(
                Path::new("o"),
                &["band".into(), "viewport".into()],
                &["0.1".into(), "64,48".into()]
            ),
            Path::new("o/runs/band=0.1+viewport=64x48")
        );
        assert_eq!(run_folder_of(Path::new("o"), &[], &[]), Path::new("o"));
        let c = ClipFiles::new("s", 2, 3);
        assert_eq!(c.frame_image(7), "s_c2_t03/frame_00007.png");
        assert_eq!(c.animation("gif"), "s_c2_t03.gif");
    }
}
