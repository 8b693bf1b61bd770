//! `lodbench probe` through the binary on the software adapter: bad flags are refused in one line, runs record the
//! ceilings and the rate around each block, fragments and passes are counted whole. Its timing bands (each
//! probe's doubled variant about doubles its time, its control leaves it) are in the long suite
//! (tests/long/commands_probe_bands.rs): ratios of a loaded two-core machine's rounds, measured up to three times.

use crate::common::{column, fails_with, lodbench};

#[test]
fn bad_probe_flags_are_one_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("p");
    let o = out.to_str().unwrap();
    fails_with(
        &lodbench(&["probe", "--scale", "0", "--out", o], &[]),
        &["--scale 0"],
    );
    fails_with(
        &lodbench(&["probe", "--rounds", "1", "--out", o], &[]),
        &["--rounds 1"],
    );
    fails_with(
        &lodbench(&["probe", "--width", "0", "--out", o], &[]),
        &["--width 0"],
    );
}

/// Every run records the ceilings before its blocks and the triangle rate around each block in run.json, and
/// summary.csv's rate against the ceiling; `--ceilings off` leaves all of them null.
#[test]
fn runs_record_the_ceilings_and_the_rate_around_each_block() {
    let dir = tempfile::tempdir().unwrap();
    for (flag, on) in [("on", true), ("off", false)] {
        let out = dir.path().join(flag);
        #[rustfmt::skip]
        let r = lodbench(&[
            "run", "--scene", "bunny-sweep", "--method", "discrete", "--width", "64", "--height", "48",
            "--frames", "8", "--warmup", "0", "--rounds", "2", "--quality", "off", "--ceilings", flag,
            "--out", out.to_str().unwrap(),
        ], &[]);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        let run: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
        let block = &run["blocks"][0];
        assert_eq!(run["ceilings"].is_array(), on, "{}", run["ceilings"]);
        for key in ["triangle_rate_before", "triangle_rate_after"] {
            assert_eq!(
                block[key].as_f64().is_some_and(|x| x > 0.0),
                on,
                "{key}: {}",
                block[key]
            );
        }
        let mut summary = csv::Reader::from_path(out.join("summary.csv")).unwrap();
        let header = summary.headers().unwrap().clone();
        let row = summary.records().next().unwrap().unwrap();
        let share = &row[column(&header, "triangle_ceiling_share")];
        assert_eq!(share.parse::<f64>().is_ok_and(|x| x > 0.0), on, "{share:?}");
        // The share's denominator is the highest triangle rate the run read: at its start or around a block.
        let ceiling = run["triangle_ceiling"].as_f64();
        assert_eq!(ceiling.is_some(), on, "{}", run["triangle_ceiling"]);
        if let Some(ceiling) = ceiling {
            let start = run["ceilings"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|p| p["unit"] == "triangles")
                .filter_map(|p| p["rate_median"].as_f64());
            let around =
                ["triangle_rate_before", "triangle_rate_after"].map(|k| block[k].as_f64().unwrap());
            let highest = start.chain(around).fold(0.0, f64::max);
            assert_eq!(ceiling, highest);
            let per_s = row[column(&header, "triangles_per_s")]
                .parse::<f64>()
                .unwrap();
            let share = share.parse::<f64>().unwrap();
            assert!(
                (share - per_s / ceiling).abs() <= 1e-9 * share,
                "{share} {per_s} {ceiling}"
            );
        }
    }
}

/// The quality pass counts the fragment shader invocations of each method's own frame (frames.csv's `fragments`):
/// on frames where no instance is in transition alpha draws what discrete draws, the same count; in a
/// transition it draws both LODs, more. summary.csv's `fragments_per_s` is the mean count over the median frame
/// time, and its share divides by run.json's `fragment_ceiling`; `--quality off` counts nothing.
#[test]
fn runs_count_each_methods_fragments() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("on");
    #[rustfmt::skip]
    let r = lodbench(&[
        "run", "--scene", "bunny-sweep", "--method", "discrete,alpha", "--width", "64", "--height", "48",
        "--frames", "40", "--warmup", "0", "--rounds", "2", "--out", out.to_str().unwrap(),
    ], &[]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let mut frames = csv::Reader::from_path(out.join("frames.csv")).unwrap();
    let header = frames.headers().unwrap().clone();
    let mut counts = std::collections::HashMap::new();
    for row in frames.records() {
        let row = row.unwrap();
        let fragments: u64 = row[column(&header, "fragments")]
            .parse()
            .expect("every frame counted on lavapipe");
        let key = (
            row[column(&header, "method")].to_string(),
            row[column(&header, "frame")].parse::<u32>().unwrap(),
        );
        let moving = row[column(&header, "t_instances")] != *"0";
        counts.insert(key, (fragments, moving));
    }
    let (mut same, mut more) = (0, 0);
    for f in 0..40 {
        let (d, _) = counts[&("discrete".to_string(), f)];
        let (a, moving) = counts[&("alpha".to_string(), f)];
        assert!(d > 0, "frame {f}: the bunny is on screen");
        if moving {
            assert!(a > d, "frame {f}: alpha draws both LODs ({a} vs {d})");
            more += 1;
        } else {
            assert_eq!(a, d, "frame {f}: the same draw");
            same += 1;
        }
    }
    assert!(
        more > 0 && same > 0,
        "{more} transition frames, {same} others"
    );

    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    let ceiling = run["fragment_ceiling"]
        .as_f64()
        .expect("a fragment ceiling");
    // The fastest fill probe of the short ceilings and of the two at the probe's default size.
    let fill = ["ceilings", "fill_ceilings"]
        .iter()
        .flat_map(|k| run[*k].as_array().unwrap())
        .filter(|p| p["probe"].as_str().unwrap().starts_with("fill-"))
        .filter_map(|p| p["rate_median"].as_f64())
        .fold(0.0, f64::max);
    assert_eq!(run["fill_ceilings"].as_array().unwrap().len(), 2);
    assert_eq!(ceiling, fill, "the fastest fill probe");
    let mut summary = csv::Reader::from_path(out.join("summary.csv")).unwrap();
    let header = summary.headers().unwrap().clone();
    for row in summary.records() {
        let row = row.unwrap();
        let get = |name: &str| row[column(&header, name)].parse::<f64>().unwrap();
        let method = row[column(&header, "method")].to_string();
        let mean = (0..40)
            .map(|f| counts[&(method.clone(), f)].0 as f64)
            .sum::<f64>()
            / 40.0;
        assert!((get("fragments_mean") - mean).abs() <= 1e-9 * mean);
        let per_s = get("fragments_per_s");
        let clock = row[column(&header, "clock")].to_string();
        let ms = get(&format!("{clock}_median"));
        assert!((per_s - mean / (ms / 1e3)).abs() <= 1e-9 * per_s);
        let share = get("fragment_ceiling_share");
        assert!((share - per_s / ceiling).abs() <= 1e-9 * share);
    }

    let off = dir.path().join("off");
    #[rustfmt::skip]
    let r = lodbench(&[
        "run", "--scene", "bunny-sweep", "--method", "discrete", "--width", "64", "--height", "48",
        "--frames", "4", "--warmup", "0", "--rounds", "2", "--quality", "off", "--out", off.to_str().unwrap(),
    ], &[]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let mut summary = csv::Reader::from_path(off.join("summary.csv")).unwrap();
    let header = summary.headers().unwrap().clone();
    let row = summary.records().next().unwrap().unwrap();
    for name in [
        "fragments_mean",
        "fragments_per_s",
        "fragment_ceiling_share",
    ] {
        assert_eq!(&row[column(&header, name)], "", "{name} with --quality off");
    }
}

/// `--clock-warmup on` warms the GPU before each timed segment and records it per method in run.json; `auto`
/// (the default) is off on a CPU adapter such as lavapipe; `on` with `--ceilings off` is one error.
#[test]
fn the_clock_warmup_runs_before_each_segment_where_asked() {
    let dir = tempfile::tempdir().unwrap();
    for (flag, on) in [("on", true), ("auto", false)] {
        let out = dir.path().join(flag);
        #[rustfmt::skip]
        let r = lodbench(&[
            "run", "--scene", "bunny-sweep", "--method", "discrete", "--width", "64", "--height", "48",
            "--frames", "6", "--warmup", "0", "--rounds", "2", "--quality", "off", "--clock-warmup", flag,
            "--out", out.to_str().unwrap(),
        ], &[]);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        let run: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
        assert_eq!(run["clock_warmup"], serde_json::json!(on), "{flag}");
        let block = &run["blocks"][0];
        let ms = block["clock_warmup_ms"].as_f64();
        let short = block["clock_warmups_short"].as_u64();
        if on {
            // Two segments, each at least one reading; at most the cap each, and then some for the last reading.
            assert!(
                ms.is_some_and(|ms| ms > 0.0),
                "{}",
                block["clock_warmup_ms"]
            );
            assert!(
                short.is_some_and(|s| s <= 2),
                "{}",
                block["clock_warmups_short"]
            );
        } else {
            assert!(ms.is_none() && short.is_none(), "{block}");
        }
    }
    let out = dir.path().join("bad");
    fails_with(
        &lodbench(
            &[
                "run",
                "--scene",
                "bunny-sweep",
                "--clock-warmup",
                "on",
                "--ceilings",
                "off",
                "--out",
                out.to_str().unwrap(),
            ],
            &[],
        ),
        &["--clock-warmup on", "--ceilings off"],
    );
}

/// A frame that begins more passes than one query set holds is counted whole: alpha-2pass begins two passes per
/// instance in transition, 41 on this static grid of 150 bunnies (20 in transition on every frame) against 32
/// queries a set. Every frame is counted, the same on every frame (nothing moves), and exactly: alpha-2pass draws
/// each instance in transition twice (its depth pass and its colour pass) where alpha draws it once over the same
/// opaque frame, so its count over discrete's is twice alpha's (as in every block of results/cpu/ceilings-ci).
#[test]
fn a_frame_of_many_passes_is_counted_whole() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("grid");
    #[rustfmt::skip]
    let r = lodbench(&[
        "run", "--scene", "bunny-grid", "--count", "150", "--method", "discrete,alpha,alpha-2pass", "--width", "64",
        "--height", "48", "--frames", "4", "--warmup", "0", "--rounds", "2", "--out", out.to_str().unwrap(),
    ], &[]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let mut frames = csv::Reader::from_path(out.join("frames.csv")).unwrap();
    let header = frames.headers().unwrap().clone();
    let mut by_method: std::collections::BTreeMap<String, Vec<(u64, u32)>> = Default::default();
    for row in frames.records() {
        let row = row.unwrap();
        let fragments: u64 = row[column(&header, "fragments")]
            .parse()
            .unwrap_or_else(|_| panic!("a frame not counted: {row:?}"));
        let moving: u32 = row[column(&header, "t_instances")].parse().unwrap();
        by_method
            .entry(row[column(&header, "method")].to_string())
            .or_default()
            .push((fragments, moving));
    }
    let (d, b, a) = (
        &by_method["discrete"],
        &by_method["alpha"],
        &by_method["alpha-2pass"],
    );
    assert!(
        a.iter()
            .all(|&(_, t)| 2 * t + 1 > lodbench::gpu::fragments::SET_QUERIES),
        "{a:?}"
    );
    for m in [d, b, a] {
        assert!(m.iter().all(|x| x == &m[0]), "{m:?}");
    }
    let (d, b, a) = (d[0].0, b[0].0, a[0].0);
    assert!(b > d, "alpha {b} discrete {d}");
    assert_eq!(
        a - d,
        2 * (b - d),
        "alpha-2pass {a}, alpha {b}, discrete {d}"
    );
}
