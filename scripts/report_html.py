"""report.html of a lodbench results folder: plot.py's tables and figures, a player per transition clip, the manifest.

plot.py computes the tables and figures once and hands them here (report.md shows the same ones), with the answer
the page leads with as the binary wrote it (the folder's answer.json, src/results/answer/). The page is
self-contained: inline style and script, and the folder's own files by relative paths (`figures/...`, `clips/...`),
so the folder can be moved, archived or opened from disk without a network.

Players: `lodbench clips RUN_DIR` (a run made with `--dump-frames --dump-transitions`) writes `RUN_DIR/clips/`:
index.json and, per clip (one transition of one scene), `<clip>/frame_NNNNN.png` (the reference's and each
method's frame side by side, labelled) and `<clip>/error_NNNNN.png` (each method's error heat-map at the same
places), plus animations of it (`<clip>.png`, an animated PNG, or `<clip>.gif`, and with ffmpeg `<clip>.mp4`).
One image holds every method, so the methods are in sync by construction; the player steps, plays or slides through
the clip's frames and toggles frame and error view at the same frame. A clip made with `lodbench clips --mp4 only`
has no frame images (index.json's `frame_images` and `error_images` null): its MP4, the frame grid over the error
grid, is the player's source, each frame shown by seeking to its middle and the view by which half is shown. An
experiment folder's runs get players too (`runs/<run>/clips/`).
"""
import html
import json
import re
from pathlib import Path, PurePosixPath
from urllib.parse import quote

from PIL import Image

from lodbench_results import EXPERIMENT_JSON, INDEX_JSON, RUN_JSON, RUNS_DIR, sig3

# The animations `lodbench clips` may write beside a clip's frames (index.json's key, what the link says); any may
# be null (no MP4 without ffmpeg).
MEDIA = (("apng", "animated PNG"), ("gif", "GIF"), ("mp4", "MP4"))

# What a clip of index.json must have: per-frame lists of the same length as `frames`, and its name and scene.
PER_FRAME = ("frame_images", "error_images", "k", "t_instances")

HOW_TO_GET_CLIPS = ("No transition clips in this folder. For a player per transition: run with "
                    "<code>lodbench run ... --dump-frames --dump-transitions --out FOLDER</code>, then "
                    "<code>lodbench clips FOLDER</code>, then <code>python3 scripts/plot.py FOLDER</code> again.")


def esc(v) -> str:
    return html.escape("" if v is None else str(v), quote=True)


def url(rel: str) -> str:
    """A relative path as a URL attribute value: percent-quoted (names may hold `#`, `?`, `%` or spaces)."""
    return quote(rel, safe="/=,+-_.~()")


def index_locations(folder: Path):
    """(prefix, clips folder) of a results folder: its own clips/ and, in an experiment folder, each run's."""
    out = [("", folder / "clips")]
    if (folder / RUNS_DIR).is_dir():
        out += [(f"runs/{d.name}/", d / "clips") for d in sorted((folder / RUNS_DIR).iterdir()) if d.is_dir()]
    return [(prefix, d) for prefix, d in out if (d / INDEX_JSON).exists()]


def load_clips(folder: Path):
    """The clips of `folder` (see the module's docstring) as a list, each image's path made relative to the folder
    and URL-quoted, or None without any clips/index.json. Raises ValueError naming the problem when an index.json
    is malformed or refers to an image that is not there."""
    found = index_locations(folder)
    if not found:
        return None
    clips = []
    for prefix, d in found:
        where = f"{prefix}clips/index.json"
        try:
            index = json.loads((d / INDEX_JSON).read_text())
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
            raise ValueError(f"{where}: not readable JSON ({e}); rerun `lodbench clips`") from None
        if not isinstance(index, dict) or not isinstance(index.get("clips"), list):
            raise ValueError(f"{where}: expected an object with a \"clips\" list; rerun `lodbench clips`")
        f = index.get("fps", 10)
        if isinstance(f, bool) or not isinstance(f, (int, float)) or not 0 < f <= 240:
            raise ValueError(f"{where}: fps {f!r} is not a frame rate")
        for n, clip in enumerate(index["clips"]):
            clip = check_clip(clip, n, where, prefix, d, index.get("run"))
            clip["fps"] = f
            clip["heatmap_full_scale"] = index.get("heatmap_full_scale")
            clips.append(clip)
    return clips


def check_clip(clip, n, where, prefix, clips_dir: Path, run):
    """One clip of an index.json, checked and with its paths relative to the results folder."""
    if not isinstance(clip, dict):
        raise ValueError(f"{where}: clip {n} is not an object")
    name = clip.get("name")
    if not isinstance(name, str) or not name:
        raise ValueError(f"{where}: clip {n} has no name")
    what = f"{where}: clip {name}"
    if not isinstance(clip.get("scene"), str):
        raise ValueError(f"{what}: no scene")
    frames = clip.get("frames")
    if not isinstance(frames, list) or not frames or not all(isinstance(f, int) and not isinstance(f, bool)
                                                               for f in frames):
        raise ValueError(f"{what}: \"frames\" is not a non-empty list of frame numbers")
    movie = clip.get("frame_images") is None and clip.get("error_images") is None
    for key in PER_FRAME:
        v = clip.get(key)
        if movie and key.endswith("_images"):
            continue
        if not isinstance(v, list) or len(v) != len(frames):
            raise ValueError(f"{what}: \"{key}\" is not a list of {len(frames)} entries, one per frame")
    for f, k in zip(frames, clip["k"]):
        if k is not None and (isinstance(k, bool) or not isinstance(k, (int, float))):
            raise ValueError(f"{what}: k {k!r} of frame {f} is not a number or null")
    size = None
    if clip.get("width") is not None or clip.get("height") is not None:
        size = (clip.get("width"), clip.get("height"))
        if not all(isinstance(v, int) and not isinstance(v, bool) and v > 0 for v in size):
            raise ValueError(f"{what}: width and height {size} are not pixel counts")
    out = dict(clip)
    if movie:
        if not clip.get("mp4") or size is None:
            raise ValueError(f"{what}: no frame images, and no MP4 with its width and height to play instead; "
                             "rerun `lodbench clips`")
        out["frame_images"] = out["error_images"] = None
    else:
        for key in ("frame_images", "error_images"):
            out[key], size = clip_images(clip, key, size, what, prefix, clips_dir)
    out["width"], out["height"] = size
    for key, _ in MEDIA:
        rel = clip.get(key)
        out[key] = None if rel is None else image_path(rel, what, key, prefix, clips_dir)
    out["movie"] = out["mp4"] if movie else None
    out["run"] = run
    out["prefix"] = prefix
    return out


def clip_images(clip, key, size, what, prefix, clips_dir: Path):
    """The checked URLs of a clip's frame or error images (`key`), and their common size (`size` when given)."""
    paths = []
    for f, rel in zip(clip["frames"], clip[key]):
        p = image_path(rel, what, f"{key[:-7]} image of frame {f}", prefix, clips_dir)
        try:
            with Image.open(clips_dir / rel) as im:
                got = im.size
        except OSError as e:
            raise ValueError(f"{what}: {prefix}clips/{rel}: not an image ({e})") from None
        size = size or got
        if got != size:
            raise ValueError(f"{what}: {prefix}clips/{rel} is {got[0]}x{got[1]} pixels, the clip's images "
                             f"{size[0]}x{size[1]}")
        paths.append(p)
    return paths, size


def image_path(rel, what, role, prefix, clips_dir: Path) -> str:
    """`rel` (a path in index.json, relative to clips/) checked to be a file under clips/; returned as a URL
    relative to the results folder."""
    if not isinstance(rel, str) or not rel:
        raise ValueError(f"{what}: the {role} is {rel!r}, not a path")
    p = PurePosixPath(rel)
    if p.is_absolute() or ".." in p.parts or "\\" in rel:
        raise ValueError(f"{what}: the {role} {rel!r} is not a path inside clips/")
    if not (clips_dir / p).is_file():
        raise ValueError(f"{what}: the {role}, {prefix}clips/{rel}, is missing; rerun `lodbench clips`")
    return url(f"{prefix}clips/{rel}")


def manifest(folder: Path):
    """What the folder's results were made with: {"experiment": experiment.json or None, "runs": [(label,
    run.json)]}, the folder's own run.json and each run folder's of an experiment (runs/*/run.json). Raises
    ValueError on a run.json that is not JSON."""
    runs = []
    paths = [folder / RUN_JSON]
    if (folder / RUNS_DIR).is_dir():
        paths += sorted((folder / RUNS_DIR).glob(f"*/{RUN_JSON}"))
    for p in paths:
        if p.is_file():
            runs.append((p.parent.relative_to(folder).as_posix() if p.parent != folder else folder.name,
                         read_json(p, folder)))
    experiment = read_json(folder / EXPERIMENT_JSON, folder) if (folder / EXPERIMENT_JSON).is_file() else None
    return {"experiment": experiment, "runs": runs}


def read_json(path: Path, folder: Path):
    try:
        v = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise ValueError(f"{path.relative_to(folder)}: not readable JSON ({e})") from None
    if not isinstance(v, dict):
        raise ValueError(f"{path.relative_to(folder)}: not a JSON object")
    return v


def is_number(cell: str) -> bool:
    try:
        float(cell)
        return cell.strip() != ""
    except ValueError:
        return False


def anchor(text: str) -> str:
    return "".join(c if c.isalnum() else "-" for c in text.lower()).strip("-")


def table(columns, cells) -> str:
    head = "".join(f"<th>{esc(c).replace('_', '_<wbr>')}</th>" for c in columns)
    body = "\n".join("<tr>" + "".join(f'<td class="num">{esc(v)}</td>' if is_number(v) else f"<td>{esc(v)}</td>"
                                      for v in row) + "</tr>" for row in cells)
    return f'<div class="scroll"><table>\n<thead><tr>{head}</tr></thead>\n<tbody>\n{body}\n</tbody></table></div>'


def player(i: int, clip) -> str:
    """The markup of one clip's player, showing its first frame before the script runs (and without it)."""
    n = len(clip["frames"])
    lods = f" ({clip['lods']})" if clip.get("lods") else ""
    span = (f", frames {clip['first_frame']}-{clip['last_frame']}"
            if clip.get("first_frame") is not None and clip.get("last_frame") is not None else "")
    count = f", count {clip['count']}" if clip.get("count") is not None else ""
    run = f"{clip['prefix'].rstrip('/')}: " if clip["prefix"] else ""
    title = f"{run}{clip['scene']}{count}: transition {clip.get('transition', '?')}{lods}{span}"
    methods = clip.get("methods") or []
    full = clip.get("heatmap_full_scale")
    heat = f"; error view: full scale at {esc(full)}" if full is not None else ""
    links = [f'<a href="{esc(clip[key])}">{what}</a>' for key, what in MEDIA if clip[key]]
    if not clip["mp4"]:
        links.append("no MP4 (made without ffmpeg, or with --mp4 off)")
    return f"""<section class="player" id="clip-{esc(anchor(clip['prefix'] + clip['name']))}" data-clip="{i}">
<h4>{esc(title)}</h4>
<p class="note">{esc(clip['name'])}: {n} frames of {esc(', '.join(methods)) or 'the methods'} (labelled in the
image){heat}. {' &middot; '.join(links)}</p>
<div class="controls">
<button type="button" class="prev" title="previous frame">&#9664; step</button>
<button type="button" class="play" title="play or pause">&#9654; play</button>
<button type="button" class="next" title="next frame">step &#9654;</button>
<input type="range" class="slider" min="0" max="{n - 1}" step="1" value="0" aria-label="frame of {esc(clip['name'])}">
<span class="views" role="radiogroup" aria-label="view">
<label><input type="radio" name="view-{i}" value="frame" checked> frame</label>
<label><input type="radio" name="view-{i}" value="error"> error</label>
</span>
</div>
<p class="caption" aria-live="polite">{esc(caption(clip, 0))}</p>
<div class="frame">{shown(clip)}</div>
</section>"""


def shown(clip) -> str:
    """What a player shows: its first frame image, or its MP4 (the frame grid over the error grid) in a box one grid
    high, at the first frame's middle."""
    if clip["movie"]:
        w, h = clip["width"], clip["height"]
        return (f'<div class="movie" style="--w: {w}px; aspect-ratio: {w} / {h}" title="click: actual pixels / fit">'
                f'<video class="clip" src="{esc(clip["movie"])}#t={0.5 / clip["fps"]:.4f}" width="{w}" '
                f'height="{2 * h}" muted playsinline preload="metadata"></video></div>')
    return (f'<img class="clip" src="{esc(clip["frame_images"][0])}" width="{clip["width"]}" height="{clip["height"]}"'
            f' alt="{esc(clip["name"])}, frame {clip["frames"][0]}" title="click: actual pixels / fit">')


def caption(clip, j: int) -> str:
    """The caption of frame index j (the script writes the same for the others)."""
    k = clip["k"][j]
    return (f"frame {clip['frames'][j]} ({j + 1}/{len(clip['frames'])}), "
            f"k={'n/a' if k is None else f'{k:.3f}'}, t-instances {clip['t_instances'][j]}")


def manifest_html(m) -> str:
    out = []
    e = m["experiment"]
    if e is not None:
        rows = [(k, e.get(k)) for k in ("name", "description", "file")]
        # "variables" (one per sweep); folders of older builds wrote one "variable".
        swept = e.get("variables") or ([e["variable"]] if e.get("variable") else [])
        rows.append(("swept", " x ".join(swept) if swept else None))
        rows.append(("runs", len(e.get("runs") or [])))
        out.append("<h3>experiment.json</h3>" + key_values(rows) + details("experiment.json", e))
    if not m["runs"]:
        out.append("<p>No run.json in this folder.</p>")
    for label, run in m["runs"]:
        a = run.get("adapter") or {}
        cfg = run.get("config") or {}
        rows = [("status", run.get("status")), ("adapter", a.get("name")), ("backend", a.get("backend")),
                ("device type", a.get("device_type")), ("driver", a.get("driver")),
                ("driver info", a.get("driver_info")), ("lodbench", run.get("lodbench_version")),
                ("git commit", run.get("git_commit")), ("seed", run.get("seed")),
                ("start", run.get("start_time")), ("end", run.get("end_time")),
                ("timing", run.get("timing_source")),
                ("scenes", ", ".join(map(str, cfg.get("scenes") or []))),
                ("methods", ", ".join(map(str, cfg.get("methods") or [])))]
        if run.get("error"):
            rows.insert(1, ("error", run["error"]))
        out.append(f"<h3>{esc(label)}/run.json</h3>" + key_values(rows) + details("config (the run's flags)", cfg))
    return "\n".join(out)


def tune_manifest(meta) -> str:
    """What a tune folder's tune.json says it was made with, as the manifest section."""
    a = meta.get("adapter") or {}
    rows = [("scene", meta.get("scene")), ("adapter", a.get("name")), ("driver", a.get("driver")),
            ("lodbench", meta.get("lodbench_version")), ("git commit", meta.get("git_commit")),
            ("size", f"{meta.get('width')}x{meta.get('height')}"), ("vertical field of view", meta.get("fov_y_deg"))]
    return "<h3>tune.json</h3>" + key_values(rows) + details("settings", meta.get("settings"))


def key_values(rows) -> str:
    return '<table class="kv">' + "".join(f"<tr><th>{esc(k)}</th><td>{esc(v)}</td></tr>" for k, v in rows
                                          if v not in (None, "")) + "</table>"


def details(summary: str, value) -> str:
    return f"<details><summary>{esc(summary)}</summary><pre>{esc(json.dumps(value, indent=2))}</pre></details>"


def script_json(value) -> str:
    """JSON safe inside <script>: no `<`, `>` or `&` that could end the element."""
    return (json.dumps(value, separators=(",", ":")).replace("<", "\\u003c").replace(">", "\\u003e")
            .replace("&", "\\u0026"))


def value_html(v) -> str:
    """A part of answer.json's sentences and rows: a str as it is, a number (an object: text, file, row, cols, fmt,
    op) as a span whose data- attributes say which CSV cells it shows."""
    if isinstance(v, str):
        return esc(v)
    return (f'<span class="v" data-file="{esc(v["file"])}" data-row="{esc(json.dumps(v["row"]))}" '
            f'data-cols="{esc(",".join(v["cols"]))}" data-fmt="{esc(v["fmt"])}" data-op="{esc(v["op"])}">'
            f'{esc(v["text"])}</span>')


def answer_html(a) -> str:
    """One block's answer: its sentences, then its decision table (under `a["columns"]`, answer.json's)."""
    sentences = "".join(f'<p class="sentence">{"".join(value_html(part) for part in s)}</p>' for s in a["sentences"])
    head = "".join(f"<th>{esc(c)}</th>" for c in a["columns"])
    body = "\n".join("<tr>" + "".join(
        f'<td class="num">{value_html(c)}</td>' if i else f"<th>{value_html(c)}</th>" for i, c in enumerate(row))
        + "</tr>" for row in a["rows"])
    return (f'<section class="answer"><h2>{esc(a["name"])}</h2>{sentences}'
            f'<table class="decision"><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table></section>')


def figure_html(name, cap) -> str:
    src = esc(url(f"figures/{name}"))
    return (f'<figure id="fig-{esc(anchor(name))}"><a href="{src}"><img src="{src}" alt="{esc(cap)}"></a>'
            f"<figcaption>{esc(cap)}</figcaption></figure>")


# What the pops are measured in, without a calibration (run.json's config.calibration null or absent).
NOT_CALIBRATED = ("Not calibrated: pops are lodpop (RMS of the frame's change), not a threshold a person measured; "
                  "`lodbench calibrate` and `--calibration` give JNDs (docs/calibration.md)")


def calibration_line(cal):
    """What a run's pops are measured in, from its run.json's config.calibration (None or an object: path, metric,
    threshold, ci95, simulated, label, display): (text, simulated). The text marks code with backticks."""
    if not isinstance(cal, dict):
        return NOT_CALIBRATED, False
    ci = cal.get("ci95") if isinstance(cal.get("ci95"), list) and len(cal["ci95"]) == 2 else [None, None]
    interval = (f" (95 % {sig3_or_dash(ci[0])} to {sig3_or_dash(ci[1])})" if None not in ci
                else " (no 95 % interval)")
    text = (f"Pops in JNDs: 1 JND = {cal.get('metric') or 'lodpop'} {sig3_or_dash(cal.get('threshold'))}{interval}, "
            f"from {cal.get('path', '?')}: {cal.get('label', '?')}")
    d = cal.get("display")
    if isinstance(d, dict) and d.get("width_px") and d.get("height_px"):
        hz = f" at {d['refresh_hz']:g} Hz" if isinstance(d.get("refresh_hz"), (int, float)) else ""
        text += f"; measured for a {d['width_px']}x{d['height_px']} display{hz}"
    simulated = cal.get("simulated") is True
    if simulated:
        text += ". Simulated observer, not human data"
    return text, simulated


def calibration_lines(m):
    """What the pops of a folder's runs (m: manifest()'s, its runs [(label, run.json)]) are measured in:
    [(text, simulated)], one line where every run says the same (or there is no run.json), else a line per
    calibration naming its runs."""
    groups = {}
    for label, run in m["runs"]:
        cal = (run.get("config") or {}).get("calibration")
        groups.setdefault(json.dumps(cal, sort_keys=True), (cal, []))[1].append(label)
    if len(groups) <= 1:
        return [calibration_line(next(iter(groups.values()))[0] if groups else None)]
    return [(f"{', '.join(labels)}: {text}", simulated)
            for text, simulated, labels in ((*calibration_line(cal), labels) for cal, labels in groups.values())]


def path_fps(m) -> list:
    """The frame rates visible pops per minute are counted at (run.json's config.path_fps) of a folder's runs (m:
    manifest()'s), each once; none for runs of a lodbench before pop events."""
    return sorted({(run.get("config") or {}).get("path_fps") for _, run in m["runs"]} - {None})


def sig3_or_dash(x) -> str:
    """A number of run.json to 3 significant figures (lodbench_results.sig3), `-` where it is not a number."""
    return sig3(float(x)) if isinstance(x, (int, float)) and not isinstance(x, bool) else "-"


def with_code(text: str) -> str:
    """Escaped text with its `backticked` parts as <code>."""
    return re.sub(r"`([^`]*)`", r"<code>\1</code>", esc(text))


def pops_html(lines, columns, cells, note, open_table=True) -> str:
    """The visible-pops section that follows the answer: what the pops are measured in (calibration_lines()'s),
    then the table (columns, rows of cell texts; None: nothing measured) and its note (text, code in backticks)."""
    out = ['<section id="pops"><h2>Visible pops</h2>']
    out += [f'<p class="unit{" simulated" if simulated else ""}">{with_code(text)}</p>' for text, simulated in lines]
    if cells is not None:
        out.append(f'<details open><summary>visible pops per minute, by method</summary>{table(columns, cells)}'
                   '</details>' if open_table else
                   f'<details><summary>visible pops per minute, by method ({len(cells)} rows)</summary>'
                   f'{table(columns, cells)}</details>')
    out.append(f'<p class="note">{with_code(note)}</p></section>')
    return "\n".join(out)


ANSWER_NOTE = ("Costs are paired round by round within the run and called different only where the 95 % interval "
               "excludes 1; the budget is the run's <code>--budget-lodpop</code>, else half the hard switch's "
               "largest lodpop; full precision in summary.csv and pairs.csv.")
TUNE_NOTE = ("The worst popping is over tune's views from each switch to the end of its dense check; the engines' "
             "values are those of engines/, for the model at the bounding sphere's centre; full precision in "
             "tune.json and rules.csv.")


def page(title: str, answers, headline, tables, figures, clips, runs, players=True, note=ANSWER_NOTE,
         pops=None) -> str:
    """report.html, the answer first. `answers`: [{name, sentences, columns, rows}] (a block of the folder's
    answer.json, its columns those of answer.json: sentences as lists of parts, rows of cells, each a str or a
    number's object, value_html); `headline`: [(file in figures/, caption)], the
    figures that follow the answer; `tables`: [(heading, columns, rows of cell texts)], folded (the
    "cheapest at or below a popping" tables of an experiment open); `figures`: the other figures; `clips`:
    load_clips()'s or None; `runs`: manifest()'s, or the manifest section's HTML; `players`: False leaves out the
    players' section (a tune folder has no clips to play); `pops`: pops_html()'s section, after the answer."""
    nav = [("answer", "Answer"), ("pops", "Visible pops"), ("headline", "Cost and popping"),
           ("players", "Transition players"), ("tables", "Tables"), ("figures", "More figures"),
           ("manifest", "Manifest")]
    nav = [n for n in nav if (players or n[0] != "players") and (figures or n[0] != "figures")
           and (pops or n[0] != "pops")]
    body = [f"<h1>{esc(title)}</h1>",
            '<nav>' + " ".join(f'<a href="#{a}">{esc(t)}</a>' for a, t in nav) + "</nav>",
            '<div id="answer">']
    body += [answer_html(a) for a in answers] or ['<p class="note">summary.csv has no rows.</p>']
    body.append(f'<p class="note">{note}</p></div>')
    if pops:
        body.append(pops)
    body.append('<h2 id="headline">Cost and popping</h2>')
    body += [figure_html(name, cap) for name, cap in headline] or \
        ['<p class="note">No popping measured (a run with <code>--quality off</code>?).</p>']
    if players:
        body.append('<h2 id="players">Transition players</h2>')
    if not players:
        pass  # a tune folder: nothing to play
    elif not clips:
        body.append(f'<p class="note">{HOW_TO_GET_CLIPS}</p>' if clips is None else
                    '<p class="note">clips/index.json lists no clips (no transition on the path?).</p>')
    else:
        body.append('<p class="note">Each image holds the reference and every method side by side, so they step '
                    'in sync. Slider, arrow keys on it, or the buttons step; <em>error</em> shows each method\'s '
                    'error heat-map at the same frame; k is the mean blend factor of the instances in '
                    'transition. A click on an image toggles fit and actual pixels.</p>')
        scene = None
        for i, clip in enumerate(clips):
            if (clip["prefix"], clip["scene"]) != scene:
                scene = (clip["prefix"], clip["scene"])
                body.append(f'<h3 class="scene">{esc(clip["prefix"] + clip["scene"])}</h3>')
            body.append(player(i, clip))
    body.append('<h2 id="tables">Tables</h2>')
    for heading, columns, cells in tables:
        opened = " open" if "cheapest at or below" in heading else ""
        body.append(f'<details id="{esc(anchor(heading))}"{opened}><summary>{esc(heading)}</summary>'
                    f"{table(columns, cells)}</details>")
    if figures:
        body.append('<h2 id="figures">More figures</h2>')
        body += [figure_html(name, cap) for name, cap in figures]
    body += ['<h2 id="manifest">Manifest</h2>', runs if isinstance(runs, str) else manifest_html(runs)]
    data = {"clips": [{k: c[k] for k in ("name", "fps", "frames", "k", "t_instances", "frame_images",
                                         "error_images", "movie")} for c in clips or []]}
    return f"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{esc(title)}</title>
<style>{STYLE}</style>
</head>
<body>
<main>
{chr(10).join(body)}
</main>
<script type="application/json" id="clip-data">{script_json(data)}</script>
<script>{SCRIPT}</script>
</body>
</html>
"""


STYLE = """
body { margin: 0; font: 14px/1.45 system-ui, sans-serif; color: #1d1d1f; background: #fafafa; }
main { max-width: 1340px; margin: 0 auto; padding: 12px 20px 40px; }
h1 { font-size: 22px; margin: 8px 0; }
h2 { font-size: 18px; margin: 28px 0 8px; border-bottom: 1px solid #ddd; padding-bottom: 4px; }
h3 { font-size: 15px; margin: 18px 0 6px; }
nav a { margin-right: 14px; }
a { color: #0b57d0; }
code, pre { font: 12px/1.4 ui-monospace, monospace; }
pre { background: #f0f0f0; padding: 8px; overflow: auto; max-height: 420px; }
.note { color: #555; margin: 4px 0; }
.scroll { overflow-x: auto; }
table { border-collapse: collapse; background: #fff; font-size: 12.5px; }
th, td { border: 1px solid #ddd; padding: 2px 7px; text-align: left; white-space: nowrap; }
thead th { white-space: normal; vertical-align: bottom; }
details { margin: 6px 0; }
details > summary { cursor: pointer; font-weight: 600; }
.answer { margin: 4px 0 14px; }
.answer h2 { margin-top: 10px; }
#pops p.unit { margin: 4px 0; max-width: 1100px; }
#pops p.unit.simulated { color: #8a1c1c; font-weight: 600; }
.sentence { font-size: 15px; margin: 4px 0; max-width: 1100px; }
.sentence .v, table.decision .v { font-variant-numeric: tabular-nums; }
table.decision { font-size: 13px; margin-top: 6px; }
table.decision tbody th { font-weight: 600; background: #fafafa; }
thead th { background: #f0f0f0; position: sticky; top: 0; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
table.kv th { background: #f6f6f6; font-weight: 600; }
table.kv td { white-space: normal; overflow-wrap: anywhere; }
figure { margin: 12px 0 22px; }
figure img { max-width: 100%; height: auto; border: 1px solid #e4e4e4; background: #fff; }
figcaption { color: #555; }
.player { background: #fff; border: 1px solid #ddd; border-radius: 6px; padding: 8px 12px 12px; margin: 10px 0 18px; }
.player h4 { font-size: 14px; margin: 4px 0; }
.controls { display: flex; flex-wrap: wrap; align-items: center; gap: 8px; margin: 6px 0; }
.controls .slider { flex: 1 1 300px; }
.controls button { font: inherit; padding: 2px 10px; }
.caption { font-variant-numeric: tabular-nums; margin: 2px 0 6px; }
.player .frame { overflow-x: auto; }
.player img.clip { display: block; max-width: 100%; height: auto; background: #000; cursor: zoom-in; }
.player img.clip.actual { max-width: none; cursor: zoom-out; }
.player .movie { width: min(100%, var(--w)); overflow: hidden; background: #000; cursor: zoom-in; }
.player .movie.actual { width: var(--w); cursor: zoom-out; }
.player .movie video.clip { display: block; width: 100%; height: auto; }
.player .movie.error video.clip { transform: translateY(-50%); }
.player.broken .caption { color: #b00020; }
"""

# The players. Each preloads its clip's frame and error images when it comes near the viewport (all of a page's
# clips at once could be hundreds of megabytes), so stepping and playback never wait for the disk; a missing image
# is logged with console.error and shown in the caption. A player of an MP4 (`clips --mp4 only`) preloads the whole
# MP4 instead and shows frame j by seeking to (j + 0.5) / fps. scripts/tests/test_report_browser.py waits on a
# player's data-total/data-settled (its images or its MP4, and those loaded or failed) and calls its preload().
SCRIPT = """
(function () {
  "use strict";
  var data = JSON.parse(document.getElementById("clip-data").textContent);
  var players = document.querySelectorAll(".player");
  function setup(el) {
    var clip = data.clips[Number(el.dataset.clip)];
    var img = el.querySelector("img.clip"), slider = el.querySelector(".slider");
    var movie = el.querySelector("video.clip"), box = el.querySelector(".movie");
    var caption = el.querySelector(".caption"), play = el.querySelector(".play");
    var n = clip.frames.length, index = 0, view = "frame", timer = null, cache = null, missing = [];
    function settled() { el.dataset.settled = String(Number(el.dataset.settled || 0) + 1); }
    function fail(src) {
      if (missing.indexOf(src) >= 0) return;
      missing.push(src);
      el.classList.add("broken");
      console.error("lodbench report: cannot load " + src);
      show(index);
    }
    el.preload = function () {
      if (cache) return;
      cache = [];
      if (movie) {
        el.dataset.total = "1";
        if (movie.readyState >= 2) settled();
        else movie.addEventListener("loadeddata", settled, { once: true });
        movie.preload = "auto";
        return;
      }
      el.dataset.total = String(2 * n);
      ["frame_images", "error_images"].forEach(function (key) {
        clip[key].forEach(function (src) {
          var im = new Image();
          im.onerror = function () { settled(); fail(src); };
          im.onload = settled;
          im.src = src;
          cache.push(im);
        });
      });
    };
    function show(i) {
      index = Math.max(0, Math.min(n - 1, i));
      if (movie) {
        var at = (index + 0.5) / clip.fps;
        if (Math.abs(movie.currentTime - at) > 1e-4) movie.currentTime = at;
        box.classList.toggle("error", view === "error");
        movie.setAttribute("aria-label", clip.name + ", frame " + clip.frames[index] + ", " + view + " view");
      } else {
        var src = clip[view === "frame" ? "frame_images" : "error_images"][index];
        if (img.getAttribute("src") !== src) img.setAttribute("src", src);
        img.alt = clip.name + ", frame " + clip.frames[index] + ", " + view + " view";
      }
      slider.value = String(index);
      var k = clip.k[index];
      caption.textContent = "frame " + clip.frames[index] + " (" + (index + 1) + "/" + n + "), k=" +
        (k === null ? "n/a" : k.toFixed(3)) + ", t-instances " + clip.t_instances[index] +
        (missing.length ? " \\u2014 missing: " + missing.join(", ") : "");
    }
    function pause() {
      if (timer !== null) { clearInterval(timer); timer = null; }
      play.innerHTML = "&#9654; play";
    }
    play.addEventListener("click", function () {
      if (timer !== null) { pause(); return; }
      el.preload();
      if (index === n - 1) show(0);
      timer = setInterval(function () { show(index === n - 1 ? 0 : index + 1); }, 1000 / clip.fps);
      play.innerHTML = "&#10074;&#10074; pause";
    });
    el.querySelector(".prev").addEventListener("click", function () { pause(); show(index - 1); });
    el.querySelector(".next").addEventListener("click", function () { pause(); show(index + 1); });
    slider.addEventListener("input", function () { pause(); el.preload(); show(Number(slider.value)); });
    el.querySelectorAll("input[type=radio]").forEach(function (r) {
      r.addEventListener("change", function () { if (r.checked) { view = r.value; el.preload(); show(index); } });
    });
    if (movie) {
      movie.addEventListener("error", function () { settled(); fail(clip.movie); });
      box.addEventListener("click", function () { box.classList.toggle("actual"); });
    } else {
      img.addEventListener("error", function () { fail(img.getAttribute("src")); });
      img.addEventListener("click", function () { img.classList.toggle("actual"); });
    }
    show(0);
  }
  players.forEach(setup);
  if ("IntersectionObserver" in window) {
    var seen = new IntersectionObserver(function (entries) {
      entries.forEach(function (e) { if (e.isIntersecting) { e.target.preload(); seen.unobserve(e.target); } });
    }, { rootMargin: "600px" });
    players.forEach(function (el) { seen.observe(el); });
  } else {
    players.forEach(function (el) { el.preload(); });
  }
})();
"""
