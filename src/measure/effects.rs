//! The quality pass's side of the engine effects: which shadow map stands for what, the shadow's own share of
//! the error, every frame's light, and the TAA streams of the method and the reference.

use super::diff_kernel::DiffKernel;
use crate::error::Result;
use crate::geometry::projection::Sphere;
use crate::gpu::scene_gpu::ShadowMap;
use crate::gpu::shadow_pass::ShadowPass;
use crate::gpu::taa_resolve::{TaaResolve, TaaStream};
use crate::gpu::{DrawList, GpuContext, RenderTarget, SceneGpu};
use crate::methods::{FrameInput, Method};
use crate::scene::schedule::InstanceState;
use crate::scene::Scene;
use glam::Mat4;

/// What a shadow map of the block stands for (`--shadows on`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShadowRole {
    /// What the method casts this frame (the timing pass uses only this one).
    Method,
    /// What the reference casts: its LOD0.
    Reference,
    /// What the method cast with the previous frame's states: lodpop's counterfactual.
    Before,
}

impl ShadowRole {
    /// How many shadow maps the block's scene needs.
    pub const COUNT: usize = 3;

    pub fn map(self) -> ShadowMap {
        ShadowMap::lit(match self {
            ShadowRole::Method => 0,
            ShadowRole::Reference => 1,
            ShadowRole::Before => 2,
        })
    }
}

/// Whose casters a shadow map receives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Casters {
    /// The reference's own casters: `--shadow-lod` does not apply to it.
    Reference,
    /// A method's casters under `--shadow-lod`.
    Method,
}

/// One frame's light: world to the shadow map's clip space and its depth bias.
#[derive(Debug, Clone, Copy)]
pub struct FrameLight {
    pub matrix: Mat4,
    pub bias: f32,
}

/// `--shadows on`: every frame's light, fitted to the casters' bounding spheres (every instance but the ground)
/// with room behind them for the receivers; the same for every method, so computed once per block. Empty
/// without shadows.
pub fn frame_lights(scene: &Scene) -> Vec<FrameLight> {
    if scene.shadows.is_none() {
        return Vec::new();
    }
    (0..scene.frames)
        .map(|f| {
            let spheres: Vec<Sphere> = scene
                .instances
                .iter()
                .enumerate()
                .filter(|(i, _)| scene.ground != Some(*i))
                .map(|(i, _)| Sphere::new(scene.instance_position(i, f), scene.instance_radius(i)))
                .collect();
            let r = spheres.iter().map(|s| s.radius).fold(0.0f32, f32::max);
            let (matrix, depth) = crate::effects::shadow::light_matrix(
                glam::Vec3::from(crate::gpu::LIGHT_DIR),
                &spheres,
                3.0 * r,
            );
            FrameLight {
                matrix,
                bias: crate::effects::shadow::BIAS_OF_RADIUS * r / depth.max(1e-6),
            }
        })
        .collect()
}

/// `--shadows on`: the shadow pass and the frames' lights.
pub struct Shadows {
    pass: ShadowPass,
    lights: Vec<FrameLight>,
    settings: crate::effects::shadow::Shadows,
}

impl Shadows {
    pub fn new(gpu: &SceneGpu, scene: &Scene) -> Option<Shadows> {
        Some(Shadows {
            settings: scene.shadows?,
            pass: ShadowPass::new(gpu, scene.instances.len() as u32),
            lights: frame_lights(scene),
        })
    }

    /// Frame `f`'s light into the camera uniform.
    pub fn write_light(&self, gpu: &SceneGpu, f: u32) {
        if let Some(l) = self.lights.get(f as usize) {
            gpu.write_light(&l.matrix, l.bias);
        }
    }

    /// A command buffer, to be submitted before the frame's, that draws into the shadow map of `role` what
    /// `method` casts (asked after its `encode` of the frame; `states` this frame's, or the earlier frame's for
    /// [`ShadowRole::Before`]).
    pub fn commands(
        &self,
        gpu: &SceneGpu,
        method: &dyn Method,
        input: &FrameInput<'_>,
        states: &[InstanceState],
        (role, casters): (ShadowRole, Casters),
    ) -> wgpu::CommandBuffer {
        let mut list = DrawList::default();
        let input = FrameInput { states, ..*input };
        let before = role == ShadowRole::Before;
        crate::methods::common::shadow_list(
            &input,
            |i| {
                let own = method.shadow_caster(states, i, before);
                match casters {
                    Casters::Reference => own,
                    Casters::Method => states[i].caster_under(own, self.settings.lod),
                }
            },
            &mut list,
        );
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        self.pass.encode(gpu, &mut encoder, role.map(), &list);
        encoder.finish()
    }
}

/// `--shadows on`: the shadow's own share of the error: the reference's LOD0 objects lit by the method's shadow
/// map (`now`) and by its counterfactual's (`before`), with their kernels against the reference (shadow_rmse)
/// and against each other (shadow_lodpop).
pub struct ShadowShare {
    pub now: RenderTarget,
    pub before: RenderTarget,
    pub rmse: DiffKernel,
    pub lodpop: DiffKernel,
}

impl ShadowShare {
    pub fn new(
        ctx: &GpuContext,
        scene: &Scene,
        reference: &RenderTarget,
        background: [u8; 3],
    ) -> Result<ShadowShare> {
        let (w, h) = (scene.width, scene.height);
        let now = RenderTarget::new(&ctx.device, "shadow share now", w, h);
        let before = RenderTarget::new(&ctx.device, "shadow share before", w, h);
        let pair = |a, b| [(a, b)];
        let rmse = DiffKernel::new(
            ctx,
            "shadow rmse",
            &pair(&now, reference),
            scene.frames,
            background,
        )?;
        let lodpop = DiffKernel::new(
            ctx,
            "shadow lodpop",
            &pair(&now, &before),
            scene.frames,
            background,
        )?;
        Ok(ShadowShare {
            now,
            before,
            rmse,
            lodpop,
        })
    }
}

/// The quality pass's image streams under `--taa on`, each resolved against its own history every frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stream {
    /// The method's frames: what the viewer sees.
    Method,
    /// The reference's frames.
    Reference,
    /// lodpop's counterfactual stream: every frame, the method drawn at this frame's pose with the previous
    /// frame's schedule (the method's own frame where the two draw the same), so that lodpop_t = RMS(O_t - O'_t)
    /// of two streams, each with the history it built (docs/measurement.md, "lodpop under TAA").
    Before,
    /// A lagged method's (FSI's) frames without the lag: the side lodpop compares with `Before`, and lag_rmse
    /// with `Method`.
    Unlagged,
    /// `--shadows on`: the reference's objects lit by the method's shadow map, and by its counterfactual's.
    ShadowNow,
    ShadowBefore,
}

impl Stream {
    const ALL: [Stream; 6] = [
        Stream::Method,
        Stream::Reference,
        Stream::Before,
        Stream::Unlagged,
        Stream::ShadowNow,
        Stream::ShadowBefore,
    ];

    fn name(self) -> &'static str {
        match self {
            Stream::Method => "method",
            Stream::Reference => "reference",
            Stream::Before => "lodpop before",
            Stream::Unlagged => "unlagged",
            Stream::ShadowNow => "shadow now",
            Stream::ShadowBefore => "shadow before",
        }
    }
}

/// `--taa on`: the resolve, and the quality pass's image streams ([`Stream`]), each with its own history. A
/// counterfactual never borrows another stream's history: a frame that differs once keeps differing through
/// the history for a few frames after, as the viewer sees it.
pub struct TaaStreams {
    pub resolve: TaaResolve,
    streams: Vec<TaaStream>,
}

impl TaaStreams {
    pub fn new(ctx: &GpuContext, scene: &Scene) -> Option<TaaStreams> {
        let resolve = TaaResolve::new(ctx, scene.taa?);
        let (w, h) = (scene.width, scene.height);
        let streams = Stream::ALL
            .iter()
            .filter(|s| {
                scene.shadows.is_some() || !matches!(s, Stream::ShadowNow | Stream::ShadowBefore)
            })
            .map(|s| resolve.stream(ctx, s.name(), w, h))
            .collect();
        Some(TaaStreams { resolve, streams })
    }

    fn stream(&self, s: Stream) -> Option<&TaaStream> {
        self.streams.get(s as usize)
    }

    pub fn reset(&mut self) {
        self.streams.iter_mut().for_each(TaaStream::reset);
    }

    pub fn begin_frame(&self, ctx: &GpuContext) {
        for s in &self.streams {
            self.resolve.begin_frame(ctx, s);
        }
    }

    /// `target`, stream `s`'s frame, resolved in place against the stream's history, which it updates.
    pub fn resolve(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        s: Stream,
        target: &RenderTarget,
    ) {
        if let Some(stream) = self.stream(s) {
            self.resolve.encode(ctx, encoder, stream, target);
        }
    }

    /// After the frame's submissions: every stream's new history becomes the previous one.
    pub fn advance(&mut self) {
        self.streams.iter_mut().for_each(TaaStream::advance);
    }
}
