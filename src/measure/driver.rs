//! A walk along a scene's path: the shared LOD schedule and the instance matrices of each frame, the same
//! for every method.

use crate::error::{Error, Result};
use crate::gpu::View;
use crate::measure::effects::ShadowRole;
use crate::measure::records::TransitionPair;
use crate::methods::FrameInput;
use crate::scene::schedule::{InstanceState, LodSchedule};
use crate::scene::Scene;
use glam::Mat4;
use std::sync::atomic::{AtomicBool, Ordering};

/// Set by the binary's signal handler; checked once per frame.
pub static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// An error once the run was interrupted.
pub(super) fn check_interrupt() -> Result<()> {
    if INTERRUPTED.load(Ordering::Relaxed) {
        Err(Error::Interrupted)
    } else {
        Ok(())
    }
}

/// Walks a scene's frames in order: the shared LOD schedule and the instance matrices of each frame.
pub struct FrameDriver<'s> {
    scene: &'s Scene,
    schedule: LodSchedule,
    pub states: Vec<InstanceState>,
    pub matrices: Vec<Mat4>,
    pub distances: Vec<f32>,
}

/// Method-independent facts of one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameFacts {
    pub lod_mean: f64,
    pub t_instances: u32,
    /// Mean k over the instances in transition (None when none is).
    pub k_mean: Option<f64>,
    /// The LODs the t-instances go between.
    pub pair: TransitionPair,
    /// Instances `--max-transitions` held back this frame (their LOD should change, no slot was free).
    pub t_waiting: u32,
}

/// The fewest frames any instance of `scene` spends in one transition along its path, counting only the
/// transitions that begin and end on the path (one cut by its first or last frame is no measure of the room a
/// method had); None when no transition does. The schedule is every method's, so this is the block's.
pub fn shortest_transition(scene: &Scene) -> Option<u32> {
    let mut driver = FrameDriver::new(scene);
    // Per instance: the frame its current transition began on, None while steady or in one begun on frame 0.
    let mut began: Vec<Option<u32>> = vec![None; scene.instances.len()];
    let mut was: Vec<bool> = vec![false; scene.instances.len()];
    let mut shortest: Option<u32> = None;
    for frame in 0..scene.frames {
        driver.advance(frame);
        for (i, s) in driver.states.iter().enumerate() {
            let now = s.in_transition();
            match (was[i], now) {
                (false, true) if frame > 0 => began[i] = Some(frame),
                (true, false) => {
                    if let Some(b) = began[i].take() {
                        let n = frame - b;
                        shortest = Some(shortest.map_or(n, |m| m.min(n)));
                    }
                }
                _ => {}
            }
            was[i] = now;
        }
    }
    shortest
}

impl<'s> FrameDriver<'s> {
    pub fn new(scene: &'s Scene) -> Self {
        let n = scene.instances.len();
        FrameDriver {
            scene,
            schedule: LodSchedule::new(scene.schedule, n),
            states: Vec::with_capacity(n),
            matrices: Vec::with_capacity(n),
            distances: Vec::with_capacity(n),
        }
    }

    pub fn reset(&mut self) {
        self.schedule.reset();
    }

    /// Advances to `frame` (frames must come in order after a reset).
    pub fn advance(&mut self, frame: u32) -> FrameFacts {
        self.states.clear();
        self.matrices.clear();
        self.distances.clear();
        let mut lod_sum = 0.0f64;
        let mut t = 0u32;
        let mut k_sum = 0.0f64;
        let mut pair = TransitionPair::None;
        let eye = self.scene.camera(frame).eye;
        for (i, inst) in self.scene.instances.iter().enumerate() {
            let d = self.scene.instance_position(i, frame).distance(eye);
            let switches = &self.scene.models[inst.model as usize].switches;
            // An instance `size` times its model's selects as its model would at d / size.
            let s = self.schedule.update(i, d / inst.size(), switches);
            if self.scene.ground != Some(i) {
                lod_sum += s.lod_value() as f64;
            }
            if s.in_transition() {
                t += 1;
                k_sum += s.k as f64;
                pair = pair.with(s.lod_from, s.lod_to);
            }
            self.states.push(s);
            self.distances.push(d);
            self.matrices.push(self.scene.instance_matrix(i, frame));
        }
        FrameFacts {
            lod_mean: lod_sum
                / (self.scene.instances.len() - self.scene.ground.is_some() as usize).max(1) as f64,
            t_instances: t,
            k_mean: (t > 0).then(|| k_sum / t as f64),
            pair,
            t_waiting: self.schedule.take_waiting(),
        }
    }

    pub fn input(&self, frame: u32) -> FrameInput<'_> {
        FrameInput {
            frame,
            scene: self.scene,
            states: &self.states,
            matrices: &self.matrices,
            distances: &self.distances,
            timed: false,
            view: View::lit_by(ShadowRole::Method.map()),
        }
    }
}
