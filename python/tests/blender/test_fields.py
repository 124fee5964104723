"""blender_addon/fields.py: Blender's Wind, Force and Turbulence fields at the
cloth's particles.

Each value is checked against a closed form written here from Blender's
formulas (effect.cc: get_effector_data, effector_falloff, falloff_func,
do_physical_effector), not from the module's helpers; then against Blender
itself: its particle simulation evaluates the same effectors (Newtonian
particles, Euler, no gravity: after one step a particle at rest has the
velocity force * timestep), and its cloth shows which objects act as
effectors. Nothing here registers a class.
"""

import importlib
import math
import os
import subprocess
import sys
from types import SimpleNamespace

import bpy
import mathutils
import numpy as np
import pytest
from mathutils import noise

from conftest import MODULE, ROOT

RNG = np.random.default_rng(7)
POINTS = RNG.uniform(-2.0, 2.0, size=(64, 3))


# ---------------------------------------------------------------------------
# helpers


@pytest.fixture
def fields(installed):
    return importlib.import_module(MODULE + ".fields")


@pytest.fixture
def scene(empty_scene):
    empty_scene.use_gravity = True
    return empty_scene


def weights(**kw):
    w = dict(all_=1.0, gravity=1.0, wind=1.0, force=1.0, turbulence=1.0, collection=None)
    w.update(kw)
    return SimpleNamespace(**w)


def add_field(kind, location=(0.0, 0.0, 0.0), rotation=(0.0, 0.0, 0.0), **settings):
    bpy.ops.object.effector_add(type=kind, location=location, rotation=rotation)
    ob = bpy.context.object
    for k, v in settings.items():
        setattr(ob.field, k, v)
    return ob


def sampler(fields, w=None, exclude=()):
    depsgraph = bpy.context.evaluated_depsgraph_get()
    return fields.FieldSampler(bpy.context.scene, bpy.context.view_layer, depsgraph,
                               w or weights(), exclude)


def sample(fields, points=POINTS, w=None, exclude=()):
    return sampler(fields, w, exclude).sample(points, np.zeros_like(points))


def z_axis(rotation):
    """The world Z axis of an object rotated by XYZ Euler angles."""
    return np.array(mathutils.Euler(rotation, "XYZ").to_matrix().col[2])


def power_falloff(d, power, dmin=None, dmax=None):
    """Blender's falloff_func, written out for scalars."""
    if dmax is not None and d > dmax:
        return 0.0
    if dmin is not None and d < dmin:
        return 1.0
    return (1.0 + d - (dmin or 0.0)) ** -power


def link_in_new_collection(ob, name, parent=None):
    c = bpy.data.collections.new(name)
    if parent is not None:
        parent.children.link(c)
    for owner in list(ob.users_collection):
        owner.objects.unlink(ob)
    c.objects.link(ob)
    return c


# ---------------------------------------------------------------------------
# no fields, unsupported fields, gravity


def test_no_field_gives_nothing(fields, scene):
    bpy.ops.mesh.primitive_plane_add()  # an object without a field
    s = sampler(fields)
    assert s.effectors == [] and s.ignored == []
    assert s.sample(POINTS, np.zeros_like(POINTS)) == (None, None)


def test_unsupported_fields_are_listed_as_ignored(fields, scene):
    vortex = add_field("VORTEX")
    magnet = add_field("MAGNET")
    s = sampler(fields)
    assert sorted(s.ignored) == sorted([(magnet.name, "MAGNET"), (vortex.name, "VORTEX")])
    assert s.sample(POINTS, np.zeros_like(POINTS)) == (None, None)


def test_gravity_follows_the_scene_and_the_gravity_weight(fields, scene):
    scene.gravity = (0.5, -1.0, -9.0)
    g = sampler(fields, weights(gravity=0.3, all_=0.25)).gravity(scene)
    assert g.shape == (3,)
    # Blender's cloth: scene gravity * Field Weights > Gravity; All weighs
    # the effectors only (see test_blender_cloth_agrees_on_gravity_weights)
    assert np.allclose(g, [0.15, -0.3, -2.7])
    scene.use_gravity = False
    assert np.array_equal(sampler(fields).gravity(scene), np.zeros(3))


def test_the_module_loads_on_its_own():
    """Neither bpy nor the rest of the add-on is needed to import it."""
    code = ("import importlib.util, sys; "
            "s = importlib.util.spec_from_file_location('fields', sys.argv[1]); "
            "m = importlib.util.module_from_spec(s); s.loader.exec_module(m); "
            "assert 'bpy' not in sys.modules and 'mathutils' not in sys.modules; "
            "print(m.SUPPORTED)")
    path = os.path.join(ROOT, "blender_addon", "fields.py")
    r = subprocess.run([sys.executable, "-c", code, path], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "('WIND', 'FORCE', 'TURBULENCE')"


def test_a_sampler_keeps_the_frame_it_was_built_at(fields, scene):
    """It copies what it reads: later changes, frames and depsgraph
    evaluations (which free the evaluated data) do not reach it."""
    ob = add_field("WIND", strength=1.0)
    s = sampler(fields)
    ob.field.strength = 5.0
    ob.field.use_max_distance, ob.field.distance_max = True, 0.01
    ob.rotation_euler = (1.0, 0.0, 0.0)
    scene.frame_set(3)
    bpy.context.evaluated_depsgraph_get()
    air, _ = s.sample(POINTS, np.zeros_like(POINTS))
    assert np.allclose(air, [0.0, 0.0, 1.0])


# ---------------------------------------------------------------------------
# Wind


def test_rotated_wind_blows_along_its_z_axis_everywhere(fields, scene):
    rot = (0.4, -0.7, 1.1)
    add_field("WIND", location=(0.3, 0.2, -0.5), rotation=rot, strength=3.0)
    air, force = sample(fields)
    assert force is None
    assert air.shape == POINTS.shape and air.dtype == np.float64
    assert np.allclose(air, 3.0 * z_axis(rot), atol=1e-6)


def test_weights_scale_the_field(fields, scene):
    add_field("WIND", strength=2.0)
    air, _ = sample(fields, w=weights(all_=0.5, wind=0.4, force=0.0, turbulence=0.0))
    assert np.allclose(air, [0.0, 0.0, 2.0 * 0.5 * 0.4])
    # no weight for the type: not an effector
    assert sample(fields, w=weights(wind=0.0)) == (None, None)
    assert sample(fields, w=weights(all_=0.0)) == (None, None)
    # another type's weight does not matter
    air, _ = sample(fields, w=weights(force=0.0))
    assert np.allclose(air, [0.0, 0.0, 2.0])


def test_strength_is_read_at_the_current_frame(fields, scene):
    ob = add_field("WIND", strength=1.0)
    ob.field.keyframe_insert("strength", frame=1)
    ob.field.strength = 5.0
    ob.field.keyframe_insert("strength", frame=11)
    for frame, speed in ((1, 1.0), (6, 3.0), (11, 5.0)):
        scene.frame_set(frame)
        air, _ = sample(fields, points=np.zeros((1, 3)))
        assert air[0, 2] == pytest.approx(speed, rel=1e-5), frame


def test_wind_distance_falloff_min_max_power(fields, scene):
    # Plane shape (the wind's default): the distance is the height above the
    # object's XY plane
    add_field("WIND", strength=2.0, falloff_power=2.0, use_min_distance=True, distance_min=0.5,
              use_max_distance=True, distance_max=2.0)
    assert bpy.context.object.field.shape == "PLANE"
    heights = [0.2, 1.0, 1.9, 2.5, -1.0, -3.0]
    pts = np.array([[0.7, -0.4, h] for h in heights])
    air, _ = sample(fields, points=pts)
    want = [2.0 * power_falloff(abs(h), 2.0, 0.5, 2.0) for h in heights]
    assert want == pytest.approx([2.0, 2.0 / 2.25, 2.0 / 2.4 ** 2, 0.0, 2.0 / 2.25, 0.0])
    assert np.allclose(air[:, 2], want) and np.allclose(air[:, :2], 0.0)


def test_point_shape_falloff_uses_the_distance_to_the_origin(fields, scene):
    c = np.array([1.0, -1.0, 0.5])
    add_field("WIND", location=tuple(c), strength=1.0, shape="POINT", falloff_power=1.5)
    air, _ = sample(fields)
    d = np.linalg.norm(POINTS - c, axis=1)
    assert np.allclose(air[:, 2], (1.0 + d) ** -1.5)


@pytest.mark.parametrize("direction", ["POSITIVE", "NEGATIVE"])
def test_z_direction_zeroes_the_far_side(fields, scene, direction):
    rot = (0.3, 0.5, 0.0)
    add_field("WIND", location=(0.0, 0.0, 1.0), rotation=rot, strength=1.5, z_direction=direction)
    air, _ = sample(fields)
    z = z_axis(rot)
    side = (POINTS - [0.0, 0.0, 1.0]) @ z
    keep = side >= 0.0 if direction == "POSITIVE" else side <= 0.0
    assert 0 < np.count_nonzero(keep) < len(POINTS)
    assert np.allclose(air[keep], 1.5 * z, atol=1e-6)
    assert np.array_equal(air[~keep], np.zeros((np.count_nonzero(~keep), 3)))


# ---------------------------------------------------------------------------
# Force


def test_force_pushes_radially_with_its_strength(fields, scene):
    c = np.array([1.0, 2.0, 3.0])
    ob = add_field("FORCE", location=tuple(c), strength=2.0)
    assert ob.field.shape == "POINT"
    air, force = sample(fields)
    assert air is None
    r = POINTS - c
    assert np.allclose(force, 2.0 * r / np.linalg.norm(r, axis=1)[:, None])
    # a negative strength pulls
    ob.field.strength = -2.0
    _, pull = sample(fields)
    assert np.allclose(pull, -force)
    # at the field's own origin: no direction, no force (normalize_v3)
    _, at = sample(fields, points=c[None, :])
    assert np.array_equal(at, np.zeros((1, 3)))


def test_force_gravitation_and_power(fields, scene):
    c = np.array([0.5, 0.0, -0.5])
    add_field("FORCE", location=tuple(c), strength=-3.0, use_gravity_falloff=True,
              falloff_power=1.0)
    _, force = sample(fields)
    r = POINTS - c
    d = np.linalg.norm(r, axis=1)
    want = (-3.0 / d ** 2 * (1.0 + d) ** -1.0)[:, None] * r / d[:, None]
    assert np.allclose(force, want)


def test_force_plane_pushes_along_z_away_from_the_plane(fields, scene):
    c = np.array([0.2, -0.3, 0.1])
    rot = (0.9, 0.2, -0.4)
    add_field("FORCE", location=tuple(c), rotation=rot, strength=4.0, shape="PLANE",
              falloff_power=1.0)
    _, force = sample(fields)
    z = z_axis(rot)
    h = (POINTS - c) @ z
    want = (4.0 * np.sign(h) / (1.0 + np.abs(h)))[:, None] * z
    assert np.allclose(force, want, atol=1e-6)


def test_force_line_pushes_away_from_the_z_axis(fields, scene):
    add_field("FORCE", strength=1.0, shape="LINE", use_max_distance=True, distance_max=1.5)
    _, force = sample(fields)
    radial = POINTS * [1.0, 1.0, 0.0]
    d = np.linalg.norm(radial, axis=1)
    want = np.where((d <= 1.5)[:, None], radial / d[:, None], 0.0)
    assert np.allclose(force, want)


def test_tube_falloff(fields, scene):
    add_field("FORCE", strength=1.0, falloff_type="TUBE", falloff_power=1.0,
              use_max_distance=True, distance_max=1.5, radial_falloff=2.0,
              use_radial_min=True, radial_min=0.5, use_radial_max=True, radial_max=1.5)
    pts = np.array([[0.3, 0.0, 1.0],    # radius below min: radial factor 1
                    [1.0, 0.0, -1.0],   # radial (1 + 1 - 0.5)^-2
                    [0.0, 1.4, 0.5],    # radial (1 + 1.4 - 0.5)^-2
                    [1.6, 0.0, 0.0],    # beyond the radial max
                    [0.2, 0.2, 1.6]])   # beyond the max distance along z
    _, force = sample(fields, points=pts)
    mag = np.linalg.norm(force, axis=1)
    want = [1.0 / 2.0, (1.0 / 2.0) / 1.5 ** 2, (1.0 / 1.5) / 1.9 ** 2, 0.0, 0.0]
    assert np.allclose(mag, want)


def test_cone_falloff_uses_the_angle_in_degrees(fields, scene):
    add_field("FORCE", strength=1.0, falloff_type="CONE", falloff_power=0.0, radial_falloff=1.0,
              use_radial_max=True, radial_max=50.0)
    angles = [0.0, 30.0, 45.0, 60.0, 120.0]
    pts = np.array([[math.sin(math.radians(a)), 0.0, math.cos(math.radians(a))] for a in angles])
    _, force = sample(fields, points=2.0 * pts)
    want = [1.0 / (1.0 + a) if a <= 50.0 else 0.0 for a in angles]
    assert np.allclose(np.linalg.norm(force, axis=1), want)


# ---------------------------------------------------------------------------
# Turbulence


def blender_turbulence(q):
    """2 T - 1 of BLI_noise_generic_turbulence(0, q, oct 2, soft, basis 2),
    T = 4/7 * sum_{k=0..2} 0.5^k U(2^k q), U = (noise + 1) / 2 the unsigned
    new-Perlin noise."""
    t = sum(0.5 ** k * 0.5 * (noise.noise(tuple(2 ** k * c for c in q),
                                          noise_basis="PERLIN_NEW") + 1.0)
            for k in range(3))
    return 2.0 * (4.0 / 7.0) * t - 1.0


def blender_turbulence_vector(p):
    x, y, z = p
    return [blender_turbulence((x, y, z)), blender_turbulence((y, z, x)),
            blender_turbulence((z, x, y))]


@pytest.mark.parametrize("global_coords", [False, True])
def test_turbulence_is_blenders_noise(fields, scene, global_coords):
    c = np.array([0.4, -0.2, 0.3])
    rot = (0.2, 0.0, 0.6)
    add_field("TURBULENCE", location=tuple(c), rotation=rot, strength=2.5, size=0.8,
              use_global_coords=global_coords)
    air, force = sample(fields)
    assert air is None
    where = POINTS if global_coords else POINTS - c + z_axis(rot)
    want = 2.5 * np.array([blender_turbulence_vector(p / 0.8) for p in where])
    assert np.allclose(force, want, atol=1e-5)
    # deterministic, nonzero, varying in space, bounded by the strength
    _, again = sample(fields)
    assert np.array_equal(force, again)
    assert np.all(np.abs(force) <= 2.5) and np.abs(force).max() > 0.5
    assert np.all(np.std(force, axis=0) > 0.1)


def test_turbulence_falloff_and_weights(fields, scene):
    add_field("TURBULENCE", strength=1.0, size=1.0, use_max_distance=True, distance_max=1.5)
    _, force = sample(fields, w=weights(turbulence=0.5))
    far = np.linalg.norm(POINTS, axis=1) > 1.5
    assert np.array_equal(force[far], np.zeros((np.count_nonzero(far), 3)))
    want = 0.5 * np.array([blender_turbulence_vector(p + [0.0, 0.0, 1.0]) for p in POINTS[~far]])
    assert np.allclose(force[~far], want, atol=1e-5)


def test_fields_add_up(fields, scene):
    add_field("WIND", strength=1.0)
    add_field("WIND", rotation=(math.pi / 2, 0.0, 0.0), strength=2.0)
    add_field("FORCE", location=(0.0, 0.0, -10.0), strength=1.0)
    add_field("TURBULENCE", strength=1.0, size=1.0)
    air, force = sample(fields, points=np.zeros((1, 3)))
    assert np.allclose(air, [[0.0, -2.0, 1.0]], atol=1e-6)
    assert np.allclose(force, [[0.0, 0.0, 1.0] + np.array(blender_turbulence_vector([0, 0, 1]))],
                       atol=1e-5)


# ---------------------------------------------------------------------------
# Which objects are effectors


def test_excluded_objects_are_never_effectors(fields, scene):
    bpy.ops.mesh.primitive_plane_add()
    cloth = bpy.context.object
    bpy.ops.object.forcefield_toggle()  # a field on the cloth itself
    cloth.field.type = "WIND"
    assert sample(fields)[0] is not None
    assert sample(fields, exclude=[cloth]) == (None, None)


def test_effector_collection_filter(fields, scene):
    inside = add_field("WIND", strength=1.0)
    add_field("FORCE", strength=1.0)
    # a collection of the scene
    c = link_in_new_collection(inside, "Effectors", parent=scene.collection)
    air, force = sample(fields, w=weights(collection=c))
    assert air is not None and force is None
    air, force = sample(fields, w=weights(collection=None))
    assert air is not None and force is not None
    # a collection that is not in the scene: its objects still act on a
    # cloth whose Effector Collection it is (Blender: see
    # test_blender_cloth_agrees_on_which_fields_act); without it they do not
    scene.collection.children.unlink(c)
    air, force = sample(fields, w=weights(collection=c))
    assert air is not None and force is None
    air, force = sample(fields, w=weights(collection=None))
    assert air is None and force is not None


def test_a_disabled_field_is_ignored(fields, scene):
    ob = add_field("WIND", strength=1.0)
    ob.hide_viewport = True  # Disable in Viewports
    assert sample(fields) == (None, None)
    ob.hide_viewport = False
    c = link_in_new_collection(ob, "Fields", parent=scene.collection)
    c.hide_viewport = True  # the collection disabled
    assert sample(fields) == (None, None)
    c.hide_viewport = False
    assert sample(fields)[0] is not None
    bpy.context.view_layer.layer_collection.children["Fields"].exclude = True
    assert sample(fields) == (None, None)


def test_a_field_hidden_in_the_view_layer_still_acts(fields, scene):
    ob = add_field("WIND", strength=1.0)
    ob.hide_set(True)  # the eye icon: hidden, not disabled (as in Blender)
    assert not ob.visible_get()
    assert sample(fields)[0] is not None


def test_notes_say_what_is_not_applied(fields, scene):
    add_field("WIND", strength=1.0)  # the defaults: nothing to say
    s = sampler(fields)
    assert s.notes == []
    bpy.ops.mesh.primitive_plane_add()
    ob = bpy.context.object  # a mesh's field may take its surface's shape
    bpy.ops.object.forcefield_toggle()
    ob.field.strength, ob.field.noise, ob.field.shape = 1.0, 0.5, "SURFACE"
    s = sampler(fields)
    assert sorted(t for name, kind, t in s.notes if name == ob.name) == [
        "noise amount not applied", "shape Surface evaluated as Point"]
    _, force = s.sample(POINTS, np.zeros_like(POINTS))
    assert np.allclose(force, POINTS / np.linalg.norm(POINTS, axis=1)[:, None])


# ---------------------------------------------------------------------------
# Against Blender itself


def particle_velocities(points, kind, settings):
    """Newtonian particles at rest at `points` under one field, one Euler step
    (no gravity): (positions at birth, velocity / timestep = the force)."""
    me = bpy.data.meshes.new("points")
    me.from_pydata(points.tolist(), [], [])
    emitter = bpy.data.objects.new("emitter", me)
    bpy.context.scene.collection.objects.link(emitter)
    emitter.modifiers.new("particles", "PARTICLE_SYSTEM")
    ps = emitter.particle_systems[0].settings
    ps.count, ps.emit_from, ps.use_emit_random = len(points), "VERT", False
    ps.frame_start, ps.frame_end, ps.lifetime = 1, 1, 100
    ps.normal_factor, ps.physics_type, ps.integrator = 0.0, "NEWTON", "EULER"
    ps.mass, ps.effector_weights.gravity, ps.subframes = 1.0, 0.0, 0
    add_field(kind, location=(0.3, -0.2, 0.1), rotation=(0.5, -0.3, 0.9), strength=0.01,
              flow=0.0, **settings)
    scene = bpy.context.scene
    scene.frame_set(1)
    dg = bpy.context.evaluated_depsgraph_get()
    particles = emitter.evaluated_get(dg).particle_systems[0].particles
    born = np.array([p.location[:] for p in particles])
    scene.frame_set(2)
    dg = bpy.context.evaluated_depsgraph_get()
    moved = emitter.evaluated_get(dg).particle_systems[0].particles
    velocity = np.array([p.velocity[:] for p in moved])
    assert np.array_equal(np.array([p.location[:] for p in moved]), born)  # Euler's first step
    return emitter, born, velocity / ps.timestep


BLENDER_CASES = {
    "force point, min/max/power": ("FORCE", dict(
        falloff_power=1.7, use_min_distance=True, distance_min=0.6, use_max_distance=True,
        distance_max=2.5)),
    "force plane, +z, power": ("FORCE", dict(shape="PLANE", falloff_power=1.3,
                                            z_direction="POSITIVE")),
    "force line, tube, radial": ("FORCE", dict(
        shape="LINE", falloff_type="TUBE", falloff_power=0.8, radial_falloff=1.5,
        use_radial_min=True, radial_min=0.3, use_radial_max=True, radial_max=1.2)),
    "force cone, -z side": ("FORCE", dict(falloff_type="CONE", falloff_power=0.5,
                                         radial_falloff=1.0, use_radial_max=True,
                                         radial_max=120.0, z_direction="NEGATIVE")),
    "force gravitation": ("FORCE", dict(use_gravity_falloff=True)),
    "wind, power, max": ("WIND", dict(falloff_power=2.0, use_max_distance=True,
                                      distance_max=1.5)),
    "turbulence": ("TURBULENCE", dict(size=0.7, falloff_power=1.0)),
    "turbulence, global": ("TURBULENCE", dict(size=1.3, use_global_coords=True)),
}


@pytest.mark.parametrize("case", sorted(BLENDER_CASES))
def test_matches_blenders_own_effectors(fields, scene, case):
    """The same field, evaluated by Blender's particle simulation: equal to
    float precision (Wind is Blender's force along z; here the air velocity
    along z, the same vector)."""
    kind, settings = BLENDER_CASES[case]
    emitter, born, blender = particle_velocities(POINTS, kind, settings)
    air, force = sample(fields, points=born, exclude=[emitter])
    ours = air if kind == "WIND" else force
    assert np.count_nonzero(np.any(ours != 0.0, axis=1)) >= 10
    assert np.allclose(ours, blender, rtol=0.0, atol=1e-5 * np.abs(blender).max())


def cloth_height(scene, frames=6):
    """The mean height of the Blender cloth after `frames` frames."""
    for frame in range(1, frames + 1):
        scene.frame_set(frame)
    ev = bpy.data.objects["Cloth"].evaluated_get(bpy.context.evaluated_depsgraph_get())
    mesh = ev.to_mesh()
    try:
        return float(np.mean([v.co.z for v in mesh.vertices]))
    finally:
        ev.to_mesh_clear()


def blender_cloth(scene, all_weight=1.0):
    bpy.ops.mesh.primitive_plane_add(size=1.0)
    cloth = bpy.context.object
    cloth.name = "Cloth"
    mod = cloth.modifiers.new("Cloth", "CLOTH")
    mod.settings.effector_weights.all = all_weight
    return cloth, mod.settings.effector_weights


def test_blender_cloth_agrees_on_gravity_weights(fields, scene):
    _, w = blender_cloth(scene, all_weight=0.0)
    fallen = cloth_height(scene)
    assert fallen < -0.05  # All = 0 does not stop Blender's cloth falling
    g = sampler(fields, weights(all_=w.all, gravity=w.gravity)).gravity(scene)
    assert np.allclose(g, scene.gravity)


ACTS = {  # how the field is set up: whether Blender's cloth feels it
    "shown": True,
    "eye": True,  # hidden in the view layer, not disabled
    "disabled": False,
    "collection disabled": False,
    "excluded": False,
    "effector collection outside the scene": True,
    "effector collection disabled": False,
    "effector collection's child disabled": False,
    "excluded, but the effector collection": True,
}


@pytest.mark.parametrize("how", list(ACTS))
def test_blender_cloth_agrees_on_which_fields_act(fields, scene, how):
    scene.use_gravity = False
    cloth, w = blender_cloth(scene)
    ob = add_field("FORCE", location=(0.0, 0.0, -1.0), strength=500.0)
    layers = bpy.context.view_layer.layer_collection
    if how == "eye":
        ob.hide_set(True)
    elif how == "disabled":
        ob.hide_viewport = True
    elif how == "collection disabled":
        link_in_new_collection(ob, "Fields", parent=scene.collection).hide_viewport = True
    elif how.startswith("excluded"):
        c = link_in_new_collection(ob, "Fields", parent=scene.collection)
        layers.children["Fields"].exclude = True
        if how != "excluded":
            w.collection = c
    elif how.startswith("effector collection"):
        w.collection = bpy.data.collections.new("Effectors")
        if how == "effector collection's child disabled":
            link_in_new_collection(ob, "Child", parent=w.collection).hide_viewport = True
        else:
            link_in_new_collection(ob, "Fields", parent=w.collection)
            w.collection.hide_viewport = how == "effector collection disabled"
    ours = sample(fields, w=weights(collection=w.collection), exclude=[cloth])[1] is not None
    blenders = cloth_height(scene) > 0.05
    assert blenders == ACTS[how]
    assert ours == blenders
