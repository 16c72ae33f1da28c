"""The smear operators (names fixed: tests and scripts call them). Each reports a failure in
one line with `self.report({'ERROR'}, ...)` and leaves the scene as it was."""

import bpy
from bpy.app.handlers import persistent
from bpy.props import StringProperty
from bpy_extras.io_utils import ExportHelper, ImportHelper

from . import job, sample, style


class TOONKIT_OT_smear_bake(bpy.types.Operator):
    """Sample the selected meshes over the scene range and show their smear"""

    bl_idname = "toonkit.smear_bake"
    bl_label = "Bake smear"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        why = job.bake_blocker(context)
        if why:
            cls.poll_message_set(why)  # the greyed-out button's tooltip says why
        return why is None

    def execute(self, context):
        objects = job.sources(context)
        if not objects:
            self.report({"ERROR"}, "smear bake: select at least one mesh object")
            return {"CANCELLED"}
        try:
            look = job.bake(context, objects)
        except job.JobError as e:
            self.report({"ERROR"}, f"smear bake: {e}")
            return {"CANCELLED"}
        r = look.report
        start, end, _ = sample.bake_range(context.scene)
        self.report({"INFO"}, f"smear: {len(r['objects'])} object(s), frames {start}-{end}")
        return {"FINISHED"}


class TOONKIT_OT_smear_update(bpy.types.Operator):
    """Re-stylize the baked smear from the cached offsets (no re-bake)"""

    bl_idname = "toonkit.smear_update"
    bl_label = "Update smear"
    # No undo step of its own: a restyle is derived from the settings (whose edits are
    # undoable), and an undo push copies the whole .blend (~50 ms on the robot).
    bl_options = {"REGISTER"}

    def execute(self, context):
        if not job.is_baked(context.scene):
            self.report({"ERROR"}, "smear update: nothing is baked; bake first")
            return {"CANCELLED"}
        error = job.restyle(context.scene)
        context.scene.toonkit_smear.last_error = error or ""
        if error:
            self.report({"ERROR"}, f"smear update: {error}")
            return {"CANCELLED"}
        return {"FINISHED"}


class TOONKIT_OT_smear_unbake(bpy.types.Operator):
    """Remove every toonkit result and show the original objects again"""

    bl_idname = "toonkit.smear_unbake"
    bl_label = "Unbake smear"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        job.unbake(context.scene)
        return {"FINISHED"}


class TOONKIT_OT_style_load(bpy.types.Operator, ImportHelper):
    """Load a style .toml (the CLI's --style format) into the panel"""

    bl_idname = "toonkit.style_load"
    bl_label = "Load style"
    filename_ext = ".toml"
    filter_glob: StringProperty(default="*.toml", options={"HIDDEN"})

    def execute(self, context):
        s = context.scene.toonkit_smear
        try:
            loaded = style.read(self.filepath)
        except (OSError, ValueError) as e:
            self.report({"ERROR"}, f"{self.filepath}: {' '.join(str(e).split())}")
            return {"CANCELLED"}
        fits = style.to_settings(loaded, s)
        s.style_path = self.filepath
        if not fits:
            self.report({"INFO"}, "style kept as written (preset: From file)")
        if job.is_baked(context.scene):
            return bpy.ops.toonkit.smear_update()
        return {"FINISHED"}


class TOONKIT_OT_style_save(bpy.types.Operator, ExportHelper):
    """Save the panel's style as a .toml for `toonkit smear --style`"""

    bl_idname = "toonkit.style_save"
    bl_label = "Save style"
    filename_ext = ".toml"
    filter_glob: StringProperty(default="*.toml", options={"HIDDEN"})

    def execute(self, context):
        s = context.scene.toonkit_smear
        cached = job.cached(context.scene)
        bones = cached[0].bones if cached else ()
        try:
            style.write(self.filepath, style.from_settings(s, bones))
        except (OSError, ValueError) as e:
            self.report({"ERROR"}, f"{self.filepath}: {' '.join(str(e).split())}")
            return {"CANCELLED"}
        s.style_path = self.filepath
        return {"FINISHED"}


CLASSES = (TOONKIT_OT_smear_bake, TOONKIT_OT_smear_update, TOONKIT_OT_smear_unbake,
           TOONKIT_OT_style_load, TOONKIT_OT_style_save)


@persistent
def _frame_changed(scene, *args):
    job.write_pending(scene)  # a live restyle's frame, as the scene reaches it


@persistent
def _write_all(*args):
    job.write_all_pending()


@persistent
def _undone(*args):
    job.after_undo()


@persistent
def _loading(*args):
    job.forget()  # the next file's scenes may share these scene names


HANDLERS = (("frame_change_pre", _frame_changed), ("save_pre", _write_all),
            ("render_init", _write_all), ("undo_post", _undone), ("redo_post", _undone),
            ("load_pre", _loading))


def register():
    for c in CLASSES:
        bpy.utils.register_class(c)
    for name, handler in HANDLERS:
        getattr(bpy.app.handlers, name).append(handler)


def unregister():
    job.cancel_flush()
    job.write_all_pending()
    for name, handler in HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if handler in handlers:
            handlers.remove(handler)
    for c in reversed(CLASSES):
        bpy.utils.unregister_class(c)
