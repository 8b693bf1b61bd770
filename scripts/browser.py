"""A headless Chromium driven over the DevTools protocol on a pipe (--remote-debugging-pipe: it reads commands on fd 3
and writes replies and events on fd 4, JSON messages ended by a NUL byte), standard library only: what the browser
tests of report.html (scripts/tests/test_report_browser.py) and the three.js fidelity check (scripts/three_fidelity.py)
drive."""
import base64
import fcntl
import io
import json
import os
import queue
import shutil
import subprocess
import tempfile
import threading
import time
from pathlib import Path

from PIL import Image

# The page's size unless a caller asks for another.
VIEWPORT = (1280, 900)


def chromium_binary():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        found = shutil.which(name)
        if found:
            return found
    return None


class Browser:
    """A headless Chromium and one page of it, attached as a flat session. Every wait ends at `deadline`."""

    def __init__(self, binary: str, profile: Path, deadline: float, viewport=VIEWPORT, webgl=False):
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

        self.timeout_s = deadline - time.monotonic()
        args = [binary, "--headless", "--disable-gpu", "--remote-debugging-pipe", f"--user-data-dir={profile}",
                f"--window-size={viewport[0]},{viewport[1]}", "--hide-scrollbars", "--no-first-run",
                "--no-default-browser-check", "--disable-extensions", "--disable-background-networking",
                "--disable-component-update", "--disable-sync", "--mute-audio", "about:blank"]
        if webgl:
            # WebGL without a GPU: SwiftShader, which Chromium enables for WebGL only when asked to.
            args[3:3] = ["--use-angle=swiftshader", "--enable-unsafe-swiftshader"]
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
            self.call("Emulation.setDeviceMetricsOverride", width=viewport[0], height=viewport[1],
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
            raise TimeoutError(f"the browser took more than {self.timeout_s:.0f} s")
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
                raise TimeoutError(f"no reply to {method} within {self.timeout_s:.0f} s") from None
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
                raise TimeoutError(f"waited {self.timeout_s:.0f} s for {what}")
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


