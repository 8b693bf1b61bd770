"""scripts/gpu-suite.sh's budget (scripts/gpu_suite.py): the frames a step gets from the cost model, the correction
from finished steps, and, on lavapipe (--software), a whole budgeted run that ends within its budget plus the frame
in progress, with times.txt and budget.json saying what ran, what was cut and what was left (long suite)."""
import json
import os
import subprocess
import sys
import time

import pytest

from conftest import ROOT, lodbench_binary

sys.path.insert(0, str(ROOT / "scripts"))
import gpu_suite  # noqa: E402

# One block: 2 s of set-up, 2 methods, 4 frames drawn per frame index, 1 M triangles, 0.5 M pixels.
BLOCK = (2.0, 2, 4, 1e6, 5e5)
TRI, PX = 1e8, 1e9  # 8 * (0.01 + 0.0005) = 0.084 s a frame index


def test_the_cost_is_set_up_plus_frames_at_the_rates():
    assert gpu_suite.cost([BLOCK], 50, TRI, PX) == pytest.approx(2.0 + (50 + gpu_suite.WARMUP) * 0.084)
    assert gpu_suite.cost([BLOCK, BLOCK], 50, TRI, PX) == pytest.approx(2 * gpu_suite.cost([BLOCK], 50, TRI, PX))


def test_frames_fill_the_time_left_and_no_more():
    # 20 s: (20 - 2) / 0.084 = 214 frame indices, 10 of them warm-up.
    assert gpu_suite.frames_that_fit([BLOCK], 20, TRI, PX, 1.0, 1000) == 204
    assert gpu_suite.cost([BLOCK], 204, TRI, PX) <= 20 < gpu_suite.cost([BLOCK], 205, TRI, PX)
    # At most the frames asked for; a factor of 2 (the finished steps took twice their estimate) halves the time.
    assert gpu_suite.frames_that_fit([BLOCK], 20, TRI, PX, 1.0, 60) == 60
    assert gpu_suite.frames_that_fit([BLOCK], 20, TRI, PX, 2.0, 1000) == 85  # (10 - 2) / 0.084 - 10
    # Not even MIN_FRAMES fit: 0, the step is left.
    assert gpu_suite.frames_that_fit([BLOCK], 3, TRI, PX, 1.0, 1000) == 0


def test_the_factor_is_the_median_of_measured_over_estimated():
    b = gpu_suite.Budget(100, time.monotonic())
    assert b.factor() == 1.0
    b.ratios += [3.0, 1.0, 2.0]
    assert b.factor() == 2.0
    b.ratios.append(10.0)
    assert b.factor() == 2.5


def test_the_step_in_progress_is_stopped_at_the_deadline(tmp_path):
    """At the deadline the step's process gets SIGTERM (lodbench stops after the frame in progress: the experiment
    tests' sigterm-resume); the step is cut, and the steps after it are left."""
    args = gpu_suite.argparse.Namespace(budget_s=1.0, frames=60)
    s = gpu_suite.Suite(args, "lodbench", tmp_path)
    t0 = time.monotonic()
    assert not s.step("sleeper", [["sleep", "30"]])
    assert time.monotonic() - t0 < 5
    assert not s.step("after", [["true"]])
    s.write_budget()
    budget = json.loads((tmp_path / "budget.json").read_text())
    assert [(e["step"], e["status"]) for e in budget["steps"]] == [("sleeper", "cut"), ("after", "left")]
    times = (tmp_path / "times.txt").read_text()
    assert "sleeper: cut at the budget after 1 s" in times and "after: left (the budget was spent)" in times


def test_bad_suite_arguments_are_refused(capsys):
    assert gpu_suite.main(["many"]) == 2
    assert "FRAMES must be a whole number" in capsys.readouterr().err
    assert gpu_suite.main(["60", "fsi-fig9"]) == 2
    assert "no experiment 'fsi-fig9'" in capsys.readouterr().err
    assert gpu_suite.main(["--budget-s", "0"]) == 2
    assert "--budget-s must be a positive number" in capsys.readouterr().err


BUDGET_S = 120
# What a budgeted run may take past its budget: the frame in progress when the deadline's SIGTERM comes (on lavapipe
# at the papers' sizes, a frame of 4,000 windmills or trees takes seconds), run.json written, and the suite's own
# start (the adapter listing) and end.
OVER_S = 30


@pytest.mark.long
def test_a_budgeted_suite_ends_in_time_and_says_what_it_left(tmp_path):
    env = dict(os.environ, LODBENCH=str(lodbench_binary()))
    t0 = time.monotonic()
    r = subprocess.run(["bash", str(ROOT / "scripts" / "gpu-suite.sh"), "--budget-s", str(BUDGET_S), "--software",
                        "--out", str(tmp_path), "60"], capture_output=True, text=True, env=env)
    took = time.monotonic() - t0
    print(r.stdout[-3000:], r.stderr[-2000:], f"took {took:.0f} s", sep="\n")
    assert r.returncode == 0, r.stderr
    assert took <= BUDGET_S + OVER_S
    (folder,) = [p for p in tmp_path.iterdir() if p.is_dir()]
    budget = json.loads((folder / "budget.json").read_text())
    steps = [s["step"] for s in budget["steps"]]
    assert steps[:4] == ["probe", "overhead", "aa-gpu", "fsi-fig8"], steps
    # Every step once, each ran, cut or left; one is cut at most, and only the last that ran.
    assert len(steps) == len(set(steps)) == 2 + len(gpu_suite.EXPERIMENTS) + 1
    status = {s["step"]: s["status"] for s in budget["steps"]}
    assert set(status.values()) <= {"ran", "cut", "left"} and status["probe"] == "ran"
    assert list(status.values()).count("cut") <= 1
    # lavapipe at the papers' sizes: the overhead and the A/A check need far more than the budget.
    assert status["overhead"] == status["aa-gpu"] == "left"
    for s in budget["steps"]:
        if s["status"] == "left":
            assert s["left_s"] < s.get("needs_s", 1e9), s
        if s["status"] in ("ran", "cut") and s["step"] != "probe":
            assert gpu_suite.MIN_FRAMES <= s["frames"] <= 60, s
    times = (folder / "times.txt").read_text()
    assert "probe: " in times and "overhead: left (about" in times
    assert "budget: " in times and "left: overhead, aa-gpu" in times
