"""One method's frame in the middle of each transition of a run, side by side: the figures of geomorph on textured
assets in docs/findings/materials.md.

    python3 scripts/transition_strip.py RUN_DIR METHOD OUT.png

RUN_DIR is a `lodbench run ... --dump-frames --dump-transitions` folder of one scene and count; each transition's
middle frame (transitions.csv's first_frame and last_frame) is read from frames/, every tile cropped to the box
that any of them draws (the background is the first frame's top-left pixel), 4 pixels around it, and the strip
written at twice the size (nearest neighbour)."""
import argparse
import csv
import sys
from pathlib import Path

from PIL import Image, ImageChops

from dumps import dump_path


def middle_frames(run: Path, method: str):
    """[(scene, count, frame)] of each transition of `method`, in transitions.csv's order."""
    with open(run / "transitions.csv", newline="") as f:
        rows = [r for r in csv.DictReader(f) if r["method"] == method]
    return [(r["scene"], int(r["count"]), (int(r["first_frame"]) + int(r["last_frame"])) // 2) for r in rows]


def strip(images):
    """The images cropped to what any of them draws (4 pixels around it), side by side, at twice the size."""
    background = Image.new("RGB", images[0].size, images[0].getpixel((0, 0)))
    box = None
    for im in images:
        b = ImageChops.difference(im, background).getbbox()
        if b:
            box = b if box is None else (min(box[0], b[0]), min(box[1], b[1]), max(box[2], b[2]), max(box[3], b[3]))
    w, h = images[0].size
    box = (0, 0, w, h) if box is None else (max(0, box[0] - 4), max(0, box[1] - 4), min(w, box[2] + 4),
                                           min(h, box[3] + 4))
    tiles = [im.crop(box) for im in images]
    tw, th = tiles[0].size
    out = Image.new("RGB", (tw * len(tiles), th), images[0].getpixel((0, 0)))
    for i, t in enumerate(tiles):
        out.paste(t, (i * tw, 0))
    return out.resize((out.width * 2, out.height * 2), Image.NEAREST)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("run", type=Path)
    p.add_argument("method")
    p.add_argument("out", type=Path)
    a = p.parse_args(argv)
    frames = middle_frames(a.run, a.method)
    if not frames:
        print(f"error: {a.run / 'transitions.csv'} has no transition of {a.method}", file=sys.stderr)
        return 2
    paths = [dump_path(a.run, scene, a.method, count, f, "method") for scene, count, f in frames]
    missing = [str(q) for q in paths if not q.is_file()]
    if missing:
        print(f"error: no dump {missing[0]}: run with --dump-frames --dump-transitions", file=sys.stderr)
        return 2
    strip([Image.open(q).convert("RGB") for q in paths]).save(a.out)
    print(f"{a.out}: frames {', '.join(str(f) for _, _, f in frames)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
