"""The loa operators and panel (View3D ▸ Sidebar ▸ toonkit ▸ Line of action)."""

import bpy
from bpy.props import IntProperty

from . import job, listed, loa, loa_job, sample


def _armature(context):
    obj = context.active_object
    if obj is not None and obj.type == "MESH":
        obj = sample.armature_of(obj)
    return obj if obj is not None and obj.type == "ARMATURE" else None


def joined_note(joined):
    """` (frame 12: 2 strokes joined, …)` for keyframes whose strokes were joined into one
    keystroke (`loa_strokes.read`), else empty."""
    if not joined:
        return ""
    return " (" + ", ".join(f"frame {f}: {n} strokes joined" for f, n in joined.items()) + ")"


class TOONKIT_OT_loa_animate(bpy.types.Operator):
    """Animate the active armature along the line of action drawn with Grease Pencil in the
    camera view (one keystroke per Grease Pencil keyframe); the result is a new Action"""

    bl_idname = "toonkit.loa_animate"
    bl_label = "Animate along the line"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        arm = _armature(context)
        if arm is None:
            self.report({"ERROR"}, "loa: make an armature (or its mesh) the active object")
            return {"CANCELLED"}
        try:
            r = loa_job.animate(context, arm)
        except job.JobError as e:
            self.report({"ERROR"}, f"loa: {e}")
            return {"CANCELLED"}
        rep = r.motion.report
        self.report({"INFO"}, f"loa: action '{r.action.name}' from {len(r.keystrokes)} "
                              f"keystrokes{joined_note(r.joined)}, mean distance to the line "
                              f"{100 * rep['line_distance_mean']:.1f} % of its length")
        return {"FINISHED"}


class TOONKIT_OT_loa_bone_key_add(bpy.types.Operator):
    """Change the bone set from the current frame on"""

    bl_idname = "toonkit.loa_bone_key_add"
    bl_label = "Add bone set"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        k = context.scene.toonkit_loa.bone_keys.add()
        k.frame = context.scene.frame_current
        return {"FINISHED"}


class TOONKIT_OT_loa_bone_key_remove(bpy.types.Operator):
    """Remove a per-frame bone set"""

    bl_idname = "toonkit.loa_bone_key_remove"
    bl_label = "Remove bone set"
    bl_options = {"REGISTER", "UNDO"}

    index: IntProperty(default=-1)

    def execute(self, context):
        items = context.scene.toonkit_loa.bone_keys
        return listed.remove_item(self, items, self.index, "loa bone set")


class TOONKIT_PT_loa(bpy.types.Panel):
    bl_label = "Line of action"
    bl_idname = "TOONKIT_PT_loa"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "toonkit"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        s = context.scene.toonkit_loa
        lay = self.layout
        lay.label(text="Draw the line in the camera view, one per keyframe")
        lay.label(text="(strokes on one keyframe are joined)")
        lay.prop_search(s, "strokes", context.scene, "objects")
        lay.prop(s, "mode")
        col = lay.column(align=True)
        col.prop(s, "stiffness")
        col.prop(s, "damping")
        lay.label(text="Bones (first keystroke):")
        lay.prop(s, "bones", text="")
        if s.bones == "CUSTOM":
            lay.prop(s, "joints", text="")
        for i, k in enumerate(s.bone_keys):
            row = lay.row(align=True)
            row.prop(k, "frame", text="")
            row.prop(k, "preset", text="")
            if k.preset == "CUSTOM":
                row.prop(k, "joints", text="")
            row.operator("toonkit.loa_bone_key_remove", text="", icon="X").index = i
        lay.operator("toonkit.loa_bone_key_add", icon="ADD")
        lay.prop(s, "line_width")
        lay.operator("toonkit.loa_animate", icon="ARMATURE_DATA")
        arm = _armature(context)
        if arm is not None and arm.animation_data and arm.animation_data.action:
            lay.label(text=f"Action: {arm.animation_data.action.name}", icon="ACTION")


CLASSES = (TOONKIT_OT_loa_animate, TOONKIT_OT_loa_bone_key_add, TOONKIT_OT_loa_bone_key_remove,
           TOONKIT_PT_loa)


def register():
    loa.register()
    for c in CLASSES:
        bpy.utils.register_class(c)


def unregister():
    for c in reversed(CLASSES):
        bpy.utils.unregister_class(c)
    loa.unregister()
