#!/usr/bin/env python3
"""Exports toonkit's bundled characters with a real exporter (Blender 4.2, `bpy`, headless),
for the reader checks of issue 24 (`crates/io/tests/exporters.rs`).

Usage: python .ci/io_export.py OUT_DIR ASSET...

For every asset (a .glb/.gltf) it imports the file into an empty scene and writes
- NAME.glb: plain glTF (the reference every other file is compared with);
- NAME_lights.glb: glTF with a point light added (KHR_lights_punctual);
- NAME.fbx: binary FBX 7.4 with the animation baked per action and shape keys.
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
    actions = [a for a in bpy.data.actions]
    # The importer sets the frame range of the active action only; use the longest.
    if actions:
        start = min(int(a.frame_range[0]) for a in actions)
        end = max(int(a.frame_range[1]) for a in actions)
        scene.frame_start, scene.frame_end = start, end
    return scene


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
        bpy.ops.export_scene.fbx(
            filepath=str(out / f"{name}.fbx"),
            bake_anim=True,
            bake_anim_use_all_actions=True,
            bake_anim_use_nla_strips=False,
            bake_anim_force_startend_keying=True,
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
