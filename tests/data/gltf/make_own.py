#!/usr/bin/env python3
"""Writes the glTF fixtures of tests/data/gltf/ made here (standard library only; CC0 like the rest of this
folder's own files). Run from anywhere: python3 tests/data/gltf/make_own.py.

- faceted-sphere.gltf: a UV sphere (24 segments, 12 rings, radius 1) drawn flat-shaded with a texture layout:
  every triangle has its own three vertices (its face normal on each; TEXCOORD_0 from longitude and latitude), so
  every vertex is split by a hard edge and the meridian at u = 0 / 1 is a texture seam. 528 triangles, 1584
  vertices, indexed in order: the layout that gives a position-only simplifier nothing to collapse (Fox, SciFiHelmet).
- lod-hierarchy.gltf: MSFT_lod as Microsoft's glTF-Toolkit writes it, on a scene root whose levels are node
  hierarchies: node 0 `Lamp_LOD0` (no mesh; children 1 and 2, each a tetrahedron, 1 and 2 units along +x),
  MSFT_lod ids [3]; node 3 `Lamp_LOD1`, outside the scene, with child 4 (one tetrahedron of 4 triangles at 1.5
  along +x, scaled by 1.5); `extras.MSFT_screencoverage` [0.3, 0.0]. LOD0 is 8 triangles (4 + 4), LOD1 is 4.
- still-and-moving.gltf: the faceted sphere (static, at x = -2) beside a tetrahedron (at x = +2) whose one morph
  target lifts its apex by 0.5, at weight 1 at rest; an animation drives the weight 1 -> 0 -> 1 over 2 s (LINEAR),
  so every pose lies inside the rest pose's bounding sphere (the same clip planes with and without the
  animation). The tetrahedron cannot be simplified (a chain of LOD0 alone, never in transition) and is deformed
  every frame; the sphere crosses its switches and never moves: what lodpop sees of the sphere must not depend
  on the animation.
- stretched-instances.gltf: the shape of Blender-IO's tests/roundtrip/24_gpu_instancing (one mesh drawn by two
  EXT_mesh_gpu_instancing nodes, each instance with its own translation, rotation about y and scale), small: a
  smooth UV sphere (32 segments, 16 rings, radius 1, normals along the radius) under a parent node turned 30 deg
  about y; node `stretched` (scale 1, 1.3, 1) places 13 instances, node `plain` 12. Every scale differs and
  stretches (x from 0.6 to 1.4, y and z by other factors); instance 7 of `plain` is mirrored (x negative).
- stretched-expanded.gltf: the same 25 placements, each a node of its own whose `matrix` is the placement's world
  matrix, drawing a mesh of its own (25 meshes over the same accessors): what a reader that gives every scale its
  own model draws, to compare with the shared model's instances.
- integral-floats.gltf: the unit tetrahedron of ../tetra.gltf with every integer written as an integral float
  (`"byteStride": 12.0`, `"componentType": 5126.0`, `"mesh": 0.0`, ...), which the glTF Validator accepts.
"""

import base64
import json
import math
import struct
from pathlib import Path

HERE = Path(__file__).resolve().parent
GENERATOR = "lodbench tests/data/gltf/make_own.py"


def data_uri(data: bytes) -> str:
    return "data:application/octet-stream;base64," + base64.b64encode(data).decode("ascii")


def write(name: str, doc: dict) -> None:
    (HERE / name).write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")


def faceted_sphere(segments: int = 24, rings: int = 12) -> dict:
    def point(i, j):
        theta = math.pi * j / rings
        phi = 2 * math.pi * i / segments
        return (math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi))

    positions, normals, uvs = [], [], []
    for j in range(rings):
        for i in range(segments):
            quad = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
            tris = [(quad[0], quad[2], quad[1]), (quad[0], quad[3], quad[2])]
            if j == 0:
                tris = tris[1:]
            elif j == rings - 1:
                tris = tris[:1]
            for tri in tris:
                p = [point(*c) for c in tri]
                e1 = [p[1][k] - p[0][k] for k in range(3)]
                e2 = [p[2][k] - p[0][k] for k in range(3)]
                n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
                length = math.sqrt(sum(c * c for c in n))
                n = [c / length for c in n]
                for (i2, j2), q in zip(tri, p):
                    positions.append(q)
                    normals.append(n)
                    uvs.append((i2 / segments, j2 / rings))
    count = len(positions)
    data = b"".join(struct.pack("<3f", *p) for p in positions)
    data += b"".join(struct.pack("<3f", *n) for n in normals)
    data += b"".join(struct.pack("<2f", *t) for t in uvs)
    data += struct.pack(f"<{count}H", *range(count))
    lo = [min(p[k] for p in positions) for k in range(3)]
    hi = [max(p[k] for p in positions) for k in range(3)]
    return {
        "asset": {"version": "2.0", "generator": GENERATOR},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"name": "FacetedSphere", "mesh": 0}],
        "meshes": [{"name": "FacetedSphere", "primitives": [
            {"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "mode": 4}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": count, "type": "VEC3", "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5126, "count": count, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": count, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5123, "count": count, "type": "SCALAR"},
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 12 * count},
            {"buffer": 0, "byteOffset": 12 * count, "byteLength": 12 * count},
            {"buffer": 0, "byteOffset": 24 * count, "byteLength": 8 * count},
            {"buffer": 0, "byteOffset": 32 * count, "byteLength": 2 * count},
        ],
        "buffers": [{"byteLength": len(data), "uri": data_uri(data)}],
    }


TETRA = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)]
TETRA_TRIANGLES = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]


def tetra_buffer() -> bytes:
    data = b"".join(struct.pack("<3f", *p) for p in TETRA)
    return data + b"".join(struct.pack("<3H", *t) for t in TETRA_TRIANGLES)


def tetra_accessors() -> tuple[list, list]:
    accessors = [
        {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]},
        {"bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR"},
    ]
    views = [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 24}]
    return accessors, views


def lod_hierarchy() -> dict:
    data = tetra_buffer()
    accessors, views = tetra_accessors()
    return {
        "asset": {"version": "2.0", "generator": GENERATOR},
        "extensionsUsed": ["MSFT_lod"],
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [
            {"name": "Lamp_LOD0", "children": [1, 2], "extensions": {"MSFT_lod": {"ids": [3]}},
             "extras": {"MSFT_screencoverage": [0.3, 0.0]}},
            {"name": "Lamp_LOD0_partA", "mesh": 0, "translation": [1.0, 0.0, 0.0]},
            {"name": "Lamp_LOD0_partB", "mesh": 0, "translation": [2.0, 0.0, 0.0]},
            {"name": "Lamp_LOD1", "children": [4]},
            {"name": "Lamp_LOD1_whole", "mesh": 0, "translation": [1.5, 0.0, 0.0], "scale": [1.5, 1.5, 1.5]},
        ],
        "meshes": [{"name": "tetra", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(data), "uri": data_uri(data)}],
    }


def integral_floats() -> dict:
    data = tetra_buffer()
    return {
        "asset": {"version": "2.0", "generator": GENERATOR},
        "scene": 0.0,
        "scenes": [{"nodes": [0.0]}],
        "nodes": [{"name": "tetra", "mesh": 0.0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0.0}, "indices": 1.0, "mode": 4.0}]}],
        "accessors": [
            {"bufferView": 0.0, "byteOffset": 0.0, "componentType": 5126.0, "count": 4.0, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 1]},
            {"bufferView": 1.0, "componentType": 5123.0, "count": 12.0, "type": "SCALAR"},
        ],
        "bufferViews": [
            {"buffer": 0.0, "byteOffset": 0.0, "byteLength": 48.0, "byteStride": 12.0},
            {"buffer": 0.0, "byteOffset": 48.0, "byteLength": 24.0},
        ],
        "buffers": [{"byteLength": float(len(data)), "uri": data_uri(data)}],
    }


def still_and_moving() -> dict:
    sphere = faceted_sphere()
    data = base64.b64decode(sphere["buffers"][0]["uri"].split(",", 1)[1])
    count = sphere["accessors"][0]["count"]

    def view(byte_offset: int, byte_length: int) -> dict:
        return {"buffer": 0, "byteOffset": byte_offset, "byteLength": byte_length}

    views = [view(v["byteOffset"], v["byteLength"]) for v in sphere["bufferViews"]]
    accessors = list(sphere["accessors"])
    base = len(data)
    tetra = tetra_buffer()
    lift = b"".join(struct.pack("<3f", *p) for p in [(0, 0, 0), (0, 0, 0), (0, 0.5, 0), (0, 0, 0)])
    times = struct.pack("<3f", 0.0, 1.0, 2.0)
    weights = struct.pack("<3f", 1.0, 0.0, 1.0)
    data += tetra + lift + times + weights
    v = len(views)
    views += [view(base, 48), view(base + 48, 24), view(base + 72, 48), view(base + 120, 12), view(base + 132, 12)]
    n = len(accessors)
    accessors += [
        {"bufferView": v, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]},
        {"bufferView": v + 1, "componentType": 5123, "count": 12, "type": "SCALAR"},
        {"bufferView": v + 2, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0],
         "max": [0, 0.5, 0]},
        {"bufferView": v + 3, "componentType": 5126, "count": 3, "type": "SCALAR", "min": [0.0], "max": [2.0]},
        {"bufferView": v + 4, "componentType": 5126, "count": 3, "type": "SCALAR"},
    ]
    assert count == sphere["accessors"][0]["count"]
    return {
        "asset": {"version": "2.0", "generator": GENERATOR},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [
            {"name": "StillSphere", "mesh": 0, "translation": [-2.0, 0.0, 0.0]},
            {"name": "MovingTetra", "mesh": 1, "translation": [2.0, 0.0, 0.0]},
        ],
        "meshes": [
            sphere["meshes"][0],
            {"name": "MovingTetra", "weights": [1.0], "primitives": [
                {"attributes": {"POSITION": n}, "indices": n + 1, "targets": [{"POSITION": n + 2}]}]},
        ],
        "animations": [{"name": "lift", "samplers": [{"input": n + 3, "output": n + 4, "interpolation": "LINEAR"}],
                        "channels": [{"sampler": 0, "target": {"node": 1, "path": "weights"}}]}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(data), "uri": data_uri(data)}],
    }


def smooth_sphere(segments: int = 32, rings: int = 16) -> tuple[bytes, list, list, int]:
    """A UV sphere of radius 1 with shared vertices (normal = position): its buffer, accessors, views, count."""
    verts = []
    for j in range(rings + 1):
        theta = math.pi * j / rings
        for i in range(segments + 1):
            phi = 2 * math.pi * i / segments
            verts.append((math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi)))
    tris = []
    row = segments + 1
    for j in range(rings):
        for i in range(segments):
            a, b, c, d = j * row + i, j * row + i + 1, (j + 1) * row + i + 1, (j + 1) * row + i
            if j > 0:
                tris.append((a, b, c))
            if j < rings - 1:
                tris.append((a, c, d))
    pos = b"".join(struct.pack("<3f", *v) for v in verts)
    idx = b"".join(struct.pack("<3H", *t) for t in tris)
    data = pos + pos + idx
    n = len(verts)
    accessors = [
        {"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3", "min": [-1, -1, -1], "max": [1, 1, 1]},
        {"bufferView": 1, "componentType": 5126, "count": n, "type": "VEC3"},
        {"bufferView": 2, "componentType": 5123, "count": 3 * len(tris), "type": "SCALAR"},
    ]
    views = [
        {"buffer": 0, "byteOffset": 0, "byteLength": len(pos)},
        {"buffer": 0, "byteOffset": len(pos), "byteLength": len(pos)},
        {"buffer": 0, "byteOffset": 2 * len(pos), "byteLength": len(idx)},
    ]
    return data, accessors, views, len(data)


def stretched_placements() -> list[tuple[str, tuple, float, tuple]]:
    """The 25 instances: (node, translation, angle about y in radians, scale)."""
    out = []
    for k in range(25):
        node = "stretched" if k < 13 else "plain"
        x, z = (k % 5 - 2) * 3.0, (k // 5 - 2) * 3.0
        s = 0.6 + 0.8 * ((k * 7) % 25) / 24
        scale = (s, s * (1.0 + 0.5 * ((k * 3) % 5) / 4), s * (0.8 + 0.4 * ((k * 2) % 7) / 6))
        if k == 13 + 7:
            scale = (-scale[0], scale[1], scale[2])
        out.append((node, (x, 0.0, z), 0.4 * k, scale))
    return out


def mat_mul(a: list, b: list) -> list:
    """Column-major 4x4 product a x b."""
    return [sum(a[r + 4 * k] * b[k + 4 * c] for k in range(4)) for c in range(4) for r in range(4)]


def trs(t: tuple, angle: float, s: tuple) -> list:
    """Column-major T x R_y(angle) x S."""
    c, n = math.cos(angle), math.sin(angle)
    return [c * s[0], 0, -n * s[0], 0, 0, s[1], 0, 0, n * s[2], 0, c * s[2], 0, t[0], t[1], t[2], 1]


PARENT_ANGLE = math.radians(30.0)
NODE_SCALE = {"stretched": (1.0, 1.3, 1.0), "plain": (1.0, 1.0, 1.0)}


def stretched_instances() -> dict:
    data, accessors, views, _ = smooth_sphere()
    places = stretched_placements()
    nodes = [{"name": "parent", "rotation": [0.0, math.sin(PARENT_ANGLE / 2), 0.0, math.cos(PARENT_ANGLE / 2)],
              "children": [1, 2]}]
    for name in ("stretched", "plain"):
        mine = [p for p in places if p[0] == name]
        base = len(data)
        t = b"".join(struct.pack("<3f", *p[1]) for p in mine)
        r = b"".join(struct.pack("<4f", 0.0, math.sin(p[2] / 2), 0.0, math.cos(p[2] / 2)) for p in mine)
        sc = b"".join(struct.pack("<3f", *p[3]) for p in mine)
        data += t + r + sc
        attrs = {}
        for key, blob, off, kind in (("TRANSLATION", t, 0, "VEC3"), ("ROTATION", r, len(t), "VEC4"),
                                     ("SCALE", sc, len(t) + len(r), "VEC3")):
            views.append({"buffer": 0, "byteOffset": base + off, "byteLength": len(blob)})
            accessors.append({"bufferView": len(views) - 1, "componentType": 5126, "count": len(mine),
                              "type": kind})
            attrs[key] = len(accessors) - 1
        node = {"name": name, "mesh": 0, "extensions": {"EXT_mesh_gpu_instancing": {"attributes": attrs}}}
        if NODE_SCALE[name] != (1.0, 1.0, 1.0):
            node["scale"] = list(NODE_SCALE[name])
        nodes.append(node)
    return {
        "asset": {"version": "2.0", "generator": GENERATOR},
        "extensionsUsed": ["EXT_mesh_gpu_instancing"],
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": nodes,
        "meshes": [{"name": "sphere", "primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2}]}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(data), "uri": data_uri(data)}],
    }


def stretched_expanded() -> dict:
    data, accessors, views, _ = smooth_sphere()
    parent = trs((0.0, 0.0, 0.0), PARENT_ANGLE, (1.0, 1.0, 1.0))
    nodes, meshes = [], []
    for k, (name, t, angle, s) in enumerate(stretched_placements()):
        world = mat_mul(parent, mat_mul(trs((0.0, 0.0, 0.0), 0.0, NODE_SCALE[name]), trs(t, angle, s)))
        nodes.append({"name": f"{name}.{k}", "mesh": k, "matrix": [round(v, 9) for v in world]})
        meshes.append({"name": f"sphere{k}", "primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1},
                                                             "indices": 2}]})
    return {
        "asset": {"version": "2.0", "generator": GENERATOR},
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": meshes,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(data), "uri": data_uri(data)}],
    }


def main() -> None:
    write("faceted-sphere.gltf", faceted_sphere())
    write("lod-hierarchy.gltf", lod_hierarchy())
    write("integral-floats.gltf", integral_floats())
    write("still-and-moving.gltf", still_and_moving())
    write("stretched-instances.gltf", stretched_instances())
    write("stretched-expanded.gltf", stretched_expanded())


if __name__ == "__main__":
    main()
