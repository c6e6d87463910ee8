"""The tuned smoothed-aggregation AMG (dem.network.linsolve.AMGSolver): the criterion on a packing and on a lattice
checked against sparse LU, its hierarchy reused across refreshes and radiation's Newton and time steps with the same
answer as a fresh one, and the benchmark's PETSc rows left out cleanly without petsc4py."""

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spl

from benchmarks.amg_peers import PreviousAMG
from dem.laws.conductance import ConductanceSpec
from dem.network.linsolve import AMG_REUSE_GROWTH, AMGSolver, make_solver

# The compiled multigrid's setup and cycle kernels take numba 30 s to compile in a fresh clone, and no quick test
# solves a network large enough to need them: the module runs with the slow tests.
pytestmark = pytest.mark.slow

RTOL = 1e-10  # dem.network.heat.steady's criterion


def packing_system(n=8000, seed=3):
    """The steady matrix and right-hand side of a random sintered packing between a hot and a cold layer (rojek
    law), on its anchored free particles."""
    from dem.geometry.generators import random_packing
    from dem.geometry.particles import Particles
    from dem.network.heat import build_network

    lay = random_packing(n, 1e-4, 0.12, seed=seed)
    T = np.zeros(len(lay.radius))
    fixed = np.zeros(len(T), bool)
    fixed[lay.bottom] = fixed[lay.top] = True
    T[lay.bottom] = 1.0
    net = build_network(Particles.from_arrays(lay.position, lay.radius, T, fixed=fixed), spec=ConductanceSpec())
    _, label, anchored = net.graph.components()
    keep = np.flatnonzero(anchored[label])
    return net.matrix({})[keep][:, keep].tocsr(), net.rhs({})[keep]


def lattice_system(shape=(20, 20, 20), contrast=1e4, seed=0):
    """A simple cubic lattice of nodes with bond conductances spread log-uniformly over ``contrast``, the bottom
    layer at 1 and the top at 0 (fixed), as a BoundedLaplacian's steady matrix."""
    from dem.network.laplacian import BoundedLaplacian

    nx, ny, nz = shape
    index = np.arange(nx * ny * nz).reshape(shape)
    pairs = [(index[:-1].ravel(), index[1:].ravel()), (index[:, :-1].ravel(), index[:, 1:].ravel()),
             (index[:, :, :-1].ravel(), index[:, :, 1:].ravel())]
    i = np.concatenate([p[0] for p in pairs])
    j = np.concatenate([p[1] for p in pairs])
    K = contrast ** np.random.default_rng(seed).random(len(i))
    fixed = np.zeros(index.size, bool)
    fixed[index[:, :, 0].ravel()] = fixed[index[:, :, -1].ravel()] = True
    value = np.where(np.isin(np.arange(index.size), index[:, :, 0].ravel()), 1.0, 0.0)
    system = BoundedLaplacian(index.size, i, j, K, fixed, [], [], [], 0)
    return system.matrix(), system.boundary_rhs(value[system.fixed], [])


def relative_residual(A, x, b):
    return float(np.linalg.norm(b - A @ x) / np.linalg.norm(b))


@pytest.mark.parametrize("make", [packing_system, lattice_system], ids=["packing", "lattice"])
def test_tuned_amg_reaches_the_criterion_and_agrees_with_lu(make):
    A, b = make()
    solver = AMGSolver(A, rtol=RTOL)
    assert len(solver.hierarchy.levels) >= 3  # a real multilevel hierarchy, not a coarse solve
    x = solver.solve(b)
    assert relative_residual(A, x, b) <= RTOL
    exact = spl.spsolve(sp.csc_matrix(A), b)
    # the error is at most cond(A) x the relative residual; the solution lies in [0, 1]
    assert np.max(np.abs(x - exact)) < 1e-7
    # the cheaper setup costs few iterations, if any, against pyamg's defaults (the previous settings)
    previous = PreviousAMG(A, rtol=RTOL)
    assert relative_residual(A, previous.solve(b), b) <= RTOL
    assert solver.iterations <= 1.2 * previous.iterations


def test_coarse_levels_are_csr_and_the_one_block_cycle_is_that_of_pyamgs_bsr_levels():
    """Converting the coarse levels from 1 x 1 BSR to CSR and cycling them by the compiled kernels changes the
    kernels, not the cycle: with one row block (sequential sweeps) the same result as pyamg's own V-cycle on its BSR
    levels to round-off (the block kernel multiplies by the inverted 1 x 1 block where the scalar one divides), with
    pyamg's and scipy's kernels (a system below ``COMPILED_FROM``) as with the compiled ones."""
    import pyamg
    from pyamg.relaxation.smoothing import change_smoothers

    from dem.network.amg_cycle import VCycle
    from dem.network.linsolve import AMG_OPTIONS, AMG_SEED, AMG_SMOOTHER

    A, b = packing_system()
    ours = AMGSolver(A, rtol=RTOL)
    assert all(level.A.format == "csr" for level in ours.hierarchy.levels)
    state = np.random.get_state()
    np.random.seed(AMG_SEED)
    plain = pyamg.smoothed_aggregation_solver(A, **AMG_OPTIONS)
    np.random.set_state(state)
    assert plain.levels[1].A.format == "bsr"
    change_smoothers(plain, AMG_SMOOTHER, AMG_SMOOTHER)
    plain_cycle = plain.aspreconditioner(cycle="V")(b)
    for ours_cycle in (ours.precondition(b), VCycle(ours.hierarchy, blocks=1)(b)):  # pyamg's kernels, compiled
        assert np.max(np.abs(ours_cycle - plain_cycle)) <= 1e-13 * np.max(np.abs(plain_cycle))


def hybrid_cycle(monkeypatch, A, blocks=8):
    """The AMG solver of ``A`` with its cycle's sweeps on ``blocks`` row blocks on every level but the coarsest
    (the test systems are below ``BLOCK_MIN_ROWS``; 1: sequential sweeps)."""
    import dem.network.amg_cycle as amg_cycle

    monkeypatch.setattr(amg_cycle, "BLOCK_MIN_ROWS", 0)
    solver = AMGSolver(A, rtol=RTOL)
    solver.precondition = amg_cycle.VCycle(solver.hierarchy, blocks)
    assert len(solver.precondition.levels[0].A_blocks) == blocks + 1
    return solver


def test_hybrid_cycle_is_symmetric_positive_and_the_same_on_any_number_of_threads(monkeypatch):
    """The cycle on row blocks is a valid CG preconditioner (u.M v = v.M u, v.M v > 0), close to the sequential one,
    and its result does not depend on how many threads share the blocks, to the bit; CG on it meets the criterion
    in as many iterations as on the sequential cycle, give or take one."""
    import numba

    A, b = packing_system()
    solver = hybrid_cycle(monkeypatch, A)
    cycle = solver.precondition
    sequential = hybrid_cycle(monkeypatch, A, blocks=1)
    plain = sequential.precondition(b)
    assert 0 < np.max(np.abs(cycle(b) - plain)) < 0.1 * np.max(np.abs(plain))
    rng = np.random.default_rng(0)
    u, v = rng.standard_normal((2, A.shape[0]))
    Mu, Mv = cycle(u), cycle(v)
    assert abs(u @ Mv - v @ Mu) <= 1e-12 * np.sqrt((u @ Mu) * (v @ Mv))
    assert v @ Mv > 0 and u @ Mu > 0
    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = cycle(v)
    finally:
        numba.set_num_threads(threads)
    assert np.array_equal(one, Mv)
    x, y = solver.solve(b), sequential.solve(b)
    assert relative_residual(A, x, b) <= RTOL and abs(solver.iterations - sequential.iterations) <= 1
    assert np.max(np.abs(x - y)) < 1e-8


def plain_hybrid_sweep(A, x, b, bounds, forward):
    """A hybrid Gauss-Seidel sweep as its definition reads, every entry of every row in turn (Python)."""
    read = x.copy()
    for lo, hi in zip(bounds[:-1], bounds[1:]):
        for i in (range(lo, hi) if forward else range(hi - 1, lo - 1, -1)):
            s, diag = b[i], 0.0
            for e in range(A.indptr[i], A.indptr[i + 1]):
                j, a = A.indices[e], A.data[e]
                if j == i:
                    diag = a
                else:
                    s -= a * (x[j] if lo <= j < hi else read[j])
            x[i] = s / diag


def test_sweeps_that_reuse_the_forward_sums_are_the_plain_hybrid_sweeps(monkeypatch):
    """The backward sweep, which takes each row's own-block sum before the diagonal from the forward sweep before
    it, and the forward sweep from zero, which reads only the entries before the diagonal, give the plain hybrid
    sweeps (every entry read) to round-off, on four row blocks with rows reaching into other blocks; a matrix whose
    column indices are not sorted in their rows is swept as the sorted one, to the bit; a row without its diagonal
    entry is refused."""
    import dem.network.amg_cycle as amg_cycle

    monkeypatch.setattr(amg_cycle, "BLOCK_MIN_ROWS", 0)
    A, b = lattice_system(shape=(8, 8, 8))
    level = amg_cycle.Level(A, blocks=4)
    assert level.mixed.any() and not level.mixed.all()
    x0 = np.random.default_rng(1).standard_normal(A.shape[0])
    for from_zero in (False, True):
        expected = np.zeros_like(x0) if from_zero else x0.copy()
        plain_hybrid_sweep(A, expected, b, level.A_blocks, forward=True)
        plain_hybrid_sweep(A, expected, b, level.A_blocks, forward=False)
        x = x0.copy()
        level.copies[0][:] = x0  # the copy of x the sweep reads (as the cycle keeps it)
        level.smooth(x, b, from_zero=from_zero)
        assert np.max(np.abs(x - expected)) <= 1e-13 * np.max(np.abs(expected))
        unsorted = A.copy()
        for i in range(A.shape[0]):  # each row's entries in reverse order
            row = slice(A.indptr[i], A.indptr[i + 1])
            unsorted.indices[row], unsorted.data[row] = A.indices[row][::-1], A.data[row][::-1]
        unsorted.has_sorted_indices = False
        other = amg_cycle.Level(unsorted, blocks=4)
        y = x0.copy()
        other.copies[0][:] = x0
        other.smooth(y, b, from_zero=from_zero)
        assert np.array_equal(x, y)
    holed = A.tolil()
    holed[5, 5] = 0.0
    holed = holed.tocsr()
    holed.eliminate_zeros()
    with pytest.raises(ValueError, match="1 rows without a diagonal entry"):
        amg_cycle.Level(holed, blocks=4)


def test_compiled_finest_level_is_pyamgs_and_the_solver_on_it_meets_the_criterion(monkeypatch):
    """The finest level built compiled (dem.network.amg_setup): pyamg's aggregates and prolongator to the bit, its
    Galerkin matrix to round-off (summed in another order) and scipy's product of the same factors to the bit; the
    solver on that hierarchy (its coarsest level solved exactly), with the compiled cycle, reaches the criterion in
    at most one iteration more than on pyamg's own, at sparse LU's solution."""
    import dem.network.amg_cycle as amg_cycle
    from dem.network import amg_setup
    from dem.network.linsolve import AMG_OPTIONS, AMG_SEED
    from sinterheat import amg

    A, b = packing_system()
    ours, plain = amg_setup.hierarchy(A, AMG_SEED, AMG_OPTIONS), amg.hierarchy(A, AMG_SEED, **AMG_OPTIONS)
    P, P_plain = ours.levels[0].P.copy(), plain.levels[0].P.copy()
    P.sort_indices()
    P_plain.sort_indices()
    assert P.shape == P_plain.shape and P.shape[1] < A.shape[0] / 4  # real aggregates
    assert np.array_equal(P.indptr, P_plain.indptr) and np.array_equal(P.indices, P_plain.indices)
    assert np.array_equal(P.data, P_plain.data)
    assert abs(ours.levels[0].R - P.T).max() == 0
    assert np.array_equal(ours.levels[1].B, plain.levels[1].B)  # the coarse candidates of pyamg's fit_candidates
    A_c, A_c_plain = ours.levels[1].A, plain.levels[1].A
    assert abs(A_c - A_c_plain).max() <= 1e-13 * abs(A_c_plain).max()
    # the one-pass Galerkin product sums as scipy's row-by-row product does: the same matrix to the bit
    scipy_A_c = (P.T.tocsr() @ (A @ P)).tocsr()
    scipy_A_c.sort_indices()
    for ours_array, scipy_array in ((A_c.indptr, scipy_A_c.indptr), (A_c.indices, scipy_A_c.indices),
                                    (A_c.data, scipy_A_c.data)):
        assert np.array_equal(ours_array, scipy_array)
    # pyamg's levels down to the first of at most COARSEST_MAX unknowns, which is solved exactly
    sizes = [level.A.shape[0] for level in plain.levels]
    coarsest = next(k for k, size in enumerate(sizes) if size <= amg_setup.COARSEST_MAX)
    assert coarsest >= 1 and [level.A.shape[0] for level in ours.levels] == sizes[:coarsest + 1]
    A_last = ours.levels[-1].A
    b_last = np.random.default_rng(0).random(A_last.shape[0])
    assert relative_residual(A_last, ours.coarse_solver(A_last, b_last), b_last) < 1e-12
    with pytest.raises(ValueError, match="options"):
        amg_setup.hierarchy(A, AMG_SEED, {**AMG_OPTIONS, "strength": "symmetric"})

    reference = AMGSolver(A, rtol=RTOL)
    monkeypatch.setattr(amg_cycle, "COMPILED_FROM", 0)
    monkeypatch.setattr(amg_cycle, "BLOCK_MIN_ROWS", 0)
    solver = AMGSolver(A, rtol=RTOL)
    assert solver.precondition.levels[0].kernels is not None and len(solver.precondition.levels[0].A_blocks) > 2
    assert solver.hierarchy.levels[0].P.nnz == P.nnz  # built by amg_setup
    x, y = solver.solve(b), reference.solve(b)
    assert relative_residual(A, x, b) <= RTOL and solver.iterations <= reference.iterations + 1
    exact = spl.spsolve(sp.csc_matrix(A), b)
    assert np.max(np.abs(x - exact)) < 1e-7 and np.max(np.abs(x - y)) < 1e-7


def test_compiled_cg_product_is_scipys_to_the_bit(monkeypatch):
    """From COMPILED_FROM unknowns on, CG's product A p runs on numba's threads over row blocks, each row summed in
    scipy's order: scipy's product to the bit, and the solve the same as with scipy's product."""
    import dem.network.amg_cycle as amg_cycle

    A, b = packing_system()
    plain = AMGSolver(A, rtol=RTOL)
    monkeypatch.setattr(amg_cycle, "COMPILED_FROM", 0)
    solver = AMGSolver(A, rtol=RTOL)
    p = np.random.default_rng(4).standard_normal(A.shape[0])
    assert np.array_equal(solver.product(p), A @ p)
    solver.precondition = plain.precondition  # the same cycle: only the product differs
    assert np.array_equal(solver.solve(b), plain.solve(b)) and solver.iterations == plain.iterations


def test_coarse_cholesky_solves_exactly_and_takes_the_pseudo_inverse_of_a_singular_matrix():
    """The coarsest level's solve (dem.network.amg_setup.CoarseCholesky): sparse LU's solution on a symmetric
    positive definite matrix, factorised once; on a singular graph Laplacian (not positive definite) the
    pseudo-inverse's, the minimum-norm solution of a consistent system, orthogonal to the constants."""
    from dem.network.amg_setup import CoarseCholesky

    A, _ = lattice_system(shape=(6, 5, 4))
    b = np.random.default_rng(2).random(A.shape[0])
    solve = CoarseCholesky()
    assert np.allclose(solve(A, b), spl.spsolve(sp.csc_matrix(A), b), rtol=1e-12, atol=0)
    factors = solve.factors
    assert factors is not None and solve.pseudo_inverse is None
    solve(A, 2 * b)
    assert solve.factors is factors  # kept from the first call
    n = 30
    path = sp.diags([-np.ones(n - 1), np.r_[1.0, 2 * np.ones(n - 2), 1.0], -np.ones(n - 1)], [-1, 0, 1]).tocsr()
    rhs = np.random.default_rng(3).random(n)
    rhs -= rhs.mean()  # consistent: orthogonal to the null space (the constants)
    singular = CoarseCholesky()
    x = singular(path, rhs)
    assert singular.factors is None and singular.pseudo_inverse is not None
    assert relative_residual(path, x, rhs) < 1e-10 and abs(x.sum()) < 1e-10 * np.abs(x).sum()


def test_reused_hierarchy_gives_the_fresh_answer_to_the_tolerance():
    """A refresh (conductances changed by up to 10 %, a capacity term added): the earlier hierarchy preconditions
    the new matrix with no setup and the solution is that of a fresh hierarchy to the criterion."""
    A, b = packing_system()
    first = make_solver(A, "amg", rtol=RTOL)
    first.solve(b)
    rng = np.random.default_rng(1)
    scale = sp.diags(np.sqrt(rng.uniform(0.9, 1.1, A.shape[0])))
    changed = (scale @ A @ scale + sp.diags(1e-3 * A.diagonal())).tocsr()
    reused = make_solver(changed, "amg", rtol=RTOL, previous=first)
    assert reused.reused and reused.hierarchy is first.hierarchy
    x = reused.solve(b)
    assert reused.reused  # it served: no fresh hierarchy was needed
    assert reused.iterations <= AMG_REUSE_GROWTH * first.iterations + 1
    fresh = make_solver(changed, "amg", rtol=RTOL)
    y = fresh.solve(b)
    assert relative_residual(changed, x, b) <= RTOL
    assert relative_residual(changed, y, b) <= RTOL
    exact = spl.spsolve(sp.csc_matrix(changed), b)
    assert np.max(np.abs(x - exact)) < 1e-7 and np.max(np.abs(y - exact)) < 1e-7
    # a chain of reuses holds the one solver that built the hierarchy, not every earlier matrix
    again = make_solver(changed, "amg", rtol=RTOL, previous=reused)
    assert again.hierarchy_of is first


def test_a_hierarchy_that_no_longer_serves_is_rebuilt_and_the_criterion_met():
    """Another network of the same size (a lattice against a packing's hierarchy): the reuse stops at its iteration
    bound and a fresh hierarchy solves it."""
    A_lattice, b = lattice_system(shape=(20, 20, 20))
    n = A_lattice.shape[0]
    A_packing, b_packing = packing_system()
    A_packing, b_packing = A_packing[:n][:, :n].tocsr(), b_packing[:n]  # the same size: a different graph
    first = make_solver(A_packing + sp.diags(np.full(n, A_packing.diagonal().mean())), "amg", rtol=RTOL)
    first.solve(b_packing)
    other = make_solver(A_lattice, "amg", rtol=RTOL, previous=first)
    assert other.reused
    x = other.solve(b)
    assert not other.reused and other.hierarchy is not first.hierarchy
    assert relative_residual(A_lattice, x, b) <= RTOL


def test_other_backends_ignore_previous():
    A, b = lattice_system(shape=(10, 10, 10))
    first = make_solver(A, "amg", rtol=RTOL)
    assert type(make_solver(A, "direct", rtol=RTOL, previous=first)).__name__ == "DirectSolver"
    assert type(make_solver(A, "cg", rtol=RTOL, previous=first)).__name__ == "PCGSolver"


def test_radiation_newton_and_steps_reuse_the_hierarchy_with_the_direct_answer():
    """Radiation changes the matrix at every Newton iteration and time step (its linearisation): steady and implicit
    runs on AMG, reusing the hierarchy, end where sparse LU ends, to the tolerance."""
    from dem.geometry.generators import random_packing
    from dem.geometry.particles import Particles
    from dem.laws.ambient import Radiation, Sources
    from dem.network.heat import build_network, integrate, steady

    lay = random_packing(6000, 1e-4, 0.12, seed=2)
    T = np.full(len(lay.radius), 300.0)
    fixed = np.zeros(len(T), bool)
    fixed[lay.bottom] = True
    T[lay.bottom] = 1200.0
    net = build_network(Particles.from_arrays(lay.position, lay.radius, T, fixed=fixed), spec=ConductanceSpec(),
                        sources=Sources(radiation=Radiation(emissivity=0.8, T_inf=300.0, unit="K")))
    ref = steady(net, floating="mean", linear="direct", rtol=1e-12)
    amg = steady(net, floating="mean", linear="amg", rtol=1e-12)
    assert amg.iterations == ref.iterations > 2  # several Newton iterations, each an AMG solve
    assert np.max(np.abs(amg.T - ref.T)) < 1e-6 * 1200.0
    runs = {linear: integrate(net, "implicit", dt=1e-3, t_end=5e-3, linear=linear, rtol_linear=1e-12)
            for linear in ("direct", "amg")}
    assert runs["amg"].solver == "amg"
    assert runs["amg"].factorizations < runs["direct"].factorizations == 5  # one hierarchy served several steps
    assert np.max(np.abs(runs["amg"].T - runs["direct"].T)) < 1e-6 * 1200.0


def test_benchmark_leaves_petsc_out_cleanly_without_petsc4py(monkeypatch):
    import benchmarks.amg_peers as peers

    monkeypatch.setattr(peers, "available", lambda name: False)
    assert set(peers.contenders()) == {"amg", "amg_previous"}
    A, b = lattice_system(shape=(12, 12, 12))
    rows = peers.side_by_side_rows(A, b, rounds=1)
    assert [r["solver"] for r in rows] == ["amg", "amg_reused", "amg_previous"]
    assert all(r["relative_residual"] <= RTOL and r["over_fastest_petsc"] is None for r in rows)
    assert all(r["max_difference_to_amg"] < 1e-7 for r in rows)


@pytest.mark.skipif(not __import__("benchmarks.timing").timing.available("petsc4py"), reason="petsc4py absent")
def test_petsc_peers_reach_the_same_criterion():
    import benchmarks.amg_peers as peers

    A, b = lattice_system(shape=(12, 12, 12))
    rows = {r["solver"]: r for r in peers.side_by_side_rows(A, b, rounds=1)}
    for name in peers.PETSC_PRECONDITIONERS:
        assert rows[name]["relative_residual"] <= RTOL
        assert rows[name]["max_difference_to_amg"] < 1e-7


def test_kirchhoff_refresh_reuses_the_hierarchy_with_the_fresh_answer():
    """A refresh of the contact current (conductances changed by up to 10 %): the solution that reuses the last
    refresh's hierarchy is the fresh one and sparse LU's, to the tolerance, the driven electrode's potential too."""
    from dem.network.current import Electrodes, kirchhoff

    shape = (20, 20, 20)
    index = np.arange(np.prod(shape)).reshape(shape)
    i = np.concatenate([index[:-1].ravel(), index[:, :-1].ravel(), index[:, :, :-1].ravel()])
    j = np.concatenate([index[1:].ravel(), index[:, 1:].ravel(), index[:, :, 1:].ravel()])
    bottom, top = index[:, :, 0].ravel(), index[:, :, -1].ravel()
    plane_node, plane_index = np.concatenate([bottom, top]), np.repeat([0, 1], len(bottom))
    rng = np.random.default_rng(4)
    G, G_w = 10.0 ** (2 * rng.random(len(i))), np.full(len(plane_node), 50.0)
    # the bottom grounded, the top driving 2 A (its potential found by the unit solves on the same solver)
    el = Electrodes(("bottom", "top"), (0, 1), np.array([0.0, np.nan]), np.array([np.nan, 2.0]))
    share = np.full(len(i), 0.5)
    first = kirchhoff(index.size, i, j, G, share, plane_node, plane_index, G_w, el, "amg")
    G_new = G * rng.uniform(0.9, 1.1, len(i))
    again = kirchhoff(index.size, i, j, G_new, share, plane_node, plane_index, G_w, el, "amg", previous=first.solver)
    assert again.solver.reused and again.solver.hierarchy is first.solver.hierarchy
    for linear in ("amg", "direct"):
        fresh = kirchhoff(index.size, i, j, G_new, share, plane_node, plane_index, G_w, el, linear)
        scale = np.max(np.abs(fresh.potential))
        assert np.max(np.abs(again.potential - fresh.potential)) < 1e-8 * scale
        assert again.electrode_potential[1] == pytest.approx(fresh.electrode_potential[1], rel=1e-8)
