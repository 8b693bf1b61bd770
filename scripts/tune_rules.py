#!/usr/bin/env python3
"""Checks a `lodbench tune` result along camera paths, against the engines' rules.

    python3 scripts/tune_rules.py TUNE_DIR [--out DIR] [--profile quick] [--frames N] [--binary PATH]

TUNE_DIR is a folder `lodbench tune` wrote for a scene of one model (tune.json, rules.csv, tuned.glb). On the tuned
file, with the width and height tune measured at, this runs `lodbench run`:

  1. every default method along the file's own flight (`all-default/`) and along a diagonal approach
     (`all-diagonal/`): each method's largest lodpop per transition against the budget;
  2. `reference,discrete` once per rule (tune's own switch distances, then Unreal's, Godot's and meshoptimizer's
     from rules.csv, given as --switch-distances) along two paths that are the same for every rule: the axis the
     file's flight takes and the diagonal, both from where the model fits the view to a quarter beyond the farthest
     switch of any rule, in geometric steps (`<path>-<rule>/`), starting nearer where a rule switches nearer (down
     to 1.1 radii from the centre).

and writes into OUT (default TUNE_DIR/paths): rules_path.csv (per path and rule: the switch distances, the
transitions, the largest lodpop of discrete's transitions and which break the budget, mean triangles, and
discrete's frame time over the reference's, paired round by round within the run), methods_path.csv (per path and
method: the largest lodpop over the transitions) and report.md with both tables.

The budget must be a lodpop budget (a JOD budget's check is `lodbench perceptual` on the run folders). The
diagonal path looks from another direction than tune's first view, so it tests how well the views sample.
"""
import argparse
import csv
import json
import math
import subprocess
import sys
from pathlib import Path

from lodbench_results import RULES_CSV, SUMMARY_CSV, TRANSITIONS_CSV, TUNE_JSON, read_csv

DIAGONAL = (0.55, 0.45, 0.70)
RULES = ["tune", "unreal", "godot", "meshopt"]


def run(binary, args, quiet=True):
    done = subprocess.run([str(binary)] + args, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{binary} {' '.join(args)} failed:\n{done.stderr.strip()}")
    return done.stdout


def camera_eye(binary, scene, width, height, frame):
    out = run(binary, ["describe", "--scene", str(scene), "--width", str(width), "--height", str(height),
                       "--camera-json", str(frame)])
    return json.loads(out)["eye"]


def write_path(path: Path, centre, direction, near, far, frames):
    """A camera path looking at `centre` from `direction`, its distance growing geometrically from near to far."""
    n = math.sqrt(sum(c * c for c in direction))
    u = [c / n for c in direction]
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["frame", "x", "y", "z", "target_x", "target_y", "target_z"])
        for i in range(frames):
            d = near * (far / near) ** (i / max(frames - 1, 1))
            w.writerow([i] + [f"{centre[k] + u[k] * d:.6f}" for k in range(3)] + [f"{c:.6f}" for c in centre])


def summarise(folder: Path, budget: float):
    """Per method: (largest transition lodpop, [lodpop of each transition], mean triangles, paired ratio to the
    baseline with its interval)."""
    out = {}
    transitions = read_csv(folder / TRANSITIONS_CSV)
    for row in read_csv(folder / SUMMARY_CSV):
        m = row["method"]
        pops = [float(t["lodpop_max"]) for t in transitions if t["method"] == m and t["lodpop_max"] != ""]
        out[m] = {
            "lodpop_max": max(pops) if pops else 0.0,
            "transitions": len(pops),
            "over_budget": sum(p > budget for p in pops),
            "pops": pops,
            "triangles_mean": float(row["triangles_mean"]),
            "ratio": row["ratio_to_baseline"],
            "ratio_lo": row["ratio_to_baseline_ci95_lo"],
            "ratio_hi": row["ratio_to_baseline_ci95_hi"],
            "gpu_ms_median": row["gpu_ms_median"],
        }
    return out


def markdown(rows, columns):
    """A Markdown table of `rows` (dicts) in `columns`' order, a cell a row lacks left empty."""
    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(str(r.get(c, "")) for c in columns) + " |" for r in rows]
    return "\n".join(lines)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("tune_dir", type=Path)
    ap.add_argument("--out", type=Path)
    ap.add_argument("--profile", default="quick", help="lodbench run's --profile (default quick)")
    ap.add_argument("--frames", type=int, default=120, help="frames of each path (default 120)")
    ap.add_argument("--binary", type=Path, default=Path("target/release/lodbench"))
    args = ap.parse_args()
    meta_path = args.tune_dir / TUNE_JSON
    if not meta_path.is_file() or not (args.tune_dir / RULES_CSV).is_file():
        print(f"error: {args.tune_dir} has no tune.json and rules.csv (a lodbench tune folder?)", file=sys.stderr)
        return 2
    meta = json.loads(meta_path.read_text())
    budget = meta["settings"]["budget"]
    if budget["metric"] != "lodpop":
        print(f"error: {args.tune_dir}: a {budget['metric']} budget; this checks lodpop budgets (run lodbench "
              "perceptual on the run folders for a JOD one)", file=sys.stderr)
        return 2
    limit = float(budget["value"])
    models = [m for m in meta["models"] if m["pairs"]]
    if len(models) != 1:
        print(f"error: {args.tune_dir}: {len(models)} models with LOD pairs; --switch-distances sets every "
              "model's switches, so this checks scenes of one model", file=sys.stderr)
        return 2
    model = models[0]
    rules = read_csv(args.tune_dir / RULES_CSV)
    switches = {r: [float(x["distance"]) for x in sorted((x for x in rules if x["rule"] == r),
                                                           key=lambda x: int(x["lod_from"]))] for r in RULES}
    out = args.out or args.tune_dir / "paths"
    out.mkdir(parents=True, exist_ok=True)
    tuned = args.tune_dir / "tuned.glb"
    width, height = str(meta["width"]), str(meta["height"])
    common = ["--width", width, "--height", height, "--profile", args.profile, "--frames", str(args.frames)]
    # The flight starts where the scene fits the view, straight along +z from the model's centre.
    eye = camera_eye(args.binary, tuned, width, height, 0)
    centre = [eye[0], eye[1], eye[2] - model["near"]]
    far = 1.25 * max(max(v) for v in switches.values() if v)
    # From where the model fits the view, or nearer where a rule switches nearer (not within 1.1 radii: a switch
    # there is left off the path, and its transition missing from the table).
    nearest = min(min(v) for v in switches.values() if v)
    near = max(1.1 * model["radius"], min(model["near"], 0.9 * nearest))
    paths = {}
    for name, direction in (("axis", (0.0, 0.0, 1.0)), ("diagonal", DIAGONAL)):
        paths[name] = out / f"path-{name}.csv"
        write_path(paths[name], centre, direction, near, far, args.frames)
    rows, method_rows = [], []
    for label, extra in (("default", []), ("diagonal", ["--camera-path", str(paths["diagonal"])])):
        folder = out / f"all-{label}"
        run(args.binary, ["run", "--scene", str(tuned), "--out", str(folder)] + common + extra)
        for m, s in summarise(folder, limit).items():
            method_rows.append({"path": label, "method": m, "transitions": s["transitions"],
                                "lodpop_max": f"{s['lodpop_max']:.5f}", "budget": limit,
                                "over_budget": s["over_budget"]})
    for path_name, path in paths.items():
        for rule in RULES:
            folder = out / f"{path_name}-{rule}"
            extra = [] if rule == "tune" else ["--switch-distances", ",".join(f"{d:.6g}" for d in switches[rule])]
            run(args.binary, ["run", "--scene", str(tuned), "--method", "reference,discrete", "--baseline",
                              "reference", "--camera-path", str(path), "--out", str(folder)] + common + extra)
            s = summarise(folder, limit)["discrete"]
            rows.append({
                "path": path_name, "rule": rule,
                "switches": " ".join(f"{d:.3f}" for d in switches[rule]),
                "transitions": s["transitions"], "lodpop_max": f"{s['lodpop_max']:.5f}",
                "over_budget": s["over_budget"],
                "transition_lodpops": " ".join(f"{p:.4f}" for p in s["pops"]),
                "triangles_mean": f"{s['triangles_mean']:.0f}",
                "ratio_to_reference": s["ratio"], "ratio_ci95": f"{s['ratio_lo']}..{s['ratio_hi']}",
            })
    rule_cols = ["path", "rule", "switches", "transitions", "transition_lodpops", "lodpop_max", "over_budget",
                 "triangles_mean", "ratio_to_reference", "ratio_ci95"]
    method_cols = ["path", "method", "transitions", "lodpop_max", "budget", "over_budget"]
    for name, data, cols in (("rules_path.csv", rows, rule_cols), ("methods_path.csv", method_rows, method_cols)):
        with open(out / name, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=cols)
            w.writeheader()
            w.writerows(data)
    text = [f"# {meta['scene']}: tune's switches along paths (budget lodpop {limit:g})", "",
            f"{width}x{height}, profile {args.profile}, {args.frames} frames a path; `python3 scripts/tune_rules.py "
            f"{args.tune_dir} --profile {args.profile} --frames {args.frames}`.", "",
            "## Each rule's switches: discrete along the same paths", "",
            "ratio_to_reference: discrete's frame time over the reference's (LOD0 throughout), paired round by "
            "round within the run.", "", markdown(rows, rule_cols), "",
            "## Every method on the tuned file", "", markdown(method_rows, method_cols), ""]
    (out / "report.md").write_text("\n".join(text))
    print("\n".join(text))
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except RuntimeError as e:
        print(f"error: {e}", file=sys.stderr)
        sys.exit(2)
