"""Bake, restyle and unbake: Blender's evaluated animation through `toonkit.smear`.

The prepared offsets stay in memory per scene, so a restyle is one `toonkit.smear.stylize`
plus attribute writes. After reopening a .blend the first restyle samples again.
"""

import json
import time

import numpy as np

from . import results, sample, style

_CACHE = {}  # scene name -> (Sample, toonkit Prepared)
_PENDING = {}  # scene name -> _Pending: frames of the last live restyle not written yet


class JobError(Exception):
    """One line for the operator's error report."""


def _toonkit():
    try:
        import toonkit
    except ImportError as e:  # the wheel did not install
        raise JobError(f"the toonkit module is missing ({e}); reinstall the extension") from e
    return toonkit


def _one_line(e):
    return " ".join(str(e).split()) or type(e).__name__


def is_baked(scene):
    return bool(results.owned("body"))


def sources(context):
    """The originals to bake: selected meshes (a selected armature brings its child meshes),
    with toonkit results standing for their originals."""
    import bpy

    names = []
    for o in context.selected_objects:
        if o.type == "ARMATURE":  # a selected rig stands for its meshes
            names += [c.name for c in o.children_recursive
                      if c.type == "MESH" and results.ROLE not in c and c.name not in names]
            continue
        name = o.get(results.SOURCE, o.name) if results.ROLE in o else o.name
        if name not in names:
            names.append(name)
    objs = [bpy.data.objects[n] for n in names if n in bpy.data.objects]
    return [o for o in objs if o.type == "MESH"]


def bake_blocker(context):
    """Why the bake cannot run now (one line for the panel and the greyed-out button), or
    None."""
    if not sources(context):
        picked = context.selected_objects
        what = (f"{picked[0].name} is a {picked[0].type.lower()}: " if picked else "")
        return what + "select at least one mesh object (or its armature)"
    scene = context.scene
    if scene.frame_end <= scene.frame_start:
        return (f"the scene range {scene.frame_start}-{scene.frame_end} needs at least two "
                "frames")
    return None


def _moves(s):
    """Whether any vertex of the sample moves over its frames (no copy of the frames)."""
    first = s.positions[0]
    return any(not np.array_equal(first, p) for p in s.positions[1:])


def _prepare(context, objects, settings):
    toonkit = _toonkit()
    shown = []
    try:
        for o in objects:  # hidden originals (a re-bake) must be evaluated
            if o.hide_get() or o.hide_viewport:
                shown.append((o, o.hide_get(), o.hide_viewport))
                o.hide_viewport = False
                o.hide_set(False)
        s = sample.sample(context, objects, settings.camera_relative)
    except sample.SampleError as e:
        raise JobError(str(e)) from e
    finally:
        for o, hidden, vp in shown:
            o.hide_viewport = vp
            o.hide_set(hidden)
    if not _moves(s) and s.camera is None:
        names = ", ".join(s.names[:3]) + (" …" if len(s.names) > 3 else "")
        raise JobError(f"{names}: does not move over frames {s.frame_start}-"
                       f"{s.frame_start + len(s.positions) - 1}, nothing to smear; animate it "
                       "or set the scene range to where it moves")
    positions, skin = (sample.to_camera(s) if s.camera is not None
                       else (s.positions, s.skin))
    try:
        scene = toonkit.Scene.from_arrays(positions, s.triangles, fps=s.fps, skin=skin,
                                          objects=s.objects, attributes=s.attributes,
                                          rest=s.rest)
        prepared = toonkit.smear.prepare(scene, smooth=settings.smooth)
    except (toonkit.ToonkitError, ValueError) as e:
        raise JobError(_one_line(e)) from e
    return s, prepared


def _stylize(s, prepared, settings):
    toonkit = _toonkit()
    try:
        return toonkit.smear.stylize(prepared, style.from_settings(settings, s.bones))
    except (toonkit.ToonkitError, ValueError, json.JSONDecodeError) as e:
        raise JobError(_one_line(e)) from e


def _world(s, points):
    return sample.from_camera(s.camera, points) if s.camera is not None else points


class _Pending:
    """The frames of a live restyle still to write: (mesh name, positions, alpha) per result
    object, written one frame at a time as the scene reaches it (docs/blender.md, "Speed")."""

    def __init__(self, start, writes):
        self.start, self.writes = start, writes
        self.frames = set(range(len(writes[0][1]))) if writes else set()

    def write(self, frames):
        import bpy

        frames = [k for k in frames if k in self.frames]
        for name, positions, alpha in self.writes if frames else ():
            mesh = bpy.data.meshes.get(name)
            if mesh is not None:
                results.write_frames(mesh, self.start, positions, alpha, frames)
        self.frames.difference_update(frames)

    def write_current(self, scene):
        n = len(self.writes[0][1]) if self.writes else 0
        self.write([min(max(scene.frame_current - self.start, 0), n - 1)] if n else [])


def write_pending(scene, frame_only=True):
    """Writes the pending frames of `scene`'s last live restyle: the current frame, or all."""
    p = _PENDING.get(scene.name)
    if p is None:
        return
    if frame_only:
        p.write_current(scene)
    else:
        p.write(sorted(p.frames))
    if not p.frames:
        _PENDING.pop(scene.name, None)


def _show(scene, s, look, lazy=False):
    """Creates or updates the result objects of `look` (elongation, copies, lines). `lazy`
    writes the current frame only and leaves the others pending (`write_pending`)."""
    import bpy

    _PENDING.pop(scene.name, None)
    writes = []
    start, end = s.frame_start, s.frame_start + len(s.positions) - 1
    elongated = _world(s, look.elongated)
    bodies = {o[results.SOURCE]: o for o in results.owned("body")}
    for name, r in s.objects:
        body = bodies.get(name)
        if body is None:
            original = bpy.data.objects[name]
            dg = bpy.context.evaluated_depsgraph_get()
            mesh = bpy.data.meshes.new_from_object(original.evaluated_get(dg))
            mesh.name = f"{name} smear"
            body = results.make_body(scene, original, mesh, start, end)
            bodies[name] = body
        writes.append((body.data, elongated[:, r.start:r.stop], None))
        results.set_range(body, start, end)

    wanted = {}
    for i, c in enumerate(look.multiples):
        source = s.names[c["object"]]
        k = sum(1 for key in wanted if key[0] == source)
        wanted[(source, k)] = c
    copies = {(o[results.SOURCE], int(o.get("toonkit_index", 0))): o
              for o in results.owned("multiple")}
    for key, obj in copies.items():
        if key not in wanted:
            results.remove(obj)
    for key, c in wanted.items():
        obj = copies.get(key)
        if obj is None:
            obj = results.make_copy(scene, bodies[key[0]], key[1], start, end)
            obj["toonkit_index"] = key[1]
        writes.append((obj.data, _world(s, c["positions"]), c["alpha"]))
        results.set_range(obj, start, end)

    lines = {s.names[ln["object"]]: ln for ln in look.lines}
    for obj in results.owned("lines"):
        if obj[results.SOURCE] not in lines:
            results.remove(obj)
    have = {o[results.SOURCE]: o for o in results.owned("lines")}
    for source, ln in lines.items():
        obj = have.get(source) or results.make_lines(scene, source, start, end)
        frames = ln["frames"]
        if s.camera is not None:
            frames = [dict(f, positions=sample.from_camera(s.camera[k:k + 1],
                                                          f["positions"][None])[0])
                      for k, f in enumerate(frames)]
        results.write_lines(obj.data, start, frames)
        results.set_range(obj, start, end)
    _write(scene, start, writes, lazy)


def _write(scene, start, writes, lazy):
    """Writes every frame of `writes`, or (`lazy`) only the current frame of the result
    meshes that already hold every frame, the rest pending."""
    later = []
    for mesh, positions, alpha in writes:
        if lazy and mesh.attributes.get(f"tk_P{start}") is not None:
            later.append((mesh.name, positions, alpha))
        else:
            results.write_frames(mesh, start, positions, alpha)
    if later:
        _PENDING[scene.name] = _Pending(start, later)
        write_pending(scene)


def bake(context, objects):
    """Samples, prepares and stylizes `objects`, then shows the result (replacing an earlier
    bake). Nothing in the scene changes when this raises."""
    scene, settings = context.scene, context.scene.toonkit_smear
    s, prepared = _prepare(context, objects, settings)
    look = _stylize(s, prepared, settings)
    if is_baked(scene):
        results.remove_all(scene)
    _CACHE[scene.name] = (s, prepared)
    _show(scene, s, look)
    settings.last_error = ""
    return look


def restyle(scene, lazy=False):
    """Re-stylizes the baked result from the cached offsets; returns an error line or None.
    `lazy` (a live slider) writes the current frame now and each other frame when the scene
    reaches it."""
    import bpy

    settings = scene.toonkit_smear
    try:
        cached = _CACHE.get(scene.name)
        if cached is None:  # reopened .blend: sample the baked originals again
            names = [o[results.SOURCE] for o in results.owned("body")]
            objs = [bpy.data.objects[n] for n in names if n in bpy.data.objects]
            cached = _prepare(bpy.context, objs, settings)
            _CACHE[scene.name] = cached
        s, prepared = cached
        _show(scene, s, _stylize(s, prepared, settings), lazy)
    except JobError as e:
        return str(e)
    return None


def timed_restyle(scene):
    """`restyle` and its wall time in seconds."""
    t = time.perf_counter()
    error = restyle(scene)
    return error, time.perf_counter() - t


def write_all_pending():
    """Writes every pending frame (before saving or rendering)."""
    import bpy

    for scene in bpy.data.scenes:
        write_pending(scene, frame_only=False)


def after_undo():
    """An undo may restore result meshes with some frames of a live restyle pending: those
    scenes are restyled again in full, from the restored settings."""
    import bpy

    names = list(_PENDING)
    _PENDING.clear()
    for name in names:
        scene = bpy.data.scenes.get(name)
        if scene is not None and is_baked(scene):
            scene.toonkit_smear.last_error = restyle(scene) or ""


def unbake(scene):
    _PENDING.pop(scene.name, None)
    results.remove_all(scene)
    _CACHE.pop(scene.name, None)


def cached(scene):
    """The cached (Sample, Prepared) of a bake, if any (tests compare against it)."""
    return _CACHE.get(scene.name)


def offsets_array(scene):
    c = _CACHE.get(scene.name)
    return None if c is None else np.asarray(c[1].offsets)
