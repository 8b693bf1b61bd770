//! frames.csv and summary.csv. frames.csv is written as `frames.csv.partial`, flushed after each block, and
//! renamed to `frames.csv` only when the run completes, so an interrupted run keeps what it measured without
//! leaving a file that looks complete.

use crate::error::{Error, Result};
use serde::Serialize;
use std::fs::File;
use std::path::{Path, PathBuf};

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
    /// Seeded bootstrap 95 % interval of the median (see [`bootstrap_ci`]).
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

/// Percentile with linear interpolation between closest ranks (numpy's default); None for no values.
pub fn percentile(values: &[f64], p: f64) -> Option<f64> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| !x.is_nan()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    let pos = (p / 100.0).clamp(0.0, 1.0) * (v.len() - 1) as f64;
    let lo = pos.floor() as usize;
    let hi = pos.ceil() as usize;
    Some(v[lo] + (v[hi] - v[lo]) * (pos - lo as f64))
}

/// Resamples drawn by [`bootstrap_ci`].
pub const BOOTSTRAP_RESAMPLES: usize = 1000;

/// Percentile bootstrap 95 % interval of `stat` over `values` (frames resampled with replacement,
/// [`BOOTSTRAP_RESAMPLES`] times, from `seed`); None for no values.
pub fn bootstrap_ci(
    values: &[f64],
    seed: u64,
    stat: impl Fn(&[f64]) -> Option<f64>,
) -> Option<(f64, f64)> {
    if values.is_empty() {
        return None;
    }
    let mut rng = crate::rng::SplitMix64::new(seed);
    let mut sample = vec![0.0; values.len()];
    let mut stats = Vec::with_capacity(BOOTSTRAP_RESAMPLES);
    for _ in 0..BOOTSTRAP_RESAMPLES {
        for x in sample.iter_mut() {
            *x = values[(rng.next_u64() % values.len() as u64) as usize];
        }
        stats.extend(stat(&sample));
    }
    Some((percentile(&stats, 2.5)?, percentile(&stats, 97.5)?))
}

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = values.fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    if n == 0 {
        0.0
    } else {
        s / n as f64
    }
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

pub const FRAMES_CSV: &str = "frames.csv";
pub const SUMMARY_CSV: &str = "summary.csv";
pub const PARTIAL_SUFFIX: &str = ".partial";

/// Appends frame rows to `frames.csv.partial`; `finish` renames it to `frames.csv`.
pub struct FramesWriter {
    writer: ::csv::Writer<File>,
    partial: PathBuf,
    done: PathBuf,
}

impl FramesWriter {
    pub fn create(dir: &Path) -> Result<FramesWriter> {
        let done = dir.join(FRAMES_CSV);
        let partial = dir.join(format!("{FRAMES_CSV}{PARTIAL_SUFFIX}"));
        let file = File::create(&partial).map_err(|e| Error::io(&partial, e))?;
        Ok(FramesWriter {
            writer: ::csv::Writer::from_writer(file),
            partial,
            done,
        })
    }

    pub fn write_block(&mut self, rows: &[FrameRecord]) -> Result<()> {
        for r in rows {
            self.writer.serialize(r)?;
        }
        self.writer.flush().map_err(|e| Error::io(&self.partial, e))
    }

    pub fn finish(mut self) -> Result<PathBuf> {
        self.writer
            .flush()
            .map_err(|e| Error::io(&self.partial, e))?;
        drop(self.writer);
        std::fs::rename(&self.partial, &self.done).map_err(|e| Error::io(&self.done, e))?;
        Ok(self.done)
    }
}

/// Writes summary.csv (through a temporary file, so it appears whole or not at all).
pub fn write_summary(dir: &Path, rows: &[SummaryRecord]) -> Result<PathBuf> {
    let path = dir.join(SUMMARY_CSV);
    let tmp = dir.join(format!("{SUMMARY_CSV}{PARTIAL_SUFFIX}"));
    {
        let file = File::create(&tmp).map_err(|e| Error::io(&tmp, e))?;
        let mut w = ::csv::Writer::from_writer(file);
        for r in rows {
            w.serialize(r)?;
        }
        w.flush().map_err(|e| Error::io(&tmp, e))?;
    }
    std::fs::rename(&tmp, &path).map_err(|e| Error::io(&path, e))?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(frame: u32, gpu: Option<f64>, rmse: f64, pop: f64) -> FrameRecord {
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
    fn percentile_interpolates_like_numpy() {
        let v = [1.0, 2.0, 3.0, 4.0];
        assert_eq!(percentile(&v, 50.0), Some(2.5));
        assert_eq!(percentile(&v, 0.0), Some(1.0));
        assert_eq!(percentile(&v, 100.0), Some(4.0));
        assert!((percentile(&v, 95.0).unwrap() - 3.85).abs() < 1e-12);
        assert_eq!(percentile(&[], 50.0), None);
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

    #[test]
    fn bootstrap_interval_narrows_with_more_frames_and_covers_the_mean() {
        let mut rng = crate::rng::SplitMix64::new(11);
        let draw = |n: usize, rng: &mut crate::rng::SplitMix64| -> Vec<f64> {
            (0..n).map(|_| 1.0 + rng.next_f32() as f64).collect()
        };
        let few = draw(40, &mut rng);
        let many = draw(4000, &mut rng);
        let m = |v: &[f64]| Some(v.iter().sum::<f64>() / v.len() as f64);
        let (a, b) = bootstrap_ci(&few, 3, m).unwrap();
        let (c, d) = bootstrap_ci(&many, 3, m).unwrap();
        assert!(d - c < (b - a) / 4.0, "[{a}, {b}] vs [{c}, {d}]");
        // Uniform on [1, 2): true mean 1.5, inside the large sample's interval.
        assert!(c < 1.5 && 1.5 < d, "[{c}, {d}]");
        assert_eq!(bootstrap_ci(&few, 3, m), bootstrap_ci(&few, 3, m));
        assert_eq!(bootstrap_ci(&[], 3, m), None);
    }

    #[test]
    fn frames_csv_appears_only_when_finished() {
        let dir = tempfile::tempdir().unwrap();
        let mut w = FramesWriter::create(dir.path()).unwrap();
        w.write_block(&[row(0, None, 0.5, 0.0)]).unwrap();
        assert!(!dir.path().join(FRAMES_CSV).exists());
        let partial = std::fs::read_to_string(dir.path().join("frames.csv.partial")).unwrap();
        assert!(partial.starts_with(
            "scene,method,count,frame,gpu_ms,cpu_ms,triangles,draw_calls,t_instances,lod_mean,rmse,pop,de2000_mean,flip_mean,combine_gpu_ms\n"
        ));
        assert!(
            partial.contains("s,m,1,0,,2.0,100,1,0,0.0,0.5,0.0"),
            "{partial}"
        );
        w.finish().unwrap();
        assert!(dir.path().join(FRAMES_CSV).exists());
        assert!(!dir.path().join("frames.csv.partial").exists());
    }

    #[test]
    fn csv_round_trips_exactly() {
        let dir = tempfile::tempdir().unwrap();
        let mut w = FramesWriter::create(dir.path()).unwrap();
        let r = row(3, Some(0.1 + 0.2), 1.0 / 3.0, 2f64.sqrt());
        w.write_block(std::slice::from_ref(&r)).unwrap();
        let path = w.finish().unwrap();
        let mut rd = ::csv::Reader::from_path(path).unwrap();
        let rec = rd.records().next().unwrap().unwrap();
        assert_eq!(rec[4].parse::<f64>().unwrap(), 0.1 + 0.2);
        assert_eq!(rec[10].parse::<f64>().unwrap(), 1.0 / 3.0);
        assert_eq!(rec[11].parse::<f64>().unwrap(), 2f64.sqrt());
    }
}
