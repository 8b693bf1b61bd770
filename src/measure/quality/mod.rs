//! The quality pass of one method on a block, frame by frame in stages:
//!
//! 1. **render**: the reference and the method into two targets, each lit by its own shadow map;
//! 2. **shadow maps** (`--shadows on`): what the reference, the method and the method's counterfactual cast,
//!    asked once the method has decided its frame, submitted before the frame's commands;
//! 3. **effects**: `--taa on` resolves both frames in place; `--shadows on` renders the shadow's own share;
//! 4. **metrics**: the metric kernel reduces the difference of the two targets to scalars on the GPU;
//! 5. **read-back requests**: the frames (for FLIP and dumps) and the method's intermediate images;
//! 6. **counterfactuals**: lodpop's and the lag's frames at this pose, in a submission of their own;
//! 7. **collect**: FLIP and the dump callback on the read-back images, or a bound on the frames in flight.
//!
//! The scalars of all frames are read back once at the end. FSI's combination pass is timed here.
//!
//! A method's pass is made in segments, one after each timing round over the same frames
//! ([`crate::measure::block::BlockRunner::measure_block`]), by an instance of the method of its own, warmed up as the
//! timed one: so its frames are the timed frames, and each segment's time is paired with the round's timing
//! segments for `quality_to_renders_ratio`.
//!
//! The pass lives in one file per job: [`setup`] (options, targets, kernels, the stage), [`walk`] (the
//! segments and the collection at the end), [`frame`] (the stages of one frame), [`counterfactuals`],
//! [`collect`] (FLIP and dumps), [`history`] (lodpop's state history) and [`outcome`] (what it measures).

pub mod collect;
pub mod counterfactuals;
pub mod frame;
pub mod history;
pub mod outcome;
pub mod setup;
pub mod walk;

pub use outcome::{FrameImages, QualityPass, SegmentCost, ShadowFigures};
pub use setup::{
    QualityKernels, QualityOptions, QualitySchedule, QualityStage, QualityTargets,
    METRIC_TIMED_EVERY,
};
pub use walk::Walk;
