//! `lodbench probe`: the adapter's ceilings (`gpu::probe_kernels`, measured by `measure::probe_rounds`), written as probe.csv
//! (a row per probe) and probe.json (the adapter, the target's size, the amounts, the settings and the rows), and
//! printed as a table whose last column says whether each probe isolated what it names.

use crate::cli::ProbeArgs;
use crate::error::{Error, Result};
use crate::gpu::probe_kernels::{Amounts, Probes};
use crate::gpu::GpuContext;
use crate::measure::probe_rounds::{measure, ProbeRecord, CONTROL_RANGE, DOUBLED_RANGE};
use crate::numbers::{aligned, ratio, sig3};
use crate::results::csv::write_whole;
use crate::results::files::{PROBE_CSV, PROBE_JSON};
use crate::results::manifest::BuildVersion;
use serde::Serialize;

/// What probe.json holds.
#[derive(Serialize)]
struct ProbeManifest<'a> {
    /// The build: lodbench_version, git_commit, source_diff_hash.
    #[serde(flatten)]
    build: BuildVersion,
    adapter: crate::gpu::AdapterSummary,
    width: u32,
    height: u32,
    amounts: Amounts,
    rounds: u32,
    seed: u64,
    scale: f64,
    probes: &'a [ProbeRecord],
}

/// `lodbench probe`.
pub fn execute(args: &ProbeArgs) -> Result<()> {
    if !(args.scale.is_finite() && args.scale > 0.0 && args.scale <= 64.0) {
        return Err(Error::Config(format!(
            "--scale {}: the probes' amount of work is a factor in (0, 64]",
            args.scale
        )));
    }
    if args.width == 0 || args.height == 0 {
        return Err(Error::Config(format!(
            "--width {} --height {}: a target has pixels",
            args.width, args.height
        )));
    }
    if args.rounds < 2 {
        return Err(Error::Config(format!(
            "--rounds {}: an interval needs at least 2 rounds",
            args.rounds
        )));
    }
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| super::run::default_out_dir(&["probe"]));
    super::run::prepare_output(&out)?;
    let ctx = GpuContext::new(args.adapter.as_deref())?;
    let probes = Probes::new(&ctx, (args.width, args.height), Amounts::at(args.scale))?;
    let rows = measure(&ctx, &probes, args.rounds, args.seed)?;
    write_whole(&out, PROBE_CSV, &rows)?;
    let manifest = ProbeManifest {
        build: BuildVersion::this(),
        adapter: ctx.info.clone(),
        width: args.width,
        height: args.height,
        amounts: probes.amounts(),
        rounds: args.rounds,
        seed: args.seed,
        scale: args.scale,
        probes: &rows,
    };
    crate::results::manifest::write_json_file(&out, PROBE_JSON, &manifest)?;
    out!("{}", table(&rows));
    outln!(
        "adapter: {}; rates are medians over {} rounds with the geometric mean's 95 % interval; x2 and control \
         are times over the base's, paired by round; isolates: x2 within [{}, {}] and control within [{}, {}]",
        ctx.info.name,
        args.rounds,
        DOUBLED_RANGE.0,
        DOUBLED_RANGE.1,
        CONTROL_RANGE.0,
        CONTROL_RANGE.1
    );
    outln!("results in {}", out.display());
    Ok(())
}

/// The printed table: a row per probe, columns sized to their contents.
pub fn table(rows: &[ProbeRecord]) -> String {
    let mut cells = vec![[
        "probe",
        "per second",
        "[95 % CI]",
        "ms",
        "clock",
        "x2: time ratio",
        "control",
        "control: time ratio",
        "isolates",
    ]
    .map(String::from)
    .to_vec()];
    for r in rows {
        let rate = match (r.rate_ci95_lo, r.rate_ci95_hi) {
            (Some(lo), Some(hi)) => format!("[{}, {}]", giga(lo), giga(hi)),
            _ => "-".into(),
        };
        cells.push(vec![
            r.probe.name().to_string(),
            format!("{} {}", giga(r.rate_median), r.unit.name()),
            rate,
            sig3(Some(r.ms_median)),
            r.clock.name().to_string(),
            ratio(Some(r.doubled_ratio), r.doubled_ci95_lo, r.doubled_ci95_hi),
            r.control.to_string(),
            ratio(Some(r.control_ratio), r.control_ci95_lo, r.control_ci95_hi),
            if r.scales { "yes" } else { "no" }.to_string(),
        ]);
    }
    aligned(
        &cells,
        &[false, true, false, true, false, false, false, false, false],
    )
}

/// A rate with its SI prefix, 3 figures: `1.52 G`, `830 M`.
fn giga(x: f64) -> String {
    let (v, p) = if x >= 1e9 {
        (x / 1e9, "G")
    } else if x >= 1e6 {
        (x / 1e6, "M")
    } else if x >= 1e3 {
        (x / 1e3, "k")
    } else {
        (x, "")
    };
    format!("{} {p}", sig3(Some(v))).trim_end().to_string()
}
