//! `lodbench export --scene NAME --out FILE.glb`: a built-in scene as glTF 2.0 (`scene/export.rs`).

use crate::cli::ExportArgs;
use crate::error::{Error, Result};
use crate::scene::{SceneConfig, SceneDef, SceneKind};

/// Writes the scene `args` names (its first instance count) to `args.out`.
pub fn execute(args: &ExportArgs) -> Result<()> {
    let kind = SceneKind::from_name(&args.scene)?;
    if kind.is_user() {
        return Err(Error::Config(format!(
            "export: {} is already a glTF file; export writes the built-in scenes",
            args.scene
        )));
    }
    let cfg = SceneConfig::from_args(&args.scene_args)?;
    let def = SceneDef::new(kind, &cfg)?;
    let count = def.counts[0];
    let glb = crate::scene::export::glb(&def.instantiate(count))?;
    std::fs::write(&args.out, &glb).map_err(|e| Error::Output {
        path: args.out.clone(),
        problem: format!("cannot be written ({e})"),
    })?;
    outln!(
        "{}: {} (count {count}, {} frames) written, {} bytes",
        args.out.display(),
        def.name(),
        def.frames,
        glb.len()
    );
    Ok(())
}
