//! `RunConfig`: the flags resolved against the profile and validated before any GPU work. It is copied
//! verbatim into run.json.

use crate::cli::{Profile, RunArgs, SceneArgs};
use crate::error::{Error, Result};
use crate::methods;
use crate::scene;
use crate::schedule::ScheduleParams;
use serde::Serialize;
use std::path::PathBuf;

/// Largest viewport side accepted before asking the device (wgpu's default max_texture_dimension_2d).
pub const MAX_SIDE: u32 = 8192;

/// Colour and depth formats of every render target (recorded in run.json).
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// What a profile sets for one scene.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ProfileValues {
    pub width: u32,
    pub height: u32,
    pub frames: u32,
    pub warmup: u32,
}

/// The paper's counts for bunny-grid (seed 003 section 6).
pub const PAPER_COUNTS: [u32; 5] = [50, 250, 500, 1000, 2000];

pub fn profile_values(profile: Profile, scene: &str) -> ProfileValues {
    // bunny-grid is a static scene: every frame is the same picture, so its timing needs fewer frames at small
    // profiles, and its instance counts make each frame far heavier on a software adapter.
    // bunny-sweep needs many frames: `pop` compares consecutive error images, so the bunny must move by well
    // under a pixel per frame for a LOD switch to stand out from the error pattern moving with the bunny
    // (README, "Reading pop"). At 320x240, 2,400 frames is the fewest for which every discrete switch frame is
    // a local maximum of pop; 600 frames (quick) is only a look.
    // The procedural scenes of seed 000 (simple, windmills, trees) are camera flights over a field: their
    // frames are heavy on a software adapter, so the small profiles keep few frames and instances.
    let grid = scene == "bunny-grid";
    let flight = !scene.starts_with("bunny");
    match profile {
        Profile::Quick => ProfileValues {
            width: 320,
            height: 240,
            frames: if grid {
                20
            } else if flight {
                60
            } else {
                600
            },
            warmup: 5,
        },
        Profile::Ci => ProfileValues {
            width: 320,
            height: 240,
            frames: if grid {
                30
            } else if flight {
                120
            } else {
                2400
            },
            warmup: 10,
        },
        Profile::Paper => ProfileValues {
            width: 800,
            height: 600,
            frames: 3600,
            warmup: 120,
        },
    }
}

/// Instance counts of `scene` under a profile, unless --count is given: bunny-grid's sweep of counts
/// (seed 003), the paper's 4,000 windmills and trees (seed 000 section 4; SIMPLE's count is not given there:
/// 1,000), and small fields for the small profiles.
pub fn profile_counts(profile: Profile, scene: &str) -> Vec<u32> {
    match (scene, profile) {
        ("bunny-sweep", _) => vec![1],
        ("bunny-grid", Profile::Quick) => vec![50],
        ("bunny-grid", Profile::Ci) => vec![50, 250],
        ("bunny-grid", Profile::Paper) => PAPER_COUNTS.to_vec(),
        ("simple", Profile::Quick) => vec![36],
        ("simple", Profile::Ci) => vec![64],
        ("simple", Profile::Paper) => vec![1000],
        ("windmills", Profile::Quick) => vec![9],
        ("windmills", Profile::Ci) => vec![16],
        ("trees", Profile::Quick) => vec![4],
        ("trees", Profile::Ci) => vec![6],
        (_, Profile::Paper) => vec![4000],
        _ => vec![1],
    }
}

/// Scene-defining settings after the profile is applied.
#[derive(Debug, Clone, Serialize)]
pub struct SceneConfig {
    pub profile: Profile,
    pub camera: crate::scene::CameraMode,
    /// Explicit overrides; None = the profile's value for each scene.
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub frames: Option<u32>,
    pub mesh: Option<PathBuf>,
    pub pixel_error: f32,
    pub switch_distances: Option<Vec<f32>>,
    pub counts: Option<Vec<u32>>,
    pub fov_deg: f32,
    pub schedule: ScheduleParams,
}

impl SceneConfig {
    pub fn from_args(a: &SceneArgs) -> Result<SceneConfig> {
        for (flag, v) in [("--width", a.width), ("--height", a.height)] {
            if let Some(v) = v {
                if v == 0 || v > MAX_SIDE {
                    return Err(Error::Config(format!(
                        "{flag} {v} must be between 1 and {MAX_SIDE}"
                    )));
                }
            }
        }
        if a.frames == Some(0) {
            return Err(Error::Config("--frames must be at least 1".into()));
        }
        if !(a.pixel_error.is_finite() && a.pixel_error > 0.0) {
            return Err(Error::Config(format!(
                "--pixel-error {} must be a positive number",
                a.pixel_error
            )));
        }
        if !(a.fov.is_finite() && a.fov > 1.0 && a.fov < 170.0) {
            return Err(Error::Config(format!(
                "--fov {} must be between 1 and 170 degrees",
                a.fov
            )));
        }
        if a.count.contains(&0) {
            return Err(Error::Config("--count values must be at least 1".into()));
        }
        if let Some(s) = &a.switch_distances {
            if s.is_empty() || s.iter().any(|d| !(d.is_finite() && *d > 0.0)) {
                return Err(Error::Config(format!(
                    "--switch-distances {s:?} must be positive numbers"
                )));
            }
            if s.windows(2).any(|w| w[1] <= w[0]) {
                return Err(Error::Config(format!(
                    "--switch-distances {s:?} must increase"
                )));
            }
        }
        let schedule = ScheduleParams {
            fade: a.fade,
            band: a.band,
            fade_frames: a.fade_frames,
            hysteresis: a.hysteresis,
        };
        schedule.validate()?;
        Ok(SceneConfig {
            profile: a.profile,
            width: a.width,
            height: a.height,
            frames: a.frames,
            mesh: a.mesh.clone(),
            pixel_error: a.pixel_error,
            switch_distances: a.switch_distances.clone(),
            counts: if a.count.is_empty() {
                None
            } else {
                Some(a.count.clone())
            },
            fov_deg: a.fov,
            schedule,
            camera: a.camera,
        })
    }

    /// The profile's values for `scene` with the explicit flags applied.
    pub fn resolved(&self, scene: &str) -> ProfileValues {
        let p = profile_values(self.profile, scene);
        ProfileValues {
            width: self.width.unwrap_or(p.width),
            height: self.height.unwrap_or(p.height),
            frames: self.frames.unwrap_or(p.frames),
            warmup: p.warmup,
        }
    }

    pub fn counts(&self, scene: &str) -> Vec<u32> {
        self.counts
            .clone()
            .unwrap_or_else(|| profile_counts(self.profile, scene))
    }
}

/// Everything a run does, validated. Serialised into run.json as `config`.
#[derive(Debug, Clone, Serialize)]
pub struct RunConfig {
    pub scenes: Vec<String>,
    pub methods: Vec<String>,
    pub scene: SceneConfig,
    /// Explicit --warmup; None = the profile's.
    pub warmup: Option<u32>,
    pub seed: u64,
    /// Threshold pattern of `dither`.
    pub noise: crate::noise::NoisePattern,
    /// Vertex correspondence of `geomorph`.
    pub correspondence: crate::morph::Correspondence,
    /// Visibility texture of `fsi*`.
    pub vis_texture: crate::noise::VisTexture,
    /// Older-fragment test of `fsi`'s combination pass (not in the paper; `none` by default).
    pub fsi_check: crate::methods::fsi::FsiCheck,
    /// `--metrics` (rmse, pop, de2000 always; flip when listed).
    pub metrics: Vec<crate::metrics::Metric>,
    pub out: Option<PathBuf>,
    pub adapter: Option<String>,
    pub dump_frames: bool,
    pub dump_every: u32,
    /// With `dump_frames`: only frames with an instance in transition.
    pub dump_transitions: bool,
    pub msaa_samples: u32,
    pub color_format: String,
    pub depth_format: String,
}

impl RunConfig {
    pub fn from_args(a: &RunArgs) -> Result<RunConfig> {
        let scenes = resolve_names("scene", &a.scene, scene::SCENES)?;
        let methods = resolve_names("method", &a.method, methods::METHODS)?;
        if a.dump_every == 0 {
            return Err(Error::Config("--dump-every must be at least 1".into()));
        }
        if a.dump_transitions && !a.dump_frames {
            return Err(Error::Config(
                "--dump-transitions selects which frames --dump-frames writes: add --dump-frames"
                    .into(),
            ));
        }
        Ok(RunConfig {
            scenes,
            methods,
            scene: SceneConfig::from_args(&a.scene_args)?,
            warmup: a.warmup,
            seed: a.seed,
            noise: a.noise,
            correspondence: a.correspondence,
            vis_texture: a.vis_texture,
            fsi_check: a.fsi_check,
            metrics: a.metrics.clone(),
            out: a.out.clone(),
            adapter: a.adapter.clone(),
            dump_frames: a.dump_frames,
            dump_every: a.dump_every,
            dump_transitions: a.dump_transitions,
            msaa_samples: 1,
            color_format: format!("{COLOR_FORMAT:?}"),
            depth_format: format!("{DEPTH_FORMAT:?}"),
        })
    }

    pub fn resolved(&self, scene: &str) -> ProfileValues {
        let mut v = self.scene.resolved(scene);
        if let Some(w) = self.warmup {
            v.warmup = w;
        }
        v
    }
}

/// Checks names against the registry (keeping the user's order, dropping repeats); empty = all.
pub fn resolve_names(kind: &'static str, given: &[String], valid: &[&str]) -> Result<Vec<String>> {
    if given.is_empty() {
        return Ok(valid.iter().map(|s| s.to_string()).collect());
    }
    let mut out: Vec<String> = Vec::new();
    for name in given {
        let name = name.trim();
        if !valid.contains(&name) {
            return Err(Error::unknown(kind, name, valid));
        }
        if !out.iter().any(|n| n == name) {
            out.push(name.to_string());
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::{Cli, Command};
    use clap::Parser;

    fn run_args(extra: &[&str]) -> RunArgs {
        let mut argv = vec!["lodbench", "run"];
        argv.extend_from_slice(extra);
        match Cli::try_parse_from(argv).unwrap().command {
            Command::Run(r) => r,
            _ => unreachable!(),
        }
    }

    #[test]
    fn unknown_names_list_the_valid_ones() {
        let e = RunConfig::from_args(&run_args(&["--scene", "bunny-swep"])).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains("bunny-swep") && msg.contains("bunny-sweep"),
            "{msg}"
        );
        let e = RunConfig::from_args(&run_args(&["--method", "fsii"])).unwrap_err();
        assert!(e.to_string().contains("discrete"), "{e}");
    }

    #[test]
    fn absent_lists_mean_all() {
        let c = RunConfig::from_args(&run_args(&[])).unwrap();
        assert_eq!(c.scenes, scene::SCENES);
        assert_eq!(c.methods, methods::METHODS);
    }

    #[test]
    fn flags_override_profile() {
        let c = RunConfig::from_args(&run_args(&["--profile", "paper", "--frames", "7"])).unwrap();
        let v = c.resolved("bunny-sweep");
        assert_eq!((v.width, v.height, v.frames), (800, 600, 7));
        assert_eq!(c.scene.counts("bunny-grid"), PAPER_COUNTS.to_vec());
    }

    #[test]
    fn bad_values_are_errors() {
        for bad in [
            vec!["--width", "0"],
            vec!["--height", "100000"],
            vec!["--frames", "0"],
            vec!["--pixel-error", "0"],
            vec!["--switch-distances", "3,2"],
            vec!["--band", "0.7"],
            vec!["--count", "0"],
            vec!["--fade-frames", "0"],
        ] {
            assert!(
                RunConfig::from_args(&run_args(&bad)).is_err(),
                "{bad:?} accepted"
            );
        }
    }
}
