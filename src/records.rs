//! The records lodbench writes: a row per frame (frames.csv) and a row per block (summary.csv). A frame record
//! is built once, by the runner, when every figure of its frame is known; a summary record is computed here
//! from a block's frame records with `crate::stats`. The exporters only serialise them.

use crate::stats::{bootstrap_ci, mean, percentile};
use serde::Serialize;

/// One row of frames.csv: one frame of one method on one scene block.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct FrameRecord {
    pub scene: String,
    pub method: String,
    /// Instance count of the block (bunny-grid's n; 1 for bunny-sweep).
    pub count: u32,
    pub frame: u32,
    /// GPU time between timestamps around all of the frame's passes (empty without timestamp queries).
    pub gpu_ms: Option<f64>,
    /// CPU wall time from the start of encoding to the GPU's completion of the frame.
    pub cpu_ms: f64,
    pub triangles: u64,
    pub draw_calls: u32,
    /// Instances in transition (lod_from != lod_to) this frame.
    pub t_instances: u32,
    /// Mean over instances of lod_from + k (lod_to - lod_from), the same for every method.
    pub lod_mean: f64,
    pub rmse: f64,
    pub pop: f64,
    /// Mean CIEDE2000 over pixels between method and reference frame (sRGB D65 -> XYZ -> CIELAB).
    pub de2000_mean: f64,
    /// Mean FLIP error, with `--metrics ...,flip` (empty otherwise).
    pub flip_mean: Option<f64>,
    /// GPU time of FSI's combination pass within gpu_ms (empty for other methods or without timestamps).
    pub combine_gpu_ms: Option<f64>,
}

/// One row of summary.csv: one method on one scene block.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct SummaryRecord {
    pub scene: String,
    pub method: String,
    pub count: u32,
    pub frames: u32,
    pub gpu_ms_median: Option<f64>,
    /// Seeded bootstrap 95 % interval of the median (see [`crate::stats::bootstrap_ci`]).
    pub gpu_ms_median_ci95_lo: Option<f64>,
    pub gpu_ms_median_ci95_hi: Option<f64>,
    pub gpu_ms_p5: Option<f64>,
    pub gpu_ms_p95: Option<f64>,
    pub cpu_ms_median: f64,
    pub triangles_mean: f64,
    pub draw_calls_mean: f64,
    pub t_instances_mean: f64,
    pub rmse_mean: f64,
    pub rmse_mean_ci95_lo: f64,
    pub rmse_mean_ci95_hi: f64,
    pub rmse_max: f64,
    pub pop_max: f64,
    pub pop_p95: f64,
    /// Mean over frames of de2000_mean, and its largest frame.
    pub de2000_mean: f64,
    pub de2000_max: f64,
    /// Mean over frames of flip_mean (empty without `--metrics flip`).
    pub flip_mean: Option<f64>,
    pub extra_target_bytes: u64,
    /// Largest relative change of the triangle count between consecutive frames,
    /// max |t_f - t_(f-1)| / t_(f-1) (seed 000 section 4 saw at most 2 % with FSI).
    pub tri_alternation_max: f64,
    /// Median GPU time of FSI's combination pass (empty for other methods).
    pub combine_gpu_ms_median: Option<f64>,
}

impl SummaryRecord {
    /// Summarises one block's rows (all of the same scene, method and count); `seed` drives the bootstrap.
    pub fn from_frames(
        rows: &[FrameRecord],
        extra_target_bytes: u64,
        seed: u64,
    ) -> Option<SummaryRecord> {
        let first = rows.first()?;
        let gpu: Vec<f64> = rows.iter().filter_map(|r| r.gpu_ms).collect();
        let cpu: Vec<f64> = rows.iter().map(|r| r.cpu_ms).collect();
        let pop: Vec<f64> = rows.iter().map(|r| r.pop).collect();
        let rmse: Vec<f64> = rows.iter().map(|r| r.rmse).collect();
        let gpu_ci = bootstrap_ci(&gpu, seed, |v| percentile(v, 50.0));
        let rmse_ci = bootstrap_ci(&rmse, seed ^ 0x524D_5345, |v| Some(mean(v.iter().copied())))
            .unwrap_or((0.0, 0.0));
        Some(SummaryRecord {
            scene: first.scene.clone(),
            method: first.method.clone(),
            count: first.count,
            frames: rows.len() as u32,
            gpu_ms_median: percentile(&gpu, 50.0),
            gpu_ms_median_ci95_lo: gpu_ci.map(|c| c.0),
            gpu_ms_median_ci95_hi: gpu_ci.map(|c| c.1),
            gpu_ms_p5: percentile(&gpu, 5.0),
            gpu_ms_p95: percentile(&gpu, 95.0),
            cpu_ms_median: percentile(&cpu, 50.0).unwrap_or(f64::NAN),
            triangles_mean: mean(rows.iter().map(|r| r.triangles as f64)),
            draw_calls_mean: mean(rows.iter().map(|r| r.draw_calls as f64)),
            t_instances_mean: mean(rows.iter().map(|r| r.t_instances as f64)),
            rmse_mean: mean(rows.iter().map(|r| r.rmse)),
            rmse_mean_ci95_lo: rmse_ci.0,
            rmse_mean_ci95_hi: rmse_ci.1,
            rmse_max: rows.iter().map(|r| r.rmse).fold(0.0, f64::max),
            pop_max: pop.iter().copied().fold(0.0, f64::max),
            pop_p95: percentile(&pop, 95.0).unwrap_or(0.0),
            de2000_mean: mean(rows.iter().map(|r| r.de2000_mean)),
            de2000_max: rows.iter().map(|r| r.de2000_mean).fold(0.0, f64::max),
            flip_mean: rows
                .iter()
                .map(|r| r.flip_mean)
                .collect::<Option<Vec<f64>>>()
                .map(|v| mean(v.into_iter())),
            extra_target_bytes,
            tri_alternation_max: tri_alternation_max(rows),
            combine_gpu_ms_median: percentile(
                &rows
                    .iter()
                    .filter_map(|r| r.combine_gpu_ms)
                    .collect::<Vec<_>>(),
                50.0,
            ),
        })
    }
}

/// max over consecutive frames of |t_f - t_(f-1)| / t_(f-1), triangles t, from the second frame of the block
/// on (0 for fewer than three frames): the block's first frame has no previous one to read, and FSI renders
/// both LOD buffers there, a start-up cost and not the alternation the paper measures (section 4.1).
pub fn tri_alternation_max(rows: &[FrameRecord]) -> f64 {
    rows.get(1..)
        .unwrap_or_default()
        .windows(2)
        .map(|w| {
            let (a, b) = (w[0].triangles as f64, w[1].triangles as f64);
            if a > 0.0 {
                (b - a).abs() / a
            } else {
                0.0
            }
        })
        .fold(0.0, f64::max)
}

/// Per (scene, count, method) block: sizes and the cost of the two passes.
#[derive(Debug, Clone, Serialize)]
pub struct BlockInfo {
    pub scene: String,
    pub method: String,
    /// The options the method reads (`MethodEntry::options`; absent for methods without options).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub method_options: Option<serde_json::Value>,
    pub count: u32,
    pub width: u32,
    pub height: u32,
    pub frames: u32,
    pub warmup: u32,
    /// Wall time per frame of the timing pass (render + wait), milliseconds.
    pub timing_pass_ms_per_frame: f64,
    /// Wall time per frame of the quality pass (reference + method + metric kernel), milliseconds.
    pub quality_pass_ms_per_frame: f64,
    /// quality_pass_ms_per_frame / timing_pass_ms_per_frame (2.0 is the floor: the reference doubles the work).
    pub quality_to_timing_ratio: f64,
    /// Median GPU time of the metric kernel alone per quality-pass frame (None without timestamps).
    pub metric_gpu_ms_median: Option<f64>,
    pub extra_target_bytes: u64,
    /// Instance data per timing-pass frame: what the method's draw lists held, and what was written to the
    /// GPU (only the entries that changed since the previous upload into the same buffer range).
    pub instance_bytes_listed_per_frame: f64,
    pub instance_bytes_written_per_frame: f64,
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub(crate) fn row(frame: u32, gpu: Option<f64>, rmse: f64, pop: f64) -> FrameRecord {
        FrameRecord {
            scene: "s".into(),
            method: "m".into(),
            count: 1,
            frame,
            gpu_ms: gpu,
            cpu_ms: 2.0,
            triangles: 100 + frame as u64,
            draw_calls: 1,
            t_instances: 0,
            lod_mean: 0.0,
            rmse,
            pop,
            de2000_mean: rmse / 2.0,
            flip_mean: None,
            combine_gpu_ms: None,
        }
    }

    #[test]
    fn tri_alternation_leaves_out_the_first_frame() {
        let with = |tris: &[u64]| {
            let rows: Vec<FrameRecord> = tris
                .iter()
                .enumerate()
                .map(|(f, &t)| FrameRecord {
                    triangles: t,
                    ..row(f as u32, None, 0.0, 0.0)
                })
                .collect();
            tri_alternation_max(&rows)
        };
        // FSI's first frame renders both LOD buffers: 200 -> 100 is left out; 100 -> 110 is 10 %.
        assert!((with(&[200, 100, 110, 100]) - 0.1).abs() < 1e-12);
        assert_eq!(with(&[200, 100]), 0.0);
        assert_eq!(with(&[]), 0.0);
    }

    #[test]
    fn summary_of_rows() {
        let rows = vec![
            row(0, Some(1.0), 0.0, 0.0),
            row(1, Some(3.0), 0.2, 0.5),
            row(2, Some(2.0), 0.1, 0.1),
        ];
        let s = SummaryRecord::from_frames(&rows, 0, 7).unwrap();
        assert_eq!(s.frames, 3);
        assert_eq!(s.gpu_ms_median, Some(2.0));
        assert!((s.rmse_mean - 0.1).abs() < 1e-12);
        assert_eq!(s.rmse_max, 0.2);
        assert_eq!(s.pop_max, 0.5);
        assert_eq!(s.triangles_mean, 101.0);
        let no_gpu: Vec<_> = rows
            .iter()
            .map(|r| FrameRecord {
                gpu_ms: None,
                ..r.clone()
            })
            .collect();
        let s_no_gpu = SummaryRecord::from_frames(&no_gpu, 0, 7).unwrap();
        assert_eq!(s_no_gpu.gpu_ms_median, None);
        assert_eq!(s_no_gpu.gpu_ms_median_ci95_lo, None);
        // The intervals hold the statistic, and are the same for the same seed.
        assert!(s.rmse_mean_ci95_lo <= s.rmse_mean && s.rmse_mean <= s.rmse_mean_ci95_hi);
        assert_eq!(s, SummaryRecord::from_frames(&rows, 0, 7).unwrap());
    }
}
