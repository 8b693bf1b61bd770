//! `RunConfig`: the flags resolved against the profile and validated before any GPU work. It is copied
//! verbatim into run.json. `SceneConfig` (the part a scene needs) is defined by `crate::scene` and built from
//! the flags here.

use crate::cli::{RunArgs, SceneArgs};
use crate::effects::OnOff;
use crate::error::{Error, Result};
use crate::formats::{COLOR_FORMAT, DEPTH_FORMAT, MAX_SIDE, MSAA_SAMPLES};
use crate::measure::metrics::{Metric, MetricReduction, MetricRegion};
use crate::measure::QualitySchedule;
use crate::methods::{MethodOptions, Registry};
use crate::scene::schedule::ScheduleParams;
use crate::scene::{ProfileValues, SceneConfig, SceneKind, SweepStart};
use serde::Serialize;
use std::path::PathBuf;

impl SceneConfig {
    /// The scene flags, validated.
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
        if let Some(p) = a.pixel_error {
            if !(p.is_finite() && p > 0.0) {
                return Err(Error::Config(format!(
                    "--pixel-error {p} must be a positive number"
                )));
            }
        }
        if !(a.fov.is_finite() && a.fov > 1.0 && a.fov < 170.0) {
            return Err(Error::Config(format!(
                "--fov {} must be between 1 and 170 degrees",
                a.fov
            )));
        }
        if let Some(b) = a.blocks {
            if !(1..=256).contains(&b) {
                return Err(Error::Config(format!(
                    "--blocks {b} must be between 1 and 256"
                )));
            }
        }
        if a.count.contains(&0) {
            return Err(Error::Config("--count values must be at least 1".into()));
        }
        check_switches(a)?;
        // The built-in scenes fade as their papers do; a user's file by time (ScheduleParams::FOR_USER_FILES).
        let schedule_of = |defaults: ScheduleParams| ScheduleParams {
            fade: a.fade.unwrap_or(defaults.fade),
            band: a.band,
            fade_frames: a.fade_frames.unwrap_or(defaults.fade_frames),
            hysteresis: a.hysteresis,
            max_transitions: a.max_transitions,
        };
        let schedule = schedule_of(ScheduleParams::default());
        let user_schedule = schedule_of(ScheduleParams::FOR_USER_FILES);
        user_schedule.validate()?;
        // --max-transitions needs a time fade, which a built-in scene has only with --fade time: that is checked
        // where a built-in scene takes its schedule (SceneConfig::schedule), so a user's file takes the flag alone.
        ScheduleParams {
            max_transitions: 0,
            ..schedule
        }
        .validate()?;
        let camera_path = match &a.camera_path {
            Some(p) => Some(crate::scene::camera_path::CameraPath::load(p)?),
            None => None,
        };
        // A path's own field of view replaces --fov (the switch distances are computed for it).
        let fov_deg = camera_path
            .as_ref()
            .and_then(|p| p.fov_deg)
            .unwrap_or(a.fov);
        Ok(SceneConfig {
            profile: a.profile,
            width: a.width,
            height: a.height,
            frames: a.frames,
            mesh: a.mesh.clone(),
            camera_path,
            pixel_error: a.pixel_error,
            sweep_start: a.sweep_start,
            switch_distances: a.switch_distances.clone(),
            switch_screen_sizes: a.switch_screen_sizes.clone(),
            partition: a.partition,
            blocks: a.blocks,
            counts: if a.count.is_empty() {
                None
            } else {
                Some(a.count.clone())
            },
            fov_deg,
            animation: a
                .animation
                .as_deref()
                .map(crate::scene::config::AnimationChoice::parse)
                .unwrap_or_default(),
            simplify: a.simplify,
            materials: a.materials,
            shader_work: a.shader_work,
            schedule,
            user_schedule,
            camera: a.camera,
            taa: a.taa.resolve()?,
            shadows: a.shadow.resolve()?,
            impostor: a.impostor.params()?,
        })
    }
}

/// `--switch-distances` (positive, increasing) and `--switch-screen-sizes` (positive, decreasing), where
/// given.
fn check_switches(a: &SceneArgs) -> Result<()> {
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
    if let Some(s) = &a.switch_screen_sizes {
        if s.is_empty() || s.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(Error::Config(format!(
                "--switch-screen-sizes {s:?} must be positive numbers"
            )));
        }
        if s.windows(2).any(|w| w[1] >= w[0]) {
            return Err(Error::Config(format!(
                "--switch-screen-sizes {s:?} must decrease (a coarser LOD at a smaller screen size)"
            )));
        }
    }
    Ok(())
}

/// `--calibration`'s lodpop JND, checked against every scene's viewport (a calibration holds for its display),
/// and `--budget-jnd`'s range.
fn calibration_of(
    a: &RunArgs,
    scenes: &[SceneKind],
) -> Result<Option<(crate::cli::calibration::Jnd, f64)>> {
    let Some(path) = &a.calibration else {
        return Ok(None);
    };
    let (jnd, budget) = crate::cli::calibration::Jnd::lodpop_budget(path, a.budget_jnd)?;
    let scene = SceneConfig::from_args(&a.scene_args)?;
    for &kind in scenes {
        let pv = scene.resolved(kind);
        jnd.check_viewport(pv.width, pv.height, "--width, --height")?;
    }
    Ok(Some((jnd, budget)))
}

/// Everything a run does, validated. Serialised into run.json as `config`.
#[derive(Debug, Clone, Serialize)]
pub struct RunConfig {
    pub scenes: Vec<SceneKind>,
    /// Every label `--method` names (all methods when absent); each scene runs [`RunConfig::methods_for`].
    pub methods: Vec<String>,
    /// `--method` was given: every scene runs exactly those (else each its defaults).
    pub methods_given: bool,
    pub scene: SceneConfig,
    /// Explicit --warmup; None = the profile's.
    pub warmup: Option<u32>,
    pub seed: u64,
    /// `--rounds`: timing rounds per block (at most one per frame).
    pub rounds: u32,
    /// `--baseline` as given (None: each scene's default, [`RunConfig::baseline_for`]).
    pub baseline: Option<String>,
    /// `--budget-lodpop`: the popping budget of the answer printed and in report.html (None: half of the hard
    /// switch's largest lodpop, `results::answer`).
    pub budget_lodpop: Option<f64>,
    /// `--calibration`: its lodpop JND (the budget is `--budget-jnd` of it, in `budget_lodpop`).
    pub calibration: Option<crate::cli::calibration::Jnd>,
    /// `--path-fps`, else the calibration's refresh rate, else 60: the frame rate of visible_pops_per_min.
    pub path_fps: f64,
    /// `--ceilings`: measure the adapter's ceilings before the blocks.
    pub ceilings: OnOff,
    /// `--clock-warmup`: warm the GPU's clock before each timed segment.
    pub clock_warmup: super::ClockWarmup,
    /// Every method's flags (recorded whether or not the method runs).
    #[serde(flatten)]
    pub method_options: MethodOptions,
    /// `--metrics` (rmse, pop, de2000 always; flip when listed).
    pub metrics: Vec<Metric>,
    pub metric_reduction: MetricReduction,
    /// `--metric-region`.
    pub metric_region: MetricRegion,
    pub out: Option<PathBuf>,
    /// `--adapter`: an index into `lodbench list`'s adapters or a part of a name (run.json's `adapter` records
    /// the one chosen, with its `index`).
    pub adapter: Option<String>,
    /// `--quality off`: the timing rounds only, no quality pass (its figures empty).
    pub quality: OnOff,
    /// `--quality-schedule`.
    pub quality_schedule: QualitySchedule,
    /// `--reference-cache-mib`.
    pub reference_cache_mib: u64,
    pub dump_frames: bool,
    pub dump_every: u32,
    /// With `dump_frames`: only frames with an instance in transition.
    pub dump_transitions: bool,
    /// The scenes' notes are not printed (`lodbench calibrate`'s stimulus runs, whose switches are placed on
    /// purpose where the dolly does not reach them). Not in run.json.
    #[serde(skip)]
    pub quiet: bool,
    pub msaa_samples: u32,
    pub color_format: String,
    pub depth_format: String,
    /// What each scene runs with once the profile and the defaults are applied (the flags above keep what was
    /// given: `null` for "the profile's"), so run.json records the values a run used, not only the flags, and
    /// `experiment --resume` and `merge` compare them. Filled by [`RunConfig::from_args_in`] from the fields
    /// above ([`RunConfig::resolve_scenes`]).
    pub resolved: Vec<ResolvedScene>,
}

/// One scene of a run with everything resolved: the profile's values with the flags applied, the instance
/// counts, the pixel error its switch distances are made for, the methods it runs and its baseline.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ResolvedScene {
    pub scene: SceneKind,
    pub width: u32,
    pub height: u32,
    pub frames: u32,
    pub warmup: u32,
    /// Where the bunny scenes' path starts (recorded for every scene; only the bunny scenes read it).
    pub sweep_start: SweepStart,
    pub pixel_error: f32,
    pub counts: Vec<u32>,
    pub methods: Vec<String>,
    pub baseline: Option<String>,
}

/// The scene flags that only some scenes take: `--animation` (a glTF scene among them), `--shadows on` (no
/// unified scene).
fn check_scene_flags(a: &RunArgs, scenes: &[SceneKind]) -> Result<()> {
    if let Some(anim) = &a.scene_args.animation {
        if !scenes.iter().any(|k| k.is_user()) {
            return Err(Error::Config(format!(
                "--animation {anim}: only glTF scenes (--scene FILE.glb) have animations, and none is among \
                 the scenes"
            )));
        }
    }
    if a.scene_args.shadow.shadows == OnOff::On && a.scene_args.impostor.impostor {
        return Err(Error::Config(
            "--shadows on with --impostor: an impostor's card faces the camera, not the light, so it casts no \
             shadow of its model; run one or the other"
                .into(),
        ));
    }
    if a.scene_args.shadow.shadows == OnOff::On {
        if let Some(scene) = scenes.iter().find(|k| k.is_unified()) {
            return Err(Error::Config(format!(
                "--shadows on: not built for the unified scenes yet (scene {}: its blocks and seams, and \
                 clusterlod's cut, have no shadow casters); run it without --shadows",
                scene.name()
            )));
        }
    }
    Ok(())
}

/// The named methods that need a kind of scene: a unified one, or the terrain's height field; and those that
/// cannot draw a transition into an impostor under `--impostor`.
fn check_methods_fit(a: &RunArgs, scenes: &[SceneKind], methods: &[String]) -> Result<()> {
    if a.scene_args.impostor.impostor {
        if let Some(m) = methods
            .iter()
            .find(|m| crate::methods::not_with_impostor(m))
        {
            return Err(Error::Config(format!(
                "method {m} cannot move into an impostor (it morphs the finer LOD's vertices onto the coarser \
                 LOD's surface, and an impostor's card has none): run it without --impostor, or run discrete, \
                 dither, alpha or alpha-2pass"
            )));
        }
    }
    if let Some(scene) = scenes.iter().find(|k| !k.is_unified()) {
        if let Some(m) = methods.iter().find(|m| crate::methods::needs_unified(m)) {
            return Err(Error::Config(format!(
                "method {m} needs a scene of one large mesh in blocks (bunny-halves, terrain); scene \
                 {} is not one: run it with --scene bunny-halves or --scene terrain",
                scene.name()
            )));
        }
    }
    let height_field = |k: &SceneKind| *k == SceneKind::Terrain && a.scene_args.mesh.is_none();
    if let Some(scene) = scenes.iter().find(|k| !height_field(k)) {
        if let Some(m) = methods
            .iter()
            .find(|m| crate::methods::needs_height_field(m))
        {
            return Err(Error::Config(format!(
                "method {m} needs the terrain's height field: run it on --scene terrain without --mesh \
                 (scene {}{} has none: a mesh is not a height field)",
                scene.name(),
                if a.scene_args.mesh.is_some() { " with --mesh" } else { "" }
            )));
        }
    }
    Ok(())
}

/// `--budget-lodpop` in (0, 1), the dump flags, and no flag that needs the quality pass with `--quality off`.
fn check_budget_and_outputs(a: &RunArgs) -> Result<()> {
    if let Some(b) = a.budget_lodpop {
        if !(b > 0.0 && b < 1.0) {
            return Err(Error::Config(format!(
                "--budget-lodpop {b}: a lodpop budget is a change in (0, 1) (the RMS over the frame of a \
                 switch's change, sRGB-encoded)"
            )));
        }
    }
    if a.dump_every == 0 {
        return Err(Error::Config("--dump-every must be at least 1".into()));
    }
    if a.dump_transitions && !a.dump_frames {
        return Err(Error::Config(
            "--dump-transitions selects which frames --dump-frames writes: add --dump-frames"
                .into(),
        ));
    }
    if a.clock_warmup == super::ClockWarmup::On && a.ceilings == OnOff::Off {
        return Err(Error::Config(
            "--clock-warmup on warms the GPU with the ceilings' triangle probe, and --ceilings off skips it: \
             drop one of the two"
                .into(),
        ));
    }
    if a.quality == OnOff::Off {
        let needs = if a.dump_frames {
            Some(("--dump-frames", "it writes the quality pass's frames"))
        } else if a.metrics.contains(&Metric::De2000) {
            Some(("--metrics de2000", "CIEDE2000 is measured in it"))
        } else if a.metrics.contains(&Metric::Flip) {
            Some(("--metrics flip", "FLIP is measured in it"))
        } else {
            None
        };
        if let Some((flag, why)) = needs {
            return Err(Error::Config(format!(
                "--quality off skips the quality pass, and {flag} needs it ({why}): drop one of the two"
            )));
        }
    }
    Ok(())
}

impl RunConfig {
    /// The flags checked against the built-in methods.
    pub fn from_args(a: &RunArgs) -> Result<RunConfig> {
        Self::from_args_in(a, &Registry::builtin())
    }

    /// The flags checked against `registry`'s methods.
    pub fn from_args_in(a: &RunArgs, registry: &Registry) -> Result<RunConfig> {
        let scenes = SceneKind::resolve(&a.scene)?;
        let methods = resolve_methods(&a.method, &registry.names())?;
        if a.rounds == 0 {
            return Err(Error::Config("--rounds must be at least 1".into()));
        }
        let methods_given = !a.method.is_empty();
        check_scene_flags(a, &scenes)?;
        if methods_given {
            check_methods_fit(a, &scenes, &methods)?;
        }
        let baseline = match &a.baseline {
            Some(b) if methods.iter().any(|m| m == b.trim()) => Some(b.trim().to_string()),
            Some(b) => {
                return Err(Error::Config(format!(
                    "--baseline {b} is not among the methods run ({})",
                    methods.join(", ")
                )))
            }
            None => None,
        };
        check_budget_and_outputs(a)?;
        let (calibration, budget_lodpop) = match calibration_of(a, &scenes)? {
            Some((jnd, budget)) => (Some(jnd), Some(budget)),
            None => (None, a.budget_lodpop),
        };
        let path_fps = a
            .path_fps
            .or(calibration.as_ref().map(|j| j.display.refresh_hz))
            .unwrap_or(60.0);
        if !(path_fps.is_finite() && path_fps > 0.0) {
            return Err(Error::Config(format!(
                "--path-fps {path_fps}: a frame rate above 0"
            )));
        }
        let mut cfg = RunConfig {
            scenes,
            methods,
            methods_given,
            scene: SceneConfig::from_args(&a.scene_args)?,
            warmup: a.warmup,
            seed: a.seed,
            rounds: a.rounds,
            baseline,
            budget_lodpop,
            calibration,
            path_fps,
            ceilings: a.ceilings,
            clock_warmup: a.clock_warmup,
            method_options: a.method_options,
            metrics: a.metrics.clone(),
            metric_reduction: a.metric_reduction,
            metric_region: a.metric_region,
            out: a.out.clone(),
            adapter: a.adapter.clone(),
            quality: a.quality,
            quality_schedule: a.quality_schedule,
            reference_cache_mib: a.reference_cache_mib,
            dump_frames: a.dump_frames,
            dump_every: a.dump_every,
            dump_transitions: a.dump_transitions,
            quiet: false,
            msaa_samples: MSAA_SAMPLES,
            color_format: format!("{COLOR_FORMAT:?}"),
            depth_format: format!("{DEPTH_FORMAT:?}"),
            resolved: Vec::new(),
        };
        cfg.resolved = cfg.resolve_scenes();
        Ok(cfg)
    }

    /// Each scene's resolved values (what [`RunConfig::resolved`] holds).
    pub fn resolve_scenes(&self) -> Vec<ResolvedScene> {
        self.scenes
            .iter()
            .map(|&kind| {
                let v = self.resolved(kind);
                let methods = self.methods_for(kind);
                ResolvedScene {
                    scene: kind,
                    width: v.width,
                    height: v.height,
                    frames: v.frames,
                    warmup: v.warmup,
                    sweep_start: v.sweep_start,
                    pixel_error: self.scene.pixel_error(kind, v.height),
                    counts: self.scene.counts(kind),
                    baseline: self.baseline_for(&methods),
                    methods,
                }
            })
            .collect()
    }

    /// The labels `scene` runs: `--method`'s, or by default every method that fits the scene (the unified
    /// scenes: the reference and the four unified methods; the others: every method but those).
    pub fn methods_for(&self, scene: SceneKind) -> Vec<String> {
        if self.methods_given {
            return self.methods.clone();
        }
        let builtin = crate::methods::names();
        let defaults = crate::methods::defaults_for(scene.is_unified());
        let impostor = self.scene.impostor.is_some();
        self.methods
            .iter()
            .filter(|m| {
                defaults.contains(&m.as_str())
                    || (!builtin.contains(&m.as_str()) && !scene.is_unified())
            })
            .filter(|m| !(impostor && crate::methods::not_with_impostor(m)))
            .cloned()
            .collect()
    }

    /// The label the times of `methods` are divided by: `--baseline` when it is among them, else `discrete`,
    /// else `blocks-discrete` (the unified scenes' hard switch), else none.
    pub fn baseline_for(&self, methods: &[String]) -> Option<String> {
        let has = |b: &str| methods.iter().any(|m| m == b);
        match &self.baseline {
            Some(b) => has(b).then(|| b.clone()),
            None => ["discrete", "blocks-discrete"]
                .into_iter()
                .find(|b| has(b))
                .map(String::from),
        }
    }

    /// Whether the quality pass runs (`--quality on`, the default).
    pub fn quality_pass(&self) -> bool {
        self.quality == OnOff::On
    }

    pub fn resolved(&self, scene: SceneKind) -> ProfileValues {
        let mut v = self.scene.resolved(scene);
        if let Some(w) = self.warmup {
            v.warmup = w;
        }
        v
    }
}

/// The methods' labels: checked against the registry in the user's order; a name given again runs again as
/// `NAME#2`, `NAME#3`, ... (an A/A comparison); empty = every method once.
pub fn resolve_methods(given: &[String], valid: &[&str]) -> Result<Vec<String>> {
    if given.is_empty() {
        return Ok(valid.iter().map(|s| s.to_string()).collect());
    }
    let mut out: Vec<String> = Vec::new();
    for name in given {
        let name = name.trim();
        let base = crate::methods::base_name(name);
        if !valid.contains(&base) {
            return Err(Error::unknown("method", name, valid));
        }
        let mut label = name.to_string();
        let mut k = 2;
        while out.contains(&label) {
            label = format!("{base}#{k}");
            k += 1;
        }
        out.push(label);
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
    fn a_repeated_method_runs_again_under_its_own_label() {
        let c = RunConfig::from_args(&run_args(&["--method", "discrete,alpha,discrete,discrete"]))
            .unwrap();
        assert_eq!(c.methods, ["discrete", "alpha", "discrete#2", "discrete#3"]);
        assert_eq!(c.baseline_for(&c.methods).as_deref(), Some("discrete"));
        let c = RunConfig::from_args(&run_args(&["--method", "alpha,fsi"])).unwrap();
        assert_eq!(
            c.baseline_for(&c.methods),
            None,
            "no discrete, no default baseline"
        );
        let c = RunConfig::from_args(&run_args(&[
            "--method",
            "alpha,alpha",
            "--baseline",
            "alpha#2",
        ]))
        .unwrap();
        assert_eq!(c.baseline_for(&c.methods).as_deref(), Some("alpha#2"));
        let e = RunConfig::from_args(&run_args(&["--method", "alpha", "--baseline", "discrete"]))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("--baseline discrete") && e.contains("alpha"),
            "{e}"
        );
        let e = RunConfig::from_args(&run_args(&["--method", "alpha#x"]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("alpha#x"), "{e}");
        assert!(RunConfig::from_args(&run_args(&["--rounds", "0"])).is_err());
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
        assert_eq!(c.scenes, SceneKind::ALL);
        assert_eq!(c.methods, crate::methods::names());
        // Each scene runs the methods that fit it, with its own default baseline.
        let terrain = c.methods_for(SceneKind::Terrain);
        assert_eq!(terrain, crate::methods::UNIFIED_DEFAULT);
        assert_eq!(c.baseline_for(&terrain).as_deref(), Some("blocks-discrete"));
        let sweep = c.methods_for(SceneKind::BunnySweep);
        assert!(sweep.contains(&"fsi".to_string()) && !sweep.iter().any(|m| m == "blocks"));
        assert_eq!(c.baseline_for(&sweep).as_deref(), Some("discrete"));
        // Named methods run as named on every scene they fit.
        let c = RunConfig::from_args(&run_args(&["--scene", "terrain", "--method", "fsi,blocks"]))
            .unwrap();
        assert_eq!(c.methods_for(SceneKind::Terrain), ["fsi", "blocks"]);
    }

    #[test]
    fn flags_override_profile() {
        let c = RunConfig::from_args(&run_args(&["--profile", "paper", "--frames", "7"])).unwrap();
        let v = c.resolved(SceneKind::BunnySweep);
        assert_eq!((v.width, v.height, v.frames), (800, 600, 7));
        assert_eq!(
            c.scene.counts(SceneKind::BunnyGrid),
            crate::scene::PAPER_COUNTS.to_vec()
        );
    }

    #[test]
    fn the_resolved_values_are_recorded() {
        let c = RunConfig::from_args(&run_args(&[
            "--scene",
            "bunny-sweep,bunny-grid",
            "--profile",
            "regress",
            "--frames",
            "7",
            "--method",
            "discrete,alpha",
        ]))
        .unwrap();
        assert_eq!(c.resolved, c.resolve_scenes());
        let r = &c.resolved[1];
        assert_eq!(r.scene, SceneKind::BunnyGrid);
        assert_eq!((r.width, r.height, r.frames, r.warmup), (96, 72, 7, 2));
        assert_eq!(r.sweep_start, SweepStart::CloseUp);
        assert_eq!(r.counts, [50]);
        assert_eq!(r.baseline.as_deref(), Some("discrete"));
        // run.json records the flag as given and the value it resolved to.
        let j = serde_json::to_value(&c).unwrap();
        assert_eq!(j["scene"]["sweep_start"], serde_json::Value::Null);
        assert_eq!(j["resolved"][0]["sweep_start"], "close-up");
        assert_eq!(j["resolved"][0]["scene"], "bunny-sweep");
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
