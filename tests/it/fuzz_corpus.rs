//! The fuzz targets' corpora replayed (tests/fuzz/, docs/fuzzing.md): every seed the fuzzing starts from (the
//! test inputs of tests/data/ and scenes/), every input the fuzzing kept (tests/fuzz/corpus/<target>/, minimised)
//! and every crash it found, each once more through its target's body (tests/fuzz/harness.rs). The fuzzing itself
//! runs by hand; a reader that panics on any of these fails here.

use std::path::{Path, PathBuf};

include!("../fuzz/harness.rs");

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).to_path_buf()
}

/// The files of `dirs` (relative to the repository), recursively, whose names end in one of `ends` (every file
/// when empty).
fn files(dirs: &[&str], ends: &[&str]) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack: Vec<PathBuf> = dirs.iter().map(|d| root().join(d)).collect();
    while let Some(p) = stack.pop() {
        if p.is_dir() {
            for e in std::fs::read_dir(&p).unwrap() {
                stack.push(e.unwrap().path());
            }
        } else if p.is_file() && ends.is_empty()
            || p.is_file() && ends.iter().any(|e| p.to_string_lossy().ends_with(e))
        {
            out.push(p);
        }
    }
    out.sort();
    out
}

/// Runs `target` on every file and returns how many there were.
fn replay(paths: Vec<PathBuf>, target: fn(&[u8])) -> usize {
    for p in &paths {
        let data = std::fs::read(p).unwrap();
        let name = p.display().to_string();
        if let Err(e) = std::panic::catch_unwind(|| target(&data)) {
            let why = e
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            panic!("{name}: {why}");
        }
    }
    paths.len()
}

fn corpus(target: &str) -> Vec<PathBuf> {
    files(
        &[
            &format!("tests/fuzz/corpus/{target}"),
            &format!("tests/fuzz/regressions/{target}"),
        ],
        &[],
    )
}

#[test]
fn gltf() {
    let mut inputs = files(&["tests/data"], &[".gltf", ".glb"]);
    inputs.extend(corpus("gltf"));
    assert!(replay(inputs, fuzz_gltf) > 30);
}

#[test]
fn gltf_scene() {
    let mut inputs = files(&["tests/data/gltf", "tests/data/tools"], &[".gltf", ".glb"]);
    inputs.retain(|p| !p.to_string_lossy().contains("Fox"));
    inputs.extend(corpus("gltf_scene"));
    assert!(replay(inputs, fuzz_gltf_scene) > 20);
}

#[test]
fn obj() {
    let mut inputs = files(&["scenes", "tests/data"], &[".obj"]);
    inputs.extend(corpus("obj"));
    assert!(replay(inputs, fuzz_obj) >= 1);
}

#[test]
fn camera_path() {
    let mut inputs = files(&["scenes/paths"], &[".csv"]);
    inputs.extend(corpus("camera_path"));
    assert!(replay(inputs, fuzz_camera_path) >= 1);
}

#[test]
fn experiment() {
    let mut inputs = files(&["scenes/experiments"], &[".toml"]);
    inputs.extend(corpus("experiment"));
    assert!(replay(inputs, fuzz_experiment) >= 5);
}
