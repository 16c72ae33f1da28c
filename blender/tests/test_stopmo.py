"""Headless tests of the extension's stop-motion operator (issue 17, first half):

    python blender/tests/test_stopmo.py dist/toonkit-<version>-<platform>.zip [OUT_DIR]

The bundled talking face (2 fps), two `part_<NAME>` vertex groups painted around the seed
points the CLI tests use; `toonkit.stopmo_run` must write the same `assembly.csv` and energy as
`toonkit.stopmo.run` on the same evaluated data (the module equals the CLI: crates/python/tests),
and the reconstruction object must show at frame k the pieces of `assembly.csv` row k.
Without vertex groups, the same seed points picked at the 3D cursor must give the CLI's
result for those seed points (the .glb loaded as the CLI loads it). A second mesh, Suzanne
subdivided once and animated by two shape keys, split into upper and lower parts by two
3D-cursor seeds, must write pieces and an assembly.csv whose row k the reconstruction shows
at frame k.
"""

import csv
import json
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
os.environ.setdefault("BLENDER_USER_RESOURCES", os.path.join(
    os.environ.get("TMPDIR", "/tmp"), f"toonkit-blender-user-{os.getpid()}"))

import bpy  # noqa: E402
import numpy as np  # noqa: E402
from mathutils import Vector  # noqa: E402

from harness import (REPO, argv_after_dashes, attribute, check, empty_scene, install,  # noqa: E402
                     read_pc2, run, tmpdir, world_positions)

ARGS = argv_after_dashes()
ZIP = os.path.abspath(ARGS[0])
OUT = os.path.abspath(ARGS[1]) if len(ARGS) > 1 else tmpdir()
os.makedirs(OUT, exist_ok=True)
toonkit = install(ZIP)
# The CLI tests' seeds (glTF, Y up) in Blender's Z-up frame: (x, y, z) -> (x, -z, y).
SEEDS = {"upper": (0.0, -13.0, 10.0), "lower": (0.0, -10.0, -14.0)}
GLTF_SEEDS = {"upper": [(0.0, 10.0, 13.0)], "lower": [(0.0, -14.0, 10.0)]}
PIECES = 4


def same_as(folder, ref, ref_dir):
    """`folder`'s assembly, shooting order and energy equal those of the library `ref`."""
    ref.save(ref_dir)
    for name in ("assembly.csv", "shooting_order.csv"):
        with open(os.path.join(folder, name)) as a, open(os.path.join(ref_dir, name)) as b:
            check(a.read() == b.read(), f"{name} differs from the module's")
    ours = json.load(open(os.path.join(folder, "report.json")))
    theirs = json.load(open(os.path.join(ref_dir, "report.json")))
    check(abs(ours["energy"] - theirs["energy"]) <= 1e-6 * abs(theirs["energy"]),
          f"energy {ours['energy']} vs {theirs['energy']}")
    return ours, theirs


def face():
    scene = empty_scene()
    scene.render.fps = 2
    bpy.ops.import_scene.gltf(filepath=os.path.join(REPO, "assets", "face", "ict-face-talk.glb"))
    obj = next(o for o in bpy.data.objects if o.type == "MESH" and o.name != "Icosphere")
    ad = obj.data.shape_keys.animation_data if obj.data.shape_keys else obj.animation_data
    first, last = ad.action.frame_range
    scene.frame_start, scene.frame_end = int(first), int(last)
    rest = world_positions(obj, scene.frame_start)
    for name, seed in SEEDS.items():
        d = np.linalg.norm(rest - np.array(seed), axis=1)
        near = np.nonzero(d <= np.sort(d)[30])[0]  # the 31 vertices nearest the seed
        g = obj.vertex_groups.new(name=f"part_{name}")
        g.add([int(i) for i in near], 1.0, "REPLACE")
    for o in bpy.data.objects:
        o.select_set(False)
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj
    return scene, obj


def test_stopmo_run_matches_the_module():
    scene, obj = face()
    s = scene.toonkit_stopmo
    s.count, s.pieces, s.restarts, s.seed = "EACH", PIECES, 2, 1
    # Printed as a studio mounts it: a 3x2 mm disc magnet (3.5 mm walls: where a part hardly
    # moves it is as thick as its wall, and the pocket needs 2.15 mm and 1 mm in front of
    # it), STL and library.3mf.
    s.magnets, s.magnet_diameter_mm, s.magnet_height_mm = True, 3.0, 2.0
    s.thickness_mm = 3.5
    s.print_format = "stl,3mf"
    folder = os.path.join(OUT, "stopmo")
    r = bpy.ops.toonkit.stopmo_run(directory=folder)
    check(r == {"FINISHED"}, f"stopmo_run returned {r}")
    from bl_ext.user_default.toonkit import sample, stopmo

    taken = sample.sample(bpy.context, [obj])
    parts = stopmo.parts_of(obj, taken.triangles)
    ref = toonkit.stopmo.run(toonkit.Scene.from_arrays(taken.positions, taken.triangles,
                                                       fps=taken.fps),
                             parts=parts, **stopmo.options(s))
    same_as(folder, ref, os.path.join(OUT, "module"))
    shows_assembly(scene, folder, ref)
    printed_with_magnets(folder)
    reconstruction_glb_plays(scene, folder)
    check(bpy.data.images.get("toonkit error curve") is not None or s.count == "EACH",
          "no size-vs-error image")
    # The job's warnings reach the user (the operator reports them) and stay with the result.
    rec = next(o for o in bpy.data.objects if o.get("toonkit_role") == "stopmo")
    warnings = ref.report["warnings"]
    check(rec.get(stopmo.WARNINGS) == "\n".join(warnings),
          f"warnings {rec.get(stopmo.WARNINGS)!r} vs the module's {warnings}")
    check(any("cross the solid" in w for w in warnings) == any(
        p["shell"]["self_intersecting_triangles"] > 0 for p in ref.report["printing"]["parts"]),
        f"crossing warning vs report: {warnings}")


def printed_with_magnets(folder):
    """The panel's magnet and 3MF reached the files: report.json lists the magnet, a pocket
    per part and every piece with a pocket and a plate; each part's mount is a whole binary
    STL; library.3mf holds one object per piece, named by its ID, in millimetres."""
    import struct
    import xml.etree.ElementTree as ET
    import zipfile

    printing = json.load(open(os.path.join(folder, "report.json")))["printing"]
    check(printing["magnet"] == {"diameter_mm": 3.0, "height_mm": 2.0},
          f"magnet {printing['magnet']}")
    check(printing["print_format"] == "stl,3mf", f"print format {printing['print_format']}")
    pieces = printing["pieces"]
    check(pieces and all(p["magnet"] and p["plate"] >= 1 and p["volume_mm3"] > 0
                         for p in pieces), f"pieces {pieces}")
    for part in printing["parts"]:
        check(part["magnet_pocket"] is not None, f"part {part['name']}: no pocket")
        with open(os.path.join(folder, "pieces", f"{part['name']}_back.stl"), "rb") as fh:
            stl = fh.read()
        n = struct.unpack_from("<I", stl, 80)[0]
        check(n > 0 and len(stl) == 84 + 50 * n, f"mount {part['name']}: {len(stl)} bytes")
    with zipfile.ZipFile(os.path.join(folder, "library.3mf")) as z:
        model = ET.fromstring(z.read("3D/3dmodel.model"))
    ns = {"m": model.tag[1:].split("}")[0]}
    names = sorted(o.get("name") for o in model.iterfind("m:resources/m:object", ns))
    check(model.get("unit") == "millimeter", f"unit {model.get('unit')}")
    check(names == sorted(p["id"] for p in pieces), f"3MF objects {names}")
    print(f"  magnets: {len(pieces)} pieces with pockets on {len(printing['plates'])} plate(s)")


def shows_assembly(scene, folder, ref):
    """Pieces were written, and the reconstruction object shows at frame k the pieces of
    `assembly.csv` row k (those of the library `ref`, equal to the operator's)."""
    pieces = sorted(os.listdir(os.path.join(folder, "pieces")))
    check(len(pieces) > 0, "no pieces written")
    rec = next(o for o in bpy.data.objects if o.get("toonkit_role") == "stopmo")
    rows = list(csv.reader(open(os.path.join(folder, "assembly.csv"))))
    header, rows = rows[0], rows[1:]
    labels = np.asarray(ref.labels)
    check(len(rows) == len(labels) == scene.frame_end - scene.frame_start + 1,
          f"{len(rows)} assembly rows, {len(labels)} labels")
    ids = {(p["part"], p["index"]): p["id"] for p in ref.pieces}
    for k, f in enumerate(range(scene.frame_start, scene.frame_end + 1)):
        piece = attribute(rec, "piece", np.int32, frame=f)
        shown = [ids[(p, int(i))] for p, i in enumerate(labels[k])]
        check(set(shown) <= set(rows[k]), f"frame {f}: {shown} not in {rows[k]}")
        check(set(np.unique(piece)) == set(int(i) for i in labels[k]),
              f"frame {f}: piece attribute {np.unique(piece)} vs labels {labels[k]}")
    return pieces, rows


def reconstruction_glb_plays(scene, folder):
    """reconstruction.glb (each part's pieces as morph targets, STEP weights) imports through
    Blender's glTF importer and plays: at frame k every part shows the positions of
    reconstruction.pc2's frame k (glTF axes there, Z up here), within the quantization."""
    frames = read_pc2(os.path.join(folder, "reconstruction.pc2"))
    before = set(bpy.data.objects)
    bpy.ops.import_scene.gltf(filepath=os.path.join(folder, "reconstruction.glb"))
    # Blender suffixes a name that is taken (".001").
    new = {o.name.split(".")[0]: o for o in bpy.data.objects
           if o not in before and o.type == "MESH"}
    # One object per part, in report.json's part order (that of the .pc2's vertices).
    names = [p["name"] for p in json.load(open(os.path.join(folder, "report.json")))["parts"]]
    check(sorted(new) == sorted(names), f"reconstruction.glb imported {sorted(new)}")
    parts = [new[n] for n in names]
    keys = parts[0].data.shape_keys
    check(keys is not None and keys.animation_data and keys.animation_data.action,
          "reconstruction.glb: no shape-key animation")
    first = int(keys.animation_data.action.frame_range[0])
    diag = float(np.linalg.norm(frames[0].max(0) - frames[0].min(0)))
    worst = 0.0
    for k in range(len(frames)):
        got = np.concatenate([world_positions(o, first + k) for o in parts])
        got = got[:, [0, 2, 1]] * np.array([1.0, 1.0, -1.0], np.float32)  # Z up -> Y up
        check(got.shape == frames[k].shape, f"{got.shape} imported vertices, pc2 {frames[k].shape}")
        worst = max(worst, float(np.abs(got - frames[k]).max()))
    check(worst <= 1e-4 * diag, f"reconstruction.glb vs pc2: {worst} (diagonal {diag})")
    print(f"  reconstruction.glb: {len(frames)} frames play as reconstruction.pc2 "
          f"(largest distance {worst:.2e} of a {diag:.1f} diagonal)")
    for o in parts:
        bpy.data.objects.remove(o)


def test_stopmo_cursor_seeds():
    """No part_ groups: seeds picked at the 3D cursor give the CLI's result for its seed
    points (the .glb read as the CLI reads it, seeds in glTF axes): same assembly, shooting
    order and energy."""
    scene, obj = face()
    for g in list(obj.vertex_groups):
        obj.vertex_groups.remove(g)
    s = scene.toonkit_stopmo
    # One restart and no solids: what is tested here is where the parts come from.
    s.count, s.pieces, s.restarts, s.seed = "EACH", PIECES, 1, 1
    s.print_solids = False
    for name, seed in SEEDS.items():
        scene.cursor.location = seed
        r = bpy.ops.toonkit.stopmo_add_seed(part=name)
        check(r == {"FINISHED"}, f"stopmo_add_seed returned {r}")
    scene.cursor.location = (5.0, 5.0, 5.0)
    s.seed_part = "stray"
    bpy.ops.toonkit.stopmo_add_seed()
    check([x.part for x in s.seeds] == ["upper", "lower", "stray"], "seeds not stored")
    bpy.ops.toonkit.stopmo_remove_seed(index=2)
    check([x.part for x in s.seeds] == ["upper", "lower"], "the seed was not removed")
    folder = os.path.join(OUT, "stopmo-seeds")
    r = bpy.ops.toonkit.stopmo_run(directory=folder)
    check(r == {"FINISHED"}, f"stopmo_run returned {r}")
    from bl_ext.user_default.toonkit import stopmo

    # The CLI's way: the .glb as `toonkit stopmo run` reads it, the seeds in glTF axes.
    glb = toonkit.load(os.path.join(REPO, "assets", "face", "ict-face-talk.glb"), fps=2)
    ref = toonkit.stopmo.run(glb, parts=GLTF_SEEDS, **stopmo.options(s))
    ours, theirs = same_as(folder, ref, os.path.join(OUT, "cli-seeds"))
    written = os.listdir(os.path.join(folder, "pieces"))
    check(written and not any(f.endswith(".stl") for f in written),
          f"'Printable solids' off still wrote solids: {written}")
    check(ours["printing"] is None, "a printing report without solids")
    print(f"  cursor seeds: energy {ours['energy']!r} (CLI seeds {theirs['energy']!r})")
    # One seed part only: one line, nothing made.
    bpy.ops.toonkit.stopmo_remove_seed()
    refused("bad-seeds", "at least two parts")


def suzanne():
    """Blender's Suzanne subdivided once, animated over 12 frames by two shape keys: the jaw
    (below the nose) opens and closes, the brow (above the eyes) rises and falls, at other
    rates."""
    scene = empty_scene()
    scene.render.fps = 12
    scene.frame_start, scene.frame_end = 1, 12
    bpy.ops.mesh.primitive_monkey_add(size=2.0)
    obj = bpy.context.active_object
    mod = obj.modifiers.new("subdivide", "SUBSURF")
    mod.levels = 1
    bpy.ops.object.modifier_apply(modifier=mod.name)
    obj.shape_key_add(name="Basis")
    for name, moved in (("jaw", lambda c: (0.0, -0.1, -0.35) if c.z < -0.15 else None),
                        ("brow", lambda c: (0.0, 0.05, 0.25) if c.z > 0.35 else None)):
        key = obj.shape_key_add(name=name, from_mix=False)
        for v, k in zip(obj.data.vertices, key.data):
            d = moved(v.co)
            if d is not None:
                w = min(1.0, abs(v.co.z - (-0.15 if name == "jaw" else 0.35)) / 0.3)
                k.co = v.co + w * Vector(d)
        for f in range(scene.frame_start, scene.frame_end + 1):
            rate = 6.0 if name == "jaw" else 4.0
            key.value = 0.5 - 0.5 * math.cos(2.0 * math.pi * (f - 1) / rate)
            key.keyframe_insert("value", frame=f)
    return scene, obj


def test_stopmo_cursor_seeds_suzanne():
    """A second mesh: Suzanne's upper and lower halves from two 3D-cursor seeds; the pieces
    and assembly.csv written, the reconstruction showing row k at frame k."""
    scene, obj = suzanne()
    s = scene.toonkit_stopmo
    s.count, s.pieces, s.restarts, s.seed = "EACH", 3, 1, 1
    seeds = {"upper": (0.0, -0.6, 0.75), "lower": (0.0, -0.8, -0.45)}
    for name, seed in seeds.items():
        scene.cursor.location = seed
        check(bpy.ops.toonkit.stopmo_add_seed(part=name) == {"FINISHED"}, "no seed added")
    folder = os.path.join(OUT, "stopmo-suzanne")
    r = bpy.ops.toonkit.stopmo_run(directory=folder)
    check(r == {"FINISHED"}, f"stopmo_run returned {r}")
    report = json.load(open(os.path.join(folder, "report.json")))
    sizes = {p["name"]: p["vertices"] for p in report["parts"]}
    check(list(sizes) == ["upper", "lower"] and min(sizes.values()) > 0, f"parts {sizes}")
    pieces = sorted(os.listdir(os.path.join(folder, "pieces")))
    rows = list(csv.DictReader(open(os.path.join(folder, "assembly.csv"))))
    check(len(rows) == scene.frame_end - scene.frame_start + 1, f"{len(rows)} assembly rows")
    # Frame k of the reconstruction: each part's vertices (rest.obj's part order) carry the
    # index of the piece that assembly.csv row k names for the part, and its file exists.
    rec = next(o for o in bpy.data.objects if o.get("toonkit_role") == "stopmo")
    for k, f in enumerate(range(scene.frame_start, scene.frame_end + 1)):
        piece = attribute(rec, "piece", np.int32, frame=f)
        check(len(piece) == sum(sizes.values()), f"{len(piece)} reconstruction vertices")
        at = 0
        for name, n in sizes.items():
            named = rows[k][name]
            check(f"{named}.obj" in pieces, f"frame {f}: no file for piece {named}")
            want = int(named.rsplit("_", 1)[1])
            check((piece[at:at + n] == want).all(),
                  f"frame {f}: part {name} shows {np.unique(piece[at:at + n])}, "
                  f"assembly.csv {named}")
            at += n
    shown = sorted({r[n] for r in rows for n in sizes})
    print(f"  Suzanne: parts {sizes} (vertices), {len(rows)} assembly rows using {shown}, "
          f"energy {report['energy']!r}")
    check(all(len({r[n] for r in rows}) > 1 for n in sizes), "a part never changes piece")


def refused(directory, expect):
    """`stopmo_run` fails with `expect` in its one-line message and adds no object."""
    before = sorted(o.name for o in bpy.data.objects)
    try:
        bpy.ops.toonkit.stopmo_run(directory=os.path.join(OUT, directory))
    except RuntimeError as e:
        check(expect in str(e), f"message {e}")
    else:
        raise AssertionError(f"no error ({expect})")
    check(sorted(o.name for o in bpy.data.objects) == before, "the scene changed")


def test_stopmo_errors():
    scene, obj = face()
    obj.vertex_groups.remove(obj.vertex_groups["part_lower"])
    refused("bad", "at least two vertex groups")


if __name__ == "__main__":
    code = run([test_stopmo_errors, test_stopmo_cursor_seeds, test_stopmo_run_matches_the_module,
                test_stopmo_cursor_seeds_suzanne])
    os._exit(code)  # bpy's interpreter teardown can crash after a headless run
