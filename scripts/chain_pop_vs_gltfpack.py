#!/usr/bin/env python3
"""lodbench's LOD chain of a textured glTF mesh against gltfpack's `-si` chain of it, by how each pops: the
coverage and shading parts of lodpop per transition, with the materials drawn, along the same flight with the same
switch distances.

For each file (one mesh placed by one root node, as the Khronos sample assets hold): lodbench's chain (`lodbench
describe --json --animation none`: its levels' triangle counts and switch distances at the quick profile), then
gltfpack 1.3.0 run on the file once per level with `-noq -si R -se 0.5` (R the level's triangle fraction; textures and
materials kept, no quantisation), the levels joined into one file by glTF-Transform's `merge` and made an authored
chain (MSFT_lod on the file's root node, the gltfpack levels' root nodes as its levels). Both chains then run with the
same flags and `--switch-distances` set to lodbench's own switches:

    lodbench run --scene FILE --method discrete,dither --frames 600 --animation none --switch-distances D
    lodbench run --scene CHAIN.glb ... (the same)

and the script writes each run's transitions (discrete's and dither's largest lodpop, its coverage and shading parts)
side by side in a CSV and prints a Markdown table.

    python3 scripts/chain_pop_vs_gltfpack.py --lodbench target/release/lodbench --tools DIR --out DIR FILE.glb ...

--tools is a folder where `npm install gltfpack@1.3.0 @gltf-transform/cli@4.5.1` was run (their binaries are taken
from its node_modules/.bin)."""
import argparse
import csv
import json
import struct
import subprocess
import sys
from pathlib import Path

from lodbench_results import TRANSITIONS_CSV, read_csv

METHODS = "discrete,dither"
FRAMES = "600"


def run(args, **kw):
    r = subprocess.run([str(a) for a in args], capture_output=True, text=True, **kw)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, args))}: {r.stderr.strip()}")
    return r.stdout


def describe(lodbench, path: Path, switches=None) -> dict:
    extra = ["--switch-distances", ",".join(f"{d:.6g}" for d in switches)] if switches else []
    return json.loads(run([lodbench, "describe", "--scene", path, "--json", "--animation", "none", *extra]))


def read_glb(path: Path):
    data = path.read_bytes()
    length = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + length])
    rest = data[20 + length:]
    return doc, rest


def write_glb(path: Path, doc: dict, rest: bytes):
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    chunk = struct.pack("<II", len(text), 0x4E4F534A) + text
    total = 12 + len(chunk) + len(rest)
    path.write_bytes(struct.pack("<III", 0x46546C67, 2, total) + chunk + rest)


def chain_file(tools: Path, src: Path, fractions, work: Path) -> Path:
    """gltfpack's levels of `src` at `fractions` of its triangles, joined as an MSFT_lod chain (one GLB)."""
    gltfpack = tools / "node_modules" / ".bin" / "gltfpack"
    gltf_transform = tools / "node_modules" / ".bin" / "gltf-transform"
    levels = []
    for k, r in enumerate(fractions):
        out = work / f"level{k + 1}.glb"
        run([gltfpack, "-i", src, "-o", out, "-noq", "-si", f"{r:.6f}", "-se", "0.5"])
        levels.append(out)
    merged = work / "merged.glb"
    run([gltf_transform, "merge", src, *levels, merged])
    doc, rest = read_glb(merged)

    def holds_mesh(n):
        node = doc["nodes"][n]
        return "mesh" in node or any(holds_mesh(c) for c in node.get("children", []))

    # Each scene's root holding geometry (a file's other roots, such as a camera's node, stay where they are).
    roots = [[n for n in s["nodes"] if holds_mesh(n)] for s in doc["scenes"]]
    if any(len(r) != 1 for r in roots):
        raise RuntimeError(f"{src.name}: every level must have one root node with geometry, found {roots}")
    lod0 = roots[0][0]
    node = doc["nodes"][lod0]
    node.setdefault("extensions", {})["MSFT_lod"] = {"ids": [r[0] for r in roots[1:]]}
    doc["scenes"] = [doc["scenes"][0]]
    doc["scene"] = 0
    doc["extensionsUsed"] = sorted(set(doc.get("extensionsUsed", [])) | {"MSFT_lod"})
    out = work / f"{src.stem}-gltfpack-chain.glb"
    write_glb(out, doc, rest)
    return out


def transitions(lodbench, scene: Path, switches, out: Path):
    run([lodbench, "run", "--scene", scene, "--method", METHODS, "--frames", FRAMES, "--animation", "none",
         "--switch-distances", ",".join(f"{d:.6g}" for d in switches), "--out", out])
    return read_csv(out / TRANSITIONS_CSV)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--lodbench", required=True)
    ap.add_argument("--tools", required=True, type=Path)
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument("files", nargs="+", type=Path)
    a = ap.parse_args()
    a.out.mkdir(parents=True, exist_ok=True)
    rows = []
    for src in a.files:
        model = describe(a.lodbench, src)["models"][0]
        t0 = model["lods"][0]["triangles"]
        fractions = [lod["triangles"] / t0 for lod in model["lods"][1:]]
        switches = [lod["switch_distance"] for lod in model["lods"][1:]]
        work = a.out / src.stem
        work.mkdir(exist_ok=True)
        chain = chain_file(a.tools, src.resolve(), fractions, work)
        try:
            packed = describe(a.lodbench, chain, switches)["models"][0]
        except RuntimeError as e:
            # gltfpack's levels are no chain (a level as large as the one before): nothing to run.
            print(f"{src.name}: gltfpack's levels are no LOD chain: {e}", file=sys.stderr)
            continue
        ours = transitions(a.lodbench, src, switches, work / "lodbench-run")
        theirs = transitions(a.lodbench, chain, switches, work / "gltfpack-run")
        for mine, other in zip(ours, theirs):
            if mine["method"] != other["method"] or mine["transition"] != other["transition"]:
                raise RuntimeError(f"{src.name}: the two runs' transitions differ")
            row = {"file": src.name, "method": mine["method"], "transition": mine["transition"],
                   "frames": f"{mine['first_frame']}-{mine['last_frame']}", "lods": mine["lods"]}
            k = [int(x) for x in mine["lods"].split("->")] if "->" in mine["lods"] else None
            for name, r, m in (("lodbench", mine, model), ("gltfpack", other, packed)):
                row[f"{name}_triangles"] = "->".join(str(m["lods"][i]["triangles"]) for i in k) if k else ""
                for c in ("lodpop_max", "lodpop_coverage", "lodpop_shading"):
                    row[f"{name}_{c}"] = r[c]
            rows.append(row)
    if not rows:
        return 1
    with open(a.out / "chain-pop.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    f = lambda v: f"{float(v):.4f}" if v != "" else "-"  # noqa: E731
    print("| file | method | transition | LODs | lodbench triangles | lodpop (coverage / shading) | "
          "gltfpack -si triangles | lodpop (coverage / shading) |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['file']} | {r['method']} | {r['transition']} ({r['frames']}) | {r['lods']} | "
              f"{r['lodbench_triangles']} | {f(r['lodbench_lodpop_max'])} ({f(r['lodbench_lodpop_coverage'])} / "
              f"{f(r['lodbench_lodpop_shading'])}) | {r['gltfpack_triangles']} | {f(r['gltfpack_lodpop_max'])} "
              f"({f(r['gltfpack_lodpop_coverage'])} / {f(r['gltfpack_lodpop_shading'])}) |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
