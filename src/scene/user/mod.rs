//! User scenes: `--scene PATH.gltf|PATH.glb`, the user's own content, read as glTF places it and as an engine
//! draws it.
//!
//! - Every node with a mesh is an instance (EXT_mesh_gpu_instancing: one instance per entry). Placements of the
//!   same glTF mesh and morph weights share one model, drawn instanced, whatever their scale: the model bakes in
//!   its first placement's scale (a mirroring one with the winding reversed; mirrors share a model of their
//!   own), every instance carries its rotation, translation and scale over the model's (`models.rs`). A
//!   transform that shears is refused.
//! - Skinned meshes are placed by their joints (the node's own transform ignored, as glTF specifies), morph
//!   targets take their node's weights, else the mesh's. Points and lines are not drawn (a note names the mesh).
//! - An authored LOD chain (MSFT_lod, or `NAME_LODn` siblings) is one model whose levels are the chain's node
//!   hierarchies, never merged; its switch distances come from the file (`chains.rs`). Every other mesh gets
//!   meshoptimizer's chain by error.
//! - The animation `--animation` names (by default the file's first) plays over the frames (`motion.rs`,
//!   `scene/animated.rs`): moving nodes move their instances, skinned and morph-animated meshes are deformed
//!   per frame, each its own model.
//! - The camera is `--camera-path`, else the file's animated camera, else a flight that shows the whole scene on
//!   frame 0 and moves out until every model has passed its last switch (`flight.rs`).
//!
//! `def` reads the file in named steps: open, choose the camera and the animation, collect the models at rest
//! (`models.rs`), place the flight's start, build the LOD chains (`chains.rs`), animate, end the flight.

mod chains;
mod flight;
mod models;
mod motion;
mod parts;

pub use parts::{ChainDescription, InstanceSource, UserParts};

use crate::error::{Error, Result};
use crate::geometry::gltf;
use crate::geometry::mesh::read_mesh_file;
use crate::geometry::projection::{fit_distance, Sphere};
use crate::scene::animated::Animated;
use crate::scene::config::SceneConfig;
use crate::scene::kind::{ProfileValues, SceneKind};
use crate::scene::model::{size_of, CameraTrack, Instance, Layout, Model, ModelSet, Motion};
use glam::{Mat4, Vec3};
use std::path::Path;
use std::sync::Arc;

/// User scene `kind` (its path): the models and instances of the file, in named steps.
pub fn def(
    kind: SceneKind,
    cfg: &SceneConfig,
    pv: &ProfileValues,
    fov_y: f32,
) -> Result<(ModelSet, UserParts)> {
    let started = std::time::Instant::now();
    let file = kind.user_path().unwrap_or(kind.name());
    let bytes = read_mesh_file(Path::new(file), file)?;

    // The camera and the animation: the file camera's field of view replaces --fov before any switch distance.
    let (mut content, camera, rig, clip) = open(file, &bytes, cfg)?;
    let fov_y = camera.as_ref().and_then(|c| c.0.yfov).unwrap_or(fov_y);

    // The models at rest, and how the clip moves their instances.
    let mut collected = models::Collector::new(file, &mut content, &rig, cfg).collect()?;
    let materials = Arc::new(std::mem::take(&mut collected.materials));
    let placed = Placed::new(&content, &rig, clip.as_ref(), pv.frames, &collected);
    let deform_specs: Vec<Option<models::DeformSpec>> =
        collected.models.iter().map(|p| p.deform.clone()).collect();

    // The default flight's start: the whole scene on frame 0.
    let spheres = first_frame_spheres(clip.as_ref(), &rig, &collected, &deform_specs, &placed);
    let sphere = Sphere::holding(&spheres);
    let (eye0, start) = flight::start(sphere, pv, fov_y);

    // The LOD chains, a generated chain's levels at multiples of the distance its model is first seen from.
    let view = chains::View::new(kind, cfg, pv, fov_y);
    let first_seen = FirstSeen {
        spheres: &spheres,
        eye: (camera.is_none() && cfg.camera_path.is_none()).then_some(eye0),
    };
    let (mut models, chain_descriptions, mut notes) = build_models(
        file,
        collected.models,
        &collected.instances,
        &view,
        &first_seen,
    )?;
    notes.splice(0..0, collected.notes);
    let instances = place_instances(&collected.instances, &models);

    // The animation, when something moves, and the deformed models' reach over every pose.
    let animation = clip
        .map(|c| {
            Animated::new(
                c,
                rig,
                pv.frames,
                placed.tracks.clone(),
                motion::deformers(&deform_specs, &collected.instances),
            )
        })
        .filter(|a| !a.is_still());
    if let Some(a) = &animation {
        motion::widen_to_poses(a, &mut models, &|i, f| placed.at(i, f));
        notes.push(motion::note(file, a, instances.len()));
    }
    // The flight's end, the clip planes, and what the camera does.
    let end = flight::end(
        cfg,
        sphere.centre,
        start,
        pv.frames,
        &last_places(&models, &instances, &placed, pv.frames),
    );
    let (from, to) = (eye0, sphere.centre + Vec3::Z * end);
    let eyes = clip_eyes(&camera, cfg.camera_path.as_ref(), [from, to]);
    let (near, far) = clip_planes(&models, &instances, &placed, pv.frames, &camera, &eyes);
    let camera_source = camera_source(&camera, [from, to], sphere.radius);
    let parts = UserParts {
        materials,
        instance_count: instances.len(),
        instances,
        from: from.to_array(),
        to: to.to_array(),
        forward: [0.0, 0.0, -1.0],
        near,
        far,
        scene_sphere: (sphere.centre.to_array(), sphere.radius),
        start,
        chains: chain_descriptions,
        fov_y: camera.as_ref().and_then(|c| c.0.yfov),
        camera: camera.map(|c| c.1),
        camera_source,
        animation: animation.map(Arc::new),
        animations: content.animation_names(),
        notes,
        sources: instance_sources(&collected.instances),
        skipped: collected.skipped,
    };
    let set = ModelSet {
        models,
        mesh_source: file.to_string(),
        lod_generation_ms: started.elapsed().as_secs_f64() * 1e3,
        notes: Vec::new(),
    };
    Ok((set, parts))
}

/// The file camera's animation, when the file has one.
type FileCamera = Option<(
    gltf::AnimatedCamera,
    Arc<crate::scene::camera_path::CameraPath>,
)>;

/// glTF file `file` (its `bytes`) opened: its content, its camera (`--camera-path` or the file's), and its rig
/// with the clip `--animation` chooses.
fn open<'b>(
    file: &'b str,
    bytes: &'b [u8],
    cfg: &SceneConfig,
) -> Result<(
    gltf::Content<'b>,
    FileCamera,
    gltf::Rig,
    Option<crate::scene::animated::Clip>,
)> {
    let bad = |problem: String| Error::Mesh {
        path: file.to_string(),
        problem,
    };
    let path = Path::new(file);
    let mut content = gltf::read(bytes, path.parent().unwrap_or(Path::new(""))).map_err(bad)?;
    let camera = flight::file_camera(file, &mut content, cfg)?;
    let clip_index = motion::choose(file, &content, &cfg.animation)?;
    let rig = content.rig(clip_index).map_err(bad)?;
    let clip = motion::clip(&rig);
    Ok((content, camera, rig, clip))
}

/// The instances at rest: each at its placement, its model's centre moved with it.
fn place_instances(pending: &[models::PendingInstance], models: &[Model]) -> Vec<Instance> {
    pending
        .iter()
        .map(|i| Instance {
            model: i.model as u32,
            position: i.translation + i.rotation * (i.scale * models[i.model].center),
            yaw: 0.0,
            rotation: i.rotation,
            scale: i.scale,
        })
        .collect()
}

/// Each instance's source: its node, and what it holds.
fn instance_sources(pending: &[models::PendingInstance]) -> Vec<InstanceSource> {
    pending.iter().map(|i| i.source.clone()).collect()
}

/// What the camera does, in words: the file's camera animation, or the default flight `[from, to]` over a
/// scene of bounding radius `radius`.
fn camera_source(camera: &FileCamera, [from, to]: [Vec3; 2], radius: f32) -> String {
    match camera {
        Some((a, c)) => format!(
            "the file's camera animation (node {}, {} keys{}), resampled to the frames",
            a.node,
            c.keys,
            a.yfov
                .map_or(String::new(), |f| format!(", vertical fov {:.2} deg", f.to_degrees()))
        ),
        None => format!(
            "a flight from {:?} to {:?} looking along -z: frame 0 shows the whole scene (its bounding sphere, \
             radius {:.4}, fits the view), then out until every model has passed its last switch",
            from.to_array(),
            to.to_array(),
            radius
        ),
    }
}

/// Every instance's model-to-world matrix on every frame: its track where the clip moves it, else its rest
/// placement.
struct Placed {
    tracks: Vec<Option<Vec<Mat4>>>,
    rest: Vec<Mat4>,
}

impl Placed {
    fn new(
        content: &gltf::Content<'_>,
        rig: &gltf::Rig,
        clip: Option<&crate::scene::animated::Clip>,
        frames: u32,
        collected: &models::Collected,
    ) -> Placed {
        Placed {
            tracks: match clip {
                Some(c) => motion::tracks(content, rig, c, frames, &collected.instances),
                None => vec![None; collected.instances.len()],
            },
            rest: collected
                .instances
                .iter()
                .map(|i| Mat4::from_scale_rotation_translation(i.scale, i.rotation, i.translation))
                .collect(),
        }
    }

    fn at(&self, i: usize, f: u32) -> Mat4 {
        self.tracks[i].as_ref().map_or(self.rest[i], |t| {
            t[(f as usize).min(t.len().saturating_sub(1))]
        })
    }
}

/// Each instance's bounding sphere on frame 0 (world space), deformed models as the clip poses them there.
fn first_frame_spheres(
    clip: Option<&crate::scene::animated::Clip>,
    rig: &gltf::Rig,
    collected: &models::Collected,
    deform_specs: &[Option<models::DeformSpec>],
    placed: &Placed,
) -> Vec<Sphere> {
    let levels0: Vec<&crate::geometry::mesh::Mesh> =
        collected.models.iter().map(|m| &m.levels[0]).collect();
    let poses = match clip {
        Some(c) => {
            motion::first_poses(c, rig, &levels0, deform_specs, &collected.instances, &|k| {
                placed.at(k, 0)
            })
        }
        None => vec![None; levels0.len()],
    };
    collected
        .instances
        .iter()
        .enumerate()
        .map(|(k, i)| {
            let sphere = match &poses[i.model] {
                Some(p) => Sphere::around(p),
                None => levels0[i.model].bounding_sphere(),
            };
            let m = placed.at(k, 0);
            let s = m.to_scale_rotation_translation().0.abs().max_element();
            Sphere::new(m.transform_point3(sphere.centre), sphere.radius * s)
        })
        .collect()
}

/// Where each model is first seen from: the default flight's first eye (None with the file's camera or
/// `--camera-path`) and every instance's sphere on frame 0.
struct FirstSeen<'a> {
    spheres: &'a [Sphere],
    eye: Option<Vec3>,
}

/// Every model with its chain and switch distances, the authored chains' descriptions, and the notes the chains
/// leave. A generated chain's levels are at multiples of the distance its model is first seen from: the nearest
/// of its instances from the flight's first eye, never nearer than where the model alone fits the view.
fn build_models(
    file: &str,
    pending: Vec<models::PendingModel>,
    instances: &[models::PendingInstance],
    view: &chains::View<'_>,
    seen: &FirstSeen<'_>,
) -> Result<(Vec<Model>, Vec<ChainDescription>, Vec<String>)> {
    let (mut models, mut descriptions, mut notes) = (Vec::new(), Vec::new(), Vec::new());
    for (m, p) in pending.into_iter().enumerate() {
        let radius = p.levels[0].bounding_sphere().radius;
        let fit = fit_distance(radius, view.pv.width, view.pv.height, view.fov_y);
        let nearest = match seen.eye {
            Some(eye) => seen
                .spheres
                .iter()
                .zip(instances)
                .filter(|(_, i)| i.model == m)
                // An instance `size` times its model's shows the model's errors as the model would nearer.
                .map(|(s, i)| s.centre.distance(eye) / size_of(i.scale))
                .fold(f32::INFINITY, f32::min),
            None => fit,
        };
        let (model, description, note) = chains::build(file, p, view, fit.max(nearest))?;
        models.push(model);
        descriptions.extend(description);
        notes.extend(note);
    }
    Ok((models, descriptions, notes))
}

/// Each instance's centre on the last frame and its model's last switch (what the flight's end must pass).
fn last_places(
    models: &[Model],
    instances: &[Instance],
    placed: &Placed,
    frames: u32,
) -> Vec<(Vec3, Option<f32>)> {
    let last = frames.saturating_sub(1);
    instances
        .iter()
        .enumerate()
        .map(|(k, i)| {
            let m = &models[i.model as usize];
            (
                placed.at(k, last).transform_point3(m.center),
                m.switches.last().map(|s| s * i.size()),
            )
        })
        .collect()
}

/// The eyes the clip planes must hold everything from: the file's camera's, `--camera-path`'s, or the flight's
/// ends.
fn clip_eyes(
    camera: &FileCamera,
    path: Option<&crate::scene::camera_path::CameraPath>,
    flight: [Vec3; 2],
) -> Vec<Vec3> {
    match (camera, path) {
        (Some((_, c)), _) => c.eyes().collect(),
        (None, Some(p)) => p.eyes().collect(),
        (None, None) => flight.to_vec(),
    }
}

/// The clip planes: the file camera's when it gives them; else near at 0.02 of the smallest instance's radius and
/// far at 1.5 times the farthest any instance gets from the camera's `eyes` (its keys, `--camera-path`'s, or the
/// flight's ends), over the frames (every 64th and the last).
fn clip_planes(
    models: &[Model],
    instances: &[Instance],
    placed: &Placed,
    frames: u32,
    camera: &FileCamera,
    eyes: &[Vec3],
) -> (f32, f32) {
    let last = frames.saturating_sub(1);
    let reach = (0..frames.max(1))
        .step_by((frames / 64).max(1) as usize)
        .chain([last])
        .flat_map(|f| instances.iter().enumerate().map(move |(k, i)| (k, i, f)))
        .map(|(k, i, f)| {
            let m = &models[i.model as usize];
            let p = placed.at(k, f).transform_point3(m.center);
            eyes.iter().map(|e| p.distance(*e)).fold(0.0f32, f32::max) + m.radius * i.size()
        })
        .fold(0.0f32, f32::max);
    let smallest = instances
        .iter()
        .map(|i| models[i.model as usize].radius * i.size())
        .fold(f32::INFINITY, f32::min);
    let file = camera.as_ref().map(|c| (c.0.znear, c.0.zfar));
    (
        file.and_then(|c| c.0).unwrap_or(smallest * 0.02),
        file.and_then(|c| c.1).unwrap_or(reach * 1.5),
    )
}

/// The instances and camera of a user scene.
pub fn layout(parts: &UserParts) -> Layout {
    let (from, to) = (Vec3::from(parts.from), Vec3::from(parts.to));
    Layout {
        instances: parts.instances.clone(),
        motion: match &parts.animation {
            Some(a) => Motion::Animated(a.clone()),
            None => Motion::Static,
        },
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
