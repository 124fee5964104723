"""The command line: python -m wetcloth run / demo.

A good run writes the PC2 caches, OBJs, stats.json and preview.png with the
right contents; every kind of bad scene file gets one message naming the
file and the field or line, exit status 2, and leaves no file behind.
"""

import json
import os
import struct
import subprocess
import sys

import numpy as np
import pytest

from wetcloth import cli, meshio

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def wetcloth_cli(*args, cwd=None):
    """python -m wetcloth ARGS in a new process: the real exit status."""
    return subprocess.run([sys.executable, "-m", "wetcloth", *args], capture_output=True,
                          text=True, cwd=cwd, timeout=300)


def wetcloth_main(capsys, *args):
    """The same in this process (faster, for the many bad-input cases):
    (exit status, stdout, stderr). An exception escaping main() fails the
    test, as a traceback would fail the one-line check."""
    status = cli.main(list(args))
    out, err = capsys.readouterr()
    return subprocess.CompletedProcess(args, status, out, err)


SMALL = {
    "duration": 0.25, "fps": 24,
    "cloths": [{"name": "sheet", "wetness": 1.0, "pins": [0],
                "grid": {"nu": 8, "nv": 6, "size": [0.6, 0.4], "center": [0.0, 0.0, 0.2]}}],
    "colliders": [{"type": "box", "center": [0.0, 0.0, -0.1], "half_extents": [0.5, 0.5, 0.1]}],
}


def write_scene(folder, scene, name="scene.json"):
    path = folder / name
    path.write_text(json.dumps(scene) if not isinstance(scene, str) else scene)
    return path


def listing(folder):
    return sorted(os.listdir(folder))


# ---------------------------------------------------------------------------
# a good run


def test_run_writes_every_output(tmp_path):
    scene = write_scene(tmp_path, SMALL)
    out = tmp_path / "out"
    r = wetcloth_cli("run", str(scene), "--out", str(out))
    assert r.returncode == 0, r.stderr
    assert "6 frames" in r.stdout and str(out) in r.stdout
    assert "frame/s" in r.stderr  # tqdm's progress bar
    assert listing(out) == ["preview.png", "sheet.obj", "sheet.pc2", "stats.json"]
    assert listing(tmp_path) == ["out", "scene.json"]  # no temporary folder left

    header, frames = meshio.read_pc2(out / "sheet.pc2")
    assert header["magic"] == b"POINTCACHE2\0" and header["version"] == 1
    assert header["vertex_count"] == 48 and header["frame_count"] == 7  # start + 6 frames
    assert header["start"] == 1.0 and header["sampling"] == 1.0
    # frame 0 is the grid as given: row-major, x with i, y with j
    x = np.linspace(-0.3, 0.3, 8)
    y = np.linspace(-0.2, 0.2, 6)
    grid = np.stack([np.tile(x, 6), np.repeat(y, 8), np.full(48, 0.2)], axis=1)
    np.testing.assert_allclose(frames[0], grid, atol=1e-7)
    # the pinned particle stays; the others fall
    np.testing.assert_allclose(frames[-1][0], grid[0], atol=1e-7)
    assert np.all(frames[-1][1:, 2] < 0.2)

    verts, faces = meshio.read_obj(str(out / "sheet.obj"))
    np.testing.assert_allclose(verts, frames[-1], atol=1e-6)
    assert len(faces) == 7 * 5 and all(len(f) == 4 for f in faces)

    stats = json.loads((out / "stats.json").read_text())
    assert stats["frames"] == 6 and len(stats["per_frame"]) == 6
    assert stats["steps"] == sum(f["substeps"] for f in stats["per_frame"])
    assert stats["simulated_seconds"] == pytest.approx(0.25)
    assert stats["intersections"]["frames_checked"] == 6
    assert stats["intersections"]["final"] == {"cloth_cloth": 0, "cloth_collider": 0}
    assert stats["cloths"][0]["name"] == "sheet" and stats["cloths"][0]["particles"] == 48
    assert stats["contacts"]["collider_max"] > 0  # it reached the box
    assert stats["cloths"][0]["stuck_final"] == stats["per_frame"][-1]["stuck"][0]

    png = (out / "preview.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = struct.unpack(">II", png[16:24])
    assert (width, height) == (800, 600)


def test_run_replaces_files_in_an_existing_folder(tmp_path):
    scene = write_scene(tmp_path, SMALL)
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.txt").write_text("mine")
    (out / "stats.json").write_text("old")
    r = wetcloth_cli("run", str(scene), "--out", str(out), "--frames", "2", "--no-progress",
                     "--check", "final")
    assert r.returncode == 0, r.stderr
    assert r.stderr == ""
    assert (out / "keep.txt").read_text() == "mine"
    stats = json.loads((out / "stats.json").read_text())
    assert stats["frames"] == 2 and stats["intersections"]["frames_checked"] == 1
    assert listing(tmp_path) == ["out", "scene.json"]


def test_demo(tmp_path):
    out = tmp_path / "demo"
    r = wetcloth_cli("demo", "--out", str(out), "--frames", "12", "--no-progress")
    assert r.returncode == 0, r.stderr
    assert listing(out) == ["dry.obj", "dry.pc2", "preview.png", "stats.json", "wet.obj",
                            "wet.pc2"]
    stats = json.loads((out / "stats.json").read_text())
    dry, wet = stats["cloths"]
    assert (dry["name"], wet["name"]) == ("dry", "wet")
    assert dry["wetness_mean_final"] == 0.0 and wet["wetness_mean_final"] == 1.0
    # after half a second the wet cloth sticks to its solid, the dry one cannot
    assert dry["stuck_final"] == 0 and wet["stuck_final"] > 50


def test_demo_has_no_intersections(tmp_path):
    # the whole demo (2 s): the soaked cloth wraps its solid in folds, which
    # at the default integrator's large steps passed through each other
    # (32 of 48 frames) until the demo's cloths collided with themselves
    out = tmp_path / "demo"
    r = wetcloth_cli("demo", "--out", str(out), "--check", "every", "--no-progress")
    assert r.returncode == 0, r.stderr
    checked = json.loads((out / "stats.json").read_text())["intersections"]
    assert checked["frames_checked"] == 48
    assert checked["frames_with_intersections"] == 0, checked


def test_simulation_failure_leaves_nothing(tmp_path):
    # frames of 10 s of a very stiff cloth need more substeps than a world
    # may take (max_substeps): the library refuses the first frame
    scene = dict(SMALL, fps=0.1, duration=20, integrator="verlet")
    scene["cloths"] = [dict(SMALL["cloths"][0], material={"stretch": 1e9})]
    path = write_scene(tmp_path, scene)
    r = wetcloth_cli("run", str(path), "--out", str(tmp_path / "out"), "--no-progress")
    assert r.returncode == 1, (r.stdout, r.stderr)
    assert "simulation failed at frame 1 (t = 10 s): advance:" in r.stderr, r.stderr
    assert "max_substeps" in r.stderr, r.stderr
    assert listing(tmp_path) == ["scene.json"]


# ---------------------------------------------------------------------------
# bad scene files: message, exit status 2, nothing written

OBJ_OK = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n"


def with_cloth(**fields):
    s = json.loads(json.dumps(SMALL))
    s["cloths"][0].update(fields)
    return s


def with_grid(**fields):
    s = json.loads(json.dumps(SMALL))
    s["cloths"][0]["grid"].update(fields)
    return s


BAD = {
    # name: (scene text or dict, extra files, strings the message must contain)
    "unreadable": (None, {}, ["missing.json", "cannot read the scene file",
                              "No such file or directory"]),
    "a folder": ("FOLDER", {}, ["folder.json", "cannot read the scene file"]),
    "invalid JSON": ('{\n  "duration": 1,\n  "fps": 24\n  "cloths": []\n}', {},
                     ["scene.json:4:3", "invalid JSON", "Expecting ',' delimiter"]),
    "not an object": ("[1, 2]", {}, ["scene.json", "expected an object, found an array of 2"]),
    "unknown field": (dict(SMALL, durration=1.0), {},
                      ["scene.json: durration: unknown field", "duration"]),
    "unknown nested field": (with_grid(nuu=4), {},
                             ["cloths[0].grid.nuu: unknown field", "nu, nv, size"]),
    "unknown material field": (with_cloth(material={"densty": 0.2}), {},
                               ["cloths[0].material.densty: unknown field", "density"]),
    "wrong type": (with_grid(nu="8"), {},
                   ["cloths[0].grid.nu: expected an integer, found the string \"8\""]),
    "wrong type boolean": (dict(SMALL, fps=True), {},
                           ["fps: expected a number, found a boolean (true)"]),
    "wrong vector": (with_grid(center=[0, 0]), {},
                     ["cloths[0].grid.center: expected an array of 3 numbers, found an array of 2"]),
    "missing field": (dict(SMALL, cloths=[{"grid": {"nv": 4}}]), {},
                      ["cloths[0].grid.nu: missing (required)"]),
    "out of range": (dict(SMALL, duration=-1), {},
                     ["duration: must be greater than 0, found -1"]),
    "out of range fps": (dict(SMALL, fps=0.05), {},
                         ["fps: must be at least 0.1, found 0.05"]),
    "out of range wetness": (with_cloth(wetness=1.5), {},
                             ["cloths[0].wetness: must be at most 1, found 1.5"]),
    "out of range wetness map": (with_cloth(wetness=[0.5] * 47 + [2.0]), {},
                                 ["cloths[0].wetness[47]: must be at most 1, found 2"]),
    "wrong wetness map length": (with_cloth(wetness=[0.5] * 3), {},
                                 ["cloths[0].wetness", "array of 48 numbers", "found an array of 3"]),
    "out of range pin": (with_cloth(pins=[48]), {},
                         ["cloths[0].pins[0]: particle index must be in [0, 48), found 48"]),
    "wrong air_velocity": (with_cloth(air_velocity=[1, 0]), {},
                           ["cloths[0].air_velocity: expected 3 numbers (a constant air "
                            "velocity, m/s) or an array of keyframes"]),
    "out of range air_velocity": (with_cloth(air_velocity=[0, 0, 2e4]), {},
                                  ["cloths[0].air_velocity: the air velocity must be at most "
                                   "10000 m/s long, found [0, 0, 20000]"]),
    "external_force keyframes out of order": (
        with_cloth(external_force=[{"time": 1, "value": [0, 0, 1]},
                                   {"time": 0.5, "value": [0, 0, 2]}]), {},
        ["cloths[0].external_force[1].time: keyframe times must increase, found 0.5 after 1"]),
    "pin_stiffness without pins": (with_cloth(pins=[], pin_stiffness=100), {},
                                   ["cloths[0].pin_stiffness: there are no pins to make soft"]),
    "out of range pin_stiffness": (with_cloth(pins=[0, 5], pin_stiffness=[100, -1]), {},
                                   ["cloths[0].pin_stiffness[1]: must be greater than 0, found -1"]),
    "out of range (library)": (with_cloth(material={"density": -0.1}), {},
                               ["cloths[0]: add_grid_cloth: material.density must be in (0, 1000]",
                                "but is -0.1"]),
    "out of range (library, Python name)": (
        with_cloth(material={"damping": 2}), {},
        ["cloths[0]", "material.stretch_damping must be in [0, 1] but is 2", "Material.damping"]),
    "bad collider type": (dict(SMALL, colliders=[{"type": "cone"}]), {},
                          ["colliders[0].type: expected one of \"mesh\", \"sphere\"",
                           "found \"cone\""]),
    "field of another collider type": (
        dict(SMALL, colliders=[{"type": "sphere", "center": [0, 0, 0], "radius": 1,
                                "half_extents": [1, 1, 1]}]), {},
        ["colliders[0].half_extents: unknown field", "center, radius"]),
    "keyframes out of order": (
        dict(SMALL, colliders=[{"type": "sphere", "center": [0, 0, 0], "radius": 0.3,
                                "keyframes": [{"time": 1, "translate": [0, 0, 0]},
                                              {"time": 0.5, "translate": [0, 0, 1]}]}]), {},
        ["colliders[0].keyframes[1].time: keyframe times must increase, found 0.5 after 1"]),
    "missing OBJ": (dict(SMALL, cloths=[{"obj": "nothere.obj"}]), {},
                    ["cloths[0].obj: cannot read", "nothere.obj", "No such file or directory"]),
    "OBJ with bad indices": (dict(SMALL, cloths=[{"obj": "bad.obj"}]),
                             {"bad.obj": "v 0 0 0\nv 1 0 0\nv 0 1 0\n# a comment\nf 1 2 3\n"
                                         "f 1 3 9\n"},
                             ["cloths[0].obj", "bad.obj:6: face uses vertex 9, but the file has "
                                               "3 vertices"]),
    "OBJ with a bad number": (dict(SMALL, colliders=[{"type": "mesh", "obj": "bad.obj"}]),
                              {"bad.obj": "v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n"},
                              ["colliders[0].obj", "bad.obj:2: a vertex coordinate is not a number"]),
    "OBJ cloth with a pentagon": (dict(SMALL, cloths=[{"obj": "penta.obj"}]),
                                  {"penta.obj": "v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\n"
                                                "f 1 2 3 4 5\n"},
                                  ["cloths[0].obj", "triangles or quads",
                                   "a face of 5 vertices"]),
    "degenerate mesh (library)": (dict(SMALL, cloths=[{"obj": "line.obj"}]),
                                  {"line.obj": "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"},
                                  ["cloths[0]: add_cloth:"]),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_scene(tmp_path, capsys, case):
    scene, files, expected = BAD[case]
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    if scene is None:
        path = tmp_path / "missing.json"
    elif scene == "FOLDER":
        path = tmp_path / "folder.json"
        path.mkdir()
    else:
        path = write_scene(tmp_path, scene)
    before = listing(tmp_path)
    out = tmp_path / "out"
    r = wetcloth_main(capsys, "run", str(path), "--out", str(out), "--no-progress")
    assert r.returncode == 2, (case, r.returncode, r.stdout, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr  # one message, no traceback
    assert lines[0].startswith("wetcloth: error: " + str(path.parent)), lines[0]
    for text in expected:
        assert text in lines[0], (text, lines[0])
    assert r.stdout == ""
    assert listing(tmp_path) == before  # no output folder, no temporary files


def test_bad_scene_leaves_an_existing_output_untouched(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "stats.json").write_text("previous run")
    path = write_scene(tmp_path, dict(SMALL, fps="fast"))
    r = wetcloth_cli("run", str(path), "--out", str(out))
    assert r.returncode == 2 and "fps: expected a number" in r.stderr
    assert listing(out) == ["stats.json"] and (out / "stats.json").read_text() == "previous run"
    assert listing(tmp_path) == ["out", "scene.json"]


def test_output_path_that_is_a_file(tmp_path):
    path = write_scene(tmp_path, SMALL)
    (tmp_path / "out").write_text("a file")
    r = wetcloth_cli("run", str(path), "--out", str(tmp_path / "out"))
    assert r.returncode == 2 and "exists and is not a folder" in r.stderr
    assert (tmp_path / "out").read_text() == "a file"
    assert listing(tmp_path) == ["out", "scene.json"]


def test_bad_arguments_exit_2(tmp_path):
    r = wetcloth_cli("run", "x.json")
    assert r.returncode == 2 and "--out" in r.stderr
    r = wetcloth_cli("demo", "--out", str(tmp_path / "o"), "--frames", "0")
    assert r.returncode == 2 and "--frames must be at least 1" in r.stderr
    assert listing(tmp_path) == []
