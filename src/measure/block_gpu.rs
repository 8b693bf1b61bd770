//! What both passes over a block share: the GPU context, the scene and its GPU objects, the methods' setup, the
//! timing pass's target and the shadow pass.

use super::effects::{ShadowRole, Shadows};
use crate::error::Result;
use crate::gpu::{GpuContext, RenderTarget, SceneGpu};
use crate::methods::{Build, MethodOptions, Registry};
use crate::scene::Scene;

/// Which methods a block can run and what they are built with.
#[derive(Clone)]
pub struct MethodSetup {
    pub registry: Registry,
    pub options: MethodOptions,
    /// `--seed`.
    pub seed: u64,
}

impl Default for MethodSetup {
    /// The built-in methods with every flag at its default (`--seed 1`).
    fn default() -> Self {
        MethodSetup {
            registry: Registry::builtin(),
            options: MethodOptions::default(),
            seed: 1,
        }
    }
}

/// The GPU side of one scene block, shared by the timing rounds and the quality pass of all its methods.
pub struct BlockGpu<'a> {
    pub ctx: &'a GpuContext,
    pub scene: &'a Scene,
    pub gpu: SceneGpu,
    pub setup: MethodSetup,
    /// Where the timing pass draws.
    pub timing_target: RenderTarget,
    /// `--shadows on`: the shadow pass and the frames' lights.
    pub shadows: Option<Shadows>,
    /// `--clock-warmup`: the probe that warms the GPU's clock before each timed segment (None: no warm-up).
    pub clock: Option<&'a crate::measure::probe_rounds::ClockCheck>,
}

impl<'a> BlockGpu<'a> {
    pub fn new(ctx: &'a GpuContext, scene: &'a Scene, setup: MethodSetup) -> Result<Self> {
        ctx.check_viewport(scene.width, scene.height)?;
        let gpu = SceneGpu::with_shadow_maps(ctx, scene, ShadowRole::COUNT)?;
        let timing_target =
            RenderTarget::new(&ctx.device, "timing target", scene.width, scene.height);
        Ok(BlockGpu {
            ctx,
            scene,
            shadows: Shadows::new(&gpu, scene),
            gpu,
            setup,
            timing_target,
            clock: None,
        })
    }

    /// What a method's constructor is given.
    pub fn build(&self) -> Build<'_> {
        Build {
            gpu: &self.gpu,
            scene: self.scene,
            options: &self.setup.options,
            seed: self.setup.seed,
        }
    }

    /// The frame's camera, and with `--shadows on` its light, into the camera uniform, and the frame's pose of
    /// the deformed models into the vertex buffer (the frame's input says which shadow map its passes are lit
    /// by: `FrameDriver::input`).
    pub fn write_frame(&self, f: u32) {
        self.gpu.write_camera(&self.scene.camera(f));
        self.gpu.write_pose(self.scene, f);
        if let Some(s) = &self.shadows {
            s.write_light(&self.gpu, f);
        }
    }
}
