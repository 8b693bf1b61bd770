//! The search for a pair's switch: each view's curve over a log grid of distances, the crossing refined by
//! bisection, the dense check's distances, the seeded view directions.

use crate::error::Result;
use glam::{Quat, Vec3};

use crate::measure::switch_tuning::outcome::{Budget, PairSwitch};

/// How many steps [`nearest_within`] refines a crossing by (each halves the interval of a grid step in log
/// distance).
pub const BISECTIONS: u32 = 5;

/// Where a view's curve crosses the budget.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Crossing {
    /// Within the budget at every distance measured: the switch can be as near as the nearest one.
    Everywhere,
    /// Within it from this distance outwards.
    From(f32),
    /// Broken even at the farthest distance measured.
    Never,
}

/// The nearest distance from which the curve stays within `budget`: `grid` (distances, increasing) with the value
/// at each, and `probe` measuring the value at any distance (for the bisection between the farthest excess and
/// the grid distance after it, geometric midpoints).
pub fn nearest_within(
    grid: &[(f32, f64)],
    budget: Budget,
    mut probe: impl FnMut(f32) -> Result<f64>,
) -> Result<Crossing> {
    let Some(last) = grid.iter().rposition(|&(_, v)| budget.broken_by(v)) else {
        return Ok(Crossing::Everywhere);
    };
    if last + 1 == grid.len() {
        return Ok(Crossing::Never);
    }
    let (mut lo, mut hi) = (grid[last].0, grid[last + 1].0);
    for _ in 0..BISECTIONS {
        let mid = (lo * hi).sqrt();
        if budget.broken_by(probe(mid)?) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(Crossing::From(hi))
}

/// Where the grid's worst view (as an excess, [`Budget::excess`]) comes within this share of the budget, the
/// switch is checked between grid distances too.
pub const NEAR_BUDGET: f64 = 0.8;

/// Distances per grid step of that check.
pub const DENSE_PER_STEP: u32 = 8;

/// Whether a grid's worst excess `e` lies within [`NEAR_BUDGET`] of `budget`.
pub(super) fn close_excess(e: f64, budget: Budget) -> bool {
    e > NEAR_BUDGET * budget.excess_limit()
}

/// `per_step` distances in each step of `grid` (increasing distances) that overlaps `from .. to`, evenly spaced in
/// log distance within the step, its far end included: the dense check's distances, increasing, from `from` to
/// `to`.
pub fn dense_points(grid: &[f32], from: f32, to: f32, per_step: u32) -> Vec<f32> {
    let mut out = Vec::new();
    for w in grid.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b <= from || a >= to {
            continue;
        }
        for i in 1..=per_step {
            let p = a * (b / a).powf(i as f32 / per_step as f32);
            if p > from && p <= to * 1.0001 {
                out.push(p);
            }
        }
    }
    out
}

/// `n` distances from `near` to `far`, evenly spaced in log distance.
pub fn log_grid(near: f32, far: f32, n: u32) -> Vec<f32> {
    let n = n.max(2);
    let (a, b) = (near.ln(), far.ln());
    (0..n)
        .map(|i| (a + (b - a) * i as f32 / (n - 1) as f32).exp())
        .collect()
}

/// `n` view directions (unit vectors towards the camera, from the model's centre): the scene's own (+z, where the
/// default flight looks from) first, then points of a Fibonacci sphere turned by a rotation drawn from `seed`.
pub fn view_directions(n: u32, seed: u64) -> Vec<Vec3> {
    let mut rng = crate::rng::SplitMix64::new(seed);
    let turn = Quat::from_euler(
        glam::EulerRot::YXZ,
        rng.next_f32() * std::f32::consts::TAU,
        (rng.next_f32() * 2.0 - 1.0).asin(),
        rng.next_f32() * std::f32::consts::TAU,
    );
    let others = n.saturating_sub(1);
    let golden = std::f32::consts::PI * (3.0 - 5.0f32.sqrt());
    std::iter::once(Vec3::Z)
        .chain((0..others).map(|i| {
            let y = 1.0 - 2.0 * (i as f32 + 0.5) / others as f32;
            let r = (1.0 - y * y).max(0.0).sqrt();
            let phi = golden * i as f32;
            turn * Vec3::new(r * phi.cos(), y, r * phi.sin())
        }))
        .take(n as usize)
        .collect()
}

/// The view whose crossing is farthest, and that distance; None when some view never comes within the budget.
pub(super) fn limiting_view(per_view: &[Option<f32>], near: f32) -> Option<(u32, f32)> {
    if per_view.iter().any(Option::is_none) {
        None
    } else {
        per_view
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.unwrap_or(0.0).total_cmp(&b.1.unwrap_or(0.0)))
            .map(|(v, d)| (v as u32, d.unwrap_or(near)))
    }
}

/// The switch the views ask for: the `limiting` view's, no nearer than the `previous` pair's band (half-width
/// `b`) allows; none once the previous pair has none.
pub(super) fn first_switch(
    limiting: Option<(u32, f32)>,
    previous: Option<&PairSwitch>,
    b: f32,
) -> Option<f32> {
    // A coarser LOD never switches in nearer than the finer one before it, and its transition band starts
    // where the one before ends (s_k (1 - b) > s_(k-1) (1 + b)).
    let floor = previous
        .and_then(|p| p.switch_distance)
        .map_or(0.0, |d| d * (1.0 + b) / (1.0 - b) * 1.001);
    match (limiting, previous) {
        (_, Some(p)) if p.switch_distance.is_none() => None,
        (Some((_, d)), _) => Some(d.max(floor)),
        (None, _) => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// A curve with its budget planted at a known distance: the search finds it to the bisection's precision,
    /// whether the curve falls smoothly or has a dip below the budget nearer than its last excess.
    #[test]
    fn the_search_finds_a_planted_threshold() {
        let threshold = 7.3f32;
        // lodpop falls as 1 / d^2 and equals the budget at the threshold.
        let budget = 0.01;
        let value = |d: f32| budget * f64::from(threshold / d).powi(2);
        let grid: Vec<(f32, f64)> = log_grid(1.0, 100.0, 24)
            .into_iter()
            .map(|d| (d, value(d)))
            .collect();
        let found = nearest_within(&grid, Budget::Lodpop(budget), |d| Ok(value(d))).unwrap();
        let Crossing::From(d) = found else {
            panic!("{found:?}")
        };
        // One grid step is a factor 100^(1/23) = 1.22; five bisections leave 1.22^(1/32), 0.6 %.
        assert!(d >= threshold && d < threshold * 1.007, "{d}");
        // A dip within the budget at 3 units (nearer than the excess at 4 to 7.3) is not taken.
        let dipped = |d: f32| {
            if (2.5..3.5).contains(&d) {
                0.0
            } else {
                value(d)
            }
        };
        let grid: Vec<(f32, f64)> = log_grid(1.0, 100.0, 24)
            .into_iter()
            .map(|d| (d, dipped(d)))
            .collect();
        assert!(grid
            .iter()
            .any(|&(d, v)| (2.5..3.5).contains(&d) && v == 0.0));
        let Crossing::From(d) =
            nearest_within(&grid, Budget::Lodpop(budget), |d| Ok(dipped(d))).unwrap()
        else {
            panic!()
        };
        assert!(d >= threshold && d < threshold * 1.007, "{d}");
        // Within everywhere, and never within.
        assert_eq!(
            nearest_within(&grid, Budget::Lodpop(1.0), |_| Ok(0.0)).unwrap(),
            Crossing::Everywhere
        );
        assert_eq!(
            nearest_within(&grid, Budget::Lodpop(1e-9), |_| Ok(1.0)).unwrap(),
            Crossing::Never
        );
        // A JOD budget: higher is better.
        let jod = |d: f32| 10.0 - f64::from(threshold / d);
        let grid: Vec<(f32, f64)> = log_grid(1.0, 100.0, 24)
            .into_iter()
            .map(|d| (d, jod(d)))
            .collect();
        let Crossing::From(d) = nearest_within(&grid, Budget::Jod(9.0), |d| Ok(jod(d))).unwrap()
        else {
            panic!()
        };
        assert!(d >= threshold && d < threshold * 1.007, "{d}");
    }

    /// The dense check's distances: per_step of them in each grid step from the switch to where it ends,
    /// increasing, the far end of each step included and nothing before the switch.
    #[test]
    fn dense_points_fill_the_steps_from_the_switch() {
        let grid = log_grid(1.0, 16.0, 5); // 1, 2, 4, 8, 16
        let p = dense_points(&grid, 2.5, 8.0, 4);
        assert!(p.windows(2).all(|w| w[1] > w[0]));
        assert!(p.iter().all(|&x| x > 2.5 && x <= 8.0 * 1.0001));
        // The step 2..4 past 2.5 (2.83, 3.36, 4), the whole step 4..8 (4.76, 5.66, 6.73, 8).
        assert_eq!(p.len(), 7, "{p:?}");
        assert!((p[2] - 4.0).abs() < 1e-4 && (p[6] - 8.0).abs() < 1e-4);
        assert!(dense_points(&grid, 5.0, 5.0, 4).is_empty());
    }

    #[test]
    fn views_start_at_the_scenes_own_and_are_seeded() {
        let a = view_directions(8, 3);
        assert_eq!(a.len(), 8);
        assert_eq!(a[0], Vec3::Z);
        assert!(a.iter().all(|v| (v.length() - 1.0).abs() < 1e-5));
        assert_eq!(a, view_directions(8, 3));
        assert_ne!(a, view_directions(8, 4));
        let g = log_grid(2.0, 32.0, 5);
        assert!(
            (g[0] - 2.0).abs() < 1e-5 && (g[4] - 32.0).abs() < 1e-4 && (g[2] - 8.0).abs() < 1e-4
        );
    }
}
