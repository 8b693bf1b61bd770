// The fuzz targets' bodies, shared by the cargo-fuzz targets (tests/fuzz/fuzz_targets/, `include!`d there) and by
// the corpus replay in the tests (tests/it/fuzz_corpus.rs): each takes arbitrary bytes through one reader of
// user input and everything that reads its result. None may panic; an error is an answer.

/// A folder that does not exist: a glTF's external buffers are looked up there, so no URI reads a real file.
const NO_FOLDER: &str = "/nonexistent-lodbench-fuzz";

/// A glTF or GLB through the reader: every placement's mesh at rest (skins posed, morph targets weighed), every
/// animation's nodes and weights at a few times, the animated camera, and `--mesh`'s merge of the whole scene.
pub fn fuzz_gltf(data: &[u8]) {
    let dir = std::path::Path::new(NO_FOLDER);
    let _ = lodbench::geometry::mesh::Mesh::parse_gltf("fuzz.glb", data, dir);
    let Ok(mut content) = lodbench::geometry::gltf::read(data, dir) else {
        return;
    };
    let placements = content.placements.clone();
    for p in placements.iter().take(32) {
        if let Ok(prims) = content.mesh_primitives(p.mesh) {
            let _ = content.placed(p, &prims, glam::Mat4::IDENTITY);
        }
    }
    for i in 0..content.animation_names().len().min(4) {
        if let Ok(rig) = content.rig(Some(i)) {
            for t in [-1.0, 0.0, 0.37, 1e9] {
                let worlds = rig.worlds_at(t);
                for n in 0..worlds.len().min(8) {
                    let _ = rig.weights_at(n, t, 4);
                }
            }
        }
    }
    let _ = content.animated_camera();
}

/// A glTF or GLB as a user scene (`--scene FILE.glb`, 4 frames at 32x24): models, LOD chains, animation and
/// deformation, the camera, and every frame's instances and pose (`lodbench export --out FILE.obj`'s geometry).
pub fn fuzz_gltf_scene(data: &[u8]) {
    use std::sync::OnceLock;
    static FILE: OnceLock<std::path::PathBuf> = OnceLock::new();
    let path = FILE.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("lodbench-fuzz-{}", std::process::id()));
        let _ = std::fs::create_dir_all(&dir);
        dir.join("scene.glb")
    });
    if std::fs::write(path, data).is_err() {
        return;
    }
    let Some(name) = path.to_str() else { return };
    let Ok(kind) = lodbench::scene::SceneKind::from_name(name) else {
        return;
    };
    let args = lodbench::cli::SceneArgs {
        width: Some(32),
        height: Some(24),
        frames: Some(4),
        ..Default::default()
    };
    let Ok(cfg) = lodbench::scene::SceneConfig::from_args(&args) else {
        return;
    };
    let Ok(def) = lodbench::scene::SceneDef::new(kind, &cfg) else {
        return;
    };
    let _ = def.notes();
    let scene = def.instantiate(def.counts[0]);
    for f in 0..scene.frames {
        let _ = lodbench::scene::export_obj::obj(&def, &scene, f);
        let _ = scene.camera(f);
    }
}

/// An OBJ file (`--mesh FILE.obj`).
pub fn fuzz_obj(data: &[u8]) {
    let _ = lodbench::geometry::mesh::Mesh::parse_obj("fuzz.obj", data);
}

/// A camera path (`--camera-path FILE.csv`) and its view on a few frames.
pub fn fuzz_camera_path(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(path) = lodbench::scene::camera_path::CameraPath::parse("fuzz.csv", text) {
        for f in [0, 1, 7, 99] {
            let _ = path.view(f, 100);
        }
        let _ = path.eyes().count();
    }
}

/// An experiment file (`lodbench experiment FILE.toml`), with and without a `--set`.
pub fn fuzz_experiment(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let file = std::path::Path::new("fuzz.toml");
    let _ = lodbench::cli::experiment_file::Experiment::parse(file, text.to_string(), &[]);
    let _ = lodbench::cli::experiment_file::Experiment::parse(
        file,
        text.to_string(),
        &["frames=3".to_string()],
    );
}
