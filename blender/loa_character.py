"""The armature as a loa character, and the synthesized motion back as a new Action.

The loa crate poses characters read from a skinned glTF or a BVH file. The armature is handed
over as a BVH of its pose at the scene's start frame as it is evaluated (its current action,
constraints and drivers; for a glTF import the pose the importer gives), not its rest (bind)
pose, which for imported characters often looks broken: one `ROOT`/`JOINT` per bone at its
posed head, an `End Site` at each leaf bone's posed tip, one frame of zeros, in world space
(world units, so the solver sees the character at the size the camera sees it). BVH joints
have no rest rotation, so the crate's world rotation of a joint is the bone's rotation away
from that posed reference, `D_b(t)` in armature space once the armature's own rotation `W` is
taken out (`W⁻¹ · D · W`).

With `P_b` the reference's armature-space rotation of bone b (`pose_bone.matrix`) and `R_b` its
rest rotation (`bone.matrix_local`), the new armature-space rotation is `Q_b = D_b · P_b`.
Blender composes a pose bone as `M_b = M_parent · R_parent⁻¹ · R_b · basis_b` (rotations;
translations follow the same chain), so `basis_b = R_b⁻¹ · R_parent · Q_parent⁻¹ · Q_b`, and
`basis_b = R_b⁻¹ · Q_b` for a root. A root's location moves its head to the crate's joint
position `h`: `M_root = matrix_local · basis` puts the head at `head_local + R_b · loc`, so
`loc = R_b⁻¹ · (h − head_local)`. Other bones keep the reference's location (and scale, when
it is not 1) channel, so a child's head stays where its parent carries it, as the BVH offset
does — except a bone whose head the crate moved elsewhere (an IK foot under the root, which
it attaches to the shin), whose location channel then puts its head there (`_location`).
With every `D_b` the identity the new action reproduces the reference pose.
"""

import os

import bpy
from mathutils import Matrix, Quaternion, Vector

from . import job, loa_bones

VIRTUAL_ROOT = "toonkit_loa_root"  # joins several root bones under one BVH ROOT
# The pose the crate starts from: the file's one frame, where every joint is (a BVH's rest
# pose, its OFFSETs, has the root at the origin).
POSE = "motion@0"


def _name(bone):
    name = loa_bones.bvh_name(bone.name)
    if not name or "{" in name or "}" in name:
        raise job.JobError(f"bone '{bone.name}' cannot be named in a BVH file")
    return name


def leaf_tip(armature, bone):
    """Rest tip of a leaf bone (armature space): the glTF importer's `<bone>_end` empty parented
    to it (the file's tip node, on the node's +Y), else the bone's tail. Written as the BVH's
    `End Site`, it gives the crate the bone's axis (a BVH joint has no rest orientation); the
    crate puts the tip on that axis at the parent bone's length, as for the glTF file itself
    (SPEC bones), so the CLI and the extension solve the same chain."""
    for child in armature.children:
        if (child.type == "EMPTY" and child.parent_type == "BONE"
                and child.parent_bone == bone.name and child.name.startswith(f"{bone.name}_end")):
            at_tail = bone.matrix_local @ Matrix.Translation((0.0, bone.length, 0.0))
            return (at_tail @ child.matrix_parent_inverse @ child.matrix_basis).translation
    return bone.tail_local


class Reference:
    """The evaluated pose of `armature` at `frame` (armature space): per bone its matrix,
    location and scale channels. The scene's current frame is restored."""

    def __init__(self, scene, armature, frame):
        back, sub = scene.frame_current, scene.frame_subframe
        scene.frame_set(frame)
        try:
            ev = armature.evaluated_get(bpy.context.evaluated_depsgraph_get())
            self.matrix = {pb.name: pb.matrix.copy() for pb in ev.pose.bones}
            self.location = {pb.name: pb.location.copy() for pb in ev.pose.bones}
            self.scale = {pb.name: pb.scale.copy() for pb in ev.pose.bones}
        finally:
            scene.frame_set(back, subframe=sub)

    def head(self, bone):
        return self.matrix[bone.name].translation

    def tip(self, armature, bone):
        """The posed tip of a leaf bone: its rest tip carried by the bone's pose."""
        return self.matrix[bone.name] @ bone.matrix_local.inverted() @ leaf_tip(armature, bone)


def write_bvh(armature, ref, path):
    """Writes the skeleton of `armature` posed as `ref` (a `Reference`; world space) through
    the toonkit module (`toonkit.loa.save_pose`, BVH by tkio); returns {joint: bone name}."""
    import toonkit

    bones = armature.data.bones
    if len(bones) == 0:
        raise job.JobError(f"{armature.name}: the armature has no bones")
    w = armature.matrix_world
    names, order, parents, heads = {}, [], [], []

    def add(name, parent, at):
        order.append(name)
        parents.append(parent)
        heads.append(tuple(at))
        return len(order) - 1

    def joint(bone, parent):
        n = _name(bone)
        if n in names:
            raise job.JobError(f"{armature.name}: two bones are named '{n}' in a BVH file")
        names[n] = bone.name
        k = add(n, parent, w @ ref.head(bone))
        if bone.children:
            for c in bone.children:
                joint(c, k)
        else:  # the bone's tip: the file's End Site
            add(f"{n}_end", k, w @ ref.tip(armature, bone))

    roots = [b for b in bones if b.parent is None]
    if len(roots) == 1:
        joint(roots[0], -1)
    else:
        names[VIRTUAL_ROOT] = None
        top = add(VIRTUAL_ROOT, -1, (0.0, 0.0, 0.0))
        for r in roots:
            joint(r, top)
    try:
        toonkit.loa.save_pose(path, order, parents, heads)
    except (toonkit.ToonkitError, ValueError) as e:
        raise job.JobError(f"{armature.name}: {job._one_line(e)}") from e
    return names


def pose_keys(armature, motion, names, ref):
    """[(frame, {bone: (rotation, location, scale or None)})] of the crate's motion, as deltas
    from the reference pose `ref`."""
    rotations = motion.rotations  # (frames, joints, 4) x, y, z, w
    positions = motion.positions
    index = {n: k for k, n in enumerate(motion.joint_names)}
    missing = [n for n in names if n not in index]
    if missing:
        raise job.JobError(f"the motion has no joint {missing[0]!r}")
    bones = armature.data.bones
    rest = {b.name: b.matrix_local.to_quaternion() for b in bones}
    turn = armature.matrix_world.to_quaternion()
    to_arm = armature.matrix_world.inverted()
    posed = {b.name: ref.matrix[b.name].to_quaternion() for b in bones}
    scale = {b.name: ref.scale[b.name] for b in bones
             if (ref.scale[b.name] - Vector((1.0, 1.0, 1.0))).length > 1e-6}
    tol = 1e-5 * max(b.length for b in bones)
    keys, before = [], {}
    for f in range(rotations.shape[0]):
        world = {}
        for n, bone in names.items():
            if bone is not None:
                x, y, z, w = rotations[f, index[n]]
                world[bone] = turn.inverted() @ Quaternion((w, x, y, z)) @ turn
        heads = {bone: to_arm @ Vector(positions[f, index[n]])
                 for n, bone in names.items() if bone is not None}
        q = {b.name: world[b.name] @ posed[b.name] for b in bones}  # Q_b = D_b · P_b
        pose = {}
        for b in bones:
            if b.parent is None:
                basis = rest[b.name].inverted() @ q[b.name]
                loc = rest[b.name].inverted() @ (heads[b.name] - b.head_local)
            else:
                p = b.parent.name
                basis = (rest[b.name].inverted() @ rest[p] @ q[p].inverted() @ q[b.name])
                loc = _location(b, ref, q[p], heads[p], heads[b.name], tol)
            basis.normalize()
            if b.name in before and basis.dot(before[b.name]) < 0.0:
                basis.negate()  # the same rotation, keyed without a flip between frames
            before[b.name] = basis
            pose[b.name] = (basis, loc, scale.get(b.name))
        keys.append((motion.first_frame + f, pose))
    return keys


def _location(bone, ref, turn, parent_head, head, tol):
    """The location channel of a child bone: the reference's, which keeps its head where its
    parent carries it, unless the crate moved the head elsewhere (an IK foot parented to the
    root, which the crate attaches to its shin while solving): then the channel that puts it
    there. `M_b = M_parent · R_parent⁻¹ · R_b · basis` puts the head at
    `M_parent · R_parent⁻¹ · R_b · loc`, with `M_parent` the parent's new pose (its head, its
    rotation `turn`, the reference's scale)."""
    p = bone.parent
    carry = (Matrix.LocRotScale(parent_head, turn, ref.matrix[p.name].to_scale())
             @ p.matrix_local.inverted() @ bone.matrix_local)
    loc = ref.location[bone.name]
    if (carry @ loc - head).length <= tol:
        return loc
    return carry.inverted() @ head


def key_action(armature, keys):
    """Keys `keys` into a NEW action of `armature` (the previous one kept with a fake user)."""
    ad = armature.animation_data or armature.animation_data_create()
    previous = ad.action
    if previous is not None:
        previous.use_fake_user = True
    ad.action = None
    for frame, pose in keys:
        for name, (rot, loc, scale) in pose.items():
            pb = armature.pose.bones[name]
            if pb.rotation_mode == "QUATERNION":
                pb.rotation_quaternion = rot
                pb.keyframe_insert("rotation_quaternion", frame=frame, group=name)
            elif pb.rotation_mode == "AXIS_ANGLE":
                axis, angle = rot.to_axis_angle()
                pb.rotation_axis_angle = (angle, *axis)
                pb.keyframe_insert("rotation_axis_angle", frame=frame, group=name)
            else:
                pb.rotation_euler = rot.to_euler(pb.rotation_mode, pb.rotation_euler)
                pb.keyframe_insert("rotation_euler", frame=frame, group=name)
            pb.location = loc
            pb.keyframe_insert("location", frame=frame, group=name)
            if scale is not None:
                pb.scale = scale
                pb.keyframe_insert("scale", frame=frame, group=name)
    action = ad.action
    action.name = f"{armature.name} loa"
    return action, previous


def bvh_path(folder):
    return os.path.join(folder, "character.bvh")


def center(armature, ref):
    """Centre of the bones' heads and tails posed as `ref` and the diagonal of their box
    (world)."""
    w = armature.matrix_world
    pts = []
    for b in armature.data.bones:
        m = ref.matrix[b.name]
        pts += [w @ m.translation, w @ (m @ Vector((0.0, b.length, 0.0)))]
    lo = Vector(tuple(min(p[i] for p in pts) for i in range(3)))
    hi = Vector(tuple(max(p[i] for p in pts) for i in range(3)))
    return 0.5 * (lo + hi), (hi - lo).length

