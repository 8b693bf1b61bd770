//! `lodbench probe`'s measurement: every probe of `gpu::probe_kernels` and its doubled and control variants, timed in
//! rounds (each round times every variant of every probe once, in an order shuffled from the seed), on the GPU's
//! timestamps where the adapter has them, else the CPU's clock around a submission and its wait.
//!
//! Each probe is read on the GPU's timestamps unless they hold less than half of the CPU's time from the
//! submission to the device's idle (less an empty submission's): lavapipe's timestamps do not wait for a compute
//! dispatch, and its bandwidth probe reads 1,000 times faster on them than the CPU waits. probe.csv's `clock`
//! says which was read.
//!
//! Per probe: the rate (its quantity over the base's time) as the median over rounds and the geometric mean with
//! its Student-t 95 % interval; the doubled variant's time over the base's and the control's time over the base's,
//! paired round by round (geometric means with their intervals). A probe isolates what it names when doubling it
//! about doubles the time and the control leaves it: `scales` (a ratio in one run, never a time).

use crate::error::Result;
use crate::gpu::context::GpuContext;
use crate::gpu::probe_kernels::{Amounts, Probe, Probes, Unit, Variant, PROBES, VARIANTS};
use crate::gpu::timestamps::GpuTimer;
use crate::measure::records::Clock;
use crate::measure::stats::{paired_log_ratio, percentile};
use crate::rng::SplitMix64;
use serde::Serialize;
use std::time::Instant;

/// Where `scales` draws the line: doubling within [1.6, 2.5] times, the control within [0.8, 1.25].
pub const DOUBLED_RANGE: (f64, f64) = (1.6, 2.5);
pub const CONTROL_RANGE: (f64, f64) = (0.8, 1.25);

/// One row of probe.csv.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ProbeRecord {
    pub probe: Probe,
    pub unit: Unit,
    /// The base variant's amount of the unit.
    pub quantity: f64,
    /// `gpu_ms` (timestamps) or `cpu_ms` (submission to idle).
    pub clock: Clock,
    pub rounds: u32,
    /// The base variant's median time on `clock`; on the timestamps (None without them); and on the CPU's
    /// clock from its submission to the device's idle, less an empty submission's time.
    pub ms_median: f64,
    pub gpu_ms_median: Option<f64>,
    pub cpu_ms_median: f64,
    /// The unit per second: the median over rounds, and the geometric mean's 95 % interval.
    pub rate_median: f64,
    pub rate_ci95_lo: Option<f64>,
    pub rate_ci95_hi: Option<f64>,
    /// The doubled variant's time over the base's, paired by round: the geometric mean with its interval, and
    /// the median over rounds (what a round disturbed by other work moves least).
    pub doubled_ratio: f64,
    pub doubled_ratio_median: f64,
    pub doubled_ci95_lo: Option<f64>,
    pub doubled_ci95_hi: Option<f64>,
    /// What the control changes, and its time over the base's.
    pub control: &'static str,
    pub control_ratio: f64,
    pub control_ratio_median: f64,
    pub control_ci95_lo: Option<f64>,
    pub control_ci95_hi: Option<f64>,
    /// Doubling within DOUBLED_RANGE and the control within CONTROL_RANGE.
    pub scales: bool,
}

/// Times every probe's variants over `rounds` rounds, their order shuffled from `seed`; one untimed pass first.
pub fn measure(
    ctx: &GpuContext,
    probes: &Probes,
    rounds: u32,
    seed: u64,
) -> Result<Vec<ProbeRecord>> {
    measure_variants(ctx, probes, rounds, seed, &VARIANTS)
}

/// The ceilings every run records in run.json before its blocks: each probe's base variant alone (no scaling
/// check: that is `lodbench probe`'s), on `clock`'s probes (a tenth of the default work on a 256 x 256 target),
/// 3 rounds; a tenth of a second on lavapipe.
pub fn ceilings(ctx: &GpuContext, clock: &ClockCheck, seed: u64) -> Result<Vec<ProbeRecord>> {
    measure_variants(ctx, &clock.probes, 3, seed, &[Variant::Base])
}

/// The two fill probes at `lodbench probe`'s default size and work (512 x 512, scale 1), base variants, 3 rounds:
/// what a run's fragment ceiling is read from besides [`ceilings`]. The short probes' quads, a tenth of the work
/// on 256 x 256, are too little work to fill the adapter: on lavapipe opaque fill read 0.65 G fragments a second
/// on them against 3.3 G at this size in the same run (docs/measurement.md, run.json). Tens of milliseconds on
/// lavapipe.
pub fn fill_ceilings(ctx: &GpuContext, seed: u64) -> Result<Vec<ProbeRecord>> {
    let probes = Probes::new(ctx, (512, 512), Amounts::at(1.0))?;
    measure_probes(
        ctx,
        (&probes, &[Probe::FillOpaque, Probe::FillBlended]),
        3,
        seed,
        &[Variant::Base],
    )
}

/// The probes a run reads the adapter with: its ceilings before the blocks ([`ceilings`]) and its speed around
/// each block, the triangle probe's base variant 3 times, at a tenth of the default work on a 256 x 256 target (a
/// few milliseconds on lavapipe, well under one on a GPU).
/// A block whose rate after differs from its rate before by more than a fifth ran while the adapter changed
/// speed (the H200's GPU clock dropping while ROAM's selection kept it idle): detected and said. With
/// `--clock-warmup`, [`ClockCheck::warm`] before every timed segment works to prevent it.
pub struct ClockCheck {
    probes: Probes,
    /// The highest triangle rate read so far (the start's probes and every reading since).
    best: std::cell::Cell<f64>,
}

/// A warm-up's target: this share of the highest triangle rate the run has read.
pub const WARM_TARGET: f64 = 0.9;
/// A warm-up's longest time, ms: a GPU's clock ramps up within tens of milliseconds of steady work.
pub const WARM_CAP_MS: f64 = 250.0;
/// The busy work between two readings of a warm-up, ms at the best rate read.
const WARM_BATCH_MS: f64 = 5.0;

/// What one warm-up before a timed segment did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WarmUp {
    /// Wall time, ms.
    pub ms: f64,
    /// Readings taken (each after a batch of busy work).
    pub readings: u32,
    /// The last reading reached the target (else the cap ended it).
    pub reached: bool,
}

/// Busy work and a reading (`busy_then_read`), repeated until a reading reaches `target` or `elapsed_ms()`
/// passes `cap_ms`; at least one reading.
pub fn warm_until(
    mut busy_then_read: impl FnMut() -> Result<f64>,
    target: f64,
    cap_ms: f64,
    elapsed_ms: impl Fn() -> f64,
) -> Result<WarmUp> {
    let mut readings = 0;
    loop {
        let rate = busy_then_read()?;
        readings += 1;
        let reached = rate >= target;
        if reached || elapsed_ms() >= cap_ms {
            return Ok(WarmUp {
                ms: elapsed_ms(),
                readings,
                reached,
            });
        }
    }
}

impl ClockCheck {
    pub fn new(ctx: &GpuContext) -> Result<ClockCheck> {
        Ok(ClockCheck {
            probes: Probes::new(ctx, (256, 256), Amounts::at(0.1))?,
            best: std::cell::Cell::new(0.0),
        })
    }

    /// Counts the start's ceilings into the highest rate read ([`ClockCheck::warm`]'s target).
    pub fn note_ceilings(&self, rows: &[ProbeRecord]) {
        if let Some(t) = triangle_ceiling(rows) {
            self.note(t);
        }
    }

    fn note(&self, rate: f64) {
        if rate.is_finite() && rate > self.best.get() {
            self.best.set(rate);
        }
    }

    /// Keeps the adapter busy with the triangle probe until it reads [`WARM_TARGET`] of the highest triangle
    /// rate read so far, or [`WARM_CAP_MS`] has passed: before a timed segment, so that a clock that dropped
    /// while the GPU idled (a CPU-heavy method's frames, the harness between blocks) is up again. Each round of
    /// it submits about [`WARM_BATCH_MS`] of the probe without waiting, then reads the rate
    /// ([`ClockCheck::triangle_rate`]).
    pub fn warm(&self, ctx: &GpuContext) -> Result<WarmUp> {
        let start = Instant::now();
        let item = (Probe::Triangles, Variant::Base);
        let q = self.probes.quantity(item.0, item.1);
        let best = self.best.get();
        let batch = match best > 0.0 && q > 0.0 {
            true => (WARM_BATCH_MS / 1e3 * best / q).ceil().clamp(1.0, 256.0) as u32,
            false => 1,
        };
        warm_until(
            || {
                let mut encoder = ctx.device.create_command_encoder(&Default::default());
                for _ in 0..batch {
                    self.probes.record(&mut encoder, item.0, item.1);
                }
                ctx.queue.submit([encoder.finish()]);
                self.triangle_rate(ctx)
            },
            WARM_TARGET * best,
            WARM_CAP_MS,
            || start.elapsed().as_secs_f64() * 1e3,
        )
    }

    /// Triangles a second now: one untimed submission (after a block, the probe's first reading was slower
    /// by up to 44 % on lavapipe with nothing else changed: caches, not clocks), then the median of 5 timings
    /// (timestamps where the adapter has them).
    pub fn triangle_rate(&self, ctx: &GpuContext) -> Result<f64> {
        let item = (Probe::Triangles, Variant::Base);
        submit(ctx, &self.probes, item, None)?;
        let timer = GpuTimer::new(ctx, 5);
        let cpu = (0..5)
            .map(|slot| submit(ctx, &self.probes, item, timer.as_ref().map(|t| (t, slot))))
            .collect::<Result<Vec<f64>>>()?;
        let gpu: Vec<f64> = match &timer {
            Some(t) => t.read(ctx)?.into_iter().flatten().collect(),
            None => Vec::new(),
        };
        let ms = if gpu.len() == 5 { gpu } else { cpu };
        let q = self.probes.quantity(Probe::Triangles, Variant::Base);
        let rate = q / (percentile(&ms, 50.0).unwrap_or(f64::NAN) / 1e3);
        self.note(rate);
        Ok(rate)
    }
}

/// A block's triangle rates before and after it whose lower is below this fraction of the higher differ by more
/// than a fifth: the adapter changed speed during the block. scripts/clock_drops.py's `CHANGED_BELOW` is this
/// (scripts/tests/test_clock_drops.py reads both).
pub const CLOCK_CHANGED_BELOW: f64 = 0.8;

/// Whether a block's rates before and after differ by more than a fifth ([`CLOCK_CHANGED_BELOW`]).
pub fn clock_changed(before: f64, after: f64) -> bool {
    let (lo, hi) = (before.min(after), before.max(after));
    lo.is_finite() && hi > 0.0 && lo / hi < CLOCK_CHANGED_BELOW
}

/// The run's triangle ceiling: the highest of the triangle probes' rates at its start ([`triangle_ceiling`] of
/// `rows`) and of its readings around the blocks (`readings`, [`ClockCheck::triangle_rate`]). A ceiling is a
/// rate the adapter reaches, and on a shared or throttled adapter a reading errs low, never high: on lavapipe the
/// start's short probe read 9.05 M triangles a second in one run and 14.1 M in another of the same command, and
/// the readings around one run's blocks ranged from 10.2 M to 17.4 M (docs/findings/ceilings.md); shares over
/// the start's alone came out above 1. The highest reading is the steadier denominator.
pub fn run_triangle_ceiling(
    rows: &[ProbeRecord],
    readings: impl IntoIterator<Item = f64>,
) -> Option<f64> {
    triangle_ceiling(rows)
        .into_iter()
        .chain(readings.into_iter().filter(|r| r.is_finite() && *r > 0.0))
        .reduce(f64::max)
}

/// The fragment ceiling of a run's ceilings (`rows`: [`ceilings`]' and [`fill_ceilings`]'): the fastest of the fill
/// probes (full-screen quads, opaque and blended), in fragments a second. Their quads cover whole tiles and quads,
/// so the fragment shader invocations an adapter counts for them are the fragments they name; a method's count
/// (`fragments`) includes what the adapter shades around a triangle's edges besides, which is work of the same
/// kind. The depth probe has no fragment shader and is not a fill rate of shaded fragments.
pub fn fragment_ceiling<'r>(rows: impl IntoIterator<Item = &'r ProbeRecord>) -> Option<f64> {
    fastest(rows, |r| r.probe.is_fill())
}

/// The triangle ceiling of a run's ceilings: the larger of the two triangle probes' rates.
pub fn triangle_ceiling(rows: &[ProbeRecord]) -> Option<f64> {
    fastest(rows, |r| r.unit == Unit::Triangles)
}

/// The highest finite rate of the rows `keep` keeps.
fn fastest<'r>(
    rows: impl IntoIterator<Item = &'r ProbeRecord>,
    keep: impl Fn(&ProbeRecord) -> bool,
) -> Option<f64> {
    rows.into_iter()
        .filter(|r| keep(r) && r.rate_median.is_finite())
        .map(|r| r.rate_median)
        .reduce(f64::max)
}

fn measure_variants(
    ctx: &GpuContext,
    probes: &Probes,
    rounds: u32,
    seed: u64,
    variants: &[Variant],
) -> Result<Vec<ProbeRecord>> {
    measure_probes(ctx, (probes, &PROBES), rounds, seed, variants)
}

/// The probes `which` of `probes`, each variant of `variants`, timed over `rounds` rounds.
fn measure_probes(
    ctx: &GpuContext,
    (probes, which): (&Probes, &[Probe]),
    rounds: u32,
    seed: u64,
    variants: &[Variant],
) -> Result<Vec<ProbeRecord>> {
    let items: Vec<(Probe, Variant)> = which
        .iter()
        .flat_map(|&p| variants.iter().map(move |&v| (p, v)))
        .collect();
    let rounds = rounds.max(2);
    let times = time_items(ctx, probes, &items, rounds, seed)?;
    Ok(which
        .iter()
        .map(|&p| probe_record(probes, p, &items, &times, rounds))
        .collect())
}

/// Each item's time per round on both clocks.
struct ItemTimes {
    /// time[item][round] on the GPU's clock (NaN where no timestamp came back).
    gpu: Vec<Vec<f64>>,
    /// The same on the CPU's, less an empty submission's time.
    cpu: Vec<Vec<f64>>,
    /// Every slot has a positive timestamp.
    stamped: bool,
}

/// Times every item once per round (after an untimed warm-up), in a fresh random order each round.
fn time_items(
    ctx: &GpuContext,
    probes: &Probes,
    items: &[(Probe, Variant)],
    rounds: u32,
    seed: u64,
) -> Result<ItemTimes> {
    let total = items.len() as u32 * rounds;
    let timer = GpuTimer::new(ctx, total);
    // Warm-up: every item once, untimed (pipelines compiled, buffers resident).
    for &item in items {
        submit(ctx, probes, item, None)?;
    }
    let timed = run_rounds(ctx, probes, items, (rounds, seed), timer.as_ref())?;
    let gpu_ms = match &timer {
        Some(t) => t.read(ctx)?,
        None => vec![None; timed.slots.len()],
    };
    let stamped = gpu_ms.iter().all(|t| t.is_some_and(|t| t > 0.0));
    let overhead = percentile(&timed.empty_ms, 50.0).unwrap_or(0.0);
    // time[item][round] on each clock; the CPU's less an empty submission's time.
    let mut gpu = vec![vec![f64::NAN; rounds as usize]; items.len()];
    let mut cpu = gpu.clone();
    for ((&(round, k), g), &c) in timed.slots.iter().zip(&gpu_ms).zip(&timed.cpu_ms) {
        gpu[k][round as usize] = g.unwrap_or(f64::NAN);
        cpu[k][round as usize] = (c - overhead).max(1e-6);
    }
    Ok(ItemTimes { gpu, cpu, stamped })
}

/// The timed slots of [`run_rounds`].
struct Slots {
    /// (round, item index) of each timed slot, and its CPU time.
    slots: Vec<(u32, usize)>,
    cpu_ms: Vec<f64>,
    /// An empty submission's CPU time, per round: what the CPU clock adds to a probe's work.
    empty_ms: Vec<f64>,
}

/// `rounds` rounds of every item, each round an empty submission and then the items in an order shuffled from
/// `seed`, each timed at the next slot of `timer` where there is one.
fn run_rounds(
    ctx: &GpuContext,
    probes: &Probes,
    items: &[(Probe, Variant)],
    (rounds, seed): (u32, u64),
    timer: Option<&GpuTimer>,
) -> Result<Slots> {
    let total = items.len() as u32 * rounds;
    // An empty submission's CPU time, per round: what the CPU clock adds to a probe's work.
    let mut empty_ms = Vec::with_capacity(rounds as usize);
    let mut rng = SplitMix64::new(seed ^ 0x0050_524F_4245);
    // (round, item index) of each timed slot, and its CPU time.
    let mut slots = Vec::with_capacity(total as usize);
    let mut cpu_ms = Vec::with_capacity(total as usize);
    for round in 0..rounds {
        let t0 = Instant::now();
        ctx.queue.submit([ctx
            .device
            .create_command_encoder(&Default::default())
            .finish()]);
        ctx.wait_idle()?;
        empty_ms.push(t0.elapsed().as_secs_f64() * 1e3);
        let mut order: Vec<usize> = (0..items.len()).collect();
        for i in (1..order.len()).rev() {
            let j = (rng.next_u64() % (i as u64 + 1)) as usize;
            order.swap(i, j);
        }
        for k in order {
            let slot = slots.len() as u32;
            cpu_ms.push(submit(ctx, probes, items[k], timer.map(|t| (t, slot)))?);
            slots.push((round, k));
        }
    }
    Ok(Slots {
        slots,
        cpu_ms,
        empty_ms,
    })
}

/// Probe `p`'s record from the items' `times`: its rate on the clock that saw the work, and its doubled and
/// control variants' ratios to its base.
fn probe_record(
    probes: &Probes,
    p: Probe,
    items: &[(Probe, Variant)],
    times: &ItemTimes,
    rounds: u32,
) -> ProbeRecord {
    let ItemTimes { gpu, cpu, stamped } = times;
    let stamped = *stamped;
    let index = |p: Probe, v: Variant| items.iter().position(|&x| x == (p, v));
    let none = vec![f64::NAN; rounds as usize];
    let k = index(p, Variant::Base).unwrap_or(0);
    let gpu_median = percentile(&gpu[k], 50.0).unwrap_or(f64::NAN);
    let cpu_median = percentile(&cpu[k], 50.0).unwrap_or(f64::NAN);
    // The timestamps, unless they hold less than half of what the CPU waited for: then they missed the
    // work (lavapipe's stamps do not wait for a compute dispatch), and the CPU's clock is read.
    let use_gpu = stamped && gpu_median >= 0.5 * cpu_median;
    let time = if use_gpu { gpu } else { cpu };
    let base = &time[k];
    let q = probes.quantity(p, Variant::Base);
    let rates: Vec<f64> = base.iter().map(|t| q / (t / 1e3)).collect();
    let (_, rate_ci) = geometric(&rates);
    let of = |v| index(p, v).map_or(&none, |i| &time[i]);
    let (doubled, doubled_ci) = paired(of(Variant::Doubled), base);
    let (control, control_ci) = paired(of(Variant::Control), base);
    let median_ratio = |a: &[f64]| {
        let r: Vec<f64> = a.iter().zip(base).map(|(x, y)| x / y).collect();
        percentile(&r, 50.0).unwrap_or(f64::NAN)
    };
    ProbeRecord {
        probe: p,
        unit: p.unit(),
        quantity: q,
        clock: if use_gpu { Clock::GpuMs } else { Clock::CpuMs },
        rounds,
        ms_median: percentile(base, 50.0).unwrap_or(f64::NAN),
        gpu_ms_median: stamped.then_some(gpu_median),
        cpu_ms_median: cpu_median,
        rate_median: percentile(&rates, 50.0).unwrap_or(f64::NAN),
        rate_ci95_lo: rate_ci.map(|c| c.0),
        rate_ci95_hi: rate_ci.map(|c| c.1),
        doubled_ratio: doubled,
        doubled_ratio_median: median_ratio(of(Variant::Doubled)),
        doubled_ci95_lo: doubled_ci.map(|c| c.0),
        doubled_ci95_hi: doubled_ci.map(|c| c.1),
        control: p.control(),
        control_ratio: control,
        control_ratio_median: median_ratio(of(Variant::Control)),
        control_ci95_lo: control_ci.map(|c| c.0),
        control_ci95_hi: control_ci.map(|c| c.1),
        scales: (DOUBLED_RANGE.0..=DOUBLED_RANGE.1).contains(&doubled)
            && (CONTROL_RANGE.0..=CONTROL_RANGE.1).contains(&control),
    }
}

/// Records `item` in an encoder of its own (bracketed by `timed`'s timestamps at its slot, where given),
/// submits it and waits for the device: the CPU's milliseconds from the submission to idle.
fn submit(
    ctx: &GpuContext,
    probes: &Probes,
    (probe, variant): (Probe, Variant),
    timed: Option<(&GpuTimer, u32)>,
) -> Result<f64> {
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    if let Some((t, slot)) = timed {
        t.begin(&mut encoder, slot);
    }
    probes.record(&mut encoder, probe, variant);
    if let Some((t, slot)) = timed {
        t.end(&mut encoder, slot);
    }
    let t0 = Instant::now();
    ctx.queue.submit([encoder.finish()]);
    ctx.wait_idle()?;
    Ok(t0.elapsed().as_secs_f64() * 1e3)
}

/// Geometric mean of positive values and its 95 % interval.
fn geometric(values: &[f64]) -> (f64, Option<(f64, f64)>) {
    if values.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
        return (f64::NAN, None);
    }
    let logs: Vec<f64> = values.iter().map(|v| v.ln()).collect();
    match paired_log_ratio(&logs) {
        Some((m, ci)) => (m.exp(), ci.map(|(lo, hi)| (lo.exp(), hi.exp()))),
        None => (f64::NAN, None),
    }
}

/// `a`'s time over `b`'s, paired by round: geometric mean and its 95 % interval.
fn paired(a: &[f64], b: &[f64]) -> (f64, Option<(f64, f64)>) {
    let ratios: Vec<f64> = a.iter().zip(b).map(|(x, y)| x / y).collect();
    geometric(&ratios)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_warm_up_reads_until_the_clock_is_up_or_the_cap_passes() {
        use std::cell::Cell;
        // A clock that ramps: each reading 20 % faster than the one before, from a fifth of full speed.
        let ramp = |rates: &Cell<f64>| {
            let r = rates.get();
            rates.set(r * 1.2);
            Ok(r)
        };
        let (rate, t) = (Cell::new(2.0), Cell::new(0.0));
        let tick = || {
            t.set(t.get() + 10.0);
            t.get()
        };
        let w = warm_until(|| ramp(&rate), 0.9 * 10.0, WARM_CAP_MS, tick).unwrap();
        // 2 * 1.2^k >= 9 first at k = 9: the tenth reading.
        assert_eq!((w.readings, w.reached), (10, true));
        // A clock that stays down: the cap ends it, the target not reached.
        let (t, tick) = (Cell::new(0.0), |t: &Cell<f64>| {
            t.set(t.get() + 10.0);
            t.get()
        });
        let w = warm_until(|| Ok(2.0), 9.0, 100.0, || tick(&t)).unwrap();
        assert_eq!((w.readings, w.reached), (10, false));
        assert!(w.ms >= 100.0);
        // Already up: one reading.
        let w = warm_until(|| Ok(10.0), 9.0, 100.0, || 0.0).unwrap();
        assert_eq!((w.readings, w.reached), (1, true));
        // A failing reading is the warm-up's error.
        assert!(warm_until(
            || Err(crate::error::Error::Gpu("lost".into())),
            9.0,
            100.0,
            || 0.0
        )
        .is_err());
    }

    #[test]
    fn the_run_ceiling_is_the_highest_rate_read() {
        // No probe rows: the readings alone; NaN and zero readings are no rate.
        assert_eq!(
            run_triangle_ceiling(&[], [3.0, f64::NAN, 0.0, 5.0]),
            Some(5.0)
        );
        assert_eq!(run_triangle_ceiling(&[], [f64::NAN]), None);
    }

    #[test]
    fn a_fifth_either_way_is_a_clock_change() {
        assert!(!clock_changed(10.0, 8.5));
        assert!(!clock_changed(8.5, 10.0));
        assert!(clock_changed(10.0, 7.9));
        assert!(clock_changed(2.0, 10.0));
        assert!(!clock_changed(f64::NAN, 10.0));
    }

    #[test]
    fn paired_ratio_of_doubled_times_is_two() {
        let b = [1.0, 1.2, 0.9, 1.1];
        let a: Vec<f64> = b.iter().map(|x| x * 2.0).collect();
        let (r, ci) = paired(&a, &b);
        assert!((r - 2.0).abs() < 1e-12);
        let (lo, hi) = ci.expect("an interval of 4 rounds");
        assert!((lo - 2.0).abs() < 1e-9 && (hi - 2.0).abs() < 1e-9);
    }
}
