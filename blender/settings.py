"""`scene.toonkit_smear`: the smear settings the panel shows and the operators read.

Changing a style value re-stylizes the baked result from the cached offsets (live sliders);
the offset options (smoothing, camera-relative speed) only take effect at the next bake.
"""

import bpy
from bpy.props import (
    BoolProperty,
    EnumProperty,
    FloatProperty,
    IntProperty,
    StringProperty,
)


def _restyle(self, context):
    """Property update: re-stylize the baked result, if any, without re-baking."""
    if not self.live or context is None or context.scene is None:
        return
    from . import job

    if job.is_baked(context.scene):
        # A failing style leaves the last good result on screen; the panel shows the error.
        self.last_error = job.restyle(context.scene, lazy=True) or ""


PRESETS = [
    ("LINEAR", "Linear", "β = β max · δ (SMEAR Eq. 10, Fig. 11b)"),
    ("SPEED", "Speed", "β = β max · |v| · δ: fast parts stretch (Fig. 11c)"),
    ("NOISE", "Noise", "β = β max · |v| · F1(κ) · δ: a ragged smear (Fig. 11d)"),
    ("CUSTOM", "From file", "The style loaded from a .toml file, as written"),
]

SIGNS = [
    ("BOTH", "δ±", "Leading parts stretch forward, trailing parts backward"),
    ("PAST", "δ−", "Trailing parts only (smear behind the motion)"),
    ("FUTURE", "δ+", "Leading parts only"),
]


class SmearSettings(bpy.types.PropertyGroup):
    """Settings of the smear bake and style (SMEAR Sections 3-5)."""

    # Offsets (take effect at bake).
    smooth: IntProperty(name="Smoothing", default=2, min=0, max=10,
                        description="Temporal smoothing half-window N (SMEAR Eq. 2); next bake")
    camera_relative: BoolProperty(
        name="Camera-relative speed", default=False,
        description="Measure motion relative to the scene camera (next bake)")

    # Elongation.
    elongate: BoolProperty(name="Elongate", default=True, update=_restyle)
    preset: EnumProperty(name="Preset", items=PRESETS, default="SPEED", update=_restyle)
    beta_max: FloatProperty(name="β max", default=3.0, min=0.0, soft_max=30.0, update=_restyle,
                            description="Largest elongation, in frames along the trajectory")
    kappa: FloatProperty(name="κ", default=18.0, min=0.01, soft_max=100.0, update=_restyle,
                         description="Noise frequency (Voronoi F1 scale)")
    sign: EnumProperty(name="Offsets", items=SIGNS, default="BOTH", update=_restyle)
    warp: BoolProperty(name="Warp", default=False, update=_restyle,
                       description="Hise's curve on the offsets (SMEAR Fig. 12)")
    warp_s: FloatProperty(name="s", default=0.5, min=0.0, max=0.99, update=_restyle)
    warp_p: FloatProperty(name="p", default=0.8, min=0.01, max=0.99, update=_restyle)
    weight_group: StringProperty(
        name="Weight group", default="", update=_restyle,
        description="A bone (its skin weights and children) or any vertex group (painted "
                    "weights) restricting every effect; empty = everywhere")

    # Multiples.
    multiples: BoolProperty(name="Multiples", default=False, update=_restyle)
    past: IntProperty(name="Past", default=2, min=0, max=16, update=_restyle)
    future: IntProperty(name="Future", default=1, min=0, max=16, update=_restyle)
    spacing_mode: EnumProperty(
        name="Spacing", default="OVERLAP", update=_restyle,
        items=[("SPACING", "Spacing", "Δf frames between copies"),
               ("OVERLAP", "Overlap", "N∩ copies overlapping between frames")])
    spacing: FloatProperty(name="Δf", default=0.5, min=0.01, max=4.0, update=_restyle)
    overlap: IntProperty(name="N∩", default=1, min=0, max=16, update=_restyle)

    # Motion lines.
    lines: BoolProperty(name="Motion lines", default=False, update=_restyle)
    line_count: IntProperty(name="Count", default=20, min=0, max=2000, update=_restyle)
    line_length: FloatProperty(name="Length", default=10.0, min=0.0, soft_max=50.0,
                               update=_restyle, description="τ max in frames (SMEAR Eq. 13)")
    line_thickness: FloatProperty(name="Thickness", default=0.0, min=0.0, soft_max=0.1,
                                  update=_restyle, precision=4,
                                  description="Tube radius in scene units; 0 = 0.2 % of the size")
    line_gap: FloatProperty(name="Gap", default=0.0, min=0.0, soft_max=2.0, update=_restyle,
                            description="Gap to the surface, in frames along the trajectory")
    seed: IntProperty(name="Seed", default=7, min=0, update=_restyle)

    on_twos: BoolProperty(name="On twos", default=False, update=_restyle)

    # Bookkeeping.
    live: BoolProperty(name="Live update", default=True,
                       description="Re-stylize the baked result when a value changes")
    custom_style: StringProperty(name="Loaded style", default="",
                                 description="JSON of the style loaded from a .toml file")
    style_path: StringProperty(name="Style file", subtype="FILE_PATH", default="")
    last_error: StringProperty(name="Last error", default="")


def register():
    bpy.utils.register_class(SmearSettings)
    bpy.types.Scene.toonkit_smear = bpy.props.PointerProperty(type=SmearSettings)


def unregister():
    del bpy.types.Scene.toonkit_smear
    bpy.utils.unregister_class(SmearSettings)
