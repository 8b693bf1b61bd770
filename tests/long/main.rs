//! lodbench's long suite (`cargo test --release --test long`): the tests that are whole experiments by nature,
//! which `cargo test` leaves out (`test = false` in Cargo.toml) and `.ci/run` runs after the README's test
//! command. Both must pass for a change to land. The helpers are tests/it/common.rs's, shared.
//!
//! - `regress`: the regression set, every scene and method at 96x72 against results/baseline/regress/ (about
//!   a minute and a half on lavapipe);
//! - `commands_clips`: `lodbench clips` on the regression set's dumps;
//! - `scene_fidelity`: a dense scan-like mesh (58,784 triangles) swept through every LOD by discrete and FSI at the
//!   quick profile's 600 frames (about 37 s);
//! - `commands_cluster`: the GNU parallel and Slurm recipes, each a sharded experiment merged (Slurm's on a local
//!   one-node cluster, about 12 s);
//! - `commands_probe_bands`: `lodbench probe`'s timing bands, ratios of paired rounds measured up to three times;
//! - `methods_fsi_memory`: FSI's combination pass holds no memory per frame, 40 frames against 280 (about 15 s).

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    reason = "a test fails by panicking"
)]

#[path = "../it/common.rs"]
#[allow(dead_code, reason = "the long suite uses a few of the shared helpers")]
mod common;

mod commands_clips;
mod commands_cluster;
mod commands_probe_bands;
mod methods_fsi_memory;
mod regress;
mod scene_fidelity;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The regression set (`--profile regress`, every scene and method at 96x72, with the transitions' dumps), run
/// once per test binary into the target's temporary folder; the regression tests and the clips tests read it.
pub fn regress_run() -> &'static PathBuf {
    static OUT: OnceLock<PathBuf> = OnceLock::new();
    OUT.get_or_init(|| {
        let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("regress");
        common::run_into(
            &out,
            &[
                "--profile",
                "regress",
                "--metrics",
                "rmse,pop,de2000",
                "--dump-frames",
                "--dump-transitions",
            ],
        )
    })
}
