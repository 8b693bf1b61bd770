"""The calibration page (src/commands/calibrate/page.html) in a real browser: headless Chromium, driven over the
DevTools protocol (scripts/browser.py) by key presses and clicks as a person would, on synthetic stimuli
(test_calibration.make_stimuli) written into the page by `calibration.py page` (the substitution `lodbench calibrate`
makes). The test reads window.lodbenchCalibration.currentTrial() only to know which answer its simulated observer
gives.

  - a whole short session, answered by an observer planted on flip, downloaded and fitted by `calibration.py fit`;
  - a reload in the middle of a session loses no answer and goes on with the trial it was at;
  - a busy-wait of 100 ms planted in an animation frame during playback (from outside the page, by
    Runtime.evaluate) makes that trial invalid, and its stimulus is shown again;
  - stimuli made for another refresh rate are refused, naming both rates.

Headless Chromium's requestAnimationFrame runs at 60 Hz here (median interval 16.7 ms, the timestamps rounded to
0.1 ms; steady within 16.5..16.8 ms even with three busy processes on this machine's two cores), so the synthetic
stimuli are made for 60 Hz. Skipped without Chromium. Each browser session has a deadline (TIMEOUT_S): a hung browser
fails the test instead of hanging it."""
import json
import math
import re
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from test_calibration import PLANT, SCRIPT, make_stimuli, run

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import calibration  # noqa: E402
from browser import Browser, chromium_binary  # noqa: E402

# The long suite (conftest.py): a whole browser session per test.
pytestmark = pytest.mark.long

# A deadline against a hung browser, not a time the page must keep: under the long suite's load (pytest -n auto
# beside lodbench runs) the stutter test once took over 45 s, its real stutters repeating trials before the planted one.
TIMEOUT_S = 90
HEADLESS_HZ = 60.0
CAL = "window.lodbenchCalibration"


@pytest.fixture(scope="session")
def chromium() -> str:
    binary = chromium_binary()
    if binary is None:
        pytest.skip("no Chromium (chromium, chromium-browser or google-chrome on PATH): apt-get install chromium")
    return binary


@pytest.fixture
def browser(chromium, tmp_path):
    b = Browser(chromium, tmp_path / "profile", time.monotonic() + TIMEOUT_S)
    yield b
    b.close()


def experiment(folder: Path, **kw):
    """Synthetic stimuli and their page in `folder`: (stimuli, the page's file:// URL)."""
    path = make_stimuli(folder, **kw)
    stimuli = calibration.read_stimuli(path)
    (folder / "index.html").write_text(calibration.page(stimuli), encoding="utf-8")
    return stimuli, (folder / "index.html").resolve().as_uri()


def centre(b: Browser, element_id: str):
    return b.js(f"(r => [r.left + r.width / 2, r.top + r.height / 2])"
                f"(document.getElementById('{element_id}').getBoundingClientRect())")


def phase(b: Browser) -> str:
    return b.js(f"{CAL}.currentTrial().phase")


def begin(b: Browser, url: str, initials="TS"):
    """Opens the page, types the initials into their box and clicks Start."""
    b.open(url)
    b.until(f"{CAL}.currentTrial().phase === 'intro'", "the page's introduction")
    b.click(*centre(b, "initials"))
    b.call("Input.insertText", text=initials)
    b.click(*centre(b, "start"))


class Observer:
    """Answers as the simulated observer planted on flip: correct with P = calibration.p_correct at the shown
    stimulus's flip (seeded). Answers by the keys 1 / 2 mostly, by the arrow keys every fourth trial and by clicking
    the answer's button every fifth."""

    def __init__(self, stimuli, seed=7):
        self.flip = {s["id"]: s["flip"] for s in stimuli["stimuli"]}
        self.rng = np.random.default_rng(seed)
        self.answered = 0

    def answer(self, b: Browser, trial: dict):
        p = calibration.p_correct(math.log10(self.flip[trial["stimulus"]]), math.log10(PLANT["threshold"]),
                                  PLANT["slope"], PLANT["lapse"])
        right = self.rng.random() < p
        answer = trial["switch_interval"] if right else 3 - trial["switch_interval"]
        if self.answered % 5 == 2:
            b.click(*centre(b, f"answer{answer}"))
        elif self.answered % 4 == 3:
            b.key(*(("ArrowLeft", 37) if answer == 1 else ("ArrowRight", 39)))
        else:
            b.key(str(answer), 48 + answer)
        self.answered += 1


def next_question(b: Browser) -> dict:
    """Waits for the next question (or the end): currentTrial()."""
    b.until(f"['waiting-response', 'done', 'refused'].includes({CAL}.currentTrial().phase)", "the next question")
    return b.js(f"{CAL}.currentTrial()")


def answer_one(b: Browser, observer: Observer) -> dict:
    trial = next_question(b)
    assert trial["phase"] == "waiting-response", trial
    observer.answer(b, trial)
    b.until(f"{CAL}.state().trials.length > {trial['n']}", "the answer saved")
    return trial


def answer_until_done(b: Browser, observer: Observer):
    while True:
        trial = next_question(b)
        if trial["phase"] != "waiting-response":
            assert trial["phase"] == "done", trial
            return
        observer.answer(b, trial)
        b.until(f"{CAL}.state().trials.length > {trial['n']}", "the answer saved")


def check_canvas(b: Browser, stimuli, dpr: float):
    """The canvas holds the stimulus at one image pixel per device pixel, its corner on a whole device pixel, on a
    mid-grey screen."""
    g = b.js("""(() => { const c = document.getElementById('canvas'), r = c.getBoundingClientRect();
        return {size: [c.width, c.height], css: [r.width, r.height], at: [r.left, r.top], dpr: devicePixelRatio,
                surround: getComputedStyle(document.body).backgroundColor}; })()""")
    w, h = stimuli["stimulus"]["width_px"], stimuli["stimulus"]["height_px"]
    assert g["dpr"] == dpr and g["size"] == [w, h], g
    assert g["css"] == [pytest.approx(w / dpr), pytest.approx(h / dpr)], g
    assert all(abs(v * dpr - round(v * dpr)) < 1e-6 for v in g["at"]), g
    assert g["surround"] == "rgb(128, 128, 128)", g


def replay(stimuli, trials):
    """The stimuli and intervals the Python mirror of the procedure shows for the page's outcomes."""
    state = calibration.procedure_start(stimuli)
    shown = []
    for t in trials:
        shown.append((state["trial"]["stimulus"], state["trial"]["switch_interval"]))
        state = calibration.procedure_next(stimuli, state, {"valid": t["valid"], "correct": t["correct"]})
    assert state["trial"] is None
    return shown


def check_trials(stimuli, r):
    period = 1000 / stimuli["display"]["refresh_hz"]
    frames = stimuli["stimulus"]["frames_per_interval"]
    for t in r["trials"]:
        assert len(t["frame_intervals_ms"]) == 2 * frames, t
        if t["valid"]:
            assert t["correct"] == (t["response"] == t["switch_interval"]) and t["rt_ms"] > 0, t
            assert all(0.5 * period <= d <= 1.5 * period for d in t["frame_intervals_ms"]), t
    assert [(t["stimulus"], t["switch_interval"]) for t in r["trials"]] == replay(stimuli, r["trials"])


def test_a_session_is_answered_downloaded_and_fitted(browser, tmp_path):
    """3 tracks x 5 trials on 5-step ladders, answered through keys, arrows and clicks, downloaded with the page's
    button and fitted. Loose check of the fit (15 trials cannot pin a threshold; the 20-seed study of
    test_calibration.py checks its accuracy): it succeeds, every metric has a finite threshold inside the fit's
    bounds with an ordered interval, and the figures are written."""
    stimuli, url = experiment(tmp_path / "exp", assets=1, steps=5, trials_per_track=5)
    b = browser
    downloads = tmp_path / "downloads"
    downloads.mkdir()
    b.call("Browser.setDownloadBehavior", session=False, behavior="allow", downloadPath=str(downloads))
    t0 = time.monotonic()
    begin(b, url)
    next_question(b)
    check_canvas(b, stimuli, 1)
    answer_until_done(b, Observer(stimuli))
    session_s = time.monotonic() - t0
    r = b.js(f"{CAL}.responses()")
    assert "finished" in b.js("document.getElementById('message').textContent")
    b.click(*centre(b, "download"))
    path = downloads / "responses-TS.json"
    deadline = time.monotonic() + 10
    while not path.exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    assert path.exists(), list(downloads.iterdir())
    downloaded = json.loads(path.read_text())
    assert downloaded == r
    assert r["observer"] == "TS" and r["simulated"] is False and r["stimuli_id"] == stimuli["id"]
    assert abs(r["measured_refresh_hz"] - HEADLESS_HZ) < 0.03 * HEADLESS_HZ, r["measured_refresh_hz"]
    valid = [t for t in r["trials"] if t["valid"]]
    assert len(valid) == 15, r["trials"]
    check_trials(stimuli, r)
    assert browser.errors() == [], browser.errors()
    invalid = len(r["trials"]) - len(valid)
    print(f"\nsession: {len(r['trials'])} trials ({invalid} invalid) in {session_s:.1f} s")

    out = tmp_path / "fit"
    p = run("fit", str(tmp_path / "exp" / "stimuli.json"), str(path), "--out", str(out), "--bootstrap", "50")
    assert p.returncode == 0, p.stderr
    cal = json.loads((out / "calibration.json").read_text())
    assert cal["simulated"] is False and cal["label"] == "1 observer, 15 trials" and cal["trials"] == 15
    assert set(cal["metrics"]) == set(stimuli["metrics"]) and cal["best_metric"] in cal["metrics"]
    for m, f in cal["metrics"].items():
        values = calibration.intensity(m, [s[m] for s in stimuli["stimuli"]])
        lo, hi = to_intensity_range(m, f["ci95"])
        assert lo <= hi, (m, f)
        thr = float(calibration.intensity(m, f["threshold"]))
        assert math.isfinite(thr) and values.min() / 10**1.5 <= thr <= values.max() * 10**1.5, (m, f)
        assert (out / f"fit-{m}.png").stat().st_size > 1000
    print(p.stdout)


def to_intensity_range(metric, ci):
    a, b = (float(calibration.intensity(metric, v)) for v in ci)
    return min(a, b), max(a, b)


def test_a_reload_loses_nothing(browser, tmp_path):
    """2 tracks x 4 trials: after 3 answers, the page is reloaded while the 4th trial waits for its answer; it says
    it resumes, holds the 3 answers, shows the same 4th trial again and finishes. On a device pixel ratio of 2 (the
    canvas is then half the stimulus's size in CSS pixels)."""
    stimuli, url = experiment(tmp_path / "exp", assets=1, methods=("discrete", "alpha"), steps=4, trials_per_track=4)
    b = browser
    b.call("Emulation.setDeviceMetricsOverride", width=1280, height=900, deviceScaleFactor=2, mobile=False)
    begin(b, url)
    observer = Observer(stimuli, seed=3)
    for _ in range(3):
        answer_one(b, observer)
    waiting = next_question(b)
    check_canvas(b, stimuli, 2)
    before = b.js(f"{CAL}.responses()")
    done = len(before["trials"])  # 3, and any trial that stuttered
    assert sum(t["valid"] for t in before["trials"]) == 3 and waiting["n"] == done, (before, waiting)
    b.open(url)  # reload
    b.until(f"{CAL}.currentTrial().phase === 'intro'", "the page's introduction after the reload")
    assert f"Resuming: {done} trials done" in b.js("document.getElementById('resume').textContent")
    assert b.js(f"{CAL}.responses()") == before
    b.click(*centre(b, "start"))  # "Continue"
    b.until(f"['preloading', 'playing', 'waiting-response'].includes({CAL}.currentTrial().phase)", "the trial")
    again = b.js(f"{CAL}.currentTrial()")
    assert (again["n"], again["stimulus"], again["switch_interval"]) == (
        waiting["n"], waiting["stimulus"], waiting["switch_interval"]), (waiting, again)
    answer_until_done(b, observer)
    after = b.js(f"{CAL}.responses()")
    assert after["trials"][:done] == before["trials"] and after["started"] == before["started"]
    assert sum(t["valid"] for t in after["trials"]) == 8
    check_trials(stimuli, after)
    assert b.errors() == [], b.errors()


# Planted from outside the page: once interval 1 of a trial has drawn its third frame, one animation-frame
# callback busy-waits 100 ms (what a stalled browser or a busy machine does to playback).
STALL = """(() => {
  let done = false;
  function tick() {
    const c = window.lodbenchCalibration.currentTrial();
    if (!done && c.phase === 'playing' && c.interval === 1 && c.frame >= 2) {
      done = true;
      const t0 = performance.now();
      while (performance.now() - t0 < 100) {}
      return;
    }
    requestAnimationFrame(tick);
  }
  requestAnimationFrame(tick);
})()"""


def test_a_stutter_makes_the_trial_invalid_and_repeats_it(browser, tmp_path):
    """One track of 3 trials: a 100 ms stall planted in the first trial's playback makes it invalid (recorded, the
    observer told), the same stimulus is shown next, and it does not count: the session ends after 3 valid trials.
    (On an overloaded machine a real stutter may add invalid trials of its own: the page repeats those too, and the
    test finds the planted one by its interval of at least 90 ms.)"""
    stimuli, url = experiment(tmp_path / "exp", assets=1, methods=("dither",), steps=4, trials_per_track=3)
    b = browser
    begin(b, url)
    b.js(STALL)
    b.until(f"{CAL}.currentTrial().phase === 'invalid'", "a stuttered trial")
    told = b.js("document.getElementById('stage-message').textContent")
    assert told == "Playback stuttered, this trial will be repeated.", told
    planted = f"{CAL}.state().trials.findIndex(t => !t.valid && Math.max(...t.frame_intervals_ms) >= 90)"
    b.until(f"{planted} >= 0", "the planted stall's trial")
    i = b.js(planted)
    answer_until_done(b, Observer(stimuli))
    r = b.js(f"{CAL}.responses()")
    bad = r["trials"][i]
    assert bad["response"] is None and bad["correct"] is None and bad["rt_ms"] is None, bad
    assert re.fullmatch(r"dropped or repeated frame: interval [\d.]+ ms at frame \d of interval [12]",
                        bad["invalid_reason"]), bad
    # The same stimulus next (one track: the staircase did not move) ...
    assert r["trials"][i + 1]["stimulus"] == bad["stimulus"], r["trials"]
    # ... and the stuttered trial did not count: 3 valid trials besides it.
    assert sum(t["valid"] for t in r["trials"]) == 3 and len(r["trials"]) >= 4, r["trials"]
    check_trials(stimuli, r)
    assert b.errors() == [], b.errors()
    print(f"\nplanted stall: trial {i}: {bad['invalid_reason']}; {len(r['trials'])} trials")


@pytest.mark.parametrize("made_for", [144.0, 30.0])
def test_another_refresh_rate_is_refused(browser, tmp_path, made_for):
    _, url = experiment(tmp_path / "exp", assets=1, methods=("discrete",), steps=3, trials_per_track=2,
                        refresh_hz=made_for)
    b = browser
    begin(b, url)
    b.until(f"{CAL}.currentTrial().phase === 'refused'", "the refusal")
    message = b.js("document.getElementById('message').textContent")
    print(f"\n{message}")
    m = re.search(r"This display refreshes at ([\d.]+) Hz; these stimuli were made for ([\d.]+) Hz: "
                  r"run `lodbench calibrate --refresh-hz (\d+) \.\.\.`", message)
    assert m, message
    assert abs(float(m.group(1)) - HEADLESS_HZ) < 2 and float(m.group(2)) == made_for and m.group(3) == "60", message
    assert b.js(f"{CAL}.responses()") is None and b.js("localStorage.length") == 0
    assert b.js("document.getElementById('stage').hidden") is True
    assert b.errors() == [], b.errors()


def test_the_template_alone_says_it_has_no_stimuli(browser, tmp_path):
    page = SCRIPT.parents[1] / "src" / "commands" / "calibrate" / "page.html"
    browser.open(page.resolve().as_uri())
    browser.until(f"{CAL}.currentTrial().phase === 'refused'", "the refusal")
    assert "holds no stimuli" in browser.js("document.getElementById('message').textContent")
    assert browser.errors() == [], browser.errors()
