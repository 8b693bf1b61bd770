"""pop_regions.py on synthetic dumps whose answers are known: a square that lags one pixel behind the reference
(every bit of pop on its silhouette), one whose colour is off inside (every bit inside), and bad input."""
import subprocess
import sys
from pathlib import Path

import numpy as np
from PIL import Image

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "pop_regions.py"
BG = (10, 12, 14)
FG = (200, 150, 100)


def square(left: int, colour=FG) -> np.ndarray:
    """A 32x32 frame, background BG, with an 8x8 square at rows 10-17 and columns left..left+7."""
    img = np.zeros((32, 32, 3), np.uint8)
    img[:] = BG
    img[10:18, left:left + 8] = colour
    return img


def write_run(folder: Path, method_frames, reference_frames, method="fsi") -> Path:
    frames = folder / "frames"
    frames.mkdir(parents=True)
    for t, (m, r) in enumerate(zip(method_frames, reference_frames)):
        Image.fromarray(m).save(frames / f"bunny-sweep_{method}_c1_f{t:05d}_method.png")
        Image.fromarray(r).save(frames / f"bunny-sweep_{method}_c1_f{t:05d}_reference.png")
    return folder


def run(*args):
    return subprocess.run([sys.executable, str(SCRIPT), *map(str, args)], capture_output=True, text=True)


def rows(stdout: str):
    lines = stdout.strip().splitlines()
    header = lines[0].split(",")
    return [dict(zip(header, line.split(","))) for line in lines[1:]]


def test_lag_is_all_silhouette(tmp_path):
    # The reference square moves one pixel right per frame; the method shows the previous frame's square.
    reference = [square(8 + t) for t in range(4)]
    method = [reference[0]] + reference[:-1]
    folder = write_run(tmp_path / "lag", method, reference)
    r = run(folder, "--band", "2")
    assert r.returncode == 0, r.stderr
    out = rows(r.stdout)
    assert [int(x["frame"]) for x in out] == [1, 2, 3]
    for x in out[1:]:
        # E_t is +(FG-BG) on column 8+t-1 (extra) and -(FG-BG) on column 8+t+7 (missing); E_{t-1} the same one
        # column left: E_t - E_{t-1} is nonzero on four columns of 8 pixels, all within 2 steps of the edge.
        expected = np.sqrt(4 * 8 * sum((f - b) ** 2 for f, b in zip(FG, BG)) / 255.0 ** 2 / (32 * 32 * 3))
        assert abs(float(x["pop"]) - expected) < 1e-6
        assert float(x["silhouette"]) == 1.0
        assert float(x["interior"]) == 0.0
        assert int(x["extra"]) == 8 and int(x["missing"]) == 8
    # With a 1-pixel band, E_{t-1}'s columns lie a step further: its missing column 8+t+6 is interior except its
    # top and bottom pixels (next to the background above and below), its extra column 8+t-2 is background in
    # both references (neither region). Of 32 equal pixels: silhouette 16 + 2, interior 6.
    for x in rows(run(folder, "--band", "1").stdout)[1:]:
        assert float(x["silhouette"]) == 18 / 32 and float(x["interior"]) == 6 / 32


def test_colour_change_inside_is_all_interior(tmp_path):
    # A static square; at frame 1 the method's square is 20 levels brighter, 3 or more pixels (4-neighbour steps)
    # from the background, so the change lies outside a 2-pixel silhouette band.
    reference = [square(8), square(8)]
    brighter = square(8)
    brighter[13:15, 11:13] = [c + 20 for c in FG]
    method = [square(8), brighter]
    r = run(write_run(tmp_path / "inside", method, reference), "--band", "2")
    assert r.returncode == 0, r.stderr
    (x,) = rows(r.stdout)
    assert float(x["interior"]) == 1.0 and float(x["silhouette"]) == 0.0
    assert int(x["extra"]) == 0 and int(x["missing"]) == 0
    # And with a band wide enough to reach the centre, it is all silhouette.
    (y,) = rows(run(tmp_path / "inside", "--band", "4").stdout)
    assert float(y["silhouette"]) == 1.0


def test_border_strip(tmp_path):
    # The square sits at columns 8-15, rows 10-17: a change there lies 8 or more pixels from the edge, so none of
    # it is in a 4-pixel border; a change of the same size in the top-left corner is all border.
    reference = [square(8), square(8)]
    inside = square(8)
    inside[12:14, 10:12] = [c + 20 for c in FG]
    (x,) = rows(run(write_run(tmp_path / "inside", [square(8), inside], reference)).stdout)
    assert float(x["border"]) == 0.0 and float(x["border_pop"]) == 0.0
    corner = square(8)
    corner[0:2, 0:2] = (30, 30, 30)
    (y,) = rows(run(write_run(tmp_path / "corner", [square(8), corner], reference)).stdout)
    assert float(y["border"]) == 1.0
    # border_pop: the same energy over the 32 x 32 - 24 x 24 = 448 border pixels instead of all 1,024.
    assert abs(float(y["border_pop"]) - float(y["pop"]) * np.sqrt(1024 / 448)) < 2e-6
    (z,) = rows(run(tmp_path / "corner", "--border", "1").stdout)
    # A 1-pixel strip holds three of the four changed pixels: (0, 0), (0, 1) and (1, 0), not (1, 1).
    assert float(z["border"]) == 0.75
    r = run(tmp_path / "corner", "--border", "0")
    assert r.returncode == 2 and "--border" in r.stderr


def test_bad_input_is_named(tmp_path):
    r = run(tmp_path)
    assert r.returncode == 2 and "no dumped frames" in r.stderr
    folder = write_run(tmp_path / "run", [square(8)] * 2, [square(8)] * 2)
    r = run(folder, "--frames", "1-x")
    assert r.returncode == 2 and "--frames" in r.stderr
    r = run(folder, "--method", "alpha")
    assert r.returncode == 2 and "no dumped frame matched" in r.stderr
    for bad in ("1,2", "a,b,c", "1,2,256"):
        r = run(folder, "--background", bad)
        assert r.returncode == 2 and "--background" in r.stderr, (bad, r.stderr)
    r = run(folder, "--frames", "40-")
    assert r.returncode == 2 and "--frames" in r.stderr
