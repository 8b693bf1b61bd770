"""A `lodbench tune` folder: plot.py draws its curves and writes its report; tune_rules.py builds its paths and
refuses what it cannot check."""
import csv
import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import lodbench

SCRIPTS = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(SCRIPTS))
import tune_rules  # noqa: E402


@pytest.fixture(scope="session")
def tuned(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("tune") / "bunny"
    lodbench("tune", "--scene", "bunny-sweep", "--budget-lodpop", "0.01", "--views", "2", "--distances", "8",
             "--width", "96", "--height", "72", "--out", str(out))
    return out


def test_plot_draws_the_curves_and_the_rules(tuned):
    r = subprocess.run([sys.executable, str(SCRIPTS / "plot.py"), str(tuned)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert [p.name for p in (tuned / "figures").glob("*.png")] == ["tune_bunny.png"]
    report = (tuned / "report.md").read_text()
    rules = list(csv.DictReader(open(tuned / "rules.csv")))
    # tune's row and the three engines' per pair.
    assert {r["rule"] for r in rules} == {"tune", "unreal", "godot", "meshopt"}
    assert "## Switches" in report and "## Switch distances by rule" in report
    assert report.count("| bunny |") == len(rules) + len({(r["lod_from"]) for r in rules if r["rule"] == "tune"})


def test_the_rules_checker_refuses_what_it_cannot_check(tuned, tmp_path):
    meta = json.loads((tuned / "tune.json").read_text())
    for change, needle in ((lambda m: m["settings"].update(budget={"metric": "jod", "value": 9.0}), "jod budget"),
                           (lambda m: m["models"].append(m["models"][0]), "2 models")):
        folder = tmp_path / needle.replace(" ", "-")
        folder.mkdir()
        (folder / "rules.csv").write_text((tuned / "rules.csv").read_text())
        m = json.loads(json.dumps(meta))
        change(m)
        (folder / "tune.json").write_text(json.dumps(m))
        r = subprocess.run([sys.executable, str(SCRIPTS / "tune_rules.py"), str(folder)], capture_output=True,
                           text=True)
        assert r.returncode == 2 and needle in r.stderr, r.stderr
    r = subprocess.run([sys.executable, str(SCRIPTS / "tune_rules.py"), str(tmp_path)], capture_output=True,
                       text=True)
    assert r.returncode == 2 and "no tune.json" in r.stderr


def test_paths_look_at_the_centre_in_geometric_steps(tmp_path):
    path = tmp_path / "p.csv"
    tune_rules.write_path(path, [1.0, 2.0, 3.0], (0.0, 3.0, 4.0), 2.0, 32.0, 5)
    rows = list(csv.DictReader(open(path)))
    d = [math.dist([float(r[k]) for k in "xyz"], [1.0, 2.0, 3.0]) for r in rows]
    assert [round(x, 4) for x in d] == [2.0, 4.0, 8.0, 16.0, 32.0]
    assert all((float(r["target_x"]), float(r["target_y"]), float(r["target_z"])) == (1.0, 2.0, 3.0) for r in rows)
    # Along the direction given (normalised): x stays, y and z grow 3:4.
    assert abs((float(rows[1]["y"]) - 2.0) / (float(rows[1]["z"]) - 3.0) - 0.75) < 1e-4


THREE = SCRIPTS / "threejs" / "node_modules" / "three"

# Loads engines/threejs-lod.js with Node's require beside the pinned three.js, builds every model's THREE.LOD
# from placeholder levels and prints what three.js holds: its levels' distances and the offset of level 0.
BUILD_LODS = """
const THREE = require(process.argv[2]);
const { lodbenchModels, lodbenchLod } = require(process.argv[3]);
const out = {};
for (const name of Object.keys(lodbenchModels)) {
  const n = lodbenchModels[name].distances.length;
  const lod = lodbenchLod(THREE, name, Array.from({ length: n }, () => new THREE.Object3D()));
  out[name] = { isLOD: lod.isLOD === true, revision: THREE.REVISION,
                distances: lod.levels.map((l) => l.distance), offset: lod.levels[0].object.position.toArray() };
}
process.stdout.write(JSON.stringify(out));
"""


@pytest.mark.skipif(not THREE.is_dir(), reason="three.js is installed by .ci/setup-tests (npm ci --prefix "
                    "scripts/threejs)")
def test_the_threejs_file_builds_a_lod_with_the_tuned_distances(tuned, tmp_path):
    check = tmp_path / "build_lods.js"
    check.write_text(BUILD_LODS)
    r = subprocess.run(["node", str(check), str(THREE), str(tuned / "engines" / "threejs-lod.js")],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    built = json.loads(r.stdout)
    pinned = json.loads((SCRIPTS / "threejs" / "package.json").read_text())["dependencies"]["three"]
    engines = json.loads((tuned / "tune.json").read_text())["engines"]
    assert sorted(built) == sorted(m["name"] for m in engines)
    for m in engines:
        b = built[m["name"]]
        assert b["isLOD"] and b["revision"] == pinned.split(".")[1], b
        assert b["distances"] == pytest.approx([0.0] + m["switches"], rel=1e-6)
        assert b["offset"] == pytest.approx([-c for c in m["center"]], abs=1e-6)
