#!/usr/bin/env python3
"""Independent check of lodbench's image differences, from the PNGs alone.

For every frame dumped with `lodbench run --dump-frames` (results/<run>/frames/*_method.png and
*_reference.png), recompute
  - rmse as Sheliemietiev et al. 2023 section 6 steps 5-6, with numpy: per pixel the mean over R, G, B of |a - b| on the
    sRGB-encoded values in [0, 1], then the root mean square over pixels;
  - the mean CIEDE2000 with colour-science:
    colour.delta_E(XYZ_to_Lab(sRGB_to_XYZ(a)), XYZ_to_Lab(sRGB_to_XYZ(b)), method="CIE 2000"), averaged over pixels;
and compare them with the `rmse` and `de2000_mean` columns of frames.csv. Exits 1 on any mismatch, naming the
frame; 2 when the folder cannot be checked.

    python3 scripts/check_colour.py RESULTS_DIR [--rmse-tol 1e-4] [--de2000-tol 1e-3]
"""
import argparse
import sys
import warnings
from pathlib import Path

import numpy as np

from dumps import load_rgb, parse_stem
from lodbench_results import FRAMES_CSV, frames_by_key

with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # colour-science warns about optional packages it does not need here
    import colour


def rmse(a: np.ndarray, b: np.ndarray) -> float:
    d = np.abs(a - b).mean(axis=-1)
    return float(np.sqrt(np.mean(d * d)))


def de2000_mean(a: np.ndarray, b: np.ndarray) -> float:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        lab_a = colour.XYZ_to_Lab(colour.sRGB_to_XYZ(a))
        lab_b = colour.XYZ_to_Lab(colour.sRGB_to_XYZ(b))
        return float(np.mean(colour.delta_E(lab_a, lab_b, method="CIE 2000")))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("results", type=Path, help="a results folder written with --dump-frames")
    ap.add_argument("--rmse-tol", type=float, default=1e-4)
    ap.add_argument("--de2000-tol", type=float, default=1e-3)
    args = ap.parse_args()

    frames_csv = args.results / FRAMES_CSV
    if not frames_csv.is_file():
        print(f"error: {frames_csv} not found (is this a complete lodbench run?)", file=sys.stderr)
        return 2
    rows = frames_by_key(frames_csv)
    dumps = sorted((args.results / "frames").glob("*_method.png"))
    if not dumps:
        print(f"error: no *_method.png under {args.results / 'frames'} (run with --dump-frames)", file=sys.stderr)
        return 2

    mismatches = 0
    checked = 0
    with_de2000 = 0
    for method_png in dumps:
        key = parse_stem(method_png.name)
        if key is None:
            print(f"error: unexpected file name {method_png.name}", file=sys.stderr)
            return 2
        scene, method, count, frame = key
        row = rows.get(key)
        reference_png = method_png.with_name(method_png.name.replace("_method.png", "_reference.png"))
        if row is None or not reference_png.is_file():
            print(f"MISMATCH frame {frame} ({scene} {method} n={count}): no frames.csv row or no reference PNG")
            mismatches += 1
            continue
        a, b = load_rgb(method_png), load_rgb(reference_png)
        got_rmse, csv_rmse = rmse(a, b), float(row["rmse"])
        checked += 1
        problems = []
        if abs(got_rmse - csv_rmse) > args.rmse_tol:
            problems.append(f"rmse csv {csv_rmse:.6g} vs png {got_rmse:.6g}")
        # de2000_mean is empty unless the run asked for it (--metrics rmse,pop,de2000).
        if row.get("de2000_mean", "") != "":
            got_de, csv_de = de2000_mean(a, b), float(row["de2000_mean"])
            with_de2000 += 1
            if abs(got_de - csv_de) > args.de2000_tol:
                problems.append(f"de2000_mean csv {csv_de:.6g} vs png {got_de:.6g}")
        if problems:
            mismatches += 1
            print(f"MISMATCH frame {frame} ({scene} {method} n={count}): " + "; ".join(problems))
    print(f"checked {checked} frames ({with_de2000} with de2000_mean): {checked - mismatches} agree, "
          f"{mismatches} differ (tolerances rmse {args.rmse_tol}, de2000 {args.de2000_tol})")
    return 1 if mismatches else 0


if __name__ == "__main__":
    sys.exit(main())
