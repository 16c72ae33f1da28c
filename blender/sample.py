"""What Blender evaluates, as toonkit arrays: every frame of the scene range through the
depsgraph (rigs, constraints, drivers, NLA, shape keys, bone parents all apply).

Meshes deformed by one armature form one articulated group: that armature's pose gives the
skeleton of SMEAR Eqs. 3-9 (joint world matrices per frame, skin weights from the vertex
groups named after its bones). Meshes parented to one of its bones ride that bone; other
meshes are simple objects (SMEAR Eq. 1). Vertex groups that are not bones become scalar
attributes (painted weights).
"""

from dataclasses import dataclass, field

import numpy as np


class SampleError(Exception):
    """The selection cannot be sampled; the message is one line for the operator."""


@dataclass
class Sample:
    """Arrays for `toonkit.Scene.from_arrays`, plus what the results need to map back."""

    names: list                 # original object names, in vertex order
    ranges: list                # vertex range of each object
    positions: np.ndarray       # (frames, vertices, 3) float32, world space
    triangles: np.ndarray       # (t, 3) int32
    frame_start: int
    fps: float
    skin: dict = None
    attributes: dict = field(default_factory=dict)
    bones: list = field(default_factory=list)
    camera: np.ndarray = None   # (frames, 4, 4) camera world matrices (camera-relative mode)

    @property
    def objects(self):
        return [(n, r) for n, r in zip(self.names, self.ranges)]


def armature_of(obj):
    """The armature deforming `obj` (an Armature modifier's object), if any."""
    for m in obj.modifiers:
        if m.type == "ARMATURE" and m.object is not None and m.show_render:
            return m.object
    return None


def _bone_parent(obj):
    """The armature and bone carrying `obj` (through object parents, e.g. a prop parented to
    a bone-parented empty), or (None, None)."""
    while obj.parent is not None:
        if obj.parent.type == "ARMATURE" and obj.parent_type == "BONE":
            return obj.parent, obj.parent_bone
        obj = obj.parent
    return None, None


def _joint_order(armature):
    """Bones with parents before children; returns names and parent indices."""
    names, parents = [], []
    index = {}

    def visit(bone):
        index[bone.name] = len(names)
        names.append(bone.name)
        parents.append(index[bone.parent.name] if bone.parent else -1)
        for c in bone.children:
            visit(c)

    for b in armature.data.bones:
        if b.parent is None:
            visit(b)
    return names, parents


def _evaluated(obj, depsgraph):
    """World-space vertex positions of `obj` as evaluated, and its evaluated mesh's triangles."""
    ev = obj.evaluated_get(depsgraph)
    mesh = ev.to_mesh()
    try:
        n = len(mesh.vertices)
        co = np.empty(n * 3, np.float32)
        mesh.vertices.foreach_get("co", co)
        m = np.array(ev.matrix_world, dtype=np.float64)
        p = co.reshape(n, 3).astype(np.float64) @ m[:3, :3].T + m[:3, 3]
        mesh.calc_loop_triangles()
        tris = np.empty(len(mesh.loop_triangles) * 3, np.int32)
        mesh.loop_triangles.foreach_get("vertices", tris)
        return p.astype(np.float32), tris.reshape(-1, 3)
    finally:
        ev.to_mesh_clear()


def _groups(obj, n):
    """Every vertex group of `obj` as a dense (n,) weight array (one pass over the vertices)."""
    names = {g.index: g.name for g in obj.vertex_groups}
    out = {name: np.zeros(n, np.float32) for name in names.values()}
    for v in obj.data.vertices:
        for g in v.groups:
            if g.group in names:
                out[names[g.group]][v.index] = g.weight
    return out


def sample(context, objects, camera_relative=False):
    """Samples `objects` (meshes) over the scene range; restores the current frame."""
    scene = context.scene
    meshes = [o for o in objects if o.type == "MESH"]
    if not meshes:
        raise SampleError("select at least one mesh object")
    if camera_relative and scene.camera is None:
        raise SampleError("camera-relative speed needs a scene camera")
    start, end = scene.frame_start, scene.frame_end
    if end <= start:
        raise SampleError(f"the scene range {start}-{end} needs at least two frames")
    rigs = [armature_of(o) or _bone_parent(o)[0] for o in meshes]
    counts = {}
    for r in rigs:
        if r is not None:
            counts[r.name] = counts.get(r.name, 0) + 1
    armature = None
    if counts:
        name = max(counts, key=counts.get)
        armature = next(r for r in rigs if r is not None and r.name == name)
    joint_names, parents = _joint_order(armature) if armature else ([], [])
    joint_index = {n: i for i, n in enumerate(joint_names)}

    frames = end - start + 1
    current = scene.frame_current, scene.frame_subframe
    per_frame, mats, cams, tris = [], [], [], None
    try:
        for k in range(frames):
            scene.frame_set(start + k)
            dg = context.evaluated_depsgraph_get()
            ps, ts = [], []
            for o in meshes:
                p, t = _evaluated(o, dg)
                ps.append(p)
                ts.append(t)
            if tris is None:
                tris = ts
                counts0 = [len(p) for p in ps]
            elif [len(p) for p in ps] != counts0:
                changed = next(o.name for o, p, c in zip(meshes, ps, counts0) if len(p) != c)
                raise SampleError(
                    f"{changed}: its vertex count changes at frame {start + k} "
                    "(a modifier changes topology); apply or disable it")
            per_frame.append(np.concatenate(ps))
            if armature is not None:
                ev = armature.evaluated_get(dg)
                world = np.array(ev.matrix_world, dtype=np.float64)
                mats.append(np.stack([world @ np.array(ev.pose.bones[n].matrix, np.float64)
                                      for n in joint_names]))
            if camera_relative:
                cams.append(np.array(scene.camera.evaluated_get(dg).matrix_world, np.float64))
    finally:
        scene.frame_set(current[0], subframe=current[1])

    ranges, offset, all_tris = [], 0, []
    for c, t in zip(counts0, tris):
        ranges.append(range(offset, offset + c))
        all_tris.append(t + offset)
        offset += c
    positions = np.stack(per_frame)
    result = Sample(
        names=[o.name for o in meshes], ranges=ranges, positions=positions,
        triangles=np.concatenate(all_tris).astype(np.int32), frame_start=start,
        fps=scene.render.fps / scene.render.fps_base, bones=joint_names)

    weights = np.zeros((offset, len(joint_names)), np.float32)
    object_parents = []
    for o, r, c in zip(meshes, ranges, counts0):
        parent, bone = _bone_parent(o)
        object_parents.append(joint_index.get(bone, -1) if parent == armature else -1)
        if len(o.data.vertices) != c:
            continue  # a topology-changing modifier: no weights, a simple object
        skinned = armature is not None and armature_of(o) == armature
        for name, values in _groups(o, c).items():
            if skinned and name in joint_index:
                weights[r.start:r.stop, joint_index[name]] = values
            else:
                painted = result.attributes.setdefault(name, np.zeros(offset, np.float32))
                painted[r.start:r.stop] = values
    if armature is not None:
        total = weights.sum(axis=1, keepdims=True)
        np.divide(weights, total, out=weights, where=total > 0)
        result.skin = {
            "parents": np.array(parents, np.int64),
            "joint_names": joint_names,
            "matrices": np.stack(mats).astype(np.float32),
            "weights": weights,
            "object_parents": object_parents,
        }
    if camera_relative:
        result.camera = np.stack(cams)
    return result


def to_camera(sample):
    """Positions and joint matrices in the camera's frame (SMEAR: camera space)."""
    inv = np.linalg.inv(sample.camera)
    p = sample.positions.astype(np.float64)
    p = np.einsum("fij,fvj->fvi", inv[:, :3, :3], p) + inv[:, None, :3, 3]
    skin = None
    if sample.skin is not None:
        skin = dict(sample.skin)
        skin["matrices"] = np.einsum("fij,fkjl->fkil", inv,
                                     sample.skin["matrices"].astype(np.float64)).astype(np.float32)
    return p.astype(np.float32), skin


def from_camera(camera, points):
    """Points (frames, n, 3) from camera space back to the world."""
    c = camera.astype(np.float64)
    return (np.einsum("fij,fvj->fvi", c[:, :3, :3], points.astype(np.float64))
            + c[:, None, :3, 3]).astype(np.float32)
