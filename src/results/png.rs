//! `--dump-frames`: the method frame, the reference frame and an error heat-map as PNGs.

use super::files::{DumpKind, FRAMES_DIR};
use crate::error::{Error, Result};
use crate::measure::metrics::difference_image;
use std::path::{Path, PathBuf};

/// Difference (mean over R, G, B of |a - b|, encoded values) that maps to the top of the heat-map's scale.
/// Fixed, so heat-maps of different frames and methods can be compared by eye.
pub const HEATMAP_FULL_SCALE: f32 = 0.25;

pub struct FrameDumper {
    dir: PathBuf,
}

/// Which frame a dump is of: scene, method label, instance count and frame number, as frames.csv names it.
#[derive(Debug, Clone, Copy)]
pub struct FrameId<'a> {
    pub scene: &'a str,
    pub method: &'a str,
    pub count: u32,
    pub frame: u32,
}

/// One frame's images: the method's and the reference's frames (RGBA, `width` x `height`), and the extra images
/// the quality pass and the method add (lodpop's counterfactuals, FSI's buffers), each named by its
/// [`DumpKind`].
pub struct DumpImages<'a> {
    pub width: u32,
    pub height: u32,
    pub method: &'a [u8],
    pub reference: &'a [u8],
    pub extras: &'a [(DumpKind, Vec<u8>)],
}

impl FrameDumper {
    pub fn create(out: &Path) -> Result<FrameDumper> {
        let dir = out.join(FRAMES_DIR);
        std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
        Ok(FrameDumper { dir })
    }

    /// File stem shared by the three images of one frame, e.g. `bunny-sweep_discrete_c1_f00042`.
    pub fn stem(scene: &str, method: &str, count: u32, frame: u32) -> String {
        format!("{scene}_{method}_c{count}_f{frame:05}")
    }

    /// The dumps folder of the run folder `dir`; its absence is one error saying how to make it.
    pub fn dumps_of(dir: &Path) -> Result<PathBuf> {
        let frames = dir.join(FRAMES_DIR);
        if !frames.is_dir() {
            return Err(Error::results(
                dir,
                "has no frames/: run with --dump-frames --dump-transitions",
            ));
        }
        Ok(frames)
    }

    /// In the dumps folder `frames`, the image `kind` of one frame.
    pub fn path(frames: &Path, id: &FrameId<'_>, kind: DumpKind) -> PathBuf {
        frames.join(format!(
            "{}_{}.png",
            Self::stem(id.scene, id.method, id.count, id.frame),
            kind.name()
        ))
    }

    /// Writes the images of frame `id`: the extras first, then the method's and the reference's frames and the
    /// error heat-map.
    pub fn write(&self, id: &FrameId<'_>, images: &DumpImages<'_>) -> Result<()> {
        let (width, height) = (images.width, images.height);
        for (kind, rgba) in images.extras {
            save(&Self::path(&self.dir, id, *kind), width, height, rgba)?;
        }
        let at = |kind: DumpKind| Self::path(&self.dir, id, kind);
        save(&at(DumpKind::Method), width, height, images.method)?;
        save(&at(DumpKind::Reference), width, height, images.reference)?;
        let heat = heatmap(&difference_image(images.method, images.reference));
        save(&at(DumpKind::Error), width, height, &heat)
    }
}

fn save(path: &Path, width: u32, height: u32, rgba: &[u8]) -> Result<()> {
    crate::raster::write_png(path, width, height, rgba, crate::raster::Packing::Balanced)
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
