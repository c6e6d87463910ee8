"""The network with mixed flux modes (dem.network.necks, "Flux modes"; dem.network.trefftz_element's ``where``): the
three-mode Trefftz element on some particles, the law's one-mode element on the others. ``where`` all is the
all-Trefftz network and ``where`` none the law's, bit for bit; a free chain with one Trefftz particle is the law's
chain; a mixed cell's k_eff is that of an independent flux formulation in which a neck carries only the modes both its
particles have; holding the dipoles flux-free on a growing mask lowers k_eff step by step; the heat balances with
walls, a fixed particle and sources; each neck has the nodes of its modes."""

import functools

import numpy as np
import pytest

from dem.geometry.bonds import find_bonds
from dem.geometry.particles import Particles
from dem.geometry.walls import Wall
from dem.laws.shared_body import ParticleElements, particle_elements
from dem.network.heat import integrate
from dem.network.necks import DIPOLE, NeckHeat, assembled, live_necks, neck_network, steady_necks
from dem.network.trefftz_element import trefftz_elements
from test_neck_modes import _cell, _coupled
from test_neck_nodes import NECKS, UNIT
from test_neck_transient import _random_packing

# Mixed modes put some particles on the Trefftz element, whose kernels take numba 25 s to compile in a fresh clone:
# the module runs with the slow tests.
pytestmark = pytest.mark.slow

HALF = np.random.default_rng(0).random(27) < 0.5  # the Trefftz particles of the mixed cell


def _network(where, seen=None):
    """The network of test_neck_modes' 27-sphere periodic cell with the Trefftz element on ``where`` (None: all),
    keeping the elements and their bonds in ``seen``."""
    particles, bonds, box = _cell()

    def build(*args, **kwargs):
        el = trefftz_elements(*args, **kwargs, where=where)
        if seen is not None:
            seen.update(el=el, bonds=args[2])
        return el

    return neck_network(NECKS, particles, bonds, box=box, elements=build)


@functools.lru_cache(maxsize=None)
def _all_trefftz():
    """The cell's network with the Trefftz element on every particle (``where`` None), built once."""
    return _network(None)


def _same(a, b):
    """Whether two networks are the same bit for bit: matrix, right-hand side, entries and the steady solution."""
    sa, sb = steady_necks(a), steady_necks(b)
    return (a.A.shape == b.A.shape and all(np.array_equal(getattr(a.A, f), getattr(b.A, f))
                                           for f in ("data", "indices", "indptr"))
            and np.array_equal(a.rhs, b.rhs) and all(np.array_equal(x, y) for x, y in zip(a.entries, b.entries))
            and np.array_equal(sa.T_necks, sb.T_necks) and np.array_equal(sa.periodic_heat_flow, sb.periodic_heat_flow))


def test_where_all_is_the_three_mode_network_and_where_none_the_laws_bit_for_bit():
    n = 27
    every = _network(np.ones(n, dtype=bool))
    assert every.modes == 3 and _same(every, _all_trefftz())
    particles, bonds, box = _cell()
    none = _network(np.zeros(n, dtype=bool))
    assert none.modes == 1 and _same(none, neck_network(NECKS, particles, bonds, box=box))


def _flux_formulation(particles, sub, box, el) -> float:
    """k_eff / kappa along z by the flux formulation, independent of the nodal assembly: per live bond the flows of
    the modes both its particles carry (the fewer: a mode one particle lacks carries nothing), minimising the
    complementary energy sum_k Q_k^T R_k Q_k / 2 (R_k the inverse of each element's modes block) less the work of the
    periodic jumps on the monopoles, under Kirchhoff's law at every centre."""
    n, m = particles.n, len(sub.i)
    M = np.broadcast_to(np.asarray(el.modes), (n,))
    both = np.minimum(M[sub.i], M[sub.j])
    at = np.concatenate([[0], np.cumsum(both)])
    H, C = np.zeros((at[-1], at[-1])), np.zeros((n, at[-1]))
    for k in range(n):
        ends = el.ends[el.offsets[k]:el.offsets[k + 1]]
        z, Mk = len(ends), M[k]
        if not z:
            continue
        R = np.linalg.inv(el.values[el.start[k]:el.start[k + 1]].reshape(Mk * z + 1, -1)[:-1, :-1])
        P = np.zeros((Mk * z, at[-1]))  # the particle's inflows from the flows
        for p, e in enumerate(ends):
            b, sign = (e, -1.0) if e < m else (e - m, 1.0)
            for d in range(both[b]):
                P[Mk * p + d, at[b] + d] = sign
        H += P.T @ R @ P
        C[k] = P[::Mk].sum(axis=0)
    g = np.zeros(at[-1])
    g[at[:-1]] = sub.shifts @ box.drop
    K = np.block([[H, C.T], [C, np.zeros((n, n))]])
    q = np.linalg.lstsq(K, np.concatenate([g, np.zeros(n)]), rcond=None)[0]
    return q[at[:-1]] @ sub.shifts[:, 2] * box.lengths[2] / box.cross_section(2)


def test_a_mixed_cell_against_the_flux_formulation_with_its_nodes_per_neck():
    """Half the particles on Trefftz: the nodal network's k_eff is the flux formulation's; each live bond has the
    nodes of the most modes of its two particles, one after another; a mixed neck's dipoles are seen by its Trefftz
    particle's element only; a floating cell keeps its mean temperature, shifted on the centres and monopoles only;
    and the mixture lies apart from both uniform networks (it is another network)."""
    particles, bonds, box = _cell()
    seen = {}
    net = _network(HALF, seen)
    sub, el = seen["bonds"], seen["el"]
    k = steady_necks(net).periodic_heat_flow[2] * box.lengths[2] / box.cross_section(2)
    assert k == pytest.approx(_flux_formulation(particles, sub, box, el), rel=1e-10)
    three = HALF[sub.i] | HALF[sub.j]
    assert 0 < three.sum() < len(three) and np.array_equal(net.bond_modes, np.where(three, 3, 1))
    assert net.n_nodes == particles.n + len(sub.i) + 2 * three.sum() == particles.n + net.bond_modes.sum()
    assert np.array_equal(np.diff(net.monopoles), net.bond_modes[:-1]) and net.monopoles[0] == particles.n
    row, col, value, known, end = net.entries
    dipole = (row >= particles.n) & (end == DIPOLE)
    assert np.all(HALF[net.owner[dipole]]) and np.any(dipole)
    mixed = three & ~(HALF[sub.i] & HALF[sub.j])
    assert np.any(mixed)
    # the floating cell at 300 K keeps its capacity-weighted mean, the shift moving centres and monopoles only (the
    # network's rows hold after it), and the flow across the period does not depend on the level
    warm = Particles.from_arrays(particles.position, particles.radius, np.full(particles.n, 300.0), materials=(UNIT,))
    hot = neck_network(NECKS, warm, bonds, box=box, elements=functools.partial(trefftz_elements, where=HALF))
    res = steady_necks(hot)
    T = np.concatenate([res.T, res.T_necks])
    assert np.average(res.T, weights=warm.capacity) == pytest.approx(300.0, rel=1e-12)
    assert np.max(np.abs(hot.A @ T - hot.rhs)) < 1e-10 * np.abs(hot.rhs).max()
    assert res.periodic_heat_flow[2] * box.lengths[2] / box.cross_section(2) == pytest.approx(k, rel=1e-10)
    k_all = steady_necks(_all_trefftz()).periodic_heat_flow[2] * box.lengths[2] / box.cross_section(2)
    k_law = steady_necks(neck_network(NECKS, particles, bonds, box=box)).periodic_heat_flow[2] * box.lengths[2] \
        / box.cross_section(2)
    assert min(abs(k / k_all - 1), abs(k / k_law - 1)) > 1e-4


def _condensed(E):
    """A three-mode element with its dipoles' flows held at zero: its Schur complement onto the monopoles and the
    centre, a one-mode element."""
    keep = np.append(np.arange(0, len(E) - 1, 3), len(E) - 1)
    drop = np.setdiff1d(np.arange(len(E)), keep)
    S = E[np.ix_(keep, keep)] - E[np.ix_(keep, drop)] @ np.linalg.solve(E[np.ix_(drop, drop)], E[np.ix_(drop, keep)])
    return 0.5 * (S + S.T)


def test_dipoles_held_flux_free_on_a_growing_mask_lower_k_eff_step_by_step():
    """The Trefftz element everywhere, condensed onto its monopoles (one mode) on the particles of a mask: a neck
    shared with a condensed particle keeps three modes, its dipoles flux-free (module docstring of
    dem.network.necks, "Flux modes"), which constrains the flux field, so by Thomson's principle k_eff falls as the
    mask grows, from the three-mode network's to the condensed one's, every mixture between. A mixture of two
    different elements has no such order (the verification guide, "Mixed flux modes": the law's element against
    exact ones)."""
    particles, bonds, box = _cell()
    necks = live_necks(NECKS, particles, bonds, box=box)
    el = trefftz_elements(*necks.arguments)
    three = [el.values[el.start[k]:el.start[k + 1]].reshape(3 * z + 1, -1) for k, z in enumerate(np.diff(el.offsets))]
    one = [_condensed(E) for E in three]

    def k_eff(mask):
        blocks = [(one[k] if mask[k] else three[k]).ravel() for k in range(particles.n)]
        mixed = el._replace(start=np.cumsum([0] + [len(b) for b in blocks]), values=np.concatenate(blocks),
                            modes=np.where(mask, 1, 3))
        net = assembled(necks, mixed)
        assert np.array_equal(net.bond_modes, np.where(mask[necks.arguments[2].i] & mask[necks.arguments[2].j], 1,
                                                       3))
        return steady_necks(net).periodic_heat_flow[2] * box.lengths[2] / box.cross_section(2)

    order = np.random.default_rng(3).permutation(particles.n)
    k = [k_eff(np.isin(np.arange(particles.n), order[:j])) for j in (0, 4, 9, 14, 19, 24, 27)]
    assert k[0] == pytest.approx(steady_necks(_all_trefftz()).periodic_heat_flow[2] * box.lengths[2]
                                 / box.cross_section(2), rel=1e-12)
    assert np.all(np.diff(k) < 0) and k[-1] < (1 - 1e-3) * k[0]


def _free_chain(n=5, q=0.5):
    """``n`` union spheres (radius 1 mm) along x with necks of a/r ``q``, the first held at 1, the last at 0: no
    walls (the Trefftz element has none)."""
    r = 1e-3
    d = 2 * np.sqrt(1 - q * q) * r
    fixed = np.zeros(n, dtype=bool)
    fixed[[0, -1]] = True
    T = np.zeros(n)
    T[0] = 1.0
    x = np.arange(n)[:, None] * [d, 0.0, 0.0]
    return Particles.from_arrays(x, np.full(n, r), T, materials=(UNIT,), fixed=fixed)


def test_a_free_chain_with_one_trefftz_particle_is_the_laws_chain():
    """The middle particle on Trefftz: its collinear necks' shifted monopoles are the law's halves (at a/r 0.5, a
    node of the shift table), its dipoles flux-free beside the law's neighbours, so temperatures and flows are the
    law's."""
    particles = _free_chain()
    bonds = find_bonds(particles, (), "union")
    where = np.zeros(particles.n, dtype=bool)
    where[2] = True
    law = steady_necks(neck_network(NECKS, particles, bonds))
    net = neck_network(NECKS, particles, bonds, elements=functools.partial(trefftz_elements, where=where))
    mixed = steady_necks(net)
    assert np.array_equal(net.bond_modes, [1, 3, 3, 1])
    assert np.max(np.abs(mixed.T - law.T)) < 1e-9
    assert mixed.bond_flow == pytest.approx(law.bond_flow, rel=1e-9)
    assert mixed.fixed_flow == pytest.approx(law.fixed_flow, rel=1e-9)
    assert law.bond_flow.min() > 0.0 and np.ptp(law.bond_flow) < 1e-12 * law.bond_flow.max()  # heat did flow along


def _mixed_hook(chosen):
    """The law's elements, those of ``chosen`` expanded to three modes with dipoles coupled to their monopoles
    (test_neck_modes' random SPD resistance), the others left with one."""
    def build(*args, **kwargs):
        el = particle_elements(*args, **kwargs)
        blocks, start = [], [0]
        for k in range(len(el.offsets) - 1):
            z = el.offsets[k + 1] - el.offsets[k]
            E1 = el.values[el.start[k]:el.start[k + 1]].reshape(z + 1, z + 1)
            blocks.append((_coupled(k, z, E1) if chosen[k] else E1).ravel())
            start.append(start[-1] + blocks[-1].size)
        return ParticleElements(el.offsets, el.ends, np.array(start), np.concatenate(blocks), el.plain, el.shrink,
                                np.where(chosen, 3, 1))
    return build


def test_heat_in_is_heat_out_with_mixed_modes_walls_a_fixed_particle_and_sources():
    """Steady: each particle passes on what it takes (its necks' and walls' monopole flows, its source and its fixed
    centre's feed sum to zero), what one side of a neck takes the other gives, the walls', fixed particle's and
    sources' flows sum to zero; transient: the heat stored is the heat that came in. Three modes on a wall's neck
    follow its particle."""
    one = _random_packing(heat=True)
    walls = (Wall("hot", point=[0.0, 0.0, 0.2e-3], normal=[0.0, 0.0, 1.0], temperature=1.0),  # _random_packing's
             Wall("cold", point=[0.0, 0.0, 3.8e-3], normal=[0.0, 0.0, -1.0], temperature=0.0))
    p = one.particles
    chosen = np.random.default_rng(2).random(p.n) < 0.5
    net = neck_network(NECKS, p, one.bonds, walls=walls, elements=_mixed_hook(chosen))
    sub = one.bonds.subset(net.live, net.live_walls)
    assert not np.isscalar(net.modes) and np.array_equal(net.bond_modes, np.where(chosen[sub.i] | chosen[sub.j], 3, 1))
    assert np.any(chosen[sub.wall_particle]) and np.any(~chosen[sub.wall_particle])
    res = steady_necks(net)
    T = np.concatenate([res.T, res.T_necks])
    Q = net.end_flows(T)
    m = len(net.live)
    scale = np.abs(Q).max()
    assert np.max(np.abs(Q[:m] + Q[m:2 * m])) < 1e-10 * scale
    into = np.bincount(np.concatenate([sub.i, sub.j, sub.wall_particle]), Q, p.n) + p.heat + res.fixed_flow
    assert np.max(np.abs(into)) < 1e-10 * scale
    boundary = np.concatenate([res.fixed_flow[p.fixed], -res.wall_flow, p.heat])
    assert abs(boundary.sum()) < 1e-10 * np.abs(boundary).sum() and res.energy_error < 1e-10
    assert np.max(np.abs(res.T_necks[np.setdiff1d(np.arange(len(res.T_necks)), net.monopoles - p.n)])) > 1e-3
    out = integrate(NeckHeat(net), "implicit", 2e-6, 4e-5)
    stored = float(p.capacity @ (out.T - p.temperature))
    assert abs(stored - sum(out.heat_in.values())) < 1e-12 * sum(abs(v) for v in out.heat_in.values())
    assert out.heat_in["walls"] != 0.0 and out.energy_error < 1e-12


def test_bad_modes_and_a_bad_where_are_refused_in_one_line():
    particles, bonds, box = _cell()
    n = particles.n
    for modes, message in ((np.ones(n - 1, dtype=int), r"modes has shape \(26,\): must be one number or one per "
                                                       r"particle \(27\)"),
                           (np.where(np.arange(n) == 4, 0, 1), "modes = 0: must be an integer >= 1 .*, particle 4")):
        with pytest.raises(ValueError, match=message) as err:
            neck_network(NECKS, particles, bonds, box=box,
                         elements=lambda *a, **k: particle_elements(*a, **k)._replace(modes=modes))
        assert "\n" not in str(err.value)
    for where in (np.ones(n - 1, dtype=bool), np.ones(n)):
        with pytest.raises(ValueError, match="where: .* must be a bool mask of the 27 particles") as err:
            neck_network(NECKS, particles, bonds, box=box, elements=functools.partial(trefftz_elements, where=where))
        assert "\n" not in str(err.value)
