//! lodbench's integration tests, one binary (`cargo test --test it`; one file's tests with `cargo test --test it
//! methods_fsi::`). The helpers every test shares are in `common.rs`, and only there.
//!
//! One rule says where a test goes (docs/ARCHITECTURE.md, "Contributing: where a test goes"): a file per folder
//! of `src/` whose behaviour it checks, named `<folder>_<subject>.rs` (`methods_fsi.rs` checks
//! `src/methods/fsi/`, `effects_taa.rs` the TAA of `src/effects/`); a test that checks every layer at once
//! (a whole run against blessed figures or images) goes to one of the suites, and the checks of the source tree
//! itself are named after what they read.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    reason = "a test fails by panicking"
)]

mod common;

// src/cli: flags, validation and the errors of bad input; the help texts.
mod cli_help;
mod cli_input;
// src/commands: the subcommands through the binary.
mod commands_calibrate;
mod commands_compare;
mod commands_experiment;
mod commands_overhead;
mod commands_probe;
mod commands_score;
mod commands_tune;
// src/geometry: the projection every layer computes with.
mod geometry_projection;
// src/gpu: what the GPU draws of a scene's materials.
mod gpu_materials;
// src/measure: the quality pass's figures, and runs without it.
mod measure_coverage;
mod measure_lodpop;
mod measure_metric_kernel;
mod measure_quality_off;
mod measure_reference_cache;
mod measure_timing;
// src/methods: one method (or a family of variants) in images.
mod methods_fsi;
mod methods_impostor;
mod methods_registry;
mod methods_variants;
// src/scene: the scenes' paths, animation and the unified scenes.
mod scene_animation;
mod scene_fidelity;
mod scene_unified;
mod scene_user;
// src/effects: TAA and shadows.
mod effects_shadows;
mod effects_taa;

// The suites: whole runs against the snapshots and the ci profile (the regression set is in tests/long/).
mod ci_profile;
mod render;

// The fuzz targets' corpora replayed (tests/fuzz/).
mod fuzz_corpus;

// The source tree: the import graph of src/ and the WGSL of shaders/.
mod architecture;
mod shaders;
