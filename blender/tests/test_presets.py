"""Every named smear preset means the same smear in Blender as in the CLI, on real Blender via
`bpy`:

    python blender/tests/test_presets.py dist/toonkit-<version>-<platform>.zip [OUT_DIR]

For the bundled CesiumMan, RobotExpressive (its first clip, Dance) and the benchmark tube, the
panel's presets with one β max and κ are baked once and restyled (`smear_update`), and every
frame's evaluated result is compared with `toonkit smear elongate FILE --preset P --beta-max B
--kappa K` of the CLI built from the same tree (`$TOONKIT_CLI`, else `target/debug/toonkit`):
within 1 % of the bounding-box diagonal (Blender samples its own evaluated meshes; the CLI
samples the file, which crates/python/tests/test_gltf_spec.py checks against an independent
reading of the glTF; measured on the robot: ≤ 0.03 %). The panel's defaults are the CLI's
(`toonkit smear elongate --help`).

The robot is imported with the importer's "Bone Dir" set to Temperance (or Fortune): with the
default ("Blender") the importer shortens every bone by the armature's scale (100 here) but
still pulls the parts parented to a bone back by the unshortened length, so the robot's arms,
shoulders, legs, feet, torso and head sit 0.57-0.65 units (6.7-7.8 % of its 8.438 size) from
where the file puts them, in every frame and at rest, and its size is 8.132 (docs/blender.md,
"Importing glTF characters"). `test_the_robots_bone_parented_parts_follow_the_bone_heuristic`
measures both imports.
"""

import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
os.environ.setdefault("BLENDER_USER_RESOURCES", os.path.join(
    os.environ.get("TMPDIR", "/tmp"), f"toonkit-blender-user-{os.getpid()}"))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from harness import (ASSETS, REPO, check, empty_scene, finish, read_pc2, run, start,  # noqa: E402
                     tmpdir, world_positions)

toonkit, OUT = start()
CLI = os.environ.get("TOONKIT_CLI") or os.path.join(REPO, "target", "debug", "toonkit")
#: Non-default parameters, so a front end that dropped one would disagree.
BETA_MAX, KAPPA = 4.0, 12.0
#: The acceptance bound: Blender's result within 1 % of the bounding-box diagonal of the CLI's.
TOL = 0.01
REPORT = {"blender": bpy.app.version_string, "beta_max": BETA_MAX, "kappa": KAPPA}
#: glTF is Y-up, Blender Z-up: the importer's axis change, (x, y, z) -> (x, -z, y).
GLTF_TO_BLENDER = np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]], np.float64)


def cli(*args):
    out = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True, cwd=REPO)
    check(out.returncode == 0, f"toonkit {args}: {out.stderr}")
    return out.stdout


def character(path, clip=None, bone_heuristic="BLENDER"):
    """Imports `file` with the importer's `bone_heuristic` ("Bone Dir"), puts `clip` (an
    action name prefix) on its objects and selects its meshes (without the importer's bone
    shape); returns the meshes and the action's first frame."""
    empty_scene()
    bpy.ops.import_scene.gltf(filepath=path, bone_heuristic=bone_heuristic)
    for o in bpy.data.objects:
        ad = o.animation_data or (o.data.shape_keys.animation_data
                                  if o.type == "MESH" and o.data.shape_keys else None)
        if clip and ad is not None and f"{clip}_{o.name}" in bpy.data.actions:
            ad.action = bpy.data.actions[f"{clip}_{o.name}"]
    arm = next(o for o in bpy.data.objects if o.type == "ARMATURE")
    meshes = [o for o in bpy.data.objects if o.type == "MESH" and o.name != "Icosphere"]
    for o in bpy.data.objects:
        o.select_set(o in meshes)
    bpy.context.view_layer.objects.active = meshes[0]
    return meshes, int(arm.animation_data.action.frame_range[0])


def frames_of(objs, frames):
    """The world positions of `objs` at each of `frames` (one frame change per frame: the
    robot has 20 objects)."""
    out = []
    for f in frames:
        bpy.context.scene.frame_set(f)
        out.append(np.concatenate([world_positions(o) for o in objs]))
    return np.stack(out)


def nearest(a, b):
    """For each row of `a`, the index of the nearest row of `b`, and the largest such distance."""
    b2 = (b * b).sum(1)
    index, worst = np.empty(len(a), np.int64), 0.0
    for start in range(0, len(a), 512):
        chunk = a[start:start + 512]
        d = (chunk * chunk).sum(1)[:, None] - 2.0 * chunk @ b.T + b2[None, :]
        index[start:start + 512] = d.argmin(1)
        worst = max(worst, float(np.sqrt(max(d.min(1).max(), 0.0))))
    return index, worst


def align(meshes, first, file_positions, diag, file_objects=()):
    """The scene frames that show the file's sampled frames, and for each of Blender's vertices
    the file's vertex: the same vertex of the object of the same name when the importer kept
    each object's vertex order (`file_objects`: the core's (name, range) list), else the one
    with the same unsmeared trajectory (nearest over three frames, so coincident vertices of
    parts that move apart stay apart; coincident vertices of one part, a seam, may be swapped):
    the importer maps key times to frames and may split and order vertices its own way."""
    n = len(file_positions)
    keys = [0, n // 2, n - 1]
    file_keys = np.concatenate([file_positions[k] @ GLTF_TO_BLENDER.T for k in keys], axis=1)
    def seen(start):
        return np.concatenate(list(frames_of(meshes, [start + k for k in keys])), axis=1)

    some = slice(None, None, max(1, len(file_keys) // 256))  # enough to tell the frames apart
    start = min(range(first - 2, first + 3),
                key=lambda f: nearest(seen(f)[some].astype(np.float64), file_keys)[1])
    mine = seen(start).astype(np.float64)
    ranges = dict(file_objects)
    orders = []
    if all(o.name in ranges for o in meshes):  # each object in the file's own order
        orders.append(np.concatenate([np.arange(ranges[o.name].start, ranges[o.name].stop)
                                      for o in meshes]))
    if mine.shape == file_keys.shape:  # the file's own order, when the importer kept it
        orders.append(np.arange(len(mine)))
    for index in orders:
        if len(index) == len(mine) and \
                float(np.abs(mine - file_keys[index]).max()) <= 1e-4 * diag:
            return range(start, start + n), index
    index, fit = nearest(mine, file_keys)
    check(fit <= 1e-4 * diag, f"Blender's vertices are not the file's ({fit / diag:.2e} of the "
                              "diagonal apart at best)")
    return range(start, start + n), index


def agree(path, clip, name, bone_heuristic="BLENDER"):
    """Every preset on one character: Blender's bake and restyles against the CLI's caches."""
    args = [path, *(["--clip", clip] if clip else [])]
    meshes, first = character(path, clip, bone_heuristic)
    loaded = toonkit.load(args[0], clip=clip)  # the file's sampling, only to align frames
    diag = float(np.linalg.norm(np.ptp(loaded.positions[0], axis=0)))
    frames, index = align(meshes, first, loaded.positions, diag, loaded.objects)
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = frames.start, frames.stop - 1
    originals = frames_of(meshes, frames)
    r = bpy.ops.toonkit.smear_bake()
    check(r == {"FINISHED"}, f"smear_bake returned {r}")
    bodies = [bpy.data.objects[f"{o.name} smear"] for o in meshes]
    s = scene.toonkit_smear
    s.live = False
    s.beta_max, s.kappa, s.sign = BETA_MAX, KAPPA, "PRESET"
    REPORT[name] = {"frames": [frames.start, frames.stop - 1], "vertices":
                    [originals.shape[1], loaded.positions.shape[1]], "diagonal": diag}
    out = tmpdir()
    for preset in [p["name"] for p in toonkit.smear.presets()]:
        s.preset = preset.upper()
        r = bpy.ops.toonkit.smear_update()
        check(r == {"FINISHED"}, f"smear_update returned {r}")
        path = os.path.join(out, f"{preset}.pc2")
        cli("smear", "elongate", *args, "--preset", preset, "--beta-max", BETA_MAX,
            "--kappa", KAPPA, "-o", path)
        want = read_pc2(path)[:, index] @ GLTF_TO_BLENDER.T
        got = frames_of(bodies, frames)
        moved = float(np.abs(want - originals).max()) / diag
        error = float(np.abs(got - want).max()) / diag
        REPORT[name][preset] = {"error": error, "largest_elongation": moved}
        print(f"agreement: {name} {preset}: Blender vs CLI {100 * error:.3f} % of the diagonal "
              f"(the smear moves vertices up to {100 * moved:.1f} %)", flush=True)
        check(moved > 0.01, f"{name} {preset}: the CLI's smear moves nothing")
        check(error <= TOL, f"{name} {preset}: Blender differs from the CLI by "
                            f"{100 * error:.2f} % of the diagonal (tolerance 1 %)")


def test_every_preset_on_cesium_man_as_the_cli():
    agree(os.path.join(ASSETS, "CesiumMan.glb"), None, "cesium_man")


def test_every_preset_on_the_robot_as_the_cli():
    """RobotExpressive's first clip (Dance, the one the importer leaves on the armature; a clip
    assigned afterwards keeps the last evaluated values of every channel it does not key,
    docs/blender.md), imported with the Temperance bone heuristic."""
    agree(os.path.join(ASSETS, "RobotExpressive.glb"), None, "robot", "TEMPERANCE")


def test_the_robots_bone_parented_parts_follow_the_bone_heuristic():
    """What the extension samples of RobotExpressive (every frame of Dance, and the rest pose
    its size unit is measured on) against the core's sampling of the file, part by part, for
    both bone heuristics: Temperance gives the file's geometry; the default ("Blender") moves
    every part parented to a bone along that bone by 99 % of the length the importer picked
    for it (the bone is drawn 100× shorter, the armature's scale), and leaves the skinned
    hands where the file puts them (docs/blender.md, "Importing glTF characters")."""
    from bl_ext.user_default.toonkit import sample

    path = os.path.join(ASSETS, "RobotExpressive.glb")
    loaded = toonkit.load(path)
    diag = float(np.linalg.norm(np.ptp(loaded.positions[0], axis=0)))
    frames = index = None
    REPORT["robot_import"] = measured = {}
    for heuristic in ("TEMPERANCE", "BLENDER"):
        meshes, first = character(path, None, heuristic)
        if index is None:  # the Temperance import is the file's: it gives the vertex order
            frames, index = align(meshes, first, loaded.positions, diag, loaded.objects)
        scene = bpy.context.scene
        scene.frame_start, scene.frame_end = frames.start, frames.stop - 1
        s = sample.sample(bpy.context, meshes)
        want = loaded.positions[:, index] @ GLTF_TO_BLENDER.T
        size = float(np.linalg.norm(np.ptp(s.rest, axis=0)))
        parts = {}
        for name, r in zip(s.names, s.ranges):
            offset = s.positions[:, r.start:r.stop].astype(np.float64) - want[:, r.start:r.stop]
            d = np.linalg.norm(offset, axis=2)
            # How far the part is from a rigid translation of the file's (per frame).
            spread = float(np.abs(offset - offset.mean(axis=1, keepdims=True)).max())
            parts[name] = {"max": float(d.max()), "mean": float(d.mean()), "spread": spread}
        measured[heuristic] = {"size": size, "core_size": loaded.size, "parts": parts}
        worst = max(p["max"] for p in parts.values())
        print(f"robot imported with bone heuristic {heuristic}: size {size:.4f} (core "
              f"{loaded.size:.4f}); worst part {worst:.3g} units ({100 * worst / loaded.size:.2f}"
              " % of the size); per part max/mean: " + ", ".join(
                  f"{n} {p['max']:.3g}/{p['mean']:.3g}" for n, p in sorted(parts.items())),
              flush=True)
        skinned = {o.name for o in meshes if sample.armature_of(o) is not None}
        on_bones = {o.name for o in meshes if sample._bone_parent(o)[0] is not None}
        check(skinned and on_bones, f"skinned {skinned}, on bones {on_bones}")
        for name, p in parts.items():
            if heuristic == "TEMPERANCE" or name in skinned:
                check(p["max"] <= 1e-5 * diag, f"{heuristic}: {name} is {p['max']:.2e} from "
                                               "the file")
            elif name in on_bones:
                check(p["max"] > 0.05 * diag and p["spread"] <= 1e-5 * diag,
                      f"{heuristic}: {name} is not the documented offset along its bone: {p}")
        if heuristic == "TEMPERANCE":
            check(abs(size - loaded.size) <= 1e-5 * loaded.size,
                  f"Temperance: rest size {size:.6f} vs the core's {loaded.size:.6f}")
        else:
            check(size < 0.98 * loaded.size, f"Blender heuristic: rest size {size:.4f} vs the "
                                             f"core's {loaded.size:.4f}")


def test_every_preset_on_the_benchmark_tube_as_the_cli():
    """The benchmark tube (15,002 vertices skinned to a 10-bone chain), which .ci/blender.sh
    writes with the smear crate's `write_tube` example."""
    tube = os.environ.get("TOONKIT_TUBE")
    if not tube:
        tube = os.path.join(tmpdir(), "tube.glb")
        subprocess.run([os.path.join(REPO, "target", "debug", "examples", "write_tube"), tube,
                        "40"], check=True, capture_output=True)
    agree(tube, None, "tube")


def test_the_panel_defaults_are_the_clis():
    empty_scene()
    s = bpy.context.scene.toonkit_smear
    help_text = " ".join(cli("smear", "elongate", "--help").split())
    for flag, value in (("--beta-max", s.beta_max), ("--kappa", s.kappa),
                        ("--smooth", s.smooth)):
        shown = re.search(rf"{flag} <\w+>[^\[]*\[default: ([^\]]+)\]", help_text)
        check(shown and float(shown.group(1)) == value,
              f"panel {flag} {value} vs the CLI's {shown and shown.group(1)}")
    shown = re.search(r"--preset <\w+>[^\[]*\[default: ([^\]]+)\]", help_text)
    check(shown and shown.group(1) == s.preset.lower(),
          f"panel preset {s.preset} vs the CLI's {shown and shown.group(1)}")
    # The motion-line seed has no shown default: the CLI without `--seed` draws the panel's.
    out = tmpdir()
    cesium = os.path.join(ASSETS, "CesiumMan.glb")
    written = []
    for seed in (None, s.seed, s.seed + 1):
        path = os.path.join(out, f"lines-{seed}.glb")
        cli("smear", "lines", cesium, *(["--seed", seed] if seed is not None else []),
            "-o", path)
        written.append(open(path, "rb").read())
    check(written[0] == written[1], f"the CLI's lines without --seed are not seed {s.seed}'s")
    check(written[1] != written[2], "the motion lines do not depend on the seed")


if __name__ == "__main__":
    code = run([
        test_the_panel_defaults_are_the_clis,
        test_every_preset_on_cesium_man_as_the_cli,
        test_every_preset_on_the_robot_as_the_cli,
        test_the_robots_bone_parented_parts_follow_the_bone_heuristic,
        test_every_preset_on_the_benchmark_tube_as_the_cli,
    ])
    finish(code, REPORT, OUT)
