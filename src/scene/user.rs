//! User scenes: `--scene PATH.gltf|PATH.glb`, the user's own content.
//!
//! Every node with a mesh is an instance (EXT_mesh_gpu_instancing: one instance per entry). Placements of the
//! same glTF mesh at the same scale share one model, drawn instanced; the node's rotation and translation
//! place the instance, its scale is baked into the model (so the LOD errors and switch distances, which are
//! per model, hold for every instance of it). An authored LOD chain (MSFT_lod, or `NAME_LODn` siblings) is one
//! model whose levels are the chain's meshes, never merged; its switch distances come from MSFT_screencoverage
//! when the file has it (engine screen size, converted by [`screen_size_distance`]), else from the pixel error of
//! an error estimated for each level (meshopt's error when it simplifies LOD0 to that level's triangle count).
//! A mesh without a chain gets meshopt's chain by error, as `--mesh` does (`bunny::USER_SWITCH_FIT_MULTIPLES`).
//!
//! The camera is the file's animated camera node when it has one (its first, keys resampled to the frames,
//! its vertical fov replacing `--fov`), `--camera-path` when given; otherwise it flies away from the first
//! instance along +z, glTF's front, looking at it: from where its
//! bounding sphere fits the view (or nearer, just before its first switch's band, but never inside the sphere)
//! to past its last switch, so it passes every LOD switch of that instance. The scene is static: only the
//! camera moves.

use crate::error::{Error, Result};
use crate::geometry::gltf::{self, ChainSource};
use crate::geometry::lod::{self, LodChain};
use crate::geometry::mesh::{read_mesh_file, Mesh};
use crate::scene::bunny::{fit_distance, USER_SWITCH_FIT_MULTIPLES};
use crate::scene::camera_path::CameraPath;
use crate::scene::config::{screen_size_distance, SceneConfig};
use crate::scene::kind::{ProfileValues, SceneKind};
use crate::scene::model::{CameraTrack, Instance, Layout, Model, ModelSet, Motion};
use glam::{Mat4, Quat, Vec3};
use serde::Serialize;
use std::path::Path;

/// Colours of models whose material has no base colour factor, in turn.
const PALETTE: [[f32; 3]; 6] = [
    [0.72, 0.45, 0.28],
    [0.30, 0.55, 0.75],
    [0.45, 0.70, 0.35],
    [0.80, 0.70, 0.30],
    [0.65, 0.40, 0.70],
    [0.55, 0.55, 0.55],
];

/// What a user scene has beyond its models: its instances, the camera's flight, and what `describe` reports.
#[derive(Debug, Clone, Serialize)]
pub struct UserParts {
    #[serde(skip)]
    pub instances: Vec<Instance>,
    /// The camera flight: from, to, and the direction it looks in.
    pub from: [f32; 3],
    pub to: [f32; 3],
    pub forward: [f32; 3],
    #[serde(skip)]
    pub near: f32,
    #[serde(skip)]
    pub far: f32,
    /// The instance the default flight follows through its switches.
    pub followed: usize,
    /// Its distance from the camera where the flight starts.
    pub start: f32,
    pub instance_count: usize,
    /// The authored chains: model name, where the chain came from, levels.
    pub chains: Vec<ChainDescription>,
    /// The file's animated camera, when it has one and no `--camera-path` is given: it replaces the flight.
    #[serde(skip)]
    pub camera: Option<std::sync::Arc<CameraPath>>,
    /// What the camera does, in words.
    pub camera_source: String,
    /// The animated camera's vertical field of view (radians), which replaces `--fov`.
    #[serde(skip)]
    pub fov_y: Option<f32>,
}

#[derive(Debug, Clone, Serialize)]
pub struct ChainDescription {
    pub model: String,
    pub source: &'static str,
    pub levels: usize,
    /// Where the switch distances came from.
    pub thresholds: String,
}

/// One model being built, with its key: the glTF meshes of its levels and the scale baked into them.
struct Built {
    meshes: Vec<usize>,
    scale: [i64; 3],
    model: Model,
}

/// A scale as a model's key: to 1e-6, so the same scale decomposed from differently rotated placements (which
/// differ in the last bits) shares one model.
fn scale_key(scale: Vec3) -> [i64; 3] {
    scale
        .to_array()
        .map(|s| (f64::from(s) * 1e6).round() as i64)
}

/// User scene `kind` (its path): the models and instances of the file.
pub fn def(
    kind: SceneKind,
    cfg: &SceneConfig,
    pv: &ProfileValues,
    fov_y: f32,
) -> Result<(ModelSet, UserParts)> {
    let started = std::time::Instant::now();
    let name = kind.user_path().unwrap_or(kind.name());
    let path = Path::new(name);
    let bad = |problem: String| Error::Mesh {
        path: name.to_string(),
        problem,
    };
    let bytes = read_mesh_file(path, name)?;
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut content = gltf::read(&bytes, dir).map_err(bad)?;
    // The file's camera animation, unless --camera-path replaces it; its field of view replaces --fov before
    // the switch distances are computed.
    let animated = match cfg.camera_path {
        Some(_) => None,
        None => content.animated_camera().map_err(bad)?,
    };
    let camera = match &animated {
        Some(a) => Some(std::sync::Arc::new(CameraPath::from_orientations(
            name,
            &a.keys,
            a.yfov.map(f32::to_degrees),
        )?)),
        None => None,
    };
    let fov_override = animated.as_ref().and_then(|a| a.yfov);
    if let Some(f) = fov_override {
        if !(1.0..170.0).contains(&f.to_degrees()) {
            return Err(bad(format!(
                "the animated camera's yfov {f} rad ({:.1} deg) is not between 1 and 170 degrees",
                f.to_degrees()
            )));
        }
    }
    if let Some(a) = &animated {
        if let (Some(n), Some(f)) = (a.znear, a.zfar) {
            if n >= f {
                return Err(bad(format!(
                    "the animated camera's znear {n} is not below its zfar {f}"
                )));
            }
        }
    }
    let fov_y = fov_override.unwrap_or(fov_y);
    let pixel_error = cfg.pixel_error(kind, pv.height);
    let view = View {
        cfg,
        pv,
        fov_y,
        pixel_error,
    };
    let placements = std::mem::take(&mut content.placements);
    let chains = content.chains.clone();
    let mut built: Vec<Built> = Vec::new();
    let mut instances: Vec<Instance> = Vec::new();
    let mut chain_descriptions = Vec::new();

    // Authored chains: one model each, placed by its LOD0 node.
    for chain in &chains {
        let level_placements: Vec<&gltf::Placement> = chain
            .nodes
            .iter()
            .map(|&n| {
                let p: Vec<&gltf::Placement> = placements.iter().filter(|p| p.node == n).collect();
                match p.as_slice() {
                    [one] if one.instance.is_none() => Ok(*one),
                    _ => Err(bad(format!(
                        "LOD chain '{}': node {n} must place exactly one mesh, without instancing",
                        chain.name
                    ))),
                }
            })
            .collect::<Result<_>>()?;
        let (scale, rotation, translation) = decompose(name, level_placements[0])?;
        let key_meshes: Vec<usize> = level_placements.iter().map(|p| p.mesh).collect();
        let key_scale = scale_key(scale);
        // Chains of the same meshes at the same scale (one per instance, as `lodbench export` writes them)
        // share one model.
        if let Some(i) = built
            .iter()
            .position(|b| b.meshes == key_meshes && b.scale == key_scale)
        {
            instances.push(Instance {
                model: i as u32,
                position: translation + rotation * built[i].model.center,
                yaw: 0.0,
                rotation,
            });
            continue;
        }
        let to_model = Mat4::from_rotation_translation(rotation, translation).inverse();
        let mut meshes = Vec::new();
        for p in &level_placements {
            meshes.push(placed_mesh(
                &mut content,
                name,
                p,
                to_model * p.world,
                to_model,
            )?);
        }
        let model_name = if chain.name.is_empty() {
            format!("chain{}", built.len())
        } else {
            chain.name.clone()
        };
        let (center, radius) = meshes[0].bounding_sphere();
        let exact = chain
            .switch_distances
            .as_ref()
            .filter(|d| d.len() + 1 == meshes.len());
        let (errors, thresholds, source) = match (&chain.screen_coverage, exact) {
            (_, Some(d)) => {
                let mut e = vec![0.0];
                e.extend(
                    d.iter()
                        .map(|&d| lod::error_at_distance(d, 1.0, pixel_error, pv.height, fov_y)),
                );
                (
                    e,
                    format!("extras.lodbench_switch_distances {d:?} (lodbench export's exact distances)"),
                    "lodbench_switch_distances",
                )
            }
            (Some(c), None) if c.len() + 1 >= meshes.len() && meshes.len() > 1 => {
                let d: Vec<f32> = c[..meshes.len() - 1]
                    .iter()
                    .map(|&c| screen_size_distance(radius, c as f32, fov_y))
                    .collect();
                let mut e = vec![0.0];
                e.extend(
                    d.iter()
                        .map(|&d| lod::error_at_distance(d, 1.0, pixel_error, pv.height, fov_y)),
                );
                (
                    e,
                    format!(
                        "MSFT_screencoverage {c:?} (the last value, the cull threshold, not used)"
                    ),
                    "MSFT_screencoverage",
                )
            }
            _ => (
                estimated_errors(name, &meshes)?,
                "meshopt's error at each level's triangle count, projected to --pixel-error"
                    .to_string(),
                "pixel-error (estimated)",
            ),
        };
        let chain_lod = LodChain::from_meshes(&model_name, meshes, &errors)
            .map_err(|e| bad(format!("LOD chain '{}': {e}", chain.name)))?;
        let color = content
            .mesh_color(level_placements[0].mesh)
            .unwrap_or(PALETTE[built.len() % PALETTE.len()]);
        let mut model = finish_model(
            &view,
            model_name.clone(),
            chain_lod,
            (center, radius),
            source,
            color,
        )?;
        // Levels of other colours (SIMPLE's box) keep them.
        let colors: Vec<[f32; 3]> = level_placements
            .iter()
            .map(|p| content.mesh_color(p.mesh).unwrap_or(color))
            .collect();
        if colors.iter().any(|c| *c != color) {
            model.lod_colors = colors;
        }
        if let (Some(d), false) = (exact, model.switch_source == "override") {
            // Exact as written (the round trip through the pixel error may move the last bit), unless
            // --switch-distances or --switch-screen-sizes replaced them.
            cfg.schedule.check_switches(&model_name, d)?;
            model.switches = d.to_vec();
        }
        model.spin_per_frame = chain.spin_per_frame;
        chain_descriptions.push(ChainDescription {
            model: model_name,
            source: match chain.source {
                ChainSource::MsftLod => "MSFT_lod",
                ChainSource::LodNames => "NAME_LODn node names",
            },
            levels: chain.nodes.len(),
            thresholds,
        });
        instances.push(Instance {
            model: built.len() as u32,
            position: translation + rotation * center,
            yaw: 0.0,
            rotation,
        });
        built.push(Built {
            meshes: key_meshes,
            scale: key_scale,
            model,
        });
    }

    // Every other placement: models shared by mesh and scale.
    let in_chain: Vec<bool> = placements
        .iter()
        .map(|p| content.in_chain(p.node))
        .collect();
    for (p, _) in placements.iter().zip(in_chain).filter(|(_, c)| !c) {
        let (scale, rotation, translation) = decompose(name, p)?;
        let key = scale_key(scale);
        let index = match built
            .iter()
            .position(|b| b.meshes == [p.mesh] && b.scale == key)
        {
            Some(i) => i,
            None => {
                let to_frame = Mat4::from_scale(scale) * p.world.inverse();
                let mesh = placed_mesh(&mut content, name, p, Mat4::from_scale(scale), to_frame)?;
                let (center, radius) = mesh.bounding_sphere();
                let fit = fit_distance(radius, pv.width, pv.height, fov_y);
                let errors: Vec<f32> = USER_SWITCH_FIT_MULTIPLES
                    .iter()
                    .map(|m| lod::error_at_distance(m * fit, 1.0, pixel_error, pv.height, fov_y))
                    .collect();
                let model_name = match content.mesh_name(p.mesh) {
                    "" => format!("mesh{}", p.mesh),
                    n => n.to_string(),
                };
                let chain = LodChain::build_by_error(&model_name, &mesh, &errors)?;
                let color = content
                    .mesh_color(p.mesh)
                    .unwrap_or(PALETTE[built.len() % PALETTE.len()]);
                let model = finish_model(
                    &view,
                    model_name,
                    chain,
                    (center, radius),
                    "pixel-error",
                    color,
                )?;
                built.push(Built {
                    meshes: vec![p.mesh],
                    scale: key,
                    model,
                });
                built.len() - 1
            }
        };
        let center = built[index].model.center;
        instances.push(Instance {
            model: index as u32,
            position: translation + rotation * center,
            yaw: 0.0,
            rotation,
        });
    }
    if instances.is_empty() {
        return Err(bad(match content.scene {
            Some(s) => format!("has no triangle primitives in scene {s}"),
            None => "has no triangle primitives".to_string(),
        }));
    }
    let models: Vec<Model> = built.into_iter().map(|b| b.model).collect();

    // The default flight: back from the first instance along +z, looking along -z, through its switches.
    let followed = 0;
    let m = &models[instances[followed].model as usize];
    let target = instances[followed].position;
    let fit = fit_distance(m.radius, pv.width, pv.height, fov_y);
    let last = m.switches.last().copied().unwrap_or(2.0 * fit);
    let (b, h) = (cfg.schedule.band, cfg.schedule.hysteresis);
    // From where the instance fits the view, or nearer, just before its first switch's band, but never inside
    // its bounding sphere (switches nearer than that are not reached: `SceneDef::notes` says which).
    let first_band = m
        .switches
        .first()
        .map_or(fit, |s| s * (1.0 - h) * (1.0 - b));
    let start = fit.min(first_band * 0.9).max(m.radius * 1.1);
    let end = (last * (1.0 + h) * (1.0 + b) * 1.15).max(start * 1.25);
    let from = target + Vec3::Z * start;
    let to = target + Vec3::Z * end;
    let eyes: Vec<Vec3> = match &camera {
        Some(c) => c.eyes().collect(),
        None => vec![from, to],
    };
    let reach = instances
        .iter()
        .map(|i| {
            let r = models[i.model as usize].radius;
            eyes.iter()
                .map(|e| i.position.distance(*e))
                .fold(0.0f32, f32::max)
                + r
        })
        .fold(0.0f32, f32::max);
    let camera_source = match (&camera, &animated) {
        (Some(c), Some(a)) => format!(
            "the file's camera animation (node {}, {} keys{}), resampled to the frames",
            a.node,
            c.keys,
            a.yfov
                .map_or(String::new(), |f| format!(", vertical fov {:.2} deg", f.to_degrees()))
        ),
        _ => format!(
            "a flight from {:?} to {:?} looking along -z, through the switches of instance {followed}",
            from.to_array(),
            to.to_array()
        ),
    };
    let near = animated.as_ref().and_then(|a| a.znear).unwrap_or(
        models
            .iter()
            .map(|m| m.radius)
            .fold(f32::INFINITY, f32::min)
            * 0.02,
    );
    let far_plane = animated.as_ref().and_then(|a| a.zfar);
    let parts = UserParts {
        instance_count: instances.len(),
        instances,
        from: from.to_array(),
        to: to.to_array(),
        forward: [0.0, 0.0, -1.0],
        near,
        far: far_plane.unwrap_or(reach * 1.5),
        followed,
        start,
        chains: chain_descriptions,
        camera,
        camera_source,
        fov_y: fov_override,
    };
    let set = ModelSet {
        models,
        mesh_source: name.to_string(),
        lod_generation_ms: started.elapsed().as_secs_f64() * 1e3,
    };
    Ok((set, parts))
}

/// The instances and camera of a user scene.
pub fn layout(parts: &UserParts) -> Layout {
    let (from, to) = (Vec3::from(parts.from), Vec3::from(parts.to));
    Layout {
        instances: parts.instances.clone(),
        motion: Motion::Static,
        near: parts.near,
        far: parts.far,
        eye: from,
        forward: Vec3::from(parts.forward),
        track: Some(match &parts.camera {
            Some(c) => CameraTrack::Path(c.clone()),
            None => CameraTrack::Flight(from, to),
        }),
        unified: None,
    }
}

/// A placement's world transform as scale, rotation, translation; refused when it shears (no such
/// decomposition reproduces it).
fn decompose(name: &str, p: &gltf::Placement) -> Result<(Vec3, Quat, Vec3)> {
    let (s, r, t) = p.world.to_scale_rotation_translation();
    let again = Mat4::from_scale_rotation_translation(s, r, t);
    let tol = 1e-4
        * p.world
            .abs()
            .to_cols_array()
            .iter()
            .fold(1.0f32, |a, &b| a.max(b));
    if !again.abs_diff_eq(p.world, tol) || !s.is_finite() || s.min_element() <= 0.0 {
        return Err(Error::Mesh {
            path: name.to_string(),
            problem: format!(
                "node {} ('{}') has a transform that shears or mirrors, which a user scene does not place; \
                 apply the transform to the mesh in the tool that wrote it",
                p.node, p.name
            ),
        });
    }
    Ok((s, r, t))
}

/// Placement `p`'s mesh at rest ([`gltf::Content::placed_as`]): unskinned under `mesh_to_frame`, skinned by its
/// joints into the frame `to_frame` maps world space to.
fn placed_mesh(
    content: &mut gltf::Content<'_>,
    name: &str,
    p: &gltf::Placement,
    mesh_to_frame: Mat4,
    to_frame: Mat4,
) -> Result<Mesh> {
    let bad = |problem: String| Error::Mesh {
        path: name.to_string(),
        problem,
    };
    let prims = content.mesh_primitives(p.mesh).map_err(bad)?;
    let parts = content
        .placed_as(p, &prims, mesh_to_frame, to_frame)
        .map_err(bad)?;
    if parts.indices.is_empty() {
        return Err(bad(format!("mesh {} has no triangle primitives", p.mesh)));
    }
    let mut m = Mesh::new(name, parts.positions, parts.normals, parts.indices)?;
    if let Some(aux) = parts.aux {
        m = m.with_aux(name, aux)?;
    }
    m = m.with_data(name, parts.data)?;
    m.check_area(name)?;
    Ok(m)
}

/// An authored chain's errors without thresholds: for each level after LOD0, the error meshopt reaches when it
/// simplifies LOD0 to that level's triangle count (an estimate of what the level gives up).
fn estimated_errors(name: &str, meshes: &[Mesh]) -> Result<Vec<f32>> {
    let t0 = meshes[0].triangle_count() as f32;
    let targets: Vec<f32> = std::iter::once(1.0)
        .chain(meshes[1..].iter().map(|m| m.triangle_count() as f32 / t0))
        .collect();
    if targets.windows(2).any(|w| w[1] >= w[0]) {
        return Err(Error::Mesh {
            path: name.to_string(),
            problem: "an authored LOD chain's levels must have fewer triangles each".into(),
        });
    }
    let estimate = LodChain::build(name, &meshes[0], &targets)?;
    let mut errors: Vec<f32> = estimate.lods.iter().map(|l| l.error_abs).collect();
    for i in 1..errors.len() {
        errors[i] = errors[i].max(errors[i - 1] * 1.0001 + f32::MIN_POSITIVE);
    }
    Ok(errors)
}

/// What a model's switch distances depend on besides its chain.
struct View<'a> {
    cfg: &'a SceneConfig,
    pv: &'a ProfileValues,
    fov_y: f32,
    pixel_error: f32,
}

/// The model of a chain: its switch distances (`--switch-distances` overrides them).
fn finish_model(
    view: &View<'_>,
    name: String,
    chain: LodChain,
    (center, radius): (Vec3, f32),
    source: &'static str,
    color: [f32; 3],
) -> Result<Model> {
    let (switches, switch_source) =
        match view
            .cfg
            .switch_override(&name, chain.lods.len(), radius, view.fov_y)?
        {
            Some(s) => (s, "override"),
            None => (
                lod::switch_distances(&chain, 1.0, view.pixel_error, view.pv.height, view.fov_y),
                source,
            ),
        };
    view.cfg.schedule.check_switches(&name, &switches)?;
    Ok(Model {
        color,
        name,
        lod_colors: Vec::new(),
        spin_per_frame: 0.0,
        chain,
        switches,
        switch_source,
        center,
        radius,
        scale: 1.0,
    })
}
