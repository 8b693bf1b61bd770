#!/usr/bin/env python3
"""Fidelity of lodbench's materials against a real renderer: three.js (scripts/threejs/, pinned in its package.json)
draws each glTF file in headless Chromium (WebGL on SwiftShader) with lodbench's camera of frame 0, its light and
ambient, no tone mapping (scripts/threejs/render.html), and the mean FLIP (NVIDIA's flip-evaluator, LDR, 67 pixels
per degree) of lodbench's reference frame against three.js's says how far apart the two are. As a control, the
same file drawn with `--materials flat` (one colour per model, no texture) against the same three.js frame: what a
renderer that ignores the materials scores.

    python3 scripts/three_fidelity.py --lodbench target/release/lodbench --out DIR FILE.gltf [FILE.glb ...]

Writes, per file, DIR/<name>_lodbench.png, _three.png, _flat.png, _flip.png (FLIP's error map of lodbench against
three.js) and _side.png (three.js | lodbench | the error map), and DIR/fidelity.csv (a row per file). The animation
is held at rest on both sides (lodbench --animation none; three.js plays nothing). Needs Chromium and
`npm ci --prefix scripts/threejs` (.ci/setup-tests does both)."""
import argparse
import base64
import csv
import functools
import http.server
import io
import json
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
from PIL import Image

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from browser import Browser, chromium_binary  # noqa: E402

THREEJS = HERE / "threejs"
# lodbench's clear colour in linear RGB (src/scene/model.rs BACKGROUND).
BACKGROUND = [0.045, 0.05, 0.06]
# Pixels per degree FLIP assumes: its default, a 0.7 m view of a 0.7 m wide 3840-pixel monitor.
PPD = 67
# A whole browser session per file, start-up and the drawing on SwiftShader included.
BROWSER_TIMEOUT_S = 120
COLUMNS = ["file", "width", "height", "flip_mean", "flip_mean_flat", "flip_covered", "flip_covered_flat", "rmse",
           "rmse_flat", "covered_share", "three_ms"]


def lodbench_frame(binary, scene, width, height, out: Path, flat=False) -> np.ndarray:
    """lodbench's reference frame 0 of `scene` (RGBA8 array), the animation at rest."""
    args = [str(binary), "run", "--scene", str(scene), "--method", "reference", "--frames", "1", "--warmup", "0",
            "--rounds", "1", "--animation", "none", "--width", str(width), "--height", str(height),
            "--dump-frames", "--out", str(out)]
    if flat:
        args += ["--materials", "flat"]
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"lodbench run {scene}: {r.stderr.strip()}")
    png = next((out / "frames").glob("*_reference_c1_f00000_reference.png"))
    return np.asarray(Image.open(png).convert("RGBA"))


def lodbench_camera(binary, scene, width, height) -> dict:
    """`lodbench describe --camera-json 0` with the run's flags (the same flight, clip planes and viewport)."""
    r = subprocess.run([str(binary), "describe", "--scene", str(scene), "--frames", "1", "--animation", "none",
                        "--width", str(width), "--height", str(height), "--camera-json", "0"],
                       capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"lodbench describe {scene}: {r.stderr.strip()}")
    return json.loads(r.stdout)


class _Quiet(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):
        pass


def serve_page(site: Path, page: str, links: dict, job: dict):
    """A page of scripts/threejs/ served from the new folder `site` on localhost: the page and lighting.js (the
    renderer and lighting every page shares) copied, node_modules and each of `links` (name: path) linked, `job`
    as job.json. Returns the server (shut it down when done) and the page's URL."""
    site.mkdir(parents=True)
    for name in (page, "lighting.js"):
        shutil.copy(THREEJS / name, site / name)
    os.symlink(THREEJS / "node_modules", site / "node_modules")
    for name, target in links.items():
        os.symlink(target, site / name)
    (site / "job.json").write_text(json.dumps(job))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(_Quiet, directory=str(site)))
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server, f"http://127.0.0.1:{server.server_address[1]}/{page}"


def three_frame(chromium, scene: Path, camera: dict, work: Path) -> tuple:
    """three.js's frame of `scene` with lodbench's `camera` (RGBA8 array) and the milliseconds the page took."""
    job = {**camera, "background": BACKGROUND, "model": f"asset/{scene.name}"}
    server, url = serve_page(work / "site", "render.html", {"asset": scene.resolve().parent}, job)
    t0 = time.monotonic()
    browser = Browser(chromium, work / "profile", t0 + BROWSER_TIMEOUT_S, viewport=(camera["width"],
                      camera["height"]), webgl=True)
    try:
        browser.open(url)
        browser.until("window.result || window.error", "three.js's frame")
        error = browser.js("window.error || null")
        if error:
            raise RuntimeError(f"three.js on {scene.name}: {error}")
        data = browser.js("window.result")
        ms = (time.monotonic() - t0) * 1e3
    finally:
        browser.close()
        server.shutdown()
    png = base64.b64decode(data.split(",", 1)[1])
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGBA")), ms


def flip_map(reference: np.ndarray, test: np.ndarray) -> tuple:
    """FLIP of `test` against `reference` (sRGB RGBA8 arrays): its per-pixel error (H x W, in [0, 1]) and the error map
    in FLIP's magma colours (RGB8)."""
    import flip_evaluator as flip
    ref = reference[..., :3].astype(np.float32) / 255.0
    tst = test[..., :3].astype(np.float32) / 255.0
    error, _, _ = flip.evaluate(ref, tst, "LDR", applyMagma=False, parameters={"ppd": PPD})
    error = np.asarray(error, dtype=np.float64).reshape(ref.shape[:2])
    magma, _, _ = flip.evaluate(ref, tst, "LDR", parameters={"ppd": PPD})
    return error, (np.clip(magma, 0, 1) * 255).round().astype(np.uint8)


def rmse(a: np.ndarray, b: np.ndarray) -> float:
    d = a[..., :3].astype(np.float64) - b[..., :3].astype(np.float64)
    return float(np.sqrt(np.mean((d / 255.0) ** 2)))


def compare(binary, chromium, scene: Path, out: Path, width: int, height: int) -> dict:
    """Every figure and image of one file, written under `out`."""
    name = scene.stem
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        ours = lodbench_frame(binary, scene, width, height, tmp / "full")
        flat = lodbench_frame(binary, scene, width, height, tmp / "flat", flat=True)
        camera = lodbench_camera(binary, scene, width, height)
        theirs, ms = three_frame(chromium, scene, camera, tmp / "three")
    if theirs.shape != ours.shape:
        raise RuntimeError(f"{name}: three.js drew {theirs.shape}, lodbench {ours.shape}")
    error, error_map = flip_map(theirs, ours)
    error_flat, _ = flip_map(theirs, flat)
    # Pixels either renderer covers (not the clear colour): the means over them say how far apart the drawn surfaces
    # are, whatever share of the frame they fill.
    background = ours[0, 0, :3]
    mask = np.any(ours[..., :3] != background, axis=-1) | np.any(theirs[..., :3] != background, axis=-1)
    covered = float(np.mean(mask))
    on = lambda e: float(e[mask].mean()) if mask.any() else 0.0  # noqa: E731
    for tag, img in (("lodbench", ours), ("three", theirs), ("flat", flat)):
        Image.fromarray(img[..., :3]).save(out / f"{name}_{tag}.png")
    Image.fromarray(error_map).save(out / f"{name}_flip.png")
    side = np.concatenate([theirs[..., :3], ours[..., :3], error_map], axis=1)
    Image.fromarray(side).save(out / f"{name}_side.png")
    return {"file": scene.name, "width": width, "height": height, "flip_mean": f"{error.mean():.5f}",
            "flip_mean_flat": f"{error_flat.mean():.5f}", "flip_covered": f"{on(error):.5f}",
            "flip_covered_flat": f"{on(error_flat):.5f}", "rmse": f"{rmse(theirs, ours):.5f}",
            "rmse_flat": f"{rmse(theirs, flat):.5f}", "covered_share": f"{covered:.4f}", "three_ms": f"{ms:.0f}"}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--lodbench", default="target/release/lodbench", help="the lodbench binary")
    ap.add_argument("--out", required=True, help="folder for the images and fidelity.csv")
    ap.add_argument("--width", type=int, default=480)
    ap.add_argument("--height", type=int, default=360)
    ap.add_argument("files", nargs="+", help="glTF or GLB files")
    a = ap.parse_args()
    chromium = chromium_binary()
    if chromium is None:
        print("error: no Chromium (chromium, chromium-browser or google-chrome on PATH): apt-get install chromium",
              file=sys.stderr)
        return 1
    if not (THREEJS / "node_modules" / "three").is_dir():
        print(f"error: three.js is not installed: npm ci --prefix {THREEJS}", file=sys.stderr)
        return 1
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for f in a.files:
        row = compare(Path(a.lodbench), chromium, Path(f), out, a.width, a.height)
        print(f"{row['file']}: FLIP {row['flip_mean']} (flat {row['flip_mean_flat']}), over covered pixels "
              f"{row['flip_covered']} (flat {row['flip_covered_flat']}), rmse {row['rmse']}")
        rows.append(row)
    with open(out / "fidelity.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=COLUMNS)
        w.writeheader()
        w.writerows(rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
