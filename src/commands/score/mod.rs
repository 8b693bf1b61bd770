//! `lodbench score DIR`: popping from any renderer's frames. The renderer writes a score folder ([`folder`]):
//! its frames, each one's counterfactual where its LOD selection changed (the same pose drawn with the previous
//! frame's selection), optionally the high-poly reference, and lods.csv; this computes the figures a run
//! computes from the same exact sums ([`crate::measure::frame_figures`]) and writes them as a run folder does:
//! frames.csv, transitions.csv, summary.csv, run.json, answer.json, and frames/ holding the pictures under a
//! run's dump names, so `plot.py`, `clips`, `perceptual` and report.html read the folder as a run's.
//!
//! A transition here is what the renderer shows: an object is in transition on a frame where it blends
//! (`lod_to` and `k`) or where the level it draws differs from the previous frame's (a switch, one frame).

pub mod folder;

use crate::cli::ScoreArgs;
use crate::commands::run::prepare_output;
use crate::error::{Error, Result};
use crate::measure::frame_figures::{FramePictures, ImageFigures, SequenceFigures};
use crate::measure::metrics::Metric;
use crate::measure::records::{
    set_visible_pops, switches, transitions, Clock, FrameChanges, FrameRecord, SummaryRecord,
    TransitionPair, Visibility,
};
use crate::raster::RgbaImage;
use crate::results::csv::{
    write_events, write_pairs, write_rounds, write_summary, write_transitions, FramesWriter,
};
use crate::results::files::{DumpKind, RUN_JSON};
use crate::results::png::{FrameDumper, FrameId};
use folder::{ScoreFolder, Selection, COUNTERFACTUAL_DIR, FRAME_DIR, REFERENCE_DIR};
use std::path::Path;

/// Scores the folder `args` names.
pub fn execute(args: &ScoreArgs) -> Result<()> {
    let folder = ScoreFolder::read(&args.dir)?;
    let out = args.out.clone().unwrap_or_else(|| args.dir.clone());
    let flip = args.metrics.contains(&Metric::Flip);
    let de2000 = args.metrics.contains(&Metric::De2000);
    let figures = figures_of(&folder, (flip, de2000))?;
    prepare_output(&out)?;
    let (scene, method) = names(&folder);
    let moving: Vec<_> = (0..folder.selections.len())
        .map(|f| in_transition(&folder.selections, f))
        .collect();
    let rows = records(&folder, (&figures, &moving), (&scene, &method));
    let pairs = frame_pairs(&moving);
    let mut found = transitions(&rows, &pairs);
    let mut summaries: Vec<SummaryRecord> =
        SummaryRecord::from_frames(&rows, 0, 1, Clock::of(&rows))
            .into_iter()
            .collect();
    let visibility = Visibility {
        threshold: args.budget_lodpop,
        fps: folder.manifest.fps,
        jnd: None,
    };
    let changed = changed_objects(&folder.selections);
    let events = set_visible_pops(
        &mut summaries,
        &mut found,
        &switches(&rows, &changed),
        visibility,
    );
    link_pictures(&folder, &out, (&scene, &method))?;
    let mut frames_csv = FramesWriter::create(&out)?;
    frames_csv.write_block(&rows)?;
    frames_csv.finish()?;
    write_summary(&out, &summaries)?;
    write_transitions(&out, &found)?;
    write_events(&out, &events)?;
    write_rounds(&out, &[])?;
    write_pairs(&out, &[])?;
    write_manifest(&folder, args, &out, (&scene, &method))?;
    crate::results::answer::write(&out)?;
    print_transitions(&found, args.budget_lodpop);
    outln!(
        "{}: {} frames of {} scored",
        out.display(),
        rows.len(),
        folder.manifest.engine
    );
    Ok(())
}

/// The scene's and the method's names in the CSVs.
fn names(folder: &ScoreFolder) -> (String, String) {
    let m = &folder.manifest;
    let dir_name = folder
        .dir
        .canonicalize()
        .ok()
        .and_then(|d| d.file_name().map(|n| n.to_string_lossy().to_string()))
        .unwrap_or_else(|| "engine".into());
    (
        m.scene.clone().unwrap_or(dir_name),
        m.method.clone().unwrap_or_else(|| "engine".into()),
    )
}

/// Every frame's image figures, each picture read and its size checked against frame 0's.
fn figures_of(folder: &ScoreFolder, (flip, de2000): (bool, bool)) -> Result<Vec<ImageFigures>> {
    let first = load(&folder.picture(FRAME_DIR, 0))?;
    let size = first.dimensions();
    let mut seq = SequenceFigures::new(size.0, size.1, folder.manifest.background, (flip, de2000));
    let mut out = Vec::with_capacity(folder.frames() as usize);
    for f in 0..folder.frames() {
        let picture = |sub: &str| -> Result<RgbaImage> {
            let path = folder.picture(sub, f);
            let img = load(&path)?;
            match img.dimensions() == size {
                true => Ok(img),
                false => Err(Error::score(
                    &path,
                    format!(
                        "is {}x{}, but frame/00000.png is {}x{}: every picture of a score folder is one size",
                        img.width(),
                        img.height(),
                        size.0,
                        size.1
                    ),
                )),
            }
        };
        let frame = picture(FRAME_DIR)?;
        let counterfactual = folder.counterfactual[f as usize]
            .then(|| picture(COUNTERFACTUAL_DIR))
            .transpose()?;
        let reference = folder
            .reference
            .then(|| picture(REFERENCE_DIR))
            .transpose()?;
        out.push(seq.next(&FramePictures {
            frame: frame.as_raw(),
            counterfactual: counterfactual.as_ref().map(RgbaImage::as_raw),
            reference: reference.as_ref().map(RgbaImage::as_raw),
        }));
    }
    Ok(out)
}

fn load(path: &Path) -> Result<RgbaImage> {
    if !path.is_file() {
        return Err(Error::score(path, "is missing"));
    }
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    crate::raster::decode(&bytes)
        .map_err(|e| Error::score(path, format!("is not a readable PNG ({e})")))
}

/// A frame's objects in transition: (from, to, k) of each ([`in_transition`]).
type Moving = Vec<(u32, u32, f64)>;

/// Per frame, the objects whose selection differs from the frame before's (a blend's every frame), each of
/// weight 1: a renderer's folder holds no object's size on screen, so a frame's change is shared equally.
fn changed_objects(selections: &[Vec<Selection>]) -> Vec<FrameChanges> {
    (0..selections.len())
        .map(|f| match f.checked_sub(1) {
            Some(p) => selections[f]
                .iter()
                .zip(&selections[p])
                .enumerate()
                .filter(|(_, (now, before))| now != before)
                .map(|(i, _)| (i as u32, 1.0))
                .collect(),
            None => Vec::new(),
        })
        .collect()
}

/// Per frame, the pair of levels its objects in transition (`moving`, [`in_transition`]) go between.
fn frame_pairs(moving: &[Moving]) -> Vec<TransitionPair> {
    moving
        .iter()
        .map(|m| {
            m.iter()
                .fold(TransitionPair::None, |p, &(from, to, _)| p.with(from, to))
        })
        .collect()
}

/// The objects in transition on frame `f`: (from, to, k) of each that blends, or that draws another level than
/// on the frame before (k = 1: the switch is whole).
fn in_transition(selections: &[Vec<Selection>], f: usize) -> Moving {
    selections[f]
        .iter()
        .enumerate()
        .filter_map(|(i, s)| match s.blend {
            Some((to, k)) => Some((s.lod, to, k)),
            None => f
                .checked_sub(1)
                .map(|p| selections[p][i].lod)
                .filter(|&before| before != s.lod)
                .map(|before| (before, s.lod, 1.0)),
        })
        .collect()
}

/// frames.csv's rows: the selections and the objects in transition (`moving`), the renderer's stats (or its
/// frame period where it gave none) and the figures.
fn records(
    folder: &ScoreFolder,
    (figures, moving): (&[ImageFigures], &[Moving]),
    (scene, method): (&str, &str),
) -> Vec<FrameRecord> {
    let period = 1000.0 / folder.manifest.fps;
    let objects = folder.objects.len() as u32;
    figures
        .iter()
        .enumerate()
        .map(|(f, fig)| {
            let stats = folder.stats.as_ref().map(|s| s[f]).unwrap_or_default();
            let moving = &moving[f];
            let lod_mean = folder.selections[f]
                .iter()
                .map(|s| {
                    s.blend.map_or(s.lod as f64, |(to, k)| {
                        s.lod as f64 + k * (to as f64 - s.lod as f64)
                    })
                })
                .sum::<f64>()
                / objects.max(1) as f64;
            FrameRecord {
                scene: scene.to_string(),
                method: method.to_string(),
                count: objects,
                frame: f as u32,
                gpu_ms: stats.gpu_ms,
                cpu_ms: folder.stats.as_ref().map_or(period, |_| stats.cpu_ms),
                triangles: stats.triangles,
                draw_calls: stats.draw_calls,
                units_drawn: objects as u64,
                t_instances: moving.len() as u32,
                lod_mean,
                k_mean: (!moving.is_empty())
                    .then(|| moving.iter().map(|m| m.2).sum::<f64>() / moving.len() as f64),
                rmse: fig.rmse,
                pop: fig.pop,
                lodpop: Some(fig.lodpop),
                lodpop_coverage: Some(fig.lodpop_coverage),
                lodpop_shading: Some(fig.lodpop_shading),
                de2000_mean: fig.de2000_mean,
                uncovered_px: fig.uncovered_px,
                crack_px: fig.crack_px,
                flip_mean: fig.flip_mean,
                combine_gpu_ms: None,
                lag_rmse: None,
                shadow_rmse: None,
                shadow_lodpop: None,
                view_pop: None,
                splits: None,
                merges: None,
                select_cpu_ms: None,
                round: 0,
                fragments: None,
            }
        })
        .collect()
}

/// frames/: each frame's pictures under a run's dump names (hard links, copies where the file system has none),
/// so `lodbench clips` and `perceptual` read them.
fn link_pictures(folder: &ScoreFolder, out: &Path, (scene, method): (&str, &str)) -> Result<()> {
    FrameDumper::create(out)?;
    let frames_dir = out.join(crate::results::files::FRAMES_DIR);
    for f in 0..folder.frames() {
        let id = FrameId {
            scene,
            method,
            count: folder.objects.len() as u32,
            frame: f,
        };
        let mut kinds = vec![(FRAME_DIR, DumpKind::Method)];
        if folder.counterfactual[f as usize] {
            kinds.push((COUNTERFACTUAL_DIR, DumpKind::LodpopBefore));
        }
        if folder.reference {
            kinds.push((REFERENCE_DIR, DumpKind::Reference));
        }
        for (sub, kind) in kinds {
            let (from, to) = (
                folder.picture(sub, f),
                FrameDumper::path(&frames_dir, &id, kind),
            );
            let _ = std::fs::remove_file(&to);
            if std::fs::hard_link(&from, &to).is_err() {
                std::fs::copy(&from, &to).map_err(|e| Error::io(&to, e))?;
            }
        }
    }
    Ok(())
}

/// run.json: what was scored, from where, with what; `config` holds what the answer and report.html read of a
/// run's (scenes, methods, the budget, the frame rate).
fn write_manifest(
    folder: &ScoreFolder,
    args: &ScoreArgs,
    out: &Path,
    (scene, method): (&str, &str),
) -> Result<()> {
    let version = crate::results::manifest::BuildVersion::this();
    let json = serde_json::json!({
        "command": "score",
        "status": "complete",
        "lodbench_version": version.lodbench_version,
        "git_commit": version.git_commit,
        "source_diff_hash": version.source_diff_hash,
        "source": folder.dir,
        "engine": folder.manifest,
        "objects": folder.objects,
        "frames": folder.frames(),
        "reference": folder.reference,
        "frame_stats": match folder.stats {
            Some(_) => "stats.csv",
            None => "none given: cpu_ms is score.json's frame period (1000 / fps); triangles and draw_calls are 0",
        },
        "config": {
            "scenes": [scene],
            "methods": [method],
            "metrics": args.metrics,
            "budget_lodpop": args.budget_lodpop,
            "path_fps": folder.manifest.fps,
        },
    });
    // Compact, as every run.json is (results::manifest::RunManifest::write).
    crate::results::manifest::write_compact_json_file(out, RUN_JSON, &json)
}

fn print_transitions(found: &[crate::measure::records::TransitionRecord], budget: Option<f64>) {
    for t in found {
        let over = match (budget, t.lodpop_max) {
            (Some(b), Some(v)) if v > b => " (over the budget)",
            _ => "",
        };
        outln!(
            "transition {} frames {}-{} {}: lodpop {}{over}",
            t.transition,
            t.first_frame,
            t.last_frame,
            t.lods,
            crate::numbers::sig3(t.lodpop_max)
        );
    }
}
