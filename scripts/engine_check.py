#!/usr/bin/env python3
"""Does a real engine switch where lodbench says, and pop as much? lodbench's discrete against three.js's THREE.LOD
along the same camera paths, per `lodbench tune` folder.

    python3 scripts/engine_check.py TUNE_DIR [TUNE_DIR ...] --out DIR [--frames 240] [--binary PATH]
        [--fades default,distance] [--keep-pictures]

Each TUNE_DIR is a folder `lodbench tune` wrote for a scene of one model (tune.json with a lodpop budget, rules.csv,
engines/threejs-lod.js, tuned.glb); ASSET is its name without a leading `tune-`. Per folder, into DIR/ASSET/:

  1. path-axis.csv and path-diagonal.csv: the two paths of scripts/tune_rules.py (its write_path, DIAGONAL and the
     same geometry: looking at the model's centre from +z and from the diagonal, from where the model fits the view,
     or 0.9 of the nearest switch of any rule, to 1.25x the farthest), --frames frames each;
  2. per path and rule (tune, unreal, godot, meshopt; each rule's distances from rules.csv, tune's own for tune):
       PATH-RULE/lodbench   `lodbench run --scene tuned.glb --method reference,discrete --baseline reference
                            --camera-path P --switch-distances D --width W --height H --frames N --warmup 0 --rounds 2
                            --metrics rmse,pop,flip --budget-lodpop B` (W, H, B: tune.json's), lodbench's own
                            prediction with its defaults for a glTF file (a time fade of 8 frames, discrete switching
                            at its middle);
       PATH-RULE/lodbench-fade-distance  the same with `--fade distance` (the switch at the distance itself; with
                            --fades ...,distance, the default); only its transitions.csv and summary.csv are kept;
       PATH-RULE/three      `scripts/three_lod.py TUNE_DIR --path P --rule R`, then `lodbench score --budget-lodpop B
                            --metrics rmse,pop,flip`;
       axis|diagonal-tune/three-origin  the same with `--anchor origin` (THREE.LOD at the model's origin, not its
                            bounding-sphere centre);
  3. the switches of lodbench's discrete (per frame the level floor(lod_mean + 0.5) of frames.csv, which is what
     discrete draws along an outward path) and of three.js (lods.csv), matched by order within each pair from->to
     (match_switches): a row per switch in DIR/engine_check.csv (COLUMNS) with each side's frame, the distance from
     the eye to the model's centre there (`lodbench describe --cameras-json` eyes, the centre the paths look at: the
     world position of tune.json's center, which is in the model's own space), each side's lodpop on its switch
     frame (and its coverage and shading parts), the verdicts against the budget and a status: agree (same frame,
     same verdict), frame-differs (same verdict), verdict-differs, missing-in-three, missing-in-lodbench;
  4. DIR/fidelity.csv: scripts/three_fidelity.py's compare() of each tuned.glb at tune's viewport (FLIP of lodbench's
     reference frame 0 against three.js's);
  5. DIR/figures/lodpop_ASSET.png (lodpop per frame along the axis path, rule tune: lodbench's discrete, three.js,
     three.js at the origin, the budget) and switch_ASSET.png (the tune rule's first switch on the axis path of the
     DamagedHelmet-like asset, else the first: frames f-1 and f of each renderer and their |difference| x8; the
     lodbench run of that one makes --dump-frames --dump-transitions);
  6. DIR/report.md: the status counts, per asset the table of switches, the fidelity, the commands.

Then, unless --keep-pictures, every run's and score's PNG folders (frames/, frame/, counterfactual/, reference/)
and frames.csv (but under the tune rule's runs) are deleted, and fidelity's pictures are left in a
temporary folder: what stays is CSVs, run.json, score.json, lods.csv, the figures and report.md.

frame_diff is frame_three - frame_lodbench. Needs Chromium and `npm ci --prefix scripts/threejs` (as three_lod.py).
"""
import argparse
import csv
import json
import math
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from lodbench_results import read_csv, save_figure  # noqa: E402
from tune_rules import DIAGONAL, RULES, camera_eye, markdown, write_path  # noqa: E402

PATHS = (("axis", (0.0, 0.0, 1.0)), ("diagonal", DIAGONAL))
FADES = ("default", "time", "distance")
PICTURE_DIRS = ("frames", "frame", "counterfactual", "reference")
# What a kept-small lodbench-fade-* folder keeps.
FADE_KEEP = ("transitions.csv", "summary.csv", "answer.json")
COLUMNS = [
    "asset", "path", "rule", "variant", "lodbench_fade", "pair", "order", "switch_distance",
    "frame_lodbench", "frame_three", "frame_diff", "distance_lodbench", "distance_three", "anchor_distance_three",
    "lodpop_lodbench", "lodpop_three", "coverage_lodbench", "shading_lodbench", "coverage_three", "shading_three",
    "budget", "within_lodbench", "within_three", "status",
]
STATUSES = ("agree", "frame-differs", "verdict-differs", "missing-in-three", "missing-in-lodbench")
STRIP_GAIN = 8

T0 = time.monotonic()


def progress(message: str):
    print(f"[{time.monotonic() - T0:7.1f} s] {message}", flush=True)


# ---- The matching (pure) ----

def switch_events(lods):
    """[(frame, from, to)] of a per-frame list of levels: every frame whose level differs from the frame before."""
    return [(f, lods[f - 1], lods[f]) for f in range(1, len(lods)) if lods[f] != lods[f - 1]]


def match_switches(lods_lodbench, lods_three):
    """lodbench's switches against three.js's: per-frame level lists (index = frame) in, one dict per switch out,
    in frame order. Switches are matched by their order within their pair from->to (the n-th 0->1 of one with the
    n-th 0->1 of the other); a switch of one with no partner has the other's frame None. Keys: pair ("0->1"),
    order (0-based within the pair), frame_lodbench, frame_three, frame_diff (three - lodbench, or None), status
    (None where matched, else missing-in-three or missing-in-lodbench)."""
    def by_pair(events):
        out = {}
        for f, a, b in events:
            out.setdefault((a, b), []).append(f)
        return out

    ours, theirs = by_pair(switch_events(lods_lodbench)), by_pair(switch_events(lods_three))
    rows = []
    for pair in sorted(set(ours) | set(theirs)):
        a, b = ours.get(pair, []), theirs.get(pair, [])
        for i in range(max(len(a), len(b))):
            fl = a[i] if i < len(a) else None
            ft = b[i] if i < len(b) else None
            rows.append({
                "pair": f"{pair[0]}->{pair[1]}", "order": i, "frame_lodbench": fl, "frame_three": ft,
                "frame_diff": ft - fl if fl is not None and ft is not None else None,
                "status": None if fl is not None and ft is not None else
                ("missing-in-three" if ft is None else "missing-in-lodbench"),
            })
    rows.sort(key=lambda r: min(f for f in (r["frame_lodbench"], r["frame_three"]) if f is not None))
    return rows


def status_of(frame_lodbench, frame_three, within_lodbench, within_three) -> str:
    """agree, frame-differs or verdict-differs for a matched switch (a verdict difference wins)."""
    if within_lodbench != within_three:
        return "verdict-differs"
    return "agree" if frame_lodbench == frame_three else "frame-differs"


def discrete_lods(frames_rows, method="discrete"):
    """The level lodbench's discrete draws per frame, from frames.csv's rows: floor(lod_mean + 0.5) (lod_from while
    k < 0.5, lod_to from k = 0.5 along an outward path). A list indexed by frame."""
    rows = sorted((r for r in frames_rows if r["method"] == method), key=lambda r: int(r["frame"]))
    frames = [int(r["frame"]) for r in rows]
    if frames != list(range(len(frames))):
        raise ValueError(f"{method}: frames.csv's frames are not 0..{len(frames) - 1} once each")
    return [math.floor(float(r["lod_mean"]) + 0.5) for r in rows]


def three_lods(lods_rows, obj=None):
    """The level three.js drew per frame, from a score folder's lods.csv (one LOD object: `obj`, or the only one)."""
    objects = sorted({r["object"] for r in lods_rows})
    if obj is None:
        if len(objects) != 1:
            raise ValueError(f"lods.csv has {len(objects)} objects ({', '.join(objects)}): name one")
        obj = objects[0]
    rows = sorted((r for r in lods_rows if r["object"] == obj), key=lambda r: int(r["frame"]))
    frames = [int(r["frame"]) for r in rows]
    if frames != list(range(len(frames))):
        raise ValueError(f"lods.csv: {obj}'s frames are not 0..{len(frames) - 1} once each")
    return [int(r["lod"]) for r in rows]


# ---- Running things ----

def call(args, what: str):
    done = subprocess.run([str(a) for a in args], capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{what} failed: {' '.join(map(str, args))}\n{done.stderr.strip()[-2000:]}")
    return done.stdout


def number(x, digits=6):
    return "" if x is None else f"{x:.{digits}g}"


def per_frame(frames_rows, method, column):
    return {int(r["frame"]): (float(r[column]) if r[column] != "" else None) for r in frames_rows
            if r["method"] == method}


class Asset:
    """One tune folder: its model, rules and paths."""

    def __init__(self, tune_dir: Path, out: Path, frames: int, binary: Path):
        self.tune_dir = tune_dir.resolve()
        self.name = self.tune_dir.name.removeprefix("tune-")
        self.meta = json.loads((self.tune_dir / "tune.json").read_text())
        budget = self.meta["settings"]["budget"]
        if budget["metric"] != "lodpop":
            raise RuntimeError(f"{tune_dir}: a {budget['metric']} budget; this checks lodpop budgets")
        self.budget = float(budget["value"])
        models = [m for m in self.meta["models"] if m["pairs"]]
        if len(models) != 1:
            raise RuntimeError(f"{tune_dir}: {len(models)} models with LOD pairs; this checks scenes of one model")
        self.model = models[0]
        self.width, self.height = int(self.meta["width"]), int(self.meta["height"])
        self.tuned = self.tune_dir / "tuned.glb"
        rules = read_csv(self.tune_dir / "rules.csv")
        # The distances as rules.csv writes them (f32's shortest text): lodbench reads the same f32 three.js gets.
        self.switch_text = {r: [x["distance"] for x in sorted((x for x in rules if x["rule"] == r),
                                                               key=lambda x: int(x["lod_from"]))] for r in RULES}
        self.switches = {r: [float(d) for d in v] for r, v in self.switch_text.items()}
        self.out = out / self.name
        self.frames = frames
        self.binary = binary
        # The geometry of scripts/tune_rules.py's paths: the flight starts where the model fits the view, straight
        # along +z from the model's centre (in the world); from there, or nearer where a rule switches nearer (not
        # within 1.1 radii), to a quarter beyond the farthest switch of any rule.
        eye = camera_eye(binary, self.tuned, self.width, self.height, 0)
        self.centre = [eye[0], eye[1], eye[2] - self.model["near"]]
        far = 1.25 * max(max(v) for v in self.switches.values() if v)
        nearest = min(min(v) for v in self.switches.values() if v)
        self.near = max(1.1 * self.model["radius"], min(self.model["near"], 0.9 * nearest))
        self.far = far
        self.paths, self.eyes = {}, {}

    def write_paths(self):
        self.out.mkdir(parents=True, exist_ok=True)
        for name, direction in PATHS:
            p = self.out / f"path-{name}.csv"
            write_path(p, self.centre, direction, self.near, self.far, self.frames)
            self.paths[name] = p
            cams = json.loads(call([self.binary, "describe", "--scene", self.tuned, "--camera-path", p, "--frames",
                                    self.frames, "--width", self.width, "--height", self.height, "--cameras-json"],
                                   "lodbench describe"))
            self.eyes[name] = [c["eye"] for c in sorted(cams["frames"], key=lambda c: c["frame"])]

    def distance(self, path, frame, to=None):
        if frame is None:
            return None
        return math.dist(self.eyes[path][frame], to or self.centre)


def lodbench_run(asset: Asset, path: str, rule: str, folder: Path, fade: str, dump: bool):
    args = [asset.binary, "run", "--scene", asset.tuned, "--method", "reference,discrete", "--baseline",
            "reference", "--camera-path", asset.paths[path], "--switch-distances", ",".join(asset.switch_text[rule]),
            "--width", asset.width, "--height", asset.height, "--frames", asset.frames, "--warmup", 0, "--rounds", 2,
            "--metrics", "rmse,pop,flip", "--budget-lodpop", number(asset.budget)]
    if fade != "default":
        args += ["--fade", fade]
    if dump:
        args += ["--dump-frames", "--dump-transitions"]
    shutil.rmtree(folder, ignore_errors=True)
    try:
        call(args + ["--out", folder], "lodbench run")
    except RuntimeError as e:
        # A distance fade refuses switches whose bands (5 % each side) overlap; discrete switches at the band's
        # centre whatever its width, so a narrower band gives the same switches.
        if fade != "distance" or "overlap" not in str(e):
            raise
        shutil.rmtree(folder, ignore_errors=True)
        args += ["--band", "0.01"]
        call(args + ["--out", folder], "lodbench run")
    return args + ["--out", folder]


def three_run(asset: Asset, path: str, rule: str, folder: Path, anchor: str):
    args = [sys.executable, HERE / "three_lod.py", asset.tune_dir, "--path", asset.paths[path], "--rule", rule,
            "--anchor", anchor, "--frames", asset.frames, "--lodbench", asset.binary, "--out", folder]
    call(args, "three_lod.py")
    score = [asset.binary, "score", folder, "--budget-lodpop", number(asset.budget), "--metrics", "rmse,pop,flip"]
    call(score, "lodbench score")
    return args, score


def fade_label(folder: Path) -> str:
    s = json.loads((folder / "run.json").read_text())["scenes"][0]["schedule"]
    return f"time{s['fade_frames']}" if s["fade"] == "time" else s["fade"]


def compare(asset: Asset, path: str, rule: str, variant: str, lb: Path, three: Path):
    """The rows of engine_check.csv of one lodbench run against one score folder, and notes on what looks off."""
    lb_frames, th_frames = read_csv(lb / "frames.csv"), read_csv(three / "frames.csv")
    ours = discrete_lods(lb_frames)
    th_method = json.loads((three / "score.json").read_text())["method"]
    theirs = three_lods(read_csv(three / "lods.csv"))
    score = json.loads((three / "score.json").read_text())
    anchor = score["notes"]["objects"][0]["position"]
    notes = []
    if len(ours) != len(theirs):
        notes.append(f"{lb}: {len(ours)} frames, three.js {len(theirs)}")
    lp = {k: (per_frame(lb_frames, "discrete", c), per_frame(th_frames, th_method, c))
          for k, c in (("lodpop", "lodpop"), ("coverage", "lodpop_coverage"), ("shading", "lodpop_shading"))}
    # lodbench's discrete changes pixels exactly where its level does (the counterfactual is drawn there).
    switch_frames = {f for f, _, _ in switch_events(ours)}
    popped = {f for f, v in lp["lodpop"][0].items() if v}
    if popped - switch_frames:
        notes.append(f"{lb}: discrete has lodpop > 0 on frames {sorted(popped - switch_frames)} where its level "
                     "(floor(lod_mean + 0.5)) does not change")
    pairs = {f"{p['lod_from']}->{p['lod_to']}": i for i, p in enumerate(asset.model["pairs"])}
    fade = fade_label(lb)
    rows = []
    for m in match_switches(ours, theirs):
        fl, ft = m["frame_lodbench"], m["frame_three"]
        get = lambda side, key, f: None if f is None else lp[key][side].get(f)  # noqa: E731
        pop_l, pop_t = get(0, "lodpop", fl), get(1, "lodpop", ft)
        within_l = None if pop_l is None else pop_l <= asset.budget
        within_t = None if pop_t is None else pop_t <= asset.budget
        k = pairs.get(m["pair"])
        rows.append({
            "asset": asset.name, "path": path, "rule": rule, "variant": variant, "lodbench_fade": fade,
            "pair": m["pair"], "order": m["order"],
            "switch_distance": number(asset.switches[rule][k]) if k is not None and k < len(asset.switches[rule])
            else "",
            "frame_lodbench": "" if fl is None else fl, "frame_three": "" if ft is None else ft,
            "frame_diff": "" if m["frame_diff"] is None else m["frame_diff"],
            "distance_lodbench": number(asset.distance(path, fl)), "distance_three": number(asset.distance(path, ft)),
            "anchor_distance_three": number(asset.distance(path, ft, anchor)),
            "lodpop_lodbench": number(pop_l), "lodpop_three": number(pop_t),
            "coverage_lodbench": number(get(0, "coverage", fl)), "shading_lodbench": number(get(0, "shading", fl)),
            "coverage_three": number(get(1, "coverage", ft)), "shading_three": number(get(1, "shading", ft)),
            "budget": number(asset.budget),
            "within_lodbench": "" if within_l is None else str(within_l).lower(),
            "within_three": "" if within_t is None else str(within_t).lower(),
            "status": m["status"] or status_of(fl, ft, within_l, within_t),
        })
    return rows, notes, {"lodbench": ours, "three": theirs, "lodpop_lodbench": lp["lodpop"][0],
                         "lodpop_three": lp["lodpop"][1]}


# ---- Figures ----

def lodpop_figure(asset: Asset, series: dict, out: Path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9, 3.6), dpi=100)
    styles = {
        "lodbench discrete": dict(color="tab:blue", marker="o", ms=7),
        "lodbench discrete (--fade distance)": dict(color="tab:cyan", marker="^", ms=6),
        "three.js THREE.LOD": dict(color="tab:orange", marker="s", ms=5),
        "three.js, LOD at the origin": dict(color="tab:red", marker="x", ms=6),
    }
    for label, values in series.items():
        frames = sorted(values)
        ys = [values[f] or 0.0 for f in frames]
        ax.plot(frames, ys, lw=0.8, alpha=0.6, label=label, **styles.get(label, {}), markevery=[
            i for i, y in enumerate(ys) if y > 0])
    ax.axhline(asset.budget, color="k", ls="--", lw=1, label=f"budget {asset.budget:g}")
    ax.set_xlabel("frame (axis path, distance growing geometrically)")
    ax.set_ylabel("lodpop")
    ax.set_title(f"{asset.name}: lodpop per frame, rule tune, {asset.width}x{asset.height}")
    ax.legend(fontsize=7, loc="upper left")
    ax.set_ylim(bottom=0)
    fig.tight_layout()
    save_figure(fig, out)
    plt.close(fig)


def switch_figure(asset: Asset, row: dict, lb: Path, three: Path, out: Path):
    """Per renderer, around its own switch frame f: frames f-1 and f, |f - (f-1)| amplified (the pop and the
    camera's motion) and |f - f's counterfactual| amplified (frame f's pose drawn with frame f-1's level: the pop
    alone, what lodpop measures), cropped to where the model is."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from PIL import Image

    def load(p):
        return np.asarray(Image.open(p).convert("RGB"), dtype=np.float64) / 255.0

    def dumped(f, kind):
        p = next((lb / "frames").glob(f"*_discrete_c1_f{f:05d}_{kind}.png"), None)
        if p is None:
            raise RuntimeError(f"{lb}/frames has no discrete {kind} dump of frame {f}")
        return load(p)

    fl, ft = int(row["frame_lodbench"]), int(row["frame_three"])
    sides = [("lodbench discrete", fl, dumped(fl - 1, "method"), dumped(fl, "method"),
              dumped(fl, "lodpop-before"), row["lodpop_lodbench"]),
             ("three.js THREE.LOD", ft, load(three / "frame" / f"{ft - 1:05d}.png"),
              load(three / "frame" / f"{ft:05d}.png"), load(three / "counterfactual" / f"{ft:05d}.png"),
              row["lodpop_three"])]
    # The crop: every pixel of any picture that is not the clear colour (its corner), with a margin.
    covered = np.zeros(sides[0][2].shape[:2], dtype=bool)
    for side in sides:
        for img in side[2:5]:
            covered |= np.any(np.abs(img - img[0, 0]) > 1.5 / 255, axis=-1)
    ys, xs = np.nonzero(covered)
    if len(ys):
        h, w = covered.shape
        m = max(8, (ys.max() - ys.min()) // 8, (xs.max() - xs.min()) // 8)
        y0, y1, x0, x1 = max(0, ys.min() - m), min(h, ys.max() + m + 1), max(0, xs.min() - m), min(w, xs.max() + m + 1)
    else:
        y0, y1, x0, x1 = 0, covered.shape[0], 0, covered.shape[1]
    a, b = row["pair"].split("->")
    cw, ch = (x1 - x0), (y1 - y0)
    scale = 2.2 / max(cw, ch)
    fig, axes = plt.subplots(2, 4, figsize=(4 * cw * scale + 0.6, 2 * ch * scale + 1.0), dpi=110, squeeze=False)
    for r, (label, f, before, after, counterfactual, pop) in enumerate(sides):
        panels = ((before, f"frame {f - 1} (LOD {a})"), (after, f"frame {f} (LOD {b})"),
                  (np.clip(np.abs(after - before) * STRIP_GAIN, 0, 1), f"|{f} - {f - 1}| x{STRIP_GAIN}"),
                  (np.clip(np.abs(after - counterfactual) * STRIP_GAIN, 0, 1),
                   f"|{f} - {f} at LOD {a}| x{STRIP_GAIN}\nlodpop {float(pop):.5f}"))
        for c, (img, title) in enumerate(panels):
            ax = axes[r][c]
            ax.imshow(img[y0:y1, x0:x1], interpolation="nearest")
            ax.set_title(title, fontsize=7)
            ax.set_xticks([])
            ax.set_yticks([])
        axes[r][0].set_ylabel(label, fontsize=8)
    fig.suptitle(f"{asset.name}: rule tune, axis path, first switch {row['pair']}, {asset.width}x{asset.height} "
                 f"cropped to x {x0}-{x1 - 1}, y {y0}-{y1 - 1} (budget {asset.budget:g})", fontsize=8)
    fig.tight_layout()
    save_figure(fig, out, palette=False)  # rendered frames: every shade kept
    plt.close(fig)


# ---- Report ----

def shell(args):
    """A command as one line: python3 for this interpreter, paths under the working folder relative to it."""
    cwd = Path.cwd()

    def show(a):
        if str(a) == sys.executable:
            return "python3"
        p = Path(str(a))
        if p.is_absolute() and p.is_relative_to(cwd):
            return str(p.relative_to(cwd))
        return str(a)
    return " ".join(show(a) for a in args)


def report(out: Path, rows, fidelity, notes, commands, argv, seconds):
    text = ["# lodbench's discrete against three.js's THREE.LOD along the same paths", "",
            f"`python3 {shell(argv)}` ({seconds:.0f} s).", "",
            "Per asset (a `lodbench tune` folder), path (axis, diagonal) and rule (tune, unreal, godot, meshopt): "
            "lodbench's discrete (`lodbench run`, the level drawn per frame is floor(lod_mean + 0.5) of frames.csv) "
            "and three.js's THREE.LOD (`scripts/three_lod.py`, scored by `lodbench score`) with the rule's switch "
            "distances; switches matched by order within each pair. frame_diff = three.js's frame - lodbench's. "
            "variant origin: three.js with the LOD object at the model's origin (`--anchor origin`), against the "
            "same lodbench run. lodbench_fade: time8 is lodbench's default on a glTF file (a time fade of 8 frames "
            "from the frame the distance is crossed; discrete switches where k reaches 0.5, 3 frames later), "
            "distance is `--fade distance` (discrete switches at the switch distance itself, as THREE.LOD does). "
            "distance_*: camera eye to the model's bounding-sphere centre on that side's switch frame; "
            "anchor_distance_three: eye to the LOD object, what three.js compared.", ""]
    keys = sorted({(r["lodbench_fade"], r["variant"]) for r in rows})
    counts = []
    for fade, variant in keys:
        sel = [r for r in rows if r["lodbench_fade"] == fade and r["variant"] == variant]
        c = {"lodbench_fade": fade, "variant": variant, "switches": len(sel)}
        c.update({s: sum(r["status"] == s for r in sel) for s in STATUSES})
        diffs = sorted({r["frame_diff"] for r in sel if r["frame_diff"] != ""})
        c["frame_diffs"] = " ".join(str(d) for d in diffs)
        counts.append(c)
    text += ["## Status counts", "", markdown(counts, ["lodbench_fade", "variant", "switches", *STATUSES,
                                                       "frame_diffs"]), ""]
    cols = ["path", "rule", "variant", "lodbench_fade", "pair", "switch_distance", "frame_lodbench", "frame_three",
            "frame_diff", "distance_lodbench", "distance_three", "lodpop_lodbench", "lodpop_three",
            "within_lodbench", "within_three", "status"]
    for asset in sorted({r["asset"] for r in rows}, key=[r["asset"] for r in rows].index):
        sel = [r for r in rows if r["asset"] == asset]
        text += [f"## {asset}", "", markdown(sel, cols), "",
                 f"![lodpop per frame](figures/lodpop_{asset}.png)", ""]
    strips = sorted((out / "figures").glob("switch_*.png"))
    for s in strips:
        text += [f"![a switch in both](figures/{s.name})", ""]
    text += ["## Fidelity: lodbench's reference against three.js on each tuned.glb", "",
             "scripts/three_fidelity.py's compare() at tune's viewport: mean FLIP of lodbench's reference frame 0 "
             "against three.js's (flat: lodbench with --materials flat, a renderer that ignores the materials); "
             "covered: over the pixels either draws.", "",
             markdown(fidelity, ["asset", "file", "width", "height", "flip_mean", "flip_mean_flat", "flip_covered",
                                 "flip_covered_flat", "rmse", "covered_share"]), ""]
    if notes:
        text += ["## Notes", ""] + [f"- {n}" for n in notes] + [""]
    text += ["## Commands", "", "Per asset, path and rule (PATH-RULE folders under DIR/ASSET/):", "", "```"]
    text += [shell(c) for c in commands] + ["```", ""]
    (out / "report.md").write_text("\n".join(text))


def clean(out: Path):
    """Every run's and score's PNG folders under `out`, and frames.csv but under the tune rule's runs; the fade runs
    keep FADE_KEEP only."""
    for folder in out.glob("*/*-*/*"):
        if not folder.is_dir():
            continue
        for name in PICTURE_DIRS:
            shutil.rmtree(folder / name, ignore_errors=True)
        # frames.csv is kept for the tune rule's runs alone (the lodpop figures'): engine_check.csv holds every
        # switch of the others.
        if not folder.parent.name.endswith("-tune"):
            (folder / "frames.csv").unlink(missing_ok=True)
        if folder.name.startswith("lodbench-fade-"):
            for p in folder.iterdir():
                if p.name not in FADE_KEEP:
                    shutil.rmtree(p) if p.is_dir() else p.unlink()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("tune_dirs", type=Path, nargs="+", metavar="TUNE_DIR")
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--frames", type=int, default=240, help="frames of each path (default 240)")
    ap.add_argument("--binary", type=Path, default=Path("target/release/lodbench"))
    ap.add_argument("--fades", default="default,distance",
                    help="lodbench's fades to run, comma-separated: default (lodbench's for the file), time, "
                         "distance (default: default,distance); the first one's run folder is `lodbench`")
    ap.add_argument("--keep-pictures", action="store_true",
                    help="keep the PNG folders of every run and score folder and fidelity's pictures")
    a = ap.parse_args()
    fades = [f.strip() for f in a.fades.split(",") if f.strip()]
    if not fades or any(f not in FADES for f in fades):
        ap.error(f"--fades takes {', '.join(FADES)}")
    binary = a.binary.resolve()
    for t in a.tune_dirs:
        for name in ("tune.json", "rules.csv", "tuned.glb", "engines/threejs-lod.js"):
            if not (t / name).is_file():
                print(f"error: {t} has no {name}: give folders `lodbench tune --out` wrote", file=sys.stderr)
                return 2
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / "figures").mkdir(exist_ok=True)
    assets = [Asset(t, a.out, a.frames, binary) for t in a.tune_dirs]
    if len({x.name for x in assets}) != len(assets):
        print("error: two tune folders give the same asset name", file=sys.stderr)
        return 2
    strip_asset = next((x for x in assets if "helmet" in x.name.lower()), assets[0])
    rows, notes, commands = [], [], []
    for asset in assets:
        progress(f"{asset.name}: paths ({a.frames} frames, {asset.near:.4g} to {asset.far:.4g} from the centre "
                 f"{[round(c, 4) for c in asset.centre]})")
        asset.write_paths()
        series = {}
        for path, _ in PATHS:
            for rule in RULES:
                folder = asset.out / f"{path}-{rule}"
                runs = {}
                for i, fade in enumerate(fades):
                    lb = folder / ("lodbench" if i == 0 else f"lodbench-fade-{fade}")
                    dump = i == 0 and asset is strip_asset and path == "axis" and rule == "tune"
                    progress(f"{asset.name} {path} {rule}: lodbench run ({fade} fade{', dumps' if dump else ''})")
                    args = lodbench_run(asset, path, rule, lb, fade, dump)
                    if asset is assets[0] and path == "axis":
                        commands.append(args)
                    runs[fade] = lb
                variants = [("centre", "three")] + ([("origin", "three-origin")] if rule == "tune" else [])
                for variant, sub in variants:
                    progress(f"{asset.name} {path} {rule}: three.js ({variant}) and lodbench score")
                    three_args, score_args = three_run(asset, path, rule, folder / sub, variant)
                    if asset is assets[0] and path == "axis":
                        commands += [three_args, score_args]
                    for fade, lb in runs.items():
                        got, n, data = compare(asset, path, rule, variant, lb, folder / sub)
                        rows += got
                        notes += n
                        if path == "axis" and rule == "tune":
                            label = "lodbench discrete" + ("" if fade == fades[0] else f" (--fade {fade})")
                            series[label] = data["lodpop_lodbench"]
                            series["three.js THREE.LOD" if variant == "centre" else
                                   "three.js, LOD at the origin"] = data["lodpop_three"]
                done = [r for r in rows if r["asset"] == asset.name and r["path"] == path and r["rule"] == rule]
                progress(f"{asset.name} {path} {rule}: " + ", ".join(
                    f"{r['variant']}/{r['lodbench_fade']} {r['pair']} {r['frame_lodbench']}|{r['frame_three']} "
                    f"{r['status']}" for r in done))
        lodpop_figure(asset, series, a.out / "figures" / f"lodpop_{asset.name}.png")
    progress("switch strip")
    first = next((r for r in rows if r["asset"] == strip_asset.name and r["path"] == "axis" and r["rule"] == "tune"
                  and r["variant"] == "centre" and r["lodbench_fade"] == fade_label(
                      strip_asset.out / "axis-tune" / "lodbench")
                  and r["frame_lodbench"] != "" and r["frame_three"] != ""), None)
    if first is None:
        notes.append(f"{strip_asset.name}: no switch in both renderers on the axis path with rule tune: no strip")
    else:
        switch_figure(strip_asset, first, strip_asset.out / "axis-tune" / "lodbench",
                      strip_asset.out / "axis-tune" / "three", a.out / "figures" / f"switch_{strip_asset.name}.png")
    with open(a.out / "engine_check.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=COLUMNS)
        w.writeheader()
        w.writerows(rows)
    progress("fidelity (scripts/three_fidelity.py compare)")
    import three_fidelity
    from browser import chromium_binary
    fidelity = []
    keep = a.out / "fidelity" if a.keep_pictures else None
    with tempfile.TemporaryDirectory() as tmp:
        for asset in assets:
            where = keep / asset.name if keep else Path(tmp) / asset.name
            where.mkdir(parents=True, exist_ok=True)
            row = three_fidelity.compare(binary, chromium_binary(), asset.tuned, where, asset.width, asset.height)
            fidelity.append({"asset": asset.name, **row})
            progress(f"{asset.name}: FLIP {row['flip_mean']} (flat {row['flip_mean_flat']}), covered "
                     f"{row['flip_covered']}")
    with open(a.out / "fidelity.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=["asset"] + three_fidelity.COLUMNS)
        w.writeheader()
        w.writerows(fidelity)
    if not a.keep_pictures:
        progress("deleting the PNG folders (--keep-pictures keeps them)")
        clean(a.out)
    argv = ["scripts/engine_check.py"] + sys.argv[1:]
    report(a.out, rows, fidelity, notes, commands, argv, time.monotonic() - T0)
    for n in notes:
        print(f"note: {n}")
    counts = {s: sum(r["status"] == s for r in rows) for s in STATUSES}
    progress(f"{len(rows)} switches: " + ", ".join(f"{k} {v}" for k, v in counts.items()) +
             f"; {a.out / 'engine_check.csv'}, {a.out / 'report.md'}")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except RuntimeError as e:
        print(f"error: {e}", file=sys.stderr)
        sys.exit(2)
