//! The experiment as files: the stimuli (stimuli.json), their frames (named by their bytes' hash, so a frame two
//! stimuli share is stored once) and the page (index.html: `page.html` with the stimuli written into it, so it
//! opens from the disk with no server).

use super::stimulus::Rendered;
use crate::cli::calibration::Display;
use crate::error::{Error, Result};
use crate::results::files::{CALIBRATE_PAGE, STIMULI_FRAMES_DIR, STIMULI_JSON};
use crate::results::manifest::BuildVersion;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The page: one file, its stimuli at [`PLACEHOLDER`] (`scripts/calibration.py page` fills it the same way).
pub const PAGE: &str = include_str!("page.html");
pub const PLACEHOLDER: &str = "__LODBENCH_STIMULI__";

/// The stimuli window and the intervals.
#[derive(Debug, Clone, Serialize)]
pub struct StimulusWindow {
    pub width_px: u32,
    pub height_px: u32,
    pub frames_per_interval: u32,
    pub gap_ms: f64,
    pub fov_y_deg: f32,
    pub fade_frames: u32,
}

/// The adaptive procedure the page runs (and `scripts/calibration.py simulate` mirrors).
#[derive(Debug, Clone, Serialize)]
pub struct Procedure {
    pub kind: &'static str,
    pub target: f64,
    pub down_steps: u32,
    pub up_steps: u32,
    pub trials_per_track: u32,
    pub seed: u64,
}

/// One stimulus as stimuli.json lists it.
#[derive(Debug, Clone, Serialize)]
pub struct StimulusRecord {
    pub id: String,
    pub track: String,
    pub asset: String,
    pub method: String,
    pub lods: String,
    pub switch_distance: f32,
    /// The switch distance over the one where the pair's error projects to one pixel: the ladder's step.
    pub scale: f32,
    pub switch_frame: u32,
    pub switch_frames: Vec<String>,
    pub still_frames: Vec<String>,
    pub lodpop: f64,
    pub lodpop_coverage: f64,
    pub lodpop_shading: f64,
    pub flip: f64,
    pub jod_popping: f64,
}

/// One staircase: an asset and a method, its stimuli in ascending order of the ladder's metric.
#[derive(Debug, Clone, Serialize)]
pub struct Track {
    pub id: String,
    pub asset: String,
    pub method: String,
    pub stimuli: Vec<String>,
}

/// stimuli.json.
#[derive(Debug, Clone, Serialize)]
pub struct Stimuli {
    pub format: &'static str,
    pub version: u32,
    pub id: String,
    pub command: String,
    #[serde(flatten)]
    pub build: BuildVersion,
    pub display: Display,
    pub stimulus: StimulusWindow,
    pub procedure: Procedure,
    pub ladder_metric: &'static str,
    pub metrics: [&'static str; 5],
    pub tracks: Vec<Track>,
    pub stimuli: Vec<StimulusRecord>,
}

/// The metrics each stimulus carries, the ladder's first.
pub const METRICS: [&str; 5] = [
    "lodpop",
    "lodpop_coverage",
    "lodpop_shading",
    "flip",
    "jod_popping",
];

/// FNV-1a, 64 bits: a frame's name from its bytes (stable across platforms and builds).
pub fn hash64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// Copies a rendered frame into `out`'s frames folder under its hash; its path relative to `out`.
fn keep(out: &Path, frame: &Path, kept: &mut BTreeMap<u64, String>) -> Result<String> {
    let bytes = std::fs::read(frame).map_err(|e| Error::io(frame, e))?;
    let h = hash64(&bytes);
    if let Some(name) = kept.get(&h) {
        return Ok(name.clone());
    }
    let name = format!("{STIMULI_FRAMES_DIR}/{h:016x}.png");
    let path = out.join(&name);
    std::fs::write(&path, &bytes).map_err(|e| Error::io(&path, e))?;
    kept.insert(h, name.clone());
    Ok(name)
}

/// The frames of `r` kept in `out` (their paths relative to it).
pub fn keep_frames(
    out: &Path,
    r: &Rendered,
    kept: &mut BTreeMap<u64, String>,
) -> Result<(Vec<String>, Vec<String>)> {
    let mut names = |frames: &[PathBuf]| -> Result<Vec<String>> {
        frames.iter().map(|f| keep(out, f, kept)).collect()
    };
    Ok((names(&r.switch_frames)?, names(&r.still_frames)?))
}

/// The stimuli as the page holds them: compact JSON with every `</` written `<\/`, so no string in it can end
/// the script element it sits in.
pub fn page_json(stimuli: &Stimuli) -> Result<String> {
    Ok(serde_json::to_string(stimuli)?.replace("</", "<\\/"))
}

/// Writes stimuli.json and index.html into `out`, each whole or not at all (a temporary file renamed).
pub fn write(out: &Path, stimuli: &Stimuli) -> Result<()> {
    let page = PAGE.replacen(PLACEHOLDER, &page_json(stimuli)?, 1);
    let files = [
        (STIMULI_JSON, serde_json::to_string_pretty(stimuli)?),
        (CALIBRATE_PAGE, page),
    ];
    for (name, text) in files {
        let path = out.join(name);
        let partial = out.join(crate::results::files::partial(name));
        std::fs::write(&partial, text).map_err(|e| Error::io(&partial, e))?;
        std::fs::rename(&partial, &path).map_err(|e| Error::io(&path, e))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_page_has_one_placeholder_inside_its_stimuli_script() {
        assert_eq!(PAGE.matches(PLACEHOLDER).count(), 1);
        let at = PAGE.find(PLACEHOLDER).unwrap();
        let open = PAGE[..at].rfind("<script").unwrap();
        assert!(PAGE[open..at].contains("id=\"stimuli\"") && !PAGE[open..at].contains("</script"));
    }

    #[test]
    fn frame_names_are_their_bytes_hash() {
        // FNV-1a's published test vectors: the empty string and "a".
        assert_eq!(hash64(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(hash64(b"a"), 0xaf63_dc4c_8601_ec8c);
    }
}
