"""Stiff steps give the right answer or are refused (Crank-Nicolson far above the stiffest time constant).

The built-in ``pair`` (copper, r = 1 and 3 mm, 100 and 0 C) equalises at the capacity-weighted mean
``100 C_1 / (C_1 + C_2) = 100 / 28 = 3.5714 C`` (r^3 = 1 : 27); with a convection of ``h = 1e10 W/(m^2 K)`` both
particles end at the ambient's 20 C. Plain Crank-Nicolson at a step ~1e4-1e8 times the pair's time constant
kept the initial difference alternating (T = [99.9998, 7e-6] and the like) and exited 0; each case now ends within
1e-4 of the true answer, or, where the capacities are lost to round-off next to the conductances, is refused in
one line naming ``dt``. Steps within the stable limit still run plain Crank-Nicolson.

The network coupled to moving particles takes a thermal step of many mechanical steps: far above the stiffest time
constant, each Crank-Nicolson step surely above the stable limit is an implicit Euler step.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from dem.cli import main as dem_main
from dem.engines.verlet.engine import VerletEngine
from dem.network.heat import Checkpoint, integrate, stable_limit
from dem.scene import parse_scene
from test_cli_stress import refuse_scene, run_scene
from test_dem_coupled import pile
from test_dem_pair import pair_network

EQUAL = 100.0 / 28.0  # capacity-weighted mean: C_1 : C_2 = 1 : 27


def pair_toml(k="394.0", rho="8960.0", cp="385.0", dt="1.0e-3", t_end="0.1", extra="") -> str:
    return (f"[material]\nconductivity = {k}\ndensity = {rho}\nspecific_heat = {cp}\n"
            "[particles]\nposition = [[0.0, 0.0, 0.0], [0.0, 0.0, 3.94e-3]]\nradius = [1.0e-3, 3.0e-3]\n"
            f"temperature = [100.0, 0.0]\n{extra}"
            f'[solver]\nmode = "transient"\nintegrator = "crank-nicolson"\ndt = {dt}\nt_end = {t_end}\n')


@pytest.mark.parametrize("case, expected", [
    (dict(dt="1.0e6", t_end="1.0e7"), EQUAL),  # the first case: 10 steps of ~1e8 time constants
    (dict(k="1.0e10"), EQUAL),  # conductivity 1e10: dt = 1e-3 s is ~2e6 time constants
    (dict(extra="[convection]\nh = 1.0e10\nT_inf = 20.0\n"), 20.0),  # stiff ambient exchange
])
def test_stiff_crank_nicolson_ends_at_the_true_answer(tmp_path, capsys, case, expected):
    code, out, err = run_scene(tmp_path, pair_toml(**case), capsys)
    assert code == 0, err
    s = json.loads(out)
    assert np.allclose(s["T"], expected, rtol=0, atol=1e-4 * 100.0), s["T"]
    assert s["max_principle_violation"] <= 1e-6 and s["energy_error"] < 1e-10
    assert s["startup_steps"] == 2


def test_capacities_lost_to_round_off_are_refused(tmp_path, capsys):
    """Conductivity 1e10, density and specific heat 1e-10 (all within the documented ranges): C/dt ~1e-32 of the
    bond's conductance. It ended at T = [83.5, -16.5] with energy_error 0.165 and exit 0."""
    refuse_scene(tmp_path, pair_toml(k="1.0e10", rho="1.0e-10", cp="1.0e-10"), capsys, "solver.dt = 0.001 s",
                 "energy_error", "wrong")
    # dt = "auto" (the default): its smallest step, t_end / 2^40, is still ~1e22 time constants
    refuse_scene(tmp_path, pair_toml(k="1.0e10", rho="1.0e-10", cp="1.0e-10", dt='"auto"'), capsys,
                 "solver.dt = 'auto'", "wrong", "density and specific heat")


@pytest.mark.parametrize("linear, needles", [
    ("cg", ("cg broke down", "singular to round-off", "capacities")),  # p.Ap = 0: ZeroDivisionError in CG
    ("amg", ("amg did not reach rtol",)),  # the residuals' sum over the matrix's, both 0: ZeroDivisionError
])
def test_capacities_lost_to_round_off_in_an_iterative_solve_are_refused(tmp_path, capsys, linear, needles):
    """The same pair with an iterative linear solver: a ZeroDivisionError traceback (CG's p.Ap, or the uniform
    shift that balances the residuals, divided by the matrix's sum: C/dt lost next to K in every row sum)."""
    refuse_scene(tmp_path, pair_toml(k="1.0e10", rho="1.0e-10", cp="1.0e-10") + f'linear = "{linear}"\n', capsys,
                 *needles)


def test_oscillating_steps_are_refused_where_nothing_damps_them():
    """The pair resumed from a checkpoint past the start-up, still at 100 and 0 C: nothing damps the stiff mode,
    plain Crank-Nicolson alternates it (T_1 -> -92.9 C), and the maximum-principle check refuses the run in one
    line naming dt instead of ending at [99.9998, 7e-6]."""
    net, p = pair_network()
    T = p.temperature.astype(float)
    past = Checkpoint(T, 2e6, 2, 0, 0, 1e6, {k: 0.0 for k in net.flow_names}, 0.0, 1e6, 1e6, 0.0,
                      float(net.C @ T), [])
    with pytest.raises(ValueError, match=r"solver.dt = 1e\+06 s \(crank-nicolson\): at t = 3e\+06 s .*"
                                         r"max_principle_violation"):
        integrate(net, "crank-nicolson", 1e6, 1e7, resume=past)
    res = integrate(net, "crank-nicolson", 1e6, 1e7)  # from t = 0 the start-up damps it
    assert np.allclose(res.T, EQUAL, atol=1e-4) and res.startup_steps == 2


def test_within_the_stable_limit_plain_crank_nicolson():
    """dt below 2/lambda_max: no start-up, the result is the theta method's, to the bit (the pair's closed form
    of one Crank-Nicolson step, (1 - z/2)/(1 + z/2), z = lambda dt, applied 100 times)."""
    net, p = pair_network()
    C = p.capacity
    lam = net.K_pairs[0] * (1 / C[0] + 1 / C[1])
    dt = 1e-3
    assert dt < stable_limit(net)
    res = integrate(net, "crank-nicolson", dt, 0.1)
    assert res.startup_steps == 0 and res.factorizations == 1
    z = lam * dt
    diff = 100.0 * ((1 - z / 2) / (1 + z / 2)) ** 100
    assert res.T[0] - res.T[1] == pytest.approx(diff, rel=1e-9)


def test_builtin_pair_prints_what_it_printed(capsys):
    """The built-in pair (dt within the stable limit) still prints the numbers of the guide's console block."""
    assert dem_main(["run", "pair", "--json"]) == 0
    s = json.loads(capsys.readouterr().out)
    assert s["T"] == pytest.approx([16.87003057, 3.078887757], rel=1e-9)
    assert "startup_steps" not in s


def settling_columns(integrator: str, thermal_interval: float, specific_heat: float = 1e-3):
    """The 3 x 3 spheres of tests/test_dem_coupled.py settling under gravity on an insulated floor (Hertz, no force
    depends on the temperature): three columns of three touching spheres (neighbouring columns just touch, no
    overlap) at 0, 100, 0 C, then 100, 0, 100 C, then 0, 100, 0 C. With a specific heat of 1e-3 J/(kg K) the
    stiffest time constant is ~1e-7 s, so each column is at its mean long before the first thermal step of 2 ms
    ends (z = lambda dt ~ 3e4)."""
    doc = pile(t_end=0.02, integrator=integrator, thermal_interval=thermal_interval)
    doc["contact"] = {"law": "hertz_mindlin", "youngs_modulus": 1.0e7, "poisson_ratio": 0.3, "restitution": 0.3,
                      "tangential_damping": 0.0, "mu": 0.5, "mu_wall": 0.5}
    doc["material"]["specific_heat"] = specific_heat
    del doc["walls"][0]["temperature"]
    doc["particles"]["temperature"] = [100.0 * (k % 2) for k in range(9)]
    doc["output"] = {"interval": 2e-3}
    engine = VerletEngine(parse_scene(doc))
    engine.run()
    return engine


@pytest.mark.slow
def test_stiff_crank_nicolson_on_moving_particles_ends_at_the_true_answer():
    """Plain Crank-Nicolson in steps of 2 ms kept the columns alternating: [66.45, -32.68, 66.24] C in the first
    (true: 33.33 C each, 100 C out of its range). Each step is now an implicit Euler step (startup_steps: every
    thermal step of the run): every column at its mean to 1e-6 of the range, as the implicit run at 1/64 of the
    step, and the heat balance exact."""
    true = np.repeat([100.0 / 3.0, 200.0 / 3.0, 100.0 / 3.0], 3)
    run = settling_columns("crank-nicolson", 2e-3)
    assert np.max(np.abs(run.thermal.T - true)) <= 1e-6 * 100.0, run.thermal.T
    s = run.summary()
    assert s["network_assemblies"] == 1  # the columns stayed as they were
    assert s["startup_steps"] == s["network_assemblies"] + s["network_refreshes"] >= 10
    assert s["energy_error"] < 1e-12
    reference = settling_columns("implicit", 2e-3 / 64)
    assert np.max(np.abs(run.thermal.T - reference.thermal.T)) <= 1e-6 * 100.0
    assert "startup_steps" not in reference.summary()


@pytest.mark.slow  # the Hertz-Mindlin law's force loop (20 s for numba to compile in a fresh clone)
def test_crank_nicolson_on_moving_particles_within_the_limit_stays_crank_nicolson():
    """The same columns with a specific heat of 30 J/(kg K): the stable limit is 3.4 ms, the bound 2 / max(A_ii /
    C_i) 5.2 ms, so the steps of 2 ms are Crank-Nicolson's. They end 0.026 K from the run at 1/32 of the step
    (implicit Euler steps: 0.17 K)."""
    run = settling_columns("crank-nicolson", 2e-3, specific_heat=30.0)
    assert "startup_steps" not in run.summary()
    fine = settling_columns("crank-nicolson", 2e-3 / 32, specific_heat=30.0).thermal.T
    assert np.max(np.abs(run.thermal.T - fine)) <= 0.05
    implicit = settling_columns("implicit", 2e-3, specific_heat=30.0).thermal.T
    assert np.max(np.abs(implicit - fine)) > 0.1
