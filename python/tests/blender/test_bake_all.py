"""Bake All: every Wet Cloth object of the view layer in one world, so that
they collide with each other (and stick where wet), each with its own cache
(see test_addon.py for the one-object bake and the helpers)."""

import os

import bpy
import numpy as np
import pytest

from test_addon import (SPHERE_R, add_cloth, add_sphere, bake, cache_names, cache_path,
                        evaluated_attribute, read_pc2, wetness_path)

FRAMES = 24


def bake_all(**kw):
    return bpy.ops.wetcloth.bake_all(**kw)


def bake_all_error():
    with pytest.raises(RuntimeError) as info:
        bake_all()
    text = str(info.value)
    assert "Traceback" not in text
    return text


def two_cloths(cache_dir):
    """A sphere, a 12 x 12 cloth 0.2 m above it and a second one, turned
    30 degrees about z, 0.15 m above the first: the upper one lands on the
    lower one as it drapes."""
    sphere = add_sphere()
    lower = add_cloth(cache_dir, z=0.5, cuts=10, name="Lower")
    upper = add_cloth(cache_dir, z=0.65, cuts=10, name="Upper")
    upper.rotation_euler.z = np.radians(30.0)
    return sphere, lower, upper


def world_frames(ob):
    """The baked frames of an object in world space (its transform is not
    animated in these scenes)."""
    _header, frames = read_pc2(cache_path(ob))
    m = np.array(ob.matrix_world, dtype=np.float64)
    return frames.astype(np.float64) @ m[:3, :3].T + m[:3, 3]


def faces(ob):
    return np.array([list(p.vertices) for p in ob.data.polygons], dtype=np.int32)


def sphere_mesh(sphere):
    m = np.array(sphere.matrix_world, dtype=np.float64)
    v = np.array([list(x.co) for x in sphere.data.vertices]) @ m[:3, :3].T + m[:3, 3]
    sphere.data.calc_loop_triangles()
    t = np.array([list(x.vertices) for x in sphere.data.loop_triangles], dtype=np.int32)
    return v, t


def checker_counts(wc, cloths, sphere):
    """The library's independent intersection checker on cloths given as
    (positions, faces), with the sphere as a collider."""
    world = wc.World(gravity=(0.0, 0.0, 0.0))
    try:
        for x, f in cloths:
            world.add_cloth(x, f)
        v, t = sphere_mesh(sphere)
        world.add_mesh_collider(v, t)
        return world.count_intersections()
    finally:
        world.close()


def between_and_collider(wc, a, b, sphere):
    """Per frame: triangle pairs of the two cloths that intersect each other
    (all pairs, less each cloth's own), and cloth-sphere intersections."""
    (xa, fa), (xb, fb) = a, b
    out = []
    for k in range(xa.shape[0]):
        both = checker_counts(wc, [(xa[k], fa), (xb[k], fb)], sphere)
        alone_a = checker_counts(wc, [(xa[k], fa)], sphere)
        alone_b = checker_counts(wc, [(xb[k], fb)], sphere)
        out.append((both["cloth_cloth"] - alone_a["cloth_cloth"] - alone_b["cloth_cloth"],
                    both["cloth_collider"]))
    return np.array(out)


@pytest.fixture
def wetcloth_lib(installed):
    from bl_ext.user_default.wetcloth import bake as bake_mod
    return bake_mod.load_wetcloth()


def test_two_cloths_collide_and_get_their_own_caches(empty_scene, cache_dir, wetcloth_lib):
    sphere, lower, upper = two_cloths(cache_dir)
    assert bake_all() == {"FINISHED"}
    for ob in (lower, upper):
        header, frames = read_pc2(cache_path(ob))
        assert header["frames"] == FRAMES and header["n"] == len(ob.data.vertices) == 144
        assert os.path.basename(cache_path(ob)) == "%s.%s.pc2" % (ob.name,
                                                                  ob.wet_cloth.cache_id)
        assert ob.modifiers["Wet Cloth"].type == "MESH_CACHE"
        assert "with " in ob.wet_cloth.bake_info
        empty_scene.frame_set(FRAMES)
        stuck = evaluated_attribute(ob, "wet_cloth_stuck")
        assert stuck.sum() > 0  # wet: each sticks (the upper one to the lower one)
    xl, xu = world_frames(lower), world_frames(upper)
    # the upper one fell onto the lower one: over the sphere's top it rests
    # on it, a thickness or more above
    top_l = np.argmin(np.linalg.norm(xl[0, :, :2], axis=1))
    top_u = np.argmin(np.linalg.norm(xu[0, :, :2], axis=1))
    gap = xu[-1, top_u, 2] - xl[-1, top_l, 2]
    assert 0.004 < gap < 0.05, gap
    counts = between_and_collider(wetcloth_lib, (xl, faces(lower)), (xu, faces(upper)), sphere)
    assert not counts.any(), counts[counts.any(axis=1)][:5]
    # with Cloth Collisions off on one, the two pass through each other, and
    # the checker sees it (so the check above can fail)
    upper.wet_cloth.collide_with_cloths = False
    assert bake_all() == {"FINISHED"}
    counts = between_and_collider(wetcloth_lib, (world_frames(lower), faces(lower)),
                                  (world_frames(upper), faces(upper)), sphere)
    assert counts[:, 0].max() > 0
    print("bake all: upper rests %.4f m over the lower one; with Cloth Collisions off on it, "
          "up to %d intersecting pairs" % (gap, counts[:, 0].max()))


def test_one_object_bakes_the_same_bits(empty_scene, cache_dir):
    """Bake All of a scene with one Wet Cloth object is Bake, bit for bit.
    The collider is an ico sphere (all triangles): a UV sphere's quads are
    split into triangles differently from one Blender process to the next
    (measured with bpy 4.5.4: the loop triangles' hash differs between runs,
    the vertices' does not), and the library's answer with them."""
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=2, radius=SPHERE_R)
    bpy.context.object.modifiers.new("Collision", "COLLISION")
    cloth = add_cloth(cache_dir, cuts=10)
    assert bake(cloth) == {"FINISHED"}
    alone = [open(p, "rb").read() for p in (cache_path(cloth), wetness_path(cloth))]
    bpy.ops.wetcloth.free_bake(object=cloth.name)
    assert bake_all() == {"FINISHED"}
    assert [open(p, "rb").read() for p in (cache_path(cloth), wetness_path(cloth))] == alone
    assert "with " not in cloth.wet_cloth.bake_info


def test_bake_all_errors_and_failures_keep_previous(empty_scene, cache_dir):
    assert "no mesh in the view layer has Wet Cloth enabled" in bake_all_error()
    sphere, lower, upper = two_cloths(cache_dir)
    upper.wet_cloth.use_scene_range = False
    upper.wet_cloth.frame_start, upper.wet_cloth.frame_end = 1, 12
    text = bake_all_error()
    assert "same frame range" in text and "Upper has 1 to 12" in text, text
    upper.wet_cloth.use_scene_range = True
    upper.wet_cloth.integrator = "XPBD"
    assert "same integrator" in bake_all_error()
    for ob in (lower, upper):
        ob.wet_cloth.integrator = "IMPLICIT"
    upper.wet_cloth.implicit_tolerance = 0.0
    assert "same solver tolerance" in bake_all_error()
    for ob in (lower, upper):
        ob.wet_cloth.integrator = "VERLET"
    upper.wet_cloth.implicit_tolerance = 0.5
    assert not os.path.exists(cache_dir) or os.listdir(cache_dir) == []

    assert bake_all() == {"FINISHED"}
    before = {}
    for ob in (lower, upper):
        with open(cache_path(ob), "rb") as f:
            before[ob.name] = f.read()
    # a collider that loses vertices midway fails the bake: both previous
    # caches stay byte for byte, no temporary file is left
    build = sphere.modifiers.new("Build", "BUILD")
    build.use_reverse = True
    build.frame_start, build.frame_duration = 5, 20
    sphere.modifiers.move(len(sphere.modifiers) - 1, 0)
    assert "collider Sphere changed its vertex count" in bake_all_error()
    assert sorted(os.listdir(cache_dir)) == sorted(cache_names(lower) + cache_names(upper))
    for ob in (lower, upper):
        with open(cache_path(ob), "rb") as f:
            assert f.read() == before[ob.name]
        assert ob.modifiers["Wet Cloth"].show_viewport

    assert bpy.ops.wetcloth.free_bake_all() == {"FINISHED"}
    assert os.listdir(cache_dir) == []
    for ob in (lower, upper):
        assert ob.modifiers["Wet Cloth"].filepath == ""
        assert "Wet Cloth Wetness" not in ob.modifiers


# ---------------------------------------------------------------------------
# the interactive (modal) bake: Esc cancels and keeps the previous bakes


class _Event:
    def __init__(self, kind):
        self.type = kind


def modal_driver():
    """Bake All's interactive path, driven by hand. Headless Blender has no
    window: invoke() runs execute() there, and nothing would send a modal
    handler its events. So the test starts the bake as invoke() does in the
    UI (_begin_modal: all of it but the timer and the handler, which need a
    window) and sends modal() the TIMER and ESC events itself. The driver
    is the operator's own class minus Blender's operator machinery; its
    reports are kept in .reports."""
    from bl_ext.user_default.wetcloth import ops

    class Driver(ops._BakeOperator):
        _objects = ops.WETCLOTH_OT_bake_all._objects

        def __init__(self):
            self.reports = []

        def report(self, level, text):
            self.reports.append((set(level), text))

    return Driver(), ops


def caches(objects):
    out = {}
    for ob in objects:
        with open(cache_path(ob), "rb") as f:
            out[ob.name] = f.read()
    return out


def test_escape_cancels_a_modal_bake_and_keeps_the_previous(empty_scene, cache_dir):
    _sphere, lower, upper = two_cloths(cache_dir)
    # long enough that one TIMER event (0.1 s of stepping) cannot finish it
    empty_scene.frame_end = 240
    assert bake_all() == {"FINISHED"}
    before = caches((lower, upper))
    upper.wet_cloth.wetness = 0.0  # a new bake would differ
    empty_scene.frame_set(3)
    driver, ops = modal_driver()
    ctx = bpy.context
    assert driver._begin_modal(ctx) == {"RUNNING_MODAL"}
    assert ops._running == {"Lower", "Upper"}
    assert driver.modal(ctx, _Event("MOUSEMOVE")) == {"PASS_THROUGH"}
    assert driver.modal(ctx, _Event("TIMER")) == {"RUNNING_MODAL"}
    baker = driver._baker
    assert 0 < baker.progress < baker.frame_count
    # a second bake of the same objects is refused while this one runs
    second, _ = modal_driver()
    assert second._begin_modal(ctx) == {"CANCELLED"}
    assert "being baked already" in second.reports[-1][1]
    assert driver.modal(ctx, _Event("ESC")) == {"CANCELLED"}
    level, text = driver.reports[-1]
    assert level == {"WARNING"} and "cancelled" in text and "previous bake is kept" in text
    assert ops._running == set()
    assert caches((lower, upper)) == before
    assert sorted(os.listdir(os.path.dirname(cache_path(lower)))) == \
        sorted(cache_names(lower) + cache_names(upper))
    assert empty_scene.frame_current == 3
    print("modal bake cancelled at frame %d of %d" % (baker.progress, baker.frame_count))


def test_a_modal_bake_to_the_end_is_the_synchronous_one(empty_scene, cache_dir):
    _sphere, lower, upper = two_cloths(cache_dir)
    assert bake_all() == {"FINISHED"}
    synchronous = caches((lower, upper))
    bpy.ops.wetcloth.free_bake_all()
    driver, ops = modal_driver()
    ctx = bpy.context
    assert driver._begin_modal(ctx) == {"RUNNING_MODAL"}
    result, events = {"RUNNING_MODAL"}, 0
    while result == {"RUNNING_MODAL"} and events < 10000:
        result = driver.modal(ctx, _Event("TIMER"))
        events += 1
    assert result == {"FINISHED"}, driver.reports
    assert driver.reports[-1][0] == {"INFO"} and "baked" in driver.reports[-1][1]
    assert ops._running == set()
    assert caches((lower, upper)) == synchronous
