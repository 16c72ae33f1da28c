import bpy, math
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.fps = 24
scene.frame_start, scene.frame_end = 1, 13
# A 2-bone armature and a 2x2x4 box skinned to it, with one shape key.
arm_data = bpy.data.armatures.new("rig")
arm = bpy.data.objects.new("rig", arm_data)
scene.collection.objects.link(arm)
bpy.context.view_layer.objects.active = arm
bpy.ops.object.mode_set(mode="EDIT")
b0 = arm_data.edit_bones.new("root"); b0.head = (0, 0, 0); b0.tail = (0, 0, 2)
b1 = arm_data.edit_bones.new("tip"); b1.head = (0, 0, 2); b1.tail = (0, 0, 4); b1.parent = b0
bpy.ops.object.mode_set(mode="OBJECT")
bpy.ops.mesh.primitive_cube_add(size=2, location=(0, 0, 2))
box = bpy.context.active_object
box.name = "box"
box.scale = (0.5, 0.5, 2.0)
bpy.ops.object.transform_apply(scale=True, location=True)
g0 = box.vertex_groups.new(name="root"); g1 = box.vertex_groups.new(name="tip")
for v in box.data.vertices:
    (g1 if v.co.z > 2 else g0).add([v.index], 1.0, "REPLACE")
mod = box.modifiers.new("skin", "ARMATURE"); mod.object = arm
box.parent = arm
box.shape_key_add(name="Basis")
key = box.shape_key_add(name="bulge")
for i, v in enumerate(key.data):
    v.co.x *= 1.5
key.value = 0.0
key.keyframe_insert("value", frame=1)
key.value = 1.0
key.keyframe_insert("value", frame=13)
bpy.context.view_layer.objects.active = arm
bpy.ops.object.mode_set(mode="POSE")
tip = arm.pose.bones["tip"]
tip.rotation_mode = "XYZ"
tip.rotation_euler = (0, 0, 0); tip.keyframe_insert("rotation_euler", frame=1)
tip.rotation_euler = (math.radians(60), 0, 0); tip.keyframe_insert("rotation_euler", frame=13)
bpy.ops.object.mode_set(mode="OBJECT")
arm.animation_data.action.name = "bend"
cam_data = bpy.data.cameras.new("cam"); cam_data.lens = 35
cam = bpy.data.objects.new("cam", cam_data); cam.location = (0, -10, 2); cam.rotation_euler = (math.radians(90), 0, 0)
scene.collection.objects.link(cam)
import sys
out = sys.argv[-1]
bpy.ops.export_scene.fbx(filepath=out, bake_anim=True, bake_anim_use_all_actions=True, bake_anim_use_nla_strips=False, add_leaf_bones=False, axis_forward="-Z", axis_up="Y")
bpy.ops.export_scene.gltf(filepath=out.replace(".fbx", ".glb"), export_format="GLB")
