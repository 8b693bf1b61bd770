//! `lodbench tune`: LOD switch distances chosen from a popping budget, by measurement. For each model and each
//! pair of its LODs (k, k + 1), the model alone is drawn at LOD k and at LOD k + 1, with its materials and the
//! scene's light, from N view directions at a range of distances; the image change that switching there would
//! cause is lodpop's (the RMS over the frame of the two frames' difference, with its coverage and shading parts),
//! or ColorVideoVDP's JOD between the two frames. The pair's switch distance is the nearest one from which every
//! view stays within the budget (docs/methods.md, "Choosing thresholds: lodbench tune").
//!
//! The search ([`nearest_within`]) takes each view's curve on a grid of distances, nearest first, finds the
//! farthest grid distance that breaks the budget and refines the crossing just beyond it by bisection: a curve
//! that is not monotone (a coarse LOD whose error shows only from some angles and distances) is within the budget
//! from the switch outwards, at every grid distance. A dip below the budget nearer than its last excess is not
//! taken. A LOD that breaks the budget even at the farthest distance measured (its projected size two pixels) is
//! never switched to. Every view is then measured at the switch (moving it out a grid distance while one
//! breaks the budget), and, since rasterisation makes the curve jagged between grid distances, at
//! [`DENSE_PER_STEP`] distances per grid step from the switch to where the grid's worst view stays below
//! [`NEAR_BUDGET`] of the budget, the switch moving past any distance that breaks it.
//!
//! One file per job: [`search`] (the search and its grid), [`camera`] (the camera that draws each model
//! alone), [`reset`] (its crops put back as a clear leaves them), [`frame_cache`] (frames one pair draws for the
//! next), [`model`] (the per-model driver), [`bands`] (the blending methods' bands) and [`outcome`] (what it
//! finds).

pub mod bands;
pub mod camera;
pub mod frame_cache;
pub mod model;
pub mod outcome;
pub mod reset;
pub mod search;

pub use camera::{FrameScore, ModelCamera};
pub use model::tune_model;
pub use outcome::Budget;
pub use outcome::{BlendBand, ModelSwitches, PairSwitch, RuleAt, Sample, TuneSettings};
pub use search::view_directions;
