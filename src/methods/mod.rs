//! Transition methods behind one trait and a registry. A method only decides how to draw the shared schedule's
//! `(lod_from, lod_to, k)` per instance; it never selects LODs itself.

mod discrete;
mod reference;

use crate::error::{Error, Result};
use crate::gpu::renderer::{
    DrawList, DrawStats, InstanceBuffer, InstanceRaw, RenderTarget, SceneGpu,
};
use crate::gpu::Variant;
use crate::scene::Scene;
use crate::schedule::InstanceState;
use glam::Mat4;

/// Every method name `--method` accepts, in the order runs use when none is given.
pub const METHODS: &[&str] = &["reference", "discrete"];

/// What a method gets for one frame.
pub struct FrameInput<'a> {
    pub frame: u32,
    pub scene: &'a Scene,
    /// One state per instance, from the shared schedule.
    pub states: &'a [InstanceState],
    /// One object-to-world matrix per instance.
    pub matrices: &'a [Mat4],
}

pub trait Method {
    fn name(&self) -> &'static str;

    /// Writes the frame's per-instance data (through the queue, before the submission) and records its passes
    /// into `encoder`, leaving the final image in `target`. Returns what it really submitted.
    fn encode(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
    ) -> DrawStats;

    /// Render-target memory the method holds beyond the frame's own colour and depth target, in bytes.
    fn extra_target_bytes(&self) -> u64 {
        0
    }
}

/// Builds the method called `name` for `scene`; GPU objects are created here, once.
pub fn create(name: &str, gpu: &SceneGpu, scene: &Scene) -> Result<Box<dyn Method>> {
    match name {
        "reference" => Ok(Box::new(reference::Reference::new(gpu, scene))),
        "discrete" => Ok(Box::new(discrete::Discrete::new(gpu, scene))),
        _ => Err(Error::unknown("method", name, METHODS)),
    }
}

/// Shared by methods that draw every instance once, opaque, at one LOD each.
pub(crate) struct OpaqueInstances {
    list: DrawList,
    buffer: InstanceBuffer,
}

impl OpaqueInstances {
    pub fn new(gpu: &SceneGpu, scene: &Scene, label: &str) -> Self {
        OpaqueInstances {
            list: DrawList::default(),
            buffer: gpu.create_instance_buffer(label, scene.instances.len() as u32),
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
            let model = &input.scene.models[inst.model as usize];
            let lod = lod_of(state);
            self.list.push(
                Variant::Opaque,
                inst.model,
                lod,
                InstanceRaw::new(
                    &input.matrices[i],
                    model.color,
                    [state.k, 1.0, lod as f32, 0.0],
                ),
            );
        }
        self.list.build();
        gpu.upload(&self.buffer, &self.list);
        let mut pass = gpu.begin_clear_pass(encoder, target, label);
        gpu.draw(&mut pass, &self.buffer, &self.list)
    }
}
