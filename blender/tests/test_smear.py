"""Headless tests of the toonkit Blender extension (issue 16), on real Blender via `bpy`:

    python blender/tests/test_smear.py dist/toonkit-<version>-<platform>.zip [OUT_DIR]

Installs the zip, builds scenes programmatically (the bundled robot and CesiumMan glTF, a
bone-parented prop, non-bone vertex groups, a still-frame hold, a clip shorter than the scene
range), bakes, and checks every frame's evaluated result against `toonkit.smear` run on the
evaluated data read independently here (<= 1e-5 of the bounding-box diagonal), a render that
differs from the unbaked one, save/reload, and an unbake that restores the originals exactly.
Prints the `smear_update` benchmark (target <= 100 ms on the robot's Dance clip).
"""

import json
import os
import sys
import time

# Process CPU time above which `smear_update` fails the test: 5x its target of 100 ms on the
# robot, far beyond what a machine's load moves (a regression, not a slow runner).
SMEAR_UPDATE_CEILING_MS = 500.0

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
os.environ.setdefault("BLENDER_USER_RESOURCES", os.path.join(
    os.environ.get("TMPDIR", "/tmp"), f"toonkit-blender-user-{os.getpid()}"))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from harness import (ASSETS, argv_after_dashes, attribute, check, empty_scene, install, rel,  # noqa: E402
                     finish, run, tmpdir, world_positions)

ARGS = argv_after_dashes()
ZIP = os.path.abspath(ARGS[0])
OUT = os.path.abspath(ARGS[1]) if len(ARGS) > 1 else tmpdir()
os.makedirs(OUT, exist_ok=True)
toonkit = install(ZIP)
TOL = 1e-5
REPORT = {"blender": bpy.app.version_string}


def robot(clip="Dance"):
    """The robot with `clip` on its armature and shape keys, scene range = the clip."""
    scene = empty_scene()
    bpy.ops.import_scene.gltf(filepath=os.path.join(ASSETS, "RobotExpressive.glb"))
    for o in bpy.data.objects:
        ad = o.animation_data or (o.data.shape_keys.animation_data
                                  if o.type == "MESH" and o.data.shape_keys else None)
        if ad is None or ad.action is None:
            continue
        owner = o.name if o.type == "ARMATURE" else o.name
        name = f"{clip}_{owner}"
        if name in bpy.data.actions:
            ad.action = bpy.data.actions[name]
    arm = bpy.data.objects["RobotArmature"]
    first, last = arm.animation_data.action.frame_range
    scene.frame_start, scene.frame_end = int(first), int(last)
    meshes = [o for o in bpy.data.objects if o.type == "MESH" and o.name != "Icosphere"]
    select(meshes)
    return scene, meshes


def select(objs):
    for o in bpy.data.objects:
        o.select_set(False)
    for o in objs:
        o.select_set(True)
    bpy.context.view_layer.objects.active = objs[0]


def evaluated(objs):
    """Every frame's evaluated world positions of `objs`, read here (not by the extension)."""
    scene = bpy.context.scene
    frames = []
    for f in range(scene.frame_start, scene.frame_end + 1):
        scene.frame_set(f)
        frames.append(np.concatenate([world_positions(o) for o in objs]))
    return np.stack(frames)


def bodies(objs):
    return [bpy.data.objects[f"{o.name} smear"] for o in objs]


def expected(objs, style=None):
    """`toonkit.smear` on the evaluated data, with the skin the bake read."""
    from bl_ext.user_default.toonkit import job, style as style_mod

    s, _ = job.cached(bpy.context.scene)
    check(sorted(s.names) == sorted(o.name for o in objs), f"baked {s.names}")
    objs[:] = [bpy.data.objects[n] for n in s.names]  # the bake's object order
    positions = evaluated_with_originals(objs)
    check(positions.shape == s.positions.shape, f"{positions.shape} vs {s.positions.shape}")
    # Pose-only sampling skins in the core: Blender's vertices within float precision
    # (docs/blender.md); the smear, whose discrete choices float noise may flip, is then
    # checked on the bake's own sample.
    diag = float(np.linalg.norm(np.ptp(positions[0], axis=0)))
    check(rel(positions, s.positions, diag) <= TOL, "the bake sampled other vertices")
    positions = s.positions
    # The bake hands the core the Y-up world of glTF and the CLI (docs/blender.md, "Axes").
    skin = s.skin and dict(s.skin, matrices=s.skin["matrices"][..., [0, 2, 1, 3], :]
                           * np.array([1, 1, -1, 1], np.float32)[:, None])
    scene = toonkit.Scene.from_arrays(y_up(positions), s.triangles, fps=s.fps, skin=skin,
                                      objects=s.objects, attributes=s.attributes, rest=s.rest)
    settings = bpy.context.scene.toonkit_smear
    prepared = toonkit.smear.prepare(scene, smooth=settings.smooth)
    return positions, InWorld(toonkit.smear.stylize(
        prepared, style or style_mod.from_settings(settings, s.bones)))


def y_up(p):
    """Blender's Z-up world as the glTF exporter turns it: (x, y, z) -> (x, z, -y)."""
    return p[..., [0, 2, 1]] * np.array([1, 1, -1], p.dtype)


def z_up(p):
    return p[..., [0, 2, 1]] * np.array([1, -1, 1], p.dtype)


class InWorld:
    """The module's result turned back into Blender's world."""

    def __init__(self, look):
        self.elongated = z_up(look.elongated)
        self.multiples = [dict(c, positions=z_up(c["positions"])) for c in look.multiples]
        self.lines = look.lines


def evaluated_with_originals(objs):
    shown = [(o, o.hide_get(), o.hide_render) for o in objs]
    for o in objs:
        o.hide_set(False)
    try:
        return evaluated(objs)
    finally:
        for o, hidden, render in shown:
            o.hide_set(hidden)
            o.hide_render = render


def check_every_frame(objs, look, what="elongated"):
    scene = bpy.context.scene
    want = look.elongated
    diag = float(np.linalg.norm(want[0].max(0) - want[0].min(0)))
    worst = 0.0
    for k, f in enumerate(range(scene.frame_start, scene.frame_end + 1)):
        scene.frame_set(f)
        got = np.concatenate([world_positions(b) for b in bodies(objs)])
        worst = max(worst, rel(got, want[k], diag))
    check(worst <= TOL, f"{what}: worst frame differs by {worst:.2e} of the diagonal")
    return worst


def bake():
    r = bpy.ops.toonkit.smear_bake()
    check(r == {"FINISHED"}, f"smear_bake returned {r}")


def test_robot_bake_matches_the_module_on_every_frame():
    scene, meshes = robot()
    bake()
    positions, look = expected(meshes)  # (meshes now in the bake's order)
    scene.toonkit_smear.live = False
    bpy.ops.toonkit.smear_unbake()
    before = evaluated(meshes)
    check(before.shape == (81, 7214, 3), f"robot Dance: {before.shape}")
    diag = float(np.linalg.norm(np.ptp(before[0], axis=0)))
    check(rel(positions, before, diag) <= TOL, "hidden originals evaluate otherwise")
    select(meshes)
    bake()
    scene.toonkit_smear.live = True
    worst = check_every_frame(meshes, look)
    moved = np.abs(look.elongated - before).max()
    check(moved > 1e-3, "the smear changes nothing")
    REPORT["robot_worst_relative_error"] = worst

    # Live slider: restyle from cached offsets; benchmark smear_update.
    s = scene.toonkit_smear
    s.live = False
    # Wall time depends on the machine's load (CI shares 2 cores); process CPU time (all
    # threads, so an upper bound of an idle machine's wall time) is what the target checks.
    times, cpu = [], []
    for beta in (1.0, 2.0, 4.0, 6.0, 5.0, 3.0, 2.0):
        s.beta_max = beta
        t, c = time.perf_counter(), time.process_time()
        r = bpy.ops.toonkit.smear_update()
        times.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
        check(r == {"FINISHED"}, f"smear_update returned {r}")
    wall, cpu_ms = 1000 * float(np.median(times)), 1000 * float(np.median(cpu))
    REPORT.update(smear_update_wall_ms=round(wall, 1), smear_update_cpu_ms=round(cpu_ms, 1),
                  smear_update_wall_runs=[round(1000 * t, 1) for t in times],
                  load_average=os.getloadavg()[0])
    print(f"benchmark: smear_update on the robot (7,214 vertices, 81 frames, bpy.ops call incl. "
          f"depsgraph update): median CPU {cpu_ms:.1f} ms (target <= 100 ms), wall {wall:.1f} ms "
          f"at load average {os.getloadavg()[0]:.1f}")
    # The target is printed, not asserted: CI's shared machines measured 51-92 ms of CPU for
    # the same binary, so a check at 100 ms fails on a slower runner without any change. Only
    # a step back to per-frame Python work (seconds) fails the test.
    check(cpu_ms <= SMEAR_UPDATE_CEILING_MS,
          f"smear_update takes {cpu_ms:.1f} ms of CPU, over {SMEAR_UPDATE_CEILING_MS} ms "
          f"(target <= 100 ms)")
    _, look = expected(meshes)
    check_every_frame(meshes, look, "after smear_update")
    s.live = True
    s.beta_max = 2.5  # the update callback restyles too
    _, look = expected(meshes)
    check_every_frame(meshes, look, "after a live slider change")

    # Unbake restores the original evaluated positions exactly and leaves no trace.
    bpy.ops.toonkit.smear_unbake()
    np.testing.assert_array_equal(evaluated(meshes), before)
    check(not [o for o in bpy.data.objects if "toonkit_role" in o], "toonkit objects remain")
    check("toonkit smear" not in bpy.data.node_groups, "node group remains")
    check("toonkit" not in bpy.data.collections, "collection remains")
    check(not [m for m in bpy.data.meshes if m.name.endswith(" smear")], "meshes remain")
    check(all(not o.hide_get() and not o.hide_render for o in meshes), "originals still hidden")


def test_multiples_and_lines_show_with_alpha():
    scene, meshes = robot()
    s = scene.toonkit_smear
    s.live = False
    s.multiples, s.past, s.future, s.lines, s.line_count = True, 2, 1, True, 30
    s.live = True
    bake()
    _, look = expected(meshes)
    copies = [o for o in bpy.data.objects if o.get("toonkit_role") == "multiple"]
    check(len(copies) == len(look.multiples) == 3 * len(meshes),
          f"{len(copies)} copy objects for {len(look.multiples)} multiples")
    # Every copy at every frame = the module's copy, its alpha attribute = the module's alpha.
    from bl_ext.user_default.toonkit import job

    sample = job.cached(scene)[0]
    worst = 0.0
    multiples = look.multiples  # (each access builds new dicts)
    for c in multiples[:6]:
        src = sample.names[c["object"]]
        same = [m for m in multiples if sample.names[m["object"]] == src]
        k = next(i for i, m in enumerate(same) if m is c)
        obj = next(o for o in copies if o["toonkit_source"] == src and o["toonkit_index"] == k)
        for i, f in enumerate(range(scene.frame_start, scene.frame_end + 1, 7)):
            alpha = attribute(obj, "tk_alpha", np.float32, frame=f)
            k_frame = f - scene.frame_start
            np.testing.assert_allclose(alpha, c["alpha"][k_frame], atol=1e-6)
            diag = float(np.ptp(c["positions"][0], axis=0).max()) or 1.0
            worst = max(worst, rel(world_positions(obj), c["positions"][k_frame], diag))
    check(worst <= TOL, f"multiples differ by {worst:.2e}")
    lines = [o for o in bpy.data.objects if o.get("toonkit_role") == "lines"]
    check(len(lines) == len(look.lines), f"{len(lines)} line objects, {len(look.lines)} expected")
    shown = 0
    for f in range(scene.frame_start, scene.frame_end + 1):
        scene.frame_set(f)
        k = f - scene.frame_start
        want = sum(len(ln["frames"][k]["positions"]) for ln in look.lines)
        got = sum(len(world_positions(o)) for o in lines)
        check(got == want, f"frame {f}: {got} line points shown, {want} expected")
        shown += got
    check(shown > 0, "no motion line shows at any frame")
    # Fewer copies: the extra copy objects go away.
    s.past = 1
    check(len([o for o in bpy.data.objects if o.get("toonkit_role") == "multiple"])
          == 2 * len(meshes), "restyle with fewer copies left stale copies")


def test_render_save_reload_unbake():
    scene, meshes = robot()
    p = evaluated(meshes)  # render the fastest frame: the smear shows most there
    speed = np.linalg.norm(p[2:] - p[:-2], axis=2).mean(axis=1)
    frame = scene.frame_start + 1 + int(np.argmax(speed))
    REPORT["render_frame"] = frame
    scene.frame_set(frame)
    cam_data = bpy.data.cameras.new("cam")
    cam = bpy.data.objects.new("cam", cam_data)
    scene.collection.objects.link(cam)
    cam.location = (0.0, -13.0, 1.8)
    cam.rotation_euler = (1.5708, 0.0, 0.0)
    scene.camera = cam
    light = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    scene.collection.objects.link(light)
    engine = render_engine(scene)
    scene.render.resolution_x, scene.render.resolution_y = 360, 400
    scene.render.image_settings.file_format = "PNG"
    plain = render(scene, "unbaked.png")
    select(meshes)
    s = scene.toonkit_smear
    s.live = False
    s.preset, s.beta_max, s.lines, s.line_count, s.line_length = "LINEAR", 4.0, True, 40, 4.0
    bake()
    smeared = render(scene, "smear.png")
    side_by_side(plain, smeared, "unbaked_and_smear.png")  # the README's picture
    diff = np.abs(plain - smeared).max(axis=2)
    changed = float((diff > 0.05).mean())
    REPORT["render_engine"] = engine
    REPORT["render_changed_pixels"] = changed
    check(changed > 0.001, f"the render barely changes ({changed:.4%} of the pixels)")

    scene.frame_set(33)
    before = np.concatenate([world_positions(b) for b in bodies(meshes)])
    path = os.path.join(OUT, "smear.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path)
    bpy.ops.wm.open_mainfile(filepath=path)
    scene = bpy.context.scene
    scene.frame_set(33)
    meshes = [bpy.data.objects[o] for o in [m.name for m in meshes]] if False else [
        o for o in bpy.data.objects if o.type == "MESH" and o.name != "Icosphere"
        and "toonkit_role" not in o]
    after = np.concatenate([world_positions(b) for b in bodies(meshes)])
    np.testing.assert_array_equal(after, before)
    scene.frame_set(frame)
    again = render(scene, "smear_reloaded.png")
    check(np.abs(again - smeared).max() < 0.02, "the reloaded render differs")
    # A restyle after reload samples again (no cached offsets) and still matches.
    select(bodies(meshes))
    r = bpy.ops.toonkit.smear_update()
    check(r == {"FINISHED"}, f"smear_update after reload returned {r}")
    _, look = expected(meshes)
    check_every_frame(meshes, look, "after reload")
    bpy.ops.toonkit.smear_unbake()
    scene.frame_set(frame)
    back = render(scene, "unbaked_again.png")
    check(np.abs(back - plain).max() < 0.02, "unbake did not restore the render")


def render_engine(scene):
    for engine in ("BLENDER_WORKBENCH", "BLENDER_EEVEE_NEXT", "BLENDER_EEVEE", "CYCLES"):
        try:
            scene.render.engine = engine
        except TypeError:
            continue
        try:
            bpy.ops.render.render(write_still=False)
            return engine
        except RuntimeError:
            continue
    raise AssertionError("no render engine works headless")


def render(scene, name):
    path = os.path.join(OUT, name)
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(path, check_existing=False)
    px = np.array(img.pixels[:], np.float32).reshape(img.size[1], img.size[0], img.channels)
    bpy.data.images.remove(img)
    return px[..., :3]


def side_by_side(a, b, name):
    both = np.concatenate([a, b], axis=1)
    h, w, _ = both.shape
    img = bpy.data.images.new(name, w, h)
    img.pixels.foreach_set(np.concatenate([both, np.ones((h, w, 1), np.float32)], 2).ravel())
    img.filepath_raw, img.file_format = os.path.join(OUT, name), "PNG"
    img.save()
    bpy.data.images.remove(img)


def keyed_cube(name, keys, size=1.0):
    """A cube with location keys {frame: x}."""
    bpy.ops.mesh.primitive_cube_add(size=size)
    cube = bpy.context.active_object
    cube.name = name
    for f, x in keys.items():
        cube.location = (x, 0.0, 0.0)
        cube.keyframe_insert("location", frame=f)
    return cube


def test_bone_parented_prop_and_non_bone_vertex_groups():
    scene, meshes = robot()
    arm = bpy.data.objects["RobotArmature"]
    bpy.ops.mesh.primitive_cube_add(size=0.3)
    prop = bpy.context.active_object
    prop.name = "Sword"
    prop.parent, prop.parent_type, prop.parent_bone = arm, "BONE", "LowerArmR"
    hand = bpy.data.objects["HandR_1"]
    paint = hand.vertex_groups.new(name="paint")
    paint.add(list(range(0, len(hand.data.vertices), 2)), 1.0, "REPLACE")
    hand.vertex_groups.new(name="unrelated")
    objs = meshes + [prop]
    select(objs)
    bake()
    _, look = expected(objs)
    check_every_frame(objs, look, "with a bone-parented prop")
    from bl_ext.user_default.toonkit import job

    sample = job.cached(scene)[0]
    check(sample.skin["object_parents"][-1] == sample.bones.index("LowerArmR"),
          "the prop does not ride its bone")
    # The painted group restricts the smear: unpainted vertices keep their input positions.
    s = scene.toonkit_smear
    s.weight_group = "paint"
    positions, look = expected(objs)
    check_every_frame(objs, look, "with a painted weight group")
    r = sample.ranges[sample.names.index("HandR_1")]
    unpainted = np.arange(r.start, r.stop)[1::2]
    np.testing.assert_array_equal(look.elongated[:, unpainted], positions[:, unpainted])
    s.weight_group = "ShoulderR"  # a bone: its skin weights
    _, look = expected(objs)
    check_every_frame(objs, look, "with a bone weight group")


def test_still_hold_and_clip_shorter_than_the_range():
    scene = empty_scene()
    cube = keyed_cube("Mover", {1: 0.0, 10: 4.0, 20: 4.0, 30: 8.0})
    scene.frame_start, scene.frame_end = 1, 45  # the clip ends at 30
    select([cube])
    s = scene.toonkit_smear
    s.live = False
    s.preset, s.beta_max = "LINEAR", 2.0
    bake()
    positions, look = expected([cube])
    check(np.isfinite(look.elongated).all(), "NaN in the smear")
    check_every_frame([cube], look, "hold and short clip")
    body = bodies([cube])[0]
    # Held frames (12-18) and frames after the clip (35-45) show the object where it is:
    # nothing vanishes, nothing stays frozen in a smeared pose.
    for f in list(range(12, 19)) + list(range(35, 46)):
        got = world_positions(body, f)
        check(np.abs(got - positions[f - 1]).max() < 1e-5, f"frame {f}: not the held pose")
    moving = np.abs(world_positions(body, 5) - positions[4]).max()
    check(moving > 1e-2, "no smear while moving")
    # Outside the baked range the display clamps to the range's ends.
    np.testing.assert_allclose(world_positions(body, 60), positions[-1], atol=1e-6)


def test_cesium_man_and_camera_relative_speed():
    scene = empty_scene()
    bpy.ops.import_scene.gltf(filepath=os.path.join(ASSETS, "CesiumMan.glb"))
    arm = next(o for o in bpy.data.objects if o.type == "ARMATURE")
    first, last = arm.animation_data.action.frame_range
    scene.frame_start, scene.frame_end = int(first), int(last)
    # The glTF importer adds an "Icosphere" as the bones' display shape: not the character.
    meshes = [o for o in bpy.data.objects if o.type == "MESH" and o.name != "Icosphere"]
    select(meshes)
    bake()
    # The bake's size unit is the rest pose's the CLI and the module measure on the file
    # (docs/smear-units.md): CesiumMan's bind pose, not its first frame (1.914 vs 1.784).
    size, module = baked_size(scene), toonkit.load(os.path.join(ASSETS, "CesiumMan.glb")).size
    check(abs(size - module) <= 1e-5 * module, f"CesiumMan: Blender's rest size {size:.6f} vs "
          f"the module's {module:.6f}")
    REPORT["cesium_man_size"] = size
    _, look = expected(meshes)
    check_every_frame(meshes, look, "CesiumMan")
    world = look.elongated
    # A still camera: camera-relative offsets give the same smear.
    cam = bpy.data.objects.new("cam", bpy.data.cameras.new("cam"))
    scene.collection.objects.link(cam)
    cam.location, cam.rotation_euler = (1.0, -5.0, 1.0), (1.3, 0.2, 0.1)
    scene.camera = cam
    scene.toonkit_smear.camera_relative = True
    select(bodies(meshes))  # a re-bake: the results stand for their hidden originals
    bake()
    got = np.stack([np.concatenate([world_positions(b, f) for b in bodies(meshes)])
                    for f in range(scene.frame_start, scene.frame_end + 1)])
    diag = float(np.linalg.norm(np.ptp(world[0], axis=0)))
    check(rel(got, world, diag) < 1e-4, f"camera-relative with a still camera differs "
                                        f"by {rel(got, world, diag):.2e}")


def test_errors_leave_the_scene_unchanged():
    scene = empty_scene()
    cube = keyed_cube("Cube", {1: 0.0, 10: 3.0})
    scene.frame_start, scene.frame_end = 1, 10
    for o in bpy.data.objects:
        o.select_set(False)

    def fails(op, needle):
        names = sorted(o.name for o in bpy.data.objects)
        try:
            r = op()
        except RuntimeError as e:  # the operator's ERROR report, raised by bpy.ops
            msg = str(e)
            check(needle in msg and "Traceback" not in msg, f"unexpected message {msg!r}")
            check(len(msg.strip().splitlines()) <= 2, f"not one line: {msg!r}")
        else:
            raise AssertionError(f"{op} returned {r}, expected an error")
        check(sorted(o.name for o in bpy.data.objects) == names, "the scene changed")

    fails(bpy.ops.toonkit.smear_bake, "select at least one mesh")
    fails(bpy.ops.toonkit.smear_update, "nothing is baked")
    select([cube])
    m = cube.modifiers.new("grow", "BUILD")
    m.frame_start, m.frame_duration = 1, 8
    fails(bpy.ops.toonkit.smear_bake, "vertex count changes")
    cube.modifiers.remove(m)
    s = scene.toonkit_smear
    s.live = False
    s.preset, s.custom_style = "CUSTOM", json.dumps({"elongate": {"function": {"expr": "2 *"}}})
    fails(bpy.ops.toonkit.smear_bake, "smear bake:")
    s.preset = "SPEED"
    bake()
    s.preset, s.custom_style = "CUSTOM", json.dumps({"lines": {"count": -3}})
    before = world_positions(bodies([cube])[0], 5)
    fails(bpy.ops.toonkit.smear_update, "smear update:")
    np.testing.assert_array_equal(world_positions(bodies([cube])[0], 5), before)


def test_style_files_round_trip():
    scene = empty_scene()
    s = scene.toonkit_smear
    s.live = False
    s.preset, s.beta_max, s.sign, s.warp, s.warp_p = "NOISE", 7.5, "PAST", True, 0.7
    s.multiples, s.spacing_mode, s.spacing, s.lines, s.line_count = True, "SPACING", 0.25, True, 12
    s.on_twos, s.weight_group = True, "paint"
    from bl_ext.user_default.toonkit import style

    path = os.path.join(OUT, "panel.toml")
    r = bpy.ops.toonkit.style_save(filepath=path)
    check(r == {"FINISHED"}, f"style_save returned {r}")
    written = style.from_settings(s)
    scene.toonkit_smear.beta_max = 1.0
    r = bpy.ops.toonkit.style_load(filepath=path)
    check(r == {"FINISHED"}, f"style_load returned {r}")
    check(style.from_settings(s) == written and s.preset == "NOISE",
          "a saved style does not load back")
    # A CLI example with expressions loads as written ("From file").
    example = os.path.join(os.path.dirname(os.path.dirname(HERE)), "examples", "smear",
                           "fig16_combined.toml")
    bpy.ops.toonkit.style_load(filepath=example)
    check(s.preset == "CUSTOM" and style.from_settings(s) == style.read(example),
          "the CLI example is not kept as written")


def smeared_relative(scale):
    """The speed preset's elongation on the robot with every root object scaled by `scale`:
    mean and largest vertex displacement over the clip, relative to the bounding-box diagonal."""
    scene, meshes = robot("Punch")
    for o in bpy.data.objects:
        if o.parent is None:
            o.scale = [c * scale for c in o.scale]
    bpy.context.view_layer.update()
    s = scene.toonkit_smear
    s.live = False
    s.preset, s.beta_max = "SPEED", 1.0
    bake()
    size = baked_size(scene)
    s.live = True
    smeared = evaluated(bodies(meshes))
    s.live = False
    bpy.ops.toonkit.smear_unbake()
    before = evaluated(meshes)
    diag = float(np.linalg.norm(np.ptp(before[0], axis=0)))
    moved = np.linalg.norm(smeared - before, axis=2) / diag
    return float(moved.mean()), float(moved.max()), size


def baked_size(scene):
    """The size unit the bake's style was measured in (docs/smear-units.md)."""
    from bl_ext.user_default.toonkit import job

    _, prepared = job.cached(scene)
    return toonkit.smear.stylize(prepared, {"elongate": {}}).report["size"]


def test_a_style_means_the_same_in_centimetres_and_metres():
    # Speeds are in character sizes per second (docs/smear-units.md): a scene at 0.01x or
    # 100x scale smears the same relative to its size, with no special case for units.
    base = smeared_relative(1.0)
    check(base[0] > 1e-4, f"the speed preset smears nothing: {base}")
    # The size follows the root scale. (Not compared with the module's on the glTF file: with
    # the importer's default bone heuristic the robot's bone-parented parts sit off their
    # bones, docs/blender.md; test_presets.py compares the file with a Temperance import.)
    for scale in (0.01, 100.0):
        got = smeared_relative(scale)
        check(abs(got[2] - scale * base[2]) <= 1e-4 * scale * base[2],
              f"x{scale}: size {got[2]} vs {scale * base[2]}")
        for a, b, what in zip(got[:2], base[:2], ("mean", "largest")):
            check(abs(a - b) <= 0.01 * b, f"x{scale}: {what} elongation {a:.5f} of the "
                  f"diagonal vs {b:.5f} at 1x (tolerance 1 %)")
    REPORT["scale_invariance"] = {"mean": base[0], "largest": base[1], "size": base[2]}


if __name__ == "__main__":
    code = run([
        test_style_files_round_trip,
        test_errors_leave_the_scene_unchanged,
        test_still_hold_and_clip_shorter_than_the_range,
        test_robot_bake_matches_the_module_on_every_frame,
        test_multiples_and_lines_show_with_alpha,
        test_bone_parented_prop_and_non_bone_vertex_groups,
        test_cesium_man_and_camera_relative_speed,
        test_render_save_reload_unbake,
        test_a_style_means_the_same_in_centimetres_and_metres,
    ])
    finish(code, REPORT, OUT)
