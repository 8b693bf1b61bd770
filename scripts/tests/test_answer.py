"""The answer first: scripts/answer.py's sentences and decision table against the CSVs they quote, and against the
sentences `lodbench run` prints (src/results/answer.rs): the terminal and report.html must say the same."""
import csv
import json
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

import pytest

from conftest import lodbench_binary

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import answer  # noqa: E402

SCRIPT = Path(__file__).resolve().parents[1] / "plot.py"


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_numbers_by_unit():
    # The same cases as src/results/answer.rs's numbers_by_unit.
    assert answer.sig3(1.5203795) == "1.52"
    assert answer.sig3(15.2049) == "15.2"
    assert answer.sig3(152.49) == "152"
    assert answer.sig3(1523.4) == "1523"
    assert answer.sig3(0.0028712) == "0.00287"
    assert answer.sig3(0.0) == "0"
    assert answer.sig3(float("nan")) == "-"
    assert answer.thousands(3674.0) == "3,674"
    assert answer.thousands(557500.4) == "557,500"
    assert answer.ratio_text(1.2345, 1.1, 1.37) == "1.23 [1.10, 1.37]"


def row(method, lodpop, r, lo, hi, baseline="discrete"):
    return {"scene": "s", "method": method, "count": "1", "lodpop_max": str(lodpop), "baseline": baseline,
            "ratio_to_baseline": str(r), "ratio_to_baseline_ci95_lo": str(lo), "ratio_to_baseline_ci95_hi": str(hi)}


def test_sentences_match_the_rust_unit_case():
    """The case of answer.rs's least_popping_and_cheapest_within_the_default_budget, word for word."""
    rows = [row("reference", 0.0, 2.0, 1.8, 2.2), row("discrete", 0.004, 1.0, 1.0, 1.0),
            row("alpha", 0.0015, 1.3, 1.2, 1.4), row("dither", 0.0018, 1.1, 1.05, 1.15),
            row("geomorph", 0.003, 1.01, 0.98, 1.04)]
    pairs = [{"scene": "s", "count": "1", "method_a": "alpha", "method_b": "dither", "ratio": "1.18",
              "ratio_ci95_lo": "1.1", "ratio_ci95_hi": "1.27"}]
    (_, _, _, said), = answer.answers(rows, pairs, None)
    assert [answer.text(s) for s in said] == [
        "s: alpha pops least, a largest lodpop of 0.00150 against discrete's 0.00400; it takes 1.30 [1.20, 1.40] "
        "times discrete's frame time.",
        "Within a largest lodpop of 0.00200 (half of discrete's), dither is the cheapest: it takes 1.10 [1.05, "
        "1.15] times discrete's frame time. dither ran 1.18 [1.10, 1.27] times faster than alpha, the next within "
        "it."]


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


def expected(span, folder: Path) -> str:
    """A number span's text as it should read, from the CSV cells it names: the check of test_report_browser too."""
    key = json.loads(span["data-row"])
    cols = span["data-cols"].split(",")
    if span["data-file"] == "run.json":
        return answer.sig3(json.loads((folder / "run.json").read_text())["config"]["budget_lodpop"])
    rows = [r for r in read_csv(folder / span["data-file"]) if all(r.get(k) == v for k, v in key.items())]
    assert len(rows) == 1, (span, len(rows))
    vals = [float(rows[0][c]) if rows[0][c] != "" else float("nan") for c in cols]
    op, fmt = span["data-op"], span["data-fmt"]
    if op == "half":
        vals = [v / 2 for v in vals]
    if op == "inv":
        vals = [1 / vals[0], 1 / vals[2], 1 / vals[1]]
    if fmt == "ratio":
        return answer.ratio_text(*vals) if len(vals) == 3 else answer.ratio_text(vals[0])
    return answer.thousands(vals[0]) if fmt == "thousands" else answer.sig3(vals[0])


def check_numbers(folder: Path) -> Spans:
    """Every number span of folder's report.html reads as the cells it names; returns the parsed page."""
    page = Spans()
    page.feed((folder / "report.html").read_text())
    assert page.sentences, "no sentences in report.html"
    assert page.spans, "no numbers in report.html's answer"
    for span in page.spans:
        assert span["text"] == expected(span, folder), span
    return page


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
    p = subprocess.run([sys.executable, str(SCRIPT), str(out)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    return out, r.stdout


def test_report_numbers_are_the_csvs(answered):
    folder, _ = answered
    page = check_numbers(folder)
    assert any(s["in_sentence"] for s in page.spans)


def test_report_says_what_the_terminal_says(answered):
    folder, stdout = answered
    page = check_numbers(folder)
    printed = [line for line in stdout.splitlines() if line.startswith(("bunny-sweep: ", "Within ", "No method "))]
    assert printed, stdout
    assert page.sentences == printed


def test_a_wrong_number_is_caught(answered, tmp_path):
    """The check can fail: one cell of summary.csv changed after the report was written."""
    folder, _ = answered
    copy = tmp_path / "copy"
    import shutil
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


def test_a_lone_method_is_not_said_to_pop_least():
    """The case of answer.rs's a_lone_method_is_not_said_to_pop_least, word for word."""
    rows = [row("reference", 0.0, 2.0, 1.8, 2.2), row("discrete", 0.004, 1.0, 1.0, 1.0)]
    (_, _, _, said), = answer.answers(rows, [], None)
    assert [answer.text(s) for s in said] == [
        "s: discrete is the only method with LOD transitions in the run, a largest lodpop of 0.00400; it is the "
        "baseline (discrete)."]
    (_, _, _, said), = answer.answers(rows, [], 0.005)
    assert len(said) == 2


def test_a_transition_of_one_frame_names_no_method():
    """The case of answer.rs's a_transition_of_one_frame_names_no_method, word for word."""
    def rows(frames):
        return [dict(row(m, 0.004, 1.0, 1.0, 1.0), transition_frames_min=str(frames))
                for m in ("discrete", "alpha", "dither")]
    (_, _, _, said), = answer.answers(rows(1), [], None)
    assert [answer.text(s) for s in said] == [
        "s: a transition here lasts 1 frame (the camera crosses a switch's band within it), too few for a blending "
        "method to act, so this run cannot say which method pops least; give the transitions room with --fade time "
        "--fade-frames 8, or a slower path."]
    (_, _, _, said), = answer.answers(rows(answer.MIN_TRANSITION_FRAMES), [], None)
    assert "pops least" in answer.text(said[0])
    (_, _, _, said), = answer.answers(rows(1)[:1], [], None)
    assert "the only method" in answer.text(said[0])
