#!/usr/bin/env python3
"""three.js choosing the levels along a camera path: a score folder for `lodbench score`.

    python3 scripts/three_lod.py TUNE_DIR --path PATH.csv --out DIR [--rule tune|unreal|godot|meshopt]
        [--anchor centre|origin] [--width W --height H] [--frames N] [--fps 60] [--reference/--no-reference]
        [--fade none|dither --fade-frames N] [--lodbench BIN]

TUNE_DIR is a folder `lodbench tune --out TUNE_DIR` wrote (tune.json, rules.csv, engines/threejs-lod.js,
tuned.glb). Headless Chromium (WebGL on SwiftShader) loads tuned.glb with three.js (scripts/threejs/, pinned in
its package.json) in scripts/threejs/lod.html, lit as scripts/three_fidelity.py draws a file (lodbench's light,
ambient and clear colour, no tone mapping, no antialiasing, sRGB output, pixel ratio 1). Each MSFT_lod chain of
the file (its LOD0 node in the scene, the coarser levels nodes outside it, which GLTFLoader leaves alone and the
page loads itself) becomes a THREE.LOD made by the folder's own `lodbenchLod(THREE, name, levels)`. The camera of
every frame is lodbench's: `lodbench describe --scene TUNE_DIR/tuned.glb --camera-path PATH.csv --cameras-json`
with the same viewport and field of view. Per frame f the page

  1. sets the camera, calls `lod.update(camera)` (autoUpdate off, so the renderer never changes a level behind
     our back) and records `lod.getCurrentLevel()` per LOD object;
  2. draws the frame (its time: performance.now() around renderer.render and gl.finish());
  3. where the selection differs from frame f-1's, draws frame f's pose with f-1's selection (the
     counterfactual);
  4. unless --no-reference, draws every object at level 0 (the reference);

and the script writes DIR in the score-folder protocol: score.json (engine, fps, background: the clear colour's
sRGB bytes as three.js draws it, scene, method `threejs-<rule>`, blend, notes with the path, rule, anchor, tune
folder and the distances three.js used), lods.csv (frame,object,lod[,lod_to,k]: a row per frame and LOD object,
the object named as tune.json's model, with `_i` for the i-th of several instances), frame/NNNNN.png,
counterfactual/NNNNN.png, reference/NNNNN.png, stats.csv (frame,cpu_ms,gpu_ms,triangles,draw_calls; gpu_ms empty:
WebGL on SwiftShader has no timer queries). Then `lodbench score DIR`. DIR must be new, empty or a score folder:
writing it again replaces the pictures, the CSVs and what `lodbench score` wrote in it.

Flags:
  --rule      tune (default): engines/threejs-lod.js as written. unreal, godot, meshopt: the same lodbenchLod
              with that rule's distances from rules.csv (level k+1 comes in at the rule's distance of pair
              k->k+1).
  --anchor    centre (default): the LOD object at the model's bounding-sphere centre, its levels shifted by minus
              the centre, as lodbenchLod builds it. origin: the LOD object at the model's origin and the levels
              not shifted, as a user who ignores the centre places it (the method is then threejs-<rule>-origin).
  --width, --height  the viewport (default tune.json's, which the switches were tuned for).
  --frames    frames of the path (default: its key frames, last - first + 1; lodbench resamples the path to it).
  --fps       the rate the frames stand for (score.json).
  --fade      none (default): THREE.LOD switches; it has no cross-fade of its own. dither: a screen-door
              cross-fade added here (not three.js's): after a switch both levels are drawn for --fade-frames N
              frames with complementary 4x4 Bayer dither (k = 1/N .. (N-1)/N, as lodbench's time fade), and a
              switch during a fade waits for its end; lods.csv then has lod (from), lod_to and k, blend "dither".

What three.js does differently from lodbench:
  - THREE.LOD measures the distance from the camera's world position to the LOD object's world position (over
    camera.zoom), and switches to level k when that distance is at least level k's distance (no hysteresis
    here). lodbench measures from the model's bounding-sphere centre. lodbenchLod keeps the two equal by standing
    the LOD object at the centre; a LOD object at the model's origin (--anchor origin, or a model whose origin is
    far from its centre) switches at other camera positions, how far off depending on the direction of view.
  - A level switch is a pop; nothing blends unless --fade dither.
  - THREE.LOD.addLevel sorts levels by distance: a rule whose distances are not increasing reorders the levels.
  - The tuned file's animation is not played (the rest pose), and its coarser levels stand where lodbench puts
    them (MSFT_lod's levels outside the scene replace the LOD0 node under its parent).

Needs Chromium and `npm ci --prefix scripts/threejs` (.ci/setup-tests does both)."""
import argparse
import base64
import csv
import json
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from PIL import Image

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from browser import Browser, chromium_binary  # noqa: E402
from three_fidelity import BACKGROUND, THREEJS, serve_page  # noqa: E402

ROOT = HERE.parent
RULES = ["tune", "unreal", "godot", "meshopt"]
# Browser start-up and the file's loading; then each frame (up to three pictures on SwiftShader) gets FRAME_S.
START_S = 120
FRAME_S = 2.0
# Pixels a batch of frames may hold in the page (each frame up to three pictures).
BATCH_PIXELS = 4_000_000
PICTURES = ("frame", "counterfactual", "reference")
OUT_FILES = ("score.json", "lods.csv", "stats.csv")
# What `lodbench score DIR` writes into DIR: stale once the folder is written again.
SCORED_FILES = ("frames.csv", "transitions.csv", "summary.csv", "run.json", "answer.json", "pairs.csv", "rounds.csv")
SCORED_DIRS = ("frames",)


def fail(message: str):
    raise SystemExit(f"error: {message}")


def path_frames(path: Path) -> int:
    """The frames a camera path's keys span (last frame - first + 1)."""
    with open(path, newline="") as fh:
        frames = [float(row["frame"]) for row in csv.DictReader(fh)]
    if not frames:
        fail(f"{path} has no keys")
    return int(round(max(frames) - min(frames))) + 1


def rule_distances(tune_dir: Path, meta: dict, rule: str) -> dict:
    """Per model with LOD pairs: the rule's distances as lodbenchLod takes them (0 for level 0, then the rule's
    distance of each pair k->k+1), from rules.csv."""
    with open(tune_dir / "rules.csv", newline="") as fh:
        rows = [r for r in csv.DictReader(fh) if r["rule"] == rule]
    out = {}
    for m in meta["models"]:
        if not m["pairs"]:
            continue
        pairs = {int(r["lod_from"]): float(r["distance"]) for r in rows if r["model"] == m["name"]}
        need = [int(p["lod_from"]) for p in m["pairs"]]
        missing = [k for k in need if k not in pairs]
        if missing:
            fail(f"{tune_dir / 'rules.csv'} has no {rule} distance for {m['name']} pairs {missing}")
        out[m["name"]] = [0.0] + [pairs[k] for k in sorted(need)]
    return out


def cameras(binary: Path, scene: Path, path: Path, width: int, height: int, frames: int, fov: float) -> dict:
    """`lodbench describe --cameras-json`: every frame's camera along the path, with the light and ambient."""
    args = [str(binary), "describe", "--scene", str(scene), "--camera-path", str(path), "--width", str(width),
            "--height", str(height), "--frames", str(frames), "--fov", f"{fov:.9g}", "--cameras-json"]
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode != 0:
        fail(f"{' '.join(args)}: {r.stderr.strip()}")
    return json.loads(r.stdout)


def clear_out(out: Path, subs):
    """An empty DIR, a score folder (score.json: its pictures, CSVs and what `lodbench score` wrote in it are
    replaced) or what a failed run of this left."""
    if out.exists():
        if not out.is_dir():
            fail(f"{out} is not a folder")
        if not (out / "score.json").is_file():
            strange = sorted(p.name for p in out.iterdir() if p.name not in PICTURES + OUT_FILES)
            if strange:
                fail(f"{out} holds {', '.join(strange[:5])} and no score.json: give a new folder or a score folder")
        for name in PICTURES + SCORED_DIRS:
            shutil.rmtree(out / name, ignore_errors=True)
        for name in OUT_FILES + SCORED_FILES:
            (out / name).unlink(missing_ok=True)
    for sub in subs:
        (out / sub).mkdir(parents=True, exist_ok=True)


def png_bytes(data_url: str) -> bytes:
    return base64.b64decode(data_url.split(",", 1)[1])


def number(x) -> str:
    return f"{x:.6g}"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("tune_dir", type=Path, help="a folder `lodbench tune` wrote")
    ap.add_argument("--path", type=Path, required=True, help="camera path CSV (frame,x,y,z,target_x,...)")
    ap.add_argument("--out", type=Path, required=True, help="the score folder to write")
    ap.add_argument("--rule", choices=RULES, default="tune")
    ap.add_argument("--anchor", choices=["centre", "origin"], default="centre")
    ap.add_argument("--width", type=int)
    ap.add_argument("--height", type=int)
    ap.add_argument("--frames", type=int, help="frames (default: the path's keys, last - first + 1)")
    ap.add_argument("--fps", type=float, default=60.0)
    ap.add_argument("--reference", action=argparse.BooleanOptionalAction, default=True,
                    help="also draw every frame with every object at level 0 (default on)")
    ap.add_argument("--fade", choices=["none", "dither"], default="none")
    ap.add_argument("--fade-frames", type=int, default=8, help="with --fade dither: k steps 1/N a frame")
    ap.add_argument("--lodbench", type=Path, default=ROOT / "target" / "release" / "lodbench")
    a = ap.parse_args()

    tune_dir = a.tune_dir.resolve()
    for name in ("tune.json", "rules.csv", "tuned.glb", "engines/threejs-lod.js"):
        if not (tune_dir / name).is_file():
            fail(f"{tune_dir} has no {name}: give a folder `lodbench tune --out` wrote")
    if not a.path.is_file():
        fail(f"no camera path {a.path}")
    if a.fade_frames < 1:
        fail("--fade-frames must be at least 1")
    chromium = chromium_binary()
    if chromium is None:
        fail("no Chromium (chromium, chromium-browser or google-chrome on PATH): apt-get install chromium")
    if not (THREEJS / "node_modules" / "three").is_dir():
        fail(f"three.js is not installed: npm ci --prefix {THREEJS}")
    meta = json.loads((tune_dir / "tune.json").read_text())
    width, height = a.width or int(meta["width"]), a.height or int(meta["height"])
    frames = a.frames or path_frames(a.path)
    distances = None if a.rule == "tune" else rule_distances(tune_dir, meta, a.rule)
    t_start = time.monotonic()
    cams = cameras(a.lodbench, tune_dir / "tuned.glb", a.path, width, height, frames, float(meta["fov_y_deg"]))
    if len(cams["frames"]) != frames:
        fail(f"lodbench describe gave {len(cams['frames'])} cameras for {frames} frames")
    three_version = json.loads((THREEJS / "node_modules" / "three" / "package.json").read_text())["version"]

    out = a.out
    clear_out(out, PICTURES if a.reference else PICTURES[:2])
    method = f"threejs-{a.rule}" + ("-origin" if a.anchor == "origin" else "") + \
        (f"-dither{a.fade_frames}" if a.fade == "dither" else "")
    lods_rows, stats_rows, changes = [], [], []
    with tempfile.TemporaryDirectory() as tmp:
        job = {key: cams[key] for key in ("fov_y_deg", "near", "far", "width", "height", "light_direction",
                                          "ambient")}
        job.update(frames=[{"view": c["view"]} for c in cams["frames"]], background=BACKGROUND,
                   model="tune/tuned.glb", anchor=a.anchor, distances=distances, reference=a.reference,
                   fade=a.fade, fade_frames=a.fade_frames)
        server, url = serve_page(Path(tmp) / "site", "lod.html", {"tune": tune_dir}, job)
        browser = Browser(chromium, Path(tmp) / "profile", time.monotonic() + START_S + FRAME_S * frames,
                          viewport=(width, height), webgl=True)
        try:
            chromium_version = browser.call("Browser.getVersion", session=False)["product"]
            browser.open(url)
            browser.until("window.ready || window.error", "three.js's set-up")
            error = browser.js("window.error || null")
            if error:
                fail(f"three.js: {error}\n" + "\n".join(browser.errors()))
            ready = browser.js("window.ready")
            if not ready["objects"]:
                fail(f"{tune_dir / 'tuned.glb'} has no MSFT_lod chain in its scene: nothing for THREE.LOD")
            for o in ready["objects"]:
                if distances and len(distances[o["model"]]) > o["levels"]:
                    print(f"note: tuned.glb keeps {o['levels']} levels of {o['model']} (tune found no switch for "
                          f"the rest); {a.rule}'s distances past them are left out", file=sys.stderr)
            t_setup = time.monotonic()
            names = [o["name"] for o in ready["objects"]]
            batch = max(1, min(32, BATCH_PIXELS // (width * height)))
            previous = None
            for first in range(0, frames, batch):
                end = min(frames, first + batch)
                for fr in browser.js(f"lodbenchBatch({first}, {end})", wait=True):
                    f = fr["frame"]
                    for sub, picture in fr["pictures"].items():
                        (out / sub / f"{f:05d}.png").write_bytes(png_bytes(picture))
                    for name, s in zip(names, fr["selection"]):
                        row = {"frame": f, "object": name, "lod": s["lod"]}
                        if a.fade == "dither":
                            row.update(lod_to="" if s["to"] is None else s["to"],
                                       k="" if s["k"] is None else number(s["k"]))
                        lods_rows.append(row)
                    if previous is not None and fr["selection"] != previous:
                        changes.append(f)
                        if "counterfactual" not in fr["pictures"]:
                            fail(f"frame {f}: the selection changed but the page drew no counterfactual")
                    previous = fr["selection"]
                    stats_rows.append({"frame": f, "cpu_ms": f"{fr['cpu_ms']:.3f}", "gpu_ms": "",
                                       "triangles": fr["triangles"], "draw_calls": fr["calls"]})
            t_frames = time.monotonic()
            page_errors = browser.errors()
        finally:
            browser.close()
            server.shutdown()
    if page_errors:
        print("three.js page logged:\n  " + "\n  ".join(page_errors), file=sys.stderr)

    size = Image.open(out / "frame" / "00000.png").size
    if size != (width, height):
        fail(f"three.js drew {size[0]}x{size[1]}, not {width}x{height}")
    columns = ["frame", "object", "lod"] + (["lod_to", "k"] if a.fade == "dither" else [])
    for name, rows, cols in (("lods.csv", lods_rows, columns),
                             ("stats.csv", stats_rows, ["frame", "cpu_ms", "gpu_ms", "triangles", "draw_calls"])):
        with open(out / name, "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=cols, extrasaction="ignore")
            w.writeheader()
            w.writerows(rows)
    version = chromium_version.split("/", 1)[-1]
    manifest = {
        "engine": f"three.js {three_version} (WebGL, headless Chromium {version})",
        "fps": a.fps,
        "background": ready["background"],
        "scene": "tuned.glb",
        "method": method,
        "blend": "dither" if a.fade == "dither" else "none",
        "notes": {
            "client": "scripts/three_lod.py",
            "tune_dir": str(tune_dir),
            "tuned_from": meta.get("scene"),
            "path": str(a.path.resolve()),
            "frames": frames,
            "width": width,
            "height": height,
            "fov_y_deg": cams["fov_y_deg"],
            "rule": a.rule,
            "anchor": a.anchor,
            "fade_frames": a.fade_frames if a.fade == "dither" else None,
            "webgl_renderer": ready["webgl"],
            "objects": ready["objects"],
            "rule_distances": distances,
            "selection_changes": changes,
            "reference": a.reference,
        },
    }
    (out / "score.json").write_text(json.dumps(manifest, indent=2) + "\n")
    print(f"{out}: {frames} frames at {width}x{height}, {len(names)} LOD object(s) ({', '.join(names)}), rule "
          f"{a.rule}, anchor {a.anchor}; the selection changed on {len(changes)} frame(s)"
          f"{': ' + ' '.join(map(str, changes[:20])) if changes else ''}{' ...' if len(changes) > 20 else ''}; "
          f"set-up {t_setup - t_start:.1f} s, frames {t_frames - t_setup:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
