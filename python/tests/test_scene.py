"""Scene files in-process: defaults, every cloth and collider kind, keyframed
animation, the applied forces (air_velocity, external_force, pin_stiffness),
the shipped thesis scenes, OBJ reading and PC2 writing."""

import glob
import json
import os

import numpy as np
import pytest

from wetcloth import Material, World, meshio, scene

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENES = sorted(glob.glob(os.path.join(ROOT, "tools", "scenes", "*.json")))


def from_dict(d, base="."):
    return scene.from_dict(d, "test.json", base)


def test_defaults():
    s = from_dict({"cloths": [{"grid": {"nu": 3, "nv": 4}}]})
    assert (s.duration, s.fps, s.substeps, s.threads, s.start_frame) == (2.0, 24.0, 0, 0, 1.0)
    assert s.gravity == [0.0, 0.0, -9.81] and s.frame_count == 48
    c = s.cloths[0]
    assert c["name"] == "cloth" and c["wetness"] == 0.0 and c["pins"] == []
    assert c["grid"]["size"] == [1.0, 1.0] and c["grid"]["center"] == [0.0, 0.0, 0.0]
    assert c["material"] == {} and c["self_collision"] is False
    assert c["collide_with_cloths"] is True
    assert s.colliders == []


def test_duplicate_names_are_rejected():
    with pytest.raises(scene.SceneError, match=r"cloths\[1\].name: another cloth"):
        from_dict({"cloths": [{"grid": {"nu": 3, "nv": 3}}, {"name": "cloth",
                                                              "grid": {"nu": 3, "nv": 3}}]})


def test_grid_and_obj_cloths_are_the_same_cloth(tmp_path):
    # the same 5 x 4 grid, once as "grid" and once as an OBJ of its quads,
    # gives bitwise the same motion
    nu, nv = 5, 4
    x, y = np.linspace(-0.5, 0.5, nu), np.linspace(-0.5, 0.5, nv)
    verts = np.stack([np.tile(x, nv), np.repeat(y, nu), np.full(nu * nv, 0.3)], 1)
    quads = [[j * nu + i, j * nu + i + 1, (j + 1) * nu + i + 1, (j + 1) * nu + i]
             for j in range(nv - 1) for i in range(nu - 1)]
    meshio.write_obj(str(tmp_path / "grid.obj"), verts, quads)
    common = {"duration": 0.125, "colliders": [{"type": "sphere", "center": [0, 0, 0],
                                                "radius": 0.25}]}
    a = from_dict(dict(common, cloths=[{"grid": {"nu": nu, "nv": nv,
                                                 "center": [0, 0, 0.3]}}]))
    b = from_dict(dict(common, cloths=[{"obj": "grid.obj"}]), str(tmp_path))
    out = []
    for s in (a, b):
        built = scene.build(s)
        for f in range(1, s.frame_count + 1):
            built.world.advance(1 / s.fps)
        out.append(built.cloths[0][1].positions)
        built.world.close()
    np.testing.assert_array_equal(out[0], out[1])


def test_keyframes_interpolate_and_hold():
    k = scene.Keyframes([0.5, 1.0], [[0, 0, 0], [2, 0, -1]])
    np.testing.assert_array_equal(k.at(0.0), [0, 0, 0])
    np.testing.assert_array_equal(k.at(0.75), [1, 0, -0.5])
    np.testing.assert_array_equal(k.at(3.0), [2, 0, -1])


def test_pin_keyframes_move_the_pins():
    s = from_dict({"duration": 0.5, "cloths": [{
        "grid": {"nu": 4, "nv": 4}, "pins": [0, 3],
        "pin_keyframes": [{"time": 0, "translate": [0, 0, 0]},
                          {"time": 0.25, "translate": [0, 0, 0.2]}]}]})
    built = scene.build(s)
    start = built.cloths[0][1].positions[[0, 3]]
    for f in range(1, s.frame_count + 1):
        built.set_targets(f / s.fps)
        built.world.advance(1 / s.fps)
        if f == 3:  # t = 0.125: halfway
            np.testing.assert_allclose(built.cloths[0][1].positions[[0, 3]],
                                       start + [0, 0, 0.1], atol=1e-12)
    np.testing.assert_allclose(built.cloths[0][1].positions[[0, 3]], start + [0, 0, 0.2],
                               atol=1e-12)
    built.world.close()


@pytest.mark.parametrize("kind", ["mesh", "sphere", "box", "capsule", "convex"])
def test_keyframed_colliders_lift_the_cloth(kind):
    shapes = {
        "mesh": {"vertices": [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]],
                 "triangles": [[0, 1, 2], [0, 2, 3]]},
        "sphere": {"center": [0, 0, -2], "radius": 2},
        "box": {"center": [0, 0, -0.5], "half_extents": [1, 1, 0.5]},
        "capsule": {"a": [-1, 0, -1], "b": [1, 0, -1], "radius": 1},
        "convex": {"points": [[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                              [-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]]},
    }
    s = from_dict({"duration": 0.5, "cloths": [{"grid": {"nu": 5, "nv": 5, "size": [0.3, 0.3],
                                                         "center": [0, 0, 0.01]}}],
                   "colliders": [dict(shapes[kind], type=kind, keyframes=[
                       {"time": 0, "translate": [0, 0, 0]},
                       {"time": 0.25, "translate": [0, 0, 0.3]}])]})
    built = scene.build(s)
    for f in range(1, s.frame_count + 1):
        built.set_targets(f / s.fps)
        built.world.advance(1 / s.fps)
    z = built.cloths[0][1].positions[:, 2]
    built.world.close()
    # the top came up 0.3 m; the cloth lies on it (its edges lower on the
    # curved shapes)
    assert z[12] > 0.3 and np.all(z > 0.28), (kind, z[12], z.min())


def test_collider_keyframe_at_time_zero_places_it():
    s = from_dict({"duration": 0.1, "cloths": [{"grid": {"nu": 3, "nv": 3}}],
                   "colliders": [{"type": "convex", "points": [[0, 0, 0], [1, 0, 0], [0, 1, 0],
                                                               [0, 0, 1]],
                                  "keyframes": [{"time": 0, "translate": [5, 0, 0]}]},
                                 {"type": "sphere", "center": [0, 0, 0], "radius": 1,
                                  "keyframes": [{"time": 0, "translate": [0, 5, 0]}]}]})
    built = scene.build(s)
    hull, ball = built.colliders[0][1], built.colliders[1][1]
    np.testing.assert_array_equal(hull.params["points"][0], [5, 0, 0])
    np.testing.assert_array_equal(ball.position, [0, 5, 0])
    built.set_targets(0.05)  # held: the hull stays where it is
    np.testing.assert_array_equal(hull.position, [0, 0, 0])
    built.world.close()


# ---------------------------------------------------------------------------
# per-cloth applied forces: air_velocity, external_force, pin_stiffness


def grid_cloth(**fields):
    c = {"grid": {"nu": 4, "nv": 4, "size": [0.5, 0.5]},
         "material": {"damping": 0, "bend": 0, "stretch": 100, "air_drag": 1.5}}
    c.update(fields)
    return c


def test_scene_fields_default_to_none():
    c = from_dict({"cloths": [grid_cloth()]}).cloths[0]
    assert c["air_velocity"] is None and c["external_force"] is None
    assert c["pin_stiffness"] is None


def test_constant_scene_fields_are_set_when_built():
    s = from_dict({"gravity": [0, 0, 0], "cloths": [grid_cloth(
        air_velocity=[2.0, 0.0, 0.0], external_force=[0.0, 0.0, 0.3],
        pins=[0, 15], pin_stiffness=[40.0, 60.0])]})
    built = scene.build(s)
    with built.world as w, World(gravity=(0, 0, 0)) as w2:
        cloth = built.cloths[0][1]
        assert cloth.pin_count == 2
        # the same by hand
        c2 = w2.add_grid_cloth(4, 4, size=(0.5, 0.5), material=Material(
            damping=0, bend=0, stretch=100, air_drag=1.5))
        c2.pin([0, 15], stiffness=[40.0, 60.0])
        c2.set_air_velocity([2.0, 0.0, 0.0])
        c2.set_external_forces([0.0, 0.0, 0.3])
        for f in range(1, 4):
            built.set_fields((f - 0.5) / 24)
            built.set_targets(f / 24)
            w.advance(1 / 24)
            w2.advance(1 / 24)
        np.testing.assert_array_equal(cloth.positions, c2.positions)
        assert cloth.velocities[5, 0] > 0.5  # drifting with the wind


def test_keyframed_fields_are_set_at_each_frames_middle():
    keys = [{"time": 0.0, "value": [0.0, 0.0, 0.0]}, {"time": 1.0, "value": [0.0, 0.0, 2.4]}]
    s = from_dict({"gravity": [0, 0, 0], "duration": 0.25,
                   "cloths": [grid_cloth(external_force=keys, air_velocity=[
                       {"time": 0.5, "value": [1.0, 0.0, 0.0]}])]})
    field = s.cloths[0]["external_force"]
    assert isinstance(field, scene.Keyframes)
    np.testing.assert_array_equal(field.at(0.5), [0, 0, 1.2])
    built = scene.build(s)
    with built.world as w, World(gravity=(0, 0, 0)) as w2:
        cloth = built.cloths[0][1]
        c2 = w2.add_grid_cloth(4, 4, size=(0.5, 0.5), material=Material(
            damping=0, bend=0, stretch=100, air_drag=1.5))
        c2.set_air_velocity([1.0, 0.0, 0.0])  # one keyframe: held
        for f in range(1, s.frame_count + 1):
            built.set_fields((f - 0.5) / s.fps)
            built.set_targets(f / s.fps)
            w.advance(1 / s.fps)
            # the frame's middle: on a linear stretch, the frame's mean
            c2.set_external_forces([0.0, 0.0, 2.4 * (f - 0.5) / s.fps])
            w2.advance(1 / s.fps)
        np.testing.assert_array_equal(cloth.positions, c2.positions)


def test_scene_run_applies_the_keyframed_fields(tmp_path):
    keys = [{"time": 0.0, "value": [0.0, 0.0, 0.0]}, {"time": 0.25, "value": [0.0, 0.0, 3.0]}]
    s = from_dict({"gravity": [0, 0, 0], "duration": 0.25,
                   "cloths": [grid_cloth(external_force=keys)]})
    scene.run(s, str(tmp_path / "out"), progress=False, check="none")
    _, frames = meshio.read_pc2(str(tmp_path / "out" / "cloth.pc2"))
    rise = frames[:, :, 2].mean(axis=1)
    # pushed up ever harder: the rise grows faster than linearly
    assert rise[-1] > rise[0] and np.all(np.diff(rise, 2) > 0)


@pytest.mark.parametrize("fields,message", [
    ({"air_velocity": [1, 2]}, "cloths[0].air_velocity: expected 3 numbers (a constant air "
                               "velocity, m/s) or an array of keyframes"),
    ({"air_velocity": "north"}, "cloths[0].air_velocity: expected 3 numbers"),
    ({"air_velocity": [0, 0, True]}, "cloths[0].air_velocity[2]: expected a number, found a "
                                     "boolean"),
    ({"air_velocity": [2e4, 0, 0]}, "cloths[0].air_velocity: the air velocity must be at most "
                                    "10000 m/s long, found [20000, 0, 0] (20000 m/s)"),
    ({"external_force": [{"time": 0, "value": [0, 0, 1]}, {"time": 0, "value": [0, 0, 2]}]},
     "cloths[0].external_force[1].time: keyframe times must increase, found 0 after 0"),
    ({"external_force": [{"time": 0, "value": [0, 0, 1]}, 5]},
     "cloths[0].external_force[1]: expected an object, found the number 5"),
    ({"external_force": [{"time": 0, "translate": [0, 0, 1]}]},
     "cloths[0].external_force[0].translate: unknown field; expected one of: time, value"),
    ({"external_force": [{"time": 1, "value": [0, 0, -3e6]}]},
     "cloths[0].external_force[0].value: the force density must be at most 1e+06 N/m^2 long"),
    ({"pin_stiffness": 10.0}, "cloths[0].pin_stiffness: there are no pins to make soft"),
    ({"pins": [0, 1], "pin_stiffness": [10.0]},
     "cloths[0].pin_stiffness: expected a number or an array of 2 numbers (one per pin), found "
     "an array of 1"),
    ({"pins": [0, 1], "pin_stiffness": [10.0, 0.0]},
     "cloths[0].pin_stiffness[1]: must be greater than 0, found 0"),
    ({"pins": [0], "pin_stiffness": 2e8}, "cloths[0].pin_stiffness: must be at most 1e+08, found 2e+08"),
    ({"pins": [0], "pin_stiffness": None}, "cloths[0].pin_stiffness: expected a number, found null"),
])
def test_bad_scene_fields_are_named(fields, message):
    with pytest.raises(scene.SceneError) as e:
        from_dict({"cloths": [grid_cloth(**fields)]})
    assert message in str(e.value), str(e.value)


@pytest.mark.parametrize("path", SCENES, ids=[os.path.basename(p) for p in SCENES])
def test_shipped_scene_runs(path, tmp_path):
    s = scene.load(path)
    with open(path, encoding="utf-8") as f:
        assert json.load(f)["description"]
    stats = scene.run(s, str(tmp_path / "out"), progress=False, frames=2)
    assert stats["frames"] == 2
    assert stats["intersections"]["final"] == {"cloth_cloth": 0, "cloth_collider": 0}
    names = sorted(os.listdir(tmp_path / "out"))
    assert "stats.json" in names and "preview.png" in names


@pytest.mark.parametrize("name", ["verlet", "implicit"])
def test_scene_stats_count_the_solver_iterations(name, tmp_path):
    """stats.json sums the implicit integrator's conjugate-gradient
    iterations over the run (its per-frame records hold each frame's), at
    least one per step; the other integrators solve no system and report 0.
    (Here and not in test_integrators.py, which the sanitizer build also
    runs: the run's preview goes through matplotlib, whose C++ exceptions
    abort under the preloaded ASan runtime.)"""
    d = {"cloths": [{"grid": {"nu": 8, "nv": 8}}], "integrator": name}
    s = from_dict(d)
    stats = scene.run(s, str(tmp_path / "out"), progress=False, frames=3)
    total = stats["solver_iterations"]["total"]
    assert total == sum(r["solver_iterations"] for r in stats["per_frame"])
    if name == "verlet":
        assert total == 0
    else:
        assert total >= stats["steps"] > 0
        assert stats["solver_iterations"]["per_step_mean"] == total / stats["steps"]


def test_thesis_scenes_are_shipped():
    names = {os.path.basename(p) for p in SCENES}
    assert {"thesis_wrap_wet.json", "thesis_wrap_dry.json", "thesis_slack.json",
            "thesis_fold.json"} <= names


def test_obj_reader_forms(tmp_path):
    p = tmp_path / "m.obj"
    p.write_text("# c\no x\nv 0 0 0\nv 1 0 0 1\nv 1 1 0\nvt 0 0\nvn 0 0 1\nv 0 1 0\n"
                 "s off\nf 1/1/1 2/1/1 3//1\nf -4 -2 -1\n")
    v, f = meshio.read_obj(str(p))
    assert v.shape == (4, 3) and f == [[0, 1, 2], [0, 2, 3]]
    np.testing.assert_array_equal(meshio.triangulate([[0, 1, 2, 3]]), [[0, 1, 2], [0, 2, 3]])
    np.testing.assert_array_equal(meshio.cloth_faces([[0, 1, 2, 3], [1, 4, 2]], "x"),
                                  [[0, 1, 2, 3], [1, 4, 2, -1]])


@pytest.mark.parametrize("text,message", [
    ("v 0 0\n", "m.obj:1: a vertex needs 3 coordinates, found 2"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", "m.obj:4: a face needs at least 3 vertices"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", "m.obj:4: face vertex index 0"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n", "m.obj:4: relative face index -4"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", "m.obj:4: face vertex 'x' is not an index"),
    ("v 0 0 nan\n", "m.obj:1: a vertex coordinate is not finite"),
    ("v 0 0 0\nbogus 1\n", "m.obj:2: unknown OBJ statement 'bogus'"),
    ("v 0 0 0\n", "m.obj: no faces"),
])
def test_obj_reader_errors(tmp_path, text, message):
    p = tmp_path / "m.obj"
    p.write_text(text)
    with pytest.raises(meshio.MeshError) as e:
        meshio.read_obj(str(p))
    assert message in str(e.value)


def test_pc2_round_trip(tmp_path):
    frames = np.random.default_rng(3).normal(size=(3, 5, 3))
    w = meshio.PC2Writer(str(tmp_path / "c.pc2"), 5, 3, start=1.0)
    for f in frames:
        w.write(f)
    w.close()
    header, back = meshio.read_pc2(str(tmp_path / "c.pc2"))
    assert header["frame_count"] == 3 and header["vertex_count"] == 5
    np.testing.assert_array_equal(back, frames.astype(np.float32))
    assert os.path.getsize(tmp_path / "c.pc2") == 32 + 3 * 5 * 3 * 4
    short = meshio.PC2Writer(str(tmp_path / "d.pc2"), 5, 3)
    short.write(frames[0])
    with pytest.raises(RuntimeError, match="wrote 1 frames, the header says 3"):
        short.close()


# Found by fuzzing the loader (tests/fuzz/fuzz_scene.py): each of these raised
# something other than SceneError.
@pytest.mark.parametrize("text,message", [
    # json.loads refuses integers of more than 4300 digits with ValueError
    ('{"duration": ' + "9" * 5000 + "}", "invalid JSON: Exceeds the limit"),
    # and deep nesting with RecursionError
    ("[" * 100000, "invalid JSON: nested too deeply"),
    # an integer that float() cannot hold raised OverflowError
    ('{"gravity": [0, 0, 1' + "0" * 400 + '], "cloths": [{"grid": {"nu": 2, "nv": 2}}]}',
     "gravity[2]: expected a finite number, found a 1329-bit integer, too large for a double"),
    # a NUL in an OBJ path raised ValueError from open()
    ('{"cloths": [{"obj": "a\\u0000.obj"}]}', "cloths[0].obj: cannot read"),
    # a device would be read forever
    ('{"cloths": [{"obj": "/dev/zero"}]}', "cloths[0].obj: cannot read /dev/zero: not a regular file"),
])
def test_loader_raises_only_scene_error(tmp_path, text, message):
    p = tmp_path / "s.json"
    p.write_text(text)
    with pytest.raises(scene.SceneError) as e:
        scene.load(str(p))
    assert message in str(e.value)
