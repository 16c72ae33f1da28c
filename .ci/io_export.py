#!/usr/bin/env python3
"""Exports toonkit's bundled characters with a real exporter (Blender 4.2, `bpy`, headless),
for the reader checks of issue 24 (`crates/io/tests/exporters.rs`).

Usage: python .ci/io_export.py OUT_DIR ASSET...

For every asset (a .glb/.gltf) it imports the file into an empty scene and writes
- NAME.glb: plain glTF (the reference every other file is compared with);
- NAME_lights.glb: glTF with a point light added (KHR_lights_punctual);
- NAME.fbx: binary FBX 7.4 with the animation baked per action (or the scene's timeline for a
  mesh animated by shape keys only) and shape keys.
Each export covers the same frame range (the scene's, set by the glTF importer).
"""

import os
import pathlib
import sys

import bpy


def reset():
    bpy.ops.wm.read_factory_settings(use_empty=True)


def import_gltf(path):
    reset()
    bpy.ops.import_scene.gltf(filepath=str(path))
    scene = bpy.context.scene
    # Keys land on frames like 0.9999989 (CesiumMan's first key at 1/24 s): Blender's glTF
    # exporter truncates that to frame 0 and its FBX exporter does not; snap to whole frames.
    for action in bpy.data.actions:
        for fc in action.fcurves:
            for k in fc.keyframe_points:
                shift = round(k.co.x) - k.co.x
                k.co.x += shift
                k.handle_left.x += shift
                k.handle_right.x += shift
    key_unkeyed_bones_at_rest()
    actions = [a for a in bpy.data.actions]
    # The importer sets the frame range of the active action only; use the longest.
    if actions:
        start = min(round(a.frame_range[0]) for a in actions)
        end = max(round(a.frame_range[1]) for a in actions)
        scene.frame_start, scene.frame_end = start, end
    return scene


def key_unkeyed_bones_at_rest():
    """Keys, in every armature action, the bones it leaves unkeyed at their rest pose.

    Blender's two exporters disagree on such bones: the glTF exporter resets them to rest
    between actions, the FBX exporter keeps the pose the previously baked action left. Keyed
    at rest, both files describe the same animation.
    """
    rest = {"location": (0.0, 0.0, 0.0), "rotation_quaternion": (1.0, 0.0, 0.0, 0.0),
            "scale": (1.0, 1.0, 1.0)}
    arms = [o for o in bpy.data.objects if o.type == "ARMATURE"]
    for action in bpy.data.actions:
        paths = {fc.data_path for fc in action.fcurves}
        if not any(p.startswith("pose.bones") for p in paths):
            continue
        start = action.frame_range[0]
        for arm in arms:
            for bone in arm.pose.bones:
                base = f'pose.bones["{bone.name}"].'
                if base + "rotation_euler" in paths:
                    paths.add(base + "rotation_quaternion")
                for prop, values in rest.items():
                    if base + prop in paths:
                        continue
                    for i, v in enumerate(values):
                        fc = action.fcurves.new(base + prop, index=i, action_group=bone.name)
                        fc.keyframe_points.insert(start, v)


def export_gltf(path, **extra):
    bpy.ops.export_scene.gltf(
        filepath=str(path),
        export_format="GLB",
        export_animations=True,
        export_morph=True,
        export_skins=True,
        **extra,
    )


def main():
    out = pathlib.Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    for asset in map(pathlib.Path, sys.argv[2:]):
        name = asset.stem
        # A fresh import before every export: the FBX exporter's baking changes the scene.
        import_gltf(asset)
        export_gltf(out / f"{name}.glb")
        import_gltf(asset)
        light = bpy.data.lights.new("lamp", type="POINT")
        obj = bpy.data.objects.new("lamp", light)
        bpy.context.scene.collection.objects.link(obj)
        export_gltf(out / f"{name}_lights.glb", export_lights=True)
        import_gltf(asset)
        # The glTF importer adds helper objects (bone shapes, e.g. an 'Icosphere') to a
        # 'glTF_not_exported' collection: the glTF exporter skips them, the FBX exporter
        # would write them as meshes of the character.
        helpers = bpy.data.collections.get("glTF_not_exported")
        for obj in list(helpers.objects) if helpers else []:
            bpy.data.objects.remove(obj, do_unlink=True)
        # One stack per action of an armature or object; a mesh animated by shape keys only
        # has no such action: bake the scene's timeline into one stack instead.
        per_action = any(o.animation_data and o.animation_data.action for o in bpy.data.objects)
        bpy.ops.export_scene.fbx(
            filepath=str(out / f"{name}.fbx"),
            bake_anim=True,
            bake_anim_use_all_actions=per_action,
            bake_anim_use_nla_strips=False,
            bake_anim_force_startend_keying=True,
            # No key reduction (its default 1.0 drops keys within a tolerance: 6e-4 of the
            # robot's diagonal between keys), so the FBX holds the glTF's poses at every frame.
            bake_anim_simplify_factor=0.0,
            add_leaf_bones=False,
            use_mesh_modifiers=False,
            axis_forward="-Z",
            axis_up="Y",
        )
        print(f"exported {name}: glb, lights, fbx")


if __name__ == "__main__":
    main()
    # bpy 4.2 as a module can crash while the interpreter shuts down; the files are written.
    sys.stdout.flush()
    os._exit(0)
