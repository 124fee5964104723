"""The "Wet Cloth" panels in Properties > Physics, laid out as Blender's own
Cloth panels are: presets in the header, the quality in the main panel,
then Physical Properties, Shape, Collisions, Wetness, Field Weights and
Cache."""

import os

import bpy

from . import bake, cache, presets, stack


class _WetClothPanel:
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "physics"

    @classmethod
    def poll(cls, context):
        ob = context.object
        return ob is not None and ob.type == "MESH"


class _WetClothSubPanel(_WetClothPanel):
    bl_parent_id = "PHYSICS_PT_wet_cloth"
    bl_options = {"DEFAULT_CLOSED"}

    @classmethod
    def poll(cls, context):
        ob = context.object
        return ob is not None and ob.type == "MESH" and ob.wet_cloth.enabled


class PHYSICS_PT_wet_cloth(_WetClothPanel, bpy.types.Panel):
    bl_label = "Wet Cloth"

    def draw_header(self, context):
        self.layout.prop(context.object.wet_cloth, "enabled", text="")

    def draw_header_preset(self, context):
        if context.object.wet_cloth.enabled:
            presets.WETCLOTH_PT_presets.draw_panel_header(self.layout)

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        ob = context.object
        s = ob.wet_cloth
        if not s.enabled:
            if bake.is_baked(ob):
                layout.label(text="Wet Cloth is off; its bake still plays (Cache: Free Bake "
                                  "removes it)", icon="INFO")
            return
        col = layout.column()
        col.prop(s, "integrator")
        row = col.row(heading="Quality Steps")
        row.prop(s, "substeps_auto", text="Automatic")
        sub = row.row()
        sub.active = not s.substeps_auto
        sub.prop(s, "substeps", text="")
        if s.integrator == "IMPLICIT":
            col.prop(s, "implicit_tolerance")
        if stack.cloth_modifier(ob) is None:
            col.label(text="The Wet Cloth modifier is missing: baking adds it at the end",
                      icon="ERROR")


class PHYSICS_PT_wet_cloth_physical(_WetClothSubPanel, bpy.types.Panel):
    bl_label = "Physical Properties"
    bl_options = set()

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        s = context.object.wet_cloth
        col = layout.column()
        col.prop(s, "density")
        col.prop(s, "air_drag")
        col = layout.column(heading="Stiffness")
        col.prop(s, "stretch")
        col.prop(s, "bend")
        col = layout.column(heading="Damping")
        col.prop(s, "damping")


class PHYSICS_PT_wet_cloth_shape(_WetClothSubPanel, bpy.types.Panel):
    bl_label = "Shape"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        ob = context.object
        s = ob.wet_cloth
        col = layout.column()
        col.prop_search(s, "pin_group", ob, "vertex_groups", text="Pin Group")
        sub = col.column()
        sub.active = bool(s.pin_group)
        sub.prop(s, "pin_stiffness", text="Stiffness")


class PHYSICS_PT_wet_cloth_collisions(_WetClothSubPanel, bpy.types.Panel):
    bl_label = "Collisions"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        s = context.object.wet_cloth
        col = layout.column()
        col.prop(s, "thickness", text="Distance")
        col.prop(s, "friction")
        col.separator()
        col.prop(s, "use_colliders")
        sub = col.column()
        sub.active = s.use_colliders
        sub.prop(s, "collision_collection", text="Collection")
        col.prop(s, "self_collision")
        col.prop(s, "collide_with_cloths")


class PHYSICS_PT_wet_cloth_wetness(_WetClothSubPanel, bpy.types.Panel):
    bl_label = "Wetness"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        ob = context.object
        s = ob.wet_cloth
        col = layout.column()
        col.prop(s, "wetness")
        col.prop_search(s, "wetness_group", ob, "vertex_groups", text="Vertex Group")
        col.separator()
        col.prop(s, "adhesion")
        col.prop(s, "spread")
        col.prop(s, "wet_friction")
        col.prop(s, "wet_grip")
        col.prop(s, "wet_mass_gain")
        col.prop(s, "wet_softening")
        col.prop(s, "wicking")
        col.prop(s, "drying")
        layout.operator("wetcloth.add_wet_material", icon="MATERIAL")


class PHYSICS_PT_wet_cloth_field_weights(_WetClothSubPanel, bpy.types.Panel):
    bl_label = "Field Weights"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        s = context.object.wet_cloth
        col = layout.column()
        col.prop(s, "field_collection", text="Collection")
        col.prop(s, "field_all")
        col.prop(s, "field_gravity")
        col.prop(s, "field_wind")
        col.prop(s, "field_force")
        col.prop(s, "field_turbulence")


class PHYSICS_PT_wet_cloth_cache(_WetClothPanel, bpy.types.Panel):
    bl_label = "Cache"
    bl_parent_id = "PHYSICS_PT_wet_cloth"

    @classmethod
    def poll(cls, context):
        # also when Wet Cloth is off but a bake still plays: Free Bake is here
        ob = context.object
        return ob is not None and ob.type == "MESH" and (ob.wet_cloth.enabled or
                                                         bake.is_baked(ob))

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        ob = context.object
        s = ob.wet_cloth
        col = layout.column(align=True)
        col.active = s.enabled
        col.prop(s, "use_scene_range")
        sub = col.column(align=True)
        if s.use_scene_range:
            sub.enabled = False
            sub.prop(context.scene, "frame_start", text="Frame Start")
            sub.prop(context.scene, "frame_end", text="End")
        else:
            sub.prop(s, "frame_start", text="Frame Start")
            sub.prop(s, "frame_end", text="End")
        col = layout.column()
        col.active = s.enabled
        col.prop(s, "cache_dir")
        col.prop(s, "work_limit")

        grid = layout.column(align=True)
        grid.use_property_split = False
        row = grid.row(align=True)
        row.enabled = s.enabled
        row.operator("wetcloth.bake", text="Bake", icon="PHYSICS")
        row.operator("wetcloth.bake", text="Bake to Current Frame").to_current_frame = True
        row = grid.row(align=True)
        row.operator("wetcloth.free_bake", text="Free Bake", icon="TRASH")
        row = grid.row(align=True)
        row.operator("wetcloth.bake_all", text="Bake All Wet Cloth", icon="PHYSICS")
        row.operator("wetcloth.free_bake_all", text="Free All", icon="TRASH")

        box = layout.box()
        _folder, where = cache.folder_for(s)
        if s.cache_file:
            if s.outdated:
                box.label(text="Outdated: bake again to see the changes", icon="ERROR")
            else:
                box.label(text="Baked: " + s.bake_info, icon="CHECKMARK")
            box.label(text=os.path.basename(s.cache_file), icon="FILE_CACHE")
            if stack.cloth_modifier(ob) is None:
                box.label(text="The Wet Cloth modifier was removed", icon="ERROR")
        else:
            box.label(text="Not baked", icon="INFO")
        if not bpy.data.filepath:
            box.label(text="Bakes go to the temporary folder until the file is saved;")
            box.label(text="saving moves them next to the .blend file")
        else:
            box.label(text="Folder: " + where)


classes = (PHYSICS_PT_wet_cloth, PHYSICS_PT_wet_cloth_physical, PHYSICS_PT_wet_cloth_shape,
           PHYSICS_PT_wet_cloth_collisions, PHYSICS_PT_wet_cloth_wetness,
           PHYSICS_PT_wet_cloth_field_weights, PHYSICS_PT_wet_cloth_cache)


def register():
    for c in classes:
        bpy.utils.register_class(c)


def unregister():
    for c in reversed(classes):
        bpy.utils.unregister_class(c)
