"""The Python binding: every call of the API surface, the arrays it returns,
errors, and that a world stays usable after one.

The physics itself is tested in C (tests/); these tests check that the
binding hands the right arguments to the library and gives back what the
library computed, so each compares with a closed form or with what the
C API says must happen.
"""

import gc
import math
import os
import subprocess
import sys

import numpy as np
import pytest

import wetcloth
from wetcloth import Material, World, WetclothError

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def project_version():
    with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
        for line in f:
            if line.startswith("project(wetcloth VERSION "):
                return line.split()[2]
    raise AssertionError("no project() line in CMakeLists.txt")


# ---------------------------------------------------------------------------
# package, library, version


def test_version_is_the_projects():
    assert wetcloth.__version__ == project_version()


def test_library_is_found_inside_the_package():
    # ctest runs the staged package with WETCLOTH_LIBRARY unset (empty)
    assert not os.environ.get("WETCLOTH_LIBRARY")
    pkg = os.path.dirname(wetcloth.__file__)
    assert os.path.dirname(wetcloth.library_path) == pkg


def _import_in_subprocess(env_library):
    env = dict(os.environ, WETCLOTH_LIBRARY=env_library)
    code = "import wetcloth; print(wetcloth.library_path)"
    return subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)


def test_environment_override_is_used(tmp_path):
    copy = tmp_path / "libwetcloth-copy.so"
    copy.write_bytes(open(wetcloth.library_path, "rb").read())
    r = _import_in_subprocess(str(copy))
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == str(copy)


def test_environment_override_to_a_missing_file_is_an_error(tmp_path):
    r = _import_in_subprocess(str(tmp_path / "nothing.so"))
    assert r.returncode != 0
    assert "WETCLOTH_LIBRARY" in r.stderr and "nothing.so" in r.stderr


def test_a_process_that_ran_threads_exits_cleanly():
    """A world that ran on 2 threads leaves OpenMP's workers behind; with
    OMP_WAIT_POLICY=active they spin in the runtime's code until the process
    ends. The interpreter's shutdown frees the library handle, and the
    library (with the runtime) must stay mapped for them: before it did, the
    process crashed on its way out every time (exit status -11)."""
    code = ("import wetcloth\n"
            "w = wetcloth.World(threads=2, adapt_threads=False)\n"
            "w.add_grid_cloth(64, 64, size=(1, 1), center=(0, 0, 1))\n"
            "w.advance(1 / 24, 2)\n"
            "print(w.stats['threads'])\n")
    env = dict(os.environ, OMP_WAIT_POLICY="active")
    for _ in range(3):
        r = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                           timeout=120)
        assert r.returncode == 0, (r.returncode, r.stdout, r.stderr)
        assert r.stdout.strip() == "2", r.stdout


def test_every_struct_of_the_binding_has_the_libraries_size():
    from wetcloth import _lib
    structs = _lib.declared_structs(wetcloth.ffi)
    names = [name for name, _ in structs]
    # the header's 11 structs with a body; wc_world is opaque
    assert len(structs) == 11 and "wc_world_def" in names and "wc_world" not in names
    for name, size in structs:
        assert wetcloth.lib.wc_struct_size(name.encode()) == size, name
    _lib.check_struct_sizes(wetcloth.lib, wetcloth.ffi, "here")  # raises on a mismatch


def test_a_binding_from_another_header_is_refused_by_name():
    """A binding whose structs differ from the library's (generated from an
    older or newer wetcloth.h) is refused when it loads, naming each struct
    and both sizes, instead of passing the library a struct too short."""
    import cffi
    from wetcloth import _lib
    stale = cffi.FFI()
    stale.cdef("typedef struct wc_world wc_world;"
               "typedef struct wc_world_def { double gravity[3]; } wc_world_def;"
               "typedef struct wc_from_the_future { int a; } wc_from_the_future;")
    with pytest.raises(ImportError) as e:
        _lib.check_struct_sizes(wetcloth.lib, stale, "/some/libwetcloth.so")
    text = str(e.value)
    assert "/some/libwetcloth.so" in text and "different versions of wetcloth.h" in text
    size = wetcloth.ffi.sizeof("wc_world_def")
    assert "wc_world_def is %d bytes in the library, 24 in the binding" % size in text
    assert "wc_from_the_future is not a struct the library knows" in text
    assert "pip install ." in text

    # a library from before wc_struct_size, loaded as the package loads one
    # (the C library stands in: it has no wc_ symbols either; Windows has
    # none by that name, and find_library("c") finds none there)
    import ctypes.util
    old = wetcloth.ffi.dlopen("kernel32.dll" if sys.platform == "win32"
                              else ctypes.util.find_library("c"))
    with pytest.raises(ImportError, match="has no wc_struct_size"):
        _lib.check_struct_sizes(old, wetcloth.ffi, "/old/libwetcloth.so")


# ---------------------------------------------------------------------------
# Material


def test_material_defaults_are_the_libraries():
    c = wetcloth.lib.wc_material_default()
    m = Material()
    assert (m.density, m.stretch, m.bend, m.damping, m.air_drag, m.thickness, m.friction) == (
        c.density, c.stretch_stiffness, c.bend_stiffness, c.stretch_damping, c.air_drag,
        c.thickness, c.friction)
    assert (m.adhesion, m.spread, m.wet_friction, m.wet_grip, m.wet_mass_gain, m.wet_softening,
            m.wicking, m.drying) == (c.adhesion, c.spread, c.wet_friction, c.wet_grip,
                                     c.wet_mass_gain, c.wet_softening, c.wicking, c.drying)


def test_material_reaches_the_library():
    # mass of a grid particle = density * its area; doubling density doubles it
    with World() as w:
        a = w.add_grid_cloth(3, 3, material=Material(density=0.1))
        b = w.add_grid_cloth(3, 3, material=Material(density=0.2))
        np.testing.assert_allclose(b.masses, 2 * a.masses, rtol=1e-15)
        # the centre particle of a 3 x 3 grid of 1 m owns 0.5 x 0.5 m^2
        assert a.masses[4] == pytest.approx(0.1 * 0.25, rel=1e-12)


def test_material_unknown_field_is_rejected():
    with pytest.raises(TypeError):
        Material(densty=1.0)


def test_material_out_of_range_names_the_python_field():
    with World() as w:
        with pytest.raises(WetclothError) as e:
            w.add_grid_cloth(4, 4, material=Material(stretch=-1.0))
        assert "stretch_stiffness" in str(e.value) and "Material.stretch" in str(e.value)
        assert e.value.status_name == "WC_ERROR_INVALID_ARGUMENT"


# ---------------------------------------------------------------------------
# World, grid and mesh cloths


def test_world_rejects_bad_gravity_with_the_c_message():
    with pytest.raises(WetclothError) as e:
        World(gravity=(0.0, 0.0, float("nan")))
    assert "gravity" in str(e.value)
    with pytest.raises(WetclothError) as e:
        World(gravity=(0.0, 1.0))
    assert "gravity" in str(e.value) and "3" in str(e.value)


def test_grid_layout():
    with World() as w:
        nu, nv = 5, 3
        c = w.add_grid_cloth(nu, nv, size=(2.0, 1.0), center=(1.0, -1.0, 0.5))
        p = c.positions
        assert p.shape == (nu * nv, 3) and p.dtype == np.float64
        for j in range(nv):
            for i in range(nu):
                np.testing.assert_allclose(
                    p[j * nu + i], [1.0 + (i / (nu - 1) - 0.5) * 2.0,
                                    -1.0 + (j / (nv - 1) - 0.5) * 1.0, 0.5], atol=1e-15)
        assert c.faces.shape == ((nu - 1) * (nv - 1), 4)
        assert c.triangles.shape == (2 * (nu - 1) * (nv - 1), 3)


def test_free_fall_matches_closed_form():
    # Verlet is exact for constant acceleration (docs/model.md, Integration)
    g = -9.81
    with World(gravity=(0.0, 0.0, g)) as w:
        c = w.add_grid_cloth(4, 4, center=(0.0, 0.0, 2.0), material=Material(air_drag=0.0))
        dt, n = 1e-3, 100
        for _ in range(n):
            w.step(dt)
        t = n * dt
        np.testing.assert_allclose(c.positions[:, 2], 2.0 + 0.5 * g * t * t, rtol=0, atol=1e-12)
        assert w.time == pytest.approx(t, rel=1e-12)
        assert w.stats["steps"] == n


def test_mesh_cloth_triangles_and_quads():
    v = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0]]
    with World() as w:
        quads = w.add_cloth(v, [[0, 1, 2, 3], [1, 4, 2, -1]])
        tris = w.add_cloth(v, [[0, 1, 2], [0, 2, 3], [1, 4, 2]])
        np.testing.assert_array_equal(quads.positions, np.array(v, dtype=float))
        assert quads.triangles.shape == (3, 3) and tris.triangles.shape == (3, 3)
        assert quads.particle_count == 5 and len(w.cloths) == 2


def test_bad_face_names_face_and_vertex_and_world_stays_usable():
    with World() as w:
        good = w.add_grid_cloth(4, 4)
        before = good.positions
        with pytest.raises(WetclothError) as e:
            w.add_cloth([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 7]])
        msg = str(e.value)
        assert "add_cloth" in msg and "7" in msg and "3" in msg, msg
        with pytest.raises(WetclothError) as e:
            w.add_cloth([[0, 0, 0], [1, 0, 0]], [[0, 1]])
        assert "faces" in str(e.value) and "(n, 3 or 4)" in str(e.value)
        with pytest.raises(WetclothError) as e:
            w.add_cloth([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0.0, 1.0, 2.0]])
        assert "faces must be integers" in str(e.value)
        assert len(w.cloths) == 1 and wetcloth.lib.wc_world_cloth_count(w._ptr) == 1
        w.advance(1 / 24)
        assert np.all(good.positions[:, 2] < before[:, 2])


def test_bad_arguments_are_wetcloth_errors():
    with World() as w:
        with pytest.raises(WetclothError, match="nu must be an integer"):
            w.add_grid_cloth(4.5, 4)
        with pytest.raises(WetclothError, match="nu must fit in 32 bits"):
            w.add_grid_cloth(2 ** 40, 4)
        with pytest.raises(WetclothError, match="center must be 3 numbers"):
            w.add_grid_cloth(4, 4, center=(0, 0))
        with pytest.raises(WetclothError, match="dt must be a number"):
            w.step("fast")


# ---------------------------------------------------------------------------
# pins


def test_pins_reach_their_targets():
    with World() as w:
        c = w.add_grid_cloth(5, 5)
        c.pin([0, 4])
        assert c.pin_count == 2
        start = c.positions[[0, 4]]
        target = start + [0.1, 0.0, 0.2]
        c.set_pin_targets(target)
        w.advance(1 / 24)
        np.testing.assert_allclose(c.positions[[0, 4]], target, atol=1e-12)
        with pytest.raises(WetclothError) as e:
            c.set_pin_targets(target[:1])
        assert "(2, 3)" in str(e.value)
        with pytest.raises(WetclothError) as e:
            c.pin([0])  # already pinned
        assert "0" in str(e.value) and "pin" in str(e.value)
        with pytest.raises(WetclothError) as e:
            c.pin([25])
        assert "25" in str(e.value)
        assert c.pin_count == 2
        c.unpin_all()
        assert c.pin_count == 0


# ---------------------------------------------------------------------------
# wetness, contact, stuck


def test_wetness_scalar_and_map():
    with World() as w:
        c = w.add_grid_cloth(4, 4, wetness=0.25)
        np.testing.assert_array_equal(c.wetness, np.full(16, 0.25))
        m = np.linspace(0.0, 1.0, 16)
        c.set_wetness(m)
        np.testing.assert_array_equal(c.wetness, m)
        c.set_wetness(0.5)
        np.testing.assert_array_equal(c.wetness, np.full(16, 0.5))
        with pytest.raises(WetclothError) as e:
            c.set_wetness(np.r_[m[:15], 1.5])
        assert "wetness[15]" in str(e.value), str(e.value)
        np.testing.assert_array_equal(c.wetness, np.full(16, 0.5))
        with pytest.raises(WetclothError, match=r"shape \(16\)"):
            c.set_wetness(m[:3])
        d = w.add_grid_cloth(4, 4, wetness=m)
        np.testing.assert_array_equal(d.wetness, m)
        with pytest.raises(WetclothError, match=r"wetness\[2\]"):
            w.add_grid_cloth(4, 4, wetness=np.r_[0.0, 0.0, -0.1, np.zeros(13)])
        assert len(w.cloths) == 2  # the rejected cloth was not added
        # wet cloth is heavier: mass x (1 + wet_mass_gain * w)
        np.testing.assert_allclose(d.masses, c.masses / 1.5 * (1 + m), rtol=1e-12)


def _drop_on_sphere(wetness, frames=24):
    w = World()
    c = w.add_grid_cloth(12, 12, size=(0.8, 0.8), center=(0.0, 0.0, 0.4), wetness=wetness)
    w.add_sphere((0.0, 0.0, 0.0), 0.3)
    for _ in range(frames):
        w.advance(1 / 24)
    return w, c


def test_contact_and_stuck_on_a_sphere():
    w, wet = _drop_on_sphere(1.0)
    contact, stuck = wet.in_contact, wet.stuck
    assert contact.dtype == bool and stuck.dtype == bool and contact.shape == (144,)
    assert stuck.sum() > 0 and not np.any(stuck & ~contact)
    assert w.stats["stuck_particles"] == stuck.sum()
    normals = wet.contact_normals
    # each normal of a particle touching the sphere points away from its centre
    p = wet.positions[contact]
    radial = p / np.linalg.norm(p, axis=1)[:, None]
    assert np.all(np.einsum("ij,ij->i", normals[contact], radial) > 0.9)
    # particles in contact keep radius + thickness from the centre, within 1 mm
    r = np.linalg.norm(p, axis=1)
    assert np.all(np.abs(r - 0.305) < 1e-3), (r.min(), r.max())
    _, dry = _drop_on_sphere(0.0)
    assert dry.in_contact.sum() > 0 and dry.stuck.sum() == 0
    assert w.count_intersections() == {"cloth_cloth": 0, "cloth_collider": 0}
    w.close()


@pytest.mark.parametrize("collide", [True, False])
def test_two_cloths_collide_unless_told_not_to(collide):
    # a cloth dropped onto another lying on a box rests on it when both
    # collide with cloths (the default), and falls through it when not
    with World() as w:
        w.add_box((0.0, 0.0, -0.1), (1.0, 1.0, 0.1))
        lower = w.add_grid_cloth(10, 10, size=(0.6, 0.6), center=(0.0, 0.0, 0.01))
        upper = w.add_grid_cloth(10, 10, size=(0.5, 0.5), center=(0.0, 0.0, 0.08),
                                 collide_with_cloths=collide)
        worst = 0
        for _ in range(12):
            w.advance(1 / 24)
            worst = max(worst, w.count_intersections()["cloth_cloth"])
        gap = upper.positions[:, 2].mean() - lower.positions[:, 2].mean()
        if collide:
            assert worst == 0 and 0.004 < gap < 0.02, (worst, gap)
        else:
            assert worst > 0 and abs(gap) < 0.004, (worst, gap)


# ---------------------------------------------------------------------------
# colliders


@pytest.mark.parametrize("kind", ["sphere", "box", "capsule", "convex", "mesh"])
def test_each_collider_holds_the_cloth(kind):
    # A 0.6 m cloth falls 0.15 m onto a shape whose top is at z = 0 and
    # whose extent covers the cloth's middle; the middle particle must rest
    # on it: at thickness (cloth 0.005 + collider 0.01) above the top.
    with World() as w:
        c = w.add_grid_cloth(9, 9, size=(0.6, 0.6), center=(0.0, 0.0, 0.15))
        t = 0.01
        if kind == "sphere":
            col = w.add_sphere((0.0, 0.0, -0.5), 0.5, thickness=t)
        elif kind == "box":
            col = w.add_box((0.0, 0.0, -0.1), (0.2, 0.2, 0.1), thickness=t)
        elif kind == "capsule":
            col = w.add_capsule((-0.4, 0.0, -0.1), (0.4, 0.0, -0.1), 0.1, thickness=t)
        elif kind == "convex":
            col = w.add_convex([[-0.2, -0.2, -0.2], [0.2, -0.2, -0.2], [0.2, 0.2, -0.2],
                                [-0.2, 0.2, -0.2], [-0.2, -0.2, 0.0], [0.2, -0.2, 0.0],
                                [0.2, 0.2, 0.0], [-0.2, 0.2, 0.0]], thickness=t)
        else:
            col = w.add_mesh_collider([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]],
                                      [[0, 1, 2], [0, 2, 3]], thickness=t)
        assert col.kind == kind and w.colliders == [col]
        for _ in range(24):
            w.advance(1 / 24)
        z = c.positions[40, 2]
        assert z == pytest.approx(0.015, abs=1e-3), (kind, z)
        assert c.in_contact[40]


def test_animated_mesh_collider_lifts_the_cloth():
    with World() as w:
        c = w.add_grid_cloth(6, 6, size=(0.5, 0.5), center=(0.0, 0.0, 0.01))
        plate = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], dtype=float)
        col = w.add_mesh_collider(plate, [[0, 1, 2], [0, 2, 3]])
        for f in range(1, 13):
            col.set_vertices(plate + [0.0, 0.0, 0.5 * f / 12])
            w.advance(1 / 24)
        np.testing.assert_array_equal(col.vertices, plate + [0.0, 0.0, 0.5])
        assert np.all(c.positions[:, 2] > 0.5)
        with pytest.raises(WetclothError, match=r"shape \(4, 3\)"):
            col.set_vertices(plate[:3])


def test_convex_set_transform_moves_the_shape():
    with World() as w:
        c = w.add_grid_cloth(6, 6, size=(0.5, 0.5), center=(0.0, 0.0, 0.0))
        box = w.add_box((0.0, 0.0, -0.1), (1.0, 1.0, 0.1))
        for f in range(1, 13):
            box.set_transform((0.0, 0.0, -0.1 + 0.5 * f / 12))
            w.advance(1 / 24)
        assert np.all(c.positions[:, 2] > 0.5)
        with pytest.raises(WetclothError) as e:
            box.set_transform((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 0.0))
        assert "rotation" in str(e.value) or "quaternion" in str(e.value)


def test_collider_errors_name_the_argument():
    with World() as w:
        with pytest.raises(WetclothError, match="radius"):
            w.add_sphere((0, 0, 0), -1.0)
        with pytest.raises(WetclothError) as e:
            w.add_mesh_collider([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 3]])
        assert "3" in str(e.value)
        with pytest.raises(WetclothError):
            w.add_convex([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])  # flat: no volume
        assert w.colliders == []


# ---------------------------------------------------------------------------
# stepping, errors, statistics


def test_advance_picks_substeps_from_the_stable_step():
    with World() as w:
        w.add_grid_cloth(10, 10)
        dt = w.stable_dt()
        assert 0 < dt < 1
        used = w.advance(1 / 24)
        assert used == math.ceil((1 / 24) / (0.9 * dt))
        assert w.advance(1 / 24, substeps=7) == 7
        assert w.stats["last_substeps"] == 7 and w.stats["steps"] == used + 7


def test_world_without_cloth_has_infinite_stable_step():
    with World() as w:
        assert w.stable_dt() == math.inf


def test_failed_step_keeps_the_world_usable():
    with World() as w:
        c = w.add_grid_cloth(10, 10)
        with pytest.raises(WetclothError) as e:
            w.step(20.0)  # out of range
        assert "dt" in str(e.value) and e.value.status_name == "WC_ERROR_INVALID_ARGUMENT"
        before = c.positions
        v = np.zeros((100, 3))
        v[99, 2] = 1e308  # overflows in a 10 s step (as tests/test_bad_input.c does)
        c.set_velocities(v)
        with pytest.raises(WetclothError) as e:
            w.step(10.0)
        assert e.value.status_name == "WC_ERROR_NON_FINITE", str(e.value)
        np.testing.assert_array_equal(c.positions, before)
        assert w.stats["steps"] == 0 and w.time == 0.0
        c.set_velocities(np.zeros((100, 3)))
        w.advance(1 / 24)
        assert np.all(np.isfinite(c.positions)) and np.all(c.positions[:, 2] < 0)
        assert w.stats["steps"] > 0


def test_stats_keys():
    with World(integrator="verlet") as w:
        w.add_grid_cloth(4, 4)
        w.advance(1 / 24)
        s = w.stats
        assert set(s) == {"steps", "time", "last_substeps", "collider_contacts",
                          "cloth_contacts", "failsafe_particles", "stuck_particles",
                          "step_seconds", "phase_seconds", "solver_iterations", "threads",
                          "halved_steps"}
        assert s["steps"] == s["last_substeps"] > 0 and s["step_seconds"] > 0
        assert s["solver_iterations"] == 0  # Verlet solves no linear system
        assert s["threads"] >= 1
        assert s["halved_steps"] == 0  # no collider: no step is looked at


def test_adapt_threads():
    """adapt_threads=False runs exactly `threads`; True (the default) may
    run fewer, with the same bits (test_thread_tuner checks the choice)."""
    out = []
    for adapt in (False, True):
        with World(threads=2, adapt_threads=adapt) as w:
            c = w.add_grid_cloth(70, 70)
            for _ in range(8):
                w.advance(1 / 240, substeps=1)
                assert w.stats["threads"] in ((2,) if not adapt else (1, 2))
            out.append(c.positions.tobytes())
    assert out[0] == out[1]
    with pytest.raises(WetclothError, match="adapt_threads must be True or False"):
        World(adapt_threads=2)


def test_solver_iterations_of_the_implicit_integrator():
    """The implicit integrator reports its conjugate-gradient iterations:
    at least one per substep of the advance, at most the solver's cap of
    1000 per substep."""
    with World(integrator="implicit") as w:
        w.add_grid_cloth(10, 10)
        w.advance(1 / 24, substeps=3)
        s = w.stats
        assert 3 <= s["solver_iterations"] <= 3000


def test_phase_seconds_split_the_step_time():
    """The library's per-phase times are >= 0, cover all substeps of the
    advance (forces and integration always run, so they are > 0), and add
    up to no more than the wall time the binding measured around the call."""
    with World() as w:
        w.add_grid_cloth(30, 30)
        w.add_sphere((0.0, 0.0, -0.3), 0.25)
        w.advance(1 / 24)
        s = w.stats
        phases = s["phase_seconds"]
        assert set(phases) == {"forces", "integrate", "collide", "wet"}
        assert all(v >= 0.0 for v in phases.values())
        assert phases["forces"] > 0 and phases["integrate"] > 0 and phases["collide"] > 0
        assert sum(phases.values()) <= s["step_seconds"]
        w.step(w.stable_dt())
        one = w.stats["phase_seconds"]
        assert sum(one.values()) < sum(phases.values())  # one step, not the whole advance


def test_threads_give_identical_results():
    out = []
    for threads in (1, 2):
        with World(threads=threads) as w:
            c = w.add_grid_cloth(12, 12, center=(0, 0, 0.4), wetness=1.0)
            w.add_sphere((0, 0, 0), 0.3)
            for _ in range(6):
                w.advance(1 / 24)
            out.append(c.positions)
    np.testing.assert_array_equal(out[0], out[1])


# ---------------------------------------------------------------------------
# arrays are copies that cannot dangle


def test_arrays_are_independent_copies():
    w = World()
    c = w.add_grid_cloth(6, 6, wetness=0.5)
    arrays = {"positions": c.positions, "velocities": c.velocities, "wetness": c.wetness,
              "stuck": c.stuck, "in_contact": c.in_contact, "triangles": c.triangles,
              "masses": c.masses, "contact_normals": c.contact_normals}
    for name, a in arrays.items():
        assert a.flags.owndata or (a.base is not None and a.base.flags.owndata), name
        assert a.flags.writeable, name
    snapshot = {k: v.copy() for k, v in arrays.items()}
    # writing to a returned array does not change the world
    arrays["positions"][:] = 99.0
    assert np.all(c.positions[:, 2] == 0.0)
    arrays["positions"][:] = snapshot["positions"]
    # stepping does not change arrays already returned
    w.advance(1 / 24)
    for k in arrays:
        np.testing.assert_array_equal(arrays[k], snapshot[k], err_msg=k)
    # nor does freeing the world, and reusing its memory
    w.close()
    del w
    gc.collect()
    churn = [World() for _ in range(3)]
    for x in churn:
        x.add_grid_cloth(6, 6, center=(5, 5, 5), wetness=1.0).set_positions(np.full((36, 3), 7.0))
    for k in arrays:
        np.testing.assert_array_equal(arrays[k], snapshot[k], err_msg=k)
        assert float(np.sum(arrays[k], dtype=float)) == float(np.sum(snapshot[k], dtype=float))
    for x in churn:
        x.close()


def test_closed_world_refuses_calls():
    w = World()
    c = w.add_grid_cloth(4, 4)
    w.close()
    assert w.closed
    for call in (lambda: c.positions, lambda: w.step(1e-3), lambda: w.stats,
                 lambda: c.pin([0]), lambda: w.add_sphere((0, 0, 0), 1.0)):
        with pytest.raises(WetclothError, match="closed"):
            call()
    w.close()  # twice is fine


def test_cloth_keeps_its_world_alive():
    c = World().add_grid_cloth(4, 4)
    gc.collect()
    c.world.advance(1 / 24)
    assert np.all(c.positions[:, 2] < 0)
