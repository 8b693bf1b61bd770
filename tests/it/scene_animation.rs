//! A glTF scene's animation on the run's timeline (src/scene/animated.rs, src/scene/user/motion.rs): moving and
//! deforming instances seen alike by the reference and every method, lodpop's counterfactual at the frame's
//! pose, and a skinned character's chain swept through every transition by every method.

use crate::common::{col, read_csv, run_into};
use std::path::{Path, PathBuf};

fn assets(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/gltf")
        .join(file)
}

const SMOOTH: &str = "discrete,alpha,dither,geomorph,fsi";

/// still-and-moving.gltf: a static sphere crossing its switches beside a tetrahedron whose morph weight the
/// clip drives (deformed every frame, never in transition, every pose inside its rest sphere so the clip planes
/// are the same). lodpop holds the pose (the counterfactual is drawn at this frame's pose), so every figure of
/// every method is the same, frame by frame, with the clip playing and at rest: the tetrahedron's motion is in
/// the reference and in every method's frame and counterfactual alike, and cancels.
#[test]
fn lodpop_holds_the_pose_of_a_deforming_neighbour() {
    let dir = tempfile::tempdir().unwrap();
    let path = assets("still-and-moving.gltf");
    let run = |animation: &str| {
        let out = dir.path().join(animation);
        #[rustfmt::skip]
        run_into(&out, &[
            "--scene", path.to_str().unwrap(), "--method", SMOOTH, "--animation", animation,
            "--width", "96", "--height", "72", "--frames", "120", "--rounds", "1", "--warmup", "1",
        ]);
        read_csv(&out.join("frames.csv"))
    };
    let (moving, still) = (run("0"), run("none"));
    let transitions = read_csv(&dir.path().join("0/transitions.csv"));
    for m in SMOOTH.split(',') {
        assert!(
            transitions.iter().filter(|t| t["method"] == m).count() >= 2,
            "{m}: the sphere crosses its switches"
        );
        for figure in ["lodpop", "rmse", "pop"] {
            assert_eq!(
                col(&moving, m, figure),
                col(&still, m, figure),
                "{m}: {figure}"
            );
        }
        assert!(col(&moving, m, "lodpop").iter().any(|&x| x > 0.0), "{m}");
    }
}

/// Fox.glb (skinned, its first clip playing): kept at LOD0 on every frame (switches beyond the flight), every
/// method's frame equals the reference's on every frame: the pose is written once per frame and every method,
/// FSI's two buffers and geomorph's targets included, draws it.
#[test]
fn a_deformed_mesh_is_drawn_alike_by_every_method() {
    let dir = tempfile::tempdir().unwrap();
    let path = assets("Fox.glb");
    #[rustfmt::skip]
    let out = run_into(&dir.path().join("fox"), &[
        "--scene", path.to_str().unwrap(), "--method", "reference,discrete,alpha,dither,geomorph,fsi,fsi-sameframe",
        "--switch-distances", "1e6,2e6,3e6", "--width", "96", "--height", "72", "--frames", "40",
        "--rounds", "1", "--warmup", "1",
    ]);
    let rows = read_csv(&out.join("frames.csv"));
    for m in [
        "discrete",
        "alpha",
        "dither",
        "geomorph",
        "fsi",
        "fsi-sameframe",
    ] {
        assert!(col(&rows, m, "rmse").iter().all(|&x| x == 0.0), "{m}");
    }
}

/// Fox.glb walks (its first clip, skinned) while the camera flies out: its chain (made from split vertices)
/// is swept through every transition by every method.
#[test]
fn a_skinned_character_sweeps_every_transition() {
    let dir = tempfile::tempdir().unwrap();
    let path = assets("Fox.glb");
    #[rustfmt::skip]
    let out = run_into(&dir.path().join("fox"), &[
        "--scene", path.to_str().unwrap(), "--width", "96", "--height", "72", "--frames", "120",
        "--rounds", "1", "--warmup", "1",
    ]);
    let transitions = read_csv(&out.join("transitions.csv"));
    let frames = read_csv(&out.join("frames.csv"));
    let methods: Vec<String> = frames
        .iter()
        .map(|r| r["method"].clone())
        .filter(|m| m != "reference")
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect();
    assert!(methods.len() >= 10, "{methods:?}");
    for m in &methods {
        let pairs: Vec<&str> = transitions
            .iter()
            .filter(|t| &t["method"] == m)
            .map(|t| t["lods"].as_str())
            .collect();
        assert_eq!(pairs, ["0->1", "1->2", "2->3"], "{m}");
    }
}

/// The clip is what is drawn: Fox.glb under a camera that holds still, its reference frames 0 and 20 differ with
/// its first clip playing (the fox turns its head) and are the same with `--animation none`.
#[test]
fn the_clip_is_drawn() {
    let dir = tempfile::tempdir().unwrap();
    let path = assets("Fox.glb");
    let camera = dir.path().join("still.csv");
    std::fs::write(
        &camera,
        "frame,x,y,z,target_x,target_y,target_z\n0,0,40,160,0,40,0\n1,0,40,160,0,40,0\n",
    )
    .unwrap();
    let frame = |animation: &str, f: u32| -> Vec<u8> {
        let out = dir.path().join(animation);
        if !out.exists() {
            #[rustfmt::skip]
            run_into(&out, &[
                "--scene", path.to_str().unwrap(), "--method", "reference", "--animation", animation,
                "--camera-path", camera.to_str().unwrap(), "--width", "96", "--height", "72", "--frames", "21",
                "--rounds", "1", "--warmup", "1", "--dump-frames", "--dump-every", "20",
            ]);
        }
        let png = out.join(format!("frames/Fox.glb_reference_c1_f{f:05}_reference.png"));
        lodbench::raster::read(&png)
            .unwrap_or_else(|e| panic!("{}: {e}", png.display()))
            .into_raw()
    };
    assert_ne!(frame("0", 0), frame("0", 20), "the clip moves the fox");
    assert_eq!(frame("none", 0), frame("none", 20), "at rest nothing moves");
}

/// Every set of joints and weights skins a vertex (glTF 2.0 section 3.7.3.3), as assimp's quad_skin.glb has three:
/// SimpleSkin.gltf with its weights split over three sets (half in JOINTS_0/WEIGHTS_0, a quarter in each of _1 and
/// _2, the same joints) is posed exactly as the file itself, at rest and on a frame of its clip. Reading the first
/// two sets alone would scale each skinned vertex's offset by 3/4.
#[test]
fn every_set_of_joints_and_weights_skins_the_vertex() {
    let dir = tempfile::tempdir().unwrap();
    let path = assets("SimpleSkin.gltf");
    let mut doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    // WEIGHTS_0: accessor 3 (10 VEC4 floats at byte 160 of buffer view 2, in buffer 1, an embedded data URI).
    let uri = doc["buffers"][1]["uri"].as_str().unwrap().to_string();
    let b64 = uri.split_once(',').unwrap().1;
    let bytes = base64::Engine::decode(&base64::engine::general_purpose::STANDARD, b64).unwrap();
    let weights: Vec<f32> = bytes[160..160 + 160]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    let mut extra = Vec::new();
    for share in [0.5f32, 0.25, 0.25] {
        for w in &weights {
            extra.extend_from_slice(&(w * share).to_le_bytes());
        }
    }
    std::fs::write(dir.path().join("weights.bin"), &extra).unwrap();
    let buffer = doc["buffers"].as_array().unwrap().len();
    doc["buffers"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!({ "uri": "weights.bin", "byteLength": extra.len() }));
    let views = doc["bufferViews"].as_array().unwrap().len();
    doc["bufferViews"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!({ "buffer": buffer, "byteLength": extra.len() }));
    let first = doc["accessors"].as_array().unwrap().len();
    for k in 0..3 {
        doc["accessors"].as_array_mut().unwrap().push(serde_json::json!({
            "bufferView": views, "byteOffset": 160 * k, "componentType": 5126, "count": 10, "type": "VEC4"
        }));
    }
    let attrs = &mut doc["meshes"][0]["primitives"][0]["attributes"];
    for k in 0..3 {
        attrs[format!("JOINTS_{k}")] = serde_json::json!(2);
        attrs[format!("WEIGHTS_{k}")] = serde_json::json!(first + k);
    }
    let split = dir.path().join("three-sets.gltf");
    std::fs::write(&split, doc.to_string()).unwrap();
    let obj = |file: &Path, frame: &str, tag: &str| -> String {
        let out = dir.path().join(format!("{tag}-{frame}.obj"));
        #[rustfmt::skip]
        let r = crate::common::lodbench(&[
            "export", "--scene", file.to_str().unwrap(), "--out", out.to_str().unwrap(), "--frame", frame,
        ], &[]);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        std::fs::read_to_string(&out).unwrap()
    };
    let vertices = |text: &str| -> Vec<f64> {
        text.lines()
            .filter(|l| l.starts_with("v "))
            .flat_map(|l| l[2..].split_whitespace().map(|x| x.parse::<f64>().unwrap()))
            .collect()
    };
    for frame in ["0", "40"] {
        let (a, b) = (
            vertices(&obj(&path, frame, "file")),
            vertices(&obj(&split, frame, "split")),
        );
        assert_eq!(a.len(), b.len());
        let worst = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        assert!(
            worst < 1e-5,
            "frame {frame}: vertices differ by up to {worst}"
        );
    }
}
