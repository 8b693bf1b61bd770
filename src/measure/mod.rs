//! The measurement of the methods of one scene block: warm-up, timing rounds and a quality pass over the same
//! frames, then one frame record per frame, built once every figure of the frame is known.
//!
//! - `driver.rs`: the walk along the path (the LOD schedule, shared by every method);
//! - `rounds.rs`: the warm-up and the interleaved timing rounds;
//! - `quality/`: the quality pass in stages, a file per job (render, shadow maps, effects, metrics, read-back requests,
//!   counterfactuals, collect);
//! - `effects.rs`: which shadow map stands for what, the shadow's share, the lights, the TAA streams;
//! - `reference_cache.rs`: the reference's frames kept for the block's next methods;
//! - `block_gpu.rs`: what both passes over a block share; `block.rs`: the block and the records built from both
//!   passes;
//! - `records/` (rows, summaries, transitions), `stats.rs`: the records and their statistics; `metrics.rs`: the CPU definitions of every
//!   image figure (the GPU kernels' oracle); `metric_kernel.rs`, `diff_kernel.rs`: the GPU reductions.

pub mod block;
pub mod block_gpu;
pub mod coverage;
pub mod diff_kernel;
pub mod driver;
pub mod effects;
pub mod engine_rules;
pub mod frame_figures;
pub mod metric_kernel;
pub mod metrics;
pub mod overhead_rounds;
pub mod probe_rounds;
pub mod quality;
pub mod records;
pub mod reference_cache;
pub mod rounds;
pub mod stats;
pub mod switch_tuning;

pub use block::{BlockOutput, BlockRunner, DumpPolicy};
pub use block_gpu::{BlockGpu, MethodSetup};
pub use driver::{shortest_transition, FrameDriver, FrameFacts};
pub use quality::{FrameImages, QualityOptions, QualitySchedule, QualityStage};
pub use records::{BlockRounds, Round};
pub use rounds::{round_frames, shuffled_order, Prepared, TimedMethod, Uploads, WarmUpPlan};

pub use crate::methods::is_reference;
pub use driver::INTERRUPTED;
