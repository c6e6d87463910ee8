"""Zohdi 2014 on the engine: the contact law against its closed forms, the trapezoidal fixed-point step against its
own recurrence and against momentum conservation, sliding friction, bonds, the adaptive step (halving TOL, a
restart), the staggered heat balance with Joule heating, the current in the engine against a direct solve, the
volume fraction of Remark 1, and bad input."""

import copy
import math

import numpy as np
import pytest

from dem.scene import parse_scene
from dem.laws.contact.normal import zohdi as zohdi_normal
from dem.laws.contact.zohdi import ZohdiMaterial
from dem.scene.staggered import ZohdiStepping
from dem.engines.staggered.engine import StaggeredEngine

# This module's tests compile the Zohdi law's own kernels, its force loop and the staggered engine's iteration (numba
# takes 10-30 s for them in a fresh clone), so it runs with the slow tests; the quick run moves particles under the
# default law, Luding's, and the Verlet engine.
pytestmark = pytest.mark.slow

R = 0.075
RHO = 2000.0
MASS = RHO * 4.0 / 3.0 * math.pi * R**3
CONTACT = {"law": "zohdi", "K_p": 1.0e7, "p_p": 2.0, "K_p_lim": 1.0e6, "K_w": 1.0e7, "p_w": 2.0, "K_w_lim": 1.0e6,
           "theta_star": 500.0, "K_b": 1.0e6, "p_b": 2.0, "E_star": 0.3, "mu_d": 0.1, "c_env": 0.1, "v_slip": 0.1}


def scene(position, velocity=None, temperature=300.0, walls=(), gravity=(0.0, 0.0, 0.0), t_end=0.05,
          physics=("mechanical",), contact=None, solver=None, electrical=None, material=None, output=None):
    n = len(position)
    doc = {"scene": {"physics": list(physics)},
           "material": {"density": RHO, **(material or {})},
           "particles": {"position": [list(map(float, p)) for p in position], "radius": [R] * n,
                         "temperature": [temperature] * n},
           "contact": {**CONTACT, **(contact or {})}, "walls": [dict(w) for w in walls],
           "gravity": {"acceleration": list(gravity)},
           "solver": {"mode": "transient", "t_end": t_end, "dt": 0.005, **(solver or {})}}
    if velocity is not None:
        doc["particles"]["velocity"] = [list(map(float, v)) for v in velocity]
    if electrical is not None:
        doc["electrical"] = electrical
    if output is not None:
        doc["output"] = output
    return doc


FLOOR = {"name": "bottom", "point": [-1.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0]}


def test_lens_area_and_softening_closed_forms():
    ri, rj, d = 0.075, 0.05, 0.11
    li = 0.5 * (d - (rj**2 - ri**2) / d)
    assert zohdi_normal.lens_area(ri, rj, d) == pytest.approx(math.pi * (ri**2 - li**2), rel=1e-14)
    assert zohdi_normal.lens_area(ri, rj, d) == pytest.approx(math.pi * (rj**2 - (d - li) ** 2), rel=1e-12)  # one circle
    assert zohdi_normal.lens_area(ri, rj, ri + rj) == 0.0
    m = ZohdiMaterial(**{k: v for k, v in CONTACT.items() if k != "law"}, density=RHO)
    assert m.stiffness(300.0) == pytest.approx(4.0e6) and m.stiffness(480.0) == 1.0e6 and m.stiffness(0.0) == 1e7


def test_free_fall_with_drag_follows_the_trapezoidal_recurrence():
    """A particle falling with drag: v' = g - k v is linear, so each converged step is the trapezoidal (phi = 1/2)
    recurrence v+ = ((1 - h k/2) v + h g)/(1 + h k/2) to the iteration tolerance, and it approaches the exact
    solution as dt^2."""
    g = 9.81
    sim = StaggeredEngine(parse_scene(scene([[0.0, 0.0, 0.0]], gravity=(-g, 0.0, 0.0), t_end=0.2,
                                            contact={"c_env": 2.0}, solver={"tolerance": 1e-12})))
    sim.run()
    k = 2.0 * 6.0 * math.pi * R / MASS
    v = 0.0
    for h in sim.dt_taken:
        v = ((1.0 - 0.5 * h * k) * v + h * -g) / (1.0 + 0.5 * h * k)
    assert sim.mechanics.state.v[0, 0] == pytest.approx(v, rel=1e-9)
    exact = -g / k * (1.0 - math.exp(-k * 0.2))
    assert sim.mechanics.state.v[0, 0] == pytest.approx(exact, rel=1e-5)
    assert sim.restarts == 0 and sim.steps == 40  # 40 steps of dt_max = 0.005 s


def test_collision_conserves_momentum_and_the_elastic_law_returns_the_energy():
    """Two spheres meet head on without friction or drag: every iterate keeps the momentum (the pair forces are
    equal and opposite); the contact is elastic, so the trapezoidal rule gives the kinetic energy back."""
    doc = scene([[0.0, 0.0, 0.0], [0.2, 0.0, 0.0]], velocity=[[1.0, 0.1, 0.0], [-0.5, 0.0, 0.0]], t_end=0.3,
                contact={"mu_d": 0.0, "c_env": 0.0})
    sim = StaggeredEngine(parse_scene(doc))
    p0 = sim.mechanics.state.momentum().copy()
    e0 = sim.mechanics.state.kinetic_energy()
    touched = False
    while sim.t < 0.3:
        sim.step()
        touched |= len(sim.mechanics.contacts()[0]) > 0
    s = sim.mechanics.state
    assert touched and s.v[0, 0] < 0 < s.v[1, 0]  # they met and bounced
    assert np.allclose(s.momentum(), p0, rtol=0, atol=1e-12 * MASS)
    assert s.kinetic_energy() == pytest.approx(e0, rel=2e-3)


def test_sliding_on_the_floor_decelerates_at_mu_g():
    """A sphere resting on the floor, sliding at 1 m/s: friction mu_d |F_wall| against its tangential velocity
    (eqs. 16-17) slows it at mu_d g while it slides well above v_slip."""
    g, mu = 9.81, 0.2
    # rest where the wall force K_w E^2 A balances the weight (E = overlap/R, A = pi (R^2 - dist^2))
    dist = R - 0.0055
    for _ in range(60):
        force = 4.0e6 * ((R - dist) / R) ** 2 * math.pi * (R * R - dist * dist)
        dist += (force - MASS * g) / 2e6
    doc = scene([[-1.0 + dist, 0.0, 0.0]], velocity=[[0.0, 1.0, 0.0]], walls=[FLOOR], gravity=(-g, 0.0, 0.0),
                t_end=0.2, contact={"mu_d": mu, "c_env": 0.0, "v_slip": 0.01})
    sim = StaggeredEngine(parse_scene(doc))
    sim.run()
    assert sim.mechanics.state.v[0, 1] == pytest.approx(1.0 - mu * g * 0.2, rel=5e-3)


def test_a_bond_is_kept_from_the_step_after_E_star_and_cancels_part_of_the_repulsion():
    """Two spheres pressed to |E| = 0.12 > E* = 0.1 and held: the step that reaches E* bonds them; from then on the
    normal force is (K_p(theta) - K_b) |E|^2 A (eq. 19)."""
    gap = 2 * R * (1 - 0.12)
    doc = scene([[0.0, 0.0, 0.0], [gap, 0.0, 0.0]], t_end=0.01, contact={"E_star": 0.1, "c_env": 50.0})
    sim = StaggeredEngine(parse_scene(doc))
    i, j, fn, area, bond = sim.mechanics.contacts()
    strain = (2 * R - gap) / (2 * R)
    assert fn[0] == pytest.approx(4.0e6 * strain**2 * area[0], rel=1e-12)  # not bonded yet
    sim.step()
    s = sim.mechanics.state
    i, j, fn, area, bond = sim.mechanics.contacts()
    strain = (2 * R - np.linalg.norm(s.x[1] - s.x[0])) / (2 * R)
    mech = sim.mechanics
    assert bond[0] == 1 and mech.pair_column("bonded")[(mech.pi == i[0]) & (mech.pj == j[0])][0] == 1
    assert fn[0] == pytest.approx((4.0e6 - 1.0e6) * strain**2 * area[0], rel=1e-12)


def settling(tolerance, dt_max=0.002, t_end=0.15):
    """Eight spheres dropped into a small box with walls (a steady, converging case)."""
    rng = np.random.default_rng(3)
    pos = [[-0.9 + 0.2 * k + rng.uniform(-0.01, 0.01), rng.uniform(-0.05, 0.05), 0.0] for k in range(8)]
    walls = [FLOOR, {"name": "y-", "point": [0, -0.2, 0], "normal": [0, 1, 0]},
             {"name": "y+", "point": [0, 0.2, 0], "normal": [0, -1, 0]}]
    doc = scene(pos, walls=walls, gravity=(-9.81, 0.0, 0.0), t_end=t_end,
                solver={"dt": dt_max, "dt_max": dt_max, "tolerance": tolerance})
    sim = StaggeredEngine(parse_scene(doc))
    x0 = sim.mechanics.state.x.copy()
    sim.run()
    return sim, x0


def test_halving_the_tolerance_changes_the_answer_by_less_than_the_tolerance():
    a, x0 = settling(5e-4)
    b, _ = settling(2.5e-4)
    assert a.dt_taken == b.dt_taken  # the same steps (dt_max binds): only the iteration error differs
    assert b.iterations > a.iterations
    moved = np.abs(a.mechanics.state.x - x0).sum()
    assert moved > 10 * R
    difference = np.abs(a.mechanics.state.x - b.mechanics.state.x).sum()
    assert difference / moved < 5e-4


def test_a_step_that_cannot_converge_in_K_d_iterations_restarts_smaller():
    """A fast, stiff collision with a large first step: the fixed point cannot contract in K_d iterations, so the
    step restarts with Phi_K dt < dt (Algorithm 1, step 7) and the run goes on; the step then grows back."""
    doc = scene([[0.0, 0.0, 0.0], [0.16, 0.0, 0.0]], velocity=[[3.0, 0.0, 0.0], [-3.0, 0.0, 0.0]], t_end=0.1,
                contact={"K_p": 1e9, "K_p_lim": 1e8, "mu_d": 0.0, "c_env": 0.0},
                solver={"dt": 0.005, "dt_max": 0.005, "iterations": 5})
    sim = StaggeredEngine(parse_scene(doc))
    sim.run()
    assert sim.restarts > 0
    assert min(sim.dt_taken) < 0.005 / 2
    assert max(sim.dt_taken[-4:]) == pytest.approx(0.005)  # grown back to dt_max once they have parted
    summary = sim.summary()
    assert summary["restarts"] == sim.restarts and summary["dt_min"] == min(sim.dt_taken)


def test_step_factor_of_eq_30():
    st = ZohdiStepping(dt=0.005, dt_max=0.005, iterations=10, tolerance=5e-4, order=2.0, growth=10.0)
    assert st.factor(5e-4, 10) == pytest.approx(1.0)  # the tolerance met in exactly K_d iterations: keep dt
    assert st.factor(5e-4 ** (5 / 10), 5) == pytest.approx(1.0)  # converging at the same rate: keep dt
    assert st.factor(1e-6, 4) > 1.0 and st.factor(1e-2, 10) < 1.0
    assert st.restart_factor(0.9) == 0.5 and st.restart_factor(0.2) == 0.2


ELECTRODES = [{"name": "bottom", "point": [-1.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0], "temperature": 300.0,
               "potential": 0.0},
              {"name": "top", "point": [0.0, 0.0, 0.0], "normal": [-1.0, 0.0, 0.0], "temperature": 300.0,
               "potential": 50.0}]


def column(n=6, **kwargs):
    """A column of touching spheres between a grounded bottom and a top electrode at 50 V."""
    pitch = 2 * R * 0.95
    pos = [[-1.0 + R * 0.95 + k * pitch, 0.0, 0.0] for k in range(n)]
    walls = copy.deepcopy(ELECTRODES)
    walls[1]["point"] = [pos[-1][0] + R * 0.95, 0.0, 0.0]
    material = {"conductivity": 100.0, "specific_heat": 3.0, "electrical_conductivity": 0.1}
    kwargs.setdefault("electrical", {"scheme": "kirchhoff", "absorption": 0.5})
    doc = scene(pos, walls=walls, physics=("mechanical", "thermal", "electrical"), material=material, **kwargs)
    doc["conductance"] = {"law": "zohdi"}  # the paper's K A / d with the lens area
    return doc


def test_joule_heat_equals_electrode_power_and_the_heat_balance_is_exact():
    doc = column(t_end=0.05)
    doc["walls"][1]["potential"] = 5000.0  # heats by ~10 K per step: the balance is not lost in T's round-off
    sim = StaggeredEngine(parse_scene(doc))
    c = sim.current
    assert c.joule_heat > 0 and c.joule_heat == pytest.approx(c.electrode_power, rel=1e-12)
    assert c.flow.residual < 1e-12  # current conserved at every particle
    assert c.heating.sum() == pytest.approx(0.5 * c.joule_heat, rel=1e-12)
    sim.run()
    th = sim.thermal
    assert th.energy_error() < 1e-12
    assert th.heat_in["joule"] == pytest.approx(0.5 * c.joule_energy, rel=1e-12)
    assert c.joule_energy == pytest.approx(c.electrode_energy, rel=1e-12)
    assert np.all(sim.mechanics.state.T > 300.0)  # Joule heated, and walls at the initial temperature


def test_current_in_the_engine_is_the_direct_kirchhoff_solve_of_the_column():
    """The column in series: the current is 50 V over the sum of the contact resistances sigma pi a^2 / d (the
    thermal lens law with sigma for kappa) and the two electrode contacts."""
    sim = StaggeredEngine(parse_scene(column()))
    s = sim.mechanics.state
    sigma = 0.1
    d = np.linalg.norm(np.diff(s.x, axis=0), axis=1)
    a2 = R * R - (d / 2) ** 2
    resistance = np.sum(d / (sigma * math.pi * a2))
    for k, q in ((0, -1.0), (len(s.x) - 1, sim.mechanics.w.q[1])):
        dist = abs(s.x[k, 0] - (q if k == 0 else -q))
        resistance += dist / (sigma * math.pi * (R * R - dist * dist))
    assert sim.current.flow.electrode_current[1] == pytest.approx(50.0 / resistance, rel=1e-12)


def test_zohdi_scheme_in_the_engine_heats_by_J_squared():
    doc = column(electrical={"scheme": "zohdi", "absorption": 0.5})
    doc["walls"][0].pop("potential")
    doc["walls"][1].pop("potential")
    doc["walls"][0]["current"] = 10.0
    doc["walls"][1]["current"] = 40.0
    sim = StaggeredEngine(parse_scene(doc))
    J = sim.current.J
    assert J[0] == 10.0 and J[-1] == 40.0 and np.allclose(J, np.linspace(10.0, 40.0, len(J)), rtol=1e-6)
    V = 4.0 / 3.0 * math.pi * R**3
    assert np.allclose(sim.current.heating, 0.5 * J**2 * V / 0.1)


def test_volume_fraction_of_remark_1():
    """The solid inside the box between the bottom wall and the lowest point the top wall reached, over the box:
    the top wall comes down to x = -0.55 and goes back up; a particle that rose above x = -0.55 counts by its part
    below it (a spherical cap)."""
    walls = [FLOOR, {"name": "top", "point": [-0.5, 0, 0], "normal": [-1, 0, 0], "motion": "strain",
                     "velocity": 1.0},
             {"name": "y-", "point": [0, -0.5, 0], "normal": [0, 1, 0]},
             {"name": "y+", "point": [0, 0.5, 0], "normal": [0, -1, 0]},
             {"name": "z-", "point": [0, 0, -0.5], "normal": [0, 0, 1]},
             {"name": "z+", "point": [0, 0, 0.5], "normal": [0, 0, -1]}]
    pos = [[-0.8, 0.0, 0.0], [-0.8, 0.2, 0.2], [-0.7, -0.2, 0.0]]
    doc = scene(pos, velocity=[[0, 0, 0], [0, 0, 0], [1.2, 0, 0]], walls=walls, t_end=0.1,
                output={"fraction_axis": "x"}, solver={"dt": 0.01, "dt_max": 0.01})
    doc["phases"] = [{"start": 0.05, "wall_velocity": {"top": -1.0}}]
    sim = StaggeredEngine(parse_scene(doc))
    sim.run()
    x = sim.mechanics.state.x[:, 0]
    assert x[2] + R > -0.55 > x[2] - R  # the third one crosses the lowest compression point
    V = 4.0 / 3.0 * math.pi * R**3
    h = -0.55 - (x[2] - R)
    cap = math.pi * h * h * (3 * R - h) / 3.0
    bed = sim.bed()
    assert bed["lowest_compression"] == pytest.approx(-0.55)
    assert bed["volume_fraction"] == pytest.approx((2 * V + cap) / (1.0 * 0.45), rel=1e-12)


@pytest.mark.parametrize("change, message", [
    ({"material": {"electrical_conductivity": -0.1}}, r"\[material\] electrical_conductivity = -0.1: must be > 0"),
    ({"solver": {"phi": 1.5}}, r"phi = 1.5: must be in \[0, 1\]"),
    ({"solver": {"iterations": 0}}, "iterations = 0: must be an integer >= 2"),
    ({"solver": {"tolerance": 0.0}}, "tolerance = 0.0: must be > 0"),
    ({"electrical": {"floating": "maybe"}}, "floating = 'maybe'"),
])
def test_bad_input_is_named(change, message):
    doc = column()
    for table, values in change.items():
        doc[table].update(values)
    with pytest.raises(ValueError, match=message):
        parse_scene(doc)


def test_fixed_current_without_a_path_and_floating_particles_stop_the_run():
    doc = column()
    doc["walls"][1].pop("potential")
    doc["walls"][1]["current"] = 2.0
    doc["walls"][1]["point"] = [0.5, 0.0, 0.0]  # lifted off the column
    with pytest.raises(ValueError, match="walls.top.current = 2 A at t = 0 s: no path"):
        StaggeredEngine(parse_scene(doc))
    doc = column(electrical={"scheme": "kirchhoff", "absorption": 0.5, "floating": "error"})
    doc["particles"]["position"].append([-0.5, 0.5, 0.5])
    doc["particles"]["radius"].append(R)
    doc["particles"]["temperature"].append(300.0)
    with pytest.raises(ValueError, match=r"1 particle\(s\) touch no electrode .*: 6$"):
        StaggeredEngine(parse_scene(doc))


def to_toml(doc: dict) -> str:
    """A scene dict as TOML (scalars, lists, tables and arrays of tables: what these tests build)."""
    def value(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, str):
            return f'"{v}"'
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(value(x) for x in v) + "]"
        return repr(float(v)) if isinstance(v, float) else str(v)

    lines = []
    for name, table in doc.items():
        for t in (table if isinstance(table, list) else [table]):
            lines.append(f"[[{name}]]" if isinstance(table, list) else f"[{name}]")
            lines += [f"{k} = {value(v)}" for k, v in t.items()]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("table, key, value, message", [
    ("solver", "phi", -0.1, "phi = -0.1: must be in [0, 1]"),
    ("solver", "iterations", 1, "iterations = 1: must be an integer >= 2"),
    ("solver", "tolerance", -1e-3, "tolerance = -0.001: must be > 0"),
    ("material", "electrical_conductivity", 0.0, "electrical_conductivity = 0.0: must be > 0"),
    ("walls", "current", 2.0, "walls.top.current = 2 A at t = 0 s: no path"),
])
def test_cli_bad_input_is_one_line_and_exit_2(tmp_path, capsys, table, key, value, message):
    from dem.cli import main

    doc = column()
    if table == "walls":
        doc["walls"][1].pop("potential")
        doc["walls"][1]["point"] = [0.5, 0.0, 0.0]
        doc["walls"][1][key] = value
    else:
        doc[table][key] = value
    path = tmp_path / "bad.toml"
    path.write_text(to_toml(doc))
    assert main(["run", str(path)]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and "Traceback" not in err


def test_section_7_three_phases_of_fig_9():
    """The built-in scene (1000 spheres, 1 s): poured to 0.5-0.6, pressed to near full density, sprung back to
    between the two; the temperature rises while pouring and pressing and falls after the release."""
    from dem.scene import load_scene

    rows = []
    sim = StaggeredEngine(load_scene("zohdi-compaction"))
    sim.run(lambda: rows.append(sim.record()))
    t = np.array([r["t"] for r in rows])
    vf = np.array([r["volume_fraction"] for r in rows])
    T = np.array([r["T_mean"] for r in rows])
    first = next(k for k, r in enumerate(rows) if r["joule_heat"] > 1.0)  # the top wall reaches the powder
    poured, pressed, final = vf[first], vf.max(), vf[-1]
    assert 0.5 <= poured <= 0.6
    assert pressed >= 0.97
    assert poured + 0.1 < final < pressed - 0.05
    rising = (t <= 0.8) & (t > 0.0)
    assert np.all(np.diff(T[rising]) >= -1e-9 * T[rising][1:])  # phases 1-2: never falls
    assert T[first] > T[0] + 20.0 and T[t <= 0.8][-1] > T[first] + 1000.0
    cooling = t >= t[np.argmax(T)]
    assert t[np.argmax(T)] < 0.85 and np.all(np.diff(T[cooling]) < 0.0) and T[-1] < T.max() - 50.0
    assert sim.thermal.energy_error() < 1e-12
    assert sim.current.joule_energy == pytest.approx(sim.current.electrode_energy, rel=1e-12)


def test_conducted_heat_is_the_conductance_law_on_the_bonds():
    """The paper's law compiled on the Verlet list (dem.laws.lens_conductance.lens_list_conductances, the open pairs at
    K = 0) gives the conductances of the general path (dem.geometry.bonds.find_bonds + bond_conductances with law =
    "zohdi") on the touching pairs and walls, and Q is their flows summed per particle, here on a pressed column with
    hot walls."""
    from dem.engines.staggered.heat import contact_bonds
    from dem.laws.conductance import bond_conductances

    doc = column()
    doc["walls"][0]["temperature"] = 900.0
    sim = StaggeredEngine(parse_scene(doc))
    th, mech = sim.thermal, sim.mechanics
    x = mech.state.x.copy()
    x[-1, 0] += 0.15 * R  # the top particle off its neighbour (overlap 0.1 R): a listed pair that does not touch
    T = np.random.default_rng(0).uniform(300.0, 700.0, mech.state.n)
    K, K_w, plane_node, plane_index = th.conductances(mech, x, T)
    now, b = contact_bonds(th.particles, mech, x, T, th.thermal_walls, "lens", "error")
    K_b, K_wb = bond_conductances(th.spec, now, b)
    closed = K > 0.0
    assert len(K) == closed.sum() + 1 == 5 and b.n_walls == 2  # open listed pairs are edges with K = 0
    assert np.array_equal(mech.pi[closed], b.i) and np.array_equal(mech.pj[closed], b.j)
    assert np.allclose(K[closed], K_b, rtol=1e-13, atol=0.0)
    assert np.allclose(K_w[K_w > 0], K_wb, rtol=1e-13, atol=0.0)
    Q = th.conduction(mech, x, T)
    flow = K_b * (T[b.j] - T[b.i])
    into_wall = K_wb * (th.wall_T[b.wall_index] - T[b.wall_particle])
    n = mech.state.n
    direct = np.bincount(b.i, flow, n) - np.bincount(b.j, flow, n) + np.bincount(b.wall_particle, into_wall, n)
    assert np.all(Q != 0.0) and np.allclose(Q, direct, rtol=1e-12, atol=0.0)
    # another law runs on the bonds and lands on the same edges of the list
    law_fit = StaggeredEngine(parse_scene({**doc, "conductance": {"law": "fit", "out_of_range": "clip"}})).thermal
    K_fit = law_fit.conductances(mech, x, T)[0]
    assert np.array_equal(K_fit > 0.0, closed)


def test_heat_network_is_refreshed_in_place_between_list_rebuilds():
    """The network's edges are the Verlet list's pairs: iterations and steps on the same list rewrite its
    conductances; it is assembled again only when the list is rebuilt."""
    doc = column(t_end=0.02)
    sim = StaggeredEngine(parse_scene(doc))
    sim.run()
    th = sim.thermal
    assert th.refreshes > 10 * th.assemblies and th.assemblies <= sim.mechanics.rebuilds + 1


def test_frames_are_rendered_off_screen_in_one_colour_range(tmp_path, monkeypatch):
    from dem.output import frames as frames_module
    from dem.output.frames import FrameWriter

    ranges = []
    draw = frames_module.render
    monkeypatch.setattr(frames_module, "render", lambda *args: ranges.append(args[6]) or draw(*args))
    doc = column()
    doc["output"] = {"fraction_axis": "x"}
    sim = StaggeredEngine(parse_scene(doc))
    frames = FrameWriter(tmp_path, 2, 0.01, 0, 300.0, 300.0)
    frames(sim)
    sim.run(lambda: frames(sim))
    assert frames.render() == ["frame_00.png", "frame_01.png"]
    assert all((tmp_path / "frames" / name).stat().st_size > 10_000 for name in frames.written)
    first, last = (float(np.max(np.load(tmp_path / "frames" / f"frame_{k:02d}.npz")["T"])) for k in range(2))
    assert first == 300.0 < last and ranges == [(300.0, last)] * 2  # Joule-heated: the first frame on the last's scale
    assert FrameWriter(tmp_path, 2, 0.01, 0, 300.0, 300.0).next == 2  # resumed: the frames taken are kept
