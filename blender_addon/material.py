"""A ready material for wet cloth: the baked wetness (the point attribute
wet_cloth_wetness, per frame) darkens the cloth's colour and makes it
glossier, as water does to fabric.

The setup is one node group, "Wet Cloth Shading" (Color, Roughness, Wetness
in; the wet Color and Roughness out), put between a Principled BSDF and what
fed its Base Color and Roughness, with an Attribute node reading the
wetness. Made once per .blend and recognised by a mark; adding it again to
a material that has it changes nothing.
"""

import bpy

from . import stack

GROUP = "Wet Cloth Shading"
_MARK = "wet_cloth_shading"
_VERSION = 1
# Soaked fabric: colour times this (water lowers the diffuse albedo of
# cloth to about a third), roughness blended toward this (a wet film).
WET_DARKENING = 0.35
WET_ROUGHNESS = 0.2


def shading_group():
    for ng in bpy.data.node_groups:
        if ng.bl_idname == "ShaderNodeTree" and ng.get(_MARK) == _VERSION:
            return ng
    ng = bpy.data.node_groups.new(GROUP, "ShaderNodeTree")
    ng[_MARK] = _VERSION
    face = ng.interface
    face.new_socket("Color", in_out="INPUT", socket_type="NodeSocketColor")
    face.new_socket("Roughness", in_out="INPUT", socket_type="NodeSocketFloat")
    face.new_socket("Wetness", in_out="INPUT", socket_type="NodeSocketFloat")
    face.new_socket("Color", in_out="OUTPUT", socket_type="NodeSocketColor")
    face.new_socket("Roughness", in_out="OUTPUT", socket_type="NodeSocketFloat")
    nodes, links = ng.nodes, ng.links
    gi, go = nodes.new("NodeGroupInput"), nodes.new("NodeGroupOutput")
    gi.location, go.location = (-400.0, 0.0), (400.0, 0.0)

    dark = nodes.new("ShaderNodeMix")
    dark.data_type, dark.blend_type = "RGBA", "MULTIPLY"
    dark.inputs["Factor"].default_value = 1.0
    dark.inputs["B"].default_value = (WET_DARKENING, WET_DARKENING, WET_DARKENING, 1.0)
    links.new(gi.outputs["Color"], dark.inputs["A"])
    dark.location = (-150.0, 150.0)

    color = nodes.new("ShaderNodeMix")
    color.data_type = "RGBA"
    links.new(gi.outputs["Wetness"], color.inputs["Factor"])
    links.new(gi.outputs["Color"], color.inputs["A"])
    links.new(dark.outputs["Result"], color.inputs["B"])
    links.new(color.outputs["Result"], go.inputs["Color"])
    color.location = (100.0, 150.0)

    rough = nodes.new("ShaderNodeMix")
    rough.data_type = "FLOAT"
    links.new(gi.outputs["Wetness"], rough.inputs["Factor"])
    links.new(gi.outputs["Roughness"], rough.inputs["A"])
    rough.inputs["B"].default_value = WET_ROUGHNESS
    links.new(rough.outputs["Result"], go.inputs["Roughness"])
    rough.location = (100.0, -150.0)
    return ng


def _principled(mat):
    for node in mat.node_tree.nodes:
        if node.bl_idname == "ShaderNodeBsdfPrincipled":
            return node
    return None


def _has_setup(mat):
    return any(n.bl_idname == "ShaderNodeGroup" and n.node_tree is not None and
               n.node_tree.get(_MARK) == _VERSION for n in mat.node_tree.nodes)


def _feed(links, group_input, bsdf_input):
    """What fed bsdf_input now feeds group_input (or its value is copied)."""
    if bsdf_input.is_linked:
        link = bsdf_input.links[0]
        links.new(link.from_socket, group_input)
        links.remove(link)
    else:
        value = bsdf_input.default_value
        group_input.default_value = value[:] if hasattr(value, "__len__") else value


def add_wet_shading(ob):
    """Adds the setup to the object's active material (a new material when
    it has none). Returns (material, whether anything was added)."""
    mat = ob.active_material
    if mat is None:
        mat = bpy.data.materials.new("Wet Cloth")
        mat.use_nodes = True
        if ob.material_slots:
            ob.active_material = mat
        else:
            ob.data.materials.append(mat)
    if not mat.use_nodes:
        mat.use_nodes = True
    if _has_setup(mat):
        return mat, False
    bsdf = _principled(mat)
    if bsdf is None:
        raise ValueError("the material %s has no Principled BSDF to make wet" % mat.name)
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    group = nodes.new("ShaderNodeGroup")
    group.node_tree = shading_group()
    group.label = "Wet Cloth"
    group.location = (bsdf.location.x - 250.0, bsdf.location.y)
    attr = nodes.new("ShaderNodeAttribute")
    attr.attribute_type = "GEOMETRY"
    attr.attribute_name = stack.WETNESS_ATTRIBUTE
    attr.location = (group.location.x - 250.0, group.location.y - 200.0)
    _feed(links, group.inputs["Color"], bsdf.inputs["Base Color"])
    _feed(links, group.inputs["Roughness"], bsdf.inputs["Roughness"])
    links.new(attr.outputs["Fac"], group.inputs["Wetness"])
    links.new(group.outputs["Color"], bsdf.inputs["Base Color"])
    links.new(group.outputs["Roughness"], bsdf.inputs["Roughness"])
    return mat, True
