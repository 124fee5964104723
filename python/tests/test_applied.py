"""The binding of the applied forces: Cloth.set_air_velocity,
Cloth.set_external_forces and soft pins (Cloth.pin with a stiffness).
(The scene fields that use them are tested in test_scene.py.)

The physics is tested against closed forms in C (tests/test_applied.c);
these tests check that the binding hands the library the right arrays
(broadcast vectors, per-particle arrays, None to clear), that each closed
form still comes out through it, and that every bad argument is a
WetclothError naming the argument.
"""

import math

import numpy as np
import pytest

from wetcloth import Material, World, WetclothError

# no damping, no bending, soft links: the clean closed forms of
# tests/test_applied.c
PLAIN = dict(damping=0.0, bend=0.0, stretch=100.0)


def plain_world(gravity=(0.0, 0.0, 0.0), integrator="verlet", side=5, air_drag=0.0):
    w = World(gravity=gravity, threads=1, integrator=integrator, implicit_tolerance=0.0)
    c = w.add_grid_cloth(side, side, size=(0.5, 0.5), center=(0, 0, 1),
                         material=Material(air_drag=air_drag, **PLAIN))
    return w, c


# ---------------------------------------------------------------------------
# air velocity


def test_uniform_wind_follows_verlets_law():
    """v_n = u + (v_0 - u) (1 - x / 2) (1 - x)^(n-1), x = h / tau, tau =
    density / air_drag (tests/test_applied.c derives it): to rounding."""
    u = np.array([2.0, -1.0, 0.5])
    tau, h = 0.15 / 1.5, 5e-4
    w, c = plain_world(air_drag=1.5)
    with w:
        c.set_air_velocity(u)
        x = h / tau
        for n in range(1, 201):
            w.step(h)
        law = u - u * (1 - x / 2) * (1 - x) ** (200 - 1)
        np.testing.assert_allclose(c.velocities, np.tile(law, (c.particle_count, 1)), rtol=0,
                                   atol=1e-9)


def test_a_vector_is_every_particles_and_none_clears():
    u = np.array([1.0, 0.5, -0.2])
    runs = []
    for form in ("vector", "array", "cleared", "still"):
        w, c = plain_world(gravity=(0, 0, -9.81), air_drag=0.8)
        with w:
            if form == "vector":
                c.set_air_velocity(u)
            elif form == "array":
                c.set_air_velocity(np.tile(u, (c.particle_count, 1)))
            elif form == "cleared":
                c.set_air_velocity(u)
                c.set_air_velocity(None)
            for _ in range(30):
                w.step(1e-3)
            runs.append(c.positions)
    np.testing.assert_array_equal(runs[0], runs[1])
    np.testing.assert_array_equal(runs[2], runs[3])
    assert not np.array_equal(runs[0], runs[3])


def test_air_velocity_without_drag_has_no_effect():
    runs = []
    for wind in (True, False):
        w, c = plain_world(gravity=(0, 0, -9.81), air_drag=0.0)
        with w:
            if wind:
                c.set_air_velocity([30.0, 0.0, 0.0])
            for _ in range(30):
                w.step(1e-3)
            runs.append(c.positions)
    np.testing.assert_array_equal(runs[0], runs[1])


def test_a_wind_field_varies_per_particle():
    w, c = plain_world(air_drag=1.5)
    with w:
        u = np.zeros((c.particle_count, 3))
        u[:, 0] = np.linspace(0.0, 1.0, c.particle_count)
        c.set_air_velocity(u)
        w.step(1e-3)
        v = c.velocities
        # the first step from rest: v = a h / 2 with a = u / tau
        np.testing.assert_allclose(v[:, 0], u[:, 0] / 0.1 * 1e-3 / 2, rtol=1e-9, atol=1e-15)


@pytest.mark.parametrize("value,needle", [
    ([1.0, 2.0], "velocity must be 3 numbers (one vector for every particle) or an array of "
                 "shape (25, 3), found shape (2,)"),
    (np.zeros((24, 3)), "found shape (24, 3)"),
    ("east", "velocity must be 3 numbers or an array of shape (25, 3)"),
    ([0.0, math.nan, 0.0], "velocity: wc_cloth_set_air_velocity: velocity_xyz[1] (y of particle "
                           "0) must be finite but is nan"),
    ([2e4, 0.0, 0.0], "the air velocity of particle 0 is (20000, 0, 0)"),
])
def test_bad_air_velocity_is_named(value, needle):
    w, c = plain_world(air_drag=1.0)
    with w:
        before = c.positions
        with pytest.raises(WetclothError) as e:
            c.set_air_velocity(value)
        assert needle in str(e.value), str(e.value)
        assert str(e.value).startswith("set_air_velocity: velocity")
        w.step(1e-3)  # still still air: no drift sideways
        np.testing.assert_array_equal(c.positions[:, :2], before[:, :2])


# ---------------------------------------------------------------------------
# external forces


@pytest.mark.parametrize("integrator", ["verlet", "xpbd", "implicit"])
def test_external_force_density_accelerates_by_p_over_density(integrator):
    p = np.array([3.0, -2.0, 5.0])
    for side in (5, 9):
        w, c = plain_world(integrator=integrator, side=side)
        with w:
            c.set_external_forces(p)
            x0 = c.positions
            steps, h = 400, 5e-4
            for _ in range(steps):
                w.step(h)
            t = steps * h
            expect = x0 + 0.5 * p / 0.15 * t * t
            np.testing.assert_allclose(c.positions, expect, rtol=0, atol=1e-8)


def test_hard_pins_ignore_the_external_force_and_none_clears_it():
    w, c = plain_world()
    with w:
        c.pin([0])
        start = c.positions[0]
        c.set_external_forces(np.tile([0.0, 0.0, 50.0], (c.particle_count, 1)))
        for _ in range(20):
            w.step(1e-3)
        np.testing.assert_array_equal(c.positions[0], start)
        assert c.positions[12, 2] > start[2] + 1e-3
        c.set_external_forces(None)
        v = c.velocities[12].copy()
        w.step(1e-3)
        assert c.velocities[12, 2] <= v[2] + 1e-9  # no more push (the links pull back)


@pytest.mark.parametrize("value,needle", [
    (np.zeros((3, 3)), "force_per_area must be 3 numbers (one vector for every particle)"),
    ([0.0, 0.0, -2e6], "the external force density of particle 0 is (0, 0, -2e+06)"),
    ([math.inf, 0.0, 0.0], "force_per_area_xyz[0] (x of particle 0) must be finite but is inf"),
])
def test_bad_external_forces_are_named(value, needle):
    w, c = plain_world()
    with w:
        with pytest.raises(WetclothError) as e:
            c.set_external_forces(value)
        assert needle in str(e.value), str(e.value)
        assert str(e.value).startswith("set_external_forces: force_per_area")
        w.step(1e-3)
        assert np.all(c.velocities == 0.0)


# ---------------------------------------------------------------------------
# soft pins


def test_soft_pins_swing_about_their_targets():
    """Every particle soft-pinned with s, under g: the cloth drops by
    (g / s) (1 - cos(Omega t)), Verlet's Omega = (2 / h) asin(sqrt(s) h / 2)."""
    s, h, g = 100.0, 5e-4, 9.81
    w, c = plain_world(gravity=(0, 0, -g))
    with w:
        x0 = c.positions
        c.pin(np.arange(c.particle_count), stiffness=s)
        assert c.pin_count == c.particle_count
        omega = 2 / h * math.asin(math.sqrt(s) * h / 2)
        for n in range(1, 301):
            w.step(h)
        drop = x0[:, 2] - c.positions[:, 2]
        np.testing.assert_allclose(drop, g / s * (1 - math.cos(omega * 300 * h)), rtol=0,
                                   atol=1e-12)


def test_soft_pin_stiffness_per_index_and_the_shared_pin_list():
    w, c = plain_world(gravity=(0, 0, -9.81))
    with w:
        dt = c.stable_dt()
        c.pin([0])                        # hard
        c.pin([4, 20], stiffness=[1e6, 50.0])
        c.pin([24], stiffness=2e6)
        assert c.pin_count == 4
        assert c.stable_dt() < dt and c.stable_dt() <= 2 / math.sqrt(2e6)
        targets = c.positions[[0, 4, 20, 24]] + [0.0, 0.0, 0.1]
        c.set_pin_targets(targets)
        with pytest.raises(WetclothError, match=r"\(4, 3\)"):
            c.set_pin_targets(targets[:3])
        w.advance(1 / 24)
        # the hard pin is on its target; the soft ones only pulled toward theirs
        np.testing.assert_allclose(c.positions[0], targets[0], atol=1e-12)
        assert not np.allclose(c.positions[20], targets[2], atol=1e-3)
        c.unpin_all()
        assert c.pin_count == 0 and c.stable_dt() == dt


@pytest.mark.parametrize("indices,stiffness,needle", [
    ([1, 2], [10.0], "stiffness must have shape (2), found shape (1,)"),
    ([1, 2], [10.0, -1.0], "pin: wc_cloth_pin_soft: stiffness[1] (for particle 2) must be in "
                           "(0, 1e+08] 1/s^2 but is -1"),
    ([1], 1e9, "stiffness[0] (for particle 1) must be in (0, 1e+08] 1/s^2 but is 1e+09"),
    ([1], math.nan, "but is nan"),
    ([1], True, "stiffness must be a number, found True"),
    ([1], "stiff", "stiffness must be a number"),
    ([3, 3], 5.0, "indices[1] = 3 is repeated in the list"),
    ([0, 7], 5.0, "indices[0] = 0 is already pinned"),
    ([9], 5.0, "indices[0] = 9 is already pinned (soft pin 1)"),
    ([25], 5.0, "indices[0] is 25, but the cloth has 25 particles"),
])
def test_bad_soft_pins_are_named(indices, stiffness, needle):
    w, c = plain_world(gravity=(0, 0, -9.81))
    with w:
        c.pin([0])
        c.pin([9], stiffness=5.0)
        dt = c.stable_dt()
        with pytest.raises(WetclothError) as e:
            c.pin(indices, stiffness=stiffness)
        assert needle in str(e.value), str(e.value)
        assert c.pin_count == 2 and c.stable_dt() == dt
        w.step(1e-3)


def test_a_hard_pin_cannot_take_a_soft_pinned_particle():
    w, c = plain_world()
    with w:
        c.pin([3], stiffness=10.0)
        with pytest.raises(WetclothError, match=r"indices\[0\] = 3 is already pinned \(soft pin 0\)"):
            c.pin([3])
