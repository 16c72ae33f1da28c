"""Headless tests of Blender's USD importer on toonkit's USD smears, on real Blender via `bpy`:

    python blender/tests/test_usd.py dist/toonkit-<version>-<platform>.zip [OUT_DIR]

The files are written by the toonkit CLI the build made (`$TOONKIT_BIN`, default
`target/debug/toonkit`), then imported with `bpy.ops.wm.usd_import` as a user would:
- motion lines (`smear lines -o x.usda`, a `BasisCurves` prim) arrive as one curves object
  whose point count at every frame is the file's (the sum of `curveVertexCounts`);
- a smear's `velocities` arrive as the mesh's `velocity` attribute, equal to the file's
  (after Blender's Y-up to Z-up turn), on a point cache and on a subdivided smear whose
  vertex count changes per frame.
The extension zip is accepted like the other Blender tests but not needed: the importer is
Blender's own.
"""

import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from harness import REPO, ASSETS, argv_after_dashes, check, run, tmpdir  # noqa: E402

ARGS = argv_after_dashes()
OUT = os.path.abspath(ARGS[1]) if len(ARGS) > 1 else tmpdir()
os.makedirs(OUT, exist_ok=True)
TOONKIT = os.environ.get("TOONKIT_BIN", os.path.join(REPO, "target", "debug", "toonkit"))
CESIUM = os.path.join(ASSETS, "CesiumMan.glb")


def toonkit(*args):
    subprocess.run([TOONKIT, *args], check=True, stdout=subprocess.DEVNULL)


def time_samples(text, prim, decl):
    """The `decl.timeSamples` of the prim `prim` in a `.usda` text: {time code: value text}."""
    start = text.index(f'"{prim}"')
    head = f"{decl}.timeSamples = {{\n"
    body = text[text.index(head, start) + len(head):]
    body = body[:body.index("\n        }")]
    out = {}
    for line in body.splitlines():
        t, value = line.split(": ", 1)
        out[float(t)] = value.rstrip(",")
    return out


def vectors(value):
    """`[(x, y, z), ...]` as an (n, 3) array."""
    numbers = re.findall(r"[-+0-9.eE]+(?:inf|nan)?", value)
    return np.array([float(x) for x in numbers], np.float64).reshape(-1, 3)


def import_usd(path):
    bpy.ops.wm.read_homefile(use_empty=True)
    bpy.ops.wm.usd_import(filepath=path, set_frame_range=True)
    return bpy.context.scene


def curve_points(obj):
    """Points of a curves object (new `CURVES` or legacy `CURVE`) as evaluated now."""
    data = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
    if obj.type == "CURVES":
        return len(data.points)
    return sum(len(s.points) for s in data.splines)


def test_motion_lines_import_as_curves_with_the_files_point_counts():
    path = os.path.join(OUT, "cesium_lines.usda")
    toonkit("smear", "lines", CESIUM, "--count", "0:0,8:30", "--length-max", "4", "-o", path)
    text = open(path).read()
    counts = time_samples(text, "motion_lines", "int[] curveVertexCounts")
    want = {t: sum(int(c) for c in re.findall(r"\d+", v)) for t, v in counts.items()}
    scene = import_usd(path)
    curves = [o for o in scene.objects if o.type in ("CURVES", "CURVE")]
    check(len(curves) == 1, f"{len(curves)} curves objects: {[o.type for o in scene.objects]}")
    got = {}
    for frame in range(scene.frame_start, scene.frame_end + 1):
        scene.frame_set(frame)
        got[float(frame)] = curve_points(curves[0])
    print(f"  Blender {bpy.app.version_string}: {curves[0].type} object, points per frame "
          f"{[got[t] for t in sorted(got)]}")
    check(max(want.values()) > 2, f"the file has no motion line: {want}")
    for t, n in want.items():
        check(got.get(t) == n, f"frame {t:g}: {got.get(t)} curve points, the file has {n}")


def velocity_check(path, prim):
    """Imports `path`; at three frames, the `velocity` attribute of the mesh `prim` equals
    the file's `velocities` (per second, Y-up turned Z-up as the points)."""
    text = open(path).read()
    velocities = time_samples(text, prim, "vector3f[] velocities")
    scene = import_usd(path)
    obj = next(o for o in scene.objects if o.type == "MESH" and o.name.startswith(prim))
    frames = sorted(velocities)
    checked = []
    for t in (frames[1], frames[len(frames) // 2], frames[-2]):
        scene.frame_set(int(t))
        ev = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
        mesh = ev.to_mesh()
        try:
            attr = mesh.attributes.get("velocity")
            check(attr is not None, f"frame {t:g}: no 'velocity' attribute after import "
                  f"(attributes: {sorted(a.name for a in mesh.attributes)})")
            v = np.empty(len(attr.data) * 3, np.float64)
            attr.data.foreach_get("vector", v)
            n = len(mesh.vertices)
        finally:
            ev.to_mesh_clear()
        m = np.array(obj.matrix_world, np.float64)
        v = v.reshape(-1, 3) @ m[:3, :3].T
        f = vectors(velocities[t])
        want = np.stack([f[:, 0], -f[:, 2], f[:, 1]], axis=1)
        check(v.shape == want.shape, f"frame {t:g}: {v.shape[0]} velocities for {n} "
              f"vertices, the file has {want.shape[0]}")
        err = float(np.abs(v - want).max())
        check(err <= 1e-4 * (1.0 + np.abs(want).max()), f"frame {t:g}: off by {err:.3g}")
        checked.append(n)
    return checked


def test_velocities_of_a_point_cache_and_of_a_subdivided_smear():
    plain = os.path.join(OUT, "cesium_smear.usda")
    toonkit("smear", "elongate", CESIUM, "--beta-max", "3", "-o", plain)
    sub = os.path.join(OUT, "cesium_subdivided.usda")
    toonkit("smear", "elongate", CESIUM, "--beta-max", "3", "--subdivide", "2", "-o", sub)
    n_plain = velocity_check(plain, "CesiumMan")
    n_sub = velocity_check(sub, "CesiumMan")
    print(f"  Blender {bpy.app.version_string}: velocity on {n_plain} (point cache) and "
          f"{n_sub} (subdivided) vertices")
    check(len(set(n_plain)) == 1, f"a point cache keeps its vertices: {n_plain}")
    check(max(n_sub) > n_plain[0], f"nothing was subdivided: {n_sub}")


if __name__ == "__main__":
    sys.exit(run([
        test_motion_lines_import_as_curves_with_the_files_point_counts,
        test_velocities_of_a_point_cache_and_of_a_subdivided_smear,
    ]))
