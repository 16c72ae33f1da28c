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


# Presets, defaults, ranges and tooltips come from the smear crate through the bundled module
# (`toonkit.smear.presets()`, `toonkit.smear.parameters()`), so the panel's "Noise" with the
# same β max and κ is the CLI's `--preset noise` and every default is the CLI's.
from toonkit import smear as _core  # noqa: E402  (the extension's wheel, installed with it)

CORE = {p["name"]: p for p in _core.presets()}
PARAMS = _core.parameters()
PRESETS = [(name.upper(), name.title(), p["doc"]) for name, p in CORE.items()] + [
    ("CUSTOM", "From file", "The style loaded from a .toml file, as written"),
]
DEFAULT_PRESET = next(name.upper() for name, p in CORE.items() if p["default"])

SIGNS = [
    ("PRESET", "Preset", "The preset's own restriction (δ− for Noise, none otherwise)"),
    ("BOTH", "δ±", "Leading parts stretch forward, trailing parts backward"),
    ("PAST", "δ−", "Trailing parts only (smear behind the motion)"),
    ("FUTURE", "δ+", "Leading parts only"),
]


def _core_prop(name, label, **kw):
    """A float or int property with the smear crate's default, range and tooltip."""
    p = PARAMS[name]
    kw.setdefault("description", p["doc"])
    if p["integer"]:
        return IntProperty(name=label, default=int(p["default"]), min=int(p["min"]),
                           soft_max=int(p["max"]), **kw)
    return FloatProperty(name=label, default=p["default"], min=p["min"], soft_max=p["max"],
                         **kw)


class SmearSettings(bpy.types.PropertyGroup):
    """Settings of the smear bake and style (SMEAR Sections 3-5)."""

    # Offsets (take effect at bake).
    smooth: _core_prop("smooth", "Smoothing")
    camera_relative: BoolProperty(
        name="Camera-relative speed", default=False,
        description="Measure motion relative to the scene camera (next bake)")

    # Elongation.
    elongate: BoolProperty(name="Elongate", default=True, update=_restyle)
    preset: EnumProperty(name="Preset", items=PRESETS, default=DEFAULT_PRESET, update=_restyle)
    beta_max: _core_prop("beta_max", "β max", update=_restyle)
    kappa: _core_prop("kappa", "κ", update=_restyle)
    sign: EnumProperty(name="Offsets", items=SIGNS, default="PRESET", update=_restyle)
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
    past: _core_prop("past", "Past", update=_restyle)
    future: _core_prop("future", "Future", update=_restyle)
    spacing_mode: EnumProperty(
        name="Spacing", default="OVERLAP", update=_restyle,
        items=[("SPACING", "Spacing", "Δf frames between copies"),
               ("OVERLAP", "Overlap", "N∩ copies overlapping between frames")])
    spacing: _core_prop("spacing", "Δf", update=_restyle)
    overlap: IntProperty(name="N∩", default=1, min=0, max=16, update=_restyle)

    # Motion lines.
    lines: BoolProperty(name="Motion lines", default=False, update=_restyle)
    line_count: _core_prop("count", "Count", update=_restyle)
    line_length: _core_prop("length_max", "Length", update=_restyle)
    line_thickness: FloatProperty(name="Thickness", default=0.0, min=0.0, soft_max=0.1,
                                  update=_restyle, precision=4,
                                  description="Tube radius in character sizes (bounding-box "
                                              "diagonals); 0 = 0.2 % of the size")
    line_gap: FloatProperty(name="Gap", default=0.0, min=0.0, soft_max=2.0, update=_restyle,
                            description="Gap to the surface, in frames along the trajectory")
    seed: _core_prop("seed", "Seed", update=_restyle)

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
