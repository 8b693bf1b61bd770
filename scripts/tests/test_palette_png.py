"""Figures in at most 256 colours (lodbench_results.save_figure, palette_png): every series' colour survives exactly,
even a series drawn under others, and the rest of the picture moves by little."""
import sys

import matplotlib
import numpy as np
from PIL import Image

from conftest import ROOT

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, str(ROOT / "scripts"))
from lodbench_results import save_figure  # noqa: E402


def test_every_series_colour_is_kept_exactly(tmp_path):
    # 40 series of distinct colours over each other, the first drawn under all the others (it shows only in the
    # legend): more blends than a palette holds.
    rng = np.random.default_rng(1)
    colours = [tuple(int(c) for c in rng.integers(0, 256, 3)) for _ in range(40)]
    fig, ax = plt.subplots(figsize=(8, 5))
    x = np.linspace(0, 10, 400)
    for i, c in enumerate(colours):
        ax.plot(x, np.sin(x) if i == 0 else np.sin(x + i) + 0.02 * i, color=np.array(c) / 255, label=f"s{i}",
                zorder=0 if i == 0 else 1, linewidth=3 if i else 1)
    ax.plot(x, np.sin(x), color="white", linewidth=4, zorder=2)  # the first series' line, hidden
    ax.legend(ncol=4, fontsize=6, handlelength=1.5)
    fig.savefig(tmp_path / "rgba.png", dpi=100)
    save_figure(fig, tmp_path / "palette.png", dpi=100)
    plt.close(fig)
    with Image.open(tmp_path / "palette.png") as im:
        assert im.mode == "P" and "Matplotlib" in im.info.get("Software", "")
        got = np.asarray(im.convert("RGB")).astype(int)
    want = np.asarray(Image.open(tmp_path / "rgba.png").convert("RGB")).astype(int)
    present = {tuple(p) for p in got.reshape(-1, 3)}
    missing = [c for c in colours if c not in present]
    assert not missing, f"series colours lost: {missing}"
    # Pixels left as they were: the background, the text's core, the lines' middles; blends move to a kept colour.
    # 40 crossing series make this figure mostly edges (83 % of its pixels stay); a quantiser that moved the flat
    # colours too would change nearly all of them.
    assert (np.abs(got - want).sum(axis=2) == 0).mean() > 0.75
    assert (tmp_path / "palette.png").stat().st_size < (tmp_path / "rgba.png").stat().st_size
