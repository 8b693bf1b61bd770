"""Methods compared at equal reference error, from an experiment folder that sweeps the pixel error.

    python3 scripts/equal_error.py RESULTS_DIR [--levels 0.006,0.008,...] [--out DIR]

RESULTS_DIR is what `lodbench experiment` wrote for a sweep of one variable (summary.csv with that variable's
column, as scenes/experiments/cpu/terrain-equal-error-ci.toml makes it). For each scene and method the sweep is a
curve of points (mean rmse against the reference, triangles, cost, largest lodpop, largest crack count); this
script reads every curve at the same mean rmse levels, interpolating linearly in rmse between the two sweep
points that bracket a level (none where the level lies outside the method's sweep: never extrapolated).

Cost is summary.csv's ratio_to_baseline (all frames), which `lodbench run` pairs round by round with the
baseline of the same run; with the reference as the baseline (the one method whose frame does not change with the
pixel error) it is a fraction of the same reference in every run, so the curves share a unit. It is on the GPU
clock where the adapter has timestamps, which leaves out what a method does on the CPU (ROAM's update); the
CPU-clock cost is the same pairing on frames.csv's cpu_ms (encode to completion), computed here from the runs'
frames.csv (empty where they are not kept). Two methods read at
one rmse level come from different runs (different pixel errors), whose rounds are not paired: the table is a
description, not a ranking; a paired comparison of two methods exists only within one run (pairs.csv).

Writes equal_error.csv and equal_error.png into --out (default RESULTS_DIR) and prints the table in Markdown.
Default levels: four, evenly spaced in log between the largest of the methods' smallest rmse and the smallest of
their largest, so that every method's curve spans every level.
"""
import argparse
import csv
import math
import sys
from collections import OrderedDict
from pathlib import Path

from lodbench_results import FRAMES_CSV, SUMMARY_CSV, num, read_csv, run_folder_of, save_figure

COLUMNS = (
    ("triangles", "triangles_mean"),
    ("cost", "ratio_to_baseline"),
    ("cpu_cost", None),
    ("lodpop_max", "lodpop_max"),
    ("crack_px_max", "crack_px_max"),
    ("variable", None),
)


def cpu_ratios(frames_csv: Path):
    """{(scene, method): geometric mean over rounds of the method's median cpu_ms over the round's frames divided by
    the baseline's over the same frames} from one run's frames.csv and summary.csv (the baseline's name): the
    paired ratio on the CPU clock, which holds the work a method does on the CPU (ROAM's update), where
    summary.csv's ratio is on the GPU clock whenever timestamps exist. Empty without frames.csv."""
    if not frames_csv.is_file():
        return {}
    from aa_check import t_interval

    baseline = {(r["scene"], r["count"]): r.get("baseline") for r in read_csv(frames_csv.parent / SUMMARY_CSV)}
    times = {}
    for r in read_csv(frames_csv):
        key = (r["scene"], r["count"], r["method"], r["round"])
        times.setdefault(key, []).append(float(r["cpu_ms"]))
    med = {k: sorted(v)[len(v) // 2] if len(v) % 2 else sum(sorted(v)[len(v) // 2 - 1: len(v) // 2 + 1]) / 2
           for k, v in times.items()}
    logs = {}
    for (scene, count, method, rnd), t in med.items():
        b = med.get((scene, count, baseline.get((scene, count)), rnd))
        if b:
            logs.setdefault((scene, method), []).append(math.log(t / b))
    return {k: t_interval(v)[0] for k, v in logs.items()}


def curves(rows, variable, folder=None):
    """{scene: {method: [point, ...]}} with each point's rmse, the swept value and COLUMNS, sorted by rmse; the
    baseline itself is left out (its cost is 1 by definition). `folder`: the experiment folder, whose runs'
    frames.csv give the CPU-clock cost (NaN without them)."""
    out = OrderedDict()
    cpu = {}
    for r in rows:
        if r["method"] == r.get("baseline") or r["method"] == "reference":
            continue
        run = r[variable]
        if folder is not None and run not in cpu:
            cpu[run] = cpu_ratios(run_folder_of(folder, [variable], [run]) / FRAMES_CSV)
        p = {"rmse": num(r["rmse_mean"]), "variable": num(r[variable])}
        p["cpu_cost"] = cpu.get(run, {}).get((r["scene"], r["method"]), float("nan"))
        for name, col in COLUMNS:
            if col is not None:
                p[name] = num(r.get(col))
        if p["rmse"] != p["rmse"]:
            continue
        out.setdefault(r["scene"], OrderedDict()).setdefault(r["method"], []).append(p)
    for methods in out.values():
        for pts in methods.values():
            pts.sort(key=lambda p: p["rmse"])
    return out


def at(points, level):
    """The curve read at rmse `level`: each column interpolated linearly between the two points that bracket it
    (crack_px_max: the larger of the two), or None outside the curve."""
    for a, b in zip(points, points[1:] + points[-1:]):
        if a["rmse"] <= level <= b["rmse"]:
            t = 0.0 if b["rmse"] == a["rmse"] else (level - a["rmse"]) / (b["rmse"] - a["rmse"])
            out = {"rmse": level}
            for name, _ in COLUMNS:
                out[name] = (
                    max(a[name], b[name]) if name == "crack_px_max" else a[name] + t * (b[name] - a[name])
                )
            return out
    return None


def default_levels(methods, n=4):
    lo = max(pts[0]["rmse"] for pts in methods.values())
    hi = min(pts[-1]["rmse"] for pts in methods.values())
    if not (lo > 0 and hi >= lo):
        return []
    if n == 1 or hi == lo:
        return [lo]
    inner = [math.exp(math.log(lo) + (math.log(hi) - math.log(lo)) * i / (n - 1)) for i in range(1, n - 1)]
    return [lo] + inner + [hi]  # the ends exact, so that rounding never puts them outside a curve


def table(scene, methods, levels, variable):
    lines = [
        f"| {scene}: rmse | method | {variable} | triangles | cost (x reference) | CPU-clock cost | largest lodpop | "
        "cracks |",
        "|---|---|---|---|---|---|---|---|",
    ]
    rows = []
    for level in levels:
        for m, pts in methods.items():
            v = at(pts, level)
            rows.append((scene, level, m, v))
            if v is None:
                lines.append(f"| {level:.5f} | {m} | - | - | - | - | - | - |")
            else:
                lines.append(
                    f"| {level:.5f} | {m} | {v['variable']:.2f} | {v['triangles']:,.0f} | {v['cost']:.3f} | "
                    f"{v['cpu_cost']:.3f} | {v['lodpop_max']:.5f} | {v['crack_px_max']:.0f} |"
                )
    return lines, rows


def figure(scene_curves, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    import method_colours

    scenes = list(scene_curves)
    fig, axes = plt.subplots(len(scenes), 4, figsize=(18, 4 * len(scenes)), squeeze=False)
    for row, scene in zip(axes, scenes):
        colours = method_colours.series_colours(scene_curves[scene])  # as in plot.py's figures
        for m, pts in scene_curves[scene].items():
            x = [p["rmse"] for p in pts]
            for ax, name, label in zip(
                row,
                ("triangles", "cost", "cpu_cost", "lodpop_max"),
                ("triangles (mean)", "cost, GPU clock (x reference, paired)", "cost, CPU clock (x reference, paired)",
                 "largest lodpop"),
            ):
                ax.plot(x, [p[name] for p in pts], marker="o", label=m, color=colours[m])
                ax.set_xlabel("mean rmse against the reference")
                ax.set_ylabel(label)
                ax.set_title(f"{scene}: {label}")
        row[0].set_yscale("log")
        row[0].legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("results")
    ap.add_argument("--levels", help="comma-separated mean rmse levels (default: four spanning every curve)")
    ap.add_argument("--out", help="folder for equal_error.csv and .png (default: RESULTS)")
    a = ap.parse_args(argv)
    folder = Path(a.results)
    summary = folder / SUMMARY_CSV
    if not summary.is_file():
        sys.exit(f"error: {summary} not found: give the folder `lodbench experiment` wrote")
    rows = read_csv(summary)
    # The swept variables are the columns before `scene` (lodbench experiment writes them first).
    header = list(rows[0].keys()) if rows else []
    variables = header[: header.index("scene")] if "scene" in header else []
    if len(variables) != 1:
        sys.exit(f"error: {summary}: expected one swept variable, found {variables or 'none'}")
    variable = variables[0]
    levels = [float(x) for x in a.levels.split(",")] if a.levels else None
    out_dir = Path(a.out) if a.out else folder
    all_rows = []
    scene_curves = curves(rows, variable, folder)
    if not scene_curves:
        sys.exit(f"error: {summary} holds no method with an rmse (a run with --quality off?)")
    for scene, methods in scene_curves.items():
        lv = levels or default_levels(methods)
        lines, rows_out = table(scene, methods, lv, variable)
        print("\n".join(lines))
        print()
        all_rows += rows_out
    with open(out_dir / "equal_error.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["scene", "rmse", "method", variable, "triangles", "cost", "cpu_cost", "lodpop_max", "crack_px_max"])
        for scene, level, m, v in all_rows:
            if v is None:
                w.writerow([scene, f"{level:.6g}", m, "", "", "", "", "", ""])
            else:
                w.writerow(
                    [scene, f"{level:.6g}", m]
                    + [f"{v[k]:.6g}"
                       for k in ("variable", "triangles", "cost", "cpu_cost", "lodpop_max", "crack_px_max")]
                )
    figure(scene_curves, out_dir / "equal_error.png")
    print(f"wrote {out_dir / 'equal_error.csv'} and {out_dir / 'equal_error.png'}")


if __name__ == "__main__":
    main()
