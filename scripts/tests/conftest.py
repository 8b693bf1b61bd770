"""Fixtures shared by the tests of scripts/: small lodbench runs on whatever adapter the machine has."""
import functools
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@functools.lru_cache(maxsize=1)
def lodbench_binary() -> Path:
    """LODBENCH_BIN, or the binary `cargo test` builds (target/debug/lodbench, the README's test command builds it
    just before pytest), brought up to date with `cargo test --no-run` (the same build, a no-op when fresh), so the
    scripts are never tested against an older or a release binary."""
    if os.environ.get("LODBENCH_BIN"):
        return Path(os.environ["LODBENCH_BIN"])
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    if not target.is_absolute():
        target = ROOT / target
    subprocess.run(["cargo", "test", "--no-run", "--quiet"], cwd=ROOT, check=True, capture_output=True)
    return target / "debug" / "lodbench"


def lodbench(*args: str) -> None:
    subprocess.run([str(lodbench_binary()), *args], check=True, capture_output=True)


@pytest.fixture(scope="session")
def dump(tmp_path_factory) -> Path:
    """bunny-sweep, discrete, dither and fsi (a method name containing `_f`), 60 frames at 160x120 with de2000, every
    5th frame dumped."""
    out = tmp_path_factory.mktemp("dump") / "run"
    lodbench("run", "--scene", "bunny-sweep", "--method", "discrete,dither,fsi", "--width", "160", "--height", "120",
             "--frames", "60", "--warmup", "0", "--switch-distances", "14,16,18", "--metrics", "rmse,pop,de2000", "--dump-frames",
             "--dump-every", "5", "--out", str(out))
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
def pixel_error_experiment(tmp_path_factory) -> Path:
    """A two-value pixel-error sweep of the terrain at the regress profile (small), every unified method."""
    base = tmp_path_factory.mktemp("experiment")
    spec = base / "unified.toml"
    spec.write_text('name = "unified"\n[run]\nscene = ["terrain"]\nprofile = "regress"\nframes = 8\nwarmup = 0\n'
                    '[sweep]\nvariable = "pixel-error"\nvalues = [1.0, 4.0]\n')
    out = base / "run"
    lodbench("experiment", str(spec), "--out", str(out))
    return out
