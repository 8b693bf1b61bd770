#!/usr/bin/env python3
"""Where the adapter changed speed during a block, and what the clock warm-up did, from run.json alone.

Every run reads the triangle probe just before and just after each block (run.json's `triangle_rate_before` and
`triangle_rate_after`); where the two differ by more than a fifth the adapter changed speed during the block
(`measure::probe_rounds::clock_changed`), and the block's times are suspect. With `--clock-warmup` on, each
method's warm-ups before its timed segments are recorded too (`clock_warmup_ms`, `clock_warmups_short`).

Prints a table per run folder (a folder, or every run.json under it: an experiment's runs), a row per block:
the two readings, their ratio, whether the rate changed, and the warm-ups' total time and how many ended short
of their target. `scripts/gpu-suite.sh` runs terrain-equal-error with and without the warm-up and lists both, to
see whether the warm-up prevents the H200's slow block.

Usage:
    python3 scripts/clock_drops.py DIR [DIR ...]
Exits 1 when a folder holds no run.json.
"""
import json
import sys
from pathlib import Path

# A change of more than a fifth either way: src/measure/probe_rounds.rs's CLOCK_CHANGED_BELOW (its test reads both).
CHANGED_BELOW = 0.8


def changed(before, after):
    if not (isinstance(before, (int, float)) and isinstance(after, (int, float))):
        return None
    lo, hi = min(before, after), max(before, after)
    return hi > 0 and lo / hi < CHANGED_BELOW


def block_rows(run: dict):
    """A row per (scene, count): the readings around the block and its methods' warm-ups summed."""
    rows = {}
    for b in run.get("blocks", []):
        key = (b.get("scene"), b.get("count"))
        r = rows.setdefault(key, {"scene": key[0], "count": key[1], "before": b.get("triangle_rate_before"),
                                  "after": b.get("triangle_rate_after"), "warmup_ms": None, "short": None,
                                  "methods": 0})
        r["methods"] += 1
        if b.get("clock_warmup_ms") is not None:
            r["warmup_ms"] = (r["warmup_ms"] or 0.0) + b["clock_warmup_ms"]
            r["short"] = (r["short"] or 0) + (b.get("clock_warmups_short") or 0)
    return list(rows.values())


def fmt(v, spec=".3g"):
    return "" if v is None else format(v, spec)


def table(path: Path, run: dict) -> list:
    lines = [f"## {path.parent}", "",
             f"adapter: {(run.get('adapter') or {}).get('name', '?')}; clock warm-up: {run.get('clock_warmup')}", "",
             "| scene | count | methods | rate before | rate after | after / before | changed | warm-up ms | "
             "warm-ups short |", "|---|---|---|---|---|---|---|---|---|"]
    for r in block_rows(run):
        b, a = r["before"], r["after"]
        ratio = a / b if isinstance(a, (int, float)) and isinstance(b, (int, float)) and b > 0 else None
        c = changed(b, a)
        lines.append(f"| {r['scene']} | {r['count']} | {r['methods']} | {fmt(b)} | {fmt(a)} | {fmt(ratio)} | "
                     f"{'' if c is None else ('yes' if c else 'no')} | {fmt(r['warmup_ms'], '.0f')} | "
                     f"{fmt(r['short'], 'd')} |")
    return lines + [""]


def main(argv):
    if not argv or argv[0] in ("-h", "--help"):
        print(__doc__)
        return 0 if argv else 2
    status = 0
    for folder in map(Path, argv):
        found = sorted(folder.rglob("run.json")) if folder.is_dir() else []
        if not found:
            print(f"error: {folder}: no run.json in it (a `lodbench run` or `experiment` folder)", file=sys.stderr)
            status = 1
            continue
        for path in found:
            try:
                run = json.loads(path.read_text())
            except (OSError, json.JSONDecodeError) as e:
                print(f"error: {path}: not readable as JSON ({e})", file=sys.stderr)
                status = 1
                continue
            print("\n".join(table(path, run)))
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
