#!/usr/bin/env python3
"""Writes tetra.gltf and tetra.glb, the glTF fixtures of src/geometry/mesh.rs's tests (standard library only).

Run from anywhere: python3 tests/data/make_gltf.py. Both files hold the same scene:

- one buffer (120 bytes): 4 float positions of the unit tetrahedron (0,0,0) (1,0,0) (0,1,0) (0,0,1),
  4 float normals (each vertex's direction from the centroid), 12 uint16 indices (4 outward CCW triangles);
- mesh 0 with two primitives: the triangles (with NORMAL) and a POINTS primitive that loaders skip;
- node 0 "base" (mesh 0, no transform) with child node 1 "moved" (mesh 0, translation (2, 0, 0));
- scene 0, the default, holding node 0.

So a loader that merges the default scene's triangles with node transforms gets 8 vertices, 8 triangles,
bounds (0,0,0)..(3,1,1). tetra.gltf embeds the buffer as a base64 data: URI; tetra.glb carries it in the
GLB binary chunk.
"""

import base64
import json
import math
import struct
from pathlib import Path

HERE = Path(__file__).resolve().parent

POSITIONS = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)]
TRIANGLES = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]


def normals():
    c = [sum(p[i] for p in POSITIONS) / len(POSITIONS) for i in range(3)]
    out = []
    for p in POSITIONS:
        d = [p[i] - c[i] for i in range(3)]
        n = math.sqrt(sum(x * x for x in d))
        out.append(tuple(x / n for x in d))
    return out


def buffer_bytes():
    data = b"".join(struct.pack("<3f", *p) for p in POSITIONS)
    data += b"".join(struct.pack("<3f", *n) for n in normals())
    data += b"".join(struct.pack("<3H", *t) for t in TRIANGLES)
    assert len(data) == 120
    return data


def document(buffer):
    """The glTF JSON; `buffer` is the buffers[0] object (with or without a uri)."""
    return {
        "asset": {"version": "2.0", "generator": "lodbench tests/data/make_gltf.py"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [
            {"name": "base", "mesh": 0, "children": [1]},
            {"name": "moved", "mesh": 0, "translation": [2.0, 0.0, 0.0]},
        ],
        "meshes": [
            {
                "name": "tetra",
                "primitives": [
                    {"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "mode": 4},
                    {"attributes": {"POSITION": 0}, "mode": 0},
                ],
            }
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 1.0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5123, "count": 12, "type": "SCALAR"},
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48, "target": 34962},
            {"buffer": 0, "byteOffset": 48, "byteLength": 48, "target": 34962},
            {"buffer": 0, "byteOffset": 96, "byteLength": 24, "target": 34963},
        ],
        "buffers": [buffer],
    }


def readable_json(doc):
    """One top-level key a line, and one array element a line in arrays of objects."""
    def one(v):
        return json.dumps(v, separators=(", ", ": "))

    lines = []
    for key, value in doc.items():
        if isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
            items = ",\n".join("    " + one(v) for v in value)
            lines.append(f"  {json.dumps(key)}: [\n{items}\n  ]")
        else:
            lines.append(f"  {json.dumps(key)}: {one(value)}")
    return "{\n" + ",\n".join(lines) + "\n}\n"


def pad4(b, fill):
    return b + fill * (-len(b) % 4)


def main():
    data = buffer_bytes()
    uri = "data:application/octet-stream;base64," + base64.b64encode(data).decode("ascii")
    gltf = document({"byteLength": len(data), "uri": uri})
    text = readable_json(gltf)
    (HERE / "tetra.gltf").write_text(text, encoding="utf-8")

    # GLB: 12-byte header, then a JSON chunk (space-padded) and a BIN chunk (zero-padded), 4-byte aligned.
    js = pad4(json.dumps(document({"byteLength": len(data)}), separators=(",", ":")).encode("utf-8"), b" ")
    bin_ = pad4(data, b"\0")
    chunks = struct.pack("<I4s", len(js), b"JSON") + js + struct.pack("<I4s", len(bin_), b"BIN\0") + bin_
    glb = struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks
    (HERE / "tetra.glb").write_bytes(glb)


if __name__ == "__main__":
    main()
