//! Image metrics, CPU implementation. This is the test oracle for the GPU kernels in `shaders/metrics.wgsl`
//! (they must agree to 1e-5) and what `--dump-frames` heat-maps are made from.
//!
//! Images are tightly packed RGBA8 with sRGB-encoded colour; alpha is ignored. Values are taken as encoded
//! values in [0, 1] (byte / 255), as Sheliemietiev et al. 2023 section 6 compares the stored images.

/// rmse of Sheliemietiev et al. 2023 section 6 steps 5-6: per pixel the mean over R, G, B of |a - b|, then the root mean square
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

/// rmse from the metric kernel's exact sum over `pixels` pixels of (the sum over R, G, B of |a - b|, in bytes)
/// squared: the one expression the GPU's figures and `lodbench score`'s are made by.
pub fn rmse_of_sum(sum: u64, pixels: f64) -> f64 {
    (sum as f64 / (9.0 * 255.0 * 255.0 * pixels)).sqrt()
}

/// An RMS over `pixels` pixels and R, G, B from an exact sum of squared byte differences (pop, lodpop and its
/// parts, lag_rmse): the one expression the kernels' figures and `lodbench score`'s are made by.
pub fn rms_of_sum(sum: u64, pixels: f64) -> f64 {
    (sum as f64 / (3.0 * 255.0 * 255.0 * pixels)).sqrt()
}

/// Root mean square over pixels and R, G, B of `a - b` (encoded values in [0, 1]): lodpop, a method's frame
/// against the same frame rendered with the previous frame's LOD schedule, and lag_rmse (the oracle of
/// `shaders/diff.wgsl`).
pub fn rms_difference(a: &[u8], b: &[u8]) -> f64 {
    assert_eq!(a.len(), b.len(), "images of different sizes");
    let pixels = a.len() / 4;
    if pixels == 0 {
        return 0.0;
    }
    let sum: f64 = a
        .chunks_exact(4)
        .zip(b.chunks_exact(4))
        .flat_map(|(p, q)| (0..3).map(move |c| (p[c] as f64 - q[c] as f64) / 255.0))
        .map(|d| d * d)
        .sum();
    (sum / (3 * pixels) as f64).sqrt()
}

/// [`rms_difference`] and its two parts (shaders/diff.wgsl's CPU twin): coverage, over the pixels whose RGB is
/// `background` in exactly one of the two images; shading, over the rest. Each is an RMS over every pixel, so
/// `coverage^2 + shading^2 = rms^2`.
pub fn rms_difference_parts(a: &[u8], b: &[u8], background: [u8; 3]) -> (f64, f64, f64) {
    rms_difference_parts_over(a, b, background, a.len() / 4)
}

/// [`rms_difference_parts`] of two crops of frames of `pixels` pixels, the frames equal outside the crops (the
/// same sums, over the whole frame's pixel count: bit for bit the figures of the whole frames).
pub fn rms_difference_parts_over(
    a: &[u8],
    b: &[u8],
    background: [u8; 3],
    pixels: usize,
) -> (f64, f64, f64) {
    assert_eq!(a.len(), b.len(), "images of different sizes");
    assert!(a.len() / 4 <= pixels, "a crop larger than its frame");
    if pixels == 0 {
        return (0.0, 0.0, 0.0);
    }
    let (mut all, mut coverage) = (0u64, 0u64);
    for (p, q) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        let e: u64 = (0..3).map(|c| (p[c].abs_diff(q[c]) as u64).pow(2)).sum();
        all += e;
        if (p[..3] == background) != (q[..3] == background) {
            coverage += e;
        }
    }
    let pixels = pixels as f64;
    (
        rms_of_sum(all, pixels),
        rms_of_sum(coverage, pixels),
        rms_of_sum(all - coverage, pixels),
    )
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

/// sRGB RGB-to-XYZ matrix of IEC 61966-2-1 (four decimals), the one colour-science 0.4 uses for "sRGB".
const SRGB_TO_XYZ: [[f64; 3]; 3] = [
    [0.4124, 0.3576, 0.1805],
    [0.2126, 0.7152, 0.0722],
    [0.0193, 0.1192, 0.9505],
];
/// D65 white (CIE 1931 2 degree, xy = 0.3127, 0.3290) as XYZ with Y = 1.
const D65_WHITE: [f64; 3] = [0.3127 / 0.3290, 1.0, (1.0 - 0.3127 - 0.3290) / 0.3290];

/// An sRGB-encoded 8-bit colour to CIELAB (D65): decode, sRGB matrix, CIE 1976 L*a*b*.
pub fn srgb8_to_lab(rgb: [u8; 3]) -> [f64; 3] {
    let lin = rgb.map(|c| {
        let c = c as f64 / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    });
    let xyz: [f64; 3] = std::array::from_fn(|i| {
        (0..3).map(|j| SRGB_TO_XYZ[i][j] * lin[j]).sum::<f64>() / D65_WHITE[i]
    });
    let f = |t: f64| {
        const E: f64 = 216.0 / 24389.0;
        const K: f64 = 24389.0 / 27.0;
        if t > E {
            t.cbrt()
        } else {
            (K * t + 16.0) / 116.0
        }
    };
    let (fx, fy, fz) = (f(xyz[0]), f(xyz[1]), f(xyz[2]));
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// CIEDE2000 colour difference (Sharma, Wu, Dalal 2005), kL = kC = kH = 1.
pub fn ciede2000(lab1: [f64; 3], lab2: [f64; 3]) -> f64 {
    let [l1, a1, b1] = lab1;
    let [l2, a2, b2] = lab2;
    let pow7 = |x: f64| x.powi(7);
    let c_bar = (a1.hypot(b1) + a2.hypot(b2)) / 2.0;
    let g = 0.5 * (1.0 - (pow7(c_bar) / (pow7(c_bar) + pow7(25.0))).sqrt());
    let (a1p, a2p) = ((1.0 + g) * a1, (1.0 + g) * a2);
    let (c1p, c2p) = (a1p.hypot(b1), a2p.hypot(b2));
    let hue = |b: f64, ap: f64| {
        if b == 0.0 && ap == 0.0 {
            0.0
        } else {
            b.atan2(ap).to_degrees().rem_euclid(360.0)
        }
    };
    let (h1p, h2p) = (hue(b1, a1p), hue(b2, a2p));
    let dlp = l2 - l1;
    let dcp = c2p - c1p;
    let dhp = if c1p * c2p == 0.0 {
        0.0
    } else {
        let d = h2p - h1p;
        if d.abs() <= 180.0 {
            d
        } else if d > 180.0 {
            d - 360.0
        } else {
            d + 360.0
        }
    };
    let d_hp = 2.0 * (c1p * c2p).sqrt() * (dhp / 2.0).to_radians().sin();
    let lbp = (l1 + l2) / 2.0;
    let cbp = (c1p + c2p) / 2.0;
    let hbp = if c1p * c2p == 0.0 {
        h1p + h2p
    } else if (h1p - h2p).abs() <= 180.0 {
        (h1p + h2p) / 2.0
    } else if h1p + h2p < 360.0 {
        (h1p + h2p + 360.0) / 2.0
    } else {
        (h1p + h2p - 360.0) / 2.0
    };
    let cosd = |d: f64| d.to_radians().cos();
    let t = 1.0 - 0.17 * cosd(hbp - 30.0) + 0.24 * cosd(2.0 * hbp) + 0.32 * cosd(3.0 * hbp + 6.0)
        - 0.20 * cosd(4.0 * hbp - 63.0);
    let d_theta = 30.0 * (-((hbp - 275.0) / 25.0).powi(2)).exp();
    let rc = 2.0 * (pow7(cbp) / (pow7(cbp) + pow7(25.0))).sqrt();
    let sl = 1.0 + 0.015 * (lbp - 50.0).powi(2) / (20.0 + (lbp - 50.0).powi(2)).sqrt();
    let sc = 1.0 + 0.045 * cbp;
    let sh = 1.0 + 0.015 * cbp * t;
    let rt = -(2.0 * d_theta).to_radians().sin() * rc;
    let (x, y, z) = (dlp / sl, dcp / sc, d_hp / sh);
    (x * x + y * y + z * z + rt * y * z).sqrt()
}

/// Mean CIEDE2000 over all pixels between two RGBA8 sRGB images (alpha ignored).
pub fn de2000_mean(method: &[u8], reference: &[u8]) -> f64 {
    let pixels = method.len() / 4;
    if pixels == 0 {
        return 0.0;
    }
    let sum: f64 = method
        .chunks_exact(4)
        .zip(reference.chunks_exact(4))
        .filter(|(a, b)| a[..3] != b[..3])
        .map(|(a, b)| {
            ciede2000(
                srgb8_to_lab([a[0], a[1], a[2]]),
                srgb8_to_lab([b[0], b[1], b[2]]),
            )
        })
        .sum();
    sum / pixels as f64
}

/// `--metrics`: the per-frame image metrics. rmse, pop and de2000 are always computed (on the GPU, at little
/// cost); `flip` adds NVIDIA FLIP, computed on the CPU from read-back frames.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum Metric {
    Rmse,
    Pop,
    De2000,
    Flip,
}

/// How the metric kernel adds a row's 64 partial sums into the frame's totals (`--metric-reduction`).
#[derive(
    Debug,
    Clone,
    Copy,
    Default,
    PartialEq,
    Eq,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum MetricReduction {
    /// Each invocation adds its own sums with atomics (no barrier).
    #[default]
    Atomics,
    /// The row's sums meet in workgroup memory behind a barrier; one invocation adds them.
    Workgroup,
}

/// Which pixels the quality pass's kernels read and lodpop's counterfactual draws (`--metric-region`).
#[derive(
    Debug,
    Clone,
    Copy,
    Default,
    PartialEq,
    Eq,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum MetricRegion {
    /// Only the pixels the instances can cover (src/measure/coverage.rs) where that bound holds, else all:
    /// the same figures for less work.
    #[default]
    Covered,
    /// Every pixel of every frame, and every counterfactual drawn whole (the check of `covered`).
    Full,
}

/// Mean FLIP error (LDR-FLIP, Andersson et al. 2020, via the `nv-flip` crate) of the method frame against the
/// reference frame, at FLIP's default viewing condition (67 pixels per degree).
pub fn flip_mean(method: &[u8], reference: &[u8], width: u32, height: u32) -> f64 {
    let rgb = |img: &[u8]| -> Vec<u8> {
        img.chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect()
    };
    let reference = nv_flip::FlipImageRgb8::with_data(width, height, &rgb(reference));
    let test = nv_flip::FlipImageRgb8::with_data(width, height, &rgb(method));
    let error = nv_flip::flip(reference, test, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    nv_flip::FlipPool::from_image(&error).mean() as f64
}

/// Per-frame metrics of a sequence, keeping E_{t-1} between frames. `pop` is 0 on the first frame.
#[derive(Debug, Default)]
pub struct SequenceMetrics {
    previous: Option<Vec<f32>>,
    /// Width, height and background bytes of the frames, for uncovered_px and crack_px (0 without).
    image: Option<(u32, u32, [u8; 3])>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameMetrics {
    pub rmse: f64,
    pub pop: f64,
    /// Mean CIEDE2000 between method and reference frame.
    pub de2000: f64,
    /// Pixels where the method shows the background and the reference does not ([`crack_pixels`]).
    pub uncovered_px: u64,
    /// The uncovered pixels enclosed by the method's own surface: cracks and holes ([`crack_pixels`]).
    pub crack_px: u64,
}

impl SequenceMetrics {
    pub fn new() -> Self {
        Self::default()
    }

    /// Also counts uncovered and crack pixels of `width` x `height` frames whose background is `background`.
    pub fn with_cracks(self, width: u32, height: u32, background: [u8; 3]) -> Self {
        SequenceMetrics {
            image: Some((width, height, background)),
            ..self
        }
    }

    pub fn frame(&mut self, method: &[u8], reference: &[u8]) -> FrameMetrics {
        let e = error_image(method, reference);
        let pop = self.previous.as_deref().map_or(0.0, |p| pop(p, &e));
        let rmse = rmse_srgb(method, reference);
        self.previous = Some(e);
        let (uncovered_px, crack_px) = self.image.map_or((0, 0), |(w, h, bg)| {
            crack_pixels(method, reference, w, h, bg)
        });
        FrameMetrics {
            rmse,
            pop,
            de2000: de2000_mean(method, reference),
            uncovered_px,
            crack_px,
        }
    }
}

/// How far (pixels) [`crack_pixels`] looks for the method's surface on each side of an uncovered pixel.
pub const CRACK_REACH: i64 = 4;
/// How far (pixels) from the reference's silhouette a crack must lie ([`crack_pixels`]).
pub const CRACK_MARGIN: i64 = 2;

/// (uncovered, crack) pixels of a method frame against the reference frame (RGBA8, `width` x `height`,
/// `background` the bytes of a pixel nothing was drawn on):
/// - uncovered: the method shows the background where the reference shows surface;
/// - crack: an uncovered pixel with the method's own surface within [`CRACK_REACH`] pixels on both sides
///   along its row or along its column, and the reference's surface on every pixel within [`CRACK_MARGIN`] of
///   it (a square; outside the image counts as background). A crack or a hole through the method's surface (a
///   missing seam, FSI's holes) counts, up to `2 CRACK_REACH - 1` pixels wide; a silhouette that a coarser LOD
///   moved inwards does not: beyond it lies background on one side, and where it closes a concave corner (the
///   bunny's neck seen from the side: 1-2 pixels per frame at 320x240) it lies within the margin of the
///   reference's silhouette. A crack's pixels within the margin of the silhouette are not counted either.
pub fn crack_pixels(
    method: &[u8],
    reference: &[u8],
    width: u32,
    height: u32,
    background: [u8; 3],
) -> (u64, u64) {
    let (w, h) = (width as i64, height as i64);
    let is_bg = |img: &[u8], x: i64, y: i64| {
        let i = ((y * w + x) * 4) as usize;
        img[i..i + 3] == background
    };
    let surface = |x: i64, y: i64| x >= 0 && y >= 0 && x < w && y < h && !is_bg(method, x, y);
    let enclosed = |x: i64, y: i64, dx: i64, dy: i64| {
        let before = (1..=CRACK_REACH).any(|d| surface(x - dx * d, y - dy * d));
        let after = (1..=CRACK_REACH).any(|d| surface(x + dx * d, y + dy * d));
        before && after
    };
    let inside_reference = |x: i64, y: i64| {
        (-CRACK_MARGIN..=CRACK_MARGIN).all(|dy| {
            (-CRACK_MARGIN..=CRACK_MARGIN).all(|dx| {
                let (qx, qy) = (x + dx, y + dy);
                qx >= 0 && qy >= 0 && qx < w && qy < h && !is_bg(reference, qx, qy)
            })
        })
    };
    let (mut uncovered, mut cracks) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            if is_bg(method, x, y) && !is_bg(reference, x, y) {
                uncovered += 1;
                if (enclosed(x, y, 1, 0) || enclosed(x, y, 0, 1)) && inside_reference(x, y) {
                    cracks += 1;
                }
            }
        }
    }
    (uncovered, cracks)
}

/// Per-pixel mean absolute difference over R, G, B in [0, 1]: the single-channel difference image of Sheliemietiev et al. 2023
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
    /// A pixel that is the background in one image only is coverage, one covered in both is shading, one that
    /// is the background in both adds nothing; the parts' squares add up to the whole's.
    #[test]
    fn a_difference_splits_into_coverage_and_shading() {
        let bg = [10, 20, 30];
        let px = |c: [u8; 3]| [c[0], c[1], c[2], 255];
        let a: Vec<u8> = [px(bg), px([200, 20, 30]), px([100, 100, 100]), px(bg)].concat();
        let b: Vec<u8> = [px(bg), px(bg), px([110, 100, 90]), px(bg)].concat();
        let (rms, coverage, shading) = rms_difference_parts(&a, &b, bg);
        let scale = 3.0 * 255.0 * 255.0 * 4.0;
        assert!((coverage - (190.0f64 * 190.0 / scale).sqrt()).abs() < 1e-12);
        assert!((shading - (200.0f64 / scale).sqrt()).abs() < 1e-12);
        assert!((rms * rms - coverage * coverage - shading * shading).abs() < 1e-15);
        assert!((rms - rms_difference(&a, &b)).abs() < 1e-12);
        // The two middle pixels as a crop of the four-pixel frames (the same outside): the same figures, bit
        // for bit.
        let crop = |x: &[u8]| x[4..12].to_vec();
        let parts = rms_difference_parts_over(&crop(&a), &crop(&b), bg, 4);
        assert_eq!(parts, (rms, coverage, shading));
    }

    use super::*;

    fn img(px: &[[u8; 3]]) -> Vec<u8> {
        px.iter().flat_map(|p| [p[0], p[1], p[2], 255]).collect()
    }

    /// A 12 x 9 frame of surface (S) on background (.): a one-pixel crack down the middle column counts as
    /// uncovered and, where it lies at least 2 pixels inside the reference's surface (rows 2 to 5), as a crack;
    /// background where the reference has surface outside the method's silhouette (the right edge) counts as
    /// uncovered only.
    #[test]
    fn cracks_are_uncovered_pixels_enclosed_by_the_surface() {
        let bg = [9, 9, 9];
        let m = "SSSSS.SSSS..";
        let rows_method = [m, m, m, m, m, m, m, "SSSSSSSSSS..", "............"];
        let r = "SSSSSSSSSSSS";
        let rows_reference = [r, r, r, r, r, r, r, r, "............"];
        let image = |rows: &[&str]| -> Vec<u8> {
            rows.iter()
                .flat_map(|r| r.chars())
                .flat_map(|c| match c {
                    'S' => [200, 100, 50, 255],
                    _ => [bg[0], bg[1], bg[2], 255],
                })
                .collect()
        };
        let (m, r) = (image(&rows_method), image(&rows_reference));
        assert_eq!(crack_pixels(&m, &r, 12, 9, bg), (7 + 16, 4));
        let mut s = SequenceMetrics::new().with_cracks(12, 9, bg);
        let f = s.frame(&m, &r);
        assert_eq!((f.uncovered_px, f.crack_px), (23, 4));
        assert_eq!(crack_pixels(&r, &r, 12, 9, bg), (0, 0));
    }

    #[test]
    fn identical_images_score_zero() {
        let a = img(&[[10, 20, 30], [200, 100, 0]]);
        assert_eq!(rmse_srgb(&a, &a), 0.0);
        let mut s = SequenceMetrics::new();
        let zero = FrameMetrics {
            rmse: 0.0,
            pop: 0.0,
            de2000: 0.0,
            uncovered_px: 0,
            crack_px: 0,
        };
        assert_eq!(s.frame(&a, &a), zero);
        assert_eq!(s.frame(&a, &a), zero);
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

    /// Test pairs of Sharma, Wu and Dalal (2005), Table 1, with their published CIEDE2000.
    #[test]
    fn ciede2000_matches_sharma_test_data() {
        let pairs: [([f64; 3], [f64; 3], f64); 8] = [
            ([50.0, 2.6772, -79.7751], [50.0, 0.0, -82.7485], 2.0425),
            ([50.0, 3.1571, -77.2803], [50.0, 0.0, -82.7485], 2.8615),
            ([50.0, 2.8361, -74.0200], [50.0, 0.0, -82.7485], 3.4412),
            ([50.0, 0.0, 0.0], [50.0, -1.0, 2.0], 2.3669),
            ([50.0, 2.5, 0.0], [73.0, 25.0, -18.0], 27.1492),
            (
                [60.2574, -34.0099, 36.2677],
                [60.4626, -34.1751, 39.4387],
                1.2644,
            ),
            (
                [2.0776, 0.0795, -1.1350],
                [0.9033, -0.0636, -0.5514],
                0.9082,
            ),
            ([50.0, 2.5, 0.0], [50.0, 0.0, -2.5], 4.3065),
        ];
        for (a, b, expect) in pairs {
            let got = ciede2000(a, b);
            assert!(
                (got - expect).abs() < 1e-4,
                "{a:?} {b:?}: {got} vs {expect}"
            );
            assert!((ciede2000(b, a) - expect).abs() < 1e-4, "not symmetric");
        }
    }

    /// Against colour-science 0.4.7: `colour.XYZ_to_Lab(colour.sRGB_to_XYZ(rgb))`.
    #[test]
    fn srgb_to_lab_matches_colour_science() {
        let cases: [([u8; 3], [f64; 3]); 3] = [
            (
                [255, 0, 0],
                [53.232881785842, 80.111177743139, 67.22370366687],
            ),
            (
                [0, 255, 0],
                [87.737033473544, -86.18285499658, 83.187834658196],
            ),
            (
                [51, 102, 153],
                [42.009985776866, -0.143511443107, -32.842250098583],
            ),
        ];
        for (rgb, expect) in cases {
            let got = srgb8_to_lab(rgb);
            for c in 0..3 {
                assert!(
                    (got[c] - expect[c]).abs() < 1e-6,
                    "{rgb:?}: {got:?} vs {expect:?}"
                );
            }
        }
        assert_eq!(srgb8_to_lab([0, 0, 0]), [0.0, 0.0, 0.0]);
    }

    #[test]
    fn flip_is_zero_for_equal_images_and_grows_with_difference() {
        let (w, h) = (32u32, 32u32);
        let a: Vec<u8> = (0..w * h)
            .flat_map(|i| [(i % 251) as u8, 90, 140, 255])
            .collect();
        assert_eq!(flip_mean(&a, &a, w, h), 0.0);
        let shift = |d: u8| -> Vec<u8> {
            a.chunks_exact(4)
                .flat_map(|p| [p[0], p[1].saturating_add(d), p[2], 255])
                .collect()
        };
        let small = flip_mean(&shift(8), &a, w, h);
        let large = flip_mean(&shift(80), &a, w, h);
        assert!(small > 0.0 && large > small, "{small} {large}");
    }

    #[test]
    fn difference_image_is_channel_mean() {
        let a = img(&[[255, 0, 0]]);
        let b = img(&[[0, 0, 0]]);
        assert!((difference_image(&a, &b)[0] - 1.0 / 3.0).abs() < 1e-6);
    }

    #[test]
    fn rms_difference_over_pixels_and_channels() {
        let a = [10u8, 20, 30, 255, 0, 0, 0, 255];
        let b = [10u8, 20, 30, 0, 255, 0, 0, 0];
        // One channel of one pixel differs by 1.0 (alpha ignored): sqrt(1 / 6).
        assert!((rms_difference(&a, &b) - (1.0f64 / 6.0).sqrt()).abs() < 1e-12);
        assert_eq!(rms_difference(&a, &a), 0.0);
        assert_eq!(rms_difference(&[], &[]), 0.0);
    }
}
