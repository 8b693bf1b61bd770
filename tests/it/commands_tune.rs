//! `lodbench tune` through the binary: the search finds a threshold whose distance is known in closed form, the
//! tuned glTF reads back with the switches it was given, every engine file reads back as the same switches, and
//! bad budgets are refused in one line.

use crate::common::{fails_with, lodbench};
use lodbench::results::engines;
use std::path::Path;

fn fixture(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/gltf")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// pop-shading.gltf's switch turns an unlit unit quad from red to blue, its outline unchanged: seen head-on (one
/// view, the scene's own) from distance d on a W x H viewport with vertical field of view 60 degrees, the quad
/// covers (H / (2 d tan 30))^2 pixels, each of which changes by 255 in two of its three channels, so lodpop =
/// (H / (2 d tan 30)) sqrt(2 / (3 W H)), and the budget B is met from d* = (H / (2 tan 30)) sqrt(2 / (3 W H)) / B
/// outwards. tune finds d* to within 4 %: the quad's covered pixels are its area rounded at its edges, and at
/// 320x240 and B = 0.1 it is about 34 pixels wide there, so a row and a column of pixels more or less is at most 6 %
/// of its area, 3 % of lodpop and of the distance; the search's bisection adds 0.6 % (measured: 3.0 % farther).
/// Its figure at the switch is within the budget.
#[test]
fn tune_finds_a_switch_known_in_closed_form() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tune");
    let (w, h, budget) = (320.0f64, 240.0f64, 0.1f64);
    #[rustfmt::skip]
    let r = lodbench(&[
        "tune", "--scene", &fixture("pop-shading.gltf"), "--budget-lodpop", "0.1", "--views", "1",
        "--width", "320", "--height", "240", "--out", out.to_str().unwrap(),
    ], &[]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let t = json(&out.join("tune.json"));
    let pair = &t["models"][0]["pairs"][0];
    let found = pair["switch_distance"].as_f64().unwrap();
    let tan = (30f64).to_radians().tan();
    let expected = h / (2.0 * tan) * (2.0 / (3.0 * w * h)).sqrt() / budget;
    assert!(
        (found / expected - 1.0).abs() < 0.04,
        "switch {found}, closed form {expected}"
    );
    assert!(pair["value_at_switch"].as_f64().unwrap() <= budget);
    assert_eq!(t["views"].as_array().unwrap().len(), 1);
    // The view's curve from the farthest grid distance in to the first that breaks the budget (nearer than d*),
    // then the bisection's 5 steps.
    let csv = std::fs::read_to_string(out.join("tune.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    let grid = rows.iter().filter(|l| l.ends_with(",false")).count();
    assert_eq!(rows.len() - grid, 5, "{csv}");
    assert!((2..24).contains(&grid), "{csv}");

    // The tuned file reads back with the switch it was given, exactly.
    let d = lodbench(
        &[
            "describe",
            "--scene",
            out.join("tuned.glb").to_str().unwrap(),
            "--json",
        ],
        &[],
    );
    assert!(d.status.success(), "{}", String::from_utf8_lossy(&d.stderr));
    let desc: serde_json::Value = serde_json::from_slice(&d.stdout).unwrap();
    let lods = &desc["models"][0]["lods"];
    assert_eq!(
        lods[1]["switch_distance"].as_f64().unwrap() as f32,
        found as f32
    );

    // Each engine's file holds the same switch (Unity's and Unreal's as screen sizes of the sphere).
    let radius = t["models"][0]["radius"].as_f64().unwrap();
    let fov = t["fov_y_deg"].as_f64().unwrap().to_radians();
    let size = radius / (found * (fov * 0.5).tan());
    let unreal = json(&out.join("engines/unreal-screen-sizes.json"));
    assert!((unreal[0]["screen_size"][1].as_f64().unwrap() - size).abs() < 1e-5 * size);
    let unity = json(&out.join("engines/unity-lodgroup.json"));
    let h0 = unity[0]["lods"][0]["screenRelativeTransitionHeight"]
        .as_f64()
        .unwrap();
    assert!((h0 - size).abs() < 1e-5 * size, "{h0} {size}");
    let godot = json(&out.join("engines/godot-visibility-ranges.json"));
    assert!(
        (godot[0][1][1]["visibility_range_begin"].as_f64().unwrap() - found).abs() < 1e-4 * found
    );
    let three = std::fs::read_to_string(out.join("engines/threejs-lod.js")).unwrap();
    let three = engines::from_threejs(&three).expect("threejs-lod.js's table reads back");
    assert_eq!(three.len(), 1);
    assert_eq!(three[0].1, [found as f32]);

    // Every engine file, read back as written into its engine's settings, converts back to the switches tune.json
    // gives its engines (the file's own conversion, docs/engines.md).
    let models: Vec<engines::EngineModel> = serde_json::from_value(t["engines"].clone()).unwrap();
    let read = |f: &str| std::fs::read_to_string(out.join("engines").join(f)).unwrap();
    let unity: Vec<engines::UnityLodGroup> =
        serde_json::from_str(&read("unity-lodgroup.json")).unwrap();
    let unreal: Vec<engines::UnrealLods> =
        serde_json::from_str(&read("unreal-screen-sizes.json")).unwrap();
    let godot: Vec<(String, Vec<engines::GodotNode>)> =
        serde_json::from_str(&read("godot-visibility-ranges.json")).unwrap();
    let bevy: Vec<(String, Vec<engines::BevyRange>)> =
        serde_json::from_str(&read("bevy-visibility-ranges.json")).unwrap();
    let close = |a: &[f32], b: &[f32]| {
        a.len() == b.len()
            && a.iter()
                .zip(b)
                .all(|(x, y)| (x - y).abs() <= 1e-4 * y.abs())
    };
    for (k, m) in models.iter().enumerate() {
        let fov = fov as f32;
        assert!(close(&engines::from_unity(&unity[k], fov).0, &m.switches));
        assert!(close(
            &engines::from_unreal(&unreal[k], m.radius, fov),
            &m.switches
        ));
        assert!(close(&engines::from_godot(&godot[k].1).0, &m.switches));
        assert!(close(&engines::from_bevy(&bevy[k].1).0, &m.switches));
        assert_eq!(
            (godot[k].0.as_str(), bevy[k].0.as_str()),
            (m.name.as_str(), m.name.as_str())
        );
        assert_eq!(m.triangles.len(), m.switches.len() + 1, "{m:?}");
    }
    let readme = read("README.md");
    assert!(
        readme.contains("320x240") && readme.contains("## Unity"),
        "{readme}"
    );
}

#[test]
fn a_budget_is_required_and_checked() {
    let scene = fixture("pop-shading.gltf");
    fails_with(
        &lodbench(&["tune", "--scene", &scene], &[]),
        &["tune needs a budget", "--budget-lodpop", "--budget-jod"],
    );
    fails_with(
        &lodbench(&["tune", "--scene", &scene, "--budget-lodpop", "2"], &[]),
        &["--budget-lodpop 2"],
    );
    fails_with(
        &lodbench(&["tune", "--scene", &scene, "--budget-jod", "11"], &[]),
        &["--budget-jod 11"],
    );
    fails_with(
        &lodbench(
            &["tune", "--scene", "terrain", "--budget-lodpop", "0.01"],
            &[],
        ),
        &["unified scene"],
    );
}

/// The default search measures each view from the farthest grid distance in to the first that breaks the budget;
/// `--full-grid` measures every grid distance. Both give the same switches, rules, engine files and tuned glTF
/// (the bunny's chain of 4 pairs, 3 views; tune.json differs only in its `full_grid` setting), and every sample
/// of the default is one of the full grid's, with the same figures: the distances it leaves out are not read.
#[test]
fn stopping_each_curve_at_its_first_break_changes_no_switch() {
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        #[rustfmt::skip]
        let mut args = vec![
            "tune", "--scene", "bunny-sweep", "--budget-lodpop", "0.004", "--views", "3", "--distances", "12",
            "--width", "160", "--height", "120", "--out", out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let r = lodbench(&args, &[]);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        out
    };
    let (lazy, full) = (run("lazy", &[]), run("full", &["--full-grid"]));
    let mut tunes = [json(&lazy.join("tune.json")), json(&full.join("tune.json"))];
    assert_eq!(tunes[1]["settings"]["full_grid"], true);
    for t in &mut tunes {
        t["settings"].as_object_mut().unwrap().remove("full_grid");
    }
    assert!(tunes[0]["models"][0]["pairs"].as_array().unwrap().len() >= 3);
    assert_eq!(tunes[0], tunes[1]);
    let bytes = |p: std::path::PathBuf| std::fs::read(p).unwrap();
    for f in [
        "rules.csv",
        "tuned.glb",
        "engines/unreal-screen-sizes.json",
        "engines/threejs-lod.js",
    ] {
        assert!(bytes(lazy.join(f)) == bytes(full.join(f)), "{f} differs");
    }
    let csv = |p: &Path| std::fs::read_to_string(p.join("tune.csv")).unwrap();
    let (few, all) = (csv(&lazy), csv(&full));
    let all_rows: std::collections::HashSet<&str> = all.lines().collect();
    assert!(
        few.lines().all(|l| all_rows.contains(l)),
        "a sample the full grid lacks"
    );
    assert!(
        few.lines().count() < all.lines().count(),
        "{} rows against {}",
        few.lines().count(),
        all.lines().count()
    );
}
