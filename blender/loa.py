"""`scene.toonkit_loa`: the settings of `toonkit.loa_animate` (dynamic lines of action, Guay
et al. SBIM 2015).

Keystrokes are the strokes of a Grease Pencil object (`strokes`; empty = the first Grease
Pencil object of the scene) drawn in the active camera's view, one keystroke per Grease Pencil
keyframe. The bone set Ω(t_k) of the first keystroke is `bones`; `bone_keys` change it from a
keystroke frame on (LoA Section 4: the set may change per keystroke), as the CLI's
`--bones SET@FRAME` values.
"""

import bpy
from bpy.props import (CollectionProperty, EnumProperty, FloatProperty, IntProperty,
                       StringProperty)

from toonkit import loa as _core  # noqa: E402  (the extension's wheel, installed with it)

from . import loa_bones

# The bone-set presets, defined once in the loa crate (`toonkit.loa.BONE_SETS`): found from
# humanoid bone names (the CLI's `--bones NAME`) or from the hierarchy (`foot-head`,
# `spine-head`, for any bone names); then a custom bone list.
PRESETS = [
    *(tuple(p) for p in _core.BONE_SETS),
    ("CUSTOM", "Bones…", "A comma-separated list of bones along the line (e.g. FootR,Head)"),
]
HIERARCHY = ("foot-head", "spine-head")  # presets that read no bone names
# The documented slider ranges, defined once in the loa crate; a value outside is refused by
# the core with a message naming the range (reported by the operator).
STIFFNESS = _core.STIFFNESS_RANGE
DAMPING = _core.DAMPING_RANGE

MODES = [
    ("physics", "Physics", "An elastic chain re-targeted onto every keystroke (LoA Eqs. 1-2)"),
    ("hermite", "Hermite", "Hermite interpolation between the keystrokes"),
]


class LoaBoneKey(bpy.types.PropertyGroup):
    """A bone set Ω from a keystroke frame on."""

    frame: IntProperty(name="Frame", default=1)
    preset: EnumProperty(name="Bones", items=PRESETS, default="right-leg-spine-head")
    joints: StringProperty(name="Bone list", default="",
                           description="Comma-separated bones (when the set is 'Bones…')")


class LoaSettings(bpy.types.PropertyGroup):
    """Settings of `toonkit.loa_animate` (LoA Sections 3-4)."""

    strokes: StringProperty(name="Strokes", default="",
                            description="Grease Pencil object with the keystrokes "
                                        "(empty: the first Grease Pencil object)")
    bones: EnumProperty(name="Bones", items=PRESETS, default="right-leg-spine-head",
                        description="Bone set of the first keystroke")
    joints: StringProperty(name="Bone list", default="",
                           description="Comma-separated bones (when the set is 'Bones…')")
    bone_keys: CollectionProperty(type=LoaBoneKey, name="Bone sets per frame")
    mode: EnumProperty(name="Line", items=MODES, default="physics")
    stiffness: FloatProperty(name="Stiffness", default=0.0, min=0.0, max=STIFFNESS[1],
                             description="Spring stiffness of every keystroke, "
                                         f"{STIFFNESS[0]:g} to {STIFFNESS[1]:g} "
                                         "(0: the default)")
    damping: FloatProperty(name="Damping", default=0.0, min=0.0, max=DAMPING[1],
                           description="Damping ratio of every keystroke, "
                                       f"{DAMPING[0]:g} to {DAMPING[1]:g} (0: the default)")
    line_width: FloatProperty(name="Line width", default=0.0, min=0.0, precision=4,
                              description="Bevel of the line curve; 0 = 0.5 % of the height")


def bone_sets(s, first_frame):
    """The `--bones` values: the first set at `first_frame`, then the per-frame ones."""
    out = [f"{loa_bones.bone_set(s.bones, s.joints)}@{first_frame}"]
    for k in sorted(s.bone_keys, key=lambda k: k.frame):
        out.append(f"{loa_bones.bone_set(k.preset, k.joints)}@{k.frame}")
    return out


CLASSES = (LoaBoneKey, LoaSettings)


def register():
    for c in CLASSES:
        bpy.utils.register_class(c)
    bpy.types.Scene.toonkit_loa = bpy.props.PointerProperty(type=LoaSettings)


def unregister():
    del bpy.types.Scene.toonkit_loa
    for c in reversed(CLASSES):
        bpy.utils.unregister_class(c)
