"""Vertex weights per mesh, read once and kept until the mesh is edited (docs/blender.md,
"Speed").

Blender has no bulk read of vertex weights: one pass over the vertices in Python is the
largest part of sampling that is not Blender's own evaluation. A bake keeps what it read per
mesh data-block; any update of that mesh Blender's depsgraph reports (weight painting, edit
mode, `VertexGroup.add`, a modifier toggled) drops it, and so do undo, redo and loading a
file. Keys also hold the vertex count and the vertex group names, so a mesh swapped in at
the same address reads again.
"""

import bpy
from bpy.app.handlers import persistent
import numpy as np

_KEPT = {}  # mesh pointer -> (key, {group name: read-only (n,) float32 weights})
_own_updates = [0]  # > 0 while a bake samples: its own modifier toggles are not edits


def _key(obj, n):
    return (n, tuple((g.index, g.name) for g in obj.vertex_groups))


def read(obj, n):
    """Every vertex group of `obj` as a dense (n,) float32 weight array (read-only), by name.
    Read from the mesh when it is not kept (see the module's doc)."""
    pointer = obj.data.as_pointer()
    key = _key(obj, n)
    kept = _KEPT.get(pointer)
    if kept is not None and kept[0] == key:
        return kept[1]
    groups = _read(obj, n)
    _KEPT[pointer] = (key, groups)
    return groups


def _read(obj, n):
    """One pass over the vertices collects (group, vertex, weight) triples in lists, and
    numpy scatters them at once (the fastest of the per-vertex reads tried)."""
    names = {g.index: g.name for g in obj.vertex_groups}
    dense = np.zeros((max(names, default=-1) + 1, n), np.float32)
    group, vertex, weight = [], [], []
    for i, v in enumerate(obj.data.vertices):
        for g in v.groups:
            group.append(g.group)
            vertex.append(i)
            weight.append(g.weight)
    if group:
        group = np.array(group, np.int64)
        known = group < len(dense)  # a weight of a group that no longer exists
        dense[group[known], np.array(vertex, np.int64)[known]] = np.array(weight,
                                                                         np.float32)[known]
    dense.flags.writeable = False
    return {name: dense[i] for i, name in names.items()}


class own_updates:
    """While a bake samples (mutes and restores Armature modifiers, sets frames), the mesh
    updates it causes itself keep the weights."""

    def __init__(self, context):
        # Updates still pending from before the bake (an edit by a script) are reported now,
        # not swallowed by the sampling's first frame change.
        context.evaluated_depsgraph_get()

    def __enter__(self):
        _own_updates[0] += 1
        return self

    def __exit__(self, *exc):
        _own_updates[0] -= 1
        return False


def forget(mesh=None):
    """Drops the weights kept for `mesh` (all when None)."""
    if mesh is None:
        _KEPT.clear()
    else:
        _KEPT.pop(mesh.as_pointer(), None)


@persistent
def _updated(scene, depsgraph=None):
    if not _KEPT or _own_updates[0] or depsgraph is None:
        return
    for u in depsgraph.updates:
        if isinstance(u.id, bpy.types.Mesh):
            _KEPT.pop(u.id.original.as_pointer(), None)


@persistent
def _forget_all(*args):
    _KEPT.clear()


HANDLERS = (("depsgraph_update_post", _updated), ("frame_change_post", _updated),
            ("undo_post", _forget_all), ("redo_post", _forget_all), ("load_pre", _forget_all))


def register():
    for name, handler in HANDLERS:
        getattr(bpy.app.handlers, name).append(handler)


def unregister():
    _KEPT.clear()
    for name, handler in HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if handler in handlers:
            handlers.remove(handler)
