//! The two traits a method implements. [`Method`] draws: the timing rounds and the quality pass call it for every
//! frame. [`Counterfactual`] answers the quality pass's other questions: which frame the method would show had
//! the LOD schedule stayed where it was (lodpop's counterfactual, docs/measurement.md "lodpop"), whether its
//! frame lags the pose, and what of its image the pass may skip. A method opts in to the second by implementing
//! it (overriding the answers that differ from the defaults) and returning itself from
//! [`Method::counterfactual`]; a method that does not is asked through [`Plain`], which gives every default. The
//! timing rounds never ask.

use crate::effects::shadow::Caster;
use crate::error::Result;
use crate::gpu::scene_gpu::ShadowMap;
use crate::gpu::{DrawStats, RenderTarget, SceneGpu, View};
use crate::scene::schedule::InstanceState;
use crate::scene::Scene;
use glam::Mat4;

/// The images of a quality-pass frame that `--dump-frames` writes, `<stem>_<kind>.png` (`results::png::FrameDumper::path`):
/// the frames and the heat-map, and the intermediate images the quality pass and the methods hand over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DumpKind {
    /// The method's frame.
    Method,
    /// The reference's frame.
    Reference,
    /// The heat-map of the method's frame against the reference's.
    Error,
    /// lodpop's counterfactuals: the frame with this frame's schedule, and with the previous frame's.
    LodpopNow,
    LodpopBefore,
    /// FSI's two LOD buffers (the method's `debug_targets`).
    LodBuffer0,
    LodBuffer1,
}

impl DumpKind {
    pub const ALL: [DumpKind; 7] = [
        DumpKind::Method,
        DumpKind::Reference,
        DumpKind::Error,
        DumpKind::LodpopNow,
        DumpKind::LodpopBefore,
        DumpKind::LodBuffer0,
        DumpKind::LodBuffer1,
    ];

    /// The kind as the file name ends: `..._method.png`.
    pub fn name(self) -> &'static str {
        match self {
            DumpKind::Method => "method",
            DumpKind::Reference => "reference",
            DumpKind::Error => "error",
            DumpKind::LodpopNow => "lodpop-now",
            DumpKind::LodpopBefore => "lodpop-before",
            DumpKind::LodBuffer0 => "lodbuffer0",
            DumpKind::LodBuffer1 => "lodbuffer1",
        }
    }
}

/// What a method gets for one frame.
#[derive(Clone, Copy)]
pub struct FrameInput<'a> {
    pub frame: u32,
    pub scene: &'a Scene,
    /// One state per instance, from the shared schedule.
    pub states: &'a [InstanceState],
    /// One object-to-world matrix per instance.
    pub matrices: &'a [Mat4],
    /// Camera-to-instance-centre distance per instance (what LOD selection used).
    pub distances: &'a [f32],
    /// This frame belongs to the timing pass (methods that time a pass of their own do it only then).
    pub timed: bool,
    /// The shadow map every pass of the frame is lit by and the scissor its colour passes draw within: each
    /// pass a method begins takes it ([`SceneGpu::begin_pass`]).
    pub view: View,
}

impl FrameInput<'_> {
    /// This frame's input with its passes lit by shadow map `map`.
    pub fn lit_by(&self, map: ShadowMap) -> Self {
        FrameInput {
            view: View {
                shadow: map,
                ..self.view
            },
            ..*self
        }
    }
}

pub trait Method {
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

    /// GPU milliseconds per frame of the method's own named stage over the last timing pass (FSI: its
    /// combination pass), or None for methods without one.
    fn stage_gpu_ms(&self, _ctx: &crate::gpu::GpuContext) -> Result<Option<Vec<Option<f64>>>> {
        Ok(None)
    }

    /// Intermediate images worth seeing (`--dump-frames` writes them next to the frame): (name, target).
    fn debug_targets(&self) -> Vec<(DumpKind, &RenderTarget)> {
        Vec::new()
    }

    /// The frame just drawn (untimed, at the pose of the frame that comes next) stands for the frame before the
    /// next one: the warm-up ends this way on the first timed frame's pose, so that the first timed frame finds
    /// the state every later timed frame finds (FSI: the older LOD buffer of the previous frame). Default:
    /// nothing to do, for a method whose frame depends on the current frame alone.
    fn replay_as_previous(&mut self) {}

    /// What of a scene's materials this method does not draw as the reference does, in a sentence (run.json's
    /// `material_limits`, a note under the run's table); None when it draws them all. Default: None.
    fn material_limits(&self, _materials: &crate::geometry::material::Materials) -> Option<String> {
        None
    }

    /// `--shadows on`, `--shadow-lod follow`: what instance `i` casts into the frame's shadow map given the
    /// states `states` (this frame's after `encode`; the earlier frame's for lodpop's counterfactual,
    /// `before` true). Called after `encode` of the frame. The default, the blending methods' choice: the LOD
    /// out of transition, both LODs dithered at k in one (src/effects/shadow.rs).
    fn shadow_caster(&self, states: &[InstanceState], i: usize, _before: bool) -> Caster {
        states[i].blended_caster()
    }

    /// The method's own answers to the quality pass's questions (lodpop's counterfactual, the lag, what of
    /// the image it may skip: [`Counterfactual`]), for a method that implements
    /// [`Counterfactual`]: `Some(self)`. Default: None, every answer the default.
    fn counterfactual(&mut self) -> Option<&mut dyn Counterfactual> {
        None
    }
}

pub trait Counterfactual: Method {
    /// lodpop's counterfactual: records into `before` the frame this method would show at this frame's pose
    /// (`input`'s matrices, camera and animation) had the LOD schedule stayed where it was `lodpop_history()`
    /// frames ago: `history[0]` holds the states of frame t-1, `history[1]` those of t-2 (present when
    /// `lodpop_history` is 2). Called after `encode` of the same frame, in a submission of its own, never in the
    /// timing pass. The default, right for a method whose frame is a function of this frame's states and pose
    /// alone, draws the frame again with the states of t-1.
    fn encode_before(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        history: &[&[InstanceState]],
        encoder: &mut wgpu::CommandEncoder,
        before: &RenderTarget,
    ) {
        let previous = FrameInput {
            states: history[0],
            timed: false,
            ..*input
        };
        self.encode(gpu, &previous, encoder, before);
    }

    /// For a method that selects what it draws itself, beyond the shared schedule (`clusterlod`'s cut): whether
    /// the frame just encoded selected differently from the frame before, so lodpop renders its
    /// counterfactual (`encode_before` then draws the previous selection at this pose). Default: false, the
    /// schedule's states decide alone.
    fn selection_changed(&self) -> bool {
        false
    }

    /// Whether the method's frame shows nothing but its instances' meshes (the vertices of their LOD chains,
    /// blended or morphed among themselves, windmill blades turned about their hubs) over the background, with
    /// each pixel a function of the fragments drawn there alone (no screen-space pass reading other pixels,
    /// nothing carried from earlier frames). The quality pass then reads only the pixels the instances can
    /// cover, and draws lodpop's counterfactual only where the instances whose state changed can reach
    /// (`measure/coverage.rs`); the figures are the same. Default: false (every pixel is read and drawn).
    fn image_confined_to_instances(&self) -> bool {
        false
    }

    /// Whether instance states `a` and `b` draw the same image of the instance (the same fragments with the
    /// same colours, at the same pose): lodpop's counterfactual is drawn only when some instance's state
    /// changed by this test (`--metric-region covered`; `full` compares the states whole). Default: the
    /// states are equal. `discrete` draws one LOD whatever k is.
    fn same_image_state(&self, a: &InstanceState, b: &InstanceState) -> bool {
        a == b
    }

    /// Whether the frame of an instance in transition changes every frame at the same state, through an input
    /// that exists only because of the transition (dither's pattern under `--noise-temporal`). That input is
    /// part of the transition state: lodpop's counterfactual holds it at frame t-1 (`encode_before`), and an
    /// instance in transition counts as changed on every frame. Default: false.
    fn transition_pattern_moves(&self) -> bool {
        false
    }

    /// How many earlier frames' states this method's frame depends on (1 for a frame that is a function of the
    /// current states; FSI's older LOD buffer makes it 2).
    fn lodpop_history(&self) -> usize {
        1
    }

    /// For a method whose frame lags the pose (FSI, whose older LOD buffer was rendered at the previous
    /// frame's camera and instance transforms): records into `now` this frame as it would be with every
    /// buffer rendered at this frame's pose, and returns true. lodpop then compares `now` with `before`, and
    /// lag_rmse compares the method's own frame with `now`. The default (no lag) returns false and records
    /// nothing: lodpop compares the method's frame with `before`.
    fn encode_unlagged(
        &mut self,
        _gpu: &SceneGpu,
        _input: &FrameInput<'_>,
        _encoder: &mut wgpu::CommandEncoder,
        _now: &RenderTarget,
    ) -> bool {
        false
    }
}

/// A method that gave no answers of its own, asked the quality pass's questions: every answer the default.
pub struct Plain<'m>(pub &'m mut dyn Method);

impl Method for Plain<'_> {
    fn encode(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
    ) -> DrawStats {
        self.0.encode(gpu, input, encoder, target)
    }
}

impl Counterfactual for Plain<'_> {}

/// Runs `ask` on `method`'s own answers, or on the defaults ([`Plain`]) where it gave none.
pub fn ask_counterfactual<T>(
    method: &mut dyn Method,
    ask: impl FnOnce(&mut dyn Counterfactual) -> T,
) -> T {
    match method.counterfactual() {
        Some(own) => ask(own),
        None => ask(&mut Plain(method)),
    }
}
