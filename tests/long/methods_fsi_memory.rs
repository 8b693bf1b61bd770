//! FSI's combination pass holds no memory per frame (moved from tests/it/methods_fsi.rs: a leak shows only over
//! hundreds of frames, so the test is slow by nature, 15 s on lavapipe).

use crate::common::lodbench;

/// run.json's `peak_resident_bytes` of `lodbench run --scene bunny-sweep --method METHODS --profile ci --frames
/// FRAMES`, in MiB, in rounds of 10 frames (the reference cache holds a round's frames, so its size is the same
/// for any FRAMES); a process of its own, so that no other test's memory is in it.
fn peak_resident_mib(methods: &str, frames: u32, dir: &std::path::Path) -> f64 {
    let out = dir.join(format!("frames-{frames}"));
    let (rounds, frames) = ((frames / 10).to_string(), frames.to_string());
    let run = lodbench(
        &[
            "run",
            "--scene",
            "bunny-sweep",
            "--method",
            methods,
            "--profile",
            "ci",
            "--frames",
            &frames,
            "--rounds",
            &rounds,
            "--out",
            out.to_str().unwrap(),
        ],
        &[],
    );
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "lodbench run failed: {stderr}");
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    run["peak_resident_bytes"]
        .as_u64()
        .expect("peak_resident_bytes in run.json") as f64
        / (1 << 20) as f64
}

/// FSI's combination pass holds no memory per frame. With the variant read from the uniform instead of fixed
/// in the pipeline, lavapipe (Mesa 22.3) grew by about 330 KB a dispatch at the ci profile's 320x240, in every
/// variant; fsi and fsi-blend with their quality passes dispatch it 4 to 6 times a frame, so 240 more frames
/// would add over 300 MB. Without that growth the two peaks differ by about 3 MB (141.1 and 143.9 MiB when
/// written); the bound of 32 MB sits far from both.
#[test]
fn the_combination_pass_holds_no_memory_per_frame() {
    let dir = tempfile::tempdir().unwrap();
    let short = peak_resident_mib("fsi,fsi-blend", 40, dir.path());
    let long = peak_resident_mib("fsi,fsi-blend", 280, dir.path());
    assert!(
        long - short < 32.0,
        "peak resident memory {short:.1} MiB after 40 frames, {long:.1} MiB after 280"
    );
}
