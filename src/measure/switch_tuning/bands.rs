//! The blending methods' bands: how many frames a blend needs to keep each frame's change within the budget, and
//! the band of camera travel that holds them beyond each switch.

use crate::measure::switch_tuning::outcome::Budget;
use crate::measure::switch_tuning::outcome::{BlendBand, TuneSettings};

/// The blending methods tune gives bands for, and whether a frame's change falls with the square root of the
/// transition's frames (dither: a share of the pixels flips fully each frame) or with the frames (a linear blend).
pub const BLEND_METHODS: [(&str, bool); 3] =
    [("alpha", false), ("dither", true), ("geomorph", false)];

/// The frames a blending method needs for each frame's change to stay within `budget` when the whole change is
/// `pop`: a linear blend (alpha, geomorph) changes the frame by pop / n a frame over n frames; dither flips a share
/// 1 / n of the pixels fully each frame, an RMS of pop / sqrt(n).
pub fn frames_needed(pop: f64, budget: f64, sqrt_law: bool) -> u32 {
    if pop <= budget {
        return 1;
    }
    let r = pop / budget;
    (if sqrt_law { r * r } else { r }).ceil().min(1e6) as u32
}

/// The nearest grid distance at which a blending method's band fits: `worst` is the largest value over the views
/// at each grid distance (increasing distances), `step` the camera's travel per frame, `after` the distance the
/// previous pair's band ends at; the band around a candidate d reaches d (1 +- h), h = n step / (2 d), n the frames
/// the largest change within the band needs; it must stay below half the distance and clear the previous band.
pub fn blend_band(
    worst: &[(f32, f64)],
    budget: f64,
    step: f32,
    after: f32,
    sqrt_law: bool,
) -> Option<(f32, f32, u32)> {
    for &(d, _) in worst {
        let mut h = 0.0f32;
        let mut n = 1;
        for _ in 0..8 {
            let pop = worst
                .iter()
                .filter(|(x, _)| *x >= d * (1.0 - h) && *x <= d * (1.0 + h))
                .map(|p| p.1)
                .fold(0.0f64, f64::max);
            n = frames_needed(pop, budget, sqrt_law);
            let next = n as f32 * step / (2.0 * d);
            if (next - h).abs() <= 1e-6 {
                break;
            }
            h = next;
        }
        if h < 0.45 && d * (1.0 - h) >= after {
            return Some((d, h, n));
        }
    }
    None
}

/// With `--speed` and a lodpop budget: alpha's, dither's and geomorph's bands at the hard `switch` or nearer
/// (`worst`: the grid's worst excess), each starting where its previous one ends (`band_end`, moved on).
pub(super) fn blend_bands(
    settings: &TuneSettings,
    worst: &[(f32, f64)],
    switch: Option<f32>,
    band_end: &mut [f32; 3],
) -> Vec<BlendBand> {
    let mut bands = Vec::new();
    if let (Some((speed, fps)), Budget::Lodpop(budget), Some(hard)) =
        (settings.speed, settings.budget, switch)
    {
        let step = speed / fps.max(1e-6);
        for (k, (method, sqrt_law)) in BLEND_METHODS.into_iter().enumerate() {
            // A band around a distance no farther than the hard switch's, or the hard switch itself.
            let candidates: Vec<(f32, f64)> =
                worst.iter().copied().filter(|(d, _)| *d <= hard).collect();
            let (d, h, n) = blend_band(&candidates, budget, step, band_end[k], sqrt_law)
                .unwrap_or((hard.max(band_end[k] * 1.001), 0.0, 1));
            band_end[k] = d * (1.0 + h);
            bands.push(BlendBand {
                method,
                switch_distance: d,
                band: h,
                frames: n,
            });
        }
    }
    bands
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::switch_tuning::search::log_grid;

    /// A blend spreads a change over frames: linear blends need pop / budget frames, dither (pop / budget)^2; the
    /// nearest band that fits clears the previous band and stays under half the distance.
    #[test]
    fn blend_bands_spread_the_change_over_enough_frames() {
        assert_eq!(frames_needed(0.004, 0.001, false), 4);
        assert_eq!(frames_needed(0.004, 0.001, true), 16);
        assert_eq!(frames_needed(0.0005, 0.001, true), 1);
        // pop = 0.01 / d at distance d; budget 0.001; the camera moves 0.1 a frame.
        let worst: Vec<(f32, f64)> = log_grid(1.0, 100.0, 40)
            .into_iter()
            .map(|d| (d, 0.01 / f64::from(d)))
            .collect();
        let (d, h, n) = blend_band(&worst, 0.001, 0.1, 0.0, false).unwrap();
        // Every grid distance inside the band needs at most n frames, and the band is n frames of travel.
        assert!(h < 0.45, "{d} {h} {n}");
        for &(x, pop) in &worst {
            if x >= d * (1.0 - h) && x <= d * (1.0 + h) {
                assert!(frames_needed(pop, 0.001, false) <= n, "{x}");
            }
        }
        assert!((h - n as f32 * 0.1 / (2.0 * d)).abs() < 1e-5);
        // The nearest such distance: the grid distance before it cannot hold its band under half its distance.
        let before = worst.iter().rev().find(|p| p.0 < d).unwrap();
        assert!(
            frames_needed(before.1, 0.001, false) as f32 * 0.1 / (2.0 * before.0) >= 0.45 * 0.5
        );
        // Beyond the previous band's end only.
        let (d2, h2, _) = blend_band(&worst, 0.001, 0.1, 20.0, false).unwrap();
        assert!(d2 * (1.0 - h2) >= 20.0 && d2 > d);
        // dither needs more frames, so a wider band, so a farther switch.
        let (dd, _, nd) = blend_band(&worst, 0.001, 0.1, 0.0, true).unwrap();
        assert!(dd >= d && nd >= n);
    }
}
