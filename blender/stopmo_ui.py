"""The stopmo operator and panel (View3D ▸ Sidebar ▸ toonkit ▸ Stop motion)."""

import bpy
from bpy.props import StringProperty

from . import job, stopmo


class TOONKIT_OT_stopmo_run(bpy.types.Operator):
    """Build a replacement library from the active mesh's part_<NAME> vertex groups"""

    bl_idname = "toonkit.stopmo_run"
    bl_label = "Build library"
    bl_options = {"REGISTER", "UNDO"}

    directory: StringProperty(name="Directory", default="", subtype="DIR_PATH",
                              description="Output folder (default: the panel's)")

    def execute(self, context):
        obj = context.active_object
        if obj is None or obj.type != "MESH":
            self.report({"ERROR"}, "stopmo: make a mesh the active object")
            return {"CANCELLED"}
        s = context.scene.toonkit_stopmo
        if self.directory:
            s.directory = self.directory
        try:
            lib = stopmo.run(context, obj)
        except job.JobError as e:
            self.report({"ERROR"}, f"stopmo: {e}")
            return {"CANCELLED"}
        self.report({"INFO"}, f"stopmo: {len(lib.pieces)} pieces in {s.directory}")
        return {"FINISHED"}


class TOONKIT_PT_stopmo(bpy.types.Panel):
    bl_label = "Stop motion"
    bl_idname = "TOONKIT_PT_stopmo"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "toonkit"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        s = context.scene.toonkit_stopmo
        lay = self.layout
        lay.label(text="Parts: vertex groups 'part_<NAME>'")
        lay.prop(s, "count", text="")
        lay.prop(s, {"EACH": "pieces", "BUDGET": "budget", "MAX_ERROR": "max_error_mm"}[s.count])
        col = lay.column(align=True)
        for name in ("lam", "restarts", "seed", "print_height_mm", "plugs", "directory"):
            col.prop(s, name)
        lay.operator("toonkit.stopmo_run", icon="MOD_BUILD")
        img = bpy.data.images.get("toonkit error curve")
        if img is not None:
            lay.label(text="Size vs error: image 'toonkit error curve'", icon="IMAGE_DATA")


def register():
    bpy.utils.register_class(stopmo.StopmoSettings)
    bpy.types.Scene.toonkit_stopmo = bpy.props.PointerProperty(type=stopmo.StopmoSettings)
    bpy.utils.register_class(TOONKIT_OT_stopmo_run)
    bpy.utils.register_class(TOONKIT_PT_stopmo)


def unregister():
    bpy.utils.unregister_class(TOONKIT_PT_stopmo)
    bpy.utils.unregister_class(TOONKIT_OT_stopmo_run)
    del bpy.types.Scene.toonkit_stopmo
    bpy.utils.unregister_class(stopmo.StopmoSettings)
