"""Wet Cloth presets through Blender's preset system, as Blender's cloth
has them: the preset button in the Wet Cloth panel's header lists the
presets that come with the add-on (presets/wet_cloth/ in it) and the user's
own (Blender's user scripts folder, presets/wet_cloth/), and adds or
removes the user's own with + and -."""

import os

import bpy
from bl_operators.presets import AddPresetBase
from bl_ui.utils import PresetPanel

SUBDIR = "wet_cloth"
BUNDLED = os.path.join(os.path.dirname(os.path.abspath(__file__)), "presets", SUBDIR)

# What a preset holds: the material, as Blender's cloth presets hold its
# physical properties (not the pins, groups, colliders or cache).
VALUES = ("density", "air_drag", "stretch", "bend", "damping", "thickness", "friction",
          "adhesion", "spread", "wet_friction", "wet_grip", "wet_mass_gain", "wet_softening",
          "wicking", "drying")


def preset_folders():
    """Where presets are listed from: the add-on's, then the user's."""
    return [BUNDLED] + [p for p in bpy.utils.preset_paths(SUBDIR) if p != BUNDLED]


class WETCLOTH_PT_presets(PresetPanel, bpy.types.Panel):
    bl_label = "Wet Cloth Presets"
    preset_subdir = SUBDIR
    preset_operator = "script.execute_preset"
    preset_add_operator = "wetcloth.preset_add"

    def draw(self, _context):
        layout = self.layout
        layout.emboss = "PULLDOWN_MENU"
        layout.operator_context = "EXEC_DEFAULT"
        self.path_menu(preset_folders(), self.preset_operator,
                       props_default={"menu_idname": type(self).__name__},
                       filter_ext=lambda ext: ext.lower() == ".py",
                       add_operator=self.preset_add_operator,
                       display_name=lambda name: bpy.path.display_name(name, title_case=False))


class WETCLOTH_OT_preset_add(AddPresetBase, bpy.types.Operator):
    """Add or remove a Wet Cloth preset"""
    bl_idname = "wetcloth.preset_add"
    bl_label = "Add Wet Cloth Preset"
    preset_menu = "WETCLOTH_PT_presets"
    preset_defines = ["s = bpy.context.object.wet_cloth"]
    preset_values = ["s.%s" % v for v in VALUES]
    preset_subdir = SUBDIR


classes = (WETCLOTH_PT_presets, WETCLOTH_OT_preset_add)


def register():
    for c in classes:
        bpy.utils.register_class(c)


def unregister():
    for c in reversed(classes):
        bpy.utils.unregister_class(c)
