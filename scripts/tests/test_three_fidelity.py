"""lodbench's materials against three.js (scripts/three_fidelity.py) on two Khronos sample assets committed in
tests/data/gltf/: TextureSettingsTest (sampler wrap modes, single- and double-sided materials, textures lit by the
light and ambient) and VertexColorTest (COLOR_0 times base colour textures). At 320x240 the mean FLIP of lodbench's
reference frame against three.js's, over the pixels either covers, must stay below 0.06: measured 0.029 and 0.034,
from what the two renderers are known to do differently on these dielectric, non-normal-mapped files (texture
filtering: WebGL's own mipmaps and filtering against lodbench's linear-light box mipmaps; texels on pixel-centre
boundaries; silhouette pixels). The same files drawn without their materials (`--materials flat`) score 0.36 and 0.91
against the same frames, so the check tells a renderer that draws the materials from one that does not: it must
score above 0.3.

Skipped without Chromium or without three.js installed (`npm ci --prefix scripts/threejs`, which .ci/setup-tests
runs)."""
import csv
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import ROOT, lodbench_binary

sys.path.insert(0, str(ROOT / "scripts"))
from browser import chromium_binary  # noqa: E402

# The long suite (conftest.py): a whole browser session per test.
pytestmark = pytest.mark.long

SCRIPT = ROOT / "scripts" / "three_fidelity.py"
FILES = ["TextureSettingsTest.glb", "VertexColorTest.glb"]
TOLERANCE = 0.06
FLAT_FLOOR = 0.3


@pytest.fixture(scope="module")
def fidelity(tmp_path_factory):
    if chromium_binary() is None:
        pytest.skip("no Chromium (chromium, chromium-browser or google-chrome on PATH): apt-get install chromium")
    if not (ROOT / "scripts" / "threejs" / "node_modules" / "three").is_dir():
        pytest.skip("three.js is not installed: npm ci --prefix scripts/threejs")
    out = tmp_path_factory.mktemp("fidelity")
    files = [str(ROOT / "tests" / "data" / "gltf" / f) for f in FILES]
    r = subprocess.run([sys.executable, str(SCRIPT), "--lodbench", str(lodbench_binary()), "--width", "320",
                        "--height", "240", "--out", str(out), *files], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    with open(out / "fidelity.csv") as fh:
        return out, {row["file"]: row for row in csv.DictReader(fh)}


@pytest.mark.parametrize("name", FILES)
def test_lodbench_draws_the_materials_as_three_js_does(fidelity, name):
    out, rows = fidelity
    row = rows[name]
    assert float(row["flip_covered"]) < TOLERANCE, row
    assert float(row["flip_covered_flat"]) > FLAT_FLOOR, row
    assert float(row["covered_share"]) > 0.05, row
    stem = Path(name).stem
    for tag in ("lodbench", "three", "flat", "flip", "side"):
        assert (out / f"{stem}_{tag}.png").is_file()
