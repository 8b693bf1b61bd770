//! `alpha-2pass` and `alpha-linear`: the double pass of Sheliemietiev et al. 2023 section 11. Each translucent LOD contributes
//! only its nearest surface, so its own back faces never show through: a depth-only pass writes the object's
//! nearest depth, then a colour pass draws it again with a depth-equal test and blending.
//!
//! The two differ in their weights ([`Weights`]):
//! - `alpha-2pass` keeps Giegl's unpopping schedule (Scherzer & Wimmer 2008 Fig. 2): one LOD of a t-instance is opaque (drawn
//!   with the rest of the scene), the other translucent over it with alpha 2k or 2(1 - k), one double pass per
//!   t-instance.
//! - `alpha-linear` is Sheliemietiev et al. 2023's own blending (section 8, eq. 2, and the `DrawTransparentModelDoublePass`
//!   listing): during a transition both LODs are translucent, the outgoing one (`lod_from`) with weight 1 - k,
//!   then the incoming one (`lod_to`) with weight k, each with its own double pass (depth cleared, depth only,
//!   then colour with depth read-only and `colour = w src + (1 - w) dst`): 4 draw calls per t-instance. A LOD
//!   whose weight is 0 is not drawn (the paper: "when the transparency of the old model reaches zero, the old
//!   model is not drawn"). The listing's blend is over the frame, so what lies behind the object shows through
//!   with weight k (1 - k) (a quarter at k = 0.5): Sheliemietiev et al. 2023's "translucent ghost" at close range. The paper
//!   does not say which LOD is drawn first; here the outgoing one, so at k = 0 and k = 1 the frame is exactly
//!   one LOD.
//!
//! The paper clears the whole depth buffer before each translucent model, which would let it draw over nearer
//! objects that should hide it. Here the object's depth passes go to a depth buffer of the method's own
//! (`object_depth`, cleared per t-instance), and the colour pass reads the scene's depth buffer (the opaque
//! pass's) as a texture and drops fragments behind it: occlusion by the rest of the scene stays intact, and,
//! in `alpha-2pass`, as in `alpha`, the object's own opaque LOD hides the parts of the translucent one that lie
//! behind it (`alpha-linear` has no opaque LOD in transition, so the scene depth holds only the other
//! objects). Cost: two render passes per translucent draw.

use super::alpha::OVER;
use super::common::{BlendLists, Counterfactual, FrameInput, Method};
use crate::formats::DEPTH_FORMAT;
use crate::gpu::{texture_2d, DrawStats, InstanceBuffer, MeshPipeline, RenderTarget, SceneGpu};
use crate::scene::schedule::InstanceState;
use crate::scene::Scene;

/// How a t-instance's two LODs are weighted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Weights {
    /// Giegl's unpopping (`alpha-2pass`): one LOD opaque, the other translucent with alpha 2k or 2(1 - k).
    Unpop,
    /// Sheliemietiev et al. 2023's eq. 2 (`alpha-linear`): both translucent, `lod_from` with 1 - k, then `lod_to` with k.
    Linear,
}

/// The translucent draws of a t-instance under `weights` (LOD, weight), in drawing order; none for an
/// n-instance. Unpop's opaque LOD is not among them.
pub fn translucent_draws(weights: Weights, s: &InstanceState) -> [Option<(u32, f32)>; 2] {
    if !s.in_transition() {
        return [None, None];
    }
    match weights {
        Weights::Unpop => [super::common::unpop(s).translucent, None],
        Weights::Linear => {
            [(s.lod_from, 1.0 - s.k), (s.lod_to, s.k)].map(|(lod, w)| (w > 0.0).then_some((lod, w)))
        }
    }
}

/// The opaque LOD of an instance under `weights`: Giegl's unpopping always has one, Sheliemietiev et al. 2023's blend only
/// outside transitions.
fn opaque_lod(weights: Weights, s: &InstanceState) -> Option<u32> {
    match weights {
        Weights::Unpop => Some(super::common::unpop(s).opaque),
        Weights::Linear => (!s.in_transition()).then_some(s.lod_from),
    }
}

pub struct AlphaTwoPass {
    weights: Weights,
    lists: BlendLists,
    buffer: InstanceBuffer,
    depth_only: crate::gpu::MeshPipelines,
    colour: crate::gpu::MeshPipelines,
    scene_depth_layout: wgpu::BindGroupLayout,
    /// Bind groups of the scene-depth textures seen so far (one per render target: timing, quality).
    scene_depth_groups: Vec<(wgpu::Texture, wgpu::BindGroup)>,
    object_depth: wgpu::Texture,
    object_depth_view: wgpu::TextureView,
}

impl AlphaTwoPass {
    pub fn new(gpu: &SceneGpu, scene: &Scene, weights: Weights) -> Self {
        let scene_depth_layout =
            gpu.device
                .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some("alpha-2pass scene depth layout"),
                    entries: &[wgpu::BindGroupLayoutEntry {
                        binding: 2,
                        visibility: wgpu::ShaderStages::FRAGMENT,
                        ty: wgpu::BindingType::Texture {
                            sample_type: wgpu::TextureSampleType::Depth,
                            view_dimension: wgpu::TextureViewDimension::D2,
                            multisampled: false,
                        },
                        count: None,
                    }],
                });
        let object_depth = texture_2d(
            &gpu.device,
            "alpha-2pass object depth",
            (scene.width, scene.height),
            DEPTH_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        AlphaTwoPass {
            weights,
            lists: BlendLists::default(),
            buffer: gpu
                .create_instance_buffer("alpha-2pass instances", 2 * scene.instances.len() as u32),
            depth_only: gpu.mesh_pipeline(&MeshPipeline {
                label: "alpha-2pass depth only",
                morph: false,
                fragment: None,
                id_target: None,
                cull: None,
                depth_compare: wgpu::CompareFunction::Less,
                depth_write: true,
                blend: None,
                extra_layouts: &[],
            }),
            colour: gpu.mesh_pipeline(&MeshPipeline {
                label: "alpha-2pass colour",
                morph: false,
                fragment: Some("fs_translucent_occluded"),
                id_target: None,
                cull: None,
                depth_compare: wgpu::CompareFunction::Equal,
                depth_write: false,
                blend: Some(OVER),
                extra_layouts: &[&scene_depth_layout],
            }),
            scene_depth_layout,
            scene_depth_groups: Vec::new(),
            object_depth_view: object_depth.create_view(&Default::default()),
            object_depth,
        }
    }

    fn scene_depth_group(&mut self, gpu: &SceneGpu, target: &RenderTarget) -> usize {
        if let Some(i) = self
            .scene_depth_groups
            .iter()
            .position(|(t, _)| *t == target.depth)
        {
            return i;
        }
        let group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("alpha-2pass scene depth"),
            layout: &self.scene_depth_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 2,
                resource: wgpu::BindingResource::TextureView(&target.depth_view),
            }],
        });
        self.scene_depth_groups.push((target.depth.clone(), group));
        self.scene_depth_groups.len() - 1
    }
}

impl Method for AlphaTwoPass {
    fn material_limits(&self, materials: &crate::geometry::material::Materials) -> Option<String> {
        materials
            .materials
            .iter()
            .any(|m| m.alpha == crate::geometry::material::AlphaMode::Blend)
            .then(|| "BLEND materials' parts of an instance in transition are not drawn: the double pass keeps the fragments at each translucent LOD's nearest opaque surface (a depth-equal test), and a blended surface writes no depth".to_string())
    }

    fn extra_target_bytes(&self) -> u64 {
        let s = self.object_depth.size();
        s.width as u64 * s.height as u64 * 4
    }

    fn encode(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
    ) -> DrawStats {
        let group = self.scene_depth_group(gpu, target);
        // Translucent neighbours of one bucket share a draw; each of its instances gets its own pair of passes.
        let weights = self.weights;
        let n_opaque = self.lists.prepare_with(
            gpu,
            input,
            &self.buffer,
            |s| opaque_lod(weights, s),
            |s| translucent_draws(weights, s).map(|d| d.map(|(lod, w)| (0, lod, w))),
        );
        let (opaque, translucent) = (&self.lists.opaque, &self.lists.translucent);
        let mut stats = {
            let mut pass = gpu.begin_clear_pass(encoder, target, input.view, "alpha-2pass opaque");
            gpu.draw(&mut pass, &self.buffer, 0, opaque, &[&gpu.opaque_pipeline])
        };
        for d in &translucent.draws {
            for j in 0..d.instance_count {
                let at = n_opaque + d.first_instance + j;
                {
                    let mut pass = gpu.begin_depth_pass(
                        encoder,
                        &self.object_depth_view,
                        input.view,
                        "alpha-2pass nearest surface",
                    );
                    stats += gpu.draw_instances(
                        &mut pass,
                        &self.buffer,
                        at,
                        1,
                        d.model,
                        d.lod,
                        &self.depth_only,
                    );
                }
                let mut pass = gpu.begin_pass(
                    encoder,
                    (&target.color_view, &self.object_depth_view),
                    input.view,
                    "alpha-2pass colour",
                    false,
                );
                pass.set_bind_group(1, &self.scene_depth_groups[group].1, &[]);
                stats += gpu.draw_instances(
                    &mut pass,
                    &self.buffer,
                    at,
                    1,
                    d.model,
                    d.lod,
                    &self.colour,
                );
            }
        }
        stats
    }

    fn counterfactual(&mut self) -> Option<&mut dyn Counterfactual> {
        Some(self)
    }
}

impl Counterfactual for AlphaTwoPass {
    fn image_confined_to_instances(&self) -> bool {
        true
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

    fn translucent_draws(weights: Weights, s: &InstanceState) -> Vec<(u32, f32)> {
        super::translucent_draws(weights, s)
            .into_iter()
            .flatten()
            .collect()
    }

    #[test]
    fn linear_weights_are_one_minus_k_then_k() {
        assert!(translucent_draws(Weights::Linear, &st(2, 2, 0.0)).is_empty());
        assert_eq!(
            translucent_draws(Weights::Linear, &st(1, 2, 0.25)),
            vec![(1, 0.75), (2, 0.25)]
        );
        // Coarsening and refining alike: the outgoing LOD first.
        assert_eq!(
            translucent_draws(Weights::Linear, &st(2, 1, 0.5)),
            vec![(2, 0.5), (1, 0.5)]
        );
        // A LOD of weight 0 is not drawn.
        assert_eq!(
            translucent_draws(Weights::Linear, &st(0, 1, 0.0)),
            vec![(0, 1.0)]
        );
    }

    #[test]
    fn unpop_weights_keep_one_lod_opaque() {
        // Only the translucent LOD is listed; the opaque one goes with the rest of the scene.
        assert_eq!(
            translucent_draws(Weights::Unpop, &st(1, 2, 0.25)),
            vec![(2, 0.5)]
        );
        assert_eq!(
            translucent_draws(Weights::Unpop, &st(1, 2, 0.75)),
            vec![(1, 0.5)]
        );
    }
}
