"""The stopmo operator and panel (View3D ▸ Sidebar ▸ toonkit ▸ Stop motion)."""

import bpy
from bpy.props import IntProperty, StringProperty

from . import job, listed, stopmo


class TOONKIT_OT_stopmo_run(bpy.types.Operator):
    """Build a replacement library from the active mesh's part_<NAME> vertex groups (or the
    3D-cursor seeds)"""

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
        for warning in lib.report.get("warnings", []):
            self.report({"WARNING"}, f"stopmo: {warning}")
        self.report({"INFO"}, f"stopmo: {len(lib.pieces)} pieces in {s.directory}")
        return {"FINISHED"}


class TOONKIT_OT_stopmo_add_seed(bpy.types.Operator):
    """Add the 3D cursor's location as a seed point of a part"""

    bl_idname = "toonkit.stopmo_add_seed"
    bl_label = "Add cursor seed"
    bl_options = {"REGISTER", "UNDO"}

    part: StringProperty(name="Part", default="",
                         description="Part name (default: the panel's)")

    def execute(self, context):
        s = context.scene.toonkit_stopmo
        name = (self.part or s.seed_part).strip()
        if not name:
            self.report({"ERROR"}, "stopmo seed: name the part first")
            return {"CANCELLED"}
        seed = s.seeds.add()
        seed.part = name
        seed.location = context.scene.cursor.location
        return {"FINISHED"}


class TOONKIT_OT_stopmo_remove_seed(bpy.types.Operator):
    """Remove a 3D-cursor seed"""

    bl_idname = "toonkit.stopmo_remove_seed"
    bl_label = "Remove seed"
    bl_options = {"REGISTER", "UNDO"}

    index: IntProperty(name="Index", default=-1, description="Seed index (-1: the last)")

    def execute(self, context):
        items = context.scene.toonkit_stopmo.seeds
        return listed.remove_item(self, items, self.index, "stopmo seed")


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
        lay.label(text="or seeds at the 3D cursor:")
        row = lay.row(align=True)
        row.prop(s, "seed_part", text="")
        row.operator("toonkit.stopmo_add_seed", text="", icon="ADD")
        for i, seed in enumerate(s.seeds):
            row = lay.row(align=True)
            x, y, z = seed.location
            row.label(text=f"{seed.part}: {x:.3g}, {y:.3g}, {z:.3g}", icon="PIVOT_CURSOR")
            row.operator("toonkit.stopmo_remove_seed", text="", icon="X").index = i
        lay.prop(s, "count", text="")
        lay.prop(s, {"EACH": "pieces", "BUDGET": "budget", "MAX_ERROR": "max_error_mm"}[s.count])
        col = lay.column(align=True)
        for name in ("lam", "restarts", "seed", "print_height_mm", "print_solids", "thickness_mm",
                     "plugs", "magnets"):
            col.prop(s, name)
        if s.magnets:
            row = col.row(align=True)
            row.prop(s, "magnet_diameter_mm", text="D")
            row.prop(s, "magnet_height_mm", text="H")
        for name in ("clearance_mm", "print_format", "plate_mm", "min_wall_mm", "min_feature_mm",
                     "directory"):
            col.prop(s, name)
        lay.operator("toonkit.stopmo_run", icon="MOD_BUILD")
        img = bpy.data.images.get("toonkit error curve")
        if img is not None:
            lay.label(text="Size vs error: image 'toonkit error curve'", icon="IMAGE_DATA")


CLASSES = (TOONKIT_OT_stopmo_run, TOONKIT_OT_stopmo_add_seed, TOONKIT_OT_stopmo_remove_seed,
           TOONKIT_PT_stopmo)


def register():
    bpy.utils.register_class(stopmo.StopmoSeed)
    bpy.utils.register_class(stopmo.StopmoSettings)
    bpy.types.Scene.toonkit_stopmo = bpy.props.PointerProperty(type=stopmo.StopmoSettings)
    for c in CLASSES:
        bpy.utils.register_class(c)


def unregister():
    for c in reversed(CLASSES):
        bpy.utils.unregister_class(c)
    del bpy.types.Scene.toonkit_stopmo
    bpy.utils.unregister_class(stopmo.StopmoSettings)
    bpy.utils.unregister_class(stopmo.StopmoSeed)
