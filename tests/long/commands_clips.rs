//! `lodbench clips`: the clips of the regression run's transitions (its dumps, `--dump-transitions`), checked
//! against the dumps they are made of, pixel for pixel; and its bad input.

use crate::common::{fails_with, lodbench, run_into};
use crate::regress_run;
use lodbench::commands::clips::{make, ClipIndex, ClipSettings, Mp4};
use lodbench::measure::records::{TransitionRecord, TRANSITION_LEAD, TRANSITION_TAIL};
use lodbench::results::png::FrameDumper;
use std::path::Path;

fn transitions(dir: &Path) -> Vec<TransitionRecord> {
    csv::Reader::from_path(dir.join("transitions.csv"))
        .unwrap()
        .deserialize()
        .collect::<Result<_, _>>()
        .unwrap()
}

fn open(path: &Path) -> lodbench::raster::RgbaImage {
    lodbench::raster::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// `image`'s picture `[x, y, w, h]` equals `source` cropped to `crop` and upscaled by `scale` (exactly: the
/// clip copies the dumps' pixels, nearest neighbour).
fn assert_tile(
    image: &lodbench::raster::RgbaImage,
    tile: [u32; 4],
    source: &lodbench::raster::RgbaImage,
    crop: [u32; 4],
    scale: u32,
    what: &str,
) {
    assert_eq!(
        [tile[2], tile[3]],
        [crop[2] * scale, crop[3] * scale],
        "{what}: tile size"
    );
    for y in 0..tile[3] {
        for x in 0..tile[2] {
            let got = image.get_pixel(tile[0] + x, tile[1] + y);
            let want = source.get_pixel(crop[0] + x / scale, crop[1] + y / scale);
            assert_eq!(got, want, "{what}: pixel ({x}, {y}) of the tile");
        }
    }
}

/// One clip per transition of the path of every scene block; each clip's frames are the dumped frames from
/// 2 before to 2 after its transition, k is in [0, 1] exactly on the frames with an instance in transition,
/// every tile of the frame and error images is its dump (cropped and upscaled), and the animated PNG has a
/// frame per clip frame.
#[test]
fn clips_are_the_dumps_side_by_side() {
    let dir = regress_run();
    // .ci/setup installs ffmpeg; where it is missing, the MP4s are not checked.
    let ffmpeg = std::process::Command::new("ffprobe")
        .arg("-version")
        .output()
        .is_ok_and(|o| o.status.success());
    let settings = ClipSettings {
        methods: Some(vec!["discrete".into(), "fsi".into()]),
        mp4: if ffmpeg { Mp4::On } else { Mp4::Off },
        ..ClipSettings::default()
    };
    let index = make(dir, &settings).unwrap();
    let rows = transitions(dir);
    let mut paths: Vec<(String, u32, u32)> = rows
        .iter()
        .filter(|r| r.method == "discrete")
        .map(|r| (r.scene.clone(), r.count, r.transition))
        .collect();
    paths.dedup();
    let clips: Vec<(String, u32, u32)> = index
        .clips
        .iter()
        .map(|c| (c.scene.clone(), c.count, c.transition))
        .collect();
    assert_eq!(
        clips, paths,
        "one clip per transition of every block that ran discrete"
    );
    let clips_dir = dir.join("clips");
    assert!(!dir.join("clips.partial").exists());
    let mut checked_fsi = false;
    for c in &index.clips {
        assert_eq!(c.methods[0], "reference");
        assert_eq!(c.methods[1], "discrete");
        let lead = c.first_frame.saturating_sub(TRANSITION_LEAD);
        assert!(
            c.frames
                .iter()
                .all(|&f| f >= lead && f <= c.last_frame + TRANSITION_TAIL),
            "{}: {:?}",
            c.name,
            c.frames
        );
        assert!(
            c.frames.contains(&c.first_frame) && c.frames.contains(&c.last_frame),
            "{}",
            c.name
        );
        for (i, &f) in c.frames.iter().enumerate() {
            let t = c.t_instances[i].unwrap();
            match c.k[i] {
                Some(k) => assert!(
                    t > 0 && (0.0..=1.0).contains(&k),
                    "{} frame {f}: k {k}, {t} in transition",
                    c.name
                ),
                None => assert_eq!(t, 0, "{} frame {f}: no k with {t} in transition", c.name),
            }
        }
        // Every tile of the transition's middle frame.
        let i = c.frames.len() / 2;
        let f = c.frames[i];
        let frame = open(&clips_dir.join(&c.frame_images.as_ref().unwrap()[i]));
        let error = open(&clips_dir.join(&c.error_images.as_ref().unwrap()[i]));
        assert_eq!((frame.width(), frame.height()), (c.width, c.height));
        assert_eq!(frame.dimensions(), error.dimensions());
        let dump = |method: &str, kind: &str| {
            open(&dir.join("frames").join(format!(
                "{}_{kind}.png",
                FrameDumper::stem(&c.scene, method, c.count, f)
            )))
        };
        assert_tile(
            &frame,
            c.tiles[0],
            &dump("discrete", "reference"),
            c.crop,
            c.scale,
            "reference",
        );
        for (m, tile) in c.methods.iter().zip(&c.tiles).skip(1) {
            assert_tile(
                &frame,
                *tile,
                &dump(m, "method"),
                c.crop,
                c.scale,
                &format!("{} {m} frame", c.name),
            );
            assert_tile(
                &error,
                *tile,
                &dump(m, "error"),
                c.crop,
                c.scale,
                &format!("{} {m} error", c.name),
            );
            checked_fsi |= m == "fsi";
        }
        // The animation: the frame image over the error image, one frame per clip frame.
        let file = std::fs::File::open(clips_dir.join(c.apng.as_ref().unwrap())).unwrap();
        let mut reader = png::Decoder::new(std::io::BufReader::new(file))
            .read_info()
            .unwrap();
        let animation = reader.info().animation_control().copied();
        assert!(animation.is_some(), "{:?} is not an APNG", c.apng);
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let frames: Vec<lodbench::raster::RgbaImage> = (0..animation.unwrap().num_frames)
            .map(|_| {
                let info = reader.next_frame(&mut buf).unwrap();
                let px = buf[..info.buffer_size()].to_vec();
                lodbench::raster::RgbaImage::from_raw(info.width, info.height, px).unwrap()
            })
            .collect();
        let shown = &frames[i];
        assert_eq!(shown.dimensions(), (c.width, c.height * 2));
        let top = shown.crop(0, 0, c.width, c.height);
        assert!(
            top == frame,
            "{}: the animation's frame {i} is not its frame image",
            c.name
        );
    }
    assert!(checked_fsi, "no clip showed fsi");
    assert!(
        index.clips.iter().any(|c| c.scale > 1),
        "the regress viewport is small: some clip is upscaled"
    );
    if ffmpeg {
        mp4_only_is_the_same_clip(dir, &settings, &index);
    }
}

/// `--mp4 only` (what committed example folders keep): the same clips, the MP4 alone (no animated PNG, no frame
/// images, index.json's fields for them null), each MP4 with a picture per clip frame, the frame grid over the
/// error grid, and its middle picture the lossless frame grid within H.264's loss. Run after the lossless clips
/// of the same folder, which it replaces.
fn mp4_only_is_the_same_clip(dir: &Path, settings: &ClipSettings, lossless: &ClipIndex) {
    let clips_dir = dir.join("clips");
    let middles: Vec<lodbench::raster::RgbaImage> = lossless
        .clips
        .iter()
        .map(|c| open(&clips_dir.join(&c.frame_images.as_ref().unwrap()[c.frames.len() / 2])))
        .collect();
    let only = ClipSettings {
        mp4: Mp4::Only,
        ..settings.clone()
    };
    let index = make(dir, &only).unwrap();
    assert_eq!(index.clips.len(), lossless.clips.len());
    let mut files: Vec<String> = std::fs::read_dir(&clips_dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    files.sort();
    let mut want: Vec<String> = index.clips.iter().map(|c| c.mp4.clone().unwrap()).collect();
    want.push("index.json".into());
    want.sort();
    assert_eq!(
        files, want,
        "--mp4 only writes the MP4s and index.json alone"
    );
    for (c, middle) in index.clips.iter().zip(&middles) {
        assert!(c.apng.is_none() && c.frame_images.is_none() && c.error_images.is_none());
        let mp4 = clips_dir.join(c.mp4.as_ref().unwrap());
        let out = std::process::Command::new("ffmpeg")
            .args(["-loglevel", "error", "-i"])
            .arg(&mp4)
            .args(["-f", "rawvideo", "-pix_fmt", "rgba", "-"])
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let picture = (c.width * c.height * 2 * 4) as usize;
        assert_eq!(
            out.stdout.len(),
            picture * c.frames.len(),
            "{}: a {}x{} picture per clip frame",
            c.name,
            c.width,
            c.height * 2
        );
        // The frame grid is the top half of the middle picture. Mean absolute difference over its RGB: H.264 at
        // CRF 18 in 4:2:0 loses a level or two where the picture is flat and more at the labels' edges; a
        // wrong frame, a shifted grid or the error grid in its place differs by tens of levels.
        let i = c.frames.len() / 2;
        let top = &out.stdout[i * picture..i * picture + picture / 2];
        let diff: u64 = top
            .chunks(4)
            .zip(middle.as_raw().chunks(4))
            .map(|(a, b)| (0..3).map(|k| a[k].abs_diff(b[k]) as u64).sum::<u64>())
            .sum();
        let mean = diff as f64 / (3 * c.width * c.height) as f64;
        assert!(mean < 3.0, "{}: mean difference {mean:.2} levels", c.name);
    }
}

/// A folder without dumps, an unknown method, `--mp4 on` without ffmpeg: one error line each, and no clips
/// folder left behind. On a small run of its own (windmills' four discrete transitions at the regress profile),
/// not the regression set's: waiting for that one would idle a test thread for its whole minute.
#[test]
fn bad_clip_input_is_one_error() {
    let tmp = tempfile::tempdir().unwrap();
    let dumped = run_into(
        &tmp.path().join("run"),
        &[
            "--scene",
            "windmills",
            "--method",
            "discrete",
            "--profile",
            "regress",
            "--dump-frames",
            "--dump-transitions",
        ],
    );
    let empty = tmp.path().join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    std::fs::copy(
        dumped.join("transitions.csv"),
        empty.join("transitions.csv"),
    )
    .unwrap();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    fails_with(
        &lodbench(&["clips", &s(&empty)], &[]),
        &["frames/", "--dump-frames --dump-transitions"],
    );
    fails_with(
        &lodbench(&["clips", &s(&tmp.path().join("nowhere"))], &[]),
        &["nowhere"],
    );
    let run = s(&dumped);
    fails_with(
        &lodbench(&["clips", &run, "--methods", "discrete,nosuch"], &[]),
        &["nosuch", "its methods"],
    );
    fails_with(
        &lodbench(
            &["clips", &run, "--methods", "discrete", "--mp4", "on"],
            &[("PATH", "")],
        ),
        &["ffmpeg"],
    );
    fails_with(
        &lodbench(
            &["clips", &run, "--methods", "discrete", "--mp4", "only"],
            &[("PATH", "")],
        ),
        &["--mp4 only", "ffmpeg"],
    );
    assert!(!empty.join("clips").exists() && !empty.join("clips.partial").exists());
}
