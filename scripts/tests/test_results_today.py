"""The committed results are today's: every manifest under results/ names the build that made it (a commit of this
repository, so a stale folder can be seen), and two small folders of results/cpu/, remade from the code under test by
scripts/regenerate-results.sh, equal the committed ones cell for cell on their image columns.

The remake is compared exactly: the image figures are exact integer sums on the same adapter and driver, so any
difference is a change of the code's output (on another adapter the comparison is skipped, with the reason; the
regression set, tests/long/regress.rs, holds the cross-adapter tolerance). Timing columns are not compared."""
import csv
import json
import os
import re
import subprocess
from pathlib import Path

import pytest

from conftest import ROOT, lodbench_binary

# The cheapest folders with image figures: a glTF scene with its materials, and a unified scene's blocks and seams.
FOLDERS = ["report-fox-quick", "unified-bunny-halves-ci"]
# Figures of the images and of what was drawn (CPU counts, and the fragments the adapter counted: exact on the
# same adapter and driver); everything else is time or its ratios.
IMAGE = re.compile(
    r"rmse|pop|de2000|flip|uncovered|crack|^(scene|method|count|frames|triangles_mean|draw_calls_mean|"
    r"t_instances_mean|units_drawn_mean|first_frame|last_frame|lods|transition|fragments|fragments_mean)$"
)
MANIFESTS = ("run.json", "probe.json", "overhead.json", "tune.json")


def manifests():
    for name in MANIFESTS:
        yield from sorted((ROOT / "results").rglob(name))


def build_of(path: Path) -> str:
    data = json.loads(path.read_text())
    return data.get("git_commit") or data.get("lodbench", {}).get("git_commit", "")


def test_every_manifest_names_a_build_of_this_repository():
    found = list(manifests())
    assert found, "no manifests under results/"
    in_git = subprocess.run(["git", "rev-parse", "--git-dir"], cwd=ROOT, capture_output=True).returncode == 0
    problems = []
    for path in found:
        build = build_of(path)
        commit = build.removesuffix("-dirty")
        if not re.fullmatch(r"[0-9a-f]{7,40}", commit):
            problems.append(f"{path.relative_to(ROOT)}: names no build ({build!r})")
        elif in_git and subprocess.run(["git", "cat-file", "-e", f"{commit}^{{commit}}"], cwd=ROOT,
                                       capture_output=True).returncode != 0:
            problems.append(f"{path.relative_to(ROOT)}: {commit} is not a commit of this repository")
    assert not problems, "\n".join(problems)


def test_a_manifest_without_a_build_is_caught(tmp_path):
    path = tmp_path / "run.json"
    path.write_text(json.dumps({"git_commit": ""}))
    assert not re.fullmatch(r"[0-9a-f]{7,40}", build_of(path).removesuffix("-dirty"))


def rows(path: Path):
    if not path.exists():
        return []
    with path.open(newline="") as f:
        return [{k: v for k, v in r.items() if IMAGE.search(k)} for r in csv.DictReader(f)]


def adapter(run_json: Path):
    a = json.loads(run_json.read_text()).get("adapter") or {}
    return a.get("name"), a.get("driver"), a.get("driver_info")


@pytest.mark.long
@pytest.mark.parametrize("name", FOLDERS)
def test_a_committed_folder_is_what_the_code_makes(name, tmp_path):
    committed = ROOT / "results" / "cpu" / name
    env = dict(os.environ, LODBENCH=str(lodbench_binary()))
    r = subprocess.run(["bash", "scripts/regenerate-results.sh", "--out", str(tmp_path), name], cwd=ROOT, env=env,
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    remade = tmp_path / name
    if adapter(remade / "run.json") != adapter(committed / "run.json"):
        pytest.skip(f"{name} was made on {adapter(committed / 'run.json')}, this machine has "
                    f"{adapter(remade / 'run.json')}")
    for csv_name in ("summary.csv", "transitions.csv"):
        want, got = rows(committed / csv_name), rows(remade / csv_name)
        assert len(got) == len(want), f"{csv_name}: {len(got)} rows, committed {len(want)}"
        for i, (w, g) in enumerate(zip(want, got)):
            differ = {k: (w[k], g.get(k)) for k in w if w[k] != g.get(k)}
            assert not differ, f"{name}/{csv_name} row {i + 1} (committed, remade): {differ}"
