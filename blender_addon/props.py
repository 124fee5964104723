"""Object.wet_cloth: the settings of one wet cloth object.

Material values are in the library's units (SI, resolution independent; see
docs/python.md); the presets only fill them in.
"""

import bpy
import numpy as np
from bpy.props import (BoolProperty, EnumProperty, FloatProperty, IntProperty,
                       PointerProperty, StringProperty)

# Library field -> value, for each preset. Cotton is the library's default.
PRESETS = {
    "COTTON": dict(density=0.15, stretch=1000.0, bend=1e-5, damping=0.05, air_drag=0.02,
                   thickness=0.005, friction=0.5, adhesion=30.0, spread=0.5,
                   wet_friction=0.05, wet_mass_gain=1.0, wet_softening=0.3),
    "SILK": dict(density=0.06, stretch=600.0, bend=2e-6, damping=0.05, air_drag=0.02,
                 thickness=0.002, friction=0.3, adhesion=40.0, spread=0.6,
                 wet_friction=0.03, wet_mass_gain=0.8, wet_softening=0.4),
    "DENIM": dict(density=0.40, stretch=3000.0, bend=1e-4, damping=0.08, air_drag=0.02,
                  thickness=0.008, friction=0.6, adhesion=20.0, spread=0.3,
                  wet_friction=0.1, wet_mass_gain=0.7, wet_softening=0.2),
    "TOWEL": dict(density=0.45, stretch=800.0, bend=5e-5, damping=0.1, air_drag=0.02,
                  thickness=0.010, friction=0.8, adhesion=35.0, spread=0.4,
                  wet_friction=0.05, wet_mass_gain=2.0, wet_softening=0.4),
}

MATERIAL_FIELDS = ("density", "stretch", "bend", "damping", "air_drag", "thickness", "friction",
                   "adhesion", "spread", "wet_friction", "wet_mass_gain", "wet_softening",
                   "wicking", "drying")

_applying_preset = False

# Blender 4.5 warns about "//" paths unless the property says it takes them.
_PATH_OPTIONS = ({"PATH_SUPPORTS_BLEND_RELATIVE"} if bpy.app.version >= (4, 5, 0) else set())


def _apply_preset(self, _context):
    global _applying_preset
    values = PRESETS.get(self.preset)
    if values is None:
        return
    _applying_preset = True
    try:
        for k, v in values.items():
            setattr(self, k, v)
        self.wicking = 0.0
        self.drying = 0.0
    finally:
        _applying_preset = False

def _material_edited(self, _context):
    # Editing a value by hand makes the material custom (like Blender's own
    # presets menu, which then shows no preset name).
    if not _applying_preset and self.preset != "CUSTOM":
        values = PRESETS.get(self.preset, {})
        if any(abs(getattr(self, k) - v) > 1e-12 * max(1.0, abs(v)) for k, v in values.items()):
            self["preset"] = 4  # CUSTOM, set without running the update


def _float32_within(lo, hi):
    """The float32 limits inside the library's [lo, hi]. Blender keeps a
    FloatProperty, and its limits, as 32-bit floats: a limit of 0.99 would be
    kept as 0.99000001, which the library refuses."""
    lo32, hi32 = np.float32(lo), np.float32(hi)
    if lo32 < lo:
        lo32 = np.nextafter(lo32, np.float32(np.inf))
    if hi32 > hi:
        hi32 = np.nextafter(hi32, np.float32(-np.inf))
    return float(lo32), float(hi32)


def _mat(name, description, default, min_, max_, unit_text, precision=3, step=1):
    """A material value; [min_, max_] is the library's range (material.c)."""
    min_, max_ = _float32_within(min_, max_)
    return FloatProperty(name=name, description="%s (%s)" % (description, unit_text),
                         default=default, min=min_, max=max_, precision=precision, step=step,
                         update=_material_edited)


class WetClothSettings(bpy.types.PropertyGroup):
    enabled: BoolProperty(
        name="Wet Cloth", default=False,
        description="Simulate this mesh as wet cloth with libwetcloth when baking")

    # Material -------------------------------------------------------------
    preset: EnumProperty(
        name="Preset", description="Fill in the material values of a kind of fabric",
        items=[("COTTON", "Cotton", "Cotton shirting, 150 g/m²"),
               ("SILK", "Silk", "Light silk, 60 g/m²"),
               ("DENIM", "Denim", "Heavy denim, 400 g/m², stiff"),
               ("TOWEL", "Towel", "Terry towel, 450 g/m², soaks up much water"),
               ("CUSTOM", "Custom", "Values set by hand")],
        default="COTTON", update=_apply_preset)
    density: _mat("Density", "Areal density of the dry cloth", 0.15, 1e-4, 1000.0, "kg/m²", 3)
    stretch: _mat("Stretch", "In-plane stretch stiffness", 1000.0, 0.0, 1e9, "N/m", 1, 100)
    bend: _mat("Bending", "Bending stiffness", 1e-5, 0.0, 1e3, "N·m", 7, 0.0001)
    damping: _mat("Damping", "Damping along stretch links, fraction of critical", 0.05, 0.0, 1.0,
                  "0 to 1")
    air_drag: _mat("Air Drag", "Linear air drag", 0.02, 0.0, 1e4, "N·s/m³")
    thickness: _mat("Thickness", "Collision thickness of the cloth", 0.005, 0.0, 1.0, "m", 4, 0.1)
    friction: _mat("Friction", "Coulomb friction coefficient of the cloth", 0.5, 0.0, 10.0, "-")
    adhesion: _mat("Adhesion", "Adhesion pressure of soaked cloth", 30.0, 0.0, 1e6, "Pa", 2, 100)
    spread: _mat("Spread", "How far a stuck region spreads outward (thesis beta)", 0.5, 0.0, 1.0,
                 "0 to 1")
    wet_friction: _mat("Wet Friction", "Tangential velocity kept in sustained wet contact", 0.05,
                       0.0, 1.0, "0 to 1")
    wet_mass_gain: _mat("Water Uptake", "Mass of water at wetness 1, as a fraction of the dry "
                        "mass", 1.0, 0.0, 10.0, "fraction")
    wet_softening: _mat("Wet Softening", "Stiffness lost at wetness 1", 0.3, 0.0, 0.99, "0 to 1")
    wicking: _mat("Wicking", "Wetness diffusing along the cloth (0 = off)", 0.0, 0.0, 1.0, "m²/s",
                  5, 0.01)
    drying: _mat("Drying", "Exponential drying rate (0 = off)", 0.0, 0.0, 100.0, "1/s")

    # Wetness --------------------------------------------------------------
    wetness: FloatProperty(
        name="Wetness", default=1.0, min=0.0, max=1.0, subtype="FACTOR",
        description="How wet the cloth is, 0 dry to 1 soaked (multiplied by the wetness "
                    "vertex group's weight when one is set)")
    wetness_group: StringProperty(
        name="Wetness Group", default="",
        description="Vertex group whose weights (0 to 1) scale the wetness per vertex; "
                    "vertices outside the group are dry")

    # Shape ----------------------------------------------------------------
    pin_group: StringProperty(
        name="Pin Group", default="",
        description="Vertex group of pinned vertices (weight above 0): they follow the mesh's "
                    "own animation and deformation")

    # Collisions -----------------------------------------------------------
    use_colliders: BoolProperty(
        name="Object Collisions", default=True,
        description="Collide with objects that have Collision physics (their Thickness Outer "
                    "and Friction are used)")
    collision_collection: PointerProperty(
        type=bpy.types.Collection, name="Collision Collection",
        description="Only collide with objects in this collection (all with Collision "
                    "physics when empty)")
    self_collision: BoolProperty(name="Self Collisions", default=False,
                                 description="Collide the cloth with itself")
    collide_with_cloths: BoolProperty(
        name="Cloth Collisions", default=True,
        description="When baked together with other Wet Cloth objects (Bake All): collide with "
                    "those of them that do, and stick to them where wet")

    # Bake -----------------------------------------------------------------
    use_scene_range: BoolProperty(name="Scene Frame Range", default=True,
                                  description="Bake the scene's frame range")
    frame_start: IntProperty(name="Start", default=1, min=0, max=1048574,
                             description="First baked frame (the cloth's rest state)")
    frame_end: IntProperty(name="End", default=250, min=1, max=1048574,
                           description="Last baked frame")
    integrator: EnumProperty(
        name="Integrator",
        items=[("VERLET", "Verlet", "Position Verlet, the thesis' explicit method: the reference, "
                "but a fine or stiff cloth needs hundreds of substeps per frame"),
               ("XPBD", "Strain Limited",
                "Stretch links as constraints (XPBD): stable at large steps for any stretch "
                "stiffness"),
               ("IMPLICIT", "Semi-Implicit",
                "Backward Euler with conjugate gradients (Choi & Ko): stable at large steps, "
                "damps more")],
        default="VERLET",
        description="How a step advances the cloth (docs/model.md, Integrators)")
    implicit_tolerance: FloatProperty(
        name="Solver Tolerance", default=1.0, min=0.0, max=1000.0, soft_max=5.0,
        precision=3,
        description="Semi-Implicit only: how exactly each step's linear system is solved, as a "
                    "stray acceleration the solve may leave, m/s² (0 solves to round-off). "
                    "Larger is faster; from about 2 a very stiff cloth can gain energy")
    substeps_auto: BoolProperty(
        name="Automatic Substeps", default=True,
        description="Choose the steps per frame from the library's stable step")
    substeps: IntProperty(name="Substeps", default=20, min=1, max=100000,
                          description="Steps per frame when not automatic")
    cache_dir: StringProperty(
        name="Cache Folder", default="//wetcloth_cache/", subtype="DIR_PATH",
        options=_PATH_OPTIONS,
        description="Folder for the PC2 point cache (// means next to the .blend file)")

    # What the last bake wrote (read only in the UI).
    cache_file: StringProperty(name="Cache File", default="",
                               description="The PC2 file of the current bake")
    baked_frames: IntProperty(name="Baked Frames", default=0)
    baked_start: IntProperty(name="Baked Start", default=0)
    bake_info: StringProperty(name="Bake Info", default="")


def frame_range(settings, scene):
    if settings.use_scene_range:
        return scene.frame_start, scene.frame_end
    return settings.frame_start, settings.frame_end


def integrator_name(settings):
    """The wetcloth.World integrator name of the panel's choice."""
    return settings.integrator.lower()


def material_kwargs(settings):
    return {k: float(getattr(settings, k)) for k in MATERIAL_FIELDS}


classes = (WetClothSettings,)


def register():
    for c in classes:
        bpy.utils.register_class(c)
    bpy.types.Object.wet_cloth = PointerProperty(type=WetClothSettings)


def unregister():
    del bpy.types.Object.wet_cloth
    for c in reversed(classes):
        bpy.utils.unregister_class(c)
