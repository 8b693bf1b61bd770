//! A user scene's animation on the run's timeline: frame f shows the clip at `start + (f / ANIMATION_FPS mod
//! duration)` seconds (the clip loops), its moving instances placed by a matrix per frame, its skinned and
//! morph-animated models deformed per frame on the CPU (`geometry/deform.rs`).
//!
//! A moving instance's model space is fixed to it: an unskinned node's model is its mesh under the node's rest
//! scale (as for a static one), placed each frame by the node's animated world matrix; a skinned model is its
//! mesh posed at rest in world space, placed each frame by the rigid part of its skeleton root's motion since
//! rest, and deformed inside that frame, so the LOD schedule follows the character as it moves while the skin
//! bends the vertices.

use crate::geometry::deform::{deform_with_tangents, Placing};
use crate::geometry::gltf::Rig;
use crate::geometry::lod::LodChain;
use glam::{Mat4, Vec3};
use serde::Serialize;

/// Frames per second of clip time.
pub const ANIMATION_FPS: f32 = 60.0;

/// The clip a run plays.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Clip {
    pub index: usize,
    pub name: String,
    pub start_s: f32,
    pub end_s: f32,
}

impl Clip {
    /// The clip time frame `f` shows: frames at [`ANIMATION_FPS`] from the clip's start, looped over its
    /// duration (a clip of one key time holds it).
    pub fn time_of(&self, f: u32) -> f32 {
        let duration = self.end_s - self.start_s;
        let t = f as f32 / ANIMATION_FPS;
        if duration > 0.0 {
            self.start_s + t.rem_euclid(duration)
        } else {
            self.start_s
        }
    }
}

/// A skin as a deformer uses it: joint nodes and inverse bind matrices.
#[derive(Debug, Clone)]
pub struct SkinBinding {
    pub joints: Vec<usize>,
    pub inverse_bind: Vec<Mat4>,
}

/// How one deformed model's vertices are made each frame. A deformed model has one instance (its pose is its
/// node's own).
#[derive(Debug, Clone)]
pub struct Deformer {
    pub model: u32,
    pub instance: usize,
    /// The glTF node whose morph weights (and skin) drive it.
    pub node: usize,
    /// Its morph weights where the clip does not drive them.
    pub rest_weights: Vec<f32>,
    pub targets: usize,
    /// Skinned: the joints; not skinned, the morph targets' displacements are in model space already.
    pub skin: Option<SkinBinding>,
}

/// One deformed LOD as a frame poses it.
#[derive(Debug, Default)]
pub struct PosedLod {
    pub model: u32,
    pub lod: u32,
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    /// Empty when the mesh has no tangents.
    pub tangents: Vec<[f32; 4]>,
}

/// Every deformed model's LODs as one frame poses them.
#[derive(Debug, Default)]
pub struct Posed {
    pub lods: Vec<PosedLod>,
}

impl Posed {
    /// The posed vertices of `model`'s LOD `lod`, when it is deformed.
    pub fn of(&self, model: u32, lod: u32) -> Option<&PosedLod> {
        self.lods.iter().find(|p| p.model == model && p.lod == lod)
    }
}

/// What moves in a user scene, frame by frame.
#[derive(Debug)]
pub struct Animated {
    pub clip: Clip,
    pub rig: Rig,
    frames: u32,
    /// Per instance: its track in `matrices`, when it moves.
    track_of: Vec<Option<u32>>,
    /// Track t's model-to-world matrix on frame f at `t * frames + f`.
    matrices: Vec<Mat4>,
    pub deformers: Vec<Deformer>,
}

impl Serialize for Animated {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        #[derive(Serialize)]
        struct Summary<'a> {
            clip: &'a Clip,
            fps: f32,
            moving_instances: usize,
            deformed_models: usize,
        }
        Summary {
            clip: &self.clip,
            fps: ANIMATION_FPS,
            moving_instances: self.track_of.iter().flatten().count(),
            deformed_models: self.deformers.len(),
        }
        .serialize(s)
    }
}

impl Animated {
    /// `tracks`: per instance, its model-to-world matrix on every frame when it moves (None when static).
    pub fn new(
        clip: Clip,
        rig: Rig,
        frames: u32,
        tracks: Vec<Option<Vec<Mat4>>>,
        deformers: Vec<Deformer>,
    ) -> Animated {
        let mut track_of = Vec::with_capacity(tracks.len());
        let mut matrices = Vec::new();
        let mut next = 0u32;
        for t in tracks {
            match t {
                Some(m) => {
                    debug_assert_eq!(m.len(), frames as usize);
                    matrices.extend(m);
                    track_of.push(Some(next));
                    next += 1;
                }
                None => track_of.push(None),
            }
        }
        Animated {
            clip,
            rig,
            frames,
            track_of,
            matrices,
            deformers,
        }
    }

    /// Instance `i`'s model-to-world matrix on `frame`, when it moves.
    pub fn instance_matrix(&self, i: usize, frame: u32) -> Option<Mat4> {
        let t = (*self.track_of.get(i)?)?;
        let f = frame.min(self.frames.saturating_sub(1));
        self.matrices.get((t * self.frames + f) as usize).copied()
    }

    /// Whether anything moves or deforms.
    pub fn is_still(&self) -> bool {
        self.track_of.iter().all(Option::is_none) && self.deformers.is_empty()
    }

    /// Poses every deformed model's LODs on `frame` into `out` (its buffers reused): `chains[m]` is model m's
    /// chain, `model_to_world` gives each instance's matrix on that frame.
    pub fn pose(
        &self,
        chains: &[&LodChain],
        frame: u32,
        model_to_world: &dyn Fn(usize) -> Mat4,
        out: &mut Posed,
    ) {
        let t = self.clip.time_of(frame);
        let worlds = self.rig.worlds_at(t);
        let mut slot = 0;
        for d in &self.deformers {
            let weights = self
                .rig
                .weights_at(d.node, t, d.targets)
                .unwrap_or_else(|| d.rest_weights.clone());
            let joints: Vec<Mat4> = match &d.skin {
                Some(s) => {
                    let to_model = model_to_world(d.instance).inverse();
                    s.joints
                        .iter()
                        .zip(&s.inverse_bind)
                        .map(|(&j, ibm)| to_model * worlds[j] * *ibm)
                        .collect()
                }
                None => Vec::new(),
            };
            let placing = match d.skin {
                Some(_) => Placing::Skin(&joints),
                None => Placing::Rigid(Mat4::IDENTITY),
            };
            for (l, lod) in chains[d.model as usize].lods.iter().enumerate() {
                let Some(data) = lod.mesh.data.deform.as_deref() else {
                    continue;
                };
                if out.lods.len() <= slot {
                    out.lods.push(PosedLod::default());
                }
                let p = &mut out.lods[slot];
                (p.model, p.lod) = (d.model, l as u32);
                p.positions.resize(data.base_positions.len(), [0.0; 3]);
                p.normals.resize(data.base_positions.len(), [0.0; 3]);
                let n = data.base_tangents.as_ref().map_or(0, Vec::len);
                p.tangents.resize(n, [0.0; 4]);
                deform_with_tangents(
                    data,
                    &weights,
                    placing,
                    &mut p.positions,
                    &mut p.normals,
                    (n > 0).then_some(p.tangents.as_mut_slice()),
                );
                slot += 1;
            }
        }
        out.lods.truncate(slot);
    }

    /// The box (model space) holding every vertex each deformed model takes on any frame, and the largest
    /// distance of one from the model's centre (`centres[m]`), per deformer: what coverage tiles and shadow bounds
    /// need.
    pub fn deformed_reach(
        &self,
        chains: &[&LodChain],
        centres: &[Vec3],
        model_to_world: &dyn Fn(usize, u32) -> Mat4,
    ) -> Vec<(u32, (Vec3, Vec3), f32)> {
        let mut reach: Vec<(u32, (Vec3, Vec3), f32)> = self
            .deformers
            .iter()
            .map(|d| {
                (
                    d.model,
                    (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                    0.0,
                )
            })
            .collect();
        let mut posed = Posed::default();
        for f in 0..self.frames {
            self.pose(chains, f, &|i| model_to_world(i, f), &mut posed);
            for p in &posed.lods {
                let Some(r) = reach.iter_mut().find(|r| r.0 == p.model) else {
                    continue;
                };
                let c = centres[p.model as usize];
                for v in &p.positions {
                    let v = Vec3::from(*v);
                    r.1 .0 = r.1 .0.min(v);
                    r.1 .1 = r.1 .1.max(v);
                    r.2 = f32::max(r.2, v.distance(c));
                }
            }
        }
        reach
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Frames run at 60 per second from the clip's start and loop over its duration.
    #[test]
    fn clip_time_loops() {
        let clip = Clip {
            index: 0,
            name: String::new(),
            start_s: 1.0,
            end_s: 2.0,
        };
        assert_eq!(clip.time_of(0), 1.0);
        assert_eq!(clip.time_of(30), 1.5);
        assert_eq!(clip.time_of(60), 1.0);
        assert!((clip.time_of(75) - 1.25).abs() < 1e-6);
        let held = Clip { end_s: 1.0, ..clip };
        assert_eq!(held.time_of(75), 1.0);
    }
}
