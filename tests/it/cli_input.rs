//! Bad input ends in one clear `error:` line and a non-zero exit, never a panic.

use crate::common::{fails_with, lodbench};
use std::path::Path;
use std::process::Command;

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

#[test]
fn unknown_scene_and_method_list_valid_names() {
    let out = lodbench(&["run", "--scene", "bunny-swep"], &[]);
    fails_with(
        &out,
        &["unknown scene 'bunny-swep'", "bunny-sweep, bunny-grid"],
    );
    let out = lodbench(&["run", "--method", "reference,fsii"], &[]);
    fails_with(&out, &["unknown method 'fsii'", "reference", "discrete"]);
    let out = lodbench(&["describe", "--scene", "nope"], &[]);
    fails_with(&out, &["unknown scene 'nope'"]);
}

#[test]
fn bad_meshes_name_the_file_and_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.obj");
    let out = lodbench(
        &[
            "run",
            "--scene",
            "bunny-sweep",
            "--mesh",
            missing.to_str().unwrap(),
        ],
        &[],
    );
    fails_with(&out, &["missing.obj", "not found"]);

    let bad = write(
        dir.path(),
        "range.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 7\n",
    );
    let out = lodbench(&["run", "--scene", "bunny-sweep", "--mesh", &bad], &[]);
    fails_with(&out, &["range.obj"]);

    let nan = write(
        dir.path(),
        "nan.obj",
        "v 0 0 0\nv 1 NaN 0\nv 0 1 0\nf 1 2 3\n",
    );
    let out = lodbench(&["describe", "--scene", "bunny-grid", "--mesh", &nan], &[]);
    fails_with(&out, &["nan.obj", "non-finite"]);

    let empty = write(dir.path(), "empty.obj", "# nothing\n");
    let out = lodbench(&["run", "--scene", "bunny-sweep", "--mesh", &empty], &[]);
    fails_with(&out, &["empty.obj", "no triangles"]);

    // Every triangle degenerate (three points on a line, twice): named by file, not by model.
    let flat = write(
        dir.path(),
        "flat.obj",
        "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nf 1 2 3\nf 2 3 4\n",
    );
    let out = lodbench(
        &["describe", "--scene", "bunny-sweep", "--mesh", &flat],
        &[],
    );
    fails_with(&out, &["flat.obj", "all 2 triangles are degenerate"]);

    let folder = dir.path().to_str().unwrap();
    let out = lodbench(&["run", "--scene", "bunny-sweep", "--mesh", folder], &[]);
    fails_with(&out, &[folder, "is a directory"]);

    let garbage = write(dir.path(), "garbage.glb", "glTF but not really");
    let out = lodbench(&["run", "--scene", "bunny-sweep", "--mesh", &garbage], &[]);
    fails_with(&out, &["garbage.glb", "not a readable glTF file"]);

    let text = write(dir.path(), "mesh.ply", "ply\n");
    let out = lodbench(&["run", "--scene", "bunny-sweep", "--mesh", &text], &[]);
    fails_with(&out, &["mesh.ply", "unsupported extension '.ply'"]);

    // Files real tools write that --mesh cannot take: Draco (the remedy names the command that rewrites it) and
    // an authored LOD chain (never merged into one mesh).
    let tools = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/tools");
    let draco = tools.join("bunny-gt-draco.glb");
    let out = lodbench(
        &[
            "describe",
            "--scene",
            "bunny-sweep",
            "--mesh",
            draco.to_str().unwrap(),
        ],
        &[],
    );
    fails_with(
        &out,
        &["bunny-gt-draco.glb", "Draco", "gltf-transform/cli meshopt"],
    );
    let chain = tools.join("bunny-msft-lod.glb");
    let out = lodbench(
        &[
            "describe",
            "--scene",
            "bunny-sweep",
            "--mesh",
            chain.to_str().unwrap(),
        ],
        &[],
    );
    fails_with(
        &out,
        &["bunny-msft-lod.glb", "authored LOD chain", "MSFT_lod"],
    );
}

/// The built-in bunny written as a binary glTF (one mesh, one node translated by (5, 0, 0), positions and
/// indices only): the smallest GLB the spec allows, made here so the test needs no generator.
fn bunny_glb() -> Vec<u8> {
    let m = lodbench::geometry::mesh::Mesh::parse_obj("bunny", lodbench::scene::BUNNY_OBJ).unwrap();
    let mut bin: Vec<u8> = m
        .positions
        .iter()
        .flatten()
        .flat_map(|c| c.to_le_bytes())
        .collect();
    let pos_len = bin.len();
    bin.extend(m.indices.iter().flat_map(|i| i.to_le_bytes()));
    let (lo, hi) = m.bounds();
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0,"translation":[5,0,0]}}],"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],"buffers":[{{"byteLength":{}}}],"bufferViews":[{{"buffer":0,"byteLength":{pos_len}}},{{"buffer":0,"byteOffset":{pos_len},"byteLength":{}}}],"accessors":[{{"bufferView":0,"componentType":5126,"count":{},"type":"VEC3","min":[{},{},{}],"max":[{},{},{}]}},{{"bufferView":1,"componentType":5125,"count":{},"type":"SCALAR"}}]}}"#,
        bin.len(),
        bin.len() - pos_len,
        m.vertex_count(),
        lo.x,
        lo.y,
        lo.z,
        hi.x,
        hi.y,
        hi.z,
        m.indices.len()
    );
    let mut json = json.into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut glb = Vec::new();
    glb.extend(b"glTF");
    glb.extend(2u32.to_le_bytes());
    glb.extend((total as u32).to_le_bytes());
    glb.extend((json.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(json);
    glb.extend((bin.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(bin);
    glb
}

/// `a` and `b` hold the same JSON, numbers within `rel` of each other (integers exactly).
fn assert_close(a: &serde_json::Value, b: &serde_json::Value, rel: f64) {
    use serde_json::Value;
    match (a, b) {
        (Value::Number(x), Value::Number(y)) if x.is_f64() || y.is_f64() => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            assert!((x - y).abs() <= rel * x.abs().max(y.abs()), "{x} vs {y}");
        }
        (Value::Array(x), Value::Array(y)) => {
            assert_eq!(x.len(), y.len(), "{a} vs {b}");
            x.iter().zip(y).for_each(|(x, y)| assert_close(x, y, rel));
        }
        (Value::Object(x), Value::Object(y)) => {
            assert_eq!(x.keys().collect::<Vec<_>>(), y.keys().collect::<Vec<_>>());
            x.iter().for_each(|(k, v)| assert_close(v, &y[k], rel));
        }
        _ => assert_eq!(a, b),
    }
}

/// `--mesh` takes glTF: the bunny as a .glb gives the scene the same bunny as an OBJ gives (same LODs, switch
/// distances and path to float rounding; the node's translation moves the mesh, not its bounding sphere's size), and the committed fixtures of
/// tests/data/ load.
#[test]
fn gltf_mesh_gives_the_scene_the_obj_gives() {
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("bunny.glb");
    std::fs::write(&glb, bunny_glb()).unwrap();
    let describe = |mesh: Option<&str>| -> serde_json::Value {
        let mut args = vec![
            "describe",
            "--scene",
            "bunny-sweep",
            "--profile",
            "ci",
            "--json",
        ];
        if let Some(m) = mesh {
            args.extend_from_slice(&["--mesh", m]);
        }
        let out = lodbench(&args, &[]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice(&out.stdout).unwrap()
    };
    let obj = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/bunny.obj");
    let (from_glb, from_obj) = (
        describe(Some(glb.to_str().unwrap())),
        describe(Some(obj.to_str().unwrap())),
    );
    // The node's translation moves every position by float rounding, and the attribute-aware simplifier weighs
    // normals computed from them: the same chain, its errors (and so the switches and the path) to 1e-4.
    assert_close(&from_glb["models"], &from_obj["models"], 1e-4);
    assert_close(&from_glb["path"], &from_obj["path"], 1e-4);
    // A user's mesh gets a chain chosen by error (its switches on the path), the built-in bunny the paper's
    // triangle fractions: the same mesh, other LODs.
    let built_in = describe(None);
    assert_eq!(built_in["models"][0]["lods"][1]["triangles"], 1836);
    assert_ne!(from_obj["models"][0]["lods"][1]["triangles"], 1836);
    assert!(from_glb["mesh"].as_str().unwrap().ends_with("bunny.glb"));
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    for f in ["tetra.gltf", "tetra.glb"] {
        let m = lodbench::geometry::mesh::Mesh::load(&data.join(f)).unwrap();
        assert_eq!((m.vertex_count(), m.triangle_count()), (8, 8), "{f}");
    }
}

/// What `--scene` names but is not a scene gets the remedy: a folder the glTF files in it (or in its folders, the
/// Khronos sample assets' layout), an OBJ `--mesh`, and a glTF file whose image is missing `--materials flat`
/// (which then draws it).
#[test]
fn a_scene_that_is_not_one_names_its_remedy() {
    let dir = tempfile::tempdir().unwrap();
    let tetra = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/tetra.gltf");
    let model = dir.path().join("Tetra");
    std::fs::create_dir_all(model.join("glTF")).unwrap();
    std::fs::copy(&tetra, model.join("glTF/Tetra.gltf")).unwrap();
    let inner = model.join("glTF");
    let one = format!(
        "is a folder, not a scene: did you mean --scene {}?",
        inner.join("Tetra.gltf").display()
    );
    fails_with(
        &lodbench(&["run", "--scene", inner.to_str().unwrap()], &[]),
        &[&one],
    );
    std::fs::create_dir_all(model.join("glTF-Binary")).unwrap();
    let glb = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/tetra.glb");
    std::fs::copy(&glb, model.join("glTF-Binary/Tetra.glb")).unwrap();
    fails_with(
        &lodbench(&["describe", "--scene", model.to_str().unwrap()], &[]),
        &[
            "is a folder, not a scene: did you mean one of its glTF files",
            "glTF/Tetra.gltf",
            "glTF-Binary/Tetra.glb",
        ],
    );
    let obj = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/bunny.obj");
    fails_with(
        &lodbench(&["run", "--scene", obj.to_str().unwrap()], &[]),
        &["is an OBJ mesh, not a scene", "--mesh FILE.obj"],
    );
    // tetra.gltf with a base colour texture whose image is not there.
    let mut doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&tetra).unwrap()).unwrap();
    doc["images"] = serde_json::json!([{ "uri": "missing.png" }]);
    doc["textures"] = serde_json::json!([{ "source": 0 }]);
    doc["materials"] =
        serde_json::json!([{ "pbrMetallicRoughness": { "baseColorTexture": { "index": 0 } } }]);
    for m in doc["meshes"].as_array_mut().unwrap() {
        for p in m["primitives"].as_array_mut().unwrap() {
            p["material"] = serde_json::json!(0);
        }
    }
    let missing = write(dir.path(), "missing-image.gltf", &doc.to_string());
    fails_with(
        &lodbench(&["describe", "--scene", &missing], &[]),
        &[
            "missing.png",
            "not found: put the image beside the file, or draw the file without its materials with --materials flat",
        ],
    );
    let flat = lodbench(
        &["describe", "--scene", &missing, "--materials", "flat"],
        &[],
    );
    assert!(
        flat.status.success(),
        "{}",
        String::from_utf8_lossy(&flat.stderr)
    );
    // The shape of assimp's test/models/glTF2/wrongTypes/badArray.gltf: a mesh's `primitives` an object holding one
    // primitive, not an array. It was read as a mesh without triangles ("its meshes hold only points or lines").
    let mut bad: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&tetra).unwrap()).unwrap();
    let first = bad["meshes"][0]["primitives"][0].clone();
    bad["meshes"][0]["primitives"] =
        serde_json::json!({ "not an array": first["attributes"], "mode": 4 });
    let path = write(dir.path(), "bad-array.gltf", &bad.to_string());
    let out = lodbench(&["describe", "--scene", &path], &[]);
    fails_with(
        &out,
        &[
            "bad-array.gltf",
            "meshes[0].primitives is an object, not an array: the file does not follow the glTF 2.0 schema",
        ],
    );
    assert!(
        !String::from_utf8_lossy(&out.stderr).contains("points or lines"),
        "the real defect, not its symptom"
    );
}

#[test]
fn bad_numbers_are_rejected() {
    let out = lodbench(&["run", "--width", "0"], &[]);
    fails_with(&out, &["--width 0"]);
    let out = lodbench(&["run", "--switch-distances", "5,3"], &[]);
    fails_with(&out, &["--switch-distances", "increase"]);
}

#[test]
fn unknown_metric_and_fsi_check_are_rejected() {
    let out = lodbench(&["run", "--metrics", "rmse,psnr"], &[]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("psnr") && stderr.contains("flip") && !stderr.contains("panicked"),
        "{stderr}"
    );
    let out = lodbench(&["run", "--method", "fsi", "--fsi-check", "backward"], &[]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("backward") && stderr.contains("forward") && !stderr.contains("panicked"),
        "{stderr}"
    );
}

#[test]
fn unwritable_output_folder_fails_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "a-file", "x");
    let target = format!("{file}/results");
    let out = lodbench(
        &[
            "run",
            "--scene",
            "bunny-sweep",
            "--method",
            "reference",
            "--out",
            &target,
        ],
        &[],
    );
    fails_with(&out, &["output folder", "a-file"]);
}

#[test]
fn no_adapter_says_how_to_install_one() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let out = lodbench(
        &[
            "run",
            "--scene",
            "bunny-sweep",
            "--method",
            "reference",
            "--frames",
            "2",
            "--fsi-check",
            "forward",
            "--out",
            out_dir.to_str().unwrap(),
        ],
        &[
            ("VK_ICD_FILENAMES", "/nonexistent/icd.json"),
            ("VK_DRIVER_FILES", "/nonexistent/icd.json"),
        ],
    );
    fails_with(&out, &["no GPU adapter", "mesa-vulkan-drivers"]);
    // The failed run is visibly incomplete.
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("run.json")).unwrap()).unwrap();
    assert_eq!(manifest["status"], "failed", "{manifest}");
    // Every resolved flag is recorded, the failed run's too.
    assert_eq!(manifest["config"]["fsi_check"], "forward", "{manifest}");
    assert!(!out_dir.join("frames.csv").exists());
    assert!(!out_dir.join("summary.csv").exists());
}

#[test]
fn list_and_describe_work() {
    let out = lodbench(&["list"], &[]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("bunny-sweep") && text.contains("discrete"),
        "{text}"
    );

    let out = lodbench(
        &[
            "describe",
            "--scene",
            "bunny-grid",
            "--profile",
            "paper",
            "--json",
        ],
        &[],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        v["instance_counts"],
        serde_json::json!([50, 250, 500, 1000, 2000])
    );
    assert_eq!(v["frames"], 3600);
    let lods = v["models"][0]["lods"].as_array().unwrap();
    assert_eq!(lods.len(), 4);
    assert_eq!(lods[0]["triangles"], 3674);
    assert!(lods[0]["switch_distance"].is_null());
    let s: Vec<f64> = lods[1..]
        .iter()
        .map(|l| l["switch_distance"].as_f64().unwrap())
        .collect();
    assert!(s.windows(2).all(|w| w[1] > w[0]), "{s:?}");
}

#[test]
fn dump_transitions_dumps_the_frames_around_transitions() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let out = lodbench(
        &[
            "run",
            "--scene",
            "bunny-sweep",
            "--method",
            "discrete",
            "--profile",
            "quick",
            "--frames",
            "200",
            "--width",
            "64",
            "--height",
            "48",
            "--warmup",
            "0",
            "--dump-frames",
            "--dump-transitions",
            "--dump-every",
            "2",
            "--out",
            out_dir.to_str().unwrap(),
        ],
        &[],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let frames = std::fs::read_to_string(out_dir.join("frames.csv")).unwrap();
    let mut lines = frames.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (frame, t) = (col("frame"), col("t_instances"));
    let in_transition: Vec<u32> = lines
        .map(|l| l.split(',').collect::<Vec<_>>())
        .filter(|r| r[t] != "0")
        .map(|r| r[frame].parse::<u32>().unwrap())
        .collect();
    // The frames in transition and the 2 before and after each (a transition's clip), every 2nd frame.
    let last = frames.lines().count() as u32 - 2;
    let expected: Vec<u32> = (0..=last)
        .filter(|f| in_transition.iter().any(|&t| f + 2 >= t && *f <= t + 2))
        .filter(|f| f % 2 == 0)
        .collect();
    let mut dumped: Vec<u32> = std::fs::read_dir(out_dir.join("frames"))
        .unwrap()
        .filter_map(|e| {
            let name = e.unwrap().file_name().into_string().unwrap();
            let stem = name.strip_suffix("_method.png")?;
            stem[stem.len() - 5..].parse().ok()
        })
        .collect();
    dumped.sort();
    assert!(
        expected.len() >= 4,
        "too few frames in transition: {expected:?}"
    );
    assert_eq!(dumped, expected);
    // Without --dump-frames the flag is refused, with one error line.
    let out = lodbench(&["run", "--dump-transitions"], &[]);
    fails_with(&out, &["--dump-frames"]);
}

/// `lodbench describe ... | true`: the reader is gone before lodbench writes (it builds the scene's LOD
/// chains first); lodbench stops quietly, no panic.
#[test]
fn a_closed_stdout_is_no_panic() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_lodbench"))
        .args(["describe", "--scene", "windmills", "--profile", "ci"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
}

/// `--baseline` must name a method of the run; `--rounds 0` is no run.
#[test]
fn bad_timing_flags_are_rejected() {
    let out = lodbench(
        &["run", "--method", "alpha,fsi", "--baseline", "dither"],
        &[],
    );
    fails_with(&out, &["--baseline dither", "alpha, fsi"]);
    let out = lodbench(&["run", "--rounds", "0"], &[]);
    fails_with(&out, &["--rounds"]);
}

/// The unified methods need a unified scene, the unified scenes take no --switch-distances (each block has its
/// own), and --blocks stays in range: each a one-line error before any GPU work.
#[test]
fn unified_scenes_and_methods_reject_what_does_not_fit() {
    let out = lodbench(
        &["run", "--scene", "simple,terrain", "--method", "blocks"],
        &[],
    );
    fails_with(
        &out,
        &["method blocks", "scene simple", "bunny-halves", "terrain"],
    );
    let out = lodbench(&["run", "--method", "clusterlod"], &[]);
    fails_with(&out, &["method clusterlod", "scene bunny-sweep"]);
    // ROAM needs the terrain's height field: not bunny-halves, not a --mesh.
    let out = lodbench(&["run", "--scene", "bunny-halves", "--method", "roam"], &[]);
    fails_with(&out, &["method roam", "height field", "scene bunny-halves"]);
    let out = lodbench(
        &["run", "--scene", "bunny-halves", "--method", "blocks-tree"],
        &[],
    );
    fails_with(
        &out,
        &["method blocks-tree", "height field", "scene bunny-halves"],
    );
    let mesh = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/tetra.gltf");
    let out = lodbench(
        &[
            "run",
            "--scene",
            "terrain",
            "--mesh",
            mesh,
            "--method",
            "roam-morph",
        ],
        &[],
    );
    fails_with(&out, &["method roam-morph", "height field", "--mesh"]);
    let out = lodbench(
        &[
            "describe",
            "--scene",
            "terrain",
            "--profile",
            "regress",
            "--switch-distances",
            "1,2,3",
        ],
        &[],
    );
    fails_with(&out, &["--switch-distances", "terrain", "--pixel-error"]);
    let out = lodbench(&["describe", "--scene", "terrain", "--blocks", "0"], &[]);
    fails_with(&out, &["--blocks 0"]);
    let dir = tempfile::tempdir().unwrap();
    let flat = write(
        dir.path(),
        "flat.obj",
        "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n",
    );
    let out = lodbench(&["describe", "--scene", "terrain", "--mesh", &flat], &[]);
    fails_with(&out, &["flat.obj"]);
}

/// `--adapter` takes an index, 0-based in the order `lodbench list` prints the adapters (identical GPUs differ
/// only in it), as well as a part of a name; run.json records the adapter chosen with its index. An index out
/// of range is one error naming the flag, the index and the adapters found.
#[test]
fn adapter_by_index() {
    let list = lodbench(&["list"], &[]);
    let text = String::from_utf8_lossy(&list.stdout).to_string();
    let adapters: Vec<&str> = text
        .lines()
        .skip_while(|l| !l.starts_with("adapters"))
        .skip(1)
        .collect();
    assert!(adapters[0].starts_with("  0  "), "{text}");
    let first = adapters[0]["  0  ".len()..].split("  [").next().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let run = |adapter: &str, out: &str| {
        let out = dir.path().join(out);
        let o = lodbench(
            &[
                "run",
                "--scene",
                "bunny-sweep",
                "--method",
                "discrete",
                "--frames",
                "2",
                "--width",
                "32",
                "--height",
                "24",
                "--adapter",
                adapter,
                "--out",
                out.to_str().unwrap(),
            ],
            &[],
        );
        (o, out)
    };
    let (o, out) = run("0", "zero");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    assert_eq!(manifest["adapter"]["index"], 0);
    assert_eq!(manifest["adapter"]["name"], first);
    assert_eq!(manifest["config"]["adapter"], "0");
    let beyond = adapters.len().to_string();
    let (o, _) = run(&beyond, "beyond");
    fails_with(
        &o,
        &[
            &format!("--adapter {beyond}"),
            &format!("index {beyond}"),
            &format!("0 {first}"),
        ],
    );
}

/// `--quality off` skips the quality pass, so what needs it is refused before any GPU work.
#[test]
fn quality_off_refuses_what_needs_the_quality_pass() {
    for (extra, needle) in [
        (&["--dump-frames"][..], "--dump-frames"),
        (&["--metrics", "rmse,pop,de2000"][..], "--metrics de2000"),
        (&["--metrics", "flip"][..], "--metrics flip"),
    ] {
        let mut args = vec!["run", "--quality", "off"];
        args.extend_from_slice(extra);
        fails_with(&lodbench(&args, &[]), &["--quality off", needle]);
    }
    let out = lodbench(&["run", "--quality", "of"], &[]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("--quality") && stderr.contains("off"),
        "{stderr}"
    );
}
