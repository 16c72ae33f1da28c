"""Headless tests of the smear bake on the rigs users have, on real Blender via `bpy`:

    python blender/tests/test_rigs.py dist/toonkit-<version>-<platform>.zip [OUT_DIR]

Both sampling paths (pose only: bone matrices + `toonkit.skin`; evaluated meshes) agree on
every scene; bone-parented props, several meshes, a scene range past the keys, a 2,000-frame
clip, shape keys on a rig, an object that does not move, the panel's bake state, a preview
range; with TOONKIT_CLI=toonkit (as .ci/blender.sh sets it) the results on both paths equal
the CLI's on CesiumMan. With
TOONKIT_TUBE=tube.glb (written by `write_tube`, as .ci/blender.sh does) it prints the first
and the repeated bake's times, the slider + frame change time and Blender's own floor on the
benchmark tube (printed, never asserted: docs/blender.md, "Speed").
"""

import json
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
os.environ.setdefault("BLENDER_USER_RESOURCES", os.path.join(
    os.environ.get("TMPDIR", "/tmp"), f"toonkit-blender-user-{os.getpid()}"))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from harness import (ASSETS, argv_after_dashes, check, empty_scene, install, rel,  # noqa: E402
                     finish, run, tmpdir, world_positions)

ARGS = argv_after_dashes()
ZIP = os.path.abspath(ARGS[0])
OUT = os.path.abspath(ARGS[1]) if len(ARGS) > 1 else tmpdir()
os.makedirs(OUT, exist_ok=True)
toonkit = install(ZIP)
# Both paths skin in float32 (Blender's Armature modifier, the core), summing in their own
# orders: a few ulps of the coordinates.
PATHS_TOL = 1e-5
REPORT = {"blender": bpy.app.version_string}


def ext():
    from bl_ext.user_default.toonkit import job, sample

    return job, sample


def select(objs):
    for o in bpy.data.objects:
        o.select_set(False)
    for o in objs:
        o.select_set(True)
    bpy.context.view_layer.objects.active = objs[0]


def imported(name, clip=None):
    """A bundled glTF character, scene range = its armature's clip; returns its meshes."""
    scene = empty_scene()
    bpy.ops.import_scene.gltf(filepath=os.path.join(ASSETS, name))
    arm = next(o for o in bpy.data.objects if o.type == "ARMATURE")
    if clip is not None:
        # The glTF importer names a clip's action `<clip>_<armature>` up to 4.3 and `<clip>`
        # (one slotted action per clip) from 4.4 on.
        names = (f"{clip}_{arm.name}", clip)
        arm.animation_data.action = next(bpy.data.actions[n] for n in names
                                         if n in bpy.data.actions)
    first, last = arm.animation_data.action.frame_range
    scene.frame_start, scene.frame_end = int(first), int(last)
    # The importer's "Icosphere" is the bones' display shape, not the character.
    return [o for o in bpy.data.objects if o.type == "MESH" and o.name != "Icosphere"]


def rig(keyed_end, scene_end, shape_keys=False):
    """A 3-bone chain skinning a 16-sided cylinder (vertex groups by height), the bones keyed
    over frames 1..keyed_end, scene range 1..scene_end."""
    scene = empty_scene()
    arm_data = bpy.data.armatures.new("chain")
    arm = bpy.data.objects.new("Chain", arm_data)
    scene.collection.objects.link(arm)
    bpy.context.view_layer.objects.active = arm
    bpy.ops.object.mode_set(mode="EDIT")
    parent = None
    for k in range(3):
        b = arm_data.edit_bones.new(f"b{k}")
        b.head, b.tail, b.parent = (0, 0, k), (0, 0, k + 1), parent
        parent = b
    bpy.ops.object.mode_set(mode="OBJECT")
    bpy.ops.mesh.primitive_cylinder_add(vertices=16, depth=3.0, location=(0, 0, 1.5))
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.subdivide(number_cuts=8)  # rings along the height
    bpy.ops.object.mode_set(mode="OBJECT")
    body = bpy.context.active_object
    body.name = "Body"
    z = np.array([(body.matrix_world @ v.co).z for v in body.data.vertices])
    for k in range(3):
        g = body.vertex_groups.new(name=f"b{k}")
        for i, h in enumerate(z):
            w = max(0.0, 1.0 - abs(h - (k + 0.5)))
            if w > 0:
                g.add([i], w * 0.7, "REPLACE")  # unnormalized, as painted weights often are
    body.parent = arm
    body.matrix_parent_inverse = arm.matrix_world.inverted()
    body.modifiers.new("Armature", "ARMATURE").object = arm
    if shape_keys:
        body.shape_key_add(name="Basis")
        bulge = body.shape_key_add(name="bulge")
        for v in bulge.data:
            v.co.x *= 1.5
        bulge.value = 0.0
        bulge.keyframe_insert("value", frame=1)
        bulge.value = 1.0
        bulge.keyframe_insert("value", frame=max(2, keyed_end // 2))
    keys = sorted({1, max(2, keyed_end // 3), max(3, 2 * keyed_end // 3), keyed_end})
    for i, f in enumerate(keys):
        for k, pb in enumerate(arm.pose.bones):
            pb.rotation_mode = "XYZ"
            pb.rotation_euler = (0.4 * (-1) ** i * (k + 1), 0.2 * i, 0.0)
            pb.keyframe_insert("rotation_euler", frame=f)
    arm.location = (0.0, 0.0, 0.0)
    arm.keyframe_insert("location", frame=1)
    arm.location = (3.0, 0.0, 0.0)
    arm.keyframe_insert("location", frame=keyed_end)
    scene.frame_start, scene.frame_end = 1, scene_end
    return [body]


def both_paths(objs):
    """The pose-only and the evaluated sample of `objs`: same vertices within float
    tolerance, same skeleton; returns the pose-only sample."""
    _, sample = ext()
    a = sample.sample(bpy.context, objs, pose_only=True)
    b = sample.sample(bpy.context, objs, pose_only=False)
    check(a.names == b.names and a.ranges == b.ranges, f"{a.names} vs {b.names}")
    diag = float(np.linalg.norm(np.ptp(b.positions.reshape(-1, 3), axis=0)))
    worst = rel(a.positions, b.positions, diag)
    check(worst <= PATHS_TOL, f"the two sampling paths differ by {worst:.2e} of the diagonal")
    np.testing.assert_array_equal(a.triangles, b.triangles)
    # One rest pose (docs/smear-units.md) whichever way the frames were read.
    np.testing.assert_allclose(a.rest, b.rest, atol=1e-5 * diag)
    if b.skin is not None:
        np.testing.assert_allclose(a.skin["matrices"], b.skin["matrices"], atol=1e-5)
        np.testing.assert_array_equal(a.skin["weights"], b.skin["weights"])
    return a, worst


def pose_only(objs):
    _, sample = ext()
    return [o.name for o in objs if sample.pose_only_reason(o) is None]


def bake():
    r = bpy.ops.toonkit.smear_bake()
    check(r == {"FINISHED"}, f"smear_bake returned {r}")


def body_frames(objs, step=1):
    """The baked bodies' evaluated world vertices at every `step`-th frame of the baked range
    (the scene's, or the preview range)."""
    start, end, _ = ext()[1].bake_range(bpy.context.scene)
    bodies = [bpy.data.objects[f"{o.name} smear"] for o in objs]
    return np.stack([np.concatenate([world_positions(b, f) for b in bodies])
                     for f in range(start, end + 1, step)])


def matches_the_module(objs, step=1):
    """The baked bodies at every `step`-th frame = `toonkit.smear` on the bake's own
    sample; returns the sample and the module's elongated bodies in Blender's world."""
    job, sample = ext()
    from bl_ext.user_default.toonkit import style

    s, prepared = job.cached(bpy.context.scene)
    look = toonkit.smear.stylize(prepared, style.from_settings(bpy.context.scene.toonkit_smear,
                                                               s.bones))
    # The bake's core works in the Y-up world of the CLI (docs/blender.md, "Axes").
    elongated = sample.from_y_up(look.elongated)
    objs[:] = [bpy.data.objects[n] for n in s.names]
    got = body_frames(objs, step)
    diag = float(np.linalg.norm(np.ptp(elongated[0], axis=0)))
    check(np.isfinite(got).all(), "NaN in a baked body")
    worst = rel(got, elongated[::step], diag)
    check(worst <= 1e-5, f"the bodies differ from the module by {worst:.2e}")
    return s, elongated


def test_both_paths_agree_on_every_scene():
    worst = {}
    meshes = imported("RobotExpressive.glb", "Dance")
    posed = pose_only(meshes)
    check("HandL_1" in posed and "ArmL" in posed, f"pose-only on the robot: {posed}")
    check("Head_2" not in posed, "shape keys must take the evaluated path")
    _, worst["robot"] = both_paths(meshes)
    meshes = imported("CesiumMan.glb")
    check(pose_only(meshes) == [o.name for o in meshes], "CesiumMan is not pose-only")
    _, worst["cesium_man"] = both_paths(meshes)
    for name, keyed, shape_keys in (("chain", 20, False), ("chain_shape_keys", 20, True)):
        meshes = rig(keyed, 24, shape_keys)
        check(bool(pose_only(meshes)) != shape_keys, f"{name}: pose-only {pose_only(meshes)}")
        _, worst[name] = both_paths(meshes)
    if os.environ.get("TOONKIT_TUBE"):
        _, worst["tube"] = both_paths(tube())
    REPORT["paths_worst_relative"] = worst
    print("both sampling paths, worst difference / bbox diagonal:", json.dumps(worst))


def test_robot_props_parented_to_bones_several_meshes_and_shape_keys():
    meshes = imported("RobotExpressive.glb", "Dance")
    select(meshes)
    bake()
    s, elongated = matches_the_module(meshes, step=8)
    check(len(s.names) == len(meshes) > 10, f"baked {len(s.names)} meshes")
    # Props ride their bones (SMEAR's articulated group), and they do smear.
    arm = s.skin["object_parents"]
    props = [o.name for o in meshes if o.parent_type == "BONE"]
    check(len(props) >= 8, f"the robot's bone-parented props: {props}")
    for prop in props:
        i = s.names.index(prop)
        check(s.bones[arm[i]] == bpy.data.objects[prop].parent_bone, f"{prop} rides no bone")
    for prop in ("ArmL", "ArmR", "ShoulderL_1"):  # the arms swing in the Dance
        r = s.ranges[s.names.index(prop)]
        check(np.abs(elongated[:, r.start:r.stop] - s.positions[:, r.start:r.stop]).max()
              > 1e-4, f"{prop} does not smear")
    bpy.ops.toonkit.smear_unbake()


def test_scene_range_longer_than_the_keys_and_a_2000_frame_clip():
    meshes = rig(keyed_end=20, scene_end=40)
    select(meshes)
    bake()
    s, _ = matches_the_module(meshes)
    check(len(s.positions) == 40, f"{len(s.positions)} frames baked, 40 in the scene range")
    # After the keys the rig holds its pose: the body shows it, no frozen smear.
    got = body_frames(meshes)
    np.testing.assert_allclose(got[25:], s.positions[25:], atol=1e-5)
    check(np.abs(got[3:15] - s.positions[3:15]).max() > 1e-3, "no smear while moving")

    # A range the user sets: the timeline's preview range, inside the scene range.
    scene = bpy.context.scene
    scene.use_preview_range = True
    scene.frame_preview_start, scene.frame_preview_end = 8, 30
    bpy.ops.toonkit.smear_unbake()
    select(meshes)
    bake()
    s, look = matches_the_module(meshes)
    check((s.frame_start, len(s.positions)) == (8, 23),
          f"preview range 8-30 baked as {s.frame_start}+{len(s.positions)}")
    scene.frame_preview_end = 8
    select([bpy.data.objects["Body smear"]])  # a result stands for its original
    job, _ = ext()
    why = job.bake_blocker(bpy.context)
    check(why and "preview range 8-8" in why, f"a one-frame preview range: {why!r}")
    scene.use_preview_range = False

    meshes = rig(keyed_end=2000, scene_end=2000)
    select(meshes)
    t = time.perf_counter()
    bake()
    REPORT["bake_2000_frames_s"] = round(time.perf_counter() - t, 2)
    job, _ = ext()
    s, prepared = job.cached(bpy.context.scene)
    check(s.positions.shape[0] == 2000, f"{s.positions.shape}")
    check(np.isfinite(np.asarray(prepared.offsets)).all(), "NaN in the offsets")
    body = bpy.data.objects["Body smear"].data
    # The bake writes the frame on screen; a save writes the others (docs/blender.md).
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(OUT, "clip_2000.blend"))
    check(sum(a.name.startswith("tk_P") for a in body.attributes) == 2000,
          "the saved file lacks frames")
    for f in (1, 700, 1500, 2000):
        a = body.attributes[f"tk_P{f}"]
        v = np.empty(len(a.data) * 3, np.float32)
        a.data.foreach_get("vector", v)
        check(np.isfinite(v).all(), f"NaN in frame {f}'s positions")
    for f in (1, 999, 2000):
        check(np.isfinite(world_positions(bpy.data.objects["Body smear"], f)).all(),
              f"NaN shown at frame {f}")


def cli():
    """The toonkit CLI of this tree (TOONKIT_CLI, set by .ci/blender.sh), or None."""
    path = os.environ.get("TOONKIT_CLI")
    if path:
        check(os.access(path, os.X_OK), f"TOONKIT_CLI={path} is not an executable")
    return path


def gltf_to_blender(p):
    """glTF's y-up points in Blender's z-up frame (as the glTF importer maps them)."""
    return np.stack([p[..., 0], -p[..., 2], p[..., 1]], axis=-1)


def test_results_equal_the_cli_on_both_sampling_paths():
    exe = cli()
    if exe is None:
        print("CLI comparison: TOONKIT_CLI not set, skipped")
        return
    meshes = imported("CesiumMan.glb")
    scene = bpy.context.scene
    # The importer keys the clip's time 0 at frame 1: the CLI's frames are Blender's 1..48.
    scene.frame_start = 1
    settings = scene.toonkit_smear
    settings.live = False
    settings.preset, settings.beta_max, settings.smooth = "SPEED", 1.0, 2
    out = os.path.join(OUT, "cesium_man_speed.npy")
    subprocess.run([exe, "smear", "elongate", os.path.join(ASSETS, "CesiumMan.glb"),
                    "--preset", "speed", "--beta-max", "1", "--smooth", "2", "-o", out],
                   check=True, stdout=subprocess.DEVNULL)
    want = gltf_to_blender(np.load(out))
    inputs = gltf_to_blender(toonkit.load(os.path.join(ASSETS, "CesiumMan.glb")).positions)
    diag = float(np.linalg.norm(np.ptp(want[0], axis=0)))
    check(rel(want, inputs, diag) > 0.01, "the CLI's speed preset barely smears CesiumMan")
    job, sample = ext()
    from bl_ext.user_default.toonkit import style

    worst = {}
    for pose_only in (True, False):
        s = sample.sample(bpy.context, meshes, pose_only=pose_only)
        prepared = toonkit.smear.prepare(
            toonkit.Scene.from_arrays(s.positions, s.triangles, fps=s.fps, skin=s.skin,
                                      objects=s.objects, attributes=s.attributes, rest=s.rest),
            smooth=settings.smooth)
        got = toonkit.smear.stylize(prepared, style.from_settings(settings, s.bones)).elongated
        check(got.shape == want.shape, f"{got.shape} vs the CLI's {want.shape}")
        worst["pose_only" if pose_only else "evaluated"] = rel(got, want, diag)
    # And what the bake shows (the pose-only path, through the result objects).
    select(meshes)
    bake()
    worst["bake"] = rel(body_frames(meshes), want, diag)
    REPORT["cli_worst_relative"] = worst
    print("CesiumMan against the CLI, worst difference / bbox diagonal:", json.dumps(worst))
    # The acceptance bound is 1 %; both paths agree with the CLI far closer.
    check(max(worst.values()) <= 1e-3, f"the extension differs from the CLI: {worst}")
    bpy.ops.toonkit.smear_unbake()


def test_kept_weights_follow_every_edit_of_the_mesh():
    """A re-bake reuses the vertex weights read by the last bake (docs/blender.md, "Speed")
    until the mesh is edited: after each kind of edit the bake samples what a fresh read
    gives, and differs from the bake before the edit."""
    from bl_ext.user_default.toonkit import weights

    job, sample = ext()
    objs = rig(20, 24)
    body = objs[0]
    n = len(body.data.vertices)

    def baked():
        bpy.ops.toonkit.smear_unbake()
        select(objs)
        bake()
        return job.cached(bpy.context.scene)[0]

    def fresh():
        weights.forget()
        return sample.sample(bpy.context, objs)

    before = baked()
    kept = weights.read(body, n)
    again = baked()
    check(weights.read(body, n) is kept, "an unbake and a bake without an edit read again")
    np.testing.assert_array_equal(again.y_up, before.y_up)
    vertices = body.data.vertices

    def add():
        body.vertex_groups["b1"].add(list(range(0, n, 3)), 1.0, "REPLACE")

    def element():
        for v in list(vertices)[1::4]:
            for g in v.groups:
                g.weight = 0.05

    def paint():
        select(objs)
        bpy.ops.object.mode_set(mode="WEIGHT_PAINT")
        body.vertex_groups.active_index = body.vertex_groups["b0"].index
        bpy.ops.object.vertex_group_smooth(group_select_mode="ALL", factor=1.0, repeat=4)
        bpy.ops.object.mode_set(mode="OBJECT")

    def remove():
        body.vertex_groups["b2"].remove(list(range(0, n, 2)))

    for name, edit in (("VertexGroup.add", add), ("a vertex's group weight", element),
                       ("weight paint smoothing", paint), ("VertexGroup.remove", remove)):
        edit()
        got = baked()
        want = fresh()
        np.testing.assert_array_equal(got.skin["weights"], want.skin["weights"],
                                      err_msg=f"after {name}")
        np.testing.assert_array_equal(got.y_up, want.y_up, err_msg=f"after {name}")
        check(not np.array_equal(got.y_up, before.y_up), f"{name} changed nothing")
        before = got
    bpy.ops.toonkit.smear_unbake()


def test_weights_through_geometry_nodes_equal_a_pass_over_the_vertices():
    """The vertex weights a bake reads through a Geometry Nodes modifier (docs/blender.md,
    "Speed") are the per-vertex pass's bit for bit on every test scene with vertex groups
    (the robot's skinned hands and bone-named, shape-keyed head, CesiumMan, the chain rig
    with shape keys), and the read leaves each mesh's modifiers as they were."""
    from bl_ext.user_default.toonkit import weights

    scenes = (("robot", lambda: imported("RobotExpressive.glb", "Dance")),
              ("cesium_man", lambda: imported("CesiumMan.glb")),
              ("chain", lambda: rig(20, 24, True)))
    for name, scene in scenes:  # each one replaces the one before
        meshes = [o for o in scene() if len(o.vertex_groups)]
        check(bool(meshes), f"{name}: no mesh with vertex groups")
        before = {o.name: [(m.name, m.show_viewport) for m in o.modifiers] for o in meshes}
        read = weights._read_nodes(bpy.context, meshes)
        check(sorted(read) == sorted(o.name for o in meshes), f"{name}: read {sorted(read)}")
        for o in meshes:
            want = weights._read(o, len(o.data.vertices))
            check(list(read[o.name]) == list(want), f"{o.name}: groups {list(read[o.name])}")
            for group, values in want.items():
                np.testing.assert_array_equal(read[o.name][group], values,
                                              err_msg=f"{o.name}: {group}")
            after = [(m.name, m.show_viewport) for m in o.modifiers]
            check(after == before[o.name], f"{o.name}: modifiers {after}")


def test_object_without_animation_says_so():
    scene = empty_scene()
    bpy.ops.mesh.primitive_cube_add()
    cube = bpy.context.active_object
    scene.frame_start, scene.frame_end = 1, 20
    select([cube])
    try:
        bpy.ops.toonkit.smear_bake()
    except RuntimeError as e:
        msg = str(e)
        check("does not move" in msg and "Traceback" not in msg, f"message {msg!r}")
    else:
        raise AssertionError("a still object baked without a word")
    check(not [o for o in bpy.data.objects if "toonkit_role" in o], "the scene changed")


def test_panel_says_what_to_select_and_why_bake_is_disabled():
    job, _ = ext()
    scene = empty_scene()
    scene.frame_start, scene.frame_end = 1, 20
    why = job.bake_blocker(bpy.context)
    check(why and "select" in why.lower(), f"nothing selected: {why!r}")
    check(not bpy.ops.toonkit.smear_bake.poll(), "bake enabled with nothing selected")
    cam = bpy.data.objects.new("cam", bpy.data.cameras.new("cam"))
    scene.collection.objects.link(cam)
    select([cam])
    why = job.bake_blocker(bpy.context)
    check(why and "mesh" in why, f"a camera selected: {why!r}")
    meshes = rig(10, 10)
    select(meshes)
    check(job.bake_blocker(bpy.context) is None, job.bake_blocker(bpy.context) or "")
    check(bpy.ops.toonkit.smear_bake.poll(), "bake disabled with a rigged mesh selected")
    scene = bpy.context.scene
    scene.frame_end = scene.frame_start
    why = job.bake_blocker(bpy.context)
    check(why and "two frames" in why, f"a one-frame range: {why!r}")
    # The panel draws its status line and how-to (no error while drawing headless).
    from bl_ext.user_default.toonkit import panel

    check(any("Select" in line for line in panel.HOW_TO), "the how-to does not say what to select")


def attr_frame(mesh, f):
    a = mesh.attributes[f"tk_P{f}"]
    v = np.empty(len(a.data) * 3, np.float32)
    a.data.foreach_get("vector", v)
    return v.reshape(-1, 3)


def test_live_restyle_writes_each_frame_when_the_scene_reaches_it():
    meshes = rig(keyed_end=20, scene_end=24)
    scene = bpy.context.scene
    select(meshes)
    bake()
    mesh = bpy.data.objects["Body smear"].data
    # The bake stylized and wrote the frame on screen only; saving writes the others.
    check(mesh.attributes.get("tk_P12") is None, "the bake wrote frames not shown yet")
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(OUT, "baked.blend"))
    before = {f: attr_frame(mesh, f) for f in (5, 12)}
    scene.frame_set(5)
    scene.toonkit_smear.beta_max = 6.0  # a live slider change
    check(np.abs(attr_frame(mesh, 5) - before[5]).max() > 1e-4, "the current frame kept")
    np.testing.assert_array_equal(attr_frame(mesh, 12), before[12])  # not touched yet
    scene.frame_set(12)
    check(np.abs(attr_frame(mesh, 12) - before[12]).max() > 1e-4, "frame 12 not written")
    # Blender idle: the timer (headless bpy runs no timers: called here) writes the rest.
    job, _ = ext()
    scene.toonkit_smear.beta_max = 3.0
    check(job.pending_frames(scene) == 23, f"{job.pending_frames(scene)} frames pending")
    check(bpy.app.timers.is_registered(job._flush), "no idle timer")
    job._flush()
    check(job.pending_frames(scene) == 0, "the idle timer left frames pending")
    # Saving writes every pending frame: the file holds the whole restyle.
    scene.toonkit_smear.beta_max = 1.0
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(OUT, "pending.blend"))
    job, sample = ext()
    from bl_ext.user_default.toonkit import style

    s, prepared = job.cached(scene)
    want = sample.from_y_up(
        toonkit.smear.stylize(prepared, style.from_settings(scene.toonkit_smear)).elongated)
    got = np.stack([attr_frame(mesh, f) for f in range(1, 25)])
    np.testing.assert_allclose(got, want, atol=1e-6)


def tube():
    """The benchmark tube (docs/blender.md, "Speed"), imported; its one mesh."""
    scene = empty_scene()
    bpy.ops.import_scene.gltf(filepath=os.environ["TOONKIT_TUBE"])
    arm = next(o for o in bpy.data.objects if o.type == "ARMATURE")
    first, last = arm.animation_data.action.frame_range
    scene.frame_start, scene.frame_end = int(first), int(last)
    return [o for o in bpy.data.objects if o.type == "MESH" and o.name != "Icosphere"]


def test_tube_speed():
    """Prints (never asserts) the bake, the slider + frame change and Blender's floor."""
    if not os.environ.get("TOONKIT_TUBE"):
        print("speed: TOONKIT_TUBE not set, skipped")
        return
    meshes = tube()
    scene = bpy.context.scene
    arm = next(o for o in bpy.data.objects if o.type == "ARMATURE")
    # Blender's floor: the frame_set loop over the pose alone (the mesh's modifiers off).
    mods = [m for o in meshes for m in o.modifiers if m.type == "ARMATURE"]
    for m in mods:
        m.show_viewport = False
    floor = []
    for _ in range(3):
        t = time.perf_counter()
        for f in range(scene.frame_start, scene.frame_end + 1):
            scene.frame_set(f)
            arm.evaluated_get(bpy.context.evaluated_depsgraph_get())
        floor.append(time.perf_counter() - t)
    for m in mods:
        m.show_viewport = True
    scene.frame_set(scene.frame_start)
    select(meshes)
    from bl_ext.user_default.toonkit import weights

    # A first bake reads the mesh's vertex weights; a repeated one (after an unbake, no edit
    # of the mesh) reuses them (docs/blender.md, "Speed"). Alternated, 3 of each.
    bakes = {True: ([], []), False: ([], [])}
    for i in range(6):
        first = i % 2 == 0
        bpy.ops.toonkit.smear_unbake()  # a bake hides its original
        select(meshes)
        if first:
            weights.forget()
        t, c = time.perf_counter(), time.process_time()
        bake()
        bakes[first][0].append(time.perf_counter() - t)
        bakes[first][1].append(time.process_time() - c)
    s = scene.toonkit_smear
    slider, slider_cpu = [], []
    for i in range(20):
        t, c = time.perf_counter(), time.process_time()
        s.beta_max = 2.0 + 0.1 * i  # the live update restyles
        scene.frame_set(scene.frame_start + 5 + i % 20)
        slider.append(time.perf_counter() - t)
        slider_cpu.append(time.process_time() - c)
    figures = {"vertices": sum(len(o.data.vertices) for o in meshes),
               "frames": scene.frame_end - scene.frame_start + 1,
               "bake_ms": round(1000 * min(bakes[True][0]), 1),
               "bake_cpu_ms": round(1000 * min(bakes[True][1]), 1),
               "repeated_bake_ms": round(1000 * min(bakes[False][0]), 1),
               "repeated_bake_cpu_ms": round(1000 * min(bakes[False][1]), 1),
               "slider_and_frame_change_median_ms": round(1000 * float(np.median(slider)), 2),
               # Every thread's CPU time: what a loaded machine's waits do not inflate.
               "slider_and_frame_change_cpu_median_ms": round(
                   1000 * float(np.median(slider_cpu)), 2),
               "floor_pose_frame_set_ms": round(1000 * min(floor), 1),
               "load_average": os.getloadavg()[0]}
    REPORT["tube"] = figures
    print("speed on the tube:", json.dumps(figures), flush=True)


if __name__ == "__main__":
    code = run([
        test_panel_says_what_to_select_and_why_bake_is_disabled,
        test_object_without_animation_says_so,
        test_both_paths_agree_on_every_scene,
        test_robot_props_parented_to_bones_several_meshes_and_shape_keys,
        test_scene_range_longer_than_the_keys_and_a_2000_frame_clip,
        test_live_restyle_writes_each_frame_when_the_scene_reaches_it,
        test_kept_weights_follow_every_edit_of_the_mesh,
        test_weights_through_geometry_nodes_equal_a_pass_over_the_vertices,
        test_results_equal_the_cli_on_both_sampling_paths,
        test_tube_speed,
    ])
    finish(code, REPORT, OUT)
