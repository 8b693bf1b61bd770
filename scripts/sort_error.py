"""The sorting error of a blending method, apart from its LOD error: per dumped frame, lodbench's rmse between the
method's frame and the same blend composited in exact depth order (`alpha-sorted`, claim F9).

    python3 scripts/sort_error.py RUN_DIR [--method alpha] [--sorted alpha-sorted]

RUN_DIR is a `lodbench run --method alpha,alpha-sorted --dump-frames` folder (add `--dump-transitions` to keep
only the frames near transitions). Both methods draw the same LODs with the same alphas; `alpha` composites the
translucent ones in draw order (sorted by instance only), `alpha-sorted` every fragment in depth order, so their
difference is the sorting error alone. rmse as lodbench defines it (docs/measurement.md: per pixel the mean
over R, G, B of |a - b| on the stored sRGB bytes / 255, then the root mean square over pixels), with each
channel's difference first lowered by --tolerance levels: `alpha` blends layer by layer in the hardware,
rounding to 8 bits after each, `alpha-sorted` accumulates in floats and rounds once, so where the order is the
same the two frames still differ by one level on some pixels (measured: every differing pixel of a frame with one
translucent layer differs by exactly 1). Compared with each method's own rmse to the reference from frames.csv.
Writes sort_error.csv into RUN_DIR and prints a summary per scene and instance count.
"""
import argparse
import csv
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from dumps import load_rgb, parse_stem  # noqa: E402
from lodbench_results import FRAMES_CSV, frames_by_key  # noqa: E402


def rmse(a: np.ndarray, b: np.ndarray, tolerance: int = 0) -> float:
    """lodbench's rmse between two sRGB images in [0, 1] (as dumps.load_rgb reads them), each channel's difference
    first lowered by `tolerance` levels of 8 bits (at least 0), in whole levels."""
    levels = np.abs(np.rint(a * 255.0).astype(np.int64) - np.rint(b * 255.0).astype(np.int64))
    d = np.maximum(levels - tolerance, 0) / 255.0
    return float(np.sqrt(np.mean(np.mean(d, axis=2) ** 2)))


def mean_of(rows, k):
    """The mean of column `k` over the rows where it is not empty; nan where it is empty in every row."""
    return np.mean([float(r[k]) for r in rows if r[k] != ""]) if any(r[k] != "" for r in rows) else float("nan")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run")
    ap.add_argument("--method", default="alpha")
    ap.add_argument("--sorted", default="alpha-sorted")
    ap.add_argument("--tolerance", type=int, default=1,
                    help="levels of 8 bits by which a channel may differ before it counts (default 1: the two "
                         "composites round differently)")
    a = ap.parse_args(argv)
    run = Path(a.run)
    frames_dir, frames_csv = run / "frames", run / FRAMES_CSV
    if not frames_dir.is_dir() or not frames_csv.is_file():
        sys.exit(f"error: {run}: no frames/ or frames.csv (run lodbench with --dump-frames into it)")
    rows = frames_by_key(frames_csv)
    out = []
    for path in sorted(frames_dir.glob(f"*_{a.method}_c*_method.png")):
        key = parse_stem(path.name)
        if key is None or key[1] != a.method:
            continue
        scene, _, count, frame = key
        other = path.with_name(path.name.replace(f"_{a.method}_c", f"_{a.sorted}_c", 1))
        if not other.is_file():
            continue
        m, s = rows.get((scene, a.method, count, frame)), rows.get((scene, a.sorted, count, frame))
        out.append({
            "scene": scene, "count": count, "frame": frame,
            "t_instances": m["t_instances"] if m else "",
            "sort_rmse": rmse(load_rgb(path), load_rgb(other), a.tolerance),
            "rmse": m["rmse"] if m else "", "rmse_sorted": s["rmse"] if s else "",
        })
    if not out:
        sys.exit(f"error: {run}: no frame dumped for both {a.method} and {a.sorted}")
    with open(run / "sort_error.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(out[0]))
        w.writeheader()
        for r in out:
            w.writerow({**r, "sort_rmse": f"{r['sort_rmse']:.6g}"})
    groups = defaultdict(list)
    for r in out:
        groups[(r["scene"], r["count"])].append(r)
    print("| scene | count | frames | in transition | sort_rmse mean | sort_rmse max | rmse mean (method) | "
          "rmse mean (sorted) |")
    print("|---|---|---|---|---|---|---|---|")
    for (scene, count), rs in groups.items():
        sort = np.array([r["sort_rmse"] for r in rs])
        moving = sum(1 for r in rs if r["t_instances"] not in ("", "0"))
        print(f"| {scene} | {count} | {len(rs)} | {moving} | {sort.mean():.5f} | {sort.max():.5f} | "
              f"{mean_of(rs, 'rmse'):.5f} | {mean_of(rs, 'rmse_sorted'):.5f} |")
    print(f"wrote {run / 'sort_error.csv'}")


if __name__ == "__main__":
    main()
