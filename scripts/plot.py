#!/usr/bin/env python3
"""Figures and a report from a lodbench results folder.

    python3 scripts/plot.py RESULTS_DIR [RESULTS_DIR ...]

Writes into each folder a `figures/` subfolder, `report.md` (the summary table and every figure that folder's
data allows) and `report.html` (the same tables and figures, the run's manifest and, where `lodbench clips FOLDER`
wrote `clips/`, a player per transition stepping through the methods' frames side by side; self-contained: it loads
nothing but the folder's own files, see scripts/report_html.py):
  - sweep_<scene>.png       rmse, pop and lodpop along the path per method, and FSI's lag_rmse, discrete LOD switch
                            frames marked;
  - fig6_<scene>.png        Sheliemietiev et al. 2023 Fig. 6: popping per method (mean rmse, max pop, max lodpop;
                            bunny-sweep or any moving scene);
  - transitions_<scene>.png per transition of the path (up to 16), the largest lodpop and pop of each method (from
                            transitions.csv: the transition's frames and the 2 after; older folders without it: the
                            largest pop within 5 frames), also as tables in report.md;
  - fig5_<scene>.png        Sheliemietiev et al. 2023 Fig. 5: median frame time against instance count per method
                            (scenes run with several --count values, e.g. bunny-grid), with bootstrap 95 % intervals;
  - cost_<scene>.png        error against cost: mean rmse and max pop against median GPU time, per method;
  - contact_<scene>.png     three dumped frames around one transition per method with their error heat-maps, cropped
                            to where the scene is (runs with --dump-frames); `--transition worst` (default: the
                            frame where the methods' rmse differ most), `first`, or N (the N-th along the path).
  - fsi_buffers_<scene>.png FSI's two LOD buffers and the combined frame, at the dumped frame with the most instances
                            in transition (ties: the largest rmse), cropped (an fsi method run with --dump-frames).
  - fig8_<scene>.png        Scherzer & Wimmer 2008 Fig. 8: median frame time against viewport size per method
                            (experiment folders sweeping `viewport`, e.g. `lodbench experiment` with [sweep] variable =
                            "viewport").
  - unified_<scene>.png     unified LOD (experiment folders sweeping `pixel-error`, e.g.
                            scenes/experiments/unified-lod.toml): mean triangles, largest lodpop and mean crack pixels
                            against the pixel error, per method.
  - frontier_<scene>.png    experiment folders sweeping anything but the viewport (e.g.
                            scenes/experiments/cpu/frontier-ci.toml, a band sweep): each method's cost (paired ratio to
                            the baseline on transition frames) against its largest lodpop, the perceptual popping
                            figure where `lodbench perceptual` ran, and mean rmse, one curve across the last swept
                            variable; with the table "cheapest at or below a popping" (scripts/frontier.py).
A `lodbench tune` folder (tune.csv, tune.json, rules.csv) gets instead:
  - tune_<model>.png        per LOD pair of the model, each view's curve of the budget's figure (lodpop, or JOD with
                            --budget-jod) against distance, the budget, tune's switch and where Unreal's, Godot's and
                            meshoptimizer's rules would switch; with report.md, the switch table and rules.csv's.
Experiment folders carry the swept variables as the first CSV columns, one per sweep. A lone `viewport` sweep gets
fig8 and a lone `pixel-error` sweep the unified figure, and their first value in the other figures; any other sweep
(`fsi-check`, `noise`, ..., or several crossed) makes each (method, values) combination its own series, labelled
`method (variable value, ...)`. A merged folder (`lodbench merge`) has an `adapter` column after it:
with more than one adapter (`merge --allow-adapters`) each (method, adapter) pair is its own series, labelled
`method [adapter]`, so no curve mixes two GPUs.
Every figure draws a method in its one colour (scripts/method_colours.py), the same in all of them, and a method's
further series (a repeat `NAME#2`, another adapter, other swept values) in shades of it.

The answer report.md and report.html lead with (per scene: which method pops least, which is the cheapest within
the popping budget, and the decision table) is the folder's answer.json, as the binary wrote it (src/results/answer/:
`lodbench run`, `experiment`, `merge` and `perceptual` write it, word for word what `lodbench run` prints). A folder
without one (made before the binary wrote it), or with a perceptual.csv newer than it, gets it first from
`lodbench answer FOLDER`: the binary is $LODBENCH (or $LODBENCH_BIN), else target/release/lodbench of this
repository (under $CARGO_TARGET_DIR where set), else `lodbench` on the PATH.
After the answer, "Visible pops": what the pops are measured in (JNDs of the run's `--calibration`, from run.json's
config.calibration, each run's in an experiment or merged folder, a simulated observer said to be one; else not
calibrated, plain lodpop) and per method its largest lodpop (in JNDs where calibrated) beside its visible pops per
minute (summary.csv's pop_events, visible_pop_threshold, visible_pops_per_min; a folder made before them says they
were not measured).
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
from collections import OrderedDict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402
from PIL import Image  # noqa: E402

import frontier  # noqa: E402  (scripts/frontier.py, beside this file)
import method_colours  # noqa: E402  (scripts/method_colours.py, beside this file)
import report_html  # noqa: E402  (scripts/report_html.py, beside this file)
from lodbench_results import (  # noqa: E402  (scripts/lodbench_results.py, beside this file)
    ANSWER_JSON,
    FRAMES_CSV,
    PAIRS_CSV,
    PERCEPTUAL_CSV,
    RULES_CSV,
    RUNS_DIR,
    SUMMARY_CSV,
    TRANSITIONS_CSV,
    TUNE_CSV,
    TUNE_JSON,
    part_text,
    ratio_text,
    read_csv,
    save_figure,
    sentence_text,
    sig3,
    thousands,
)

# Every figure colours a method by method_colours.series_colours (one colour per method across the figures);
# what is not a method (a budget line, a metric) is grey or told apart by hatching, never a method's colour.
# Fig. 6's and the ceilings' bars per measure: plain, then hatched.
HATCHES = ("", "///", "...")


def num(v):
    """A cell as a float, nan where empty; unlike lodbench_results.num, a cell that is not a number is an error."""
    return float(v) if v not in ("", None) else float("nan")


def group(rows, *keys):
    out = OrderedDict()
    for r in rows:
        out.setdefault(tuple(r[k] for k in keys), []).append(r)
    return out


def switch_frames(rows):
    """Frames where the LOD a hard switch shows changes (lod_mean crosses a half-integer)."""
    lod = [round(num(r["lod_mean"])) for r in rows]
    return [i for i in range(1, len(lod)) if lod[i] != lod[i - 1]]


def save(fig, path, palette=True):
    fig.tight_layout()
    save_figure(fig, path, dpi=110, palette=palette)
    plt.close(fig)


def sweep_figure(scene, by_method, path):
    has_lodpop = "lodpop" in next(iter(by_method.values()))[0]
    lagged = [m for m, rows in by_method.items() if rows and rows[0].get("lag_rmse", "") != ""]
    panels = 2 + has_lodpop + bool(lagged)
    fig, axes = plt.subplots(panels, 1, figsize=(10, 3 + 2.8 * (panels - 1)), sharex=True)
    first = next(iter(by_method.values()))
    for f in switch_frames(first):
        for ax in axes:
            ax.axvline(f, color="0.85", lw=0.8, zorder=0)
    colours = method_colours.series_colours(by_method)
    for method, rows in by_method.items():
        frames = [int(r["frame"]) for r in rows]
        c = colours[method]
        axes[0].plot(frames, [num(r["rmse"]) for r in rows], lw=0.9, label=method, color=c)
        axes[1].plot(frames, [num(r["pop"]) for r in rows], lw=0.9, label=method, color=c)
        if has_lodpop:
            axes[2].plot(frames, [num(r["lodpop"]) for r in rows], lw=0.9, label=method, color=c)
    axes[0].set_ylabel("rmse (Sheliemietiev et al. 2023 sec. 6)")
    axes[1].set_ylabel("pop (motion included)")
    if has_lodpop:
        axes[2].set_ylabel("lodpop (pose held)")
    if lagged:
        for method in lagged:
            rows = by_method[method]
            axes[-1].plot([int(r["frame"]) for r in rows], [num(r["lag_rmse"]) for r in rows], lw=0.9,
                          label=method, color=colours[method])
        axes[-1].set_ylabel("lag_rmse (fsi*)")
        axes[-1].legend(fontsize=8)
    axes[-1].set_xlabel("frame (grey: discrete LOD switches)")
    axes[0].legend(ncol=4, fontsize=8)
    axes[0].set_title(f"{scene}: error along the path")
    save(fig, path)


def fig6(scene, summary, path):
    methods = [r["method"] for r in summary]
    x = np.arange(len(methods))
    fig, ax = plt.subplots(figsize=(9, 4))
    bars = [("rmse_mean", "mean rmse"), ("pop_max", "max pop"), ("lodpop_max", "max lodpop")]
    bars = [(c, label) for c, label in bars if c in summary[0]]
    w = 0.8 / len(bars)
    colours = method_colours.series_colours(methods)
    for i, (c, _) in enumerate(bars):
        # The method's colour (as in every figure), the measure by its hatching.
        ax.bar(x - 0.4 + (i + 0.5) * w, [num(r[c]) for r in summary], w, color=[colours[m] for m in methods],
               hatch=HATCHES[i], edgecolor="white", linewidth=0)
    ax.set_xticks(x, methods, rotation=20)
    ax.set_title(f"{scene}: popping per method (cf. Sheliemietiev et al. 2023 Fig. 6)")
    ax.legend(handles=[Patch(facecolor="0.6", edgecolor="white", hatch=HATCHES[i], label=label)
                       for i, (_, label) in enumerate(bars)])
    save(fig, path)


# Frames either side of a transition that count as its own in the per-transition pop figure and table.
TRANSITION_WINDOW = 5


def transition_pops(by_method, window=TRANSITION_WINDOW):
    """Per transition of the path (episodes with an instance in transition), the largest pop of each method within
    `window` frames before its first and after its last frame: [(first, last, {method: max pop})]. A discrete
    switch and the end of a smooth transition both fall inside that window."""
    first = next(iter(by_method.values()))
    out = []
    for e in transitions(first):
        lo, hi = e[0] - window, e[-1] + window
        pops = {}
        for (m,), rows in by_method.items():
            if m == "reference":
                continue
            vals = [num(r["pop"]) for r in rows if lo <= int(r["frame"]) <= hi]
            pops[m] = max(vals) if vals else float("nan")
        out.append((e[0], e[-1], pops))
    return out


def transition_table(rows, scene):
    """Per transition from transitions.csv (one scene, the first count): [(first, last, lods, {method: (max lodpop,
    max pop, its coverage part, its shading part)})] (the parts nan in folders older than them), the reference left
    out. A transition is its frames as well as its index: runs of a sweep whose
    schedules differ (band, pixel error) have different transitions under one index, and each is its own entry,
    the methods of the other runs missing from it."""
    rows = [r for r in rows if r["scene"] == scene]
    if not rows:
        return []
    first_count = min((r["count"] for r in rows), key=int)
    out = OrderedDict()
    for r in rows:
        if r["count"] != first_count or r["method"].startswith("reference"):
            continue
        key = (int(r["transition"]), int(r["first_frame"]), int(r["last_frame"]), r["lods"])
        entry = out.setdefault(key, (int(r["first_frame"]), int(r["last_frame"]), r["lods"], OrderedDict()))
        entry[3][r["method"]] = (num(r["lodpop_max"]), num(r["pop_max"]),
                                 num(r.get("lodpop_coverage", "")), num(r.get("lodpop_shading", "")))
    return [out[k] for k in sorted(out, key=lambda k: (k[1], k[0], k[2], k[3]))]


def transition_methods(per_transition):
    """Every method of the per-transition entries, in order of first appearance."""
    return list(OrderedDict.fromkeys(m for p in per_transition for m in p[-1]))


def stacked_parts(lodpop, coverage, shading):
    """lodpop split into two heights that add up to it, each part's share of lodpop^2 (coverage^2 + shading^2 =
    lodpop^2): (coverage height, shading height), or None where the parts are missing."""
    if any(v != v for v in (lodpop, coverage, shading)) or lodpop <= 0:
        return None
    return coverage * coverage / lodpop, shading * shading / lodpop


def transitions_figure(scene, per_transition, path):
    """Bars per transition and method: lodpop (top; each bar stacked by its parts, coverage hatched below shading,
    heights in proportion to their squares) and pop (bottom) from transitions.csv, or pop alone from the frames
    (older folders: `per_transition` entries are (first, last, {method: pop}))."""
    with_lodpop = len(per_transition[0]) == 4
    methods = transition_methods(per_transition)
    missing = (float("nan"),) * 4 if with_lodpop else float("nan")
    x = np.arange(len(per_transition))
    width = 0.8 / len(methods)
    panels = [("max lodpop (pose held)", 0), ("max pop (motion included)", 1)] if with_lodpop else \
        [(f"max pop within {TRANSITION_WINDOW} frames", None)]
    fig, axes = plt.subplots(len(panels), 1, figsize=(max(8, 1.3 * len(per_transition) + 3), 3.6 * len(panels)),
                             squeeze=False)
    colours = method_colours.series_colours(methods)
    for ax, (label, k) in zip(axes[:, 0], panels):
        for i, m in enumerate(methods):
            at = x - 0.4 + (i + 0.5) * width
            colour = colours[m]
            if k == 0:
                figures = [p[-1].get(m, missing) for p in per_transition]
                parts = [stacked_parts(f[0], f[2], f[3]) for f in figures]
                if all(pt is not None for pt in parts):
                    cov = [pt[0] for pt in parts]
                    ax.bar(at, cov, width, color=colour, hatch="///", edgecolor="white", linewidth=0)
                    ax.bar(at, [pt[1] for pt in parts], width, bottom=cov, color=colour, label=m)
                    continue
            vals = [p[-1].get(m, missing) if k is None else p[-1].get(m, missing)[k] for p in per_transition]
            ax.bar(at, vals, width, label=m, color=colour)
        ticks = [f"frames {p[0]}-{p[1]}" + (f"\n{p[2]}" if with_lodpop else "") for p in per_transition]
        ax.set_xticks(x, ticks, rotation=20, fontsize=8)
        ax.set_ylabel(label)
    if with_lodpop:
        axes[0, 0].set_ylabel("max lodpop (pose held);\nhatched: its coverage part")
    axes[0, 0].set_title(f"{scene}: popping per transition and method")
    axes[0, 0].legend(fontsize=7, ncol=2)
    save(fig, path)


def fig5(scene, summary, path):
    fig, ax = plt.subplots(figsize=(8, 5))
    by_method = group(summary, "method")
    colours = method_colours.series_colours(m for (m,) in by_method)
    for (method,), rows in by_method.items():
        rows = sorted(rows, key=lambda r: int(r["count"]))
        n = [int(r["count"]) for r in rows]
        med = np.array([num(r["gpu_ms_median"]) for r in rows])
        # No error bars on absolute times: compare methods by summary.csv's ratio_to_baseline and its interval.
        ax.plot(n, med, marker="o", label=method, color=colours[method])
    ax.set_xlabel("models")
    ax.set_ylabel("median GPU frame time, ms")
    ax.set_title(f"{scene}: frame time against model count (cf. Sheliemietiev et al. 2023 Fig. 5)")
    ax.legend()
    save(fig, path)


def fig8(scene, summary, path):
    fig, ax = plt.subplots(figsize=(8, 5))
    by_method = group(summary, "method")
    colours = method_colours.series_colours(m for (m,) in by_method)
    for (method,), rows in by_method.items():
        px = [int(r["viewport"].split(",")[0]) * int(r["viewport"].split(",")[1]) for r in rows]
        order = np.argsort(px)
        ax.plot(np.array(px)[order], np.array([num(r["gpu_ms_median"]) for r in rows])[order], marker="o",
                label=method, color=colours[method])
    ax.set_xscale("log")
    ax.set_xlabel("viewport pixels")
    ax.set_ylabel("median GPU frame time, ms")
    ax.set_title(f"{scene}: frame time against viewport size (cf. Scherzer & Wimmer 2008 Fig. 8)")
    ax.legend()
    save(fig, path)


def unified(scene, summary, path):
    """Triangles, popping and cracks against the pixel error each method was run at (a `pixel-error` sweep)."""
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2))
    by_method = group(summary, "method")
    colours = method_colours.series_colours(m for (m,) in by_method)
    for (method,), rows in by_method.items():
        rows = sorted(rows, key=lambda r: float(r["pixel-error"]))
        px = [float(r["pixel-error"]) for r in rows]
        for ax, col in zip(axes, ("triangles_mean", "lodpop_max", "crack_px_mean")):
            ax.plot(px, [num(r.get(col)) for r in rows], marker="o", label=method, color=colours[method])
    for ax, what in zip(axes, ("mean triangles drawn", "largest lodpop (pose held)", "mean crack pixels")):
        ax.set_xscale("log")
        ax.set_xlabel("--pixel-error (pixels)")
        ax.set_ylabel(what)
        ax.grid(alpha=0.3)
    axes[0].set_yscale("log")
    axes[0].legend(fontsize=8)
    fig.suptitle(f"{scene}: unified LOD against pixel error")
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    plt.close(fig)


def cost(scene, summary, path):
    """Mean rmse and max pop against median GPU time: one colour per method, one marker per count, a legend
    instead of labels at the points (methods of similar cost overlap)."""
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.2))
    methods = list(OrderedDict.fromkeys(r["method"] for r in summary))
    counts = list(OrderedDict.fromkeys(r["count"] for r in summary))
    markers = "osD^v<>px*"
    colours = method_colours.series_colours(methods)
    for r in summary:
        g = num(r["gpu_ms_median"])
        ci = counts.index(r["count"])
        for ax, col in zip(axes, ("rmse_mean", "pop_max")):
            ax.scatter(g, num(r[col]), color=colours[r["method"]], marker=markers[ci % len(markers)], alpha=0.85)
    for ax, col in zip(axes, ("mean rmse", "max pop")):
        ax.set_xlabel("median GPU frame time, ms")
        ax.set_ylabel(col)
        ax.grid(alpha=0.3)
    # Two legends: colour = method, marker = count.
    handles = [Line2D([], [], color=colours[m], marker="o", linestyle="", label=m) for m in methods]
    if len(counts) > 1:
        handles += [Line2D([], [], color="grey", marker=markers[i % len(markers)], linestyle="", label=f"n={c}")
                    for i, c in enumerate(counts)]
    fig.legend(handles=handles, loc="center right", fontsize=7, frameon=False)
    fig.suptitle(f"{scene}: error against cost")
    fig.tight_layout(rect=(0, 0, 0.84, 1))
    save_figure(fig, path, dpi=110)
    plt.close(fig)


def ceilings_figure(scene, summary, path):
    """Each block's triangles a second as a share of the adapter's triangle ceiling, and its fragments a second
    (counted in the quality pass) as a share of its fill ceiling (run.json's ceilings, `lodbench probe`): near 1,
    the block is bound by that; far below both, by something else (the harness, the CPU, a stage not probed)."""
    rows = [r for r in summary if r.get("triangle_ceiling_share") or r.get("fragment_ceiling_share")]
    labels = [f"{r['method']} n={r['count']}" if len({x['count'] for x in rows}) > 1 else r["method"] for r in rows]
    fragments = any(r.get("fragment_ceiling_share") for r in rows)
    width = 0.4 if fragments else 0.8
    x = np.arange(len(rows))
    fig, ax = plt.subplots(figsize=(max(6, 0.5 * len(rows) + 2), 3.6))
    shift = -width / 2 if fragments else 0.0
    # The method's colour (as in every figure), fragments hatched; the legend's swatches grey.
    colours = method_colours.series_colours(r["method"] for r in rows)
    colour = [colours[r["method"]] for r in rows]
    ax.bar(x + shift, [num(r.get("triangle_ceiling_share", "")) for r in rows], width, color=colour,
           hatch=HATCHES[0], edgecolor="white", linewidth=0)
    legend = [Patch(facecolor="0.6", edgecolor="white", hatch=HATCHES[0], label="triangles")]
    if fragments:
        ax.bar(x + width / 2, [num(r.get("fragment_ceiling_share", "")) for r in rows], width, color=colour,
               hatch=HATCHES[1], edgecolor="white", linewidth=0)
        legend.append(Patch(facecolor="0.6", edgecolor="white", hatch=HATCHES[1], label="fragments"))
    legend.append(ax.axhline(0.8, color="0.3", ls="--", lw=1, label="0.8: bound"))
    ax.set_xticks(x, labels, rotation=30, ha="right", fontsize=8)
    ax.set_ylabel("rate / the adapter's ceiling")
    ax.set_title(f"{scene}: rates against the adapter's ceilings")
    ax.legend(handles=legend, fontsize=7)
    save(fig, path)


# The frames of a transition's clip, from CLIP_LEAD before its first frame to CLIP_TAIL after its last: the frames
# `--dump-transitions` dumps around it. Mirrors results::files::ClipWindow (TRANSITION_LEAD and TRANSITION_TAIL of
# the Rust source); scripts/tests/test_plot.py checks that they agree.
CLIP_LEAD = 2
CLIP_TAIL = 2
# crop_box: pixels kept around what the pictures draw, and the share of the frame above which the whole frame is
# shown. Mirror CROP_MARGIN and CROP_MAX_SHARE of src/results/clips/compose.rs (its crop_box), also checked by
# test_plot.py.
CROP_MARGIN = 8
CROP_MAX_SHARE = 0.5


def clip_window(episode):
    """The frames of the clip of a transition whose frames are `episode` (ascending), as `lodbench clips` shows."""
    return range(max(0, episode[0] - CLIP_LEAD), episode[-1] + CLIP_TAIL + 1)


def transitions(rows):
    """Episodes of the path with an instance in transition: lists of consecutive frame numbers."""
    episodes = []
    for r in rows:
        if int(r["t_instances"]) == 0:
            continue
        f = int(r["frame"])
        if episodes and f == episodes[-1][-1] + 1:
            episodes[-1].append(f)
        else:
            episodes.append([f])
    return episodes


def pick_transition(by_method, dumped, which):
    """The episode and the frame in it for the contact sheet. `which`: "worst" (the episode, among those with dumped
    frames, holding the frame where the methods' rmse spreads most: max minus min over the methods), "first", or
    a 1-based episode number. Returns (episode number, frame) or None when no episode has dumped frames."""
    first = next(iter(by_method.values()))
    episodes = transitions(first)
    dumped = set(dumped)
    shown = [(n, e) for n, e in enumerate(episodes, 1) if dumped.intersection(clip_window(e))]
    if not shown:
        return None
    if which == "first":
        n, e = shown[0]
        return n, e[len(e) // 2]
    if which != "worst":
        n = int(which)
        if not 1 <= n <= len(episodes):
            raise ValueError(f"--transition {n}: the run has {len(episodes)} transitions")
        e = episodes[n - 1]
        if n not in dict(shown):
            raise ValueError(f"--transition {n} (frames {e[0]}-{e[-1]}): no frames of it were dumped")
        return n, e[len(e) // 2]

    rmse = {m: {int(r["frame"]): num(r["rmse"]) for r in rs} for (m,), rs in by_method.items() if m != "reference"}

    def spread(f):
        vals = [v[f] for v in rmse.values() if f in v]
        return max(vals) - min(vals) if vals else 0.0

    return max(((n, f) for n, e in shown for f in e), key=lambda nf: spread(nf[1]))


def crop_box(images, margin=CROP_MARGIN):
    """The box holding everything that is not background (the first image's top-left colour) in any of the
    images, with a margin; None when it covers more than CROP_MAX_SHARE of the frame (as compose.rs's crop_box)."""
    arrays = [np.asarray(im.convert("RGB"), dtype=np.int16) for im in images]
    h, w = arrays[0].shape[:2]
    bg = arrays[0][0, 0]
    mask = np.zeros((h, w), bool)
    for a in arrays:
        if a.shape[:2] == (h, w):
            mask |= np.abs(a - bg).sum(axis=2) > 0
    if not mask.any():
        return None
    ys, xs = np.nonzero(mask)
    box = (max(0, xs.min() - margin), max(0, ys.min() - margin), min(w, xs.max() + 1 + margin),
           min(h, ys.max() + 1 + margin))
    if (box[2] - box[0]) * (box[3] - box[1]) > CROP_MAX_SHARE * w * h:
        return None
    return box


def crop_note(box):
    return f", cropped to x {box[0]}-{box[2]}, y {box[1]}-{box[3]}" if box else ""


def contact(scene, frames_dir, by_method, path, which="worst"):
    # The frame number is the last `_fNNNNN` before `_method.png` (method names may contain `_f`, e.g. fsi).
    dumped = sorted({int(p.name[: -len("_method.png")][-5:]) for p in frames_dir.glob(f"{scene}_*_method.png")})
    if not dumped:
        return None
    picked = pick_transition(by_method, dumped, which)
    if picked is None:
        return None
    episode, mid = picked
    i = min(range(len(dumped)), key=lambda j: abs(dumped[j] - mid))
    lo = min(max(0, i - 1), max(0, len(dumped) - 3))
    picks = dumped[lo: lo + 3]
    methods = [m for (m,) in by_method]
    stems = {(m, f): frames_dir / f"{scene}_{m}_c{by_method[(m,)][0]['count']}_f{f:05d}" for m in methods
             for f in picks}
    opened = {}
    for (m, f), stem in stems.items():
        for kind in ("reference", "method", "error"):
            p = Path(f"{stem}_{kind}.png")
            if p.is_file():
                opened[(m, f, kind)] = Image.open(p)
    box = crop_box([im for (m, f, kind), im in opened.items() if kind != "error"])
    fig, axes = plt.subplots(len(methods), 2 * len(picks), figsize=(2.2 * 2 * len(picks), 2.0 * len(methods)),
                             squeeze=False)
    for row, method in enumerate(methods):
        for col, f in enumerate(picks):
            for k, kind in enumerate(("method", "error")):
                ax = axes[row][2 * col + k]
                ax.axis("off")
                im = opened.get((method, f, kind))
                if im is not None:
                    ax.imshow(im.crop(box) if box else im, interpolation="nearest")
                if row == 0:
                    ax.set_title(f"frame {f} {kind}", fontsize=8)
            axes[row][0].text(-0.05, 0.5, method, transform=axes[row][0].transAxes, ha="right", va="center",
                              fontsize=8)
    fig.suptitle(f"{scene}: transition {episode} of the path, frames {picks[0]}-{picks[-1]}{crop_note(box)}\n"
                 "(error heat-map: black = equal, white >= 0.25)", fontsize=9)
    fig.tight_layout()
    save_figure(fig, path, dpi=100, palette=False)  # rendered frames: every shade kept
    plt.close(fig)
    for im in opened.values():
        im.close()
    return episode


def fsi_buffers(scene, frames_dir, by_method, path):
    """FSI's two LOD buffers and the combined frame side by side, for the dumped frame of an fsi-family method
    with the most instances in transition (the `_lodbuffer0/1.png` dumps). Returns the frame or None."""
    for (method,), rows in by_method.items():
        if not method.startswith("fsi"):
            continue
        count = rows[0]["count"]
        stem = f"{scene}_{method}_c{count}_f"
        frames = [r for r in rows if int(r["t_instances"]) > 0
                  and (frames_dir / f"{stem}{int(r['frame']):05d}_lodbuffer0.png").is_file()]
        if not frames:
            continue
        # Most instances in transition; among those, the largest rmse (where the objects are largest on screen).
        best = max(frames, key=lambda r: (int(r["t_instances"]), num(r["rmse"]), -int(r["frame"])))
        f = int(best["frame"])
        panels = [("LOD buffer 0", "lodbuffer0"), ("LOD buffer 1", "lodbuffer1"), ("combined frame", "method")]
        images = [Image.open(frames_dir / f"{stem}{f:05d}_{kind}.png") for _, kind in panels]
        box = crop_box(images)
        w, h = (box[2] - box[0], box[3] - box[1]) if box else images[0].size
        fig, axes = plt.subplots(1, 3, figsize=(3 * 4.0, 4.0 * h / w + 0.6), squeeze=False)
        for ax, (title, _), im in zip(axes[0], panels, images):
            ax.imshow(im.crop(box) if box else im, interpolation="nearest")
            ax.set_title(title, fontsize=9)
            ax.axis("off")
            im.close()
        fig.suptitle(f"{scene}, {method}, frame {f} ({best['t_instances']} instances in transition"
                     f"{crop_note(box)}): the two "
                     "LOD buffers hold this frame and the previous one; the combination pass merges them", fontsize=9)
        save(fig, path, palette=False)  # rendered frames: every shade kept
        return f
    return None


def table_cells(rows, columns, raw=()):
    """The text of each cell of a table of `rows` (dicts) under `columns`, numbers by unit (src/numbers.rs's rules:
    lodbench_results.sig3, thousands and ratio_text; counts with thousands separators, a ratio with its interval,
    other figures to 3 significant figures; full precision stays in the CSVs), other values as they are, a missing
    one empty. report.md and report.html show the same cells. Columns in `raw` (the swept variables, labels) are
    shown as they are."""
    out = []
    for r in rows:
        cells = []
        for c in columns:
            v = r.get(c, "")
            if c in raw:
                cells.append(v)
                continue
            if c.startswith("ratio_to_baseline") and f"{c}_ci95_lo" in r:
                cells.append(ratio_text(num(v), num(r.get(f"{c}_ci95_lo")), num(r.get(f"{c}_ci95_hi")))
                             if v != "" else "")
                continue
            try:
                x = float(v)
            except (TypeError, ValueError):
                cells.append(v)
                continue
            if x != x or c in ("count",):
                cells.append(v)
            else:
                cells.append(thousands(x) if c in COUNT_COLUMNS else sig3(x))
        out.append(cells)
    return out


def markdown_table(rows, columns, raw=()):
    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    for cells in table_cells(rows, columns, raw):
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


ROOT = Path(__file__).resolve().parents[1]
ANSWER_SCHEMA = "lodbench-answer/1"


def lodbench_binary():
    """The lodbench binary that makes answer.json, as scripts/tests/conftest.py's lodbench_binary finds it but never
    building it: $LODBENCH (the name scripts/regenerate-results.sh takes) or $LODBENCH_BIN (the tests'), else this
    repository's target/release/lodbench (under $CARGO_TARGET_DIR where set), else `lodbench` on the PATH; None
    where there is none."""
    for var in ("LODBENCH", "LODBENCH_BIN"):
        if os.environ.get(var):
            return Path(os.environ[var])
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    if not target.is_absolute():
        target = ROOT / target
    if (target / "release" / "lodbench").is_file():
        return target / "release" / "lodbench"
    found = shutil.which("lodbench")
    return Path(found) if found else None


def answer_stale(folder: Path):
    """Why folder's answer.json must be (re)made, or None: it has none (a folder made before the binary wrote
    one), or a perceptual.csv the answer reads (the folder's own, its runs') is newer (`lodbench perceptual` of an
    older binary, which did not rewrite it)."""
    path = folder / ANSWER_JSON
    if not path.is_file():
        return f"no {ANSWER_JSON} (a folder made before lodbench wrote one)"
    made = path.stat().st_mtime
    for p in [folder / PERCEPTUAL_CSV, *sorted((folder / RUNS_DIR).glob(f"*/{PERCEPTUAL_CSV}"))]:
        if p.is_file() and p.stat().st_mtime > made:
            return f"{p.relative_to(folder).as_posix()} is newer than {ANSWER_JSON}"
    return None


def answer_of(folder: Path):
    """folder's answer.json (the answer report.md and report.html lead with), made first by `lodbench answer FOLDER`
    where answer_stale says so. Raises ValueError where it cannot be made or read."""
    why = answer_stale(folder)
    if why is not None:
        command = f"lodbench answer {folder}"
        binary = lodbench_binary()
        if binary is None:
            raise ValueError(f"{why}, and no lodbench binary to make it: build it (cargo build --release), or set "
                             f"LODBENCH to one, and run `{command}`")
        print(f"{folder}: {why}; making it with `{command}` ({binary})")
        try:
            r = subprocess.run([str(binary), "answer", str(folder)], capture_output=True, text=True)
        except OSError as e:
            raise ValueError(f"{why}, and `{command}` could not run {binary} ({e})") from None
        if r.returncode != 0:
            raise ValueError(f"`{command}` ({binary}) failed with status {r.returncode}: "
                             f"{(r.stderr or r.stdout).strip()}")
    path = folder / ANSWER_JSON
    try:
        said = json.loads(path.read_text())
    except (OSError, ValueError) as e:
        raise ValueError(f"{ANSWER_JSON}: not readable JSON ({e}); remake it with `lodbench answer {folder}`") from None
    if not isinstance(said, dict) or said.get("schema") != ANSWER_SCHEMA:
        raise ValueError(f"{ANSWER_JSON}: not of schema {ANSWER_SCHEMA}; remake it with `lodbench answer {folder}`")
    return said


def report(folder: Path, transition: str = "worst") -> list:
    """Writes folder's figures, report.md and report.html; returns the figures as [(file name, caption)]. Raises
    ValueError on what the folder's data does not allow (a malformed clips/index.json, a missing clip image, ...)
    before anything is written (answer.json that can be neither read nor made, among them)."""
    answer = answer_of(folder)
    clips = report_html.load_clips(folder)
    runs = report_html.manifest(folder)
    frames = read_csv(folder / FRAMES_CSV)
    summary = read_csv(folder / SUMMARY_CSV)
    transitions_csv = read_csv(folder / TRANSITIONS_CSV) if (folder / TRANSITIONS_CSV).is_file() else None
    figs = folder / "figures"
    figs.mkdir(exist_ok=True)
    made = []
    headline = []  # the figures that follow the answer: cost against popping, popping per transition
    tables = []
    header = list(summary[0]) if summary else []
    # The swept variables lead the columns, one per sweep; a merged folder's `adapter` column follows them.
    variables = [c for c in header[:header.index("scene")] if c != "adapter"] if "scene" in header else []
    variable = variables[0] if len(variables) == 1 else None
    swept = variable in ("viewport", "pixel-error")
    first_viewport = summary[0][variable] if swept else None
    frontier_tables = []
    if variables and variable != "viewport" and any(r.get("lodpop_max") for r in summary):
        # Before the methods are relabelled below: pairs.csv names them as the runs do.
        pairs = read_csv(folder / PAIRS_CSV) if (folder / PAIRS_CSV).is_file() else []
        pts = frontier.points(folder, summary, variables)
        for (scene,), scene_pts in group(pts, "scene").items():
            first_count = scene_pts[0]["count"]
            scene_pts = [p for p in scene_pts if p["count"] == first_count]
            frontier.figure(scene, scene_pts, variables[-1], figs / f"frontier_{scene}.png")
            headline.append((f"frontier_{scene}.png", f"{scene}: cost against popping across {variables[-1]}"))
            rows = frontier.cheapest(scene, scene_pts, pairs, variables)
            if rows:
                frontier_tables.append((f"{scene}: cheapest at or below a popping (paired within a run)", rows,
                                        frontier.COLUMNS))
    # The answer first: answer.json's blocks, as the binary wrote them.
    answers = [{"name": b["name"], "sentences": b["sentences"], "columns": answer["columns"], "rows": b["rows"]}
               for b in answer["blocks"]]
    # Then what the pops are measured in and how many a minute are visible (before the methods are relabelled
    # below: the swept values have their own columns).
    adapters = sorted({r["adapter"] for r in summary if "adapter" in r})
    pops_lead = variables + (["adapter"] if len(adapters) > 1 else []) + ["scene", "method", "count"]
    pops = visible_pops(summary, header, pops_lead, runs)
    if not variables:
        for (scene,), rows in group(summary, "scene").items():
            first_count = rows[0]["count"]
            rows = [r for r in rows if r["count"] == first_count]
            if any(r.get("lodpop_max") for r in rows) and any(r.get("ratio_to_baseline") for r in rows):
                block = next((b for b in answer["blocks"] if b["scene"] == scene and b["count"] == first_count), None)
                decision_figure(scene, rows, block, figs / f"decision_{scene}.png")
                headline.append((f"decision_{scene}.png", f"{scene}: cost against popping, one point per method"))
    if variables and not swept:
        # Each combination of swept values is its own series, in the figures and the tables.
        for r in summary + frames + (transitions_csv or []):
            r["method"] = f"{r['method']} ({', '.join(f'{v} {r[v]}' for v in variables)})"
    if len(adapters) > 1:
        # Runs on different GPUs (merge --allow-adapters): each (method, adapter) is its own series.
        for r in summary + frames + (transitions_csv or []):
            r["method"] = f"{r['method']} [{r['adapter']}]"
    for (scene,), all_viewports in group(summary, "scene").items():
        if variable == "viewport":
            fig8(scene, all_viewports, figs / f"fig8_{scene}.png")
            made.append((f"fig8_{scene}.png", f"{scene}: median GPU frame time against viewport size"))
        if variable == "pixel-error":
            unified(scene, all_viewports, figs / f"unified_{scene}.png")
            made.append((f"unified_{scene}.png", f"{scene}: triangles, popping and cracks against pixel error"))
        scene_summary = [r for r in all_viewports if not swept or r[variable] == first_viewport]
        scene_frames = [r for r in frames if r["scene"] == scene and (not swept or r[variable] == first_viewport)]
        counts = sorted({r["count"] for r in scene_summary}, key=int)
        if len(counts) > 1:
            fig5(scene, scene_summary, figs / f"fig5_{scene}.png")
            made.append((f"fig5_{scene}.png", f"{scene}: median GPU frame time against model count"))
        # A run without the quality pass (--quality off) has empty image figures: no popping figures, no cost one.
        moving = any(num(r["pop"]) > 0 for r in scene_frames)
        if moving:
            first_count = counts[0]
            by_method = group([r for r in scene_frames if r["count"] == first_count], "method")
            sweep_figure(scene, OrderedDict((m, rs) for (m,), rs in by_method.items()),
                         figs / f"sweep_{scene}.png")
            made.append((f"sweep_{scene}.png", f"{scene}: rmse, pop"
                         + (" and lodpop" if "lodpop" in scene_frames[0] else "") + " per frame"))
            fig6(scene, [r for r in scene_summary if r["count"] == first_count], figs / f"fig6_{scene}.png")
            made.append((f"fig6_{scene}.png", f"{scene}: popping per method"))
            if transitions_csv is not None:
                scene_transitions = [r for r in transitions_csv
                                     if not swept or r[variable] == first_viewport]
                per_transition = transition_table(scene_transitions, scene)
            else:
                per_transition = transition_pops(by_method)
            if 0 < len(per_transition) <= 16:
                transitions_figure(scene, per_transition, figs / f"transitions_{scene}.png")
                headline.append((f"transitions_{scene}.png", f"{scene}: popping per transition"))
                tables.append((scene, per_transition))
            if (folder / "frames").is_dir():
                episode = contact(scene, folder / "frames", by_method, figs / f"contact_{scene}.png", transition)
                if episode is not None:
                    made.append((f"contact_{scene}.png", f"{scene}: frames around transition {episode} of the path"))
                if fsi_buffers(scene, folder / "frames", by_method, figs / f"fsi_buffers_{scene}.png") is not None:
                    made.append((f"fsi_buffers_{scene}.png", f"{scene}: FSI's two LOD buffers and the combined frame"))
        if any(r["rmse_mean"] != "" for r in scene_summary):
            cost(scene, scene_summary, figs / f"cost_{scene}.png")
            made.append((f"cost_{scene}.png", f"{scene}: error against cost"))
        if any(r.get("triangle_ceiling_share") or r.get("fragment_ceiling_share") for r in scene_summary):
            ceilings_figure(scene, scene_summary, figs / f"ceilings_{scene}.png")
            made.append((f"ceilings_{scene}.png", f"{scene}: triangles and fragments a second against the "
                                                  "adapter's ceilings"))
    lead = variables + (["adapter"] if len(adapters) > 1 else []) + ["scene", "method", "count"]
    # The tables once, as (heading, rows, columns): report.md and report.html render the same ones.
    sections = [(f"Summary: {what}", summary, lead + cols) for what, cols in summary_groups(header, lead)] \
        + frontier_tables
    for scene, per_transition in tables:
        methods = transition_methods(per_transition)
        if len(per_transition[0]) == 4:
            for k, what in ((0, "max lodpop (pose held)"), (2, "max lodpop's coverage part"),
                            (3, "max lodpop's shading part"), (1, "max pop (motion included)")):
                if all(p[m][k] != p[m][k] for *_, p in per_transition for m in p):
                    continue
                rows = [{"transition": f"frames {a}-{b} ({lods})",
                         **{m: sig3(p[m][k]) for m in methods if m in p}} for a, b, lods, p in per_transition]
                sections.append((f"{scene}: {what} of each transition (its frames and the 2 after)", rows,
                                 ["transition"] + methods))
        else:
            rows = [{"transition": f"frames {a}-{b}", **{m: sig3(p[m]) for m in methods if m in p}}
                    for a, b, p in per_transition]
            sections.append((f"{scene}: max pop within {TRANSITION_WINDOW} frames of each transition", rows,
                             ["transition"] + methods))
    title = f"lodbench report: {folder.name}"
    text = [f"# {title}", ""]
    for a in answers:
        text += [f"## {a['name']}", ""] + [sentence_text(s) for s in a["sentences"]] + [""]
        text += ["| " + " | ".join(a["columns"]) + " |", "|" + "---|" * len(a["columns"])]
        text += ["| " + " | ".join(part_text(c) for c in row) + " |" for row in a["rows"]] + [""]
    text += ["## Visible pops", ""] + [line for line, _ in pops["lines"] for line in (line, "")]
    if pops["rows"] is not None:
        text += [markdown_table(pops["rows"], pops["columns"], pops_lead), ""]
    text += [pops["note"], ""]
    for name, caption in headline:
        text += [f"## {caption}", "", f"![{caption}](figures/{name})", ""]
    for heading, rows, cols in sections:
        text += [f"## {heading}", "", markdown_table(rows, cols, lead), ""]
    for name, caption in made:
        text += [f"## {caption}", "", f"![{caption}](figures/{name})", ""]
    (folder / "report.md").write_text("\n".join(text))
    tables_html = [(heading, cols, table_cells(rows, cols, lead)) for heading, rows, cols in sections]
    pops_html = report_html.pops_html(
        pops["lines"], pops["columns"],
        None if pops["rows"] is None else table_cells(pops["rows"], pops["columns"], pops_lead), pops["note"],
        open_table=pops["rows"] is None or len(pops["rows"]) <= POPS_OPEN_ROWS)
    (folder / "report.html").write_text(report_html.page(title, answers, headline, tables_html, made, clips, runs,
                                                         pops=pops_html))
    return headline + made


# summary.csv's columns of the visible pops (pop events over a threshold, per minute of the path), beside the
# largest lodpop; lodpop_max_jnd only where a run was calibrated.
POPS_COLUMNS = ("lodpop_max", "lodpop_max_jnd", "pop_events", "visible_pop_threshold", "visible_pops_per_min")
# The visible pops' table is open up to this many rows, folded beyond (a large experiment).
POPS_OPEN_ROWS = 24


def visible_pops(summary, header, lead, runs):
    """The section after the answer: {"lines": what the pops are measured in (report_html.calibration_lines of the
    folder's run.json files, `runs` = report_html.manifest()'s: the run's, or each run's of an experiment or merged
    folder), "columns" and "rows" (the table: each summary row's largest lodpop, in JNDs where calibrated, its pop
    events, the threshold they are counted visible over and the visible ones per minute; rows None where nothing
    was measured), "note"}. A folder made before pop events has none of the columns: not measured."""
    lines = report_html.calibration_lines(runs)
    if "visible_pops_per_min" not in header:
        return {"lines": lines, "columns": [], "rows": None,
                "note": "Visible pops per minute: not measured (this summary.csv has no visible_pops_per_min: made "
                        "by a lodbench before pop events; `lodbench run` again to count them)."}
    if not any(r.get("pop_events") for r in summary):
        return {"lines": lines, "columns": [], "rows": None,
                "note": "Visible pops per minute: not measured (no transition has a lodpop: a run with "
                        "`--quality off`?)."}
    columns = lead + [c for c in POPS_COLUMNS if c in header and (c != "lodpop_max_jnd"
                                                                   or any(r.get(c) for r in summary))]
    fps = report_html.path_fps(runs)
    at = (f"at {fps[0]:g} frames a second (run.json's path_fps)" if len(fps) == 1 else
          "at each run's frame rate (its run.json's path_fps)" if fps else "at its frame rate")
    note = ("visible_pops_per_min: a method's pop events (events.csv: its instances' switches, those that begin "
            "within 0.1 s of a wave's first joined into one event, scored by the root of the sum of their lodpop "
            "squared) "
            "whose score exceeds visible_pop_threshold (1 JND of the calibration; without one the run's "
            "`--budget-lodpop`, else half the hard switch's largest lodpop), per minute of the path "
            f"{at}; pop_events counts them all. Empty: not measured (no threshold, or no lodpop). Full precision in "
            "summary.csv.")
    rows = [{c: r.get(c, "") for c in columns} for r in summary]
    return {"lines": lines, "columns": columns, "rows": rows, "note": note}


# summary.csv's columns in the report's folded tables, a table per group (each fits a window); the intervals are
# shown with their ratio, and a column of no group goes to "other".
SUMMARY_GROUPS = (
    ("time", ("frames", "gpu_ms_median", "gpu_ms_median_transition", "gpu_ms_median_steady", "gpu_ms_p5",
              "gpu_ms_p95", "cpu_ms_median", "combine_gpu_ms_median")),
    ("paired ratios", ("baseline", "rounds", "ratio_to_baseline", "ratio_to_baseline_transition",
                       "ratio_to_baseline_steady")),
    ("image error", ("rmse_mean", "rmse_max", "de2000_mean", "de2000_max", "flip_mean", "lag_rmse_mean",
                     "lag_rmse_max", "shadow_rmse_mean")),
    ("popping", ("pop_max", "pop_p95", "lodpop_max", "lodpop_p95", "lodpop_sum", "shadow_lodpop_max",
                 "lodpop_max_jnd", "pop_events", "visible_pop_threshold", "visible_pops_per_min")),
    ("geometry", ("triangles_mean", "draw_calls_mean", "t_instances_mean", "units_drawn_mean", "uncovered_px_mean",
                  "crack_px_mean", "crack_px_max", "extra_target_bytes", "tri_alternation_max")),
    ("ceilings", ("triangles_per_s", "triangle_ceiling_share", "fragments_mean", "fragments_per_s",
                  "fragment_ceiling_share", "bound")),
)
# Counts, shown with thousands separators.
COUNT_COLUMNS = {"frames", "rounds", "triangles_mean", "fragments_mean", "draw_calls_mean", "units_drawn_mean",
                 "pop_events", "crack_px_max", "extra_target_bytes", "uncovered_px_mean", "crack_px_mean"}


def summary_groups(header, lead):
    """[(group, its columns present in `header`)], the groups of SUMMARY_GROUPS then "other"."""
    placed = set(lead)
    out = []
    for what, cols in SUMMARY_GROUPS:
        present = [c for c in cols if c in header]
        placed.update(present)
        placed.update(f"{c}_ci95_{e}" for c in present for e in ("lo", "hi"))
        if present:
            out.append((what, present))
    rest = [c for c in header if c not in placed and not c.endswith(("_ci95_lo", "_ci95_hi"))]
    if rest:
        out.append(("other", rest))
    return out


def decision_figure(scene, rows, block, path):
    """Each method's cost (time over the baseline's, all frames, with its 95 % interval) against its largest
    lodpop, the budget of the answer drawn across (`block`: the scene's block of answer.json, whose budget is the
    run's --budget-lodpop or half its hard switch's largest lodpop; none where it has no budget): the answer's two
    sentences at a glance. The methods are named in the legend only: labels at the points pile up where methods
    cost and pop alike."""
    fig, ax = plt.subplots(figsize=(9, 4.4))
    budget = (block or {}).get("budget")
    colours = method_colours.series_colours(r["method"] for r in rows)
    for r in rows:
        x, lo, hi, y = (num(r.get(c)) for c in ("ratio_to_baseline", "ratio_to_baseline_ci95_lo",
                                                  "ratio_to_baseline_ci95_hi", "lodpop_max"))
        if x != x or y != y:
            continue
        err = [[x - lo], [hi - x]] if lo == lo and hi == hi else None
        ax.errorbar([x], [y], xerr=err, fmt="o", color=colours[r["method"]], capsize=3, label=r["method"])
    if budget is not None:
        ax.axhline(budget["lodpop"], color="0.3", lw=1.2, ls="--",
                   label=f"budget {sig3(budget['lodpop'])} ({budget['source']})")
    baseline = next((r["baseline"] for r in rows if r.get("baseline")), "the baseline")
    ax.set_xlabel(f"time over {baseline}'s, all frames (95 % interval)")
    ax.set_ylabel("largest lodpop (lower: less popping)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5), frameon=False)
    ax.set_title(f"{scene}: cost against popping")
    save(fig, path)


RULE_STYLE = {"tune": ("black", "-"), "unreal": ("tab:red", "--"), "godot": ("tab:blue", "-."),
              "meshopt": ("tab:green", ":")}


def tune_figure(model, samples, rules, budget, path):
    """One panel per LOD pair: each view's curve of the budget's figure against distance (log), the budget, and the
    switch distance of tune and of each engine rule."""
    pairs = sorted({(int(r["lod_from"]), int(r["lod_to"])) for r in samples})
    metric, limit = budget["metric"], float(budget["value"])
    fig, axes = plt.subplots(1, len(pairs), figsize=(4.2 * len(pairs), 3.4), squeeze=False)
    for ax, (a, b) in zip(axes[0], pairs):
        rows = [r for r in samples if int(r["lod_from"]) == a and r["refined"] == "false"]
        for (view,), vrows in group(rows, "view").items():
            xs = [num(r["distance"]) for r in vrows]
            ys = [num(r["jod" if metric == "jod" else "lodpop"]) for r in vrows]
            ax.plot(xs, ys, color="0.55", lw=0.8, label="views" if view == "0" else None)
        ax.axhline(limit, color="tab:orange", lw=1.2, label=f"budget {limit:g}")
        for r in rules:
            if int(r["lod_from"]) == a:
                colour, style = RULE_STYLE.get(r["rule"], ("0.3", "-"))
                flag = "" if r["within_budget"] == "true" else " (breaks)"
                ax.axvline(num(r["distance"]), color=colour, ls=style, lw=1.2, label=f"{r['rule']}{flag}")
        ax.set_xscale("log")
        ax.set_xlabel("distance from the bounding sphere's centre")
        ax.set_ylabel("JOD" if metric == "jod" else "lodpop (RMS over the frame)")
        ax.set_title(f"{model}: LOD {a} -> {b}", fontsize=9)
        ax.legend(fontsize=7)
    save(fig, path)


def tune_report(folder: Path) -> list:
    """A tune folder's figures and report.md; returns [(file name, caption)]."""
    import json
    meta = json.loads((folder / TUNE_JSON).read_text())
    samples = read_csv(folder / TUNE_CSV)
    rules = read_csv(folder / RULES_CSV) if (folder / RULES_CSV).is_file() else []
    figs = folder / "figures"
    figs.mkdir(exist_ok=True)
    made = []
    budget = meta["settings"]["budget"]
    for (model,), rows in group(samples, "model").items():
        safe = "".join(c if c.isalnum() or c in "-_" else "_" for c in model)
        name = f"tune_{safe}.png"
        tune_figure(model, rows, [r for r in rules if r["model"] == model], budget, figs / name)
        made.append((name, f"{model}: the budget's figure against distance per view, and each rule's switch"))
    columns = ["model", "lod_from", "lod_to", "rule", "distance", "screen_size", "value", "within_budget"]
    fmt = lambda v, f: "-" if v is None else format(v, f)  # noqa: E731
    switches = [{"model": m["name"], "LODs": f"{p['lod_from']}->{p['lod_to']}",
                 "triangles": f"{p['triangles_from']} -> {p['triangles_to']}",
                 "switch distance": fmt(p["switch_distance"], ".4g"), "screen size": fmt(p["screen_size"], ".4f"),
                 "worst from switch": fmt(p.get("checked_worst", p["value_at_switch"]), ".5f"),
                 "error px at switch": fmt(p["error_px_at_switch"], ".3f"),
                 "bands (method: half-width, frames)": ", ".join(f"{b['method']}: {b['band']:.3f}, {b['frames']}"
                                                                 for b in p["bands"]) or "-"}
                for m in meta["models"] for p in m["pairs"]]
    switch_cols = list(switches[0]) if switches else []
    text = [f"# lodbench tune: {meta['scene']}", "",
            f"Budget: {budget['metric']} {budget['value']}, {meta['settings']['views']} views, "
            f"{meta['width']}x{meta['height']}, {meta['fov_y_deg']:.1f} degrees vertical field of view.", "",
            "## Switches", "", markdown_table(switches, switch_cols), "",
            "## Switch distances by rule", "", markdown_table(rules, columns), ""]
    for name, caption in made:
        text += [f"## {caption}", "", f"![{caption}](figures/{name})", ""]
    (folder / "report.md").write_text("\n".join(text))
    answers = tune_answers(folder, meta, rules)
    cells = table_cells(rules, columns)
    (folder / "report.html").write_text(report_html.page(
        f"lodbench tune: {meta['scene']}", answers, made, [("Switch distances by rule (rules.csv)", columns, cells)],
        [], None, report_html.tune_manifest(meta), players=False, note=report_html.TUNE_NOTE))
    return made


def engine_units(folder: Path):
    """{model: {lod_from: {engine column: value}}} from the tune folder's engines/ files (what an engine is given):
    Unity's screenRelativeTransitionHeight, Unreal's screen size, Godot's visibility_range_end, Bevy's end margin
    and three.js's LOD.addLevel distance, each of the switch from LOD k; missing files give no entries."""
    import json

    def load(name):
        try:
            return json.loads((folder / "engines" / name).read_text())
        except (OSError, ValueError):
            return None
    out = {}

    def put(model, k, col, v):
        out.setdefault(model, {}).setdefault(k, {})[col] = v
    for m in load("unity-lodgroup.json") or []:
        for k, lod in enumerate(m.get("lods", [])[:-1]):
            put(m["name"], k, "Unity transition height", lod.get("screenRelativeTransitionHeight"))
    for m in load("unreal-screen-sizes.json") or []:
        for k, size in enumerate(m.get("screen_size", [])[1:]):
            put(m["name"], k, "Unreal screen size", size)
    for name, lods in load("godot-visibility-ranges.json") or []:
        for lod in lods[:-1]:
            put(name, lod["lod"], "Godot visibility_range_end", lod.get("visibility_range_end"))
    for name, lods in load("bevy-visibility-ranges.json") or []:
        for k, lod in enumerate(lods[:-1]):
            put(name, k, "Bevy end_margin", (lod.get("end_margin") or [None])[-1])
    return out


def tune_answers(folder: Path, meta, rules):
    """A tune folder's answer per model: where it switches within the budget, how the engines' rules fare there,
    and a table of the switches in each engine's units with the measured popping against the budget."""
    budget = meta["settings"]["budget"]
    metric, limit = budget["metric"], float(budget["value"])
    units = engine_units(folder)
    columns = ["LODs", "triangles", "distance", f"worst {metric} from the switch", "budget", "within",
               "error px at switch", "Unity transition height", "Unreal screen size", "Godot visibility_range_end",
               "Bevy end_margin", "three.js addLevel"]
    out = []
    for m in meta["models"]:
        pairs = m["pairs"]
        where = ", ".join(f"{p['lod_from']}->{p['lod_to']} at {sig3(p['switch_distance'])}"
                          if p["switch_distance"] is not None else f"{p['lod_from']}->{p['lod_to']} never"
                          for p in pairs)
        said = [[f"{m['name']}: within a {metric} of {limit:g} ({meta['width']}x{meta['height']}, "
                 f"{meta['settings']['views']} views), the switches are {where} (distance from the bounding "
                 f"sphere's centre, radius {sig3(m['radius'])})."]]
        broken = []
        for rule in ("unreal", "godot", "meshopt"):
            rs = [r for r in rules if r["model"] == m["name"] and r["rule"] == rule]
            if rs:
                n = sum(r["within_budget"] != "true" for r in rs)
                broken.append(f"{RULE_NAMES[rule]} breaks it at {n} of {len(rs)}")
        if broken:
            said.append(["Switching by the engines' error bounds instead: " + "; ".join(broken) + " (rules.csv)."])
        rows = []
        for p in pairs:
            worst = p.get("checked_worst", p["value_at_switch"])
            ok = worst is not None and (worst >= limit if metric == "jod" else worst <= limit)
            u = units.get(m["name"], {}).get(p["lod_from"], {})
            rows.append([f"{p['lod_from']}->{p['lod_to']}",
                         f"{thousands(p['triangles_from'])} -> {thousands(p['triangles_to'])}",
                         sig3(p["switch_distance"]), sig3(worst), f"{limit:g}",
                         "yes" if ok else "no", sig3(p["error_px_at_switch"]),
                         *(sig3(u.get(c)) for c in columns[7:11]), sig3(p["switch_distance"])])
        out.append({"name": m["name"], "sentences": said, "columns": columns, "rows": rows})
    return out


RULE_NAMES = {"unreal": "Unreal's auto screen size", "godot": "Godot's mesh_lod_threshold",
              "meshopt": "meshoptimizer's 1 pixel"}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("results", type=Path, nargs="+")
    ap.add_argument("--transition", default="worst",
                    help='which transition the contact sheet shows: "worst" (default: where the methods\' rmse '
                         'differ most), "first", or a 1-based number along the path')
    args = ap.parse_args()
    if args.transition not in ("worst", "first") and not args.transition.isdigit():
        print(f"error: --transition {args.transition!r}: expected worst, first or a number", file=sys.stderr)
        return 2
    for folder in args.results:
        if (folder / TUNE_CSV).is_file() and (folder / TUNE_JSON).is_file():
            made = tune_report(folder)
            print(f"{folder}: report.md, report.html and {len(made)} figures in {folder / 'figures'}")
            continue
        if not (folder / FRAMES_CSV).is_file() or not (folder / SUMMARY_CSV).is_file():
            print(f"error: {folder} has no frames.csv and summary.csv (a complete lodbench run?)", file=sys.stderr)
            return 2
        try:
            made = report(folder, args.transition)
        except ValueError as e:
            print(f"error: {folder}: {e}", file=sys.stderr)
            return 2
        print(f"{folder}: report.md, report.html and {len(made)} figures in {folder / 'figures'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
