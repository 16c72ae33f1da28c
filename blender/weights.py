"""Vertex weights per mesh, read once and kept until the mesh is edited (docs/blender.md,
"Speed").

Blender's Python API has no bulk read of vertex weights, but Geometry Nodes sees vertex
groups as attributes: a modifier whose inputs read the groups by name and whose outputs store
them as float attributes gives every group in one evaluation, each read with one
`foreach_get` (a pass over the vertices in Python is the fallback). A bake keeps what it read
per mesh data-block; any update of that mesh Blender's depsgraph reports (weight painting, edit
mode, `VertexGroup.add`, a modifier toggled) drops it, and so do undo, redo and loading a
file. Keys also hold the vertex count and the vertex group names, so a mesh swapped in at
the same address reads again.
"""

import uuid

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
    return read_all(bpy.context, [obj])[obj.name]


def read_all(context, objs):
    """`read` of every mesh object in `objs` (by object name): the ones not kept are read
    together, in one evaluation of the depsgraph."""
    out, missing = {}, []
    for o in objs:
        key = _key(o, len(o.data.vertices))
        kept = _KEPT.get(o.data.as_pointer())
        if kept is not None and kept[0] == key:
            out[o.name] = kept[1]
        else:
            missing.append((o, key))
    read = _read_nodes(context, [o for o, _ in missing])
    for o, key in missing:
        groups = read.get(o.name)
        if groups is None:
            groups = _read(o, key[0])
        _KEPT[o.data.as_pointer()] = (key, groups)
        out[o.name] = groups
    return out


#: The stored attribute of a mesh's `i`-th vertex group while `_read_nodes` reads it.
_STORED = "tk_weights_{}"


def _read_nodes(context, objs):
    """The vertex groups of `objs` through Geometry Nodes (see the module's doc), by object
    name: a temporary modifier (the object's own modifiers off) whose float inputs read the
    groups as attributes and whose outputs store them (`_tree`). An object this cannot read
    (linked, not evaluated, a group name taken by an attribute) is left out, for `_read`."""
    objs = [o for o in objs if len(o.vertex_groups) and o.library is None
            and not any(_STORED.format(i) in o.data.attributes or g.name in o.data.attributes
                        for i, g in enumerate(o.vertex_groups))]
    if not objs:
        return {}
    added, muted, out = [], [], {}
    outside = _own_updates[0] == 0  # a read outside a bake: no edit of the mesh either
    _own_updates[0] += 1
    try:
        tree = _tree(max(len(o.vertex_groups) for o in objs))
        sockets = [i for i in tree.interface.items_tree
                   if getattr(i, "socket_type", None) == "NodeSocketFloat"]
        ins = [i.identifier for i in sockets if i.in_out == "INPUT"]
        outs = [i.identifier for i in sockets if i.in_out == "OUTPUT"]
        for o in objs:
            muted += [m for m in o.modifiers if m.show_viewport]
            try:
                mod = o.modifiers.new("toonkit weights", "NODES")
            except RuntimeError:  # e.g. an object Blender does not let scripts change
                continue
            added.append((o, mod))
            mod.node_group = tree
            for i, g in enumerate(o.vertex_groups):
                mod[ins[i] + "_use_attribute"] = True
                mod[ins[i] + "_attribute_name"] = g.name
                mod[outs[i] + "_attribute_name"] = _STORED.format(i)
        for m in muted:
            m.show_viewport = False
        dg = context.evaluated_depsgraph_get()
        for o, _ in added:
            out_o = _stored(o, o.evaluated_get(dg).data)
            if out_o is not None:
                out[o.name] = out_o
    finally:
        for o, mod in added:
            o.modifiers.remove(mod)
        for m in muted:
            m.show_viewport = True
        if outside:  # the updates of the restored modifiers are reported now, as ours
            context.evaluated_depsgraph_get()
        _own_updates[0] -= 1
    return out


#: The node group `_read_nodes` uses, kept for the session: no object uses it once read, so
#: a save leaves it out; a bake that needs more groups than it has builds it again.
TREE = ".toonkit weights"
_BUILD = uuid.uuid4().hex  # this extension's build: a reloaded one builds its own


def _tree(slots):
    """The node group of `_read_nodes` with at least `slots` float inputs, each linked to a
    float output (two nodes and a link per group)."""
    tree = bpy.data.node_groups.get(TREE)
    if (tree is not None and tree.get("toonkit_build") == _BUILD
            and tree.get("toonkit_slots", 0) >= slots):
        return tree
    if tree is not None:
        bpy.data.node_groups.remove(tree)
    tree = bpy.data.node_groups.new(TREE, "GeometryNodeTree")
    face = tree.interface
    face.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    face.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    for i in range(slots):
        face.new_socket(f"in {i}", in_out="INPUT", socket_type="NodeSocketFloat")
        face.new_socket(f"out {i}", in_out="OUTPUT", socket_type="NodeSocketFloat")
    gin, gout = tree.nodes.new("NodeGroupInput"), tree.nodes.new("NodeGroupOutput")
    for i in range(slots + 1):
        tree.links.new(gin.outputs[i], gout.inputs[i])
    tree["toonkit_build"], tree["toonkit_slots"] = _BUILD, slots
    return tree


def _stored(obj, mesh):
    """The groups `_read_nodes` stored on the evaluated `mesh` of `obj`, or None."""
    n = len(obj.data.vertices)
    if mesh is None or len(mesh.vertices) != n:
        return None
    dense = np.empty((len(obj.vertex_groups), n), np.float32)
    for i in range(len(dense)):
        a = mesh.attributes.get(_STORED.format(i))
        if a is None or a.data_type != "FLOAT" or a.domain != "POINT":
            return None
        a.data.foreach_get("value", dense[i])
    dense.flags.writeable = False
    return {g.name: dense[i] for i, g in enumerate(obj.vertex_groups)}


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
