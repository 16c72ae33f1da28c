"""toonkit-owned result objects: the smear stored inside the .blend, shown by a node group.

Each result object (elongated body, each multiple in-between, each object's motion lines) is
an ordinary mesh in the "toonkit" collection whose mesh holds one point attribute per baked
frame (`tk_P<frame>` positions, `tk_A<frame>` opacity). The "toonkit smear" Geometry Nodes
modifier picks the attribute of the current scene frame (clamped to the baked range), so the
result plays in the viewport and in F12 / animation renders, survives save/reload (all data is
in the .blend, no external cache, no frame handler) and needs no add-on to display. Motion
lines change topology per frame: all frames are stored in one mesh with a `tk_frame` point
attribute and the node group deletes the other frames. `tk_alpha` carries the opacity to the
material (Attribute node).
"""

import uuid

import bpy
import numpy as np

COLLECTION = "toonkit"
GROUP = "toonkit smear"
ROLE = "toonkit_role"  # on every toonkit-owned object: body/multiple/lines/stopmo
SOURCE = "toonkit_source"  # the original object's name
HIDDEN = "toonkit_hidden"  # the original's (hide_viewport, hide_render) before the bake


def _frame_text(n, gi):
    """The scene frame rounded and clamped to [Start, End] (node links; `gi` the group
    input): the clamp node and the frame as text, shared by every per-frame attribute the
    group reads."""
    g = n.id_data
    t = n.new("GeometryNodeInputSceneTime")
    rnd = n.new("ShaderNodeMath")
    rnd.operation = "ROUND"
    g.links.new(t.outputs["Frame"], rnd.inputs[0])
    clamp = n.new("ShaderNodeClamp")
    g.links.new(rnd.outputs[0], clamp.inputs["Value"])
    g.links.new(gi.outputs["Start"], clamp.inputs["Min"])
    g.links.new(gi.outputs["End"], clamp.inputs["Max"])
    text = n.new("FunctionNodeValueToString")
    g.links.new(clamp.outputs[0], text.inputs["Value"])
    return clamp, text


def _frame_attribute(n, prefix, text):
    """The attribute `prefix + text` (the frame's, see `_frame_text`): one Replace String
    node fills the prefix's placeholder (a node and a link fewer than a string node and a
    join: each costs an API call on every first bake, docs/blender.md "Speed")."""
    g = n.id_data
    name = n.new("FunctionNodeReplaceString")
    name.inputs["String"].default_value = prefix + "#"
    name.inputs["Find"].default_value = "#"
    g.links.new(text.outputs[0], name.inputs["Replace"])
    attr = n.new("GeometryNodeInputNamedAttribute")
    attr.data_type = {"tk_P": "FLOAT_VECTOR", "tk_I": "INT"}.get(prefix, "FLOAT")
    g.links.new(name.outputs[0], attr.inputs["Name"])
    return attr


#: A copy of the node group kept for the session (docs/blender.md, "Speed"): an unbake
#: removes the group, and a bake after it copies this one instead of building it again. No
#: object uses it, so a save leaves it out.
TEMPLATE = ".toonkit smear template"
_BUILD = uuid.uuid4().hex  # this extension's build: a reloaded one builds its own template


def node_group():
    """The shared node group (made once per .blend; copied from the session's template)."""
    g = bpy.data.node_groups.get(GROUP)
    if g is not None:
        return g
    template = bpy.data.node_groups.get(TEMPLATE)
    if template is None or template.get(ROLE) != _BUILD:
        if template is not None:
            bpy.data.node_groups.remove(template)
        template = _build(TEMPLATE)
        template[ROLE] = _BUILD
    g = template.copy()
    g.name = GROUP
    del g[ROLE]
    return g


def _build(name):
    """The node group (19 nodes, each node and link an API call that updates the tree)."""
    g = bpy.data.node_groups.new(name, "GeometryNodeTree")
    g.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    for name in ("Start", "End"):
        g.interface.new_socket(name, in_out="INPUT", socket_type="NodeSocketInt")
    g.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    n, links = g.nodes, g.links
    gin, gout = n.new("NodeGroupInput"), n.new("NodeGroupOutput")
    clamp, text = _frame_text(n, gin)
    pos = _frame_attribute(n, "tk_P", text)
    alpha = _frame_attribute(n, "tk_A", text)
    setpos = n.new("GeometryNodeSetPosition")
    links.new(gin.outputs["Geometry"], setpos.inputs["Geometry"])
    links.new(pos.outputs["Exists"], setpos.inputs["Selection"])
    links.new(pos.outputs["Attribute"], setpos.inputs["Position"])
    store = n.new("GeometryNodeStoreNamedAttribute")
    store.data_type, store.domain = "FLOAT", "POINT"
    store.inputs["Name"].default_value = "tk_alpha"
    links.new(setpos.outputs["Geometry"], store.inputs["Geometry"])
    links.new(alpha.outputs["Exists"], store.inputs["Selection"])
    links.new(alpha.outputs["Attribute"], store.inputs["Value"])
    # Stop-motion reconstructions: the piece shown at this frame, as the integer `piece`.
    piece = _frame_attribute(n, "tk_I", text)
    store_piece = n.new("GeometryNodeStoreNamedAttribute")
    store_piece.data_type, store_piece.domain = "INT", "POINT"
    store_piece.inputs["Name"].default_value = "piece"
    links.new(store.outputs["Geometry"], store_piece.inputs["Geometry"])
    links.new(piece.outputs["Exists"], store_piece.inputs["Selection"])
    links.new(piece.outputs["Attribute"], store_piece.inputs["Value"])
    store = store_piece
    # Motion lines: keep only the points (and their faces) of the current frame.
    frame = n.new("GeometryNodeInputNamedAttribute")
    frame.data_type = "FLOAT"
    frame.inputs["Name"].default_value = "tk_frame"
    other = n.new("FunctionNodeCompare")
    other.data_type, other.operation = "FLOAT", "NOT_EQUAL"
    links.new(frame.outputs["Attribute"], other.inputs["A"])
    links.new(clamp.outputs[0], other.inputs["B"])
    both = n.new("FunctionNodeBooleanMath")
    both.operation = "AND"
    links.new(frame.outputs["Exists"], both.inputs[0])
    links.new(other.outputs["Result"], both.inputs[1])
    delete = n.new("GeometryNodeDeleteGeometry")
    delete.domain = "POINT"
    links.new(store.outputs["Geometry"], delete.inputs["Geometry"])
    links.new(both.outputs[0], delete.inputs["Selection"])
    links.new(delete.outputs["Geometry"], gout.inputs["Geometry"])
    return g


def material(name, color, alpha=True):
    """A toonkit material: `color`, opacity from the `tk_alpha` attribute."""
    m = bpy.data.materials.get(name)
    if m is not None:
        return m
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    m.diffuse_color = (*color, 0.5)
    bsdf = next(x for x in m.node_tree.nodes if x.type == "BSDF_PRINCIPLED")
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    if alpha:
        a = m.node_tree.nodes.new("ShaderNodeAttribute")
        a.attribute_name = "tk_alpha"
        m.node_tree.links.new(a.outputs["Fac"], bsdf.inputs["Alpha"])
        if hasattr(m, "surface_render_method"):
            m.surface_render_method = "BLENDED"
        else:
            m.blend_method = "BLEND"
    m[ROLE] = "material"
    return m


def collection(scene):
    c = bpy.data.collections.get(COLLECTION)
    if c is None:
        c = bpy.data.collections.new(COLLECTION)
        c[ROLE] = "collection"
    if c.name not in scene.collection.children:
        scene.collection.children.link(c)
    return c


def add_object(scene, name, mesh, role, source, start, end):
    obj = bpy.data.objects.new(name, mesh)
    obj[ROLE], obj[SOURCE] = role, source
    collection(scene).objects.link(obj)
    mod = obj.modifiers.new(GROUP, "NODES")
    mod.node_group = node_group()
    set_range(obj, start, end)
    return obj


def set_range(obj, start, end):
    """The modifier's baked frame range (a restyle that keeps it tags nothing)."""
    mod = obj.modifiers[GROUP]
    changed = False
    for item in mod.node_group.interface.items_tree:
        if getattr(item, "in_out", None) == "INPUT" and item.name in ("Start", "End"):
            value = start if item.name == "Start" else end
            if mod.get(item.identifier) != value:
                mod[item.identifier] = value
                changed = True
    if changed:
        obj.update_tag()


def mesh_like(source_mesh, name):
    """A copy of `source_mesh`'s topology and materials (vertices set per frame)."""
    m = source_mesh.copy()
    m.name = name
    for a in [a.name for a in m.attributes if a.name.startswith("tk_")]:
        m.attributes.remove(m.attributes[a])
    return m


def write_frames(mesh, start, positions, alpha=None, frames=None):
    """Per-frame attributes `tk_P<frame>` (and `tk_A<frame>`) of the frame indices `frames`
    (all when None). `positions` (frames, n, 3) and `alpha` (frames, n) are float32 arrays
    whose frames are contiguous (the core's output): each frame goes to Blender straight from
    its buffer, nothing is allocated per frame. A new mesh (no `tk_P` yet) also gets the first
    frame as its rest vertices; later writes only tag the mesh for re-evaluation."""
    attrs = mesh.attributes
    fresh = attrs.get(f"tk_P{start}") is None
    for k in range(len(positions)) if frames is None else frames:
        f = start + k
        _layer(attrs, f"tk_P{f}", "FLOAT_VECTOR").data.foreach_set(
            "vector", _flat(positions[k]))
        if alpha is not None:
            _layer(attrs, f"tk_A{f}", "FLOAT").data.foreach_set("value", _flat(alpha[k]))
    if fresh:
        mesh.vertices.foreach_set("co", _flat(positions[0]))
        mesh.update()
    else:
        mesh.update_tag()


def _layer(attrs, name, kind):
    return attrs.get(name) or attrs.new(name, kind, "POINT")


def _flat(a):
    """`a` as a flat float32 view (a copy only when it is not contiguous float32)."""
    return np.ascontiguousarray(a, np.float32).reshape(-1)


def write_lines(mesh, start, frames):
    """All frames' line tubes in one mesh, `tk_frame` telling which frame a point shows at."""
    pts, tris, alpha, frame, base = [], [], [], [], 0
    for k, fr in enumerate(frames):
        p = fr["positions"]
        pts.append(p)
        tris.append(fr["triangles"] + base)
        alpha.append(fr["alpha"])
        frame.append(np.full(len(p), start + k, np.float32))
        base += len(p)
    p = np.concatenate(pts) if pts else np.zeros((0, 3), np.float32)
    t = np.concatenate(tris) if tris else np.zeros((0, 3), np.int32)
    mesh.clear_geometry()
    mesh.vertices.add(len(p))
    mesh.vertices.foreach_set("co", np.ascontiguousarray(p, np.float32).ravel())
    mesh.loops.add(3 * len(t))
    mesh.loops.foreach_set("vertex_index", np.ascontiguousarray(t, np.int32).ravel())
    mesh.polygons.add(len(t))
    mesh.polygons.foreach_set("loop_start", np.arange(0, 3 * len(t), 3, dtype=np.int32))
    mesh.update()
    for name, data in (("tk_frame", frame), ("tk_alpha", alpha)):
        a = mesh.attributes.get(name) or mesh.attributes.new(name, "FLOAT", "POINT")
        if len(p):
            a.data.foreach_set("value", np.concatenate(data).astype(np.float32))


def owned(kind=None):
    """Every toonkit-owned object (of one role)."""
    return [o for o in bpy.data.objects if ROLE in o and (kind is None or o[ROLE] == kind)]


def make_body(scene, original, mesh, start, end):
    """The elongated body of `original` (its data untouched; it is hidden until unbake)."""
    obj = add_object(scene, f"{original.name} smear", mesh, "body", original.name, start, end)
    obj[HIDDEN] = [original.hide_viewport, original.hide_render, original.hide_get()]
    original.hide_render = True
    original.hide_set(True)
    return obj


def make_copy(scene, body, index, start, end):
    mesh = mesh_like(body.data, f"{body[SOURCE]} multiple {index}")
    mesh.materials.clear()
    mesh.materials.append(material("toonkit multiple", (0.8, 0.8, 0.8)))
    return add_object(scene, mesh.name, mesh, "multiple", body[SOURCE], start, end)


def make_lines(scene, source, start, end):
    mesh = bpy.data.meshes.new(f"{source} lines")
    mesh.materials.append(material("toonkit line", (0.05, 0.05, 0.05)))
    return add_object(scene, mesh.name, mesh, "lines", source, start, end)


def remove(obj):
    mesh = obj.data
    bpy.data.objects.remove(obj)
    if mesh is not None and mesh.users == 0:
        bpy.data.meshes.remove(mesh)


SMEAR_ROLES = ("body", "multiple", "lines")


def remove_all(scene, roles=SMEAR_ROLES):
    """Removes the toonkit-owned objects of `roles` (and their meshes), shows their originals
    as they were, and removes the materials, node group and collection once nothing of
    toonkit's is left."""
    for obj in owned("body") if "body" in roles else []:
        original = bpy.data.objects.get(obj[SOURCE])
        if original is not None and HIDDEN in obj:
            vp, render, hidden = obj[HIDDEN]
            original.hide_viewport, original.hide_render = bool(vp), bool(render)
            if original.name in scene.view_layers[0].objects:
                original.hide_set(bool(hidden))
    for obj in owned():
        if obj[ROLE] in roles:
            remove(obj)
    for m in [m for m in bpy.data.materials if ROLE in m and m.users == 0]:
        bpy.data.materials.remove(m)
    if owned():
        return
    g = bpy.data.node_groups.get(GROUP)
    if g is not None:
        bpy.data.node_groups.remove(g)
    c = bpy.data.collections.get(COLLECTION)
    if c is not None and ROLE in c:
        bpy.data.collections.remove(c)
