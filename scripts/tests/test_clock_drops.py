"""clock_drops.py reads the triangle rates around each block from run.json, calls a change of more than a fifth
(either way) a change of speed, sums each block's methods' clock warm-ups, and fails on a folder without runs."""
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "clock_drops.py"
sys.path.insert(0, str(ROOT / "scripts"))

import clock_drops  # noqa: E402


def block(scene, count, before, after, warm=None, short=None):
    return {"scene": scene, "count": count, "triangle_rate_before": before, "triangle_rate_after": after,
            "clock_warmup_ms": warm, "clock_warmups_short": short}


def test_the_threshold_is_the_rust_one():
    """The script's line is the binary's (src/measure/probe_rounds.rs, CLOCK_CHANGED_BELOW): one figure, two
    readers."""
    import re
    rust = (ROOT / "src" / "measure" / "probe_rounds.rs").read_text()
    m = re.search(r"pub const CLOCK_CHANGED_BELOW: f64 = ([0-9.]+);", rust)
    assert m, "CLOCK_CHANGED_BELOW is gone from probe_rounds.rs"
    assert float(m.group(1)) == clock_drops.CHANGED_BELOW


def test_a_fifth_either_way_is_a_change():
    assert clock_drops.changed(10.0, 7.9) and clock_drops.changed(2.0, 10.0)
    assert not clock_drops.changed(10.0, 8.5) and not clock_drops.changed(8.5, 10.0)
    assert clock_drops.changed(None, 10.0) is None


def test_blocks_are_listed_once_with_their_methods_warmups(tmp_path):
    run = {"adapter": {"name": "GPU"}, "clock_warmup": True, "blocks": [
        block("terrain", 1, 100.0, 22.0, 250.0, 1), block("terrain", 1, 100.0, 22.0, 30.0, 0),
        block("bunny-sweep", 1, 100.0, 95.0, 10.0, 0)]}
    (tmp_path / "run.json").write_text(json.dumps(run))
    r = subprocess.run([sys.executable, str(SCRIPT), str(tmp_path)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    rows = [line for line in r.stdout.splitlines() if line.startswith("| terrain") or line.startswith("| bunny")]
    assert rows == ["| terrain | 1 | 2 | 100 | 22 | 0.22 | yes | 280 | 1 |",
                    "| bunny-sweep | 1 | 1 | 100 | 95 | 0.95 | no | 10 | 0 |"]


def test_a_folder_without_runs_fails(tmp_path):
    r = subprocess.run([sys.executable, str(SCRIPT), str(tmp_path)], capture_output=True, text=True)
    assert r.returncode == 1 and "no run.json" in r.stderr
