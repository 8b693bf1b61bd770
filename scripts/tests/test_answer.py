"""The answer first: a folder's answer.json (the sentences and decision table, written by the binary,
src/results/answer/) against the CSVs its numbers quote, against report.html (scripts/plot.py writes the page's
answer from it, word for word), and against the sentences `lodbench run` and `lodbench answer` print: the terminal,
answer.json and report.html must say the same."""
import csv
import json
import os
import shutil
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

import pytest

from conftest import ROOT, lodbench_binary

sys.path.insert(0, str(ROOT / "scripts"))
import report_html  # noqa: E402
from lodbench_results import (  # noqa: E402
    ANSWER_JSON,
    PERCEPTUAL_CSV,
    RUN_JSON,
    RUNS_DIR,
    part_text,
    ratio_text,
    run_folder_of,
    sentence_text,
    sig3,
    thousands,
)

SCRIPT = ROOT / "scripts" / "plot.py"
# Committed folders whose answer.json is checked number by number: a glTF scene, bunny-sweep, an experiment.
COMMITTED = ["report-fox-quick", "report-bunny-sweep-quick", "frontier-ci"]
# The decision table's columns (answer.json's "columns").
COLUMNS = ["method", "frame time, ms", "time / baseline [95 %]", "on transition frames", "triangles",
           "largest lodpop", "its coverage part", "its shading part", "lowest JOD", "mean rmse"]


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def load(folder: Path) -> dict:
    return json.loads((folder / ANSWER_JSON).read_text())


def results_folders():
    """Every folder of results/ that lodbench wrote a summary.csv into (runs, experiments, merged folders, an
    experiment's runs), but the regression baseline (results/baseline/, blessed by `cargo test`)."""
    return sorted(p.parent for p in (ROOT / "results").rglob("summary.csv")
                  if (ROOT / "results" / "baseline") not in p.parents)


def numbers(answer):
    """(block, part) of every number (an object part) of answer.json's sentences and rows."""
    for block in answer["blocks"]:
        for parts in block["sentences"] + block["rows"]:
            for p in parts:
                if not isinstance(p, str):
                    yield block, p


def test_numbers_by_unit():
    # The same cases as src/numbers.rs's numbers_by_unit: the report's other tables read as the answer does.
    assert sig3(1.5203795) == "1.52"
    assert sig3(15.2049) == "15.2"
    assert sig3(152.49) == "152"
    assert sig3(1523.4) == "1523"
    assert sig3(0.0028712) == "0.00287"
    assert sig3(0.0) == "0"
    assert sig3(float("nan")) == "-"
    assert sig3(None) == "-"
    assert thousands(3674.0) == "3,674"
    assert thousands(557500.4) == "557,500"
    assert thousands(999.6) == "1,000"
    assert thousands(12.0) == "12"
    assert thousands(float("inf")) == "-"
    assert ratio_text(1.2345, 1.1, 1.37) == "1.23 [1.10, 1.37]"
    assert ratio_text(0.5) == "0.50"
    assert ratio_text(float("nan"), 1.0, 1.0) == "-"


def as_shown(part, folder: Path, run: Path = None) -> str:
    """A number part's text as it should read, from the cells it names (`file` of `folder`, `row`'s cells, `cols`),
    `op` (half; inv: the ratio read the other way round) and `fmt`; run.json's budget from `run` (the block's run
    folder, the folder itself by default). The check of test_report_browser too."""
    if part["file"] == RUN_JSON:
        return sig3(json.loads(((run or folder) / RUN_JSON).read_text())["config"]["budget_lodpop"])
    rows = [r for r in read_csv(folder / part["file"]) if all(r.get(k) == v for k, v in part["row"].items())]
    assert len(rows) == 1, (part, len(rows))
    vals = [float(rows[0][c]) if rows[0][c] != "" else float("nan") for c in part["cols"]]
    if part["op"] == "half":
        vals = [v / 2 for v in vals]
    if part["op"] == "inv":
        vals = [1 / vals[0], 1 / vals[2], 1 / vals[1]]
    if part["fmt"] == "ratio":
        return ratio_text(*vals) if len(vals) == 3 else ratio_text(vals[0])
    return thousands(vals[0]) if part["fmt"] == "thousands" else sig3(vals[0])


def expected(span, folder: Path) -> str:
    """A number span of report.html (its data- attributes) as it should read, from the CSV cells it names."""
    return as_shown({"file": span["data-file"], "row": json.loads(span["data-row"]),
                     "cols": span["data-cols"].split(","), "fmt": span["data-fmt"], "op": span["data-op"]}, folder)


class Spans(HTMLParser):
    """report.html's sentences (their text) and every number span (its attributes and text)."""

    def __init__(self):
        super().__init__()
        self.sentences, self.spans = [], []
        self.in_sentence = self.in_span = False

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "p" and a.get("class") == "sentence":
            self.in_sentence = True
            self.sentences.append("")
        if tag == "span" and a.get("class") == "v":
            self.in_span = True
            self.spans.append({**a, "text": "", "in_sentence": self.in_sentence})

    def handle_endtag(self, tag):
        if tag == "p":
            self.in_sentence = False
        if tag == "span":
            self.in_span = False

    def handle_data(self, data):
        if self.in_sentence:
            self.sentences[-1] += data
        if self.in_span:
            self.spans[-1]["text"] += data


def check_numbers(folder: Path) -> Spans:
    """Every number span of folder's report.html reads as the cells it names; returns the parsed page."""
    page = Spans()
    page.feed((folder / "report.html").read_text())
    assert page.sentences, "no sentences in report.html"
    assert page.spans, "no numbers in report.html's answer"
    for span in page.spans:
        assert span["text"] == expected(span, folder), span
    return page


def answer_section(page: str) -> str:
    """The answer's blocks of a report.html, as written: from its first section.answer to the note after the last."""
    start = page.index('<div id="answer">') + len('<div id="answer">')
    return page[start:page.index('<p class="note">', start)]


def rendered(answer) -> str:
    """answer.json's blocks as report.html writes them (a line each)."""
    return "\n" + "".join(report_html.answer_html({"name": b["name"], "sentences": b["sentences"],
                                                   "columns": answer["columns"], "rows": b["rows"]}) + "\n"
                          for b in answer["blocks"])


def answers_of(stdout: str, scene: str):
    """The sentences a lodbench command printed: the lines that open with the scene's name or a budget's words."""
    return [line for line in stdout.splitlines() if line.startswith((f"{scene}: ", "Within ", "No method "))]


# ---- The committed folders' answer.json ----

def test_every_results_folder_has_its_answer():
    """Every committed folder with a summary.csv carries the answer.json today's binary writes into it."""
    folders = results_folders()
    assert folders
    missing = [str(f.relative_to(ROOT)) for f in folders if not (f / ANSWER_JSON).is_file()]
    assert not missing, f"no {ANSWER_JSON} (`lodbench answer FOLDER` makes it): {missing}"


@pytest.mark.parametrize("name", COMMITTED)
def test_committed_numbers_are_the_csvs(name):
    """Every number of the answer reads as the cells it names, formatted by its fmt after its op."""
    folder = ROOT / "results" / "cpu" / name
    answer = load(folder)
    assert answer["schema"] == "lodbench-answer/1"
    assert answer["columns"] == COLUMNS
    seen = 0
    for block, part in numbers(answer):
        assert set(part) == {"text", "file", "row", "cols", "fmt", "op"}, part
        assert part["fmt"] in ("sig3", "thousands", "ratio") and part["op"] in ("", "half", "inv"), part
        run = run_folder_of(folder, answer["variables"], block["values"])
        assert part["text"] == as_shown(part, folder, run), (block["name"], part)
        seen += 1
    assert seen >= 10 * len(answer["blocks"]), seen
    # In a sentence too, and where the budget is the default one, its halved figure.
    assert any(not isinstance(p, str) for b in answer["blocks"] for s in b["sentences"] for p in s)


@pytest.mark.parametrize("name", COMMITTED)
def test_committed_blocks_are_the_summary_s(name):
    """A block per run (swept values), scene and count of summary.csv, in its order, with a row per summary row
    (the method first); its budget is the run's --budget-lodpop or half its hard switch's largest lodpop."""
    folder = ROOT / "results" / "cpu" / name
    answer = load(folder)
    summary = read_csv(folder / "summary.csv")
    variables = answer["variables"]
    header = list(summary[0])
    assert variables == [c for c in header[:header.index("scene")] if c != "adapter"]
    keys = {}
    for r in summary:
        keys.setdefault((tuple(r[v] for v in variables), r["scene"], r["count"]), []).append(r["method"])
    assert [(tuple(b["values"]), b["scene"], b["count"]) for b in answer["blocks"]] == list(keys)
    for b in answer["blocks"]:
        methods = keys[(tuple(b["values"]), b["scene"], b["count"])]
        assert [row[0] for row in b["rows"]] == methods
        assert all(len(row) == len(COLUMNS) for row in b["rows"])
        assert b["name"].startswith(b["scene"]) and b["sentences"]
        budget = b["budget"]
        if budget is not None and budget["source"] != "--budget-lodpop":
            assert budget["source"] == f"half of {b['hard_switch']}'s", b
            hard = next(r for r in summary if (r["scene"], r["count"], r["method"]) == (b["scene"], b["count"],
                                                                                     b["hard_switch"])
                        and tuple(r[v] for v in variables) == tuple(b["values"]))
            assert budget["lodpop"] == pytest.approx(float(hard["lodpop_max"]) / 2, rel=1e-12)


@pytest.mark.parametrize("name", COMMITTED)
def test_committed_report_says_what_answer_json_says(name):
    """A committed report.html's answer is its answer.json's, byte for byte: the sentences, the numbers' data-
    attributes, the decision tables (the sentences as they read, and the whole section as written). (Not every
    committed report.html: some were made before the answer led the page, or before their folder's pairs.csv.)"""
    folder = ROOT / "results" / "cpu" / name
    answer = load(folder)
    page = (folder / "report.html").read_text()
    parsed = Spans()
    parsed.feed(page)
    assert parsed.sentences == [sentence_text(s) for b in answer["blocks"] for s in b["sentences"]]
    assert answer_section(page) == rendered(answer)


# ---- What the binary writes and prints ----

@pytest.fixture(scope="module")
def answered(tmp_path_factory):
    """A small bunny-sweep run whose stdout is kept: reference, discrete, alpha and dither, 240 frames at 160x120,
    with an explicit budget, plotted."""
    out = tmp_path_factory.mktemp("answer") / "run"
    r = subprocess.run([str(lodbench_binary()), "run", "--scene", "bunny-sweep", "--method",
                        "reference,discrete,alpha,dither", "--width", "160", "--height", "120", "--frames", "240",
                        "--warmup", "2", "--budget-lodpop", "0.003", "--out", str(out)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert (out / ANSWER_JSON).is_file(), "lodbench run wrote no answer.json"
    p = subprocess.run([sys.executable, str(SCRIPT), str(out)], capture_output=True, text=True,
                       env=dict(os.environ, LODBENCH=str(lodbench_binary())))
    assert p.returncode == 0, p.stderr
    return out, r.stdout


def test_report_numbers_are_the_csvs(answered):
    folder, _ = answered
    page = check_numbers(folder)
    assert any(s["in_sentence"] for s in page.spans)
    # The budget given: its number is run.json's.
    assert any(s["data-file"] == RUN_JSON for s in page.spans)
    for _, part in numbers(load(folder)):
        assert part["text"] == as_shown(part, folder), part


def test_report_says_what_the_terminal_says(answered):
    folder, stdout = answered
    page = check_numbers(folder)
    printed = answers_of(stdout, "bunny-sweep")
    assert printed, stdout
    assert page.sentences == printed
    answer = load(folder)
    assert [sentence_text(s) for b in answer["blocks"] for s in b["sentences"]] == printed
    assert answer_section((folder / "report.html").read_text()) == rendered(answer)


def test_lodbench_answer_remakes_what_run_wrote(answered, tmp_path):
    """`lodbench answer DIR` on a copy of the run's folder, its answer.json gone: the same answer.json, and the
    same sentences printed as `lodbench run` printed."""
    folder, stdout = answered
    copy = tmp_path / "copy"
    shutil.copytree(folder, copy)
    (copy / ANSWER_JSON).unlink()
    r = subprocess.run([str(lodbench_binary()), "answer", str(copy)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert (copy / ANSWER_JSON).read_bytes() == (folder / ANSWER_JSON).read_bytes()
    assert answers_of(r.stdout, "bunny-sweep") == answers_of(stdout, "bunny-sweep")


@pytest.mark.parametrize("name", COMMITTED)
def test_lodbench_answer_remakes_the_committed_answer(name, tmp_path):
    """Today's binary makes a committed folder's answer.json again, all but the build that made it; and prints its
    sentences."""
    folder = ROOT / "results" / "cpu" / name
    copy = tmp_path / name
    shutil.copytree(folder, copy, ignore=shutil.ignore_patterns("figures", "frames", "clips"))
    (copy / ANSWER_JSON).unlink()
    r = subprocess.run([str(lodbench_binary()), "answer", str(copy)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    made, committed = load(copy), load(folder)
    made.pop("build")
    committed.pop("build")
    assert made == committed
    said = [sentence_text(s) for b in committed["blocks"] for s in b["sentences"]]
    assert said and all(s in r.stdout for s in said), r.stdout


def test_a_wrong_number_is_caught(answered, tmp_path):
    """The check can fail: one cell of summary.csv changed after the report was written."""
    folder, _ = answered
    copy = tmp_path / "copy"
    shutil.copytree(folder, copy)
    rows = read_csv(copy / "summary.csv")
    target = next(r for r in rows if r["method"] == "discrete")
    target["lodpop_max"] = str(float(target["lodpop_max"]) * 1.5)
    with open(copy / "summary.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    with pytest.raises(AssertionError):
        check_numbers(copy)
    with pytest.raises(AssertionError):
        for _, part in numbers(load(copy)):
            assert part["text"] == as_shown(part, copy), part


# ---- plot.py reads the answer from answer.json ----

def frames_for(folder: Path):
    """A frames.csv for a committed folder (which keeps none): two frames per summary row, enough for plot.py."""
    rows = read_csv(folder / "summary.csv")
    lead = list(rows[0])[:list(rows[0]).index("scene")]
    cols = lead + ["scene", "method", "count", "frame", "round", "gpu_ms", "cpu_ms", "t_instances", "lod_mean",
                   "rmse", "pop", "lodpop", "lag_rmse"]
    with open(folder / "frames.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=cols)
        w.writeheader()
        for r in rows:
            for frame in range(2):
                w.writerow({**{c: r[c] for c in lead}, "scene": r["scene"], "method": r["method"],
                            "count": r["count"], "frame": frame, "round": 0, "gpu_ms": 1, "cpu_ms": 1,
                            "t_instances": frame, "lod_mean": frame, "rmse": 0.01, "pop": 0.01 * frame,
                            "lodpop": 0.01 * frame, "lag_rmse": ""})


def fox_copy(tmp_path: Path) -> Path:
    """report-fox-quick without its answer.json and figures, with a frames.csv plot.py can read."""
    folder = tmp_path / "fox"
    shutil.copytree(ROOT / "results" / "cpu" / "report-fox-quick", folder,
                    ignore=shutil.ignore_patterns("figures", ANSWER_JSON, "report.*"))
    frames_for(folder)
    return folder


def hand_written(folder: Path) -> dict:
    """An answer.json of one block whose words are not lodbench's, with a number naming a summary.csv cell."""
    r = read_csv(folder / "summary.csv")[0]
    value = {"text": "0.123", "file": "summary.csv", "row": {"scene": r["scene"], "method": r["method"],
                                                            "count": r["count"]},
             "cols": ["lodpop_max"], "fmt": "sig3", "op": ""}
    answer = {"schema": "lodbench-answer/1", "build": {"lodbench_version": "0.0.0", "git_commit": None,
                                                       "source_diff_hash": None},
              "variables": [], "columns": COLUMNS,
              "blocks": [{"name": "hand block", "values": [], "scene": r["scene"], "count": r["count"],
                          "hard_switch": "discrete", "budget": {"lodpop": 0.5, "source": "half of discrete's"},
                          "sentences": [["Hand-written <sentence> of ", value, "."]],
                          "rows": [[r["method"], value, "-", "-", "-", "-", "0.1", "0.2", "-", "-"]]}]}
    (folder / ANSWER_JSON).write_text(json.dumps(answer))
    return answer


def plot(folder: Path, **env) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(SCRIPT), str(folder)], capture_output=True, text=True,
                          env=dict(os.environ, **env))


def test_plot_writes_the_answer_json_says(tmp_path):
    """plot.py computes no answer: report.md and report.html say what answer.json says, whatever it says."""
    folder = fox_copy(tmp_path)
    answer = hand_written(folder)
    r = plot(folder)
    assert r.returncode == 0, r.stderr
    assert "answer.json" not in r.stdout  # nothing to remake
    page = (folder / "report.html").read_text()
    assert answer_section(page) == rendered(answer)
    assert ('Hand-written &lt;sentence&gt; of <span class="v" data-file="summary.csv" data-row="{&quot;scene&quot;: '
            '&quot;Fox.glb&quot;, &quot;method&quot;: ') in page
    md = (folder / "report.md").read_text()
    assert "\n## hand block\n\nHand-written <sentence> of 0.123.\n" in md
    assert "\n| " + " | ".join(COLUMNS) + " |\n|---|" in md
    row = answer["blocks"][0]["rows"][0]
    assert " | ".join(part_text(c) for c in row) == f"{row[0]} | 0.123 | - | - | - | - | 0.1 | 0.2 | - | -"
    assert "\n| " + " | ".join(part_text(c) for c in row) + " |\n" in md


def test_plot_without_a_binary_says_how_to_make_the_answer(tmp_path):
    """No answer.json and no binary to make it: plot.py stops before writing anything, naming the command."""
    folder = fox_copy(tmp_path)
    env = {k: v for k, v in os.environ.items() if k not in ("LODBENCH", "LODBENCH_BIN")}
    env.update(CARGO_TARGET_DIR=str(tmp_path / "no-target"), PATH=str(Path(sys.executable).parent))
    assert shutil.which("lodbench", path=env["PATH"]) is None
    r = subprocess.run([sys.executable, str(SCRIPT), str(folder)], capture_output=True, text=True, env=env)
    assert r.returncode != 0
    assert f"`lodbench answer {folder}`" in r.stderr and "no answer.json" in r.stderr, r.stderr
    assert not (folder / "report.html").exists() and not (folder / "figures").exists()


def test_a_stale_answer_is_seen(tmp_path):
    """plot.answer_stale: no answer.json, or a perceptual.csv (the folder's, a run's) newer than it."""
    import plot as plot_module

    folder = tmp_path / "exp"
    (folder / RUNS_DIR / "band=0.1").mkdir(parents=True)
    assert "no answer.json" in plot_module.answer_stale(folder)
    (folder / ANSWER_JSON).write_text("{}")
    os.utime(folder / ANSWER_JSON, (1_000_000, 1_000_000))
    assert plot_module.answer_stale(folder) is None
    run_csv = folder / RUNS_DIR / "band=0.1" / PERCEPTUAL_CSV
    run_csv.write_text("scene,method,count,jod_popping\n")
    assert "band=0.1/perceptual.csv is newer" in plot_module.answer_stale(folder)
    os.utime(run_csv, (999_999, 999_999))
    assert plot_module.answer_stale(folder) is None
    (folder / PERCEPTUAL_CSV).write_text("scene,method,count,jod_popping\n")
    assert "perceptual.csv is newer" in plot_module.answer_stale(folder)


def test_plot_makes_a_missing_answer(tmp_path):
    """A folder made before the binary wrote answer.json: plot.py says so in a line, makes it with `lodbench answer`
    (the committed one, but its build), and leads report.html with it."""
    folder = fox_copy(tmp_path)
    r = plot(folder, LODBENCH=str(lodbench_binary()))
    assert r.returncode == 0, r.stderr
    line = [s for s in r.stdout.splitlines() if "answer.json" in s]
    assert len(line) == 1 and f"`lodbench answer {folder}`" in line[0], r.stdout
    made, committed = load(folder), load(ROOT / "results" / "cpu" / "report-fox-quick")
    made.pop("build")
    committed.pop("build")
    assert made == committed
    assert answer_section((folder / "report.html").read_text()) == \
        answer_section((ROOT / "results" / "cpu" / "report-fox-quick" / "report.html").read_text())


def test_an_answer_older_than_perceptual_is_remade(tmp_path, monkeypatch):
    """An experiment whose runs' perceptual.csv is newer than its answer.json (`lodbench perceptual` of a binary
    that did not rewrite it): plot.answer_of remakes it, the lowest JOD column included."""
    import plot as plot_module

    name = "frontier-perceptual-ci"
    folder = tmp_path / name
    shutil.copytree(ROOT / "results" / "cpu" / name, folder, ignore=shutil.ignore_patterns("figures", "report.*"))
    hand_written(folder)
    os.utime(folder / ANSWER_JSON, (1_000_000, 1_000_000))
    monkeypatch.setenv("LODBENCH", str(lodbench_binary()))
    made = plot_module.answer_of(folder)
    committed = load(ROOT / "results" / "cpu" / name)
    made.pop("build")
    committed.pop("build")
    assert made == committed
    jods = [row[COLUMNS.index("lowest JOD")] for b in made["blocks"] for row in b["rows"]]
    assert any(j != "-" for j in jods), jods


def test_the_decision_figure_draws_the_answer_s_budget(monkeypatch, tmp_path):
    """decision_figure's budget line is answer.json's block budget (its level and source), none without one."""
    import plot as plot_module

    drawn = []
    monkeypatch.setattr(plot_module, "save", lambda fig, path: drawn.append(fig))
    rows = [{"method": m, "baseline": "discrete", "ratio_to_baseline": str(x), "ratio_to_baseline_ci95_lo": str(x),
             "ratio_to_baseline_ci95_hi": str(x), "lodpop_max": str(y)}
            for m, x, y in (("discrete", 1.0, 0.004), ("alpha", 1.3, 0.0015))]
    block = {"budget": {"lodpop": 0.002, "source": "half of discrete's"}, "hard_switch": "discrete"}
    plot_module.decision_figure("s", rows, block, tmp_path / "a.png")
    plot_module.decision_figure("s", rows, dict(block, budget=None), tmp_path / "b.png")
    plot_module.decision_figure("s", rows, None, tmp_path / "c.png")
    labels = [[t.get_text() for t in fig.axes[0].get_legend().get_texts()] for fig in drawn]
    assert "budget 0.00200 (half of discrete's)" in labels[0], labels
    assert [line.get_ydata()[0] for line in drawn[0].axes[0].get_lines() if line.get_linestyle() == "--"] == [0.002]
    assert not any(s.startswith("budget") for s in labels[1] + labels[2]), labels
