//! `discrete`: plain discrete LOD switching, the popping baseline of Sheliemietiev et al. 2023 section 6 and Scherzer & Wimmer 2008 Fig. 8.
//! Each instance shows one LOD; the switch is hard, at the centre of the schedule's band (k = 0.5, i.e. at the
//! switch distance itself).

use super::common::{Counterfactual, FrameInput, Method, OpaqueInstances};
use crate::effects::shadow::Caster;
use crate::gpu::{DrawStats, RenderTarget, SceneGpu};
use crate::scene::schedule::InstanceState;
use crate::scene::Scene;

pub struct Discrete {
    draw: OpaqueInstances,
}

impl Discrete {
    pub fn new(gpu: &SceneGpu, scene: &Scene) -> Self {
        Discrete {
            draw: OpaqueInstances::new(gpu, scene, "discrete instances"),
        }
    }

    /// `discrete-mesh`: discrete with `--impostor`'s cards left out, each model's last mesh level drawn in their
    /// place: the frame the impostor saves the cost of, paired with discrete round by round in the same run
    /// (without `--impostor` it is discrete itself, an A/A pair).
    pub fn without_impostors(gpu: &SceneGpu, scene: &Scene) -> Self {
        Discrete {
            draw: OpaqueInstances::without_impostors(gpu, scene, "discrete-mesh instances"),
        }
    }

    /// `blocks-discrete` (Blow 2003a and 2003b without the blending): each block of a unified scene switches
    /// hard, and the seams between the blocks' LODs close the cracks.
    pub fn with_seams(gpu: &SceneGpu, scene: &Scene) -> Self {
        Discrete {
            draw: OpaqueInstances::with_seams(gpu, scene, "blocks-discrete instances"),
        }
    }
}

impl Method for Discrete {
    fn encode(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
    ) -> DrawStats {
        self.draw
            .encode(gpu, input, encoder, target, "discrete pass", |s| {
                s.discrete_lod()
            })
    }

    /// The LOD it shows.
    fn shadow_caster(&self, states: &[InstanceState], i: usize, _before: bool) -> Caster {
        Caster::Lod(states[i].discrete_lod())
    }

    fn counterfactual(&mut self) -> Option<&mut dyn Counterfactual> {
        Some(self)
    }
}

impl Counterfactual for Discrete {
    fn image_confined_to_instances(&self) -> bool {
        true
    }

    /// The LOD shown is the whole of the state's effect: k reaches the instance data (params.x) but the
    /// opaque pipeline's fragment shader does not read it.
    fn same_image_state(&self, a: &InstanceState, b: &InstanceState) -> bool {
        a.discrete_lod() == b.discrete_lod()
    }
}
