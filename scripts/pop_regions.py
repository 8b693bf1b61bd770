#!/usr/bin/env python3
"""Where a method's pop comes from: the object's silhouette or its interior, from a run's dumped frames.

    python3 scripts/pop_regions.py RUN_DIR [--method fsi,discrete] [--frames 40-50] [--band 2] [--border 4]

RUN_DIR is a `lodbench run --dump-frames` folder (frames need their predecessor dumped: `--dump-every 1`, the
default, with or without `--dump-transitions`). For each dumped frame t of each method, from the PNGs:
  - pop        lodbench's pop, recomputed: sqrt(mean over pixels and channels of (E_t - E_{t-1})^2), E = method -
               reference, values b / 255; `pop_csv` is frames.csv's value for comparison (they agree to ~1e-5);
  - silhouette the share of sum (E_t - E_{t-1})^2 on pixels within --band pixels (4-neighbour steps) of the
               reference's silhouette at t, i.e. within the band of both the object and the background;
  - interior   the share on the rest of the pixels the object covers in the reference at t or t-1 (the two
               shares need not sum to 1: the remainder lies on background outside the band);
  - extra      pixels where the method shows the object and the reference shows background (at t);
  - missing    pixels where the reference shows the object and the method shows background (at t);
  - border     the share of sum (E_t - E_{t-1})^2 on the pixels within --border pixels of the viewport's edge
               (where a camera's motion brings in pixels no earlier frame saw: FSI's border artefacts), whatever
               they show;
  - border_pop pop over those pixels alone: sqrt(mean over them and the channels of (E_t - E_{t-1})^2).
"Object" is any pixel whose colour differs from the background, which is the most frequent colour on the
reference's border (override with --background R,G,B as bytes). Exit 2 with a message on a folder without dumps.
"""
import argparse
import sys
from collections import Counter
from pathlib import Path

import numpy as np

from dumps import load_rgb, parse_stem
from lodbench_results import FRAMES_CSV, frames_by_key


def dilate(mask: np.ndarray, steps: int) -> np.ndarray:
    out = mask.copy()
    for _ in range(steps):
        grown = out.copy()
        grown[1:] |= out[:-1]
        grown[:-1] |= out[1:]
        grown[:, 1:] |= out[:, :-1]
        grown[:, :-1] |= out[:, 1:]
        out = grown
    return out


def border_colour(img: np.ndarray) -> tuple:
    border = np.concatenate([img[0], img[-1], img[:, 0], img[:, -1]])
    return Counter(map(tuple, border)).most_common(1)[0][0]


def regions(method_prev, reference_prev, method, reference, band, background=None, border=4) -> dict:
    """The numbers of one frame t from the method and reference images (H x W x 3, values in [0, 1], as
    `load_rgb` reads them) at t-1 and t; `background` in the same units; `border`: the edge strip's width."""
    bg = np.array(background if background is not None else border_colour(reference))
    diff = (method - reference) - (method_prev - reference_prev)
    energy = (diff ** 2).sum(axis=2)
    obj = np.any(reference != bg, axis=2)
    obj_prev = np.any(reference_prev != bg, axis=2)
    shown = np.any(method != bg, axis=2)
    silhouette = dilate(obj, band) & dilate(~obj, band)
    interior = (obj | obj_prev) & ~silhouette
    total = energy.sum()
    edge = np.zeros(energy.shape, dtype=bool)
    edge[:border] = edge[-border:] = True
    edge[:, :border] = edge[:, -border:] = True
    return {
        "pop": float(np.sqrt(energy.sum() / diff.size)),
        "silhouette": float(energy[silhouette].sum() / total) if total > 0 else 0.0,
        "interior": float(energy[interior].sum() / total) if total > 0 else 0.0,
        "extra": int((shown & ~obj).sum()),
        "missing": int((obj & ~shown).sum()),
        "border": float(energy[edge].sum() / total) if total > 0 else 0.0,
        "border_pop": float(np.sqrt(energy[edge].sum() / (3 * edge.sum()))),
    }


def parse_frames(text):
    frames = set()
    for part in text.split(","):
        lo, sep, hi = part.partition("-")
        if not lo.strip().isdigit() or (sep and not hi.strip().isdigit()):
            raise ValueError(f"--frames {text!r}: expected numbers and ranges like 40-50,60")
        frames.update(range(int(lo), int(hi or lo) + 1))
    return frames


def parse_background(text):
    """`R,G,B` bytes -> the colour in [0, 1]."""
    parts = text.split(",")
    if len(parts) != 3 or not all(p.strip().isdigit() and int(p) <= 255 for p in parts):
        raise ValueError(f"--background {text!r}: expected three bytes R,G,B")
    return [int(p) / 255.0 for p in parts]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run", type=Path)
    ap.add_argument("--method", help="comma-separated methods (default: every method with dumps)")
    ap.add_argument("--frames", help="frames t to report, e.g. 40-50,60 (default: every dumped frame whose "
                                     "predecessor is dumped)")
    ap.add_argument("--band", type=int, default=2, help="silhouette half-width in pixels (default 2)")
    ap.add_argument("--border", type=int, default=4, help="width in pixels of the viewport's edge strip (default 4)")
    ap.add_argument("--background", help="background colour as R,G,B bytes (default: the reference's most "
                                          "frequent border colour)")
    args = ap.parse_args()
    frames_dir = args.run / "frames"
    try:
        wanted = parse_frames(args.frames) if args.frames else None
        background = parse_background(args.background) if args.background else None
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    if args.border < 1:
        print(f"error: --border {args.border}: expected 1 or more", file=sys.stderr)
        return 2
    if args.band < 1:
        print(f"error: --band {args.band}: expected 1 or more", file=sys.stderr)
        return 2
    dumps = sorted(frames_dir.glob("*_method.png")) if frames_dir.is_dir() else []
    keys = [k for k in (parse_stem(p.name) for p in dumps) if k]
    if not keys:
        print(f"error: {frames_dir} holds no dumped frames (run lodbench with --dump-frames)", file=sys.stderr)
        return 2
    methods = args.method.split(",") if args.method else sorted({method for _, method, _, _ in keys})
    csv_pop = {}
    if (args.run / FRAMES_CSV).is_file():
        csv_pop = {key: r["pop"] for key, r in frames_by_key(args.run / FRAMES_CSV).items()}
    print("scene,method,count,frame,pop,pop_csv,silhouette,interior,extra,missing,border,border_pop")
    reported = 0
    for key in keys:
        scene, method, count, frame = key
        t = int(frame)
        if method not in methods or (wanted is not None and t not in wanted):
            continue
        stem = frames_dir / f"{scene}_{method}_c{count}_f"
        paths = [Path(f"{stem}{f:05d}_{kind}.png") for f in (t - 1, t) for kind in ("method", "reference")]
        if not all(p.is_file() for p in paths):
            continue
        r = regions(*(load_rgb(p) for p in paths), band=args.band, background=background, border=args.border)
        pop_csv = csv_pop.get(key, "")
        print(f"{scene},{method},{count},{t},{r['pop']:.6f},{pop_csv and f'{float(pop_csv):.6f}'},"
              f"{r['silhouette']:.4f},{r['interior']:.4f},{r['extra']},{r['missing']},{r['border']:.4f},"
              f"{r['border_pop']:.6f}")
        reported += 1
    if reported == 0:
        print("error: no dumped frame matched whose previous frame is dumped too (--method, --frames, "
              "--dump-every 1?)", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
