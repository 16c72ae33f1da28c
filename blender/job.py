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
    start, end, what = sample.bake_range(context.scene)
    if end <= start:
        return f"the {what} {start}-{end} needs at least two frames"
    return None


def _sample(context, objects, settings):
    """The sample of `objects` (see `sample.sample`); raises JobError when nothing moves."""
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
    if not s.moves() and s.camera is None:
        names = ", ".join(s.names[:3]) + (" …" if len(s.names) > 3 else "")
        raise JobError(f"{names}: does not move over frames {s.frame_start}-"
                       f"{s.frame_start + s.frame_count - 1}, nothing to smear; animate it "
                       "or set the scene range to where it moves")
    return s


def _start(s, settings):
    """The core's scene of the sample `s`, its offsets being prepared on a thread of their
    own: a `toonkit.smear.Preparing` (`_result` waits for it)."""
    toonkit = _toonkit()
    positions, skin = sample.to_camera(s)
    try:
        scene = toonkit.Scene.from_arrays(positions, s.triangles, fps=s.fps, skin=skin,
                                          objects=s.objects, attributes=s.attributes,
                                          rest=s.rest,
                                          skinning=s.clip_skinning() if positions is None else None)
        return toonkit.smear.start_prepare(scene, smooth=settings.smooth)
    except (toonkit.ToonkitError, ValueError) as e:
        raise JobError(_one_line(e)) from e


def _result(preparing):
    """The offsets `_start` started to prepare."""
    toonkit = _toonkit()
    try:
        return preparing.result()
    except (toonkit.ToonkitError, ValueError) as e:
        raise JobError(_one_line(e)) from e


def _prepare(context, objects, settings):
    s = _sample(context, objects, settings)
    return s, _result(_start(s, settings))


def _stylize(s, prepared, style, frames=None):
    """`toonkit.smear.stylize` of the style dict `style`; `frames` = (start, end) clip frames
    only."""
    toonkit = _toonkit()
    try:
        return toonkit.smear.stylize(prepared, style, frames=frames)
    except (toonkit.ToonkitError, ValueError, json.JSONDecodeError) as e:
        raise JobError(_one_line(e)) from e


def _settings_style(s, settings):
    try:
        return style.from_settings(settings, s.bones)
    except (ValueError, json.JSONDecodeError) as e:
        raise JobError(_one_line(e)) from e


class _Pending:
    """The frames of a live restyle not written yet (docs/blender.md, "Speed"): the style is
    stylized and written one frame at a time as the scene reaches it (`smear::stylize_frames`
    costs the frames asked for), or all at once before a save or a render."""

    def __init__(self, style, frames):
        self.style, self.frames = style, set(frames)

    def write(self, scene, frames):
        frames = sorted(k for k in frames if k in self.frames)
        cached = _CACHE.get(scene.name)
        if not frames or cached is None:
            return
        s, prepared = cached
        look = _stylize(s, prepared, self.style, (frames[0], frames[-1] + 1))
        _write(s, look, [k - frames[0] for k in frames])
        self.frames.difference_update(frames)


def _current(scene, s):
    """The clip frame index of the scene's frame, clamped to the baked range."""
    return min(max(scene.frame_current - s.frame_start, 0), s.frame_count - 1)


def write_pending(scene, frame_only=True):
    """Writes the pending frames of `scene`'s last live restyle: the current frame, or all.
    A failure (the style cannot be applied) drops the pending frames and says why in the
    panel."""
    p = _PENDING.get(scene.name)
    cached = _CACHE.get(scene.name)
    if p is None or cached is None:
        _PENDING.pop(scene.name, None)
        return
    try:
        p.write(scene, [_current(scene, cached[0])] if frame_only else sorted(p.frames))
    except JobError as e:
        p.frames.clear()
        scene.toonkit_smear.last_error = str(e)
    if not p.frames:
        _PENDING.pop(scene.name, None)


def _targets(s, look):
    """What `look` shows: per result object, its key (the body of a source, or the k-th
    copy of a source), its world positions (frames, n, 3) and opacity (frames, n) or None."""
    first = look.first_frame
    elongated = look.elongated
    camera = None if s.camera is None else s.camera[first:first + len(elongated)]

    def world(points):
        return sample.from_y_up(points) if camera is None else sample.from_camera(camera, points)

    elongated = world(elongated)
    out = [(("body", name), elongated[:, r.start:r.stop], None) for name, r in s.objects]
    count = {}
    for c in look.multiples:
        source = s.names[c["object"]]
        k = count.get(source, 0)
        count[source] = k + 1
        out.append((("multiple", source, k), world(c["positions"]), c["alpha"]))
    return out


def _result_meshes():
    """The result objects' meshes by key (see `_targets`)."""
    meshes = {("body", o[results.SOURCE]): o.data for o in results.owned("body")}
    for o in results.owned("multiple"):
        meshes[("multiple", o[results.SOURCE], int(o.get("toonkit_index", 0)))] = o.data
    return meshes


def _write(s, look, frames=None):
    """Writes the frames `frames` of `look` (indices into its frames; all when None) to the
    result meshes, as clip frames from `look.first_frame` on."""
    meshes = _result_meshes()
    start = s.frame_start + look.first_frame
    for key, positions, alpha in _targets(s, look):
        mesh = meshes.get(key)
        if mesh is not None:
            results.write_frames(mesh, start, positions, alpha, frames)


def _bodies(scene, s):
    """The elongated body of each sampled object by source name, made when missing (its
    mesh a copy of the original's evaluated mesh), over the sample's frames."""
    import bpy

    start, end = s.frame_start, s.frame_start + s.frame_count - 1
    bodies = {o[results.SOURCE]: o for o in results.owned("body")}
    for name, _ in s.objects:
        body = bodies.get(name)
        if body is None:
            original = bpy.data.objects[name]
            dg = bpy.context.evaluated_depsgraph_get()
            mesh = bpy.data.meshes.new_from_object(original.evaluated_get(dg))
            mesh.name = f"{name} smear"
            body = results.make_body(scene, original, mesh, start, end)
            bodies[name] = body
        results.set_range(body, start, end)
    return bodies


def _show(scene, s, look):
    """Creates or updates the result objects of `look` (elongation, copies, lines) and
    writes its frames."""
    start, end = s.frame_start, s.frame_start + s.frame_count - 1
    bodies = _bodies(scene, s)

    wanted = {}
    for c in look.multiples:
        source = s.names[c["object"]]
        k = sum(1 for key in wanted if key[0] == source)
        wanted[(source, k)] = c
    copies = {(o[results.SOURCE], int(o.get("toonkit_index", 0))): o
              for o in results.owned("multiple")}
    for key, obj in copies.items():
        if key not in wanted:
            results.remove(obj)
    for key in wanted:
        obj = copies.get(key)
        if obj is None:
            obj = results.make_copy(scene, bodies[key[0]], key[1], start, end)
            obj["toonkit_index"] = key[1]
        results.set_range(obj, start, end)

    lines = {s.names[ln["object"]]: ln for ln in look.lines}
    for obj in results.owned("lines"):
        if obj[results.SOURCE] not in lines:
            results.remove(obj)
    have = {o[results.SOURCE]: o for o in results.owned("lines")}
    for source, ln in lines.items():
        obj = have.get(source) or results.make_lines(scene, source, start, end)
        frames = [dict(f, positions=sample.from_y_up(f["positions"]) if s.camera is None
                       else sample.from_camera(s.camera[k:k + 1], f["positions"][None])[0])
                  for k, f in enumerate(ln["frames"])]
        results.write_lines(obj.data, start, frames)
        results.set_range(obj, start, end)
    _write(s, look)


def _stylize_lazily(scene, s, prepared, wanted, lazy):
    """`wanted` stylized: the whole clip, or (`lazy`) the frame on screen only, the others
    left for `_show_lazily`. Motion lines, one mesh for all frames, are stylized whole.
    Returns the look and whether it is the frame on screen only."""
    lazy = lazy and "lines" not in wanted
    k = _current(scene, s)
    return _stylize(s, prepared, wanted, (k, k + 1) if lazy else None), lazy


def _show_lazily(scene, s, look, wanted, lazy):
    """Shows `look`; when it is the frame on screen only (`lazy`), every other frame is
    stylized and written when the scene reaches it, before a save or a render, or once
    Blender is idle (docs/blender.md, "Speed")."""
    _PENDING.pop(scene.name, None)
    _show(scene, s, look)
    if lazy:
        k = look.first_frame
        _PENDING[scene.name] = _Pending(wanted, set(range(s.frame_count)) - {k})
        _flush_when_idle()


def bake(context, objects):
    """Samples, prepares and stylizes `objects`, then shows the result (replacing an earlier
    bake): the frame on screen at once, the others as `_show_lazily` says. Nothing in the
    scene changes when this raises."""
    scene, settings = context.scene, context.scene.toonkit_smear
    s = _sample(context, objects, settings)
    wanted = _settings_style(s, settings)
    fresh = not is_baked(scene)
    preparing = _start(s, settings)
    if fresh:
        # Made while the core solves the offsets (docs/blender.md, "Speed"); removed again
        # when the core or the style fails (hiding an original deselects it).
        picked = [o for o in objects if o.select_get()]
        _bodies(scene, s)
    try:
        prepared = _result(preparing)
        look, lazy = _stylize_lazily(scene, s, prepared, wanted, True)
    except JobError:
        if fresh:
            results.remove_all(scene)
            for o in picked:
                o.select_set(True)
        raise
    if not fresh:
        results.remove_all(scene)
    _CACHE[scene.name] = (s, prepared)
    _show_lazily(scene, s, look, wanted, lazy)
    settings.last_error = ""
    return look


def restyle(scene, lazy=False):
    """Re-stylizes the baked result from the cached offsets; returns an error line or None.
    `lazy` (a live slider) stylizes and writes the current frame now, the others later
    (`_show_lazily`)."""
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
        wanted = _settings_style(s, settings)
        # A style that fails leaves the last good one, its pending frames included.
        look, lazy = _stylize_lazily(scene, s, prepared, wanted, lazy)
        _show_lazily(scene, s, look, wanted, lazy)
    except JobError as e:
        return str(e)
    return None


#: Seconds without a restyle before the pending frames are written (a slider being dragged
#: restyles only the frame on screen).
IDLE_SECONDS = 0.3


def _flush_when_idle():
    """Writes every pending frame once Blender has been idle `IDLE_SECONDS` (a timer, set
    again by each restyle: the interface shows the bake or the slider's frame first)."""
    import bpy

    cancel_flush()
    bpy.app.timers.register(_flush, first_interval=IDLE_SECONDS)


def cancel_flush():
    import bpy

    if bpy.app.timers.is_registered(_flush):
        bpy.app.timers.unregister(_flush)


def _flush():
    write_all_pending()
    return None  # once


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
    """An undo restores result meshes as they were at its step, some frames perhaps written
    from another style or not yet: every baked scene whose offsets are cached is restyled
    from the restored settings (lazily: the frame on screen at once)."""
    import bpy

    _PENDING.clear()
    for name in list(_CACHE):
        scene = bpy.data.scenes.get(name)
        if scene is not None and is_baked(scene):
            scene.toonkit_smear.last_error = restyle(scene, lazy=True) or ""


def unbake(scene):
    _PENDING.pop(scene.name, None)
    results.remove_all(scene)
    _CACHE.pop(scene.name, None)


def forget():
    """Drops every cached bake and pending frame (another .blend is being opened: its results
    sample their originals again at the first restyle)."""
    cancel_flush()
    _PENDING.clear()
    _CACHE.clear()


def pending_frames(scene):
    """How many frames of `scene`'s last bake or live restyle are not written yet."""
    p = _PENDING.get(scene.name)
    return 0 if p is None else len(p.frames)


def cached(scene):
    """The cached (Sample, Prepared) of a bake, if any (tests compare against it)."""
    return _CACHE.get(scene.name)


def offsets_array(scene):
    c = _CACHE.get(scene.name)
    return None if c is None else np.asarray(c[1].offsets)
