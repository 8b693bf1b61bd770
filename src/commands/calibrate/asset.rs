//! What a calibration draws of a scene: its first model with two LODs or more, alone at rest, as a glTF file the
//! stimulus runs read (a built-in scene is exported first, its motion stopped), and where the camera looks at it
//! from.

use crate::cli::Cli;
use crate::cli::Command;
use crate::error::{Error, Result};
use crate::scene::{SceneConfig, SceneDef, SceneKind};
use glam::Vec3;
use std::path::{Path, PathBuf};

/// A scene's model as the stimuli show it.
#[derive(Debug, Clone)]
pub struct Asset {
    /// The scene's name (`bunny-sweep`; a file's name without its folder, as the CSVs name it).
    pub name: String,
    /// The glTF file the runs draw.
    pub file: PathBuf,
    /// The model's bounding-sphere centre (world).
    pub centre: Vec3,
    /// Unit vector from the centre towards the scene's own camera: the dolly's line.
    pub direction: Vec3,
    /// Per LOD, the object-space error (at the instance's scale) of the chain's simplification; LOD0's is 0.
    pub errors: Vec<f32>,
}

/// The scene flags of a run of `file`, parsed as `lodbench run` parses them.
pub fn scene_config(scene: &str, extra: &[&str]) -> Result<SceneConfig> {
    let mut argv = vec!["lodbench", "run", "--scene", scene];
    argv.extend_from_slice(extra);
    match Cli::try_parse_checked_from(argv) {
        Ok(Cli {
            command: Command::Run(args),
        }) => SceneConfig::from_args(&args.scene_args),
        Ok(_) => Err(Error::Config(
            "calibrate: a run's flags parsed as another command".into(),
        )),
        Err(e) => Err(Error::Config(format!("calibrate: {}", e.kind()))),
    }
}

/// The asset of scene `name` (built-in or a glTF file); a built-in scene is written to `work` as a .glb.
pub fn asset_of(name: &str, work: &Path) -> Result<Asset> {
    let kind = SceneKind::from_name(name)?;
    if kind.is_unified() {
        return Err(Error::Config(format!(
            "calibrate: {name} is a unified scene; its blocks are one mesh, not a model with LODs to switch"
        )));
    }
    let short = match kind.is_user() {
        true => kind.name().to_string(),
        false => name.to_string(),
    };
    let file = if kind.is_user() {
        PathBuf::from(name)
    } else {
        let def = SceneDef::new(kind, &scene_config(name, &[])?)?;
        let mut scene = def.instantiate(def.counts[0]);
        scene.motion = crate::scene::Motion::Static;
        // The model alone: the first instance of a model with LODs, no ground.
        let lods =
            |i: &crate::scene::Instance| scene.models[i.model as usize].chain.lods.len() >= 2;
        scene.instances = scene
            .instances
            .iter()
            .filter(|i| lods(i))
            .take(1)
            .cloned()
            .collect();
        scene.ground = None;
        let glb = crate::scene::export_glb::glb_with(&scene, false)?;
        let path = work.join(format!("{}.glb", def.name()));
        std::fs::write(&path, glb).map_err(|e| Error::io(&path, e))?;
        path
    };
    let file_name = file.to_string_lossy().to_string();
    let def = SceneDef::new(
        SceneKind::from_name(&file_name)?,
        &scene_config(&file_name, &[])?,
    )?;
    let scene = def.instantiate(def.counts[0]);
    let placed = scene.instances.len() - usize::from(scene.ground.is_some());
    if placed > 1 {
        return Err(Error::Config(format!(
            "calibrate: {name} places {placed} instances; the stimuli show one model alone: give a file of one \
             node (one mesh instance)"
        )));
    }
    let (i, model) = scene
        .instances
        .iter()
        .enumerate()
        .map(|(i, inst)| (i, &scene.models[inst.model as usize]))
        .find(|(_, m)| m.chain.lods.len() >= 2)
        .ok_or_else(|| {
            Error::Config(format!(
                "calibrate: {name} has no model with two LODs or more to switch"
            ))
        })?;
    let centre = scene.instance_position(i, 0);
    let eye = scene.camera(0).eye;
    let direction = (eye - centre).try_normalize().unwrap_or(Vec3::Z);
    Ok(Asset {
        name: short,
        file,
        centre,
        direction,
        errors: model
            .chain
            .lods
            .iter()
            .map(|l| l.error_abs * model.scale)
            .collect(),
    })
}
