#!/usr/bin/env python3
"""Reports and checks what each fixture in tests/data/tools/ holds, from its GLB JSON chunk.

Python 3 standard library only. Run: python3 tests/data/tools/expect.py [--markdown]
For each file: extensionsUsed / extensionsRequired, node and mesh counts, triangles per mesh
(index count / 3), the POSITION accessor (component type, normalized, min/max as stored) with the
transform of the node using it, and the scene's world bounds: accessor min/max, dequantized
(normalized integers divided by 32767 / 65535 / 127 / 255), through each node's TRS and, for
EXT_mesh_gpu_instancing, each instance's TRANSLATION/SCALE (read from the BIN chunk). Nodes are
walked from the scene roots; MSFT_lod is not applied (a loader without it draws what is listed).
The reference is scenes/bunny.obj: its triangle count and the min/max of its vertices.
Exits 1 if a file's scene triangle count or world bounds differ from what is expected.
"""

import json
import math
import struct
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
OBJ = HERE.parents[2] / "scenes" / "bunny.obj"

CT = {5120: ("i8", "b", 127), 5121: ("u8", "B", 255), 5122: ("i16", "h", 32767),
      5123: ("u16", "H", 65535), 5125: ("u32", "I", None), 5126: ("f32", "f", None)}
NCOMP = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
SIX_STEP = 15.0  # six.mjs: ceil(1.5 * largest extent of the bunny) = ceil(14.86)


def read_obj(path):
    verts, tris = [], 0
    for line in path.read_text().splitlines():
        p = line.split()
        if p and p[0] == "v":
            verts.append(tuple(float(x) for x in p[1:4]))
        elif p and p[0] == "f":
            tris += len(p) - 3
    lo = [min(v[i] for v in verts) for i in range(3)]
    hi = [max(v[i] for v in verts) for i in range(3)]
    return len(verts), tris, lo, hi


def read_glb(path):
    data = path.read_bytes()
    magic, version, _ = struct.unpack_from("<4sII", data, 0)
    assert magic == b"glTF" and version == 2, path
    off, gltf, bin_chunk = 12, None, None
    while off < len(data):
        length, kind = struct.unpack_from("<II", data, off)
        chunk = data[off + 8:off + 8 + length]
        if kind == 0x4E4F534A:
            gltf = json.loads(chunk)
        elif kind == 0x004E4942:
            bin_chunk = chunk
        off += 8 + length
    return gltf, bin_chunk


def dequant(acc, values):
    scale = CT[acc["componentType"]][2]
    if acc.get("normalized") and scale:
        return [max(v / scale, -1.0) for v in values]
    return list(values)


def read_floats(gltf, bin_chunk, index):
    """Reads an uncompressed accessor from the BIN chunk as float tuples (dequantized)."""
    acc = gltf["accessors"][index]
    view = gltf["bufferViews"][acc["bufferView"]]
    assert "extensions" not in view and view["buffer"] == 0, "compressed or external data"
    _, fmt, _ = CT[acc["componentType"]]
    n = NCOMP[acc["type"]]
    size = struct.calcsize("<" + fmt)
    stride = view.get("byteStride", size * n)
    base = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    return [tuple(dequant(acc, struct.unpack_from("<" + fmt * n, bin_chunk, base + i * stride)))
            for i in range(acc["count"])]


def mat_mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def trs(t=(0, 0, 0), r=(0, 0, 0, 1), s=(1, 1, 1)):
    x, y, z, w = r
    rot = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
           [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
           [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    return [[rot[i][0] * s[0], rot[i][1] * s[1], rot[i][2] * s[2], t[i]] for i in range(3)] + [[0, 0, 0, 1]]


def node_matrix(node):
    if "matrix" in node:
        m = node["matrix"]
        return [[m[c * 4 + r] for c in range(4)] for r in range(4)]
    return trs(node.get("translation", (0, 0, 0)), node.get("rotation", (0, 0, 0, 1)), node.get("scale", (1, 1, 1)))


def mesh_triangles(gltf, mesh):
    tris = 0
    for prim in mesh["primitives"]:
        if prim.get("mode", 4) != 4:
            continue
        count = gltf["accessors"][prim["indices"] if "indices" in prim else prim["attributes"]["POSITION"]]["count"]
        tris += count // 3
    return tris


def describe(path):
    gltf, bin_chunk = read_glb(path)
    meshes = gltf.get("meshes", [])
    out = {
        "file": path.name,
        "generator": gltf.get("asset", {}).get("generator", ""),
        "used": gltf.get("extensionsUsed", []),
        "required": gltf.get("extensionsRequired", []),
        "nodes": len(gltf.get("nodes", [])),
        "meshes": len(meshes),
        "mesh_tris": [mesh_triangles(gltf, m) for m in meshes],
        "positions": [],
        "views": [],
    }
    for m, mesh in enumerate(meshes):
        for prim in mesh["primitives"]:
            acc = gltf["accessors"][prim["attributes"]["POSITION"]]
            users = [n for n in gltf.get("nodes", []) if n.get("mesh") == m]
            draco = prim.get("extensions", {}).get("KHR_draco_mesh_compression")
            out["positions"].append({
                "mesh": m, "type": CT[acc["componentType"]][0], "normalized": acc.get("normalized", False),
                "count": acc["count"], "min": acc.get("min"), "max": acc.get("max"),
                "bufferView": acc.get("bufferView"), "draco": draco,
                "node_transforms": sorted({json.dumps({k: n[k] for k in ("translation", "rotation", "scale", "matrix")
                                                       if k in n}) for n in users}),
            })
    for i, view in enumerate(gltf.get("bufferViews", [])):
        if "extensions" in view:
            out["views"].append((i, {k: v for k, v in view.items() if k != "extensions"}, view["extensions"]))
    # scene traversal
    scene = gltf["scenes"][gltf.get("scene", 0)]
    lo, hi, drawn = [math.inf] * 3, [-math.inf] * 3, 0
    stack = [(n, [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) for n in scene["nodes"]]
    while stack:
        index, parent = stack.pop()
        node = gltf["nodes"][index]
        world = mat_mul(parent, node_matrix(node))
        stack.extend((c, world) for c in node.get("children", []))
        if "mesh" not in node:
            continue
        inst = node.get("extensions", {}).get("EXT_mesh_gpu_instancing")
        if inst:
            attrs = inst["attributes"]
            count = gltf["accessors"][next(iter(attrs.values()))]["count"]
            cols = {k: read_floats(gltf, bin_chunk, attrs[k]) if k in attrs else None
                    for k in ("TRANSLATION", "ROTATION", "SCALE")}
            locals_ = [trs(cols["TRANSLATION"][i] if cols["TRANSLATION"] else (0, 0, 0),
                           cols["ROTATION"][i] if cols["ROTATION"] else (0, 0, 0, 1),
                           cols["SCALE"][i] if cols["SCALE"] else (1, 1, 1)) for i in range(count)]
            mats = [mat_mul(world, m) for m in locals_]
        else:
            mats = [world]
        mesh = meshes[node["mesh"]]
        drawn += mesh_triangles(gltf, mesh) * len(mats)
        for prim in mesh["primitives"]:
            acc = gltf["accessors"][prim["attributes"]["POSITION"]]
            amin, amax = dequant(acc, acc["min"]), dequant(acc, acc["max"])
            for m in mats:
                for corner in range(8):
                    p = [amax[i] if corner >> i & 1 else amin[i] for i in range(3)]
                    w = [sum(m[r][c] * p[c] for c in range(3)) + m[r][3] for r in range(3)]
                    lo = [min(a, b) for a, b in zip(lo, w)]
                    hi = [max(a, b) for a, b in zip(hi, w)]
    out["scene_tris"], out["lo"], out["hi"] = drawn, lo, hi
    return out


def fmt(v):
    return "(" + ", ".join(f"{x:.6f}" for x in v) + ")"


def main():
    markdown = "--markdown" in sys.argv
    nverts, ntris, ref_lo, ref_hi = read_obj(OBJ)
    six_hi = [ref_hi[0] + 5 * SIX_STEP, ref_hi[1], ref_hi[2]]
    print(f"reference scenes/bunny.obj: {nverts} vertices, {ntris} triangles, bounds {fmt(ref_lo)} .. {fmt(ref_hi)}")
    print(f"reference six nodes (x step {SIX_STEP:g}): {6 * ntris} triangles, bounds {fmt(ref_lo)} .. {fmt(six_hi)}")
    lod = None
    expected = {}
    for f in sorted(HERE.glob("*.glb")):
        if f.name.startswith("bunny-six-"):
            expected[f.name] = (6 * ntris, ref_lo, six_hi)
        elif f.name in ("bunny-lod-names.glb", "bunny-msft-lod-in-scene.glb"):
            expected[f.name] = (None, ref_lo, ref_hi)  # LOD0 + LOD1 + LOD2, checked below
        else:
            expected[f.name] = (ntris, ref_lo, ref_hi)
    failed = False
    rows = []
    for name, (want_tris, want_lo, want_hi) in expected.items():
        d = describe(HERE / name)
        if name == "bunny-lod-names.glb":
            lod = d["mesh_tris"]
        if want_tris is None:
            want_tris = sum(lod) if lod else d["scene_tris"]
        quantized = any(p["type"] != "f32" for p in d["positions"])
        tol = 1e-3 if quantized else 1e-5
        dev = max(max(abs(a - b) for a, b in zip(d["lo"], want_lo)), max(abs(a - b) for a, b in zip(d["hi"], want_hi)))
        ok = d["scene_tris"] == want_tris and dev <= tol
        failed |= not ok
        print(f"\n{name} [{d['generator']}] {'OK' if ok else 'MISMATCH'}")
        print(f"  extensionsUsed {d['used']} extensionsRequired {d['required']}")
        print(f"  nodes {d['nodes']} meshes {d['meshes']} triangles per mesh {d['mesh_tris']}"
              f" scene triangles {d['scene_tris']} (want {want_tris})")
        for p in d["positions"]:
            print(f"  mesh {p['mesh']} POSITION {p['type']} normalized={p['normalized']} count {p['count']}"
                  f" min {p['min']} max {p['max']} node transforms {p['node_transforms'] or '[none]'}"
                  + (f" draco {p['draco']}" if p["draco"] else ""))
        for i, view, ext in d["views"]:
            print(f"  bufferView {i} {view} extensions {ext}")
        print(f"  world bounds {fmt(d['lo'])} .. {fmt(d['hi'])} (max deviation {dev:.2g}, tolerance {tol:g})")
        rows.append(d)
    if markdown:
        print("\n| file | extensions used / required | meshes | nodes | triangles per mesh | scene triangles |")
        print("| --- | --- | --- | --- | --- | --- |")
        for d in rows:
            used = ", ".join(d["used"]) or "-"
            req = ", ".join(d["required"]) or "-"
            tris = ", ".join(str(t) for t in d["mesh_tris"])
            print(f"| `{d['file']}` | {used} / {req} | {d['meshes']} | {d['nodes']} | {tris} | {d['scene_tris']} |")
    print("\nexpect.py:", "MISMATCH" if failed else "all files OK")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
