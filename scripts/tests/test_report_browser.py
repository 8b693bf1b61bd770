"""report.html in a real browser: headless Chromium opens a results folder's report, moves the first player's slider
with the mouse and the keyboard, toggles the error view, and the player's image and caption change while nothing
is logged as an error. Chromium is driven over the DevTools protocol on a pipe (--remote-debugging-pipe: it reads
commands on fd 3 and writes replies and events on fd 4, JSON messages ended by a NUL byte), standard library only.

Skipped when no Chromium is installed (Debian's `chromium` package). LODBENCH_SCREENSHOTS=DIR keeps the screenshots
in DIR (else the test's temporary folder)."""
import base64
import fcntl
import io
import json
import os
import queue
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from conftest import lodbench_binary

SCRIPT = Path(__file__).resolve().parents[1] / "plot.py"
# The whole browser session of a test, start-up included: a hung browser fails the test instead of hanging CI.
TIMEOUT_S = 60
VIEWPORT = (1280, 900)


def chromium_binary():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        found = shutil.which(name)
        if found:
            return found
    return None


class Browser:
    """A headless Chromium and one page of it, attached as a flat session. Every wait ends at `deadline`."""

    def __init__(self, binary: str, profile: Path, deadline: float):
        self.deadline = deadline
        self.events = []  # every event of the page's session, in order
        self.replies = queue.Queue()
        self.next_id = 0
        to_browser_r, self.to_browser = os.pipe()
        self.from_browser, from_browser_w = os.pipe()

        def fds_3_and_4():
            # In the child: the pipe ends as fds 3 and 4, by way of fds >= 10 so neither clobbers the other.
            a, b = fcntl.fcntl(to_browser_r, fcntl.F_DUPFD, 10), fcntl.fcntl(from_browser_w, fcntl.F_DUPFD, 10)
            os.dup2(a, 3)
            os.dup2(b, 4)

        args = [binary, "--headless", "--disable-gpu", "--remote-debugging-pipe", f"--user-data-dir={profile}",
                f"--window-size={VIEWPORT[0]},{VIEWPORT[1]}", "--hide-scrollbars", "--no-first-run",
                "--no-default-browser-check", "--disable-extensions", "--disable-background-networking",
                "--disable-component-update", "--disable-sync", "--mute-audio", "about:blank"]
        if os.geteuid() == 0:
            # Chromium refuses to run as root with its sandbox (CI containers run the tests as root).
            args.insert(1, "--no-sandbox")
        self.log = tempfile.TemporaryFile()
        # close_fds=False: fds 3 and 4 made in preexec_fn must survive to exec (the other pipe ends and Python's
        # own fds are close-on-exec).
        self.proc = subprocess.Popen(args, stdin=subprocess.DEVNULL, stdout=self.log, stderr=self.log,
                                     preexec_fn=fds_3_and_4, close_fds=False)
        os.close(to_browser_r)
        os.close(from_browser_w)
        self.session = None
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()
        try:
            target = self.call("Target.createTarget", url="about:blank", session=False)["targetId"]
            self.session = self.call("Target.attachToTarget", targetId=target, flatten=True,
                                     session=False)["sessionId"]
            for domain in ("Page", "Runtime", "Log"):
                self.call(f"{domain}.enable")
            self.call("Emulation.setDeviceMetricsOverride", width=VIEWPORT[0], height=VIEWPORT[1],
                      deviceScaleFactor=1, mobile=False)
        except BaseException:
            self.close(wait_s=0)
            raise

    def _read(self):
        buf = b""
        while True:
            try:
                chunk = os.read(self.from_browser, 1 << 16)
            except OSError:
                chunk = b""
            if not chunk:
                self.replies.put(None)
                return
            buf += chunk
            *messages, buf = buf.split(b"\0")
            for m in messages:
                msg = json.loads(m)
                if "id" in msg:
                    self.replies.put(msg)
                elif msg.get("sessionId") == self.session:
                    self.events.append(msg)

    def left(self) -> float:
        left = self.deadline - time.monotonic()
        if left <= 0:
            raise TimeoutError(f"the browser took more than {TIMEOUT_S} s")
        return left

    def call(self, method: str, session=True, **params):
        self.next_id += 1
        msg = {"id": self.next_id, "method": method, "params": params}
        if session:
            msg["sessionId"] = self.session
        try:
            os.write(self.to_browser, json.dumps(msg).encode() + b"\0")
        except OSError as e:
            raise RuntimeError(f"Chromium is gone ({e}) before {method}: {self.output()}") from None
        while True:
            try:
                reply = self.replies.get(timeout=self.left())
            except queue.Empty:
                raise TimeoutError(f"no reply to {method} within {TIMEOUT_S} s") from None
            if reply is None:
                raise RuntimeError(f"Chromium exited during {method}: {self.output()}")
            if reply["id"] == self.next_id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply["result"]

    def js(self, expression: str, wait=False):
        """The value of a JavaScript expression in the page (awaited when it is a promise and `wait`)."""
        r = self.call("Runtime.evaluate", expression=expression, returnByValue=True, awaitPromise=wait)
        if "exceptionDetails" in r:
            raise RuntimeError(f"{expression}: {r['exceptionDetails']}")
        return r["result"].get("value")

    def until(self, expression: str, what: str):
        """Polls until the expression is truthy."""
        while not self.js(expression):
            if self.deadline - time.monotonic() <= 0:
                raise TimeoutError(f"waited {TIMEOUT_S} s for {what}")
            time.sleep(0.05)

    def open(self, url: str):
        seen = len(self.events)
        self.call("Page.navigate", url=url)
        while not any(e["method"] == "Page.loadEventFired" for e in self.events[seen:]):
            self.left()
            time.sleep(0.02)

    def painted(self):
        """After two animation frames: what the page shows now has been painted."""
        self.js("new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))", wait=True)

    def screenshot(self) -> Image.Image:
        data = self.call("Page.captureScreenshot", format="png")["data"]
        return Image.open(io.BytesIO(base64.b64decode(data))).convert("RGB")

    def click(self, x: float, y: float):
        for kind in ("mouseMoved", "mousePressed", "mouseReleased"):
            self.call("Input.dispatchMouseEvent", type=kind, x=x, y=y, button="left", clickCount=1)

    def key(self, name: str, code: int):
        for kind in ("keyDown", "keyUp"):
            self.call("Input.dispatchKeyEvent", type=kind, key=name, code=name, windowsVirtualKeyCode=code)

    def errors(self):
        """What the page logged as an error: uncaught exceptions, console.error, and the browser's own log entries
        of level error (a file that is not there, ...)."""
        out = []
        for e in self.events:
            p = e.get("params", {})
            if e["method"] == "Runtime.exceptionThrown":
                d = p["exceptionDetails"]
                out.append(f"exception: {d.get('exception', {}).get('description') or d.get('text')}")
            elif e["method"] == "Runtime.consoleAPICalled" and p.get("type") == "error":
                out.append("console.error: " + " ".join(str(a.get("value", a.get("description"))) for a in p["args"]))
            elif e["method"] == "Log.entryAdded" and p["entry"]["level"] == "error":
                entry = p["entry"]
                out.append(f"log ({entry.get('source')}): {entry.get('text')} {entry.get('url', '')}".rstrip())
        return out

    def output(self) -> str:
        self.log.seek(0)
        return self.log.read().decode(errors="replace")[-2000:]

    def close(self, wait_s=5):
        """Asks the browser to close, and kills it after `wait_s` seconds."""
        try:
            os.write(self.to_browser, json.dumps({"id": 0, "method": "Browser.close"}).encode() + b"\0")
        except OSError:
            pass
        try:
            self.proc.wait(timeout=wait_s)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        self.reader.join(timeout=5)  # it ends at the end of the browser's output, before its fd is closed
        for fd in (self.to_browser, self.from_browser):
            os.close(fd)
        self.log.close()


@pytest.fixture(scope="session")
def chromium() -> str:
    binary = chromium_binary()
    if binary is None:
        pytest.skip("no Chromium (chromium, chromium-browser or google-chrome on PATH): apt-get install chromium")
    return binary


@pytest.fixture
def browser(chromium, tmp_path):
    t0 = time.monotonic()
    b = Browser(chromium, tmp_path / "profile", t0 + TIMEOUT_S)
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


def player_state(b: Browser):
    return b.js(f"""(() => {{ const p = {PLAYER}, img = p.querySelector('img.clip'),
        box = r => (r => [r.left, r.top, r.width, r.height])(r.getBoundingClientRect());
        return {{ src: img.getAttribute('src'), ready: img.complete && img.naturalWidth > 0,
                  caption: p.querySelector('.caption').textContent, value: p.querySelector('.slider').value,
                  max: p.querySelector('.slider').max, img: box(img), slider: box(p.querySelector('.slider')),
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
    b.until(f"{PLAYER}.querySelector('img.clip').complete", "the first image")
    b.painted()
    loaded_s = time.monotonic() - t0
    s0 = player_state(b)
    shot0 = b.screenshot()
    # Real input: a click at three quarters of the slider's track moves its thumb there.
    x, y, w, h = s0["slider"]
    b.click(x + 0.75 * w, y + h / 2)
    b.until(f"{PLAYER}.querySelector('img.clip').complete", "the clicked frame")
    b.painted()
    s1 = player_state(b)
    shot1 = b.screenshot()
    # The focused slider's arrow key: one frame on (or back, at the end).
    step = ("ArrowLeft", 37) if s1["value"] == s1["max"] else ("ArrowRight", 39)
    b.key(*step)
    b.until(f"{PLAYER}.querySelector('img.clip').complete", "the next frame")
    b.painted()
    s2 = player_state(b)
    shot2 = b.screenshot()
    # The error view of the same frame.
    x, y, w, h = s2["error"]
    b.click(x + w / 2, y + h / 2)
    b.until(f"{PLAYER}.querySelector('img.clip').complete", "the error view")
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
    assert s1["src"] != s0["src"] and "/frame_" in s1["src"]
    assert abs(int(s2["value"]) - int(s1["value"])) == 1, (s1, s2)
    assert s3["value"] == s2["value"] and frame_of(s3["caption"]) == frame_of(s2["caption"]), (s2, s3)
    assert "/error_" in s3["src"], s3
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
