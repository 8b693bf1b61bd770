"""scripts/engine_check.py's matching of lodbench's discrete switches against three.js's, on synthetic frames.csv and
lods.csv data: no binary, no Chromium."""
import csv
import sys

import pytest

from conftest import ROOT

sys.path.insert(0, str(ROOT / "scripts"))
import engine_check as ec  # noqa: E402


def write(path, columns, rows):
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(columns)
        w.writerows(rows)
    return ec.read_csv(path)


def frames_csv(tmp_path, lod_means):
    """A frames.csv of reference and discrete rows, the discrete's lod_mean per frame as given, in two rounds."""
    rows = []
    half = len(lod_means) // 2
    for method in ("reference", "discrete"):
        for f, m in enumerate(lod_means):
            rows.append([method, f, 0.0 if method == "reference" else m, f >= half])
    return write(tmp_path / "frames.csv", ["method", "frame", "lod_mean", "round"], rows)


def lods_csv(tmp_path, lods, obj="bunny_0_LOD0"):
    return write(tmp_path / "lods.csv", ["frame", "object", "lod"], [[f, obj, v] for f, v in enumerate(lods)])


def time_fade(n, crossings, fade_frames=8):
    """lod_mean per frame of a time fade along an outward path: from each crossing frame, k = 1/N, 2/N, ..."""
    out, level, k, pending = [], 0, None, list(crossings)
    for f in range(n):
        if k is None and pending and f >= pending[0]:
            pending.pop(0)
            k = 0
        if k is not None:
            k += 1
            if k >= fade_frames:
                level, k = level + 1, None
                out.append(float(level))
                continue
            out.append(level + k / fade_frames)
        else:
            out.append(float(level))
    return out


def test_discrete_level_is_lod_mean_rounded_half_up(tmp_path):
    means = time_fade(40, [10, 25])
    lods = ec.discrete_lods(frames_csv(tmp_path, means))
    # k reaches 0.5 on the fourth frame of an 8-frame fade: 3 frames after the crossing.
    assert [f for f, _, _ in ec.switch_events(lods)] == [13, 28]
    assert lods[12] == 0 and lods[13] == 1 and lods[27] == 1 and lods[28] == 2


def test_a_time_fade_puts_lodbench_three_frames_after_three_js(tmp_path):
    ours = ec.discrete_lods(frames_csv(tmp_path, time_fade(40, [10, 25])))
    theirs = ec.three_lods(lods_csv(tmp_path, [0] * 10 + [1] * 15 + [2] * 15))
    rows = ec.match_switches(ours, theirs)
    assert [(r["pair"], r["frame_lodbench"], r["frame_three"], r["frame_diff"], r["status"]) for r in rows] == [
        ("0->1", 13, 10, -3, None), ("1->2", 28, 25, -3, None)]


def test_same_frames_match_with_no_difference():
    lods = [0] * 5 + [1] * 5 + [2] * 5 + [3] * 5
    rows = ec.match_switches(lods, list(lods))
    assert [(r["pair"], r["frame_diff"]) for r in rows] == [("0->1", 0), ("1->2", 0), ("2->3", 0)]
    assert ec.status_of(5, 5, True, True) == "agree"
    assert ec.status_of(5, 6, True, True) == "frame-differs"
    assert ec.status_of(5, 5, True, False) == "verdict-differs"
    assert ec.status_of(5, 7, False, True) == "verdict-differs"


def test_missing_switches_on_either_side():
    ours = [0] * 5 + [1] * 5 + [2] * 10
    # three.js skips level 1 (0->2 in one frame), and adds a 2->3 lodbench never makes.
    theirs = [0] * 6 + [2] * 9 + [3] * 5
    rows = ec.match_switches(ours, theirs)
    got = [(r["pair"], r["frame_lodbench"], r["frame_three"], r["frame_diff"], r["status"]) for r in rows]
    assert got == [
        ("0->1", 5, None, None, "missing-in-three"),
        ("0->2", None, 6, None, "missing-in-lodbench"),
        ("1->2", 10, None, None, "missing-in-three"),
        ("2->3", None, 15, None, "missing-in-lodbench"),
    ]


def test_repeated_pairs_match_by_order():
    # Back and forth across one switch: the n-th 0->1 of one with the n-th 0->1 of the other.
    ours = [0, 0, 1, 1, 0, 0, 1, 1, 1, 1]
    theirs = [0, 0, 0, 1, 1, 0, 0, 0, 1, 1]
    rows = ec.match_switches(ours, theirs)
    got = [(r["pair"], r["order"], r["frame_lodbench"], r["frame_three"], r["frame_diff"]) for r in rows]
    assert got == [("0->1", 0, 2, 3, 1), ("1->0", 0, 4, 5, 1), ("0->1", 1, 6, 8, 2)]


def test_frames_must_be_complete(tmp_path):
    rows = frames_csv(tmp_path, [0.0, 0.0, 1.0])
    with pytest.raises(ValueError):
        ec.discrete_lods([r for r in rows if r["frame"] != "1"])
    two = write(tmp_path / "lods2.csv", ["frame", "object", "lod"], [[0, "a", 0], [0, "b", 0]])
    with pytest.raises(ValueError):
        ec.three_lods(two)
    assert ec.three_lods(two, "b") == [0]
