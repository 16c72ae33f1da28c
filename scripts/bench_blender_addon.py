"""The extension's smear bake beside the SMEAR authors' add-on, in one bpy process, on the
benchmark tube (docs/blender.md, "Speed"):

    python scripts/bench_blender_addon.py TUBE.glb EXTENSION.zip [ADDON_DIR] [RUNS]

TUBE.glb: `cargo run -p toonkit-smear --example write_tube -- TUBE.glb 40`; EXTENSION.zip:
`python blender/build.py`; ADDON_DIR: a checkout of the add-on (github.com/MoStyle/SMEAR;
never part of this repository), whose package directory is imported as `SMEAR`. Run with the
Python of a `bpy` venv. The add-on's bake is its operator body without the node-group setup
(it appends node groups from a .blend the timing does not need): the frame loop, its offsets
and their attribute writes. RUNS interleaved rounds of the extension's first bake (the
mesh's vertex weights read), its repeated bake (kept weights, as after an unbake) and the
add-on's bake, on the same mesh. Prints one JSON line with the median, least and CPU times
and their ratios.
"""

import importlib.util
import json
import os
import sys
import time

import bpy
import numpy as np


def tube(path):
    bpy.ops.wm.read_homefile(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=path)
    scene = bpy.context.scene
    arm = next(o for o in bpy.data.objects if o.type == "ARMATURE")
    first, last = arm.animation_data.action.frame_range
    scene.frame_start, scene.frame_end = int(first), int(last)
    mesh = next(o for o in bpy.data.objects if o.type == "MESH" and o.name != "Icosphere")
    for o in bpy.data.objects:
        o.select_set(False)
    mesh.select_set(True)
    bpy.context.view_layer.objects.active = mesh
    return mesh


def addon(path):
    spec = importlib.util.spec_from_file_location(
        "SMEAR", os.path.join(path, "__init__.py"), submodule_search_locations=[path])
    module = importlib.util.module_from_spec(spec)
    sys.modules["SMEAR"] = module
    spec.loader.exec_module(module)
    module.register()
    panel = sys.modules["SMEAR.smear_control_panel"]
    panel.BakeDeltasTrajectoriesOperator.appended_files = True  # no node-group .blend
    panel.set_node_tree = lambda *args: None
    return panel


def clock(bake):
    """Wall and process CPU time (every thread's) of one call of `bake`."""
    t, c = time.perf_counter(), time.process_time()
    bake()
    return time.perf_counter() - t, time.process_time() - c


def summary(times):
    """Median and least wall time, median CPU time, in seconds. On a shared machine the least
    wall time and the CPU time are the figures least disturbed by other processes; the CPU
    time of a parallel bake bounds an idle machine's wall time from above."""
    wall = [w for w, _ in times]
    return (round(float(np.median(wall)), 4), round(min(wall), 4),
            round(float(np.median([c for _, c in times])), 4))


def main():
    path, zip_path = sys.argv[1], sys.argv[2]
    addon_dir = sys.argv[3] if len(sys.argv) > 3 else None
    runs = int(sys.argv[4]) if len(sys.argv) > 4 else 5
    r = bpy.ops.extensions.package_install_files(filepath=os.path.abspath(zip_path),
                                                 repo="user_default", enable_on_install=True)
    assert r == {"FINISHED"}, r
    from bl_ext.user_default.toonkit import weights

    addon_error = None
    if addon_dir:
        addon(addon_dir)
    mesh = tube(path)

    def select():
        for o in bpy.data.objects:
            o.select_set(False)
        mesh.select_set(True)
        bpy.context.view_layer.objects.active = mesh

    def ours(first):
        bpy.ops.toonkit.smear_unbake()  # a bake hides its original
        select()
        if first:  # as on a first bake of the mesh: its vertex weights are read
            weights.forget()
        return clock(lambda: bpy.ops.toonkit.smear_bake())

    def theirs():
        bpy.ops.toonkit.smear_unbake()
        select()
        # Each add-on bake writes its attributes anew (no earlier bake's to overwrite).
        for name in [a.name for a in mesh.data.attributes if a.name.startswith("delta_")]:
            mesh.data.attributes.remove(mesh.data.attributes[name])
        t = clock(lambda: bpy.ops.scene.bake_deltas_and_trajectories())
        written = [a.name for a in mesh.data.attributes if a.name.startswith("delta_")]
        frames = bpy.context.scene.frame_end - bpy.context.scene.frame_start + 1
        assert len(written) == frames, f"the add-on wrote {len(written)} frames"
        for name in written:  # our bakes copy the mesh: leave it as it was
            mesh.data.attributes.remove(mesh.data.attributes[name])
        return t

    # Interleaved rounds (first bake, repeated bake, the add-on's) after one warm-up round,
    # so that a busy machine slows all three alike.
    first, repeated, addon_times = [], [], []
    for i in range(runs + 1):
        a, b = ours(True), ours(False)
        c = None
        if addon_dir and addon_error is None:
            try:
                c = theirs()
            except RuntimeError as e:  # e.g. Blender 5.0, whose actions have no `fcurves`
                lines = [ln for ln in str(e).splitlines() if "Error" in ln]
                addon_error = lines[-1].strip() if lines else str(e)
        if i > 0:
            first.append(a)
            repeated.append(b)
            if c is not None:
                addon_times.append(c)
    bpy.ops.toonkit.smear_unbake()
    figures = {"blender": bpy.app.version_string, "vertices": len(mesh.data.vertices),
               "frames": bpy.context.scene.frame_end - bpy.context.scene.frame_start + 1}
    for label, times in (("first_bake", first), ("repeated_bake", repeated)):
        wall, least, cpu = summary(times)
        figures.update({f"{label}_s": wall, f"{label}_min_s": least, f"{label}_cpu_s": cpu})
    if addon_error is not None:
        figures["addon_error"] = addon_error
    elif addon_times:
        wall, least, cpu = summary(addon_times)
        figures.update(addon_bake_s=wall, addon_bake_min_s=least, addon_bake_cpu_s=cpu)
        for label in ("first_bake", "repeated_bake"):
            figures[f"ratio_{label}"] = round(wall / figures[f"{label}_s"], 1)
            figures[f"ratio_{label}_min"] = round(least / figures[f"{label}_min_s"], 1)
            figures[f"ratio_{label}_cpu"] = round(cpu / figures[f"{label}_cpu_s"], 1)
    figures["load_average"] = os.getloadavg()[0]
    print(json.dumps(figures), flush=True)


if __name__ == "__main__":
    main()
    os._exit(0)  # bpy's interpreter teardown can crash after a headless run
