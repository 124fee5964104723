"""Integrator choice (issue 7) through the binding and scene files."""
import numpy as np
import pytest

import wetcloth
from wetcloth import scene


@pytest.mark.parametrize("name", ["verlet", "xpbd", "implicit"])
def test_world_integrator_steps_a_frame(name):
    w = wetcloth.World(integrator=name)
    c = w.add_grid_cloth(8, 8)
    w.advance(1.0 / 24)
    # a free cloth falls; all three agree with g t^2 / 2 to within a
    # millimetre after one frame (backward Euler lags by g t dt / 2)
    assert abs(c.positions[:, 2].mean() + 0.5 * 9.81 / 24 ** 2) < 1e-3
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
    assert scene.from_dict(base, "test.json", ".").integrator == "verlet"
    s = scene.from_dict(dict(base, integrator="implicit"), "test.json", ".")
    assert s.integrator == "implicit"
    with pytest.raises(scene.SceneError, match=r"integrator: expected one of"):
        scene.from_dict(dict(base, integrator="euler"), "test.json", ".")
