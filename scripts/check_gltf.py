#!/usr/bin/env python3
"""An independent glTF 2.0 geometry decoder, written from the specification, to check what lodbench draws.

    python3 scripts/check_gltf.py decode FILE.gltf|.glb [--animation N|none] [--time T] --out OUT.obj
    python3 scripts/check_gltf.py compare FILE.gltf|.glb LODBENCH.obj [--tol X]
    python3 scripts/check_gltf.py run --lodbench BINARY [--frames 0,30] [--jobs N] FILES_OR_DIRS...

`decode` writes the world-space triangles of every mesh node of the default scene (`scene`, else scene 0, else
every parentless node) at a time of one animation (or the rest pose) as an OBJ: one group `o node<N>` per node
(`o node<N>.<I>` per instance of EXT_mesh_gpu_instancing), three `v` (and, where any primitive has normals, three
`vn`) per triangle, `f a//a b//b c//c`.

`compare` reads the OBJ that `lodbench export` wrote (its `# frame F animation A time T` header says what to
decode, `# skipped node N: why` lines name nodes it left out, `# node N holds n1 n2 ...` lines name nodes whose
triangles follow N's own in N's group), decodes the glTF itself and compares group by group, triangle by
triangle in order: the three vertices up to a cyclic rotation (never a reflection, so a winding error shows),
each within `tol` (default 1e-4 * the diagonal of the decoded scene's bounding box + 1e-6), and normals within
1e-3 rad where both sides have them.

`run` exports every .gltf/.glb found with lodbench at each frame (frame 0 also with `--animation none`) and
compares each export; a lodbench run that fails is "refused", not a mismatch.

Exit status: 0 every compared file OK, 1 a mismatch (or a file this decoder could not read), 3 when the only
problems were files not checked (geometry compressed with meshopt or Draco, which this decoder does not
decompress).

What is decoded (glTF 2.0 specification section in brackets): accessors of every component type, normalized
integers dequantized as the specification says, byteStride, byteOffset of view and accessor, padded matrix
columns, accessors without a bufferView (zeros), sparse accessors (3.6.2); primitive modes TRIANGLES,
TRIANGLE_STRIP and TRIANGLE_FAN (3.7.2.1; points and lines are skipped); node matrix or T*R*S and the hierarchy
(3.5); animation channels on translation, rotation, scale and weights with STEP, LINEAR (slerp for rotations)
and CUBICSPLINE samplers, time clamped to the keys (3.11, Appendix C); morph targets (3.7.2.2); skins, the skinned
node's own transform ignored (3.7.3); EXT_mesh_gpu_instancing (instance T*R*S before the node's world matrix);
normals by the inverse transpose; winding reversed where a (non-skinned) world matrix has a negative determinant.
"""
from __future__ import annotations

import argparse
import base64
import concurrent.futures
import json
import math
import re
import struct
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from urllib.parse import unquote, unquote_to_bytes

import numpy as np

EXIT_OK, EXIT_MISMATCH, EXIT_NOT_CHECKED = 0, 1, 3

COMPONENT_DTYPES = {5120: "<i1", 5121: "<u1", 5122: "<i2", 5123: "<u2", 5125: "<u4", 5126: "<f4"}
NORMALIZED_DIVISORS = {5120: 127.0, 5121: 255.0, 5122: 32767.0, 5123: 65535.0, 5125: 4294967295.0}
TYPE_SHAPES = {  # (columns, rows)
    "SCALAR": (1, 1), "VEC2": (1, 2), "VEC3": (1, 3), "VEC4": (1, 4), "MAT2": (2, 2), "MAT3": (3, 3), "MAT4": (4, 4),
}
MESHOPT_EXTENSIONS = ("EXT_meshopt_compression", "KHR_meshopt_compression")
DRACO_EXTENSION = "KHR_draco_mesh_compression"
INSTANCING_EXTENSION = "EXT_mesh_gpu_instancing"
TRIANGLE_MODES = (4, 5, 6)
GLB_JSON, GLB_BIN = 0x4E4F534A, 0x004E4942
NORMAL_ANGLE = 1e-3
REPORT_LIMIT = 5


class GltfError(Exception):
    """The file breaks the specification in a way that stops decoding."""


class NotChecked(Exception):
    """Geometry the scene needs is compressed with an extension this decoder does not implement."""

    def __init__(self, extension: str):
        super().__init__(f"not checked: {extension}")
        self.extension = extension


# ---------------------------------------------------------------------------------------------------------------
# Files and buffers


@dataclass
class Document:
    """A parsed glTF: its JSON, the folder its relative URIs start from, the GLB's BIN chunk, and caches."""

    gltf: dict
    base: Path
    glb_bin: bytes | None = None
    buffers: dict = field(default_factory=dict)
    accessors: dict = field(default_factory=dict)


def _parse_float(text: str) -> float | int:
    """JSON numbers with a fraction or exponent that are integral (`24.0`) become ints, so that indices, counts,
    offsets and strides written as floats are accepted; every float field is converted with float() anyway."""
    value = float(text)
    return int(value) if value.is_integer() else value


def parse_json(data: bytes) -> dict:
    """The glTF JSON (UTF-8, a byte order mark tolerated)."""
    text = data.decode("utf-8-sig")
    doc = json.loads(text, parse_float=_parse_float)
    if not isinstance(doc, dict):
        raise GltfError("the JSON is not an object")
    return doc


def parse_glb(data: bytes) -> tuple[dict, bytes | None]:
    """The JSON and the BIN chunk (or None) of a GLB container (section 4.4)."""
    if len(data) < 20:
        raise GltfError("GLB shorter than its header")
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    if magic != b"glTF" or version != 2:
        raise GltfError(f"not a GLB version 2 (magic {magic!r}, version {version})")
    end = min(length, len(data))
    offset, json_chunk, bin_chunk = 12, None, None
    while offset + 8 <= end:
        chunk_length, chunk_type = struct.unpack_from("<II", data, offset)
        chunk = data[offset + 8:offset + 8 + chunk_length]
        if chunk_type == GLB_JSON and json_chunk is None:
            json_chunk = chunk
        elif chunk_type == GLB_BIN and bin_chunk is None and json_chunk is not None:
            bin_chunk = chunk
        offset += 8 + chunk_length
    if json_chunk is None:
        raise GltfError("GLB without a JSON chunk")
    return parse_json(json_chunk), bin_chunk


def load_document(path: Path) -> Document:
    """Reads a .gltf or .glb (told apart by the GLB magic, not the name)."""
    path = Path(path)
    data = path.read_bytes()
    if data[:4] == b"glTF":
        gltf, bin_chunk = parse_glb(data)
    else:
        gltf, bin_chunk = parse_json(data), None
    return Document(gltf=gltf, base=path.resolve().parent, glb_bin=bin_chunk)


def decode_data_uri(uri: str) -> bytes:
    """The bytes of a `data:` URI, base64 or percent-encoded."""
    header, sep, payload = uri.partition(",")
    if not sep:
        raise GltfError("data URI without a comma")
    if header.endswith(";base64"):
        return base64.b64decode(payload)
    return unquote_to_bytes(payload)


def buffer_data(doc: Document, index: int) -> bytes:
    """The bytes of buffer `index`: a data URI, a file beside the glTF, or the GLB's BIN chunk. A buffer without a
    URI that only backs meshopt-compressed views (its `fallback`) reads as zeros."""
    if index in doc.buffers:
        return doc.buffers[index]
    buffers = doc.gltf.get("buffers", [])
    if not 0 <= index < len(buffers):
        raise GltfError(f"buffer {index} does not exist")
    buf = buffers[index]
    uri = buf.get("uri")
    length = buf.get("byteLength", 0)
    if uri is None:
        extensions = buf.get("extensions", {})
        if index == 0 and doc.glb_bin is not None:
            data = doc.glb_bin
        elif any(e in extensions for e in MESHOPT_EXTENSIONS):
            data = bytes(length)
        else:
            raise GltfError(f"buffer {index} has no uri and there is no GLB BIN chunk")
    elif uri.startswith("data:"):
        data = decode_data_uri(uri)
    else:
        data = (doc.base / unquote(uri)).read_bytes()
    if len(data) < length:
        raise GltfError(f"buffer {index}: {len(data)} bytes, byteLength {length}")
    doc.buffers[index] = data
    return data


# ---------------------------------------------------------------------------------------------------------------
# Accessors


def _align4(n: int) -> int:
    """n rounded up to a multiple of 4."""
    return (n + 3) // 4 * 4


def _element_layout(ctype: int, type_name: str) -> tuple[np.dtype, int, int, int]:
    """dtype, columns, rows and bytes between columns of one element (matrix columns start on 4-byte
    boundaries, section 3.6.2.4)."""
    if ctype not in COMPONENT_DTYPES:
        raise GltfError(f"unknown componentType {ctype}")
    if type_name not in TYPE_SHAPES:
        raise GltfError(f"unknown accessor type {type_name}")
    dtype = np.dtype(COMPONENT_DTYPES[ctype])
    cols, rows = TYPE_SHAPES[type_name]
    column_stride = _align4(rows * dtype.itemsize) if cols > 1 else rows * dtype.itemsize
    return dtype, cols, rows, column_stride


def _check_view_compression(view: dict) -> None:
    """Raises NotChecked for a bufferView whose real bytes are meshopt-compressed."""
    for name in MESHOPT_EXTENSIONS:
        if name in view.get("extensions", {}):
            raise NotChecked(name)


def read_view_elements(doc: Document, view_index: int, byte_offset: int, count: int, ctype: int, type_name: str,
                       packed: bool = False) -> np.ndarray:
    """`count` elements from a bufferView, as raw components of shape (count, columns*rows), matrices flattened
    column by column. `packed` ignores byteStride (sparse indices and values are tightly packed)."""
    dtype, cols, rows, column_stride = _element_layout(ctype, type_name)
    views = doc.gltf.get("bufferViews", [])
    if not 0 <= view_index < len(views):
        raise GltfError(f"bufferView {view_index} does not exist")
    view = views[view_index]
    _check_view_compression(view)
    data = buffer_data(doc, view["buffer"])
    element_size = column_stride * cols
    stride = element_size if packed else (view.get("byteStride") or element_size)
    start = view.get("byteOffset", 0) + byte_offset
    view_end = view.get("byteOffset", 0) + view.get("byteLength", len(data))
    if count == 0:
        return np.zeros((0, cols * rows), dtype)
    last = start + (count - 1) * stride + element_size
    if last > view_end or view_end > len(data):
        raise GltfError(f"bufferView {view_index}: {count} elements of {element_size} bytes at offset {start} "
                        f"stride {stride} run past its end")
    arr = np.ndarray((count, cols, rows), dtype=dtype, buffer=data, offset=start,
                     strides=(stride, column_stride, dtype.itemsize))
    return arr.reshape(count, cols * rows).copy()


def dequantize(raw: np.ndarray, ctype: int, normalized: bool) -> np.ndarray:
    """Components as float64; normalized integers by the specification's equations (3.11, animation section):
    max(c/127, -1), c/255, max(c/32767, -1), c/65535."""
    values = raw.astype(np.float64)
    if not normalized or ctype not in NORMALIZED_DIVISORS:
        return values
    values /= NORMALIZED_DIVISORS[ctype]
    if ctype in (5120, 5122):
        np.maximum(values, -1.0, out=values)
    return values


def _apply_sparse(doc: Document, sparse: dict, raw: np.ndarray, ctype: int, type_name: str) -> np.ndarray:
    """raw with the sparse substitution applied (section 3.6.2.3)."""
    count = sparse["count"]
    indices_spec, values_spec = sparse["indices"], sparse["values"]
    indices = read_view_elements(doc, indices_spec["bufferView"], indices_spec.get("byteOffset", 0), count,
                                 indices_spec["componentType"], "SCALAR", packed=True)[:, 0].astype(np.int64)
    values = read_view_elements(doc, values_spec["bufferView"], values_spec.get("byteOffset", 0), count, ctype,
                                type_name, packed=True)
    if count and (indices.min() < 0 or indices.max() >= len(raw)):
        raise GltfError("sparse index out of the accessor's range")
    out = raw.copy()
    out[indices] = values
    return out


def read_accessor(doc: Document, index: int, normalize: bool = True) -> np.ndarray:
    """Accessor `index` as an array of shape (count, components): float64 dequantized when `normalize`, else the
    raw integers (indices, joints). Cached in the document; the result is read-only."""
    key = (index, normalize)
    if key in doc.accessors:
        return doc.accessors[key]
    accessors = doc.gltf.get("accessors", [])
    if not 0 <= index < len(accessors):
        raise GltfError(f"accessor {index} does not exist")
    acc = accessors[index]
    ctype, type_name, count = acc["componentType"], acc["type"], acc["count"]
    dtype, cols, rows, _ = _element_layout(ctype, type_name)
    if "bufferView" in acc:
        raw = read_view_elements(doc, acc["bufferView"], acc.get("byteOffset", 0), count, ctype, type_name)
    else:
        raw = np.zeros((count, cols * rows), dtype)
    if "sparse" in acc:
        raw = _apply_sparse(doc, acc["sparse"], raw, ctype, type_name)
    out = dequantize(raw, ctype, bool(acc.get("normalized", False))) if normalize else raw.astype(np.int64)
    out.flags.writeable = False
    doc.accessors[key] = out
    return out


# ---------------------------------------------------------------------------------------------------------------
# Transforms


def quat_matrices(q: np.ndarray) -> np.ndarray:
    """Rotation matrices (n, 3, 3) of quaternions (n, 4) stored x, y, z, w (normalized first; a zero quaternion
    gives the identity)."""
    q = np.asarray(q, dtype=np.float64).reshape(-1, 4)
    norm = np.linalg.norm(q, axis=1, keepdims=True)
    q = np.where(norm > 0, q / np.where(norm > 0, norm, 1.0), np.array([0.0, 0.0, 0.0, 1.0]))
    x, y, z, w = q.T
    m = np.empty((len(q), 3, 3))
    m[:, 0, 0] = 1 - 2 * (y * y + z * z)
    m[:, 0, 1] = 2 * (x * y - z * w)
    m[:, 0, 2] = 2 * (x * z + y * w)
    m[:, 1, 0] = 2 * (x * y + z * w)
    m[:, 1, 1] = 1 - 2 * (x * x + z * z)
    m[:, 1, 2] = 2 * (y * z - x * w)
    m[:, 2, 0] = 2 * (x * z - y * w)
    m[:, 2, 1] = 2 * (y * z + x * w)
    m[:, 2, 2] = 1 - 2 * (x * x + y * y)
    return m


def trs_matrices(t: np.ndarray, r: np.ndarray, s: np.ndarray) -> np.ndarray:
    """T * R * S as (n, 4, 4) from translations (n, 3), quaternions (n, 4) and scales (n, 3)."""
    t, s = np.asarray(t, float).reshape(-1, 3), np.asarray(s, float).reshape(-1, 3)
    rot = quat_matrices(r)
    m = np.zeros((len(rot), 4, 4))
    m[:, :3, :3] = rot * s[:, None, :]
    m[:, :3, 3] = t
    m[:, 3, 3] = 1.0
    return m


def local_matrix(node: dict, animated: dict) -> np.ndarray:
    """A node's local matrix: its `matrix` (column-major), or T * R * S with animated values replacing the node's
    own. A node with a matrix that is nevertheless animated uses its TRS properties (the specification forbids
    animating such a node)."""
    animated_trs = any(k in animated for k in ("translation", "rotation", "scale"))
    if "matrix" in node and not animated_trs:
        return np.array(node["matrix"], dtype=np.float64).reshape(4, 4).T
    t = animated.get("translation", node.get("translation", [0.0, 0.0, 0.0]))
    r = animated.get("rotation", node.get("rotation", [0.0, 0.0, 0.0, 1.0]))
    s = animated.get("scale", node.get("scale", [1.0, 1.0, 1.0]))
    return trs_matrices(t, r, s)[0]


def parents(gltf: dict) -> dict[int, int]:
    """Each node's parent."""
    out = {}
    for i, node in enumerate(gltf.get("nodes", [])):
        for child in node.get("children", []):
            out[child] = i
    return out


def world_matrices(gltf: dict, state: dict) -> list[np.ndarray]:
    """Every node's global matrix (parent's global times local), with the animation state applied."""
    nodes = gltf.get("nodes", [])
    parent = parents(gltf)
    local = [local_matrix(n, state.get(i, {})) for i, n in enumerate(nodes)]
    world: list[np.ndarray | None] = [None] * len(nodes)
    for i in range(len(nodes)):
        chain, j = [], i
        while j is not None and world[j] is None:
            if j in chain:
                raise GltfError(f"node hierarchy has a cycle through node {j}")
            chain.append(j)
            j = parent.get(j)
        for k in reversed(chain):
            p = parent.get(k)
            world[k] = local[k] if p is None else world[p] @ local[k]
    return world


def scene_nodes(gltf: dict) -> list[int]:
    """The nodes of the default scene (`scene`, else scene 0, else every parentless node), depth first, each once."""
    scenes = gltf.get("scenes", [])
    if scenes:
        roots = scenes[gltf.get("scene", 0)].get("nodes", [])
    else:
        parent = parents(gltf)
        roots = [i for i in range(len(gltf.get("nodes", []))) if i not in parent]
    order, seen, stack = [], set(), list(reversed(roots))
    while stack:
        i = stack.pop()
        if i in seen:
            continue
        seen.add(i)
        order.append(i)
        stack.extend(reversed(gltf["nodes"][i].get("children", [])))
    return order


# ---------------------------------------------------------------------------------------------------------------
# Animation (section 3.11 and Appendix C)


def slerp(q0: np.ndarray, q1: np.ndarray, u: float) -> np.ndarray:
    """Spherical linear interpolation along the short arc (Appendix C.3), normalized."""
    d = float(np.dot(q0, q1))
    sign = 1.0 if d >= 0 else -1.0
    a = math.acos(min(abs(d), 1.0))
    if math.sin(a) < 1e-9:
        r = (1 - u) * q0 + sign * u * q1
    else:
        r = math.sin(a * (1 - u)) / math.sin(a) * q0 + sign * math.sin(a * u) / math.sin(a) * q1
    return r / np.linalg.norm(r)


def sample(times: np.ndarray, values: np.ndarray, interpolation: str, t: float, rotation: bool) -> np.ndarray:
    """The sampler's value at time t, t clamped to [first key, last key]. values: (keys, width) for STEP and
    LINEAR, (keys * 3, width) in-tangent, value, out-tangent per key for CUBICSPLINE. Rotations are normalized."""
    n = len(times)
    if n == 0:
        raise GltfError("animation sampler without keys")
    cubic = interpolation == "CUBICSPLINE"
    triples = values.reshape(n, 3, -1) if cubic else None
    keys = triples[:, 1] if cubic else values[:n]

    def finish(v: np.ndarray) -> np.ndarray:
        v = np.asarray(v, dtype=np.float64)
        if rotation:
            norm = np.linalg.norm(v)
            return v / norm if norm > 0 else v
        return v

    if n == 1 or t <= times[0]:
        return finish(keys[0])
    if t >= times[-1]:
        return finish(keys[-1])
    k = int(np.searchsorted(times, t, side="right")) - 1
    t0, t1 = float(times[k]), float(times[k + 1])
    td = t1 - t0
    u = (t - t0) / td
    if interpolation == "STEP":
        return finish(keys[k])
    if cubic:
        h00, h10 = 2 * u ** 3 - 3 * u ** 2 + 1, u ** 3 - 2 * u ** 2 + u
        h01, h11 = -2 * u ** 3 + 3 * u ** 2, u ** 3 - u ** 2
        v = (h00 * triples[k, 1] + h10 * td * triples[k, 2] + h01 * triples[k + 1, 1]
             + h11 * td * triples[k + 1, 0])
        return finish(v)
    if rotation:
        return slerp(np.asarray(keys[k], float), np.asarray(keys[k + 1], float), u)
    return finish((1 - u) * keys[k] + u * keys[k + 1])


def animation_state(doc: Document, animation: int | None, t: float) -> dict[int, dict[str, np.ndarray]]:
    """node -> {path: value} of animation `animation` at time t (empty for the rest pose). Channels without
    target.node, or with a path other than translation, rotation, scale and weights, are ignored."""
    if animation is None:
        return {}
    animations = doc.gltf.get("animations", [])
    if not 0 <= animation < len(animations):
        raise GltfError(f"animation {animation} does not exist ({len(animations)} in the file)")
    anim = animations[animation]
    state: dict[int, dict[str, np.ndarray]] = {}
    for channel in anim.get("channels", []):
        target = channel.get("target", {})
        node, path = target.get("node"), target.get("path")
        if node is None or path not in ("translation", "rotation", "scale", "weights"):
            continue
        sampler = anim["samplers"][channel["sampler"]]
        interpolation = sampler.get("interpolation", "LINEAR")
        times = read_accessor(doc, sampler["input"])[:, 0]
        output = read_accessor(doc, sampler["output"])
        per_key = 3 if interpolation == "CUBICSPLINE" else 1
        width = {"translation": 3, "scale": 3, "rotation": 4}.get(path) or output.size // max(1, len(times) * per_key)
        values = output.reshape(-1)[:len(times) * per_key * width].reshape(-1, width)
        state.setdefault(node, {})[path] = sample(times, values, interpolation, t, path == "rotation")
    return state


# ---------------------------------------------------------------------------------------------------------------
# Meshes


@dataclass
class Unit:
    """The decoded triangles of one node (or one instance of it): positions (n, 3, 3) in world space, normals
    (n, 3, 3) unit length (zero where the primitive has none or the normal is degenerate), has_normal (n,)."""

    node: int
    instance: int | None
    positions: np.ndarray
    normals: np.ndarray
    has_normal: np.ndarray

    @property
    def name(self) -> str:
        """The OBJ group name: node<N> or node<N>.<I>."""
        return f"node{self.node}" if self.instance is None else f"node{self.node}.{self.instance}"


@dataclass
class Decode:
    """The decoded scene: one unit per mesh node (per instance for EXT_mesh_gpu_instancing) in scene order."""

    units: list[Unit]
    animation: int | None
    time: float

    def extent(self) -> float:
        """The diagonal of the bounding box of every decoded vertex (0 when there is none)."""
        points = [u.positions.reshape(-1, 3) for u in self.units if len(u.positions)]
        if not points:
            return 0.0
        allp = np.concatenate(points)
        finite = allp[np.isfinite(allp).all(axis=1)]
        if not len(finite):
            return 0.0
        return float(np.linalg.norm(finite.max(axis=0) - finite.min(axis=0)))


@dataclass
class Primitive:
    """A primitive's vertices in the mesh's space (morph targets applied), normals or None, triangles (m, 3) of
    vertex indices, and the skinning attribute sets [(joints (v, 4) ints, weights (v, 4))]."""

    positions: np.ndarray
    normals: np.ndarray | None
    triangles: np.ndarray
    skin_sets: list


def triangulate(indices: np.ndarray, mode: int) -> np.ndarray:
    """Triangles (m, 3) of an index list for TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN (section 3.7.2.1):
    strip p_i = (v_i, v_{i+1+i%2}, v_{i+2-i%2}), fan p_i = (v_{i+1}, v_{i+2}, v_0)."""
    n = len(indices)
    if mode == 4:
        return indices[:n // 3 * 3].reshape(-1, 3)
    if n < 3:
        return np.zeros((0, 3), dtype=np.int64)
    i = np.arange(n - 2)
    if mode == 5:
        return np.stack([indices[i], indices[i + 1 + i % 2], indices[i + 2 - i % 2]], axis=1)
    if mode == 6:
        return np.stack([indices[i + 1], indices[i + 2], np.full(n - 2, indices[0])], axis=1)
    raise ValueError(f"mode {mode} is not triangle-based")


def morphed(doc: Document, prim: dict, semantic: str, weights: np.ndarray) -> np.ndarray | None:
    """Attribute `semantic` plus the weighted deltas of the morph targets that have it (None when absent)."""
    attributes = prim.get("attributes", {})
    if semantic not in attributes:
        return None
    base = read_accessor(doc, attributes[semantic])[:, :3].copy()
    for j, target in enumerate(prim.get("targets", [])):
        w = float(weights[j]) if j < len(weights) else 0.0
        if w != 0.0 and semantic in target:
            delta = read_accessor(doc, target[semantic])[:, :3]
            if len(delta) != len(base):
                raise GltfError(f"morph target {j} {semantic}: {len(delta)} elements for {len(base)} vertices")
            base += w * delta
    return base


def decode_primitive(doc: Document, prim: dict, weights: np.ndarray) -> Primitive | None:
    """A triangle-based primitive's morphed vertices and triangles; None for points, lines and primitives
    without POSITION (which are not drawn). Raises NotChecked for Draco-compressed primitives."""
    mode = prim.get("mode", 4)
    if mode not in TRIANGLE_MODES:
        return None
    if DRACO_EXTENSION in prim.get("extensions", {}):
        raise NotChecked(DRACO_EXTENSION)
    positions = morphed(doc, prim, "POSITION", weights)
    if positions is None:
        return None
    normals = morphed(doc, prim, "NORMAL", weights)
    if normals is not None and len(normals) != len(positions):
        raise GltfError("NORMAL and POSITION counts differ")
    if "indices" in prim:
        indices = read_accessor(doc, prim["indices"], normalize=False)[:, 0]
    else:
        indices = np.arange(len(positions), dtype=np.int64)
    triangles = triangulate(indices, mode)
    if triangles.size and (triangles.min() < 0 or triangles.max() >= len(positions)):
        raise GltfError(f"index {int(triangles.max())} out of {len(positions)} vertices")
    attributes = prim.get("attributes", {})
    skin_sets, k = [], 0
    while f"JOINTS_{k}" in attributes and f"WEIGHTS_{k}" in attributes:
        skin_sets.append((read_accessor(doc, attributes[f"JOINTS_{k}"], normalize=False),
                          read_accessor(doc, attributes[f"WEIGHTS_{k}"])))
        k += 1
    return Primitive(positions, normals, triangles, skin_sets)


def morph_weights(node: dict, mesh: dict, animated: dict, targets: int) -> np.ndarray:
    """Morph weights: animated at t, else node.weights, else mesh.weights, else zeros; padded to `targets`."""
    if "weights" in animated:
        w = animated["weights"]
    elif "weights" in node:
        w = node["weights"]
    elif "weights" in mesh:
        w = mesh["weights"]
    else:
        w = []
    w = np.asarray(w, dtype=np.float64).reshape(-1)[:targets]
    return np.concatenate([w, np.zeros(targets - len(w))])


def joint_matrices(doc: Document, skin: dict, world: list[np.ndarray]) -> np.ndarray:
    """world(joint_k) * inverseBindMatrix_k for every joint (k, 4, 4); inverse bind matrices default to identity."""
    joints = skin.get("joints", [])
    if "inverseBindMatrices" in skin:
        ibm = read_accessor(doc, skin["inverseBindMatrices"]).reshape(-1, 4, 4).transpose(0, 2, 1)
        if len(ibm) < len(joints):
            raise GltfError("fewer inverseBindMatrices than joints")
    else:
        ibm = np.broadcast_to(np.eye(4), (len(joints), 4, 4))
    return np.stack([world[j] @ ibm[k] for k, j in enumerate(joints)]) if joints else np.zeros((0, 4, 4))


def blended_skin(sets: list, joints: np.ndarray, count: int) -> np.ndarray:
    """Per-vertex skin matrices sum_k w_k * joints[j_k] (count, 4, 4) over every JOINTS_n/WEIGHTS_n set."""
    out = np.zeros((count, 4, 4))
    for joint_index, weight in sets:
        weight = weight[:count, :4]
        joint_index = joint_index[:count, :4]
        bad = (joint_index < 0) | (joint_index >= len(joints))
        if np.any(bad & (weight != 0)):
            raise GltfError("a skinned vertex names a joint the skin does not have")
        joint_index = np.where(bad, 0, joint_index)
        if len(joints):
            out += np.einsum("vk,vkab->vab", weight, joints[joint_index])
    return out


def normal_matrices(linear: np.ndarray) -> np.ndarray:
    """Inverse transposes (n, 3, 3) of (n, 3, 3) matrices; zero for singular ones."""
    det = np.linalg.det(linear)
    scale = np.abs(linear).max(axis=(1, 2))
    ok = np.isfinite(det) & (np.abs(det) > 1e-12 * np.maximum(scale, 1e-300) ** 3)
    out = np.zeros_like(linear)
    if ok.any():
        out[ok] = np.linalg.inv(linear[ok]).transpose(0, 2, 1)
    return out


def unit_length(v: np.ndarray) -> np.ndarray:
    """v normalized along the last axis; zero vectors stay zero."""
    norm = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.where(norm > 0, v / np.where(norm > 0, norm, 1.0), 0.0)


def place(prim: Primitive, matrices: np.ndarray, flip: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A primitive's triangles transformed by one matrix (4, 4) or per-vertex matrices (v, 4, 4): positions,
    unit normals (zero where none), has_normal per triangle. `flip` reverses the winding to (a, c, b)."""
    linear, offset = matrices[..., :3, :3], matrices[..., :3, 3]
    if matrices.ndim == 2:
        positions = prim.positions @ linear.T + offset
    else:
        positions = np.einsum("vij,vj->vi", linear, prim.positions) + offset
    triangles = prim.triangles[:, [0, 2, 1]] if flip else prim.triangles
    tri_positions = positions[triangles]
    has = prim.normals is not None
    if has:
        if matrices.ndim == 2:
            normals = prim.normals @ normal_matrices(linear[None])[0].T
        else:
            normals = np.einsum("vij,vj->vi", normal_matrices(linear), prim.normals)
        tri_normals = unit_length(normals)[triangles]
    else:
        tri_normals = np.zeros_like(tri_positions)
    return tri_positions, tri_normals, np.full(len(triangles), has)


def instance_matrices(doc: Document, node: dict) -> np.ndarray | None:
    """EXT_mesh_gpu_instancing's per-instance T * R * S (n, 4, 4), or None for a node without it."""
    ext = node.get("extensions", {}).get(INSTANCING_EXTENSION)
    if ext is None:
        return None
    attributes = ext.get("attributes", {})
    columns = {"TRANSLATION": 3, "ROTATION": 4, "SCALE": 3}
    read = {k: read_accessor(doc, attributes[k])[:, :columns[k]] for k in columns if k in attributes}
    counts = {len(v) for v in read.values()}
    if len(counts) > 1:
        raise GltfError("EXT_mesh_gpu_instancing attributes of different counts")
    n = counts.pop() if counts else 0
    t = read.get("TRANSLATION", np.zeros((n, 3)))
    r = read.get("ROTATION", np.tile([0.0, 0.0, 0.0, 1.0], (n, 1)))
    s = read.get("SCALE", np.ones((n, 3)))
    return trs_matrices(t, r, s)


def node_units(doc: Document, index: int, world: list[np.ndarray], state: dict) -> list[Unit]:
    """The units of one mesh node: one, or one per EXT_mesh_gpu_instancing instance. A skinned node's vertices
    are sum_k w_k * world(joint_k) * IBM_k * v (its own transform ignored; an instance matrix is applied after
    the skin; a primitive without JOINTS_n/WEIGHTS_n is drawn rigidly); a rigid node's are world * instance * v,
    winding reversed where that matrix mirrors."""
    gltf = doc.gltf
    node = gltf["nodes"][index]
    mesh = gltf["meshes"][node["mesh"]]
    targets = max([len(p.get("targets", [])) for p in mesh.get("primitives", [])] + [0])
    weights = morph_weights(node, mesh, state.get(index, {}), targets)
    prims = [p for p in (decode_primitive(doc, p, weights) for p in mesh.get("primitives", [])) if p is not None]
    skin = gltf["skins"][node["skin"]] if "skin" in node else None
    joints = joint_matrices(doc, skin, world) if skin is not None else None
    instances = instance_matrices(doc, node)
    transforms = [None] if instances is None else list(instances)
    units = []
    for i, instance in enumerate(transforms):
        parts = []
        for prim in prims:
            count = len(prim.positions)
            if joints is not None and prim.skin_sets:
                matrices = blended_skin(prim.skin_sets, joints, count)
                if instance is not None:
                    matrices = instance @ matrices
                flip = False
            else:
                matrices = world[index] if instance is None else world[index] @ instance
                flip = bool(np.linalg.det(matrices[:3, :3]) < 0)
            parts.append(place(prim, matrices, flip))
        units.append(_join(index, None if instances is None else i, parts))
    return units


def _join(node: int, instance: int | None, parts: list) -> Unit:
    """One unit from the (positions, normals, has_normal) of each primitive, in order."""
    if not parts:
        empty = np.zeros((0, 3, 3))
        return Unit(node, instance, empty, empty.copy(), np.zeros(0, dtype=bool))
    return Unit(node, instance, np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts]),
                np.concatenate([p[2] for p in parts]))


def decode(doc: Document, animation: int | None = None, time: float = 0.0) -> Decode:
    """Every mesh node of the default scene in world space, with animation `animation` (None: rest pose) at
    `time` seconds."""
    state = animation_state(doc, animation, time)
    world = world_matrices(doc.gltf, state)
    units = []
    for index in scene_nodes(doc.gltf):
        if "mesh" in doc.gltf["nodes"][index]:
            units.extend(node_units(doc, index, world, state))
    return Decode(units, animation, time)


# ---------------------------------------------------------------------------------------------------------------
# OBJ


def write_obj(result: Decode, out: Path, source: str) -> None:
    """The decode as an OBJ in lodbench's export format (3 `v` per triangle, `vn` when any triangle has a
    normal, zero normals where a primitive has none)."""
    with_normals = any(u.has_normal.any() for u in result.units)
    animation = "none" if result.animation is None else str(result.animation)
    base = 1
    with open(out, "w") as f:
        f.write(f"# check_gltf decode: {source}\n# frame 0 animation {animation} time {result.time!r}\n")
        for unit in result.units:
            f.write(f"o {unit.name}\n")
            m = len(unit.positions)
            if m == 0:
                continue
            np.savetxt(f, unit.positions.reshape(-1, 3), fmt="v %.9g %.9g %.9g")
            if with_normals:
                np.savetxt(f, unit.normals.reshape(-1, 3), fmt="vn %.9g %.9g %.9g")
                faces = np.repeat(base + np.arange(3 * m).reshape(m, 3), 2, axis=1)
                np.savetxt(f, faces, fmt="f %d//%d %d//%d %d//%d")
            else:
                np.savetxt(f, base + np.arange(3 * m).reshape(m, 3), fmt="f %d %d %d")
            base += 3 * m


@dataclass
class ObjGroup:
    """One `o` group: node, instance (or None), and its faces as 1-based v and vn indices (vn: -1 when none)."""

    name: str
    node: int
    instance: int | None
    v: list = field(default_factory=list)
    vn: list = field(default_factory=list)


@dataclass
class ObjFile:
    """What lodbench exported: header, skipped nodes, holds lines, groups, vertices and normals."""

    source: str | None = None
    frame: str | None = None
    animation: int | None = None
    time: float = 0.0
    has_header: bool = False
    skipped: dict = field(default_factory=dict)
    holds: dict = field(default_factory=dict)
    groups: list = field(default_factory=list)
    vertices: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    normals: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    errors: list = field(default_factory=list)


HEADER_SOURCE = re.compile(r"#\s*(?:lodbench export|check_gltf decode):\s*(.*)$")
HEADER_FRAME = re.compile(r"#\s*frame\s+(\S+)\s+animation\s+(\S+)\s+time\s+(\S+)")
HEADER_SKIPPED = re.compile(r"#\s*skipped node\s+(\d+)\s*:?\s*(.*)$")
HEADER_HOLDS = re.compile(r"#\s*node\s+(\d+)\s+holds\b(.*)$")
GROUP_NAME = re.compile(r"node(\d+)(?:\.(\d+))?$")


def _obj_index(token: str, count: int) -> int:
    """A 1-based OBJ index (negative: relative to the end so far) as 1-based; 0 when empty."""
    if not token:
        return 0
    i = int(token)
    return count + i + 1 if i < 0 else i


def _parse_comment(line: str, obj: ObjFile) -> None:
    """The header lines lodbench writes."""
    if m := HEADER_SOURCE.match(line):
        obj.source = m.group(1).strip()
    elif m := HEADER_FRAME.match(line):
        obj.frame, animation, time = m.groups()
        obj.animation = None if animation == "none" else int(animation)
        obj.time = float(time)
        obj.has_header = True
    elif m := HEADER_SKIPPED.match(line):
        obj.skipped[int(m.group(1))] = m.group(2).strip()
    elif m := HEADER_HOLDS.match(line):
        obj.holds[int(m.group(1))] = [int(x) for x in m.group(2).split()]


def _parse_face(tokens: list[str], group: ObjGroup, nv: int, nn: int) -> None:
    """A face `f a b c` or `f a//a ...` (polygons fanned) into the group."""
    vs, ns = [], []
    for token in tokens:
        parts = token.split("/")
        vs.append(_obj_index(parts[0], nv))
        ns.append(_obj_index(parts[2], nn) if len(parts) > 2 else 0)
    for k in range(1, len(vs) - 1):
        group.v.append((vs[0], vs[k], vs[k + 1]))
        group.vn.append((ns[0], ns[k], ns[k + 1]))


def read_obj(path: Path) -> ObjFile:
    """Parses lodbench's OBJ export."""
    obj = ObjFile()
    vertices, normals = [], []
    group = None
    with open(path) as f:
        for number, raw in enumerate(f, 1):
            line = raw.strip()
            if not line:
                continue
            if line.startswith("#"):
                _parse_comment(line, obj)
                continue
            tokens = line.split()
            if tokens[0] == "v":
                vertices.append(tuple(float(x) for x in tokens[1:4]))
            elif tokens[0] == "vn":
                normals.append(tuple(float(x) for x in tokens[1:4]))
            elif tokens[0] == "o":
                name = tokens[1] if len(tokens) > 1 else ""
                m = GROUP_NAME.match(name)
                if not m:
                    obj.errors.append(f"line {number}: group {name!r} is not node<N> or node<N>.<I>")
                    group = ObjGroup(name, -1, None)
                else:
                    group = ObjGroup(name, int(m.group(1)), None if m.group(2) is None else int(m.group(2)))
                obj.groups.append(group)
            elif tokens[0] == "f":
                if group is None:
                    obj.errors.append(f"line {number}: face before any group")
                    group = ObjGroup("(none)", -1, None)
                    obj.groups.append(group)
                _parse_face(tokens[1:], group, len(vertices), len(normals))
    obj.vertices = np.array(vertices, dtype=np.float64).reshape(-1, 3)
    obj.normals = np.array(normals, dtype=np.float64).reshape(-1, 3)
    return obj


# ---------------------------------------------------------------------------------------------------------------
# Comparison


@dataclass
class Report:
    """The outcome of comparing one export: status OK, MISMATCH, NOT CHECKED or ERROR, and lines to print."""

    status: str
    lines: list = field(default_factory=list)
    groups: int = 0
    triangles: int = 0
    mismatched: int = 0

    @property
    def exit_code(self) -> int:
        """0 OK, 3 not checked, 1 otherwise."""
        return {"OK": EXIT_OK, "NOT CHECKED": EXIT_NOT_CHECKED}.get(self.status, EXIT_MISMATCH)


def normals_close(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Per row (..., 3): the angle between a and b is below NORMAL_ANGLE, or either is zero."""
    na, nb = np.linalg.norm(a, axis=-1), np.linalg.norm(b, axis=-1)
    angle = np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, axis=-1))
    return (na == 0) | (nb == 0) | (angle < NORMAL_ANGLE)


def triangles_match(expected: Unit, got_pos: np.ndarray, got_nrm: np.ndarray | None, tol: float,
                    reflect: bool = False) -> np.ndarray:
    """Per triangle: got equals expected up to a cyclic rotation of its vertices (a reflection too when
    `reflect`), every vertex within tol, normals within NORMAL_ANGLE where both exist."""
    orders = [[0, 1, 2], [1, 2, 0], [2, 0, 1]]
    if reflect:
        orders += [[0, 2, 1], [2, 1, 0], [1, 0, 2]]
    ok = np.zeros(len(got_pos), dtype=bool)
    for order in orders:
        g = got_pos[:, order]
        match = (np.linalg.norm(expected.positions - g, axis=2) <= tol).all(axis=1)
        if got_nrm is not None:
            normal_ok = normals_close(expected.normals, got_nrm[:, order]).all(axis=1) | ~expected.has_normal
            match &= normal_ok
        ok |= match
    return ok


def expected_for(result: Decode, obj: ObjFile, group: ObjGroup) -> Unit | None:
    """What the group should hold: the node's unit (the named instance, or all instances in order for a group
    without one), then the units of the nodes it holds. None when the decode has no such node or instance."""
    own = [u for u in result.units if u.node == group.node
           and (group.instance is None or u.instance == group.instance)]
    holds = obj.holds.get(group.node, [])
    if not own and (not holds or group.instance is not None):
        return None
    held = [u for h in holds for u in result.units if u.node == h]
    parts = [(u.positions, u.normals, u.has_normal) for u in own + held]
    return _join(group.node, group.instance, parts)


def _format_triangle(t: np.ndarray) -> str:
    """(x y z) (x y z) (x y z) with 6 significant digits."""
    return " ".join("(" + " ".join(f"{c:.6g}" for c in p) + ")" for p in t)


def group_triangles(obj: ObjFile, group: ObjGroup) -> tuple[np.ndarray, np.ndarray | None, str | None]:
    """A group's triangles (n, 3, 3), its normals (n, 3, 3) or None when the file has none, or an error."""
    v = np.array(group.v, dtype=np.int64).reshape(-1, 3)
    if v.size and (v.min() < 1 or v.max() > len(obj.vertices)):
        return np.zeros((0, 3, 3)), None, f"group {group.name}: a face refers to a missing vertex"
    positions = obj.vertices[v - 1] if v.size else np.zeros((0, 3, 3))
    if not len(obj.normals):
        return positions, None, None
    vn = np.array(group.vn, dtype=np.int64).reshape(-1, 3)
    vn = np.where(vn == 0, v, vn)  # `f a b c` with vn present: one vn per v, same order
    if vn.size and (vn.min() < 1 or vn.max() > len(obj.normals)):
        return positions, None, f"group {group.name}: a face refers to a missing normal"
    return positions, (obj.normals[vn - 1] if vn.size else np.zeros((0, 3, 3))), None


def compare_group(result: Decode, obj: ObjFile, group: ObjGroup, tol: float) -> tuple[list[str], int, int]:
    """Problems found in one group (at most REPORT_LIMIT triangle lines), its triangle count and the number of
    mismatched triangles (a count difference counts the missing or extra ones)."""
    expected = expected_for(result, obj, group)
    if expected is None:
        return [f"group {group.name}: no such mesh node (or instance) in the decoded scene"], 0, 1
    got_pos, got_nrm, error = group_triangles(obj, group)
    if error:
        return [error], len(got_pos), 1
    decoded_nodes = {u.node for u in result.units}
    problems = [f"group {group.name} holds node {h}, which is no mesh node of the decoded scene"
                for h in obj.holds.get(group.node, []) if h not in decoded_nodes]
    n_exp, n_got = len(expected.positions), len(got_pos)
    if n_exp != n_got:
        problems.append(f"group {group.name}: {n_got} triangles, expected {n_exp}")
    n = min(n_exp, n_got)
    head = Unit(expected.node, expected.instance, expected.positions[:n], expected.normals[:n],
                expected.has_normal[:n])
    ok = triangles_match(head, got_pos[:n], None if got_nrm is None else got_nrm[:n], tol)
    bad = np.flatnonzero(~ok)
    for i in bad[:REPORT_LIMIT]:
        problems.append(_describe(head, got_pos, got_nrm, int(i), tol, group.name))
    if len(bad) > REPORT_LIMIT:
        problems.append(f"group {group.name}: {len(bad) - REPORT_LIMIT} more mismatched triangles")
    return problems, n_got, len(bad) + abs(n_exp - n_got)


def _describe(expected: Unit, got_pos: np.ndarray, got_nrm: np.ndarray | None, i: int, tol: float,
              name: str) -> str:
    """One mismatched triangle: both vertex lists, the distance, and what kind of difference it is."""
    e = Unit(expected.node, None, expected.positions[i:i + 1], expected.normals[i:i + 1],
             expected.has_normal[i:i + 1])
    g, gn = got_pos[i:i + 1], None if got_nrm is None else got_nrm[i:i + 1]
    if triangles_match(e, g, None, tol)[0]:
        kind = "normals differ"
    elif triangles_match(e, g, None, tol, reflect=True)[0]:
        kind = "winding reversed"
    else:
        d = min(np.linalg.norm(e.positions[0] - g[0][o], axis=1).max() for o in ([0, 1, 2], [1, 2, 0], [2, 0, 1]))
        kind = f"vertices off by up to {d:.3g} (tol {tol:.3g})"
    line = (f"group {name} triangle {i}: {kind}; expected {_format_triangle(e.positions[0])} "
            f"got {_format_triangle(g[0])}")
    if kind == "normals differ" and gn is not None:
        line += f"; normals expected {_format_triangle(e.normals[0])} got {_format_triangle(gn[0])}"
    return line


def coverage_problems(result: Decode, obj: ObjFile) -> list[str]:
    """Decoded nodes with triangles that the export neither outputs, holds nor lists as skipped."""
    named = {(g.node, g.instance) for g in obj.groups}
    group_nodes = {g.node for g in obj.groups}
    held = {h for n, hs in obj.holds.items() if n in group_nodes for h in hs}
    problems = []
    for unit in result.units:
        if not len(unit.positions) or unit.node in obj.skipped or unit.node in held:
            continue
        if (unit.node, None) in named or (unit.node, unit.instance) in named:
            continue
        problems.append(f"{unit.name} ({len(unit.positions)} triangles) is neither output, held nor skipped")
    return problems


def compare(result: Decode, obj: ObjFile, tol: float | None = None) -> Report:
    """Compares a decode with lodbench's export, group by group."""
    tol = 1e-4 * result.extent() + 1e-6 if tol is None else tol
    problems, triangles, mismatched = list(obj.errors), 0, len(obj.errors)
    for group in obj.groups:
        lines, count, bad = compare_group(result, obj, group, tol)
        problems.extend(lines)
        triangles += count
        mismatched += bad
    cover = coverage_problems(result, obj)
    problems.extend(cover)
    mismatched += len(cover)
    status = "OK" if not problems else "MISMATCH"
    summary = (f"{len(obj.groups)} groups, {triangles} triangles, {len(obj.skipped)} skipped nodes, "
               f"tol {tol:.3g}" + (f", {mismatched} problems" if problems else ""))
    return Report(status, [summary] + problems, len(obj.groups), triangles, mismatched)


def compare_files(gltf_path: Path, obj_path: Path, tol: float | None = None, doc: Document | None = None) -> Report:
    """Decodes gltf_path at the animation and time that obj_path's header names, and compares."""
    try:
        obj = read_obj(obj_path)
        if not obj.has_header:
            return Report("ERROR", [f"{obj_path}: no '# frame F animation A time T' line"])
        doc = doc or load_document(gltf_path)
        result = decode(doc, obj.animation, obj.time)
    except NotChecked as e:
        return Report("NOT CHECKED", [str(e)])
    except (GltfError, OSError, ValueError, KeyError, IndexError, TypeError, struct.error) as e:
        return Report("ERROR", [f"{type(e).__name__}: {e}"])
    report = compare(result, obj, tol)
    frame = f"frame {obj.frame} animation {'none' if obj.animation is None else obj.animation} time {obj.time:g}"
    report.lines[0] = f"{frame}: {report.lines[0]}"
    return report


# ---------------------------------------------------------------------------------------------------------------
# run: lodbench over many files


def find_files(paths: list[str]) -> list[Path]:
    """The .gltf/.glb files named, and those found recursively in the folders named, sorted per folder."""
    out = []
    for p in map(Path, paths):
        if p.is_dir():
            out.extend(sorted(f for f in p.rglob("*") if f.is_file() and f.suffix.lower() in (".gltf", ".glb")))
        else:
            out.append(p)
    return out


def export_commands(binary: str, path: Path, frames: list[int], out_dir: Path) -> list[tuple[str, list[str], Path]]:
    """(label, command, OBJ path) of every lodbench export a file needs: each frame with the file's default
    animation, and frame 0 also with `--animation none` (the rest pose)."""
    runs = []
    for frame in frames:
        out = out_dir / f"frame{frame}.obj"
        runs.append((f"frame {frame}", [binary, "export", "--scene", str(path), "--frame", str(frame), "--out",
                                        str(out)], out))
        if frame == 0:
            rest = out_dir / "rest.obj"
            runs.append(("rest pose", [binary, "export", "--scene", str(path), "--frame", "0", "--animation", "none",
                                       "--out", str(rest)], rest))
    return runs


@dataclass
class FileResult:
    """The outcome of one file in `run`: status (OK, MISMATCH, REFUSED, NOT CHECKED) and lines to print."""

    path: Path
    status: str
    lines: list


def _last_line(text: str) -> str:
    """The last non-empty line of a process's output."""
    lines = [line for line in text.strip().splitlines() if line.strip()]
    return lines[-1].strip() if lines else "(no message)"


def check_file(binary: str, path: Path, frames: list[int], timeout: float) -> FileResult:
    """Every export of one file, each compared with the decode at its frame's animation and time."""
    lines, statuses, doc = [], [], None
    with tempfile.TemporaryDirectory(prefix="check_gltf_") as tmp:
        for label, command, out in export_commands(binary, path, frames, Path(tmp)):
            try:
                proc = subprocess.run(command, capture_output=True, text=True, timeout=timeout)
            except subprocess.TimeoutExpired:
                statuses.append("REFUSED")
                lines.append(f"{label}: refused: timed out after {timeout:g} s")
                continue
            except OSError as e:
                statuses.append("REFUSED")
                lines.append(f"{label}: refused: {e}")
                continue
            if proc.returncode != 0:
                statuses.append("REFUSED")
                lines.append(f"{label}: refused: {_last_line(proc.stderr or proc.stdout)}")
                continue
            if doc is None:
                try:
                    doc = load_document(path)
                except (GltfError, OSError, ValueError) as e:
                    statuses.append("ERROR")
                    lines.append(f"{label}: cannot read the file: {e}")
                    break
            report = compare_files(path, out, doc=doc)
            statuses.append(report.status)
            lines.append(f"{label}: {report.status}: " + report.lines[0])
            lines.extend("    " + line for line in report.lines[1:])
    return FileResult(path, _file_status(statuses), lines)


def _file_status(statuses: list[str]) -> str:
    """The worst of a file's export outcomes: mismatch/error, then refused, then not checked, then OK."""
    for status in ("ERROR", "MISMATCH", "REFUSED", "NOT CHECKED"):
        if status in statuses:
            return "MISMATCH" if status == "ERROR" else status
    return "OK"


def run(binary: str, paths: list[str], frames: list[int], jobs: int, timeout: float, out=sys.stdout) -> int:
    """Checks every file, prints a line per file (details under mismatches) and a summary; the exit status."""
    files = find_files(paths)
    counts = {"OK": 0, "MISMATCH": 0, "REFUSED": 0, "NOT CHECKED": 0}
    refused = []
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        for result in pool.map(lambda p: check_file(binary, p, frames, timeout), files):
            counts[result.status] += 1
            print(f"{result.status:<11} {result.path}", file=out)
            if result.status != "OK":
                for line in result.lines:
                    print(f"    {line}", file=out)
            refused.extend(f"{result.path}: {line}" for line in result.lines if ": refused: " in line)
            out.flush()
    print(f"summary: {len(files)} files: {counts['OK']} OK, {counts['MISMATCH']} mismatch, {counts['REFUSED']} "
          f"refused, {counts['NOT CHECKED']} not checked", file=out)
    for line in refused:
        print(f"  refused {line}", file=out)
    if counts["MISMATCH"]:
        return EXIT_MISMATCH
    return EXIT_NOT_CHECKED if counts["NOT CHECKED"] else EXIT_OK


# ---------------------------------------------------------------------------------------------------------------
# Command line


def parse_animation(text: str) -> int | None:
    """`none` or an animation index."""
    return None if text.lower() == "none" else int(text)


def main(argv: list[str] | None = None) -> int:
    """The command line; returns the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("decode", help="write this decoder's OBJ of a glTF")
    p.add_argument("file", type=Path)
    p.add_argument("--animation", type=parse_animation, default=None, help="animation index or none (default)")
    p.add_argument("--time", type=float, default=0.0, help="seconds within the animation")
    p.add_argument("--out", type=Path, required=True)
    p = sub.add_parser("compare", help="compare lodbench's OBJ export with this decoder")
    p.add_argument("file", type=Path)
    p.add_argument("obj", type=Path)
    p.add_argument("--tol", type=float, default=None, help="vertex tolerance (default 1e-4 * extent + 1e-6)")
    p = sub.add_parser("run", help="export with lodbench and compare, for many files")
    p.add_argument("--lodbench", required=True)
    p.add_argument("--frames", default="0,30", help="comma-separated frame numbers (default 0,30)")
    p.add_argument("--jobs", type=int, default=1)
    p.add_argument("--timeout", type=float, default=600.0, help="seconds one lodbench export may take")
    p.add_argument("paths", nargs="+")
    args = parser.parse_args(argv)

    if args.command == "decode":
        try:
            result = decode(load_document(args.file), args.animation, args.time)
        except NotChecked as e:
            print(f"{args.file}: {e}")
            return EXIT_NOT_CHECKED
        except (GltfError, OSError, ValueError, KeyError, IndexError, TypeError, struct.error) as e:
            print(f"{args.file}: {type(e).__name__}: {e}", file=sys.stderr)
            return EXIT_MISMATCH
        write_obj(result, args.out, str(args.file))
        print(f"{args.file}: {len(result.units)} groups, {sum(len(u.positions) for u in result.units)} triangles")
        return EXIT_OK
    if args.command == "compare":
        report = compare_files(args.file, args.obj, args.tol)
        print(f"{report.status}: {args.file}: " + report.lines[0])
        for line in report.lines[1:]:
            print(f"    {line}")
        return report.exit_code
    frames = [int(f) for f in args.frames.split(",") if f.strip()]
    return run(args.lodbench, args.paths, frames, args.jobs, args.timeout)


if __name__ == "__main__":
    sys.exit(main())
