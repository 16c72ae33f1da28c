"""Headless tests of the extension's line-of-action operator (issue 17, second half):

    python blender/tests/test_loa.py dist/toonkit-<version>-<platform>.zip [OUT_DIR]

The bundled robot in front of a perspective camera; a Grease Pencil object made by script
(Blender 4.2's Grease Pencil or 4.3+'s, whichever this Blender has) with one stroke at each of
3 frames, drawn on a plane facing the camera. `toonkit.loa_animate` must give a line (a curve
object keyed per frame) that passes through each stroke at its frame in the camera view
(within 2 % of the stroke's length) and a NEW action (the previous one kept) that brings the
robot's skeleton closer to the line than its starting pose (the importer's pose at the
scene's start frame, the character loa starts from). Keying the crate's identity motion must
reproduce that starting pose. With OUT_DIR, renders the start and frame 24.
"""

import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
os.environ.setdefault("BLENDER_USER_RESOURCES", os.path.join(
    os.environ.get("TMPDIR", "/tmp"), f"toonkit-blender-user-{os.getpid()}"))

import bpy  # noqa: E402
import numpy as np  # noqa: E402
from mathutils import Vector  # noqa: E402

from harness import ASSETS, argv_after_dashes, check, empty_scene, install, run  # noqa: E402

ARGS = argv_after_dashes()
ZIP = os.path.abspath(ARGS[0])
OUT = os.path.abspath(ARGS[1]) if len(ARGS) > 1 else None
toonkit = install(ZIP)

FOOT, TOP = 0.0, 3.55  # the robot's feet and head top at the start frame (Blender world z)


def stroke(frame, n=24):
    """A stroke from the feet up: straight at the first key, bending left, then right."""
    t = np.linspace(0.0, 1.0, n)
    z = FOOT + (TOP - FOOT) * t
    x = {1: 0.15 * t, 12: -1.6 * t ** 2, 24: 1.8 * t ** 1.5}[frame]
    return np.stack([x, np.zeros(n), z * (1.0 if frame == 1 else 0.95)], axis=1)


def robot():
    scene = empty_scene()
    scene.render.fps = 24
    scene.frame_start, scene.frame_end = 1, 30
    bpy.ops.import_scene.gltf(filepath=os.path.join(ASSETS, "RobotExpressive.glb"))
    arm = next(o for o in bpy.data.objects if o.type == "ARMATURE")
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(cam)
    cam.location = (0.4, -11.0, 2.0)
    cam.rotation_euler = (math.pi / 2, 0.0, 0.0)
    scene.camera = cam
    for o in bpy.data.objects:
        o.select_set(False)
    arm.select_set(True)
    bpy.context.view_layer.objects.active = arm
    return scene, arm, cam


def grease_pencil(scene, keys, depth=0.0):
    """A Grease Pencil object with one stroke per (frame, points), in this Blender's API."""
    data = (getattr(bpy.data, "grease_pencils_v3", None) or bpy.data.grease_pencils).new("Line")
    obj = bpy.data.objects.new("Line", data)
    scene.collection.objects.link(obj)
    layer = data.layers.new("strokes")
    for frame, pts in keys:
        fr = layer.frames.new(frame)
        pts = [(x, y + depth, z) for x, y, z in pts]
        for extra in (False, True):  # a short second stroke: the longest one is the key
            p = pts[:3] if extra else pts
            if obj.type == "GPENCIL":
                s = fr.strokes.new()
                s.points.add(len(p))
                for q, c in zip(s.points, p):
                    q.co = c
            else:
                fr.drawing.add_strokes([len(p)])
                s = fr.drawing.strokes[len(fr.drawing.strokes) - 1]
                for q, c in zip(s.points, p):
                    q.position = c
    return obj


def image(cam, points):
    """Camera image-plane coordinates (tangents) of world points."""
    m = cam.matrix_world.inverted()
    out = []
    for p in points:
        q = m @ Vector(p)
        out.append((q.x / -q.z, q.y / -q.z))
    return np.array(out)


def to_polyline(points, line):
    """Distance of each point to the polyline `line` (2D)."""
    a, b = line[:-1], line[1:]
    ab = b - a
    d = []
    for p in points:
        t = np.clip(((p - a) * ab).sum(1) / np.maximum((ab * ab).sum(1), 1e-30), 0.0, 1.0)
        d.append(np.linalg.norm(a + t[:, None] * ab - p, axis=1).min())
    return np.array(d)


def to_segments(points, a, b):
    ab = b - a
    t = np.clip(((points[:, None] - a) * ab).sum(2) / np.maximum((ab * ab).sum(1), 1e-30), 0, 1)
    return np.linalg.norm(a + t[..., None] * ab - points[:, None], axis=2).min(1)


def line_points(obj):
    return [obj.matrix_world @ Vector(p.co[:3]) for p in obj.data.splines[0].points]


def skeleton(arm):
    """World (parent head, head) segments of the evaluated pose."""
    dg = bpy.context.evaluated_depsgraph_get()
    ev = arm.evaluated_get(dg)
    a, b = [], []
    for pb in ev.pose.bones:
        if pb.parent is not None:
            a.append(ev.matrix_world @ pb.parent.head)
            b.append(ev.matrix_world @ pb.head)
    return a, b


class IdentityMotion:
    """The crate's motion shape with every joint unrotated at its reference position."""

    def __init__(self, arm, ref, names, first_frame, frames=2):
        self.joint_names = list(names)
        self.first_frame = first_frame
        j = len(names)
        self.rotations = np.tile(np.array([0.0, 0.0, 0.0, 1.0]), (frames, j, 1))
        heads = [arm.matrix_world @ ref.head(arm.data.bones[b]) if b else Vector()
                 for b in names.values()]
        self.positions = np.tile(np.array([tuple(h) for h in heads]), (frames, 1, 1))


def angle(a, b):
    """The angle between two rotations (quaternions), in [0, π]."""
    t = a.rotation_difference(b).angle
    return min(t, 2.0 * math.pi - t)


def test_loa_identity_reproduces_the_start_pose():
    from bl_ext.user_default.toonkit import loa_character

    scene, arm, cam = robot()
    ref = loa_character.Reference(scene, arm, scene.frame_start)
    rest = max(angle(arm.data.bones[n].matrix_local.to_quaternion(), m.to_quaternion())
               for n, m in ref.matrix.items())
    check(rest > 0.1, f"the starting pose is the rest pose ({rest} rad)")
    folder = os.path.join(os.environ.get("TMPDIR", "/tmp"), f"toonkit-loa-id-{os.getpid()}")
    os.makedirs(folder, exist_ok=True)
    names = loa_character.write_bvh(arm, ref, loa_character.bvh_path(folder))
    keys = loa_character.pose_keys(arm, IdentityMotion(arm, ref, names, 7), names, ref)
    loa_character.key_action(arm, keys)
    size = loa_character.center(arm, ref)[1]
    for f in (7, 8):
        scene.frame_set(f)
        ev = arm.evaluated_get(bpy.context.evaluated_depsgraph_get())
        turn = max(angle(pb.matrix.to_quaternion(), ref.matrix[pb.name].to_quaternion())
                   for pb in ev.pose.bones)
        move = max((arm.matrix_world @ pb.head - arm.matrix_world @ ref.head(pb.bone)).length
                   for pb in ev.pose.bones) / size
        print(f"  frame {f}: identity motion vs starting pose: {turn:.2e} rad, "
              f"{move:.2e} of the skeleton's size (starting pose vs rest {rest:.2f} rad)")
        check(turn < 1e-4 and move < 1e-5, f"the identity motion moves the robot: {turn}, {move}")


def test_loa_animate_follows_the_strokes():
    scene, arm, cam = robot()
    previous = arm.animation_data.action
    keys = [(f, stroke(f)) for f in (1, 12, 24)]
    gp = grease_pencil(scene, keys)
    scene.frame_set(scene.frame_start)
    start = skeleton(arm)
    if OUT:
        render(scene, os.path.join(OUT, "loa_start.png"), scene.frame_start)
    r = bpy.ops.toonkit.loa_animate()
    check(r == {"FINISHED"}, f"loa_animate returned {r}")
    action = arm.animation_data.action
    check(action is not None and action != previous, "no new action")
    check(previous.name in bpy.data.actions and previous.use_fake_user,
          "the previous action was not kept")
    line = next(o for o in bpy.data.objects if o.get("toonkit_role") == "loa line")
    check(line.type == "CURVE", f"the line is a {line.type}")
    print(f"  {gp.type}: action '{action.name}', line '{line.name}'")
    ours, rest, begin = [], [], []
    for f, pts in keys:
        scene.frame_set(f)
        drawn = image(cam, [gp.matrix_world @ Vector(p) for p in pts])
        shown = image(cam, line_points(line))
        length = float(np.linalg.norm(np.diff(drawn, axis=0), axis=1).sum())
        gap = max(to_polyline(drawn, shown).max(), to_polyline(shown, drawn).max()) / length
        print(f"  frame {f}: line to stroke {100 * gap:.2f} % of the stroke length")
        check(gap <= 0.02, f"frame {f}: the line is {100 * gap:.2f} % of the stroke away")
        a, b = skeleton(arm)
        ours.append(to_segments(shown, image(cam, a), image(cam, b)).mean() / length)
        arm.data.pose_position = "REST"
        scene.frame_set(f)
        a, b = skeleton(arm)
        rest.append(to_segments(shown, image(cam, a), image(cam, b)).mean() / length)
        arm.data.pose_position = "POSE"
        begin.append(to_segments(shown, image(cam, start[0]), image(cam, start[1])).mean()
                     / length)
        print(f"  frame {f}: line → skeleton {100 * ours[-1]:.2f} % "
              f"(starting pose {100 * begin[-1]:.2f} %, rest pose {100 * rest[-1]:.2f} %)")
    print(f"  mean distance line → skeleton: {100 * np.mean(ours):.2f} % of the stroke length "
          f"(starting pose {100 * np.mean(begin):.2f} %, rest pose {100 * np.mean(rest):.2f} %)")
    check(np.mean(ours) < 0.6 * np.mean(begin),
          f"the character does not move toward the line: {np.mean(ours)} vs {np.mean(begin)}")
    if OUT:
        render(scene, os.path.join(OUT, "loa_frame24.png"), 24)


def render(scene, path, frame):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    scene.frame_set(frame)
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.render.resolution_x, scene.render.resolution_y = 640, 480
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    print(f"  rendered {path}")


def test_loa_errors():
    scene, arm, cam = robot()
    before = (sorted(o.name for o in bpy.data.objects), sorted(a.name for a in bpy.data.actions),
              arm.animation_data.action.name)

    def fails(expect):
        try:
            bpy.ops.toonkit.loa_animate()
        except RuntimeError as e:
            check(expect in str(e) and "\n" not in str(e).strip(), f"message {e!r}")
        else:
            raise AssertionError(f"no error ({expect})")
        after = (sorted(o.name for o in bpy.data.objects),
                 sorted(a.name for a in bpy.data.actions), arm.animation_data.action.name)
        check(after == before, "the scene changed")

    fails("no Grease Pencil object")
    scene.toonkit_loa.strokes = "Camera"
    fails("not a Grease Pencil object")
    scene.toonkit_loa.strokes = ""
    grease_pencil(scene, [(1, stroke(1)), (12, stroke(12))])
    before = (sorted(o.name for o in bpy.data.objects), before[1], before[2])
    # A bone set from frame 12 on naming a bone the armature lacks: the crate's message.
    bpy.ops.toonkit.loa_bone_key_add()
    key = scene.toonkit_loa.bone_keys[0]
    key.frame, key.preset, key.joints = 12, "CUSTOM", "FootR,NoSuchBone"
    fails("RobotArmature: no joint named 'NoSuchBone'")
    bpy.ops.toonkit.loa_bone_key_remove(index=0)
    check(len(scene.toonkit_loa.bone_keys) == 0, "the bone set was not removed")
    scene.camera = None
    fails("no active camera")


if __name__ == "__main__":
    code = run([test_loa_errors, test_loa_identity_reproduces_the_start_pose,
                test_loa_animate_follows_the_strokes])
    os._exit(code)  # bpy's interpreter teardown can crash after a headless run
