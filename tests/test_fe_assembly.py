"""The systems of the periodic-cell FE (fem_neck.pcg, fem_neck.dual, fem_neck.primal) against the plain sums they
replace: a dense or COO sum of the element matrices, the Galerkin product of the coarse space."""

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg  # noqa: F401  (for sp.linalg)

from fem_neck import dual, lattice, pcg, primal
from fem_neck.simplex import lagrange, raviart_thomas, tet_quadrature


def _random_elements(seed, elements=300, n=10, dofs=500):
    rng = np.random.default_rng(seed)
    l2g = np.array([rng.choice(dofs, n, replace=False) for _ in range(elements)])
    fixed = rng.random(dofs) < 0.2
    values = np.where(fixed, rng.random(dofs), 0.0)
    K = rng.standard_normal((elements, n, n))
    return l2g, fixed, values, K + np.swapaxes(K, 1, 2)


def _dense(system):
    """The matrix of an ElementSystem, column by column from its products."""
    return np.column_stack([system @ column for column in np.eye(system.shape[0])])


def _added(system, K, chunk=64):
    """``system`` with the element matrices ``K`` added in chunks, as the solvers add them."""
    for start in range(0, len(K), chunk):
        system.add(K[start:start + chunk], np.arange(start, min(start + chunk, len(K))))
    return system


@pytest.mark.parametrize("seed", [0, 1])
def test_element_system_is_the_sum_of_the_element_matrices_on_the_free_dofs(seed):
    l2g, fixed, values, K = _random_elements(seed)
    system = pcg.ElementSystem(l2g, fixed, values)
    system.add(K[:64], np.arange(64))
    with pytest.raises(ValueError, match="ElementSystem: 64 of 300 element matrices added"):
        system @ np.ones(system.shape[0])
    for start in range(64, len(l2g), 64):
        system.add(K[start:start + 64], np.arange(start, min(start + 64, len(l2g))))
    n = l2g.shape[1]
    full = sp.csr_matrix((K.ravel(), (np.repeat(l2g, n, axis=1).ravel(), np.tile(l2g, (1, n)).ravel())),
                         shape=(len(fixed),) * 2).toarray()
    free = system.free
    assert sorted(free) == list(np.flatnonzero(~fixed)) and system.shape == (len(free), len(free))
    np.testing.assert_allclose(_dense(system), full[np.ix_(free, free)], atol=1e-13)
    np.testing.assert_allclose(system.b, -full[np.ix_(free, np.flatnonzero(fixed))] @ values[fixed], atol=1e-12)
    u = values.copy()
    x = np.random.default_rng(seed + 10).random(len(free))
    u[free] = x
    assert system.energy(x) == pytest.approx(u @ full @ u, rel=1e-12)


def _grouped_elements():
    """Random symmetric element matrices on groups of 1, 1, 3, 3 and 2 local dofs, each a run of consecutive global
    dofs of one "entity", fixed or free together."""
    rng = np.random.default_rng(7)
    sizes, count = [1, 1, 3, 3, 2], 40                                   # 40 entities of each size
    size_of = rng.permutation(np.repeat([1, 2, 3], count))
    base = np.concatenate([[0], np.cumsum(size_of)])                     # entity j owns base[j] .. base[j + 1] - 1
    held = rng.random(len(size_of)) < 0.2
    l2g = np.empty((200, 10), dtype=np.int64)
    for e in range(200):
        columns = []
        for size in sizes:
            entity = rng.choice(np.flatnonzero((size_of == size) & ~np.isin(np.arange(len(size_of)), columns)))
            columns.append(entity)
        l2g[e] = np.concatenate([base[j] + np.arange(size_of[j]) for j in columns])
    fixed = np.repeat(held, size_of)
    values = np.where(fixed, rng.random(len(fixed)), 0.0)
    K = rng.standard_normal((200, 10, 10))
    return l2g, fixed, values, K + np.swapaxes(K, 1, 2)


def test_grouped_element_system_is_the_sum_of_the_element_matrices_on_the_free_dofs():
    l2g, fixed, values, K = _grouped_elements()
    sizes = [1, 1, 3, 3, 2]
    grouped = _added(pcg.ElementSystem(l2g, fixed, values, sizes), K)
    plain = _added(pcg.ElementSystem(l2g, fixed, values), K)
    n = l2g.shape[1]
    full = sp.csr_matrix((K.ravel(), (np.repeat(l2g, n, axis=1).ravel(), np.tile(l2g, (1, n)).ravel())),
                         shape=(len(fixed),) * 2).toarray()
    free = grouped.free
    A = _dense(grouped)
    np.testing.assert_array_equal(A, _dense(plain))
    np.testing.assert_allclose(A, full[np.ix_(free, free)], atol=1e-13)
    np.testing.assert_allclose(grouped.b, -full[np.ix_(free, np.flatnonzero(fixed))] @ values[fixed], atol=1e-12)


@pytest.mark.parametrize("groups, match", [([1, 1, 3, 3, 3], "positive sizes summing to the 3 local dofs"),
                                           ([3], "consecutive global dofs"),
                                           ([2, 1], "one group in every element")])
def test_groups_that_do_not_hold_are_refused(groups, match):
    # elements (0, 1, 2) and (2, 3, 4): dof 2 starts a group in the second but not in the first; then dofs 4 and 5
    # fixed and free within a group
    l2g = np.array([[0, 1, 2], [2, 3, 4]]) if groups != [3] else np.array([[0, 1, 2], [4, 5, 6]])
    fixed = np.zeros(7, dtype=bool)
    fixed[4] = True
    with pytest.raises(ValueError, match=match):
        pcg.ElementSystem(l2g, fixed, np.zeros(7), groups)


def test_packed_symmetric_products_are_the_full_ones():
    g = np.random.default_rng(2).standard_normal((7, 3, 5))
    packed = primal.symmetric_products(g)
    full = np.stack([0.5 * (np.einsum("qa,qb->qab", g[:, i], g[:, j]) + np.einsum("qa,qb->qab", g[:, j], g[:, i]))
                     for i, j in primal.UPPER], axis=1).reshape(7 * 6, 25)
    np.testing.assert_array_equal(packed[:, primal.symmetric_gather(5)], full)


@pytest.fixture(scope="module")
def cell_mesh():
    cm = lattice.build_cell_mesh(lattice.lattice_cell("bcc", 0.08), **lattice.mesh_sizes(0.1))
    cm.curved.keep_jacobians(tet_quadrature(primal.quadrature_degree(3))[0])
    yield cm
    cm.curved.keep_jacobians(None)


def _element_matrices(mesh, k):
    """``H_K`` of every element, as :func:`fem_neck.dual.solve` makes them."""
    rt = raviart_thomas(k)
    return dual.element_matrices(mesh, rt, primal.quadrature_degree(k + 1)), rt.n_face


@pytest.mark.parametrize("k", [1, 3])
@pytest.mark.slow
def test_element_matrices_are_the_traces_through_the_inverse_mass(cell_mesh, k):
    # the compiled Cholesky pass against T A^-1 T^T by LAPACK's dense solve, on curved and straight elements
    mesh, rt = cell_mesh.curved, raviart_thomas(k)
    elements = np.arange(len(mesh.tets))
    packed = dual.mass_matrices(mesh, rt, primal.quadrature_degree(k + 1), elements)
    A = packed[:, primal.symmetric_gather(rt.m)].reshape(len(elements), rt.m, rt.m)
    T = rt.traces
    H = np.matmul(T, np.linalg.solve(A, np.broadcast_to(T.T, (len(A),) + T.T.shape)))
    stack = dual.element_matrices(mesh, rt, primal.quadrature_degree(k + 1))
    assert mesh.is_curved.any() and not mesh.is_curved.all()
    np.testing.assert_allclose(stack[elements], H, rtol=0, atol=1e-13 * np.abs(H).max())


def test_element_matrices_refuse_a_mass_matrix_that_is_not_positive_definite():
    T, position = np.ones((2, 3)), primal.symmetric_gather(3).reshape(3, 3)
    A = np.array([[1.0, 0, 0, 1, 0, 1], [1, 0, 0, -1, 0, 1]])                 # I and diag(1, -1, 1), packed
    assert dual._trace_products(A[:1], position, T, 0, np.empty((1, 3)))
    assert not dual._trace_products(A, position, T, 0, np.empty((2, 3)))


def test_face_system_is_the_sum_of_the_element_matrices_on_the_free_faces(cell_mesh):
    mesh = cell_mesh.curved
    H_K, nf = _element_matrices(mesh, 1)
    fixed = np.zeros(len(mesh.faces), dtype=bool)
    fixed[cell_mesh.hot] = fixed[cell_mesh.cold] = True
    lam = np.zeros(len(mesh.faces) * nf)
    lam[cell_mesh.hot * nf] = 1.0
    system = dual.face_system(mesh, H_K, fixed, lam)
    face_dofs = (mesh.t2f[:, :, None] * nf + np.arange(nf)).reshape(len(mesh.tets), -1)
    n = 4 * nf
    full = sp.csr_matrix((H_K[np.arange(len(H_K))].ravel(), (np.repeat(face_dofs, n, axis=1).ravel(),
                                                             np.tile(face_dofs, (1, n)).ravel())),
                         shape=(len(lam),) * 2)
    held = np.setdiff1d(np.arange(len(lam)), system.free)
    free = system.free
    difference = system.matrix.tocsr() - full[free][:, free]
    assert abs(difference).max() <= 1e-12 * abs(full).max()
    x = np.random.default_rng(4).random(len(free))
    np.testing.assert_allclose(system.matrix @ x, full[free][:, free] @ x, rtol=1e-12, atol=1e-12 * abs(full).max())
    stored = system.matrix.data.shape[0]
    assert stored < 0.6 * (full[free][:, free].nnz / nf**2)              # the blocks above the diagonal only
    np.testing.assert_allclose(system.b, -(full[free][:, held] @ lam[held]), atol=1e-12)
    assert system.constant == pytest.approx(lam[held] @ (full[held][:, held] @ lam[held]), rel=1e-12)
    blocks = system.diagonal.reshape(-1, nf, nf)
    for face in range(0, len(blocks), 97):
        rows = free[face * nf:(face + 1) * nf]
        np.testing.assert_allclose(blocks[face], full[rows][:, rows].toarray(), atol=1e-12)


def test_the_given_coarse_matrix_of_the_face_means_is_the_galerkin_product(cell_mesh):
    # the lower bound hands pcg.two_level the (0, 0) entries of the face system's blocks (both triangles) as P^T H P
    mesh = cell_mesh.curved
    H_K, nf = _element_matrices(mesh, 2)
    fixed = np.zeros(len(mesh.faces), dtype=bool)
    fixed[cell_mesh.hot] = fixed[cell_mesh.cold] = True
    system = dual.face_system(mesh, H_K, fixed, np.zeros(len(mesh.faces) * nf))
    H = system.matrix
    n_free = H.shape[0] // nf
    P = sp.csr_matrix((np.ones(n_free), (np.arange(n_free) * nf, np.arange(n_free))), shape=(H.shape[0], n_free))
    coarse = H.entries(0, 0)
    assert abs(coarse - (P.T @ H.tocsr() @ P)).max() == 0.0
    r = np.random.default_rng(3).random(H.shape[0])
    given = pcg.two_level(H, P, coarse, system.diagonal)(r)
    computed = pcg.two_level(H.tocsr(), P, None, system.diagonal)(r)
    np.testing.assert_allclose(given, computed, rtol=1e-12)


def test_block_jacobi_on_groups_inverts_the_diagonal_blocks_of_the_matrix():
    # the upper bound's P_4 system: its groups (a vertex, an edge's or a face's nodes) against dense inverses
    l2g, fixed, values, K = _grouped_elements()
    K = np.matmul(K, K) + np.eye(10)                                         # positive definite element matrices
    system = _added(pcg.ElementSystem(l2g, fixed, values, [1, 1, 3, 3, 2]), K)
    groups = system.groups()
    local = system.block_jacobi().toarray()
    dense = _dense(system)
    starts = np.concatenate([[0], np.cumsum(groups)])
    assert sorted(set(groups)) == [1, 2, 3] and starts[-1] == dense.shape[0]
    expected = np.zeros_like(dense)
    for begin, end in zip(starts[:-1], starts[1:]):
        expected[begin:end, begin:end] = np.linalg.inv(dense[begin:end, begin:end])
    np.testing.assert_allclose(local, expected, rtol=0, atol=1e-13 * abs(expected).max())
    r = np.random.default_rng(4).random(dense.shape[0])
    identity, coarse = sp.identity(dense.shape[0], format="csr"), sp.csr_matrix(dense)
    given = pcg.two_level(system, identity, coarse, local=system.block_jacobi())
    np.testing.assert_allclose(given.local @ r, expected @ r, rtol=1e-12)
    with pytest.raises(ValueError, match="local: shape"):
        pcg.two_level(system, identity, coarse, local=sp.identity(3, format="csr"))
    negative = _added(pcg.ElementSystem(l2g, fixed, values, [1, 1, 3, 3, 2]), -K)   # negative definite blocks
    with pytest.raises(ValueError, match="a diagonal block of the system has a pivot that is not positive"):
        negative.block_jacobi()


def test_cg_reports_the_first_iterate_settled_to_a_looser_tolerance():
    # a shifted 1D Laplacian (condition ~ 400; 138 steps): the reported iterate comes well before the end, its energy
    # above the final one by about the looser tolerance (1.2e-4 of it); the final iterate is the one CG reaches
    # without a report
    n = 400
    A = sp.diags([-np.ones(n - 1), 2.01 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1], format="csr")
    b = np.random.default_rng(8).random(n)
    constant = 2.0 * float(b @ sp.linalg.spsolve(A.tocsc(), b))              # the least energy is half of it

    def energy(x):
        return float(x @ (A @ x) - 2.0 * x @ b + constant)

    reports = []
    x, iterations, _ = pcg.solve(A, b, lambda r: r / 2.01, energy=(constant, 1e-12), settled=(1e-3, reports.append))
    y, same, _ = pcg.solve(A, b, lambda r: r / 2.01, energy=(constant, 1e-12))
    assert len(reports) == 1 and same == iterations and np.array_equal(x, y)
    early = energy(reports[0]) - energy(x)
    assert 1e-5 * energy(x) < early <= 1e-2 * energy(x)


def test_block_jacobi_needs_blocks_that_cover_the_unknowns():
    A = sp.identity(10, format="csr")
    with pytest.raises(ValueError, match="block_matrices: 3 blocks of 3 unknowns for 10 unknowns"):
        pcg.two_level(A, sp.identity(10, format="csr"), None, np.ones((3, 3, 3)))


def test_upper_bound_matrix_is_the_conforming_stiffness(cell_mesh):
    # the P_2 system on the free skeleton dofs (no interior nodes at p = 2) against a COO sum of the same elements
    mesh, basis = cell_mesh.curved, lagrange(2)
    num = primal.numbering(mesh, basis)
    K = primal.stiffness_matrices(mesh, basis)
    fixed = np.zeros(num.n, dtype=bool)
    fixed[primal.face_dofs(mesh, basis, cell_mesh.hot)] = True
    system = pcg.ElementSystem(num.l2g, fixed, fixed.astype(float))
    system.add(K, np.arange(len(K)))
    n = basis.n
    full = sp.csr_matrix((K.ravel(), (np.repeat(num.l2g, n, axis=1).ravel(), np.tile(num.l2g, (1, n)).ravel())),
                         shape=(num.n, num.n))
    free = system.free
    x = np.random.default_rng(6).random((len(free), 3))
    expected = full[free][:, free] @ x
    for k in range(3):
        np.testing.assert_allclose(system @ x[:, k], expected[:, k], rtol=0, atol=1e-12 * abs(expected).max())


def test_condensed_element_matrix_is_the_energy_minimised_over_the_interior_nodes():
    rng = np.random.default_rng(5)
    for interior in (1, 3):  # the rank-one update (P_4) and the general Schur complement
        n = 6 + interior
        K = rng.standard_normal((4, n, n))
        K = np.matmul(K, np.swapaxes(K, 1, 2)) + n * np.eye(n)
        S = primal.condensed(K, 6)
        x = rng.standard_normal((4, 6))
        y = -np.linalg.solve(K[:, 6:, 6:], np.einsum("eib,eb->ei", K[:, 6:, :6], x)[:, :, None])[:, :, 0]
        u = np.concatenate([x, y], axis=1)                                     # with the minimising interior
        np.testing.assert_allclose(np.einsum("ea,eab,eb->e", x, S, x), np.einsum("ea,eab,eb->e", u, K, u),
                                   rtol=1e-12)
    np.testing.assert_array_equal(primal.condensed(K[:, :6, :6], 6), K[:, :6, :6])  # no interior nodes (P_3)


def test_coarse_matrix_of_the_hats_is_the_galerkin_product(cell_mesh):
    # the upper bound sums P^T A_ff P of the hats element by element, as primal.solve does, at p = 4 (condensed)
    mesh, basis = cell_mesh.curved, lagrange(4)
    skel = basis.n - basis.n_interior
    num = primal.numbering(mesh, basis)
    fixed = np.zeros(num.n, dtype=bool)
    fixed[primal.face_dofs(mesh, basis, cell_mesh.hot)] = fixed[primal.face_dofs(mesh, basis, cell_mesh.cold)] = True
    K = primal.condensed(primal.stiffness_matrices(mesh, basis), skel)
    system = pcg.ElementSystem(num.l2g, fixed, fixed.astype(float), primal.skeleton_groups(basis))
    n = K.shape[1]
    full = sp.csr_matrix((K.ravel(), (np.repeat(num.l2g, n, axis=1).ravel(), np.tile(num.l2g, (1, n)).ravel())),
                         shape=(num.n, num.n))
    A = full[system.free][:, system.free]
    P = primal.hat_prolongation(mesh, basis, num)[system.free]
    free = ~fixed[num.l2g]
    hats = primal.hat_values(basis)
    parts = primal.hat_parts(K, free, hats)
    np.testing.assert_allclose(parts, hats.T @ (K * free[:, :, None] * free[:, None, :]) @ hats, rtol=0,
                               atol=1e-13 * abs(parts).max())
    assert (~free).any(axis=1).any() and free.all(axis=1).any()                # elements with and without a fixed dof
    coarse = primal.coarse_matrix(mesh, parts)
    product = (P.T @ A @ P).tocsr()
    assert abs(coarse - product).max() <= 1e-12 * abs(product).max()


def test_block_jacobi_on_given_blocks_inverts_them():
    # the lower bound's face blocks (10 x 10 at k = 3): random symmetric positive definite ones against numpy's
    # inverses; a block with a negative eigenvalue is refused
    rng = np.random.default_rng(3)
    M = rng.random((40, 10, 10))
    blocks = M @ np.transpose(M, (0, 2, 1)) + 0.1 * np.eye(10)
    A = sp.block_diag(list(blocks), format="csr")
    local = pcg.two_level(A, sp.identity(400, format="csr"), None, blocks).local.toarray()
    expected = sp.block_diag(list(np.linalg.inv(blocks))).toarray()
    np.testing.assert_allclose(local, expected, rtol=0, atol=1e-12 * abs(expected).max())
    blocks[7, 4, 4] = -1.0
    with pytest.raises(ValueError, match="block_matrices: a block has a pivot that is not positive"):
        pcg.two_level(A, sp.identity(400, format="csr"), None, blocks)
