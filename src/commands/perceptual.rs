//! `lodbench perceptual RUN_DIR`: an independent perceptual check of the popping ranking. For each transition
//! of a run (its transitions.csv), the dumped frames around it (`--dump-frames --dump-transitions`: the
//! transition's frames, the 2 before and the 2 after) form three clips of each method: its own frames, its
//! counterfactual frames (each frame drawn at its pose with the previous frame's schedule, lodpop's `before`
//! frames), and the reference's. Two figures, each ColorVideoVDP's JOD (Mantiuk et al., SIGGRAPH 2024; 10 = no
//! visible difference, lower is worse), computed by the pure-Rust port `colorvideovdp` (validated by its
//! authors against the PyTorch reference to 3e-6 JOD):
//! - `jod_popping`: the method's clip against its own counterfactual clip: how visible the change of LOD
//!   itself is, frame by frame, with the pose and the static LOD error the same on both sides (the perceptual
//!   counterpart of lodpop);
//! - `jod_reference`: the method's clip against the reference's: how far the clip is from the high-poly one
//!   (quality), where the static LOD error of every frame dominates and a one-frame pop is diluted.
//!
//! It reads only the PNGs, not lodbench's numbers, and writes `perceptual.csv` beside them with each
//! transition's lodpop for comparison.

use crate::cli::PerceptualArgs;
use crate::error::{Error, Result};
use crate::measure::records::TransitionRecord;
use crate::methods::is_reference;
use crate::results::csv::read_transitions;
use crate::results::files::{ClipWindow, DumpKind};
use crate::results::png::{FrameDumper, FrameId};
use colorvideovdp::{Color, Cvvdp, DisplayModel, Execution, Image, Options};
use serde::Serialize;
use std::path::{Path, PathBuf};

pub use crate::results::files::PERCEPTUAL_CSV;

/// One row of perceptual.csv: one method's clip of one transition.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct PerceptualRecord {
    pub scene: String,
    pub method: String,
    pub count: u32,
    pub transition: u32,
    /// The clip: frames `clip_first..=clip_last`.
    pub clip_first: u32,
    pub clip_last: u32,
    /// ColorVideoVDP's JOD of the method's clip against its counterfactual clip (each frame with the previous
    /// frame's schedule): the popping (10 = no visible difference).
    pub jod_popping: f64,
    /// ColorVideoVDP's JOD of the method's clip against the reference's: the quality.
    pub jod_reference: f64,
    /// From transitions.csv, for comparison.
    pub lodpop_max: f64,
    pub pop_max: f64,
}

/// The settings of the check.
#[derive(Debug, Clone)]
pub struct PerceptualSettings {
    /// A display model of ColorVideoVDP (`standard_fhd`: a 24-inch 1920x1080 monitor at 60 cm, 200 cd/m2).
    pub display: String,
    /// Frames per second the clips are shown at.
    pub fps: f32,
}

/// A dumped PNG as ColorVideoVDP's input: interleaved RGB, the stored sRGB-encoded values in [0, 1].
fn load(path: &Path) -> Result<Image> {
    let img = crate::raster::read(path)?;
    let (w, h) = img.dimensions();
    let data = img
        .as_raw()
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .map(|b| b as f32 / 255.0)
        .collect();
    Image::new(w as usize, h as usize, 3, data).map_err(|e| Error::Perceptual(e.to_string()))
}

/// ColorVideoVDP's JOD of image `a` against image `b` (RGBA8, `width` x `height`, sRGB).
pub fn jod_of_images(metric: &Cvvdp, a: &[u8], b: &[u8], width: u32, height: u32) -> Result<f64> {
    let image = |px: &[u8]| -> Result<Image> {
        let data = px
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .map(|b| b as f32 / 255.0)
            .collect();
        Image::new(width as usize, height as usize, 3, data)
            .map_err(|e| Error::Perceptual(e.to_string()))
    };
    metric
        .predict_image(&image(a)?, &image(b)?, Color::Srgb)
        .map(|p| p.jod as f64)
        .map_err(|e| Error::Perceptual(e.to_string()))
}

/// `lodbench perceptual`: scores the clips, prints the table and where perceptual.csv is.
pub fn execute(args: &PerceptualArgs) -> Result<()> {
    let settings = PerceptualSettings {
        display: args.display.clone(),
        fps: args.fps,
    };
    let records = check(&args.dir, &settings)?;
    out!("{}", table(&records));
    outln!(
        "{} clips scored; {}",
        records.len(),
        args.dir.join(PERCEPTUAL_CSV).display()
    );
    Ok(())
}

/// ColorVideoVDP on the display `settings.display` names.
fn metric(settings: &PerceptualSettings) -> Result<Cvvdp> {
    metric_on(&settings.display)
}

/// ColorVideoVDP on the display model `display` names.
pub fn metric_on(display_name: &str) -> Result<Cvvdp> {
    let display = DisplayModel::from_name(display_name).map_err(|e| {
        let names = DisplayModel::names().unwrap_or_default().join(", ");
        Error::Perceptual(format!(
            "display {display_name}: {e} (the displays: {names})"
        ))
    })?;
    metric_of(display)
}

/// ColorVideoVDP on `display`, run in parallel.
pub fn metric_of(display: DisplayModel) -> Result<Cvvdp> {
    Cvvdp::new(
        display,
        Options::default().with_execution(Execution::Parallel),
    )
    .map_err(|e| Error::Perceptual(e.to_string()))
}

/// A run's transitions and its dumps, where the clips come from.
struct Clips<'a> {
    dir: &'a Path,
    frames_dir: PathBuf,
    transitions: &'a [TransitionRecord],
}

impl Clips<'_> {
    fn path(&self, t: &TransitionRecord, f: u32, kind: DumpKind) -> PathBuf {
        let id = FrameId {
            scene: &t.scene,
            method: &t.method,
            count: t.count,
            frame: f,
        };
        FrameDumper::path(&self.frames_dir, &id, kind)
    }

    /// The clip of `t`: its [`ClipWindow`], stopped at the end of the path (the last window of its block) and
    /// at the last frame dumped there.
    fn window(&self, t: &TransitionRecord) -> ClipWindow {
        let end = self
            .transitions
            .iter()
            .filter(|o| o.scene == t.scene && o.count == t.count)
            .map(|o| ClipWindow::of(o).last)
            .max()
            .unwrap_or(t.last_frame);
        let mut w = ClipWindow::of(t);
        w.last = w.last.min(end);
        // The path may end inside the tail: keep the frames that were dumped at the end.
        while w.last > t.last_frame && !self.path(t, w.last, DumpKind::Method).is_file() {
            w.last -= 1;
        }
        w
    }

    /// The method's, its counterfactual's and the reference's clip of `t`, every frame of `window` dumped. The
    /// popping test frame is lodpop's `now` frame where the method has one (FSI's frame without its lag), else
    /// the method's; the counterfactual frame is lodpop's `before` frame where the quality pass drew one, else
    /// the test frame itself (nothing changed: the two are the same frame).
    fn load(&self, t: &TransitionRecord, window: ClipWindow) -> Result<ClipSet> {
        let (first, last) = (window.first, window.last);
        let mut test = Vec::new();
        let mut reference = Vec::new();
        let mut now = Vec::new();
        let mut before = Vec::new();
        for f in window.frames() {
            let m = self.path(t, f, DumpKind::Method);
            if !m.is_file() {
                return Err(Error::results(
                    self.dir,
                    format!(
                        "{} is missing: the clip of transition {} needs every frame from {first} to {last} \
                         (run with --dump-frames --dump-transitions and --dump-every 1)",
                        m.display(),
                        t.transition
                    ),
                ));
            }
            let shown = load(&m)?;
            let unlagged = self.path(t, f, DumpKind::LodpopNow);
            let popping_test = match unlagged.is_file() {
                true => load(&unlagged)?,
                false => shown.clone(),
            };
            let counterfactual = self.path(t, f, DumpKind::LodpopBefore);
            before.push(match counterfactual.is_file() {
                true => load(&counterfactual)?,
                false => popping_test.clone(),
            });
            now.push(popping_test);
            test.push(shown);
            reference.push(load(&self.path(t, f, DumpKind::Reference))?);
        }
        Ok(ClipSet {
            test,
            reference,
            now,
            before,
        })
    }
}

/// The clips of one transition: the method's frames (the test) and the reference's; lodpop's two sides, the
/// frames with this frame's schedule (`now`) and with the previous frame's (`before`).
struct ClipSet {
    test: Vec<Image>,
    reference: Vec<Image>,
    now: Vec<Image>,
    before: Vec<Image>,
}

/// Scores every method's clip of every transition in `dir` and writes `dir/perceptual.csv` (and its answer.json
/// anew, whose decision table quotes the lowest JOD).
pub fn check(dir: &Path, settings: &PerceptualSettings) -> Result<Vec<PerceptualRecord>> {
    let transitions = read_transitions(dir)?;
    let clips = Clips {
        dir,
        frames_dir: FrameDumper::dumps_of(dir)?,
        transitions: &transitions,
    };
    let metric = metric(settings)?;
    let mut out = Vec::new();
    for t in transitions.iter().filter(|t| !is_reference(&t.method)) {
        let (Some(lodpop_max), Some(pop_max)) = (t.lodpop_max, t.pop_max) else {
            return Err(Error::results(
                dir,
                "transitions.csv has no lodpop and pop: a run without the quality pass (--quality off)",
            ));
        };
        let window = clips.window(t);
        let clip = clips.load(t, window)?;
        let jod = |test: &[Image], reference: &[Image]| {
            metric
                .predict_video(test, reference, settings.fps, Color::Srgb)
                .map(|p| p.jod as f64)
                .map_err(|e| Error::Perceptual(e.to_string()))
        };
        let jod_popping = jod(&clip.now, &clip.before)?;
        let jod_reference = jod(&clip.test, &clip.reference)?;
        out.push(PerceptualRecord {
            scene: t.scene.clone(),
            method: t.method.clone(),
            count: t.count,
            transition: t.transition,
            clip_first: window.first,
            clip_last: window.last,
            jod_popping,
            jod_reference,
            lodpop_max,
            pop_max,
        });
    }
    let path = dir.join(PERCEPTUAL_CSV);
    let mut w = csv::Writer::from_path(&path)?;
    for r in &out {
        w.serialize(r)?;
    }
    w.flush().map_err(|e| Error::io(&path, e))?;
    drop(w);
    // The answer's decision table quotes each method's lowest JOD.
    if dir.join(crate::results::files::SUMMARY_CSV).is_file() {
        crate::results::answer::write(dir)?;
    }
    Ok(out)
}

/// Kendall's tau-b between two scores of the same items (1: the same order, -1: reversed; ties count for
/// neither); None for fewer than two items or no untied pair.
pub fn kendall_tau(a: &[f64], b: &[f64]) -> Option<f64> {
    let n = a.len().min(b.len());
    let (mut concordant, mut discordant, mut ties_a, mut ties_b) = (0.0f64, 0.0, 0.0, 0.0);
    for i in 0..n {
        for j in i + 1..n {
            let (da, db) = (a[i] - a[j], b[i] - b[j]);
            match (da == 0.0, db == 0.0) {
                (true, true) => {}
                (true, false) => ties_a += 1.0,
                (false, true) => ties_b += 1.0,
                _ if da.signum() == db.signum() => concordant += 1.0,
                _ => discordant += 1.0,
            }
        }
    }
    let denominator = (concordant + discordant + ties_a) * (concordant + discordant + ties_b);
    (denominator > 0.0).then(|| (concordant - discordant) / denominator.sqrt())
}

/// One transition of one scene block.
#[derive(PartialEq)]
struct TransitionKey<'a> {
    scene: &'a str,
    count: u32,
    transition: u32,
}

/// The table `lodbench perceptual` prints: per transition, each method's two JODs and lodpop, and Kendall's tau
/// between the ranking by the popping JOD (higher is better) and by lodpop (lower is better).
pub fn table(records: &[PerceptualRecord]) -> String {
    let mut out = String::new();
    let mut keys: Vec<TransitionKey> = Vec::new();
    for r in records {
        let k = TransitionKey {
            scene: &r.scene,
            count: r.count,
            transition: r.transition,
        };
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    for TransitionKey {
        scene,
        count,
        transition,
    } in keys
    {
        let rows: Vec<&PerceptualRecord> = records
            .iter()
            .filter(|r| r.scene == scene && r.count == count && r.transition == transition)
            .collect();
        let jod: Vec<f64> = rows.iter().map(|r| r.jod_popping).collect();
        let lodpop: Vec<f64> = rows.iter().map(|r| -r.lodpop_max).collect();
        let tau = kendall_tau(&jod, &lodpop).map_or("-".into(), |t| format!("{t:.2}"));
        out.push_str(&format!(
            "{scene} n={count} transition {transition} (frames {}-{}): Kendall tau(JOD popping, -lodpop) = {tau}\n",
            rows[0].clip_first, rows[0].clip_last
        ));
        for r in rows {
            out.push_str(&format!(
                "  {:<16} JOD popping {:>7.4}  JOD vs reference {:>7.4}  lodpop_max {:.5}  pop_max {:.5}\n",
                r.method, r.jod_popping, r.jod_reference, r.lodpop_max, r.pop_max
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kendall_tau_of_orders() {
        assert_eq!(
            kendall_tau(&[1.0, 2.0, 3.0], &[10.0, 20.0, 30.0]),
            Some(1.0)
        );
        assert_eq!(kendall_tau(&[1.0, 2.0, 3.0], &[3.0, 2.0, 1.0]), Some(-1.0));
        let t = kendall_tau(&[1.0, 2.0, 3.0, 4.0], &[1.0, 3.0, 2.0, 4.0]).unwrap();
        assert!((t - 4.0 / 6.0).abs() < 1e-12);
        assert_eq!(kendall_tau(&[1.0], &[1.0]), None);
        assert_eq!(kendall_tau(&[1.0, 1.0], &[2.0, 2.0]), None);
    }
}
