//! One step of a calibration's ladder: an asset's LOD pair switched at one distance while the camera dollies away,
//! drawn by each method (`lodbench run` with a camera path, its frames dumped), and the same frames without the
//! switch; each method's pop measured on them (lodpop and its parts from the run, FLIP over the switch's frame
//! pair, ColorVideoVDP's JOD of the two intervals).

use super::asset::Asset;
use crate::cli::calibration::Display;
use crate::cli::run_config::RunConfig;
use crate::cli::{Cli, Command};
use crate::error::{Error, Result};
use crate::measure::records::TransitionRecord;
use crate::results::csv::read_transitions;
use crate::results::files::{DumpKind, FRAMES_DIR};
use crate::results::png::{FrameDumper, FrameId};
use crate::scene::camera_path::CameraPath;
use colorvideovdp::{Color, Cvvdp, Image};
use std::path::{Path, PathBuf};

/// How every stimulus is drawn: the stimulus window and its projection, the interval, the fade.
#[derive(Debug, Clone)]
pub struct Drawing {
    pub display: Display,
    /// The stimulus window's side in pixels.
    pub size: u32,
    /// The display's full-frame vertical field of view (radians); the window's is its part of it.
    pub fov_y: f32,
    pub frames: u32,
    pub fade_frames: u32,
    pub methods: Vec<String>,
    pub adapter: Option<String>,
}

/// The dolly's length as a fraction of the switch distance; the switch is crossed [`CROSSING`] of the way in.
const DOLLY: f32 = 0.08;
const CROSSING: f32 = 0.4;

impl Drawing {
    /// The window's vertical field of view: the display's projection cropped to `size` rows.
    pub fn window_fov(&self) -> f32 {
        let t = (self.fov_y / 2.0).tan() * self.size as f32 / self.display.height_px as f32;
        2.0 * t.atan()
    }

    /// The distance where LOD `lod`'s error projects to one pixel of the display.
    pub fn one_pixel_distance(&self, asset: &Asset, lod: usize) -> f32 {
        crate::geometry::projection::switch_distance(
            asset.errors[lod],
            1.0,
            1.0,
            self.display.height_px,
            self.fov_y,
        )
    }
}

/// One step's place on the ladder: LOD `from` -> `from + 1`, switched at `distance`.
#[derive(Debug, Clone, Copy)]
pub struct Step {
    pub from: u32,
    pub distance: f32,
}

/// One method's stimulus of one step: its frames (PNG files, in order) and its pop's figures.
#[derive(Debug, Clone)]
pub struct Rendered {
    pub method: String,
    pub switch_frames: Vec<PathBuf>,
    pub still_frames: Vec<PathBuf>,
    pub switch_frame: u32,
    pub lodpop: f64,
    pub lodpop_coverage: f64,
    pub lodpop_shading: f64,
    pub flip: f64,
    pub jod_popping: f64,
}

/// The switch distances of a step: LODs up to `from` switched before the dolly starts, `from + 1` at the step's
/// distance (or, without the switch, far beyond the dolly's end), the rest far beyond.
fn switch_distances(asset: &Asset, step: Step, switch: bool) -> String {
    let d = step.distance;
    let far = d * 1000.0;
    (1..asset.errors.len() as u32)
        .map(|lod| match lod {
            l if l <= step.from => d * 0.5 * l as f32 / (step.from + 1) as f32,
            l if l == step.from + 1 && switch => d,
            l => far * (l - step.from) as f32,
        })
        .map(|x| format!("{x}"))
        .collect::<Vec<_>>()
        .join(",")
}

/// The dolly of a step: the eye from `(1 - CROSSING DOLLY) d` to `(1 + (1 - CROSSING) DOLLY) d` away from the
/// model along its line, the model's centre looked at.
fn dolly(asset: &Asset, step: Step, frames: u32) -> Result<CameraPath> {
    let d = step.distance;
    let (c, v) = (asset.centre, asset.direction);
    let eye = |s: f32| c + v * d * s;
    let (a, b) = (
        eye(1.0 - CROSSING * DOLLY),
        eye(1.0 + (1.0 - CROSSING) * DOLLY),
    );
    let key =
        |f: u32, e: glam::Vec3| format!("{f},{},{},{},{},{},{}\n", e.x, e.y, e.z, c.x, c.y, c.z);
    let text = format!(
        "frame,x,y,z,target_x,target_y,target_z\n{}{}",
        key(0, a),
        key(frames - 1, b)
    );
    CameraPath::parse("calibrate dolly", &text)
}

/// The run of a step into `out`: the drawing's methods with the switch, or discrete without it.
fn run_step(asset: &Asset, step: Step, drawing: &Drawing, switch: bool, out: &Path) -> Result<()> {
    let methods = match switch {
        true => drawing.methods.join(","),
        false => "discrete".to_string(),
    };
    let file = asset.file.to_string_lossy().to_string();
    let (size, frames) = (drawing.size.to_string(), drawing.frames.to_string());
    let fov = drawing.window_fov().to_degrees().to_string();
    let (distances, fade) = (
        switch_distances(asset, step, switch),
        drawing.fade_frames.to_string(),
    );
    let out_text = out.to_string_lossy().to_string();
    let mut argv = vec![
        "lodbench",
        "run",
        "--scene",
        &file,
        "--method",
        &methods,
        "--width",
        &size,
        "--height",
        &size,
        "--fov",
        &fov,
        "--frames",
        &frames,
        "--switch-distances",
        &distances,
        "--fade",
        "time",
        "--fade-frames",
        &fade,
        "--animation",
        "none",
        "--warmup",
        "0",
        "--rounds",
        "1",
        "--ceilings",
        "off",
        "--dump-frames",
        "--out",
        &out_text,
    ];
    if let Some(a) = &drawing.adapter {
        argv.extend(["--adapter", a]);
    }
    let args = match Cli::try_parse_checked_from(argv) {
        Ok(Cli {
            command: Command::Run(args),
        }) => args,
        Ok(_) => {
            return Err(Error::Config(
                "calibrate: a run's flags parsed as another command".into(),
            ))
        }
        Err(e) => {
            return Err(Error::Config(format!(
                "calibrate: a stimulus run's flags: {e}"
            )))
        }
    };
    let mut cfg = RunConfig::from_args(&args)?;
    cfg.scene.camera_path = Some(dolly(asset, step, drawing.frames)?);
    cfg.quiet = true;
    crate::commands::run::run(&cfg).map(|_| ())
}

/// Renders `step` of `asset` in `work` (emptied first) and measures each method's stimulus.
pub fn render(
    asset: &Asset,
    step: Step,
    drawing: &Drawing,
    jod: &Cvvdp,
    work: &Path,
) -> Result<Vec<Rendered>> {
    let (with, without) = (work.join("switch"), work.join("still"));
    for dir in [&with, &without] {
        if dir.exists() {
            std::fs::remove_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        }
    }
    run_step(asset, step, drawing, true, &with)?;
    run_step(asset, step, drawing, false, &without)?;
    let transitions = read_transitions(&with)?;
    let still_rows = read_transitions(&without)?;
    if let Some(t) = still_rows.first() {
        return Err(Error::results(
            &without,
            format!(
                "the interval without the switch has a transition (frames {} to {})",
                t.first_frame, t.last_frame
            ),
        ));
    }
    let scene = transitions
        .first()
        .map(|t| t.scene.clone())
        .unwrap_or_default();
    let frames = |dir: &Path, method: &str| -> Vec<PathBuf> {
        (0..drawing.frames)
            .map(|frame| {
                let id = FrameId {
                    scene: &scene,
                    method,
                    count: 1,
                    frame,
                };
                FrameDumper::path(&dir.join(FRAMES_DIR), &id, DumpKind::Method)
            })
            .collect()
    };
    let still_frames = frames(&without, "discrete");
    drawing
        .methods
        .iter()
        .map(|m| {
            let t = switch_of(&transitions, m, &with)?;
            measure(t, frames(&with, m), still_frames.clone(), drawing, jod)
        })
        .collect()
}

/// Method `m`'s one transition in `dir`'s transitions.csv.
fn switch_of<'a>(
    rows: &'a [TransitionRecord],
    m: &str,
    dir: &Path,
) -> Result<&'a TransitionRecord> {
    let mine: Vec<&TransitionRecord> = rows.iter().filter(|t| t.method == m).collect();
    match mine.as_slice() {
        [t] if t.lodpop_max.is_some() => Ok(t),
        _ => Err(Error::results(
            dir,
            format!(
                "{m} has {} transitions with lodpop on the dolly; a stimulus needs one",
                mine.len()
            ),
        )),
    }
}

/// Reads a dumped frame as RGBA8.
fn rgba(path: &Path) -> Result<(Vec<u8>, u32, u32)> {
    let img = crate::raster::read(path)?;
    let (w, h) = img.dimensions();
    Ok((img.into_raw(), w, h))
}

/// The figures of one method's stimulus. lodpop and FLIP are means over the frame: the window's are scaled to
/// the display's whole frame (the rest of it unchanged), the figure `run` and `tune` measure at the display's
/// size; JOD is the window's, as it is shown.
fn measure(
    t: &TransitionRecord,
    switch_frames: Vec<PathBuf>,
    still_frames: Vec<PathBuf>,
    drawing: &Drawing,
    jod: &Cvvdp,
) -> Result<Rendered> {
    let d = &drawing.display;
    let area = (drawing.size as f64).powi(2) / (d.width_px as f64 * d.height_px as f64);
    let at = t.lodpop_max_frame.unwrap_or(t.first_frame) as usize;
    let (a, w, h) = rgba(&switch_frames[at])?;
    let (b, _, _) = rgba(&still_frames[at])?;
    let rgb = |px: &[u8]| {
        px.chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect::<Vec<u8>>()
    };
    let error = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(w, h, &rgb(&b)),
        nv_flip::FlipImageRgb8::with_data(w, h, &rgb(&a)),
        d.pixels_per_degree as f32,
    );
    let flip = nv_flip::FlipPool::from_image(&error).mean() as f64 * area;
    let clip = |paths: &[PathBuf]| -> Result<Vec<Image>> {
        paths
            .iter()
            .map(|p| {
                let (px, w, h) = rgba(p)?;
                let data = rgb(&px).into_iter().map(|v| v as f32 / 255.0).collect();
                Image::new(w as usize, h as usize, 3, data)
                    .map_err(|e| Error::Perceptual(e.to_string()))
            })
            .collect()
    };
    let jod_popping = jod
        .predict_video(
            &clip(&switch_frames)?,
            &clip(&still_frames)?,
            d.refresh_hz as f32,
            Color::Srgb,
        )
        .map(|p| p.jod as f64)
        .map_err(|e| Error::Perceptual(e.to_string()))?;
    let scale = area.sqrt();
    Ok(Rendered {
        method: t.method.clone(),
        switch_frame: at as u32,
        lodpop: t.lodpop_max.unwrap_or(0.0) * scale,
        lodpop_coverage: t.lodpop_coverage.unwrap_or(0.0) * scale,
        lodpop_shading: t.lodpop_shading.unwrap_or(0.0) * scale,
        flip,
        jod_popping,
        switch_frames,
        still_frames,
    })
}
