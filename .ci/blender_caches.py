#!/usr/bin/env python3
"""Checks toonkit's scene caches in Blender (`bpy`, headless): every `NAME.abc` and `NAME.usdc`
in DIR that has a `NAME.pc2` beside it (the same shot written as a point cache).

Usage: python .ci/blender_caches.py DIR

Per cache:
1. `bpy.ops.wm.alembic_import` / `bpy.ops.wm.usd_import` into an empty scene creates exactly one
   mesh object;
2. the scene's frame range set by the importer is 1 .. F, F the frames of the `.pc2`;
3. at the first, middle and last frame, the evaluated vertex positions (world space) equal the
   `.pc2` positions of that frame within 1e-5, after Blender's Y-up → Z-up conversion
   (x, y, z) → (x, -z, y) (both importers convert a Y-up file so);
4. a moving `.usdc` point cache's `velocities` arrive as the `velocity` attribute, equal at
   the middle frame to the points' central difference per second.
Every `NAME_lines.usda` (motion lines) must import as one curves object whose points change
per frame and have a width (the BasisCurves prim's widths).
Prints one line per cache, exits 1 on any failure or when DIR holds no cache to check.
"""

import pathlib
import struct
import sys

import bpy
import numpy as np

TOLERANCE = 1e-5


def read_pc2(path):
    data = path.read_bytes()
    magic, _version, points, _start, _rate, samples = struct.unpack("<12siiffi", data[:32])
    assert magic == b"POINTCACHE2\0", f"{path}: not a PC2 file"
    values = np.frombuffer(data[32:], dtype="<f4", count=samples * points * 3)
    return values.reshape(samples, points, 3).astype(np.float64)


def import_cache(path):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    if path.suffix == ".abc":
        bpy.ops.wm.alembic_import(filepath=str(path), as_background_job=False, set_frame_range=True)
    else:
        bpy.ops.wm.usd_import(filepath=str(path), set_frame_range=True)
    return [o for o in bpy.context.scene.objects if o.type == "MESH"]


def world_points(obj):
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    co = np.empty(len(mesh.vertices) * 3, dtype=np.float64)
    mesh.vertices.foreach_get("co", co)
    evaluated.to_mesh_clear()
    co = co.reshape(-1, 3)
    m = np.array(obj.matrix_world, dtype=np.float64)
    return co @ m[:3, :3].T + m[:3, 3]


def check(path, pc2):
    failures = []
    objects = import_cache(path)
    if len(objects) != 1:
        return [f"{len(objects)} mesh objects, expected 1"]
    obj = objects[0]
    scene = bpy.context.scene
    frames = pc2.shape[0]
    if (scene.frame_start, scene.frame_end) != (1, frames):
        failures.append(f"frame range {scene.frame_start}..{scene.frame_end}, expected 1..{frames}")
    worst = 0.0
    for frame in sorted({1, (frames + 1) // 2, frames}):
        scene.frame_set(frame)
        got = world_points(obj)
        p = pc2[frame - 1]
        want = np.stack([p[:, 0], -p[:, 2], p[:, 1]], axis=1)
        if got.shape != want.shape:
            failures.append(f"frame {frame}: {got.shape[0]} vertices, expected {want.shape[0]}")
            continue
        err = float(np.abs(got - want).max()) if len(want) else 0.0
        worst = max(worst, err)
        if err > TOLERANCE:
            failures.append(f"frame {frame}: max |blender - pc2| = {err:.3g} > {TOLERANCE}")
    if path.suffix == ".usdc":
        failures += check_velocities(obj, pc2, scene.render.fps)
    print(f"{path.name}: object {obj.name!r}, frames {scene.frame_start}..{scene.frame_end}, "
          f"max error {worst:.3g}")
    return failures


def check_velocities(obj, pc2, fps):
    """A moving point cache's `velocities` arrive as the mesh's `velocity` attribute: at the
    middle frame, the points' central difference per second (in world space, as the points)."""
    frames = pc2.shape[0]
    if frames < 3 or not np.abs(pc2[-1] - pc2[0]).max() > 0:
        return []
    frame = (frames + 1) // 2
    bpy.context.scene.frame_set(frame)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    attr = mesh.attributes.get("velocity")
    if attr is None:
        evaluated.to_mesh_clear()
        return [f"frame {frame}: no 'velocity' attribute after import"]
    v = np.empty(len(attr.data) * 3, dtype=np.float64)
    attr.data.foreach_get("vector", v)
    evaluated.to_mesh_clear()
    m = np.array(obj.matrix_world, dtype=np.float64)
    v = v.reshape(-1, 3) @ m[:3, :3].T
    d = (pc2[frame] - pc2[frame - 2]) * (fps / 2.0)
    want = np.stack([d[:, 0], -d[:, 2], d[:, 1]], axis=1)
    if v.shape != want.shape:
        return [f"frame {frame}: {v.shape[0]} velocities, expected {want.shape[0]}"]
    err = float(np.abs(v - want).max())
    scale = float(np.abs(want).max()) + 1e-9
    print(f"  velocity at frame {frame}: max |blender - motion| = {err:.3g} (max speed {scale:.3g})")
    if err > 1e-3 * scale:
        return [f"frame {frame}: velocities differ from the motion by {err:.3g}"]
    return []


def check_lines(path):
    """A motion-lines layer (`NAME_lines.usda`): Blender imports the BasisCurves prim as a
    curves object whose points change per frame, with the widths as the curves' radii."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.usd_import(filepath=str(path), set_frame_range=True)
    scene = bpy.context.scene
    curves = [o for o in scene.objects if o.type in ("CURVES", "CURVE")]
    if len(curves) != 1:
        kinds = sorted(o.type for o in scene.objects)
        return [f"{len(curves)} curves objects, expected 1 (objects: {kinds})"]
    obj = curves[0]
    counts, radii = [], []
    for frame in range(scene.frame_start, scene.frame_end + 1):
        scene.frame_set(frame)
        evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
        data = evaluated.data
        if obj.type == "CURVES":
            counts.append(len(data.points))
            if len(data.points) and "radius" in data.attributes:
                radii += [p.radius for p in data.points]
        else:
            points = [p for s in data.splines for p in s.points]
            counts.append(len(points))
            radii += [p.radius for p in points]
    print(f"{path.name}: {obj.type} object {obj.name!r}, points per frame {counts}")
    failures = []
    if not any(counts):
        failures.append("no curve point on any frame")
    if len(set(counts)) < 2:
        failures.append(f"the curves do not change from frame to frame: {counts}")
    if not radii or max(radii) <= 0:
        failures.append("the curves have no width")
    return failures


def main_lines(paths):
    failed = 0
    for path in paths:
        failures = check_lines(path.resolve())
        for f in failures:
            print(f"{path}: {f}")
        failed += bool(failures)
    print(f"Blender motion-lines import: {len(paths) - failed} passed, {failed} failed")
    return failed


def main():
    if len(sys.argv) != 2:
        print(__doc__.splitlines()[2])
        return 2
    root = pathlib.Path(sys.argv[1])
    caches = sorted(p for p in root.rglob("*") if p.suffix in (".abc", ".usdc")
                    and p.with_suffix(".pc2").exists())
    failed = 0
    for path in caches:
        failures = check(path.resolve(), read_pc2(path.with_suffix(".pc2")))
        for f in failures:
            print(f"{path}: {f}")
        failed += bool(failures)
    print(f"Blender cache import: {len(caches) - failed} passed, {failed} failed")
    lines = sorted(p for p in root.rglob("*_lines.usda"))
    failed += main_lines(lines)
    return 1 if failed or not caches else 0


if __name__ == "__main__":
    sys.exit(main())
