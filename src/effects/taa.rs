//! `--taa on`: temporal anti-aliasing as engines apply it after the frame, so LOD transitions are measured the
//! way a TAA game shows them (Bevy issue 17643: dithered cross-fades under TAA).
//!
//! The CPU half: the settings and the sub-pixel jitter. Every frame's projection is offset by a point of the
//! Halton (2, 3) sequence, in pixels within [-0.5, 0.5) (`Scene::camera`, so every pass of every method and the
//! reference see the same jittered camera, FSI's reprojection included). The resolve (`gpu/taa.rs`,
//! `shaders/taa.wgsl`) blends each frame into an exponential history, `h = h + alpha (c - h)`, after clamping
//! the history to the min/max of the current frame's 3x3 neighbourhood (no reprojection: the history is read at
//! the same pixel). Defaults and their sources:
//! - 8 Halton (2, 3) samples: Unreal Engine 4's `r.TemporalAASamples` default (Karis, "High Quality Temporal
//!   Supersampling", SIGGRAPH 2014 Advances course, which jitters by the Halton (2, 3) sequence);
//! - alpha 0.1: O3DE Atom's TAA `m_currentFrameContribution` default (docs.o3de.org, atom-guide/features/taa;
//!   Unreal's `r.TemporalAACurrentFrameWeight` is 0.04);
//! - 3x3 min/max clamp of the history: Karis 2014 (O3DE clips to the 3x3 mean +- 1 standard deviation).

use super::OnOff;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// The TAA flags of `lodbench run` (a part of `SceneArgs`: they change what every frame shows).
#[derive(Debug, Clone, Copy, PartialEq, clap::Args, Deserialize, Serialize)]
#[serde(default, rename_all = "kebab-case")]
pub struct TaaArgs {
    /// Temporal anti-aliasing after every frame of every method and the reference.
    #[arg(long, value_enum, default_value_t = OnOff::Off, help_heading = crate::defaults::heading::EFFECTS)]
    pub taa: OnOff,
    /// With --taa on: the current frame's weight in the history (0.1 is O3DE's).
    #[arg(long, default_value_t = 0.1, help_heading = crate::defaults::heading::EFFECTS)]
    pub taa_alpha: f32,
    /// With --taa on: length of the Halton (2, 3) jitter sequence (8 is Unreal Engine 4's).
    #[arg(long, default_value_t = 8, help_heading = crate::defaults::heading::EFFECTS)]
    pub taa_samples: u32,
    /// With --taa on: clamp the history to the current frame's 3x3 neighbourhood (min/max).
    #[arg(long, value_enum, default_value_t = OnOff::On, help_heading = crate::defaults::heading::EFFECTS)]
    pub taa_clamp: OnOff,
}

impl Default for TaaArgs {
    fn default() -> Self {
        crate::defaults::clap_defaults()
    }
}

/// A validated TAA setting (present only with `--taa on`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Taa {
    pub alpha: f32,
    pub samples: u32,
    pub clamp: bool,
}

impl TaaArgs {
    /// None with `--taa off`; the setting, checked, with `--taa on`.
    pub fn resolve(&self) -> Result<Option<Taa>> {
        if self.taa == OnOff::Off {
            return Ok(None);
        }
        if !(self.taa_alpha > 0.0 && self.taa_alpha <= 1.0) {
            return Err(Error::Config(format!(
                "--taa-alpha {}: must be in (0, 1]",
                self.taa_alpha
            )));
        }
        if self.taa_samples == 0 || self.taa_samples > 1024 {
            return Err(Error::Config(format!(
                "--taa-samples {}: must be 1 to 1024",
                self.taa_samples
            )));
        }
        Ok(Some(Taa {
            alpha: self.taa_alpha,
            samples: self.taa_samples,
            clamp: self.taa_clamp == OnOff::On,
        }))
    }
}

/// The radical inverse of `i` in `base` (the Halton sequence's i-th point in [0, 1)).
pub fn halton(mut i: u32, base: u32) -> f32 {
    let mut f = 1.0f64;
    let mut r = 0.0f64;
    while i > 0 {
        f /= base as f64;
        r += f * (i % base) as f64;
        i /= base;
    }
    r as f32
}

impl Taa {
    /// Frame `frame`'s sub-pixel offset in pixels, each coordinate in [-0.5, 0.5): Halton (2, 3) points 1 to
    /// `samples`, repeating (point 0 is the origin, skipped as engines do).
    pub fn jitter_px(&self, frame: u32) -> (f32, f32) {
        let i = frame % self.samples + 1;
        (halton(i, 2) - 0.5, halton(i, 3) - 0.5)
    }

    /// The offset as a clip-space translation for a `width` x `height` viewport: x right, y up (NDC), so a
    /// projection `T * P` moves the image by `jitter_px` pixels (y down in pixel rows).
    pub fn jitter_ndc(&self, frame: u32, width: u32, height: u32) -> (f32, f32) {
        let (x, y) = self.jitter_px(frame);
        (
            2.0 * x / width.max(1) as f32,
            -2.0 * y / height.max(1) as f32,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halton_points() {
        assert_eq!(halton(1, 2), 0.5);
        assert_eq!(halton(2, 2), 0.25);
        assert_eq!(halton(3, 2), 0.75);
        assert!((halton(1, 3) - 1.0 / 3.0).abs() < 1e-7);
        assert!((halton(2, 3) - 2.0 / 3.0).abs() < 1e-7);
        assert!((halton(4, 3) - 4.0 / 9.0).abs() < 1e-7);
    }

    #[test]
    fn jitter_repeats_and_stays_in_the_pixel() {
        let t = Taa {
            alpha: 0.1,
            samples: 8,
            clamp: true,
        };
        let points: Vec<(f32, f32)> = (0..8).map(|f| t.jitter_px(f)).collect();
        assert_eq!(t.jitter_px(8), points[0]);
        assert!(points
            .iter()
            .all(|(x, y)| (-0.5..0.5).contains(x) && (-0.5..0.5).contains(y)));
        // Eight distinct points whose mean is near the pixel centre (what the history converges to).
        let mean = points
            .iter()
            .fold((0.0, 0.0), |a, p| (a.0 + p.0 / 8.0, a.1 + p.1 / 8.0));
        assert!(mean.0.abs() < 0.07 && mean.1.abs() < 0.07, "{mean:?}");
        let (nx, ny) = t.jitter_ndc(0, 100, 50);
        assert_eq!(nx, 0.0);
        assert!((ny - (-2.0 * (1.0 / 3.0 - 0.5) / 50.0)).abs() < 1e-7);
    }

    #[test]
    fn bad_settings_are_named() {
        let mut a = TaaArgs {
            taa: OnOff::On,
            ..TaaArgs::default()
        };
        assert!(a.resolve().unwrap().is_some());
        a.taa_alpha = 0.0;
        assert!(a.resolve().unwrap_err().to_string().contains("--taa-alpha"));
        a.taa_alpha = 0.1;
        a.taa_samples = 0;
        assert!(a
            .resolve()
            .unwrap_err()
            .to_string()
            .contains("--taa-samples"));
        assert_eq!(TaaArgs::default().resolve().unwrap(), None);
    }
}
