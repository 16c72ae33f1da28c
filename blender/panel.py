"""View3D ▸ Sidebar ▸ toonkit: the smear settings, bake/update/unbake, a short how-to."""

import bpy

from . import job, settings

HOW_TO = (
    "1. Select the character's meshes (or its armature)",
    "2. Bake: every frame of the scene range (or the preview range)",
    "3. Drag a value: the smear updates",
    "4. Unbake removes every trace",
)


class TOONKIT_PT_smear(bpy.types.Panel):
    bl_label = "Smear"
    bl_idname = "TOONKIT_PT_smear"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "toonkit"

    def draw(self, context):
        s = context.scene.toonkit_smear
        lay = self.layout
        row = lay.row(align=True)
        row.operator("toonkit.smear_bake", icon="RENDER_ANIMATION")
        row.operator("toonkit.smear_update", text="", icon="FILE_REFRESH")
        row.operator("toonkit.smear_unbake", text="", icon="TRASH")
        if s.last_error:
            lay.label(text=s.last_error, icon="ERROR")
        col = lay.column(align=True)
        col.prop(s, "smooth")
        col.prop(s, "camera_relative")
        box = lay.box()
        box.prop(s, "elongate")
        col = box.column(align=True)
        col.active = s.elongate
        col.prop(s, "preset", text="")
        col.prop(s, "beta_max")
        if "kappa" in settings.CORE.get(s.preset.lower(), {}).get("parameters", ()):
            col.prop(s, "kappa")
        col.row().prop(s, "sign", expand=True)
        row = col.row(align=True)
        row.prop(s, "warp")
        sub = row.row(align=True)
        sub.active = s.warp
        sub.prop(s, "warp_s")
        sub.prop(s, "warp_p")
        col.prop(s, "weight_group", icon="GROUP_VERTEX")
        box = lay.box()
        box.prop(s, "multiples")
        col = box.column(align=True)
        col.active = s.multiples
        row = col.row(align=True)
        row.prop(s, "past")
        row.prop(s, "future")
        col.prop(s, "spacing_mode", text="")
        col.prop(s, "spacing" if s.spacing_mode == "SPACING" else "overlap")
        box = lay.box()
        box.prop(s, "lines")
        col = box.column(align=True)
        col.active = s.lines
        col.prop(s, "line_count")
        col.prop(s, "line_length")
        col.prop(s, "line_thickness")
        col.prop(s, "line_gap")
        col.prop(s, "seed")
        row = lay.row()
        row.prop(s, "on_twos")
        row.prop(s, "live")
        row = lay.row(align=True)
        row.operator("toonkit.style_load", icon="FILE_FOLDER")
        row.operator("toonkit.style_save", icon="FILE_TICK")
        if not job.is_baked(context.scene):
            why = job.bake_blocker(context)
            if why:  # why the Bake button is greyed out
                lay.label(text=why[0].upper() + why[1:], icon="INFO")
            col = lay.column(align=True)
            for line in HOW_TO:
                col.label(text=line)


def register():
    bpy.utils.register_class(TOONKIT_PT_smear)


def unregister():
    bpy.utils.unregister_class(TOONKIT_PT_smear)
