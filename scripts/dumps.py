"""What the scripts share about `lodbench run --dump-frames` output: the PNG names and how a PNG is read."""
from pathlib import Path

import numpy as np
from PIL import Image


def load_rgb(path: Path) -> np.ndarray:
    """The PNG's R, G, B as sRGB-encoded floats in [0, 1]."""
    with Image.open(path) as im:
        return np.asarray(im.convert("RGB"), dtype=np.float64) / 255.0


def dump_path(run: Path, scene: str, method: str, count: int, frame: int, kind: str) -> Path:
    """The dump of `kind` (method, reference, error, ...) of a frame: `frames/{scene}_{method}_c{count}_f{frame:05}_
    {kind}.png` (src/results/files.rs names it)."""
    return run / "frames" / f"{scene}_{method}_c{count}_f{frame:05d}_{kind}.png"


def parse_stem(name: str):
    """`{scene}_{method}_c{count}_f{frame:05}_method.png` -> (scene, method, count, frame) as frames.csv writes
    them (strings, the frame without leading zeros); None for another name."""
    parts = name[: -len("_method.png")].split("_")
    if len(parts) != 4 or not parts[2].startswith("c") or not parts[3].startswith("f"):
        return None
    return parts[0], parts[1], parts[2][1:], str(int(parts[3][1:]))
