"""Wet Cloth: bakes wet cloth with libwetcloth onto Blender mesh objects.

Properties > Physics > Wet Cloth on a mesh; bpy.ops.wetcloth.bake() and
bpy.ops.wetcloth.free_bake() from scripts. See docs/blender.md.

The physics is libwetcloth's, called through the `wetcloth` package bundled
in this extension (cffi ABI mode; the cffi wheel ships with it).
"""

from . import bake, ops, props, ui

_modules = (props, ops, ui)


def register():
    for m in _modules:
        m.register()


def unregister():
    for m in reversed(_modules):
        m.unregister()
