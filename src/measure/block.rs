//! One scene block: the GPU objects both passes share ([`BlockGpu`]) and the quality pass's own
//! ([`QualityStage`]; none with `--quality off`), and what a method's measurement on it returns: one frame
//! record per frame, built once every figure of the frame is known (without the quality pass, from the
//! timing rounds alone, its figures empty).

use super::context::{BlockGpu, MethodSetup};
use super::quality::{FrameImages, QualityOptions, QualityPass, QualityStage};
use super::timing::{reference_ms_per_frame, TimedMethod};
use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::measure::records::{
    near_transitions, transitions, BlockInfo, BlockRounds, FrameRecord, TransitionPair,
    TransitionRecord,
};
use crate::scene::Scene;
use indicatif::ProgressBar;

/// One method's measurement on one scene block.
pub struct BlockOutput {
    pub rows: Vec<FrameRecord>,
    pub transitions: Vec<TransitionRecord>,
    pub info: BlockInfo,
}

/// The GPU objects of one scene block, shared by all methods run on it.
pub struct BlockRunner<'a> {
    base: BlockGpu<'a>,
    /// None with [`QualityOptions::timing_only`] (`--quality off`).
    quality: Option<QualityStage>,
}

impl<'a> BlockRunner<'a> {
    /// `dump`: hand frames to the quality pass's callback; `quality.timing_only`: build no quality stage.
    pub fn new(
        ctx: &'a GpuContext,
        scene: &'a Scene,
        setup: MethodSetup,
        dump: bool,
        quality: &QualityOptions,
    ) -> Result<Self> {
        let base = BlockGpu::new(ctx, scene, setup)?;
        let quality = if quality.timing_only {
            None
        } else {
            Some(QualityStage::new(&base, dump, quality)?)
        };
        ctx.check_errors()?;
        Ok(BlockRunner { base, quality })
    }

    /// Dump only frames with an instance in transition (of those, still every `dump_every`-th frame).
    pub fn dump_transitions_only(&mut self, on: bool) {
        if let Some(q) = self.quality.as_mut() {
            q.dumps.transitions_only = on;
        }
    }

    /// Warm-up, timing and quality pass of one method alone (one round): what a run of `--method NAME
    /// --rounds 1` measures. `on_frames` is called with the quality-pass images of every `dump_every`-th frame
    /// when the runner was built with read-back.
    pub fn run_method(
        &mut self,
        label: &str,
        warmup: u32,
        dump_every: u32,
        progress: &ProgressBar,
        on_frames: impl FnMut(u32, FrameImages<'_>) -> Result<()>,
    ) -> Result<BlockOutput> {
        let (mut timed, _) = self.time_methods(&[label.to_string()], warmup, 1, 0, progress)?;
        let reference_ms = reference_ms_per_frame(&timed);
        let method = timed
            .drain(..)
            .find(|t| t.label == label)
            .ok_or_else(|| Error::Gpu(format!("method {label} was not timed")))?;
        self.measure_quality(method, reference_ms, dump_every, progress, on_frames)
    }

    /// The warm-up and timing rounds of the methods `labels` ([`BlockGpu::time_methods`]; the reference is timed
    /// too, for `quality_to_renders_ratio`, only where the quality pass runs).
    pub fn time_methods(
        &self,
        labels: &[String],
        warmup: u32,
        rounds: u32,
        seed: u64,
        progress: &ProgressBar,
    ) -> Result<(Vec<TimedMethod<'a>>, BlockRounds)> {
        let time_reference = self.quality.is_some();
        self.base
            .time_methods(labels, warmup, rounds, seed, time_reference, progress)
    }

    /// The quality pass of a timed method, then its frame records. `reference_ms`: the reference's timing-pass
    /// time per frame (for `quality_to_renders_ratio`). Without a quality stage (`--quality off`) the records
    /// are the timing rounds' alone, every quality figure empty, and `on_frames` is never called.
    pub fn measure_quality(
        &mut self,
        mut timed: TimedMethod<'a>,
        reference_ms: Option<f64>,
        dump_every: u32,
        progress: &ProgressBar,
        mut on_frames: impl FnMut(u32, FrameImages<'_>) -> Result<()>,
    ) -> Result<BlockOutput> {
        let t_instances: Vec<u32> = timed.facts.iter().map(|f| f.t_instances).collect();
        let dump_frames = self.dump_frames(dump_every, &near_transitions(&t_instances));
        let quality = match self.quality.as_mut() {
            Some(stage) => Some(stage.pass(
                &self.base,
                (
                    timed.method.as_mut(),
                    crate::methods::is_reference(&timed.label),
                ),
                &mut timed.driver,
                &dump_frames,
                progress,
                &mut on_frames,
            )?),
            None => None,
        };
        self.base.ctx.check_errors()?;
        let rows = self.frame_records(&timed, quality.as_ref());
        let pairs: Vec<TransitionPair> = timed.facts.iter().map(|f| f.pair).collect();
        Ok(BlockOutput {
            transitions: transitions(&rows, &pairs),
            rows,
            info: self.block_info(&timed, quality.as_ref(), reference_ms),
        })
    }

    /// Per frame, whether the quality pass hands it to the dump callback: every `dump_every`-th frame, of those
    /// only the ones near a transition with `--dump-transitions`.
    fn dump_frames(&self, dump_every: u32, near_transition: &[bool]) -> Vec<bool> {
        let Some(dumps) = self.quality.as_ref().map(|q| q.dumps) else {
            return vec![false; self.base.scene.frames as usize];
        };
        (0..self.base.scene.frames)
            .map(|f| {
                dumps.dump
                    && f % dump_every == 0
                    && (!dumps.transitions_only || near_transition[f as usize])
            })
            .collect()
    }

    /// One record per frame from the method's timed frames and its quality pass (None: every figure of the
    /// quality pass empty).
    fn frame_records(
        &self,
        timed: &TimedMethod<'_>,
        quality: Option<&QualityPass>,
    ) -> Vec<FrameRecord> {
        let scene = self.base.scene;
        let de2000 = self.quality.as_ref().is_some_and(|q| q.de2000);
        (0..scene.frames as usize)
            .map(|f| FrameRecord {
                scene: scene.name().to_string(),
                method: timed.label.clone(),
                count: scene.count,
                frame: f as u32,
                gpu_ms: timed.gpu_ms.get(f).copied().flatten(),
                cpu_ms: timed.cpu_ms[f],
                triangles: timed.stats[f].triangles,
                draw_calls: timed.stats[f].draw_calls,
                units_drawn: timed.stats[f]
                    .clusters
                    .unwrap_or(scene.instances.len() as u64),
                t_instances: timed.facts[f].t_instances,
                lod_mean: timed.facts[f].lod_mean,
                k_mean: timed.facts[f].k_mean,
                rmse: quality.map(|q| q.metrics[f].rmse),
                pop: quality.map(|q| q.metrics[f].pop),
                lodpop: quality.map(|q| q.lodpop[f]),
                de2000_mean: quality.and_then(|q| de2000.then_some(q.metrics[f].de2000)),
                uncovered_px: quality.map(|q| q.metrics[f].uncovered_px),
                crack_px: quality.map(|q| q.metrics[f].crack_px),
                flip_mean: quality.and_then(|q| q.flip[f]),
                combine_gpu_ms: quality
                    .and_then(|q| q.stage_ms.as_ref())
                    .and_then(|s| s.get(f).copied().flatten()),
                lag_rmse: quality.and_then(|q| q.lag.as_ref().map(|l| l[f])),
                shadow_rmse: quality.and_then(|q| q.shadow.as_ref().map(|s| s.rmse[f])),
                shadow_lodpop: quality.and_then(|q| q.shadow.as_ref().map(|s| s.lodpop[f])),
                splits: timed.stats[f].selection.map(|s| s.splits),
                merges: timed.stats[f].selection.map(|s| s.merges),
                select_cpu_ms: timed.stats[f].selection.map(|s| s.cpu_ns as f64 * 1e-6),
                round: timed.round[f],
            })
            .collect()
    }

    /// The block's facts for run.json.
    fn block_info(
        &self,
        timed: &TimedMethod<'_>,
        quality: Option<&QualityPass>,
        reference_ms: Option<f64>,
    ) -> BlockInfo {
        let scene = self.base.scene;
        let frames = scene.frames as f64;
        let timing_ms = timed.ms_per_frame();
        BlockInfo {
            scene: scene.name().to_string(),
            method: timed.label.clone(),
            method_options: (timed.entry.options)(&self.base.setup.options),
            count: scene.count,
            width: scene.width,
            height: scene.height,
            frames: scene.frames,
            warmup: timed.warmup,
            timing_pass_ms_per_frame: timing_ms,
            quality_pass_ms_per_frame: quality.map(|q| q.ms_per_frame),
            quality_to_timing_ratio: quality.map(|q| q.ms_per_frame / timing_ms),
            quality_to_renders_ratio: quality.and_then(|q| {
                let drawn = 1.0 - q.reference_frames_copied as f64 / frames;
                let counterfactual = q.counterfactual_frames as f64 / frames;
                reference_ms
                    .map(|r| q.ms_per_frame / (timing_ms * (1.0 + counterfactual) + r * drawn))
            }),
            counterfactual_frame_share: quality.map(|q| q.counterfactual_frames as f64 / frames),
            reference_frames_copied: quality.map(|q| q.reference_frames_copied),
            wait_instance_frames: timed.facts.iter().map(|f| f.t_waiting as u64).sum(),
            waiting_max: timed.facts.iter().map(|f| f.t_waiting).max().unwrap_or(0),
            metric_gpu_ms_median: quality.and_then(|q| q.metric_gpu_ms_median),
            metric_tile_share: quality.map(|q| q.metric_tile_share),
            counterfactual_pixel_share: quality.and_then(|q| q.counterfactual_pixel_share),
            extra_target_bytes: timed.method.extra_target_bytes(),
            instance_bytes_listed_per_frame: timed.uploads.listed as f64 / frames,
            instance_bytes_written_per_frame: timed.uploads.written as f64 / frames,
        }
    }
}
