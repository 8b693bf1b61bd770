//! lodbench's integration tests, one binary (`cargo test --test it`; a module with `cargo test --test it
//! render::`): the helpers every test shares are in `common.rs`.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    reason = "a test fails by panicking"
)]

mod architecture;
mod ci_profile;
mod cli;
mod clips;
mod common;
mod fidelity;
mod fsi;
mod lodpop;
mod registry;
mod regress;
mod render;
mod shaders;
mod shadows;
mod sharding;
mod taa;
mod unified;
mod variants;
