#!/usr/bin/env python3
"""The A/A check of lodbench's timing comparisons, recomputed from the CSVs alone.

Reads one or more results folders of runs that list a method twice (`--method discrete,discrete`, e.g. the
experiments `scenes/experiments/cpu/aa-*.toml`, whose merged CSVs carry a `seed` column) and reports, over
every block of a method measured against itself, how often each rule calls the two "different":

- `t over rounds` (lodbench's rule): summary.csv's `ratio_to_baseline` interval excludes 1.0. The script
  recomputes that interval from rounds.csv (geometric mean of the per-round ratios, Student-t over rounds) and
  fails when it disagrees with summary.csv.
- `bootstrap over rounds`: a percentile bootstrap of the same geometric mean, resampling rounds.
- `frame bootstrap` (the rule before rounds): the 95 % percentile-bootstrap intervals of the two methods'
  median gpu_ms, frames resampled as if independent, do not overlap (from frames.csv, when the folder has it).

At 95 % a rule that holds its level calls about 5 % of A/A blocks different.

Usage:
    python3 scripts/aa_check.py DIR [DIR ...] [--resamples 2000] [--seed 1]
"""
import argparse
import math
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

from lodbench_results import FRAMES_CSV, ROUNDS_CSV, SUMMARY_CSV, read_csv

# Student's t quantile 0.975 (as src/measure/stats.rs).
T975 = [12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160, 2.145, 2.131,
        2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042]


def t975(df: int) -> float:
    return T975[df - 1] if df <= 30 else 1.96 + 2.4 / df


def t_interval(logs):
    """Geometric mean of exp(logs) and its Student-t 95 % interval (None with fewer than two values)."""
    logs = np.asarray(logs, dtype=float)
    m = float(logs.mean())
    if len(logs) < 2:
        return math.exp(m), None
    half = t975(len(logs) - 1) * float(logs.std(ddof=1)) / math.sqrt(len(logs))
    return math.exp(m), (math.exp(m - half), math.exp(m + half))


def bootstrap_interval(logs, rng, resamples):
    logs = np.asarray(logs, dtype=float)
    idx = rng.integers(0, len(logs), size=(resamples, len(logs)))
    means = logs[idx].mean(axis=1)
    return math.exp(np.percentile(means, 2.5)), math.exp(np.percentile(means, 97.5))


def median_interval(values, rng, resamples):
    values = np.asarray(values, dtype=float)
    idx = rng.integers(0, len(values), size=(resamples, len(values)))
    medians = np.median(values[idx], axis=1)
    return np.percentile(medians, 2.5), np.percentile(medians, 97.5)


def block_key(row):
    return tuple(row.get(k, "") for k in ("seed", "viewport", "scene", "count"))


def check(folder: Path, resamples: int, seed: int):
    """Per A/A block of `folder`: (key, method, ratio, t interval, bootstrap interval, frame-rule different).
    Raises ValueError when summary.csv's interval is not the one rounds.csv gives."""
    rng = np.random.default_rng(seed)
    summary = read_csv(folder / SUMMARY_CSV)
    rounds = read_csv(folder / ROUNDS_CSV)
    # frames.csv is optional (committed results leave it out for size): without it the frame rule is not computed.
    frames = read_csv(folder / FRAMES_CSV) if (folder / FRAMES_CSV).is_file() else []
    per_round = defaultdict(list)
    for r in rounds:
        if r["ratio_to_baseline"]:
            per_round[block_key(r) + (r["method"],)].append(float(r["ratio_to_baseline"]))
    times = defaultdict(list)
    for r in frames:
        if r["gpu_ms"]:
            times[block_key(r) + (r["method"],)].append(float(r["gpu_ms"]))
    out = []
    for s in summary:
        method, baseline = s["method"], s.get("baseline", "")
        if not baseline or method == baseline or method.split("#")[0] != baseline.split("#")[0]:
            continue
        key = block_key(s)
        logs = [math.log(x) for x in per_round[key + (method,)]]
        ratio, t_ci = t_interval(logs)
        got = (float(s["ratio_to_baseline"]), s["ratio_to_baseline_ci95_lo"], s["ratio_to_baseline_ci95_hi"])
        if abs(got[0] - ratio) > 1e-9 * ratio or (t_ci and (abs(float(got[1]) - t_ci[0]) > 1e-9
                                                          or abs(float(got[2]) - t_ci[1]) > 1e-9)):
            raise ValueError(f"{folder} {key} {method}: summary.csv says {got}, rounds.csv gives {ratio} {t_ci}")
        boot = bootstrap_interval(logs, rng, resamples) if len(logs) >= 2 else None
        a, b = times.get(key + (baseline,)), times.get(key + (method,))
        frame_rule = None
        if a and b:
            (alo, ahi), (blo, bhi) = median_interval(a, rng, resamples), median_interval(b, rng, resamples)
            frame_rule = ahi < blo or bhi < alo
        out.append((key, method, ratio, t_ci, boot, frame_rule))
    return out


def excludes_one(ci):
    return ci is not None and (ci[0] > 1.0 or ci[1] < 1.0)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dirs", nargs="+", type=Path)
    ap.add_argument("--resamples", type=int, default=2000)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args(argv)
    print("| folder | A/A blocks | t over rounds: excludes 1 | bootstrap over rounds: excludes 1 | "
          "frame bootstrap: disjoint | median ratio | median t half-width |")
    print("|---|---|---|---|---|---|---|")
    pooled = []
    for folder in args.dirs:
        for name in (SUMMARY_CSV, ROUNDS_CSV):
            if not (folder / name).is_file():
                print(f"error: {folder / name} is missing", file=sys.stderr)
                return 2
        try:
            blocks = check(folder, args.resamples, args.seed)
        except ValueError as e:
            print(f"error: {e}", file=sys.stderr)
            return 1
        if not blocks:
            print(f"error: {folder} holds no method measured against itself (--method NAME,NAME)", file=sys.stderr)
            return 2
        pooled += blocks
        row(folder.name, blocks)
    if len(args.dirs) > 1:
        row("all", pooled)
    return 0


def row(name, blocks):
    """One line of the table: how often each rule calls the A/A blocks different."""
    n = len(blocks)
    t_ex = sum(excludes_one(b[3]) for b in blocks)
    boot_ex = sum(excludes_one(b[4]) for b in blocks)
    framed = [b[5] for b in blocks if b[5] is not None]
    frame_cell = f"{sum(framed)} of {len(framed)}" if framed else "- (no frames.csv)"
    half = [(b[3][1] - b[3][0]) / 2 for b in blocks if b[3]]
    print(f"| {name} | {n} | {t_ex} ({100 * t_ex / n:.0f} %) | {boot_ex} ({100 * boot_ex / n:.0f} %) | "
          f"{frame_cell} | {np.median([b[2] for b in blocks]):.3f} | "
          f"{np.median(half) if half else float('nan'):.3f} |")


if __name__ == "__main__":
    sys.exit(main())
