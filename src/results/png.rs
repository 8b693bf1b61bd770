//! `--dump-frames`: the method frame, the reference frame and an error heat-map as PNGs.

use crate::error::{Error, Result};
use crate::measure::metrics::difference_image;
use std::path::{Path, PathBuf};

/// Difference (mean over R, G, B of |a - b|, encoded values) that maps to the top of the heat-map's scale.
/// Fixed, so heat-maps of different frames and methods can be compared by eye.
pub const HEATMAP_FULL_SCALE: f32 = 0.25;

pub struct FrameDumper {
    dir: PathBuf,
}

impl FrameDumper {
    pub fn create(out: &Path) -> Result<FrameDumper> {
        let dir = out.join("frames");
        std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
        Ok(FrameDumper { dir })
    }

    /// File stem shared by the three images of one frame, e.g. `bunny-sweep_discrete_c1_f00042`.
    pub fn stem(scene: &str, method: &str, count: u32, frame: u32) -> String {
        format!("{scene}_{method}_c{count}_f{frame:05}")
    }

    /// The dumps folder of the run folder `dir`; its absence is one error saying how to make it.
    pub fn dumps_of(dir: &Path) -> Result<PathBuf> {
        let frames = dir.join("frames");
        if !frames.is_dir() {
            return Err(Error::results(
                dir,
                "has no frames/: run with --dump-frames --dump-transitions",
            ));
        }
        Ok(frames)
    }

    /// In the dumps folder `frames`, the image `kind` (`method`, `reference`, `error`, ...) of one frame.
    pub fn path(
        frames: &Path,
        (scene, method, count, frame): (&str, &str, u32, u32),
        kind: &str,
    ) -> PathBuf {
        frames.join(format!(
            "{}_{kind}.png",
            Self::stem(scene, method, count, frame)
        ))
    }

    #[allow(
        clippy::too_many_arguments,
        reason = "a frame's images and their identity: grouping them would only add a struct used once"
    )]
    pub fn write(
        &self,
        scene: &str,
        method: &str,
        count: u32,
        frame: u32,
        width: u32,
        height: u32,
        method_rgba: &[u8],
        reference_rgba: &[u8],
        extras: &[(&str, Vec<u8>)],
    ) -> Result<()> {
        let id = (scene, method, count, frame);
        let at = |kind: &str| Self::path(&self.dir, id, kind);
        for (name, rgba) in extras {
            save(&at(name), width, height, rgba)?;
        }
        save(&at("method"), width, height, method_rgba)?;
        save(&at("reference"), width, height, reference_rgba)?;
        let heat = heatmap(&difference_image(method_rgba, reference_rgba));
        save(&at("error"), width, height, &heat)
    }
}

fn save(path: &Path, width: u32, height: u32, rgba: &[u8]) -> Result<()> {
    image::save_buffer(path, rgba, width, height, image::ExtendedColorType::Rgba8)
        .map_err(|e| Error::image(path, e))
}

/// Black (no difference) through red and yellow to white (HEATMAP_FULL_SCALE or more).
pub fn heatmap(diff: &[f32]) -> Vec<u8> {
    diff.iter()
        .flat_map(|&d| {
            let t = (d / HEATMAP_FULL_SCALE).clamp(0.0, 1.0);
            let r = (t * 3.0).min(1.0);
            let g = (t * 3.0 - 1.0).clamp(0.0, 1.0);
            let b = (t * 3.0 - 2.0).clamp(0.0, 1.0);
            [
                (r * 255.0).round() as u8,
                (g * 255.0).round() as u8,
                (b * 255.0).round() as u8,
                255,
            ]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heatmap_ends() {
        assert_eq!(heatmap(&[0.0]), vec![0, 0, 0, 255]);
        assert_eq!(heatmap(&[1.0]), vec![255, 255, 255, 255]);
        let mid = heatmap(&[HEATMAP_FULL_SCALE / 3.0]);
        assert_eq!(mid, vec![255, 0, 0, 255]);
    }
}
