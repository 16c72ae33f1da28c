"""Stop-motion replacement libraries (StopShop) from the active mesh's painted parts.

Parts are the vertex groups named `part_<NAME>` (two or more): the triangles whose three
vertices weigh >= 0.5 in a group seed that part. A mesh without such groups uses the seed
points picked with the 3D cursor (`scene.toonkit_stopmo.seeds`, world space, two or more part
names), exactly as the CLI's `--part NAME=x,y,z` seeds. `toonkit.stopmo.run` segments the animation
over the scene range and builds the library; the CLI's folder layout is written to the chosen
directory, and a reconstruction object (toonkit-owned, beside the original) plays the
replacement animation with an integer point attribute `piece` (the piece index of the
vertex's part at the current frame).
"""

import os

import bpy
import numpy as np
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty,
                       FloatVectorProperty, IntProperty, StringProperty)

from . import job, results, sample

PREFIX = "part_"


class StopmoSeed(bpy.types.PropertyGroup):
    """A seed point of a part, picked from the 3D cursor (world space)."""

    part: StringProperty(name="Part", default="")
    location: FloatVectorProperty(name="Location", size=3, subtype="XYZ")


class StopmoSettings(bpy.types.PropertyGroup):
    """Settings of `toonkit.stopmo_run` (StopShop Sections 4-6)."""

    count: EnumProperty(name="Library size", default="EACH", items=[
        ("EACH", "Pieces per part", "The same number of pieces for every part"),
        ("BUDGET", "Budget", "A total number of pieces over all parts"),
        ("MAX_ERROR", "Max error", "The smallest library within an error (mm)")])
    pieces: IntProperty(name="Pieces", default=8, min=1, max=500)
    budget: IntProperty(name="Budget", default=16, min=2, max=2000)
    max_error_mm: FloatProperty(name="Max error (mm)", default=0.5, min=0.001)
    lam: FloatProperty(name="λ", default=1.0, min=0.0,
                       description="Temporal smoothness weight (StopShop Eq. 10)")
    restarts: IntProperty(name="Restarts", default=4, min=1, max=100)
    seed: IntProperty(name="Seed", default=1, min=0)
    print_height_mm: FloatProperty(name="Print height (mm)", default=60.0, min=1.0)
    thickness_mm: FloatProperty(
        name="Wall (mm)", default=0.0, min=0.0, max=20.0,
        description="Wall thickness of the pieces (a magnet pocket needs its depth plus 1 mm "
                    "where a part hardly moves); 0: the tool's default (1.5 mm)")
    plugs: BoolProperty(name="Plugs", default=False,
                        description="Registration plugs between parts")
    magnets: BoolProperty(
        name="Magnets", default=False,
        description="A pocket for a disc magnet in every piece, at one place of its part's "
                    "back all pieces share, and the matching pocket in the part's mount")
    magnet_diameter_mm: FloatProperty(name="Magnet diameter (mm)", default=3.0, min=0.5,
                                      max=100.0)
    magnet_height_mm: FloatProperty(name="Magnet height (mm)", default=2.0, min=0.5,
                                    max=100.0)
    clearance_mm: FloatProperty(
        name="Clearance (mm)", default=0.0, min=0.0, max=5.0,
        description="Clearance of fits (magnet pockets, key sockets, plugs); 0: from the "
                    "printer resolution (0.15 mm)")
    print_format: EnumProperty(name="Print format", default="stl", items=[
        ("stl", "STL", "One STL per piece"),
        ("3mf", "3MF", "One library.3mf: every piece a named object on build plates"),
        ("stl,3mf", "STL and 3MF", "Both")])
    plate_mm: FloatVectorProperty(name="Build plate (mm)", size=2, default=(120.0, 68.0),
                                  min=10.0, max=2000.0)
    min_wall_mm: FloatProperty(
        name="Min wall (mm)", default=0.0, min=0.0, max=10.0,
        description="The printer's thinnest wall: thinner walls of a piece or mount are "
                    "warned about; 0: the tool's default (0.8 mm)")
    min_feature_mm: FloatProperty(
        name="Min feature (mm)", default=0.0, min=0.0, max=10.0,
        description="The printer's smallest free-standing feature (IDs, keys, plug pins); "
                    "0: the tool's default (0.3 mm)")
    print_solids: BoolProperty(
        name="Printable solids", default=True,
        description="Build the STL solids; off, the pieces' surfaces, labels and errors only "
                    "(a quick look at a library size, many times sooner)")
    directory: StringProperty(name="Directory", default="//stopmo", subtype="DIR_PATH")
    seeds: CollectionProperty(type=StopmoSeed, name="Seeds")
    seed_part: StringProperty(name="Part", default="upper",
                              description="The part the next 3D-cursor seed belongs to")


def seed_parts(s):
    """{name: [(x, y, z), ...]} of the 3D-cursor seeds, in the order the parts were named."""
    parts = {}
    for seed in s.seeds:
        parts.setdefault(seed.part, []).append(tuple(float(c) for c in seed.location))
    return parts


def parts_for(obj, triangles, s):
    """The parts of `obj`: its `part_<NAME>` vertex groups, else the 3D-cursor seeds."""
    if any(g.name.startswith(PREFIX) for g in obj.vertex_groups) or len(s.seeds) == 0:
        return parts_of(obj, triangles)
    parts = seed_parts(s)
    if len(parts) < 2:
        raise job.JobError(f"3D-cursor seeds name {len(parts)} part(s); add seeds for at "
                           f"least two parts (or paint vertex groups '{PREFIX}<NAME>')")
    return parts


def parts_of(obj, triangles):
    """{name: [triangle ids]} from the `part_<NAME>` vertex groups of `obj`."""
    groups = [g for g in obj.vertex_groups if g.name.startswith(PREFIX)]
    if len(groups) < 2:
        raise job.JobError(f"{obj.name}: paint at least two vertex groups named "
                           f"'{PREFIX}<NAME>' (found {len(groups)}) or add 3D-cursor seeds "
                           f"for two parts")
    n = len(obj.data.vertices)
    weights = np.zeros((len(groups), n), np.float32)
    index = {g.index: k for k, g in enumerate(groups)}
    for v in obj.data.vertices:
        for e in v.groups:
            if e.group in index:
                weights[index[e.group], v.index] = e.weight
    parts = {}
    for k, g in enumerate(groups):
        inside = (weights[k][triangles] >= 0.5).all(axis=1)
        ids = np.nonzero(inside)[0]
        if len(ids) == 0:
            raise job.JobError(f"{obj.name}: vertex group '{g.name}' covers no whole triangle")
        parts[g.name[len(PREFIX):]] = [int(t) for t in ids]
    return parts


def options(s):
    """Keyword arguments of `toonkit.stopmo.run` from the panel."""
    count = {"EACH": {"pieces": s.pieces}, "BUDGET": {"budget": s.budget},
             "MAX_ERROR": {"max_error_mm": s.max_error_mm}}[s.count]
    opts = {**count, "lambda": s.lam, "restarts": s.restarts, "seed": s.seed,
            "print_height_mm": s.print_height_mm, "print": bool(s.print_solids)}
    if s.plugs:
        opts["plugs"] = {}
    if s.print_solids:
        if s.thickness_mm > 0.0:
            opts["thickness_mm"] = s.thickness_mm
        opts["print_format"] = s.print_format
        opts["plate_mm"] = [float(v) for v in s.plate_mm]
        if s.magnets:
            opts["magnets"] = {"diameter_mm": s.magnet_diameter_mm,
                               "height_mm": s.magnet_height_mm}
        if s.clearance_mm > 0.0:
            opts["clearance_mm"] = s.clearance_mm
        for name in ("min_wall_mm", "min_feature_mm"):
            if getattr(s, name) > 0.0:
                opts[name] = getattr(s, name)
    return opts


WARNINGS = "toonkit_warnings"
"""Custom property of the reconstruction object: the job's warnings, one per line."""


def run(context, obj):
    """Runs the job on `obj` and shows the reconstruction; returns the library."""
    toonkit = job._toonkit()
    s = context.scene.toonkit_stopmo
    try:
        taken = sample.sample(context, [obj])
    except sample.SampleError as e:
        raise job.JobError(str(e)) from e
    parts = parts_for(obj, taken.triangles, s)
    folder = bpy.path.abspath(s.directory)
    if s.directory.startswith("//") and not bpy.data.filepath:
        raise job.JobError("save the .blend first, or choose an absolute directory")
    try:
        scene = toonkit.Scene.from_arrays(taken.positions, taken.triangles, fps=taken.fps)
        lib = toonkit.stopmo.run(scene, parts=parts, **options(s))
        os.makedirs(folder, exist_ok=True)
        lib.save(folder)
    except (toonkit.ToonkitError, ValueError, OSError) as e:
        raise job.JobError(job._one_line(e)) from e
    rec = show(context.scene, obj, folder, lib, taken.frame_start)
    # The job's warnings (pieces below the printer resolution, thin walls, crossing
    # triangles) stay with the result, one per line; the operator reports them.
    rec[WARNINGS] = "\n".join(lib.report.get("warnings", []))
    return lib


def show(scene, obj, folder, lib, start):
    """The reconstruction object (replacing an earlier one of `obj`) and the error curve."""
    for old in results.owned("stopmo"):
        if old[results.SOURCE] == obj.name:
            results.remove(old)
    # The reconstruction from the library itself (the core's merge, as in rest.obj and
    # reconstruction.pc2), not read back from the files just written.
    r = lib.reconstruction
    rest, tris, frames = r["rest"], r["triangles"], r["positions"]
    mesh = bpy.data.meshes.new(f"{obj.name} stopmo")
    mesh.from_pydata(rest.tolist(), [], tris.tolist())
    end = start + len(frames) - 1
    results.write_frames(mesh, start, frames)
    labels = np.asarray(lib.labels)  # (frames, parts)
    sizes = [p["vertices"] for p in lib.report["parts"]]  # part order of rest.obj
    if sum(sizes) != len(rest):
        raise job.JobError(f"{folder}: rest.obj has {len(rest)} vertices, parts {sum(sizes)}")
    part_of_vertex = np.repeat(np.arange(len(sizes)), sizes)
    for k in range(len(frames)):
        a = mesh.attributes.new(f"tk_I{start + k}", "INT", "POINT")
        a.data.foreach_set("value", labels[k][part_of_vertex].astype(np.int32))
    rec = results.add_object(scene, mesh.name, mesh, "stopmo", obj.name, start, end)
    width = float(np.ptp(rest[:, 0])) if len(rest) else 1.0
    rec.location = (1.2 * width, 0.0, 0.0)
    curve = os.path.join(folder, "error_curve.png")
    if os.path.exists(curve):
        old = bpy.data.images.get("toonkit error curve")
        if old is not None:
            bpy.data.images.remove(old)
        img = bpy.data.images.load(curve)
        img.name = "toonkit error curve"
    return rec

