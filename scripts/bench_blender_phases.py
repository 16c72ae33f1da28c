"""Where the extension's smear bake spends its time, phase by phase, in one bpy process on the
benchmark tube (docs/blender.md, "Speed"):

    python scripts/bench_blender_phases.py TUBE.glb EXTENSION.zip [RUNS] [first|repeated]

TUBE.glb: `cargo run -p toonkit-smear --example write_tube -- TUBE.glb 40`; EXTENSION.zip:
`python blender/build.py`. Run with the Python of a `bpy` venv. Wraps the extension's sampling,
transfer, core and write-back functions with timers (process CPU time of every thread, and wall
time), bakes RUNS times after two warm-up bakes and prints the median bake and each phase's
time per bake, largest first. Nested phases are included in their callers' times. `first`
(the default) forgets the vertex weights the extension keeps per mesh before each bake, as
on a first bake of the mesh; `repeated` keeps them, as on a bake after an unbake or a restyle
without an edit of the mesh.
"""

import functools
import os
import sys
import time
import types

import bpy
import numpy as np

TIMES = {}


def timed(label, f):
    @functools.wraps(f)
    def g(*args, **kwargs):
        c, t = time.process_time(), time.perf_counter()
        try:
            return f(*args, **kwargs)
        finally:
            d = TIMES.setdefault(label, [0.0, 0.0, 0])
            d[0] += time.process_time() - c
            d[1] += time.perf_counter() - t
            d[2] += 1
    return g


def wrap(owner, name, label):
    if hasattr(owner, name):  # an older extension may not have it (A/B runs)
        setattr(owner, name, timed(label, getattr(owner, name)))


def instrument():
    import toonkit
    from bl_ext.user_default.toonkit import job, results, sample, weights

    wrap(weights, "read_all", "sample: vertex weights (kept or read)")
    wrap(weights, "_read_nodes", "sample: vertex weights read (Geometry Nodes)")
    wrap(weights, "_read", "sample: vertex weights read (per vertex)")
    for name, label in (("sample", "sample (all of it)"),
                        ("_rest_matrices", "sample: rest pose matrices"),
                        ("_rest_positions", "sample: rest positions"),
                        ("_skin_and_attributes", "sample: SMEAR skin + attributes"),
                        ("_positions", "sample: skinning (all)")):
        wrap(sample, name, label)
    wrap(sample._Pose, "read", "sample: bone/object matrices per frame")
    wrap(sample._Pose, "first_frame", "sample: triangles + modifiers off")
    wrap(sample._Pose, "mute_early", "sample: own triangles + modifiers off")
    wrap(sample._Pose, "start", "sample: skinning inputs (before the frames)")
    wrap(sample._Pose, "frames_read", "sample: skinning matrices per chunk (+ push)")
    wrap(toonkit, "skin", "sample: toonkit.skin (core)")
    wrap(toonkit.smear, "prepare", "toonkit.smear.prepare (core offsets)")
    wrap(job, "_stylize", "toonkit.smear.stylize (frame on screen)")
    wrap(job, "_show", "result objects + write-back")
    wrap(job, "_bodies", "result bodies (first: while the core prepares)")
    wrap(job, "_result", "waiting for the prepared offsets")
    wrap(results, "node_group", "result: node group")
    wrap(results, "write_frames", "result: write frames")
    from_arrays = timed("Scene.from_arrays (transfer)", toonkit.Scene.from_arrays)
    proxy = types.SimpleNamespace(Scene=types.SimpleNamespace(from_arrays=from_arrays),
                                  smear=toonkit.smear, ToonkitError=toonkit.ToonkitError)
    job._toonkit = lambda: proxy


def main():
    path, zip_path = sys.argv[1], sys.argv[2]
    runs = int(sys.argv[3]) if len(sys.argv) > 3 else 10
    fresh = (sys.argv[4] if len(sys.argv) > 4 else "first") == "first"
    r = bpy.ops.extensions.package_install_files(filepath=os.path.abspath(zip_path),
                                                 repo="user_default", enable_on_install=True)
    assert r == {"FINISHED"}, r
    instrument()
    bpy.ops.wm.read_homefile(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=path)
    scene = bpy.context.scene
    arm = next(o for o in bpy.data.objects if o.type == "ARMATURE")
    first, last = arm.animation_data.action.frame_range
    scene.frame_start, scene.frame_end = int(first), int(last)
    mesh = next(o for o in bpy.data.objects if o.type == "MESH" and o.name != "Icosphere")
    bakes = []
    for i in range(runs + 2):
        if i == 2:
            TIMES.clear()
        bpy.ops.toonkit.smear_unbake()  # a bake hides its original
        for o in bpy.data.objects:
            o.select_set(False)
        mesh.select_set(True)
        bpy.context.view_layer.objects.active = mesh
        if fresh:
            from bl_ext.user_default.toonkit import weights
            weights.forget()
        c, t = time.process_time(), time.perf_counter()
        bpy.ops.toonkit.smear_bake()
        if i >= 2:
            bakes.append((time.process_time() - c, time.perf_counter() - t))
    print(f"{'first' if fresh else 'repeated'} bake ({bpy.app.version_string}, "
          f"{len(mesh.data.vertices)} vertices, {scene.frame_end - scene.frame_start + 1} frames): median CPU "
          f"{1000 * np.median([c for c, _ in bakes]):.1f} ms, wall "
          f"{1000 * np.median([w for _, w in bakes]):.1f} ms (least "
          f"{1000 * min(w for _, w in bakes):.1f}), load average {os.getloadavg()[0]:.1f}")
    for label, (c, w, n) in sorted(TIMES.items(), key=lambda kv: -kv[1][0]):
        print(f"  {label:42s} CPU {1000 * c / runs:6.2f} ms  wall {1000 * w / runs:6.2f} ms"
              f"  ({n / runs:.0f} calls)")


if __name__ == "__main__":
    main()
    os._exit(0)  # bpy's interpreter teardown can crash after a headless run
