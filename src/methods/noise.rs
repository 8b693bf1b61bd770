//! Threshold patterns for noise blending (`dither`, Sheliemietiev et al. 2023 section 9): values in (0, 1), tiled over the
//! screen. All are deterministic; white noise is seeded by `--seed`, blue noise by a fixed seed.

use crate::rng::SplitMix64;
use serde::Serialize;

/// `--noise`: which threshold pattern noise blending uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum NoisePattern {
    /// 16x16 white noise from the run's seed, as the paper's texture.
    White16,
    /// 4x4 Bayer ordered dither.
    Bayer4,
    /// 8x8 Bayer ordered dither.
    Bayer8,
    /// 64x64 blue noise, void-and-cluster (Ulichney 1993) with a fixed seed.
    Blue64,
    /// Interleaved gradient noise (Jimenez 2014), computed in the shader.
    Ign,
}

/// Seed of the blue-noise generator: fixed, so the pattern never depends on `--seed`.
pub const BLUE_NOISE_SEED: u64 = 0x5EED_B1E0;

/// A square threshold texture (row-major), or None for patterns computed in the shader.
pub fn threshold_texture(pattern: NoisePattern, seed: u64) -> Option<(u32, Vec<f32>)> {
    match pattern {
        NoisePattern::White16 => Some((16, white(16, seed))),
        NoisePattern::Bayer4 => Some((4, ranks_to_thresholds(&bayer(4)))),
        NoisePattern::Bayer8 => Some((8, ranks_to_thresholds(&bayer(8)))),
        NoisePattern::Blue64 => Some((
            64,
            ranks_to_thresholds(&void_and_cluster(64, BLUE_NOISE_SEED)),
        )),
        NoisePattern::Ign => None,
    }
}

/// `--vis-texture`: the visibility texture of FSI (Scherzer & Wimmer 2008 section 3.3, eq. 1). A t-instance's fragment is kept
/// where the texture's value at its object-space position is <= tau, so low values appear first while a LOD
/// fades in and disappear last while it fades out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum VisTexture {
    /// 64x64 uniform white noise from the run's seed: the paper's choice for all its images.
    Noise,
    /// 64x64, decreasing from the centre outward (1 at the centre, 0 at the farthest corner): the outside of a
    /// repeat appears first.
    Radial,
    /// 64x64 checkerboard of 8x8-texel cells: one colour of cells holds noise values in [0, 0.5), the other in
    /// [0.5, 1), so the first cells fill in during the first half of a fade and the others during the second
    /// (the pattern of the paper's Fig. 5, without a hard pop at one tau).
    Checker,
}

/// Side of every visibility texture, in texels.
pub const VIS_TEXTURE_SIZE: u32 = 64;

/// The visibility texture `kind`, row-major, `VIS_TEXTURE_SIZE`^2 values in [0, 1].
pub fn visibility_texture(kind: VisTexture, seed: u64) -> Vec<f32> {
    let n = VIS_TEXTURE_SIZE as usize;
    match kind {
        VisTexture::Noise => white(n, seed),
        VisTexture::Radial => {
            let c = (n as f32 - 1.0) / 2.0;
            let max = (2.0f32).sqrt() * c;
            (0..n * n)
                .map(|i| {
                    let (x, y) = ((i % n) as f32 - c, (i / n) as f32 - c);
                    1.0 - (x * x + y * y).sqrt() / max
                })
                .collect()
        }
        VisTexture::Checker => white(n, seed)
            .into_iter()
            .enumerate()
            .map(|(i, v)| {
                let cell = (i % n) / 8 + (i / n) / 8;
                0.5 * v + if cell.is_multiple_of(2) { 0.0 } else { 0.5 }
            })
            .collect(),
    }
}

/// Uniform values in [0, 1).
pub fn white(n: usize, seed: u64) -> Vec<f32> {
    let mut rng = SplitMix64::new(seed);
    (0..n * n).map(|_| rng.next_f32()).collect()
}

/// Rank r of n^2 becomes the threshold (r + 0.5) / n^2.
pub fn ranks_to_thresholds(ranks: &[u32]) -> Vec<f32> {
    let n = ranks.len() as f32;
    ranks.iter().map(|&r| (r as f32 + 0.5) / n).collect()
}

/// The Bayer index matrix of side n (a power of two), ranks 0..n^2.
pub fn bayer(n: usize) -> Vec<u32> {
    let mut m = vec![0u32];
    let mut side = 1;
    while side < n {
        let mut next = vec![0u32; 4 * side * side];
        for y in 0..side {
            for x in 0..side {
                let v = 4 * m[y * side + x];
                next[y * 2 * side + x] = v;
                next[y * 2 * side + x + side] = v + 2;
                next[(y + side) * 2 * side + x] = v + 3;
                next[(y + side) * 2 * side + x + side] = v + 1;
            }
        }
        m = next;
        side *= 2;
    }
    m
}

/// Blue-noise ranks 0..n^2 by void-and-cluster: a Gaussian energy (sigma 1.5) on the torus; the initial
/// pattern is relaxed by moving the tightest cluster into the largest void, then ranked by removing clusters
/// (ranks below the initial count) and filling voids (ranks above).
pub fn void_and_cluster(n: usize, seed: u64) -> Vec<u32> {
    let cells = n * n;
    let sigma = 1.5f64;
    // Energy kernel on the torus, by offset.
    let mut kernel = vec![0f64; cells];
    for dy in 0..n {
        for dx in 0..n {
            let wx = dx.min(n - dx) as f64;
            let wy = dy.min(n - dy) as f64;
            kernel[dy * n + dx] = (-(wx * wx + wy * wy) / (2.0 * sigma * sigma)).exp();
        }
    }
    let apply = |energy: &mut [f64], at: usize, sign: f64| {
        let (ax, ay) = (at % n, at / n);
        for y in 0..n {
            let dy = (y + n - ay) % n;
            for x in 0..n {
                let dx = (x + n - ax) % n;
                energy[y * n + x] += sign * kernel[dy * n + dx];
            }
        }
    };
    // Extremes with deterministic tie-breaking (lowest index).
    let tightest = |on: &[bool], e: &[f64]| {
        (0..cells)
            .filter(|&i| on[i])
            .fold(None, |best: Option<usize>, i| match best {
                Some(b) if e[b] >= e[i] => Some(b),
                _ => Some(i),
            })
    };
    let largest_void = |on: &[bool], e: &[f64]| {
        (0..cells)
            .filter(|&i| !on[i])
            .fold(None, |best: Option<usize>, i| match best {
                Some(b) if e[b] <= e[i] => Some(b),
                _ => Some(i),
            })
    };

    let mut rng = SplitMix64::new(seed);
    let initial = (cells / 10).max(1);
    let mut on = vec![false; cells];
    let mut energy = vec![0f64; cells];
    let mut placed = 0;
    while placed < initial {
        let i = (rng.next_u64() % cells as u64) as usize;
        if !on[i] {
            on[i] = true;
            apply(&mut energy, i, 1.0);
            placed += 1;
        }
    }
    // Relax: move the tightest cluster to the largest void until that is the same pixel.
    for _ in 0..cells {
        let (Some(c), Some(_)) = (tightest(&on, &energy), largest_void(&on, &energy)) else {
            break;
        };
        on[c] = false;
        apply(&mut energy, c, -1.0);
        let Some(v) = largest_void(&on, &energy) else {
            break;
        };
        on[v] = true;
        apply(&mut energy, v, 1.0);
        if v == c {
            break;
        }
    }
    let mut rank = vec![0u32; cells];
    // Phase 1: ranks below `initial`, removing tightest clusters from a copy.
    {
        let mut on1 = on.clone();
        let mut e1 = energy.clone();
        for r in (0..initial).rev() {
            if let Some(c) = tightest(&on1, &e1) {
                on1[c] = false;
                apply(&mut e1, c, -1.0);
                rank[c] = r as u32;
            }
        }
    }
    // Phase 2 and 3: ranks from `initial` up, filling the largest void.
    for r in initial..cells {
        if let Some(v) = largest_void(&on, &energy) {
            on[v] = true;
            apply(&mut energy, v, 1.0);
            rank[v] = r as u32;
        }
    }
    rank
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn visibility_textures_are_in_range_and_seeded() {
        for kind in [VisTexture::Noise, VisTexture::Radial, VisTexture::Checker] {
            let t = visibility_texture(kind, 7);
            assert_eq!(t.len(), 64 * 64);
            assert!(t.iter().all(|v| (0.0..=1.0).contains(v)), "{kind:?}");
            assert_eq!(t, visibility_texture(kind, 7));
        }
        assert_ne!(
            visibility_texture(VisTexture::Noise, 1),
            visibility_texture(VisTexture::Noise, 2)
        );
        let r = visibility_texture(VisTexture::Radial, 0);
        // Decreasing from the centre outward.
        assert!(r[32 * 64 + 32] > r[32 * 64 + 48] && r[32 * 64 + 48] > r[32 * 64 + 63]);
        assert!(r[0] < 1e-6);
        let c = visibility_texture(VisTexture::Checker, 3);
        assert!(c[0] < 0.5 && c[8] >= 0.5 && c[8 * 64] >= 0.5 && c[8 * 64 + 8] < 0.5);
    }

    fn is_permutation(r: &[u32]) -> bool {
        let mut s = r.to_vec();
        s.sort_unstable();
        s.iter().enumerate().all(|(i, &v)| v == i as u32)
    }

    #[test]
    fn bayer_matrices() {
        assert_eq!(
            bayer(4),
            vec![0, 8, 2, 10, 12, 4, 14, 6, 3, 11, 1, 9, 15, 7, 13, 5]
        );
        assert!(is_permutation(&bayer(8)));
    }

    #[test]
    fn thresholds_are_inside_the_unit_interval() {
        for p in [
            NoisePattern::White16,
            NoisePattern::Bayer4,
            NoisePattern::Bayer8,
        ] {
            let (n, t) = threshold_texture(p, 1).unwrap();
            assert_eq!(t.len(), (n * n) as usize);
            assert!(t
                .iter()
                .all(|&v| v > 0.0 && v < 1.0 || (p == NoisePattern::White16 && v == 0.0)));
        }
        assert!(threshold_texture(NoisePattern::Ign, 1).is_none());
    }

    #[test]
    fn white_noise_is_seeded() {
        assert_eq!(white(16, 5), white(16, 5));
        assert_ne!(white(16, 5), white(16, 6));
    }

    /// Blue noise: a permutation of ranks, and its low frequencies are weaker than white noise's: 4x4 box
    /// means of the thresholds stay much closer to 0.5.
    #[test]
    fn blue_noise_is_a_permutation_with_little_low_frequency_energy() {
        let n = 32;
        let ranks = void_and_cluster(n, BLUE_NOISE_SEED);
        assert!(is_permutation(&ranks));
        assert_eq!(ranks, void_and_cluster(n, BLUE_NOISE_SEED));
        let box_dev = |t: &[f32]| {
            let mut acc = 0.0f64;
            for by in 0..n / 4 {
                for bx in 0..n / 4 {
                    let mut m = 0.0f64;
                    for y in 0..4 {
                        for x in 0..4 {
                            m += t[(by * 4 + y) * n + bx * 4 + x] as f64;
                        }
                    }
                    acc += (m / 16.0 - 0.5).powi(2);
                }
            }
            (acc / ((n / 4) * (n / 4)) as f64).sqrt()
        };
        let blue = box_dev(&ranks_to_thresholds(&ranks));
        let white = box_dev(&white(n, 9));
        assert!(blue < white * 0.5, "blue {blue} vs white {white}");
    }
}
