"""A repository a GPU machine can take: the device machine copies the tracked tree (and what a call carries: the
release binary, the Vulkan loader) up to 64 MiB, so the tracked files must stay under 45 MiB
(../shared/gpu/RUN-ON-DEVICE.md, docs/cluster.md). The fuzz corpora are committed packed
(scripts/fuzz-corpus.sh) and results/ keeps what the docs show (docs/findings/timing.md#the-repositorys-size)."""
import subprocess
from collections import Counter

import pytest

from conftest import ROOT

LIMIT_MIB = 45.0


def tracked_sizes():
    """{path: bytes} of every file git tracks that exists in the work tree (a tracked file deleted but not yet
    committed counts as gone)."""
    try:
        out = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError) as e:
        pytest.skip(f"not a git checkout, so there is no tracked tree to size: {e}")
    sizes = {}
    for name in out.decode("utf-8", "replace").split("\0"):
        path = ROOT / name
        if name and path.is_file() and not path.is_symlink():
            sizes[name] = path.stat().st_size
    return sizes


def largest_folders(sizes, depth=3, n=8):
    by = Counter()
    for name, size in sizes.items():
        by["/".join(name.split("/")[:depth])] += size
    return ", ".join(f"{k} {v / 2**20:.1f} MiB" for k, v in by.most_common(n))


def test_the_tracked_tree_is_under_45_mib():
    sizes = tracked_sizes()
    total = sum(sizes.values()) / 2**20
    assert total < LIMIT_MIB, (f"the tracked files sum to {total:.1f} MiB, over the {LIMIT_MIB} MiB a GPU call can "
                               f"carry with the binary; the largest: {largest_folders(sizes)}")


def test_largest_folders_names_the_biggest_first():
    sizes = {"results/cpu/a/x.png": 3 * 2**20, "results/cpu/b/y.csv": 2**20, "src/main.rs": 10}
    assert largest_folders(sizes).startswith("results/cpu/a 3.0 MiB, results/cpu/b 1.0 MiB")
