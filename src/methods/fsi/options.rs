//! `fsi*`'s variants and flags: the paper's method and its ablations, `--fsi-check`, `--vis-space`, `--vis-texture`.

use crate::methods::noise::VisTexture;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variant {
    /// The paper's method: one LOD buffer per frame, the older one reprojected by eq. 2.
    Sequential,
    /// The older buffer read at the same pixel.
    NoReproject,
    /// Both LOD buffers rendered every frame, same camera.
    SameFrame,
    /// Frame-sequential blending (section 3.3, Fig. 4, the alternative the paper rejects): one LOD buffer per
    /// frame as `Sequential`, each t-instance's LOD complete (no visibility texture), and the two buffers
    /// alpha-blended by the LOD's weight (k for the incoming LOD, 1 - k for the outgoing one).
    Blend,
}

/// `--fsi-check`: an optional test on the older buffer's fragment before the combination pass uses it. Not in
/// the paper; off by default, so `fsi` is the paper's method unless asked otherwise.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum FsiCheck {
    /// The paper's combination: the older fragment at eq. 2's lookup.
    None,
    /// Forward consistency (`fsi` only; the ablations do not reproject): the older fragment used is one that,
    /// reprojected into the newer frame with its own depth (eq. 2 inverted), lands within a pixel of the
    /// pixel's centre: eq. 2's lookup if it does, else the texel found by moving the lookup by the rounded
    /// miss (at most 4 texels tried); if none does, the pixel takes the newer colour, as a pixel that
    /// reprojects outside does. Eq. 2 back-projects with the newer depth, which is the background's wherever
    /// the newer buffer shows background: where the camera's motion has uncovered it, the lookup lands where a
    /// near object stood a frame ago and case 3 shows the object there again (section 4.2's disocclusion
    /// artefact; no fragment of it lands near the pixel, so it is rejected); where eq. 1 discarded a
    /// t-instance's fragment, the lookup lands on another part of the other LOD (the search finds the part
    /// that moved here). The tolerance is a pixel, not a pixel's half-width, so that an image that magnifies
    /// between frames leaves no pixel without a match. Like eq. 2 it assumes objects do not move: a moving
    /// t-instance's older fragments can miss by more than a pixel, and then its holes show what is behind it
    /// (measured in docs/findings/fsi-forward-check.md).
    Forward,
}

/// `fsi*`'s flags.
#[derive(Debug, Clone, Copy, PartialEq, clap::Args, serde::Serialize, serde::Deserialize)]
#[serde(default, rename_all(deserialize = "kebab-case"))]
pub struct FsiOptions {
    /// fsi*: the visibility texture of Frame Sequential Interpolation (Scherzer & Wimmer 2008 section 3.3).
    #[arg(long, value_enum, value_parser = crate::defaults::names_only::<VisTexture>(),
          default_value_t = VisTexture::Noise, help_heading = crate::defaults::heading::METHODS)]
    pub vis_texture: VisTexture,
    /// fsi only, not in the paper: forward uses an older fragment only if it reprojects onto the pixel.
    #[arg(long, value_enum, value_parser = crate::defaults::names_only::<FsiCheck>(),
          default_value_t = FsiCheck::None, help_heading = crate::defaults::heading::METHODS)]
    pub fsi_check: FsiCheck,
    /// fsi*: where the visibility texture is looked up: in object space (the paper's) or in world space.
    #[arg(long, value_enum, value_parser = crate::defaults::names_only::<VisSpace>(),
          default_value_t = VisSpace::Object, help_heading = crate::defaults::heading::METHODS)]
    pub vis_space: VisSpace,
}

/// `--vis-space`: the space FSI's visibility texture is looked up in.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum VisSpace {
    /// The object-space position before animation (Scherzer & Wimmer 2008 section 3.3).
    Object,
    /// The world-space position after animation and the instance transform.
    World,
}

impl Default for FsiOptions {
    fn default() -> Self {
        crate::defaults::clap_defaults()
    }
}
