//! Engine effects that change every frame a method draws: temporal anti-aliasing (the jitter and its settings)
//! and the directional shadow map (its settings, the light's fit, what casts). Their GPU passes are in `gpu/`
//! (`taa_resolve.rs`, `shadow_pass.rs`); measure/ decides which frames they apply to.

pub mod shadow;
pub mod taa;

use serde::{Deserialize, Serialize};

/// The value of an on/off flag (`--taa`, `--shadows`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum OnOff {
    On,
    Off,
}
