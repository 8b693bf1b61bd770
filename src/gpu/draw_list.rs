//! Draw lists: a frame's instanced draws, bucketed by (shader variant, model, LOD) or kept in order, and the
//! per-instance data they carry.

use bytemuck::{Pod, Zeroable};
use glam::Mat4;

/// Per-instance vertex data (96 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct InstanceRaw {
    pub model: [[f32; 4]; 4],
    pub color: [f32; 4],
    /// x = k, y = alpha, z = LOD, w = instance id.
    pub params: [f32; 4],
}

impl InstanceRaw {
    /// `color` is linear RGB plus the instance's animation angle in radians (windmill blades).
    pub fn new(model: &Mat4, color: [f32; 4], params: [f32; 4]) -> Self {
        InstanceRaw {
            model: model.to_cols_array_2d(),
            color,
            params,
        }
    }
}

/// Index of a pipeline in the slice a method passes to [`SceneGpu::draw`] (its shader variant).
pub type PipelineIndex = u8;

/// One instanced draw call.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Draw {
    pub pipeline: PipelineIndex,
    pub model: u32,
    pub lod: u32,
    pub first_instance: u32,
    pub instance_count: u32,
}

/// Triangles and draw calls a method really submitted in a frame.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DrawStats {
    pub triangles: u64,
    pub draw_calls: u32,
    /// Clusters drawn (`clusterlod`; 1 for the one mesh of `roam`); None for methods that draw whole instances.
    pub clusters: Option<u64>,
    /// What a method that selects its own geometry changed this frame and the CPU time of the selection
    /// (`roam`); None for the others.
    pub selection: Option<Selection>,
}

/// One frame's selection work (`roam`): bintree nodes split and merged, and the CPU time of the update.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Selection {
    pub splits: u32,
    pub merges: u32,
    pub cpu_ns: u64,
}

/// A frame's draws: items added in any order, then sorted into buckets by (pipeline, model, LOD) so that each
/// bucket is one instanced draw ([`DrawList::build`]), or kept in the order given, merging only neighbours of
/// the same bucket ([`DrawList::build_in_order`], for back-to-front translucent draws). The vectors are kept
/// between frames, so nothing is allocated per frame once they have grown.
#[derive(Debug, Default)]
pub struct DrawList {
    items: Vec<((PipelineIndex, u32, u32), u32, InstanceRaw)>,
    pub instances: Vec<InstanceRaw>,
    pub draws: Vec<Draw>,
}

impl DrawList {
    /// A list of these draws alone (their instances already uploaded).
    pub fn of_draws(draws: Vec<Draw>) -> DrawList {
        DrawList {
            draws,
            ..Default::default()
        }
    }

    pub fn clear(&mut self) {
        self.items.clear();
        self.instances.clear();
        self.draws.clear();
    }

    pub fn push(&mut self, pipeline: PipelineIndex, model: u32, lod: u32, raw: InstanceRaw) {
        let order = self.items.len() as u32;
        self.items.push(((pipeline, model, lod), order, raw));
    }

    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// Sorts into buckets (stable: instances keep their order inside a bucket) and fills `instances` and
    /// `draws`.
    pub fn build(&mut self) {
        self.items
            .sort_unstable_by_key(|(key, order, _)| (*key, *order));
        self.build_in_order();
    }

    /// Keeps the order of `push`; neighbours of the same bucket share a draw (instances of one draw are
    /// rasterised in order, so the order is kept).
    pub fn build_in_order(&mut self) {
        self.instances.clear();
        self.draws.clear();
        for (i, ((pipeline, model, lod), _, raw)) in self.items.iter().enumerate() {
            self.instances.push(*raw);
            match self.draws.last_mut() {
                Some(d) if d.pipeline == *pipeline && d.model == *model && d.lod == *lod => {
                    d.instance_count += 1
                }
                _ => self.draws.push(Draw {
                    pipeline: *pipeline,
                    model: *model,
                    lod: *lod,
                    first_instance: i as u32,
                    instance_count: 1,
                }),
            }
        }
    }
}

impl std::ops::Add for DrawStats {
    type Output = DrawStats;
    fn add(self, o: DrawStats) -> DrawStats {
        DrawStats {
            triangles: self.triangles + o.triangles,
            draw_calls: self.draw_calls + o.draw_calls,
            clusters: match (self.clusters, o.clusters) {
                (None, None) => None,
                (a, b) => Some(a.unwrap_or(0) + b.unwrap_or(0)),
            },
            selection: match (self.selection, o.selection) {
                (None, None) => None,
                (a, b) => {
                    let (a, b) = (a.unwrap_or_default(), b.unwrap_or_default());
                    Some(Selection {
                        splits: a.splits + b.splits,
                        merges: a.merges + b.merges,
                        cpu_ns: a.cpu_ns + b.cpu_ns,
                    })
                }
            },
        }
    }
}

impl std::ops::AddAssign for DrawStats {
    fn add_assign(&mut self, o: DrawStats) {
        *self = *self + o;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn raw(id: f32) -> InstanceRaw {
        InstanceRaw::new(&Mat4::IDENTITY, [1.0, 1.0, 1.0, 0.0], [0.0, 0.0, 0.0, id])
    }

    #[test]
    fn draw_list_buckets_by_variant_model_lod() {
        let mut l = DrawList::default();
        l.push(0, 0, 2, raw(0.0));
        l.push(0, 0, 0, raw(1.0));
        l.push(0, 0, 2, raw(2.0));
        l.push(0, 1, 0, raw(3.0));
        l.build();
        assert_eq!(l.draws.len(), 3);
        assert_eq!((l.draws[0].lod, l.draws[0].instance_count), (0, 1));
        assert_eq!((l.draws[1].lod, l.draws[1].instance_count), (2, 2));
        assert_eq!((l.draws[2].model, l.draws[2].first_instance), (1, 3));
        // Stable inside a bucket.
        assert_eq!(l.instances[1].params[3], 0.0);
        assert_eq!(l.instances[2].params[3], 2.0);
        l.clear();
        l.build();
        assert!(l.draws.is_empty());
    }
}
