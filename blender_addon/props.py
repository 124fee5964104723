"""Object.wet_cloth: the settings of one Wet Cloth object.

Values are in the library's units: SI, with 1 Blender unit = 1 m, and the
material resolution independent (per area, not per vertex). Blender shows
lengths in the scene's units (their `unit`), and the other units are in each
setting's tooltip.

No setting has hard limits that Blender would clamp to silently: the fields
take any number, and a bake refuses a value outside the library's range
with a message that names the setting, its value and the range
(check_settings). The soft limits only set the sliders' span.
"""

import math
import uuid

import bpy
import numpy as np
from bpy.props import (BoolProperty, EnumProperty, FloatProperty, IntProperty,
                       PointerProperty, StringProperty)

# Field -> (library range lo, hi, lo excluded), as material.c checks them.
MATERIAL_RANGES = {
    "density": (0.0, 1e3, True),
    "stretch": (0.0, 1e9, False),
    "bend": (0.0, 1e3, False),
    "damping": (0.0, 1.0, False),
    "air_drag": (0.0, 1e4, False),
    "thickness": (0.0, 1.0, False),
    "friction": (0.0, 10.0, False),
    "adhesion": (0.0, 1e6, False),
    "spread": (0.0, 1.0, False),
    "wet_friction": (0.0, 1.0, False),
    "wet_grip": (0.0, 1e6, False),
    "wet_mass_gain": (0.0, 10.0, False),
    "wet_softening": (0.0, 0.99, False),
    "wicking": (0.0, 1.0, False),
    "drying": (0.0, 100.0, False),
}
MATERIAL_FIELDS = tuple(MATERIAL_RANGES)

# Other bounded settings: field -> (lo, hi, lo excluded).
OTHER_RANGES = {
    "wetness": (0.0, 1.0, False),
    "pin_stiffness": (0.0, 1e8, True),
    "implicit_tolerance": (0.0, 1e3, False),
    "substeps": (1, 10000000, False),
    "work_limit": (0.0, math.inf, True),
}

# The frame limits of Blender's own cloth cache (-MAXFRAME, MAXFRAME).
MIN_FRAME, MAX_FRAME = -1048574, 1048574

# Vertices whose pin weight is at least this are pinned outright, the others
# pulled toward their place with the weight's share of the pin stiffness
# (Blender's cloth does the same with SOFTGOALSNAP).
HARD_PIN_WEIGHT = 0.999

# Blender 4.5 warns about "//" paths unless the property says it takes them.
_PATH_OPTIONS = ({"PATH_SUPPORTS_BLEND_RELATIVE"} if bpy.app.version >= (4, 5, 0) else set())


def _result_changed(self, _context):
    """Any setting that changes what a bake would give marks the bake
    outdated (the panel says so until it is baked again)."""
    if self.cache_file:
        self.outdated = True


def _enabled_changed(self, context):
    if self.enabled:
        from . import stack  # (stack imports props)
        ob = self.id_data
        if isinstance(ob, bpy.types.Object) and ob.type == "MESH":
            stack.ensure_cloth_modifier(ob)
    _result_changed(self, context)


def _float(name, description, default, soft_min, soft_max, precision=3, step=1, **kw):
    return FloatProperty(name=name, description=description, default=default,
                         soft_min=soft_min, soft_max=soft_max, precision=precision, step=step,
                         update=_result_changed, **kw)


class WetClothSettings(bpy.types.PropertyGroup):
    enabled: BoolProperty(
        name="Wet Cloth", default=False, update=_enabled_changed,
        description="Simulate this mesh as wet cloth when baking. The mesh is taken as the "
                    "modifiers above the Wet Cloth modifier leave it; those below apply to the "
                    "baked result")

    # Quality ---------------------------------------------------------------
    integrator: EnumProperty(
        name="Integrator",
        items=[("VERLET", "Verlet", "Explicit position Verlet: the most exact, but a fine or "
                "stiff cloth needs hundreds of steps per frame"),
               ("XPBD", "Strain Limited",
                "Stretching solved as constraints: stable with few steps per frame however stiff "
                "the cloth is"),
               ("IMPLICIT", "Semi-Implicit",
                "Implicit steps solved with conjugate gradients: stable with few steps per frame, "
                "a little more damped; the best choice for large cloths")],
        default="IMPLICIT", update=_result_changed,
        description="How each step moves the cloth forward in time")
    substeps_auto: BoolProperty(
        name="Automatic", default=True, update=_result_changed,
        description="Take as many steps per frame as the cloth needs to stay stable")
    substeps: IntProperty(
        name="Quality Steps", default=20, soft_min=1, soft_max=1000, update=_result_changed,
        description="Steps per frame when not automatic: more is slower and more exact")
    implicit_tolerance: _float(
        "Solver Tolerance",
        "Semi-Implicit only: how exactly each step is solved, as the acceleration error it may "
        "leave, in m/s² (0 solves exactly). Larger is faster and less exact; the default leaves "
        "drapes and slides where an exact solve puts them", 8.0, 0.0, 50.0)

    # Physical properties ------------------------------------------------------
    density: _float("Density", "Mass of the dry cloth per area, in kg/m²", 0.15, 0.01, 2.0)
    air_drag: _float("Air Drag", "How strongly the air slows the cloth (and wind pulls it), in "
                     "N·s/m³", 0.02, 0.0, 10.0)
    stretch: _float("Stretch", "Resistance to stretching, in N/m", 1000.0, 0.0, 1e5, 1, 100)
    bend: _float("Bending", "Resistance to bending, in N·m", 1e-5, 0.0, 1e-2, 7, 0.0001)
    damping: _float("Stretch Damping", "How quickly stretching oscillations die out, as a "
                    "fraction of critical damping", 0.05, 0.0, 1.0, subtype="FACTOR")

    # Shape ---------------------------------------------------------------------
    pin_group: StringProperty(
        name="Pin Group", default="", update=_result_changed,
        description="Vertex group of pinned vertices: they follow the mesh's own animation. "
                    "Weight 1 holds a vertex in place; a lower weight pulls it there with that "
                    "share of the Pin Stiffness")
    pin_stiffness: _float(
        "Pin Stiffness", "How strongly vertices with a pin weight below 1 are pulled to their "
        "place, in 1/s² (the square of how fast such a vertex swings about its place at "
        "weight 1)", 1000.0, 1.0, 1e5, 1, 100)

    # Collisions ----------------------------------------------------------------
    use_colliders: BoolProperty(
        name="Object Collisions", default=True, update=_result_changed,
        description="Collide with objects that have Collision physics (their Thickness Outer "
                    "and Friction are used)")
    collision_collection: PointerProperty(
        type=bpy.types.Collection, name="Collision Collection", update=_result_changed,
        description="Only collide with objects in this collection (all objects with Collision "
                    "physics when empty)")
    thickness: _float("Thickness", "How far the cloth keeps from what it collides with",
                      0.005, 0.0, 0.1, 4, 0.1, subtype="DISTANCE", unit="LENGTH")
    friction: _float("Friction", "Friction of the cloth against colliders and itself", 0.5,
                     0.0, 2.0)
    self_collision: BoolProperty(name="Self Collisions", default=False, update=_result_changed,
                                 description="Collide the cloth with itself")
    collide_with_cloths: BoolProperty(
        name="Cloth Collisions", default=True, update=_result_changed,
        description="When baked together with other Wet Cloth objects (Bake All): collide with "
                    "those of them that do, and stick to them where wet")

    # Wetness -------------------------------------------------------------------
    wetness: _float("Wetness", "How wet the cloth is, from 0 (dry) to 1 (soaked); multiplied "
                    "by the wetness vertex group's weight when one is set", 1.0, 0.0, 1.0,
                    subtype="FACTOR")
    wetness_group: StringProperty(
        name="Wetness Group", default="", update=_result_changed,
        description="Vertex group whose weights (0 to 1) scale the wetness per vertex; "
                    "vertices outside the group are dry")
    adhesion: _float("Adhesion", "How strongly soaked cloth sticks to what it touches, as a "
                     "pressure in Pa", 30.0, 0.0, 500.0, 2, 100)
    spread: _float("Spread", "How far a stuck region pulls its neighbours onto the surface too",
                   0.5, 0.0, 1.0, subtype="FACTOR")
    wet_friction: _float("Wet Friction", "Share of the sliding speed that wet cloth keeps where "
                         "it stays stuck (lower holds it more firmly)", 0.05, 0.0, 1.0,
                         subtype="FACTOR")
    wet_grip: _float("Wet Grip", "Most tangential stress wet friction holds, in Pa: past it "
                     "wet cloth slides (0: no wet friction)", 60.0, 0.0, 1000.0, 2, 100)
    wet_mass_gain: _float("Water Uptake", "Mass of the water in soaked cloth, as a multiple of "
                          "the dry mass", 1.0, 0.0, 3.0)
    wet_softening: _float("Wet Softening", "Share of its stiffness that soaked cloth loses",
                          0.3, 0.0, 0.99, subtype="FACTOR")
    wicking: _float("Wicking", "How fast water spreads through the cloth, in m²/s (0: it does "
                    "not)", 0.0, 0.0, 0.01, 5, 0.01)
    drying: _float("Drying", "How fast the cloth dries, as the share of its water lost per "
                   "second (0: it does not)", 0.0, 0.0, 1.0)

    # Field weights (Blender's cloth: Field Weights) --------------------------------
    field_collection: PointerProperty(
        type=bpy.types.Collection, name="Effector Collection", update=_result_changed,
        description="Only force fields in this collection act on the cloth (all of the scene's "
                    "when empty)")
    field_all: _float("All", "Scale of every force field's effect", 1.0, 0.0, 1.0,
                      subtype="FACTOR")
    field_gravity: _float("Gravity", "Scale of the scene's gravity", 1.0, 0.0, 1.0,
                          subtype="FACTOR")
    field_wind: _float("Wind", "Scale of Wind fields (their strength is the air's speed in "
                       "m/s)", 1.0, 0.0, 1.0, subtype="FACTOR")
    field_force: _float("Force", "Scale of Force fields (their strength is a pressure in "
                        "N/m²)", 1.0, 0.0, 1.0, subtype="FACTOR")
    field_turbulence: _float("Turbulence", "Scale of Turbulence fields (their strength is a "
                             "pressure in N/m²)", 1.0, 0.0, 1.0, subtype="FACTOR")

    # Cache ------------------------------------------------------------------------
    use_scene_range: BoolProperty(name="Scene Frame Range", default=True,
                                  update=_result_changed,
                                  description="Bake the scene's frame range")
    frame_start: IntProperty(name="Start", default=1, min=MIN_FRAME, max=MAX_FRAME,
                             update=_result_changed,
                             description="First baked frame: the cloth rests as modelled here")
    frame_end: IntProperty(name="End", default=250, min=MIN_FRAME, max=MAX_FRAME,
                           update=_result_changed, description="Last baked frame")
    cache_dir: StringProperty(
        name="Cache Folder", default="", subtype="DIR_PATH", options=_PATH_OPTIONS,
        description="Where the bake's files go, in a folder named after the .blend file. "
                    "Empty: next to the .blend file (in the temporary folder until it is saved)")
    work_limit: FloatProperty(
        name="Work Limit", default=500.0, soft_min=1.0, soft_max=1e5, precision=0,
        description="The largest bake that starts without asking, in millions of vertex steps "
                    "(vertices × steps per frame × frames); a larger one is refused with its "
                    "estimate and what would make it cheaper")

    # The current bake (shown, not edited) -------------------------------------------
    cache_id: StringProperty(name="Cache Identity", default="",
                             description="Names this object's cache files, so that no other "
                                         "object or file shares them")
    cache_owner: StringProperty(name="Cache Owner", default="",
                                description="The object's name when its identity was last "
                                            "used: tells the original from a copy")
    cache_file: StringProperty(name="Cache File", default="", subtype="FILE_PATH",
                               description="The point cache of the current bake")
    wetness_file: StringProperty(name="Wetness Cache", default="", subtype="FILE_PATH",
                                 description="Wetness and stuck per frame of the current bake")
    baked_frames: IntProperty(name="Baked Frames", default=0,
                              description="How many frames the current bake has")
    baked_start: IntProperty(name="Baked Start", default=0,
                             description="The first frame of the current bake")
    baked_inputs: StringProperty(name="Baked Inputs", default="",
                                 description="Colliders and fields of the current bake")
    bake_info: StringProperty(name="Bake Info", default="",
                              description="What the current bake took")
    outdated: BoolProperty(name="Outdated", default=False,
                           description="Something that affects the result changed since the "
                                       "bake")


class FieldWeights:
    """The cloth's field weights as fields.FieldSampler reads them."""

    def __init__(self, settings):
        self.all_ = float(settings.field_all)
        self.gravity = float(settings.field_gravity)
        self.wind = float(settings.field_wind)
        self.force = float(settings.field_force)
        self.turbulence = float(settings.field_turbulence)
        self.collection = settings.field_collection


def frame_range(settings, scene):
    if settings.use_scene_range:
        return scene.frame_start, scene.frame_end
    return settings.frame_start, settings.frame_end


def integrator_name(settings):
    """The wetcloth.World integrator name of the panel's choice."""
    return settings.integrator.lower()


def label(settings, field):
    return settings.bl_rna.properties[field].name


class SettingError(ValueError):
    pass


def _checked(settings, field, ranges):
    """The value of a bounded setting as the library gets it, or
    SettingError naming the setting. Blender keeps a float setting as a
    32-bit float, so a value typed as 0.99 is kept as 0.99000001: a value
    that rounds to a limit in 32 bits is the limit."""
    lo, hi, lo_open = ranges[field]
    value = getattr(settings, field)
    if isinstance(value, float):
        v32 = np.float32(value)
        if np.isfinite(hi) and v32 == np.float32(hi):
            value = hi
        elif v32 == np.float32(lo):
            value = lo
    ok = math.isfinite(value) and (value > lo if lo_open else value >= lo) and value <= hi
    if not ok:
        shown = "%d" % value if isinstance(value, int) else "%g" % value
        raise SettingError("%s is %s but must be %s%g to %g%s" % (
            label(settings, field), shown, "above " if lo_open else "from ", lo, hi,
            "" if value == value else " (it is not a number)"))
    return value


def material_kwargs(settings):
    """The library's Material arguments; SettingError for a value out of range."""
    return {k: float(_checked(settings, k, MATERIAL_RANGES)) for k in MATERIAL_FIELDS}


def checked(settings, field):
    """A bounded non-material setting (wetness, pin stiffness, ...)."""
    return _checked(settings, field, OTHER_RANGES)


def check_settings(settings):
    """Every bounded setting the bake uses; SettingError for the first out of
    range."""
    material_kwargs(settings)
    for field in ("wetness", "pin_stiffness", "work_limit"):
        checked(settings, field)
    if settings.integrator == "IMPLICIT":
        checked(settings, "implicit_tolerance")
    if not settings.substeps_auto:
        checked(settings, "substeps")


def new_cache_id():
    return uuid.uuid4().hex[:16]


classes = (WetClothSettings,)


def register():
    for c in classes:
        bpy.utils.register_class(c)
    bpy.types.Object.wet_cloth = PointerProperty(type=WetClothSettings)


def unregister():
    del bpy.types.Object.wet_cloth
    for c in reversed(classes):
        bpy.utils.unregister_class(c)
