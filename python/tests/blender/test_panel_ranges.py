"""The panel's values against the library's limits (docs/robustness.md,
Blender panel): Blender clamps nothing (a value typed out of range stays as
typed), a bake refuses it with a message that names the setting, its value
and the range, and every value inside the range reaches the library and is
accepted.

Blender stores a FloatProperty as a 32-bit float, so a limit such as 0.99
becomes 0.99000001, just above the library's bound; this test sends the
values exactly as Blender stores them."""

import sys

import bpy
import numpy as np
import pytest

from conftest import MODULE
from test_addon import add_sphere, bake_error


def _settings_rna():
    return bpy.types.Object.bl_rna.properties["wet_cloth"].fixed_type


def _addon():
    return sys.modules[MODULE]


def _small_world(wetcloth):
    return wetcloth.World(gravity=(0.0, 0.0, -9.81))


@pytest.fixture
def cloth_settings(empty_scene):
    bpy.ops.mesh.primitive_plane_add(size=1.0)
    ob = bpy.context.object
    ob.wet_cloth.enabled = True
    return ob.wet_cloth


def _add_cloth(wetcloth, material):
    world = _small_world(wetcloth)
    try:
        verts = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (1.0, 1.0, 0.0), (0.0, 1.0, 0.0)]
        world.add_cloth(verts, [(0, 1, 2, 3)], material=material)
    finally:
        world.close()


def _inside_limits(lo, hi, lo_open):
    """The values at and next to the limits that are inside the range."""
    lo_in = float(np.nextafter(np.float32(lo), np.float32(np.inf))) if lo_open else lo
    return (lo_in, hi)


def test_material_limits_are_accepted_by_the_library(installed, cloth_settings):
    addon = _addon()
    props, wetcloth = addon.props, addon.bake.load_wetcloth()
    checked = []
    for field, (lo, hi, lo_open) in props.MATERIAL_RANGES.items():
        for limit in _inside_limits(lo, hi, lo_open):
            setattr(cloth_settings, field, limit)
            stored = getattr(cloth_settings, field)  # as Blender keeps it (float32)
            try:
                _add_cloth(wetcloth, wetcloth.Material(**props.material_kwargs(cloth_settings)))
            except (wetcloth.WetclothError, props.SettingError) as e:
                pytest.fail("the panel lets %s be %r (stored as %r), which is refused: %s"
                            % (field, limit, stored, e))
            checked.append(field)
        setattr(cloth_settings, field, _settings_rna().properties[field].default)
    assert len(checked) == 2 * len(props.MATERIAL_FIELDS)


@pytest.mark.parametrize("field", ["density", "stretch", "wet_softening", "thickness",
                                   "damping"])
def test_out_of_range_values_are_kept_and_refused(installed, cloth_settings, field):
    """Blender does not clamp a value out of range; the library's range
    check (props.check_settings) names the setting's label and the value."""
    props = _addon().props
    lo, hi, _lo_open = props.MATERIAL_RANGES[field]
    label = _settings_rna().properties[field].name
    for bad in (hi * 2.0 + 1.0, lo - 1.0):
        setattr(cloth_settings, field, bad)
        assert getattr(cloth_settings, field) == pytest.approx(bad, rel=1e-6), field
        with pytest.raises(props.SettingError) as info:
            props.check_settings(cloth_settings)
        text = str(info.value)
        assert text.startswith(label + " is ") and ("%g" % np.float32(bad))[:4] in text, text
    setattr(cloth_settings, field, _settings_rna().properties[field].default)
    props.check_settings(cloth_settings)


def test_a_bake_refuses_an_out_of_range_value(project):
    """Through the operator: the bake is refused before it starts, with the
    setting named, and nothing is written."""
    add_sphere()
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0.0, 0.0, 0.6))
    cloth = bpy.context.object
    cloth.wet_cloth.enabled = True
    cloth.wet_cloth.density = 2000.0
    text = bake_error(cloth)
    assert "Density is 2000 but must be above 0 to 1000" in text, text
    assert cloth.wet_cloth.density == 2000.0
    cloth.wet_cloth.density = 0.15
    cloth.wet_cloth.substeps_auto = False
    cloth.wet_cloth.substeps = 10 ** 7 + 1
    assert cloth.wet_cloth.substeps == 10 ** 7 + 1  # kept as typed, not clamped
    assert "Quality Steps is 10000001 but must be from 1 to 1e+07" in bake_error(cloth)
    cloth.wet_cloth.substeps = 0
    assert "Quality Steps is 0" in bake_error(cloth)
    cloth.wet_cloth.substeps = 20
    cloth.wet_cloth.wetness = 1.5
    assert "Wetness is 1.5 but must be from 0 to 1" in bake_error(cloth)
    assert cloth.wet_cloth.cache_file == ""


def test_wetness_and_substep_limits_are_accepted_by_the_library(installed, cloth_settings):
    props = _addon().props
    wetcloth = _addon().bake.load_wetcloth()
    world = _small_world(wetcloth)
    try:
        c = world.add_grid_cloth(2, 2)
        for limit in _inside_limits(*props.OTHER_RANGES["wetness"]):
            cloth_settings.wetness = limit
            c.set_wetness(props.checked(cloth_settings, "wetness"))
    finally:
        world.close()
    # the largest step count the panel lets through is one the library takes
    hi = props.OTHER_RANGES["substeps"][1]
    wetcloth.World(max_substeps=hi).close()
    with pytest.raises(wetcloth.WetclothError):
        wetcloth.World(max_substeps=hi + 1)
    # and the frame limits are those of Blender's cloth cache (negative
    # start frames included)
    rna = _settings_rna().properties
    cache_rna = bpy.types.PointCache.bl_rna.properties
    assert rna["frame_start"].hard_min == cache_rna["frame_start"].hard_min < 0
    assert rna["frame_end"].hard_max == cache_rna["frame_end"].hard_max
