//! What tune finds: each view's samples, each pair's switch with the engines' rules there and the blending
//! methods' bands, per model; and the settings it ran with.

use crate::measure::engine_rules::Rule;
use serde::Serialize;

/// One measurement: model `model`'s LOD `lod` against LOD `lod + 1`, seen from view `view` at `distance` (from the
/// model's bounding-sphere centre).
#[derive(Debug, Clone, Serialize)]
pub struct Sample {
    pub model: String,
    pub lod_from: u32,
    pub lod_to: u32,
    pub view: u32,
    pub distance: f32,
    /// The bounding sphere's projected diameter over the viewport's height at `distance`.
    pub screen_size: f32,
    pub lodpop: f64,
    pub lodpop_coverage: f64,
    pub lodpop_shading: f64,
    /// With `--budget-jod`: ColorVideoVDP's JOD between the two frames.
    pub jod: Option<f64>,
    /// Whether the sample is a bisection step (not a grid distance).
    pub refined: bool,
}

/// What `lodbench tune` measures with.
#[derive(Debug, Clone, Serialize)]
pub struct TuneSettings {
    pub budget: Budget,
    pub views: u32,
    /// Grid distances per view.
    pub distances: u32,
    /// The view directions' seed.
    pub seed: u64,
    /// `--speed` (world units per second) and `--fps`: the camera's speed the blending methods' bands are for.
    pub speed: Option<(f32, f32)>,
    /// The schedule's `--band` (its half-width as a fraction of a switch distance): consecutive switches are kept
    /// far enough apart that their bands do not overlap, as `lodbench run` requires.
    pub band: f32,
    /// `--full-grid`: every view measured at every grid distance, as tune.csv then shows (else each view from the
    /// farthest grid distance in to the nearest that breaks the budget: the same switches, fewer draws).
    pub full_grid: bool,
}

impl TuneSettings {
    /// Whether every view is measured at every grid distance: with `--full-grid`, and with `--speed` (the
    /// blending methods' bands read the grid's worst view nearer than the hard switch).
    pub fn full_grid(&self) -> bool {
        self.full_grid || self.speed.is_some()
    }
}

/// A blending method's transition at a pair: the nearest switch whose band (a relative half-width, the
/// schedule's `--band`) keeps every frame's change within the budget at the camera's speed.
#[derive(Debug, Clone, Serialize)]
pub struct BlendBand {
    pub method: &'static str,
    pub switch_distance: f32,
    /// Half-width of the band as a fraction of the switch distance (`--band`).
    pub band: f32,
    /// Frames the transition lasts at the camera's speed.
    pub frames: u32,
}

/// One pair's switch.
#[derive(Debug, Clone, Serialize)]
pub struct PairSwitch {
    pub lod_from: u32,
    pub lod_to: u32,
    pub triangles_from: usize,
    pub triangles_to: usize,
    /// Where the hard switch may happen: the nearest distance from which every view stays within the budget
    /// (None: no distance measured does; the coarser LOD is not used).
    pub switch_distance: Option<f32>,
    /// The bounding sphere's projected diameter over the viewport's height there.
    pub screen_size: Option<f32>,
    /// The view whose curve set the distance.
    pub limiting_view: Option<u32>,
    /// The largest value over the views at the switch (the budget's metric).
    pub value_at_switch: Option<f64>,
    /// How far beyond the switch the dense check went (where the grid's worst view stays below
    /// [`NEAR_BUDGET`] of the budget from there on), and the worst it saw from the switch to there.
    pub checked_to: Option<f32>,
    pub checked_worst: Option<f64>,
    /// LOD `lod_to`'s simplifier error (object-space units) and what it projects to at the switch, in pixels:
    /// the error bound an engine's rule (Godot's pixel threshold, Simplygon's deviation) would have used there.
    pub error_abs: f32,
    pub error_px_at_switch: Option<f32>,
    /// Each view's own crossing (None: never within).
    pub per_view: Vec<Option<f32>>,
    /// With `--speed`: alpha's, dither's and geomorph's bands.
    pub bands: Vec<BlendBand>,
    /// Where the engines' rules would switch, and what the views see there.
    pub rules: Vec<RuleAt>,
}

/// An engine's rule at one pair: where it switches and the budget's figure there (the worst over the views).
#[derive(Debug, Clone, Serialize)]
pub struct RuleAt {
    pub rule: Rule,
    pub distance: f32,
    pub screen_size: f32,
    pub value: Option<f64>,
    /// Whether every view stays within the budget at the rule's distance.
    pub within: bool,
}

/// One model's switches.
#[derive(Debug, Clone, Serialize)]
pub struct ModelSwitches {
    pub model: u32,
    pub name: String,
    /// Bounding-sphere radius (world units) and centre (model space).
    pub radius: f32,
    pub center: [f32; 3],
    /// The grid of distances measured: where the model fits the view, to where it is two pixels across.
    pub near: f32,
    pub far: f32,
    pub pairs: Vec<PairSwitch>,
}

/// What a switch must keep the image change within.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "metric", content = "value", rename_all = "snake_case")]
pub enum Budget {
    /// lodpop (RMS over the frame, sRGB-encoded, in [0, 1]) at most this.
    Lodpop(f64),
    /// ColorVideoVDP's JOD between the two frames at least this (10: no visible difference).
    Jod(f64),
}

impl Budget {
    /// How far `value` is from no change at all: lodpop itself, or 10 - JOD.
    pub fn excess(self, value: f64) -> f64 {
        match self {
            Budget::Lodpop(_) => value,
            Budget::Jod(_) => 10.0 - value,
        }
    }

    /// The budget as an excess ([`Budget::excess`]).
    pub fn excess_limit(self) -> f64 {
        match self {
            Budget::Lodpop(x) => x,
            Budget::Jod(j) => 10.0 - j,
        }
    }

    /// The worse of two values.
    pub fn worse(self, a: f64, b: f64) -> f64 {
        match self {
            Budget::Lodpop(_) => a.max(b),
            Budget::Jod(_) => a.min(b),
        }
    }

    /// Whether `value` (of this budget's metric) breaks the budget.
    pub fn broken_by(self, value: f64) -> bool {
        match self {
            Budget::Lodpop(x) => value > x,
            Budget::Jod(j) => value < j,
        }
    }
}
