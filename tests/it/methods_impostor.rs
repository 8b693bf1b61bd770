//! `--impostor` on the software adapter (docs/methods.md, "Impostors"): (a) a bunny (flat) and a textured sphere
//! (glTF materials) baked and drawn from one of their atlas's own view directions with 1-frame sampling look like
//! the mesh, and not from beside it; (b) baking is deterministic; (c) view_pop is 0 for a static camera and not
//! under an orbit; (d) describe shows the atlas; (e) the bad inputs get one clear error each; tune places the
//! impostor's switch; discrete-mesh draws the mesh where discrete draws the card.

use crate::common::{
    col, fails_with, gpu, lodbench, read_csv, render_frame, run_into, scene_config,
};
use glam::{Quat, Vec3};
use lodbench::geometry::impostor::{frame_direction, Layout};
use lodbench::scene::{Motion, Scene, SceneDef, SceneKind};
use std::path::Path;

/// One bunny, static, at the impostor level (its mesh LODs switch at tiny distances), seen from frame (3, 2)
/// of an 8 x 8 full atlas at 12 bounding radii, or from `offset` radians beside it.
fn bunny_on_a_frame(offset: f32) -> Scene {
    let extra = [
        "--count",
        "1",
        "--switch-distances",
        "0.001,0.002,0.003",
        "--impostor-distance",
        "0.004",
    ];
    on_a_frame("bunny-grid", &extra, offset)
}

/// The first model of `scene` (flags `extra`, which place the impostor near) alone at the origin, unrotated, seen
/// from frame (3, 2) of an 8 x 8 full atlas (1-frame sampling) at 12 bounding radii with a 15-degree view, or
/// from `offset` radians beside it.
fn on_a_frame(scene: &str, extra: &[&str], offset: f32) -> Scene {
    let mut args = vec![
        "--width",
        "160",
        "--height",
        "120",
        "--frames",
        "1",
        "--fov",
        "15",
        "--impostor",
        "--impostor-frames",
        "8",
        "--impostor-blend",
        "1",
        "--impostor-resolution",
        "1024",
    ];
    args.extend_from_slice(extra);
    let kind = SceneKind::from_name(scene).expect("a scene");
    let mut scene = SceneDef::new(kind, &scene_config(scene, &args))
        .expect("the scene builds")
        .instantiate(1);
    scene.motion = Motion::Static;
    scene.instances.truncate(1);
    let inst = &mut scene.instances[0];
    inst.yaw = 0.0;
    inst.rotation = Quat::IDENTITY;
    inst.position = Vec3::ZERO;
    let f = frame_direction(Layout::Full, 8, 3, 2);
    let f = Quat::from_axis_angle(f.any_orthonormal_vector(), offset) * f;
    let r = scene.models[0].radius;
    scene.eye = f * 12.0 * r;
    scene.forward = -f;
    scene.track = None;
    scene.near = r * 0.5;
    scene.far = r * 30.0;
    scene
}

/// (pixels the two frames cover differently) / (pixels either covers), and the mean absolute difference of
/// the sRGB bytes over the pixels both cover.
fn compare(a: &[u8], b: &[u8], background: [u8; 3]) -> (f64, f64) {
    let covered = |p: &[u8]| p[..3] != background;
    let (mut either, mut one, mut both, mut sum) = (0u64, 0u64, 0u64, 0u64);
    for (p, q) in a.chunks(4).zip(b.chunks(4)) {
        let (x, y) = (covered(p), covered(q));
        either += u64::from(x || y);
        one += u64::from(x != y);
        if x && y {
            both += 1;
            sum += (0..3).map(|c| u64::from(p[c].abs_diff(q[c]))).sum::<u64>();
        }
    }
    (
        one as f64 / either.max(1) as f64,
        sum as f64 / (3 * both.max(1)) as f64,
    )
}

/// (a) From a frame's own direction the impostor is the mesh's orthographic picture, seen here in a narrow
/// perspective (15 degrees, 12 radii away): the outline differs by the parallax of points off the card's plane
/// and the atlas's filtering, the shading by the 8-bit normals and the filter. Measured: 5.0 % of the pixels
/// either frame covers differ in coverage, and the mean byte difference is 2.8 on the pixels both cover (a bunny
/// about 70 pixels across). Tolerances: 8 % and 5 (each about 1.7 times the measurement, for another
/// rasteriser's edges). Drawn 0.2 rad beside the frame (under half the frames' spacing, so the same frame is
/// drawn), the picture no longer matches the view: 10.5 % and 8.5, over both, so the test sees a frame drawn
/// for the wrong direction.
#[test]
fn an_impostor_seen_from_its_own_frame_looks_like_the_mesh() {
    let ctx = gpu();
    let bg = {
        let scene = bunny_on_a_frame(0.0);
        let gpu = lodbench::gpu::SceneGpu::new(&ctx, &scene).unwrap();
        gpu.background_bytes(&ctx).unwrap()
    };
    let on = bunny_on_a_frame(0.0);
    let mesh = render_frame(&ctx, &on, "reference", 0);
    let card = render_frame(&ctx, &on, "discrete", 0);
    let (outline, shading) = compare(&mesh, &card, bg);
    eprintln!("on the frame: outline {outline:.3}, shading {shading:.2}");
    assert!(
        outline < 0.08 && shading < 5.0,
        "outline {outline}, shading {shading}"
    );
    let beside = bunny_on_a_frame(0.2);
    let mesh = render_frame(&ctx, &beside, "reference", 0);
    let card = render_frame(&ctx, &beside, "discrete", 0);
    let (outline, shading) = compare(&mesh, &card, bg);
    eprintln!("beside it: outline {outline:.3}, shading {shading:.2}");
    assert!(
        outline > 0.08 && shading > 5.0,
        "outline {outline}, shading {shading}"
    );
}

/// (a) The same with glTF materials: a textured, flat-shaded sphere (its texture's seam and hard edges; the
/// outline is a circle from every side, so the shading is what is checked): the PBR card's base colour, normals
/// and material from the atlas under the same light. Measured: 1.1 % of the pixels either frame covers differ in
/// coverage, mean byte difference 1.3 where both cover. Tolerances: 2 % and 2.2 (about 1.7 times). 0.2 rad
/// beside the frame the shading is not the view's: 3.4, over the tolerance (the outline, a circle, still
/// matches: 2.6 %).
#[test]
fn a_textured_impostor_seen_from_its_own_frame_looks_like_the_mesh() {
    let ctx = gpu();
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/gltf/faceted-sphere.gltf");
    let file = path.to_str().unwrap();
    let extra = ["--pixel-error", "100000", "--impostor-distance", "0.1"];
    let on = on_a_frame(file, &extra, 0.0);
    assert!(!on.materials.is_empty(), "the file's materials are drawn");
    let (max_outline, max_shading) = (0.02, 2.2);
    let bg = lodbench::gpu::SceneGpu::new(&ctx, &on)
        .unwrap()
        .background_bytes(&ctx)
        .unwrap();
    let (outline, shading) = compare(
        &render_frame(&ctx, &on, "reference", 0),
        &render_frame(&ctx, &on, "discrete", 0),
        bg,
    );
    eprintln!("on the frame: outline {outline:.3}, shading {shading:.2}");
    assert!(
        outline < max_outline && shading < max_shading,
        "outline {outline}, shading {shading}"
    );
    let beside = on_a_frame(file, &extra, 0.2);
    let (outline, shading) = compare(
        &render_frame(&ctx, &beside, "reference", 0),
        &render_frame(&ctx, &beside, "discrete", 0),
        bg,
    );
    eprintln!("beside it: outline {outline:.3}, shading {shading:.2}");
    assert!(
        shading > max_shading,
        "outline {outline}, shading {shading}"
    );
}

/// (b) The same scene and flags bake the same atlas bytes (base colour with coverage, normal with depth), and
/// the atlas is not empty.
#[test]
fn baking_is_deterministic() {
    let ctx = gpu();
    let scene = bunny_on_a_frame(0.0);
    let read = || {
        let gpu = lodbench::gpu::SceneGpu::new(&ctx, &scene).unwrap();
        let a = &gpu.impostors;
        let srgb = lodbench::gpu::read_texture(&ctx, &a.srgb, wgpu::TextureAspect::All, 4).unwrap();
        let linear =
            lodbench::gpu::read_texture(&ctx, &a.linear, wgpu::TextureAspect::All, 4).unwrap();
        (srgb, linear)
    };
    let (a, b) = (read(), read());
    let covered = a.0.chunks(4).filter(|p| p[3] > 0).count();
    assert!(covered > 1024 * 1024 / 20, "{covered} texels covered");
    assert!(a == b, "two bakes differ");
}

/// (c) bunny-grid with impostors beyond the first row: a fixed camera gives view_pop 0 on every frame; an
/// orbit does not, on frames where no LOD changes too; and summary.csv has view_pop_max.
#[rustfmt::skip]
#[test]
fn view_pop_is_zero_for_a_static_camera_only() {
    let base = [
        "--scene", "bunny-grid", "--count", "4", "--frames", "12", "--width", "96", "--height", "72",
        "--method", "discrete,dither", "--impostor", "--impostor-frames", "8", "--impostor-resolution",
        "256", "--switch-distances", "8,12,16", "--impostor-distance", "20",
    ];
    let dir = tempfile::tempdir().unwrap();
    let fixed = read_csv(&run_into(&dir.path().join("fixed"), &[&base[..], &["--camera", "fixed"]].concat()).join("frames.csv"));
    let orbit_dir = run_into(&dir.path().join("orbit"), &[&base[..], &["--camera", "orbit"]].concat());
    let orbit = read_csv(&orbit_dir.join("frames.csv"));
    for m in ["discrete", "dither"] {
        assert!(col(&fixed, m, "lod_mean").iter().any(|&l| l > 3.0), "{m}: no impostor drawn (a mean over 3 needs one at LOD4)");
        assert!(col(&fixed, m, "view_pop").iter().all(|&v| v == 0.0), "{m}: view_pop under a fixed camera");
        let (view, lodpop) = (col(&orbit, m, "view_pop"), col(&orbit, m, "lodpop"));
        assert!(
            view.iter().zip(&lodpop).any(|(&v, &l)| v > 0.0 && l == 0.0),
            "{m}: no view_pop without a switch under the orbit: {view:?}"
        );
    }
    let summary = std::fs::read_to_string(orbit_dir.join("summary.csv")).unwrap();
    assert!(summary.lines().next().unwrap().contains("view_pop_max"));
}

/// (d) describe shows the atlas: frames, layout, resolution and bytes.
#[test]
fn describe_shows_the_atlas() {
    let out = lodbench(
        &[
            "describe",
            "--scene",
            "simple",
            "--impostor",
            "--impostor-layout",
            "hemi",
        ],
        &[],
    );
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    for needle in [
        "impostor atlas",
        "16 x 16 frames (hemi",
        "1024 x 1024 texels",
        "16.0 MiB",
        "from below show",
    ] {
        assert!(text.contains(needle), "{needle} missing from\n{text}");
    }
}

/// (e) N of 0 or 1, an atlas larger than the adapter allows, geomorph, shadows and a unified scene: one error
/// each, naming the problem.
#[test]
fn bad_impostor_input_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    let o = out.to_str().unwrap();
    let run = |extra: &[&str]| {
        let mut a = vec![
            "run",
            "--scene",
            "simple",
            "--frames",
            "2",
            "--count",
            "1",
            "--out",
            o,
            "--impostor",
        ];
        a.extend_from_slice(extra);
        lodbench(&a, &[])
    };
    for n in ["0", "1"] {
        fails_with(
            &run(&["--impostor-frames", n]),
            &["--impostor-frames", "at least 2"],
        );
    }
    // The adapter's limit is known once the GPU is open, after the scene's notes are printed: one error line.
    let big = run(&["--impostor-resolution", "70000", "--method", "discrete"]);
    let stderr = String::from_utf8_lossy(&big.stderr);
    assert!(
        !big.status.success() && !stderr.contains("panicked"),
        "{stderr}"
    );
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error:")).collect();
    assert!(
        errors.len() == 1 && errors[0].contains("largest texture side"),
        "{stderr}"
    );
    fails_with(&run(&["--method", "geomorph"]), &["geomorph", "impostor"]);
    fails_with(
        &run(&["--shadows", "on"]),
        &["--shadows on with --impostor"],
    );
    let out = lodbench(&["describe", "--scene", "terrain", "--impostor"], &[]);
    fails_with(&out, &["--impostor", "terrain"]);
    let glb = dir.path().join("x.glb");
    let out = lodbench(
        &[
            "export",
            "--scene",
            "simple",
            "--impostor",
            "--out",
            glb.to_str().unwrap(),
        ],
        &[],
    );
    fails_with(&out, &["export --impostor", "without --impostor"]);
    assert!(!glb.exists());
}

/// (e) A model with no extent (bounding radius 0) cannot be baked: one error naming the model.
#[test]
fn a_model_with_no_extent_is_refused() {
    let cfg = scene_config("simple", &[]);
    let def = SceneDef::new(SceneKind::Simple, &cfg).unwrap();
    let mut models = def.models.to_vec();
    models[0].radius = 0.0;
    let imp = lodbench::geometry::impostor::ImpostorArgs {
        impostor: true,
        ..Default::default()
    }
    .params()
    .unwrap()
    .unwrap();
    let view = lodbench::scene::impostors::SwitchView {
        pixel_error: 1.0,
        height: 240,
        fov_y: 1.0,
    };
    let e = lodbench::scene::impostors::append(&mut models, &imp, &view, &def.schedule)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("no extent") && e.contains(&models[0].name),
        "{e}"
    );
}

/// tune places the impostor's switch like any other, within the budget, and prints the impostor it assumed
/// with the run that draws it; tuned.glb keeps the mesh levels (a glTF file holds no impostor).
#[test]
fn tune_places_the_impostor_switch() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tune");
    let o = out.to_str().unwrap();
    let args = [
        "tune",
        "--scene",
        "simple",
        "--impostor",
        "--budget-lodpop",
        "0.004",
        "--views",
        "4",
        "--out",
        o,
    ];
    let run = lodbench(&args, &[]);
    let text = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(
        text.contains("octahedral impostor: 16 x 16 frames (full)"),
        "{text}"
    );
    let line = text
        .lines()
        .find(|l| l.contains("the impostor from"))
        .expect("the impostor's switch");
    assert!(line.contains("--impostor --impostor-distance"), "{line}");
    let tune: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("tune.json")).unwrap()).unwrap();
    let pairs = tune["models"][0]["pairs"].as_array().unwrap();
    let card = pairs
        .iter()
        .find(|p| p["lod_to"] == 2)
        .expect("the switch into LOD2, the impostor");
    let worst = card["value_at_switch"]
        .as_f64()
        .expect("a switch within the budget");
    assert!(worst <= 0.004, "{worst}");
}

/// `discrete-mesh` draws each model's last mesh LOD where discrete draws the impostor's card, and is discrete
/// itself without `--impostor` (the same frames, figure for figure).
#[rustfmt::skip]
#[test]
fn discrete_mesh_draws_the_mesh_where_discrete_draws_the_card() {
    let base = [
        "--scene", "bunny-grid", "--count", "4", "--frames", "3", "--width", "96", "--height", "72",
        "--method", "discrete,discrete-mesh", "--switch-distances", "8,12,16",
    ];
    let dir = tempfile::tempdir().unwrap();
    let plain = read_csv(&run_into(&dir.path().join("plain"), &base).join("frames.csv"));
    for c in ["triangles", "rmse", "lodpop"] {
        assert_eq!(col(&plain, "discrete", c), col(&plain, "discrete-mesh", c), "{c} without --impostor");
    }
    let imp = [&base[..], &["--impostor", "--impostor-distance", "20", "--impostor-frames", "4", "--impostor-resolution", "64"]].concat();
    let with = read_csv(&run_into(&dir.path().join("imp"), &imp).join("frames.csv"));
    let (cards, meshes) = (col(&with, "discrete", "triangles"), col(&with, "discrete-mesh", "triangles"));
    assert!(cards.iter().zip(&meshes).all(|(c, m)| c < m), "{cards:?} against {meshes:?}");
    assert_eq!(col(&with, "discrete-mesh", "triangles"), col(&plain, "discrete", "triangles"));
}
