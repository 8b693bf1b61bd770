//! The quality pass's image figures of frames that are already pictures (another renderer's, `lodbench score`),
//! computed on the CPU from the same exact integer sums the GPU kernels add (`shaders/metrics.wgsl`,
//! `shaders/diff.wgsl`) and turned into figures by the same functions (`metrics::rmse_of_sum`, `rms_of_sum`),
//! so a run's dumped frames scored here give its frames.csv figures bit for bit.

use super::metrics::{
    crack_pixels, de2000_mean, flip_mean, rms_difference_parts, rms_of_sum, rmse_of_sum,
};

/// One frame's images, RGBA8, all `width` x `height`.
pub struct FramePictures<'a> {
    pub frame: &'a [u8],
    /// The same pose drawn with the previous frame's LOD selection (None: the selection did not change, so it
    /// is the frame itself).
    pub counterfactual: Option<&'a [u8]>,
    /// Every object at its finest level (None: no reference was drawn).
    pub reference: Option<&'a [u8]>,
}

/// The figures of one frame; those against the reference are None without one.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ImageFigures {
    pub rmse: Option<f64>,
    pub pop: Option<f64>,
    pub lodpop: f64,
    pub lodpop_coverage: f64,
    pub lodpop_shading: f64,
    pub uncovered_px: Option<u64>,
    pub crack_px: Option<u64>,
    pub flip_mean: Option<f64>,
    pub de2000_mean: Option<f64>,
}

/// A sequence's figures frame by frame, keeping the previous frame's signed error for `pop`.
pub struct SequenceFigures {
    width: u32,
    height: u32,
    background: [u8; 3],
    flip: bool,
    de2000: bool,
    previous_error: Option<Vec<i16>>,
    frame: u32,
}

impl SequenceFigures {
    /// Figures of `width` x `height` frames whose background (nothing drawn) is `background`; `flip` and
    /// `de2000` add those figures (against the reference).
    pub fn new(width: u32, height: u32, background: [u8; 3], (flip, de2000): (bool, bool)) -> Self {
        SequenceFigures {
            width,
            height,
            background,
            flip,
            de2000,
            previous_error: None,
            frame: 0,
        }
    }

    /// The next frame's figures. lodpop and pop are 0 on the first frame, as in a run.
    pub fn next(&mut self, p: &FramePictures<'_>) -> ImageFigures {
        let first = self.frame == 0;
        self.frame += 1;
        let (lodpop, lodpop_coverage, lodpop_shading) = match (first, p.counterfactual) {
            (false, Some(c)) => rms_difference_parts(p.frame, c, self.background),
            _ => (0.0, 0.0, 0.0),
        };
        let mut f = ImageFigures {
            lodpop,
            lodpop_coverage,
            lodpop_shading,
            ..ImageFigures::default()
        };
        let Some(reference) = p.reference else {
            return f;
        };
        let pixels = self.width as f64 * self.height as f64;
        let error = signed_error(p.frame, reference);
        let pop_sum = match (&self.previous_error, first) {
            (Some(prev), false) => squared_change(prev, &error),
            _ => 0,
        };
        self.previous_error = Some(error);
        f.rmse = Some(rmse_of_sum(rmse_sum(p.frame, reference), pixels));
        f.pop = Some(rms_of_sum(pop_sum, pixels));
        let (uncovered, cracks) =
            crack_pixels(p.frame, reference, self.width, self.height, self.background);
        f.uncovered_px = Some(uncovered);
        f.crack_px = Some(cracks);
        f.flip_mean = self
            .flip
            .then(|| flip_mean(p.frame, reference, self.width, self.height));
        f.de2000_mean = self.de2000.then(|| de2000_mean(p.frame, reference));
        f
    }
}

/// The metric kernel's rmse sum: over pixels, the square of the sum over R, G, B of |a - b| (bytes).
fn rmse_sum(a: &[u8], b: &[u8]) -> u64 {
    a.chunks_exact(4)
        .zip(b.chunks_exact(4))
        .map(|(p, q)| {
            let d: u64 = (0..3).map(|c| p[c].abs_diff(q[c]) as u64).sum();
            d * d
        })
        .sum()
}

/// E = method - reference per pixel and R, G, B, in bytes.
fn signed_error(method: &[u8], reference: &[u8]) -> Vec<i16> {
    method
        .chunks_exact(4)
        .zip(reference.chunks_exact(4))
        .flat_map(|(p, q)| (0..3).map(move |c| p[c] as i16 - q[c] as i16))
        .collect()
}

/// The metric kernel's pop sum: over pixels and R, G, B, (E_t - E_(t-1))^2 in bytes.
fn squared_change(previous: &[i16], current: &[i16]) -> u64 {
    previous
        .iter()
        .zip(current)
        .map(|(p, c)| ((*c as i64 - *p as i64).pow(2)) as u64)
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::metrics::{pop, rmse_srgb};

    fn image(pixels: &[[u8; 3]]) -> Vec<u8> {
        pixels
            .iter()
            .flat_map(|p| [p[0], p[1], p[2], 255])
            .collect()
    }

    /// The exact sums agree with the float oracle of metrics.rs, and lodpop is that of the counterfactual.
    #[test]
    fn the_exact_sums_agree_with_the_float_oracle() {
        let bg = [10, 12, 15];
        let r = image(&[[100, 50, 20], [10, 12, 15], [200, 200, 200], [0, 0, 0]]);
        let m0 = image(&[[90, 52, 20], [10, 12, 15], [190, 210, 200], [3, 0, 0]]);
        let m1 = image(&[[80, 52, 24], [40, 42, 45], [190, 210, 200], [3, 0, 9]]);
        let mut seq = SequenceFigures::new(2, 2, bg, (false, false));
        let none = |frame| FramePictures {
            frame,
            counterfactual: None,
            reference: Some(&r),
        };
        let f0 = seq.next(&none(&m0));
        assert_eq!(f0.pop, Some(0.0));
        assert!((f0.rmse.unwrap_or(-1.0) - rmse_srgb(&m0, &r)).abs() < 1e-12);
        let f1 = seq.next(&FramePictures {
            counterfactual: Some(&m0),
            ..none(&m1)
        });
        let e = |m: &[u8]| crate::measure::metrics::error_image(m, &r);
        assert!((f1.pop.unwrap_or(-1.0) - pop(&e(&m0), &e(&m1))).abs() < 1e-6);
        let (all, cov, shade) = rms_difference_parts(&m1, &m0, bg);
        assert_eq!(
            (f1.lodpop, f1.lodpop_coverage, f1.lodpop_shading),
            (all, cov, shade)
        );
        assert!(f1.lodpop > 0.0 && f1.lodpop_coverage > 0.0);
        // A frame whose selection did not change scores 0, and without a reference the reference's figures
        // are empty.
        let mut seq = SequenceFigures::new(2, 2, bg, (false, false));
        seq.next(&FramePictures {
            frame: &m0,
            counterfactual: None,
            reference: None,
        });
        let f = seq.next(&FramePictures {
            frame: &m1,
            counterfactual: None,
            reference: None,
        });
        assert_eq!((f.lodpop, f.rmse, f.uncovered_px), (0.0, None, None));
    }
}
