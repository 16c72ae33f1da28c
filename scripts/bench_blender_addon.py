"""The extension's smear bake beside the SMEAR authors' add-on, in one bpy process, on the
benchmark tube (docs/blender.md, "Speed"):

    python scripts/bench_blender_addon.py TUBE.glb EXTENSION.zip [ADDON_DIR] [RUNS]

TUBE.glb: `cargo run -p toonkit-smear --example write_tube -- TUBE.glb 40`; EXTENSION.zip:
`python blender/build.py`; ADDON_DIR: a checkout of the add-on (github.com/MoStyle/SMEAR;
never part of this repository), whose package directory is imported as `SMEAR`. Run with the
Python of a `bpy` venv. The add-on's bake is its operator body without the node-group setup
(it appends node groups from a .blend the timing does not need): the frame loop, its offsets
and their attribute writes. Prints one JSON line with the median, least and CPU times and
their ratios.
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


def timed(bake, runs, before=lambda: None):
    """Median and least wall time, and median process CPU time (every thread's), of `runs`
    calls of `bake`. On a shared machine the least wall time and the CPU time are the figures
    least disturbed by other processes; the CPU time of a parallel bake bounds an idle
    machine's wall time from above."""
    times, cpu = [], []
    for _ in range(runs):
        before()
        t, c = time.perf_counter(), time.process_time()
        bake()
        times.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
    return float(np.median(times)), float(min(times)), float(np.median(cpu))


def main():
    path, zip_path = sys.argv[1], sys.argv[2]
    addon_dir = sys.argv[3] if len(sys.argv) > 3 else None
    runs = int(sys.argv[4]) if len(sys.argv) > 4 else 5
    r = bpy.ops.extensions.package_install_files(filepath=os.path.abspath(zip_path),
                                                 repo="user_default", enable_on_install=True)
    assert r == {"FINISHED"}, r
    mesh = tube(path)
    def unbaked():  # a bake hides its original: unbake and select it again
        bpy.ops.toonkit.smear_unbake()
        mesh.select_set(True)

    ours = timed(lambda: bpy.ops.toonkit.smear_bake(), runs, unbaked)
    bpy.ops.toonkit.smear_unbake()
    figures = {"blender": bpy.app.version_string, "vertices": len(mesh.data.vertices),
               "frames": bpy.context.scene.frame_end - bpy.context.scene.frame_start + 1,
               "extension_bake_s": round(ours[0], 4), "extension_bake_min_s": round(ours[1], 4),
               "extension_bake_cpu_s": round(ours[2], 4)}
    if addon_dir:
        addon(addon_dir)
        mesh = tube(path)
        try:
            theirs = timed(lambda: bpy.ops.scene.bake_deltas_and_trajectories(), runs)
        except RuntimeError as e:  # e.g. Blender 5.0, whose actions have no `fcurves`
            lines = [ln for ln in str(e).splitlines() if "Error" in ln]
            figures["addon_error"] = lines[-1].strip() if lines else str(e)
            print(json.dumps(figures), flush=True)
            return
        check = [a.name for a in mesh.data.attributes if a.name.startswith("delta_")]
        assert len(check) == figures["frames"], f"the add-on wrote {len(check)} frames"
        figures.update(addon_bake_s=round(theirs[0], 4), addon_bake_min_s=round(theirs[1], 4),
                       addon_bake_cpu_s=round(theirs[2], 4),
                       ratio=round(theirs[0] / ours[0], 1), ratio_min=round(theirs[1] / ours[1], 1),
                       ratio_cpu=round(theirs[2] / ours[2], 1))
    figures["load_average"] = os.getloadavg()[0]
    print(json.dumps(figures), flush=True)


if __name__ == "__main__":
    main()
    os._exit(0)  # bpy's interpreter teardown can crash after a headless run
