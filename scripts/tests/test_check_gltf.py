"""scripts/check_gltf.py: tiny glTF documents built here (base64 data URIs, one GLB) with hand-computed answers
for strips and fans, sparse and interleaved accessors, normalized integers, mirrored nodes, skins, morph targets,
STEP / LINEAR / CUBICSPLINE animation and GPU instancing; then compare on OBJs written from the decode (a moved
vertex and a reversed winding fail, a rotated triangle passes) and `run` with a stand-in for lodbench."""
import base64
import json
import math
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import check_gltf  # noqa: E402

SCRIPT = Path(__file__).resolve().parents[1] / "check_gltf.py"
FMT = {5120: "b", 5121: "B", 5122: "h", 5123: "H", 5125: "I", 5126: "f"}
TYPES = {1: "SCALAR", 2: "VEC2", 3: "VEC3", 4: "VEC4", 16: "MAT4"}
TRIANGLE = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]


class Gltf:
    """A glTF under construction: one buffer, a view per accessor unless told otherwise."""

    def __init__(self):
        self.data = bytearray()
        self.doc = {"asset": {"version": "2.0"}, "scenes": [{"nodes": []}], "nodes": [], "meshes": [],
                    "accessors": [], "bufferViews": []}

    def view(self, raw: bytes, stride=None) -> int:
        """A bufferView over raw (4-byte aligned)."""
        self.data.extend(b"\0" * (-len(self.data) % 4))
        view = {"buffer": 0, "byteOffset": len(self.data), "byteLength": len(raw)}
        if stride is not None:
            view["byteStride"] = stride
        self.data.extend(raw)
        self.doc["bufferViews"].append(view)
        return len(self.doc["bufferViews"]) - 1

    def accessor(self, values, ctype=5126, normalized=False, **extra) -> int:
        """An accessor over values (a list of rows, or scalars), packed in its own view unless `bufferView` is
        given in extra."""
        rows = [v if isinstance(v, (list, tuple)) else [v] for v in values]
        width = len(rows[0]) if rows else 1
        acc = {"componentType": ctype, "count": len(rows), "type": TYPES[width]}
        if normalized:
            acc["normalized"] = True
        if "bufferView" not in extra and rows:
            flat = [c for r in rows for c in r]
            acc["bufferView"] = self.view(struct.pack(f"<{len(flat)}{FMT[ctype]}", *flat))
        acc.update(extra)
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def mesh(self, primitives, **extra) -> int:
        """A mesh of the given primitives."""
        self.doc["meshes"].append({"primitives": primitives, **extra})
        return len(self.doc["meshes"]) - 1

    def node(self, root=True, **fields) -> int:
        """A node (a root of scene 0 unless told otherwise)."""
        self.doc["nodes"].append(fields)
        index = len(self.doc["nodes"]) - 1
        if root:
            self.doc["scenes"][0]["nodes"].append(index)
        return index

    def triangle_node(self, positions=TRIANGLE, **fields) -> int:
        """A node with a one-triangle mesh."""
        mesh = self.mesh([{"attributes": {"POSITION": self.accessor(positions)}}])
        return self.node(mesh=mesh, **fields)

    def json(self) -> dict:
        """The document with its buffer as a base64 data URI."""
        doc = json.loads(json.dumps(self.doc))
        doc["buffers"] = [{"byteLength": len(self.data),
                           "uri": "data:application/octet-stream;base64," + base64.b64encode(self.data).decode()}]
        return doc

    def write(self, path: Path) -> Path:
        """The document as a .gltf file."""
        path.write_text(json.dumps(self.json()))
        return path

    def write_glb(self, path: Path) -> Path:
        """The document as a .glb with the buffer in the BIN chunk."""
        doc = json.loads(json.dumps(self.doc))
        doc["buffers"] = [{"byteLength": len(self.data)}]
        text = json.dumps(doc).encode()
        text += b" " * (-len(text) % 4)
        binary = bytes(self.data) + b"\0" * (-len(self.data) % 4)
        body = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(binary), 0x004E4942) + binary
        path.write_bytes(struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body)
        return path


def decode(g: Gltf, tmp_path: Path, animation=None, time=0.0) -> check_gltf.Decode:
    """check_gltf's decode of the document."""
    return check_gltf.decode(check_gltf.load_document(g.write(tmp_path / "a.gltf")), animation, time)


def only(result: check_gltf.Decode) -> np.ndarray:
    """The triangles of the one unit of a decode."""
    assert len(result.units) == 1
    return result.units[0].positions


def test_strip_and_fan_follow_the_specification(tmp_path):
    g = Gltf()
    pts = [[float(i), float(i * i), 0.0] for i in range(5)]
    strip = g.mesh([{"attributes": {"POSITION": g.accessor(pts)}, "mode": 5}])
    fan = g.mesh([{"attributes": {"POSITION": g.accessor(pts)}, "mode": 6,
                   "indices": g.accessor([0, 1, 2, 3, 4], ctype=5123)},
                  {"attributes": {"POSITION": g.accessor(pts)}, "mode": 1}])  # lines: skipped
    g.node(mesh=strip)
    g.node(mesh=fan)
    result = decode(g, tmp_path)
    p = np.array(pts)
    assert np.array_equal(result.units[0].positions, p[[[0, 1, 2], [1, 3, 2], [2, 3, 4]]])
    assert np.array_equal(result.units[1].positions, p[[[1, 2, 0], [2, 3, 0], [3, 4, 0]]])


def test_sparse_accessors_substitute_values(tmp_path):
    g = Gltf()
    pts = [[float(i), 0.0, 0.0] for i in range(6)]
    sparse = {"count": 2, "indices": {"bufferView": g.view(struct.pack("<2H", 1, 4)), "componentType": 5123},
              "values": {"bufferView": g.view(struct.pack("<6f", 7, 7, 7, 9, 9, 9))}}
    dense = g.accessor(pts, sparse=sparse)
    zeros = g.accessor([], count=6, type="VEC3", sparse=sparse)  # no bufferView: zeros, then the substitution
    g.triangle_node()  # a plain node beside them
    g.node(mesh=g.mesh([{"attributes": {"POSITION": dense}}]))
    g.node(mesh=g.mesh([{"attributes": {"POSITION": zeros}}]))
    result = decode(g, tmp_path)
    expected = np.array(pts)
    expected[1], expected[4] = 7, 9
    assert np.array_equal(result.units[1].positions.reshape(-1, 3), expected)
    expected[[0, 2, 3, 5]] = 0
    assert np.array_equal(result.units[2].positions.reshape(-1, 3), expected)


def test_interleaved_stride_and_integral_float_json(tmp_path):
    g = Gltf()
    interleaved = [c for p, n in zip(TRIANGLE, [[0, 0, 2]] * 3) for c in p + n]
    view = g.view(struct.pack("<18f", *interleaved), stride=24.0)
    position = g.accessor([], bufferView=view, count=3, type="VEC3")
    normal = g.accessor([], bufferView=view, byteOffset=12.0, count=3, type="VEC3")
    g.node(mesh=g.mesh([{"attributes": {"POSITION": position, "NORMAL": normal}}]))
    # Every second vec3 of a view with "byteStride": 12.0 written as a float.
    view = g.view(struct.pack("<9f", *[c for p in TRIANGLE for c in p]), stride=12.0)
    g.node(mesh=g.mesh([{"attributes": {"POSITION": g.accessor([], bufferView=view, count=3, type="VEC3")}}]))
    text = json.dumps(g.json())
    assert '"byteStride": 24.0' in text and '"byteStride": 12.0' in text
    result = decode(g, tmp_path)
    assert np.array_equal(result.units[0].positions[0], TRIANGLE)
    assert np.array_equal(result.units[0].normals[0], [[0, 0, 1]] * 3)  # normalized
    assert np.array_equal(result.units[1].positions[0], TRIANGLE)


def test_normalized_integers_are_dequantized(tmp_path):
    g = Gltf()
    g.node(mesh=g.mesh([{"attributes": {"POSITION": g.accessor([[0, 0, 65535], [65535, 0, 0], [0, 32768, 0]],
                                                             ctype=5123, normalized=True)}}]))
    result = decode(g, tmp_path)
    assert np.allclose(only(result)[0], [[0, 0, 1], [1, 0, 0], [0, 32768 / 65535, 0]], atol=0)
    raw = np.array([[-128, -127, 0, 127]])
    assert np.array_equal(check_gltf.dequantize(raw, 5120, True), [[-1, -1, 0, 1]])
    assert np.array_equal(check_gltf.dequantize(np.array([[-32768, 32767]]), 5122, True), [[-1, 1]])
    assert np.array_equal(check_gltf.dequantize(np.array([[255, 51]]), 5121, True), [[1, 0.2]])
    assert np.array_equal(check_gltf.dequantize(np.array([[255]]), 5121, False), [[255]])


def test_mirrored_node_reverses_the_winding(tmp_path):
    g = Gltf()
    g.triangle_node(scale=[-1, 1, 1])
    result = decode(g, tmp_path)
    # (a, b, c) mirrored in x, then drawn as (a, c, b).
    assert np.array_equal(only(result)[0], [[0, 0, 0], [0, 1, 0], [-1, 0, 0]])


def test_normals_use_the_inverse_transpose(tmp_path):
    g = Gltf()
    s = math.sqrt(0.5)
    g.node(mesh=g.mesh([{"attributes": {"POSITION": g.accessor(TRIANGLE), "NORMAL": g.accessor([[s, s, 0]] * 3)}}]),
           scale=[2, 1, 1])
    normals = only_unit(decode(g, tmp_path)).normals[0]
    assert np.allclose(normals, [[1 / math.sqrt(5), 2 / math.sqrt(5), 0]] * 3)  # (0.5, 1, 0) normalized


def only_unit(result: check_gltf.Decode) -> check_gltf.Unit:
    """The one unit of a decode."""
    assert len(result.units) == 1
    return result.units[0]


def test_second_joint_set_adds_to_the_first():
    joints = np.stack([np.eye(4), np.diag([2.0, 2.0, 2.0, 1.0])])
    sets = [(np.array([[0, 0, 0, 0]]), np.array([[0.25, 0, 0, 0]])),
            (np.array([[1, 0, 0, 0]]), np.array([[0.75, 0, 0, 0]]))]
    assert np.allclose(check_gltf.blended_skin(sets, joints, 1)[0], np.diag([1.75, 1.75, 1.75, 1.0]))


def test_two_joint_skin_with_a_rotated_joint(tmp_path):
    g = Gltf()
    positions = g.accessor([[0, 2, 0], [1, 1, 0], [0, 0, 0]])
    normals = g.accessor([[1, 0, 0]] * 3)
    joints = g.accessor([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 0]], ctype=5121)
    weights = g.accessor([[1, 0, 0, 0], [0.5, 0.5, 0, 0], [1, 0, 0, 0]])
    mesh = g.mesh([{"attributes": {"POSITION": positions, "NORMAL": normals, "JOINTS_0": joints,
                                   "WEIGHTS_0": weights}}])
    ibm = g.accessor([list(np.eye(4).T.flat), list(np.array([[1, 0, 0, 0], [0, 1, 0, -1], [0, 0, 1, 0],
                                                            [0, 0, 0, 1]], float).T.flat)])
    s = math.sqrt(0.5)
    g.node(mesh=mesh, skin=0, translation=[10, 0, 0])  # the skinned node's own transform is ignored
    root = g.node(children=[2])
    g.node(root=False, translation=[0, 1, 0], rotation=[0, 0, s, s])  # 90 degrees about z
    g.doc["skins"] = [{"joints": [root, 2], "inverseBindMatrices": ibm}]
    result = decode(g, tmp_path)
    tri = only(result)[0]
    # Vertex 0: joint 1 only, T(0,1,0) Rz90 T(0,-1,0) (0,2,0) = (-1,1,0); vertex 1: half (1,1,0) half (0,2,0).
    assert np.allclose(tri, [[-1, 1, 0], [0.5, 1.5, 0], [0, 0, 0]], atol=1e-12)
    assert np.allclose(result.units[0].normals[0], [[0, 1, 0], [s, s, 0], [1, 0, 0]], atol=1e-12)


def test_morph_target_weights(tmp_path):
    g = Gltf()
    prim = {"attributes": {"POSITION": g.accessor(TRIANGLE)}, "targets": [{"POSITION": g.accessor([[0, 0, 2]] * 3)}]}
    mesh = g.mesh([prim], weights=[0.5])
    g.node(mesh=mesh)
    g.node(mesh=mesh, weights=[0.25])  # node weights before mesh weights
    result = decode(g, tmp_path)
    assert np.array_equal(result.units[0].positions[0, :, 2], [1, 1, 1])
    assert np.array_equal(result.units[1].positions[0, :, 2], [0.5, 0.5, 0.5])


def animated(g: Gltf, interpolation: str, times, values, path="translation") -> None:
    """Animation 0: one channel on node 0."""
    g.doc["animations"] = [{"channels": [{"sampler": 0, "target": {"node": 0, "path": path}}],
                            "samplers": [{"input": g.accessor(times), "output": g.accessor(values),
                                          "interpolation": interpolation}]}]


def test_linear_translation_at_mid_time_and_clamped(tmp_path):
    g = Gltf()
    g.triangle_node()
    animated(g, "LINEAR", [0.0, 2.0], [[0, 0, 0], [4, 0, 0]])
    assert np.allclose(only(decode(g, tmp_path, 0, 0.5))[0, 0], [1, 0, 0])
    assert np.allclose(only(decode(g, tmp_path, 0, 5.0))[0, 0], [4, 0, 0])
    assert np.allclose(only(decode(g, tmp_path, None, 0.5))[0, 0], [0, 0, 0])  # rest pose


def test_step_and_cubic_spline_between_keys(tmp_path):
    g = Gltf()
    g.triangle_node()
    animated(g, "STEP", [0.0, 1.0, 2.0], [[0, 0, 0], [3, 0, 0], [5, 0, 0]])
    assert np.allclose(only(decode(g, tmp_path, 0, 1.5))[0, 0], [3, 0, 0])
    # Keys at 0 and 2 (in-tangent, value, out-tangent each): value 0 out 1, then in 3 value 4. At t=1: u=0.5,
    # td=2: h00=0.5, h10=0.125, h01=0.5, h11=-0.125: 0.125*2*1 + 0.5*4 - 0.125*2*3 = 1.5.
    animated(g, "CUBICSPLINE", [0.0, 2.0], [[9, 9, 9], [0, 0, 0], [1, 0, 0], [3, 0, 0], [4, 0, 0], [9, 9, 9]])
    assert np.allclose(only(decode(g, tmp_path, 0, 1.0))[0, 0], [1.5, 0, 0])


def test_rotation_slerp_and_weights_animation():
    s = math.sqrt(0.5)
    q = check_gltf.sample(np.array([0.0, 1.0]), np.array([[0, 0, 0, 1], [0, 0, s, s]]), "LINEAR", 0.5, True)
    assert np.allclose(q, [0, 0, math.sin(math.pi / 8), math.cos(math.pi / 8)])
    # The short way round: the second key negated gives the same rotation.
    q2 = check_gltf.sample(np.array([0.0, 1.0]), np.array([[0, 0, 0, 1], [0, 0, -s, -s]]), "LINEAR", 0.5, True)
    assert np.allclose(q2, q)
    w = check_gltf.sample(np.array([0.0, 1.0]), np.array([[0.0, 1.0], [1.0, 0.0]]), "LINEAR", 0.25, False)
    assert np.allclose(w, [0.25, 0.75])


def test_gpu_instancing_outputs_each_instance(tmp_path):
    g = Gltf()
    ext = {"attributes": {"TRANSLATION": g.accessor([[0, 0, 0], [5, 0, 0]]), "SCALE": g.accessor([[1, 1, 1],
                                                                                                   [2, 2, 2]])}}
    g.triangle_node(translation=[0, 10, 0], extensions={"EXT_mesh_gpu_instancing": ext})
    result = decode(g, tmp_path)
    assert [u.name for u in result.units] == ["node0.0", "node0.1"]
    assert np.array_equal(result.units[0].positions[0], [[0, 10, 0], [1, 10, 0], [0, 11, 0]])
    assert np.array_equal(result.units[1].positions[0], [[5, 10, 0], [7, 10, 0], [5, 12, 0]])


def test_glb_decodes_like_gltf(tmp_path):
    g = Gltf()
    g.triangle_node(translation=[1, 2, 3])
    glb = check_gltf.decode(check_gltf.load_document(g.write_glb(tmp_path / "a.glb")))
    assert np.array_equal(only(glb), only(decode(g, tmp_path)))


def scene(tmp_path: Path) -> Path:
    """A .gltf of two nodes (one with normals, mirrored) and one animation."""
    g = Gltf()
    g.node(mesh=g.mesh([{"attributes": {"POSITION": g.accessor(TRIANGLE + [[1, 1, 0]]),
                                        "NORMAL": g.accessor([[0, 0, 1]] * 4)},
                         "indices": g.accessor([0, 1, 2, 1, 3, 2], ctype=5121)}]), scale=[1, 1, -1])
    g.triangle_node(translation=[3, 0, 0])
    animated(g, "LINEAR", [0.0, 1.0], [[0, 0, 0], [0, 2, 0]])
    return g.write(tmp_path / "scene.gltf")


def decoded_obj(tmp_path: Path, animation="0", time="0.5") -> tuple[Path, Path]:
    """scene() and the OBJ of its decode, written by the command line."""
    gltf, obj = scene(tmp_path), tmp_path / "mine.obj"
    r = subprocess.run([sys.executable, str(SCRIPT), "decode", str(gltf), "--animation", animation, "--time", time,
                        "--out", str(obj)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return gltf, obj


def edit_face(obj: Path, which: int, change) -> None:
    """Rewrites the which-th `f` line of an OBJ by change(tokens)."""
    lines, n = obj.read_text().splitlines(), -1
    for i, line in enumerate(lines):
        if line.startswith("f "):
            n += 1
            if n == which:
                lines[i] = "f " + " ".join(change(line.split()[1:]))
    obj.write_text("\n".join(lines) + "\n")


def compared(gltf: Path, obj: Path) -> check_gltf.Report:
    return check_gltf.compare_files(gltf, obj)


def test_compare_passes_its_own_decode_and_rotations(tmp_path):
    gltf, obj = decoded_obj(tmp_path)
    assert compared(gltf, obj).status == "OK"
    edit_face(obj, 1, lambda t: [t[1], t[2], t[0]])  # cyclic rotation: the same triangle
    edit_face(obj, 2, lambda t: [t[2], t[0], t[1]])
    report = compared(gltf, obj)
    assert report.status == "OK", report.lines
    assert report.triangles == 3 and report.groups == 2


def test_compare_catches_a_reversed_winding(tmp_path):
    gltf, obj = decoded_obj(tmp_path)
    edit_face(obj, 0, lambda t: [t[1], t[0], t[2]])
    report = compared(gltf, obj)
    assert report.status == "MISMATCH" and any("triangle 0: winding reversed" in x for x in report.lines)
    r = subprocess.run([sys.executable, str(SCRIPT), "compare", str(gltf), str(obj)], capture_output=True, text=True)
    assert r.returncode == 1 and "winding reversed" in r.stdout


def test_compare_catches_a_moved_vertex_and_honours_tol(tmp_path):
    gltf, obj = decoded_obj(tmp_path)
    lines = obj.read_text().splitlines()
    k = next(i for i, line in enumerate(lines) if line.startswith("v "))
    x, y, z = map(float, lines[k].split()[1:])
    lines[k] = f"v {x + 0.01} {y} {z}"  # extent about 4.6: tol about 4.6e-4
    obj.write_text("\n".join(lines) + "\n")
    report = compared(gltf, obj)
    assert report.status == "MISMATCH" and "group node0 triangle 0: vertices off by up to 0.01" in report.lines[1]
    assert check_gltf.compare_files(gltf, obj, tol=0.02).status == "OK"


def test_compare_checks_normals_counts_and_coverage(tmp_path):
    gltf, obj = decoded_obj(tmp_path)
    text = obj.read_text()
    first_vn = text.index("vn ")
    obj.write_text(text[:first_vn] + "vn 0 1 0" + text[text.index("\n", first_vn):])
    assert any("normals differ" in x for x in compared(gltf, obj).lines)
    # Node 1 dropped: an error unless skipped.
    _, obj = decoded_obj(tmp_path)
    text = obj.read_text()
    cut = text[:text.index("o node1")]
    obj.write_text(cut)
    assert any("node1 (1 triangles) is neither" in x for x in compared(gltf, obj).lines)
    obj.write_text("# skipped node 1: coarser LOD\n" + cut)
    assert compared(gltf, obj).status == "OK"
    # Node 1 held by node 0's group instead.
    obj.write_text("# node 0 holds 1\n" + text.replace("o node1\n", ""))
    assert compared(gltf, obj).status == "OK"
    # Both nodes held by the group of a node without a mesh of its own.
    body = text[text.index("o node0"):].replace("o node0\n", "o node9\n").replace("o node1\n", "")
    obj.write_text("# node 9 holds 0 1\n" + text[:text.index("o node0")] + body)
    assert compared(gltf, obj).status == "OK"
    obj.write_text("# node 9 holds 0 1 4\n" + text[:text.index("o node0")] + body)
    assert any("holds node 4, which is no mesh node" in x for x in compared(gltf, obj).lines)
    # A triangle too many, and a group for a node without a mesh.
    obj.write_text(text + "f 1 2 3\no node7\n")
    lines = compared(gltf, obj).lines
    assert any("group node1: 2 triangles, expected 1" in x for x in lines)
    assert any("group node7: no such mesh node" in x for x in lines)


def test_compare_reads_the_animation_from_the_header(tmp_path):
    gltf, obj = decoded_obj(tmp_path, "0", "0.5")
    text = obj.read_text()
    assert "# frame 0 animation 0 time 0.5" in text
    obj.write_text(text.replace("time 0.5", "time 1"))
    assert compared(gltf, obj).status == "MISMATCH"  # node 0 is where it is at 0.5 s, not at 1 s
    obj.write_text(text.replace("animation 0 time 0.5", "animation none time 0"))
    assert compared(gltf, obj).status == "MISMATCH"


def test_compressed_geometry_is_not_checked(tmp_path):
    g = Gltf()
    mesh = g.mesh([{"attributes": {"POSITION": g.accessor([], count=3, type="VEC3")},
                    "extensions": {"KHR_draco_mesh_compression": {"bufferView": 0, "attributes": {"POSITION": 0}}}}])
    g.node(mesh=mesh)
    gltf = g.write(tmp_path / "draco.gltf")
    obj = tmp_path / "x.obj"
    obj.write_text("# lodbench export: x\n# frame 0 animation none time 0\n")
    r = subprocess.run([sys.executable, str(SCRIPT), "compare", str(gltf), str(obj)], capture_output=True, text=True)
    assert r.returncode == 3 and "not checked: KHR_draco_mesh_compression" in r.stdout


FAKE_LODBENCH = '''import sys
sys.path.insert(0, {scripts!r})
import check_gltf
args = sys.argv[1:]
opt = dict(zip(args[1::2], args[2::2]))
if "refuse" in opt["--scene"]:
    sys.exit("error: this file is refused")
animation = None if opt.get("--animation") == "none" else 0
time = int(opt["--frame"]) / 30
doc = check_gltf.load_document(opt["--scene"])
check_gltf.write_obj(check_gltf.decode(doc, animation, time), opt["--out"], opt["--scene"])
lines = open(opt["--out"]).read().splitlines()
lines[1] = "# frame %s animation %s time %r" % (opt["--frame"], "none" if animation is None else 0, time)
open(opt["--out"], "w").write("\\n".join(lines) + "\\n")
'''


def test_run_with_a_stand_in_for_lodbench(tmp_path):
    gltf = scene(tmp_path)
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "refuse.gltf").write_text(gltf.read_text())
    fake = tmp_path / "fake_lodbench.py"
    fake.write_text(FAKE_LODBENCH.format(scripts=str(SCRIPT.parent)))
    launcher = tmp_path / "lodbench"
    launcher.write_text(f"#!/bin/sh\nexec {sys.executable} {fake} \"$@\"\n")
    launcher.chmod(0o755)
    r = subprocess.run([sys.executable, str(SCRIPT), "run", "--lodbench", str(launcher), "--frames", "0,15",
                        "--jobs", "2", str(tmp_path)], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    assert f"OK          {gltf}" in r.stdout
    assert "REFUSED" in r.stdout and "refused: error: this file is refused" in r.stdout
    assert "summary: 2 files: 1 OK, 0 mismatch, 1 refused, 0 not checked" in r.stdout
    commands = check_gltf.export_commands("lb", gltf, [0, 30], tmp_path)
    assert [c[1][1:6] + c[1][6:-2] for c in commands] == [
        ["export", "--scene", str(gltf), "--frame", "0"], ["export", "--scene", str(gltf), "--frame", "0",
                                                            "--animation", "none"],
        ["export", "--scene", str(gltf), "--frame", "30"]]
