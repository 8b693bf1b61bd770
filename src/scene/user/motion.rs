//! A user scene's animation: which clip plays (`--animation`), each moving instance's matrix per frame, and
//! the deformers of its skinned and morph-animated models (`scene/animated.rs` plays them).

use crate::error::{Error, Result};
use crate::geometry::gltf::{Content, Rig};
use crate::scene::animated::{Animated, Clip, Deformer};
use crate::scene::config::AnimationChoice;
use crate::scene::model::Model;
use crate::scene::user::models::{Anchor, DeformSpec, PendingInstance};
use glam::Mat4;

/// The animation `choice` names among the file's: None when it asks for none, or for the first of a file that
/// has none. An index or a name the file does not have is an error listing what it has.
pub fn choose(
    file: &str,
    content: &Content<'_>,
    choice: &AnimationChoice,
) -> Result<Option<usize>> {
    let names = content.animation_names();
    let listing = || {
        if names.is_empty() {
            "the file has no animations".to_string()
        } else {
            let all: Vec<String> = names
                .iter()
                .enumerate()
                .map(|(i, n)| {
                    if n.is_empty() {
                        format!("{i}")
                    } else {
                        format!("{i} '{n}'")
                    }
                })
                .collect();
            format!("its animations are {}", all.join(", "))
        }
    };
    let bad = |what: String| Error::Config(format!("--animation {what}: {file}: {}", listing()));
    match choice {
        AnimationChoice::First => Ok((!names.is_empty()).then_some(0)),
        AnimationChoice::None => Ok(None),
        AnimationChoice::Index(i) if *i < names.len() => Ok(Some(*i)),
        AnimationChoice::Index(i) => Err(bad(i.to_string())),
        AnimationChoice::Name(n) => match names.iter().position(|m| m == n) {
            Some(i) => Ok(Some(i)),
            None => Err(bad(format!("'{n}'"))),
        },
    }
}

/// The clip the rig plays.
pub fn clip(rig: &Rig) -> Option<Clip> {
    rig.animation.as_ref().map(|a| Clip {
        index: a.index,
        name: a.name.clone(),
        start_s: a.start,
        end_s: a.end,
    })
}

/// The rigid part (rotation and translation) of `m`.
fn rigid(m: Mat4) -> Mat4 {
    let (_, r, t) = m.to_scale_rotation_translation();
    Mat4::from_rotation_translation(r.normalize(), t)
}

/// Per instance, its model-to-world matrix on each of `frames` frames when the clip moves it (None when it
/// does not).
pub fn tracks(
    content: &Content<'_>,
    rig: &Rig,
    clip: &Clip,
    frames: u32,
    instances: &[PendingInstance],
) -> Vec<Option<Vec<Mat4>>> {
    let Some(anim) = &rig.animation else {
        return vec![None; instances.len()];
    };
    // A file without scenes places its meshes on no node (`usize::MAX`): nothing moves them.
    let moves = |node: usize| {
        let mut n = Some(node).filter(|&i| i < content.nodes.parent.len());
        while let Some(i) = n {
            if anim.moves(i) {
                return true;
            }
            n = content.nodes.parent[i];
        }
        false
    };
    let moving: Vec<bool> = instances
        .iter()
        .map(|i| match i.anchor {
            Anchor::Node { node, .. } => moves(node),
            Anchor::Skeleton { root } => moves(root),
        })
        .collect();
    let mut out: Vec<Option<Vec<Mat4>>> = moving
        .iter()
        .map(|&m| m.then(|| Vec::with_capacity(frames as usize)))
        .collect();
    if !moving.contains(&true) {
        return out;
    }
    let rest = rig.rest_worlds();
    for f in 0..frames {
        let worlds = rig.worlds_at(clip.time_of(f));
        for (inst, track) in instances.iter().zip(out.iter_mut()) {
            let Some(track) = track else { continue };
            track.push(match inst.anchor {
                Anchor::Node { node, local } => worlds[node] * local,
                Anchor::Skeleton { root } => rigid(worlds[root] * rest[root].inverse()),
            });
        }
    }
    out
}

/// Each deformed model's LOD0 as the clip's first frame poses it (model space), by model; None for the others.
pub fn first_poses(
    clip: &Clip,
    rig: &Rig,
    levels0: &[&crate::geometry::mesh::Mesh],
    specs: &[Option<DeformSpec>],
    instances: &[PendingInstance],
    matrix: &dyn Fn(usize) -> Mat4,
) -> Vec<Option<Vec<[f32; 3]>>> {
    let deformers = deformers(specs, instances);
    let mut out = vec![None; levels0.len()];
    if deformers.is_empty() {
        return out;
    }
    let chains: Vec<crate::geometry::lod::LodChain> = levels0
        .iter()
        .zip(specs)
        .map(|(m, s)| crate::geometry::lod::LodChain {
            lods: match s {
                Some(_) => vec![crate::geometry::lod::Lod {
                    mesh: (*m).clone(),
                    target_fraction: 1.0,
                    error_abs: 0.0,
                }],
                None => Vec::new(),
            },
        })
        .collect();
    let refs: Vec<&crate::geometry::lod::LodChain> = chains.iter().collect();
    let probe = Animated::new(
        clip.clone(),
        rig.clone(),
        1,
        vec![None; instances.len()],
        deformers,
    );
    let mut posed = crate::scene::animated::Posed::default();
    probe.pose(&refs, 0, matrix, &mut posed);
    for p in posed.lods {
        out[p.model as usize] = Some(p.positions);
    }
    out
}

/// The deformers of the deformed models (`specs`, per model; each has one instance).
pub fn deformers(specs: &[Option<DeformSpec>], instances: &[PendingInstance]) -> Vec<Deformer> {
    specs
        .iter()
        .enumerate()
        .filter_map(|(m, d)| {
            let d = d.as_ref()?;
            let instance = instances.iter().position(|i| i.model == m)?;
            Some(Deformer {
                model: m as u32,
                instance,
                node: d.node,
                rest_weights: d.rest_weights.clone(),
                targets: d.targets,
                skin: d.skin.clone(),
            })
        })
        .collect()
}

/// The note a run prints of the clip that plays.
pub fn note(file: &str, a: &Animated, instances: usize) -> String {
    format!(
        "{file}: animation {} '{}' plays ({:.3} s, looped at 60 frames a second): {} instance(s) move, {} model(s) \
         deformed",
        a.clip.index,
        a.clip.name,
        a.clip.end_s - a.clip.start_s,
        (0..instances).filter(|&i| a.instance_matrix(i, 0).is_some()).count(),
        a.deformers.len()
    )
}

/// Widens each deformed model's reach and radius to every frame's pose (coverage tiles and shadow bounds rely
/// on them).
pub fn widen_to_poses(
    animated: &Animated,
    models: &mut [Model],
    matrix: &dyn Fn(usize, u32) -> Mat4,
) {
    let chains: Vec<&crate::geometry::lod::LodChain> = models.iter().map(|m| &m.chain).collect();
    let centres: Vec<glam::Vec3> = models.iter().map(|m| m.center).collect();
    let reaches = animated.deformed_reach(&chains, &centres, matrix);
    for (m, reach, radius) in reaches {
        let model = &mut models[m as usize];
        let rest = model
            .chain
            .lods
            .iter()
            .map(|l| l.mesh.bounds())
            .fold(reach, |a, b| (a.0.min(b.0), a.1.max(b.1)));
        model.deformed_reach = Some(rest);
        model.radius = model.radius.max(radius);
    }
}
