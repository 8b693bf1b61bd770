//! `lodbench export --scene NAME --out FILE.glb|FILE.obj`: a scene as glTF 2.0 (`scene/export_glb.rs`: a built-in
//! scene, or a glTF scene as lodbench draws it, its LOD chains and materials, at frame 0), or any non-unified
//! scene's geometry on one frame as OBJ (`scene/export_obj.rs`).

use crate::cli::ExportArgs;
use crate::error::{Error, Result};
use crate::scene::{SceneConfig, SceneDef, SceneKind};

/// Writes the scene `args` names (its first instance count) to `args.out`.
pub fn execute(args: &ExportArgs) -> Result<()> {
    let kind = SceneKind::from_name(&args.scene)?;
    let obj = args
        .out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("obj"));
    let mut cfg = SceneConfig::from_args(&args.scene_args)?;
    if cfg.impostor.is_some() {
        return Err(Error::Config(
            "export --impostor: an impostor is baked when a scene is drawn and has no glTF or OBJ form; export \
             without --impostor (and run the exported file with it)"
                .into(),
        ));
    }
    if obj {
        // An OBJ holds the geometry alone: no image is decoded (a file whose textures are missing or KTX2 still
        // exports).
        cfg.materials = crate::geometry::material::MaterialMode::Flat;
    }
    let def = SceneDef::new(kind, &cfg)?;
    if kind.is_unified() {
        return Err(Error::Config(format!(
            "export: {} is a unified scene; its blocks and seams have no glTF or OBJ form, so it is not exported",
            def.name()
        )));
    }
    if args.frame >= def.frames {
        return Err(Error::Config(format!(
            "export --frame {}: the scene has {} frames (0 to {})",
            args.frame,
            def.frames,
            def.frames - 1
        )));
    }
    let count = def.counts[0];
    let scene = def.instantiate(count);
    let bytes = match obj {
        true => crate::scene::export_obj::obj(&def, &scene, args.frame).into_bytes(),
        false => crate::scene::export_glb::glb(&scene)?,
    };
    std::fs::write(&args.out, &bytes).map_err(|e| Error::Output {
        path: args.out.clone(),
        problem: format!("cannot be written ({e})"),
    })?;
    for note in def.notes() {
        eprintln!("note: {note}");
    }
    outln!(
        "{}: {} (count {count}, {}) written, {} bytes",
        args.out.display(),
        def.name(),
        match obj {
            true => format!("frame {}", args.frame),
            false => format!("{} frames", def.frames),
        },
        bytes.len()
    );
    Ok(())
}
