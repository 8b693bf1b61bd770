#!/usr/bin/env python3
"""Writes the material fixtures of tests/data/gltf/ (standard library only; CC0 1.0 like this folder's own files),
read by tests/it/gpu_materials.rs and tests/it/measure_lodpop.rs. Run from anywhere:
python3 tests/data/gltf/make_materials.py.

Every file is quads in the z = 0 plane facing +z (the default flight looks along -z), textures embedded as PNG
data URIs, samplers NEAREST without mipmaps where a test reads texels, KHR_materials_unlit where a test needs
exact colours (an unlit material's colour is its base colour, whatever the light).

- texel-grid.gltf: one unit quad, unlit, a 4 x 4 texture of 16 distinct colours (TEXEL_GRID below), NEAREST.
  Its KHR_texture_transform offsets u by 0.25 (REPEAT): the quad's left column of texels is the texture's
  column 1, its right column the texture's column 0.
- leaf-cards.gltf: an authored chain (MSFT_lod) of cut-out cards, alphaMode MASK (cutoff 0.5), doubleSided, a
  32 x 32 texture whose alpha is 255 on texels whose centre lies within 0.5 of the texture's centre and 0
  elsewhere (DISC_FRACTION of the texels), NEAREST: LOD0 is 4 x 4 cards of side 0.5, LOD1 2 x 2 cards of side 1
  over the same square (both 2 units wide); extras.MSFT_screencoverage [0.5, 0.0].
- pop-shading.gltf: an authored chain whose levels have the same outline and differ in colour: LOD0 a unit quad
  of 8 triangles (2 x 2 squares), unlit red; LOD1 the unit quad of 2 triangles, unlit blue. A switch changes
  colours only.
- pop-coverage.gltf: an authored chain whose levels have the same colour and differ in outline: LOD0 a unit quad
  of 8 triangles, unlit white; LOD1 a quad of 2 triangles, 0.6 units wide, unlit white, centred on it. A switch
  uncovers a ring only.
- blend-over.gltf: an opaque unlit green quad at z = 0 and, 0.1 in front of it, a smaller BLEND unlit quad of
  base colour (1, 0, 0, 0.5): where they overlap the colour is half red over green.
"""

import base64
import json
import struct
import zlib
from pathlib import Path

HERE = Path(__file__).resolve().parent
GENERATOR = "lodbench tests/data/gltf/make_materials.py"

# Row-major, top row first (glTF's texture origin is the top-left corner): 16 distinct opaque colours.
TEXEL_GRID = [[(r * 60 + 20, c * 60 + 30, (r * 4 + c) * 15, 255) for c in range(4)] for r in range(4)]
DISC_SIDE = 32


def disc_alpha(x: int, y: int) -> int:
    cx, cy = (x + 0.5) / DISC_SIDE - 0.5, (y + 0.5) / DISC_SIDE - 0.5
    return 255 if cx * cx + cy * cy <= 0.25 else 0


DISC_FRACTION = sum(disc_alpha(x, y) == 255 for x in range(DISC_SIDE) for y in range(DISC_SIDE)) / DISC_SIDE**2


def png(rows) -> bytes:
    """An RGBA8 PNG of `rows` (lists of (r, g, b, a))."""
    height, width = len(rows), len(rows[0])
    raw = b"".join(b"\0" + bytes(c for px in row for c in px) for row in rows)

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def data_uri(data: bytes, mime: str) -> str:
    return f"data:{mime};base64," + base64.b64encode(data).decode("ascii")


class Doc:
    """A glTF document built mesh by mesh, its binary data in one buffer."""

    def __init__(self):
        self.data = bytearray()
        self.doc = {"asset": {"version": "2.0", "generator": GENERATOR}, "scene": 0, "scenes": [{"nodes": []}],
                    "nodes": [], "meshes": [], "materials": [], "accessors": [], "bufferViews": [],
                    "buffers": [], "textures": [], "images": [], "samplers": [], "extensionsUsed": []}

    def use(self, ext):
        if ext not in self.doc["extensionsUsed"]:
            self.doc["extensionsUsed"].append(ext)

    def accessor(self, fmt, values, kind, component, target, minmax=False):
        while len(self.data) % 4:
            self.data.append(0)
        start = len(self.data)
        for v in values:
            self.data += struct.pack(fmt, *v) if isinstance(v, tuple) else struct.pack(fmt, v)
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": start, "byteLength": len(self.data) - start,
                                        "target": target})
        acc = {"bufferView": len(self.doc["bufferViews"]) - 1, "componentType": component, "count": len(values),
               "type": kind}
        if minmax:
            acc["min"] = [min(v[k] for v in values) for k in range(3)]
            acc["max"] = [max(v[k] for v in values) for k in range(3)]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def texture(self, rows, nearest=True, transform=None):
        self.doc["images"].append({"uri": data_uri(png(rows), "image/png")})
        sampler = {"magFilter": 9728, "minFilter": 9728} if nearest else {}
        self.doc["samplers"].append(sampler)
        self.doc["textures"].append({"source": len(self.doc["images"]) - 1, "sampler": len(self.doc["samplers"]) - 1})
        info = {"index": len(self.doc["textures"]) - 1}
        if transform:
            self.use("KHR_texture_transform")
            info["extensions"] = {"KHR_texture_transform": transform}
        return info

    def material(self, name, color, texture=None, unlit=True, **extra):
        pbr = {"baseColorFactor": list(color), "metallicFactor": 0.0, "roughnessFactor": 1.0}
        if texture:
            pbr["baseColorTexture"] = texture
        m = {"name": name, "pbrMetallicRoughness": pbr, **extra}
        if unlit:
            self.use("KHR_materials_unlit")
            m["extensions"] = {"KHR_materials_unlit": {}}
        self.doc["materials"].append(m)
        return len(self.doc["materials"]) - 1

    def quads(self, name, squares, material):
        """A mesh of axis-aligned squares in z: each (x0, y0, side, z), split into its 2 triangles, texture
        coordinates 0..1 across each square (v down)."""
        pos, uv, idx = [], [], []
        for x0, y0, side, z in squares:
            b = len(pos)
            pos += [(x0, y0, z), (x0 + side, y0, z), (x0 + side, y0 + side, z), (x0, y0 + side, z)]
            uv += [(0.0, 1.0), (1.0, 1.0), (1.0, 0.0), (0.0, 0.0)]
            idx += [b, b + 1, b + 2, b, b + 2, b + 3]
        attrs = {"POSITION": self.accessor("<3f", pos, "VEC3", 5126, 34962, minmax=True),
                 "NORMAL": self.accessor("<3f", [(0.0, 0.0, 1.0)] * len(pos), "VEC3", 5126, 34962),
                 "TEXCOORD_0": self.accessor("<2f", uv, "VEC2", 5126, 34962)}
        indices = self.accessor("<H", idx, "SCALAR", 5123, 34963)
        self.doc["meshes"].append({"name": name, "primitives": [
            {"attributes": attrs, "indices": indices, "material": material}]})
        return len(self.doc["meshes"]) - 1

    def node(self, name, mesh, in_scene=True, **extra):
        self.doc["nodes"].append({"name": name, "mesh": mesh, **extra})
        n = len(self.doc["nodes"]) - 1
        if in_scene:
            self.doc["scenes"][0]["nodes"].append(n)
        return n

    def chain(self, name, lod0, lod1, coverage=(0.5, 0.0)):
        """MSFT_lod on a node of mesh `lod0`, its level 1 a node (outside the scene) of mesh `lod1`."""
        self.use("MSFT_lod")
        level1 = len(self.doc["nodes"]) + 1
        self.node(f"{name}_LOD0", lod0, extensions={"MSFT_lod": {"ids": [level1]}},
                  extras={"MSFT_screencoverage": list(coverage)})
        self.node(f"{name}_LOD1", lod1, in_scene=False)

    def write(self, file):
        self.doc["buffers"] = [{"byteLength": len(self.data),
                                "uri": data_uri(bytes(self.data), "application/octet-stream")}]
        for key in ("textures", "images", "samplers", "extensionsUsed"):
            if not self.doc[key]:
                del self.doc[key]
        (HERE / file).write_text(json.dumps(self.doc, indent=1) + "\n", encoding="utf-8")


def grid(side, cells, z=0.0):
    """The squares of a `cells` x `cells` grid covering a square of `side` centred on the origin."""
    s = side / cells
    return [(-side / 2 + i * s, -side / 2 + j * s, s, z) for j in range(cells) for i in range(cells)]


def texel_grid():
    d = Doc()
    tex = d.texture(TEXEL_GRID, transform={"offset": [0.25, 0.0]})
    d.node("Texels", d.quads("Texels", grid(1.0, 1), d.material("texels", (1, 1, 1, 1), tex)))
    d.write("texel-grid.gltf")


def leaf_cards():
    d = Doc()
    rows = [[(40, 140, 40, disc_alpha(x, y)) for x in range(DISC_SIDE)] for y in range(DISC_SIDE)]
    leaf = d.material("leaf", (1, 1, 1, 1), d.texture(rows), unlit=True, alphaMode="MASK", alphaCutoff=0.5,
                      doubleSided=True)
    d.chain("Cards", d.quads("Cards4x4", grid(2.0, 4), leaf), d.quads("Cards2x2", grid(2.0, 2), leaf))
    d.write("leaf-cards.gltf")


def pop_shading():
    d = Doc()
    d.chain("Quad", d.quads("Fine", grid(1.0, 2), d.material("red", (1, 0, 0, 1))),
            d.quads("Coarse", grid(1.0, 1), d.material("blue", (0, 0, 1, 1))))
    d.write("pop-shading.gltf")


def pop_coverage():
    d = Doc()
    white = d.material("white", (1, 1, 1, 1))
    d.chain("Quad", d.quads("Fine", grid(1.0, 2), white), d.quads("Smaller", grid(0.6, 1), white))
    d.write("pop-coverage.gltf")


def blend_over():
    d = Doc()
    d.node("Back", d.quads("Back", grid(1.0, 1), d.material("green", (0, 1, 0, 1))))
    glass = d.material("glass", (1, 0, 0, 0.5), alphaMode="BLEND")
    d.node("Front", d.quads("Front", grid(0.5, 1, z=0.1), glass))
    d.write("blend-over.gltf")


if __name__ == "__main__":
    texel_grid()
    leaf_cards()
    pop_shading()
    pop_coverage()
    blend_over()
    print(f"disc fraction {DISC_FRACTION:.6f}")
