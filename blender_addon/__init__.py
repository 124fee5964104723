"""Wet Cloth: bakes wet cloth with libwetcloth onto Blender mesh objects.

Properties > Physics > Wet Cloth on a mesh; bpy.ops.wetcloth.bake(),
bpy.ops.wetcloth.bake_all() and bpy.ops.wetcloth.free_bake() from scripts.

Modules: props (the settings), ui (the panels), presets (Blender's preset
menu), ops (the operators), bake (a bake, frame by frame), fields (Blender's
force fields at the cloth), stack (the Wet Cloth modifiers), cache (where
the files go, which ones an object may touch), outdated (the handlers),
material (the wet material).

The physics is libwetcloth's, called through the `wetcloth` package bundled
in this extension (cffi ABI mode; the cffi wheel ships with it).
"""

from . import bake, ops, outdated, presets, props, ui

_modules = (props, presets, ops, ui, outdated)


def register():
    for m in _modules:
        m.register()


def unregister():
    for m in reversed(_modules):
        m.unregister()
