"""A tiny headless test harness for bpy: install the extension zip, run test functions,
print one PASS/FAIL line each and exit non-zero on any failure."""

import os
import sys
import tempfile
import time
import traceback

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ASSETS = os.path.join(REPO, "assets", "characters")


def start():
    """The command line's zip installed (`install`) and output folder made: (toonkit, OUT)."""
    args = argv_after_dashes()
    out = os.path.abspath(args[1]) if len(args) > 1 else tmpdir()
    os.makedirs(out, exist_ok=True)
    return install(os.path.abspath(args[0])), out


def install(zip_path):
    """Installs and enables the extension zip as a user would (Install from Disk)."""
    import bpy

    result = bpy.ops.extensions.package_install_files(
        filepath=zip_path, repo="user_default", enable_on_install=True)
    assert result == {"FINISHED"}, f"package_install_files returned {result}"
    assert hasattr(bpy.ops.toonkit, "smear_bake"), "the toonkit operators are not registered"
    import toonkit  # the bundled wheel

    return toonkit


def empty_scene():
    import bpy

    bpy.ops.wm.read_homefile(use_empty=True)
    return bpy.context.scene


def world_positions(obj, frame=None):
    """The evaluated world-space vertices of `obj` (at `frame` if given)."""
    import bpy

    if frame is not None:
        bpy.context.scene.frame_set(frame)
    dg = bpy.context.evaluated_depsgraph_get()
    ev = obj.evaluated_get(dg)
    mesh = ev.to_mesh()
    try:
        co = np.empty(len(mesh.vertices) * 3, np.float32)
        mesh.vertices.foreach_get("co", co)
        m = np.array(ev.matrix_world, np.float64)
        return (co.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3]).astype(np.float32)
    finally:
        ev.to_mesh_clear()


def attribute(obj, name, dtype, frame=None):
    """The evaluated per-vertex attribute `name` of `obj` as a `dtype` array (at `frame` if
    given)."""
    import bpy

    if frame is not None:
        bpy.context.scene.frame_set(frame)
    dg = bpy.context.evaluated_depsgraph_get()
    ev = obj.evaluated_get(dg)
    mesh = ev.to_mesh()
    try:
        values = np.empty(len(mesh.vertices), dtype)
        mesh.attributes[name].data.foreach_get("value", values)
        return values
    finally:
        ev.to_mesh_clear()


def run(tests):
    only = os.environ.get("TOONKIT_TESTS")  # comma-separated names: run only those
    if only:
        tests = [t for t in tests if t.__name__ in only.split(",")]
    failed = 0
    for t in tests:
        start = time.perf_counter()
        try:
            t()
            status = "PASS"
        except Exception:  # noqa: BLE001 - report every failure and go on
            failed += 1
            status = "FAIL"
            traceback.print_exc()
        print(f"{status} {t.__name__} ({time.perf_counter() - start:.1f} s)", flush=True)
    print(f"blender: {len(tests) - failed} passed, {failed} failed", flush=True)
    return 1 if failed else 0


def finish(code, report, out):
    """Writes `report` to `out`/report.json and prints it (CI reads the line), then exits
    with `code` at once: bpy's interpreter teardown can crash after a headless run."""
    import json

    with open(os.path.join(out, "report.json"), "w") as f:
        json.dump(report, f, indent=1)
    print("blender report:", json.dumps(report), flush=True)
    os._exit(code)


def tmpdir():
    return tempfile.mkdtemp(prefix="toonkit-blender-")


def check(cond, message):
    if not cond:
        raise AssertionError(message)


def read_pc2(path):
    """(frames, points, 3) float32 of a PC2 point cache (as the CLI writes it)."""
    data = open(path, "rb").read()
    check(data[:12] == b"POINTCACHE2\0", f"{path}: not a PC2 file")
    points, _, _, frames = np.frombuffer(data[16:32], "<i4,<f4,<f4,<i4")[0]
    return np.frombuffer(data, "<f4", offset=32).reshape(frames, points, 3)


def rel(a, b, diag):
    return float(np.abs(np.asarray(a, np.float64) - np.asarray(b, np.float64)).max() / diag)


def argv_after_dashes():
    return sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
