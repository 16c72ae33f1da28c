"""What the loa tests share: a Grease Pencil object made by script (Blender 4.2's API or
4.3+'s), a camera fitted to an armature, keystrokes drawn to an armature's size in a camera's
view, and `follows`: run `toonkit.loa_animate` and measure the line against the strokes and the
skeleton against the line, in the camera's image plane, for any armature, camera and strokes.
"""

import math
import os

import bpy
import numpy as np
from mathutils import Euler, Matrix, Vector

from harness import check


def grease_pencil(scene, keys, depth=0.0, layer_matrix=None):
    """A Grease Pencil object with one stroke per (frame, world points) — or several, for a
    (frame, [points, points, …]) — in this Blender's API. With `layer_matrix` (a layer
    transform of location, rotation and scale) the layer carries it and the points are stored
    in the layer's space, so that they land on the given world points."""
    # 4.3-4.5 keep the legacy `grease_pencils` (annotations) beside `grease_pencils_v3`; an
    # empty collection is falsy, so test for the attribute, not its truth.
    v3 = getattr(bpy.data, "grease_pencils_v3", None)
    data = (v3 if v3 is not None else bpy.data.grease_pencils).new("Line")
    obj = bpy.data.objects.new("Line", data)
    scene.collection.objects.link(obj)
    layer = data.layers.new("strokes")
    inside = Matrix.Identity(4)
    if layer_matrix is not None:
        at, turn, size = layer_matrix.decompose()
        if obj.type == "GPENCIL":
            layer.location = at
        else:
            layer.translation = at
        layer.rotation = turn.to_euler("XYZ")
        layer.scale = size
        inside = layer_matrix.inverted()
    for frame, pts in keys:
        fr = layer.frames.new(frame)
        pieces = pts if isinstance(pts, list) and np.ndim(pts[0]) == 2 else [pts]
        for piece in pieces:
            p = [tuple(inside @ Vector((x, y + depth, z))) for x, y, z in piece]
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
    ev = arm.evaluated_get(bpy.context.evaluated_depsgraph_get())
    a, b = [], []
    for pb in ev.pose.bones:
        if pb.parent is not None:
            a.append(ev.matrix_world @ pb.parent.head)
            b.append(ev.matrix_world @ pb.head)
    return a, b


def bone_points(arm):
    """World heads and tails of the evaluated pose."""
    ev = arm.evaluated_get(bpy.context.evaluated_depsgraph_get())
    return ([ev.matrix_world @ pb.head for pb in ev.pose.bones]
            + [ev.matrix_world @ pb.tail for pb in ev.pose.bones])


def fitted_camera(scene, arm, yaw_deg=0.0, margin=1.8):
    """A perspective camera looking horizontally at the armature's box (start frame), turned
    `yaw_deg` about Z, far enough that the box's height fills 1/`margin` of the view."""
    scene.frame_set(scene.frame_start)
    pts = bone_points(arm)
    lo = Vector([min(p[i] for p in pts) for i in range(3)])
    hi = Vector([max(p[i] for p in pts) for i in range(3)])
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(cam)
    turn = Euler((math.pi / 2, 0.0, math.radians(yaw_deg)))
    cam.rotation_euler = turn
    ahead = turn.to_matrix() @ Vector((0.0, 0.0, -1.0))
    size = max(hi.z - lo.z, (hi - lo).xy.length)
    far = 0.5 * margin * size / math.tan(0.5 * cam.data.angle_y)
    cam.location = 0.5 * (lo + hi) - far * ahead
    scene.camera = cam
    return cam


def drawn_strokes(scene, arm, cam, frames, n=24, reverse=False, ends=None):
    """Keystrokes drawn to the armature's size in `cam`'s view: from the skeleton's lowest
    point up to its highest (start frame), projected onto the camera-facing plane through its
    centre; straight at the first frame, bending to one side (45 % of the height), then to the
    other (50 %), as the robot's strokes. `reverse`: drawn from the top down. `ends`: from and
    to these world points instead."""
    scene.frame_set(scene.frame_start)
    pts = bone_points(arm)
    m = cam.matrix_world
    eye = m.translation
    ahead = -Vector(m.col[2][:3]).normalized()
    mid = sum(pts, Vector()) / len(pts)
    depth = (mid - eye).dot(ahead)

    def on_plane(p):
        d = p - eye
        return eye + d * (depth / d.dot(ahead))

    low, high = ends or (min(pts, key=lambda p: p.z), max(pts, key=lambda p: p.z))
    foot, top = on_plane(low), on_plane(high)
    along = top - foot
    side = along.cross(ahead).normalized() * along.length
    t = np.linspace(0.0, 1.0, n)
    bends = [0.04 * t, -0.45 * t ** 2, 0.5 * t ** 1.5]
    keys = []
    for k, f in enumerate(frames):
        up = 1.0 if k == 0 else 0.95
        line = [foot + along * (up * a) + side * float(b) for a, b in zip(t, bends[k % 3])]
        if reverse:
            line.reverse()
        keys.append((f, [tuple(p) for p in line]))
    return keys


def follows(scene, arm, cam, keys, out=None, name="loa", layer_matrix=None):
    """Runs `toonkit.loa_animate` on `arm` with strokes `keys` [(frame, world points)] seen
    by `cam` and checks the acceptance figures: the line passes through each stroke at its
    frame (≤ 2 % of the stroke's length, image plane) and the skeleton's mean distance to the
    line is below 0.6× the starting pose's. Returns (gaps, mean, mean of the start pose)."""
    previous = arm.animation_data.action if arm.animation_data else None
    gp = grease_pencil(scene, keys, layer_matrix=layer_matrix)
    scene.frame_set(scene.frame_start)
    start = skeleton(arm)
    if out:
        render(scene, os.path.join(out, f"{name}_start.png"), scene.frame_start)
    r = bpy.ops.toonkit.loa_animate()
    check(r == {"FINISHED"}, f"loa_animate returned {r}")
    action = arm.animation_data.action
    check(action is not None and action != previous, "no new action")
    check(previous is None or (previous.name in bpy.data.actions and previous.use_fake_user),
          "the previous action was not kept")
    line = next(o for o in bpy.data.objects if o.get("toonkit_role") == "loa line")
    check(line.type == "CURVE", f"the line is a {line.type}")
    print(f"  {gp.type}: action '{action.name}', line '{line.name}'")
    gaps, ours, rest, begin = [], [], [], []
    for f, pts in keys:
        scene.frame_set(f)
        drawn = image(cam, [gp.matrix_world @ Vector(p) for p in pts])
        shown = image(cam, line_points(line))
        length = float(np.linalg.norm(np.diff(drawn, axis=0), axis=1).sum())
        gap = max(to_polyline(drawn, shown).max(), to_polyline(shown, drawn).max()) / length
        gaps.append(gap)
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
    if out:
        render(scene, os.path.join(out, f"{name}_frame{keys[-1][0]}.png"), keys[-1][0])
    return gaps, float(np.mean(ours)), float(np.mean(begin))


def render(scene, path, frame):
    """A workbench render of `frame`: the line red and seen through the body (X-ray)."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    scene.frame_set(frame)
    scene.render.engine = "BLENDER_WORKBENCH"
    shading = scene.display.shading
    shading.color_type, shading.show_xray, shading.xray_alpha = "OBJECT", True, 0.6
    for o in bpy.data.objects:
        o.color = (0.85, 0.1, 0.1, 1.0) if o.get("toonkit_role") == "loa line" else (
            0.7, 0.7, 0.7, 1.0)
    scene.render.resolution_x, scene.render.resolution_y = 640, 480
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    print(f"  rendered {path}")
