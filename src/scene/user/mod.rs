//! User scenes: `--scene PATH.gltf|PATH.glb`, the user's own content, read as glTF places it and as an engine
//! draws it.
//!
//! - Every node with a mesh is an instance (EXT_mesh_gpu_instancing: one instance per entry). Placements of the
//!   same glTF mesh at the same scale and morph weights share one model, drawn instanced; the node's rotation and
//!   translation place the instance, its scale is baked into the model (LOD errors and switch distances are per
//!   model), a mirroring scale with the winding reversed. A transform that shears is refused.
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
use crate::scene::animated::Animated;
use crate::scene::bunny::fit_distance;
use crate::scene::config::SceneConfig;
use crate::scene::kind::{ProfileValues, SceneKind};
use crate::scene::model::{CameraTrack, Instance, Layout, Model, ModelSet, Motion};
use glam::{Mat4, Vec3};
use std::path::Path;
use std::sync::Arc;

/// User scene `kind` (its path): the models and instances of the file.
pub fn def(
    kind: SceneKind,
    cfg: &SceneConfig,
    pv: &ProfileValues,
    fov_y: f32,
) -> Result<(ModelSet, UserParts)> {
    let started = std::time::Instant::now();
    let file = kind.user_path().unwrap_or(kind.name());
    let bad = |problem: String| Error::Mesh {
        path: file.to_string(),
        problem,
    };
    let path = Path::new(file);
    let bytes = read_mesh_file(path, file)?;
    let mut content = gltf::read(&bytes, path.parent().unwrap_or(Path::new(""))).map_err(bad)?;

    // The camera and the animation: the file camera's field of view replaces --fov before any switch distance.
    let camera = flight::file_camera(file, &mut content, cfg)?;
    let fov_y = camera.as_ref().and_then(|c| c.0.yfov).unwrap_or(fov_y);
    let clip_index = motion::choose(file, &content, &cfg.animation)?;
    let rig = content.rig(clip_index).map_err(bad)?;
    let clip = motion::clip(&rig);

    // The models at rest, and how the clip moves their instances.
    let collected = models::Collector::new(file, &mut content, &rig).collect()?;
    let tracks = match &clip {
        Some(c) => motion::tracks(&content, &rig, c, pv.frames, &collected.instances),
        None => vec![None; collected.instances.len()],
    };
    let rest: Vec<Mat4> = collected
        .instances
        .iter()
        .map(|i| Mat4::from_rotation_translation(i.rotation, i.translation))
        .collect();
    let matrix_at = |i: usize, f: u32| -> Mat4 {
        tracks[i]
            .as_ref()
            .map_or(rest[i], |t| t[(f as usize).min(t.len().saturating_sub(1))])
    };

    // The default flight's start: the whole scene on frame 0, deformed models as the clip poses them there.
    let deform_specs: Vec<Option<models::DeformSpec>> =
        collected.models.iter().map(|p| p.deform.clone()).collect();
    let first_poses = match &clip {
        Some(c) => motion::first_poses(
            c,
            &rig,
            &collected
                .models
                .iter()
                .map(|m| &m.levels[0])
                .collect::<Vec<_>>(),
            &deform_specs,
            &collected.instances,
            &|k| matrix_at(k, 0),
        ),
        None => vec![None; collected.models.len()],
    };
    let spheres: Vec<(Vec3, f32)> = collected
        .instances
        .iter()
        .enumerate()
        .map(|(k, i)| {
            let mesh = &collected.models[i.model].levels[0];
            let (c, r) = match &first_poses[i.model] {
                Some(p) => bounding_sphere_of(p),
                None => mesh.bounding_sphere(),
            };
            let m = matrix_at(k, 0);
            let s = m.to_scale_rotation_translation().0.abs().max_element();
            (m.transform_point3(c), r * s)
        })
        .collect();
    let sphere = flight::bounding_sphere(&spheres);
    let (eye0, start) = flight::start(sphere, pv, fov_y);

    // The LOD chains, a generated chain's levels at multiples of the distance its model is first seen from.
    let pixel_error = cfg.pixel_error(kind, pv.height);
    let view = chains::View {
        cfg,
        pv,
        fov_y,
        pixel_error,
    };
    let own_camera = camera.is_some() || cfg.camera_path.is_some();
    let mut models: Vec<Model> = Vec::with_capacity(collected.models.len());
    let mut chain_descriptions = Vec::new();
    let pending = collected.models;
    let mut collected_notes = collected.notes;
    for (m, p) in pending.into_iter().enumerate() {
        let radius = p.levels[0].bounding_sphere().1;
        let fit = fit_distance(radius, pv.width, pv.height, fov_y);
        let nearest = spheres
            .iter()
            .zip(&collected.instances)
            .filter(|(_, i)| i.model == m)
            .map(|(s, _)| s.0.distance(eye0))
            .fold(f32::INFINITY, f32::min);
        let seen_from = if own_camera { fit } else { fit.max(nearest) };
        let (model, description, note) = chains::build(file, p, &view, seen_from)?;
        models.push(model);
        collected_notes.extend(note);
        chain_descriptions.extend(description);
    }
    let instances: Vec<Instance> = collected
        .instances
        .iter()
        .map(|i| Instance {
            model: i.model as u32,
            position: i.translation + i.rotation * models[i.model].center,
            yaw: 0.0,
            rotation: i.rotation,
        })
        .collect();

    // The animation, when something moves, and the deformed models' reach over every pose.
    let animation = clip
        .map(|c| {
            Animated::new(
                c,
                rig,
                pv.frames,
                tracks.clone(),
                motion::deformers(&deform_specs, &collected.instances),
            )
        })
        .filter(|a| !a.is_still());
    if let Some(a) = &animation {
        motion::widen_to_poses(a, &mut models, &matrix_at);
    }
    let animation = animation.map(Arc::new);

    // The flight's end, the clip planes, and what the camera does.
    let last = pv.frames.saturating_sub(1);
    let ends: Vec<(Vec3, Option<f32>)> = instances
        .iter()
        .enumerate()
        .map(|(k, i)| {
            let m = &models[i.model as usize];
            (
                matrix_at(k, last).transform_point3(m.center),
                m.switches.last().copied(),
            )
        })
        .collect();
    let end = flight::end(cfg, sphere.0, start, &ends);
    let (from, to) = (eye0, sphere.0 + Vec3::Z * end);
    let eyes: Vec<Vec3> = match &camera {
        Some((_, c)) => c.eyes().collect(),
        None => vec![from, to],
    };
    let reach = (0..pv.frames.max(1))
        .step_by(((pv.frames / 64).max(1)) as usize)
        .chain([last])
        .flat_map(|f| instances.iter().enumerate().map(move |(k, i)| (k, i, f)))
        .map(|(k, i, f)| {
            let m = &models[i.model as usize];
            let p = matrix_at(k, f).transform_point3(m.center);
            eyes.iter().map(|e| p.distance(*e)).fold(0.0f32, f32::max) + m.radius
        })
        .fold(0.0f32, f32::max);
    let camera_source = match &camera {
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
            sphere.1
        ),
    };
    let near = camera.as_ref().and_then(|c| c.0.znear).unwrap_or(
        models
            .iter()
            .map(|m| m.radius)
            .fold(f32::INFINITY, f32::min)
            * 0.02,
    );
    let mut notes = collected_notes;
    if let Some(a) = &animation {
        notes.push(format!(
            "{file}: animation {} '{}' plays ({:.3} s, looped at 60 frames a second): {} instance(s) move, {} \
             model(s) deformed",
            a.clip.index,
            a.clip.name,
            a.clip.end_s - a.clip.start_s,
            (0..instances.len()).filter(|&i| a.instance_matrix(i, 0).is_some()).count(),
            a.deformers.len()
        ));
    }
    let parts = UserParts {
        instance_count: instances.len(),
        instances,
        from: from.to_array(),
        to: to.to_array(),
        forward: [0.0, 0.0, -1.0],
        near,
        far: camera
            .as_ref()
            .and_then(|c| c.0.zfar)
            .unwrap_or(reach * 1.5),
        scene_sphere: (sphere.0.to_array(), sphere.1),
        start,
        chains: chain_descriptions,
        fov_y: camera.as_ref().and_then(|c| c.0.yfov),
        camera: camera.map(|c| c.1),
        camera_source,
        animation,
        animations: content.animation_names(),
        notes,
        sources: collected
            .instances
            .iter()
            .map(|i| i.source.clone())
            .collect(),
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

/// The centre of the box of `points` and the radius of the sphere around it that holds them all.
fn bounding_sphere_of(points: &[[f32; 3]]) -> (Vec3, f32) {
    let (lo, hi) = points.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(Vec3::from(*p)), hi.max(Vec3::from(*p))),
    );
    let c = (lo + hi) * 0.5;
    let r = points
        .iter()
        .map(|p| Vec3::from(*p).distance(c))
        .fold(0.0f32, f32::max);
    (c, r)
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
