"""The workflows of an artist in Blender, one test each: whose files a bake
may write or delete (copies of a .blend, objects whose names clean up to the
same text, renames, copied and linked-duplicate objects), an unsaved file,
the modifier stack above and below Wet Cloth, Bake to Current Frame,
negative start frames, the outdated flag, the work limit, a cancelled or
killed bake, the wet material. (test_addon.py has the drape and its
helpers; test_fields.py the force fields themselves.)"""

import os
import shutil
import subprocess
import sys

import bpy
import numpy as np
import pytest

from conftest import WORK
from test_addon import (add_cloth, add_sphere, bake, bake_error, cache_names, cache_path,
                        evaluated_attribute, evaluated_positions, read_pc2, wetness_path)


def snapshot(folder):
    """{file name: bytes} of a folder (empty if it does not exist)."""
    if not os.path.isdir(folder):
        return {}
    out = {}
    for name in sorted(os.listdir(folder)):
        with open(os.path.join(folder, name), "rb") as f:
            out[name] = f.read()
    return out


def small_scene():
    """A sphere and a small wet cloth above it (a quick bake)."""
    add_sphere()
    return add_cloth(z=0.6, cuts=6)


def save_as(path):
    bpy.ops.wm.save_as_mainfile(filepath=path)


def free(ob):
    return bpy.ops.wetcloth.free_bake(object=ob.name)


# ---------------------------------------------------------------------------
# whose files


def test_a_copy_of_the_blend_file_bakes_into_its_own_folder(project):
    """shot_v1.blend saved as shot_v2.blend in the same folder: re-baking
    and freeing in v2 leave v1's bake byte for byte."""
    v1 = os.path.join(project, "shot_v1.blend")
    save_as(v1)
    cloth = small_scene()
    assert bake(cloth) == {"FINISHED"}
    v1_folder = os.path.join(project, "wetcloth_shot_v1")
    assert os.path.dirname(cache_path(cloth)) == v1_folder
    v1_files = snapshot(v1_folder)
    assert sorted(v1_files) == cache_names(cloth)
    save_as(v1)

    save_as(os.path.join(project, "shot_v2.blend"))
    cloth = bpy.data.objects["Cloth"]
    cloth.wet_cloth.wetness = 0.0  # a different bake
    assert bake(cloth) == {"FINISHED"}
    assert os.path.dirname(cache_path(cloth)) == os.path.join(project, "wetcloth_shot_v2")
    assert snapshot(v1_folder) == v1_files
    assert free(cloth) == {"FINISHED"}
    assert snapshot(os.path.join(project, "wetcloth_shot_v2")) == {}
    assert snapshot(v1_folder) == v1_files

    # v1 still plays its own bake
    bpy.ops.wm.open_mainfile(filepath=v1)
    cloth = bpy.data.objects["Cloth"]
    _header, frames = read_pc2(os.path.join(v1_folder, cache_names(cloth)[0]))
    bpy.context.scene.frame_set(12)
    np.testing.assert_allclose(evaluated_positions(cloth), frames[11], atol=1e-6)


def test_freeing_a_bake_that_another_file_plays_keeps_the_file(project):
    """v2 opened after Save As still plays v1's bake until it is baked
    again; Free Bake there removes the modifiers but not v1's files."""
    save_as(os.path.join(project, "shot_v1.blend"))
    cloth = small_scene()
    assert bake(cloth) == {"FINISHED"}
    v1_folder = os.path.dirname(cache_path(cloth))
    v1_files = snapshot(v1_folder)
    save_as(os.path.join(project, "shot_v2.blend"))
    cloth = bpy.data.objects["Cloth"]
    assert free(cloth) == {"FINISHED"}
    assert cloth.modifiers["Wet Cloth"].filepath == ""
    assert snapshot(v1_folder) == v1_files


def test_names_that_clean_up_alike_get_their_own_files(project):
    """Sheet.001 and Sheet_001 both become Sheet_001 in a file name: their
    identities keep the files apart, baked apart and together."""
    add_sphere()
    a = add_cloth(z=0.6, cuts=6, name="Sheet.001")
    b = add_cloth(z=0.9, cuts=6, name="Sheet_001")
    assert bake(a) == {"FINISHED"}
    assert bake(b) == {"FINISHED"}
    assert cache_path(a) != cache_path(b)
    assert bpy.path.clean_name(a.name) == bpy.path.clean_name(b.name)
    files = snapshot(os.path.dirname(cache_path(a)))
    assert sorted(files) == sorted(cache_names(a) + cache_names(b))
    _h, fa = read_pc2(cache_path(a))
    _h, fb = read_pc2(cache_path(b))
    assert np.abs(fa[-1] - fb[-1]).max() > 1e-3  # different cloths, different motion
    assert bpy.ops.wetcloth.bake_all() == {"FINISHED"}
    assert len(snapshot(os.path.dirname(cache_path(a)))) == 4


def test_rename_keeps_playing_and_rebakes_under_the_new_name(project):
    cloth = small_scene()
    cloth.name = "Sheet"
    assert bake(cloth) == {"FINISHED"}
    old = cache_path(cloth)
    _header, frames = read_pc2(old)
    cloth.name = "Towel"
    bpy.context.scene.frame_set(10)
    np.testing.assert_allclose(evaluated_positions(cloth), frames[9], atol=1e-6)
    assert bake(cloth) == {"FINISHED"}
    assert os.path.basename(cache_path(cloth)).startswith("Towel.")
    # the renamed object's old files were its own: replaced, not left over
    assert not os.path.exists(old)
    assert sorted(os.listdir(os.path.dirname(old))) == cache_names(cloth)


@pytest.mark.parametrize("linked", [False, True], ids=["copy", "linked duplicate"])
def test_a_copied_object_bakes_to_its_own_files(project, linked):
    """Shift D or Alt D copies the object's identity and modifiers: the
    copy plays the original's bake until it is baked, then gets files of
    its own; freeing it leaves the original's; the original re-bakes to
    its own files still."""
    cloth = small_scene()
    assert bake(cloth) == {"FINISHED"}
    original = {p: open(p, "rb").read() for p in (cache_path(cloth), wetness_path(cloth))}
    copy = cloth.copy()
    if not linked:
        copy.data = cloth.data.copy()
    copy.location.x += 2.0
    bpy.context.scene.collection.objects.link(copy)
    assert copy.wet_cloth.cache_id == cloth.wet_cloth.cache_id
    assert copy.wet_cloth.cache_file == cloth.wet_cloth.cache_file
    copy.wet_cloth.wetness = 0.0
    assert bake(copy) == {"FINISHED"}
    assert copy.wet_cloth.cache_id != cloth.wet_cloth.cache_id
    assert cache_path(copy) != cache_path(cloth)
    for p, data in original.items():
        with open(p, "rb") as f:
            assert f.read() == data
    assert bpy.path.abspath(cloth.modifiers["Wet Cloth"].filepath) == cache_path(cloth)
    assert free(copy) == {"FINISHED"}
    for p, data in original.items():
        with open(p, "rb") as f:
            assert f.read() == data
    # the original keeps its identity and its file names
    cloth.wet_cloth.wetness = 0.5
    assert bake(cloth) == {"FINISHED"}
    assert sorted(os.path.basename(p) for p in original) == cache_names(cloth)


def test_a_file_of_another_bake_is_never_overwritten(project):
    """A Cache Folder shared by two .blend files of the same name (a copy
    elsewhere): a file of the object's name and identity that is not its
    own bake makes the bake take a new identity instead of writing over it."""
    shared = os.path.join(WORK, "shared-cache-%d" % os.getpid())
    shutil.rmtree(shared, ignore_errors=True)
    cloth = small_scene()
    cloth.wet_cloth.cache_dir = shared
    assert bake(cloth) == {"FINISHED"}
    theirs = snapshot(os.path.dirname(cache_path(cloth)))
    # this object forgets its bake (as a copy of the .blend elsewhere would
    # not know it): its next bake must not write over those files
    assert free(cloth) == {"FINISHED"}
    folder = os.path.join(shared, "wetcloth_shot")
    assert snapshot(folder) == {}
    for name, data in theirs.items():
        with open(os.path.join(folder, name), "wb") as f:
            f.write(data)
    old_id = cloth.wet_cloth.cache_id
    assert bake(cloth) == {"FINISHED"}
    assert cloth.wet_cloth.cache_id != old_id
    now = snapshot(folder)
    for name, data in theirs.items():
        assert now[name] == data


# ---------------------------------------------------------------------------
# an unsaved file


def test_an_unsaved_file_bakes_and_saving_keeps_the_bake(empty_scene):
    assert bpy.data.filepath == ""
    cloth = small_scene()
    assert bake(cloth) == {"FINISHED"}
    tmp = os.path.join(bpy.app.tempdir, "wetcloth_unsaved")
    assert os.path.dirname(cache_path(cloth)) == tmp
    baked = {os.path.basename(p): open(p, "rb").read()
             for p in (cache_path(cloth), wetness_path(cloth))}
    folder = os.path.join(WORK, "saved-later-%d" % os.getpid())
    shutil.rmtree(folder, ignore_errors=True)
    os.makedirs(folder)
    blend = os.path.join(folder, "later.blend")
    save_as(blend)
    moved = os.path.join(folder, "wetcloth_later")
    assert snapshot(moved) == baked
    assert not any(os.path.exists(os.path.join(tmp, n)) for n in baked)
    mod = cloth.modifiers["Wet Cloth"]
    assert os.path.dirname(bpy.path.abspath(mod.filepath)) == moved
    assert os.path.dirname(cache_path(cloth)) == moved
    # the saved file plays the moved bake when opened again
    bpy.ops.wm.open_mainfile(filepath=blend)
    cloth = bpy.data.objects["Cloth"]
    _header, frames = read_pc2(cache_path(cloth))
    bpy.context.scene.frame_set(20)
    np.testing.assert_allclose(evaluated_positions(cloth), frames[19], atol=1e-6)
    assert evaluated_attribute(cloth, "wet_cloth_stuck").sum() > 0


# ---------------------------------------------------------------------------
# the modifier stack


def test_enabling_adds_the_wet_cloth_modifier_at_the_end(empty_scene):
    bpy.ops.mesh.primitive_plane_add()
    ob = bpy.context.object
    ob.modifiers.new("Sub", "SUBSURF")
    ob.wet_cloth.enabled = True
    assert [m.name for m in ob.modifiers] == ["Sub", "Wet Cloth"]
    assert ob.modifiers["Wet Cloth"].type == "MESH_CACHE"
    # with nothing baked it leaves the mesh as the modifiers above make it
    assert len(evaluated_positions(ob)) == 9


def test_subdivision_above_and_solidify_below(project):
    """Blender's cloth simulates the mesh as the modifiers above it leave
    it; the modifiers below apply to the result. A Subdivision Surface
    above: the cache has the subdivided vertices, and pins from a vertex
    group carry over to them. A Solidify below: the played mesh is the
    baked sheet, thickened."""
    add_sphere()
    cloth = add_cloth(z=0.6, cuts=4)  # 6 x 6 vertices
    base_n = len(cloth.data.vertices)
    sub = cloth.modifiers.new("Subdivision", "SUBSURF")
    sub.levels = 1
    cloth.modifiers.move(len(cloth.modifiers) - 1, 0)  # above Wet Cloth
    solid = cloth.modifiers.new("Solidify", "SOLIDIFY")  # below it
    solid.thickness = 0.01
    assert [m.name for m in cloth.modifiers] == ["Subdivision", "Wet Cloth", "Solidify"]
    v = np.array([tuple(x.co) for x in cloth.data.vertices])
    corner = int(np.argmax(v[:, 0] + v[:, 1]))
    group = cloth.vertex_groups.new(name="pin")
    group.add([corner], 1.0, "REPLACE")
    cloth.wet_cloth.pin_group = "pin"
    cloth.wet_cloth.use_scene_range = False
    cloth.wet_cloth.frame_start, cloth.wet_cloth.frame_end = 1, 12
    assert bake(cloth) == {"FINISHED"}
    header, frames = read_pc2(cache_path(cloth))
    n = header["n"]
    assert n == 11 * 11 and n > base_n  # the subdivided mesh
    assert [m.name for m in cloth.modifiers] == ["Subdivision", "Wet Cloth Wetness",
                                                  "Wet Cloth Attributes", "Wet Cloth",
                                                  "Solidify"]
    # the pinned corner (weight 1 carries over to the subdivided corner)
    corner_sub = int(np.argmax(frames[0, :, 0] + frames[0, :, 1]))
    np.testing.assert_allclose(frames[:, corner_sub], frames[:1, corner_sub].repeat(12, 0),
                               atol=1e-6)
    assert frames[-1, :, 2].min() < frames[0, :, 2].min() - 0.05  # the rest fell
    bpy.context.scene.frame_set(12)
    played = evaluated_positions(cloth)
    assert len(played) == 2 * n  # Solidify doubled the baked sheet
    np.testing.assert_allclose(played[:n], frames[11], atol=2e-3)
    # hiding Wet Cloth hides its wetness modifiers with it (alone they would
    # put the mesh at the wetness values); a bake keeps it hidden; showing
    # it again plays the bake
    layer = bpy.context.view_layer
    cloth.modifiers["Wet Cloth"].show_viewport = False
    layer.update()
    assert not cloth.modifiers["Wet Cloth Wetness"].show_viewport
    assert len(evaluated_positions(cloth)) == 2 * n  # the subdivided mesh, thickened
    assert bake(cloth) == {"FINISHED"}
    assert cloth.modifiers["Wet Cloth"].show_viewport is False
    assert read_pc2(cache_path(cloth))[0]["n"] == n
    cloth.modifiers["Wet Cloth"].show_viewport = True
    layer.update()
    assert cloth.modifiers["Wet Cloth Wetness"].show_viewport
    _header, frames = read_pc2(cache_path(cloth))
    np.testing.assert_allclose(evaluated_positions(cloth)[:n], frames[11], atol=2e-3)
    # moving Wet Cloth to the end takes the wetness modifiers along
    cloth.modifiers.move(cloth.modifiers.find("Wet Cloth"), len(cloth.modifiers) - 1)
    layer.update()
    assert [m.name for m in cloth.modifiers] == ["Subdivision", "Solidify",
                                                  "Wet Cloth Wetness", "Wet Cloth Attributes",
                                                  "Wet Cloth"]
    cloth.modifiers.move(len(cloth.modifiers) - 1, 1)
    layer.update()
    assert [m.name for m in cloth.modifiers][-1] == "Solidify"
    # removing Wet Cloth removes them (the files stay for Free Bake)
    copy = cloth.copy()
    bpy.context.scene.collection.objects.link(copy)
    copy.modifiers.remove(copy.modifiers["Wet Cloth"])
    layer.update()
    assert [m.name for m in copy.modifiers] == ["Subdivision", "Solidify"]
    bpy.data.objects.remove(copy)
    # the modifiers above changing the vertex count during the bake are an error
    sub.keyframe_insert("levels", frame=1)
    sub.levels = 2
    sub.keyframe_insert("levels", frame=6)
    text = bake_error(cloth)
    assert "modifiers above Wet Cloth" in text and "vertex count" in text, text


# ---------------------------------------------------------------------------
# frames


def test_bake_to_current_frame_and_a_negative_start(project):
    cloth = small_scene()
    s = cloth.wet_cloth
    s.use_scene_range = False
    s.frame_start, s.frame_end = -10, 30
    scene = bpy.context.scene
    scene.frame_set(5)
    with bpy.context.temp_override(active_object=cloth, object=cloth, selected_objects=[cloth]):
        assert bpy.ops.wetcloth.bake(to_current_frame=True) == {"FINISHED"}
    header, frames = read_pc2(cache_path(cloth))
    assert header["start"] == -10.0 and header["frames"] == 16
    assert cloth.modifiers["Wet Cloth"].frame_start == -10.0
    assert scene.frame_current == 5
    np.testing.assert_allclose(evaluated_positions(cloth), frames[-1], atol=1e-6)
    scene.frame_set(-10)
    with bpy.context.temp_override(active_object=cloth, object=cloth, selected_objects=[cloth]):
        with pytest.raises(RuntimeError, match="frame range -10 to -10 is empty"):
            bpy.ops.wetcloth.bake(to_current_frame=True)


# ---------------------------------------------------------------------------
# the outdated flag


def test_outdated_after_a_change(project):
    sphere = add_sphere()
    cloth = add_cloth(z=0.6, cuts=6)
    s = cloth.wet_cloth
    assert bake(cloth) == {"FINISHED"}
    layer = bpy.context.view_layer
    layer.update()
    assert not s.outdated
    # playing the animation changes nothing
    for f in (3, 12, 1):
        bpy.context.scene.frame_set(f)
    layer.update()
    assert not s.outdated
    s.friction = 0.7
    assert s.outdated
    assert bake(cloth) == {"FINISHED"}
    layer.update()
    assert not s.outdated
    cloth.location.x += 0.1  # the object's transform
    layer.update()
    assert s.outdated
    assert bake(cloth) == {"FINISHED"}
    layer.update()
    assert not s.outdated
    sphere.location.z -= 0.05  # a collider the bake used
    layer.update()
    assert s.outdated
    assert bake(cloth) == {"FINISHED"}
    bpy.ops.object.empty_add(location=(3.0, 0.0, 0.0))  # an unrelated object
    bpy.context.object.location.x += 1.0
    layer.update()
    assert not s.outdated


# ---------------------------------------------------------------------------
# feedback and guards


def test_a_runaway_bake_is_refused_with_its_estimate(project):
    """A stiff cloth with the explicit integrator would need tens of
    thousands of steps per frame: refused before it starts, saying the
    estimate and what to change; the previous bake stays."""
    add_sphere()
    cloth = add_cloth(z=0.6, cuts=30)  # 32 x 32 vertices
    bpy.context.scene.frame_end = 6
    assert bake(cloth) == {"FINISHED"}
    before = snapshot(os.path.dirname(cache_path(cloth)))
    s = cloth.wet_cloth
    s.integrator = "VERLET"  # the explicit one (the default is Semi-Implicit)
    s.stretch = 1e9  # about 50,000 explicit steps per frame
    text = bake_error(cloth)
    assert "Work Limit" in text and "vertex steps" in text, text
    assert "steps per frame" in text and "Semi-Implicit" in text, text
    assert snapshot(os.path.dirname(cache_path(cloth))) == before
    # the large-step integrator bakes the same cloth within the limit
    s.integrator = "IMPLICIT"
    assert bake(cloth) == {"FINISHED"}
    # and a fixed step count above the limit is refused the same way
    s.integrator = "VERLET"
    s.stretch = 1000.0
    s.substeps_auto = False
    s.substeps = 10 ** 5
    text = bake_error(cloth)
    assert "Work Limit" in text and "lower the Quality Steps" in text, text
    # the limit is the artist's to raise
    s.work_limit = 1e4
    s.substeps = 3000
    assert bake(cloth) == {"FINISHED"}


def test_headless_progress_lines(project, capsys):
    """A headless bake prints a progress line every 5 %."""
    cloth = small_scene()
    capsys.readouterr()
    assert bake(cloth) == {"FINISHED"}
    out = capsys.readouterr().out
    lines = [ln for ln in out.splitlines() if ln.startswith("Wet Cloth: baking Cloth")]
    assert 10 <= len(lines) <= 24, lines
    assert "frame 1 of 24 (0 %)" in lines[0] and "(100 %)" in lines[-1], lines
    assert "left" in lines[1], lines


def _stale_tmp(folder, final_name, pid):
    path = os.path.join(folder, ".%s.%d.tmp" % (final_name, pid))
    with open(path, "wb") as f:
        f.write(b"half a bake")
    return path


def _dead_pid():
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


def test_a_killed_bake_leaves_nothing_the_next_bake_keeps(project):
    """A Blender killed during a bake leaves its temporary files; the
    object's next bake removes them (those of a process that still runs,
    another Blender baking, stay), and never touches other objects'."""
    cloth = small_scene()
    other = add_cloth(z=1.2, cuts=4, name="Other")
    assert bake(cloth) == {"FINISHED"}
    assert bake(other) == {"FINISHED"}
    folder = os.path.dirname(cache_path(cloth))
    names = cache_names(cloth)
    dead = _dead_pid()
    stale = [_stale_tmp(folder, n, dead) for n in names]
    alive = _stale_tmp(folder, names[0], os.getppid())  # a running process
    others = _stale_tmp(folder, cache_names(other)[0], dead)
    before = snapshot(folder)
    assert bake(cloth) == {"FINISHED"}
    now = snapshot(folder)
    assert not any(os.path.exists(p) for p in stale)
    assert os.path.exists(alive) and os.path.exists(others)
    for name in cache_names(other):
        assert now[name] == before[name]


def test_a_cancelled_bake_keeps_the_previous_byte_for_byte(project, installed):
    cloth = small_scene()
    bpy.context.scene.frame_end = 200
    assert bake(cloth) == {"FINISHED"}
    folder = os.path.dirname(cache_path(cloth))
    before = snapshot(folder)
    cloth.wet_cloth.wetness = 0.0
    ops = installed.ops
    reports = []

    class Driver(ops._BakeOperator):
        """The operator's class minus Blender's machinery (test_bake_all's
        modal_driver explains why)."""
        object = cloth.name
        to_current_frame = False
        _objects = ops.WETCLOTH_OT_bake._objects

        def report(self, level, text):
            reports.append((set(level), text))

    driver = Driver()
    ctx = bpy.context

    class Event:
        def __init__(self, kind):
            self.type = kind

    assert driver._begin_modal(ctx) == {"RUNNING_MODAL"}
    assert driver.modal(ctx, Event("TIMER")) == {"RUNNING_MODAL"}
    assert any(n.endswith(".tmp") for n in os.listdir(folder))
    assert driver.modal(ctx, Event("ESC")) == {"CANCELLED"}
    assert "previous bake is kept" in reports[-1][1]
    assert snapshot(folder) == before
    assert all(m.show_viewport for m in cloth.modifiers)


# ---------------------------------------------------------------------------
# the wet material


def test_add_wet_material(project):
    cloth = small_scene()
    assert bake(cloth) == {"FINISHED"}
    with bpy.context.temp_override(active_object=cloth, object=cloth):
        assert bpy.ops.wetcloth.add_wet_material() == {"FINISHED"}
        mat = cloth.active_material
        assert mat is not None and mat.use_nodes
        nodes = mat.node_tree.nodes
        bsdf = next(n for n in nodes if n.bl_idname == "ShaderNodeBsdfPrincipled")
        attr = next(n for n in nodes if n.bl_idname == "ShaderNodeAttribute")
        assert attr.attribute_name == "wet_cloth_wetness"
        group = bsdf.inputs["Base Color"].links[0].from_node
        assert group.bl_idname == "ShaderNodeGroup"
        assert bsdf.inputs["Roughness"].links[0].from_node == group
        assert group.inputs["Wetness"].links[0].from_node == attr
        count = len(nodes)
        # again: nothing added
        assert bpy.ops.wetcloth.add_wet_material() == {"FINISHED"}
        assert len(mat.node_tree.nodes) == count
    # the group darkens and glosses with wetness: its nodes' constants
    inner = group.node_tree.nodes
    mixes = [n for n in inner if n.bl_idname == "ShaderNodeMix"]
    assert len(mixes) == 3


# ---------------------------------------------------------------------------
# force fields and soft pins (the library's air velocity, force density and
# goal springs; test_fields.py checks the field values themselves)


def falling_cloth(name="Cloth"):
    """A small cloth with nothing to collide with."""
    cloth = add_cloth(z=0.6, cuts=4, name=name)
    cloth.wet_cloth.use_colliders = False
    cloth.wet_cloth.wetness = 0.0
    return cloth


def test_wind_blows_the_cloth_as_drag_predicts(project):
    """A uniform Wind along +x of strength 20 (the air's speed, m/s): the
    cloth, falling freely, is dragged along x as a body under linear drag
    toward the air's velocity u, x(t) = u (t - tau (1 - exp(-t/tau))) with
    tau = density / air_drag (the drag's law, per area). The calm bake, and
    the wind weighed 0, stay where they were, byte for byte."""
    cloth = falling_cloth()
    assert bake(cloth) == {"FINISHED"}
    calm = open(cache_path(cloth), "rb").read()
    bpy.ops.object.effector_add(type="WIND", location=(-2.0, 0.0, 0.6),
                                rotation=(0.0, np.pi / 2, 0.0))  # its +Z along world +x
    wind = bpy.context.object
    wind.field.strength = 20.0
    wind.field.flow = 1.0
    cloth.wet_cloth.field_wind = 0.0
    assert bake(cloth) == {"FINISHED"}
    assert open(cache_path(cloth), "rb").read() == calm
    cloth.wet_cloth.field_wind = 1.0
    assert bake(cloth) == {"FINISHED"}
    _header, frames = read_pc2(cache_path(cloth))
    assert open(cache_path(cloth), "rb").read() != calm
    s = cloth.wet_cloth
    tau = s.density / s.air_drag
    t = np.arange(frames.shape[0]) / 24.0
    expected = 20.0 * (t - tau * (1.0 - np.exp(-t / tau)))
    dx = (frames[:, :, 0] - frames[:1, :, 0]).mean(axis=1)
    # Verlet's error for this smooth motion is far below 1 %; the links
    # stay slack (the cloth moves as one), so the law holds per particle
    np.testing.assert_allclose(dx[1:], expected[1:], rtol=0.01)
    assert expected[-1] > 1.0
    assert "Wind" in s.baked_inputs.split("\n")
    # moving the field marks the bake outdated
    bpy.context.view_layer.update()
    assert not s.outdated
    wind.location.y += 1.0
    bpy.context.view_layer.update()
    assert s.outdated


def test_a_force_field_pushes_the_cloth_away(project):
    cloth = falling_cloth()
    bpy.context.scene.use_gravity = False
    bpy.ops.object.effector_add(type="FORCE", location=(0.0, 0.0, 0.0))
    bpy.context.object.field.strength = 1.0  # N/m², upward at the cloth
    assert bake(cloth) == {"FINISHED"}
    _header, frames = read_pc2(cache_path(cloth))
    assert (frames[-1, :, 2] - frames[0, :, 2]).min() > 0.5  # pushed up, all of it


def test_soft_pins_from_the_groups_weights(project):
    """Vertices of the pin group with weight 1 hold still; with weight 0.5
    they hang from their place on a spring of half the Pin Stiffness k: a
    cloth pinned so all over moves as one (its links never stretch) and
    swings between its place and 2 g / (k/2) below it."""
    cloth = falling_cloth()
    bpy.context.scene.frame_end = 48
    group = cloth.vertex_groups.new(name="pins")
    group.add(list(range(len(cloth.data.vertices))), 0.5, "REPLACE")
    s = cloth.wet_cloth
    s.pin_group = "pins"
    s.pin_stiffness = 400.0
    s.air_drag = 0.0
    s.damping = 0.0
    assert bake(cloth) == {"FINISHED"}
    _header, frames = read_pc2(cache_path(cloth))
    drop = frames[0, :, 2] - frames[:, :, 2]  # (frames, n)
    np.testing.assert_allclose(drop, drop[:, :1].repeat(drop.shape[1], 1), atol=1e-9)
    amplitude = 2.0 * 9.81 / (0.5 * 400.0)
    assert drop.min() > -1e-9
    # sampled at frames, the swing's lowest point is seen to within the
    # phase a frame covers (omega / 24 = 0.59 rad: cos 0.3 = 0.955)
    assert amplitude * 0.95 < drop.max() <= amplitude * 1.001, (drop.max(), amplitude)
    # weight 1 holds still
    group.add([0], 1.0, "REPLACE")
    assert bake(cloth) == {"FINISHED"}
    _header, frames = read_pc2(cache_path(cloth))
    np.testing.assert_array_equal(frames[:, 0], frames[:1, 0].repeat(frames.shape[0], 0))
    assert (frames[0, 1:, 2] - frames[:, 1:, 2]).max() > 0.01
    # a stiffness out of range is refused, not clamped
    s.pin_stiffness = 0.0
    assert "Pin Stiffness is 0 but must be above 0" in bake_error(cloth)


_FARM = """
import os, sys, tempfile
os.environ["BLENDER_USER_RESOURCES"] = tempfile.mkdtemp()  # no add-on at all
import bpy
import numpy as np
bpy.ops.wm.open_mainfile(filepath=sys.argv[1])
assert not hasattr(bpy.types.Object, "wet_cloth")
ob = bpy.data.objects["Cloth"]
bpy.context.scene.frame_set(int(sys.argv[2]))
ev = ob.evaluated_get(bpy.context.evaluated_depsgraph_get())
m = ev.to_mesh()
co = np.empty(3 * len(m.vertices), np.float32)
m.vertices.foreach_get("co", co)
stuck = np.empty(len(m.vertices), np.float32)
m.attributes["wet_cloth_stuck"].data.foreach_get("value", stuck)
np.save(sys.argv[3], np.concatenate([co, stuck]))
ev.to_mesh_clear()
sys.stdout.flush()
os._exit(0)
"""


def test_a_machine_without_the_add_on_plays_the_bake(project, tmp_path):
    """A render farm has the .blend and the cache files, not the add-on:
    Blender alone plays the positions and the per-frame attributes."""
    cloth = small_scene()
    assert bake(cloth) == {"FINISHED"}
    save_as(bpy.data.filepath)
    _header, frames = read_pc2(cache_path(cloth))
    _header, state = read_pc2(wetness_path(cloth))
    script = tmp_path / "farm.py"
    script.write_text(_FARM)
    out = tmp_path / "farm.npy"
    r = subprocess.run([sys.executable, str(script), bpy.data.filepath, "24", str(out)],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0 and out.exists(), r.stdout + r.stderr
    got = np.load(out)
    n = frames.shape[1]
    np.testing.assert_allclose(got[:3 * n].reshape(n, 3), frames[23], atol=1e-6)
    np.testing.assert_array_equal(got[3 * n:], state[23, :, 1])
    assert got[3 * n:].sum() > 0
