//! What every method shares: the traits (`traits.rs`, re-exported here, so a method's file imports this file
//! alone) and the drawing helpers several methods use (the unpopping schedule and its draw lists, opaque
//! one-LOD-per-instance drawing, per-instance data).

pub use super::traits::{ask_counterfactual, Counterfactual, DumpKind, FrameInput, Method};
use crate::effects::shadow::Caster;
use crate::gpu::{
    DrawList, DrawStats, InstanceBuffer, InstanceRaw, RenderTarget, SceneGpu, Vertex,
};
use crate::scene::schedule::InstanceState;
use crate::scene::Scene;
use glam::Mat4;

/// The shadow map's draw list of one frame: each instance's caster (`caster(i)`; the ground casts nothing),
/// pipelines `gpu::shadow::CAST_WHOLE` and `CAST_DITHERED` (params: k, then 1 for the incoming LOD, 0 for the
/// outgoing).
pub fn shadow_list(input: &FrameInput<'_>, caster: impl Fn(usize) -> Caster, list: &mut DrawList) {
    use crate::gpu::shadow_pass::{CAST_DITHERED, CAST_WHOLE};
    list.clear();
    for (i, inst) in input.scene.instances.iter().enumerate() {
        if input.scene.ground == Some(i) {
            continue;
        }
        match caster(i) {
            Caster::Lod(lod) => list.push(
                CAST_WHOLE,
                inst.model,
                lod,
                instance_raw(input, i, 0.0, 1.0, lod),
            ),
            Caster::Dither { from, to, k } => {
                list.push(
                    CAST_DITHERED,
                    inst.model,
                    to,
                    instance_raw(input, i, k, 1.0, to),
                );
                list.push(
                    CAST_DITHERED,
                    inst.model,
                    from,
                    instance_raw(input, i, k, 0.0, from),
                );
            }
        }
    }
    list.build();
}

/// The Giegl-Wimmer "unpopping" schedule (Scherzer & Wimmer 2008 Fig. 2, Blow 2003a Fig. 1b): one LOD is always opaque. For
/// k < 0.5 the incoming LOD (`lod_to`) is translucent with alpha 2k over the opaque outgoing one; from k = 0.5
/// the incoming one is opaque and the outgoing one translucent with alpha 2(1 - k).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Unpop {
    pub opaque: u32,
    /// (LOD, alpha) of the translucent draw of a t-instance.
    pub translucent: Option<(u32, f32)>,
    /// True from k = 0.5 on: the roles have swapped.
    pub swapped: bool,
}

pub(crate) fn unpop(s: &InstanceState) -> Unpop {
    if !s.in_transition() {
        return Unpop {
            opaque: s.lod_from,
            translucent: None,
            swapped: false,
        };
    }
    if s.k < 0.5 {
        Unpop {
            opaque: s.lod_from,
            translucent: Some((s.lod_to, 2.0 * s.k)),
            swapped: false,
        }
    } else {
        Unpop {
            opaque: s.lod_to,
            translucent: Some((s.lod_from, 2.0 * (1.0 - s.k))),
            swapped: true,
        }
    }
}

/// Indices of the instances `select` keeps, farthest first (ties by index, so the order is deterministic).
pub(crate) fn back_to_front(
    distances: &[f32],
    out: &mut Vec<usize>,
    select: impl Fn(usize) -> bool,
) {
    out.clear();
    out.extend((0..distances.len()).filter(|&i| select(i)));
    out.sort_by(|&a, &b| distances[b].total_cmp(&distances[a]).then(a.cmp(&b)));
}

/// A t-instance's translucent draws, in drawing order: (pipeline index, LOD, alpha) each, at most two.
pub(crate) type TranslucentDraws = [Option<(u8, u32, f32)>; 2];

/// The draw lists of the blending methods: each instance's opaque LOD (if it has one), then the translucent
/// LODs of the t-instances back to front. Kept between frames.
#[derive(Default)]
pub(crate) struct BlendLists {
    pub opaque: DrawList,
    pub translucent: DrawList,
    order: Vec<usize>,
}

impl BlendLists {
    /// The lists of Giegl's unpopping: every instance's opaque LOD, one translucent draw per t-instance, whose
    /// pipeline index `pipeline_of` picks. See [`BlendLists::prepare_with`].
    pub fn prepare(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        buffer: &InstanceBuffer,
        pipeline_of: impl Fn(&Unpop) -> u8,
    ) -> u32 {
        self.prepare_with(
            gpu,
            input,
            buffer,
            |s| Some(unpop(s).opaque),
            |s| {
                let u = unpop(s);
                [
                    u.translucent
                        .map(|(lod, alpha)| (pipeline_of(&u), lod, alpha)),
                    None,
                ]
            },
        )
    }

    /// Fills and builds both lists and uploads them to `buffer`, opaque first: `opaque_of` gives an instance's
    /// opaque LOD (None: it has none), `translucent_of` a t-instance's translucent draws. Returns the first
    /// instance of the translucent list in `buffer`.
    pub fn prepare_with(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        buffer: &InstanceBuffer,
        opaque_of: impl Fn(&InstanceState) -> Option<u32>,
        translucent_of: impl Fn(&InstanceState) -> TranslucentDraws,
    ) -> u32 {
        self.opaque.clear();
        self.translucent.clear();
        for (i, (inst, s)) in input.scene.instances.iter().zip(input.states).enumerate() {
            if let Some(lod) = opaque_of(s) {
                self.opaque
                    .push(0, inst.model, lod, instance_raw(input, i, s.k, 1.0, lod));
            }
        }
        back_to_front(input.distances, &mut self.order, |i| {
            input.states[i].in_transition()
        });
        for &i in &self.order {
            let s = &input.states[i];
            let model = input.scene.instances[i].model;
            for (pipeline, lod, alpha) in translucent_of(s).into_iter().flatten() {
                self.translucent.push(
                    pipeline,
                    model,
                    lod,
                    instance_raw(input, i, s.k, alpha, lod),
                );
            }
        }
        self.opaque.build();
        self.translucent.build_in_order();
        let n_opaque = self.opaque.instances.len() as u32;
        gpu.upload_at(buffer, 0, &self.opaque);
        gpu.upload_at(buffer, n_opaque, &self.translucent);
        n_opaque
    }
}

/// A vertex buffer of `mesh`'s positions and normals (no aux): what the methods that draw a unified scene's
/// whole mesh themselves (`clusterlod`, `blocks-tree`) upload once.
pub fn mesh_vertex_buffer(
    gpu: &SceneGpu,
    mesh: &crate::geometry::mesh::Mesh,
    label: &str,
) -> wgpu::Buffer {
    use wgpu::util::DeviceExt;
    let vertices: Vec<Vertex> = mesh
        .positions
        .iter()
        .zip(&mesh.normals)
        .map(|(p, n)| Vertex {
            position: *p,
            normal: *n,
            aux: [0.0; 4],
        })
        .collect();
    gpu.device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: bytemuck::cast_slice(&vertices),
            usage: wgpu::BufferUsages::VERTEX,
        })
}

/// The one opaque instance of a method that draws a unified scene's mesh at the identity transform, in the
/// colour of the scene's first model, uploaded.
pub fn identity_instance(gpu: &SceneGpu, scene: &Scene, label: &str) -> InstanceBuffer {
    let instance = gpu.create_instance_buffer(label, 1);
    let mut list = DrawList::default();
    let [r, g, b] = scene.models.first().map_or([0.7; 3], |m| m.color);
    list.push(
        0,
        0,
        0,
        InstanceRaw::new(&Mat4::IDENTITY, [r, g, b, 0.0], [0.0, 1.0, 0.0, 0.0]),
    );
    list.build();
    gpu.upload(&instance, &list);
    instance
}

pub fn instance_raw(input: &FrameInput<'_>, i: usize, k: f32, alpha: f32, lod: u32) -> InstanceRaw {
    instance_raw_with(input, i, lod, [k, alpha, lod as f32, i as f32])
}

/// Instance i drawn at `lod`: its matrix, the LOD's colour and its animation angle this frame, with the
/// method's own `params` (shaders/mesh.wgsl reads them per method).
pub fn instance_raw_with(
    input: &FrameInput<'_>,
    i: usize,
    lod: u32,
    params: [f32; 4],
) -> InstanceRaw {
    let inst = &input.scene.instances[i];
    let model = &input.scene.models[inst.model as usize];
    let [r, g, b] = model.color_of(lod);
    InstanceRaw::new(
        &input.matrices[i],
        [r, g, b, input.scene.animation_angle(i, input.frame)],
        params,
    )
}

/// The seams of a unified scene (Blow 2003b), drawn opaque between the blocks' opaque LODs: seam s between
/// blocks a and b is drawn with its mesh for (LOD of a, LOD of b), at the blocks' shared identity transform.
/// Empty seam meshes (every quad degenerate: both blocks at full resolution) are not drawn.
pub struct SeamDraws {
    list: DrawList,
    buffer: InstanceBuffer,
}

impl SeamDraws {
    /// None when the scene has no seams.
    pub fn new(gpu: &SceneGpu, scene: &Scene) -> Option<SeamDraws> {
        let n = scene.unified.as_ref().map_or(0, |u| u.seams.len());
        (n > 0).then(|| SeamDraws {
            list: DrawList::default(),
            buffer: gpu.create_instance_buffer("seam instances", n as u32),
        })
    }

    /// Builds and uploads the seams for the blocks' opaque LODs (`lod_of(state)` of each block instance).
    pub fn prepare(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        lod_of: impl Fn(&InstanceState) -> u32,
    ) {
        self.list.clear();
        let Some(u) = &input.scene.unified else {
            return;
        };
        for (s, seam) in u.seams.iter().enumerate() {
            let (a, b) = (seam.blocks.0 as usize, seam.blocks.1 as usize);
            let mesh = seam.mesh_index(lod_of(&input.states[a]), lod_of(&input.states[b]));
            if seam.meshes[mesh as usize].indices.is_empty() {
                continue;
            }
            let model = &input.scene.models[input.scene.instances[a].model as usize];
            let [r, g, bl] = model.color;
            self.list.push(
                0,
                gpu.seam_base + s as u32,
                mesh,
                InstanceRaw::new(&Mat4::IDENTITY, [r, g, bl, 0.0], [0.0, 1.0, 0.0, a as f32]),
            );
        }
        self.list.build();
        gpu.upload(&self.buffer, &self.list);
    }

    /// Records the seams prepared last into `pass` with the opaque pipeline.
    pub fn draw(&self, gpu: &SceneGpu, pass: &mut wgpu::RenderPass<'_>) -> DrawStats {
        gpu.draw(pass, &self.buffer, 0, &self.list, &[&gpu.opaque_pipeline])
    }
}

/// Shared by methods that draw every instance once, opaque, at one LOD each (and, for `blocks-discrete`, the
/// seams between them).
pub struct OpaqueInstances {
    list: DrawList,
    buffer: InstanceBuffer,
    seams: Option<SeamDraws>,
    /// A pipeline of its own in place of the scene's opaque one (`reference-flat`'s flat surface).
    pipeline: Option<crate::gpu::MeshPipelines>,
    /// Per model, the finest LOD drawn at most in place of a coarser one (`discrete-mesh`: the last mesh level
    /// in place of an impostor's card); None: every LOD as asked.
    cap: Option<Vec<u32>>,
}

impl OpaqueInstances {
    pub fn new(gpu: &SceneGpu, scene: &Scene, label: &str) -> Self {
        OpaqueInstances {
            list: DrawList::default(),
            buffer: gpu.create_instance_buffer(label, scene.instances.len() as u32),
            seams: None,
            pipeline: None,
            cap: None,
        }
    }

    /// The same, drawing each model's last mesh level where the schedule asks for its impostor's card
    /// (`--impostor`; without it, every LOD as asked).
    pub fn without_impostors(gpu: &SceneGpu, scene: &Scene, label: &str) -> Self {
        let cap = scene
            .models
            .iter()
            .map(|m| {
                let last = m.chain.lods.len() as u32 - 1;
                match crate::geometry::impostor::ends_in_card(&m.chain) {
                    true => last.saturating_sub(1),
                    false => last,
                }
            })
            .collect();
        OpaqueInstances {
            cap: Some(cap),
            ..Self::new(gpu, scene, label)
        }
    }

    /// The same, drawn with the flat surface whatever the scene's ([`SceneGpu::flat_pipeline`]).
    pub fn flat(gpu: &SceneGpu, scene: &Scene, label: &str) -> Self {
        OpaqueInstances {
            pipeline: Some(gpu.flat_pipeline(&crate::gpu::MeshPipeline::opaque(label))),
            ..Self::new(gpu, scene, label)
        }
    }

    /// The same, drawing a unified scene's seams too (none on other scenes).
    pub fn with_seams(gpu: &SceneGpu, scene: &Scene, label: &str) -> Self {
        OpaqueInstances {
            seams: SeamDraws::new(gpu, scene),
            ..Self::new(gpu, scene, label)
        }
    }

    /// Draws instance i at `lod_of(state_i)` into a cleared `target`.
    pub fn encode(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
        label: &str,
        lod_of: impl Fn(&InstanceState) -> u32,
    ) -> DrawStats {
        self.list.clear();
        for (i, (inst, state)) in input.scene.instances.iter().zip(input.states).enumerate() {
            let lod = match &self.cap {
                Some(cap) => lod_of(state).min(cap[inst.model as usize]),
                None => lod_of(state),
            };
            self.list.push(
                0,
                inst.model,
                lod,
                instance_raw(input, i, state.k, 1.0, lod),
            );
        }
        self.list.build();
        gpu.upload(&self.buffer, &self.list);
        if let Some(seams) = &mut self.seams {
            seams.prepare(gpu, input, &lod_of);
        }
        let mut pass = gpu.begin_clear_pass(encoder, target, input.view, label);
        let stats = gpu.draw(
            &mut pass,
            &self.buffer,
            0,
            &self.list,
            &[self.pipeline.as_ref().unwrap_or(&gpu.opaque_pipeline)],
        );
        match &self.seams {
            Some(seams) => stats + seams.draw(gpu, &mut pass),
            None => stats,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn st(from: u32, to: u32, k: f32) -> InstanceState {
        InstanceState {
            lod_from: from,
            lod_to: to,
            k,
        }
    }

    #[test]
    fn unpopping_keeps_one_lod_opaque() {
        assert_eq!(unpop(&st(1, 1, 0.0)).translucent, None);
        let a = unpop(&st(0, 1, 0.2));
        assert_eq!((a.opaque, a.swapped), (0, false));
        assert_eq!(a.translucent, Some((1, 0.4)));
        let b = unpop(&st(0, 1, 0.5));
        assert_eq!((b.opaque, b.swapped), (1, true));
        assert_eq!(b.translucent, Some((0, 1.0)));
        let c = unpop(&st(0, 1, 0.9));
        assert_eq!(c.opaque, 1);
        let (lod, alpha) = c.translucent.unwrap();
        assert_eq!(lod, 0);
        assert!((alpha - 0.2).abs() < 1e-6);
        // Alpha is continuous through the swap: 2k -> 1 from below, 2(1-k) = 1 at k = 0.5.
        let below = unpop(&st(0, 1, 0.4999)).translucent.unwrap().1;
        assert!((below - 1.0).abs() < 1e-3);
    }

    #[test]
    fn back_to_front_sorts_farthest_first() {
        let mut order = Vec::new();
        back_to_front(&[3.0, 9.0, 1.0, 9.0], &mut order, |i| i != 2);
        assert_eq!(order, vec![1, 3, 0]);
    }
}
