"""The cost-popping frontier of an experiment folder that sweeps a method setting (scripts/plot.py calls it).

For each scene, each method is one curve across the swept setting (the last swept variable; any other swept
variable splits a method into several curves): cost on the x axis, the method's time over the baseline's on the
transition frames (summary.csv's ratio_to_baseline_transition, paired round by round with the baseline in the same
run; the all-frames ratio where a method has no transition frames), and popping on the y axis: the largest lodpop
(summary.csv's lodpop_max, the largest over the run's transitions), and, where `lodbench perceptual` wrote
perceptual.csv into the runs, the perceptual popping figure (the lowest jod_popping of the method's transitions;
10 = no visible change of LOD). A third panel gives the reference error (mean rmse) against the same cost.

The table "cheapest at or below a popping" reads, per scene and popping level (the baseline's own largest lodpop
times 1, 1/2, 1/4 and 1/8), the point of least cost whose lodpop_max is at or below it, and compares it with the
cheapest other method that meets the level in the same run, by that run's pairs.csv (the paired ratio on the
transition frames and its 95 % interval): "cheaper" or "dearer" only where the interval excludes 1, else "no
difference". Points of different runs are never ranked against each other (their rounds are not paired).
"""
from collections import OrderedDict
from pathlib import Path

import matplotlib.pyplot as plt
from matplotlib.lines import Line2D

import method_colours
from lodbench_results import PERCEPTUAL_CSV, num, read_csv, run_folder_of, save_figure

LEVELS = (1.0, 0.5, 0.25, 0.125)


def setting_key(v):
    """Swept values in numeric order where they are numbers."""
    x = num(v)
    return (0, x, "") if x == x else (1, 0.0, str(v))


def perceptual_popping(folder: Path, variables, values):
    """{(scene, method, count): lowest jod_popping over transitions} of the run's perceptual.csv, or {}."""
    path = run_folder_of(folder, variables, values) / PERCEPTUAL_CSV
    if not path.is_file():
        return {}
    out = {}
    for r in read_csv(path):
        key = (r["scene"], r["method"], r["count"])
        out[key] = min(out.get(key, float("inf")), num(r["jod_popping"]))
    return out


def points(folder: Path, summary, variables):
    """One point per summary row with a ratio: scene, method, the run (its swept values), the setting (the last
    swept value), the series (method and the other swept values), cost, lodpop, rmse, jod (or nan)."""
    curve = variables[-1] if variables else None
    jods = {}
    out = []
    for r in summary:
        run = tuple(r[v] for v in variables)
        if run not in jods:
            jods[run] = perceptual_popping(folder, variables, run)
        x = num(r.get("ratio_to_baseline_transition"))
        if x != x:
            x = num(r.get("ratio_to_baseline"))
        others = [f"{v} {r[v]}" for v in variables[:-1]]
        every = [f"{v} {r[v]}" for v in variables]
        out.append({
            "scene": r["scene"], "method": r["method"], "count": r["count"], "run": run,
            "setting": r[curve] if curve else "", "series": r["method"] + (f" ({', '.join(others)})" if others else ""),
            "label": r["method"] + (f" ({', '.join(every)})" if every else ""),
            "cost": x, "lodpop": num(r.get("lodpop_max")), "rmse": num(r.get("rmse_mean")),
            "jod": jods[run].get((r["scene"], r["method"], r["count"]), float("nan")),
            "baseline": r.get("baseline", ""),
        })
    return out


def figure(scene, pts, curve, path):
    """Cost against lodpop_max, against the perceptual popping where measured, and against mean rmse: a curve
    per series across the setting, each point labelled with its setting."""
    panels = [("lodpop", "largest lodpop (lower: less popping)")]
    if any(p["jod"] == p["jod"] for p in pts):
        panels.append(("jod", "lowest JOD of popping (10: invisible)"))
    panels.append(("rmse", "mean rmse against the reference"))
    fig, axes = plt.subplots(1, len(panels), figsize=(5.2 * len(panels), 4.4))
    series = list(OrderedDict.fromkeys(p["series"] for p in pts))
    colours = method_colours.series_colours(series)
    for s in series:
        line = sorted((p for p in pts if p["series"] == s), key=lambda p: setting_key(p["setting"]))
        for ax, (col, _) in zip(axes, panels):
            xs = [p["cost"] for p in line]
            ys = [p[col] for p in line]
            ax.plot(xs, ys, marker="o", color=colours[s], alpha=0.85)
            for p in line:
                if p["cost"] == p["cost"] and p[col] == p[col]:
                    ax.annotate(p["setting"], (p["cost"], p[col]), fontsize=6, xytext=(3, 3),
                                textcoords="offset points", color=colours[s])
    baseline = next((p["baseline"] for p in pts if p["baseline"]), "the baseline")
    for ax, (_, label) in zip(axes, panels):
        ax.set_xlabel(f"cost: time over {baseline}'s, transition frames")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    handles = [Line2D([], [], color=colours[s], marker="o", label=s) for s in series]
    fig.legend(handles=handles, loc="center right", fontsize=7, frameon=False)
    fig.suptitle(f"{scene}: cost against popping across {curve or 'the run'} (points labelled with {curve})")
    fig.tight_layout(rect=(0, 0, 0.84, 1))
    save_figure(fig, path, dpi=110)
    plt.close(fig)


def paired(pairs, variables, run, scene, count, a, b):
    """a's time over b's on the transition frames of run `run`, from pairs.csv: (ratio, lo, hi) or None."""
    for r in pairs:
        if r["scene"] != scene or r["count"] != count or tuple(r[v] for v in variables) != run:
            continue
        if (r["method_a"], r["method_b"]) == (a, b):
            return num(r["ratio_transition"]), num(r["ratio_transition_ci95_lo"]), num(r["ratio_transition_ci95_hi"])
        if (r["method_a"], r["method_b"]) == (b, a):
            ratio, lo, hi = (num(r["ratio_transition"]), num(r["ratio_transition_ci95_lo"]),
                             num(r["ratio_transition_ci95_hi"]))
            return 1 / ratio, 1 / hi, 1 / lo
    return None


def cheapest(scene, pts, pairs, variables):
    """The rows of the "cheapest at or below a popping" table of `scene` (dicts, columns in COLUMNS); each point is
    named by its method and every swept value."""
    base = sorted(p["lodpop"] for p in pts if p["method"] == p["baseline"] and p["lodpop"] == p["lodpop"])
    if not base:
        return []
    level0 = base[len(base) // 2]
    rows = []
    for f in LEVELS:
        level = level0 * f
        ok = [p for p in pts if p["lodpop"] == p["lodpop"] and p["lodpop"] <= level and p["cost"] == p["cost"]]
        row = {"lodpop at most": f"{level:.4g} ({f:g} x {pts[0]['baseline']})"}
        if not ok:
            rows.append({**row, "cheapest": "none meets it"})
            continue
        best = min(ok, key=lambda p: p["cost"])
        row["cheapest"] = best["label"]
        row["cost"] = f"{best['cost']:.3f}"
        same_run = [p for p in ok if p["run"] == best["run"] and p["method"] != best["method"]]
        if not same_run:
            rows.append({**row, "next in the same run": "none meets it", "paired": ""})
            continue
        other = min(same_run, key=lambda p: p["cost"])
        row["next in the same run"] = other["method"]
        r = paired(pairs, variables, best["run"], scene, best["count"], best["method"], other["method"])
        if r is None or any(x != x for x in r):
            row["paired"] = "no paired ratio"
        else:
            ratio, lo, hi = r
            verdict = "cheaper" if hi < 1 else "dearer" if lo > 1 else "no difference"
            row["paired"] = f"{ratio:.3f} [{lo:.3f}, {hi:.3f}]: {verdict}"
        rows.append(row)
    return rows


COLUMNS = ["lodpop at most", "cheapest", "cost", "next in the same run", "paired"]
# "cheapest" is the least cost by point estimate, across runs; only the "paired" column tests a difference.
