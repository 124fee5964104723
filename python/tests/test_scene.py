"""Scene files in-process: defaults, every cloth and collider kind, keyframed
animation, the shipped thesis scenes, OBJ reading and PC2 writing."""

import glob
import json
import os

import numpy as np
import pytest

from wetcloth import meshio, scene

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
