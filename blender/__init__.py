"""toonkit for Blender: smear frames (elongated in-betweens, multiples, motion lines) from
whatever Blender evaluates, on the bundled `toonkit` Python module.

Operators: `bpy.ops.toonkit.smear_bake()`, `bpy.ops.toonkit.smear_update()`,
`bpy.ops.toonkit.smear_unbake()`, `bpy.ops.toonkit.stopmo_run()`,
`bpy.ops.toonkit.loa_animate()`; settings in `context.scene.toonkit_smear`, `toonkit_stopmo`,
`toonkit_loa`; panels in View3D ▸ Sidebar ▸ toonkit.
"""

from . import loa_ui, operators, panel, settings, stopmo_ui, weights

_MODULES = (settings, weights, operators, panel, stopmo_ui, loa_ui)


def register():
    for m in _MODULES:
        m.register()


def unregister():
    for m in reversed(_MODULES):
        m.unregister()
