"""scripts/calibration.py: the simulated observer, the psychometric fit and the page's procedure, on synthetic stimuli
(made here, no lodbench binary): the fit finds a planted threshold and the planted metric, the JavaScript procedure of
page.html and its Python mirror agree, bad input is refused with one line and exit code 2.

make_stimuli (also used by test_calibration_browser.py) writes a stimuli.json as `lodbench calibrate` does: 2 assets x
3 methods (discrete, dither, alpha) tracks, a ladder of 8 steps each, tiny 32x32 PNG frames. Its metrics are
correlated but no metric is a monotone function of another across tracks: each track has its own ratio of flip to
lodpop, its own share of coverage in lodpop and its own scale of the JOD drop, so an observer planted on one metric
is fitted worse by the others."""
import csv
import hashlib
import io
import json
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image, ImageDraw

SCRIPTS = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(SCRIPTS))
import calibration  # noqa: E402

SCRIPT = SCRIPTS / "calibration.py"
METHODS = ("discrete", "dither", "alpha")
METRICS = ["lodpop", "lodpop_coverage", "lodpop_shading", "flip", "jod_popping"]
DISPLAY = {"width_px": 1920, "height_px": 1080, "refresh_hz": 60.0, "diagonal_in": 24.0, "viewing_distance_cm": 60.0,
           "peak_luminance_cd_m2": 200.0, "pixels_per_degree": 40.1}
# The observer planted on flip: its 75 % point, Weibull slope and lapse.
PLANT = {"metric": "flip", "threshold": 0.03, "slope": 3.0, "lapse": 0.02}
# Per track (cycled): flip / lodpop, coverage's share of lodpop, the JOD drop's scale, the flip ladder's offset.
RATIO = (3.0, 0.8, 1.6, 5.0, 1.0, 2.2)
COVERAGE = (0.9, 0.3, 0.6, 0.5, 0.8, 0.2)
JOD_SCALE = (1.0, 2.5, 0.5, 1.5, 0.7, 3.0)
SHIFT = (1.0, 0.8, 1.25, 0.9, 1.1, 1.0)


def png(im: Image.Image) -> bytes:
    buf = io.BytesIO()
    im.save(buf, format="PNG")
    return buf.getvalue()


def make_stimuli(folder: Path, assets=2, methods=METHODS, steps=8, trials_per_track=40, refresh_hz=60.0, frames=6,
                 gap_ms=200, size=32, seed=1) -> Path:
    """Writes folder/stimuli.json and folder/frames/*.png (named by content hash, shared when identical); returns
    the stimuli.json path. Per track, step k of the ladder has flip = 0.03 * offset * 1.6^(k - centre) (so the
    planted threshold lies inside every ladder), lodpop = flip / ratio, coverage and shading its parts, jod_popping
    = 10 - 0.8 * (flip * scale / 0.03)^0.7. Still frames: a light square sliding on mid-grey; switch frames: the
    same, its colour changing at switch_frame by an amount that grows with the step."""
    (folder / "frames").mkdir(parents=True, exist_ok=True)
    written = {}

    def frame_path(im):
        data = png(im)
        name = f"frames/{hashlib.sha256(data).hexdigest()[:16]}.png"
        if name not in written:
            (folder / name).write_bytes(data)
            written[name] = True
        return name

    def draw(x, y, colour):
        im = Image.new("RGBA", (size, size), (128, 128, 128, 255))
        ImageDraw.Draw(im).rectangle([x, y, x + size // 3, y + size // 3], fill=colour)
        return im

    switch_frame = frames // 2
    tracks, stimuli = [], []
    t_index = 0
    for a in range(assets):
        asset = f"synthetic-{chr(ord('a') + a)}"
        for method in methods:
            j = t_index % len(RATIO)
            t_index += 1
            track = {"id": f"{asset}/{method}", "asset": asset, "method": method, "stimuli": []}
            base = (170 + 20 * a, 150 + 30 * METHODS.index(method) % 90, 190)
            still = [frame_path(draw(2 + f, 4 + 3 * a, base)) for f in range(frames)]
            for k in range(steps):
                flip = 0.03 * SHIFT[j] * 1.6 ** (k - (steps - 1) / 2)
                lodpop = flip / RATIO[j]
                delta = 6 + 10 * k
                changed = tuple(min(255, c + delta) for c in base[:2]) + (max(0, base[2] - delta),)
                switch = still[:switch_frame] + [frame_path(draw(2 + f, 4 + 3 * a, changed))
                                                  for f in range(switch_frame, frames)]
                sid = f"{asset}/{method}/1->2@{20 + 2 * k:.2f}"
                track["stimuli"].append(sid)
                stimuli.append({"id": sid, "track": track["id"], "asset": asset, "method": method, "lods": "1->2",
                                "switch_distance": 20.0 + 2 * k, "switch_frame": switch_frame,
                                "switch_frames": switch, "still_frames": still,
                                "lodpop": lodpop, "lodpop_coverage": lodpop * COVERAGE[j],
                                "lodpop_shading": lodpop * (1 - COVERAGE[j]), "flip": flip,
                                "jod_popping": 10.0 - 0.8 * (flip * JOD_SCALE[j] / 0.03) ** 0.7})
            tracks.append(track)
    body = {"display": {**DISPLAY, "refresh_hz": refresh_hz},
            "stimulus": {"width_px": size, "height_px": size, "frames_per_interval": frames, "gap_ms": gap_ms},
            "procedure": {"kind": "weighted-up-down", "target": 0.75, "down_steps": 1, "up_steps": 3,
                          "trials_per_track": trials_per_track, "seed": seed},
            "ladder_metric": "lodpop", "metrics": METRICS, "tracks": tracks, "stimuli": stimuli}
    sid = hashlib.sha256(json.dumps(body, sort_keys=True).encode()).hexdigest()[:16]
    out = {"format": "lodbench-calibration-stimuli", "version": 1, "id": sid,
           "command": f"lodbench calibrate --scene synthetic --out {folder}", **body}
    path = folder / "stimuli.json"
    path.write_text(json.dumps(out, indent=2))
    return path


def run(*args) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(SCRIPT), *map(str, args)], capture_output=True, text=True)


@pytest.fixture(scope="module")
def stimuli_path(tmp_path_factory) -> Path:
    return make_stimuli(tmp_path_factory.mktemp("calibration") / "stimuli")


@pytest.fixture(scope="module")
def stimuli(stimuli_path) -> dict:
    return calibration.read_stimuli(stimuli_path)


def test_the_threshold_is_the_75_percent_point_and_the_gradient_is_right():
    for lapse in (0.0, 0.02, 0.06):
        assert calibration.p_correct(-1.5, -1.5, 3.0, lapse) == pytest.approx(0.75)
        assert calibration.p_correct(5.0, -1.5, 3.0, lapse) == pytest.approx(1 - lapse)
        assert calibration.p_correct(-9.0, -1.5, 3.0, lapse) == pytest.approx(0.5)
    rng = np.random.default_rng(0)
    lx = rng.uniform(-3, -1, 30)
    n = rng.integers(1, 9, 30).astype(float)
    k = np.minimum(n, rng.integers(0, 9, 30))
    theta = np.array([-2.0, 2.5, 0.03])
    _, g = calibration.nll(theta, lx, n, k)
    numeric = [(calibration.nll(theta + e, lx, n, k)[0] - calibration.nll(theta - e, lx, n, k)[0]) / 2e-6
               for e in np.eye(3) * 1e-6]
    assert g == pytest.approx(numeric, rel=1e-4, abs=1e-4)


def test_the_staircase_moves_1_down_3_up_and_repeats_an_invalid_trial(stimuli):
    one = {**stimuli, "tracks": stimuli["tracks"][:1], "procedure": {**stimuli["procedure"], "trials_per_track": 6}}
    state = calibration.procedure_start(one)
    assert state["trial"]["level"] == 7 and state["trial"]["stimulus"] == one["tracks"][0]["stimuli"][7]
    levels = []
    for outcome in ({"valid": True, "correct": True}, {"valid": True, "correct": True},
                    {"valid": False, "correct": None}, {"valid": True, "correct": False},
                    {"valid": True, "correct": False}, {"valid": True, "correct": True},
                    {"valid": True, "correct": True}):
        levels.append(state["trial"]["level"])
        state = calibration.procedure_next(one, state, outcome)
    # 7 -> 6 -> 5, stays 5 (invalid: the same stimulus again), up 3 to 7 (8 clamped to the top of 0..7), ...
    assert levels == [7, 6, 5, 5, 7, 7, 6], levels
    assert state["trial"] is None and state["n"] == 7 and state["tracks"][0]["valid"] == 6


def test_the_pages_procedure_and_the_python_mirror_agree(stimuli, tmp_path):
    """The JavaScript between `// BEGIN procedure` and `// END procedure` in page.html, run by node on a fixed
    sequence of outcomes (some invalid), shows the same stimuli and intervals, in the same order, with the same
    final state as calibration.py's mirror."""
    node = shutil.which("node")
    if node is None:
        pytest.skip("no node on PATH: the mirror is checked where node is")
    page = calibration.TEMPLATE.read_text()
    js = page[page.index("// BEGIN procedure"):page.index("// END procedure")]
    rng = np.random.default_rng(11)
    outcomes = [{"valid": bool(rng.random() > 0.1), "correct": bool(rng.random() < 0.7)} for _ in range(400)]
    small = {**stimuli, "procedure": {**stimuli["procedure"], "trials_per_track": 30, "seed": 987654321}}
    script = tmp_path / "mirror.js"
    script.write_text(js + """
const {stimuli, outcomes} = JSON.parse(require("fs").readFileSync(0, "utf8"));
let state = procedureStart(stimuli);
const shown = [];
for (const o of outcomes) {
  if (!state.trial) break;
  shown.push([state.trial.track, state.trial.stimulus, state.trial.switch_interval]);
  state = procedureNext(stimuli, state, o);
}
console.log(JSON.stringify({shown, state}));
""")
    r = subprocess.run([node, str(script)], input=json.dumps({"stimuli": small, "outcomes": outcomes}),
                       capture_output=True, text=True, timeout=30)
    assert r.returncode == 0, r.stderr
    js_out = json.loads(r.stdout)
    state = calibration.procedure_start(small)
    shown = []
    for o in outcomes:
        if state["trial"] is None:
            break
        shown.append([state["trial"]["track"], state["trial"]["stimulus"], state["trial"]["switch_interval"]])
        state = calibration.procedure_next(small, state, o)
    assert len(shown) > 6 * 30, "the sequence should end every track"
    assert js_out["shown"] == shown
    assert js_out["state"] == state
    # and the draws are not degenerate: both intervals and every track come up
    assert {s[2] for s in shown} == {1, 2} and {s[0] for s in shown} == set(range(6))


SEEDS = range(20)
# 60 trials per track (360 trials): with 40 (240 trials) the percentile bootstrap's 95 % interval held the planted
# threshold in 89 of 100 seeds (91 with 1000 resamples), too close to 17 of 20; with 60, 93 % (56 of 60 seeds), and
# flip had the best held-out likelihood in 60 of 60 (99 of 100 at 40 trials per track).
STUDY_TRIALS_PER_TRACK = 60
# 200 resamples: the 2.5 and 97.5 % points from 200 resamples move the interval's ends by a few percent of its width
# (the study found the same coverage, 89 vs 91 %, with 200 and with 1000); the command's default is 1000.
STUDY_BOOTSTRAP = 200


def test_a_simulated_observer_planted_on_flip_is_found(stimuli):
    """20 simulated observers (seeds 0..19) planted on flip (threshold 0.03, slope 3, lapse 0.02): the fit's 95 %
    interval of flip's threshold holds 0.03 in at least 17 of 20, and flip has the highest held-out likelihood in
    at least 18 of 20. In-process (no figures, the bootstrap of flip only) to stay within seconds."""
    t0 = time.monotonic()
    held, best, rows = 0, 0, []
    for seed in SEEDS:
        r = calibration.simulate(stimuli, seed=seed, trials_per_track=STUDY_TRIALS_PER_TRACK, **PLANT)
        cal = calibration.fit(stimuli, [r], bootstrap=STUDY_BOOTSTRAP, seed=1, bootstrap_metrics=["flip"])
        f = cal["metrics"]["flip"]
        lo, hi = f["ci95"]
        held += lo <= PLANT["threshold"] <= hi
        best += cal["best_metric"] == "flip"
        h = {m: v["heldout_log_likelihood"] for m, v in cal["metrics"].items()}
        rows.append(f"seed {seed:2}: flip {f['threshold']:.4f} [{lo:.4f}, {hi:.4f}], best {cal['best_metric']} "
                    f"(margin {h['flip'] - max(v for m, v in h.items() if m != 'flip'):+.1f})")
    print("\n" + "\n".join(rows))
    print(f"interval holds 0.03: {held}/20; flip best: {best}/20; {time.monotonic() - t0:.1f} s")
    assert held >= 17, rows
    assert best >= 18, rows


def test_simulate_and_fit_commands(stimuli_path, tmp_path):
    """The commands end to end, on an observer planted on jod_popping (threshold 9 JOD: a drop of 1): the files of
    the schema, the threshold in JOD, SIMULATED said in the label, the table and the figures, nothing half-written."""
    responses = tmp_path / "responses.json"
    r = run("simulate", stimuli_path, "--metric", "jod_popping", "--threshold", 9.0, "--slope", 3, "--lapse", 0.02,
            "--seed", 5, "--trials-per-track", 50, "--out", responses)
    assert r.returncode == 0, r.stderr
    sim = json.loads(responses.read_text())
    assert sim["simulated"] is True and sim["observer"] == "simulated" and len(sim["trials"]) == 300
    assert sim["simulation"] == {"metric": "jod_popping", "threshold": 9.0, "slope": 3.0, "lapse": 0.02, "seed": 5}
    out = tmp_path / "fit"
    r = run("fit", stimuli_path, responses, "--out", out, "--bootstrap", 200, "--seed", 3)
    assert r.returncode == 0, r.stderr
    print(r.stdout)
    cal = json.loads((out / "calibration.json").read_text())
    assert set(cal) == {"format", "version", "simulated", "label", "display", "stimuli_id", "trials", "observers",
                        "best_metric", "metrics", "psychometric", "fit"}
    assert cal["format"] == "lodbench-calibration" and cal["version"] == 1 and cal["simulated"] is True
    assert cal["label"] == ("SIMULATED observer (planted on jod_popping, threshold 9, slope 3, lapse 0.02): "
                            "not human data")
    assert cal["display"] == DISPLAY and cal["trials"] == 300 and cal["observers"] == ["simulated"]
    assert cal["fit"]["bootstrap"] == 200 and cal["fit"]["folds"] == 5 and cal["fit"]["package"].startswith("scipy ")
    assert cal["psychometric"]["lapse_bounds"] == [0, 0.06] and cal["psychometric"]["target"] == 0.75
    assert cal["best_metric"] == "jod_popping"
    for m in METRICS:
        f = cal["metrics"][m]
        assert set(f) == {"threshold", "ci95", "slope", "lapse", "log_likelihood", "heldout_log_likelihood",
                          "n_trials"}
        assert f["ci95"][0] <= f["ci95"][1] and 0 <= f["lapse"] <= 0.06 and f["n_trials"] == 300
        assert (out / f"fit-{m}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    jod = cal["metrics"]["jod_popping"]
    # In JOD: the interval's lower end is the larger drop; the planted 9 within 0.3 JOD (a drop of 1 +- 30 %).
    assert abs(jod["threshold"] - 9.0) < 0.3 and jod["ci95"][0] < jod["threshold"] < jod["ci95"][1] < 10, jod
    assert "SIMULATED" in r.stdout and "jod_popping" in r.stdout
    assert sorted(p.name for p in out.iterdir()) == sorted(["calibration.json"] + [f"fit-{m}.png" for m in METRICS])


# The trials study's test: 6 seeds at 10 and at 60 trials per track (60 and 360 trials), 40 resamples. Over 40
# seeds (seven disjoint groups of 6, the first the test's) the median relative width of the interval, (hi - lo) / T,
# was 0.59 at 10 and 0.31 at 60 trials per track, the ratio of a group's medians 0.35 to 0.66 (1 / sqrt(6) = 0.41
# were the width to shrink as 1 / sqrt(trials)); coverage at 60 was 37 of 40 (5 or 6 in every group of 6) and at 10
# only 32 of 40 (2 to 6 of 6: too few trials for the percentile bootstrap); flip was best in 40 of 40 at 60, 29 of
# 40 at 10. The test's bounds are well inside these.
TRIALS_STUDY = ("--trials", "10,60", "--seeds", 6, "--bootstrap", 40)


def test_the_trials_study(stimuli_path, stimuli, tmp_path):
    """`trials`: trials.csv's columns and rows (a row per value and seed, deterministic: a row remade in-process is
    the same), the interval narrower with 6 times the trials, the planted threshold covered and flip the best metric
    in most seeds at 60 trials per track, the table printed and the figure written."""
    out = tmp_path / "trials"
    r = run("trials", stimuli_path, "--metric", "flip", "--threshold", PLANT["threshold"], "--slope", PLANT["slope"],
            "--lapse", PLANT["lapse"], *TRIALS_STUDY, "--jobs", 2, "--out", out)
    assert r.returncode == 0, r.stderr
    print(r.stdout)
    with open(out / "trials.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert list(rows[0]) == ["trials_per_track", "seed", "total_trials", "threshold", "ci_lo", "ci_hi", "covered",
                             "best_metric"]
    assert [(r["trials_per_track"], r["seed"]) for r in rows] == [(n, str(s)) for n in ("10", "60") for s in range(6)]
    tracks = len(stimuli["tracks"])
    by = {}
    for row in rows:
        n = int(row["trials_per_track"])
        lo, hi, thr = float(row["ci_lo"]), float(row["ci_hi"]), float(row["threshold"])
        assert int(row["total_trials"]) == n * tracks
        assert 0 < lo < hi and thr > 0
        assert row["covered"] == str(lo <= PLANT["threshold"] <= hi).lower()
        assert row["best_metric"] in METRICS
        by.setdefault(n, []).append(((hi - lo) / PLANT["threshold"], row["covered"] == "true",
                                     row["best_metric"] == "flip"))
    width = {n: float(np.median([w for w, _, _ in v])) for n, v in by.items()}
    assert width[60] < 0.8 * width[10], width
    assert sum(c for _, c, _ in by[60]) >= 4 and sum(b for _, _, b in by[60]) >= 4, by[60]
    # Deterministic from the seeds: a row remade in this process (one process, not --jobs 2) is the same.
    again = calibration.trials_row(stimuli, "flip", PLANT["threshold"], PLANT["slope"], PLANT["lapse"], 40, (60, 3))
    assert {k: str(v).lower() if isinstance(v, bool) else str(v) for k, v in again.items()} == rows[9]
    table = r.stdout.splitlines()
    assert table[0].startswith("SIMULATED observers (planted on flip, threshold 0.03, slope 3, lapse 0.02)")
    assert table[2].split()[:2] == ["10", "60"] and table[3].split()[:2] == ["60", "360"]
    assert (out / "trials.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert sorted(p.name for p in out.iterdir()) == ["trials.csv", "trials.png"]


def test_the_trials_study_refuses_bad_flags(stimuli_path, tmp_path):
    for flags, reason in ((("--trials", "0,10"), "--trials '0,10': needs distinct whole numbers >= 1"),
                          (("--trials", "ten"), "not a comma-separated list of whole numbers"),
                          (("--seeds", 0), "--seeds 0: needs at least 1"),
                          (("--bootstrap", 5), "--bootstrap 5: needs at least 20"),
                          (("--metric", "nosuch"), "unknown metric 'nosuch'")):
        args = {"--metric": "flip", "--threshold": 0.03, "--slope": 3, "--trials": "10", "--seeds": 1,
                "--bootstrap": 20, **dict([flags])}
        r = run("trials", stimuli_path, *[v for kv in args.items() for v in kv], "--out", tmp_path / "t")
        assert r.returncode == 2 and r.stderr.count("\n") == 1 and reason in r.stderr, (flags, r.stderr)
    assert not (tmp_path / "t").exists()


@pytest.fixture(scope="module")
def simulated(stimuli, tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("responses") / "responses.json"
    path.write_text(json.dumps(calibration.simulate(stimuli, seed=1, trials_per_track=10, **PLANT)))
    return path


def altered(simulated: Path, tmp_path: Path, change) -> Path:
    r = json.loads(simulated.read_text())
    change(r)
    path = tmp_path / "altered.json"
    path.write_text(json.dumps(r))
    return path


def written(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def _display(r):
    r["display"]["refresh_hz"] = 144.0


def _stimuli_id(r):
    r["stimuli_id"] = "0123456789abcdef"


def _no_valid(r):
    for t in r["trials"]:
        t["valid"] = False


BAD = {
    "empty responses file": (lambda s, t: written(t / "empty.json", ""), "empty file"),
    "malformed responses": (lambda s, t: written(t / "bad.json", '{"trials": ['), "malformed JSON"),
    "another display": (lambda s, t: altered(s, t, _display), "another display"),
    "another stimuli set": (lambda s, t: altered(s, t, _stimuli_id), "responses to stimuli '0123456789abcdef'"),
    "no valid trials": (lambda s, t: altered(s, t, _no_valid), "no valid trials"),
}


@pytest.mark.parametrize("case", list(BAD))
def test_bad_responses_are_refused(case, stimuli_path, simulated, tmp_path):
    make, reason = BAD[case]
    bad = make(simulated, tmp_path)
    out = tmp_path / "fit"
    r = run("fit", stimuli_path, simulated, bad, "--out", out, "--bootstrap", 20)
    assert r.returncode == 2, (r.stdout, r.stderr)
    assert r.stderr.count("\n") == 1 and "Traceback" not in r.stderr, r.stderr
    assert str(bad) in r.stderr and reason in r.stderr, r.stderr
    assert not out.exists()


def test_an_unknown_metric_is_refused(stimuli_path, simulated, tmp_path):
    out = tmp_path / "fit"
    r = run("fit", stimuli_path, simulated, "--out", out, "--metric", "flip,nosuch")
    assert r.returncode == 2 and r.stderr.count("\n") == 1, r.stderr
    assert "unknown metric 'nosuch'" in r.stderr and str(stimuli_path) in r.stderr and not out.exists()
    r = run("simulate", stimuli_path, "--metric", "nosuch", "--threshold", 1, "--slope", 3, "--seed", 1,
            "--out", tmp_path / "sim.json")
    assert r.returncode == 2 and "unknown metric 'nosuch'" in r.stderr and r.stderr.count("\n") == 1, r.stderr
    assert not (tmp_path / "sim.json").exists()


def test_the_page_command_writes_the_stimuli_into_the_template(stimuli_path, tmp_path):
    """As `lodbench calibrate` does: the placeholder (once in the template, inside the stimuli script) replaced by
    compact JSON whose `</` are written `<\\/`, which reads back as the stimuli."""
    template = calibration.TEMPLATE.read_text()
    assert template.count(calibration.PLACEHOLDER) == 1
    assert f'<script id="stimuli" type="application/json">{calibration.PLACEHOLDER}</script>' in template
    s = json.loads(stimuli_path.read_text())
    s["command"] += " --note '</script><b>'"
    src = tmp_path / "stimuli.json"
    src.write_text(json.dumps(s))
    r = run("page", src, "--out", tmp_path / "out" / "index.html")
    assert r.returncode == 0, r.stderr
    html = (tmp_path / "out" / "index.html").read_text()
    assert calibration.PLACEHOLDER not in html and "</script><b>" not in html and "<\\/script><b>" in html
    start = html.index('<script id="stimuli" type="application/json">') + len(
        '<script id="stimuli" type="application/json">')
    assert json.loads(html[start:html.index("</script>", start)]) == s
