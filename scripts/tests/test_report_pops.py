"""The visible pops after the answer of report.html and report.md: what the pops are measured in (run.json's
config.calibration: JNDs of a calibration, said plainly where its observer was simulated; else not calibrated) and
each method's visible pops per minute beside its largest lodpop (summary.csv's lodpop_max, lodpop_max_jnd,
pop_events, visible_pop_threshold, visible_pops_per_min). A folder made before pop events says they were not
measured. Runs of the real binary at 160x120 with a hand-written calibration.json of a 160x120 display (a
calibration holds for its display's size)."""
import csv
import html
import json
import re
import shutil
import sys
from pathlib import Path

import pytest

from conftest import ROOT, lodbench
from test_answer import answer_section, load, rendered
from test_report_html import Page, markdown_tables, plot

sys.path.insert(0, str(ROOT / "scripts"))
import report_html  # noqa: E402
from lodbench_results import read_csv, sig3  # noqa: E402

POPS = ["lodpop_max", "pop_events", "visible_pop_threshold", "visible_pops_per_min"]
LABEL = "SIMULATED observer (planted on lodpop, threshold 0.002, slope 3, lapse 0.02): not human data"


def calibration_json(path: Path, simulated=True, label=LABEL, threshold=0.002, ci95=(0.0015, 0.0027)) -> Path:
    """A calibration.json as `scripts/calibration.py fit` writes it (the fields lodbench reads), of a 160x120
    display."""
    path.write_text(json.dumps({
        "format": "lodbench-calibration", "version": 1, "simulated": simulated, "label": label,
        "display": {"width_px": 160, "height_px": 120, "refresh_hz": 60.0, "diagonal_in": 24.0,
                    "viewing_distance_cm": 60.0, "peak_luminance_cd_m2": 200.0, "pixels_per_degree": 3.2},
        "best_metric": "lodpop", "metrics": {"lodpop": {"threshold": threshold, "ci95": list(ci95)}}}))
    return path


RUN = ("--scene", "bunny-sweep", "--width", "160", "--height", "120", "--frames", "60", "--warmup", "0",
       "--rounds", "4", "--switch-distances", "14,16,18")


@pytest.fixture(scope="module")
def calibrated(tmp_path_factory) -> Path:
    """bunny-sweep, discrete and dither, run with --calibration (a simulated observer's), plotted."""
    base = tmp_path_factory.mktemp("pops")
    cal = calibration_json(base / "calibration.json")
    out = base / "calibrated"
    lodbench("run", *RUN, "--method", "discrete,dither", "--calibration", str(cal), "--out", str(out))
    r = plot(out)
    assert r.returncode == 0, r.stderr
    return out


@pytest.fixture(scope="module")
def calibrated_experiment(tmp_path_factory) -> Path:
    """Two runs (a band sweep), both with the same calibration, plotted."""
    base = tmp_path_factory.mktemp("pops-experiment")
    cal = calibration_json(base / "calibration.json")
    spec = base / "band.toml"
    spec.write_text('name = "band"\n[run]\nscene = ["bunny-sweep"]\nmethod = ["discrete", "dither"]\n'
                    f'width = 160\nheight = 120\nframes = 60\nwarmup = 0\nrounds = 4\ncalibration = "{cal}"\n'
                    '[sweep]\nvariable = "band"\nvalues = [0.05, 0.15]\n')
    out = base / "run"
    lodbench("experiment", str(spec), "--out", str(out))
    r = plot(out)
    assert r.returncode == 0, r.stderr
    return out


def unit_lines(text: str):
    """The pops section's lines of what the pops are measured in: [(text, simulated)], the markup removed."""
    return [(html.unescape(re.sub(r"<[^>]+>", "", body)), bool(sim))
            for sim, body in re.findall(r'<p class="unit( simulated)?">(.*?)</p>', text, re.S)]


def pops_section(text: str) -> str:
    start = text.index('<section id="pops">')
    return text[start:text.index("</section>", start)]


def pops_table(page: Page):
    """The visible pops' table of report.html (its header row first)."""
    found = [t for t in page.tables if "visible_pops_per_min" in t[0] and "pop_max" not in t[0]]
    assert len(found) <= 1, found
    return found[0] if found else None


def check_layout(folder: Path):
    """The pops follow the answer (which stays as answer.json says, byte for byte) and come before the figures;
    report.md has the same tables."""
    text = (folder / "report.html").read_text()
    assert answer_section(text) == rendered(load(folder))
    assert text.index('<div id="answer">') < text.index('<section id="pops">') < text.index('<h2 id="headline">')
    assert '<a href="#pops">Visible pops</a>' in text
    page = Page(text)
    assert page.tables == markdown_tables((folder / "report.md").read_text())
    md = (folder / "report.md").read_text()
    assert md.index("## Visible pops") < md.index("## Summary: time")
    return text, page


def check_cells(folder: Path, table, summary, threshold_of):
    """The table's rows are summary.csv's, its cells the columns' values to 3 significant figures."""
    header, rows = table[0], table[1:]
    assert len(rows) == len(summary)
    for row, r in zip(rows, summary):
        cell = dict(zip(header, row))
        assert (cell["scene"], cell["method"], cell["count"]) == (r["scene"], r["method"], r["count"])
        for c in ("lodpop_max", "visible_pop_threshold", "visible_pops_per_min"):
            assert cell[c] == sig3(float(r[c])), (c, cell, r)
        assert cell["pop_events"] == r["pop_events"]
        assert float(r["visible_pop_threshold"]) == pytest.approx(threshold_of(r), rel=1e-9)
        # No more visible events than events: the path is frames / 60 seconds long (the default 60 fps).
        minutes = int(r["frames"]) / 60 / 60
        assert 0 <= float(r["visible_pops_per_min"]) * minutes <= int(r["pop_events"]) + 1e-9
    return [dict(zip(header, row)) for row in rows]


def test_a_calibrated_run_says_pops_are_in_jnds(calibrated):
    text, page = check_layout(calibrated)
    cfg = json.loads((calibrated / "run.json").read_text())["config"]
    cal = cfg["calibration"]
    assert cal["simulated"] is True and cfg["path_fps"] == 60
    want = (f"Pops in JNDs: 1 JND = lodpop 0.00200 (95 % 0.00150 to 0.00270), from {cal['path']}: {LABEL}; "
            "measured for a 160x120 display at 60 Hz. Simulated observer, not human data")
    assert unit_lines(text) == [(want, True)]
    # Styled apart: red and bold.
    assert '<p class="unit simulated">' in pops_section(text) and "#pops p.unit.simulated {" in text
    md = (calibrated / "report.md").read_text()
    assert f"\n## Visible pops\n\n{want}\n\n| scene | method | count | lodpop_max | lodpop_max_jnd |" in md
    summary = read_csv(calibrated / "summary.csv")
    table = pops_table(page)
    assert table[0] == ["scene", "method", "count", "lodpop_max", "lodpop_max_jnd", *POPS[1:]]
    cells = check_cells(calibrated, table, summary, lambda r: 0.002)
    for cell, r in zip(cells, summary):
        assert float(r["lodpop_max_jnd"]) == pytest.approx(float(r["lodpop_max"]) / 0.002, rel=1e-9)
        assert cell["lodpop_max_jnd"] == sig3(float(r["lodpop_max_jnd"]))
    assert any(float(r["visible_pops_per_min"]) > 0 for r in summary)
    assert "at 60 frames a second (run.json&#x27;s path_fps)" in pops_section(text)


def test_an_uncalibrated_run_says_pops_are_lodpop(dump, tmp_path):
    """The dump run (no --calibration): not calibrated, visible over half the hard switch's largest lodpop."""
    folder = tmp_path / "sweep"
    shutil.copytree(dump, folder)
    r = plot(folder)
    assert r.returncode == 0, r.stderr
    text, page = check_layout(folder)
    assert json.loads((folder / "run.json").read_text())["config"].get("calibration") is None
    assert unit_lines(text) == [(report_html.NOT_CALIBRATED.replace("`", ""), False)]
    assert "<code>lodbench calibrate</code> and <code>--calibration</code> give JNDs (docs/calibration.md)" in text
    md = (folder / "report.md").read_text()
    assert f"\n## Visible pops\n\n{report_html.NOT_CALIBRATED}\n\n| scene | method | count | lodpop_max |" in md
    summary = read_csv(folder / "summary.csv")
    table = pops_table(page)
    assert table[0] == ["scene", "method", "count", *POPS]  # no JNDs without a calibration
    hard = float(next(r for r in summary if r["method"] == "discrete")["lodpop_max"])
    check_cells(folder, table, summary, lambda r: hard / 2)


def strip_pop_events(folder: Path):
    """folder as a lodbench before pop events wrote it: no pop event columns, no calibration or path_fps."""
    for name in ("summary.csv", "transitions.csv"):
        path = folder / name
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
        drop = {"pop_events", "visible_pop_threshold", "visible_pops_per_min", "lodpop_max_jnd"}
        header = [c for c in rows[0] if c not in drop]
        with open(path, "w", newline="") as f:
            w = csv.DictWriter(f, header, extrasaction="ignore")
            w.writeheader()
            w.writerows(rows)
    run = json.loads((folder / "run.json").read_text())
    run["config"].pop("calibration", None)
    run["config"].pop("path_fps", None)
    (folder / "run.json").write_text(json.dumps(run))


def test_an_older_folder_says_visible_pops_were_not_measured(calibrated, tmp_path):
    folder = tmp_path / "old"
    shutil.copytree(calibrated, folder, ignore=shutil.ignore_patterns("figures", "report.*"))
    strip_pop_events(folder)
    r = plot(folder)
    assert r.returncode == 0, r.stderr
    text, page = check_layout(folder)
    assert unit_lines(text) == [(report_html.NOT_CALIBRATED.replace("`", ""), False)]
    assert pops_table(page) is None
    assert "Visible pops per minute: not measured (this summary.csv has no visible_pops_per_min" in text
    assert "visible_pop" not in " ".join(c for t in page.tables for c in t[0])


def test_an_experiment_says_its_runs_calibration_once(calibrated_experiment):
    text, page = check_layout(calibrated_experiment)
    runs = sorted((calibrated_experiment / "runs").glob("*/run.json"))
    assert len(runs) == 2
    lines = unit_lines(text)
    assert len(lines) == 1 and lines[0][1] and lines[0][0].startswith("Pops in JNDs: 1 JND = lodpop 0.00200 (95 % "
                                                                       "0.00150 to 0.00270), from ")
    summary = read_csv(calibrated_experiment / "summary.csv")
    table = pops_table(page)
    assert table[0] == ["band", "scene", "method", "count", "lodpop_max", "lodpop_max_jnd", *POPS[1:]]
    assert [row[:3] for row in table[1:]] == [[r["band"], r["scene"], r["method"]] for r in summary]
    check_cells(calibrated_experiment, [table[0][1:]] + [row[1:] for row in table[1:]], summary, lambda r: 0.002)


def test_runs_that_differ_get_a_line_each():
    """An experiment or merged folder whose runs were calibrated differently (or some not): a line per
    calibration naming its runs; a person's calibration says nothing of simulation; the text is escaped."""
    human = {"path": "cal/human.json", "metric": "lodpop", "threshold": 0.00812, "ci95": [0.0062, 0.0101],
             "simulated": False, "label": "2 observers, 480 trials <b>", "display": {"width_px": 1920,
                                                                                   "height_px": 1080,
                                                                                   "refresh_hz": 60.0}}
    runs = [("runs/a", {"config": {"calibration": human}}), ("runs/b", {"config": {"calibration": None}}),
            ("runs/c", {"config": {"calibration": human}}), ("runs/d", {"config": {}})]
    lines = report_html.calibration_lines({"runs": runs})
    assert lines == [
        ("runs/a, runs/c: Pops in JNDs: 1 JND = lodpop 0.00812 (95 % 0.00620 to 0.0101), from cal/human.json: "
         "2 observers, 480 trials <b>; measured for a 1920x1080 display at 60 Hz", False),
        (f"runs/b, runs/d: {report_html.NOT_CALIBRATED}", False)]
    same = report_html.calibration_lines({"runs": runs[:1] + runs[2:3]})
    assert same == [(lines[0][0].removeprefix("runs/a, runs/c: "), False)]
    assert report_html.calibration_lines({"runs": []}) == [(report_html.NOT_CALIBRATED, False)]
    section = report_html.pops_html(lines, [], None, "note")
    assert "trials &lt;b&gt;" in section and "<b>" not in section
    assert '<p class="unit simulated">' not in section


def test_the_plot_table_leaves_unmeasured_cells_empty(calibrated):
    """A row without a threshold (no hard switch, no budget) or without a lodpop: its cells empty, the row kept."""
    import plot as plot_module

    summary = read_csv(calibrated / "summary.csv")
    summary[1] = {**summary[1], "visible_pop_threshold": "", "visible_pops_per_min": ""}
    header = list(summary[0])
    runs = {"runs": [("calibrated", json.loads((calibrated / "run.json").read_text()))]}
    pops = plot_module.visible_pops(summary, header, ["scene", "method", "count"], runs)
    cells = plot_module.table_cells(pops["rows"], pops["columns"], ["scene", "method", "count"])
    row = dict(zip(pops["columns"], cells[1]))
    assert row["visible_pop_threshold"] == "" and row["visible_pops_per_min"] == ""
    assert row["lodpop_max"] == sig3(float(summary[1]["lodpop_max"]))
    # No lodpop anywhere (--quality off): not measured, no table.
    off = [{**r, "lodpop_max": "", "pop_events": "", "visible_pops_per_min": "", "lodpop_max_jnd": ""}
           for r in summary]
    pops = plot_module.visible_pops(off, header, ["scene", "method", "count"], runs)
    assert pops["rows"] is None and "not measured (no transition has a lodpop" in pops["note"]
