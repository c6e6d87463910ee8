"""The exposed surface of particles (convection and radiation act through it) and the maximum principle."""

import numpy as np
import pytest

from dem import load_scene, run
from dem.geometry.exposure import exposed_fraction, fibonacci_directions
from dem.geometry.generators import lattice
from dem.scene import parse_scene


def test_directions_cover_the_sphere_evenly():
    d = fibonacci_directions(96)
    assert np.allclose(np.linalg.norm(d, axis=1), 1.0)
    assert np.allclose(d.mean(axis=0), 0.0, atol=0.02)


def test_isolated_interior_face_edge_corner():
    assert exposed_fraction(np.zeros((1, 3)), np.ones(1))[0] == 1.0
    layout = lattice([5, 5, 5], 1e-3, 0.1)
    f = exposed_fraction(layout.position, layout.radius)

    def at(i, j, k):
        return f[(i * 5 + j) * 5 + k]

    assert at(2, 2, 2) == 0.0  # interior: every normal ray meets a particle
    assert 0.0 < at(2, 2, 0) < at(2, 0, 0) < at(0, 0, 0) < 1.0  # face < edge < corner
    # a face particle sees out through the cap its four face neighbours (1.9 r away) leave open: cos(theta) > 1/1.9
    assert at(2, 2, 0) > (1.0 - 1.0 / 1.9) / 2.0


def test_two_touching_spheres_hide_their_neck():
    x = np.array([[0.0, 0.0, 0.0], [1.9, 0.0, 0.0]])
    f = exposed_fraction(x, np.ones(2), directions=2000)
    # a normal at angle theta from the axis meets the partner (radius 1, 1.9 away) when 1.9 sin(theta) < 1: the
    # covered cap has half-angle asin(1/1.9), area fraction (1 - cos)/2
    exact = 1.0 - (1.0 - np.cos(np.arcsin(1.0 / 1.9))) / 2.0
    assert np.allclose(f, exact, atol=2e-3)


def test_cooling_block_interior_stays_warmer_than_its_surface():
    res = run(load_scene("cooling"))
    T = np.array(res.summary["T"]).reshape(5, 5, 5)
    assert T[2, 2, 2] > T[2, 2, 0] > T[0, 0, 0]
    assert res.summary["T_max"] > res.summary["T_min"]
    assert res.summary["energy_error"] < 1e-10


def test_whole_surface_is_an_explicit_opt_in():
    base = {"material": {"conductivity": 394.0, "density": 8960.0, "specific_heat": 385.0},
            "generator": {"kind": "lattice", "shape": [3, 3, 3], "radius": 1e-3, "overlap": 0.1,
                          "temperature": 100.0},
            "convection": {"h": 50.0, "T_inf": 20.0},
            "solver": {"mode": "transient", "integrator": "implicit", "dt": 1.0, "t_end": 5.0}}
    exposed = run(parse_scene(base)).summary
    base["convection"]["area_fraction"] = 1.0
    whole = run(parse_scene(base)).summary
    assert whole["T_mean"] < exposed["T_mean"]  # more surface, more cooling
    with pytest.raises(ValueError, match="area_fraction"):
        base["convection"]["area_fraction"] = "visible"
        parse_scene(base)


def test_implicit_steps_keep_the_maximum_principle():
    scene = load_scene("cooling")
    res = run(scene).summary
    assert res["max_principle_violation"] is not None and res["max_principle_violation"] <= 1e-9 * 800
