"""Property-based stress tests of the pipe-network DEM over random scenes.

Scenes: particles on a cubic lattice of spacing s with random radii in [0.52 s, 0.6 s], so every lattice neighbour
overlaps by 0.04 s .. 0.2 s (inside the neck model's range) and no diagonal pair touches; random vacancies split the
packing into clusters and leave isolated particles. Properties that must hold for every such scene:

* energy conservation: an insulated transient keeps sum C_i T_i to round-off (every integrator);
* maximum principle: without sources, backward Euler and the steady solve never leave the range of the initial and
  fixed temperatures (the network matrix is an M-matrix);
* the network matrix is symmetric, its Laplacian has zero row sums and is positive semidefinite, and it is positive
  definite once every cluster touches a fixed particle;
* independence from particle ordering: a permuted scene gives the permuted temperatures.
"""

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from dem.laws.conductance import ConductanceSpec
from dem.geometry.particles import Particles
from dem.network.heat import Network, build_network, integrate, stable_limit, steady

SPACING = 1e-4  # m
pytestmark = pytest.mark.stress


def make_network(seed: int, shape, vacancy: float, n_fixed: int, law: str = "rojek", order=None) -> Network:
    rng = np.random.default_rng(seed)
    grid = np.stack(np.meshgrid(*[np.arange(k) for k in shape], indexing="ij"), -1).reshape(-1, 3) * SPACING
    keep = rng.random(len(grid)) >= vacancy
    keep[0] = True
    pos = grid[keep]
    n = len(pos)
    radius = SPACING * rng.uniform(0.52, 0.6, n)
    temperature = rng.uniform(-50.0, 150.0, n)
    fixed = np.zeros(n, dtype=bool)
    fixed[rng.choice(n, size=min(n_fixed, n), replace=False)] = True
    particles = Particles.from_arrays(pos, radius, temperature, fixed=fixed)
    if order is not None:
        particles = particles.permuted(order(n))
    return build_network(particles, spec=ConductanceSpec(law=law))


scenes = st.fixed_dictionaries({
    "seed": st.integers(0, 2**31 - 1),
    "shape": st.tuples(st.integers(1, 5), st.integers(1, 5), st.integers(1, 4)),
    "vacancy": st.sampled_from([0.0, 0.1, 0.3, 0.5]),
})
FAST = settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@FAST
@given(scene=scenes, integrator=st.sampled_from(["explicit", "implicit", "crank-nicolson"]))
def test_insulated_transient_conserves_energy(scene, integrator):
    net = make_network(**scene, n_fixed=0)
    limit = stable_limit(net)
    dt = 0.5 * limit if np.isfinite(limit) else 1e-3
    res = integrate(net, integrator, dt=dt, t_end=20 * dt)
    C = net.particles.capacity
    e0, e1 = C @ net.particles.temperature, C @ res.T
    assert abs(e1 - e0) <= 1e-11 * (C @ np.abs(net.particles.temperature))
    assert res.energy_error <= 1e-10


@FAST
@given(scene=scenes, n_fixed=st.integers(0, 3))
def test_backward_euler_keeps_the_maximum_principle(scene, n_fixed):
    net = make_network(**scene, n_fixed=n_fixed)
    T0 = net.particles.temperature
    limit = stable_limit(net)
    dt = 50 * limit if np.isfinite(limit) else 1e-3  # far beyond the explicit limit
    res = integrate(net, "implicit", dt=dt, t_end=10 * dt)
    slack = 1e-9 * (T0.max() - T0.min()) + 1e-13 * np.abs(T0).max()  # round-off
    assert res.T.min() >= T0.min() - slack
    assert res.T.max() <= T0.max() + slack


@FAST
@given(scene=scenes, n_fixed=st.integers(1, 4))
def test_steady_within_fixed_range_or_explained(scene, n_fixed):
    net = make_network(**scene, n_fixed=n_fixed)
    try:
        res = steady(net)
    except ValueError as exc:  # some cluster has no fixed particle: must say so
        assert "singular" in str(exc) and "fix" in str(exc)
        res = steady(net, floating="mean")
        free_ok = np.isfinite(res.T).all()
        assert free_ok
        return
    fixed_T = net.particles.temperature[net.particles.fixed]
    span = max(fixed_T.max() - fixed_T.min(), 1.0)
    assert res.T.min() >= fixed_T.min() - 1e-8 * span
    assert res.T.max() <= fixed_T.max() + 1e-8 * span
    flow_scale = float(net.K_pairs.sum()) * span
    assert abs(sum(res.flows.values())) <= 1e-10 * flow_scale  # energy balance


def test_steady_energy_error_without_heat_flow():
    net = make_network(seed=0, shape=(1, 1, 4), vacancy=0.0, n_fixed=1)
    assert steady(net).energy_error < 1e-8


@FAST
@given(scene=scenes, n_fixed=st.integers(0, 3))
def test_network_matrix_symmetric_semidefinite(scene, n_fixed):
    net = make_network(**scene, n_fixed=n_fixed)
    L = net.L.toarray()
    assert np.allclose(L, L.T, rtol=0, atol=0)
    assert np.allclose(L.sum(axis=1), 0.0, atol=1e-12 * np.abs(L).max(initial=1.0))
    eig = np.linalg.eigvalsh(L)
    assert eig.min() >= -1e-10 * max(eig.max(), 1e-300)
    A = net.matrix(net.sinks(net.particles.temperature[net.free])).toarray()
    assert np.array_equal(A, A.T)
    if A.size:
        eig_a = np.linalg.eigvalsh(A)
        assert eig_a.min() >= -1e-10 * max(eig_a.max(), 1e-300)


@FAST
@given(scene=scenes)
def test_anchored_network_matrix_positive_definite(scene):
    # fix every particle of the first lattice layer x = 0, then anchor the clusters that miss it by fixing one
    # particle of each: the free block must be positive definite
    net = make_network(**scene, n_fixed=0)
    from scipy.sparse.csgraph import connected_components

    n_comp, label = connected_components(net.L, directed=False)
    first = np.array([np.flatnonzero(label == c)[0] for c in range(n_comp)])
    p = net.particles
    fixed = np.zeros(p.n, dtype=bool)
    fixed[first] = True
    assume(not fixed.all())
    p2 = Particles.from_arrays(p.position, p.radius, p.temperature, fixed=fixed)
    net2 = replace(net, particles=p2)
    A = net2.matrix(net2.sinks(p2.temperature[net2.free])).toarray()
    assert np.linalg.eigvalsh(A).min() > 0


@FAST
@given(scene=scenes, n_fixed=st.integers(1, 3), integrator=st.sampled_from(["implicit", "crank-nicolson"]))
def test_particle_order_independence(scene, n_fixed, integrator):
    perm_seed = scene["seed"] + 1

    def order(n):
        return np.random.default_rng(perm_seed).permutation(n)

    net = make_network(**scene, n_fixed=n_fixed)
    net_p = make_network(**scene, n_fixed=n_fixed, order=order)
    perm = order(net.particles.n)
    dt = 1e-4
    a = integrate(net, integrator, dt=dt, t_end=5 * dt).T
    b = integrate(net_p, integrator, dt=dt, t_end=5 * dt).T
    span = np.ptp(net.particles.temperature) + 1.0
    assert np.max(np.abs(a[perm] - b)) <= 1e-9 * span
    try:
        s_a = steady(net).T
    except ValueError:
        return
    s_b = steady(net_p).T
    assert np.max(np.abs(s_a[perm] - s_b)) <= 1e-9 * span


@pytest.mark.parametrize("factor, refused", [(0.5, False), (0.99, False), (1.01, True), (2.0, True)])
def test_explicit_step_against_the_stable_limit(factor, refused):
    """Below the limit the C-norm of the deviation from the mean never grows; above it the run is refused."""
    net = make_network(seed=3, shape=(6, 6, 4), vacancy=0.1, n_fixed=0)
    limit = stable_limit(net)
    if refused:
        with pytest.raises(ValueError, match="stability limit"):
            integrate(net, "explicit", dt=factor * limit, t_end=400 * limit)
        return
    C = net.particles.capacity
    norms = []

    def observer(step, t, T, flows):
        dev = T - (C @ T) / C.sum()
        norms.append(float(np.sqrt(C @ dev**2)))

    integrate(net, "explicit", dt=factor * limit, t_end=400 * limit, observer=observer)
    assert np.all(np.diff(norms) <= 1e-12 * norms[0])
