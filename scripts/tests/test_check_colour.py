"""check_colour.py passes on a fresh lodbench dump and fails, naming the frame, when one dumped frame is altered."""
import csv
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
from PIL import Image

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "check_colour.py"


def check(folder: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(SCRIPT), str(folder)], capture_output=True, text=True)


def test_fresh_dump_passes(dump):
    r = check(dump)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "0 differ" in r.stdout
    assert "(0 with de2000_mean)" not in r.stdout, r.stdout
    # Not vacuous: some checked frames really differ from the reference.
    with open(dump / "frames.csv", newline="") as f:
        assert any(float(r["de2000_mean"]) > 0.01 for r in csv.DictReader(f))


def test_altered_frame_is_named(dump, tmp_path):
    copy = tmp_path / "altered"
    shutil.copytree(dump, copy)
    target = copy / "frames" / "bunny-sweep_dither_c1_f00030_method.png"
    img = np.asarray(Image.open(target).convert("RGBA")).copy()
    img[50:66, 70:86, :3] = np.minimum(img[50:66, 70:86, :3].astype(int) + 4, 255).astype(np.uint8)
    Image.fromarray(img).save(target)
    r = check(copy)
    assert r.returncode == 1, r.stdout + r.stderr
    bad = [line for line in r.stdout.splitlines() if line.startswith("MISMATCH")]
    assert len(bad) == 1, r.stdout
    assert "frame 30 " in bad[0] and "dither" in bad[0], bad[0]


def test_missing_folder_is_an_error(tmp_path):
    r = check(tmp_path / "nothing")
    assert r.returncode == 2
    assert "frames.csv" in r.stderr
