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
