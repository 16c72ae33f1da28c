"""An independent reading of a glTF 2.0 file, straight from the specification, in numpy only:
the reference the core's sampling (crates/anim) is checked against.

It shares no code with toonkit: it parses the GLB (or .gltf with external or data-URI buffers)
itself and evaluates, in float64, what the specification says a clip means:

* node animation sampled with LINEAR (lerp; slerp for rotations), STEP or CUBICSPLINE
  interpolation, clamped to the first and last key (glTF 2.0, 3.11 "Animations");
* world = parent world · local (T · R · S) (3.5.3 "Transformations");
* morph targets: base + Σ weight · target delta, the weights the node's (else the mesh's)
  until a channel animates them (3.7.2.2 "Morph Targets");
* skinning: Σ w · jointWorld · inverseBind · v, with the skinned mesh node's own transform
  ignored (3.7.3 "Skins");
* an unskinned mesh placed by its node's world matrix.

Nothing here knows about Blender, a bind pose or a rest pose: it is what the file means at a
time of a clip.
"""

from __future__ import annotations

import base64
import json
import struct
from pathlib import Path

import numpy as np

_COMPONENTS = {5120: "i1", 5121: "u1", 5122: "<i2", 5123: "<u2", 5125: "<u4", 5126: "<f4"}
_SIZES = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
_NORMALIZED = {5120: 127.0, 5121: 255.0, 5122: 32767.0, 5123: 65535.0}


class Gltf:
    """A glTF document: its JSON and its buffers, with accessors read as float64 arrays."""

    def __init__(self, path: str | Path):
        path = Path(path)
        data = path.read_bytes()
        buffers: list[bytes] = []
        if data[:4] == b"glTF":
            offset, chunks = 12, []
            while offset < len(data):
                length, kind = struct.unpack_from("<II", data, offset)
                chunks.append((kind, data[offset + 8:offset + 8 + length]))
                offset += 8 + length
            self.json = json.loads(next(c for k, c in chunks if k == 0x4E4F534A))
            binary = next((c for k, c in chunks if k == 0x004E4942), b"")
        else:
            self.json, binary = json.loads(data), b""
        for b in self.json.get("buffers", []):
            uri = b.get("uri")
            if uri is None:
                buffers.append(binary)
            elif uri.startswith("data:"):
                buffers.append(base64.b64decode(uri.split(",", 1)[1]))
            else:
                buffers.append((path.parent / uri).read_bytes())
        self.buffers = buffers
        self.nodes = self.json["nodes"]
        self.parent = {c: i for i, n in enumerate(self.nodes) for c in n.get("children", [])}

    def accessor(self, index: int) -> np.ndarray:
        """Accessor `index` as a (count, components) float64 array (normalized integers
        scaled to [0, 1] / [-1, 1], sparse values applied)."""
        a = self.json["accessors"][index]
        ctype, width = a["componentType"], _SIZES[a["type"]]
        dtype = np.dtype(_COMPONENTS[ctype])
        count = a["count"]
        out = np.zeros((count, width), np.float64)
        if "bufferView" in a:
            view = self.json["bufferViews"][a["bufferView"]]
            buf = self.buffers[view["buffer"]]
            start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
            stride = view.get("byteStride") or dtype.itemsize * width
            rows = np.ndarray((count, width), dtype, buf, start, (stride, dtype.itemsize))
            out[:] = rows
        if a.get("normalized") and ctype in _NORMALIZED:
            out = np.maximum(out / _NORMALIZED[ctype], -1.0)
        if "sparse" in a:
            s = a["sparse"]
            iview = self.json["bufferViews"][s["indices"]["bufferView"]]
            idtype = np.dtype(_COMPONENTS[s["indices"]["componentType"]])
            idx = np.frombuffer(self.buffers[iview["buffer"]], idtype, s["count"],
                                iview.get("byteOffset", 0) + s["indices"].get("byteOffset", 0))
            vview = self.json["bufferViews"][s["values"]["bufferView"]]
            vals = np.frombuffer(self.buffers[vview["buffer"]], dtype, s["count"] * width,
                                 vview.get("byteOffset", 0) + s["values"].get("byteOffset", 0))
            out[idx.astype(np.int64)] = vals.reshape(-1, width)
        return out

    def animation(self, name: str | None) -> dict | None:
        """The animation called `name` (the first one when None; None without animations)."""
        anims = self.json.get("animations", [])
        if not anims:
            return None
        if name is None:
            return anims[0]
        return next(a for a in anims if a.get("name") == name)

    def time_range(self, anim: dict | None) -> tuple[float, float]:
        """First and last key time over the samplers of `anim` (0, 0 without one)."""
        if anim is None:
            return 0.0, 0.0
        times = [self.accessor(s["input"])[:, 0] for s in anim["samplers"]]
        return min(float(t[0]) for t in times), max(float(t[-1]) for t in times)


def _quat_matrix(q: np.ndarray) -> np.ndarray:
    x, y, z, w = q / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def _slerp(a: np.ndarray, b: np.ndarray, t: float) -> np.ndarray:
    d = float(a @ b)
    if d < 0.0:
        b, d = -b, -d
    if d > 0.9995:
        q = a + t * (b - a)
        return q / np.linalg.norm(q)
    theta = np.arccos(min(d, 1.0))
    return (np.sin((1 - t) * theta) * a + np.sin(t * theta) * b) / np.sin(theta)


def _sample(doc: Gltf, sampler: dict, path: str, t: float) -> np.ndarray:
    times = doc.accessor(sampler["input"])[:, 0]
    values = doc.accessor(sampler["output"])
    interp = sampler.get("interpolation", "LINEAR")
    n = len(times)
    width = values.size // (n * (3 if interp == "CUBICSPLINE" else 1))
    values = values.reshape(n, -1, width) if interp == "CUBICSPLINE" else values.reshape(n, width)
    if interp == "CUBICSPLINE":
        # (in-tangent, value, out-tangent) per key (glTF 2.0, Appendix C).
        tangents_in, points, tangents_out = (values[:, k] for k in (0, 1, 2))
    else:
        points = values
    if t <= times[0]:
        v = points[0]
    elif t >= times[-1]:
        v = points[-1]
    else:
        k = int(np.searchsorted(times, t, side="right")) - 1
        dt = times[k + 1] - times[k]
        u = (t - times[k]) / dt
        if interp == "STEP":
            v = points[k]
        elif interp == "CUBICSPLINE":
            u2, u3 = u * u, u * u * u
            v = ((2 * u3 - 3 * u2 + 1) * points[k] + (u3 - 2 * u2 + u) * dt * tangents_out[k]
                 + (-2 * u3 + 3 * u2) * points[k + 1] + (u3 - u2) * dt * tangents_in[k + 1])
        elif path == "rotation":
            v = _slerp(points[k], points[k + 1], u)
        else:
            v = (1 - u) * points[k] + u * points[k + 1]
    if path == "rotation":
        v = v / np.linalg.norm(v)
    return v


def pose(doc: Gltf, anim: dict | None, t: float) -> tuple[list[np.ndarray], dict[int, np.ndarray]]:
    """World matrices (4×4, float64) of every node and the animated morph weights per node at
    time `t` of `anim`."""
    trs = []
    for n in doc.nodes:
        if "matrix" in n:
            trs.append({"matrix": np.array(n["matrix"], np.float64).reshape(4, 4).T})
        else:
            trs.append({"translation": np.array(n.get("translation", [0, 0, 0]), np.float64),
                        "rotation": np.array(n.get("rotation", [0, 0, 0, 1]), np.float64),
                        "scale": np.array(n.get("scale", [1, 1, 1]), np.float64)})
    weights: dict[int, np.ndarray] = {}
    for ch in (anim or {}).get("channels", []):
        target = ch["target"]
        if "node" not in target:
            continue
        v = _sample(doc, anim["samplers"][ch["sampler"]], target["path"], t)
        if target["path"] == "weights":
            weights[target["node"]] = v
        else:
            trs[target["node"]][target["path"]] = v
    local = []
    for p in trs:
        if "matrix" in p:
            local.append(p["matrix"])
            continue
        m = np.eye(4)
        m[:3, :3] = _quat_matrix(p["rotation"]) * p["scale"][None, :]
        m[:3, 3] = p["translation"]
        local.append(m)
    world: list[np.ndarray | None] = [None] * len(doc.nodes)

    def resolve(i: int) -> np.ndarray:
        if world[i] is None:
            parent = doc.parent.get(i)
            world[i] = local[i] if parent is None else resolve(parent) @ local[i]
        return world[i]

    for i in range(len(doc.nodes)):
        resolve(i)
    return world, weights


def mesh_nodes(doc: Gltf) -> list[int]:
    """The nodes that draw a mesh, in the default scene, depth first."""
    scene = doc.json.get("scenes", [{}])[doc.json.get("scene", 0)]
    out: list[int] = []

    def walk(i: int) -> None:
        if "mesh" in doc.nodes[i]:
            out.append(i)
        for c in doc.nodes[i].get("children", []):
            walk(c)

    for r in scene.get("nodes", []):
        walk(r)
    return out


def node_positions(doc: Gltf, node: int, world: list[np.ndarray],
                   weights: dict[int, np.ndarray]) -> np.ndarray:
    """World positions (float64, the primitives' vertices concatenated) of the mesh `node`
    draws, posed by `world` and `weights` from [`pose`]."""
    n = doc.nodes[node]
    mesh = doc.json["meshes"][n["mesh"]]
    morph = weights.get(node)
    if morph is None:
        morph = np.array(n.get("weights", mesh.get("weights", [])), np.float64)
    parts = []
    for prim in mesh["primitives"]:
        p = doc.accessor(prim["attributes"]["POSITION"])
        for w, target in zip(morph, prim.get("targets", [])):
            if w != 0.0 and "POSITION" in target:
                p = p + w * doc.accessor(target["POSITION"])
        ph = np.c_[p, np.ones(len(p))]
        if "skin" in n:
            skin = doc.json["skins"][n["skin"]]
            joints = skin["joints"]
            if "inverseBindMatrices" in skin:
                ib = doc.accessor(skin["inverseBindMatrices"]).reshape(-1, 4, 4).transpose(0, 2, 1)
            else:
                ib = np.repeat(np.eye(4)[None], len(joints), 0)
            mats = np.stack([world[j] @ ib[k] for k, j in enumerate(joints)])
            out = np.zeros((len(p), 4))
            k = 0
            while f"JOINTS_{k}" in prim["attributes"]:
                js = doc.accessor(prim["attributes"][f"JOINTS_{k}"]).astype(np.int64)
                ws = doc.accessor(prim["attributes"][f"WEIGHTS_{k}"])
                for c in range(4):
                    out += ws[:, c:c + 1] * np.einsum("vij,vj->vi", mats[js[:, c]], ph)
                k += 1
            parts.append(out[:, :3])
        else:
            parts.append((ph @ world[node].T)[:, :3])
    return np.concatenate(parts)


def positions_at(doc: Gltf, anim: dict | None, t: float) -> dict[int, np.ndarray]:
    """World positions of every mesh node at time `t` of `anim`, by node index."""
    world, weights = pose(doc, anim, t)
    return {i: node_positions(doc, i, world, weights) for i in mesh_nodes(doc)}


def _armature(doc: Gltf, skin: dict) -> int | None:
    """The node a skin's bind pose is placed by: the deepest common ancestor of its joints
    and its `skeleton`, or that node's parent when it is a joint (None: the scene root)."""
    def path(i: int) -> list[int]:
        p = [i]
        while p[-1] in doc.parent:
            p.append(doc.parent[p[-1]])
        return p[::-1]

    paths = [path(j) for j in skin["joints"] + ([skin["skeleton"]] if "skeleton" in skin else [])]
    common = paths[0]
    for p in paths[1:]:
        k = 0
        while k < min(len(common), len(p)) and common[k] == p[k]:
            k += 1
        common = common[:k]
    node = common[-1] if common else None
    if node is not None and node in skin["joints"]:
        node = doc.parent.get(node)
    return node


def rest_positions(doc: Gltf, anim: dict | None) -> dict[int, np.ndarray]:
    """World positions of every mesh node at the rest pose toonkit measures a character's size
    on (docs/smear-units.md): every joint at its bind transform `armature · IB⁻¹` (the inverse
    bind matrix read relative to the skin's armature), every other node at its transform at the
    clip's first key, the base mesh (no morph target)."""
    t0 = doc.time_range(anim)[0]
    posed, _ = pose(doc, anim, t0)
    bind: dict[int, tuple[int | None, np.ndarray]] = {}
    for skin in doc.json.get("skins", []):
        if "inverseBindMatrices" not in skin:
            continue
        ib = doc.accessor(skin["inverseBindMatrices"]).reshape(-1, 4, 4).transpose(0, 2, 1)
        armature = _armature(doc, skin)
        for k, j in enumerate(skin["joints"]):
            bind[j] = (armature, np.linalg.inv(ib[k]))
    world: list[np.ndarray | None] = [None] * len(doc.nodes)

    def resolve(i: int) -> np.ndarray:
        if world[i] is None:
            parent = doc.parent.get(i)
            if i in bind:
                armature, b = bind[i]
                world[i] = (np.eye(4) if armature is None else resolve(armature)) @ b
            else:
                # The node's own transform at the first key, under its parent's rest.
                local = posed[i] if parent is None else np.linalg.inv(posed[parent]) @ posed[i]
                world[i] = local if parent is None else resolve(parent) @ local
        return world[i]

    for i in range(len(doc.nodes)):
        resolve(i)
    no_morph = {i: np.zeros(len(doc.nodes[i].get("weights", []) or
                               doc.json["meshes"][doc.nodes[i]["mesh"]].get("weights", [])))
                for i in mesh_nodes(doc)}
    return {i: node_positions(doc, i, world, no_morph) for i in mesh_nodes(doc)}


def diagonal(points: dict[int, np.ndarray] | np.ndarray) -> float:
    """Bounding-box diagonal of a set of points (or of every array of a dict)."""
    p = np.concatenate(list(points.values())) if isinstance(points, dict) else points
    return float(np.linalg.norm(p.max(0) - p.min(0)))
