"""report.html in a real browser: headless Chromium opens a results folder's report, moves the first player's slider
with the mouse and the keyboard, toggles the error view, and the player's image and caption change while nothing
is logged as an error. Chromium is driven over the DevTools protocol (scripts/browser.py).

Skipped when no Chromium is installed (Debian's `chromium` package). LODBENCH_SCREENSHOTS=DIR keeps the screenshots
in DIR (else the test's temporary folder)."""
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from conftest import lodbench_binary

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from browser import Browser, chromium_binary  # noqa: E402

# The long suite (conftest.py): a whole browser session per test.
pytestmark = pytest.mark.long

SCRIPT = Path(__file__).resolve().parents[1] / "plot.py"
# The whole browser session of a test, start-up included: a hung browser fails the test instead of hanging CI.
TIMEOUT_S = 60
VIEWPORT = (1280, 900)


@pytest.fixture(scope="session")
def chromium() -> str:
    binary = chromium_binary()
    if binary is None:
        pytest.skip("no Chromium (chromium, chromium-browser or google-chrome on PATH): apt-get install chromium")
    return binary


@pytest.fixture
def browser(chromium, tmp_path):
    t0 = time.monotonic()
    b = Browser(chromium, tmp_path / "profile", t0 + TIMEOUT_S, viewport=VIEWPORT)
    b.started_s = time.monotonic() - t0
    yield b
    b.close()


def screenshots_dir(tmp_path: Path) -> Path:
    d = Path(os.environ["LODBENCH_SCREENSHOTS"]) if os.environ.get("LODBENCH_SCREENSHOTS") else tmp_path / "shots"
    d.mkdir(parents=True, exist_ok=True)
    return d


def plot(folder: Path):
    r = subprocess.run([sys.executable, str(SCRIPT), str(folder)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


PLAYER = "document.querySelector('.player')"
# The first player's picture shown and settled: an image loaded, or an MP4 (`clips --mp4 only`) done seeking with
# the frame there.
SHOWN = (f"(e => e.tagName === 'IMG' ? e.complete : !e.seeking && e.readyState >= 2)"
         f"({PLAYER}.querySelector('.clip'))")


def player_state(b: Browser):
    """The first player: what it shows (`src`: the image, or the MP4 with its time), in which `view` (frame or error,
    from the image's name or the MP4's box), its caption, slider and their boxes."""
    return b.js(f"""(() => {{ const p = {PLAYER}, img = p.querySelector('.clip'),
        movie = img.tagName === 'VIDEO', shown = movie ? p.querySelector('.movie') : img,
        box = r => (r => [r.left, r.top, r.width, r.height])(r.getBoundingClientRect()),
        src = img.getAttribute('src');
        return {{ src: movie ? src.split('#')[0] + '@' + img.currentTime.toFixed(3) : src,
                  view: movie ? (shown.classList.contains('error') ? 'error' : 'frame')
                              : (src.includes('/error_') ? 'error' : src.includes('/frame_') ? 'frame' : '?'),
                  ready: movie ? !img.seeking && img.readyState >= 2 : img.complete && img.naturalWidth > 0,
                  caption: p.querySelector('.caption').textContent, value: p.querySelector('.slider').value,
                  max: p.querySelector('.slider').max, img: box(shown), slider: box(p.querySelector('.slider')),
                  error: box(p.querySelector('input[value=error]')) }}; }})()""")


def crop(shot: Image.Image, box) -> np.ndarray:
    x, y, w, h = (round(v) for v in box)
    return np.asarray(shot.crop((x, y, min(x + w, shot.width), min(y + h, shot.height))), dtype=np.int16)


def changed(before: np.ndarray, after: np.ndarray) -> float:
    """The fraction of the player's pixels that differ."""
    assert before.shape == after.shape, "the player's image moved or changed size"
    return float((np.abs(before - after).sum(axis=2) > 0).mean())


def frame_of(caption: str) -> int:
    return int(caption.split()[1])


def exercise(b: Browser, folder: Path, shots: Path, tag: str) -> dict:
    """Opens folder's report.html, preloads every player, and steps the first player's slider by mouse and keyboard
    and toggles its view, with a screenshot after each; returns what changed and the errors the page logged."""
    t0 = time.monotonic()
    b.open((folder / "report.html").resolve().as_uri())
    b.painted()
    b.screenshot().save(shots / f"{tag}-page-top.png")
    b.js(f"{PLAYER}.scrollIntoView({{block: 'start'}})")
    # The first player preloads by itself once in view; the others are asked to (an image missing anywhere shows).
    b.until(f"{PLAYER}.dataset.total && {PLAYER}.dataset.settled === {PLAYER}.dataset.total",
            "the first player's preload")
    b.js("document.querySelectorAll('.player').forEach(p => p.preload())")
    b.until("[...document.querySelectorAll('.player')].every(p => p.dataset.settled === p.dataset.total)",
            "every player's preload")
    b.until(SHOWN, "the first image")
    b.painted()
    loaded_s = time.monotonic() - t0
    s0 = player_state(b)
    shot0 = b.screenshot()
    # Real input: a click at three quarters of the slider's track moves its thumb there.
    x, y, w, h = s0["slider"]
    b.click(x + 0.75 * w, y + h / 2)
    b.until(SHOWN, "the clicked frame")
    b.painted()
    s1 = player_state(b)
    shot1 = b.screenshot()
    # The focused slider's arrow key: one frame on (or back, at the end).
    step = ("ArrowLeft", 37) if s1["value"] == s1["max"] else ("ArrowRight", 39)
    b.key(*step)
    b.until(SHOWN, "the next frame")
    b.painted()
    s2 = player_state(b)
    shot2 = b.screenshot()
    # The error view of the same frame.
    x, y, w, h = s2["error"]
    b.click(x + w / 2, y + h / 2)
    b.until(SHOWN, "the error view")
    b.painted()
    s3 = player_state(b)
    shot3 = b.screenshot()
    for name, shot in (("0-loaded", shot0), ("1-slider-clicked", shot1), ("2-error-view", shot3)):
        shot.save(shots / f"{tag}-{name}.png")
    return {"states": (s0, s1, s2, s3), "clicked": changed(crop(shot0, s0["img"]), crop(shot1, s1["img"])),
            "toggled": changed(crop(shot2, s2["img"]), crop(shot3, s3["img"])), "errors": b.errors(),
            "loaded_s": loaded_s, "total_s": time.monotonic() - t0}


def check(result):
    s0, s1, s2, s3 = result["states"]
    assert s0["ready"] and s1["ready"] and s3["ready"], result["states"]
    assert s1["value"] != s0["value"] and frame_of(s1["caption"]) != frame_of(s0["caption"]), (s0, s1)
    assert s1["src"] != s0["src"] and s0["view"] == s1["view"] == "frame", (s0, s1)
    assert abs(int(s2["value"]) - int(s1["value"])) == 1, (s1, s2)
    assert s3["value"] == s2["value"] and frame_of(s3["caption"]) == frame_of(s2["caption"]), (s2, s3)
    assert s3["view"] == "error", s3
    assert result["clicked"] > 0.001, f"the player's pixels did not change ({result['clicked']:.4%} differ)"
    assert result["toggled"] > 0.001, f"the error view looks like the frame view ({result['toggled']:.4%} differ)"
    assert result["errors"] == [], result["errors"]


def report_timing(b: Browser, result, tag: str):
    print(f"\n{tag}: Chromium up in {b.started_s:.2f} s, report loaded and preloaded in {result['loaded_s']:.2f} s, "
          f"whole check {result['total_s']:.2f} s; pixels changed: slider {result['clicked']:.2%}, "
          f"toggle {result['toggled']:.2%}; caption {result['states'][0]['caption']!r} -> "
          f"{result['states'][1]['caption']!r}")


def test_a_hung_browser_fails_in_time(tmp_path):
    """A browser that never answers fails the test at the deadline instead of hanging it (and is killed)."""
    hung = tmp_path / "hung-browser"
    hung.write_text(f"#!{sys.executable}\nimport time\ntime.sleep(60)\n")
    hung.chmod(0o755)
    t0 = time.monotonic()
    with pytest.raises(TimeoutError):
        Browser(str(hung), tmp_path / "profile", t0 + 1)
    assert time.monotonic() - t0 < 5


@pytest.fixture(scope="module")
def synthetic(chromium, software_run, make_clips, tmp_path_factory) -> Path:
    """A results folder of the software adapter with a synthetic clips/ (see conftest.write_clips), plotted."""
    folder = tmp_path_factory.mktemp("report") / "synthetic"
    shutil.copytree(software_run, folder)
    make_clips(folder, clips=3, frames=12, tile=(200, 150))
    plot(folder)
    return folder


def test_synthetic_clips_in_chromium(synthetic, browser, tmp_path):
    result = exercise(browser, synthetic, screenshots_dir(tmp_path), "synthetic")
    report_timing(browser, result, "synthetic")
    check(result)


def test_mp4_only_clips_in_chromium(chromium, software_run, make_clips, browser, tmp_path):
    """The player of `clips --mp4 only` (what committed example folders keep): stepping seeks the MP4 to the frame,
    the error view shows its lower half, and the pixels change with each."""
    folder = tmp_path / "movie"
    shutil.copytree(software_run, folder)
    make_clips(folder, clips=3, frames=12, tile=(200, 150), movie=True)
    plot(folder)
    result = exercise(browser, folder, screenshots_dir(tmp_path), "mp4-only")
    report_timing(browser, result, "mp4 only")
    check(result)
    s0, s1 = result["states"][:2]
    fps = 10
    at = lambda s: float(s["src"].split("@")[1])  # noqa: E731
    assert abs(at(s1) - (int(s1["value"]) + 0.5) / fps) < 1e-3 and abs(at(s0) - 0.5 / fps) < 1e-3, (s0, s1)


def test_missing_clip_image_is_an_error(synthetic, browser, tmp_path):
    """The check can fail: a clip image deleted after plot.py wrote the report is logged by the browser (and by
    the player), and the test's error collection sees it."""
    folder = tmp_path / "missing"
    shutil.copytree(synthetic, folder)
    index = json.loads((folder / "clips" / "index.json").read_text())
    gone = index["clips"][1]["error_images"][3]
    (folder / "clips" / gone).unlink()
    result = exercise(browser, folder, screenshots_dir(tmp_path), "missing")
    errors = result["errors"]
    print("\nerrors logged:", *errors, sep="\n  ")
    assert any("lodbench report: cannot load" in e and gone in e for e in errors), errors
    # The browser's own log, not only the player's console.error: a missing figure would show the same way.
    assert any(e.startswith("log (network)") and gone.split("/")[-1] in e for e in errors), errors


@pytest.fixture
def clipped(chromium, software_run, tmp_path) -> Path:
    """The software run with `lodbench clips` (the real clips), plotted."""
    folder = tmp_path / "clipped"
    shutil.copytree(software_run, folder)
    # Two transitions (of six) keep the fixture short; the MP4s stay (when ffmpeg is installed) for their links.
    r = subprocess.run([str(lodbench_binary()), "clips", str(folder), "--transitions", "0,1"], capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stderr
    plot(folder)
    return folder


def test_lodbench_clips_in_chromium(clipped, browser, tmp_path):
    result = exercise(browser, clipped, screenshots_dir(tmp_path), "lodbench-clips")
    report_timing(browser, result, "lodbench clips")
    check(result)


# The first screen a user sees (issue: the report answers first).
FIRST_SCREEN = (1280, 800)
FOX = Path(__file__).resolve().parents[2] / "tests" / "data" / "gltf" / "Fox.glb"


@pytest.fixture(scope="module")
def answer_reports(chromium, tmp_path_factory):
    """Two reports as a user makes them: a textured, skinned and animated user asset (Khronos Fox, its texture
    drawn) and bunny-sweep, every default method, a short flight at 160x120 (the page's layout does not depend on
    the frame's size), plotted."""
    base = tmp_path_factory.mktemp("answer-reports")
    out = {}
    for tag, scene in (("fox", str(FOX)), ("bunny-sweep", "bunny-sweep")):
        folder = base / tag
        r = subprocess.run([str(lodbench_binary()), "run", "--scene", scene, "--width", "160", "--height", "120",
                            "--frames", "120", "--rounds", "6", "--out", str(folder)], capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        plot(folder)
        out[tag] = folder
    return out


def first_screen_and_widths(b: Browser, folder: Path, shots: Path, tag: str) -> dict:
    """Opens the report at 1280x800: where the first answer's heading, sentences and table lie, the window's
    width, and every element wider than it (with every folded table opened); and every number span."""
    b.js(f"window.resizeTo({FIRST_SCREEN[0]}, {FIRST_SCREEN[1]})")
    b.call("Emulation.setDeviceMetricsOverride", width=FIRST_SCREEN[0], height=FIRST_SCREEN[1], deviceScaleFactor=1,
           mobile=False)
    b.open((folder / "report.html").resolve().as_uri())
    b.painted()
    b.screenshot().save(shots / f"answer-{tag}.png")
    state = b.js("""(() => {
        const box = el => { const r = el.getBoundingClientRect(); return [r.left, r.top, r.right, r.bottom]; };
        const first = document.querySelector('.answer');
        const parts = [first.querySelector('h2'), ...first.querySelectorAll('p.sentence'),
                       first.querySelector('table.decision')];
        document.querySelectorAll('details').forEach(d => d.open = true);
        const w = document.documentElement.clientWidth;
        const wide = [...document.querySelectorAll('body *')].filter(el => el.getBoundingClientRect().width > w + 0.5)
            .map(el => el.tagName + (el.className ? '.' + el.className : '') + ' ' +
                 Math.round(el.getBoundingClientRect().width));
        const spans = [...document.querySelectorAll('span.v')].map(s => ({
            'data-file': s.dataset.file, 'data-row': s.dataset.row, 'data-cols': s.dataset.cols,
            'data-fmt': s.dataset.fmt, 'data-op': s.dataset.op, text: s.textContent,
            in_sentence: !!s.closest('p.sentence')}));
        return {boxes: parts.map(box), height: window.innerHeight, width: w,
                scroll_width: document.documentElement.scrollWidth, wide, spans,
                sentences: [...first.querySelectorAll('p.sentence')].map(p => p.textContent)};
    })()""")
    return state


def check_answer(state, folder: Path):
    from test_answer import expected
    assert state["width"] == FIRST_SCREEN[0] and state["height"] == FIRST_SCREEN[1], state
    for left, top, right, bottom in state["boxes"]:
        assert 0 <= top and bottom <= FIRST_SCREEN[1], ("the answer is not in the first screen", state["boxes"])
        assert 0 <= left and right <= FIRST_SCREEN[0], ("the answer is wider than the window", state["boxes"])
    assert len(state["sentences"]) == 2, state["sentences"]
    assert state["wide"] == [] and state["scroll_width"] <= FIRST_SCREEN[0], state["wide"]
    in_sentences = [s for s in state["spans"] if s["in_sentence"]]
    assert len(in_sentences) >= 3, state["spans"]
    for span in state["spans"]:
        assert span["text"] == expected(span, folder), span


@pytest.mark.parametrize("tag", ["fox", "bunny-sweep"])
def test_the_answer_is_in_the_first_screen(answer_reports, browser, tmp_path, tag):
    folder = answer_reports[tag]
    state = first_screen_and_widths(browser, folder, screenshots_dir(tmp_path), tag)
    print(f"\n{tag}: answer boxes {state['boxes']}; sentences: {state['sentences']}")
    check_answer(state, folder)
    assert browser.errors() == [], browser.errors()


def test_a_wide_table_is_caught(answer_reports, browser, tmp_path):
    """The check can fail: the same report with its decision table made wider than the window."""
    folder = tmp_path / "wide"
    shutil.copytree(answer_reports["bunny-sweep"], folder)
    page = (folder / "report.html").read_text()
    (folder / "report.html").write_text(page.replace("</style>", "table.decision { min-width: 1400px; }</style>", 1))
    state = first_screen_and_widths(browser, folder, screenshots_dir(tmp_path), "wide")
    assert state["wide"], state
    with pytest.raises(AssertionError):
        check_answer(state, folder)
