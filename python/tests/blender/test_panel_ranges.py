"""The panel's limits against the library's (docs/robustness.md, Blender
panel): every value Blender lets an artist enter must be one the library
accepts, and Blender itself must keep values inside those limits.

Blender stores a FloatProperty as a 32-bit float, so a limit such as 0.99
becomes 0.99000001, just above the library's bound; this test sends the
values exactly as Blender stores them."""

import sys

import bpy
import pytest

from conftest import MODULE


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


def test_material_limits_are_accepted_by_the_library(installed, cloth_settings):
    addon = _addon()
    props, wetcloth = addon.props, addon.bake.load_wetcloth()
    rna = _settings_rna().properties
    checked = []
    for field in props.MATERIAL_FIELDS:
        p = rna[field]
        for limit in (p.hard_min, p.hard_max):
            setattr(cloth_settings, field, limit)
            stored = getattr(cloth_settings, field)  # as Blender keeps it (float32)
            try:
                _add_cloth(wetcloth, wetcloth.Material(**props.material_kwargs(cloth_settings)))
            except wetcloth.WetclothError as e:
                pytest.fail("the panel lets %s be %r (stored as %r), which the library refuses: %s"
                            % (field, limit, stored, e))
            checked.append(field)
        setattr(cloth_settings, field, p.default)
    assert len(checked) == 2 * len(props.MATERIAL_FIELDS)


def test_blender_clamps_material_values(installed, cloth_settings):
    rna = _settings_rna().properties
    for field in _addon().props.MATERIAL_FIELDS:
        p = rna[field]
        setattr(cloth_settings, field, p.hard_max * 10.0 + 1.0)
        assert getattr(cloth_settings, field) == pytest.approx(p.hard_max, rel=1e-7), field
        setattr(cloth_settings, field, p.hard_min - 1.0)
        assert getattr(cloth_settings, field) == pytest.approx(p.hard_min, rel=1e-7), field


def test_wetness_and_substep_limits_are_accepted_by_the_library(installed, cloth_settings):
    wetcloth = _addon().bake.load_wetcloth()
    rna = _settings_rna().properties
    world = _small_world(wetcloth)
    try:
        c = world.add_grid_cloth(2, 2)
        for limit in (rna["wetness"].hard_min, rna["wetness"].hard_max):
            cloth_settings.wetness = limit
            c.set_wetness(cloth_settings.wetness)
        # The fixed substep count the panel allows, on a 4-particle cloth
        # (100,000 steps take well under a second).
        cloth_settings.substeps_auto = False
        cloth_settings.substeps = rna["substeps"].hard_max
        assert world.advance(1.0 / 24.0, cloth_settings.substeps) == rna["substeps"].hard_max
    finally:
        world.close()
