"""Fixtures shared by the tests of scripts/: small lodbench runs on whatever adapter the machine has."""
import functools
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
LONG_SUITE = "python3 -m pytest -q -n auto scripts/tests --long -m long"


def pytest_addoption(parser):
    parser.addoption("--long", action="store_true",
                     help=f"also run the long suite, the tests marked long (alone: {LONG_SUITE}; .ci/run runs it)")


def pytest_configure(config):
    config.addinivalue_line("markers", "long: the long suite: whole browser sessions and results rebuilt, which the "
                            f"README's test command leaves out and .ci/run runs ({LONG_SUITE})")


def pytest_collection_modifyitems(config, items):
    """Without --long, the tests marked long are skipped with the command that runs them."""
    if config.getoption("--long"):
        return
    skip = pytest.mark.skip(reason=f"the long suite: {LONG_SUITE}")
    for item in items:
        if "long" in item.keywords:
            item.add_marker(skip)


@functools.lru_cache(maxsize=1)
def lodbench_binary() -> Path:
    """LODBENCH_BIN, or the binary `cargo test --release` builds (target/release/lodbench, the README's test command
    builds it just before pytest), brought up to date with `cargo test --release --no-run` (the same build, a no-op
    when fresh), so the scripts are never tested against an older binary."""
    if os.environ.get("LODBENCH_BIN"):
        return Path(os.environ["LODBENCH_BIN"])
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    if not target.is_absolute():
        target = ROOT / target
    subprocess.run(
        ["cargo", "test", "--release", "--no-run", "--quiet"], cwd=ROOT, check=True, capture_output=True
    )
    return target / "release" / "lodbench"


def lodbench(*args: str) -> None:
    subprocess.run([str(lodbench_binary()), *args], check=True, capture_output=True)


@pytest.fixture(scope="session")
def dump(tmp_path_factory) -> Path:
    """bunny-sweep, discrete, dither and fsi (a method name containing `_f`), 60 frames at 160x120 with de2000, every
    5th frame dumped."""
    out = tmp_path_factory.mktemp("dump") / "run"
    lodbench("run", "--scene", "bunny-sweep", "--method", "discrete,dither,fsi", "--width", "160", "--height", "120",
             "--frames", "60", "--warmup", "0", "--switch-distances", "14,16,18", "--metrics", "rmse,pop,de2000",
             "--dump-frames", "--dump-every", "5", "--out", str(out))
    return out


@pytest.fixture(scope="session")
def grid(tmp_path_factory) -> Path:
    """bunny-grid with three counts, a few frames at 64x48."""
    out = tmp_path_factory.mktemp("grid") / "run"
    lodbench("run", "--scene", "bunny-grid", "--method", "discrete,alpha", "--count", "2,4,8", "--width", "64",
             "--height", "48", "--frames", "3", "--warmup", "1", "--out", str(out))
    return out


@pytest.fixture(scope="session")
def viewport_experiment(tmp_path_factory) -> Path:
    """A two-value viewport sweep written by `lodbench experiment`."""
    base = tmp_path_factory.mktemp("experiment")
    spec = base / "viewports.toml"
    spec.write_text('name = "viewports"\n[run]\nscene = ["bunny-sweep"]\nmethod = ["discrete", "alpha"]\n'
                    'frames = 6\nwarmup = 0\n[sweep]\nvariable = "viewport"\nvalues = [[64, 48], [128, 96]]\n')
    out = base / "run"
    lodbench("experiment", str(spec), "--out", str(out))
    return out


@pytest.fixture(scope="session")
def check_experiment(tmp_path_factory) -> Path:
    """A sweep of a variable other than the viewport (`fsi-check`) written by `lodbench experiment`."""
    base = tmp_path_factory.mktemp("experiment")
    spec = base / "check.toml"
    spec.write_text('name = "check"\n[run]\nscene = ["windmills"]\nmethod = ["fsi"]\nprofile = "ci"\n'
                    'frames = 6\nwarmup = 0\nwidth = 64\nheight = 64\n'
                    '[sweep]\nvariable = "fsi-check"\nvalues = ["none", "forward"]\n')
    out = base / "run"
    lodbench("experiment", str(spec), "--out", str(out))
    return out


@pytest.fixture(scope="session")
def band_experiment(tmp_path_factory) -> Path:
    """A two-variable sweep (pixel error x band) of bunny-sweep at 160x120 with transitions in every run."""
    base = tmp_path_factory.mktemp("experiment")
    spec = base / "band.toml"
    spec.write_text('name = "band"\n[run]\nscene = ["bunny-sweep"]\nmethod = ["discrete", "alpha", "dither"]\n'
                    'width = 160\nheight = 120\nframes = 60\nwarmup = 0\nrounds = 4\n'
                    '[[sweep]]\nvariable = "pixel-error"\nvalues = [0.25, 0.5]\n'
                    '[[sweep]]\nvariable = "band"\nvalues = [0.05, 0.15]\n')
    out = base / "run"
    lodbench("experiment", str(spec), "--out", str(out))
    return out


@pytest.fixture(scope="session")
def pixel_error_experiment(tmp_path_factory) -> Path:
    """A two-value pixel-error sweep of the terrain at the regress profile (small), every unified method."""
    base = tmp_path_factory.mktemp("experiment")
    spec = base / "unified.toml"
    spec.write_text('name = "unified"\n[run]\nscene = ["terrain"]\nprofile = "regress"\nframes = 8\nwarmup = 0\n'
                    '[sweep]\nvariable = "pixel-error"\nvalues = [1.0, 4.0]\n')
    out = base / "run"
    lodbench("experiment", str(spec), "--out", str(out))
    return out


def write_clips(folder: Path, clips=2, frames=8, tile=(160, 120), methods=("reference", "discrete", "alpha"),
                movie=False) -> dict:
    """A synthetic `clips/` in `folder`, laid out as `lodbench clips` writes it (index.json, per clip a frame and an
    error image per frame, an animated PNG and a GIF, no MP4): each tile a method's colour with a white bar that
    moves with the frame, so every frame differs from every other. With `movie`, as `lodbench clips --mp4 only`
    writes it: the frame grids over the error grids in an MP4 alone (ffmpeg; the test is skipped without it).
    Returns the index."""
    import json
    import shutil

    import numpy as np
    from PIL import Image, ImageDraw

    colours = [(70, 110, 200), (200, 90, 60), (60, 160, 90), (170, 150, 40)]
    width, height = tile[0] * len(methods), tile[1]
    out = folder / "clips"
    index = {"run": folder.name, "fps": 10, "scale": 1, "heatmap_full_scale": 0.25, "clips": []}
    for c in range(clips):
        name = f"bunny-sweep_c1_t{c:02d}"
        (out / name).mkdir(parents=True, exist_ok=True)
        first = 10 + 20 * c
        numbers = list(range(first - 2, first - 2 + frames))
        gif, stacked = [], []
        for j, f in enumerate(numbers):
            for kind in ("frame", "error"):
                im = Image.new("RGB", (width, height), (0, 0, 0))
                d = ImageDraw.Draw(im)
                for t, method in enumerate(methods):
                    x0 = t * tile[0]
                    if kind == "frame":
                        d.rectangle([x0, 0, x0 + tile[0] - 1, height - 1], fill=colours[t % len(colours)])
                    bar = x0 + 4 + (tile[0] - 16) * j // max(1, frames - 1)
                    d.rectangle([bar, 20, bar + 8, height - 4], fill=(255, 255, 255) if kind == "frame" else
                                (255, 60 * t, 0))
                    d.text((x0 + 4, 4), f"{method} {kind} {f}", fill=(255, 255, 255))
                im.save(out / name / f"{kind}_{f:05d}.png")
                if kind == "frame":
                    gif.append(im)
                else:
                    stacked.append(np.concatenate([np.asarray(gif[-1]), np.asarray(im)]))
        gif[0].save(out / f"{name}.gif", save_all=True, append_images=gif[1:], duration=100, loop=0)
        gif[0].save(out / f"{name}.png", save_all=True, append_images=gif[1:], duration=100, loop=0)
        t_instances = [0 if j in (0, frames - 1) else 1 for j in range(frames)]
        index["clips"].append({
            "name": name, "scene": "bunny-sweep", "count": 1, "transition": c, "lods": f"{c}->{c + 1}",
            "first_frame": first, "last_frame": numbers[-2], "methods": list(methods), "frames": numbers,
            "k": [None if t == 0 else round(j / frames, 3) for j, t in enumerate(t_instances)],
            "t_instances": t_instances,
            "frame_images": [f"{name}/frame_{f:05d}.png" for f in numbers],
            "error_images": [f"{name}/error_{f:05d}.png" for f in numbers],
            "apng": f"{name}.png", "gif": f"{name}.gif", "mp4": None, "width": width, "height": height,
        })
        if movie:
            write_mp4(out / f"{name}.mp4", stacked, index["fps"])
            shutil.rmtree(out / name)
            for ext in ("png", "gif"):
                (out / f"{name}.{ext}").unlink()
            index["clips"][-1].update(frame_images=None, error_images=None, apng=None, gif=None, mp4=f"{name}.mp4")
    (out / "index.json").write_text(json.dumps(index, indent=2))
    return index


def write_mp4(path: Path, pictures, fps: int):
    """RGB pictures (arrays, all one size) as an H.264 MP4, as `lodbench clips` encodes it (CRF 18, yuv420p)."""
    import shutil

    if shutil.which("ffmpeg") is None:
        pytest.skip("no ffmpeg for an MP4-only clip: apt-get install ffmpeg")
    h, w = pictures[0].shape[:2]
    r = subprocess.run(["ffmpeg", "-loglevel", "error", "-y", "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", f"{w}x{h}",
                        "-r", str(fps), "-i", "-", "-c:v", "libx264", "-crf", "18", "-pix_fmt", "yuv420p",
                        "-movflags", "+faststart", str(path)], input=b"".join(p.tobytes() for p in pictures),
                       capture_output=True)
    assert r.returncode == 0, r.stderr.decode()


@pytest.fixture(scope="session")
def make_clips():
    """write_clips (a synthetic clips/ folder, as `lodbench clips` writes it) for tests of report.html."""
    return write_clips


@pytest.fixture(scope="session")
def software_run(tmp_path_factory) -> Path:
    """bunny-sweep, reference, discrete and alpha at the quick profile (320x240), 120 frames every one dumped with
    the transitions' clips (--dump-transitions): what `lodbench clips` needs. About 5 s on a 2-core software
    adapter."""
    out = tmp_path_factory.mktemp("software") / "run"
    lodbench("run", "--scene", "bunny-sweep", "--method", "reference,discrete,alpha", "--profile", "quick",
             "--frames", "120", "--dump-frames", "--dump-transitions", "--out", str(out))
    return out
