"""The "Wet Cloth" panels in Properties > Physics, laid out like Blender's
own cloth panels."""

import bpy

from . import bake, props


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

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        s = context.object.wet_cloth
        layout.active = s.enabled
        layout.prop(s, "preset")
        col = layout.column()
        col.prop(s, "density", text="Density kg/m²")
        col.prop(s, "thickness", text="Thickness m")
        col.prop(s, "wetness", text="Wetness")


class PHYSICS_PT_wet_cloth_stiffness(_WetClothSubPanel, bpy.types.Panel):
    bl_label = "Stiffness"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        s = context.object.wet_cloth
        col = layout.column()
        col.prop(s, "stretch", text="Stretch N/m")
        col.prop(s, "bend", text="Bending N·m")
        col.prop(s, "damping")
        col.prop(s, "air_drag", text="Air Drag N·s/m³")


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
        col.prop(s, "adhesion", text="Adhesion Pa")
        col.prop(s, "spread")
        col.prop(s, "wet_friction")
        col.prop(s, "wet_mass_gain")
        col.prop(s, "wet_softening")
        col.prop(s, "wicking", text="Wicking m²/s")
        col.prop(s, "drying", text="Drying 1/s")


class PHYSICS_PT_wet_cloth_shape(_WetClothSubPanel, bpy.types.Panel):
    bl_label = "Shape"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        ob = context.object
        layout.prop_search(ob.wet_cloth, "pin_group", ob, "vertex_groups", text="Pin Group")


class PHYSICS_PT_wet_cloth_collisions(_WetClothSubPanel, bpy.types.Panel):
    bl_label = "Collisions"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        s = context.object.wet_cloth
        col = layout.column()
        col.prop(s, "use_colliders")
        sub = col.column()
        sub.active = s.use_colliders
        sub.prop(s, "collision_collection", text="Collection")
        col.prop(s, "friction")
        col.prop(s, "self_collision")
        col.prop(s, "collide_with_cloths")


class PHYSICS_PT_wet_cloth_cache(_WetClothSubPanel, bpy.types.Panel):
    bl_label = "Cache"
    bl_options = set()

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        ob = context.object
        s = ob.wet_cloth
        col = layout.column()
        col.prop(s, "use_scene_range")
        sub = col.column(align=True)
        if s.use_scene_range:
            sub.enabled = False
            start, end = props.frame_range(s, context.scene)
            sub.label(text="Frames %d to %d" % (start, end))
        else:
            sub.prop(s, "frame_start", text="Frame Start")
            sub.prop(s, "frame_end", text="End")
        col.prop(s, "integrator")
        if s.integrator == "IMPLICIT":
            col.prop(s, "implicit_tolerance")
        col.prop(s, "substeps_auto")
        sub = col.column()
        sub.active = not s.substeps_auto
        sub.prop(s, "substeps")
        col.prop(s, "cache_dir")

        row = layout.row(align=True)
        row.use_property_split = False
        row.operator("wetcloth.bake", text="Bake", icon="PHYSICS")
        row.operator("wetcloth.free_bake", text="Free Bake", icon="TRASH")
        row = layout.row(align=True)
        row.use_property_split = False
        row.operator("wetcloth.bake_all", text="Bake All", icon="PHYSICS")
        row.operator("wetcloth.free_bake_all", text="Free All", icon="TRASH")
        if s.cache_file:
            box = layout.box()
            box.label(text="Baked: " + s.bake_info, icon="CHECKMARK")
            box.label(text=s.cache_file)
            if ob.modifiers.get(bake.MODIFIER_NAME) is None:
                box.label(text="The Mesh Cache modifier was removed", icon="ERROR")


classes = (PHYSICS_PT_wet_cloth, PHYSICS_PT_wet_cloth_stiffness, PHYSICS_PT_wet_cloth_wetness,
           PHYSICS_PT_wet_cloth_shape, PHYSICS_PT_wet_cloth_collisions,
           PHYSICS_PT_wet_cloth_cache)


def register():
    for c in classes:
        bpy.utils.register_class(c)


def unregister():
    for c in reversed(classes):
        bpy.utils.unregister_class(c)
