"""The error-controlled step of ``dt = "auto"`` (dem.network.heat.integrate).

The insulated pair and chain have exact solutions ``T(t) = expm(-t C^-1 L) T0`` (by eigenvectors); the global error of every
integrator must track ``rtol`` (relative to the temperature range), Crank-Nicolson must take few steps, rejected
steps must be redone without trace in the energy bookkeeping, and the step sizes of the implicit integrators must
stay on the dyadic grid ``t_end / 2^k`` so that their factorisations are reused.
"""

import math

import numpy as np
import pytest

import dem.network.heat
from dem.laws.conductance import ConductanceSpec
from dem.geometry.particles import Particles
from dem.network.heat import Network, build_network, integrate, stable_limit

INTEGRATORS = ("explicit", "implicit", "crank-nicolson")


def chain_network(n: int, hot: float = 100.0, fixed_ends: bool = False, radii=None):
    """``n`` copper spheres in a row (overlap 6 % of the radius), the first at ``hot``, the others at 0."""
    r = np.full(n, 1e-3) if radii is None else np.asarray(radii, float)
    z = np.concatenate([[0.0], np.cumsum(r[:-1] + r[1:] - 0.06 * np.minimum(r[:-1], r[1:]))])
    x = np.column_stack([np.zeros(n), np.zeros(n), z])
    T0 = np.zeros(n)
    T0[0] = hot
    fixed = np.zeros(n, dtype=bool)
    if fixed_ends:
        fixed[[0, -1]] = True
    p = Particles.from_arrays(x, r, T0, fixed=fixed)
    return build_network(p, spec=ConductanceSpec(law="rojek"))


def run_against_exact(net: Network, integrator: str, rtol: float, t_end: float):
    """(max error over the accepted steps relative to the temperature range, result, observed (step, t))."""
    s = net.particles.capacity**-0.5
    lam, V = np.linalg.eigh(s[:, None] * net.L.toarray() * s[None, :])  # C^-1/2 L C^-1/2 = V diag(lam) V^T
    modes = V.T @ (net.particles.temperature / s)
    worst, seen = [0.0], []

    def observe(step, t, T, flows):
        seen.append((step, t))
        worst[0] = max(worst[0], float(np.max(np.abs(T - s * (V @ (np.exp(-lam * t) * modes))))))

    res = integrate(net, integrator, "auto", t_end, rtol=rtol, observer=observe)
    return worst[0] / net.temperature_range(), res, seen


def decay_time(net: Network) -> float:
    """1 / (slowest nonzero decay rate) of the insulated network."""
    s = net.particles.capacity**-0.5
    lam = np.linalg.eigvalsh(s[:, None] * net.L.toarray() * s[None, :])
    return 1.0 / lam[lam > 1e-9 * lam.max()].min()


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("rtol", [1e-2, 1e-3])
def test_global_error_tracks_rtol_on_a_pair(integrator, rtol):
    net = chain_network(2, radii=[1e-3, 3e-3])
    err, res, _ = run_against_exact(net, integrator, rtol, 3.0 * decay_time(net))
    assert err <= 3.0 * rtol
    assert err >= 0.01 * rtol  # not wastefully accurate either (the old controller was 1e-3 x rtol for CN)
    assert res.energy_error < 1e-12


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_global_error_tracks_rtol_on_a_chain(integrator):
    net = chain_network(6, radii=[1e-3, 2e-3, 1e-3, 1.5e-3, 1e-3, 3e-3])
    err, res, _ = run_against_exact(net, integrator, 1e-3, 2.0 * decay_time(net))
    assert err <= 3e-3
    assert res.energy_error < 1e-12


def test_crank_nicolson_takes_few_steps():
    """At rtol 1e-3 the old change-per-step controller took 1313 steps on this pair (error 1e-6); the error
    controller needs a few dozen for an error of about rtol."""
    net = chain_network(2, radii=[1e-3, 3e-3])
    err, res, _ = run_against_exact(net, "crank-nicolson", 1e-3, 0.2)
    assert res.steps <= 60
    assert err <= 3e-3


def test_implicit_steps_on_the_dyadic_grid_and_factorisations_reused():
    net = chain_network(6)
    t_end = 2.0 * decay_time(net)
    for integrator in ("implicit", "crank-nicolson"):
        times = []
        res = integrate(net, integrator, "auto", t_end, rtol=1e-3,
                        observer=lambda step, t, T, flows: times.append(t))
        assert times[-1] == t_end and res.t == t_end  # ends exactly on t_end
        steps = np.diff(times)
        levels = np.log2(t_end / steps)
        assert np.allclose(levels, np.round(levels), atol=1e-9)
        assert res.dt_min < res.dt_max  # the step really varies
        # one factorisation per step size used (step doubling also needs dt/2)
        assert res.factorizations <= len(set(np.round(levels).astype(int))) + 1


def test_rejected_steps_are_redone(monkeypatch):
    """A controller that always asks for 4x the step overshoots, so steps are rejected and redone; the rejected
    attempts leave no trace (observer, energy), and the answer still meets the tolerance. (On linear decays the
    real controller seldom rejects: the error of a step falls smoothly as the modes decay.)"""
    factor = dem.network.heat._controller_factor
    monkeypatch.setattr(dem.network.heat, "_controller_factor", lambda err, tol, q: max(4.0, factor(err, tol, q)))
    net = chain_network(6)
    for integrator in INTEGRATORS:
        err, res, seen = run_against_exact(net, integrator, 1e-3, 2.0 * decay_time(net))
        assert res.rejected > 0
        assert [s for s, _ in seen] == list(range(res.steps + 1))
        assert np.all(np.diff([t for _, t in seen]) > 0)
        assert err <= 3e-3
        assert res.energy_error < 1e-12


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_energy_balance_with_variable_steps(integrator):
    """Heated from a fixed hot end, cooled at a fixed cold end: the change of sum C T of the free particles equals
    the heat booked through the fixed particles over the variable steps."""
    net = chain_network(8, fixed_ends=True, radii=np.linspace(1e-3, 2e-3, 8))
    res = integrate(net, integrator, "auto", 0.5 * decay_time(net), rtol=1e-3)
    assert res.dt_max > 4 * res.dt_min
    C, free = net.particles.capacity, net.free
    gained = C[free] @ (res.T[free] - net.particles.temperature[free])
    assert gained == pytest.approx(res.heat_in["fixed"], rel=1e-11)
    assert gained > 0
    assert res.energy_error < 1e-12


def test_explicit_auto_stays_below_the_stable_limit():
    net = chain_network(6)
    limit = stable_limit(net)
    res = integrate(net, "explicit", "auto", 2000 * limit, rtol=1e-1)
    assert res.dt_max <= dem.network.heat.AUTO_SAFETY * limit * (1 + 1e-12)
    assert res.steps >= 2000 / dem.network.heat.AUTO_SAFETY - 1


def test_runs_beyond_max_steps_are_refused():
    net = chain_network(6)
    limit = stable_limit(net)
    with pytest.raises(ValueError, match="exceeds solver.max_steps"):  # explicit: refused up front
        integrate(net, "explicit", "auto", 1e4 * limit, max_steps=1000)
    for integrator in ("implicit", "crank-nicolson"):  # too tight a tolerance: stopped, not hanging
        with pytest.raises(ValueError, match="max_steps = 20 steps"):
            integrate(net, integrator, "auto", decay_time(net), rtol=1e-7, max_steps=20)


def test_step_tolerance_is_the_documented_rule():
    for q in (1, 2):
        for rtol in (1e-2, 1e-3, 1e-4):
            tau = dem.network.heat.step_tolerance(rtol, q)
            assert tau == pytest.approx(min(rtol, dem.network.heat.AUTO_LOCAL[q] * rtol ** ((q + 1) / q)))
            assert tau <= rtol
    assert math.isclose(dem.network.heat.step_tolerance(1.0, 1), 1.0)


def test_linear_auto_rule_and_jacobi_cg_at_its_condition_limit():
    """``linear = "auto"`` picks Jacobi-CG only where the diagonal-dominance bound guarantees convergence: a chain
    with conductances spread over 1e8 and ``C/dt`` at exactly the bound JACOBI_MAX_CONDITION still solves to the
    direct answer; without the capacity term (steady) the same chain goes to direct (small) or AMG (large)."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spl

    from dem.network.linsolve import DIRECT_MAX, JACOBI_MAX_CONDITION, JACOBI_MIN, choose_backend, make_solver

    rng = np.random.default_rng(3)
    for n in (JACOBI_MIN + 500, DIRECT_MAX + 500):
        K = 10.0 ** rng.uniform(-4, 4, n - 1)
        L = dem.network.heat.laplacian(n, np.arange(n - 1), np.arange(1, n), K).tocsr()
        L = (L + sp.diags(np.r_[K[0], np.zeros(n - 1)])).tocsr()  # first particle tied to a fixed one: SPD
        Ld = L.diagonal()
        assert choose_backend(L, Ld) == ("direct" if n <= DIRECT_MAX else "amg")
        C = rng.uniform(0.5, 2.0, n)
        rho = 2.0 / (JACOBI_MAX_CONDITION - 1.0) * 1.001  # just inside the bound
        inv_dt = rho * np.max(Ld / C)  # min_i (C_i/dt) / L_ii = rho: the bound is just JACOBI_MAX_CONDITION
        M = (L + sp.diags(C * inv_dt)).tocsr()
        assert choose_backend(M, Ld) == "cg"
        assert choose_backend((L + sp.diags(C * inv_dt / 1.01)).tocsr(), Ld) != "cg"
        b = rng.normal(size=n)
        x = make_solver(M, "auto", Ld, rtol=1e-10).solve(b)
        exact = spl.spsolve(M.tocsc(), b)
        assert np.linalg.norm(x - exact) <= 1e-7 * np.linalg.norm(exact)


def test_auto_cg_falls_back_when_it_cannot_converge():
    """Far outside the dominance bound (conductances over 1e8, tiny C/dt) Jacobi-CG cannot reach the residual
    target; the solver behind "auto" then hands the matrix to the fallback and still returns the right answer."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spl

    from dem.network.linsolve import AutoCGSolver

    rng = np.random.default_rng(3)
    n = 1500
    K = 10.0 ** rng.uniform(-4, 4, n - 1)
    L = dem.network.heat.laplacian(n, np.arange(n - 1), np.arange(1, n), K)
    M = (L + sp.diags(1e-8 * np.r_[1.0, rng.uniform(0.5, 2.0, n - 1)])).tocsr()
    b = rng.normal(size=n)
    solver = AutoCGSolver(M, rtol=1e-10, fallback="direct")
    x = solver.solve(b)
    assert solver.name == "direct"
    exact = spl.spsolve(M.tocsc(), b)
    assert np.linalg.norm(x - exact) <= 1e-5 * np.linalg.norm(exact)  # condition number ~1e12


def test_hopeless_tolerance_refused_early():
    """A tolerance that would need ~1e8 steps is refused after a hundred steps, not after max_steps."""
    net = chain_network(6)
    seen = []
    with pytest.raises(ValueError, match="far beyond solver.max_steps"):
        integrate(net, "implicit", "auto", 5 * decay_time(net), rtol=1e-9, max_steps=100_000,
                  observer=lambda step, t, T, flows: seen.append(step))
    assert len(seen) <= 1002


@pytest.mark.slow
def test_fixed_steps_land_on_t_end_without_an_extra_step():
    """t_end / dt = max_steps exactly: the run takes exactly max_steps steps (a running sum of dt used to add one
    more at the end and refuse the run there)."""
    net = chain_network(2)
    res = integrate(net, "implicit", dt=0.00033, t_end=3.3, max_steps=10_000)  # a running sum takes 10 001
    assert res.steps == 10_000 and res.t == 3.3
    assert res.factorizations == 1  # the last step is a full one: the same matrix


def test_auto_steps_are_capped_for_conditioning():
    """A free pair (no fixed temperature) run for 1e15 s: C/dt would fall ~1e-13 below the bond conductance and the
    heat balance drift (mean T 50 -> 49.95 at 1e12 s before the cap); now steps stop at 1e8 x the fastest time
    constant and a t_end that needs more than max_steps of them is refused at once, saying why."""
    net = chain_network(2)
    res = integrate(net, "implicit", dt="auto", t_end=1e9, rtol=1e-3, max_steps=100_000)
    assert abs(float(np.mean(res.T)) - 50.0) < 1e-4 and res.energy_error < 1e-6
    with pytest.raises(ValueError, match="steps are capped at .* fastest time constant"):
        integrate(chain_network(2), "implicit", dt="auto", t_end=1e15, rtol=1e-3, max_steps=100_000)
