"""Integrator choice through the binding and scene files."""
import numpy as np
import pytest

import wetcloth
from wetcloth import scene


@pytest.mark.parametrize("name", ["verlet", "xpbd", "implicit"])
def test_world_integrator_steps_a_frame(name):
    w = wetcloth.World(integrator=name)
    c = w.add_grid_cloth(8, 8, material=wetcloth.Material(air_drag=0.0, damping=0.0))
    z0 = c.positions[:, 2].copy()
    w.advance(1.0 / 24)
    # a free cloth without drag falls exactly g t^2 / 2 with all three
    # (measured: 1.6e-17, 0 and 8.7e-18 m off); 1e-12 m is rounding's room
    assert np.abs(c.positions[:, 2] - z0 + 0.5 * 9.81 / 24 ** 2).max() < 1e-12
    assert np.isfinite(c.positions).all()


def test_large_step_integrators_take_fewer_substeps():
    used = {}
    for name in ["verlet", "xpbd", "implicit"]:
        w = wetcloth.World(integrator=name)
        w.add_grid_cloth(20, 20)
        used[name] = w.advance(1.0 / 24)
    assert used["xpbd"] < used["verlet"] and used["implicit"] < used["verlet"]


def test_unknown_integrator_names_the_field():
    with pytest.raises(wetcloth.WetclothError, match="integrator must be one of"):
        wetcloth.World(integrator="rk4")


def test_scene_integrator_field():
    base = {"cloths": [{"grid": {"nu": 3, "nv": 3}}]}
    assert scene.from_dict(base, "test.json", ".").integrator == "implicit"
    s = scene.from_dict(dict(base, integrator="implicit"), "test.json", ".")
    assert s.integrator == "implicit"
    with pytest.raises(scene.SceneError, match=r"integrator: expected one of"):
        scene.from_dict(dict(base, integrator="euler"), "test.json", ".")


def test_implicit_tolerance_through_the_binding_and_scene_files():
    """The tolerance reaches the library: solved to round-off the implicit
    integrator takes more conjugate-gradient iterations for the same frame
    than at the default; a value the library refuses is an error naming
    the field, from World and from a scene file."""
    def iterations(**kwargs):
        with wetcloth.World(integrator="implicit", **kwargs) as w:
            c = w.add_grid_cloth(16, 16)
            c.pin([0, 15])
            w.advance(1.0 / 24, 5)
            w.advance(1.0 / 24, 5)
            return w.stats["solver_iterations"]
    exact, default = iterations(implicit_tolerance=0.0), iterations()
    assert exact > default > 0
    assert wetcloth.World.DEFAULT_IMPLICIT_TOLERANCE == 8.0
    assert iterations(implicit_tolerance=wetcloth.World.DEFAULT_IMPLICIT_TOLERANCE) == default
    with pytest.raises(wetcloth.WetclothError, match=r"implicit_tolerance must be in \[0, 1000\]"):
        wetcloth.World(integrator="implicit", implicit_tolerance=-1.0)
    with pytest.raises(wetcloth.WetclothError, match="implicit_tolerance must be a number"):
        wetcloth.World(implicit_tolerance="tight")
    base = {"cloths": [{"grid": {"nu": 3, "nv": 3}}], "integrator": "implicit"}
    assert scene.from_dict(base, "test.json", ".").implicit_tolerance is None
    s = scene.from_dict(dict(base, implicit_tolerance=0.1), "test.json", ".")
    assert s.implicit_tolerance == 0.1
    with pytest.raises(scene.SceneError, match=r"implicit_tolerance: must be at most 1000"):
        scene.from_dict(dict(base, implicit_tolerance=5000), "test.json", ".")
