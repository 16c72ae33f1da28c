"""`toonkit.loa_animate`: Grease Pencil keystrokes → dynamic line of action (LoA Eqs. 1-2) →
motion of the active armature (LoA Section 4), through the toonkit module.

Everything that can fail (reading strokes, the camera, the line, the solve) runs before the
scene is touched; then the armature gets a new Action and the line is shown as a curve object
(`<armature> line of action`, toonkit-owned) whose points are keyed at every frame.
"""

import re
import shutil
import tempfile

import bpy

from . import job, loa, loa_bones, loa_character, loa_strokes, results

ROLE = "loa line"


class Result:
    """What `animate` made: the crate's line and motion, the new and previous actions and
    the line object."""

    def __init__(self, line, motion, action, previous, curve, keystrokes, joined):
        self.line, self.motion = line, motion
        self.action, self.previous = action, previous
        self.curve, self.keystrokes = curve, keystrokes
        self.joined = joined  # {frame: strokes joined into its keystroke}


def solve(context, armature):
    """Line and motion of `armature` from the scene's strokes; the scene is not changed."""
    toonkit = job._toonkit()
    s = context.scene.toonkit_loa
    gp = loa_strokes.strokes_object(context, s.strokes)
    camera = loa_strokes.camera_of(context)
    strokes, joined = loa_strokes.read(gp)
    if len(strokes) < 1:
        raise job.JobError(f"'{gp.name}' has no keystroke")
    ref = loa_character.Reference(context.scene, armature, context.scene.frame_start)
    center, size = loa_character.center(armature, ref)
    view = loa_strokes.View(camera, center)
    bones = loa.bone_sets(s, strokes[0][0])
    fps = context.scene.render.fps / context.scene.render.fps_base
    folder = tempfile.mkdtemp(prefix="toonkit-loa-")
    path = loa_character.bvh_path(folder)
    try:
        names = loa_character.write_bvh(armature, ref, path)
        if loa_character.VIRTUAL_ROOT in names:
            bones = loa_bones.off_virtual_root(path, loa_character.POSE, bones)
        first = loa_bones.first_point(armature, ref, path, loa_character.POSE, names, s.bones,
                                      s.joints)
        strokes = loa_strokes.oriented(strokes, view, first)
        keys = [_keystroke(s, frame, [view.screen(p) for p in pts]) for frame, pts in strokes]
        line = toonkit.loa.line(keys, mode=s.mode, fps=fps)
        motion = toonkit.loa.animate(path, line, bones=bones, pose=loa_character.POSE,
                                     **view.as_options())
        pose = loa_character.pose_keys(armature, motion, names, ref)
    except (toonkit.ToonkitError, ValueError, OSError) as e:
        raise job.JobError(_message(e, path, armature, bones)) from e
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    return line, motion, pose, view, strokes, size, joined


def _keystroke(s, frame, points):
    k = {"frame": frame, "points": points}
    if s.stiffness > 0:
        k["stiffness"] = s.stiffness
    if s.damping > 0:
        k["damping"] = s.damping
    return k


def _message(e, path, armature, bones):
    """The crate's error as one line naming the armature (the character file is ours and
    temporary), a name preset on other bone names pointing to the hierarchy preset."""
    text = job._one_line(e).replace(path, armature.name)
    role = re.search(r"no (\w+) joint found for the preset", text)
    named = {p[0] for p in loa.PRESETS} - set(loa.HIERARCHY) - {"CUSTOM"}
    used = sorted({b.split("@")[0] for b in bones} & named)
    if role and used:
        hierarchy = next(p[1] for p in loa.PRESETS if p[0] == "foot-head")
        text = (f"{armature.name}: the preset '{', '.join(used)}' finds no "
                f"{role.group(1)} bone by name; choose '{hierarchy}' "
                f"or list bones ({_bone_list(armature)})")
    elif role:
        text += f" ({_bone_list(armature)})"
    return text


def _bone_list(armature, most=12):
    names = [b.name for b in armature.data.bones]
    more = f", … {len(names) - most} more" if len(names) > most else ""
    return ", ".join(names[:most]) + more


def animate(context, armature):
    """Solves, then keys the new action and shows the line; returns a `Result`."""
    line, motion, pose, view, strokes, size, joined = solve(context, armature)
    action, previous = loa_character.key_action(armature, pose)
    width = context.scene.toonkit_loa.line_width or 0.005 * size
    curve = show_line(context.scene, armature, line, view, width)
    context.scene.frame_set(context.scene.frame_current)
    return Result(line, motion, action, previous, curve, strokes, joined)


def show_line(scene, armature, line, view, width):
    """The line as a poly curve keyed at every line frame (replacing an earlier one)."""
    for old in results.owned(ROLE):
        if old[results.SOURCE] == armature.name:
            data = old.data
            bpy.data.objects.remove(old)
            if data is not None and data.users == 0:
                bpy.data.curves.remove(data)
    points = line.points  # (frames, joints, 2) screen
    data = bpy.data.curves.new(f"{armature.name} line of action", "CURVE")
    data.dimensions = "3D"
    data.bevel_depth = width
    spline = data.splines.new("POLY")
    spline.points.add(points.shape[1] - 1)
    for k, frame in enumerate(line.frames):
        for i, p in enumerate(spline.points):
            x, y = points[k, i]
            p.co = (*view.unproject(float(x), float(y)), 1.0)
            p.keyframe_insert("co", frame=frame)
    obj = bpy.data.objects.new(data.name, data)
    obj[results.ROLE], obj[results.SOURCE] = ROLE, armature.name
    results.collection(scene).objects.link(obj)
    return obj
