//! The warm-up before the timing rounds (src/measure/rounds.rs): it ends on the frame before the first timed
//! frame, and it uses every pipeline a timed frame will use.

use crate::common::{col, read_csv, run_into, sweep_scene};
use lodbench::measure::rounds::WarmUpPlan;
use lodbench::measure::FrameDriver;

/// FSI's first timed frame follows a frame like every other: on a static bunny out of transition its triangle
/// count (what its frame drew) is the same on every timed frame, one LOD buffer each, frame 0 included, where a
/// first frame with no frame before it renders both buffers (twice the triangles) and inflates round 0's ratio.
#[rustfmt::skip]
#[test]
fn fsi_first_timed_frame_renders_one_lod_buffer() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_into(
        dir.path(),
        &[
            "--scene", "bunny-grid", "--count", "1", "--frames", "6", "--rounds", "6", "--width", "64",
            "--height", "48", "--method", "fsi,discrete", "--quality", "off",
        ],
    );
    let rows = read_csv(&out.join("frames.csv"));
    let tri = col(&rows, "fsi", "triangles");
    assert!(tri[0] > 0.0);
    assert!(tri.iter().all(|&t| t == tri[0]), "fsi's triangles per timed frame: {tri:?}");
}

/// The plan renders, for every distinct transition of bunny-sweep's path (out and back), a frame on each side
/// of the midpoint k = 0.5 (alpha-zwrite switches pipelines there; the way back starts from k near 1).
#[test]
fn warm_up_covers_both_sides_of_every_transition() {
    let scene = sweep_scene(&["--frames", "400", "--sweep-start", "close-up"]);
    let plan = WarmUpPlan::new(&scene, 0);
    let mut driver = FrameDriver::new(&scene);
    let mut covered: Vec<(String, bool)> = Vec::new();
    let mut all: Vec<(String, bool)> = Vec::new();
    for f in 0..scene.frames {
        let facts = driver.advance(f);
        let Some(k) = facts.k_mean else { continue };
        let key = (format!("{:?}", facts.pair), k >= 0.5);
        if !all.contains(&key) {
            all.push(key.clone());
        }
        if plan.transition_frames.contains(&f) && !covered.contains(&key) {
            covered.push(key);
        }
    }
    assert!(all.len() >= 6, "{all:?}");
    for key in &all {
        assert!(
            covered.contains(key),
            "{key:?} not warmed up; plan {:?}",
            plan.transition_frames
        );
    }
}
