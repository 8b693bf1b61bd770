#!/usr/bin/env python3
"""Fetch the Stanford bunny from the npm registry package `bunny@1.0.1` and write scenes/bunny.obj.

Run once, by hand, when the committed OBJ has to be regenerated; lodbench itself never touches the network.
The tarball's SHA-1 is checked against the registry's published `shasum`, and the SHA-256 of the written OBJ is
printed so that scenes/README.md can be updated.

    python3 scripts/fetch_bunny.py [--out scenes/bunny.obj]
"""
import argparse
import hashlib
import io
import json
import sys
import tarfile
import urllib.request
from pathlib import Path

PACKAGE = "bunny"
VERSION = "1.0.1"
REGISTRY = "https://registry.npmjs.org"
EXPECTED_SHA1 = "86383da45ab7a99571a5a572b7be0e3564815f9e"  # registry 'dist.shasum' of bunny-1.0.1.tgz


def parse_export(source: str, name: str):
    """Return the JSON array assigned to `exports.<name>=` in the package's index.js."""
    marker = f"exports.{name}="
    start = source.find(marker)
    if start < 0:
        raise ValueError(f"index.js has no '{marker}'")
    start += len(marker)
    depth = 0
    for i in range(start, len(source)):
        c = source[i]
        if c == "[":
            depth += 1
        elif c == "]":
            depth -= 1
            if depth == 0:
                return json.loads(source[start : i + 1])
    raise ValueError(f"unterminated array after '{marker}'")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=str(Path(__file__).resolve().parent.parent / "scenes" / "bunny.obj"))
    args = ap.parse_args()

    url = f"{REGISTRY}/{PACKAGE}/-/{PACKAGE}-{VERSION}.tgz"
    data = urllib.request.urlopen(url, timeout=60).read()
    sha1 = hashlib.sha1(data).hexdigest()
    if sha1 != EXPECTED_SHA1:
        print(f"error: {url} has SHA-1 {sha1}, expected {EXPECTED_SHA1}", file=sys.stderr)
        return 1
    with tarfile.open(fileobj=io.BytesIO(data), mode="r:gz") as tar:
        member = tar.extractfile("package/index.js")
        if member is None:
            print("error: package/index.js missing from the tarball", file=sys.stderr)
            return 1
        source = member.read().decode("utf-8")

    positions = parse_export(source, "positions")
    cells = parse_export(source, "cells")
    lines = [
        f"# Stanford bunny from the npm package {PACKAGE}@{VERSION} (Public Domain), tarball SHA-1 {sha1}",
        "# written by scripts/fetch_bunny.py; vertices unchanged, faces 1-based, no normals (lodbench computes them)",
        f"# {len(positions)} vertices, {len(cells)} triangles",
    ]
    lines += [f"v {x!r} {y!r} {z!r}" for x, y, z in positions]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in cells]
    text = "\n".join(lines) + "\n"
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text)
    print(f"wrote {out}: {len(positions)} vertices, {len(cells)} triangles, "
          f"sha256 {hashlib.sha256(text.encode()).hexdigest()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
