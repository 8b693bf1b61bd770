"""plot.py's report.html: the tables of report.md, every figure, a player per clip of clips/index.json, the manifest;
self-contained (only the folder's own files, by relative paths); a malformed index.json or a missing clip image is
a clear error."""
import json
import re
import shutil
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote

import pytest
from PIL import Image

SCRIPT = Path(__file__).resolve().parents[1] / "plot.py"


def plot(*folders: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(SCRIPT), *map(str, folders)], capture_output=True, text=True)


class Page(HTMLParser):
    """What a test looks at in report.html: every src and href, every tag, the report tables' cells (tables in a
    div.scroll), the players and the embedded clip data."""

    def __init__(self, text: str):
        super().__init__()
        self.refs, self.tags, self.tables, self.players = [], [], [], []
        self.in_table = self.in_cell = self.in_data = False
        self.data = ""
        self.feed(text)
        self.clips = json.loads(self.data)

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        self.tags.append((tag, a))
        self.refs += [(tag, a[k]) for k in ("src", "href") if k in a]
        if tag == "div" and a.get("class") == "scroll":
            self.in_table = True
            self.tables.append([])
        elif self.in_table and tag == "tr":
            self.tables[-1].append([])
        elif self.in_table and tag in ("td", "th"):
            self.in_cell = True
            self.tables[-1][-1].append("")
        elif tag == "section" and "player" in a.get("class", ""):
            self.players.append(a)
        elif tag == "script" and a.get("id") == "clip-data":
            self.in_data = True

    def handle_endtag(self, tag):
        if tag == "table":
            self.in_table = False
        elif tag in ("td", "th"):
            self.in_cell = False
        elif tag == "script":
            self.in_data = False

    def handle_data(self, data):
        if self.in_cell:
            self.tables[-1][-1][-1] += data
        elif self.in_data:
            self.data += data


def markdown_tables(text: str):
    """The cells of report.md's tables, header row first, the |---| line left out; the answers' decision tables
    (report.html's table.decision, checked by test_answer.py) left out."""
    tables, current = [], None
    for line in text.splitlines():
        if line.startswith("|"):
            if current is None:
                current = []
                tables.append(current)
            if not line.startswith("|---"):
                current.append([c.strip() for c in line.strip("|").split(" | ")])
        else:
            current = None
    return [t for t in tables if t[0][:2] != ["method", "frame time, ms"]]


@pytest.fixture
def folder(dump, make_clips, tmp_path) -> Path:
    """The dump run with a synthetic clips/ (two clips of 6 frames)."""
    out = tmp_path / "sweep"
    shutil.copytree(dump, out)
    make_clips(out, clips=2, frames=6)
    return out


def test_report_html_with_clips(folder):
    r = plot(folder)
    assert r.returncode == 0, r.stderr
    assert "report.html" in r.stdout
    text = (folder / "report.html").read_text()
    page = Page(text)
    # The same tables as report.md, cell for cell.
    assert page.tables == markdown_tables((folder / "report.md").read_text())
    assert [row[:2] for row in page.tables[0][1:]] == [["bunny-sweep", m] for m in ("discrete", "dither", "fsi")]
    assert "bunny-sweep: max lodpop (pose held) of each transition (its frames and the 2 after)" in text
    # Every figure, every clip image (the players' data), every GIF.
    imgs = {src for tag, src in page.refs if tag == "img"}
    for p in (folder / "figures").glob("*.png"):
        assert f"figures/{p.name}" in imgs
    index = json.loads((folder / "clips" / "index.json").read_text())
    assert len(page.players) == len(index["clips"]) == len(page.clips["clips"])
    for clip, shown in zip(index["clips"], page.clips["clips"]):
        assert shown["frame_images"] == [f"clips/{p}" for p in clip["frame_images"]]
        assert shown["error_images"] == [f"clips/{p}" for p in clip["error_images"]]
        assert shown["frames"] == clip["frames"] and shown["k"] == clip["k"]
        assert ("a", f"clips/{clip['gif']}") in page.refs and ("a", f"clips/{clip['apng']}") in page.refs
        assert f"clips/{clip['frame_images'][0]}" in imgs  # the first frame, shown before the script runs
    assert "frame 8 (1/6), k=n/a, t-instances 0" in text
    assert "no MP4 (made without ffmpeg, or with --mp4 off)" in text
    # Self-contained: no network, every reference a file of the folder (or a place in the page).
    assert not re.search(r"(https?:)?//", " ".join(ref for _, ref in page.refs))
    assert "http://" not in text and "https://" not in text
    assert not any(tag == "link" or (tag == "script" and "src" in a) for tag, a in page.tags)
    refs = [ref for _, ref in page.refs if not ref.startswith("#")]
    refs += [p for c in page.clips["clips"] for p in c["frame_images"] + c["error_images"]]
    for ref in refs:
        assert (folder / unquote(ref)).is_file(), ref
    # The manifest.
    run = json.loads((folder / "run.json").read_text())
    assert run["git_commit"] in text and run["adapter"]["name"] in text and run["start_time"] in text
    assert "<details><summary>config (the run&#x27;s flags)</summary><pre>" in text
    # report.md is as it was: no mention of the HTML or the clips.
    md = (folder / "report.md").read_text()
    assert "report.html" not in md and "clips" not in md
    # The answer first: the scene's sentences, then its decision table.
    assert md.startswith(f"# lodbench report: {folder.name}\n\n## bunny-sweep\n\nbunny-sweep: "), md[:300]
    assert "\n## Summary: time\n\n| scene | method | count |" in md


def test_report_html_without_clips(dump, tmp_path):
    folder = tmp_path / "sweep"
    shutil.copytree(dump, folder)
    r = plot(folder)
    assert r.returncode == 0, r.stderr
    text = (folder / "report.html").read_text()
    page = Page(text)
    assert page.players == [] and page.clips["clips"] == []
    assert "--dump-frames --dump-transitions" in text and "lodbench clips FOLDER" in text


def test_text_is_escaped(folder):
    index = json.loads((folder / "clips" / "index.json").read_text())
    index["clips"][0]["name"] = "<script>alert(1)</script>"
    index["clips"][0]["lods"] = "2->3 & <b>"
    (folder / "clips" / "index.json").write_text(json.dumps(index))
    assert plot(folder).returncode == 0
    text = (folder / "report.html").read_text()
    assert "<script>alert" not in text and "<b>" not in text
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in text and "2-&gt;3 &amp; &lt;b&gt;" in text
    assert Page(text).clips["clips"][0]["name"] == "<script>alert(1)</script>"


def spoil(what: str, folder: Path):
    index_path = folder / "clips" / "index.json"
    index = json.loads(index_path.read_text())
    clip = index["clips"][1]
    if what == "not json":
        index_path.write_text('{"clips": [')
        return
    if what == "no clips list":
        index = {"fps": 10}
    elif what == "k too short":
        clip["k"] = clip["k"][:-1]
    elif what == "missing image":
        (folder / "clips" / clip["error_images"][2]).unlink()
    elif what == "missing gif":
        (folder / "clips" / clip["gif"]).unlink()
    elif what == "outside clips":
        clip["frame_images"][0] = "../run.json"
    elif what == "wrong size":
        Image.new("RGB", (10, 10)).save(folder / "clips" / clip["frame_images"][1])
    elif what == "not an image":
        (folder / "clips" / clip["frame_images"][1]).write_text("not a PNG")
    index_path.write_text(json.dumps(index))


def test_an_mp4_only_clip_is_played_from_its_mp4(dump, make_clips, tmp_path):
    """`lodbench clips --mp4 only`: no frame images, the player's source is the MP4 (seeked, in a box one grid high);
    the MP4 is linked, and a clip with neither frame images nor an MP4 is refused."""
    folder = tmp_path / "movie"
    shutil.copytree(dump, folder)
    index = make_clips(folder, clips=2, frames=6, movie=True)
    r = plot(folder)
    assert r.returncode == 0, r.stderr
    page = Page((folder / "report.html").read_text())
    assert len(page.players) == 2
    videos = [a for tag, a in page.tags if tag == "video"]
    assert [v["src"] for v in videos] == [f"clips/{c['mp4']}#t=0.0500" for c in index["clips"]]
    assert all((v["width"], v["height"]) == ("480", "240") for v in videos)  # three 160x120 tiles, over three
    assert not any(tag == "img" and "clips/" in a.get("src", "") for tag, a in page.tags)
    for clip, shown in zip(index["clips"], page.clips["clips"]):
        assert shown["movie"] == f"clips/{clip['mp4']}"
        assert shown["frame_images"] is None and shown["error_images"] is None
        assert ("a", f"clips/{clip['mp4']}") in page.refs
    for v in videos:
        assert (folder / unquote(v["src"].split("#")[0])).is_file()
    index["clips"][1]["mp4"] = None
    (folder / "clips" / "index.json").write_text(json.dumps(index))
    r = plot(folder)
    assert r.returncode == 2 and "clip bunny-sweep_c1_t01: no frame images, and no MP4" in r.stderr, r.stderr


BAD_CLIPS = [
    ("not json", "clips/index.json: not readable JSON"),
    ("no clips list", "clips/index.json: expected an object with a \"clips\" list"),
    ("k too short", "clip bunny-sweep_c1_t01: \"k\" is not a list of 6 entries, one per frame"),
    ("missing image", "the error image of frame 30, clips/bunny-sweep_c1_t01/error_00030.png, is missing"),
    ("missing gif", "the gif, clips/bunny-sweep_c1_t01.gif, is missing"),
    ("outside clips", "'../run.json' is not a path inside clips/"),
    ("wrong size", "clips/bunny-sweep_c1_t01/frame_00029.png is 10x10 pixels, the clip's images 480x120"),
    ("not an image", "clips/bunny-sweep_c1_t01/frame_00029.png: not an image"),
]


@pytest.mark.parametrize("what, message", BAD_CLIPS, ids=[what for what, _ in BAD_CLIPS])
def test_bad_clips_are_an_error(folder, what, message):
    spoil(what, folder)
    r = plot(folder)
    assert r.returncode == 2, r.stdout
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {folder}: "), r.stderr
    assert message in lines[0], lines[0]
    # Nothing written: the clips are checked before the figures and reports.
    assert not (folder / "report.html").exists() and not (folder / "report.md").exists()


def test_experiment_manifest_lists_every_run(viewport_experiment, tmp_path):
    folder = tmp_path / "exp"
    shutil.copytree(viewport_experiment, folder)
    r = plot(folder)
    assert r.returncode == 0, r.stderr
    text = (folder / "report.html").read_text()
    runs = sorted((folder / "runs").glob("*/run.json"))
    assert len(runs) == 2
    for p in runs:
        assert f"<h3>runs/{p.parent.name}/run.json</h3>" in text
    assert "<h3>experiment.json</h3>" in text and "viewports" in text
    assert Page(text).tables == markdown_tables((folder / "report.md").read_text())


def test_experiment_run_clips_get_players(viewport_experiment, make_clips, tmp_path):
    """An experiment's runs/<run>/clips/ (`lodbench clips` on a run folder of it) get players too."""
    folder = tmp_path / "exp"
    shutil.copytree(viewport_experiment, folder)
    run = sorted((folder / "runs").iterdir())[0]
    make_clips(run, clips=1, frames=4)
    assert plot(folder).returncode == 0
    page = Page((folder / "report.html").read_text())
    assert len(page.players) == 1
    first = page.clips["clips"][0]["frame_images"][0]
    assert first.startswith(f"runs/{run.name}/clips/") and (folder / unquote(first)).is_file()
