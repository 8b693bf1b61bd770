//! The fuzz targets' corpora replayed (tests/fuzz/, docs/fuzzing.md): every seed the fuzzing starts from (the
//! test inputs of tests/data/ and scenes/), every input the fuzzing kept (tests/fuzz/corpus/<target>.tar.xz,
//! minimised and packed by scripts/fuzz-corpus.sh; read here from the archive as it is) and every crash it found,
//! each once more through its target's body (tests/fuzz/harness.rs). The fuzzing itself runs by hand; a reader
//! that panics on any of these fails here.

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

/// One input: where it came from, and its bytes.
struct Input {
    name: String,
    data: Vec<u8>,
}

fn read_files(paths: Vec<PathBuf>) -> Vec<Input> {
    paths
        .into_iter()
        .map(|p| Input {
            name: p.display().to_string(),
            data: std::fs::read(&p).unwrap(),
        })
        .collect()
}

/// Runs `target` on every input and returns how many there were.
fn replay(inputs: Vec<Input>, target: fn(&[u8])) -> usize {
    for input in &inputs {
        if let Err(e) = std::panic::catch_unwind(|| target(&input.data)) {
            let why = e
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            panic!("{}: {why}", input.name);
        }
    }
    inputs.len()
}

/// The inputs of tests/fuzz/corpus/<target>.tar.xz, read from the archive, named `archive:member`; none when
/// the target has no archive.
fn archive(target: &str) -> Vec<Input> {
    let path = root().join(format!("tests/fuzz/corpus/{target}.tar.xz"));
    let Ok(packed) = std::fs::read(&path) else {
        return Vec::new();
    };
    let mut tar_bytes = Vec::new();
    lzma_rs::xz_decompress(&mut packed.as_slice(), &mut tar_bytes)
        .unwrap_or_else(|e| panic!("{}: not an xz archive: {e}", path.display()));
    let mut out = Vec::new();
    let mut tar = tar::Archive::new(tar_bytes.as_slice());
    for entry in tar.entries().unwrap() {
        let mut entry = entry.unwrap();
        if !entry.header().entry_type().is_file() {
            continue;
        }
        let name = format!("{}:{}", path.display(), entry.path().unwrap().display());
        let mut data = Vec::new();
        std::io::Read::read_to_end(&mut entry, &mut data).unwrap();
        out.push(Input { name, data });
    }
    assert!(!out.is_empty(), "{}: holds no input", path.display());
    out
}

/// The kept corpus (packed) and the crashes (tests/fuzz/regressions/<target>/) of `target`.
fn corpus(target: &str) -> Vec<Input> {
    let mut out = archive(target);
    out.extend(read_files(files(
        &[&format!("tests/fuzz/regressions/{target}")],
        &[],
    )));
    out
}

/// How many inputs each target's archive holds (scripts/fuzz-corpus.sh's count when packed): a corpus that
/// stopped being read, or an archive cut short, fails here.
#[test]
fn the_archives_hold_the_kept_corpora() {
    let counts: Vec<(&str, usize)> = ["camera_path", "experiment", "gltf", "gltf_scene"]
        .iter()
        .map(|t| (*t, archive(t).len()))
        .collect();
    assert_eq!(
        counts,
        [
            ("camera_path", 441),
            ("experiment", 2456),
            ("gltf", 883),
            ("gltf_scene", 540)
        ]
    );
}

#[test]
fn gltf() {
    let mut inputs = read_files(files(&["tests/data"], &[".gltf", ".glb"]));
    inputs.extend(corpus("gltf"));
    assert!(replay(inputs, fuzz_gltf) > 30);
}

#[test]
fn gltf_scene() {
    let mut paths = files(&["tests/data/gltf", "tests/data/tools"], &[".gltf", ".glb"]);
    paths.retain(|p| !p.to_string_lossy().contains("Fox"));
    let mut inputs = read_files(paths);
    inputs.extend(corpus("gltf_scene"));
    assert!(replay(inputs, fuzz_gltf_scene) > 20);
}

#[test]
fn obj() {
    let mut inputs = read_files(files(&["scenes", "tests/data"], &[".obj"]));
    inputs.extend(corpus("obj"));
    assert!(replay(inputs, fuzz_obj) >= 1);
}

#[test]
fn camera_path() {
    let mut inputs = read_files(files(&["scenes/paths"], &[".csv"]));
    inputs.extend(corpus("camera_path"));
    assert!(replay(inputs, fuzz_camera_path) >= 1);
}

#[test]
fn experiment() {
    let mut inputs = read_files(files(&["scenes/experiments"], &[".toml"]));
    inputs.extend(corpus("experiment"));
    assert!(replay(inputs, fuzz_experiment) >= 5);
}
