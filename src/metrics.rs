//! Image metrics, CPU implementation. This is the test oracle for the GPU kernels in `shaders/metrics.wgsl`
//! (they must agree to 1e-5) and what `--dump-frames` heat-maps are made from.
//!
//! Images are tightly packed RGBA8 with sRGB-encoded colour; alpha is ignored. Values are taken as encoded
//! values in [0, 1] (byte / 255), as seed 003 section 6 compares the stored images.

/// rmse of seed 003 section 6 steps 5-6: per pixel the mean over R, G, B of |a - b|, then the root mean square
/// over pixels.
pub fn rmse_srgb(method: &[u8], reference: &[u8]) -> f64 {
    assert_eq!(method.len(), reference.len(), "images of different sizes");
    let pixels = method.len() / 4;
    if pixels == 0 {
        return 0.0;
    }
    let mut sum = 0.0f64;
    for (a, b) in method.chunks_exact(4).zip(reference.chunks_exact(4)) {
        let mut d = 0.0f64;
        for c in 0..3 {
            d += (a[c] as f64 / 255.0 - b[c] as f64 / 255.0).abs();
        }
        let d = d / 3.0;
        sum += d * d;
    }
    (sum / pixels as f64).sqrt()
}

/// The signed per-channel error image E = method - reference (RGB, encoded values in [-1, 1]).
pub fn error_image(method: &[u8], reference: &[u8]) -> Vec<f32> {
    assert_eq!(method.len(), reference.len(), "images of different sizes");
    let mut e = Vec::with_capacity(method.len() / 4 * 3);
    for (a, b) in method.chunks_exact(4).zip(reference.chunks_exact(4)) {
        for c in 0..3 {
            e.push(a[c] as f32 / 255.0 - b[c] as f32 / 255.0);
        }
    }
    e
}

/// Temporal popping score: root mean square over pixels and channels of `E_t - E_{t-1}`.
pub fn pop(previous: &[f32], current: &[f32]) -> f64 {
    assert_eq!(
        previous.len(),
        current.len(),
        "error images of different sizes"
    );
    if current.is_empty() {
        return 0.0;
    }
    let sum: f64 = previous
        .iter()
        .zip(current)
        .map(|(p, c)| {
            let d = *c as f64 - *p as f64;
            d * d
        })
        .sum();
    (sum / current.len() as f64).sqrt()
}

/// Per-frame metrics of a sequence, keeping E_{t-1} between frames. `pop` is 0 on the first frame.
#[derive(Debug, Default)]
pub struct SequenceMetrics {
    previous: Option<Vec<f32>>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameMetrics {
    pub rmse: f64,
    pub pop: f64,
}

impl SequenceMetrics {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn frame(&mut self, method: &[u8], reference: &[u8]) -> FrameMetrics {
        let e = error_image(method, reference);
        let pop = self.previous.as_deref().map_or(0.0, |p| pop(p, &e));
        let rmse = rmse_srgb(method, reference);
        self.previous = Some(e);
        FrameMetrics { rmse, pop }
    }
}

/// Per-pixel mean absolute difference over R, G, B in [0, 1]: the single-channel difference image of seed 003
/// section 6 step 5.
pub fn difference_image(method: &[u8], reference: &[u8]) -> Vec<f32> {
    method
        .chunks_exact(4)
        .zip(reference.chunks_exact(4))
        .map(|(a, b)| {
            (0..3)
                .map(|c| (a[c] as f32 - b[c] as f32).abs())
                .sum::<f32>()
                / (3.0 * 255.0)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn img(px: &[[u8; 3]]) -> Vec<u8> {
        px.iter().flat_map(|p| [p[0], p[1], p[2], 255]).collect()
    }

    #[test]
    fn identical_images_score_zero() {
        let a = img(&[[10, 20, 30], [200, 100, 0]]);
        assert_eq!(rmse_srgb(&a, &a), 0.0);
        let mut s = SequenceMetrics::new();
        assert_eq!(
            s.frame(&a, &a),
            FrameMetrics {
                rmse: 0.0,
                pop: 0.0
            }
        );
        assert_eq!(
            s.frame(&a, &a),
            FrameMetrics {
                rmse: 0.0,
                pop: 0.0
            }
        );
    }

    #[test]
    fn rmse_matches_hand_computation() {
        // Pixel 1: channel diffs 255, 0, 0 -> mean 1/3. Pixel 2: all equal -> 0.
        let a = img(&[[255, 0, 0], [5, 5, 5]]);
        let b = img(&[[0, 0, 0], [5, 5, 5]]);
        let expect = ((1.0f64 / 3.0).powi(2) / 2.0).sqrt();
        assert!((rmse_srgb(&a, &b) - expect).abs() < 1e-12);
        // Alpha is ignored.
        let mut c = a.clone();
        c[3] = 0;
        assert_eq!(rmse_srgb(&c, &b), rmse_srgb(&a, &b));
        // Symmetric, and the per-pixel mean is of absolute values (opposite signs do not cancel).
        let d = img(&[[255, 0, 0]]);
        let e = img(&[[0, 255, 0]]);
        assert!((rmse_srgb(&d, &e) - 2.0 / 3.0).abs() < 1e-12);
        assert_eq!(rmse_srgb(&d, &e), rmse_srgb(&e, &d));
    }

    #[test]
    fn constant_error_does_not_pop_and_a_switch_does() {
        let r = img(&[[100, 100, 100], [50, 50, 50]]);
        let off = img(&[[110, 100, 100], [50, 50, 50]]);
        let mut s = SequenceMetrics::new();
        let f0 = s.frame(&off, &r);
        let f1 = s.frame(&off, &r);
        assert_eq!(f0.pop, 0.0);
        assert_eq!(f1.pop, 0.0);
        assert!(f1.rmse > 0.0);
        let f2 = s.frame(&r, &r);
        // E went from +10/255 to 0 on one channel of one pixel: sqrt((10/255)^2 / 6).
        let expect = ((10.0f64 / 255.0).powi(2) / 6.0).sqrt();
        assert!((f2.pop - expect).abs() < 1e-7, "{} vs {expect}", f2.pop);
        assert_eq!(f2.rmse, 0.0);
    }

    #[test]
    fn pop_is_signed() {
        // The error flips sign with the same magnitude: rmse is unchanged, pop sees the change.
        let r = img(&[[100, 100, 100]]);
        let up = img(&[[120, 100, 100]]);
        let down = img(&[[80, 100, 100]]);
        let mut s = SequenceMetrics::new();
        let a = s.frame(&up, &r);
        let b = s.frame(&down, &r);
        assert!((a.rmse - b.rmse).abs() < 1e-12);
        assert!((b.pop - ((40.0f64 / 255.0).powi(2) / 3.0).sqrt()).abs() < 1e-7);
    }

    #[test]
    fn difference_image_is_channel_mean() {
        let a = img(&[[255, 0, 0]]);
        let b = img(&[[0, 0, 0]]);
        assert!((difference_image(&a, &b)[0] - 1.0 / 3.0).abs() < 1e-6);
    }
}
