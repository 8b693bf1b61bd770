#!/usr/bin/env python3
"""lodbench's LOD chain of a glTF mesh against gltfpack's simplification of it to the same triangle counts.

For each file (one mesh, as the Khronos sample assets hold): lodbench's chain (`lodbench describe --json --deviation
--animation none`, the quick profile's levels: meshoptimizer's attribute-aware simplifier, chosen by error), then
for each of its levels gltfpack run on the file with `-noq -si R -se 0.5` (R the level's triangle fraction, the
error limit lifted to half the mesh's extent so the ratio decides; with `-se 1` gltfpack 1.3.0 wrote no mesh at all
for the faceted sphere) and once more with `-sp` (permissive: collapses across attribute seams). Every
level is measured the same way, by lodbench (`describe --deviation` of a two-level chain: the file's triangles at
rest, decoded by scripts/check_gltf.py, and the level's): the largest and the mean distance from LOD0's vertices
to the level's surface. Prints a Markdown table and writes a CSV.

    python3 scripts/chain_vs_gltfpack.py --lodbench target/release/lodbench --out chains.csv FILE.glb ...

gltfpack comes from npm (`npm install gltfpack@1.3.0`, then `--gltfpack "npx gltfpack"` from that folder, or the
path of its bin).
"""
import argparse
import base64
import csv
import json
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import check_gltf  # noqa: E402


def describe(lodbench: str, path: Path) -> dict:
    """lodbench's chain of `path` with its deviations. `--materials flat`: the chain is geometry (the same with the
    materials read, e.g. SciFiHelmet 23,358 -> 8,546/6,253/5,055 both ways), and a copy that lacks a texture is then
    read rather than refused."""
    out = subprocess.run([lodbench, "describe", "--scene", str(path), "--json", "--deviation", "--animation", "none",
                          "--materials", "flat"], check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def triangles_at_rest(path: Path) -> np.ndarray:
    """Every triangle of the file's scene at rest, world space, (n, 3, 3)."""
    result = check_gltf.decode(check_gltf.load_document(path), None, 0.0)
    parts = [u.positions for u in result.units if len(u.positions)]
    return np.concatenate(parts) if parts else np.zeros((0, 3, 3))


def chain_gltf(levels: list[np.ndarray], out: Path) -> None:
    """A glTF of `levels` (triangle soups) as sibling nodes CHAIN_LOD0, CHAIN_LOD1, ...: an authored chain."""
    data, accessors, views, meshes, nodes = b"", [], [], [], []
    for k, tris in enumerate(levels):
        points = tris.reshape(-1, 3).astype("<f4")
        raw = points.tobytes()
        views.append({"buffer": 0, "byteOffset": len(data), "byteLength": len(raw)})
        accessors.append({"bufferView": k, "componentType": 5126, "count": len(points), "type": "VEC3",
                          "min": points.min(axis=0).tolist(), "max": points.max(axis=0).tolist()})
        meshes.append({"primitives": [{"attributes": {"POSITION": k}}]})
        nodes.append({"name": f"CHAIN_LOD{k}", "mesh": k})
        data += raw
    doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": list(range(len(levels)))}],
           "nodes": nodes, "meshes": meshes, "accessors": accessors, "bufferViews": views,
           "buffers": [{"byteLength": len(data), "uri": "data:application/octet-stream;base64,"
                        + base64.b64encode(data).decode()}]}
    out.write_text(json.dumps(doc))


def measured(lodbench: str, lod0: np.ndarray, level: np.ndarray, tmp: Path) -> tuple[float, float] | None:
    """lodbench's deviation of `level` from `lod0` (None when the level did not lose a triangle)."""
    if len(level) == 0 or len(level) >= len(lod0):
        return None
    path = tmp / "chain.gltf"
    chain_gltf([lod0, level], path)
    lods = describe(lodbench, path)["models"][0]["lods"]
    return lods[1]["deviation_max"], lods[1]["deviation_mean"]


def gltfpack(command: str, src: Path, ratio: float, permissive: bool, tmp: Path) -> np.ndarray:
    out = tmp / "packed.glb"
    args = shlex.split(command) + ["-i", str(src), "-o", str(out), "-noq", "-si", f"{ratio:.6f}", "-se", "0.5"]
    if permissive:
        args.append("-sp")
    subprocess.run(args, check=True, capture_output=True)
    return triangles_at_rest(out)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--lodbench", required=True)
    ap.add_argument("--gltfpack", default="npx gltfpack")
    ap.add_argument("--out", type=Path)
    ap.add_argument("files", nargs="+", type=Path)
    a = ap.parse_args()
    rows = []
    for src in a.files:
        model = describe(a.lodbench, src)["models"][0]
        lod0 = triangles_at_rest(src)
        with tempfile.TemporaryDirectory() as t:
            tmp = Path(t)
            for lod in model["lods"][1:]:
                ratio = lod["triangles"] / model["lods"][0]["triangles"]
                row = {"file": src.name, "lod": lod["lod"], "lodbench_triangles": lod["triangles"],
                       "lodbench_error_abs": lod["error_abs"], "lodbench_deviation_max": lod["deviation_max"],
                       "lodbench_deviation_mean": lod["deviation_mean"]}
                for name, permissive in [("gltfpack", False), ("gltfpack_sp", True)]:
                    level = gltfpack(a.gltfpack, src, ratio, permissive, tmp)
                    m = measured(a.lodbench, lod0, level, tmp)
                    row[f"{name}_triangles"] = len(level)
                    row[f"{name}_deviation_max"] = m[0] if m else ""
                    row[f"{name}_deviation_mean"] = m[1] if m else ""
                rows.append(row)
    if a.out:
        with open(a.out, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    fmt = lambda v: f"{v:.4g}" if isinstance(v, float) else str(v)  # noqa: E731
    print("| file | LOD | lodbench triangles | error_abs | deviation max / mean | gltfpack -si triangles | "
          "deviation max / mean | gltfpack -si -sp triangles | deviation max / mean |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['file']} | {r['lod']} | {r['lodbench_triangles']} | {fmt(r['lodbench_error_abs'])} | "
              f"{fmt(r['lodbench_deviation_max'])} / {fmt(r['lodbench_deviation_mean'])} | "
              f"{r['gltfpack_triangles']} | {fmt(r['gltfpack_deviation_max'])} / {fmt(r['gltfpack_deviation_mean'])} | "
              f"{r['gltfpack_sp_triangles']} | {fmt(r['gltfpack_sp_deviation_max'])} / "
              f"{fmt(r['gltfpack_sp_deviation_mean'])} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
