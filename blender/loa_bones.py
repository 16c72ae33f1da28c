"""Bone sets Ω from the armature itself, for armatures the CLI's name presets do not fit
(e.g. CesiumMan's `leg_joint_R_5`, `torso_joint_2`, `neck_joint_2`).

Two presets read the hierarchy and the pose loa starts from (world Z up, Blender's
convention), not bone names:

- `foot-head` ("Foot to head"): a foot → up the hierarchy → the leaf bone whose tip is
  highest (the head). The foot is the lowest leaf among those branching off that head's
  chain nearest its root (legs branch at the hips, arms higher up, so long hanging arms are
  not taken for legs): for a standing humanoid a foot, its leg, the spine and the head (what
  `right-leg-spine-head` finds by name);
- `spine-head` ("Spine and head"): the root bone → the highest leaf bone.

Both resolve to the crate's explicit joint lists (BVH joint names, see `loa_character`). The
first bone of a resolved chain is known here, so a keystroke drawn from the other end is
detected (`first_point`).
"""

from . import job

# (identifier, label, description) of the hierarchy presets, after the CLI's name presets.
PRESETS = [
    ("foot-head", "Foot to head (hierarchy)",
     "Lowest leg-like leaf bone → hierarchy → highest leaf bone: found from the armature's "
     "hierarchy and its pose, for any bone names"),
    ("spine-head", "Spine and head (hierarchy)",
     "Root bone → hierarchy → highest leaf bone, for any bone names"),
]
NAMES = tuple(p[0] for p in PRESETS)


def bvh_name(name):
    """The BVH joint name of Blender bone `name` (`loa_character` writes whitespace as `_`)."""
    return "_".join(name.split())


def _leaves(armature):
    return [b for b in armature.data.bones if not b.children]


def _ancestry(bone):
    """`bone` and its ancestors up to its root."""
    out = [bone]
    while out[-1].parent is not None:
        out.append(out[-1].parent)
    return out


def _foot(leaves, top, height):
    """The foot: among the leaves that branch off the spine (root → `top`) nearest the root
    (legs branch at the hips, arms higher up; a leaf of another root counts as branching at
    the root), the lowest. Hanging arms reaching below the feet do not count."""
    spine = {b.name: k for k, b in enumerate(reversed(_ancestry(top)))}

    def branch(leaf):
        return next((spine[b.name] for b in _ancestry(leaf) if b.name in spine), 0)

    others = [b for b in leaves if b != top]
    if not others:
        return top
    first = min(branch(b) for b in others)
    return min((b for b in others if branch(b) == first),
               key=lambda b: (height[b.name], b.name))


def waypoints(armature, ref, preset):
    """Bone names (Blender) along which `preset` runs on `armature` posed as `ref`."""
    w = armature.matrix_world
    leaves = _leaves(armature)
    if not leaves:
        raise job.JobError(f"{armature.name}: the armature has no bones")
    height = {b.name: (w @ ref.tip(armature, b)).z for b in leaves}
    top = max(leaves, key=lambda b: (height[b.name], b.name))
    if preset == "foot-head":
        start = _foot(leaves, top, height)
    else:
        start = _ancestry(top)[-1]
    if start == top:
        raise job.JobError(f"{armature.name}: the '{preset}' bone set needs two bones on a "
                           f"chain; list the bones instead")
    return [start.name, top.name]


def bone_set(armature, ref, preset, joints):
    """The CLI's SET text of a preset (name or hierarchy) or a custom bone list (Blender bone
    names, written as the BVH names them)."""
    if preset in NAMES:
        return ",".join(bvh_name(n) for n in waypoints(armature, ref, preset))
    if preset != "CUSTOM":
        return preset
    names = [j.strip() for j in joints.split(",") if j.strip()]
    return ",".join(bvh_name(n) for n in names)


def first_point(armature, ref, preset, joints):
    """World position of the first point of the bone set as posed in `ref` (the head of its
    first bone), or None for the CLI's name presets (resolved in the crate)."""
    if preset in NAMES:
        first = waypoints(armature, ref, preset)[0]
    elif preset == "CUSTOM":
        names = [j.strip() for j in joints.split(",") if j.strip()]
        bones = {bvh_name(b.name): b.name for b in armature.data.bones}
        first = bones.get(bvh_name(names[0])) if names else None
        if first is None:
            return None
    else:
        return None
    return armature.matrix_world @ ref.head(armature.data.bones[first])
