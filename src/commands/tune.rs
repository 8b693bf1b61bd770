//! `lodbench tune --scene FILE|NAME --budget-lodpop X | --budget-jod J`: each model's LOD switch distances chosen
//! from a popping budget by measurement (`measure/switch_tuning.rs`), written as tune.csv (every curve), tune.json (the
//! settings, views and switches), engines/ (the switches in Unity's, Unreal's, Godot's, Bevy's and three.js's
//! units, `results/engines.rs`) and tuned.glb (the scene with its chains and the chosen switches, MSFT_lod with
//! MSFT_screencoverage and lodbench's exact distances, no camera: `lodbench run --scene tuned.glb` flies its
//! default flight out through the chosen switches and measures what was chosen).

use crate::cli::calibration::Jnd;
use crate::cli::TuneArgs;
use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::measure::engine_rules::RULES;
use crate::measure::switch_tuning::{
    tune_model, view_directions, Budget, ModelCamera, ModelSwitches, Sample, TuneSettings,
};
use crate::results::csv::write_whole;
use crate::results::engines::{self, EngineModel};
use crate::results::files::{
    EngineFile, ENGINES_DIR, ENGINES_README, RULES_CSV, TUNED_GLB, TUNE_CSV, TUNE_JSON,
};
use crate::results::manifest::BuildVersion;
use crate::scene::{Scene, SceneConfig, SceneDef, SceneKind};
use glam::{Quat, Vec3};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// What tune.json holds.
#[derive(Serialize)]
struct TuneManifest<'a> {
    /// The build: lodbench_version, git_commit, source_diff_hash.
    #[serde(flatten)]
    build: BuildVersion,
    scene: String,
    adapter: crate::gpu::AdapterSummary,
    width: u32,
    height: u32,
    fov_y_deg: f32,
    settings: &'a TuneSettings,
    /// The view directions (unit vectors from the model's centre towards the camera), in order.
    views: Vec<[f32; 3]>,
    models: &'a [ModelSwitches],
    engines: Vec<EngineModel>,
    /// `--calibration`: the JND the budget is counted in, and the budget in JNDs.
    calibration: Option<&'a Jnd>,
    budget_jnd: Option<f64>,
    /// What the budget holds for: [`BUDGET_SCOPE`].
    budget_scope: &'static str,
}

/// tune's budget holds per model drawn alone, not per frame: said in tune.json and printed.
const BUDGET_SCOPE: &str = "each switch of each model drawn alone: instances that switch on the same frame add \
     up (lodpop over the frame grows with their number), so a frame along a path can exceed the budget; \
     `lodbench run --scene tuned.glb` counts the pops along a path (summary.csv's visible_pops_per_min)";

/// `--calibration`'s lodpop JND, checked against tune's viewport; tune draws at the display's size unless
/// --width/--height say otherwise (then refused).
fn calibration_of(args: &TuneArgs, cfg: &mut SceneConfig) -> Result<Option<(Jnd, f64)>> {
    let Some(path) = &args.calibration else {
        return Ok(None);
    };
    let (jnd, budget) = Jnd::lodpop_budget(path, args.budget_jnd)?;
    let (w, h) = (jnd.display.width_px, jnd.display.height_px);
    jnd.check_viewport(
        cfg.width.unwrap_or(w),
        cfg.height.unwrap_or(h),
        "leave --width and --height out",
    )?;
    (cfg.width, cfg.height) = (Some(w), Some(h));
    Ok(Some((jnd, budget)))
}

/// The budget: a calibration's (`calibrated`, in lodpop), else --budget-lodpop or --budget-jod.
fn budget_of(args: &TuneArgs, calibrated: Option<f64>) -> Result<Budget> {
    if let Some(b) = calibrated {
        return Ok(Budget::Lodpop(b));
    }
    match (args.budget_lodpop, args.budget_jod) {
        (Some(x), None) if x.is_finite() && x > 0.0 && x < 1.0 => Ok(Budget::Lodpop(x)),
        (Some(x), None) => Err(Error::Config(format!(
            "--budget-lodpop {x}: a lodpop budget is a change in (0, 1)"
        ))),
        (None, Some(j)) if j.is_finite() && j > 0.0 && j <= 10.0 => Ok(Budget::Jod(j)),
        (None, Some(j)) => Err(Error::Config(format!(
            "--budget-jod {j}: a JOD budget lies in (0, 10] (10: no visible difference)"
        ))),
        _ => Err(Error::Config(
            "tune needs a budget: --calibration FILE --budget-jnd K (JNDs of a calibration), --budget-lodpop X (the largest lodpop a switch may cause, RMS over the frame in \
             [0, 1]) or --budget-jod J (ColorVideoVDP's JOD a switch may not go below, 10 = invisible)"
                .into(),
        )),
    }
}

fn settings_of(args: &TuneArgs, band: f32, calibrated: Option<f64>) -> Result<TuneSettings> {
    if args.views == 0 || args.distances < 2 {
        return Err(Error::Config(format!(
            "tune: --views {} and --distances {}: at least one view and two distances",
            args.views, args.distances
        )));
    }
    let speed = match args.speed {
        Some(s) if s.is_finite() && s > 0.0 && args.fps.is_finite() && args.fps > 0.0 => {
            Some((s, args.fps))
        }
        Some(s) => {
            return Err(Error::Config(format!(
                "--speed {s} --fps {}: both must be positive",
                args.fps
            )))
        }
        None => None,
    };
    Ok(TuneSettings {
        budget: budget_of(args, calibrated)?,
        views: args.views,
        distances: args.distances,
        seed: args.seed,
        speed,
        band,
        full_grid: args.full_grid,
    })
}

/// The chosen switches of `m` as the engines take them: the LODs up to the first switch no distance allows; the
/// hard switches, or `blend`'s switches and bands (with `--speed`).
fn engine_model(m: &ModelSwitches, blend: Option<&str>) -> EngineModel {
    let usable: Vec<&crate::measure::switch_tuning::PairSwitch> = m
        .pairs
        .iter()
        .take_while(|p| p.switch_distance.is_some())
        .collect();
    let of = |p: &crate::measure::switch_tuning::PairSwitch| -> (f32, f32) {
        match blend.and_then(|b| p.bands.iter().find(|x| x.method == b)) {
            Some(x) => (x.switch_distance, x.band),
            None => (p.switch_distance.unwrap_or(0.0), 0.0),
        }
    };
    EngineModel {
        name: m.name.clone(),
        radius: m.radius,
        center: m.center,
        switches: usable.iter().map(|p| of(p).0).collect(),
        bands: usable.iter().map(|p| of(p).1).collect(),
        triangles: m
            .pairs
            .first()
            .map(|p| p.triangles_from as u32)
            .into_iter()
            .chain(usable.iter().map(|p| p.triangles_to as u32))
            .collect(),
    }
}

/// `lodbench tune`.
pub fn execute(args: &TuneArgs) -> Result<()> {
    let kind = SceneKind::from_name(&args.scene)?;
    let mut cfg = SceneConfig::from_args(&args.scene_args)?;
    let calibrated = calibration_of(args, &mut cfg)?;
    let settings = settings_of(args, cfg.schedule.band, calibrated.as_ref().map(|c| c.1))?;
    let jnd = calibrated.map(|c| c.0);
    let def = SceneDef::new(kind, &cfg)?;
    if kind.is_unified() {
        return Err(Error::Config(format!(
            "tune: {} is a unified scene; its blocks are one mesh, not models with switch distances",
            def.name()
        )));
    }
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| super::run::default_out_dir(&[&format!("tune-{}", def.name())]));
    super::run::prepare_output(&out)?;
    let mut scene = def.instantiate(def.counts[0]);
    // Each model alone, its first instance's rotation, at rest.
    scene.motion = crate::scene::Motion::Static;
    let ctx = GpuContext::new(args.adapter.as_deref())?;
    let views = view_directions(settings.views, settings.seed);
    let mut jod = jod_of(args, &settings, scene.width, scene.height)?;
    let (models, samples) = tune_models(&ctx, &scene, &settings, &views, &mut jod)?;
    write_samples(&out, &samples)?;
    let viewing = Viewing {
        width: scene.width,
        height: scene.height,
        fov_y: scene.fov_y,
        budget: settings.budget,
    };
    let engine_models = write_engine_tables(&out, &models, &settings, &viewing)?;
    let tuned = tuned_scene(&scene, &models);
    let glb = crate::scene::export_glb::glb_with(&tuned, false)?;
    write(&out.join(TUNED_GLB), &glb)?;
    let manifest = TuneManifest {
        build: BuildVersion::this(),
        scene: def.name().to_string(),
        adapter: ctx.info.clone(),
        width: scene.width,
        height: scene.height,
        fov_y_deg: scene.fov_y.to_degrees(),
        settings: &settings,
        views: views.iter().map(|v| v.to_array()).collect(),
        models: &models,
        engines: engine_models.clone(),
        calibration: jnd.as_ref(),
        budget_jnd: jnd.as_ref().map(|_| args.budget_jnd.unwrap_or(1.0)),
        budget_scope: BUDGET_SCOPE,
    };
    write(
        &out.join(TUNE_JSON),
        serde_json::to_string_pretty(&manifest)?.as_bytes(),
    )?;
    write_rules(&out, &models)?;
    print_results(&out, &models, &engine_models, &viewing);
    print_impostor(&scene, &models);
    if let Some(j) = &jnd {
        outln!(
            "budget: {} JND, {}",
            args.budget_jnd.unwrap_or(1.0),
            j.describe()
        );
        outln!(
            "every method with these switches, pops in JNDs: lodbench run --scene {} --width {} --height {} \
             --calibration {}",
            out.join(TUNED_GLB).display(),
            j.display.width_px,
            j.display.height_px,
            j.path.display()
        );
    }
    outln!("the budget holds for {BUDGET_SCOPE}");
    Ok(())
}

/// Tunes every model of `scene` with at least two LODs and an instance (drawn alone, at its first instance's
/// rotation): the models' switches, and every sample measured.
fn tune_models(
    ctx: &GpuContext,
    scene: &Scene,
    settings: &TuneSettings,
    views: &[Vec3],
    jod: &mut PairScore,
) -> Result<(Vec<ModelSwitches>, Vec<Sample>)> {
    let mut camera = ModelCamera::new(ctx, scene)?;
    let mut samples: Vec<Sample> = Vec::new();
    let mut models = Vec::new();
    for (m, model) in scene.models.iter().enumerate() {
        if model.chain.lods.len() < 2 {
            continue;
        }
        let Some(inst) = scene.instances.iter().find(|i| i.model as usize == m) else {
            continue;
        };
        let rotation = Quat::from_rotation_y(inst.yaw) * inst.rotation;
        models.push(tune_model(
            &mut camera,
            m as u32,
            rotation,
            settings,
            views,
            jod,
            &mut samples,
        )?);
    }
    Ok((models, samples))
}

/// Writes the engines' settings for the tuned switches, and with `--speed` the cross-fading engines'; returns
/// the hard-switch engines' models (tune.json's `engines`).
fn write_engine_tables(
    out: &Path,
    models: &[ModelSwitches],
    settings: &TuneSettings,
    viewing: &Viewing,
) -> Result<Vec<EngineModel>> {
    let fov_y = viewing.fov_y;
    let engine_models: Vec<EngineModel> = models.iter().map(|m| engine_model(m, None)).collect();
    write_engines(out, &engine_models, viewing)?;
    if settings.speed.is_some() {
        // The engines that cross-fade: Unity and Bevy dither (LOD cross-fade shaders, Bevy's visibility-range
        // fade), Godot blends (its fade modes change the node's transparency).
        let with = |b: &str| -> Vec<EngineModel> {
            models.iter().map(|m| engine_model(m, Some(b))).collect()
        };
        write_fading(out, &with("dither"), &with("alpha"), fov_y)?;
    }
    Ok(engine_models)
}

/// What the switches were chosen for: the viewport, the vertical field of view and the budget.
struct Viewing {
    width: u32,
    height: u32,
    fov_y: f32,
    budget: Budget,
}

impl Viewing {
    /// The budget as the tables name their figure.
    fn figure(&self) -> &'static str {
        match self.budget {
            Budget::Lodpop(_) => "lodpop",
            Budget::Jod(_) => "JOD",
        }
    }

    /// What every engine file's distances hold for, in sentences: the budget, the viewport and field of view,
    /// and the chain of each model (its triangles per level).
    fn about(&self, models: &[EngineModel]) -> Vec<String> {
        let budget = match self.budget {
            Budget::Lodpop(x) => format!("a largest lodpop of {x}"),
            Budget::Jod(j) => format!("ColorVideoVDP's JOD of at least {j}"),
        };
        let mut out = vec![
            format!(
                "These switches keep each switch within {budget} at {}x{} pixels with a {} degree vertical field \
                 of view; at another viewport or field of view the same switch pops differently: tune there.",
                self.width,
                self.height,
                crate::numbers::sig3(Some(self.fov_y.to_degrees() as f64)),
            ),
            "They hold for the LOD chain lodbench drew: a glTF file's authored chain (MSFT_lod), else the one \
             lodbench generated with meshoptimizer, which tuned.glb holds. Use those levels, or a chain with these \
             triangle counts:"
                .to_string(),
        ];
        for m in models {
            let tris: Vec<String> = m
                .triangles
                .iter()
                .map(|&t| crate::numbers::thousands(Some(t as f64)))
                .collect();
            out.push(format!("  {}: {} triangles", m.name, tris.join(" -> ")));
        }
        out
    }
}

/// Prints the switches' and the rules' tables with what their columns mean, what the switches hold for, where
/// the results and the engine files are, and the commands that use them.
fn print_results(out: &Path, models: &[ModelSwitches], engines: &[EngineModel], viewing: &Viewing) {
    let figure = viewing.figure();
    out!("{}", table(models, viewing.budget));
    out!("{}", rules_table(models, figure));
    outln!(
        "switch (d): the distance from the model's bounding-sphere centre (world units) beyond which the next LOD \
         is drawn; screen size: that sphere's projected diameter over the viewport's height there; worst {figure}: \
         the largest over the views of the change the switch makes to the frame; error px: the coarser LOD's \
         simplification error projected there. Second table: where tune and each engine's own rule (Unreal's auto \
         screen size, Godot's 1 pixel, meshoptimizer's error) would switch, as (distance, worst {figure}); * = \
         over the budget."
    );
    for line in viewing.about(engines) {
        outln!("{line}");
    }
    outln!("results in {}", out.display());
    outln!(
        "engine settings in {}: Unity, Unreal, Godot, Bevy and three.js; how to enter each: {} (also \
         docs/engines.md)",
        out.join(ENGINES_DIR).display(),
        out.join(ENGINES_DIR).join(ENGINES_README).display()
    );
    outln!(
        "figures: python3 scripts/plot.py {}; the rules along a path: python3 scripts/tune_rules.py {}",
        out.display(),
        out.display()
    );
    if let Budget::Lodpop(x) = viewing.budget {
        outln!(
            "every method with these switches, answered within the budget: lodbench run --scene {} \
             --budget-lodpop {x}",
            out.join(TUNED_GLB).display()
        );
    }
}

/// Scores two frames (RGBA8).
type PairScore = Box<dyn FnMut(&[u8], &[u8]) -> Result<f64>>;

/// ColorVideoVDP's JOD of two frames when the budget is a JOD (else a function never called).
fn jod_of(args: &TuneArgs, settings: &TuneSettings, width: u32, height: u32) -> Result<PairScore> {
    if !matches!(settings.budget, Budget::Jod(_)) {
        return Ok(Box::new(|_: &[u8], _: &[u8]| Ok(0.0)));
    }
    let metric = super::perceptual::metric_on(&args.display)?;
    Ok(Box::new(move |a: &[u8], b: &[u8]| {
        super::perceptual::jod_of_images(&metric, a, b, width, height)
    }))
}

/// The scene with each tuned model's chain cut after its last usable LOD and its switches the chosen ones (what
/// tuned.glb holds).
/// `--impostor`: the impostor tune assumed as every chain's last level, and where each model switches to it
/// (tuned.glb leaves it out: `run --scene tuned.glb --impostor --impostor-distance D` draws it).
fn print_impostor(scene: &crate::scene::Scene, models: &[ModelSwitches]) {
    let Some(imp) = &scene.impostor else {
        return;
    };
    outln!(
        "the last level of every chain is an impostor, as assumed (tuned.glb has the mesh levels only): {}",
        imp.describe()
    );
    for m in models {
        let last = scene.models[m.model as usize].chain.lods.len() as u32 - 1;
        let at = m.pairs.iter().find(|p| p.lod_to == last);
        match at.and_then(|p| p.switch_distance) {
            Some(d) => outln!(
                "  {}: the impostor from {d:.4} (lodbench run --scene tuned.glb --impostor --impostor-distance {d:.4})",
                m.name
            ),
            None => outln!("  {}: no distance measured keeps the impostor within the budget", m.name),
        }
    }
}

fn tuned_scene(scene: &crate::scene::Scene, models: &[ModelSwitches]) -> crate::scene::Scene {
    let mut out = scene.clone();
    let mut list: Vec<crate::scene::Model> = out.models.to_vec();
    for t in models {
        let m = &mut list[t.model as usize];
        let switches: Vec<f32> = t.pairs.iter().map_while(|p| p.switch_distance).collect();
        m.chain.lods.truncate(switches.len() + 1);
        // tuned.glb holds meshes: an impostor's card is no mesh a glTF file can carry (tune.json, rules.csv and
        // engines/ keep its switch).
        if crate::geometry::impostor::ends_in_card(&m.chain) {
            m.chain.lods.pop();
        }
        let mut switches = switches;
        switches.truncate(m.chain.lods.len() - 1);
        m.switches = switches;
        m.switch_source = crate::scene::model::SwitchSource::Tune;
    }
    out.models = list.into();
    out
}

fn write(path: &Path, bytes: &[u8]) -> Result<()> {
    std::fs::write(path, bytes).map_err(|e| Error::Output {
        path: path.to_path_buf(),
        problem: format!("cannot be written ({e})"),
    })
}

fn write_samples(out: &Path, samples: &[Sample]) -> Result<()> {
    write_whole(out, TUNE_CSV, samples).map(|_| ())
}

/// One row of rules.csv.
#[derive(Serialize)]
struct RuleRow<'a> {
    model: &'a str,
    lod_from: u32,
    lod_to: u32,
    rule: &'static str,
    distance: f32,
    screen_size: f32,
    value: Option<f64>,
    within_budget: bool,
}

/// rules.csv: per model, pair and rule (tune's own first, then the engines'), the switch distance, its screen
/// size and the budget's figure there, the worst over the views.
fn write_rules(out: &Path, models: &[ModelSwitches]) -> Result<()> {
    let mut rows = Vec::new();
    for m in models {
        for p in &m.pairs {
            let tuned = p
                .switch_distance
                .zip(p.screen_size)
                .map(|(d, s)| ("tune", d, s, p.checked_worst.or(p.value_at_switch), true));
            let rules = p
                .rules
                .iter()
                .map(|r| (r.rule.name(), r.distance, r.screen_size, r.value, r.within));
            for (rule, distance, screen_size, value, within_budget) in
                tuned.into_iter().chain(rules)
            {
                rows.push(RuleRow {
                    model: &m.name,
                    lod_from: p.lod_from,
                    lod_to: p.lod_to,
                    rule,
                    distance,
                    screen_size,
                    value,
                    within_budget,
                });
            }
        }
    }
    write_whole(out, RULES_CSV, &rows).map(|_| ())
}

/// Unity's, Unreal's, Godot's and Bevy's settings of `models`, as their files hold them (JSON).
fn engine_json(models: &[EngineModel], fov_y: f32) -> [String; 4] {
    use erased::Json;
    let unity: Vec<_> = models.iter().map(|m| engines::unity(m, fov_y)).collect();
    let unreal: Vec<_> = models.iter().map(|m| engines::unreal(m, fov_y)).collect();
    let godot: Vec<_> = models
        .iter()
        .map(|m| (m.name.clone(), engines::godot(m)))
        .collect();
    let bevy: Vec<_> = models
        .iter()
        .map(|m| (m.name.clone(), engines::bevy(m)))
        .collect();
    [unity.text(), unreal.text(), godot.text(), bevy.text()]
}

/// The cross-fading engines' files with blending methods' bands: `dithered` for Unity and Bevy, `blended` for
/// Godot.
fn write_fading(
    out: &Path,
    dithered: &[EngineModel],
    blended: &[EngineModel],
    fov_y: f32,
) -> Result<()> {
    let dir = out.join(ENGINES_DIR);
    let [unity, _, _, bevy] = engine_json(dithered, fov_y);
    let [_, _, godot, _] = engine_json(blended, fov_y);
    for (file, text) in [
        (EngineFile::UnityLodGroupCrossfade, unity),
        (EngineFile::BevyVisibilityRangesFade, bevy),
        (EngineFile::GodotVisibilityRangesFade, godot),
    ] {
        write(&dir.join(file.name()), text.as_bytes())?;
    }
    Ok(())
}

/// The engine folder's README's text (docs/engines.md), after what the switches hold for.
const ENGINES_README_TEXT: &str = include_str!("../../docs/engines.md");

fn write_engines(out: &Path, models: &[EngineModel], viewing: &Viewing) -> Result<()> {
    let fov_y = viewing.fov_y;
    let dir: PathBuf = out.join(ENGINES_DIR);
    std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
    let files = [
        EngineFile::UnityLodGroup,
        EngineFile::UnrealScreenSizes,
        EngineFile::GodotVisibilityRanges,
        EngineFile::BevyVisibilityRanges,
    ];
    for (file, text) in files.into_iter().zip(engine_json(models, fov_y)) {
        write(&dir.join(file.name()), text.as_bytes())?;
    }
    let about = viewing.about(models);
    let mut header = vec![
        "lodbench tune: switch distances for three.js (THREE.LOD), from each model's bounding-sphere centre."
            .to_string(),
    ];
    header.extend(about.iter().cloned());
    header.push(
        "Usage: const lod = lodbenchLod(THREE, \"NAME\", [level0, level1, ...]); scene.add(lod);"
            .to_string(),
    );
    write(
        &dir.join(EngineFile::ThreejsLod.name()),
        engines::threejs(models, &header).as_bytes(),
    )?;
    let readme = format!(
        "{}\n\n{}",
        about.join("\n\n"),
        outside_links(ENGINES_README_TEXT)
    );
    write(&dir.join(ENGINES_README), readme.as_bytes())
}

/// `text` with each relative Markdown link `[label](page.md#anchor)` written as `label (lodbench's
/// docs/page.md#anchor)`: the page is copied into a tune folder, where a link relative to docs/ names nothing.
fn outside_links(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(open) = rest.find('[') {
        let after = &rest[open..];
        let link = after.find("](").and_then(|mid| {
            let close = after[mid..].find(')')? + mid;
            let (label, target) = (&after[1..mid], &after[mid + 2..close]);
            let relative = !target.contains(':') && !label.contains('[') && !label.contains('\n');
            relative.then_some((close, label, target))
        });
        match link {
            Some((close, label, target)) => {
                out.push_str(&rest[..open]);
                out.push_str(&format!("{label} (lodbench's docs/{target})"));
                rest = &rest[open + close + 1..];
            }
            None => {
                out.push_str(&rest[..open + 1]);
                rest = &rest[open + 1..];
            }
        }
    }
    out.push_str(rest);
    out
}

/// Serialising what `write_engines` writes, whatever its type.
mod erased {
    pub trait Json {
        fn text(&self) -> String;
    }
    impl<T: serde::Serialize> Json for T {
        fn text(&self) -> String {
            serde_json::to_string_pretty(self).unwrap_or_default()
        }
    }
}

/// The table printed at the end: per model and pair, the triangles, the switch distance and screen size, the
/// budget's figure there and the pixel error the LOD's simplifier error projects to at the switch.
pub fn table(models: &[ModelSwitches], budget: Budget) -> String {
    let what = match budget {
        Budget::Lodpop(x) => format!("worst lodpop from switch (budget {x})"),
        Budget::Jod(j) => format!("worst JOD from switch (budget {j})"),
    };
    let name_w = models
        .iter()
        .map(|m| m.name.len())
        .max()
        .unwrap_or(5)
        .max(5);
    let mut out = format!(
        "{:<name_w$}  {:>5}  {:>21}  {:>11}  {:>11}  {:>w2$}  {:>12}\n",
        "model",
        "LODs",
        "triangles",
        "switch (d)",
        "screen size",
        what,
        "error px",
        w2 = what.len()
    );
    for m in models {
        for p in &m.pairs {
            let fig = |v: Option<f64>| v.map_or("-".into(), |x| format!("{x:.5}"));
            out.push_str(&format!(
                "{:<name_w$}  {:>5}  {:>21}  {:>11}  {:>11}  {:>w2$}  {:>12}\n",
                m.name,
                format!("{}->{}", p.lod_from, p.lod_to),
                format!("{} -> {}", p.triangles_from, p.triangles_to),
                p.switch_distance
                    .map_or("never".into(), |d| format!("{d:.4}")),
                p.screen_size.map_or("-".into(), |s| format!("{s:.4}")),
                fig(p.checked_worst.or(p.value_at_switch)),
                p.error_px_at_switch
                    .map_or("-".into(), |e| format!("{e:.3}")),
                w2 = what.len()
            ));
        }
    }
    out
}

/// The second table printed: per model and pair, where tune and each engine's rule switch, and the budget's figure
/// there (`*`: breaks the budget).
pub fn rules_table(models: &[ModelSwitches], figure: &str) -> String {
    let name_w = models
        .iter()
        .map(|m| m.name.len())
        .max()
        .unwrap_or(5)
        .max(5);
    let mut out = format!("{:<name_w$}  {:>5}", "model", "LODs");
    for rule in std::iter::once("tune").chain(RULES.iter().map(|r| r.name())) {
        out.push_str(&format!("  {:>20}", format!("{rule} (d, {figure})")));
    }
    out.push('\n');
    let fig = |d: Option<f32>, v: Option<f64>, within: bool| match (d, v) {
        (Some(d), Some(v)) => format!("{d:.3}, {v:.5}{}", if within { " " } else { "*" }),
        (Some(d), None) => format!("{d:.3}, -"),
        _ => "never".into(),
    };
    for m in models {
        for p in &m.pairs {
            out.push_str(&format!(
                "{:<name_w$}  {:>5}  {:>20}",
                m.name,
                format!("{}->{}", p.lod_from, p.lod_to),
                fig(
                    p.switch_distance,
                    p.checked_worst.or(p.value_at_switch),
                    true
                )
            ));
            for r in &p.rules {
                out.push_str(&format!(
                    "  {:>20}",
                    fig(Some(r.distance), r.value, r.within)
                ));
            }
            out.push('\n');
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The engines' README copied into a tune folder keeps no link relative to docs/ (it would name nothing
    /// there), and leaves absolute links and brackets that are no links alone.
    #[test]
    fn the_copied_readme_names_its_links_outside_the_folder() {
        let text = outside_links(ENGINES_README_TEXT);
        assert!(!text.contains("](methods.md"), "{text}");
        assert!(text.contains("(lodbench's docs/methods.md#choosing-thresholds-lodbench-tune)"));
        assert_eq!(
            outside_links("a [x](y.md#z) b [c] d [e](https://f) g"),
            "a x (lodbench's docs/y.md#z) b [c] d [e](https://f) g"
        );
    }
}
