//! `lodbench clips RUN_DIR`: animated side-by-side clips of every transition of a run, from its frame dumps
//! (`--dump-frames --dump-transitions`). The pictures and their encoders are in `results/clips/`.
//!
//! For each transition of transitions.csv, the dumped frames of its [`ClipWindow`] (from `TRANSITION_LEAD`
//! before its first frame to `TRANSITION_TAIL` after its last) form one clip. Each frame of the clip is two grids of the same
//! layout, one tile per picture, labelled, upscaled by an integer factor (nearest neighbour):
//! - the frame grid: the reference's frame, then each method's;
//! - the error grid: a legend of the heat-map's scale in the reference's tile, then each method's error
//!   heat-map against the reference (`results::png::heatmap`, full scale [`HEATMAP_FULL_SCALE`]).
//!
//! A header above each grid names the scene, the transition, the frame and k (the mean blend factor of the
//! instances in transition, from frames.csv). Written into `RUN_DIR/clips/`:
//! - `<clip>.png`: an animated PNG of the frame grid over the error grid, looping (lossless, and about half
//!   the size of a GIF of the same frames; the `png` crate, no system dependency); with `--gif` also
//!   `<clip>.gif` (the `gif` crate, crate::raster);
//! - `<clip>.mp4`: the same, H.264, when `ffmpeg` is on the PATH (`--mp4 auto`, the default);
//! - `<clip>/frame_FFFFF.png` and `<clip>/error_FFFFF.png`: each frame's two grids, for report.html's player;
//! - with `--mp4 only`, the MP4 alone: no animated PNG and no frame images (index.json's `apng`,
//!   `frame_images` and `error_images` are null), and report.html's player steps through the MP4 (a third of
//!   the bytes or less: what a committed example folder keeps);
//! - `index.json`: the clips, their frames, k per frame and the files ([`ClipIndex`]).
//!
//! The folder is built as `clips.partial/` and renamed to `clips/` only when every clip is written, so a
//! folder named `clips/` is always complete.

use crate::cli::ClipsArgs;
use crate::error::{Error, Result};
use crate::measure::records::TransitionRecord;
use crate::methods::is_reference;
use crate::raster::RgbaImage;
use crate::results::clips::compose::{
    auto_scale, crop_box, grid, heatmap_of, legend, stack, upscale, Crop,
};
use crate::results::clips::encode::{
    ffmpeg_available, load, save, write_apng, write_gif, write_mp4,
};
use crate::results::csv::read_transitions;
use crate::results::files::{
    partial, ClipFiles, ClipWindow, DumpKind, EXPERIMENT_JSON, FRAMES_CSV, TRANSITIONS_CSV,
};
use crate::results::png::{FrameDumper, FrameId, HEATMAP_FULL_SCALE};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

pub use crate::results::files::{CLIPS_DIR, INDEX_JSON};

pub use crate::cli::Mp4;

/// The settings of `lodbench clips`.
#[derive(Debug, Clone)]
pub struct ClipSettings {
    /// The methods to show, in this order (None: every method of transitions.csv but the reference).
    pub methods: Option<Vec<String>>,
    /// Tiles per row of a grid.
    pub columns: u32,
    /// Upscaling factor; None: the smallest that makes the shown part at least
    /// [`MIN_TILE_HEIGHT`](crate::results::clips::compose::MIN_TILE_HEIGHT) pixels high (at most
    /// [`MAX_TILE_WIDTH`](crate::results::clips::compose::MAX_TILE_WIDTH) wide).
    pub scale: Option<u32>,
    /// Show the whole frame, not the box around what the clip's pictures draw.
    pub full_frame: bool,
    pub fps: u32,
    /// At most this many frames per clip, spread evenly over its dumped frames (0: all of them).
    pub max_frames: u32,
    /// Only these transitions (0-based indices along the path, transitions.csv's `transition`; None: all).
    pub transitions: Option<Vec<u32>>,
    /// Also a GIF of each clip.
    pub gif: bool,
    pub mp4: Mp4,
}

impl Default for ClipSettings {
    fn default() -> Self {
        ClipSettings {
            methods: None,
            columns: 4,
            scale: None,
            fps: 10,
            max_frames: 0,
            transitions: None,
            full_frame: false,
            gif: false,
            mp4: Mp4::Auto,
        }
    }
}

impl ClipSettings {
    /// The settings `lodbench clips` was given.
    pub fn from_args(args: &ClipsArgs) -> ClipSettings {
        ClipSettings {
            methods: args.methods.clone(),
            columns: args.columns,
            scale: args.scale,
            fps: args.fps,
            max_frames: args.max_frames,
            transitions: args.transitions.clone(),
            full_frame: args.full_frame,
            gif: args.gif,
            mp4: args.mp4,
        }
    }
}

/// `lodbench clips`: makes the clips and prints each with its frames and files.
pub fn execute(args: &ClipsArgs) -> Result<()> {
    let index = make(&args.dir, &ClipSettings::from_args(args))?;
    for c in &index.clips {
        outln!(
            "{}: {} frames ({}-{}), {}",
            c.name,
            c.frames.len(),
            c.frames.first().copied().unwrap_or_default(),
            c.frames.last().copied().unwrap_or_default(),
            [&c.apng, &c.gif, &c.mp4]
                .into_iter()
                .flatten()
                .cloned()
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    outln!(
        "{} clips in {}",
        index.clips.len(),
        args.dir.join(CLIPS_DIR).display()
    );
    Ok(())
}

/// `clips/index.json`.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ClipIndex {
    /// The run folder's name.
    pub run: String,
    pub fps: u32,
    pub heatmap_full_scale: f32,
    pub clips: Vec<ClipEntry>,
}

/// One transition's clip.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ClipEntry {
    pub name: String,
    pub scene: String,
    pub count: u32,
    pub transition: u32,
    pub lods: String,
    pub first_frame: u32,
    pub last_frame: u32,
    /// The tiles in order: "reference", then the methods.
    pub methods: Vec<String>,
    pub frames: Vec<u32>,
    /// Mean k of the instances in transition per frame (None where none is, or frames.csv lacks k_mean).
    pub k: Vec<Option<f64>>,
    pub t_instances: Vec<Option<u32>>,
    /// Paths relative to `clips/` (None with `--mp4 only`).
    pub frame_images: Option<Vec<String>>,
    pub error_images: Option<Vec<String>>,
    /// The animated PNG (lossless; every current browser plays it; None with `--mp4 only`).
    pub apng: Option<String>,
    /// With `--gif` (256 colours a frame, quantised by NeuQuant).
    pub gif: Option<String>,
    pub mp4: Option<String>,
    /// Size of each frame and error image.
    pub width: u32,
    pub height: u32,
    /// The part of the frames shown, `[x, y, width, height]` in the run's pixels.
    pub crop: [u32; 4],
    /// The nearest-neighbour upscaling factor of the shown part.
    pub scale: u32,
    /// Where each tile's picture lies in the frame and error images, `[x, y, width, height]`, in the order of
    /// `methods`.
    pub tiles: Vec<[u32; 4]>,
}

/// A frame of one scene block.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
struct FrameKey {
    scene: String,
    count: u32,
    frame: u32,
}

/// A frame's schedule facts from frames.csv: the mean k of the instances in transition and their number.
#[derive(Debug, Clone, Copy, Default)]
struct FrameFacts {
    k: Option<f64>,
    t_instances: Option<u32>,
}

/// Per frame: its facts from frames.csv (of any method: they are the schedule's, the same for every method).
type FrameFactsMap = BTreeMap<FrameKey, FrameFacts>;

fn frame_facts(dir: &Path) -> Result<FrameFactsMap> {
    let path = dir.join(FRAMES_CSV);
    let mut map = BTreeMap::new();
    if !path.is_file() {
        return Ok(map);
    }
    let mut reader = csv::Reader::from_path(&path)?;
    let headers = reader.headers()?.clone();
    let at = |name: &str| headers.iter().position(|h| h == name);
    let (Some(scene), Some(count), Some(frame)) = (at("scene"), at("count"), at("frame")) else {
        return Err(Error::results(
            dir,
            "frames.csv has no scene, count and frame columns",
        ));
    };
    let (k, t) = (at("k_mean"), at("t_instances"));
    for rec in reader.records() {
        let rec = rec?;
        let parse_u32 = |i: usize| rec.get(i).and_then(|v| v.parse::<u32>().ok());
        let (Some(c), Some(f)) = (parse_u32(count), parse_u32(frame)) else {
            return Err(Error::results(
                dir,
                format!("frames.csv: a row without a count or frame: {rec:?}"),
            ));
        };
        let key = FrameKey {
            scene: rec.get(scene).unwrap_or_default().to_string(),
            count: c,
            frame: f,
        };
        map.entry(key).or_insert(FrameFacts {
            k: k.and_then(|i| rec.get(i))
                .and_then(|v| v.parse::<f64>().ok()),
            t_instances: t.and_then(parse_u32),
        });
    }
    Ok(map)
}

/// Makes every clip of `dir` and returns the index written to `dir/clips/index.json`.
pub fn make(dir: &Path, settings: &ClipSettings) -> Result<ClipIndex> {
    check_run_folder(dir)?;
    let rows = read_transitions(dir)?;
    let frames_dir = FrameDumper::dumps_of(dir)?;
    if settings.columns == 0 || settings.fps == 0 || settings.scale == Some(0) {
        return Err(Error::Config(
            "clips: --columns, --fps and --scale must be at least 1".into(),
        ));
    }
    let methods = shown_methods(dir, &rows, settings)?;
    let paths = transitions_shown(dir, &rows, settings)?;
    let job = ClipJob {
        dir,
        frames_dir,
        rows: &rows,
        methods,
        facts: frame_facts(dir)?,
        settings,
        ffmpeg: ffmpeg_wanted(settings.mp4)?,
        partial: dir.join(partial(CLIPS_DIR)),
    };
    let out = dir.join(CLIPS_DIR);
    if job.partial.exists() {
        std::fs::remove_dir_all(&job.partial).map_err(|e| Error::io(&job.partial, e))?;
    }
    std::fs::create_dir_all(&job.partial).map_err(|e| Error::io(&job.partial, e))?;
    let mut index = ClipIndex {
        run: dir
            .canonicalize()
            .ok()
            .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
            .unwrap_or_default(),
        fps: settings.fps,
        heatmap_full_scale: HEATMAP_FULL_SCALE,
        clips: Vec::new(),
    };
    let result = paths.into_iter().try_for_each(|t| {
        index.clips.extend(job.clip(t)?);
        Ok(())
    });
    if let Err(e) = result {
        // No half-written folder stays behind.
        let _ = std::fs::remove_dir_all(&job.partial);
        return Err(e);
    }
    if index.clips.is_empty() {
        let _ = std::fs::remove_dir_all(&job.partial);
        return Err(Error::results(
            dir,
            "no scene of the run has a method shown and a transition",
        ));
    }
    let index_path = job.partial.join(INDEX_JSON);
    let json = serde_json::to_string_pretty(&index)?;
    std::fs::write(&index_path, json).map_err(|e| Error::io(&index_path, e))?;
    if out.exists() {
        std::fs::remove_dir_all(&out).map_err(|e| Error::io(&out, e))?;
    }
    std::fs::rename(&job.partial, &out).map_err(|e| Error::io(&out, e))?;
    Ok(index)
}

/// `dir` is a run folder (not an experiment's).
fn check_run_folder(dir: &Path) -> Result<()> {
    if !dir.is_dir() {
        return Err(Error::results(dir, "is not a folder"));
    }
    if dir.join(EXPERIMENT_JSON).is_file() && !dir.join(TRANSITIONS_CSV).is_file() {
        return Err(Error::results(
            dir,
            "is an experiment's folder: give one of its run folders",
        ));
    }
    Ok(())
}

/// The methods the clips show, in order: `--methods`, each a method of the run, or every method of
/// transitions.csv but the reference.
fn shown_methods(
    dir: &Path,
    rows: &[TransitionRecord],
    settings: &ClipSettings,
) -> Result<Vec<String>> {
    let mut run_methods: Vec<String> = Vec::new();
    for r in rows {
        if !is_reference(&r.method) && !run_methods.contains(&r.method) {
            run_methods.push(r.method.clone());
        }
    }
    let methods = match &settings.methods {
        None => run_methods,
        Some(list) => {
            if let Some(m) = list.iter().find(|m| !run_methods.contains(m)) {
                return Err(Error::results(
                    dir,
                    format!(
                        "--methods {m}: not a method of this run (its methods: {})",
                        run_methods.join(", ")
                    ),
                ));
            }
            list.clone()
        }
    };
    if methods.is_empty() {
        return Err(Error::results(
            dir,
            "has no method but the reference to show",
        ));
    }
    Ok(methods)
}

/// One transition of the path per (scene, count, index) (the rows of every method share its frames), only
/// those of `--transitions` when given.
fn transitions_shown<'r>(
    dir: &Path,
    rows: &'r [TransitionRecord],
    settings: &ClipSettings,
) -> Result<Vec<&'r TransitionRecord>> {
    let mut paths: Vec<&TransitionRecord> = Vec::new();
    for r in rows {
        if !paths
            .iter()
            .any(|p| p.scene == r.scene && p.count == r.count && p.transition == r.transition)
        {
            paths.push(r);
        }
    }
    if paths.is_empty() {
        return Err(Error::results(
            dir,
            "transitions.csv has no transition: nothing to show",
        ));
    }
    if let Some(wanted) = &settings.transitions {
        let last = paths.iter().map(|p| p.transition).max().unwrap_or_default();
        if let Some(bad) = wanted.iter().find(|&&t| t > last) {
            return Err(Error::results(
                dir,
                format!("--transitions {bad}: the run's transitions are 0 to {last}"),
            ));
        }
        paths.retain(|p| wanted.contains(&p.transition));
    }
    Ok(paths)
}

/// Whether to write MP4s: `--mp4 auto` when ffmpeg is there; `--mp4 on` without it is an error.
fn ffmpeg_wanted(mp4: Mp4) -> Result<bool> {
    match mp4 {
        Mp4::Off => Ok(false),
        Mp4::Auto => Ok(ffmpeg_available()),
        Mp4::On | Mp4::Only if ffmpeg_available() => Ok(true),
        Mp4::On | Mp4::Only => Err(Error::Config(format!(
            "clips --mp4 {}: ffmpeg is not on the PATH (Debian: apt install ffmpeg)",
            if mp4 == Mp4::On { "on" } else { "only" }
        ))),
    }
}

/// What every clip of a run is made from, and where it goes.
struct ClipJob<'a> {
    dir: &'a Path,
    frames_dir: PathBuf,
    rows: &'a [TransitionRecord],
    /// The methods shown, in order.
    methods: Vec<String>,
    facts: FrameFactsMap,
    settings: &'a ClipSettings,
    ffmpeg: bool,
    /// `clips.partial/`, renamed to `clips/` when every clip is written.
    partial: PathBuf,
}

/// One frame's pictures (the reference's, then each method's) and each method's error heat-map.
struct FramePictures {
    pictures: Vec<RgbaImage>,
    errors: Vec<RgbaImage>,
}

/// The part of the frames a clip shows, and its upscaling.
#[derive(Clone, Copy)]
struct View {
    crop: Crop,
    scale: u32,
}

impl View {
    fn of(&self, img: &RgbaImage) -> RgbaImage {
        let c = self.crop;
        upscale(&img.crop(c.x, c.y, c.w, c.h), self.scale)
    }
}

impl ClipJob<'_> {
    fn dump(&self, t: &TransitionRecord, method: &str, f: u32, kind: DumpKind) -> PathBuf {
        let id = FrameId {
            scene: &t.scene,
            method,
            count: t.count,
            frame: f,
        };
        FrameDumper::path(&self.frames_dir, &id, kind)
    }

    /// The clip of transition `t`, or None when no method shown ran on its scene block.
    fn clip(&self, t: &TransitionRecord) -> Result<Option<ClipEntry>> {
        // The methods shown that ran on this scene block, in the order shown.
        let methods: Vec<String> = self
            .methods
            .iter()
            .filter(|m| {
                self.rows
                    .iter()
                    .any(|r| r.scene == t.scene && r.count == t.count && &r.method == *m)
            })
            .cloned()
            .collect();
        if methods.is_empty() {
            return Ok(None);
        }
        let frames = self.frames(t, &methods)?;
        let files = ClipFiles::new(&t.scene, t.count, t.transition);
        if self.settings.mp4 != Mp4::Only {
            let clip_dir = self.partial.join(files.folder());
            std::fs::create_dir_all(&clip_dir).map_err(|e| Error::io(&clip_dir, e))?;
        }
        let mut tiles = vec![DumpKind::Reference.name().to_string()];
        tiles.extend(methods.iter().cloned());
        let mut entry = new_entry(t, &files, tiles, frames, self.settings);
        let loaded = entry
            .frames
            .iter()
            .map(|&f| self.load_frame(t, &methods, f))
            .collect::<Result<Vec<_>>>()?;
        let view = self.view(t, &loaded)?;
        entry.crop = [view.crop.x, view.crop.y, view.crop.w, view.crop.h];
        entry.scale = view.scale;
        let movie = self.write_frames(t, &files, &mut entry, &loaded, view)?;
        self.write_animations(&files, &mut entry, &movie)?;
        Ok(Some(entry))
    }

    /// The frames of `t`'s [`ClipWindow`] dumped for every method shown, at most `--max-frames` of them.
    fn frames(&self, t: &TransitionRecord, methods: &[String]) -> Result<Vec<u32>> {
        let frames: Vec<u32> = ClipWindow::of(t)
            .frames()
            .filter(|&f| {
                methods
                    .iter()
                    .all(|m| self.dump(t, m, f, DumpKind::Method).is_file())
            })
            .collect();
        if frames.is_empty() {
            return Err(Error::results(
                self.dir,
                format!(
                    "frames/ has no dumps of {} {} around transition {} (frames {}-{}) for every method shown: \
                     run with --dump-frames --dump-transitions",
                    t.scene,
                    methods.join(","),
                    t.transition,
                    t.first_frame,
                    t.last_frame
                ),
            ));
        }
        Ok(spread(&frames, self.settings.max_frames))
    }

    /// Frame `f`'s pictures and heat-maps (made from the pictures where the run dumped none), all one size.
    fn load_frame(
        &self,
        t: &TransitionRecord,
        methods: &[String],
        f: u32,
    ) -> Result<FramePictures> {
        let mut pictures = vec![load(&self.dump(t, &methods[0], f, DumpKind::Reference))?];
        let mut errors = Vec::new();
        for m in methods {
            let picture = load(&self.dump(t, m, f, DumpKind::Method))?;
            let err_path = self.dump(t, m, f, DumpKind::Error);
            let error = if err_path.is_file() {
                load(&err_path)?
            } else {
                heatmap_of(&picture, &pictures[0])
            };
            pictures.push(picture);
            errors.push(error);
        }
        let size = pictures[0].dimensions();
        if pictures
            .iter()
            .chain(&errors)
            .any(|p| p.dimensions() != size)
        {
            return Err(Error::results(
                self.dir,
                format!("the dumps of frame {f} of {} differ in size", t.scene),
            ));
        }
        Ok(FramePictures { pictures, errors })
    }

    /// The part of the frames shown (the box around what any picture of the clip draws, or the whole frame
    /// with `--full-frame`) and its upscaling.
    fn view(&self, t: &TransitionRecord, loaded: &[FramePictures]) -> Result<View> {
        let (w, h) = loaded[0].pictures[0].dimensions();
        if loaded.iter().any(|l| l.pictures[0].dimensions() != (w, h)) {
            return Err(Error::results(
                self.dir,
                format!("the dumps of {} differ in size between frames", t.scene),
            ));
        }
        let crop = if self.settings.full_frame {
            Crop { x: 0, y: 0, w, h }
        } else {
            crop_box(loaded.iter().flat_map(|l| l.pictures.iter()), w, h)
        };
        let scale = self.settings.scale.unwrap_or_else(|| auto_scale(&crop, w));
        Ok(View { crop, scale })
    }

    /// Writes each frame's two grids and records them in `entry`; returns the animation's frames (the frame
    /// grid over the error grid).
    fn write_frames(
        &self,
        t: &TransitionRecord,
        files: &ClipFiles,
        entry: &mut ClipEntry,
        loaded: &[FramePictures],
        view: View,
    ) -> Result<Vec<RgbaImage>> {
        let mut movie: Vec<RgbaImage> = Vec::with_capacity(loaded.len());
        let frames = entry.frames.clone();
        for (&f, frame) in frames.iter().zip(loaded) {
            let key = FrameKey {
                scene: t.scene.clone(),
                count: t.count,
                frame: f,
            };
            let facts = self.facts.get(&key).copied().unwrap_or_default();
            let header = header(t, f, facts);
            let mut error_tiles = vec![legend(view.crop.w * view.scale, view.crop.h * view.scale)];
            error_tiles.extend(frame.errors.iter().map(|e| view.of(e)));
            let frame_grid = grid(
                &format!("{header}  [frame]"),
                &entry.methods,
                &frame
                    .pictures
                    .iter()
                    .map(|p| view.of(p))
                    .collect::<Vec<_>>(),
                self.settings.columns,
            );
            // The same layout: the two headers are as long.
            let error_grid = grid(
                &format!("{header}  [error]"),
                &entry.methods,
                &error_tiles,
                self.settings.columns,
            );
            if let (Some(frame_images), Some(error_images)) =
                (&mut entry.frame_images, &mut entry.error_images)
            {
                let frame_file = files.frame_image(f);
                let error_file = files.error_image(f);
                save(&self.partial.join(&frame_file), &frame_grid.image)?;
                save(&self.partial.join(&error_file), &error_grid.image)?;
                frame_images.push(frame_file);
                error_images.push(error_file);
            }
            entry.width = frame_grid.image.width();
            entry.height = frame_grid.image.height();
            entry.tiles = frame_grid.boxes;
            entry.k.push(facts.k);
            entry.t_instances.push(facts.t_instances);
            movie.push(stack(&frame_grid.image, &error_grid.image));
        }
        Ok(movie)
    }

    /// The animated PNG, and the GIF and the MP4 where asked for.
    fn write_animations(
        &self,
        files: &ClipFiles,
        entry: &mut ClipEntry,
        movie: &[RgbaImage],
    ) -> Result<()> {
        let fps = self.settings.fps;
        if let Some(apng) = &entry.apng {
            write_apng(&self.partial.join(apng), movie, fps)?;
        }
        if let Some(gif) = &entry.gif {
            write_gif(&self.partial.join(gif), movie, fps)?;
        }
        if self.ffmpeg {
            let mp4 = files.animation("mp4");
            write_mp4(&self.partial.join(&mp4), movie, fps)?;
            entry.mp4 = Some(mp4);
        }
        Ok(())
    }
}

/// The entry of `t`'s clip before its frames are drawn.
fn new_entry(
    t: &TransitionRecord,
    files: &ClipFiles,
    tiles: Vec<String>,
    frames: Vec<u32>,
    settings: &ClipSettings,
) -> ClipEntry {
    let lossless = settings.mp4 != Mp4::Only;
    ClipEntry {
        name: files.name.clone(),
        scene: t.scene.clone(),
        count: t.count,
        transition: t.transition,
        lods: t.lods.clone(),
        first_frame: t.first_frame,
        last_frame: t.last_frame,
        methods: tiles,
        frames,
        k: Vec::new(),
        t_instances: Vec::new(),
        frame_images: lossless.then(Vec::new),
        error_images: lossless.then(Vec::new),
        apng: lossless.then(|| files.animation("png")),
        gif: settings.gif.then(|| files.animation("gif")),
        mp4: None,
        width: 0,
        height: 0,
        crop: [0, 0, 0, 0],
        scale: 1,
        tiles: Vec::new(),
    }
}

/// The line above frame `f`'s grids: the scene, the transition, the frame, k and the instances in transition.
fn header(t: &TransitionRecord, f: u32, facts: FrameFacts) -> String {
    format!(
        "{} c{}  transition {} ({})  frame {f}  k {}  in transition {}",
        t.scene,
        t.count,
        t.transition,
        t.lods,
        facts.k.map_or("-".to_string(), |k| format!("{k:.3}")),
        facts.t_instances.map_or("-".to_string(), |n| n.to_string()),
    )
}

/// At most `max` of `frames` (0: all), evenly spread, the first and the last always among them.
pub fn spread(frames: &[u32], max: u32) -> Vec<u32> {
    let n = frames.len();
    let max = max as usize;
    if max == 0 || n <= max {
        return frames.to_vec();
    }
    if max == 1 {
        return vec![frames[0]];
    }
    (0..max)
        .map(|i| frames[(i * (n - 1) + (max - 1) / 2) / (max - 1)])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spread_keeps_ends_and_count() {
        let frames: Vec<u32> = (10..30).collect();
        assert_eq!(spread(&frames, 0), frames);
        assert_eq!(spread(&frames, 50), frames);
        let s = spread(&frames, 5);
        assert_eq!(s.len(), 5);
        assert_eq!(s[0], 10);
        assert_eq!(s[4], 29);
        assert!(s.windows(2).all(|w| w[0] < w[1]), "{s:?}");
        assert_eq!(spread(&frames, 1), vec![10]);
    }
}
