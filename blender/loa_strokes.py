"""Keystrokes from Grease Pencil, seen through the active camera (LoA Section 3: the line is
drawn in the camera view).

Both Grease Pencil APIs are read: Blender 4.2's (object type `GPENCIL`: layers → frames →
strokes → points `.co`) and 4.3+'s (object type `GREASEPENCIL`: layers → frames →
`drawing.strokes` → points `.position`), in world space: the object's transform after each
layer's own location, rotation and scale (4.2's layer transform, 4.3+'s layer
`translation`/`rotation`/`scale`). Layer parents are not followed.

Every Grease Pencil keyframe is one keystroke. Several strokes on one keyframe (over all
visible layers, in layer then drawing order) are pieces of that one line, as an animator
lifting the pen mid-line means them: they are joined end to end, each piece continuing from
the end of the line so far nearest one of its own ends (the first two by their nearest pair
of ends), and the operator's report says which keyframes were joined (docs/blender.md).

The camera is the loa crate's `ActionCamera` in world space (the space of the character
handed to the loa crate): focal plane through the character's centre, image
coordinates `P x = D/z · ((x − c)·r, (x − c)·u)` (perspective) or `((x − c)·r, (x − c)·u)`
(orthographic). Keystroke points are given to the crate as screen points `(P x)_x, −(P x)_y`
with the identity screen map, so the line is exactly where the strokes are in the view.
"""

import math

from mathutils import Euler, Matrix, Vector

from . import job

GP_TYPES = ("GPENCIL", "GREASEPENCIL")


def strokes_object(context, name):
    """The Grease Pencil object named `name`, or the scene's first one."""
    if name:
        obj = context.scene.objects.get(name)
        if obj is None:
            raise job.JobError(f"no object named '{name}' in the scene")
        if obj.type not in GP_TYPES:
            raise job.JobError(f"'{name}' is a {obj.type.lower()}, not a Grease Pencil object")
        return obj
    for obj in sorted(context.scene.objects, key=lambda o: o.name):
        if obj.type in GP_TYPES:
            return obj
    raise job.JobError("no Grease Pencil object with strokes in the scene; draw the line "
                       "of action in the camera view first")


def _stroke_points(obj, stroke):
    if obj.type == "GPENCIL":
        return [Vector(p.co) for p in stroke.points]
    return [Vector(p.position) for p in stroke.points]


def _strokes(obj, frame):
    if obj.type == "GPENCIL":
        return frame.strokes
    return frame.drawing.strokes if frame.drawing is not None else ()


def _length(points):
    return sum((b - a).length for a, b in zip(points, points[1:]))


def layer_matrix(obj, layer):
    """A layer's own transform (inside the object): 4.2's `location`/`rotation`/`scale`, 4.3+'s
    `translation`/`rotation`/`scale`, composed as Blender does (T · R_xyz · S)."""
    at = layer.location if obj.type == "GPENCIL" else layer.translation
    return Matrix.LocRotScale(Vector(at), Euler(layer.rotation, "XYZ"), Vector(layer.scale))


def joined(pieces):
    """One line from the strokes of one keyframe, in drawing order: the first two by their
    nearest pair of ends, each later one from its end nearer the line's end."""
    line = list(pieces[0])
    for k, piece in enumerate(pieces[1:]):
        piece = list(piece)
        if k == 0:
            gaps = [(line[-1] - piece[0]).length, (line[-1] - piece[-1]).length,
                    (line[0] - piece[0]).length, (line[0] - piece[-1]).length]
            best = gaps.index(min(gaps))
            if best >= 2:
                line.reverse()
            if best % 2:
                piece.reverse()
        elif (line[-1] - piece[-1]).length < (line[-1] - piece[0]).length:
            piece.reverse()
        if (piece[0] - line[-1]).length == 0.0:
            piece = piece[1:]
        line += piece
    return line


def read(obj):
    """([(frame, [world points])] by frame, {frame: strokes joined}) of `obj`: one keystroke
    per keyframe, its strokes joined (`joined`) when it has several."""
    by_frame = {}
    for layer in obj.data.layers:
        if getattr(layer, "hide", False):
            continue
        to_world = obj.matrix_world @ layer_matrix(obj, layer)
        for frame in layer.frames:
            for stroke in _strokes(obj, frame):
                pts = [to_world @ p for p in _stroke_points(obj, stroke)]
                if len(pts) >= 2 and _length(pts) > 0.0:
                    by_frame.setdefault(frame.frame_number, []).append(pts)
    if not by_frame:
        raise job.JobError(f"'{obj.name}' has no stroke of two or more points")
    keys = [(f, joined(pieces)) for f, pieces in sorted(by_frame.items())]
    return keys, {f: len(p) for f, p in sorted(by_frame.items()) if len(p) > 1}


def oriented(strokes, view, first):
    """The keystrokes with their first points on the bone set's first point (LoA maps a
    stroke's start onto the chain's start): when the first keystroke's end is nearer `first`
    (world, the chain's first point in the start pose; None: unknown, strokes kept as drawn)
    in the view than its start, the user drew from the other end and every keystroke is
    reversed (one sense for all keys, so a key where the body turns over stays as drawn)."""
    if first is None:
        return strokes
    at = Vector(view.screen(first))
    pts = strokes[0][1]
    start, end = Vector(view.screen(pts[0])), Vector(view.screen(pts[-1]))
    if (end - at).length >= (start - at).length:
        return strokes
    return [(frame, list(reversed(p))) for frame, p in strokes]


class View:
    """The active camera as the loa crate's `ActionCamera`, in world space."""

    def __init__(self, camera, target):
        m = camera.matrix_world
        eye = m.translation.copy()
        self.forward = -Vector(m.col[2][:3]).normalized()
        self.right = self.forward.cross(Vector(m.col[1][:3])).normalized()
        self.up = self.right.cross(self.forward).normalized()
        depth = max((target - eye).dot(self.forward), 1e-6)
        self.center = eye + self.forward * depth
        if camera.data.type == "ORTHO":
            self.eye_distance = None
            self.half_height = 0.5 * camera.data.ortho_scale
        else:
            self.eye_distance = depth
            self.half_height = depth * math.tan(0.5 * camera.data.angle_y)

    def as_options(self):
        """`camera` and `screen` of the crate's `AnimateOptions`."""
        cam = {"center": list(self.center), "forward": list(self.forward),
               "right": list(self.right), "up": list(self.up),
               "half_height": self.half_height, "eye_distance": self.eye_distance}
        return {"camera": cam, "screen": {"anchor": [0.0, 0.0], "origin": [0.0, 0.0],
                                          "scale": 1.0}}

    def screen(self, world):
        """Screen point (x right, y down) of a world point."""
        d = world - self.center
        s = 1.0
        if self.eye_distance is not None:
            z = self.eye_distance + d.dot(self.forward)
            s = self.eye_distance / max(z, 1e-9 * self.eye_distance)
        return (s * d.dot(self.right), -s * d.dot(self.up))

    def unproject(self, x, y):
        """The world point of screen point (x, y) on the focal plane."""
        return self.center + self.right * x - self.up * y


def camera_of(context):
    cam = context.scene.camera
    if cam is None or cam.type != "CAMERA":
        raise job.JobError("the scene has no active camera; the line is drawn in its view")
    return cam
