"""One colour per lodbench method, the same in every figure (scripts/plot.py's, frontier.py's, equal_error.py's):
a figure gets its series' colours from series_colours() and from nowhere else, so a method drawn in two figures
is drawn in one colour.

A series label names its method as plot.py writes it: `discrete`, `discrete#2` (the second `discrete` of an A/A
run, src/methods/mod.rs's base_name), `discrete (band 0.1)` (a sweep's series), `discrete [GPU B]` (a merged
folder's adapter), or those combined."""
import re
import zlib

from matplotlib.colors import to_hex, to_rgb

# Every method of src/methods/mod.rs's BUILTIN (scripts/tests/test_method_colours.py checks the list against it, and
# that no two colours are alike). A family shares a hue where the hues allow (alpha* orange and brown, fsi* blue,
# blocks* pink, the terrain's roam* teal), each member its own shade; the methods a default run draws together
# (reference, discrete, alpha, alpha-2pass, alpha-linear, alpha-zwrite, dither, geomorph, fsi, fsi-noreproject,
# fsi-sameframe) are tab10's and tab20's most distinct.
METHOD_COLOURS = {
    "reference": "#000000",
    "reference-flat": "#7f7f7f",
    "discrete": "#d62728",
    "discrete-mesh": "#5c0a0a",
    "alpha": "#ff7f0e",
    "alpha-2pass": "#ffbb78",
    "alpha-linear": "#8c564b",
    "alpha-zwrite": "#c49c94",
    "alpha-sorted": "#8c6d31",
    "dither": "#2ca02c",
    "dither-skip": "#98df8a",
    "geomorph": "#9467bd",
    "fsi": "#1f77b4",
    "fsi-noreproject": "#aec7e8",
    "fsi-sameframe": "#17becf",
    "fsi-blend": "#393b79",
    "blocks": "#e377c2",
    "blocks-noseams": "#f7b6d2",
    "blocks-discrete": "#7b4173",
    "blocks-tree": "#637939",
    "clusterlod": "#bcbd22",
    "roam": "#00796b",
    "roam-morph": "#66c2a5",
}

# A method missing from METHOD_COLOURS (added to lodbench before its colour here) gets one of these, by a hash of its
# name: the same in every figure and every run, and unlike every palette colour (two such methods may share one).
FALLBACK_COLOURS = ("#0000ff", "#4b0082", "#93003a", "#e7298a", "#fb8072", "#e6ab02", "#b15928", "#808000",
                    "#006400", "#00ffff")

# A method's further series in one figure (a repeat, another adapter, another swept value): its colour mixed toward
# black (negative) or white (positive) by these amounts in turn, so that the hue still names the method.
SHADES = (-0.4, 0.5, -0.65, 0.75, -0.2, 0.3, -0.85)


def method_of(label: str) -> str:
    """The method a series label names: its first word (method names have no spaces) less a `#k` repeat suffix."""
    word = label.split(" ", 1)[0]
    return re.sub(r"#\d+$", "", word)


def method_colour(method: str) -> str:
    """The colour of a method (a series label's method_of): its palette colour, or a fixed fallback."""
    if method in METHOD_COLOURS:
        return METHOD_COLOURS[method]
    return FALLBACK_COLOURS[zlib.crc32(method.encode()) % len(FALLBACK_COLOURS)]


def shade(colour: str, k: int) -> str:
    """The k-th shade (k >= 1) of a colour; a colour too dark to darken is lightened by as much instead."""
    t = SHADES[(k - 1) % len(SHADES)]
    rgb = to_rgb(colour)
    if t < 0 and max(rgb) < 0.3:
        t = -t
    return to_hex([c + (1 - c) * t if t > 0 else c * (1 + t) for c in rgb])


def natural(label: str):
    """Sort key: `discrete#2` before `discrete#10`."""
    return [(0, int(p), "") if p.isdigit() else (1, 0, p) for p in re.split(r"(\d+)", label)]


def series_colours(labels) -> dict:
    """{label: colour} for a figure's series: each its method's colour; where several name one method, the first of
    them in natural order (the bare method, the lowest repeat, the lowest value) has it and the others its shades,
    so that a series' colour depends on the labels, not on the order a figure draws them in."""
    labels = list(dict.fromkeys(labels))
    out = {}
    by_method = {}
    for label in labels:
        by_method.setdefault(method_of(label), []).append(label)
    for method, same in by_method.items():
        colour = method_colour(method)
        for k, label in enumerate(sorted(same, key=natural)):
            out[label] = shade(colour, k) if k else colour
    return {label: out[label] for label in labels}
