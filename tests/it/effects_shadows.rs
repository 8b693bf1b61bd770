//! `--shadows on` on the software adapter: what casts into the shadow map under `--shadow-lod follow`, and
//! the shadow in the frames.

use crate::common::{col, read_csv, run_into, scene_config};
use lodbench::effects::shadow::{light_matrix, Caster};
use lodbench::gpu::readback::read_texture;
use lodbench::gpu::scene_gpu::ShadowMap;
use lodbench::gpu::shadow_pass::ShadowPass;
use lodbench::gpu::{DrawList, GpuContext, SceneGpu};
use lodbench::measure::FrameDriver;
use lodbench::methods::common::{shadow_list, FrameInput, Method};
use lodbench::methods::{alpha::Alpha, discrete::Discrete};
use lodbench::scene::schedule::InstanceState;
use lodbench::scene::{SceneDef, SceneKind};

/// Shadow map `ShadowMap::lit(0)` as `method` casts with the bunny at `state`, as read-back depth bytes.
fn shadow_map(
    ctx: &GpuContext,
    gpu: &SceneGpu,
    input: &FrameInput<'_>,
    method: &dyn Method,
) -> Vec<u8> {
    let pass = ShadowPass::new(gpu, input.scene.instances.len() as u32);
    let mut list = DrawList::default();
    shadow_list(
        input,
        |i| method.shadow_caster(input.states, i, false),
        &mut list,
    );
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    pass.encode(gpu, &mut encoder, ShadowMap::lit(0), &list);
    ctx.queue.submit([encoder.finish()]);
    ctx.wait_idle().unwrap();
    ctx.check_errors().unwrap();
    read_texture(
        ctx,
        &gpu.shadows.maps[ShadowMap::lit(0).index()],
        wgpu::TextureAspect::DepthOnly,
        4,
    )
    .unwrap()
}

/// Under `--shadow-lod follow` a blending method (alpha) casts both LODs of a t-instance dithered at k: at
/// k = 0 its shadow map is discrete's for lod_from, bit for bit, at k = 1 discrete's for lod_to (discrete casts
/// the LOD it shows), and half way it is neither; the two LODs' maps differ, so the test can tell them apart.
#[test]
fn follow_shadow_at_k_0_and_1_is_discretes() {
    let ctx = crate::common::gpu();
    let cfg = scene_config(
        "bunny-sweep",
        &[
            "--shadows",
            "on",
            "--shadow-size",
            "256",
            "--width",
            "96",
            "--height",
            "72",
        ],
    );
    let scene = SceneDef::new(SceneKind::BunnySweep, &cfg)
        .unwrap()
        .instantiate(1);
    assert_eq!(
        scene.ground,
        Some(1),
        "the bunny scenes get a ground with --shadows on"
    );
    let gpu = SceneGpu::new(&ctx, &scene).unwrap();
    let mut driver = FrameDriver::new(&scene);
    driver.advance(0);
    let spheres: Vec<_> = [lodbench::geometry::projection::Sphere::new(
        scene.instance_position(0, 0),
        scene.models[0].radius,
    )]
    .to_vec();
    let (light, _) = light_matrix(
        glam::Vec3::from(lodbench::gpu::LIGHT_DIR),
        &spheres,
        3.0 * spheres[0].radius,
    );
    gpu.write_camera(&scene.camera(0));
    gpu.write_light(&light, 0.0);
    let (alpha, discrete) = (Alpha::new(&gpu, &scene), Discrete::new(&gpu, &scene));
    let map = |state: InstanceState, method: &dyn Method| {
        let states = [state, InstanceState::steady(0)];
        let input = FrameInput {
            states: &states,
            ..driver.input(0)
        };
        shadow_map(&ctx, &gpu, &input, method)
    };
    let t = |k| InstanceState {
        lod_from: 0,
        lod_to: 2,
        k,
    };
    let lod0 = map(t(0.0), &discrete);
    let lod2 = map(t(1.0), &discrete);
    assert_ne!(lod0, lod2, "LOD0's and LOD2's shadows differ");
    assert!(
        lod0.chunks(4)
            .any(|d| f32::from_le_bytes(d.try_into().unwrap()) < 1.0),
        "the bunny casts"
    );
    assert_eq!(
        map(t(0.0), &alpha),
        lod0,
        "alpha at k = 0 casts lod_from, as discrete does"
    );
    assert_eq!(
        map(t(1.0), &alpha),
        lod2,
        "alpha at k = 1 casts lod_to, as discrete does"
    );
    let half = map(t(0.5), &alpha);
    assert!(
        half != lod0 && half != lod2,
        "half way, both LODs cast (dithered)"
    );
    assert_eq!(
        alpha.shadow_caster(&[t(0.5)], 0, false),
        Caster::Dither {
            from: 0,
            to: 2,
            k: 0.5
        }
    );
}

/// A run with `--shadows on`: the ground receives the bunny's shadow (frames differ from the run without
/// shadows, and part of the ground is darker than the rest), the run is deterministic, the ground is not in lod_mean, and the
/// methods' rmse against a reference with its own LOD0 shadows is 0 where no LOD differs (frames before the
/// first transition, where discrete shows LOD0).
#[test]
fn shadows_darken_the_ground_and_discrete_at_lod0_matches_the_reference() {
    let tmp = tempfile::tempdir().unwrap();
    let args = |extra: &'static [&'static str]| {
        let mut a = vec![
            "--scene",
            "bunny-sweep",
            "--method",
            "reference,discrete,alpha",
            "--width",
            "96",
            "--height",
            "72",
            "--frames",
            "60",
            "--warmup",
            "0",
            "--rounds",
            "1",
            "--dump-frames",
            "--dump-every",
            "59",
        ];
        a.extend_from_slice(extra);
        a
    };
    let on = run_into(
        &tmp.path().join("on"),
        &args(&["--shadows", "on", "--shadow-size", "256"]),
    );
    let again = run_into(
        &tmp.path().join("again"),
        &args(&["--shadows", "on", "--shadow-size", "256"]),
    );
    let off = run_into(&tmp.path().join("off"), &args(&[]));
    let (a, b, c) = (
        read_csv(&on.join("frames.csv")),
        read_csv(&again.join("frames.csv")),
        read_csv(&off.join("frames.csv")),
    );
    for m in ["discrete", "alpha"] {
        assert_eq!(
            col(&a, m, "rmse"),
            col(&b, m, "rmse"),
            "{m}: same flags, same rmse"
        );
        assert_eq!(
            col(&a, m, "lod_mean"),
            col(&c, m, "lod_mean"),
            "{m}: the ground is not in lod_mean"
        );
    }
    let img = |dir: &std::path::Path| {
        lodbench::raster::read(dir.join("frames/bunny-sweep_discrete_c1_f00000_reference.png"))
            .unwrap()
    };
    let (lit, plain) = (img(&on), img(&off));
    assert_ne!(lit, plain);
    // The ground (grey) fills the lower half with shadows on; some of its pixels are in the bunny's shadow,
    // darker than the lit ground by more than 30 levels.
    let mut ground: Vec<u8> = (36..72)
        .flat_map(|y| (0..96).map(move |x| (x, y)))
        .map(|(x, y)| lit.get_pixel(x, y))
        .filter(|p| p[0] == p[1] && p[1] == p[2])
        .map(|p| p[0])
        .collect();
    ground.sort();
    let (darkest, lightest) = (ground[0], ground[ground.len() - 1]);
    assert!(
        darkest + 30 < lightest,
        "a shadow on the ground: grey from {darkest} to {lightest}"
    );
    // Before the first transition discrete shows LOD0, as the reference does: the same shadow, rmse 0.
    let t = col(&a, "discrete", "t_instances");
    let first = t.iter().position(|&x| x > 0.0).unwrap_or(t.len());
    assert!(first > 0);
    assert!(col(&a, "discrete", "rmse")[..first]
        .iter()
        .all(|&r| r == 0.0));
}

/// The unified scenes refuse `--shadows on`, and a shadow map out of range is named: one error each.
#[test]
fn bad_shadow_flags_are_refused() {
    use clap::Parser;
    use lodbench::cli::{Cli, Command};
    for (args, needle) in [
        (
            vec!["--scene", "terrain", "--shadows", "on"],
            "--shadows on",
        ),
        (
            vec![
                "--scene",
                "bunny-sweep",
                "--shadows",
                "on",
                "--shadow-size",
                "8",
            ],
            "--shadow-size",
        ),
    ] {
        let mut argv = vec!["lodbench", "run"];
        argv.extend(args);
        let Command::Run(a) = Cli::try_parse_from(argv).unwrap().command else {
            unreachable!()
        };
        let err = lodbench::cli::run_config::RunConfig::from_args(&a)
            .unwrap_err()
            .to_string();
        assert!(err.contains(needle), "{err}");
    }
}
