"""Bone sets Ω as the loa crate reads them: a preset of `toonkit.loa.BONE_SETS` (found from
bone names, or from the hierarchy for any bone names: `foot-head`, `spine-head`) or a custom
bone list, written as the BVH of `loa_character` names the bones. The crate resolves every
set on the armature handed over; its first bone is asked back (`toonkit.loa.bone_chain`) so
that a keystroke drawn from the other end is detected (`first_point`).
"""

from . import job


def bvh_name(name):
    """The BVH joint name of Blender bone `name` (`loa_character` writes whitespace as `_`)."""
    return "_".join(name.split())


def bone_set(preset, joints):
    """The CLI's SET text of a preset or of a custom bone list (Blender bone names, written
    as the BVH names them)."""
    if preset != "CUSTOM":
        return preset
    names = [j.strip() for j in joints.split(",") if j.strip()]
    return ",".join(bvh_name(n) for n in names)


def first_point(armature, ref, path, pose, names, preset, joints):
    """World position of the first point of the bone set as posed in `ref` (the head of its
    first bone), resolved by the crate on the character file `path` in `pose` that
    `loa_character` wrote (`names`: its joint → bone names); None when it starts at no bone."""
    toonkit = job._toonkit()
    chain = toonkit.loa.bone_chain(path, bone_set(preset, joints), pose=pose)
    first = names.get(chain[0]) if chain else None
    if first is None:
        return None
    return armature.matrix_world @ ref.head(armature.data.bones[first])


def off_virtual_root(path, pose, bones):
    """`bones` (`--bones` values) with a set whose chain starts at the BVH's virtual root (an
    armature of several root bones, e.g. `spine-head`) started at the real root bone after it
    instead: the virtual root sits at the world origin, no bone is there."""
    toonkit = job._toonkit()
    from .loa_character import VIRTUAL_ROOT

    out = []
    for b in bones:
        text, _, frame = b.rpartition("@")
        chain = toonkit.loa.bone_chain(path, text, pose=pose)
        if len(chain) > 2 and chain[0] == VIRTUAL_ROOT:
            text = f"{chain[1]},{chain[-1]}"
        out.append(f"{text}@{frame}")
    return out
