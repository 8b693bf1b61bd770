"""One colour per method in every figure (scripts/method_colours.py): every lodbench method has its own palette
colour, each figure draws a method in that colour (its repeats and other series of it in shades of it), and the
decision figure names its methods in the legend, not in labels piled up at the points. Synthetic rows: no lodbench
run needed."""
import itertools
import math
import re
import sys
from pathlib import Path

import matplotlib
import pytest

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import to_hex, to_rgb  # noqa: E402
from matplotlib.container import BarContainer, ErrorbarContainer  # noqa: E402

SCRIPTS = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(SCRIPTS))
import frontier  # noqa: E402
import method_colours  # noqa: E402
import plot  # noqa: E402
from method_colours import METHOD_COLOURS, method_colour, method_of, series_colours  # noqa: E402


def builtin_methods():
    """Every method name of src/methods/mod.rs's BUILTIN registry."""
    names = re.findall(r'MethodEntry \{ name: "([^"]+)"', (SCRIPTS.parent / "src" / "methods" / "mod.rs").read_text())
    assert len(names) > 10, names  # the pattern still reads the registry
    return names


def lab(colour):
    """CIELAB of an sRGB colour (D65)."""
    lin = [c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4 for c in to_rgb(colour)]
    xyz = [sum(m * c for m, c in zip(row, lin)) for row in ((0.4124, 0.3576, 0.1805), (0.2126, 0.7152, 0.0722),
                                                           (0.0193, 0.1192, 0.9505))]
    f = [t ** (1 / 3) if t > 0.008856 else 7.787 * t + 16 / 116
         for t in (xyz[0] / 0.95047, xyz[1] / 1.0, xyz[2] / 1.08883)]
    return 116 * f[1] - 16, 500 * (f[0] - f[1]), 200 * (f[1] - f[2])


def test_every_method_has_its_own_colour():
    names = builtin_methods()
    missing = [n for n in names if n not in METHOD_COLOURS]
    assert not missing, f"methods without a colour in scripts/method_colours.py's METHOD_COLOURS: {missing}"
    colours = [to_hex(METHOD_COLOURS[n]) for n in names]
    assert len(set(colours)) == len(colours), "two methods share a colour"
    # Not only different but told apart at a glance: CIELAB distance (delta E 1976) of 20 or more between any two.
    close = [(a, b, round(math.dist(lab(METHOD_COLOURS[a]), lab(METHOD_COLOURS[b]))))
             for a, b in itertools.combinations(names, 2)
             if math.dist(lab(METHOD_COLOURS[a]), lab(METHOD_COLOURS[b])) < 20]
    assert not close, f"colours too alike: {close}"
    # A repeat or another series of a method has its method's colour, or a shade of it.
    assert method_colour(method_of("discrete#2")) == METHOD_COLOURS["discrete"]
    assert method_of("fsi-sameframe (band 0.1, noise 2) [GPU B]") == "fsi-sameframe"
    assert method_of("alpha-2pass [GPU A]") == "alpha-2pass"


def test_an_unknown_method_gets_a_fixed_colour_of_its_own():
    """A method missing from the palette: a colour unlike any of the palette's, the same on every call."""
    palette = {to_hex(c) for c in METHOD_COLOURS.values()}
    for name in ("wavelet", "wavelet#2", "hybrid-lod", "x"):
        c = method_colour(method_of(name))
        assert to_hex(c) not in palette and c == method_colour(method_of(name)), name
    close = [(f, m) for f in method_colours.FALLBACK_COLOURS for m, c in METHOD_COLOURS.items()
             if math.dist(lab(f), lab(c)) < 20]
    assert not close, f"fallback colours like a method's: {close}"


def test_series_of_one_method_are_told_apart_by_shade():
    labels = ["discrete#2", "reference", "discrete", "discrete (band 0.2)", "alpha", "reference#2"]
    colours = series_colours(labels)
    assert list(colours) == labels
    assert colours["discrete"] == METHOD_COLOURS["discrete"] and colours["alpha"] == METHOD_COLOURS["alpha"]
    assert len(set(colours.values())) == len(labels), colours
    # By the labels, not the order a figure draws them in.
    assert series_colours(reversed(labels)) == colours


# Series of the synthetic run: methods that matplotlib's default cycle coloured alike (reference, fsi-sameframe),
# a repeat, and a method missing from the palette.
METHODS = ["reference", "discrete", "alpha", "alpha-2pass", "alpha-linear", "alpha-zwrite", "dither", "geomorph",
           "fsi", "fsi-noreproject", "fsi-sameframe", "discrete#2", "wavelet"]


def summary_rows(methods=METHODS, counts=("1",)):
    rows = []
    for c in counts:
        for i, m in enumerate(methods):
            rows.append({
                "scene": "bunny-sweep", "method": m, "count": c, "baseline": "discrete", "gpu_ms_median": str(1 + i),
                "rmse_mean": str(0.001 * i), "pop_max": str(0.002 * i), "lodpop_max": str(0.003 + 0.0001 * (i % 3)),
                "ratio_to_baseline": str(1 + 0.01 * (i % 4)), "ratio_to_baseline_ci95_lo": str(0.95 + 0.01 * (i % 4)),
                "ratio_to_baseline_ci95_hi": str(1.05 + 0.01 * (i % 4)),
                "triangle_ceiling_share": str(0.1 * (i % 5 + 1)), "fragment_ceiling_share": str(0.05 * (i % 5 + 1)),
                "viewport": f"{64 * int(c)},48", "pixel-error": c, "triangles_mean": str(1000 * (i + 1)),
                "crack_px_mean": str(i),
            })
    return rows


def frame_rows(method, i):
    return [{"frame": str(f), "rmse": str(0.001 * (i + f % 3)), "pop": str(0.001 * i), "lodpop": str(0.0005 * i),
             "lod_mean": str(f // 4), "t_instances": "1" if f % 4 == 3 else "0",
             "lag_rmse": str(0.001 * i) if method.startswith("fsi") else ""} for f in range(12)]


@pytest.fixture
def drawn(monkeypatch, tmp_path):
    """Draws every figure that colours by method from the synthetic rows; returns [(figure, the figure)], each
    figure kept open (plt.close collects it instead)."""
    kept = []
    close = plt.close
    monkeypatch.setattr(plot.plt, "close", lambda fig=None: kept.append(fig))
    monkeypatch.setattr(plot, "save_figure", lambda *a, **k: None)
    out = []

    def draw(name, f, *args):
        f(*args, tmp_path / f"{name}.png")
        out.append((name, kept[-1]))

    summary = summary_rows()
    draw("sweep", plot.sweep_figure, "s", {m: frame_rows(m, i) for i, m in enumerate(METHODS)})
    draw("fig6", plot.fig6, "s", summary)
    draw("transitions", plot.transitions_figure, "s",
         [(f, f + 2, "0->1", {m: (0.002 * (i + 1), 0.003, 0.001, 0.001) for i, m in enumerate(METHODS[1:])})
          for f in (3, 7)])
    draw("fig5", plot.fig5, "s", summary_rows(counts=("1", "2")))
    draw("fig8", plot.fig8, "s", summary_rows(counts=("1", "2")))
    draw("unified", plot.unified, "s", summary_rows(counts=("1", "2")))
    draw("cost", plot.cost, "s", summary)
    draw("ceilings", plot.ceilings_figure, "s", summary)
    draw("decision", plot.decision_figure, "s", summary, None)
    pts = [{"series": m, "setting": s, "cost": 1 + 0.1 * i, "lodpop": 0.001 * i + float(s), "jod": float("nan"),
            "rmse": 0.001 * i, "baseline": "discrete"} for i, m in enumerate(METHODS) for s in ("0.1", "0.2")]
    draw("frontier", frontier.figure, "s", pts, "band")
    yield out
    for fig in kept:
        close(fig)


def colour_of(artist):
    for get in ("get_color", "get_facecolor"):
        if hasattr(artist, get):
            c = getattr(artist, get)()
            return to_hex(c[0] if hasattr(c, "ndim") and c.ndim == 2 else c)
    raise AssertionError(f"no colour: {artist}")


def colours_by_label(fig):
    """{series label: {colours}} of what a figure draws: its lines, error bars and bars (a bar without a label by
    the x tick under it) and its legends' entries."""
    out = {}
    for ax in fig.axes:
        for line in ax.get_lines():
            if not line.get_label().startswith("_"):
                out.setdefault(line.get_label(), set()).add(to_hex(line.get_color()))
        ticks = {round(t, 6): label.get_text() for t, label in zip(ax.get_xticks(), ax.get_xticklabels())}
        for container in ax.containers:
            if isinstance(container, ErrorbarContainer):
                out.setdefault(container.get_label(), set()).add(to_hex(container.lines[0].get_color()))
            elif isinstance(container, BarContainer):
                for patch in container.patches:
                    if not container.get_label().startswith("_"):
                        label = container.get_label()
                    else:  # bars grouped around their tick
                        mid = patch.get_x() + patch.get_width() / 2
                        label = ticks[min(ticks, key=lambda t: abs(t - mid))]
                    out.setdefault(label, set()).add(to_hex(patch.get_facecolor()))
        legends = [ax.get_legend()] + list(fig.legends)
        for legend in filter(None, legends):
            for text, handle in zip(legend.get_texts(), legend.legend_handles):
                out.setdefault(text.get_text(), set()).add(colour_of(handle))
    return out


def test_a_method_has_one_colour_in_every_figure(drawn):
    """Each figure draws each method in series_colours' colour, which is the palette's for a method drawn alone:
    `discrete` is the same red in the bars, the scatter and the lines; no two methods of a figure share one."""
    expected = series_colours(METHODS)
    assert expected["discrete"] == METHOD_COLOURS["discrete"]
    seen = {}
    for name, fig in drawn:
        by_label = colours_by_label(fig)
        # ceilings' ticks may add the count; the other figures' labels are the methods.
        drawn_methods = {m: by_label[m] for m in METHODS if m in by_label}
        assert len(drawn_methods) >= len(METHODS) - 1, (name, sorted(by_label))
        for m, colours in drawn_methods.items():
            assert colours == {expected[m]}, f"{name}: {m} drawn in {colours}, not {expected[m]}"
            seen.setdefault(m, set()).add(name)
        drawn_colours = [c for cs in drawn_methods.values() for c in cs]
        assert len(set(drawn_colours)) == len(drawn_colours), f"{name}: two methods share a colour"
    assert len(seen["discrete"]) == len(drawn), seen["discrete"]


def test_the_figures_have_no_other_colour_for_a_method():
    """No figure script picks a method's colour from matplotlib's colour cycle (`C0`...) any more."""
    for name in ("plot.py", "frontier.py", "equal_error.py"):
        text = (SCRIPTS / name).read_text()
        for pattern in ('"C{', "prop_cycle", "colours[i", "colours[mi"):
            assert pattern not in text, f"scripts/{name} still colours by {pattern}"


def test_decision_figure_labels_do_not_overlap(drawn):
    """The scatter of cost against popping names each method once, in the legend beside the axes: no text at the
    points, where methods of like cost and popping piled their labels on each other, and no two of the names
    overlap where drawn."""
    fig = dict(drawn)["decision"]
    ax = fig.axes[0]
    assert not ax.texts, [t.get_text() for t in ax.texts]
    entries = ax.get_legend().get_texts()
    assert sorted(t.get_text() for t in entries if not t.get_text().startswith("budget")) == sorted(METHODS)
    renderer = fig.canvas.get_renderer()
    fig.draw(renderer)
    boxes = [(t.get_text(), t.get_window_extent(renderer)) for t in list(ax.texts) + list(entries)]
    overlapping = [(a, b) for (a, ba), (b, bb) in itertools.combinations(boxes, 2) if ba.overlaps(bb)]
    assert not overlapping, overlapping
