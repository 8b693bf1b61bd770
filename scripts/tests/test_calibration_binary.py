"""`lodbench calibrate` end to end with the real binary: every display flag at its default (a 1920x1080, 60 Hz,
24-inch monitor at 60 cm) writes DIR/index.html beside stimuli.json and its frames, the page holds the stimuli, and a
simulated observer's responses to them fit into a calibration.json of that display which `lodbench run
--calibration` refuses at another viewport. A tiny ladder (one pair, two steps, a 64-pixel window, 9-frame
intervals) keeps it to seconds on the software adapter."""
import json
import subprocess
import sys
from pathlib import Path

from conftest import lodbench, lodbench_binary

SCRIPTS = Path(__file__).resolve().parents[1]
SCRIPT = SCRIPTS / "calibration.py"


def test_default_display_page_stimuli_and_a_fit_that_run_reads(tmp_path):
    out = tmp_path / "cal"
    lodbench("calibrate", "--scene", "bunny-sweep", "--method", "discrete,dither", "--stimulus-size", "64",
             "--scales", "0.5,2", "--pairs", "1", "--interval-ms", "150", "--fade-ms", "50", "--trials-per-track",
             "10", "--out", str(out))
    stimuli = json.loads((out / "stimuli.json").read_text())
    assert stimuli["display"]["width_px"] == 1920 and stimuli["display"]["refresh_hz"] == 60.0
    assert abs(stimuli["display"]["pixels_per_degree"] - 37.84) < 0.01, "ColorVideoVDP's standard_fhd"
    page = (out / "index.html").read_text()
    assert "__LODBENCH_STIMULI__" not in page and stimuli["id"] in page
    for s in stimuli["stimuli"]:
        for f in s["switch_frames"] + s["still_frames"]:
            assert (out / f).is_file()

    # A simulated observer planted on lodpop at the ladder's geometric middle; its fit is of the same display.
    values = sorted(s["lodpop"] for s in stimuli["stimuli"])
    middle = (values[0] * values[-1]) ** 0.5
    responses = tmp_path / "responses.json"
    subprocess.run([sys.executable, str(SCRIPT), "simulate", str(out / "stimuli.json"), "--metric", "lodpop",
                    "--threshold", str(middle), "--slope", "3", "--lapse", "0.02", "--seed", "1", "--out",
                    str(responses)], check=True, capture_output=True)
    fit = tmp_path / "fit"
    subprocess.run([sys.executable, str(SCRIPT), "fit", str(out / "stimuli.json"), str(responses), "--out", str(fit),
                    "--bootstrap", "50"], check=True, capture_output=True)
    calibration = json.loads((fit / "calibration.json").read_text())
    assert calibration["simulated"] is True and "SIMULATED" in calibration["label"]
    assert calibration["display"] == stimuli["display"]
    assert calibration["metrics"]["lodpop"]["threshold"] > 0

    # run reads it, and refuses its default 320x240 viewport: the calibration is of a 1920x1080 display.
    r = subprocess.run([str(lodbench_binary()), "run", "--scene", "bunny-sweep", "--calibration",
                        str(fit / "calibration.json"), "--out", str(tmp_path / "run")], capture_output=True, text=True)
    assert r.returncode != 0
    assert r.stderr.startswith("error: calibration") and "1920x1080 display" in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1
