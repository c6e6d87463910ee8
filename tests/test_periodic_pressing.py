"""A stress-controlled wall in a box periodic across it takes the box's period for its extent (Luding 2005, eq. 1:
p L pushes it in): free of particles it accelerates at p Lx Ly / m exactly, and its load is a stress (Pa)."""

import pytest

from dem import run
from dem.scene import parse_scene

L = 2e-3  # m, the period along x and y
R = 1e-4


def doc(pressure=1e3, mass=1e-3, periodic=True):
    d = {"scene": {"physics": ["mechanical"]}, "material": {"density": 8960.0},
         "contact": {"law": "hertz_mindlin", "youngs_modulus": 1e8, "poisson_ratio": 0.3, "restitution": 0.5,
                     "tangential_damping": 0.0, "mu": 0.3, "mu_wall": 0.3},
         "particles": {"position": [[0.5 * L, 0.5 * L, 2 * R], [0.25 * L, 0.75 * L, 2 * R]], "radius": [R, R],
                       "temperature": [20.0, 20.0]},
         "walls": [{"name": "floor", "point": [0, 0, 0], "normal": [0, 0, 1]},
                   {"name": "piston", "point": [0, 0, 4e-3], "normal": [0, 0, -1], "motion": "stress",
                    "pressure": pressure, "mass": mass, "damping": 0.0}],
         "solver": {"mode": "transient", "t_end": 1e-4}}
    if periodic:
        d["periodic"] = {"lengths": [L, L, 1e-2], "axes": ["x", "y"]}
    return d


@pytest.mark.slow  # the Hertz-Mindlin law's force loop (20 s for numba to compile in a fresh clone)
def test_a_stress_wall_in_a_periodic_box_is_pushed_by_p_times_its_area():
    res = run(parse_scene(doc(pressure=1e3, mass=1e-3)))
    mech = res.engine.mechanics
    a = 1e3 * L * L / 1e-3  # m/s^2: p A / m, no particle touches it
    t = mech.t
    travelled = 4e-3 - (-mech.w.q[1])  # inward
    assert travelled == pytest.approx(0.5 * a * t * t, rel=1e-9)
    assert res.engine.wall_load_unit() == "Pa"
    assert res.summary["wall_piston"] == pytest.approx(0.0, abs=1e-30)  # no load yet


def test_without_the_period_it_is_refused():
    with pytest.raises(ValueError, match=r"walls\.piston: a stress-controlled wall needs one wall facing each way "
                                         r"along the x axis, or a periodic x axis"):
        run(parse_scene(doc(periodic=False)))
