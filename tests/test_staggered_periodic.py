"""Moving particles in a periodic box, the staggered engine (Zohdi 2014): contacts across the faces by the minimum
image, particles wrapped back into the box, momentum conserved; a pair across a face the same as in the middle of
the box -- its forces, its heat and the current through it; a resumed run the uninterrupted one, bit for bit; the box
kept by the run's state; and the inputs that cannot work refused in one line."""

import copy
import io

import numpy as np
import pytest

from dem import parse_scene, run
from dem.engines.staggered.engine import StaggeredEngine

# The Zohdi law's force loop and the staggered engine's iteration take numba 20 s to compile in a fresh clone: the
# module runs with the slow tests.
pytestmark = pytest.mark.slow

R = 0.075  # m
L = 1.0  # m, the period along the periodic axes
ZOHDI = {"law": "zohdi", "K_p": 1.0e7, "p_p": 2.0, "K_p_lim": 1.0e6, "K_w": 1.0e7, "p_w": 2.0, "K_w_lim": 1.0e6,
         "theta_star": 500.0, "K_b": 1.0e6, "p_b": 2.0, "E_star": 0.3, "mu_d": 0.1, "c_env": 0.0, "v_slip": 0.1}
MATERIAL = {"density": 2000.0, "conductivity": 100.0, "specific_heat": 3.0, "electrical_conductivity": 0.1}
GAS = {"scene": {"physics": ["mechanical", "thermal"]}, "material": MATERIAL, "contact": ZOHDI,
       "generator": {"kind": "box", "n": 60, "radius": R, "radius_spread": 0.1, "seed": 3, "speed": 2.0,
                     "box": [[0.0, 0.0, 0.0], [L, L, L]], "temperature": 300.0},
       "conductance": {"law": "zohdi"}, "periodic": {"lengths": [L, L, L]},
       "solver": {"mode": "transient", "t_end": 0.4, "dt": 0.005, "dt_max": 0.005}}


def gas(**solver) -> dict:
    doc = copy.deepcopy(GAS)
    doc["solver"].update(solver)
    return doc


def hot_gas():
    """The gas with every other particle at 600 K: heat flows through the contacts (and across the faces)."""
    scene = parse_scene(gas())
    scene.particles.temperature[::2] = 600.0
    return scene


def test_momentum_and_heat_are_conserved_through_contacts_across_the_faces():
    engine = StaggeredEngine(hot_gas())
    s = engine.mechanics.state
    p0 = s.momentum().copy()
    scale = float(np.sum(s.mass * np.linalg.norm(s.v, axis=1)))
    x0 = s.x.copy()
    heat0 = float(engine.thermal.C @ engine.thermal.T)
    crossed = []

    def observe():
        i, j = engine.mechanics.contacts()[:2]
        crossed.append(int(np.sum(np.any(np.abs(s.x[i] - s.x[j]) > 0.5 * L, axis=1))))

    engine.run(observe=observe)
    assert engine.mechanics.rebuilds > 0 and np.max(np.abs(s.x - x0)) > 0.5 * L  # particles crossed the faces
    assert sum(crossed) > 0  # contacts across a face were seen
    assert np.all((s.x >= -L) & (s.x < 2 * L))  # wrapped back (within one rebuild's travel)
    assert np.max(np.abs(s.momentum() - p0)) <= 1e-13 * scale
    T = engine.thermal.T
    assert T[::2].mean() < 595.0 and T[1::2].mean() > 305.0  # heat flowed from the hot half to the cold one
    assert float(engine.thermal.C @ T) == pytest.approx(heat0, rel=1e-13)  # no wall: no heat in or out
    assert engine.thermal.energy_error() < 1e-12


def pair(middle: bool, v: float = 0.0) -> dict:
    """Two spheres touching along x, the first touching a grounded bottom wall at z = 0 and the second a top wall at
    1 kV (walls at 1000 K and 300 K; the box periodic along x and y): in the middle of the box, or with the pair
    across the x faces. The first approaches the second at ``v``."""
    x_a = 0.5 if middle else 0.03
    x_b = x_a - 0.1 if middle else L + x_a - 0.1  # centre distance sqrt(0.1^2 + 0.1^2) = 0.141 m < 2R
    walls = [{"name": "bottom", "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0], "temperature": 1000.0,
              "potential": 0.0},
             {"name": "top", "point": [0.0, 0.0, 0.24], "normal": [0.0, 0.0, -1.0], "temperature": 300.0,
              "potential": 1000.0}]
    return {"scene": {"physics": ["mechanical", "thermal", "electrical"]}, "material": MATERIAL, "contact": ZOHDI,
            "particles": {"position": [[x_a, 0.5, 0.07], [x_b, 0.5, 0.17]], "radius": [R, R],
                          "temperature": [300.0, 300.0], "velocity": [[-v, 0.0, 0.0], [0.0, 0.0, 0.0]]},
            "walls": walls, "conductance": {"law": "zohdi"}, "electrical": {"scheme": "kirchhoff", "absorption": 0.5},
            "periodic": {"lengths": [L, L, L], "axes": ["x", "y"]},
            "solver": {"mode": "transient", "t_end": 0.1, "dt": 0.005, "dt_max": 0.005}}


@pytest.mark.parametrize("v", [0.0, 0.5], ids=["at-rest", "approaching"])
def test_a_pair_across_a_face_is_the_pair_in_the_middle(v):
    a, b = StaggeredEngine(parse_scene(pair(False, v))), StaggeredEngine(parse_scene(pair(True, v)))
    np.testing.assert_allclose(a.mechanics.f, b.mechanics.f, rtol=1e-9, atol=1e-9)  # the forces at the start
    assert a.current.joule_heat == pytest.approx(b.current.joule_heat, rel=1e-9)
    assert a.summary()["contacts"] == b.summary()["contacts"] == 1
    assert np.linalg.norm(b.mechanics.f[1]) > 1.0 and b.current.joule_heat > 0.0  # they touch
    for engine in (a, b):  # the contact is drawn as long as it is, to the partner's image across the face
        points, lines, _ = engine.links()
        assert np.linalg.norm(points[lines[0, 1]] - points[lines[0, 0]]) == pytest.approx(0.1 * 2**0.5, rel=1e-12)
    a.run()
    b.run()
    sa, sb = a.mechanics.state, b.mechanics.state
    np.testing.assert_allclose(sa.v, sb.v, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(sa.T, sb.T, rtol=1e-9)
    shifted = a.mechanics.periodic_box.minimum_image(sa.x - sb.x - [0.03 - 0.5, 0.0, 0.0])
    np.testing.assert_allclose(shifted, 0.0, atol=1e-12)  # the same motion, a period apart
    for key in ("joule_energy", "electrode_energy"):
        assert getattr(a.current, key) == pytest.approx(getattr(b.current, key), rel=1e-9)
    assert a.thermal.heat_in["boundaries"] == pytest.approx(b.thermal.heat_in["boundaries"], rel=1e-9)
    assert a.summary()["contacts"] == b.summary()["contacts"]
    assert a.steps == b.steps and a.restarts == b.restarts
    assert np.all(sb.T > 300.0)  # heat from the hot wall and the current
    assert not np.allclose(sb.v, 0.0)  # the contacts pushed them



@pytest.mark.parametrize("neck", ["newton", "union"])
def test_the_shared_body_law_across_a_face_is_the_law_in_the_middle(neck):
    """The ``shared-body`` law turns each neck by the angles between the necks of its particle (here the pair's and
    the wall's): the heat and the current must see the bond across the face as the minimum image, not the raw
    difference of the centres, and the current's law needs its electrodes' normals."""
    docs = [pair(middle) for middle in (False, True)]
    for doc in docs:
        doc["conductance"] = {"law": "shared-body", "neck": neck}
    a, b = (StaggeredEngine(parse_scene(doc)) for doc in docs)
    a.run()
    b.run()
    np.testing.assert_allclose(a.mechanics.state.T, b.mechanics.state.T, rtol=1e-9)
    assert a.current.joule_energy == pytest.approx(b.current.joule_energy, rel=1e-9)
    assert a.current.joule_energy > 0.0 and np.all(b.mechanics.state.T > 300.0)

def saved(checkpoint: dict) -> dict:
    """A checkpoint as the driver writes and reads it (``np.savez``, ``np.load``)."""
    buffer = io.BytesIO()
    np.savez(buffer, **checkpoint)
    buffer.seek(0)
    with np.load(buffer, allow_pickle=False) as f:
        return {k: f[k] for k in f.files}


def test_a_resumed_run_ends_as_the_uninterrupted_one_bit_for_bit():
    whole = StaggeredEngine(hot_gas())
    whole.run()
    part = StaggeredEngine(hot_gas())
    box = part.mechanics.periodic_box
    taken = []

    def checkpoint(make, final):  # the first step after which a particle is outside the box, not yet wrapped
        x = part.mechanics.state.x
        if not taken and part.mechanics.rebuilds and np.any((x < box.origin) | (x >= box.origin + box.lengths)):
            taken.append(saved(make()))
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        part.run(checkpoint=checkpoint)
    assert taken and 0.0 < float(taken[0]["t"]) < 0.4
    resumed = StaggeredEngine(hot_gas(), restart=taken[0])
    resumed.run()
    for name in ("x", "v", "T"):
        assert np.array_equal(getattr(resumed.mechanics.state, name), getattr(whole.mechanics.state, name)), name
    assert resumed.summary() == whole.summary()


def test_the_state_keeps_the_box_and_a_run_from_it_has_it(tmp_path):
    doc = gas(t_end=0.02)
    first = run(parse_scene(doc), out=tmp_path / "first")
    state = tmp_path / "first" / "state.npz"
    assert np.array_equal(np.load(state)["box_lengths"], [L, L, L])
    follow = {k: v for k, v in gas(t_end=0.04).items() if k not in ("generator", "periodic")}
    follow["start"] = {"state": str(state)}
    scene = parse_scene(follow)
    assert np.array_equal(scene.box.lengths, [L, L, L]) and scene.box.periodic == (True, True, True)
    assert np.array_equal(scene.particles.position, first.engine.mechanics.state.x)
    then = run(scene)
    assert then.engine.mechanics.periodic_box is scene.box and then.summary["t"] == pytest.approx(0.04)
    thermal = {k: v for k, v in MATERIAL.items() if k != "electrical_conductivity"}
    static = parse_scene({"scene": {"physics": ["thermal"]}, "material": thermal, "start": {"state": str(state)},
                          "conductance": {"law": "zohdi"}})
    assert static.engine == "static" and static.box.periodic == (True, True, True)  # bonds across the faces too


def test_what_cannot_work_is_refused_in_one_line():
    doc = gas()
    doc["walls"] = [{"name": "floor", "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]}]
    with pytest.raises(ValueError, match=r"walls.floor: .* periodic axis z"):
        parse_scene(doc)
    doc["periodic"]["axes"] = ["x", "y"]
    assert parse_scene(doc).box.periodic == (True, True, False)  # a floor under a box periodic along x and y
    doc = gas()
    doc["periodic"]["drop"] = [0.0, 0.0, 1.0]
    with pytest.raises(ValueError, match=r"\[periodic\] drop: not read by the staggered engine"):
        parse_scene(doc)


def test_the_solid_fraction_counts_the_periods():
    """Between a floor and a ceiling along x, periodic along y and z: the box is the walls' gap times the periods."""
    position = [[0.2, 0.1, 0.1], [0.2, 0.5, 0.9], [0.3, 0.8, 0.4]]
    doc = {"scene": {"physics": ["mechanical"]}, "material": MATERIAL, "contact": ZOHDI,
           "particles": {"position": position, "radius": [R] * 3, "temperature": [300.0] * 3},
           "walls": [{"name": "floor", "point": [0.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0]},
                     {"name": "ceiling", "point": [0.5, 0.0, 0.0], "normal": [-1.0, 0.0, 0.0]}],
           "periodic": {"lengths": [L, 0.8, 1.2], "axes": ["y", "z"]},
           "solver": {"mode": "transient", "t_end": 0.01, "dt": 0.005, "dt_max": 0.005}}
    engine = StaggeredEngine(parse_scene(doc))
    solid = 3 * 4.0 / 3.0 * np.pi * R**3
    assert engine.bed()["volume_fraction"] == pytest.approx(solid / (0.5 * 0.8 * 1.2), rel=1e-14)
