//! `lodbench clips`: the clips of the regression run's transitions (its dumps, `--dump-transitions`), checked
//! against the dumps they are made of, pixel for pixel; and its bad input.

use crate::common::{fails_with, lodbench, run_into};
use crate::regress_run;
use lodbench::commands::clips::{make, ClipSettings, Mp4};
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

fn open(path: &Path) -> image::RgbaImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgba8()
}

/// `image`'s picture `[x, y, w, h]` equals `source` cropped to `crop` and upscaled by `scale` (exactly: the
/// clip copies the dumps' pixels, nearest neighbour).
fn assert_tile(
    image: &image::RgbaImage,
    tile: [u32; 4],
    source: &image::RgbaImage,
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
        let frame = open(&clips_dir.join(&c.frame_images[i]));
        let error = open(&clips_dir.join(&c.error_images[i]));
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
        let decoder = image::codecs::png::PngDecoder::new(std::io::BufReader::new(
            std::fs::File::open(clips_dir.join(&c.apng)).unwrap(),
        ))
        .unwrap();
        assert!(decoder.is_apng().unwrap(), "{}", c.apng);
        use image::AnimationDecoder;
        let frames = decoder
            .apng()
            .unwrap()
            .into_frames()
            .collect_frames()
            .unwrap();
        assert_eq!(frames.len(), c.frames.len(), "{}", c.apng);
        let shown = frames[i].buffer();
        assert_eq!(shown.dimensions(), (c.width, c.height * 2));
        let top = image::imageops::crop_imm(shown, 0, 0, c.width, c.height).to_image();
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
    assert!(!empty.join("clips").exists() && !empty.join("clips.partial").exists());
}
