"""scripts/frontier.py: the frontier's points and the "cheapest at or below a popping" table, on made-up summaries
(the rule) and on a real two-variable sweep through plot.py (the figure and the table in report.md)."""
import shutil
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import frontier  # noqa: E402

PLOT = Path(__file__).resolve().parents[1] / "plot.py"


def row(band, method, lodpop, ratio, rmse=0.01):
    return {"band": band, "scene": "s", "method": method, "count": "1", "lodpop_max": str(lodpop),
            "ratio_to_baseline_transition": str(ratio), "ratio_to_baseline": str(ratio), "rmse_mean": str(rmse),
            "baseline": "discrete"}


def pair(band, a, b, ratio, lo, hi):
    return {"band": band, "scene": "s", "count": "1", "method_a": a, "method_b": b, "ratio_transition": str(ratio),
            "ratio_transition_ci95_lo": str(lo), "ratio_transition_ci95_hi": str(hi)}


SUMMARY = [
    row("0.05", "discrete", 0.010, 1.0), row("0.05", "alpha", 0.004, 1.10), row("0.05", "dither", 0.004, 1.20),
    row("0.2", "discrete", 0.010, 1.0), row("0.2", "alpha", 0.002, 1.30), row("0.2", "dither", 0.0012, 1.05),
]


def test_cheapest_is_paired_within_its_run_only(tmp_path):
    pts = frontier.points(tmp_path, SUMMARY, ["band"])
    assert [p["setting"] for p in pts] == ["0.05"] * 3 + ["0.2"] * 3
    pairs = [pair("0.05", "alpha", "dither", 0.92, 0.88, 0.96), pair("0.2", "discrete", "dither", 0.95, 0.9, 1.01),
             pair("0.2", "alpha", "dither", 1.24, 1.1, 1.4)]
    rows = {r["lodpop at most"].split(" ")[0]: r for r in frontier.cheapest("s", pts, pairs, ["band"])}
    # At discrete's own popping discrete is cheapest (its cost 1.0 in both runs); the next method of that run
    # (band 0.05: alpha) is compared by the pair (discrete, alpha), which pairs.csv lacks here.
    assert rows["0.01"]["cheapest"].startswith("discrete")
    assert rows["0.01"]["paired"] == "no paired ratio"
    # At half: alpha (0.05, cost 1.10) beats dither (0.05, 1.20) and dither (0.2, 1.05) is cheaper still, but in
    # another run: the cheapest point is dither at 0.2, compared with alpha of the same run by alpha/dither = 1.24,
    # read the other way round (dither/alpha = 1/1.24, interval [1/1.4, 1/1.1]): cheaper.
    half = rows["0.005"]
    assert half["cheapest"] == "dither (band 0.2)" and half["next in the same run"] == "alpha"
    assert half["paired"].endswith("cheaper") and half["paired"].startswith("0.806")
    # At a quarter only band 0.2's alpha and dither meet it; at an eighth only dither.
    assert rows["0.0025"]["cheapest"] == "dither (band 0.2)"
    assert rows["0.00125"]["cheapest"] == "dither (band 0.2)"
    assert rows["0.00125"]["next in the same run"] == "none meets it"
    # An interval that holds 1 says no difference.
    pairs[2] = pair("0.2", "alpha", "dither", 1.02, 0.97, 1.08)
    rows = frontier.cheapest("s", pts, pairs, ["band"])
    assert rows[1]["paired"].endswith("no difference")


def test_two_variable_sweep_gets_a_frontier(band_experiment, tmp_path):
    folder = tmp_path / "exp"
    shutil.copytree(band_experiment, folder)
    r = subprocess.run([sys.executable, str(PLOT), str(folder)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert (folder / "figures" / "frontier_bunny-sweep.png").is_file()
    report = (folder / "report.md").read_text()
    assert "## bunny-sweep: cheapest at or below a popping (paired within a run)" in report
    assert "| lodpop at most | cheapest | cost | next in the same run | paired |" in report
    # Every combination of the two swept values is its own series in the other figures' tables.
    assert "| 0.25 | 0.15 | bunny-sweep | dither (pixel-error 0.25, band 0.15) |" in report
