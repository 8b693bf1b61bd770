//! The Stanford-bunny scenes of Sheliemietiev et al. 2023, section 6 (or `--mesh`): one model, its path, and
//! with `--shadows on` a ground under it.
//!
//! - `bunny-sweep`: the popping experiment (steps 1-4): one bunny starts at the nearest distance that shows all
//!   of it at LOD0 and moves at constant speed along the line of sight until past the last switch band, then
//!   back the same way. The camera is fixed.
//! - `bunny-grid`: the performance experiment, eq. 1: n bunnies on the +x axis, evenly spaced by
//!   dx = (w - camera_x) / n, the camera looking along +x; nothing is culled, so bunnies behind others are
//!   still drawn (the paper turns occlusion culling off).

use crate::error::{Error, Result};
use crate::geometry::lod::{self, LodChain, DEFAULT_TARGETS};
use crate::geometry::mesh::Mesh;
use crate::geometry::projection::{error_at_distance, fit_distance, Sphere};
use crate::scene::config::SceneConfig;
use crate::scene::kind::{ProfileValues, SceneKind, SweepStart};
use crate::scene::model::{Instance, Layout, Model, ModelSet, Motion, SwitchSource};
use crate::scene::schedule::ScheduleParams;
use glam::Vec3;
use serde::Serialize;

/// The Stanford bunny, npm `bunny@1.0.1` (see scenes/README.md), compiled in so the binary needs no files.
pub const BUNNY_OBJ: &[u8] = include_bytes!("../../scenes/bunny.obj");

/// The built-in bunny's name in error messages.
const BUILT_IN: &str = "scenes/bunny.obj (built in)";

/// The built-in bunny's `mesh_source` (describe, run.json).
pub const BUILT_IN_SOURCE: &str = "scenes/bunny.obj (npm bunny@1.0.1, built in)";

/// Colour of the bunny (linear RGB).
pub const BUNNY_COLOR: [f32; 3] = [0.72, 0.45, 0.28];

/// Yaw of the bunny instances: the classic three-quarter view, face to the right.
pub const BUNNY_YAW: f32 = 1.0;

/// The built-in bunny's mesh.
pub fn built_in_mesh() -> Result<Mesh> {
    Mesh::parse_obj(BUILT_IN, BUNNY_OBJ)
}

/// Where the bunny scenes' bunnies are: bunny-sweep's bunny moves from `near` to `far` and back, bunny-grid's
/// bunnies stand between them (eq. 1 of Sheliemietiev et al. 2023). Distances from the camera to the
/// bounding-sphere centre.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BunnyPath {
    pub near: f32,
    pub far: f32,
    /// Nearest distance at which the model's bounding sphere fits the view (the narrower of the two fovs):
    /// `near` is never less, so the camera is never inside the model.
    pub fit: f32,
    /// How many switches, from LOD1 on, lie nearer than `near` (their band starts nearer): the path never
    /// reaches them, and every frame shows LOD `unreached` or coarser.
    pub unreached: usize,
    pub start: SweepStart,
}

impl BunnyPath {
    /// The path for `m` at this viewport: it starts at `fit`, or, when `fit` lies inside a switch's transition
    /// band, just past that band (so frame 0 is never in a transition), and ends past the last band with a
    /// margin so the coarsest LOD is seen for a while (at least a quarter beyond the start).
    ///
    /// A close-up (`SweepStart::CloseUp`) starts at `fit` when the first band lies beyond it, else at 0.9 of
    /// the first band's near edge, and reaches every switch.
    pub fn new(
        m: &Model,
        schedule: &ScheduleParams,
        start: SweepStart,
        width: u32,
        height: u32,
        fov_y: f32,
    ) -> Self {
        let (b, h) = (schedule.band, schedule.hysteresis);
        let fit = fit_distance(m.radius, width, height, fov_y);
        let first_band = m.switches.first().map(|s| s * (1.0 - h) * (1.0 - b));
        let (near, unreached) = match (start, first_band) {
            (SweepStart::CloseUp, Some(fb)) if fit >= fb * 0.95 => (fb * 0.9, 0),
            (SweepStart::CloseUp, _) => (fit, 0),
            (SweepStart::Fit, _) => {
                let unreached = m
                    .switches
                    .iter()
                    .take_while(|&&s| s * (1.0 - h) * (1.0 - b) < fit)
                    .count();
                let near = match unreached {
                    0 => fit,
                    n => fit.max(m.switches[n - 1] * (1.0 + h) * (1.0 + b) * 1.01),
                };
                (near, unreached)
            }
        };
        let last = m.switches.last().copied().unwrap_or(m.radius);
        let far = (last * (1.0 + h) * (1.0 + b) * 1.15).max(near * 1.25);
        BunnyPath {
            near,
            far,
            fit,
            unreached,
            start,
        }
    }

    /// What a user should know before trusting bunny scene `kind` with model `m` on this path: a close-up that
    /// starts inside the model, or switches the path never reaches. One line (empty when there is nothing to
    /// say).
    pub fn notes(&self, kind: SceneKind, m: &Model) -> Vec<String> {
        if self.near < m.radius {
            return vec![format!(
                "{}: a close-up (--sweep-start close-up): the path starts at {:.4}, inside the model's bounding \
                 sphere (radius {:.4}), so the camera may be inside the model",
                kind.name(),
                self.near,
                m.radius
            )];
        }
        if self.unreached == 0 {
            return Vec::new();
        }
        let lods: Vec<String> = m.switches[..self.unreached]
            .iter()
            .enumerate()
            .map(|(j, s)| format!("LOD{} at {s:.4}", j + 1))
            .collect();
        let start = match kind {
            SceneKind::BunnyGrid => "the first bunny",
            _ => "the sweep's start",
        };
        vec![format!(
            "{}: the switch to {} lies nearer than {start} ({:.4}, where the model's bounding sphere fits the \
             view): not reached by the sweep; a smaller --pixel-error moves the switches farther",
            kind.name(),
            lods.join(", "),
            self.near
        )]
    }
}

/// Where a user's mesh (`--mesh`) switches to LOD1, LOD2 and LOD3, as multiples of the distance at which it fits
/// the view: its LOD chain is built by error ([`LodChain::build_by_error`]), LOD i the coarsest simplification
/// whose error projects to the pixel error no nearer than `USER_SWITCH_FIT_MULTIPLES[i - 1]` x that distance.
/// A chain by triangle fraction puts a dense scan's switches nearer than the view fits it (its LODs lose almost
/// nothing), and a sweep from the fit distance then shows no transition; these put every switch on the path
/// (the first one past the transition band at the default --band and --hysteresis), an octave apart.
pub const USER_SWITCH_FIT_MULTIPLES: [f32; 3] = [1.6, 3.2, 6.4];

/// What a bunny scene has beyond its models: the path, and the ground with `--shadows on`.
#[derive(Debug, Clone, Copy)]
pub struct BunnyParts {
    pub path: BunnyPath,
    /// `--shadows on`: the ground's instance (static, always LOD0).
    pub ground: Option<Instance>,
}

/// Bunny scene `kind`: the bunny (`--mesh` or the built-in one) with its LOD chain, its path, and the ground.
pub fn def(
    kind: SceneKind,
    cfg: &SceneConfig,
    pv: &ProfileValues,
    fov_y: f32,
) -> Result<(ModelSet, BunnyParts)> {
    let started = std::time::Instant::now();
    let (mesh, mesh_source, file) = match &cfg.mesh {
        Some(p) => (
            Mesh::load(p)?,
            p.display().to_string(),
            p.display().to_string(),
        ),
        None => (
            built_in_mesh()?,
            BUILT_IN_SOURCE.to_string(),
            BUILT_IN.to_string(),
        ),
    };
    let (model, note) = bunny_model(kind, &file, &mesh, cfg, pv, fov_y)?;
    let path = BunnyPath::new(
        &model,
        &cfg.schedule,
        pv.sweep_start,
        pv.width,
        pv.height,
        fov_y,
    );
    let lod_generation_ms = started.elapsed().as_secs_f64() * 1e3;
    let mut models = vec![model];
    let ground = cfg.shadows.map(|_| {
        let (ground, position) = ground_model(&models[0], path.far);
        models.push(ground);
        Instance {
            model: 1,
            position,
            yaw: 0.0,
            rotation: glam::Quat::IDENTITY,
            scale: Vec3::ONE,
        }
    });
    let set = ModelSet {
        models,
        mesh_source,
        lod_generation_ms,
        notes: note.into_iter().collect(),
    };
    Ok((set, BunnyParts { path, ground }))
}

/// The model of bunny scene `kind` from `mesh`, read from `file` (named in error messages).
fn bunny_model(
    kind: SceneKind,
    file: &str,
    mesh: &Mesh,
    cfg: &SceneConfig,
    pv: &ProfileValues,
    fov_y: f32,
) -> Result<(Model, Option<String>)> {
    let height = pv.height;
    mesh.check_area(file)?;
    let Sphere {
        centre: center,
        radius,
    } = mesh.bounding_sphere();
    if !(radius.is_finite() && radius > 0.0) {
        return Err(Error::Mesh {
            path: file.to_string(),
            problem: "has zero extent".into(),
        });
    }
    let (chain, note) = match cfg.mesh {
        None => (LodChain::build(file, mesh, &DEFAULT_TARGETS)?, None),
        Some(_) => {
            let fit = fit_distance(radius, pv.width, height, fov_y);
            let pixel_error = cfg.pixel_error(kind, height);
            let errors: Vec<f32> = USER_SWITCH_FIT_MULTIPLES
                .iter()
                .map(|m| error_at_distance(m * fit, 1.0, pixel_error, height, fov_y))
                .collect();
            LodChain::build_by_error(file, mesh, &errors, cfg.simplify)?
        }
    };
    let scale = 1.0;
    let (switches, switch_source) =
        cfg.switches_or("the bunny", (chain.lods.len(), radius, fov_y), || {
            (
                lod::switch_distances(&chain, scale, cfg.pixel_error(kind, height), height, fov_y),
                SwitchSource::PixelError,
            )
        })?;
    cfg.schedule.check_switches("bunny", &switches)?;
    Ok((
        Model {
            name: "bunny".into(),
            color: BUNNY_COLOR,
            lod_colors: Vec::new(),
            spin_per_frame: 0.0,
            chain,
            switches,
            switch_source,
            center,
            radius: radius * scale,
            scale,
            deformed_reach: None,
        },
        note,
    ))
}

/// The bunny scenes' ground with `--shadows on`: a grey quad under the bunny's lowest point, from behind the
/// camera (at the origin, looking along +x) to past the path's far end, as wide as half its length; one LOD,
/// no switches. Returns the model and its position.
fn ground_model(bunny: &Model, far: f32) -> (Model, Vec3) {
    let r = bunny.radius;
    let lowest = bunny.chain.lods[0]
        .mesh
        .positions
        .iter()
        .map(|p| (p[1] - bunny.center.y) * bunny.scale)
        .fold(0.0f32, f32::min);
    let (hx, x_mid) = ((far + 3.0 * r) * 0.5, (far + r) * 0.5);
    let hz = (hx * 0.5).max(3.0 * r);
    let positions = vec![
        [-hx, 0.0, -hz],
        [hx, 0.0, -hz],
        [hx, 0.0, hz],
        [-hx, 0.0, hz],
    ];
    let mesh = Mesh {
        normals: vec![[0.0, 1.0, 0.0]; 4],
        aux: vec![[0.0; 4]; 4],
        indices: vec![0, 2, 1, 0, 3, 2],
        positions,
        data: Default::default(),
        parts: Vec::new(),
    };
    let model = Model {
        name: "ground".into(),
        color: [0.45, 0.45, 0.45],
        lod_colors: Vec::new(),
        spin_per_frame: 0.0,
        chain: LodChain {
            lods: vec![lod::Lod {
                mesh,
                target_fraction: 1.0,
                error_abs: 0.0,
            }],
        },
        switches: Vec::new(),
        switch_source: SwitchSource::Ground,
        center: Vec3::ZERO,
        radius: (hx * hx + hz * hz).sqrt(),
        scale: 1.0,
        deformed_reach: None,
    };
    (model, Vec3::new(x_mid, lowest, 0.0))
}

/// The bunnies of bunny scene `kind` for `count` (bunny-sweep always has one), model `m` on `path`; the camera
/// at the origin looking along +x.
pub fn layout(kind: SceneKind, m: &Model, path: &BunnyPath, count: u32) -> Layout {
    let (near_d, far_d) = (path.near, path.far);
    let yaw = BUNNY_YAW;
    let (instances, motion, far_plane) = match kind {
        SceneKind::BunnyGrid => {
            // eq. 1: dx = (w - camera_x) / n, objects from the nearest fully visible distance on.
            let camera_x = 0.0;
            let w = camera_x + far_d;
            let dx = (w - camera_x) / count as f32;
            let inst = (0..count)
                .map(|i| Instance {
                    model: 0,
                    position: Vec3::new(camera_x + near_d + i as f32 * dx, 0.0, 0.0),
                    yaw,
                    rotation: glam::Quat::IDENTITY,
                    scale: Vec3::ONE,
                })
                .collect();
            (inst, Motion::Static, near_d + w + 2.0 * m.radius)
        }
        _ => (
            vec![Instance {
                model: 0,
                position: Vec3::new(near_d, 0.0, 0.0),
                yaw,
                rotation: glam::Quat::IDENTITY,
                scale: Vec3::ONE,
            }],
            Motion::SweepX {
                near: near_d,
                far: far_d,
            },
            far_d + 2.0 * m.radius,
        ),
    };
    Layout {
        instances,
        motion,
        near: m.radius * 0.02,
        far: far_plane,
        eye: Vec3::ZERO,
        forward: Vec3::X,
        track: None,
        unified: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::{Cli, Command};
    use crate::scene::def::SceneDef;
    use crate::scene::description::NOT_REACHED;
    use clap::Parser;

    fn cfg(extra: &[&str]) -> SceneConfig {
        let mut argv = vec!["lodbench", "describe", "--scene", "bunny-sweep"];
        argv.extend_from_slice(extra);
        match Cli::try_parse_from(argv).unwrap().command {
            Command::Describe(d) => SceneConfig::from_args(&d.scene_args).unwrap(),
            _ => unreachable!(),
        }
    }

    #[test]
    fn sweep_passes_every_switch_starting_at_lod0() {
        let def = SceneDef::new(SceneKind::BunnySweep, &cfg(&[])).unwrap();
        let s = def.instantiate(1);
        let m = &s.models[0];
        let d0 = s.instance_distance(0, 0);
        let dmax = (0..s.frames)
            .map(|f| s.instance_distance(0, f))
            .fold(0.0, f32::max);
        assert!(d0 < m.switches[0] * 0.95);
        assert!(dmax > m.switches.last().unwrap() * 1.05);
    }

    #[test]
    fn grid_follows_equation_1() {
        let c = cfg(&["--count", "50,7"]);
        let def = SceneDef::new(SceneKind::BunnyGrid, &c).unwrap();
        assert_eq!(def.counts, vec![50, 7]);
        let s = def.instantiate(7);
        assert_eq!(s.instances.len(), 7);
        let xs: Vec<f32> = s.instances.iter().map(|i| i.position.x).collect();
        let dx = xs[1] - xs[0];
        for w in xs.windows(2) {
            assert!((w[1] - w[0] - dx).abs() < 1e-3);
        }
        let last = *s.models[0].switches.last().unwrap();
        // w - camera_x = n dx reaches past the last switch band.
        assert!(7.0 * dx > last * 1.05);
        assert!(s
            .instances
            .iter()
            .all(|i| i.position.y == 0.0 && i.position.z == 0.0));
        assert_eq!(s.forward, Vec3::X);
    }

    #[test]
    fn dolly_moves_the_camera_through_the_same_relative_geometry() {
        let fixed = SceneDef::new(SceneKind::BunnySweep, &cfg(&[]))
            .unwrap()
            .instantiate(1);
        let dolly = SceneDef::new(SceneKind::BunnySweep, &cfg(&["--camera", "dolly"]))
            .unwrap()
            .instantiate(1);
        let mut eyes = Vec::new();
        for f in [0, 1, fixed.frames / 4, fixed.frames / 2, fixed.frames - 1] {
            // The bunny stays put; the eye moves.
            assert_eq!(dolly.instance_position(0, f), dolly.instance_position(0, 0));
            eyes.push(dolly.camera(f).eye);
            let d = (fixed.instance_distance(0, f), dolly.instance_distance(0, f));
            assert!((d.0 - d.1).abs() <= 1e-4 * d.0, "frame {f}: {d:?}");
            // Object space to clip space is the same transform.
            let (a, b) = (
                fixed.camera(f).view_proj() * fixed.instance_matrix(0, f),
                dolly.camera(f).view_proj() * dolly.instance_matrix(0, f),
            );
            let scale = a.to_cols_array().iter().fold(0f32, |m, x| m.max(x.abs()));
            for (x, y) in a.to_cols_array().iter().zip(b.to_cols_array()) {
                assert!((x - y).abs() <= 1e-4 * scale, "frame {f}: {a} vs {b}");
            }
        }
        assert!(eyes[2].distance(eyes[0]) > 1.0, "{eyes:?}");
    }

    #[test]
    fn orbit_keeps_the_distance_and_moves_the_eye() {
        let def = SceneDef::new(SceneKind::BunnySweep, &cfg(&["--camera", "orbit"])).unwrap();
        let s = def.instantiate(1);
        let fixed = SceneDef::new(SceneKind::BunnySweep, &cfg(&[]))
            .unwrap()
            .instantiate(1);
        for f in [0, 30, 60, 90, 500] {
            let (a, b) = (s.instance_distance(0, f), fixed.instance_distance(0, f));
            assert!((a - b).abs() < 1e-3 * b, "frame {f}: {a} vs {b}");
        }
        assert_eq!(s.camera(0).eye, fixed.camera(0).eye);
        assert!(
            s.camera(60).eye.distance(fixed.camera(60).eye) > 0.1 * fixed.instance_distance(0, 60)
        );
    }

    #[test]
    fn switch_override_must_match_lod_count() {
        let c = cfg(&["--switch-distances", "10,20"]);
        assert!(SceneDef::new(SceneKind::BunnySweep, &c).is_err());
        let c = cfg(&["--switch-distances", "10,20,40"]);
        let def = SceneDef::new(SceneKind::BunnySweep, &c).unwrap();
        assert_eq!(def.models[0].switches, vec![10.0, 20.0, 40.0]);
    }

    #[test]
    fn switch_distance_halves_with_double_pixel_error() {
        let a = SceneDef::new(SceneKind::BunnySweep, &cfg(&["--pixel-error", "1"])).unwrap();
        let b = SceneDef::new(SceneKind::BunnySweep, &cfg(&["--pixel-error", "2"])).unwrap();
        for (x, y) in a.models[0].switches.iter().zip(&b.models[0].switches) {
            assert!((x / y - 2.0).abs() < 1e-3);
        }
    }

    /// The bunny scenes' default pixel error is one pixel at 800x600, so the switch distances are the same at
    /// every viewport height; a close-up keeps one pixel of its own viewport.
    #[test]
    fn bunny_switches_are_the_papers_at_every_profile() {
        let at = |extra: &[&str]| {
            SceneDef::new(SceneKind::BunnySweep, &cfg(extra))
                .unwrap()
                .models[0]
                .switches
                .clone()
        };
        let paper = at(&["--profile", "paper"]);
        for profile in ["quick", "ci", "regress"] {
            let s = at(&["--profile", profile, "--sweep-start", "fit"]);
            for (x, y) in s.iter().zip(&paper) {
                assert!(
                    (x / y - 1.0).abs() < 1e-5,
                    "{profile}: {s:?} against {paper:?}"
                );
            }
        }
        // The regress profile's close-up: 1 pixel at 72 pixels, so 600 / 72 times nearer.
        let close = at(&["--profile", "regress"]);
        assert!((paper[0] / close[0] - 600.0 / 72.0).abs() < 1e-3);
    }

    /// The fit path never starts nearer than where the bounding sphere fits the view, and says which switches
    /// it does not reach; the close-up starts before the first switch.
    #[test]
    fn the_fit_path_starts_outside_the_bounding_sphere() {
        let def = SceneDef::new(SceneKind::BunnySweep, &cfg(&["--pixel-error", "5"])).unwrap();
        let p = def.path().unwrap();
        let m = &def.models[0];
        assert!(p.near >= p.fit && p.fit > m.radius);
        assert!(p.unreached > 0 && m.switches[p.unreached - 1] < p.near);
        assert_eq!(def.notes().len(), 1);
        let d = def.describe(&cfg(&["--pixel-error", "5"]));
        assert_eq!(d.models[0].lods[1].note, Some(NOT_REACHED));
        let close = SceneDef::new(
            SceneKind::BunnySweep,
            &cfg(&["--pixel-error", "5", "--sweep-start", "close-up"]),
        )
        .unwrap();
        let c = close.path().unwrap();
        assert!(c.near < m.switches[0] && c.unreached == 0);
    }
}
