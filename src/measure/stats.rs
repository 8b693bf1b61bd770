//! Statistics over a block's frames: percentiles as numpy computes them, means, and seeded percentile-bootstrap
//! intervals. Pure functions of their inputs (the bootstrap's resamples come from `crate::rng`).

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

/// Student's t quantile 0.975 for `df` degrees of freedom (exact table to 30, then 1.96 + 2.4 / df, within
/// 0.002 of the exact value).
pub fn t975(df: usize) -> f64 {
    const T: [f64; 30] = [
        12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160,
        2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056,
        2.052, 2.048, 2.045, 2.042,
    ];
    match df {
        0 => f64::INFINITY,
        1..=30 => T[df - 1],
        _ => 1.96 + 2.4 / df as f64,
    }
}

/// Mean of per-round log ratios and its Student-t 95 % interval (None with fewer than two rounds): the rounds
/// are the independent units (consecutive frames are not), and with the 10 or so rounds of a run a t interval
/// keeps its coverage where a percentile bootstrap over rounds runs narrow (docs/measurement.md, "Paired
/// ratios"). None for no rounds.
pub fn paired_log_ratio(logs: &[f64]) -> Option<(f64, Option<(f64, f64)>)> {
    let n = logs.len();
    if n == 0 {
        return None;
    }
    let m = logs.iter().sum::<f64>() / n as f64;
    if n < 2 {
        return Some((m, None));
    }
    let var = logs.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1) as f64;
    let half = t975(n - 1) * (var / n as f64).sqrt();
    Some((m, Some((m - half, m + half))))
}

/// Mean of `values`; 0 for none.
pub fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = values.fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    if n == 0 {
        0.0
    } else {
        s / n as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn t_interval_matches_a_hand_computation() {
        // logs 0.1, 0.2, 0.3: mean 0.2, sd 0.1, half-width t(2) * 0.1 / sqrt(3).
        let (m, ci) = paired_log_ratio(&[0.1, 0.2, 0.3]).unwrap();
        let half = 4.303 * 0.1 / 3f64.sqrt();
        let (lo, hi) = ci.unwrap();
        assert!((m - 0.2).abs() < 1e-12 && (lo - (0.2 - half)).abs() < 1e-12);
        assert!((hi - (0.2 + half)).abs() < 1e-12);
        assert_eq!(paired_log_ratio(&[0.5]), Some((0.5, None)));
        assert_eq!(paired_log_ratio(&[]), None);
        assert!((t975(60) - 2.000).abs() < 0.002 && (t975(120) - 1.980).abs() < 0.002);
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
}
