"""Two copper particles (r = 1 and 3 mm, h = 0.06 mm, Rojek 2022 Sec. 6) equalising their temperatures.

The lumped pair obeys d(T_i - T_j)/dt = -K_ij (1/C_i + 1/C_j) (T_i - T_j): the difference decays exactly as
exp(-lambda t). Each integrator must follow it (to the tolerances below) and conserve energy to round-off.
"""

import numpy as np
import pytest

from dem import make_scene, run
from dem.laws.conductance import ConductanceSpec
from dem.geometry.particles import Particles
from dem.network.heat import build_network, integrate, stable_limit
from verification.cases import SEC6

X = [[0.0, 0.0, 0.0], [0.0, 0.0, 3.94e-3]]
R = [1.0e-3, 3.0e-3]
T0 = [100.0, 0.0]


def pair_network(law="rojek"):
    p = Particles.from_arrays(X, R, T0)
    return build_network(p, spec=ConductanceSpec(law=law)), p


def test_pair_conductance_is_the_papers():
    net, _ = pair_network()
    assert net.K_pairs[0] == pytest.approx(SEC6["K_model"].value, abs=5e-7)  # Rojek 2022, Sec. 6: K_ij = 0.276035 W/K


def decay_error(integrator, dt, law="rojek", t_end=0.2):
    net, p = pair_network(law)
    C = p.capacity
    lam = net.K_pairs[0] * (1 / C[0] + 1 / C[1])
    worst = [0.0]

    def observe(step, t, T, flows):
        exact = 100.0 * np.exp(-lam * t)
        worst[0] = max(worst[0], abs(T[0] - T[1] - exact) / 100.0)

    res = integrate(net, integrator, dt, t_end, observer=observe)
    assert res.t == pytest.approx(t_end, rel=1e-12)
    return worst[0], res


@pytest.mark.parametrize("law", ["rojek", "argento-bouvard", "zohdi"])
@pytest.mark.slow
def test_crank_nicolson_and_explicit_follow_exponential(law):
    err_cn, res_cn = decay_error("crank-nicolson", 1e-3, law)
    err_ex, res_ex = decay_error("explicit", 1e-4, law)
    assert err_cn < 2e-3 and err_ex < 2e-3
    assert res_cn.energy_error < 1e-10 and res_ex.energy_error < 1e-10


@pytest.mark.parametrize("integrator", ["explicit", "implicit", "crank-nicolson"])
def test_auto_dt_within_2e_2(integrator):
    err, res = decay_error(integrator, "auto")
    assert err < 2e-2
    assert res.energy_error < 1e-10
    if integrator == "explicit":
        assert res.dt_max <= res.stable_limit


def test_energy_conserved_to_round_off():
    for integrator, dt in [("implicit", 1e-3), ("crank-nicolson", 1e-3), ("explicit", 1e-4)]:
        net, p = pair_network()
        res = integrate(net, integrator, dt, 0.1)
        e0, e1 = p.capacity @ np.array(T0), p.capacity @ res.T
        assert abs(e1 - e0) / e0 < 1e-10
        assert res.energy_error < 1e-10


def test_stable_limit_is_the_pair_eigenvalue_and_larger_dt_refused():
    net, p = pair_network()
    C = p.capacity
    limit = 2.0 / (net.K_pairs[0] * (1 / C[0] + 1 / C[1]))
    assert stable_limit(net) == pytest.approx(limit, rel=1e-10)
    with pytest.raises(ValueError, match="stability limit"):
        integrate(net, "explicit", 1.01 * limit, 1.0)
    # stable below the limit, but oscillating far outside the initial range: refused as a wrong answer
    seen = []
    with pytest.raises(ValueError, match="max_principle_violation"):
        integrate(net, "explicit", 0.99 * limit, 2.0, observer=lambda step, t, T, flows: seen.append(T[0] - T[1]))
    assert len(seen) == 1 and abs(seen[0]) == 100.0  # refused at the first step, where the overshoot appears
    assert integrate(net, "explicit", 0.49 * limit, 2.0).max_principle_violation == 0.0  # not oscillating


def test_run_summary_of_the_pair_scene(tmp_path):
    scene = make_scene(X, R, T0, mode="transient", integrator="crank-nicolson", dt=1e-3, t_end=0.1)
    res = run(scene, out=tmp_path)
    s = res.summary
    for key in ("t", "steps", "particles", "bonds", "energy_error", "seconds", "physics", "T"):
        assert key in s
    assert s["steps"] == 100 and s["bonds"] == 1 and s["physics"] == ["thermal"]
    for name in ("summary.json", "timeseries.csv", "particles.pvd", "bonds.pvd", "particles_000000000.vtu",
                 "bonds_000000100.vtu"):
        assert (tmp_path / name).exists()
    rows = (tmp_path / "timeseries.csv").read_text().splitlines()
    assert len(rows) == 102
