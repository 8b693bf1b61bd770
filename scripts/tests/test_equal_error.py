"""scripts/equal_error.py: curves read at equal rmse on a made-up sweep (interpolation between the bracketing
points, nothing outside a curve, the default levels inside every curve), and the command on a folder."""
import csv
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import equal_error  # noqa: E402

SCRIPT = Path(__file__).resolve().parents[1] / "equal_error.py"


def row(pe, method, rmse, tris, ratio, lodpop, cracks=0):
    return {"pixel-error": str(pe), "scene": "terrain", "method": method, "count": "1", "rmse_mean": str(rmse),
            "triangles_mean": str(tris), "ratio_to_baseline": str(ratio), "lodpop_max": str(lodpop),
            "crack_px_max": str(cracks), "baseline": "reference"}


ROWS = [
    row(1, "reference", 0.0, 1000, 1.0, 0.0), row(2, "reference", 0.0, 1000, 1.0, 0.0),
    row(1, "a", 0.010, 400, 0.5, 0.004), row(2, "a", 0.020, 200, 0.3, 0.008, cracks=3),
    row(1, "b", 0.005, 600, 0.7, 0.002), row(2, "b", 0.015, 300, 0.4, 0.006),
]


def test_curves_are_read_between_their_points_only():
    c = equal_error.curves(ROWS, "pixel-error")["terrain"]
    assert list(c) == ["a", "b"]  # the reference (the baseline) is no curve
    v = equal_error.at(c["a"], 0.015)
    assert (v["triangles"], v["cost"], v["lodpop_max"], v["variable"]) == (300, 0.4, 0.006, 1.5)
    assert v["crack_px_max"] == 3  # the larger of the bracketing points
    assert equal_error.at(c["a"], 0.005) is None  # below a's sweep: never extrapolated
    assert equal_error.at(c["b"], 0.015)["triangles"] == 300  # an end point
    levels = equal_error.default_levels(c)
    assert (levels[0], levels[-1]) == (0.010, 0.015)  # where both curves are
    assert all(equal_error.at(p, lv) is not None for p in c.values() for lv in levels)


def test_command_writes_its_table(tmp_path):
    with open(tmp_path / "summary.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(ROWS[0]))
        w.writeheader()
        w.writerows(ROWS)
    r = subprocess.run([sys.executable, str(SCRIPT), str(tmp_path), "--levels", "0.012"], capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stderr
    assert "| 0.01200 | a | 1.20 | 360 | 0.460 | nan | 0.00480 | 3 |" in r.stdout  # no frames.csv: no CPU cost
    with open(tmp_path / "equal_error.csv") as f:
        out = list(csv.DictReader(f))
    assert [o["method"] for o in out] == ["a", "b"]
    assert (tmp_path / "equal_error.png").stat().st_size > 0
    # A folder without summary.csv is refused with its name.
    r = subprocess.run([sys.executable, str(SCRIPT), str(tmp_path / "none")], capture_output=True, text=True)
    assert r.returncode != 0 and "summary.csv not found" in r.stderr


def test_cpu_cost_is_paired_round_by_round(tmp_path):
    run = tmp_path / "runs" / "pixel-error=1"
    run.mkdir(parents=True)
    with open(run / "summary.csv", "w") as f:
        f.write("scene,method,count,baseline\nterrain,reference,1,reference\nterrain,a,1,reference\n")
    with open(run / "frames.csv", "w") as f:
        f.write("scene,method,count,frame,cpu_ms,round\n")
        # Round 0: medians 2 and 1 (ratio 2); round 1: medians 8 and 2 (ratio 4): geometric mean 2 sqrt 2.
        for method, r0, r1 in (("reference", (1, 1, 5), (2, 2, 2)), ("a", (2, 2, 9), (8, 1, 8))):
            for i, (t0, t1) in enumerate(zip(r0, r1)):
                f.write(f"terrain,{method},1,{i},{t0},0\nterrain,{method},1,{i + 3},{t1},1\n")
    got = equal_error.cpu_ratios(run / "frames.csv")
    assert abs(got[("terrain", "a")] - 8 ** 0.5) < 1e-12 and got[("terrain", "reference")] == 1.0
    c = equal_error.curves(ROWS, "pixel-error", tmp_path)["terrain"]
    assert abs(c["a"][0]["cpu_cost"] - 8 ** 0.5) < 1e-12  # the point of pixel error 1
    assert c["a"][1]["cpu_cost"] != c["a"][1]["cpu_cost"]  # pixel error 2 has no frames.csv: NaN
