//! One sphere, one projection (src/geometry/projection.rs): the scene builders, the engines' conversions, the
//! exported glTF read back, and tune's samples put the same screen size at the same distance.

use crate::common::scene_config;
use lodbench::geometry::projection::{distance_of, screen_size};
use lodbench::results::engines::{unity, unreal, EngineModel};
use lodbench::scene::{SceneDef, SceneKind};
use std::path::Path;

/// The JSON chunk of a .glb.
fn glb_json(glb: &[u8]) -> serde_json::Value {
    let len = u32::from_le_bytes([glb[12], glb[13], glb[14], glb[15]]) as usize;
    serde_json::from_slice(&glb[20..20 + len]).expect("the JSON chunk")
}

fn close(a: f32, b: f32) -> bool {
    (a - b).abs() <= 1e-5 * b.abs().max(1.0)
}

#[test]
fn builders_engines_export_and_tune_agree_on_one_sphere() {
    let sizes = [0.4f32, 0.2, 0.1];
    let flags = ["--profile", "quick", "--switch-screen-sizes", "0.4,0.2,0.1"];
    let def = SceneDef::new(SceneKind::BunnySweep, &scene_config("bunny-sweep", &flags)).unwrap();
    let scene = def.instantiate(1);
    let (m, fov) = (&scene.models[0], scene.fov_y);
    // The builder placed each switch where the model's sphere has its size.
    for (&d, s) in m.switches.iter().zip(sizes) {
        assert!(close(screen_size(m.radius, d, fov), s), "{d} {s}");
        assert!(close(d, distance_of(m.radius, s, fov)));
    }
    // The engines' units give the sizes back: Unreal's screen sizes, Unity's transition heights (hard switches).
    let engine = EngineModel {
        name: "bunny".into(),
        radius: m.radius,
        center: m.center.to_array(),
        switches: m.switches.clone(),
        bands: vec![0.0; sizes.len()],
        triangles: Vec::new(),
    };
    let u = unreal(&engine, fov);
    assert!(close(u.screen_size[0], 1.0));
    for (&got, s) in u.screen_size[1..].iter().zip(sizes) {
        assert!(close(got, s), "unreal {got} {s}");
    }
    let y = unity(&engine, fov);
    for (lod, s) in y.lods.iter().zip(sizes) {
        assert!(close(lod.height, s), "unity {} {s}", lod.height);
    }
    // The exported file's MSFT_screencoverage, and the scene read back from it, switch at the same distances.
    let glb = lodbench::scene::export_glb::glb_with(&scene, false).unwrap();
    let json = glb_json(&glb);
    let coverage: Vec<f32> = json["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .find_map(|n| n["extras"]["MSFT_screencoverage"].as_array())
        .expect("a node with MSFT_screencoverage")
        .iter()
        .map(|c| c.as_f64().unwrap() as f32)
        .collect();
    for (&c, s) in coverage.iter().zip(sizes) {
        assert!(close(c, s), "coverage {c} {s}");
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bunny.glb");
    std::fs::write(&path, &glb).unwrap();
    let path = path.to_str().unwrap();
    let back = SceneDef::new(
        SceneKind::from_name(path).unwrap(),
        &scene_config(path, &["--profile", "quick"]),
    )
    .unwrap()
    .instantiate(1);
    for (&a, &b) in back.models[0].switches.iter().zip(&m.switches) {
        assert!(close(a, b), "read back {a} against {b}");
    }
    // tune's samples: each view's screen size is the sphere's at the sample's distance.
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("results/cpu/tune-bunny-export");
    let tune: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(folder.join("tune.json")).unwrap()).unwrap();
    let fov = (tune["fov_y_deg"].as_f64().unwrap() as f32).to_radians();
    let radius = tune["models"][0]["radius"].as_f64().unwrap() as f32;
    let mut rows = csv::Reader::from_path(folder.join("tune.csv")).unwrap();
    let mut n = 0;
    for r in rows.deserialize::<std::collections::HashMap<String, String>>() {
        let r = r.unwrap();
        let d: f32 = r["distance"].parse().unwrap();
        let s: f32 = r["screen_size"].parse().unwrap();
        assert!(close(s, screen_size(radius, d, fov)), "tune.csv {d}: {s}");
        n += 1;
    }
    assert!(n > 0);
}
