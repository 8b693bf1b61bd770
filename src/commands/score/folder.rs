//! The score folder another renderer writes (docs/measurement.md, "Scoring another renderer's frames"): read
//! and checked whole before anything is computed, each breach of the protocol one error naming the file and
//! what is wrong.

use crate::error::{Error, Result};
use crate::results::csv::{read_rows, CsvRow};
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The protocol's names.
pub const SCORE_JSON: &str = "score.json";
pub const LODS_CSV: &str = "lods.csv";
pub const STATS_CSV: &str = "stats.csv";
pub const FRAME_DIR: &str = "frame";
pub const COUNTERFACTUAL_DIR: &str = "counterfactual";
pub const REFERENCE_DIR: &str = "reference";
const LODS_COLUMNS: [&str; 5] = ["frame", "object", "lod", "lod_to", "k"];
const STATS_COLUMNS: [&str; 5] = ["frame", "cpu_ms", "gpu_ms", "triangles", "draw_calls"];

/// score.json: who drew the frames and how to read them.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EngineManifest {
    /// The renderer, its version and platform, as the user wants it named.
    pub engine: String,
    /// Frames a second the frames stand for (the camera path's rate).
    pub fps: f64,
    /// sRGB bytes of a pixel nothing was drawn on.
    pub background: [u8; 3],
    /// The scene's name in the CSVs (default: the folder's name).
    #[serde(default)]
    pub scene: Option<String>,
    /// The method's name in the CSVs (default `engine`).
    #[serde(default)]
    pub method: Option<String>,
    /// How the renderer moves between levels: `none` (switches) or the name of its blend.
    #[serde(default)]
    pub blend: Option<String>,
    /// Anything else the renderer wants kept with the results (its settings, the path).
    #[serde(default)]
    pub notes: Option<serde_json::Value>,
}

/// What one object drew on one frame: a level, or a blend from `lod` to `lod_to` at `k`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Selection {
    pub lod: u32,
    pub blend: Option<(u32, f64)>,
}

/// One frame's timing and load, as the renderer measured them (stats.csv).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FrameStats {
    pub cpu_ms: f64,
    pub gpu_ms: Option<f64>,
    pub triangles: u64,
    pub draw_calls: u32,
}

/// A checked score folder.
#[derive(Debug)]
pub struct ScoreFolder {
    pub dir: PathBuf,
    pub manifest: EngineManifest,
    pub objects: Vec<String>,
    /// Per frame, per object (in `objects`' order).
    pub selections: Vec<Vec<Selection>>,
    /// Per frame: whether counterfactual/ holds its image.
    pub counterfactual: Vec<bool>,
    pub reference: bool,
    pub stats: Option<Vec<FrameStats>>,
}

impl ScoreFolder {
    /// Reads and checks `dir` (the images' sizes are checked as they are read).
    pub fn read(dir: &Path) -> Result<ScoreFolder> {
        let bad = |file: &str, problem: String| Error::score(dir.join(file), problem);
        let manifest = read_manifest(dir)?;
        let (objects, selections) = read_lods(dir)?;
        let frames = selections.len();
        let listed = |sub: &str| pictures_in(dir, sub, frames);
        let drawn = listed(FRAME_DIR)?;
        if let Some(f) = (0..frames).find(|&f| !drawn[f]) {
            return Err(bad(
                LODS_CSV,
                format!(
                    "names frame {f}, but {FRAME_DIR}/{} is not there",
                    picture_name(f as u32)
                ),
            ));
        }
        let counterfactual = listed(COUNTERFACTUAL_DIR)?;
        if let Some(f) =
            (1..frames).find(|&f| selections[f] != selections[f - 1] && !counterfactual[f])
        {
            return Err(bad(
                COUNTERFACTUAL_DIR,
                format!(
                    "has no {} although lods.csv's selection changed on frame {f}: draw frame {f}'s pose \
                     with frame {}'s selection",
                    picture_name(f as u32),
                    f - 1
                ),
            ));
        }
        let references = listed(REFERENCE_DIR)?;
        let reference = references.iter().any(|&r| r);
        if let Some(f) = (0..frames).find(|&f| reference && !references[f]) {
            return Err(bad(
                REFERENCE_DIR,
                format!(
                    "has some frames but not {}: give the reference of every frame, or none",
                    picture_name(f as u32)
                ),
            ));
        }
        let stats = read_stats(dir, frames)?;
        Ok(ScoreFolder {
            dir: dir.to_path_buf(),
            manifest,
            objects,
            selections,
            counterfactual,
            reference,
            stats,
        })
    }

    pub fn frames(&self) -> u32 {
        self.selections.len() as u32
    }

    /// The image of frame `f` in `sub` (frame/, counterfactual/, reference/).
    pub fn picture(&self, sub: &str, f: u32) -> PathBuf {
        self.dir.join(sub).join(picture_name(f))
    }
}

/// A frame's picture name: its number in five digits, `00042.png`.
pub fn picture_name(f: u32) -> String {
    format!("{f:05}.png")
}

fn read_manifest(dir: &Path) -> Result<EngineManifest> {
    let path = dir.join(SCORE_JSON);
    let text = std::fs::read_to_string(&path).map_err(|e| {
        Error::score(
            &path,
            format!("cannot be read ({e}): a score folder starts with it"),
        )
    })?;
    let m: EngineManifest = serde_json::from_str(&text)
        .map_err(|e| Error::score(&path, format!("is not a score manifest: {e}")))?;
    if !(m.fps.is_finite() && m.fps > 0.0) {
        return Err(Error::score(
            &path,
            format!("fps {} is not a positive frame rate", m.fps),
        ));
    }
    Ok(m)
}

/// lods.csv: the objects (sorted) and per frame each one's selection.
fn read_lods(dir: &Path) -> Result<(Vec<String>, Vec<Vec<Selection>>)> {
    let path = dir.join(LODS_CSV);
    let bad = |problem: String| Error::score(&path, problem);
    if !path.is_file() {
        return Err(bad(
            "is missing: a row per frame and object (frame,object,lod)".into(),
        ));
    }
    let rows = read_rows(&path).map_err(|e| bad(format!("cannot be read ({e})")))?;
    check_columns(&rows, &LODS_COLUMNS, &["frame", "object", "lod"]).map_err(bad)?;
    let mut cells: BTreeMap<(u32, String), Selection> = BTreeMap::new();
    for (i, row) in rows.iter().enumerate() {
        let line = i + 2;
        let s = selection_of(row).map_err(|p| bad(format!("line {line}: {p}")))?;
        let frame = whole(row.text("frame")).map_err(|p| bad(format!("line {line}: frame {p}")))?;
        if cells
            .insert((frame as u32, row.text("object").to_string()), s)
            .is_some()
        {
            return Err(bad(format!(
                "line {line}: frame {frame} of {} given twice",
                row.text("object")
            )));
        }
    }
    let objects: BTreeSet<String> = cells.keys().map(|(_, o)| o.clone()).collect();
    let frames = cells.keys().map(|(f, _)| f + 1).max().unwrap_or(0);
    if frames == 0 {
        return Err(bad("has no rows".into()));
    }
    let mut selections = Vec::with_capacity(frames as usize);
    for f in 0..frames {
        let row = objects
            .iter()
            .map(|o| {
                cells.get(&(f, o.clone())).copied().ok_or_else(|| {
                    bad(format!(
                        "has no row for {o} on frame {f}: every object on every frame 0..{frames}"
                    ))
                })
            })
            .collect::<Result<Vec<_>>>()?;
        selections.push(row);
    }
    Ok((objects.into_iter().collect(), selections))
}

/// A row's selection: `lod`, and `lod_to` with `k` for a blend (both or neither).
fn selection_of(row: &CsvRow) -> std::result::Result<Selection, String> {
    if row.text("object").is_empty() {
        return Err("object is empty".into());
    }
    let lod = whole(row.text("lod")).map_err(|p| format!("lod {p}"))? as u32;
    let (to, k) = (row.text("lod_to"), row.text("k"));
    let blend = match (to.is_empty(), k.is_empty()) {
        (true, true) => None,
        (false, false) => {
            let to = whole(to).map_err(|p| format!("lod_to {p}"))? as u32;
            let k: f64 = k.parse().map_err(|_| format!("k {k:?} is not a number"))?;
            if !(0.0..=1.0).contains(&k) {
                return Err(format!("k {k} is outside [0, 1]"));
            }
            Some((to, k)).filter(|&(to, _)| to != lod)
        }
        _ => return Err("lod_to and k go together: give both for a blend, or neither".into()),
    };
    Ok(Selection { lod, blend })
}

fn whole(text: &str) -> std::result::Result<u64, String> {
    text.parse()
        .map_err(|_| format!("{text:?} is not a whole number"))
}

/// The CSV's columns are among `known` and hold `required`.
fn check_columns(
    rows: &[CsvRow],
    known: &[&str],
    required: &[&str],
) -> std::result::Result<(), String> {
    let Some(first) = rows.first() else {
        return Ok(());
    };
    let columns: Vec<&str> = first.0.iter().map(|(c, _)| c.as_str()).collect();
    if let Some(c) = columns.iter().find(|c| !known.contains(c)) {
        return Err(format!(
            "has an unknown column {c:?} (known: {})",
            known.join(", ")
        ));
    }
    match required.iter().find(|r| !columns.contains(r)) {
        Some(r) => Err(format!("has no column {r:?}")),
        None => Ok(()),
    }
}

/// Per frame, whether `dir/sub/` holds its picture; a picture of a frame lods.csv does not name, or a file
/// not named as a frame's picture, is refused.
fn pictures_in(dir: &Path, sub: &str, frames: usize) -> Result<Vec<bool>> {
    let folder = dir.join(sub);
    let mut have = vec![false; frames];
    if !folder.is_dir() {
        return Ok(have);
    }
    for entry in std::fs::read_dir(&folder).map_err(|e| Error::io(&folder, e))? {
        let entry = entry.map_err(|e| Error::io(&folder, e))?;
        let name = entry.file_name().to_string_lossy().to_string();
        let number = name
            .strip_suffix(".png")
            .filter(|s| s.len() == 5)
            .and_then(|s| s.parse::<usize>().ok());
        match number {
            Some(f) if f < frames => have[f] = true,
            Some(f) => {
                return Err(Error::score(
                    folder.join(&name),
                    format!("is frame {f}, but lods.csv names frames 0..{frames} only"),
                ))
            }
            None => {
                return Err(Error::score(
                    folder.join(&name),
                    "is not a frame's picture: name them 00000.png, 00001.png, ...",
                ))
            }
        }
    }
    Ok(have)
}

/// stats.csv, if present: a row per frame.
fn read_stats(dir: &Path, frames: usize) -> Result<Option<Vec<FrameStats>>> {
    let path = dir.join(STATS_CSV);
    if !path.is_file() {
        return Ok(None);
    }
    let bad = |problem: String| Error::score(&path, problem);
    let rows = read_rows(&path).map_err(|e| bad(format!("cannot be read ({e})")))?;
    check_columns(&rows, &STATS_COLUMNS, &["frame", "cpu_ms"]).map_err(bad)?;
    let mut stats = vec![None; frames];
    for (i, row) in rows.iter().enumerate() {
        let line = i + 2;
        let f =
            whole(row.text("frame")).map_err(|p| bad(format!("line {line}: frame {p}")))? as usize;
        let number = |c: &str| row.num(c).filter(|v| v.is_finite() && *v >= 0.0);
        let cpu_ms =
            number("cpu_ms").ok_or_else(|| bad(format!("line {line}: cpu_ms is not a time")))?;
        let s = FrameStats {
            cpu_ms,
            gpu_ms: number("gpu_ms"),
            triangles: number("triangles").unwrap_or(0.0) as u64,
            draw_calls: number("draw_calls").unwrap_or(0.0) as u32,
        };
        match stats.get_mut(f) {
            Some(slot) if slot.is_none() => *slot = Some(s),
            Some(_) => return Err(bad(format!("line {line}: frame {f} given twice"))),
            None => {
                return Err(bad(format!(
                    "line {line}: frame {f} is not in lods.csv (0..{frames})"
                )))
            }
        }
    }
    match stats.iter().position(|s| s.is_none()) {
        Some(f) => Err(bad(format!("has no row for frame {f}"))),
        None => Ok(Some(stats.into_iter().flatten().collect())),
    }
}
