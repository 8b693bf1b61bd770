//! lodbench: an experiment harness that measures what smooth level-of-detail transition methods cost and how
//! much they pop. docs/ARCHITECTURE.md shows the data path through these modules and the one direction their
//! imports run in; docs/measurement.md defines every number.

#![cfg_attr(
    test,
    allow(
        clippy::unwrap_used,
        clippy::expect_used,
        reason = "unit tests fail by panicking"
    )
)]

pub mod blocks;
pub mod cli;
pub mod clips;
pub mod clusterlod;
pub mod config;
pub mod defaults;
pub mod error;
pub mod experiment;
pub mod export;
pub mod formats;
pub mod gpu;
pub mod lod;
pub mod measure;
pub mod merge;
pub mod mesh;
pub mod methods;
pub mod metrics;
pub mod morph;
pub mod noise;
pub mod perceptual;
pub mod procgen;
pub mod records;
pub mod rng;
pub mod runner;
pub mod scene;
pub mod schedule;
pub mod shadow;
pub mod stats;
pub mod taa;
pub mod terrain;

pub use error::{Error, Result};
