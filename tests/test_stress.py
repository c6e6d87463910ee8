"""Stress cases at the edge of the models' range: neck geometry, degenerate FE geometries, DEM time steps around the
stable limit and extreme networks.

Each case must either answer correctly (to its stated accuracy, or against a closed form) or refuse with a clear
one-line ``ValueError`` -- never a silent NaN, a blow-up, a hang or a traceback. All are marked ``stress``; the long
ones also ``slow``: ``python -m pytest -m stress`` runs every one of them. The CLI abuse cases are in
``test_stress_cli.py``; the property-based (hypothesis) tests over random scenes in ``test_stability_properties.py``.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np
import pytest

from dem.laws.conductance import ConductanceSpec
from dem.geometry.particles import Material, Particles
from dem.network.heat import build_network, integrate, stable_limit, steady
from fem_neck import conduction
from fem_neck.geometry import max_overlap, neck_geometry, neck_radius, overlap_for_neck
from verification.cases import CONSTRICTION_LIMIT

pytestmark = pytest.mark.stress


def assert_one_line_value_error(fn, *needles) -> str:
    """``fn()`` raises a one-line ``ValueError`` whose message names every needle (case-insensitive)."""
    with pytest.raises(ValueError) as info:
        value = fn()
        pytest.fail(f"accepted, returned {value!r:.80}")
    msg = str(info.value)
    assert "\n" not in msg.strip(), msg
    for needle in needles:
        assert needle.lower() in msg.lower(), (needle, msg)
    return msg


# ---------------------------------------------------------------------------------------------------- neck geometry
@pytest.mark.parametrize("ratio", [1.0, 10.0, 100.0])
def test_neck_from_a_over_r_1e_minus_4_to_the_limit(ratio):
    r_i = 1e-3
    r_j = ratio * r_i
    a = r_i * np.concatenate([np.logspace(-4, 0, 81)[:-1], [1.0 - 1e-12, 1.0]])
    geo = neck_geometry(r_i, r_j, overlap_for_neck(r_i, r_j, a))
    err = np.abs(geo.a - a) / a
    assert np.all(np.isfinite(geo.a))
    assert err.max() < 1e-9, f"max rel error of a {err.max():.1e}"
    assert geo.volume_residual.max() < 1e-12
    assert np.all(geo.a <= min(r_i, r_j))


def test_neck_overlap_just_beyond_the_range():
    h_max = max_overlap(1e-3, 3e-3)
    assert_one_line_value_error(lambda: neck_radius(1e-3, 3e-3, h_max * (1 + 1e-9)), "h")


@pytest.mark.parametrize("args, needle", [
    ((float("nan"), 1e-3, 1e-5), "r_i"),
    ((1e-3, -1e-3, 1e-5), "r_j"),
    ((1e-3, 1e-3, 0.0), "h"),
    ((1e-3, 1e-3, float("inf")), "h"),
    ((np.full(100_000, 1e-3), np.full(100_000, 1e-3), np.r_[np.full(99_999, 1e-5), -1.0]), "h[99999]"),
], ids=["nan radius", "negative radius", "zero overlap", "infinite overlap", "one bad bond among 1e5"])
def test_neck_bad_input_is_named(args, needle):
    assert_one_line_value_error(lambda: neck_radius(*args), needle)


# --------------------------------------------------------------------------------------------- FE degenerate geometry
def assert_converged(res, rtol: float = 1e-4) -> None:
    assert res.converged and np.isfinite(res.K) and res.error_estimate <= rtol, (
        f"K/K_cyl = {res.K_over_Kcyl:.8g}, estimate {res.error_estimate:.1e} (rtol {rtol:g}), converged "
        f"{res.converged}, {res.dofs} dofs")


def solve_or_refuse(fn, rtol: float = 1e-4):
    """A converged result, or ``None`` when ``fn()`` refused with a ValueError that explains itself. A bare gmsh
    error ("Could not create line/arc", no reason given) fails."""
    try:
        res = fn()
    except ValueError:
        return None
    except RuntimeError as exc:
        msg = str(exc)
        assert "gmsh" in msg and not msg.rstrip().endswith(("Could not create line", "Could not create arc")), (
            f"{type(exc).__name__}: {msg} (not explained: why, what range)")
        return None
    assert_converged(res, rtol)
    return res


def test_fe_semisphere_neck_below_the_supported_range():
    assert_one_line_value_error(lambda: conduction.semisphere_conductance(5e-5, rtol=1e-4), "a_over_r")


@pytest.mark.parametrize("a", [1e-4, 3e-4, 1e-3])
def test_fe_semisphere_tiny_neck_tends_to_the_constriction_limit(a):
    res = solve_or_refuse(lambda: conduction.semisphere_conductance(a, rtol=1e-4))
    if res is not None:  # K -> 4 kappa a (isothermal disk on a half-space)
        ratio = res.K_over_Kcyl / (CONSTRICTION_LIMIT.value * a / math.pi)
        assert abs(ratio - 1) < 0.01, f"K / (4 kappa a) = {ratio:.5f}"


@pytest.mark.parametrize("a", [0.999, 0.999999])
def test_fe_semisphere_a_towards_r(a):
    res = solve_or_refuse(lambda: conduction.semisphere_conductance(a, rtol=1e-4))
    if res is not None:  # a = r: the body is a cylinder of height 2r/3, K/K_cyl = 1.5 exactly
        assert 1.3646 < res.K_over_Kcyl <= 1.5 * (1 + 1e-4), "between K(a/r=0.97) and the a = r limit 1.5"


def test_fe_semisphere_a_equal_to_r():
    res = solve_or_refuse(lambda: conduction.semisphere_conductance(1.0, rtol=1e-4))
    if res is not None:
        assert abs(res.K_over_Kcyl - 1.5) < 1e-4, "closed form 1.5"


@pytest.mark.parametrize("frac", [1 - 1e-6, 1.0])
def test_fe_unequal_pair_neck_near_the_smaller_radius(frac):
    r_i, r_j = 1e-3, 3e-3
    h_max = float(max_overlap(r_i, r_j))
    res = solve_or_refuse(lambda: conduction.pair_conductance(r_i, r_j, frac * h_max, 394.0, rtol=1e-4))
    if res is not None:
        assert res.necks[0] / r_i > 0.99, f"a/r_i = {res.necks[0] / r_i:.6f}"


def test_fe_pair_vanishing_overlap():
    solve_or_refuse(lambda: conduction.pair_conductance(1e-3, 1e-3, 1e-15, 394.0, rtol=1e-4))


def test_fe_pair_radius_ratio_100():
    solve_or_refuse(lambda: conduction.pair_conductance(1e-5, 1e-3, 0.5 * float(max_overlap(1e-5, 1e-3)), 394.0,
                                                        rtol=1e-3), rtol=1e-3)


# --------------------------------------------------------------------------------------------------------------- DEM
def lattice(shape, spacing=1e-4, seed=0, temperature=None, fixed=None, keep=None) -> Particles:
    """Particles on a cubic lattice, radii 0.52-0.6 spacing (every neighbour bonded, in the neck model's range)."""
    rng = np.random.default_rng(seed)
    grid = np.stack(np.meshgrid(*[np.arange(k) for k in shape], indexing="ij"), -1).reshape(-1, 3) * spacing
    if keep is not None:
        grid = grid[keep(grid / spacing)]
    n = len(grid)
    radius = spacing * rng.uniform(0.52, 0.6, n)
    temp = rng.uniform(0.0, 100.0, n) if temperature is None else temperature(grid / spacing)
    fix = None if fixed is None else fixed(grid / spacing)
    return Particles.from_arrays(grid, radius, temp, fixed=fix)


def hot_and_cold_layers(hot: float = 1.0):
    """``temperature`` and ``fixed`` of :func:`lattice`: bottom layer fixed at ``hot``, top layer at 0."""
    return {"temperature": lambda g: np.where(g[:, 2] == 0, hot, 0.0),
            "fixed": lambda g: (g[:, 2] == 0) | (g[:, 2] == g[:, 2].max())}


@pytest.fixture(scope="module")
def block():
    """An insulated 8 x 8 x 6 block with random temperatures, and its explicit stable limit."""
    net = build_network(lattice((8, 8, 6), seed=1))
    return net, stable_limit(net)


@pytest.mark.parametrize("factor", [
    pytest.param(0.5, marks=pytest.mark.slow), pytest.param(0.99, marks=pytest.mark.slow), 1.01, 2.0])
def test_dem_explicit_step_around_the_stable_limit(block, factor):
    """Below the limit the C-norm of the deviation from the mean never grows; above it the step is refused."""
    net, limit = block
    C = net.particles.capacity
    norms = []

    def observer(step, t, T, flows):
        dev = T - (C @ T) / C.sum()
        norms.append(float(np.sqrt(C @ dev**2)))

    if factor > 1:
        assert_one_line_value_error(lambda: integrate(net, "explicit", dt=factor * limit, t_end=300 * limit),
                                    "limit")
        return
    res = integrate(net, "explicit", dt=factor * limit, t_end=300 * limit, observer=observer)
    growth = max(np.diff(norms).max() / norms[0], 0.0)
    assert np.all(np.isfinite(res.T)) and growth <= 1e-12, f"largest growth per step {growth:.1e}"


def test_dem_explicit_auto_stays_below_the_limit(block):
    net, limit = block
    res = integrate(net, "explicit", dt="auto", t_end=300 * limit)
    T0 = net.particles.temperature
    assert np.all(np.isfinite(res.T)) and res.dt_max <= limit
    assert res.T.min() >= T0.min() - 1e-9 and res.T.max() <= T0.max() + 1e-9  # maximum principle


@pytest.mark.parametrize("shape", [(10, 10, 10), pytest.param((60, 60, 30), marks=pytest.mark.slow)],
                         ids=["direct backend", "iterative backend"])
def test_dem_steady_conductance_contrast_1e8(shape):
    import scipy.sparse.linalg as spl

    particles = lattice(shape, seed=2, **hot_and_cold_layers(100.0))
    rng = np.random.default_rng(3)
    net = build_network(particles)
    net = replace(net, K_pairs=net.K_pairs * 10.0 ** (8.0 * rng.random(len(net.K_pairs))))
    res = steady(net)
    A, b = net.matrix({}), net.rhs({})
    x = res.T[net.free]
    if particles.n <= 20_000:  # independent direct solve
        err = float(np.max(np.abs(x - spl.spsolve(A.tocsc(), b))))
    else:  # too large for a direct reference: the residual, scaled by the diagonal
        err = float(np.max(np.abs(A @ x - b) / A.diagonal()))
    assert err <= 1e-6 * 100, f"solver {res.solver}: error {err:.2e} K"
    assert res.T.min() >= -1e-9 and res.T.max() <= 100 + 1e-9


def test_dem_chain_with_conductivity_contrast_1e8_is_the_series_solution():
    mats = (Material(394.0, 8960.0, 385.0, "copper"), Material(394e-8, 8960.0, 385.0, "insulator"))
    pos = np.array([[0, 0, 0], [0, 0, 1.9e-4], [0, 0, 3.8e-4], [0, 0, 5.7e-4]])
    particles = Particles.from_arrays(pos, np.full(4, 1e-4), [100.0, 0, 0, 0.0], materials=mats,
                                      material=[0, 1, 0, 0], fixed=[True, False, False, True])
    net = build_network(particles)
    res = steady(net)
    q = 100.0 / np.sum(1.0 / net.K_pairs)
    drop = 100.0 - np.cumsum(q / net.K_pairs)[:-1]
    err = float(np.max(np.abs(res.T[1:3] - drop)) / 100.0)
    assert net.K_pairs.max() / net.K_pairs.min() > 1e7
    assert err < 1e-9, f"max relative error of the free temperatures against the series solution {err:.1e}"


@pytest.mark.parametrize("integrator", ["explicit", "implicit", "crank-nicolson"])
def test_dem_particles_without_bonds_keep_their_temperature(integrator):
    block = lattice((3, 3, 3), seed=4)
    lone = np.array([[1e-2, 0, 0], [2e-2, 0, 0], [3e-2, 0, 0]])
    particles = Particles.from_arrays(np.vstack([block.position, lone]), np.r_[block.radius, [5e-5] * 3],
                                      np.r_[block.temperature, [500.0, -20.0, 7.0]])
    res = integrate(build_network(particles), integrator, dt="auto", t_end=1e-2)
    T0 = particles.temperature
    assert np.allclose(res.T[-3:], T0[-3:], rtol=4 * np.finfo(float).eps, atol=0.0)
    assert res.energy_error < 1e-10


@pytest.mark.parametrize("with_fixed", [True, False], ids=["each with fixed T", "one without fixed T"])
def test_dem_disconnected_clusters_steady(with_fixed):
    keep = lambda g: g[:, 0] != 3  # noqa: E731  two blocks of 3 x 3 x 3, no bond between them
    if with_fixed:
        fixed = lambda g: (g[:, 2] == 0) | (g[:, 2] == 2)  # noqa: E731
    else:
        fixed = lambda g: ((g[:, 2] == 0) | (g[:, 2] == 2)) & (g[:, 0] < 3)  # noqa: E731
    temperature = lambda g: np.where(g[:, 2] == 0, 10.0, 0.0) + np.where(g[:, 0] > 3, 50.0, 0.0)  # noqa: E731
    particles = lattice((7, 3, 3), keep=keep, seed=5, temperature=temperature, fixed=fixed)
    net = build_network(particles)
    if not with_fixed:
        msg = assert_one_line_value_error(lambda: steady(net), "singular", "connected group")
        assert "floating" in msg  # says what to do
        return
    res = steady(net)
    right = particles.position[:, 0] > 3.5e-4
    assert res.T[right].min() >= 50 - 1e-9 and res.T[~right].max() <= 10 + 1e-9


def test_dem_steady_energy_error_with_hot_and_cold_layers():
    res = steady(build_network(lattice((4, 4, 6), seed=6, **hot_and_cold_layers())))
    assert res.energy_error < 1e-8, res.flows


@pytest.mark.slow
@pytest.mark.parametrize("shape", [(30, 30, 30), (64, 64, 64)])
def test_dem_duplicate_and_reversed_bonds(shape):
    particles = lattice(shape, seed=7, **hot_and_cold_layers())
    base = build_network(particles)
    i, j = base.bonds.i, base.bonds.j
    extra = np.random.default_rng(8).integers(0, len(i), len(i) // 2)
    t0 = time.perf_counter()
    dup = build_network(particles, pairs=(np.concatenate([i, j, i[extra]]), np.concatenate([j, i, j[extra]])))
    seconds = time.perf_counter() - t0
    assert dup.bonds.n_pairs == base.bonds.n_pairs, f"{dup.bonds.n_pairs} bonds from {base.bonds.n_pairs} unique"
    dT = float(np.max(np.abs(steady(dup).T - steady(base).T)))
    assert dT < 1e-9, f"steady T differs by {dT:.1e} ({seconds:.1f} s to build)"


def test_dem_pair_radius_ratio_100_decays_as_the_closed_form():
    r_i, r_j = 1e-5, 1e-3
    h = 0.3 * float(max_overlap(r_i, r_j))
    particles = Particles.from_arrays([[0, 0, 0], [0, 0, r_i + r_j - h]], [r_i, r_j], [100.0, 0.0])
    net = build_network(particles, spec=ConductanceSpec("rojek"))
    C = particles.capacity
    rate = net.K_pairs[0] * (1 / C[0] + 1 / C[1])
    t_end = 3.0 / rate
    for integrator in ("explicit", "implicit", "crank-nicolson"):
        res = integrate(net, integrator, dt="auto", t_end=t_end)
        diff = (res.T[0] - res.T[1]) / 100.0
        assert abs(diff - np.exp(-rate * t_end)) < 2e-2, integrator
        assert res.energy_error < 1e-10, integrator
