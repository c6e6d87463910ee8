"""The network with several flux modes per neck (dem.network.necks, "Flux modes"): with the dipoles uncoupled from
the monopoles it is the one-mode network (steady, its flows and the transient); with them coupled its k_eff is that
of an independent dense solve of the flux formulation (Kirchhoff's laws on the neck flows, each particle's
complementary energy), its heat balances, a turn of a bond's dipole frame changes nothing, and a wrong element shape
is refused in one line."""

import functools

import numpy as np
import pytest

from dem.geometry.bonds import find_bonds
from dem.geometry.particles import Particles
from dem.geometry.periodic import PeriodicBox
from dem.geometry.walls import Wall
from dem.laws.shared_body import ParticleElements, particle_elements
from dem.network.heat import integrate
from dem.network.necks import DIPOLE, NeckHeat, neck_frames, neck_network, steady_necks
from test_neck_nodes import NECKS, UNIT
from test_neck_transient import _random_packing

MODES = 3


def _bordered(R: np.ndarray, modes: int) -> np.ndarray:
    """The element of resistance ``R`` over ``modes`` modes per neck, bordered by the centre on the monopoles."""
    Y = np.linalg.inv(R)
    Y = 0.5 * (Y + Y.T)
    e = np.zeros(len(R))
    e[::modes] = 1.0
    Ye = Y @ e
    return np.block([[Y, -Ye[:, None]], [-Ye[None, :], np.array([[e @ Ye]])]])


def _expand(el: ParticleElements, dipoles) -> ParticleElements:
    """The one-mode elements ``el`` with two dipoles per neck: ``dipoles(k, z)`` gives particle k's (3 z x 3 z)
    resistance given its one-mode one (None: the dipoles uncoupled, an SPD block of their own)."""
    blocks, start = [], [0]
    for k in range(len(el.offsets) - 1):
        z = el.offsets[k + 1] - el.offsets[k]
        E1 = el.values[el.start[k]:el.start[k + 1]].reshape(z + 1, z + 1)
        E3 = dipoles(k, z, E1)
        blocks.append(E3.ravel())
        start.append(start[-1] + E3.size)
    return ParticleElements(el.offsets, el.ends, np.array(start), np.concatenate(blocks), el.plain, el.shrink, MODES)


def _uncoupled(k, z, E1):
    """The one-mode element on the monopoles and the centre, an SPD block on the dipoles alone."""
    if z == 0:
        return E1
    rng = np.random.default_rng(k)
    scale = np.mean(np.diag(E1)[:z])
    B = rng.normal(size=(2 * z, 2 * z))
    D = scale * (B @ B.T / (2 * z) + np.eye(2 * z))
    E3 = np.zeros((3 * z + 1, 3 * z + 1))
    mono = np.append(np.arange(0, 3 * z, 3), 3 * z)
    dip = np.setdiff1d(np.arange(3 * z), mono)
    E3[np.ix_(mono, mono)] = E1
    E3[np.ix_(dip, dip)] = D
    return E3


def _coupled(k, z, E1):
    """A random SPD resistance over the 3 z modes whose monopole block is the one-mode element's, coupled to the
    dipoles."""
    if z == 0:
        return E1
    rng = np.random.default_rng(100 + k)
    Y1 = E1[:z, :z]
    R1 = np.linalg.inv(Y1)
    B = rng.normal(size=(3 * z, 3 * z))
    R = np.mean(np.diag(R1)) * (B @ B.T / (3 * z) + 0.5 * np.eye(3 * z))
    R[::3, ::3] += R1
    return _bordered(R, MODES)


def _hook(dipoles):
    def build(*args, **kwargs):
        return _expand(particle_elements(*args, **kwargs), dipoles)
    return build


@functools.lru_cache(maxsize=None)
def _cell():
    """A periodic cell of 27 overlapping spheres (radii 0.9-1.1 mm) jittered about a simple cubic lattice of 1.75 mm,
    read as their union; a drop of 1 K per period along z."""
    rng = np.random.default_rng(1)
    d = 1.75e-3
    x = (np.stack(np.meshgrid(*[np.arange(3)] * 3, indexing="ij"), -1).reshape(-1, 3) + 0.5) * d
    x += rng.uniform(-0.1e-3, 0.1e-3, x.shape)
    box = PeriodicBox(np.full(3, 3 * d), drop=[0.0, 0.0, 1.0])
    particles = Particles.from_arrays(x, rng.uniform(0.9e-3, 1.1e-3, 27), np.zeros(27), materials=(UNIT,))
    return particles, find_bonds(particles, contact=NECKS.contact, box=box), box


def test_uncoupled_dipoles_are_the_one_mode_network_with_walls_fixed_particles_and_sources():
    one = _random_packing(heat=True)
    particles, bonds = one.particles, one.bonds
    walls = (Wall("hot", point=[0.0, 0.0, 0.2e-3], normal=[0.0, 0.0, 1.0], temperature=1.0),  # _random_packing's
             Wall("cold", point=[0.0, 0.0, 3.8e-3], normal=[0.0, 0.0, -1.0], temperature=0.0))
    three = neck_network(NECKS, particles, bonds, walls=walls, elements=_hook(_uncoupled))
    assert three.modes == MODES and three.n_nodes == particles.n + MODES * len(three.live)
    a, b = steady_necks(one), steady_necks(three)
    scale = np.abs(a.bond_flow).max()
    for key in ("bond_flow", "wall_flow", "fixed_flow"):
        assert np.max(np.abs(getattr(b, key) - getattr(a, key))) < 1e-12 * scale
    assert np.max(np.abs(b.T - a.T)) < 1e-12 and b.energy_error < 1e-12
    necks = b.T_necks.reshape(-1, MODES)
    assert np.max(np.abs(necks[:, 0] - a.T_necks)) < 1e-12 and np.max(np.abs(necks[:, 1:])) < 1e-12
    assert np.max(np.abs(a.T - a.T.mean())) > 0.1  # heat did flow: the comparison is not of constants
    for integrator in ("implicit", "crank-nicolson"):
        runs = []
        for net in (one, three):
            heat, seen = NeckHeat(net), []
            res = integrate(heat, integrator, 2e-6, 4e-5, observer=lambda s, t, T, f: seen.append(heat.full(T)))
            runs.append((np.array(seen), res))
        assert runs[0][0].shape == runs[1][0].shape and np.max(np.abs(runs[1][0] - runs[0][0])) < 1e-12
        for key in ("fixed", "walls"):
            assert runs[1][1].heat_in[key] == pytest.approx(runs[0][1].heat_in[key], rel=1e-10)
        assert runs[1][1].energy_error < 1e-10


def test_uncoupled_dipoles_are_the_one_mode_network_across_the_period():
    particles, bonds, box = _cell()
    one = steady_necks(neck_network(NECKS, particles, bonds, box=box))
    three = steady_necks(neck_network(NECKS, particles, bonds, box=box, elements=_hook(_uncoupled)))
    assert np.max(np.abs(three.periodic_heat_flow - one.periodic_heat_flow)) < 1e-12 * one.periodic_heat_flow[2]
    # the floating cell keeps its capacity-weighted mean: the shift moves centres and monopoles, not the dipoles
    assert np.max(np.abs(three.T - one.T)) < 1e-12
    assert np.max(np.abs(three.T_necks.reshape(-1, MODES)[:, 1:])) < 1e-12


def _flux_formulation(particles, bonds, box, el: ParticleElements, modes: int) -> float:
    """k_eff / kappa along z by the flux formulation, independent of the nodal assembly: the neck flows q (``modes``
    per live bond, into ``j``, out of ``i``) minimise the complementary energy sum_k Q_k^T R_k Q_k / 2 (R_k the
    inverse of each element's neck block) less the work of the periodic jumps on the monopoles, under Kirchhoff's
    law at every centre (the monopoles' flows into a particle sum to zero)."""
    n, m = particles.n, len(bonds.i)
    jump = bonds.shifts @ box.drop
    H = np.zeros((modes * m, modes * m))
    C = np.zeros((n, modes * m))
    for k in range(n):
        ends = el.ends[el.offsets[k]:el.offsets[k + 1]]
        z = len(ends)
        if not z:
            continue
        Y = el.values[el.start[k]:el.start[k + 1]].reshape(modes * z + 1, modes * z + 1)[:-1, :-1]
        R = np.linalg.inv(Y)
        P = np.zeros((modes * z, modes * m))  # the particle's inflows from q
        for p, e in enumerate(ends):
            b, sign = (e, -1.0) if e < m else (e - m, 1.0)
            for d in range(modes):
                P[modes * p + d, modes * b + d] = sign
        H += P.T @ R @ P
        C[k] = P[::modes].sum(axis=0)
    g = np.zeros(modes * m)
    g[::modes] = jump  # j sees its neck jump higher: the work of the flow into j
    K = np.block([[H, C.T], [C, np.zeros((n, n))]])
    q = np.linalg.lstsq(K, np.concatenate([g, np.zeros(n)]), rcond=None)[0][:modes * m]
    heat = q[::modes] @ bonds.shifts[:, 2]
    return heat * box.lengths[2] / box.cross_section(2)


def test_coupled_dipoles_against_the_flux_formulation_and_the_heat_balance():
    particles, bonds, box = _cell()
    seen = {}

    def build(*args, **kwargs):
        seen["bonds"] = args[2]
        seen["el"] = _expand(particle_elements(*args, **kwargs), _coupled)
        return seen["el"]

    net = neck_network(NECKS, particles, bonds, box=box, elements=build)
    res = steady_necks(net)
    k_nodes = res.periodic_heat_flow[2] * box.lengths[2] / box.cross_section(2)
    sub = seen["bonds"]
    k_flux = _flux_formulation(particles, sub, box, seen["el"], MODES)
    assert k_nodes == pytest.approx(k_flux, rel=1e-10)
    one = steady_necks(neck_network(NECKS, particles, bonds, box=box))
    assert abs(k_nodes / (one.periodic_heat_flow[2] * box.lengths[2] / box.cross_section(2)) - 1) > 1e-3  # coupled
    # the heat balance: every particle passes on what it takes (the monopoles), and the dipoles' moments move
    T = np.concatenate([res.T, res.T_necks])
    Q = net.end_flows(T)
    m = len(net.live)
    assert np.max(np.abs(Q[:m] + Q[m:2 * m])) < 1e-12 * np.abs(Q).max()
    into = np.bincount(np.concatenate([sub.i, sub.j]), Q[:2 * m], particles.n)
    assert np.max(np.abs(into)) < 1e-10 * np.abs(Q).max()
    assert np.max(np.abs(res.T_necks.reshape(-1, MODES)[:, 1:])) > 1e-3 * np.ptp(res.T)
    row, col, value, known, end = net.entries
    assert np.any(end == DIPOLE) and not np.any(end[row < particles.n] == DIPOLE)


def test_a_turn_of_a_bonds_dipole_frame_changes_nothing():
    """Turning bond b's frame by an angle turns its dipole modes in both particles' elements alike: the monopoles'
    solution is the same; turning it in one particle only (frames that differ across the face) is not."""
    particles, bonds, box = _cell()
    seen = {}

    def base(*args, **kwargs):
        seen["el"] = _expand(particle_elements(*args, **kwargs), _coupled)
        return seen["el"]

    k0 = steady_necks(neck_network(NECKS, particles, bonds, box=box, elements=base)).periodic_heat_flow[2]
    el = seen["el"]
    m = len(el.ends) // 2  # the cell has no walls: its ends are 2 m
    angle = 0.7
    c, s = np.cos(angle), np.sin(angle)
    turn = np.array([[c, -s], [s, c]])

    def turned(both):
        values = el.values.copy()
        for k in range(len(el.offsets) - 1):
            ends = el.ends[el.offsets[k]:el.offsets[k + 1]]
            z = len(ends)
            Cm = np.eye(3 * z + 1)
            for p, e in enumerate(ends):
                if e == 0 or (both and e == m):  # bond 0 on its i, and on its j where both turn
                    Cm[3 * p + 1:3 * p + 3, 3 * p + 1:3 * p + 3] = turn
            block = values[el.start[k]:el.start[k + 1]].reshape(3 * z + 1, 3 * z + 1)
            values[el.start[k]:el.start[k + 1]] = (Cm @ block @ Cm.T).ravel()
        return ParticleElements(el.offsets, el.ends, el.start, values, el.plain, el.shrink, MODES)

    k_both = steady_necks(neck_network(NECKS, particles, bonds, box=box,
                                       elements=lambda *a, **k: turned(True))).periodic_heat_flow[2]
    k_one = steady_necks(neck_network(NECKS, particles, bonds, box=box,
                                      elements=lambda *a, **k: turned(False))).periodic_heat_flow[2]
    assert k_both == pytest.approx(k0, rel=1e-12)
    assert abs(k_one / k0 - 1) > 1e-6


def test_the_frames_are_the_bonds_not_the_particles():
    rng = np.random.default_rng(5)
    u = rng.normal(size=(50, 3))
    u[0] = [1.0, 0.0, 0.0]
    u[1] = [0.0, 0.0, -2.0]
    F = neck_frames(u)
    unit = u / np.linalg.norm(u, axis=1)[:, None]
    assert np.allclose(np.einsum("mij,mkj->mik", F, F), np.eye(2))  # orthonormal
    assert np.max(np.abs(np.einsum("mij,mj->mi", F, unit))) < 1e-12  # in the neck's plane
    assert np.allclose(np.cross(F[:, 0], F[:, 1]), unit)  # right-handed about i -> j


def test_a_wrong_element_shape_is_refused_in_one_line():
    particles, bonds, box = _cell()

    def short(*args, **kwargs):
        el = particle_elements(*args, **kwargs)
        return ParticleElements(el.offsets, el.ends, el.start, el.values, el.plain, el.shrink, MODES)

    with pytest.raises(ValueError, match=r"elements: particle 0 has \d+ values; with \d+ necks and modes = 3") as err:
        neck_network(NECKS, particles, bonds, box=box, elements=short)
    assert "\n" not in str(err.value)
    with pytest.raises(ValueError, match="modes = 0"):
        neck_network(NECKS, particles, bonds, box=box,
                     elements=lambda *a, **k: particle_elements(*a, **k)._replace(modes=0))


def test_the_current_refuses_dipoles():
    from dem.network.current import Electrodes
    from dem.network.necks import neck_current

    particles, bonds, box = _cell()
    net = neck_network(NECKS, particles, bonds, box=box, elements=_hook(_uncoupled))
    with pytest.raises(ValueError, match="neck_current: modes = 3"):
        neck_current(net, (), Electrodes((), (), np.zeros(0), np.zeros(0)))


def test_heat_in_is_heat_out_with_coupled_dipoles_walls_fixed_particles_and_sources():
    """Steady: the walls', the fixed particle's and the sources' flows sum to zero and every neck passes on what it
    takes; transient: the heat stored is the heat that came in (the dipoles' rows hold no heat and carry none)."""
    one = _random_packing(heat=True)
    walls = (Wall("hot", point=[0.0, 0.0, 0.2e-3], normal=[0.0, 0.0, 1.0], temperature=1.0),  # _random_packing's
             Wall("cold", point=[0.0, 0.0, 3.8e-3], normal=[0.0, 0.0, -1.0], temperature=0.0))
    net = neck_network(NECKS, one.particles, one.bonds, walls=walls, elements=_hook(_coupled))
    res = steady_necks(net)
    p = net.particles
    into = np.concatenate([res.fixed_flow[p.fixed], -res.wall_flow, p.heat])
    assert abs(into.sum()) < 1e-10 * np.abs(into).sum() and res.energy_error < 1e-10
    Q = net.end_flows(np.concatenate([res.T, res.T_necks]))
    m = len(net.live)
    assert np.max(np.abs(Q[:m] + Q[m:2 * m])) < 1e-10 * np.abs(Q).max()
    assert np.max(np.abs(res.T_necks.reshape(-1, MODES)[:, 1:])) > 1e-3  # the dipoles did move
    out = integrate(NeckHeat(net), "implicit", 2e-6, 4e-5)
    stored = float(p.capacity @ (out.T - p.temperature))
    assert abs(stored - sum(out.heat_in.values())) < 1e-12 * sum(abs(v) for v in out.heat_in.values())
    assert out.heat_in["walls"] != 0.0 and out.energy_error < 1e-12
