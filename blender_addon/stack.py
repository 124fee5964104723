"""The Wet Cloth modifiers in the object's modifier stack.

As Blender's Cloth modifier does, the "Wet Cloth" modifier marks where the
simulation sits in the stack: the cloth is the mesh as the modifiers above
it leave it (a Subdivision Surface above simulates the subdivided mesh), and
the modifiers below it apply to the baked result (a Solidify below thickens
the simulated sheet). Enabling Wet Cloth adds it at the end of the stack,
as Blender adds its Cloth modifier; it can be moved like any modifier.

"Wet Cloth" is a Mesh Cache modifier that plays the bake's point cache.
Right above it a bake adds two more, so that the wetness and stuck state of
every baked frame reach shaders at that frame, in the viewport and in any
render (a render farm needs only the .blend and the cache files, not this
add-on): "Wet Cloth Wetness", a Mesh Cache modifier playing a second point
cache whose x and y are each vertex's wetness and stuck flag, and "Wet Cloth
Attributes", a Geometry Nodes modifier that stores them as the point
attributes wet_cloth_wetness and wet_cloth_stuck before "Wet Cloth"
overwrites the positions with the baked ones (a deform modifier keeps
attributes).
"""

import bpy

POSITIONS = "Wet Cloth"
WETNESS = "Wet Cloth Wetness"
ATTRIBUTES = "Wet Cloth Attributes"
# the name of the point cache modifier before the wetness modifiers existed
_OLD_POSITIONS = "Wet Cloth Cache"

WETNESS_ATTRIBUTE = "wet_cloth_wetness"
STUCK_ATTRIBUTE = "wet_cloth_stuck"

NODE_GROUP = "Wet Cloth Attributes"
_NODE_GROUP_MARK = "wet_cloth_attributes"
_NODE_GROUP_VERSION = 1


def cloth_modifier(ob):
    """The "Wet Cloth" modifier, or None."""
    m = ob.modifiers.get(POSITIONS)
    if m is not None and m.type == "MESH_CACHE":
        return m
    old = ob.modifiers.get(_OLD_POSITIONS)
    if old is not None and old.type == "MESH_CACHE" and m is None:
        old.name = POSITIONS
        return old
    return None


def _setup_mesh_cache(m):
    m.cache_format = "PC2"
    m.frame_scale = 1.0
    m.play_mode = "SCENE"
    m.time_mode = "FRAME"
    m.deform_mode = "OVERWRITE"
    m.interpolation = "LINEAR"
    m.forward_axis = "POS_Y"
    m.up_axis = "POS_Z"
    m.factor = 1.0


def ensure_cloth_modifier(ob):
    """The "Wet Cloth" modifier, added at the end of the stack if missing
    (with no cache it leaves the mesh as it is)."""
    m = cloth_modifier(ob)
    if m is None:
        m = ob.modifiers.new(POSITIONS, "MESH_CACHE")
        _setup_mesh_cache(m)
        m.filepath = ""
    return m


def _ours(ob):
    return [m for m in ob.modifiers if m.name in (POSITIONS, WETNESS, ATTRIBUTES)]


def first_index(ob):
    """Index of the first Wet Cloth modifier in the stack (the cloth is what
    the modifiers before it make), or None."""
    for i, m in enumerate(ob.modifiers):
        if m.name in (POSITIONS, WETNESS, ATTRIBUTES):
            return i
    return None


def hide_from_cloth(ob):
    """Turns off in the viewport the Wet Cloth modifiers and every modifier
    below them, so that the object evaluates to the mesh the simulation
    takes. Returns their names for restore()."""
    start = first_index(ob)
    hidden = []
    if start is not None:
        for m in list(ob.modifiers)[start:]:
            if m.show_viewport:
                m.show_viewport = False
                hidden.append(m.name)
    return hidden


def restore(ob, hidden):
    """Turns back on what hide_from_cloth() turned off."""
    for name in hidden:
        m = ob.modifiers.get(name)
        if m is not None:
            m.show_viewport = True


def attributes_node_group():
    """The Geometry Nodes group that stores a Mesh Cache's x and y as the
    wetness and stuck attributes (made once per .blend; recognised by a
    mark, so a user's group of the same name is left alone)."""
    for ng in bpy.data.node_groups:
        if ng.bl_idname == "GeometryNodeTree" and ng.get(_NODE_GROUP_MARK) == _NODE_GROUP_VERSION:
            return ng
    ng = bpy.data.node_groups.new(NODE_GROUP, "GeometryNodeTree")
    ng[_NODE_GROUP_MARK] = _NODE_GROUP_VERSION
    ng.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    ng.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    nodes, links = ng.nodes, ng.links
    group_in = nodes.new("NodeGroupInput")
    group_out = nodes.new("NodeGroupOutput")
    position = nodes.new("GeometryNodeInputPosition")
    xyz = nodes.new("ShaderNodeSeparateXYZ")
    links.new(position.outputs["Position"], xyz.inputs[0])
    geometry = group_in.outputs[0]
    for i, name in enumerate((WETNESS_ATTRIBUTE, STUCK_ATTRIBUTE)):
        store = nodes.new("GeometryNodeStoreNamedAttribute")
        store.data_type = "FLOAT"
        store.domain = "POINT"
        store.inputs["Name"].default_value = name
        links.new(geometry, store.inputs["Geometry"])
        links.new(xyz.outputs[i], store.inputs["Value"])
        store.location = (200.0 * (i + 1), 0.0)
        geometry = store.outputs["Geometry"]
    links.new(geometry, group_out.inputs[0])
    group_in.location, group_out.location = (-200.0, 0.0), (600.0, 0.0)
    position.location, xyz.location = (-200.0, -200.0), (0.0, -200.0)
    return ng


def _move_before(ob, name, anchor):
    """Moves modifier `name` to just above modifier `anchor`."""
    names = [m.name for m in ob.modifiers]
    src, dst = names.index(name), names.index(anchor)
    if src > dst:
        ob.modifiers.move(src, dst)
    elif src < dst - 1:
        ob.modifiers.move(src, dst - 1)


def hook_up(ob, positions_file, wetness_file, start_frame):
    """Points the modifiers at a new bake's files (paths as Blender should
    keep them: "//" relative where the file is saved). The Wet Cloth
    modifier keeps the visibility the artist gave it."""
    cloth = ensure_cloth_modifier(ob)
    _setup_mesh_cache(cloth)
    cloth.filepath = positions_file
    cloth.frame_start = float(start_frame)

    wet = ob.modifiers.get(WETNESS)
    if wet is None or wet.type != "MESH_CACHE":
        if wet is not None:
            ob.modifiers.remove(wet)
        wet = ob.modifiers.new(WETNESS, "MESH_CACHE")
    _setup_mesh_cache(wet)
    wet.filepath = wetness_file
    wet.frame_start = float(start_frame)
    wet.show_expanded = False

    attrs = ob.modifiers.get(ATTRIBUTES)
    if attrs is None or attrs.type != "NODES":
        if attrs is not None:
            ob.modifiers.remove(attrs)
        attrs = ob.modifiers.new(ATTRIBUTES, "NODES")
    attrs.node_group = attributes_node_group()
    attrs.show_expanded = False
    sync(ob)


def sync(ob):
    """Keeps the wetness modifiers with the Wet Cloth modifier: right above
    it, shown when it is shown (alone they would leave the mesh's positions
    at the wetness values), and gone when it is gone (the files stay).
    Returns whether anything changed."""
    cloth = cloth_modifier(ob)
    ours = [ob.modifiers.get(n) for n in (WETNESS, ATTRIBUTES)]
    changed = False
    if cloth is None:
        for m in ours:
            if m is not None:
                ob.modifiers.remove(m)
                changed = True
        return changed
    for m in ours:
        if m is None:
            continue
        for attr in ("show_viewport", "show_render"):
            if getattr(m, attr) != getattr(cloth, attr):
                setattr(m, attr, getattr(cloth, attr))
                changed = True
    names = [m.name for m in ob.modifiers]
    want = [m.name for m in ours if m is not None] + [POSITIONS]
    at = names.index(POSITIONS) - len(want) + 1
    if names[at:at + len(want)] != want:
        for name in want[:-1]:
            _move_before(ob, name, POSITIONS)
        changed = True
    return changed


def referenced_files(ob):
    """Absolute paths of the cache files the object's Wet Cloth modifiers
    play."""
    out = set()
    for m in _ours(ob):
        if m.type == "MESH_CACHE" and m.filepath:
            out.add(bpy.path.abspath(m.filepath, library=ob.library))
    return out


def remove_bake(ob, keep_cloth_modifier):
    """Removes the wetness modifiers, and the cloth modifier unless it is to
    stay (then it plays nothing). Returns whether anything changed."""
    changed = False
    for name in (WETNESS, ATTRIBUTES):
        m = ob.modifiers.get(name)
        if m is not None:
            ob.modifiers.remove(m)
            changed = True
    cloth = cloth_modifier(ob)
    if cloth is not None:
        if keep_cloth_modifier:
            if cloth.filepath:
                cloth.filepath = ""
                changed = True
        else:
            ob.modifiers.remove(cloth)
            changed = True
    return changed
