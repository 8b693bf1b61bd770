"""three.js choosing LOD levels along a camera path (scripts/three_lod.py, scripts/threejs/lod.html): a tiny tune
folder (the exported bunny-sweep tuned at 96x72 from two views), a 32-frame path along +z from the model's centre
across tune's first switch, and the score folder three_lod.py writes checked against the protocol: the files,
pictures of the viewport's size, the level THREE.LOD chose where lodbench's distance says, a counterfactual exactly
where the selection changed, the background bytes of a corner the model does not cover; with --fade dither, the
blend's rows. `lodbench score` then scores both folders, and the switch frame must pop.

Skipped without Chromium or without three.js installed (`npm ci --prefix scripts/threejs`, which .ci/setup-tests
runs)."""
import csv
import json
import math
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

from conftest import ROOT, lodbench_binary

sys.path.insert(0, str(ROOT / "scripts"))
from browser import chromium_binary  # noqa: E402

SCRIPT = ROOT / "scripts" / "three_lod.py"
WIDTH, HEIGHT = 96, 72
FRAMES = 32
# The path's distances from the model's centre: the tuned switch at 96x72 is about 55 (tune.json's).
NEAR, FAR = 35.0, 80.0
FADE_FRAMES = 4


def run(*args, **kw):
    r = subprocess.run([str(a) for a in args], capture_output=True, text=True, timeout=300, **kw)
    assert r.returncode == 0, f"{' '.join(map(str, args))}:\n{r.stdout}\n{r.stderr}"
    return r.stdout


def read_csv(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def pixels(path):
    return np.asarray(Image.open(path).convert("RGB"))


@pytest.fixture(scope="module")
def tune(tmp_path_factory):
    if chromium_binary() is None:
        pytest.skip("no Chromium (chromium, chromium-browser or google-chrome on PATH): apt-get install chromium")
    if not (ROOT / "scripts" / "threejs" / "node_modules" / "three").is_dir():
        pytest.skip("three.js is not installed: npm ci --prefix scripts/threejs")
    base = tmp_path_factory.mktemp("three_lod")
    binary = lodbench_binary()
    run(binary, "export", "--scene", "bunny-sweep", "--out", base / "bunny.glb")
    run(binary, "tune", "--scene", base / "bunny.glb", "--budget-lodpop", "0.004", "--width", WIDTH, "--height",
        HEIGHT, "--views", "2", "--distances", "8", "--out", base / "tune")
    meta = json.loads((base / "tune" / "tune.json").read_text())
    model = meta["models"][0]
    # The flight of the tuned file starts where the model fits the view, along +z from its centre.
    eye = json.loads(run(binary, "describe", "--scene", base / "tune" / "tuned.glb", "--width", WIDTH, "--height",
                         HEIGHT, "--camera-json", "0"))["eye"]
    centre = [eye[0], eye[1], eye[2] - model["near"]]
    path = base / "path.csv"
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["frame", "x", "y", "z", "target_x", "target_y", "target_z"])
        for f in range(FRAMES):
            d = NEAR + (FAR - NEAR) * f / (FRAMES - 1)
            w.writerow([f, centre[0], centre[1], centre[2] + d, *centre])
    switch = model["pairs"][0]["switch_distance"]
    assert NEAR < switch < FAR, f"tune's first switch {switch} is off the path: move NEAR, FAR"
    return {"base": base, "binary": binary, "path": path, "centre": centre, "switch": switch}


def three_lod(tune, name, *extra):
    out = tune["base"] / name
    run(sys.executable, SCRIPT, tune["base"] / "tune", "--path", tune["path"], "--out", out, "--lodbench",
        tune["binary"], *extra)
    return out


@pytest.fixture(scope="module")
def folder(tune):
    return three_lod(tune, "score")


@pytest.fixture(scope="module")
def dither(tune):
    return three_lod(tune, "dither", "--fade", "dither", "--fade-frames", FADE_FRAMES, "--no-reference")


def selections(out):
    """Per frame, the tuple of every object's (lod, lod_to, k)."""
    rows = read_csv(out / "lods.csv")
    frames = {}
    for r in rows:
        frames.setdefault(int(r["frame"]), []).append((r["object"], r["lod"], r.get("lod_to", ""), r.get("k", "")))
    assert sorted(frames) == list(range(FRAMES))
    return [tuple(sorted(frames[f])) for f in range(FRAMES)]


def test_the_folder_follows_the_protocol(folder):
    manifest = json.loads((folder / "score.json").read_text())
    assert manifest["engine"].startswith("three.js 0.187.0 (WebGL, headless Chromium ")
    assert manifest["fps"] == 60
    assert manifest["method"] == "threejs-tune" and manifest["blend"] == "none"
    assert manifest["scene"] == "tuned.glb"
    assert len(manifest["background"]) == 3 and all(0 <= b <= 255 for b in manifest["background"])
    with open(folder / "lods.csv") as fh:
        assert fh.readline().strip() == "frame,object,lod"
    rows = read_csv(folder / "lods.csv")
    assert {r["object"] for r in rows} == {"bunny_0_LOD0"}
    assert len(rows) == FRAMES
    for sub in ("frame", "reference"):
        names = sorted(p.name for p in (folder / sub).iterdir())
        assert names == [f"{f:05d}.png" for f in range(FRAMES)], sub
    for sub in ("frame", "counterfactual", "reference"):
        for p in (folder / sub).iterdir():
            assert Image.open(p).size == (WIDTH, HEIGHT), p
    stats = read_csv(folder / "stats.csv")
    assert [int(r["frame"]) for r in stats] == list(range(FRAMES))
    assert all(float(r["cpu_ms"]) >= 0 and r["gpu_ms"] == "" for r in stats)


def test_three_js_switches_where_lodbench_measures(folder, tune):
    """THREE.LOD stands at the model's centre, so it switches on the first frame whose eye is the tuned distance
    from the centre."""
    lods = [int(r["lod"]) for r in read_csv(folder / "lods.csv")]
    assert lods[0] == 0 and lods[-1] >= 1
    cams = json.loads(run(tune["binary"], "describe", "--scene", tune["base"] / "tune" / "tuned.glb", "--camera-path",
                          tune["path"], "--width", WIDTH, "--height", HEIGHT, "--frames", FRAMES, "--cameras-json"))
    distance = [math.dist(c["eye"], tune["centre"]) for c in cams["frames"]]
    first = next(f for f in range(FRAMES) if lods[f] >= 1)
    assert distance[first] >= tune["switch"] > distance[first - 1] - 1e-3, (first, distance, tune["switch"])


def test_counterfactual_exactly_where_the_selection_changed(folder):
    sel = selections(folder)
    changed = {f for f in range(1, FRAMES) if sel[f] != sel[f - 1]}
    assert changed, "the level never changed along the path"
    drawn = {int(p.stem) for p in (folder / "counterfactual").iterdir()}
    assert drawn == changed
    for f in changed:
        # The same pose with the previous level: a different picture; with level 0 it is the reference.
        cf, frame = pixels(folder / "counterfactual" / f"{f:05d}.png"), pixels(folder / "frame" / f"{f:05d}.png")
        assert (cf != frame).any(), f
    for f in range(FRAMES):
        if sel[f][0][1] == "0":
            assert (pixels(folder / "frame" / f"{f:05d}.png") == pixels(folder / "reference" / f"{f:05d}.png")).all()


def test_background_bytes_are_the_clear_colour_three_js_draws(folder):
    background = json.loads((folder / "score.json").read_text())["background"]
    for f in (0, FRAMES - 1):
        frame = pixels(folder / "frame" / f"{f:05d}.png")
        assert list(frame[0, 0]) == background
        # The model is drawn (it covers some pixels) but not the corners.
        assert (frame != np.array(background, dtype=np.uint8)).any()
        for corner in (frame[0, -1], frame[-1, 0], frame[-1, -1]):
            assert list(corner) == background


def test_dither_fade_blends_both_levels(dither):
    manifest = json.loads((dither / "score.json").read_text())
    assert manifest["blend"] == "dither"
    with open(dither / "lods.csv") as fh:
        assert fh.readline().strip() == "frame,object,lod,lod_to,k"
    rows = read_csv(dither / "lods.csv")
    blends = [r for r in rows if r["lod_to"] != ""]
    assert [float(r["k"]) for r in blends] == [j / FADE_FRAMES for j in range(1, FADE_FRAMES)]
    assert all(r["k"] == "" for r in rows if r["lod_to"] == "")
    sel = selections(dither)
    changed = {f for f in range(1, FRAMES) if sel[f] != sel[f - 1]}
    assert len(changed) == FADE_FRAMES  # the fade's N - 1 blended frames and the new level alone
    assert {int(p.stem) for p in (dither / "counterfactual").iterdir()} == changed
    assert not (dither / "reference").exists() or not any((dither / "reference").iterdir())


def test_lodbench_scores_the_folders(folder, dither, tune):
    binary = tune["binary"]
    run(binary, "score", folder)
    assert (folder / "frames.csv").is_file(), f"lodbench score {folder} wrote no frames.csv"
    frames = read_csv(folder / "frames.csv")
    lods = [int(r["lod"]) for r in read_csv(folder / "lods.csv")]
    switch = next(f for f in range(1, FRAMES) if lods[f] != lods[f - 1])
    row = next(r for r in frames if int(r["frame"]) == switch)
    assert float(row["lodpop"]) > 0, row
    # The scored folder reads as a run's: plot.py draws its figures and report.html, and clips finds the pictures
    # under their dump names.
    run(sys.executable, ROOT / "scripts" / "plot.py", folder)
    assert (folder / "report.html").is_file() and any((folder / "figures").glob("*.png"))
    run(binary, "clips", folder, "--mp4", "off")
    assert (folder / "clips" / "index.json").is_file()
    # The dithered fade is one transition over its frames.
    run(binary, "score", dither)
    (transition,) = read_csv(dither / "transitions.csv")
    assert int(transition["last_frame"]) - int(transition["first_frame"]) + 1 == FADE_FRAMES, transition
