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

// The data path, top to bottom: each folder imports only the folders below it (tests/it/architecture.rs
// holds the order as data and fails on an import against it).
pub mod cli;
pub mod commands;
pub mod defaults;
pub mod effects;
pub mod error;
pub mod formats;
pub mod geometry;
pub mod gpu;
pub mod measure;
pub mod methods;
pub mod numbers;
pub mod raster;
pub mod results;
pub mod rng;
pub mod scene;

pub use error::{Error, Result};
