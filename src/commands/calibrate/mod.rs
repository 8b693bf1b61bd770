//! `lodbench calibrate --scene NAME|FILE,... --out DIR`: the experiment that measures when a person sees an LOD
//! switch. For each scene's model and each LOD pair, a ladder of switch distances (multiples of the distance
//! where the pair's error projects to one pixel of the display); at each, a short dolly away from the model that
//! crosses the switch, drawn by each method, and the same dolly without the switch. The page (index.html) shows
//! the two in random order, one frame per refresh, and asks which one popped; a weighted up-down staircase per
//! scene and method picks the next step. `scripts/calibration.py fit` fits the responses (calibration.json).
//! docs/calibration.md says how a lab runs it.

mod asset;
mod page;
mod stimulus;

use crate::cli::calibration::Display;
use crate::cli::CalibrateArgs;
use crate::error::{Error, Result};
use crate::results::files::{CALIBRATE_PAGE, STIMULI_FRAMES_DIR, STIMULI_JSON};
use crate::results::manifest::BuildVersion;
use asset::{asset_of, Asset};
use colorvideovdp::{Cvvdp, DisplayModel, Geometry};
use page::{Procedure, Stimuli, StimulusRecord, StimulusWindow, Track};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use stimulus::{Drawing, Step};

pub use page::{hash64, PAGE, PLACEHOLDER};

/// `lodbench calibrate`: renders the ladder, writes the page beside its stimuli and says how to run it.
pub fn execute(args: &CalibrateArgs) -> Result<()> {
    let drawing = drawing_of(args)?;
    check_scales(&args.scales)?;
    if args.trials_per_track == 0 {
        return Err(Error::Config(
            "--trials-per-track 0: a staircase needs at least one trial".into(),
        ));
    }
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| super::run::default_out_dir(&["calibrate"]));
    super::run::prepare_output(&out)?;
    // Nothing of an earlier calibration in DIR survives to look like this one's.
    for stale in [CALIBRATE_PAGE, STIMULI_JSON] {
        let p = out.join(stale);
        if p.exists() {
            std::fs::remove_file(&p).map_err(|e| Error::io(&p, e))?;
        }
    }
    let work = out.join(".work");
    for dir in [out.join(STIMULI_FRAMES_DIR), work.clone()] {
        if dir.exists() {
            std::fs::remove_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
        }
        std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
    }
    let jod = jod_metric(&drawing.display)?;
    let mut records = Vec::new();
    let mut kept = BTreeMap::new();
    let rendered = args.scene.iter().try_for_each(|name| -> Result<()> {
        let asset = asset_of(name, &work)?;
        records.extend(ladder(
            &asset, args, &drawing, &jod, &work, &out, &mut kept,
        )?);
        Ok(())
    });
    let _ = std::fs::remove_dir_all(&work);
    rendered?;
    let stimuli = stimuli_of(args, &drawing, records)?;
    page::write(&out, &stimuli)?;
    print_ladder(&stimuli);
    outln!(
        "{} stimuli, {} frames; open {} in a browser on a {} display",
        stimuli.stimuli.len(),
        kept.len(),
        out.join(CALIBRATE_PAGE).display(),
        drawing.display.describe()
    );
    Ok(())
}

/// The display and how the stimuli are drawn on it, each flag checked.
fn drawing_of(args: &CalibrateArgs) -> Result<Drawing> {
    let a = &args.display;
    let display = Display::new(
        (a.display_width, a.display_height),
        a.refresh_hz,
        a.diagonal_in,
        a.viewing_distance_cm,
        a.peak_luminance,
    )?;
    if args.stimulus_size < 16 || args.stimulus_size > a.display_width.min(a.display_height) {
        return Err(Error::Config(format!(
            "--stimulus-size {}: the window is at least 16 pixels and fits the {}x{} display",
            args.stimulus_size, a.display_width, a.display_height
        )));
    }
    let frames_of = |ms: f64| (ms * a.refresh_hz / 1000.0).round();
    let (frames, fade) = (frames_of(args.interval_ms), frames_of(args.fade_ms));
    if !(8.0..=600.0).contains(&frames) {
        return Err(Error::Config(format!(
            "--interval-ms {}: {frames} frames at {} Hz; an interval is 8 to 600 frames",
            args.interval_ms, a.refresh_hz
        )));
    }
    if !(fade >= 1.0 && fade <= frames * 0.5) {
        return Err(Error::Config(format!(
            "--fade-ms {}: {fade} frames; a fade is at least a frame and fits in half the interval ({frames} frames)",
            args.fade_ms
        )));
    }
    if !(args.fov.is_finite() && args.fov > 1.0 && args.fov < 170.0) {
        return Err(Error::Config(format!(
            "--fov {}: a field of view is between 1 and 170 degrees",
            args.fov
        )));
    }
    Ok(Drawing {
        display,
        size: args.stimulus_size,
        fov_y: args.fov.to_radians(),
        frames: frames as u32,
        fade_frames: fade as u32,
        methods: args.method.clone(),
        adapter: args.adapter.clone(),
    })
}

fn check_scales(scales: &[f32]) -> Result<()> {
    if let Some(s) = scales
        .iter()
        .enumerate()
        .find_map(|(i, s)| scales[..i].contains(s).then_some(s))
    {
        return Err(Error::Config(format!(
            "--scales: {s} is given twice: each step of the ladder is one stimulus"
        )));
    }
    match scales
        .iter()
        .find(|s| !(s.is_finite() && **s > 0.0 && **s <= 100.0))
    {
        Some(s) => Err(Error::Config(format!(
            "--scales: {s} is not a distance multiple in (0, 100]"
        ))),
        None if scales.is_empty() => Err(Error::Config("--scales: at least one step".into())),
        None => Ok(()),
    }
}

/// ColorVideoVDP on the calibration's display: standard_fhd's photometry at the display's peak luminance, the
/// display's size, resolution and distance.
fn jod_metric(d: &Display) -> Result<Cvvdp> {
    let perceptual = |e: colorvideovdp::Error| Error::Perceptual(e.to_string());
    let mut model = DisplayModel::from_name("standard_fhd").map_err(perceptual)?;
    model.name = "lodbench calibrate".into();
    model.photometry.peak_luminance = d.peak_luminance_cd_m2;
    model.geometry = Geometry::from_diagonal(
        [d.width_px as usize, d.height_px as usize],
        d.diagonal_in,
        d.viewing_distance_cm / 100.0,
    )
    .map_err(perceptual)?;
    super::perceptual::metric_of(model)
}

/// Every step of `asset`'s ladder, rendered and measured: each LOD pair (up to --pairs) at each scale.
fn ladder(
    asset: &Asset,
    args: &CalibrateArgs,
    drawing: &Drawing,
    jod: &Cvvdp,
    work: &Path,
    out: &Path,
    kept: &mut BTreeMap<u64, String>,
) -> Result<Vec<StimulusRecord>> {
    let lods = asset.errors.len() as u32;
    let pairs = match args.pairs {
        0 => lods - 1,
        n => n.min(lods - 1),
    };
    let mut records = Vec::new();
    for from in 0..pairs {
        let one_pixel = drawing.one_pixel_distance(asset, from as usize + 1);
        if !(one_pixel.is_finite() && one_pixel > 0.0) {
            return Err(Error::Config(format!(
                "calibrate: {}'s LOD{} has no simplification error to place its switch by; its chain's \
                 levels may be identical",
                asset.name,
                from + 1
            )));
        }
        for (k, &scale) in args.scales.iter().enumerate() {
            let step = Step {
                from,
                distance: one_pixel * scale,
            };
            eprintln!(
                "calibrate: {} LOD{from}->{} at {scale} x {one_pixel:.3} (pair {}/{pairs}, step {}/{})",
                asset.name,
                from + 1,
                from + 1,
                k + 1,
                args.scales.len()
            );
            for r in stimulus::render(asset, step, drawing, jod, work)? {
                let (switch_frames, still_frames) = page::keep_frames(out, &r, kept)?;
                records.push(StimulusRecord {
                    id: format!("{}/{}/{}->{}@{scale}", asset.name, r.method, from, from + 1),
                    track: format!("{}/{}", asset.name, r.method),
                    asset: asset.name.clone(),
                    method: r.method.clone(),
                    lods: format!("{}->{}", from, from + 1),
                    switch_distance: step.distance,
                    scale,
                    switch_frame: r.switch_frame,
                    switch_frames,
                    still_frames,
                    lodpop: r.lodpop,
                    lodpop_coverage: r.lodpop_coverage,
                    lodpop_shading: r.lodpop_shading,
                    flip: r.flip,
                    jod_popping: r.jod_popping,
                });
            }
        }
    }
    Ok(records)
}

/// stimuli.json: the stimuli, one track per scene and method (its stimuli by ascending lodpop), the procedure,
/// and an id (the hash of the rest) the page keys its saved session by.
fn stimuli_of(
    args: &CalibrateArgs,
    drawing: &Drawing,
    records: Vec<StimulusRecord>,
) -> Result<Stimuli> {
    let mut tracks: Vec<Track> = Vec::new();
    for r in &records {
        if !tracks.iter().any(|t| t.id == r.track) {
            let mut mine: Vec<&StimulusRecord> =
                records.iter().filter(|o| o.track == r.track).collect();
            mine.sort_by(|a, b| a.lodpop.total_cmp(&b.lodpop));
            tracks.push(Track {
                id: r.track.clone(),
                asset: r.asset.clone(),
                method: r.method.clone(),
                stimuli: mine.iter().map(|o| o.id.clone()).collect(),
            });
        }
    }
    let mut stimuli = Stimuli {
        format: "lodbench-calibration-stimuli",
        version: 1,
        id: String::new(),
        command: command_line(),
        build: BuildVersion::this(),
        display: drawing.display.clone(),
        stimulus: StimulusWindow {
            width_px: drawing.size,
            height_px: drawing.size,
            frames_per_interval: drawing.frames,
            gap_ms: 500.0,
            fov_y_deg: drawing.window_fov().to_degrees(),
            fade_frames: drawing.fade_frames,
        },
        procedure: Procedure {
            kind: "weighted-up-down",
            target: 0.75,
            down_steps: 1,
            up_steps: 3,
            trials_per_track: args.trials_per_track,
            seed: args.seed,
        },
        ladder_metric: page::METRICS[0],
        metrics: page::METRICS,
        tracks,
        stimuli: records,
    };
    stimuli.id = format!(
        "{:016x}",
        hash64(serde_json::to_string(&stimuli)?.as_bytes())
    );
    Ok(stimuli)
}

/// This process's command line, for stimuli.json.
fn command_line() -> String {
    let argv: Vec<String> = std::env::args().collect();
    let exe = PathBuf::from(argv.first().cloned().unwrap_or_default());
    let name = exe
        .file_name()
        .map_or("lodbench".into(), |n| n.to_string_lossy().to_string());
    std::iter::once(name)
        .chain(argv.into_iter().skip(1))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Per track: its steps and the range of lodpop and JOD they cover.
fn print_ladder(s: &Stimuli) {
    outln!(
        "{:<40} {:>5} {:>21} {:>15}",
        "track",
        "steps",
        "lodpop (display)",
        "jod_popping"
    );
    for t in &s.tracks {
        let mine: Vec<&StimulusRecord> = s.stimuli.iter().filter(|r| r.track == t.id).collect();
        let range = |f: fn(&StimulusRecord) -> f64| {
            let v: Vec<f64> = mine.iter().map(|r| f(r)).collect();
            (
                v.iter().cloned().fold(f64::INFINITY, f64::min),
                v.iter().cloned().fold(f64::NEG_INFINITY, f64::max),
            )
        };
        let (p0, p1) = range(|r| r.lodpop);
        let (j0, j1) = range(|r| r.jod_popping);
        outln!(
            "{:<40} {:>5} {:>10.5}-{:<10.5} {:>7.3}-{:<7.3}",
            t.id,
            mine.len(),
            p0,
            p1,
            j0,
            j1
        );
    }
}
