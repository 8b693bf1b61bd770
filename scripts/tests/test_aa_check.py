"""aa_check.py recomputes lodbench's paired timing ratio and its interval from rounds.csv alone, agrees with
summary.csv on a fresh A/A run, and fails when summary.csv's interval is not the one the rounds give."""
import csv
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import lodbench

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "aa_check.py"


@pytest.fixture(scope="module")
def aa_run(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("aa") / "run"
    lodbench("run", "--scene", "bunny-sweep", "--method", "discrete,discrete", "--width", "64", "--height", "48",
             "--frames", "24", "--warmup", "1", "--switch-distances", "14,16,18", "--rounds", "6", "--out", str(out))
    return out


def rewrite(path: Path, keep=lambda row: True, change=lambda row: None) -> None:
    """Rewrites the CSV at `path` with the rows `keep` keeps, each passed through `change` first."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        change(r)
    rows = [r for r in rows if keep(r)]
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


def run(*folders: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(SCRIPT), *map(str, folders)], capture_output=True, text=True)


def test_fresh_aa_run_agrees(aa_run):
    r = run(aa_run)
    assert r.returncode == 0, r.stdout + r.stderr
    row = [line for line in r.stdout.splitlines() if line.startswith("| run |")]
    assert len(row) == 1 and row[0].split("|")[2].strip() == "1", r.stdout


def test_tampered_interval_is_caught(aa_run, tmp_path):
    copy = tmp_path / "tampered"
    shutil.copytree(aa_run, copy)

    def widen(row):
        if row["method"] == "discrete#2":
            row["ratio_to_baseline_ci95_hi"] = str(float(row["ratio_to_baseline_ci95_hi"]) * 1.01)

    rewrite(copy / "summary.csv", change=widen)
    r = run(copy)
    assert r.returncode == 1 and "discrete#2" in r.stderr, r.stdout + r.stderr


def test_a_run_without_aa_blocks_is_an_error(aa_run, tmp_path):
    copy = tmp_path / "single"
    shutil.copytree(aa_run, copy)
    for name in ("summary.csv", "rounds.csv", "frames.csv"):
        rewrite(copy / name, keep=lambda row: row["method"] != "discrete#2")
    r = run(copy)
    assert r.returncode == 2 and "itself" in r.stderr, r.stdout + r.stderr
