//! lodbench: an experiment harness that measures what smooth level-of-detail transition methods cost and how
//! much they pop. See README.md for the data path and the meaning of every number.

pub mod cli;
pub mod config;
pub mod error;
pub mod experiment;
pub mod export;
pub mod gpu;
pub mod lod;
pub mod mesh;
pub mod methods;
pub mod metrics;
pub mod morph;
pub mod noise;
pub mod procgen;
pub mod rng;
pub mod runner;
pub mod scene;
pub mod schedule;

pub use error::{Error, Result};
