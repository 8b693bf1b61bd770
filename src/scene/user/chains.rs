//! A user scene's LOD chains and switch distances: an authored chain's levels as they are, its thresholds from
//! the file (lodbench's exact distances, else MSFT_screencoverage, else an error estimated per level); every
//! other mesh gets meshoptimizer's chain by error, its levels the coarsest within errors that project to
//! `--pixel-error` at multiples of the distance the model is first seen from, so that its switches fall on the
//! camera's path.

use crate::error::{Error, Result};
use crate::geometry::gltf::{AuthoredChain, ChainSource};
use crate::geometry::lod::{self, LodChain};
use crate::geometry::mesh::Mesh;
use crate::geometry::projection::{distance_of, error_at_distance, Sphere};
use crate::scene::bunny::USER_SWITCH_FIT_MULTIPLES;
use crate::scene::config::SceneConfig;
use crate::scene::kind::{ProfileValues, SceneKind};
use crate::scene::model::{Model, SwitchSource};
use crate::scene::user::models::PendingModel;
use crate::scene::user::parts::ChainDescription;

/// What a model's switch distances depend on besides its chain.
pub struct View<'a> {
    pub cfg: &'a SceneConfig,
    pub pv: &'a ProfileValues,
    pub fov_y: f32,
    pub pixel_error: f32,
}

impl<'a> View<'a> {
    /// The view of scene `kind` with vertical field of view `fov_y`: its pixel error at the profile's height.
    pub fn new(
        kind: SceneKind,
        cfg: &'a SceneConfig,
        pv: &'a ProfileValues,
        fov_y: f32,
    ) -> View<'a> {
        View {
            cfg,
            pv,
            fov_y,
            pixel_error: cfg.pixel_error(kind, pv.height),
        }
    }
}

/// The model of `pending` (file `file`): its chain and switch distances. `seen_from`: the nearest distance the
/// camera sees it from at the start of its path (a generated chain's levels are chosen at multiples of it), and
/// the chain's description when the file authored it.
pub fn build(
    file: &str,
    pending: PendingModel,
    view: &View<'_>,
    seen_from: f32,
) -> Result<(Model, Option<ChainDescription>, Option<String>)> {
    let bad = |problem: String| Error::Mesh {
        path: file.to_string(),
        problem,
    };
    let sphere = pending.levels[0].bounding_sphere();
    let Some(info) = &pending.authored else {
        return generated(file, pending, view, seen_from, sphere);
    };
    let chain = &info.chain;
    let meshes = pending.levels;
    let exact = chain
        .switch_distances
        .as_ref()
        .filter(|d| d.len() + 1 == meshes.len());
    let (errors, thresholds, source) =
        authored_errors(file, (chain, exact), &meshes, sphere.radius, view)?;
    let levels = meshes.len();
    let lod_chain = LodChain::from_meshes(&pending.name, meshes, &errors)
        .map_err(|e| bad(format!("LOD chain '{}': {e}", chain.name)))?;
    let mut model = finish(
        view,
        pending.name.clone(),
        lod_chain,
        sphere,
        source,
        pending.color,
    )?;
    model.lod_colors = pending.lod_colors;
    if let (Some(d), false) = (exact, model.switch_source == SwitchSource::Override) {
        // Exact as written (the round trip through the pixel error may move the last bit), unless
        // --switch-distances or --switch-screen-sizes replaced them.
        view.cfg.user_schedule.check_switches(&pending.name, d)?;
        model.switches = d.to_vec();
    }
    model.spin_per_frame = chain.spin_per_frame;
    Ok((
        model,
        Some(ChainDescription {
            model: pending.name,
            source: match chain.source {
                ChainSource::MsftLod => "MSFT_lod",
                ChainSource::LodNames => "NAME_LODn node names",
            },
            levels,
            thresholds,
        }),
        None,
    ))
}

/// The model of a `pending` model without an authored chain: LOD0 simplified to the errors `--pixel-error`
/// allows at multiples of `seen_from`, and meshopt's note where it stopped short.
fn generated(
    file: &str,
    pending: PendingModel,
    view: &View<'_>,
    seen_from: f32,
    sphere: Sphere,
) -> Result<(Model, Option<ChainDescription>, Option<String>)> {
    let bad = |problem: String| Error::Mesh {
        path: file.to_string(),
        problem,
    };
    let errors: Vec<f32> = USER_SWITCH_FIT_MULTIPLES
        .iter()
        .map(|m| {
            error_at_distance(
                m * seen_from,
                1.0,
                view.pixel_error,
                view.pv.height,
                view.fov_y,
            )
        })
        .collect();
    let mesh = pending
        .levels
        .into_iter()
        .next()
        .ok_or_else(|| bad("a model without a mesh".into()))?;
    let (mut chain, note) =
        LodChain::build_by_error(&pending.name, &mesh, &errors, view.cfg.simplify)?;
    let dropped = if view.cfg.switch_distances.is_none() && view.cfg.switch_screen_sizes.is_none() {
        drop_near_levels(&pending.name, &mut chain, view)
    } else {
        None
    };
    let note = match (note, dropped) {
        (Some(a), Some(b)) => Some(format!("{a}; {b}")),
        (a, b) => a.or(b),
    };
    let mut model = finish(
        view,
        pending.name,
        chain,
        sphere,
        SwitchSource::PixelError,
        pending.color,
    )?;
    model.lod_colors = pending.lod_colors;
    Ok((model, None, note.map(|n| format!("{file}: mesh {n}"))))
}

/// Drops from a generated chain each level that adds almost nothing over the one kept before it: a level whose
/// switch distance is within the ratio of a transition band's far edge to the next band's near edge
/// (`(1 + band)(1 + hysteresis) / ((1 - band)(1 - hysteresis))`, 1.105 by default) of the previous kept level's,
/// where meshopt stopped within a few percent of the error before (its bands would overlap under a distance fade,
/// and its switch would change next to nothing). Returns what was dropped, for the run's notes.
fn drop_near_levels(name: &str, chain: &mut LodChain, view: &View<'_>) -> Option<String> {
    let s = view.cfg.user_schedule;
    let ratio = (1.0 + s.band) * (1.0 + s.hysteresis) / ((1.0 - s.band) * (1.0 - s.hysteresis));
    let switches = lod::switch_distances(chain, 1.0, view.pixel_error, view.pv.height, view.fov_y);
    let keep = levels_to_keep(&switches, ratio);
    let dropped: Vec<String> = (1..chain.lods.len())
        .filter(|&k| !keep[k])
        .map(|k| {
            let before = (0..k).rev().find(|&j| keep[j]).unwrap_or(0);
            let prev = if before == 0 {
                switches[0]
            } else {
                switches[before - 1]
            };
            format!(
                "LOD{k} ({} triangles, switch {:.4} within {:.1} % of LOD{before}'s)",
                chain.lods[k].mesh.triangle_count(),
                switches[k - 1],
                (switches[k - 1] / prev - 1.0) * 100.0
            )
        })
        .collect();
    if dropped.is_empty() {
        return None;
    }
    let mut k = 0;
    chain.lods.retain(|_| {
        k += 1;
        keep[k - 1]
    });
    Some(format!(
        "{}: its generated chain drops {}: a level that adds almost nothing over the one before",
        name,
        dropped.join(", ")
    ))
}

/// Per level of a chain (LOD0 first) whose switch distances are `switches` (LOD1's first), whether it stays: LOD0
/// and every level whose switch lies beyond `ratio` times the last kept level's.
fn levels_to_keep(switches: &[f32], ratio: f32) -> Vec<bool> {
    let mut keep = vec![true; switches.len() + 1];
    let mut last: Option<f32> = None;
    for (k, &d) in switches.iter().enumerate() {
        match last {
            Some(prev) if d <= prev * ratio => keep[k + 1] = false,
            _ => last = Some(d),
        }
    }
    keep
}

/// An authored chain's errors per level, how its thresholds were given, and the switch source: its `exact`
/// switch distances, else its screen coverages (for a model of bounding radius `radius`), else meshopt's
/// estimate.
fn authored_errors(
    file: &str,
    (chain, exact): (&AuthoredChain, Option<&Vec<f32>>),
    meshes: &[Mesh],
    radius: f32,
    view: &View<'_>,
) -> Result<(Vec<f32>, String, SwitchSource)> {
    let to_errors =
        |d: &[f32]| -> Vec<f32> {
            std::iter::once(0.0)
                .chain(d.iter().map(|&d| {
                    error_at_distance(d, 1.0, view.pixel_error, view.pv.height, view.fov_y)
                }))
                .collect()
        };
    Ok(match (&chain.screen_coverage, exact) {
        (_, Some(d)) => (
            to_errors(d),
            format!("extras.lodbench_switch_distances {d:?} (lodbench export's exact distances)"),
            SwitchSource::ExportedDistances,
        ),
        (Some(c), None) if c.len() + 1 >= meshes.len() && meshes.len() > 1 => {
            let d: Vec<f32> = c[..meshes.len() - 1]
                .iter()
                .map(|&c| distance_of(radius, c as f32, view.fov_y))
                .collect();
            (
                to_errors(&d),
                format!("MSFT_screencoverage {c:?} (the last value, the cull threshold, not used)"),
                SwitchSource::ScreenCoverage,
            )
        }
        _ => (
            estimated_errors(file, meshes)?,
            "meshopt's error at each level's triangle count, projected to --pixel-error"
                .to_string(),
            SwitchSource::PixelErrorEstimated,
        ),
    })
}

/// An authored chain's errors without thresholds: for each level after LOD0, the error meshopt reaches when it
/// simplifies LOD0 to that level's triangle count (an estimate of what the level gives up).
fn estimated_errors(name: &str, meshes: &[Mesh]) -> Result<Vec<f32>> {
    let t0 = meshes[0].triangle_count() as f32;
    let targets: Vec<f32> = std::iter::once(1.0)
        .chain(meshes[1..].iter().map(|m| m.triangle_count() as f32 / t0))
        .collect();
    if targets.windows(2).any(|w| w[1] >= w[0]) {
        return Err(Error::Mesh {
            path: name.to_string(),
            problem: "an authored LOD chain's levels must have fewer triangles each".into(),
        });
    }
    let estimate = LodChain::build(name, &meshes[0], &targets)?;
    let mut errors: Vec<f32> = estimate.lods.iter().map(|l| l.error_abs).collect();
    for i in 1..errors.len() {
        errors[i] = errors[i].max(errors[i - 1] * 1.0001 + f32::MIN_POSITIVE);
    }
    Ok(errors)
}

/// The model of a chain: its switch distances (`--switch-distances` overrides them).
fn finish(
    view: &View<'_>,
    name: String,
    chain: LodChain,
    Sphere {
        centre: center,
        radius,
    }: Sphere,
    source: SwitchSource,
    color: [f32; 3],
) -> Result<Model> {
    let (switches, switch_source) =
        view.cfg
            .switches_or(&name, (chain.lods.len(), radius, view.fov_y), || {
                (
                    lod::switch_distances(
                        &chain,
                        1.0,
                        view.pixel_error,
                        view.pv.height,
                        view.fov_y,
                    ),
                    source,
                )
            })?;
    view.cfg.user_schedule.check_switches(&name, &switches)?;
    Ok(Model {
        color,
        name,
        lod_colors: Vec::new(),
        spin_per_frame: 0.0,
        chain,
        switches,
        switch_source,
        center,
        radius,
        scale: 1.0,
        deformed_reach: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A level whose switch is within the band ratio of the last kept one is dropped, and the next is measured
    /// against the last level kept, not the dropped one.
    #[test]
    fn near_levels_are_dropped_against_the_last_kept() {
        let r = 1.105;
        assert_eq!(levels_to_keep(&[1.0, 2.0, 4.0], r), [true; 4]);
        assert_eq!(
            levels_to_keep(&[1.0, 1.04, 1.1, 1.2, 3.0], r),
            [true, true, false, false, true, true]
        );
        assert_eq!(levels_to_keep(&[], r), [true]);
    }
}
