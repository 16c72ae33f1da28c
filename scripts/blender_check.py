#!/usr/bin/env python3
"""Check that toonkit's outputs open correctly in Blender (bpy as a Python module, headless).

Usage:
    python3 -m venv /work/venv-blender
    /work/venv-blender/bin/pip install bpy==4.2.0 "numpy<2"
    /work/venv-blender/bin/python scripts/blender_check.py DIR [--bvh FILE]

DIR must hold the files made by:
    toonkit convert RobotExpressive.glb DIR/dance_flip.glb  --clip Dance
    toonkit convert RobotExpressive.glb DIR/dance_morph.glb --clip Dance --as morph
    toonkit convert RobotExpressive.glb DIR/dance.pc2       --clip Dance   (+ dance.obj)
    toonkit convert RobotExpressive.glb DIR/dance.mdd       --clip Dance   (+ dance.obj)
    toonkit convert 02_02.bvh           DIR/walk.glb

The PC2 file is the reference for the positions of every frame (read with numpy, not with
Blender). Every case starts from an empty factory scene, imports with Blender's own
importers, evaluates the depsgraph and compares numbers. One PASS/FAIL line per case.
"""

import argparse
import json
import logging
import os
import struct
import sys

import numpy as np
import bpy

TOL = 1e-4


# ----------------------------------------------------------------------------- readers
def read_pc2(path):
    with open(path, "rb") as f:
        b = f.read()
    magic, version, points, start, rate, samples = struct.unpack("<12siiffi", b[:32])
    assert magic == b"POINTCACHE2\0", magic
    pos = np.frombuffer(b, dtype="<f4", offset=32).reshape(samples, points, 3)
    return dict(version=version, points=points, start=start, rate=rate, samples=samples), pos


def read_mdd(path):
    with open(path, "rb") as f:
        b = f.read()
    frames, points = struct.unpack(">ii", b[:8])
    times = np.frombuffer(b, dtype=">f4", count=frames, offset=8).astype(np.float64)
    pos = np.frombuffer(b, dtype=">f4", offset=8 + 4 * frames).reshape(frames, points, 3)
    return times, pos.astype(np.float32)


def read_obj_vertices(path):
    vs = []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                vs.append([float(x) for x in line.split()[1:4]])
    return np.array(vs, dtype=np.float64)


def read_glb_json(path):
    with open(path, "rb") as f:
        b = f.read()
    n = struct.unpack("<I", b[12:16])[0]
    return json.loads(b[20:20 + n])


def bvh_frames(path):
    frames = frame_time = None
    with open(path) as f:
        for line in f:
            if line.startswith("Frames:"):
                frames = int(line.split()[1])
            elif line.startswith("Frame Time:"):
                frame_time = float(line.split()[2])
                break
    return frames, frame_time


# ----------------------------------------------------------------------------- helpers
def y_up_to_z_up(p):
    """glTF (Y up) to Blender (Z up) as the glTF importer does it: (x, y, z) -> (x, -z, y)."""
    p = np.asarray(p, dtype=np.float64)
    return np.stack([p[..., 0], -p[..., 2], p[..., 1]], axis=-1)


def empty_scene():
    bpy.ops.wm.read_factory_settings(use_empty=True)


def world_positions(obj, dg):
    """Depsgraph-evaluated vertex positions of `obj` in world space (float64, N×3)."""
    ev = obj.evaluated_get(dg)
    me = ev.to_mesh()
    co = np.empty(len(me.vertices) * 3, dtype=np.float32)
    me.vertices.foreach_get("co", co)
    ev.to_mesh_clear()
    co = co.reshape(-1, 3).astype(np.float64)
    m = np.array(ev.matrix_world, dtype=np.float64)
    return co @ m[:3, :3].T + m[:3, 3]


def nn_max(a, b, chunk=512):
    """max over points of a of the distance to the nearest point of b (brute force)."""
    b2 = (b * b).sum(1)
    worst = 0.0
    for i in range(0, len(a), chunk):
        x = a[i:i + chunk]
        d2 = (x * x).sum(1)[:, None] + b2[None, :] - 2.0 * x @ b.T
        worst = max(worst, float(np.sqrt(max(d2.min(1).max(), 0.0))))
    return worst


def deviation(got, want):
    """(max deviation, how): ordered when counts match, else symmetric point-set distance."""
    if got.shape == want.shape:
        return float(np.abs(got - want).max()), "ordered"
    return max(nn_max(got, want), nn_max(want, got)), "point-set"


def set_frame(scene, frame):
    whole = int(np.floor(frame))
    scene.frame_set(whole, subframe=float(frame - whole))
    return bpy.context.evaluated_depsgraph_get()


RESULTS = []


def report(case, ok, dev, detail):
    line = f"{'PASS' if ok else 'FAIL'} {case}: max deviation {dev:.3g} ({detail})"
    RESULTS.append(ok)
    print(line, flush=True)


def note(msg):
    print(f"  - {msg}", flush=True)


# ----------------------------------------------------------------------------- cases
def check_flipbook(path, ref, clip_fps):
    empty_scene()
    scene = bpy.context.scene
    scene_fps = scene.render.fps / scene.render.fps_base
    bpy.ops.import_scene.gltf(filepath=path, loglevel=logging.WARNING)
    meshes = [o for o in scene.objects if o.type == "MESH"]
    samples = len(ref)
    note(f"{len(meshes)} mesh objects, PC2 has {samples} samples")
    # frame index from the node name  <name>_fNNNN (1-based)
    by_frame = {}
    for o in meshes:
        try:
            by_frame[int(o.name.rsplit("_f", 1)[1]) - 1] = o
        except (IndexError, ValueError):
            pass
    ok = len(meshes) == samples and sorted(by_frame) == list(range(samples))
    if not ok:
        note("object names do not map one-to-one onto frames")
    step = scene_fps / clip_fps  # glTF importer: key time t lands on scene frame t * scene fps
    note(f"clip {clip_fps:g} fps, scene {scene_fps:g} fps: sample k at scene frame {step:g}*k "
         "(the glTF importer puts t = 0 on frame 0)")
    worst, how_seen, vis_errors, counts = 0.0, set(), [], set()
    # every sample at its key, plus half way to the next key (STEP must hold the value)
    for k in range(samples):
        for frac in (0.0, 0.5) if k + 1 < samples else (0.0,):
            dg = set_frame(scene, (k + frac) * step)
            visible = [o for o in meshes
                       if max(abs(s) for s in o.evaluated_get(dg).matrix_world.to_scale()) > 1e-6]
            if len(visible) != 1 or visible[0] is not by_frame.get(k):
                vis_errors.append((k + frac, [o.name for o in visible]))
                continue
            got = world_positions(visible[0], dg)
            counts.add(len(got))
            d, how = deviation(got, y_up_to_z_up(ref[k]))
            how_seen.add(how)
            worst = max(worst, d)
    if vis_errors:
        ok = False
        note(f"{len(vis_errors)} evaluated frames without exactly the right visible object, "
             f"first: {vis_errors[:3]}")
    else:
        note(f"exactly one visible object, the right one, at all {2 * samples - 1} "
             "evaluated frames (keys and half-way)")
    note(f"vertex counts per frame object: {sorted(counts)} vs cache {ref.shape[1]} "
         f"({'match' if counts == {ref.shape[1]} else 'DIFFER'}); compared {'/'.join(sorted(how_seen))}")
    ok = ok and worst <= TOL
    report("flipbook glb", ok, worst, f"{len(meshes)} frame objects, positions vs PC2")


def check_morph(path, ref, clip_fps):
    empty_scene()
    scene = bpy.context.scene
    scene_fps = scene.render.fps / scene.render.fps_base
    bpy.ops.import_scene.gltf(filepath=path, loglevel=logging.WARNING)
    meshes = [o for o in scene.objects if o.type == "MESH"]
    samples = len(ref)
    ok = len(meshes) == 1
    if not ok:
        report("morph glb", False, float("nan"), f"{len(meshes)} mesh objects, expected 1")
        return
    obj = meshes[0]
    keys = obj.data.shape_keys.key_blocks if obj.data.shape_keys else []
    n_keys = len(keys) - 1 if len(keys) else 0  # minus "Basis"
    note(f"1 mesh, {n_keys} shape keys besides Basis (PC2 samples: {samples})")
    ok = n_keys == samples
    nv = len(obj.data.vertices)
    note(f"vertex count: Blender {nv}, cache {ref.shape[1]} "
         f"({'match' if nv == ref.shape[1] else 'DIFFER'})")
    step = scene_fps / clip_fps
    worst, hows, per_frame = 0.0, set(), []
    for k in range(samples):
        for frac in (0.0, 0.5) if k + 1 < samples else (0.0,):
            dg = set_frame(scene, (k + frac) * step)
            d, how = deviation(world_positions(obj, dg), y_up_to_z_up(ref[k]))
            hows.add(how)
            per_frame.append(d)
            worst = max(worst, d)
    bad = [i for i, d in enumerate(per_frame) if d > TOL]
    if bad:
        note(f"{len(bad)} evaluated frames off by more than {TOL:g}; first (index/2 = sample): "
             f"{[(i / 2, round(per_frame[i], 6)) for i in bad[:5]]}")
    note(f"compared {'/'.join(sorted(hows))} at every key and half-way between keys")
    ok = ok and worst <= TOL
    report("morph glb", ok, worst, f"{n_keys} shape keys, evaluated mesh vs PC2")


def check_cache(fmt, cache_path, obj_path, ref, frame_of_sample, expected_sample_in_seconds_mode):
    """Rest OBJ + Mesh Cache modifier. frame_of_sample: what the file says (for the report)."""
    empty_scene()
    scene = bpy.context.scene
    # forward Y / up Z: the importer's identity (its default -Z/Y would rotate Y-up to Z-up)
    bpy.ops.wm.obj_import(filepath=obj_path, forward_axis="Y", up_axis="Z")
    objs = [o for o in scene.objects if o.type == "MESH"]
    if len(objs) != 1:
        report(f"{fmt} cache", False, float("nan"), f"{len(objs)} mesh objects from the OBJ")
        return
    obj = objs[0]
    nv = len(obj.data.vertices)
    file_v = read_obj_vertices(obj_path)
    note(f"OBJ import: {nv} vertices, file has {len(file_v)} 'v' lines, cache {ref.shape[1]} points "
         f"({'match' if nv == ref.shape[1] else 'DIFFER: Mesh Cache will refuse'})")
    dg = bpy.context.evaluated_depsgraph_get()
    rest = world_positions(obj, dg)
    if rest.shape == file_v.shape:
        note(f"OBJ import keeps vertex order and axes: max |blender - file| = "
             f"{np.abs(rest - file_v).max():.3g}")
    mod = obj.modifiers.new("cache", "MESH_CACHE")
    mod.cache_format = fmt
    mod.filepath = cache_path
    note(f"modifier: time_mode={mod.time_mode} play_mode={mod.play_mode} "
         f"frame_start={mod.frame_start:g} frame_scale={mod.frame_scale:g} "
         f"axes forward={mod.forward_axis} up={mod.up_axis} interpolation={mod.interpolation}")
    samples = len(ref)
    # which sample does each Blender frame show?
    mapping, worst_match = {}, 0.0
    for f in range(-1, samples + 2):
        dg = set_frame(scene, f)
        got = world_positions(obj, dg)
        if got.shape != ref.shape[1:]:
            mapping[f] = None
            continue
        d = np.abs(got[None] - ref).max(axis=(1, 2))
        k = int(d.argmin())
        mapping[f] = (k, float(d[k]))
    shown = {f: m[0] for f, m in mapping.items() if m}
    offsets = {f - k for f, k in shown.items() if 0 < k < samples - 1}
    note("Blender frame -> sample shown: " + ", ".join(
        f"{f}->{shown.get(f)}" for f in [-1, 0, 1, 2, samples - 1, samples, samples + 1]))
    note(f"file says sample k is at {frame_of_sample}")
    if offsets == {0}:
        note("sample k lands on Blender frame k (sample 0 on frame 0; the default scene starts "
             "at frame 1, where sample 1 shows)")
    elif offsets == {1}:
        note("sample k lands on Blender frame k+1")
    else:
        note(f"irregular frame mapping, offsets {sorted(offsets)}")
    # deviation at the frames where the sample should land (interior samples)
    off = offsets.pop() if len(offsets) == 1 else 0
    worst = 0.0
    for k in range(samples):
        m = mapping.get(k + off)
        if m is None:
            worst = float("inf")
            break
        dg = set_frame(scene, k + off)
        worst = max(worst, float(np.abs(world_positions(obj, dg) - ref[k]).max()))
    # time_mode TIME (seconds): Blender takes scene time f / scene fps and (MDD) looks it up in
    # the file's frame times, or (PC2) turns it back into frames with the scene fps.
    scene_fps = scene.render.fps / scene.render.fps_base
    mod.time_mode = "TIME"
    worst_t, probe = 0.0, []
    for f in sorted({0, 1, 2, 3, 5, 10, samples // 2, samples - 1}):
        s = expected_sample_in_seconds_mode(f, scene_fps)
        s = min(max(s, 0.0), samples - 1.0)
        k0 = int(np.floor(s))
        k1 = min(k0 + 1, samples - 1)
        want = ref[k0] + (s - k0) * (ref[k1] - ref[k0])
        got = world_positions(obj, set_frame(scene, f))
        d = float(np.abs(got - want).max())
        probe.append(f"{f}->{s:.3g}")
        worst_t = max(worst_t, d)
    note(f"time_mode=TIME: scene frame -> expected (fractional) sample {', '.join(probe)}; "
         f"max deviation from the interpolated cache {worst_t:.3g}"
         f"{'' if worst_t <= TOL else '  <-- MISMATCH'}")
    mod.time_mode = "FRAME"
    ok = nv == ref.shape[1] and worst <= TOL and len(offsets) == 0 and worst_t <= TOL
    report(f"{fmt} cache", ok, worst,
           f"OBJ + Mesh Cache, sample k on Blender frame k+{off}, {samples} samples")
    return off


def check_skeleton(path, bvh_path):
    empty_scene()
    scene = bpy.context.scene
    scene_fps = scene.render.fps / scene.render.fps_base
    j = read_glb_json(path)
    n_nodes = len(j["nodes"])
    anim = j["animations"][0]
    t_max = max(j["accessors"][s["input"]]["max"][0] for s in anim["samplers"])
    bpy.ops.import_scene.gltf(filepath=path, loglevel=logging.WARNING)
    arms = [o for o in scene.objects if o.type == "ARMATURE"]
    empties = [o for o in scene.objects if o.type == "EMPTY"]
    n_bones = sum(len(a.data.bones) for a in arms)
    note(f"glb: {n_nodes} nodes, {len(j.get('skins', []))} skin(s), clip '{anim.get('name')}' "
         f"{len(anim['channels'])} channels, last key {t_max:.6g} s")
    note(f"Blender: {len(arms)} armature(s) with {n_bones} bones, {len(empties)} empties")
    ok = bool(arms) or bool(empties)
    actions = []
    for o in arms + empties:
        ad = o.animation_data
        if ad and ad.action:
            actions.append(ad.action)
    expect_end = t_max * scene_fps
    worst = float("inf")
    if actions:
        a = actions[0]
        fr = tuple(a.frame_range)
        n_fc = len(a.fcurves)
        worst = max(abs(fr[0] - 0.0), abs(fr[1] - expect_end))
        note(f"action '{a.name}': frame range {fr[0]:g}..{fr[1]:g}, expected 0..{expect_end:g} "
             f"(t_max × {scene_fps:g} fps), {n_fc} fcurves")
    else:
        ok = False
        note("no active action")
    if bvh_path and os.path.exists(bvh_path):
        frames, ft = bvh_frames(bvh_path)
        bvh_dur = (frames - 1) * ft
        note(f"BVH: {frames} frames × {ft:g} s = {bvh_dur:.6g} s; glb last key {t_max:.6g} s "
             f"(diff {abs(bvh_dur - t_max):.3g} s)")
        ok = ok and abs(bvh_dur - t_max) < 1e-3
        # pose sanity: bones move between first and last frame
        if arms:
            arm = arms[0]
            set_frame(scene, 0)
            p0 = np.array([list(arm.matrix_world @ b.head) for b in arm.pose.bones])
            set_frame(scene, expect_end / 2)
            p1 = np.array([list(arm.matrix_world @ b.head) for b in arm.pose.bones])
            note(f"pose moves: max bone-head displacement frame 0 -> mid {np.abs(p1 - p0).max():.3g}")
            ok = ok and np.abs(p1 - p0).max() > 1e-3
    ok = ok and worst <= 1e-3
    report("BVH skeleton glb", ok, worst, "action frame range vs clip (frames)")


# ----------------------------------------------------------------------------- main
def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dir")
    ap.add_argument("--bvh", default=os.path.join(os.path.dirname(__file__), "..", "..",
                                                  "shared", "data", "mocap", "02_02.bvh"))
    args = ap.parse_args()
    d = args.dir
    print(f"Blender {bpy.app.version_string}, numpy {np.__version__}")
    hdr, ref = read_pc2(os.path.join(d, "dance.pc2"))
    times, mdd = read_mdd(os.path.join(d, "dance.mdd"))
    clip_fps = 1.0 / float(np.mean(np.diff(times))) if len(times) > 1 else 24.0
    print(f"reference PC2: {hdr}; MDD: {len(times)} frames, times {times[0]:g}..{times[-1]:g} s "
          f"({clip_fps:.4g} fps), max |MDD - PC2| = {np.abs(mdd - ref).max():.3g}")

    print("\n[flipbook] dance_flip.glb")
    check_flipbook(os.path.join(d, "dance_flip.glb"), ref, clip_fps)
    print("\n[morph] dance_morph.glb")
    check_morph(os.path.join(d, "dance_morph.glb"), ref, clip_fps)
    print("\n[pc2] dance.obj + dance.pc2")
    check_cache("PC2", os.path.join(d, "dance.pc2"), os.path.join(d, "dance.obj"), ref,
                f"frame start + k*rate = {hdr['start']:g} + k*{hdr['rate']:g}",
                # Blender's PC2 reader in seconds mode computes ((seconds / fps) - start) / sampling,
                # i.e. divides by the frame rate twice (a Blender quirk), so TIME mode with PC2
                # stays near sample 0 whatever the file says; the check models exactly that.
                lambda f, scene_fps: ((f / scene_fps) / scene_fps - hdr["start"]) / hdr["rate"])
    print("\n[mdd] dance.obj + dance.mdd")
    check_cache("MDD", os.path.join(d, "dance.mdd"), os.path.join(d, "dance.obj"), mdd,
                f"time {times[0]:g} + k/{clip_fps:.4g} s (= frame k at {clip_fps:.4g} fps)",
                lambda f, scene_fps: float(np.interp(f / scene_fps, times, np.arange(len(times)))))
    print("\n[bvh] walk.glb")
    check_skeleton(os.path.join(d, "walk.glb"), os.path.abspath(args.bvh))

    n_ok = sum(RESULTS)
    print(f"\n{n_ok} passed, {len(RESULTS) - n_ok} failed")
    return 0 if all(RESULTS) else 1


if __name__ == "__main__":
    code = main()
    sys.stdout.flush()
    sys.stderr.flush()
    # bpy 4.2 as a module can crash while the interpreter tears it down; the results are in.
    os._exit(code)
