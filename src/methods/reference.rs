//! `reference`: the high-poly baseline of Sheliemietiev et al. 2023 section 6: every instance at LOD0, always. The quality pass
//! compares every method against this.

use super::common::{Counterfactual, FrameInput, Method, OpaqueInstances};
use crate::effects::shadow::Caster;
use crate::gpu::{DrawStats, RenderTarget, SceneGpu};
use crate::scene::schedule::InstanceState;
use crate::scene::Scene;

pub struct Reference {
    draw: OpaqueInstances,
}

impl Reference {
    pub fn new(gpu: &SceneGpu, scene: &Scene) -> Self {
        Reference {
            draw: OpaqueInstances::new(gpu, scene, "reference instances"),
        }
    }

    /// `reference-flat`: the reference's triangles with the flat surface (one colour per model, Lambert and
    /// ambient, no texture read), whatever the scene's materials: paired with `reference`, the cost of drawing
    /// the materials (the same image as `reference` in a scene without them).
    pub fn flat(gpu: &SceneGpu, scene: &Scene) -> Self {
        Reference {
            draw: OpaqueInstances::flat(gpu, scene, "reference-flat instances"),
        }
    }
}

impl Method for Reference {
    fn encode(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
    ) -> DrawStats {
        self.draw
            .encode(gpu, input, encoder, target, "reference pass", |_| 0)
    }

    /// LOD0, always.
    fn shadow_caster(&self, _states: &[InstanceState], _i: usize, _before: bool) -> Caster {
        Caster::Lod(0)
    }

    fn counterfactual(&mut self) -> Option<&mut dyn Counterfactual> {
        Some(self)
    }
}

impl Counterfactual for Reference {
    fn image_confined_to_instances(&self) -> bool {
        true
    }

    /// LOD0 whatever the state.
    fn same_image_state(&self, _a: &InstanceState, _b: &InstanceState) -> bool {
        true
    }
}
