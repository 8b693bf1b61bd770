"""lodbench's glTF reader against scripts/check_gltf.py's independent decoder, on the committed fixtures
(tests/data/gltf/, tests/data/tools/, tests/data/tetra.*): `lodbench export --out FILE.obj` at frame 0 (the clip
playing), at rest (`--animation none`) and at frame 30 gives, node by node and triangle by triangle, what the
decoder computes from the glTF specification: skins, morph targets, animation (LINEAR, STEP, CUBICSPLINE),
sparse accessors, integral floats, mirrored nodes, strips and fans, instancing, quantised attributes and
MSFT_lod node hierarchies. The decoder does not decode meshopt compression (those files are "not checked") and
neither reads Draco (lodbench refuses it with a remedy)."""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import check_gltf  # noqa: E402
from conftest import ROOT, lodbench_binary  # noqa: E402

DATA = ROOT / "tests" / "data"
UNCHECKED = {"bunny-gltfpack-c.glb", "bunny-gltfpack-c-khr.glb", "bunny-gt-meshopt.glb"}
REFUSED = {"bunny-gt-draco.glb"}


def fixtures() -> list[Path]:
    return check_gltf.find_files([str(DATA / "gltf"), str(DATA / "tools"), str(DATA / "tetra.gltf"),
                                  str(DATA / "tetra.glb")])


def test_the_fixtures_are_all_there():
    names = {p.name for p in fixtures()}
    for name in ["Fox.glb", "SimpleSkin.gltf", "SimpleMorph.gltf", "SimpleSparseAccessor.gltf",
                 "NegativeScaleTest.glb", "InterpolationTest.glb", "Animation_Node_05.gltf", "lod-hierarchy.gltf",
                 "integral-floats.gltf", "still-and-moving.gltf", "bunny-six-instanced-required.glb"]:
        assert name in names


@pytest.mark.parametrize("path", fixtures(), ids=lambda p: p.name)
def test_lodbench_draws_what_the_specification_decodes(path):
    result = check_gltf.check_file(str(lodbench_binary()), path, [0, 30], timeout=120)
    expected = "REFUSED" if path.name in REFUSED else "NOT CHECKED" if path.name in UNCHECKED else "OK"
    assert result.status == expected, "\n".join(result.lines)
