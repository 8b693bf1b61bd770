//! `lodbench compare DIR A B [--scene S] [--count N]`: method A's frame time over method B's, per block of a
//! results folder, paired round by round as summary.csv's `ratio_to_baseline` and pairs.csv are
//! (`measure::records::PairedRatios`, on the block's one clock), with the 95 % interval and the verdict, over
//! all frames, the frames in transition and the steady ones.
//!
//! It reads only frames.csv, so it works on any run made with timing rounds, on an experiment's folder and on a
//! merged one: there a block is a run's scene x count, told apart by the columns before `scene` (the swept
//! variable, `adapter`).

use crate::cli::CompareArgs;
use crate::error::{Error, Result};
use crate::measure::records::{Clock, FrameRecord, FrameTimes, PairedRatios, Ratio};
use crate::results::csv::read_frame_times;
use std::path::Path;

/// The comparison of A with B in one block.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockComparison {
    /// How the block is named: the leading columns' `name=value`, the scene and the count.
    pub block: String,
    pub scene: String,
    pub count: u32,
    /// The block's clock: over every method of the block, as the run decided it.
    pub clock: Clock,
    pub ratios: PairedRatios,
}

/// One block's frame records per method, in the order frames.csv lists them.
struct Block {
    lead: Vec<String>,
    scene: String,
    count: u32,
    methods: Vec<(String, Vec<FrameRecord>)>,
}

/// `lodbench compare`: prints each block's ratios.
pub fn execute(args: &CompareArgs) -> Result<()> {
    let blocks = compare(
        &args.dir,
        &args.a,
        &args.b,
        args.scene.as_deref(),
        args.count,
    )?;
    for c in &blocks {
        outln!("{}", report(c, &args.a, &args.b));
    }
    outln!(
        "ratio = {}'s median frame time over {}'s per timing round, geometric mean and 95 % t interval over rounds; \
         the two costs differ only where the interval excludes 1.0 (docs/measurement.md, \"Paired ratios\")",
        args.a,
        args.b
    );
    Ok(())
}

/// A over B in every block of `dir`'s frames.csv that holds both (of scene `scene` and count `count` when
/// given). Errors: no such folder or frames.csv, no timing rounds, a method the folder does not hold, no
/// block left.
pub fn compare(
    dir: &Path,
    a: &str,
    b: &str,
    scene: Option<&str>,
    count: Option<u32>,
) -> Result<Vec<BlockComparison>> {
    let times = read_frame_times(dir)?;
    let grouped = group_blocks(dir, times.rows)?;
    for m in [a, b] {
        require_listed(dir, "method", m, &grouped.methods)?;
    }
    if let Some(s) = scene {
        require_listed(dir, "scene", s, &grouped.scenes)?;
    }
    let mut out = Vec::new();
    for block in &grouped.blocks {
        if scene.is_some_and(|s| s != block.scene) || count.is_some_and(|n| n != block.count) {
            continue;
        }
        if let Some(c) = compare_block(&times.lead_header, block, a, b) {
            out.push(c);
        }
    }
    if out.is_empty() {
        let filter = match (scene, count) {
            (None, None) => String::new(),
            (s, n) => format!(
                " of{}{}",
                s.map_or(String::new(), |s| format!(" scene {s}")),
                n.map_or(String::new(), |n| format!(" count {n}"))
            ),
        };
        return Err(Error::results(
            dir,
            format!("has no block{filter} with both {a} and {b} in frames.csv"),
        ));
    }
    Ok(out)
}

/// frames.csv's rows grouped into blocks, with the methods and scenes they name, each in first-seen order.
struct Grouped {
    blocks: Vec<Block>,
    methods: Vec<String>,
    scenes: Vec<String>,
}

/// Groups `dir`'s frames.csv `rows` (leading values, times) into blocks of their leading values, scene and
/// count. Errors where a row has no timing round.
fn group_blocks(dir: &Path, rows: Vec<(Vec<String>, FrameTimes)>) -> Result<Grouped> {
    let mut blocks: Vec<Block> = Vec::new();
    let mut methods: Vec<String> = Vec::new();
    let mut scenes: Vec<String> = Vec::new();
    for (lead, t) in rows {
        if !methods.contains(&t.method) {
            methods.push(t.method.clone());
        }
        if !scenes.contains(&t.scene) {
            scenes.push(t.scene.clone());
        }
        let Some(rec) = t.record() else {
            return Err(Error::results(
                dir,
                "frames.csv has no timing rounds (its round column is missing or empty: a run made before \
                 lodbench timed in rounds); compare pairs the methods round by round",
            ));
        };
        let at = blocks
            .iter()
            .position(|k| k.lead == lead && k.scene == rec.scene && k.count == rec.count);
        let block = match at {
            Some(i) => &mut blocks[i],
            None => {
                blocks.push(Block {
                    lead,
                    scene: rec.scene.clone(),
                    count: rec.count,
                    methods: Vec::new(),
                });
                let last = blocks.len() - 1;
                &mut blocks[last]
            }
        };
        match block.methods.iter_mut().find(|(m, _)| *m == rec.method) {
            Some((_, rows)) => rows.push(rec),
            None => block.methods.push((rec.method.clone(), vec![rec])),
        }
    }
    Ok(Grouped {
        blocks,
        methods,
        scenes,
    })
}

/// An error naming `dir` unless `name` is among the `listed` values of frames.csv's column `kind`.
fn require_listed(dir: &Path, kind: &str, name: &str, listed: &[String]) -> Result<()> {
    if !listed.iter().any(|x| x == name) {
        return Err(Error::results(
            dir,
            format!(
                "has no {kind} '{name}' in frames.csv; its {kind}s: {}",
                listed.join(", ")
            ),
        ));
    }
    Ok(())
}

/// A over B in `block` (named by `lead_header`'s values, its scene and count); None unless it holds both.
fn compare_block(
    lead_header: &[String],
    block: &Block,
    a: &str,
    b: &str,
) -> Option<BlockComparison> {
    let rows = |m: &str| {
        block
            .methods
            .iter()
            .find(|(x, _)| x == m)
            .map(|(_, r)| r.as_slice())
    };
    let (Some(ra), Some(rb)) = (rows(a), rows(b)) else {
        return None;
    };
    let clock = Clock::of(block.methods.iter().flat_map(|(_, r)| r));
    let name: Vec<String> = lead_header
        .iter()
        .zip(&block.lead)
        .map(|(h, v)| format!("{h}={v}"))
        .chain([block.scene.clone(), format!("count {}", block.count)])
        .collect();
    Some(BlockComparison {
        block: name.join(", "),
        scene: block.scene.clone(),
        count: block.count,
        clock,
        ratios: PairedRatios::new(ra, rb, clock),
    })
}

/// The lines `compare` prints for one block.
pub fn report(c: &BlockComparison, a: &str, b: &str) -> String {
    let rounds = c.ratios.all.map_or(0, |r| r.rounds);
    let mut out = format!(
        "{}: {a} over {b} ({}, {rounds} rounds)",
        c.block,
        c.clock.name()
    );
    for (what, r) in [
        ("all frames", c.ratios.all),
        ("transition", c.ratios.transition),
        ("steady", c.ratios.steady),
    ] {
        out.push_str(&format!("\n  {what:<11} {}", line(r, a)));
    }
    out
}

/// A ratio, its interval and the verdict.
fn line(r: Option<Ratio>, a: &str) -> String {
    let Some(r) = r else {
        return "-  (no such frames in both)".into();
    };
    let interval = r
        .ci95
        .map_or("-".to_string(), |(lo, hi)| format!("[{lo:.6}, {hi:.6}]"));
    let verdict = match r.different() {
        Some(true) if r.ratio > 1.0 => format!("different: {a} costs more"),
        Some(true) => format!("different: {a} costs less"),
        Some(false) => "not different: the interval holds 1.0".to_string(),
        None => "no interval (fewer than two rounds hold such frames)".to_string(),
    };
    format!(
        "{:.6} {interval:<22}  {verdict}  ({} rounds)",
        r.ratio, r.rounds
    )
}
