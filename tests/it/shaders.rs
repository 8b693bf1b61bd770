//! Every WGSL file in shaders/ must parse and validate with naga (errors shown with source locations): each
//! file that stands alone, and the mesh shader with each of its surfaces (shaders/surface/*.wgsl before
//! shaders/mesh.wgsl, as the renderer composes them); and the entry points the Rust side names must exist.

use lodbench::gpu::{mesh_wgsl, Surface};
use std::path::Path;

fn validate(path: &Path) -> naga::Module {
    let source = std::fs::read_to_string(path).unwrap();
    validate_source(&source, &path.display().to_string())
}

fn validate_source(source: &str, name: &str) -> naga::Module {
    let source = source.to_string();
    let module = match naga::front::wgsl::parse_str(&source) {
        Ok(m) => m,
        Err(e) => panic!("{}", e.emit_to_string_with_path(&source, name)),
    };
    let mut validator = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    );
    if let Err(e) = validator.validate(&module) {
        panic!("{}", e.emit_to_string_with_path(&source, name));
    }
    module
}

fn entry_points(m: &naga::Module) -> Vec<String> {
    m.entry_points.iter().map(|e| e.name.clone()).collect()
}

#[test]
fn every_shader_validates() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let mut count = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        // mesh.wgsl is completed by a surface (below).
        if path.extension().is_some_and(|e| e == "wgsl") && !path.ends_with("mesh.wgsl") {
            validate(&path);
            count += 1;
        }
    }
    assert!(
        count >= 2,
        "expected the shaders in {}, found {count}",
        dir.display()
    );
    let surfaces = std::fs::read_dir(dir.join("surface")).unwrap().count();
    assert_eq!(surfaces, 2, "a surface the renderer does not compose");
    for s in [Surface::Flat, Surface::Pbr] {
        validate_source(&mesh_wgsl(s), &format!("mesh.wgsl with the {s:?} surface"));
    }
}

#[test]
fn entry_points_the_renderer_uses_exist() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    for s in [Surface::Flat, Surface::Pbr] {
        let mesh = entry_points(&validate_source(&mesh_wgsl(s), &format!("{s:?}")));
        for e in [
            "vs_main",
            "vs_morph",
            "fs_opaque",
            "fs_translucent",
            "fs_translucent_occluded",
            "fs_dither",
            "fs_depth_masked",
            "fs_fsi_n",
            "fs_fsi_t",
        ] {
            assert!(
                mesh.contains(&e.to_string()),
                "mesh.wgsl lacks {e}: {mesh:?}"
            );
        }
    }
    let mut metrics = entry_points(&validate(&dir.join("metrics.wgsl")));
    metrics.sort();
    assert_eq!(metrics, vec!["crack_main".to_string(), "main".to_string()]);
    let combine = entry_points(&validate(&dir.join("fsi_combine.wgsl")));
    assert!(combine.contains(&"cs_combine".to_string()), "{combine:?}");
    let diff = entry_points(&validate(&dir.join("diff.wgsl")));
    assert_eq!(diff, vec!["main".to_string()]);
}

#[test]
fn a_broken_shader_is_reported_with_its_location() {
    let source = "@fragment fn f() -> @location(0) vec4<f32> { return vec4<f32>(undefined_name); }";
    let err = naga::front::wgsl::parse_str(source).unwrap_err();
    let text = err.emit_to_string_with_path(source, "broken.wgsl");
    assert!(text.contains("broken.wgsl:1:"), "{text}");
}
