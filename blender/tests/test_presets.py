"""Every named smear preset means the same smear in Blender as in the CLI, on real Blender via
`bpy`:

    python blender/tests/test_presets.py dist/toonkit-<version>-<platform>.zip [OUT_DIR]

For the bundled CesiumMan and the benchmark tube, the panel's presets with one β max and κ are
baked once and restyled (`smear_update`), and every frame's evaluated result is compared with
`toonkit smear elongate FILE --preset P --beta-max B --kappa K` of the CLI built from the same
tree (`$TOONKIT_CLI`, else `target/debug/toonkit`): within 1 % of the bounding-box diagonal
(Blender samples its own evaluated meshes; the CLI samples the file). The panel's defaults are
the CLI's (`toonkit smear elongate --help`).
"""

import json
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

from harness import (ASSETS, REPO, check, empty_scene, run, start, tmpdir,  # noqa: E402
                     world_positions)

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


def read_pc2(path):
    """(frames, points, 3) float32 of a PC2 point cache (as the CLI writes it)."""
    data = open(path, "rb").read()
    check(data[:12] == b"POINTCACHE2\0", f"{path}: not a PC2 file")
    points, _, _, frames = np.frombuffer(data[16:32], "<i4,<f4,<f4,<i4")[0]
    return np.frombuffer(data, "<f4", offset=32).reshape(frames, points, 3)


def character(path, clip=None):
    """Imports `file`, puts `clip` (an action name prefix) on its objects and selects its
    meshes (without the importer's bone shape); returns the meshes and the action's first
    frame."""
    empty_scene()
    bpy.ops.import_scene.gltf(filepath=path)
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
    return np.stack([np.concatenate([world_positions(o, f) for o in objs]) for f in frames])


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


def align(meshes, first, file_positions, diag):
    """The scene frames that show the file's sampled frames, and for each of Blender's vertices
    the file's vertex with the same unsmeared trajectory (nearest over three frames, so
    coincident vertices of parts that move apart stay apart): the importer maps key times to
    frames and splits and orders vertices its own way."""
    n = len(file_positions)
    keys = [0, n // 2, n - 1]
    file_keys = np.concatenate([file_positions[k] @ GLTF_TO_BLENDER.T for k in keys], axis=1)
    def seen(start):
        return np.concatenate(list(frames_of(meshes, [start + k for k in keys])), axis=1)

    some = slice(None, None, max(1, len(file_keys) // 256))  # enough to tell the frames apart
    start = min(range(first - 2, first + 3),
                key=lambda f: nearest(seen(f)[some].astype(np.float64), file_keys)[1])
    mine = seen(start).astype(np.float64)
    if mine.shape == file_keys.shape:  # the file's own order, when the importer kept it
        index, fit = np.arange(len(mine)), float(np.abs(mine - file_keys).max())
        if fit <= 1e-4 * diag:
            return range(start, start + n), index
    index, fit = nearest(mine, file_keys)
    check(fit <= 1e-4 * diag, f"Blender's vertices are not the file's ({fit / diag:.2e} of the "
                              "diagonal apart at best)")
    return range(start, start + n), index


def agree(path, clip, name):
    """Every preset on one character: Blender's bake and restyles against the CLI's caches."""
    args = [path, *(["--clip", clip] if clip else [])]
    meshes, first = character(path, clip)
    loaded = toonkit.load(args[0], clip=clip)  # the file's sampling, only to align frames
    diag = float(np.linalg.norm(np.ptp(loaded.positions[0], axis=0)))
    frames, index = align(meshes, first, loaded.positions, diag)
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
        test_every_preset_on_the_benchmark_tube_as_the_cli,
    ])
    with open(os.path.join(OUT, "report.json"), "w") as f:
        json.dump(REPORT, f, indent=1)
    print("blender report:", json.dumps(REPORT), flush=True)
    os._exit(code)  # bpy's interpreter teardown can crash after a headless run
