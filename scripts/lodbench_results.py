"""What the scripts share about lodbench's results folders: the file names, the columns the scripts read from each
CSV, and the small readers they all use.

The names mirror src/results/files.rs (and, for the files it does not list, the commands that write them). READS
says which columns of each CSV the scripts read; scripts/tests/test_columns.py checks that each is a field of the
Rust record the file is written from, and that every column a script reads by name is declared here, so a column
renamed or removed in lodbench fails a test rather than a script (or, read with `.get`, quietly reads nothing).

A folder's answer (the sentences and decision table report.html leads with) is answer.json, written by the binary
(src/results/answer/); `part_text` and `sentence_text` read its parts. The number formats of the report's other
tables (`sig3`, `thousands`, `ratio_text`) are those of src/numbers.rs, so the two read alike. (Not in a module of
their own called `numbers`: beside the scripts, that name would hide Python's own `numbers`, which numpy imports.)

(Not called `results`: run from the repository root, Python would also find the top-level results/ folder under
that name.)
"""
import csv
import math
from pathlib import Path

# A run folder's files (src/results/files.rs), and those of `lodbench perceptual`, `tune`, `probe` and `overhead`.
FRAMES_CSV = "frames.csv"
SUMMARY_CSV = "summary.csv"
TRANSITIONS_CSV = "transitions.csv"
EVENTS_CSV = "events.csv"
ROUNDS_CSV = "rounds.csv"
PAIRS_CSV = "pairs.csv"
PERCEPTUAL_CSV = "perceptual.csv"
TUNE_CSV = "tune.csv"
RULES_CSV = "rules.csv"
PROBE_CSV = "probe.csv"
OVERHEAD_CSV = "overhead.csv"
RUN_JSON = "run.json"
# The answer of a run, experiment or merged folder (written by src/results/answer/; schema "lodbench-answer/1").
ANSWER_JSON = "answer.json"
EXPERIMENT_JSON = "experiment.json"
TUNE_JSON = "tune.json"
# The clips of a run folder: clips/index.json.
INDEX_JSON = "index.json"
# The run folders of an experiment folder.
RUNS_DIR = "runs"

# The columns the scripts read from each CSV, by name (a column of the Rust record it is written from; checked by
# scripts/tests/test_columns.py). A script that reads another column declares it here.
READS = {
    FRAMES_CSV: (
        "scene", "method", "count", "frame", "round", "gpu_ms", "cpu_ms", "t_instances", "lod_mean", "rmse", "pop",
        "lodpop", "de2000_mean", "lag_rmse",
    ),
    SUMMARY_CSV: (
        "scene", "method", "count", "frames", "baseline", "rounds",
        "gpu_ms_median", "gpu_ms_median_transition", "gpu_ms_median_steady", "gpu_ms_p5", "gpu_ms_p95",
        "cpu_ms_median", "combine_gpu_ms_median",
        "ratio_to_baseline", "ratio_to_baseline_ci95_lo", "ratio_to_baseline_ci95_hi",
        "ratio_to_baseline_transition", "ratio_to_baseline_transition_ci95_lo", "ratio_to_baseline_transition_ci95_hi",
        "ratio_to_baseline_steady", "ratio_to_baseline_steady_ci95_lo", "ratio_to_baseline_steady_ci95_hi",
        "rmse_mean", "rmse_max", "de2000_mean", "de2000_max", "flip_mean", "lag_rmse_mean", "lag_rmse_max",
        "shadow_rmse_mean",
        "pop_max", "pop_p95", "lodpop_max", "lodpop_p95", "lodpop_sum", "shadow_lodpop_max",
        "pop_events", "visible_pop_threshold", "visible_pops_per_min", "lodpop_max_jnd",
        "triangles_mean", "draw_calls_mean", "t_instances_mean", "transition_frames_min", "units_drawn_mean",
        "uncovered_px_mean",
        "crack_px_mean", "crack_px_max", "extra_target_bytes", "tri_alternation_max",
        "triangles_per_s", "triangle_ceiling_share", "fragments_mean", "fragments_per_s", "fragment_ceiling_share",
        "bound",
    ),
    TRANSITIONS_CSV: (
        "scene", "method", "count", "transition", "first_frame", "last_frame", "lods", "lodpop_max",
        "lodpop_coverage", "lodpop_shading", "pop_max",
    ),
    ROUNDS_CSV: ("scene", "method", "count", "ratio_to_baseline"),
    PAIRS_CSV: (
        "scene", "count", "method_a", "method_b", "ratio", "ratio_ci95_lo", "ratio_ci95_hi", "ratio_transition",
        "ratio_transition_ci95_lo", "ratio_transition_ci95_hi",
    ),
    PERCEPTUAL_CSV: ("scene", "method", "count", "jod_popping"),
    TUNE_CSV: ("model", "lod_from", "lod_to", "view", "distance", "lodpop", "jod", "refined"),
    RULES_CSV: ("model", "lod_from", "lod_to", "rule", "distance", "screen_size", "value", "within_budget"),
    PROBE_CSV: ("probe", "rate_median"),
}

# The columns an experiment's or a merged folder's CSVs lead with, before the record's own: one per swept variable
# (a `lodbench run` flag, or `viewport` for the width and height together), then, in a merged folder, `adapter`.
# The scripts take the swept variables from the header; these are the ones they name.
LEAD_COLUMNS = ("seed", "viewport", "pixel-error", "adapter")


def num(v):
    """A cell as a float; nan where it is empty, missing or not a number."""
    try:
        return float(v)
    except (TypeError, ValueError):
        return float("nan")


def read_csv(path: Path):
    """The rows of a CSV as dicts keyed by its header."""
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def frames_by_key(path: Path):
    """The rows of a frames.csv by (scene, method, count, frame), as strings (the names of the dumped PNGs give the
    same key: dumps.parse_stem)."""
    with open(path, newline="") as f:
        return {(r["scene"], r["method"], r["count"], r["frame"]): r for r in csv.DictReader(f)}


def run_folder_of(folder: Path, variables, values) -> Path:
    """The run folder of `values` in an experiment folder (results::files::run_folder_of:
    `runs/<var>=<value>+...`, a comma in a value as x); the folder itself without swept variables."""
    if not variables:
        return folder
    return folder / RUNS_DIR / "+".join(f"{k}={str(v).replace(',', 'x')}" for k, v in zip(variables, values))


def sig3(x) -> str:
    """At least 3 significant figures, never in exponent form: 1.52, 15.2, 152, 1523, 0.00287; `-` where there is
    none (src/numbers.rs's sig3)."""
    if x is None or x != x or x in (float("inf"), float("-inf")):
        return "-"
    if x == 0:
        return "0"
    d = max(0, 2 - math.floor(math.log10(abs(x))))
    return f"{x:.{d}f}"


def thousands(x) -> str:
    """A count with thousands separators, rounded: 3,674; `-` where there is none (src/numbers.rs's thousands)."""
    if x is None or x != x or x in (float("inf"), float("-inf")):
        return "-"
    return f"{round(x):,}"


def ratio_text(r, lo=None, hi=None) -> str:
    """A ratio with its 95 % interval, 2 decimals: 1.23 [1.10, 1.37]; the ratio alone without an interval
    (src/numbers.rs's ratio)."""
    if r is None or r != r:
        return "-"
    if lo is None or hi is None or lo != lo or hi != hi:
        return f"{r:.2f}"
    return f"{r:.2f} [{lo:.2f}, {hi:.2f}]"


def part_text(part) -> str:
    """The text of one part of answer.json's sentences and table rows: a string as it is, a number (an object with
    text, file, row, cols, fmt, op) as its text."""
    return part if isinstance(part, str) else part["text"]


def sentence_text(parts) -> str:
    """A sentence of answer.json as it reads: its parts joined."""
    return "".join(part_text(p) for p in parts)


def save_figure(fig, path, dpi=None, palette=True):
    """A matplotlib figure written as PNG to `path` (a path or a binary file): a plot in 256 colours (`palette_png`);
    with `palette=False` (a figure of rendered frames: a contact sheet, FSI's buffers, a switch strip) in matplotlib's
    own RGBA, so no shade of a frame or of an error heat-map is moved to another."""
    import io

    from PIL import Image

    if not palette:
        fig.savefig(path, format="png", dpi=dpi)
        return
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    buf.seek(0)
    with Image.open(buf) as im:
        palette_png(im, path)


# palette_png's run: a colour filling this many pixels in a row is drawn, not an antialiased blend.
RUN = 8


def palette_png(im, path):
    """A plot's pixels as a PNG of at most 256 colours, at about a third of matplotlib's RGBA bytes. Kept exactly:
    first every colour that fills a horizontal run of RUN pixels somewhere (the background, the axes, and each
    series' colour, which its legend sample draws as such a run even when its line is mostly hidden), then the most
    frequent others up to 256; every other pixel (an antialiased edge) becomes the nearest kept colour.
    Deterministic; the `Software` text matplotlib writes is kept, and an image already in a palette is written as
    it is. For plots only: a frame or a contact sheet of frames keeps its own pixels."""
    import numpy as np
    from PIL import Image
    from PIL.PngImagePlugin import PngInfo

    info = PngInfo()
    if "Software" in im.info:
        info.add_text("Software", im.info["Software"])
    if im.mode == "P":
        im.save(path, format="PNG", optimize=True, pnginfo=info)
        return
    rgba = np.asarray(im.convert("RGBA"))
    packed = rgba.reshape(-1, 4).view(np.uint32).ravel()
    colours, inverse, counts = np.unique(packed, return_inverse=True, return_counts=True)
    grid = inverse.reshape(rgba.shape[:2])
    same = np.concatenate([np.zeros((grid.shape[0], 1), int), (grid[:, 1:] == grid[:, :-1]).astype(int)], axis=1)
    ends = np.cumsum(same, axis=1)
    in_run = np.zeros(grid.shape, bool)
    in_run[:, RUN - 1:] = ends[:, RUN - 1:] - ends[:, :1 - RUN or None] == RUN - 1
    runs = np.unique(grid[in_run])
    rank = np.argsort(-(counts + np.isin(np.arange(len(colours)), runs) * counts.sum()), kind="stable")
    keep = np.sort(rank[:256])
    palette = colours[keep].view(np.uint8).reshape(-1, 4).astype(np.int32)
    # Each distinct colour's nearest kept colour (itself where kept), then each pixel's.
    every = colours.view(np.uint8).reshape(-1, 4).astype(np.int32)
    nearest = np.empty(len(colours), dtype=np.uint8)
    for i in range(0, len(every), 4096):
        d = ((every[i:i + 4096, None, :] - palette[None, :, :]) ** 2).sum(axis=2)
        nearest[i:i + 4096] = d.argmin(axis=1)
    index = nearest[inverse].reshape(rgba.shape[:2])
    out = Image.fromarray(index, mode="P")
    if (palette[:, 3] == 255).all():
        out.putpalette(palette[:, :3].astype(np.uint8).ravel().tolist())
    else:
        out.putpalette(palette.astype(np.uint8).ravel().tolist(), rawmode="RGBA")
    out.save(path, format="PNG", optimize=True, pnginfo=info)
