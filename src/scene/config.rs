//! Scene-defining settings after the profile is applied, and what they resolve to for each scene.

use crate::error::{Error, Result};
use crate::scene::kind::{CameraMode, Profile, ProfileValues, SceneKind, SweepStart};
use crate::scene::model::SwitchSource;
use crate::scene::schedule::ScheduleParams;
use serde::Serialize;

/// Scene-defining settings after the profile is applied (built from the flags by `crate::cli::run_config`).
#[derive(Debug, Clone, Serialize)]
pub struct SceneConfig {
    pub profile: Profile,
    pub camera: CameraMode,
    /// Explicit overrides; None = the profile's value for each scene.
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub frames: Option<u32>,
    pub mesh: Option<std::path::PathBuf>,
    /// `--camera-path`, read: replaces every scene's camera.
    pub camera_path: Option<crate::scene::camera_path::CameraPath>,
    /// `--pixel-error`; None = the scene's default ([`SceneConfig::pixel_error`]).
    pub pixel_error: Option<f32>,
    /// `--sweep-start`; None = the profile's.
    pub sweep_start: Option<SweepStart>,
    pub switch_distances: Option<Vec<f32>>,
    /// `--switch-screen-sizes`: switches as screen sizes, converted per model.
    pub switch_screen_sizes: Option<Vec<f32>>,
    /// `--partition` (bunny-halves, terrain).
    pub partition: crate::geometry::blocks::PartitionMode,
    /// `--blocks`; None = the profile's.
    pub blocks: Option<u32>,
    pub counts: Option<Vec<u32>>,
    pub fov_deg: f32,
    /// `--animation`: which of a glTF scene's animations plays.
    pub animation: AnimationChoice,
    /// `--simplify`: how a user's mesh is simplified into its LOD chain.
    pub simplify: crate::geometry::lod::Simplify,
    /// `--materials`: a user scene's materials drawn, or one flat colour per model.
    pub materials: crate::geometry::material::MaterialMode,
    /// `--shader-work`: extra ALU iterations per shaded fragment (0: none).
    pub shader_work: u32,
    /// The LOD schedule of the built-in scenes (`--fade` defaults to `distance`, as in the papers).
    pub schedule: ScheduleParams,
    /// The LOD schedule of a user's glTF file (`--fade` defaults to `time`, [`ScheduleParams::FOR_USER_FILES`]).
    pub user_schedule: ScheduleParams,
    /// `--taa on`: the jitter of every frame's camera and the resolve after it.
    pub taa: Option<crate::effects::taa::Taa>,
    /// `--shadows on`: the shadow map (and a ground under the bunny scenes).
    pub shadows: Option<crate::effects::shadow::Shadows>,
    /// `--impostor`: every model's chain ends in an octahedral impostor (`scene/impostors.rs`).
    pub impostor: Option<crate::geometry::impostor::Impostor>,
}

/// `--animation`: which of a glTF scene's animations plays over the frames.
#[derive(Debug, Clone, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum AnimationChoice {
    /// The file's first animation (none when it has none).
    #[default]
    First,
    /// The scene at rest.
    None,
    Index(usize),
    Name(String),
}

impl AnimationChoice {
    /// `none`, an index, or an animation's name.
    pub fn parse(text: &str) -> AnimationChoice {
        match text {
            "none" => AnimationChoice::None,
            t => t
                .parse()
                .map(AnimationChoice::Index)
                .unwrap_or_else(|_| AnimationChoice::Name(t.to_string())),
        }
    }
}

impl SceneConfig {
    /// The LOD schedule of `kind`, checked: a user's file's or the built-in scenes'.
    pub fn schedule(&self, kind: SceneKind) -> Result<ScheduleParams> {
        let s = if kind.is_user() {
            self.user_schedule
        } else {
            self.schedule
        };
        s.validate()?;
        Ok(s)
    }

    /// The profile's values for `kind` with the explicit flags applied.
    pub fn resolved(&self, kind: SceneKind) -> ProfileValues {
        let p = kind.profile(self.profile);
        ProfileValues {
            width: self.width.unwrap_or(p.width),
            height: self.height.unwrap_or(p.height),
            frames: self.frames.unwrap_or(p.frames),
            warmup: p.warmup,
            sweep_start: self.sweep_start.unwrap_or(p.sweep_start),
        }
    }

    /// The screen-space error (pixels) the switch distances of `kind` are made for, at viewport height
    /// `height`: `--pixel-error`, or by default one pixel at [`PAPER_HEIGHT`] for the bunny scenes
    /// (Sheliemietiev et al. 2023 ran them at 800x600; this keeps their switch distances and path the same at
    /// every viewport size, so a smaller profile is the same experiment at a lower resolution), except for a
    /// close-up path (1 pixel at this viewport), and 1 for the procedural scenes (whose camera flights start
    /// beyond the last switch at any size).
    pub fn pixel_error(&self, kind: SceneKind, height: u32) -> f32 {
        let close_up = self.resolved(kind).sweep_start == SweepStart::CloseUp;
        match self.pixel_error {
            Some(p) => p,
            None if kind.is_bunny() && !close_up => height as f32 / PAPER_HEIGHT as f32,
            None => 1.0,
        }
    }

    /// The instance counts of `kind`: `--count`, or the profile's (bunny-sweep is always one bunny).
    pub fn counts(&self, kind: SceneKind) -> Vec<u32> {
        match &self.counts {
            Some(c) if !kind.single_count() => c.clone(),
            _ => kind.profile_counts(self.profile),
        }
    }

    /// Model `what`'s switch distances and where they come from: `--switch-distances` or
    /// `--switch-screen-sizes` where given (an error unless they give one value for each of its `lods` LODs after
    /// LOD0), else `otherwise`'s. A screen size becomes the distance at which the model's bounding sphere
    /// (`radius`, world units) has it under the vertical field of view `fov_y` (radians,
    /// `geometry::projection::distance_of`).
    pub fn switches_or(
        &self,
        what: &str,
        (lods, radius, fov_y): (usize, f32, f32),
        otherwise: impl FnOnce() -> (Vec<f32>, SwitchSource),
    ) -> Result<(Vec<f32>, SwitchSource)> {
        Ok(match self.switch_override(what, lods, radius, fov_y)? {
            Some(s) => (s, SwitchSource::Override),
            None => otherwise(),
        })
    }

    /// `--switch-distances` (or `--switch-screen-sizes` as distances) for model `what` of `lods` LODs: None
    /// without either flag ([`SceneConfig::switches_or`]).
    fn switch_override(
        &self,
        what: &str,
        lods: usize,
        radius: f32,
        fov_y: f32,
    ) -> Result<Option<Vec<f32>>> {
        let (flag, values) = match (&self.switch_distances, &self.switch_screen_sizes) {
            (Some(d), _) => ("--switch-distances", d),
            (None, Some(s)) => ("--switch-screen-sizes", s),
            (None, None) => return Ok(None),
        };
        if values.len() != lods - 1 {
            return Err(Error::Config(format!(
                "{flag} has {} values but {what} has {} LODs after LOD0",
                values.len(),
                lods - 1
            )));
        }
        Ok(Some(match &self.switch_distances {
            Some(d) => d.clone(),
            None => values
                .iter()
                .map(|&s| crate::geometry::projection::distance_of(radius, s, fov_y))
                .collect(),
        }))
    }
}

/// Viewport height of Sheliemietiev et al. 2023's experiments (800x600): the bunny scenes' default
/// `--pixel-error` is one pixel at this height.
pub const PAPER_HEIGHT: u32 = 600;
