"""plot.py makes every figure its folder's data allows, and a report.md that embeds them."""
import csv
import shutil
import subprocess
import sys
from pathlib import Path

from PIL import Image

from conftest import lodbench

SCRIPT = Path(__file__).resolve().parents[1] / "plot.py"


def plot(*folders: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(SCRIPT), *map(str, folders)], capture_output=True, text=True)


def figures(folder: Path):
    return sorted(p.name for p in (folder / "figures").glob("*.png"))


def test_sweep_folder(dump, tmp_path):
    folder = tmp_path / "sweep"
    shutil.copytree(dump, folder)
    r = plot(folder)
    assert r.returncode == 0, r.stderr
    assert figures(folder) == [
        "ceilings_bunny-sweep.png", "contact_bunny-sweep.png", "cost_bunny-sweep.png", "decision_bunny-sweep.png",
        "fig6_bunny-sweep.png",
        "fsi_buffers_bunny-sweep.png", "sweep_bunny-sweep.png", "transitions_bunny-sweep.png",
    ]
    report = (folder / "report.md").read_text()
    for name in figures(folder):
        assert f"(figures/{name})" in report
        with Image.open(folder / "figures" / name) as im:
            assert im.width > 300 and im.height > 200
            # Plots in 256 colours; the figures of rendered frames keep every shade (lodbench_results.save_figure).
            frames = name.startswith(("contact_", "fsi_buffers_"))
            assert im.mode == ("RGBA" if frames else "P"), (name, im.mode)
    assert "| bunny-sweep | dither |" in report
    assert "| bunny-sweep | fsi |" in report
    assert "## bunny-sweep: max lodpop (pose held) of each transition (its frames and the 2 after)" in report
    assert "## bunny-sweep: max pop (motion included) of each transition (its frames and the 2 after)" in report


def test_a_timing_only_run_gets_no_quality_figures(tmp_path):
    """--quality off leaves every image figure empty: no popping or cost figure, the tables' cells empty."""
    folder = tmp_path / "timing"
    lodbench("run", "--scene", "bunny-sweep", "--method", "discrete,alpha", "--width", "64", "--height", "48",
             "--frames", "24", "--warmup", "0", "--rounds", "4", "--quality", "off", "--out", str(folder))
    r = plot(folder)
    assert r.returncode == 0, r.stderr
    # Only the timing's figure: the blocks' triangle rate against the adapter's ceiling.
    assert figures(folder) == ["ceilings_bunny-sweep.png"]
    report = (folder / "report.md").read_text()
    row = next(line for line in report.splitlines() if line.startswith("| bunny-sweep | alpha |"))
    assert "|  |" in row and "| 0.0 |" not in row, row


def test_contact_sheet_transition_choice(dump, tmp_path):
    folder = tmp_path / "sweep"
    shutil.copytree(dump, folder)
    r = subprocess.run([sys.executable, str(SCRIPT), "--transition", "first", str(folder)], capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stderr
    assert "frames around transition 1 of the path" in (folder / "report.md").read_text()
    r = subprocess.run([sys.executable, str(SCRIPT), "--transition", "99", str(folder)], capture_output=True,
                       text=True)
    assert r.returncode == 2 and "--transition 99: the run has" in r.stderr
    r = subprocess.run([sys.executable, str(SCRIPT), "--transition", "last", str(folder)], capture_output=True,
                       text=True)
    assert r.returncode == 2 and "expected worst, first or a number" in r.stderr


def test_grid_folder_gets_fig5(grid, tmp_path):
    folder = tmp_path / "grid"
    shutil.copytree(grid, folder)
    r = plot(folder)
    assert r.returncode == 0, r.stderr
    assert "fig5_bunny-grid.png" in figures(folder)
    assert "sweep_bunny-grid.png" not in figures(folder)  # a static scene has no popping to plot


def test_not_a_results_folder(tmp_path):
    r = plot(tmp_path)
    assert r.returncode == 2 and "frames.csv" in r.stderr


def test_viewport_experiment_gets_fig8(viewport_experiment, tmp_path):
    folder = tmp_path / "exp"
    shutil.copytree(viewport_experiment, folder)
    r = plot(folder)
    assert r.returncode == 0, r.stderr
    assert "fig8_bunny-sweep.png" in figures(folder)
    assert "| 64,48 | bunny-sweep | discrete |" in (folder / "report.md").read_text()


def test_other_sweep_variable_splits_the_series(check_experiment, tmp_path):
    folder = tmp_path / "exp"
    shutil.copytree(check_experiment, folder)
    r = plot(folder)
    assert r.returncode == 0, r.stderr
    report = (folder / "report.md").read_text()
    assert "| none | windmills | fsi (fsi-check none) |" in report
    assert "| forward | windmills | fsi (fsi-check forward) |" in report
    assert "fig8_windmills.png" not in figures(folder)


def test_pixel_error_experiment_gets_the_unified_figure(pixel_error_experiment, tmp_path):
    folder = tmp_path / "exp"
    shutil.copytree(pixel_error_experiment, folder)
    r = plot(folder)
    assert r.returncode == 0, r.stderr
    assert "unified_terrain.png" in figures(folder)
    report = (folder / "report.md").read_text()
    assert "| 1.0 | terrain | clusterlod |" in report and "| 4.0 | terrain | blocks |" in report
    assert "crack_px_mean" in report
    with Image.open(folder / "figures" / "unified_terrain.png") as im:
        assert im.width > 600


def rust_const(name: str) -> str:
    """The value of `const NAME: TYPE = VALUE;` in the Rust source (wherever under src/ it is)."""
    import re
    pattern = re.compile(rf"const {name}: \w+ = ([^;]+);")
    for path in sorted((SCRIPT.parents[1] / "src").rglob("*.rs")):
        m = pattern.search(path.read_text())
        if m:
            return m.group(1)
    raise AssertionError(f"no const {name} in src/")


def test_clip_window_and_crop_mirror_the_rust():
    import importlib.util
    sys.path.insert(0, str(SCRIPT.parent))
    spec = importlib.util.spec_from_file_location("plot", SCRIPT)
    plot_module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(plot_module)
    assert plot_module.CLIP_LEAD == int(rust_const("TRANSITION_LEAD"))
    assert plot_module.CLIP_TAIL == int(rust_const("TRANSITION_TAIL"))
    assert plot_module.CROP_MARGIN == int(rust_const("CROP_MARGIN"))
    assert plot_module.CROP_MAX_SHARE == float(rust_const("CROP_MAX_SHARE"))
    assert list(plot_module.clip_window([10, 11, 12])) == list(range(8, 15))
    assert list(plot_module.clip_window([1]))[0] == 0


def with_adapters(src: Path, dst: Path, adapters):
    """A copy of run folder src as a merged folder of one run per adapter: every CSV with an `adapter` column first
    and its rows once per adapter (each further adapter's GPU times doubled)."""
    dst.mkdir()
    for name in ("frames.csv", "summary.csv", "transitions.csv"):
        if not (src / name).is_file():
            continue
        with open(src / name, newline="") as f:
            rows = list(csv.DictReader(f))
        if not rows:
            continue
        with open(dst / name, "w", newline="") as f:
            w = csv.DictWriter(f, ["adapter"] + list(rows[0]))
            w.writeheader()
            for i, adapter in enumerate(adapters):
                for r in rows:
                    r = dict(r, adapter=adapter)
                    for k in ("gpu_ms", "gpu_ms_median"):
                        if r.get(k):
                            r[k] = str(float(r[k]) * (1 + i))
                    w.writerow(r)


def load_plot():
    import importlib.util
    sys.path.insert(0, str(SCRIPT.parent))
    spec = importlib.util.spec_from_file_location("plot", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_one_curve_per_method_and_adapter(grid, tmp_path, monkeypatch):
    """A merged folder of runs on two adapters: fig5 draws a curve per (method, adapter), the adapter in its label,
    and the summary table has the adapter column; with one adapter the labels are the methods' alone."""
    plot_module = load_plot()
    curves = []
    fig5 = plot_module.fig5

    def spy(scene, summary, path):
        curves.append(sorted({r["method"] for r in summary}))
        fig5(scene, summary, path)

    monkeypatch.setattr(plot_module, "fig5", spy)
    two = tmp_path / "two"
    with_adapters(grid, two, ["GPU A", "GPU B"])
    plot_module.report(two)
    assert curves == [["alpha [GPU A]", "alpha [GPU B]", "discrete [GPU A]", "discrete [GPU B]"]]
    report = (two / "report.md").read_text()
    assert "| GPU B | bunny-grid | discrete [GPU B] | 2 |" in report, report
    curves.clear()
    one = tmp_path / "one"
    with_adapters(grid, one, ["GPU A"])
    plot_module.report(one)
    assert curves == [["alpha", "discrete"]]
    assert "| bunny-grid | discrete | 2 |" in (one / "report.md").read_text()
