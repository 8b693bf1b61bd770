#!/usr/bin/env python3
"""The impostor parameter table (docs/findings/impostors.md): one lodbench run per setting of --impostor's
parameters (frames a side, layout, frames a pixel blends, parallax) on the same scene and path, and one of the
chain without an impostor (its billboard-cloud level switched in at the impostor's distance), each method's switch
lodpop split into coverage and shading, view_pop_max, the median GPU time and the atlas's bytes.

    python3 scripts/impostor_sweep.py OUT [--lodbench target/release/lodbench] [--grid table|all|quick]

OUT/<label>/ holds each run's folder; OUT/table.csv and OUT/table.md the table. --grid picks the settings
(table: the findings page's 8; all: every combination; quick: 2, the test's).
"""

import argparse
import csv
import itertools
import math
import os
import subprocess
import sys

# trees at 320 x 240: the camera flies in from where four trees are impostors (LOD4 beyond 20 units) to where
# they are meshes; every switch of the chain happens on the path (mesh LODs at 5, 10, 15 units).
# A time fade of 4 frames gives the blending methods room (the flight crosses a distance band within a frame).
SCENE = ["--scene", "trees", "--count", "4", "--frames", "12", "--width", "320", "--height", "240",
         "--rounds", "1", "--warmup", "1", "--fade", "time", "--fade-frames", "4"]
RESOLUTION = 1024
IMPOSTOR_DISTANCE = "20"
METHODS = "discrete,dither,alpha,alpha-2pass"


# The table's settings: Unreal's Impostor Baker's defaults (16 frames, 3-frame blend) and one change from them
# at a time, plus the smallest atlas both ways. --grid all runs every combination (24 settings, about 40 s each
# on the 2-core machine), --grid quick two (the test's).
TABLE = [(16, "full", 3, False), (16, "full", 1, False), (16, "full", 3, True), (16, "hemi", 3, False),
         (12, "full", 3, False), (8, "full", 3, False), (8, "full", 1, False), (8, "hemi", 3, False)]


def settings(grid):
    if grid == "all":
        chosen = list(itertools.product([8, 12, 16], ["full", "hemi"], [1, 3], [False, True]))
    elif grid == "quick":
        chosen = [(16, "full", 3, False), (8, "hemi", 1, True)]
    else:
        chosen = TABLE
    return [dict(frames=n, layout=lay, blend=b, parallax=p) for n, lay, b, p in chosen]


def label(s):
    if s is None:
        return "billboard-cloud"
    return f"n{s['frames']}-{s['layout']}-b{s['blend']}" + ("-parallax" if s["parallax"] else "")


def flags(s):
    if s is None:
        # The chain as it is: its last level (the billboard cloud) switched in where the impostor would be.
        return ["--switch-distances", "5,10," + IMPOSTOR_DISTANCE]
    f = ["--switch-distances", "5,10,15", "--impostor", "--impostor-frames", str(s["frames"]),
         "--impostor-layout", s["layout"], "--impostor-blend", str(s["blend"]),
         "--impostor-distance", IMPOSTOR_DISTANCE, "--impostor-resolution", str(RESOLUTION)]
    return f + (["--impostor-parallax"] if s["parallax"] else [])


# The orbit: one tree (trees --count 1, every level beyond 4 units the impostor) circled once at 30 units, the
# camera at each elevation looking at the tree's centre height; below the horizon too, where a hemi atlas
# shows its horizon frames.
ORBIT_SCENE = ["--scene", "trees", "--count", "1", "--frames", "48", "--width", "320", "--height", "240",
               "--rounds", "1", "--warmup", "1", "--switch-distances", "1,2,3", "--impostor",
               "--impostor-distance", "4", "--impostor-resolution", str(RESOLUTION), "--method", "discrete"]
ORBIT_RADIUS = 30.0
ORBIT_CENTRE_Y = 4.0
ELEVATIONS = [-20, 0, 30, 60, 85]
ORBIT_SETTINGS = [(16, "full", 3, False), (16, "hemi", 3, False), (16, "full", 1, False), (8, "full", 3, False)]


def orbit_path(path, elevation_deg, keys=49):
    """A camera path (docs/methods.md, "Camera paths") once round the tree at `elevation_deg`."""
    e = math.radians(elevation_deg)
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["frame", "x", "y", "z", "target_x", "target_y", "target_z"])
        for k in range(keys):
            a = 2 * math.pi * k / (keys - 1)
            r = ORBIT_RADIUS * math.cos(e)
            w.writerow([k, r * math.sin(a), ORBIT_CENTRE_Y + ORBIT_RADIUS * math.sin(e), r * math.cos(a),
                        0, ORBIT_CENTRE_Y, 0])


def orbit_table(out, lodbench, quick):
    table = []
    settings = ORBIT_SETTINGS[:2] if quick else ORBIT_SETTINGS
    elevations = [0, 85] if quick else ELEVATIONS
    for n, layout, blend, parallax in settings:
        for e in elevations:
            s = dict(frames=n, layout=layout, blend=blend, parallax=parallax)
            folder = os.path.join(out, "orbit", f"{label(s)}-elev{e}")
            os.makedirs(folder, exist_ok=True)
            path = os.path.join(folder, "path.csv")
            orbit_path(path, e)
            cmd = [lodbench, "run", *ORBIT_SCENE, "--impostor-frames", str(n), "--impostor-layout", layout,
                   "--impostor-blend", str(blend), "--camera-path", path, "--out", os.path.join(folder, "run")]
            print(" ".join(cmd), file=sys.stderr)
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
            table.append(orbit_row(folder, label(s), e))
    write_table(out, "orbit", table, ["setting", "elevation_deg", "view_pop_max", "view_pop_mean", "rmse_mean"])


def orbit_row(folder, setting, elevation):
    """An orbit run's view_pop (largest and mean over the frames) and its mean rmse against the mesh."""
    frames = rows_of(os.path.join(folder, "run", "frames.csv"))
    view = [number(r["view_pop"]) for r in frames]
    rmse = [number(r["rmse"]) for r in frames]
    return {"setting": setting, "elevation_deg": elevation, "view_pop_max": max(view),
            "view_pop_mean": sum(view) / len(view), "rmse_mean": sum(rmse) / len(rmse)}


def write_table(out, name, table, cols):
    with open(os.path.join(out, f"{name}.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(table[0]))
        w.writeheader()
        w.writerows(table)
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for r in table:
        lines.append("| " + " | ".join(str(r[c]) if isinstance(r[c], (str, int)) else sig3(r[c]) for c in cols) + " |")
    with open(os.path.join(out, f"{name}.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print(os.path.join(out, f"{name}.md"))


def rows_of(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def number(text):
    return float(text) if text not in ("", None) else None


def figures(folder, method, last):
    """The method's switch between LOD `last` (the impostor, or the billboard cloud) and the one before it: its
    largest lodpop with the parts on that frame (transitions.csv's rows of that switch); view_pop_max, the
    median GPU time and the fragments per frame."""
    rows = [r for r in rows_of(os.path.join(folder, "transitions.csv")) if r["method"] == method
            and r["lods"] in (f"{last}->{last - 1}", f"{last - 1}->{last}")]
    worst = max(rows, key=lambda r: number(r["lodpop_max"]) or 0.0) if rows else None
    summary = next(r for r in rows_of(os.path.join(folder, "summary.csv")) if r["method"] == method)
    part = (lambda c: number(worst[c])) if worst else (lambda c: None)
    return {
        "switches": len(rows),
        "lodpop_max": part("lodpop_max"),
        "lodpop_coverage": part("lodpop_coverage"),
        "lodpop_shading": part("lodpop_shading"),
        "view_pop_max": number(summary["view_pop_max"]),
        "gpu_ms_median": number(summary["gpu_ms_median"]),
        "fragments_mean": number(summary["fragments_mean"]),
    }


# The cost: 16 trees, all at the chain's last level, from a fixed eye 60 units back; discrete draws the impostors,
# discrete-mesh the billboard clouds in their place, in the same run, paired round by round (5 timing rounds).
# The same run without --impostor is the A/A check: there the two methods draw the same frames.
COST_SCENE = ["--scene", "trees", "--count", "16", "--frames", "24", "--width", "320", "--height", "240",
              "--rounds", "5", "--method", "discrete,discrete-mesh", "--switch-distances", "5,10,15"]


def cost_table(out, lodbench):
    path = os.path.join(out, "cost-path.csv")
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["frame", "x", "y", "z", "target_x", "target_y", "target_z"])
        w.writerow([0, 0, 8, -60, 0, 4, 0])
        w.writerow([1, 0, 8, -60.01, 0, 4, 0])
    table = []
    for name, extra in [("a-a (no impostor)", []),
                        ("impostor", ["--impostor", "--impostor-distance", IMPOSTOR_DISTANCE,
                                      "--impostor-resolution", str(RESOLUTION)])]:
        folder = os.path.join(out, "cost", "aa" if not extra else "impostor")
        cmd = [lodbench, "run", *COST_SCENE, *extra, "--camera-path", path, "--out", folder]
        print(" ".join(cmd), file=sys.stderr)
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        for r in rows_of(os.path.join(folder, "summary.csv")):
            ms, frags = number(r["gpu_ms_median"]), number(r["fragments_mean"])
            table.append({"run": name, "method": r["method"], "gpu_ms_median": ms,
                          "triangles_mean": number(r["triangles_mean"]), "fragments_mean": frags,
                          "ns_per_fragment": ms * 1e6 / frags if ms and frags else None,
                          "ratio_to_discrete": number(r["ratio_to_baseline"]),
                          "ci95_lo": number(r["ratio_to_baseline_ci95_lo"]),
                          "ci95_hi": number(r["ratio_to_baseline_ci95_hi"])})
    write_table(out, "cost", table, ["run", "method", "gpu_ms_median", "triangles_mean", "fragments_mean",
                                     "ns_per_fragment", "ratio_to_discrete", "ci95_lo", "ci95_hi"])


def sig3(x):
    return "-" if x is None else f"{x:.3g}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out")
    ap.add_argument("--lodbench", default="target/release/lodbench")
    ap.add_argument("--grid", choices=["table", "all", "quick"], default="table")
    ap.add_argument("--orbit", action="store_true",
                    help="also the orbit at each elevation (orbit.md) and the cost of the last level (cost.md)")
    ap.add_argument("--orbit-only", action="store_true", help="the orbit and the cost alone")
    ap.add_argument("--cost-only", action="store_true", help="the cost alone")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    if not (a.orbit_only or a.cost_only):
        main_table(a)
    if a.orbit or a.orbit_only:
        orbit_table(a.out, a.lodbench, a.grid == "quick")
    if a.orbit or a.orbit_only or a.cost_only:
        cost_table(a.out, a.lodbench)


def main_table(a):
    """The switch into the impostor for each setting, and the billboard cloud's."""
    table = []
    for s in [None] + settings(a.grid):
        folder = os.path.join(a.out, label(s))
        cmd = [a.lodbench, "run", *SCENE, *flags(s), "--method", METHODS, "--out", folder]
        print(" ".join(cmd), file=sys.stderr)
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        # Four RGBA8 layers of the atlas's side squared (geometry/impostor.rs, atlas_bytes).
        atlas_mib = 0.0 if s is None else RESOLUTION * RESOLUTION * 16 / 2**20
        for m in METHODS.split(","):
            row = {"setting": label(s), "method": m, "atlas_mib": atlas_mib}
            row.update(figures(folder, m, 3 if s is None else 4))
            table.append(row)
    cols = ["setting", "method", "switches", "lodpop_max", "lodpop_coverage", "lodpop_shading", "view_pop_max",
            "gpu_ms_median", "atlas_mib"]
    write_table(a.out, "table", table, cols)


if __name__ == "__main__":
    main()
