"""Bake, restyle and unbake: Blender's evaluated animation through `toonkit.smear`.

The prepared offsets stay in memory per scene, so a restyle is one `toonkit.smear.stylize`
plus attribute writes. After reopening a .blend the first restyle samples again.
"""

import json
import time

import numpy as np

from . import results, sample, style

_CACHE = {}  # scene name -> (Sample, toonkit Prepared)


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
    positions, skin = (sample.to_camera(s) if s.camera is not None
                       else (s.positions, s.skin))
    try:
        scene = toonkit.Scene.from_arrays(positions, s.triangles, fps=s.fps, skin=skin,
                                          objects=s.objects, attributes=s.attributes)
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


def _show(scene, s, look):
    """Creates or updates the result objects of `look` (elongation, copies, lines)."""
    import bpy

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
        results.write_frames(body.data, start, elongated[:, r.start:r.stop])
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
        results.write_frames(obj.data, start, _world(s, c["positions"]), c["alpha"])
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


def restyle(scene):
    """Re-stylizes the baked result from the cached offsets; returns an error line or None."""
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
        _show(scene, s, _stylize(s, prepared, settings))
    except JobError as e:
        return str(e)
    return None


def timed_restyle(scene):
    """`restyle` and its wall time in seconds."""
    t = time.perf_counter()
    error = restyle(scene)
    return error, time.perf_counter() - t


def unbake(scene):
    results.remove_all(scene)
    _CACHE.pop(scene.name, None)


def cached(scene):
    """The cached (Sample, Prepared) of a bake, if any (tests compare against it)."""
    return _CACHE.get(scene.name)


def offsets_array(scene):
    c = _CACHE.get(scene.name)
    return None if c is None else np.asarray(c[1].offsets)
