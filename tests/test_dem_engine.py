"""The engine for moving particles against closed forms and conservation laws (Luding 2005 contact law)."""

import copy
import math

import numpy as np
import pytest

from dem.engines.verlet.engine import VerletEngine
from dem.engines.verlet.mechanics import MechanicsError
from dem.scene import parse_scene
from dem.driver import run

ELASTIC = {"law": "luding", "k1": 2.0e5, "k2": 2.0e5, "kc": 0.0, "kt_ratio": 0.2, "gamma_n": 0.0, "gamma_t": 0.0,
           "mu": 0.5, "mu_wall": 0.5, "T_melt": 120.0, "T_var": 10.0, "expansion": 0.0, "fluid_overlap": 0.2,
           "t0": 1e3, "brittle_sliding": False}
TABLE1 = {**ELASTIC, "k1": 1.0e5, "kc": 1.0e5, "gamma_n": 0.2, "gamma_t": 0.05, "mu_wall": 0.0,
          "expansion": 1e-4, "brittle_sliding": True}


def scene_doc(position, radius, velocity=None, contact=ELASTIC, t_end=1e-3, temperature=20.0, **extra):
    n = len(radius)
    doc = {"scene": {"physics": ["mechanical"]}, "material": {"density": 2000.0},
           "particles": {"position": [list(map(float, x)) for x in position], "radius": list(map(float, radius)),
                         "temperature": [temperature] * n},
           "contact": dict(contact), "solver": {"mode": "transient", "t_end": t_end}}
    if velocity is not None:
        doc["particles"]["velocity"] = [list(map(float, v)) for v in velocity]
    for key, value in extra.items():
        doc[key] = value
    return doc


def head_on(contact, speed=0.05, r=1e-3, dt_fraction=1.0):
    """Two equal spheres approaching head on, 0.02 r apart; t_end covers the collision; ``dt_fraction`` x t_MD."""
    doc = scene_doc([[0, 0, 0], [2.02 * r, 0, 0]], [r, r], [[speed, 0, 0], [-speed, 0, 0]], contact, t_end=3e-4)
    if dt_fraction != 1.0:
        doc["solver"]["dt"] = dt_fraction * VerletEngine(parse_scene(doc)).mechanics.dt
    return VerletEngine(parse_scene(doc))


def test_elastic_collision_conserves_energy_and_momentum():
    sim = head_on(ELASTIC)
    e0, p0 = sim.mechanics.state.kinetic_energy(), sim.mechanics.state.momentum()
    sim.run()
    s = sim.mechanics.state
    assert len(sim.mechanics.contacts()[0]) == 0, "the spheres must have separated"
    assert s.v[0, 0] < 0 < s.v[1, 0]
    assert abs(s.kinetic_energy() / e0 - 1) < 1e-4  # velocity Verlet: O((omega dt)^2) over the contact
    assert np.allclose(s.momentum(), p0, rtol=0, atol=1e-18)


def test_restitution_matches_the_damped_oscillator_of_eq_6():
    gamma = 0.5
    contact = {**ELASTIC, "gamma_n": gamma}
    sim = head_on(contact, dt_fraction=0.01)
    m = sim.mechanics.state.mass[0]
    m12 = m / 2
    eta = gamma / (2 * m12)
    omega = math.sqrt(ELASTIC["k2"] / m12 - eta**2)
    expected = math.exp(-eta * math.pi / omega)  # e = exp(-eta0 t_c), t_c = pi/omega (Luding 2005, eq. 6)
    v0 = 0.1
    sim.run()
    v = sim.mechanics.state.v
    # at t_MD/100 (at t_MD the contact's start and end within a step leave 1.3 %)
    assert abs((v[1, 0] - v[0, 0]) / v0 / expected - 1) < 5e-4


def test_momentum_and_angular_momentum_conserved_without_walls():
    rng = np.random.default_rng(3)
    n = 40
    x = rng.uniform(0, 6e-3, (n, 3))
    keep = [0]
    for k in range(1, n):  # no initial overlaps
        if all(np.linalg.norm(x[k] - x[m]) > 2.1e-3 for m in keep):
            keep.append(k)
    x = x[keep]
    r = rng.uniform(0.8e-3, 1.2e-3, len(x)) * 0.95
    v = rng.normal(0, 0.05, x.shape)
    doc = scene_doc(x, r, v, TABLE1, t_end=5e-3)
    doc["particles"]["angular_velocity"] = rng.normal(0, 50.0, x.shape).tolist()
    sim = VerletEngine(parse_scene(doc))
    s = sim.mechanics.state

    def angular(state):
        return np.sum(state.mass[:, None] * np.cross(state.x, state.v), axis=0) + np.sum(
            state.inertia[:, None] * state.w, axis=0)

    p0, l0 = s.momentum(), angular(s)
    sim.run()
    assert sim.mechanics.steps > 100 and sim.mechanics.rebuilds >= 0
    scale_p = np.sum(s.mass) * 0.05
    assert np.all(np.abs(s.momentum() - p0) < 1e-12 * scale_p)
    scale_l = np.sum(s.mass) * 0.05 * 6e-3
    assert np.all(np.abs(angular(s) - l0) < 1e-10 * scale_l)


@pytest.mark.parametrize("theta_deg", [10.0, 20.0])
def test_sphere_rolls_down_a_frictional_plane_at_five_sevenths_g_sin_theta(theta_deg):
    g, theta, r = 9.81, math.radians(theta_deg), 1e-3
    contact = {**ELASTIC, "gamma_n": 0.05, "gamma_t": 0.1, "mu_wall": 0.8}
    sag = 2000.0 * 4 / 3 * math.pi * r**3 * g * math.cos(theta) / ELASTIC["k2"]  # resting overlap m g cos/k
    doc = scene_doc([[0, 0, r - sag]], [r], contact=contact, t_end=0.02,
                    walls=[{"name": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]}],
                    gravity={"acceleration": [g * math.sin(theta), 0.0, -g * math.cos(theta)]})
    sim = VerletEngine(parse_scene(doc))
    sim.run()
    s = sim.mechanics.state
    t = sim.mechanics.t
    a = 2 * s.x[0, 0] / t**2  # from rest: x = a t^2 / 2
    assert abs(a / (5 / 7 * g * math.sin(theta)) - 1) < 0.01
    assert abs(s.w[0, 1] * r / s.v[0, 0] - 1) < 0.02  # rolling without slip: omega r = v


@pytest.mark.slow  # a 3 ms run rebuilding every few steps (~15 s); the engine's other tests here are the quick check
def test_rebuilds_carry_the_contact_history():
    """The same run with a skin that forces a rebuild every few steps and with one that never rebuilds."""
    rng = np.random.default_rng(1)
    x = np.array([[0, 0, 1e-3], [2e-3, 0, 1e-3], [1e-3, 0, (1 + math.sqrt(3)) * 1e-3]])  # a pile on a floor
    v = rng.normal(0, 1e-4, x.shape)
    out = []
    for skin in (2e-9, 5e-4):
        doc = scene_doc(x, [1e-3, 1e-3, 1e-3], v, TABLE1, t_end=3e-3, temperature=110.0,
                        walls=[{"name": "floor", "point": [0, 0, 0], "normal": [0, 0, 1]}],
                        gravity={"acceleration": [0.0, 0.0, -9.81]})
        doc["solver"]["skin"] = skin
        sim = VerletEngine(parse_scene(doc))
        sim.run()
        out.append((sim.mechanics.state.x.copy(), sim.mechanics.rebuilds))
        contacts = len(sim.mechanics.contacts()[0])
    assert out[0][1] > 50 and out[1][1] == 0 and contacts > 0
    assert np.abs(out[0][0] - x).max() > 1e-8  # the particles moved
    assert np.allclose(out[0][0], out[1][0], rtol=0, atol=1e-15)


@pytest.mark.parametrize("rate", [0.0, 4096.0])
def test_a_long_call_keeps_the_pairs_constants_only_while_the_radii_stay(rate):
    """One call of many steps against one call per step (each computes the pairs' constants afresh): the same run to
    the bit. At rate 0 the radii stay (the constants are read after the first step) and a listed pair closes after
    that step; at 4096 K/s (2^-10 K per 2^-22 s step: the same temperatures either way) they change every step."""
    x = [[0, 0, 0], [1.9999e-3, 0, 0], [4.0009e-3, 0, 0]]  # two touch, the third is 1 um off and coming
    v = [[0, 0, 0], [0, 0, 0], [-0.02, 0, 0]]
    out = []
    for calls in ("one", "each step"):
        doc = scene_doc(x, [1e-3] * 3, v, TABLE1, temperature=115.0)
        doc["solver"].update(dt=2.0**-22, skin=2e-4)
        mech = VerletEngine(parse_scene(doc)).mechanics
        assert len(mech.pi) == 2 and len(mech.contacts()[0]) == 1
        T0, T_rate = np.array([115.0]), np.array([rate])
        if calls == "one":
            mech.advance(400, T0, T_rate)
        else:
            for k in range(400):
                mech.advance(1, T0 + rate * k * mech.dt, T_rate)
        out.append((mech.state.x.copy(), mech.state.radius.copy(), mech.p_hist.copy(), mech.state.v[2, 0]))
    assert out[0][3] > -0.019  # the third particle hit the second
    assert (out[0][1][0] != 1e-3) == (rate > 0)  # the radii changed with the temperature
    for a, b in zip(out[0][:3], out[1][:3]):
        assert np.array_equal(a, b)


@pytest.mark.slow  # 2D disks: Luding's force loop for them (35-40 s for numba to compile in a fresh clone)
def test_stress_wall_balances_its_pressure():
    doc = scene_doc([[1e-3, 0, 1e-3], [3.1e-3, 0, 1e-3]], [1e-3, 1e-3], contact=TABLE1, t_end=0.05,
                    walls=[{"name": "left", "point": [0, 0, 0], "normal": [1, 0, 0]},
                           {"name": "bottom", "point": [0, 0, 0], "normal": [0, 0, 1]},
                           {"name": "top", "point": [0, 0, 2e-3], "normal": [0, 0, -1]},
                           {"name": "right", "point": [4.2e-3, 0, 0], "normal": [-1, 0, 0], "motion": "stress",
                            "pressure": 50.0, "mass": 0.01, "damping": 5.0}])
    doc["scene"].update(dimension=2, height=6e-3)
    sim = VerletEngine(parse_scene(doc))
    sim.run()
    assert abs(sim.wall_stress()["right"] / 50.0 - 1) < 1e-3


def test_escaped_particle_stops_the_run_naming_it():
    doc = scene_doc([[0, 0, 2e-3]], [1e-3], [[0, 0, -400.0]], contact=ELASTIC, t_end=1e-3,
                    walls=[{"name": "floor", "point": [0, 0, 0], "normal": [0, 0, 1]}])
    sim = VerletEngine(parse_scene(doc))
    with pytest.raises(MechanicsError, match="particle 0 .* left the box through wall 'floor'"):
        sim.run()


def test_non_finite_state_stops_the_run_naming_the_particle():
    sim = head_on(ELASTIC)
    sim.mechanics.state.v[1, 2] = np.nan
    with pytest.raises(MechanicsError, match="step 1 .*particle 1 has a non-finite"):
        sim.run()


@pytest.mark.parametrize("change, needle", [
    (lambda d: d["contact"].update(k1=3e5), "k1"),
    (lambda d: d["contact"].update(k2=-1.0), "k2"),
    (lambda d: d["material"].update(density=0.0), "density"),
    (lambda d: d["solver"].update(dt=1e-3), "stable step"),
    (lambda d: d["contact"].update(fluid_overlap=1.5), "fluid_overlap"),
    (lambda d: d["scene"].update(dimension=4), "dimension"),
    (lambda d: d["scene"].update(dimension=2), "height"),
    (lambda d: d.update(temperature={"time": [0.0, 1.0], "value": [20.0]}), "temperature"),
])
def test_bad_mechanical_input_is_refused_by_name(change, needle):
    doc = copy.deepcopy(scene_doc([[0, 0, 0], [2.1e-3, 0, 0]], [1e-3, 1e-3], contact=TABLE1))
    change(doc)
    with pytest.raises(ValueError, match=needle):
        parse_scene(doc)


def test_moving_keys_are_refused_in_a_static_scene():
    doc = {"material": {"conductivity": 1.0, "density": 1.0, "specific_heat": 1.0},
           "particles": {"position": [[0, 0, 0]], "radius": [1.0], "temperature": [0.0], "velocity": [[0, 0, 0]]}}
    with pytest.raises(ValueError, match=r"\[particles\] velocity: not read by the static engine \(read by verlet, "
                                         r"staggered"):
        parse_scene(doc)


@pytest.mark.parametrize("section, key, meant", [("solver", "skinn", "skin"), ("walls", "presure", "pressure")])
def test_an_unknown_key_of_a_moving_scene_lists_the_keys_it_allows(section, key, meant):
    doc = copy.deepcopy(scene_doc([[0, 0, 0], [2.1e-3, 0, 0]], [1e-3, 1e-3], contact=TABLE1))
    doc["walls"] = [{"name": "floor", "point": [0, 0, -1e-3], "normal": [0, 0, 1]}]
    (doc[section][0] if section == "walls" else doc[section])[key] = 1.0
    with pytest.raises(ValueError, match=rf"{key}: unknown key \(allowed: .*\b{meant}\b"):
        parse_scene(doc)


def test_cli_run_writes_outputs(tmp_path):
    doc = scene_doc([[0, 0, 0], [2.1e-3, 0, 0]], [1e-3, 1e-3], [[0.05, 0, 0], [-0.05, 0, 0]], TABLE1, t_end=1e-3)
    doc["output"] = {"interval": 1e-4, "vtu_interval": 5e-4}
    res = run(parse_scene(doc), out=tmp_path)
    assert res.summary["physics"] == ["mechanical"] and res.summary["static"] is False
    rows = (tmp_path / "timeseries.csv").read_text().splitlines()
    assert rows[0].startswith("t,step,kinetic_energy") and len(rows) == 1 + 11
    pvd = (tmp_path / "particles.pvd").read_text()
    listed = pvd.count("<DataSet")
    assert listed == len(list(tmp_path.glob("particles_*.vtu"))) == 3
    assert (tmp_path / "contacts.pvd").exists() and (tmp_path / "summary.json").exists()


@pytest.mark.slow
def test_a_stopped_run_keeps_its_outputs(tmp_path):
    import json
    import subprocess
    import sys

    doc_text = """
[scene]
physics = ["mechanical"]
[material]
density = 2000.0
[particles]
position = [[0.0, 0.0, 2e-3]]
radius = [1e-3]
temperature = [20.0]
velocity = [[0.0, 0.0, -400.0]]
[contact]
law = "luding"
k1 = 2e5
k2 = 2e5
kc = 0.0
kt_ratio = 0.2
gamma_n = 0.0
gamma_t = 0.0
mu = 0.5
mu_wall = 0.5
T_melt = 120.0
T_var = 10.0
expansion = 0.0
fluid_overlap = 0.2
t0 = 1e3
brittle_sliding = false
[[walls]]
name = "floor"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[solver]
mode = "transient"
t_end = 1e-3
[output]
interval = 1e-6
"""
    path = tmp_path / "escape.toml"
    path.write_text(doc_text)
    proc = subprocess.run([sys.executable, "-m", "dem", "run", str(path), "--out", str(tmp_path / "out"), "--quiet"],
                          capture_output=True, text=True, timeout=120)  # quiet: no bar on a slow (compiling) start
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1 and "left the box through wall 'floor'" in proc.stderr
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert "left the box" in summary["stopped"] and summary["steps"] > 0
    assert len((tmp_path / "out" / "timeseries.csv").read_text().splitlines()) > 2


@pytest.mark.slow  # 2D disks: Luding's force loop for them (35-40 s for numba to compile in a fresh clone)
def test_a_saved_state_goes_on_as_if_the_run_had_not_stopped(tmp_path):
    """Run 2 ms; run 1 ms, save, start a second scene from the state for 1 ms: bit-identical (pairs, walls,
    histories, stress wall and forces of the last step all carried)."""
    from dem.scene import state_file

    rng = np.random.default_rng(5)
    x = np.array([[1.0e-3, 0, 1.0e-3], [3.0e-3, 0, 1.0e-3], [2.0e-3, 0, (1 + math.sqrt(3)) * 1e-3]])
    walls = [{"name": "floor", "point": [0, 0, 0], "normal": [0, 0, 1]},
             {"name": "left", "point": [0, 0, 0], "normal": [1, 0, 0]},
             {"name": "right", "point": [4.2e-3, 0, 0], "normal": [-1, 0, 0], "motion": "stress",
              "pressure": 20.0, "mass": 1e-3, "damping": 0.5},
             {"name": "top", "point": [0, 0, 5e-3], "normal": [0, 0, -1]}]

    def doc(t_end):
        d = scene_doc(x, [1e-3] * 3, rng.normal(0, 0.01, x.shape), TABLE1, t_end=t_end, temperature=115.0,
                      walls=walls, gravity={"acceleration": [0.0, 0.0, -9.81]})
        d["scene"].update(dimension=2, height=6e-3)
        d["particles"]["velocity"] = [[0.001, 0, -0.002], [-0.001, 0, 0.0], [0.0, 0, 0.001]]
        d["solver"]["dt"] = 2e-7
        return d

    whole = VerletEngine(parse_scene(doc(2e-3)))
    whole.run()
    first = VerletEngine(parse_scene(doc(1e-3)))
    first.run()
    state_file.save(first.state(), tmp_path / "half.npz")
    second_doc = doc(2e-3)  # the clock goes on from the state's: the run ends where the whole one ends
    del second_doc["particles"]
    second_doc["start"] = {"state": str(tmp_path / "half.npz")}
    second = VerletEngine(parse_scene(second_doc))
    second.run()
    a, b = whole.mechanics, second.mechanics
    assert whole.steps == second.steps == first.steps + b.steps and whole.t == second.t
    assert np.array_equal(a.state.x, b.state.x) and np.array_equal(a.state.v, b.state.v)
    assert np.array_equal(a.w.q, b.w.q) and len(a.contacts()[0]) > 0


def test_phases_switch_the_friction_on():
    """A sphere on a tilted floor slides while mu_wall = 0 and rolls once a phase switches friction on."""
    g, theta, r = 9.81, math.radians(15.0), 1e-3
    contact = {**ELASTIC, "gamma_n": 0.05, "gamma_t": 0.1, "mu_wall": 0.0}
    sag = 2000.0 * 4 / 3 * math.pi * r**3 * g * math.cos(theta) / ELASTIC["k2"]
    doc = scene_doc([[0, 0, r - sag]], [r], contact=contact, t_end=0.02,
                    walls=[{"name": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]}],
                    gravity={"acceleration": [g * math.sin(theta), 0.0, -g * math.cos(theta)]})
    doc["phases"] = [{"start": 0.01, "mu_wall": 0.8}]
    sim = VerletEngine(parse_scene(doc))
    sim.mechanics.advance(round(0.01 / sim.mechanics.dt), np.array([20.0]), np.zeros(1))
    assert abs(sim.mechanics.state.w[0, 1]) < 1e-9  # frictionless: no spin
    sim.run()
    s = sim.mechanics.state
    assert s.w[0, 1] > 0 and abs(s.w[0, 1] * r / s.v[0, 0]) > 0.5


def test_min_image_is_the_wrapping_formula_to_the_bit():
    """The shortcut for separations below a quarter of the box (no division, no floor) changes no bit."""
    from dem.geometry.neighbours import min_image

    rng = np.random.default_rng(7)
    length = 3.7e-3
    quarter = 0.25 * length
    d = np.concatenate([rng.uniform(-3 * length, 3 * length, 2000), rng.uniform(-1e-9, 1e-9, 200),
                        np.nextafter(quarter, 0.0) * np.array([1.0, -1.0]), [quarter, -quarter, 0.5 * length,
                                                                              -0.5 * length, 0.0, -0.0]])
    expected = d - length * np.floor(d / length + 0.5)
    got = np.array([min_image(float(x), length) for x in d])
    assert np.array_equal(got.view(np.int64), expected.view(np.int64))
    assert min_image(5.0, 0.0) == 5.0  # not periodic: unchanged


@pytest.mark.parametrize("box", [(0.0, 0.0, 0.0), (8e-3, 0.0, 6e-3), (8e-3, 8e-3, 8e-3)])
def test_verlet_list_is_every_close_pair_sorted_whatever_room_it_is_given(box):
    """The cell-binned list against all pairs by brute force (minimum image on periodic axes), in (i, j) order, for
    a capacity too small (second pass), exact and too large; history carried by matching pairs."""
    from dem.geometry.neighbours import carry_history, verlet_pairs

    rng = np.random.default_rng(11)
    box = np.array(box)
    x = rng.uniform(0.0, 8e-3, (150, 3))
    r = rng.uniform(0.3e-3, 0.8e-3, 150)
    skin = 2e-4
    d = x[:, None, :] - x[None, :, :]
    d -= np.where(box > 0, box, 1.0) * np.round(d / np.where(box > 0, box, np.inf))
    close = np.linalg.norm(d, axis=2) < r[:, None] + r[None, :] + skin
    i_ref, j_ref = np.nonzero(np.triu(close, k=1))  # row-major: sorted by (i, j)
    assert len(i_ref) > 50
    for capacity in (0, len(i_ref) // 3, len(i_ref), 2 * len(i_ref)):
        i, j = verlet_pairs(x, r, skin, box, capacity)
        assert np.array_equal(i, i_ref) and np.array_equal(j, j_ref), capacity
    keep = rng.random(len(i_ref)) < 0.7  # an older list: some of these pairs, and one that is gone
    old_i, old_j = np.append(i_ref[keep], 149), np.append(j_ref[keep], 149)
    history = np.arange(len(old_i), dtype=float) + 1.0
    (carried,) = carry_history(old_i, old_j, i_ref, j_ref, history)
    assert np.array_equal(carried[keep], history[:-1]) and np.all(carried[~keep] == 0.0)


def test_phases_change_the_speed_of_a_strain_wall():
    """[[phases]] wall_velocity: a lid pushed in at 0.1 m/s, held from 1 ms, pulled back from 2 ms."""
    doc = {"scene": {"physics": ["mechanical"]}, "material": {"density": 1000.0},
           "particles": {"position": [[0.0, 0.0, 0.0]], "radius": [1e-3], "temperature": [20.0]},
           "contact": {"law": "luding", "k1": 1e4, "k2": 2e4, "kc": 0.0, "kt_ratio": 0.2, "gamma_n": 0.0,
                       "gamma_t": 0.0, "mu": 0.0, "mu_wall": 0.0, "T_melt": 120.0, "T_var": 10.0, "expansion": 0.0,
                       "fluid_overlap": 0.2, "t0": 1.0, "brittle_sliding": True},
           "walls": [{"name": "lid", "point": [0.0, 0.0, 0.01], "normal": [0.0, 0.0, -1.0], "motion": "strain",
                      "velocity": 0.1}],
           "phases": [{"start": 1e-3, "wall_velocity": {"lid": 0.0}},
                      {"start": 2e-3, "wall_velocity": {"lid": -0.05}}],
           "solver": {"mode": "transient", "t_end": 3e-3, "dt": 1e-5}}
    sim = VerletEngine(parse_scene(doc))
    sim.run()
    # in 0.1 mm, held, out 0.05 mm: the lid's offset n . x = q went from -0.01 to -0.01 + 1e-4 - 5e-5
    assert sim.mechanics.w.q[0] == pytest.approx(-0.01 + 1e-4 - 5e-5, rel=1e-9)
    doc["phases"][0]["wall_velocity"] = {"floor": 0.0}
    with pytest.raises(ValueError, match="wall_velocity.floor: no wall named 'floor'"):
        parse_scene(doc)


@pytest.mark.slow  # 2D disks: Luding's force loop for them (35-40 s for numba to compile in a fresh clone)
@pytest.mark.parametrize("sintering", [True, False])
def test_a_wall_that_does_not_sinter_keeps_the_cold_loading_stiffness(sintering):
    """A disk set down on a floor at 140 °C with the overlap that carries its weight on the loading line: with
    ``wall_sintering`` k1(T) delta (eq. 10, the particle's factor), without it the cold-limit k1 delta; it stays."""
    r, h, g = 1e-3, 6e-3, 9.81
    weight = 2000.0 * math.pi * r**2 * h * g
    s = 1.0 / (1.0 + math.exp(-2.0 * (120.0 - 140.0) / 10.0)) if sintering else 1.0
    doc = scene_doc([[0, 0, r - weight / (s * TABLE1["k1"])]], [r], contact={**TABLE1, "wall_sintering": sintering},
                    t_end=0.01,
                    temperature=140.0, walls=[{"name": "floor", "point": [0, 0, 0], "normal": [0, 0, 1]}],
                    gravity={"acceleration": [0.0, 0.0, -g]})
    doc["scene"].update(dimension=2, height=h)
    sim = VerletEngine(parse_scene(doc))
    sim.run()
    (overlap,), (force,) = sim.mechanics.wall_contacts()[2:]
    assert force == pytest.approx(weight, rel=1e-6)
    assert overlap == pytest.approx(weight / (s * TABLE1["k1"]), rel=1e-6)
