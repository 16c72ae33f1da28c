"""What Blender evaluates, as toonkit arrays: every frame of the scene range through the
depsgraph (rigs, constraints, drivers, NLA, shape keys, bone parents all apply).

Two ways to get a mesh's vertices per frame (docs/blender.md, "Sampling"):

* **pose only** -- a mesh deformed only by Armature modifiers (vertex groups, linear blend),
  or not deformed at all (a rigid prop, a keyed object): Blender evaluates the pose with the
  mesh's Armature modifiers off, the bone and object matrices are read per frame, and
  `toonkit.skin` skins the rest vertices in the core with the vertex groups normalized as the
  Armature modifier normalizes them (deforming bones only; a vertex whose weights sum to at
  most 1e-4 stays at rest). Preserve volume (dual quaternions), envelopes, B-Bones, a
  modifier's vertex-group mask or multi-modifier blending take the evaluated path instead.
* **evaluated** -- everything else (shape keys, other modifiers, two armatures): the
  depsgraph's evaluated mesh per frame.

Meshes deformed by one armature form one articulated group: that armature's pose gives the
skeleton of SMEAR Eqs. 3-9 (joint world matrices per frame, skin weights from the vertex
groups named after its bones). Meshes parented to one of its bones ride that bone; other
meshes are simple objects (SMEAR Eq. 1). Vertex groups that are not bones become scalar
attributes (painted weights).
"""

from dataclasses import dataclass, field
from itertools import chain

import numpy as np

from . import weights


class SampleError(Exception):
    """The selection cannot be sampled; the message is one line for the operator."""


@dataclass
class Sample:
    """Arrays for `toonkit.Scene.from_arrays`, plus what the results need to map back."""

    names: list                 # original object names, in vertex order
    ranges: list                # vertex range of each object
    triangles: np.ndarray       # (t, 3) int32
    frame_start: int
    fps: float
    skin: dict = None
    attributes: dict = field(default_factory=dict)
    bones: list = field(default_factory=list)
    camera: np.ndarray = None   # (frames, 4, 4) camera world matrices (camera-relative mode)
    rest: np.ndarray = None     # (vertices, 3) float32 world space at the rest pose
    # `toonkit.skin`'s arguments when every mesh is pose-only: the core skins the clip
    # straight into the scene it makes (`Scene.from_arrays(skinning=...)`, no copy).
    skinning: tuple = None
    # The same clip already being skinned by the core while frames were read
    # (`toonkit.SkinStream`): `clip_skinning` hands it over once.
    stream: object = field(default=None, repr=False)
    _y_up: np.ndarray = field(default=None, repr=False)
    _world: np.ndarray = field(default=None, repr=False)

    @property
    def objects(self):
        return [(n, r) for n, r in zip(self.names, self.ranges)]

    @property
    def frame_count(self):
        return len(self.skinning[3]) if self._y_up is None else len(self._y_up)

    @property
    def y_up(self):
        """(frames, vertices, 3) float32 C-contiguous, the world turned Y-up (`to_y_up`);
        skinned by the core on first use when only `skinning` is kept (the bake hands the
        core `skinning` itself and never reads this)."""
        if self._y_up is None:
            import toonkit
            self._y_up = toonkit.skin(*self.skinning)
        return self._y_up

    def clip_skinning(self):
        """`Scene.from_arrays`' `skinning`: the stream the frames were pushed to (once), else
        `toonkit.skin`'s arguments."""
        stream, self.stream = self.stream, None
        return stream if stream is not None else self.skinning

    def moves(self):
        """Whether any vertex moves over the frames (no copy of them). With `skinning`: a
        vertex moves only when a matrix it is skinned with changes (the same matrices give
        the same vertices, bit for bit)."""
        if self._y_up is None:
            _, indices, weights, matrices = self.skinning
            if indices.strides[0] == 0:  # every vertex has the same slots (`_Pose`)
                slots = indices[0][(indices[0] >= 0) & (weights > 0).any(axis=0)]
            else:
                slots = indices[(indices >= 0) & (weights > 0)]
            used = matrices[:, np.unique(slots)]
            return any(not np.array_equal(used[0], m) for m in used[1:])
        first = self._y_up[0]
        return any(not np.array_equal(first, p) for p in self._y_up[1:])

    @property
    def positions(self):
        """(frames, vertices, 3) float32 in Blender's Z-up world: `y_up` turned back (exact),
        made once on first use (the bake never reads it)."""
        if self._world is None:
            self._world = np.ascontiguousarray(from_y_up(self.y_up))
        return self._world


def armature_of(obj, viewport=False):
    """The armature deforming `obj` (an Armature modifier's object, shown in renders or in
    the `viewport`), if any."""
    for m in obj.modifiers:
        if m.type == "ARMATURE" and m.object is not None and (
                m.show_viewport if viewport else m.show_render):
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


def _triangles(ev):
    """The loop triangles (t, 3) of the evaluated object `ev`'s mesh: its own mesh's corners
    when every face is a triangle and only Armature modifiers act (a triangle's triangulation
    is itself whatever the pose, and its loop triangle its corners in order)."""
    own = _own_triangles(ev.original)
    if own is not None:
        return own
    mesh = ev.to_mesh()
    try:
        mesh.calc_loop_triangles()
        tris = np.empty(len(mesh.loop_triangles) * 3, np.int32)
        mesh.loop_triangles.foreach_get("vertices", tris)
        return tris.reshape(-1, 3)
    finally:
        ev.to_mesh_clear()


def _own_triangles(obj):
    """(t, 3) int32 corners of `obj`'s own mesh when all its faces are triangles (3 corners
    per face: faces own consecutive corners) and only Armature modifiers act, else None.
    Read from the `.corner_vert` attribute in one bulk copy (`loop_triangles.foreach_get`
    goes item by item)."""
    mesh = obj.data
    if (not mesh.polygons or len(mesh.loops) != 3 * len(mesh.polygons)
            or any(m.type != "ARMATURE" for m in obj.modifiers)):
        return None
    corners = mesh.attributes.get(".corner_vert")
    if corners is None or len(corners.data) != len(mesh.loops):
        return None
    tris = np.empty(len(mesh.loops), np.int32)
    corners.data.foreach_get("value", tris)
    return tris.reshape(-1, 3)


#: A vertex whose deforming weights sum to at most this stays at rest (the Armature modifier's
#: threshold).
ARMATURE_MIN_WEIGHT = 1e-4


def pose_only_reason(obj):
    """Why the vertices of `obj` need Blender's evaluated mesh, or None when its rest vertices
    and the pose give them (no modifiers, or Armature modifiers on one armature that blend
    vertex groups linearly)."""
    if obj.data.shape_keys is not None and len(obj.data.shape_keys.key_blocks) > 1:
        return "shape keys"
    armature = None
    for m in obj.modifiers:
        if not m.show_viewport:
            continue
        if m.type != "ARMATURE":
            return f"modifier {m.name!r}"
        if m.object is None:
            continue
        if armature is not None and m.object != armature:
            return "two armatures"
        if m.object.type != "ARMATURE":
            return f"modifier {m.name!r}"
        armature = m.object
        if m.use_deform_preserve_volume:
            return "preserve volume (dual quaternions)"
        if m.use_bone_envelopes or not m.use_vertex_groups:
            return "bone envelopes"
        if m.vertex_group or m.use_multi_modifier:
            return "a masked Armature modifier"
    if armature is not None and any(b.use_deform and b.bbone_segments > 1
                                    for b in armature.data.bones):
        return "B-Bones"
    return None


def _co(obj):
    """Rest vertices (object space) of `obj`'s own mesh: no modifier, the basis shape."""
    co = np.empty(len(obj.data.vertices) * 3, np.float32)
    obj.data.vertices.foreach_get("co", co)
    return co.reshape(-1, 3)


def _matrix(m):
    """A mathutils 4x4 matrix as float64 numpy (fromiter: np.array walks its rows 5x
    slower)."""
    return np.fromiter(chain.from_iterable(m), np.float64, 16).reshape(4, 4)


def affine_inverse(m):
    """Inverses of affine 4x4 matrices (..., 4, 4) from the 3x3 part's cofactors: numpy's
    LAPACK inverse wakes BLAS threads, which on a loaded machine took hundreds of
    milliseconds for a clip's armature matrices. A singular matrix (a zero scale) inverts its
    translation only."""
    r = m[..., :3, :3]
    cols = np.stack([np.cross(r[..., 1, :], r[..., 2, :]), np.cross(r[..., 2, :], r[..., 0, :]),
                     np.cross(r[..., 0, :], r[..., 1, :])], axis=-1)
    det = np.einsum("...i,...i->...", r[..., 0, :], cols[..., :, 0])
    singular = det == 0.0
    inv3 = np.where(singular[..., None, None], np.eye(3),
                    cols / np.where(singular, 1.0, det)[..., None, None])
    out = np.zeros(m.shape, np.float64)
    out[..., :3, :3] = inv3
    out[..., :3, 3] = -np.einsum("...ij,...j->...i", inv3, m[..., :3, 3])
    out[..., 3, 3] = 1.0
    return out


def _rest_matrices(context, meshes):
    """World matrix of each mesh with the armatures it follows in rest position: where its
    own vertices (no modifier, basis shape) sit at the rest pose, whose bounding-box diagonal
    is a smear style's size unit (docs/smear-units.md)."""
    rigs = {r for o in meshes for r in (armature_of(o), _bone_parent(o)[0]) if r is not None}
    changed = []
    try:
        for data in {r.data for r in rigs if r.data.pose_position != "REST"}:
            try:
                data.pose_position = "REST"
            except (AttributeError, RuntimeError):  # linked, read-only: measured as posed
                continue
            changed.append(data)
        dg = context.evaluated_depsgraph_get()
        dg.update()
        return {o.name: _matrix(o.evaluated_get(dg).matrix_world) for o in meshes}
    finally:
        for data in changed:
            data.pose_position = "POSE"
        context.evaluated_depsgraph_get().update()


def _rest_positions(meshes, ranges, matrices, result, own):
    """(vertices, 3) float32: each mesh's own vertices (`own` by name when read already)
    through its rest matrix, or its first frame (of the sample `result`) when a modifier
    changed its vertex count."""
    rest = np.empty((ranges[-1].stop, 3), np.float32)
    for o, r in zip(meshes, ranges):
        if len(o.data.vertices) != len(r):
            rest[r.start:r.stop] = from_y_up(result.y_up[0, r.start:r.stop])
            continue
        co = (own[o.name] if o.name in own else _co(o)).astype(np.float64)
        m = matrices[o.name]
        rest[r.start:r.stop] = co @ m[:3, :3].T + m[:3, 3]
    return rest


class _Pose:
    """The pose-only objects of one sample: their rest vertices, and per frame the object and
    armature matrices and the bones' pose matrices (read by foreach_get)."""

    def __init__(self, objects, frames):
        self.objects = objects
        self.armatures = []
        self.armature_of = {o.name: armature_of(o, viewport=True) for o in objects}
        for o in objects:
            a = self.armature_of[o.name]
            if a is not None and a not in self.armatures:
                self.armatures.append(a)
        self.rest = {o.name: _co(o) for o in objects}
        self.tris = {}
        self.object_world = np.empty((frames, len(objects), 4, 4), np.float64)
        self.arm_world = np.empty((frames, len(self.armatures), 4, 4), np.float64)
        self.pose = [np.empty((frames, len(a.pose.bones) * 16), np.float32)
                     for a in self.armatures]
        self.muted = []
        self.early = False

    def mute_early(self):
        """When every mesh takes its triangles from its own corners (`_own_triangles`), the
        Armature modifiers go off before the vertex weights are read: neither that read nor
        the first frame then evaluates a deformed mesh Blender would skin for nothing."""
        tris = {o.name: _own_triangles(o) for o in self.objects}
        if all(t is not None for t in tris.values()):
            self.tris, self.early = tris, True
            self.mute()

    def first_frame(self, dg):
        """The evaluated meshes' triangles (a quad's diagonal and an n-gon's triangles follow
        its shape), then the Armature modifiers off: Blender evaluates the pose, not these
        meshes."""
        if self.early:
            return
        for o in self.objects:
            self.tris[o.name] = _triangles(o.evaluated_get(dg))
        self.mute()

    def mute(self):
        """Turns the Armature modifiers of the pose-only meshes off while sampling: Blender
        evaluates the pose, not the meshes."""
        for o in self.objects:
            for m in o.modifiers:
                if m.type == "ARMATURE" and m.show_viewport:
                    m.show_viewport = False
                    self.muted.append(m)

    def unmute(self):
        for m in self.muted:
            m.show_viewport = True
        self.muted.clear()

    def read(self, k, dg):
        """The matrices of frame `k` (the depsgraph evaluated at that frame)."""
        for i, o in enumerate(self.objects):
            self.object_world[k, i] = _matrix(o.evaluated_get(dg).matrix_world)
        for i, a in enumerate(self.armatures):
            ev = a.evaluated_get(dg)
            self.arm_world[k, i] = _matrix(ev.matrix_world)
            ev.pose.bones.foreach_get("matrix", self.pose[i][k])

    def start(self, groups, stream):
        """Before the frames are read: every object's rest vertices and influences (from
        its vertex `groups`), and with `stream` a `toonkit.SkinStream` that skins each chunk
        of frames `read` completes while Blender evaluates the next ones."""
        self.groups = groups
        rests, indices, weights, self.parts = [], [], [], []
        self.ranges, start, slots = {}, 0, 0
        for i, o in enumerate(self.objects):
            rest = self.rest[o.name]
            a = self.armature_of[o.name]
            if a is None:  # rigid: the object's matrix alone
                part = (i, None)
                idx = np.zeros((len(rest), 1), np.int64)
                w = np.ones((len(rest), 1), np.float32)
            else:
                part, idx, w = self._influences(o, i, a)
            rests.append(rest)
            indices.append(idx + slots if slots else idx)  # no -1 in them
            weights.append(w)
            self.parts.append(part)
            slots += idx.shape[1]
            self.ranges[o.name] = range(start, start + len(rest))
            start += len(rest)
        width = max(1, max(i.shape[1] for i in indices))
        indices = [i if i.shape[1] == width else
                   np.pad(i, [(0, 0), (0, width - i.shape[1])], constant_values=-1)
                   for i in indices]
        weights = [w if w.shape[1] == width else np.pad(w, [(0, 0), (0, width - w.shape[1])])
                   for w in weights]
        # One mesh (the usual bake) hands its arrays over as they are: no copies.
        self.inputs = (_joined(rests), _joined(indices), _joined(weights))
        frames = len(self.object_world)
        self.matrices = np.empty((frames, slots, 4, 4), np.float32)
        self.done = 0
        self.stream = None
        if stream:
            import toonkit
            try:
                self.stream = toonkit.SkinStream(*self.inputs, frames=frames, bones=slots)
            except ValueError as e:  # e.g. a clip over the job memory budget
                raise SampleError(" ".join(str(e).split())) from e

    def frames_read(self, count):
        """The first `count` frames are read: the skinning matrices of each whole chunk (a
        `STREAM_CHUNKS`th of the frames, and the last frames) are made and pushed to the
        stream."""
        frames = len(self.matrices)
        if count - self.done < -(-frames // STREAM_CHUNKS) and count < frames:
            return
        f = slice(self.done, count)
        chunk = _rows_y_up(np.concatenate([self._matrices(part, f) for part in self.parts],
                                          axis=1)).astype(np.float32)
        self.matrices[f] = chunk
        if self.stream is not None:
            self.stream.push(chunk)
        self.done = count

    def skinning(self):
        """`toonkit.skin`'s arguments for every frame's world vertices of the pose-only
        objects turned Y-up (`to_y_up`), concatenated in their order (float32 (frames,
        vertices, 3), the array the core reads). The turn is folded into the skinning
        matrices (a signed permutation of their rows), so the vertices are `to_y_up` of the
        world's bit for bit with no pass over them."""
        return (*self.inputs, self.matrices)

    def _influences(self, o, i, a):
        """What `_matrices` needs of `o` (deformed by the armature `a`), and the vertices'
        influences: every deforming bone of every vertex, weights as the Armature modifier
        normalizes them."""
        k = self.armatures.index(a)
        bones = a.data.bones
        pose_names = [pb.name for pb in a.pose.bones]
        deform = [j for j, n in enumerate(pose_names) if bones[n].use_deform]
        bind_inv = affine_inverse(np.stack([_matrix(bones[pose_names[j]].matrix_local)
                                           for j in deform]))
        groups = self.groups[o.name]
        n = len(self.rest[o.name])
        dense = np.zeros((n, len(deform)), np.float32)
        for j, b in enumerate(deform):
            g = groups.get(pose_names[b])
            if g is not None:
                np.maximum(g, 0.0, out=dense[:, j])
        dense[dense.sum(axis=1) <= ARMATURE_MIN_WEIGHT] = 0.0
        # Every deforming bone is an influence of every vertex: the core drops the zero
        # weights and keeps the rest in bone order (no numpy pass to compact them).
        return ((i, (k, deform, bind_inv)), np.broadcast_to(np.arange(len(deform)), dense.shape),
                dense)

    def _matrices(self, part, f):
        """Skinning matrices of the frames `f` (a slice) of one object (`start`'s part):
        its world matrix when rigid, else of each deforming bone, world space: armature
        world · pose · bind⁻¹ · armature world⁻¹ · object world, as the Armature modifier
        maps object space through the armature's."""
        i, bones = part
        world = self.object_world[f, i]
        if bones is None:
            return world[:, None]
        k, deform, bind_inv = bones
        frames = len(world)
        # foreach_get gives each 4x4 in Blender's column-major memory order.
        pose = self.pose[k][f].reshape(frames, -1, 4, 4).transpose(0, 1, 3, 2)[:, deform]
        arm = self.arm_world[f, k]
        to_arm = affine_inverse(arm) @ world
        return arm[:, None] @ pose.astype(np.float64) @ bind_inv[None] @ to_arm[:, None]


#: Chunks of frames `_Pose.frames_read` makes matrices for: each costs a few numpy calls on
#: Blender's thread (~0.25 ms), and the core skins it on another while the next frames are
#: read (the last one while the sample's other arrays are made).
STREAM_CHUNKS = 4


def _joined(arrays):
    return arrays[0] if len(arrays) == 1 else np.concatenate(arrays)


def bake_range(scene):
    """The frames a bake samples: the timeline's preview range when it is on (a range the
    user sets without touching the scene's), else the scene range; (start, end, its name)."""
    if scene.use_preview_range:
        return scene.frame_preview_start, scene.frame_preview_end, "preview range"
    return scene.frame_start, scene.frame_end, "scene range"


def sample(context, objects, camera_relative=False, pose_only=True):
    """Samples `objects` (meshes) over the bake range (`bake_range`); restores the current
    frame.
    `pose_only=False` evaluates every mesh (the reference the pose-only path is tested
    against)."""
    scene = context.scene
    meshes = [o for o in objects if o.type == "MESH"]
    if not meshes:
        raise SampleError("select at least one mesh object")
    if camera_relative and scene.camera is None:
        raise SampleError("camera-relative speed needs a scene camera")
    start, end, what = bake_range(scene)
    if end <= start:
        raise SampleError(f"the {what} {start}-{end} needs at least two frames")
    with weights.own_updates(context):
        return _sample(context, meshes, camera_relative, pose_only)


def _sample(context, meshes, camera_relative, pose_only):
    scene = context.scene
    start, end, _ = bake_range(scene)
    armature = _group_armature(meshes)
    joint_names, parents = _joint_order(armature) if armature else ([], [])

    frames = end - start + 1
    posed = _readers_evaluated(meshes, [o for o in meshes
                                        if pose_only and pose_only_reason(o) is None])
    evaluated = [o for o in meshes if o not in posed]
    pose = _Pose(posed, frames) if posed else None
    rig = _Rig(armature, joint_names, frames, pose) if armature is not None else None
    current = scene.frame_current, scene.frame_subframe
    per_object = {o.name: [] for o in evaluated}
    tris, cams = {}, []
    try:
        if pose is not None:
            pose.mute_early()
        groups = weights.read_all(context, meshes)
        if pose is not None:
            # The core skins the frames as they are read when it is to make the clip.
            pose.start(groups, stream=not evaluated and not camera_relative)
        for k in range(frames):
            scene.frame_set(start + k)
            if k == 0:
                if pose is not None:
                    pose.first_frame(context.evaluated_depsgraph_get())
                rest_matrices = _rest_matrices(context, meshes)
            dg = context.evaluated_depsgraph_get()
            for o in evaluated:
                p, t = _evaluated(o, dg)
                if k == 0:
                    tris[o.name] = t
                elif len(p) != len(per_object[o.name][0]):
                    raise SampleError(
                        f"{o.name}: its vertex count changes at frame {start + k} "
                        "(a modifier changes topology); apply or disable it")
                per_object[o.name].append(p)
            if pose is not None:
                pose.read(k, dg)
                pose.frames_read(k + 1)
            if rig is not None:
                rig.read(k, dg)
            if camera_relative:
                cams.append(_matrix(scene.camera.evaluated_get(dg).matrix_world))
    finally:
        if pose is not None:
            pose.unmute()
        scene.frame_set(current[0], subframe=current[1])

    if pose is not None:
        tris.update(pose.tris)
    counts = [len(pose.rest[o.name]) if o in posed else per_object[o.name][0].shape[0]
              for o in meshes]
    ranges, offset, all_tris = [], 0, []
    for o, c in zip(meshes, counts):
        ranges.append(range(offset, offset + c))
        all_tris.append(tris[o.name] + offset)
        offset += c
    result = Sample(
        names=[o.name for o in meshes], ranges=ranges,
        triangles=np.concatenate(all_tris).astype(np.int32), frame_start=start,
        fps=scene.render.fps / scene.render.fps_base, bones=joint_names)
    _positions(result, meshes, frames, pose, per_object)
    result.rest = _rest_positions(meshes, ranges, rest_matrices, result,
                                  pose.rest if pose is not None else {})
    _skin_and_attributes(result, meshes, counts, groups, armature, parents,
                         rig.matrices() if rig is not None else None)
    if camera_relative:
        result.camera = np.stack(cams)
    return result


def _readers_evaluated(meshes, posed):
    """`posed` without the meshes another sampled mesh's modifier reads (a Shrinkwrap onto
    the body, say): their Armature modifiers must stay on while sampling."""
    while True:
        read = {getattr(m, attr, None) for o in meshes if o not in posed for m in o.modifiers
                for attr in ("object", "target", "offset_object", "mirror_object")}
        kept = [o for o in posed if o not in read]
        if len(kept) == len(posed):
            return kept
        posed = kept


def _group_armature(meshes):
    """The armature most of `meshes` are deformed by or parented to (SMEAR's articulated
    group), if any."""
    rigs = [armature_of(o) or _bone_parent(o)[0] for o in meshes]
    counts = {}
    for r in rigs:
        if r is not None:
            counts[r.name] = counts.get(r.name, 0) + 1
    if not counts:
        return None
    name = max(counts, key=counts.get)
    return next(r for r in rigs if r is not None and r.name == name)


class _Rig:
    """The joint world matrices of the articulated group's armature per frame (SMEAR Eqs.
    3-9), read with one foreach_get per frame."""

    def __init__(self, armature, joint_names, frames, pose=None):
        self.armature = armature
        order = {pb.name: i for i, pb in enumerate(armature.pose.bones)}
        self.order = [order[n] for n in joint_names]
        self.world = np.empty((frames, 4, 4), np.float64)
        self.pose = np.empty((frames, len(order) * 16), np.float32)
        # The pose-only sampling reads this armature already: its buffers are these.
        self.shared = pose is not None and armature in pose.armatures
        if self.shared:
            i = pose.armatures.index(armature)
            self.world, self.pose = pose.arm_world[:, i], pose.pose[i]

    def read(self, k, dg):
        if self.shared:
            return
        ev = self.armature.evaluated_get(dg)
        self.world[k] = _matrix(ev.matrix_world)
        ev.pose.bones.foreach_get("matrix", self.pose[k])

    def matrices(self):
        frames = len(self.world)
        pose = self.pose.reshape(frames, -1, 4, 4).transpose(0, 1, 3, 2)[:, self.order]
        return (self.world[:, None] @ pose.astype(np.float64)).astype(np.float32)


def _positions(result, meshes, frames, pose, per_object):
    """The vertices of `meshes` in order, turned Y-up, into `result`: the skinning inputs
    when every mesh is pose-only (the core skins them into its scene), else both paths'
    vertices in their ranges of (frames, vertices, 3) float32."""
    import toonkit

    skinning = pose.skinning() if pose is not None else None
    if skinning is not None and len(pose.objects) == len(meshes):
        result.skinning, result.stream = skinning, pose.stream
        return
    skinned = toonkit.skin(*skinning) if skinning is not None else None
    positions = np.empty((frames, result.ranges[-1].stop, 3), np.float32)
    for o, r in zip(meshes, result.ranges):
        if o.name in per_object:
            for k, p in enumerate(per_object[o.name]):
                positions[k, r.start:r.stop] = to_y_up(p)
        else:
            r0 = pose.ranges[o.name]
            positions[:, r.start:r.stop] = skinned[:, r0.start:r0.stop]
    result._y_up = positions


def _skin_and_attributes(result, meshes, counts, groups, armature, parents, matrices):
    """SMEAR's skin (joint weights from the vertex groups named after the group armature's
    bones, object parents) and the painted vertex groups as attributes."""
    joint_names = result.bones
    joint_index = {n: i for i, n in enumerate(joint_names)}
    offset = result.ranges[-1].stop
    weights = np.zeros((offset, len(joint_names)), np.float32)
    object_parents = []
    for o, r, c in zip(meshes, result.ranges, counts):
        parent, bone = _bone_parent(o)
        object_parents.append(joint_index.get(bone, -1) if parent == armature else -1)
        if len(o.data.vertices) != c:
            continue  # a topology-changing modifier: no weights, a simple object
        skinned = armature is not None and armature_of(o) == armature
        for name, values in groups[o.name].items():
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
            "matrices": matrices,
            "weights": weights,
            "object_parents": object_parents,
        }


def to_camera(sample):
    """Positions and joint matrices in the frame the core works in: the camera's with
    camera-relative speed (SMEAR: camera space), else the Y-up world (`to_y_up`). Positions
    are None when the core is to skin them from `sample.skinning` (Y-up world only)."""
    if sample.camera is None:
        skin = None
        if sample.skin is not None:
            skin = dict(sample.skin, matrices=_rows_y_up(sample.skin["matrices"]))
        return (sample.y_up if sample.skinning is None else None), skin
    inv = affine_inverse(sample.camera)
    p = sample.positions.astype(np.float64)
    p = np.einsum("fij,fvj->fvi", inv[:, :3, :3], p) + inv[:, None, :3, 3]
    skin = None
    if sample.skin is not None:
        skin = dict(sample.skin)
        skin["matrices"] = np.einsum("fij,fkjl->fkil", inv,
                                     sample.skin["matrices"].astype(np.float64)).astype(np.float32)
    return p.astype(np.float32), skin


def _rows_y_up(m):
    """Matrices (..., 4, 4) followed by `to_y_up`: their rows signed and permuted (exact)."""
    return m[..., [0, 2, 1, 3], :] * np.array([1, 1, -1, 1], m.dtype)[:, None]


def to_y_up(points):
    """Points (..., 3) of Blender's Z-up world in the Y-up world of glTF, USD and the CLI, turned
    as the glTF exporter turns them: (x, y, z) -> (x, z, -y), a signed permutation (exact). The
    core works there, so a style's position-dependent parts (the noise preset's Voronoi cells,
    SMEAR Fig. 11d; an expression's rest position) fall on the character where the CLI puts
    them on the exported file."""
    return points[..., [0, 2, 1]] * np.array([1, 1, -1], points.dtype)


def from_y_up(points):
    """`to_y_up` undone: (x, y, z) -> (x, -z, y)."""
    return points[..., [0, 2, 1]] * np.array([1, -1, 1], points.dtype)


def from_camera(camera, points):
    """Points (frames, n, 3) from camera space back to the world."""
    c = camera.astype(np.float64)
    return (np.einsum("fij,fvj->fvi", c[:, :3, :3], points.astype(np.float64))
            + c[:, None, :3, 3]).astype(np.float32)
