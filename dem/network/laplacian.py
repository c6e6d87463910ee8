r"""One network problem, two fields: a weighted graph Laplacian with fixed nodes and planes at a given value.

Heat between particles (Rojek 2022, eqs. 2-4: temperatures, thermal conductances :math:`K` in W/K) and current
between particles (Kirchhoff's laws: potentials, electrical conductances :math:`G` in S) are the same linear problem
on the contact graph. Each edge :math:`c = (i, j)` carries the flow :math:`K_c (x_i - x_j)` from :math:`i` to
:math:`j`; a node may also be joined to a *plane* (a wall at a prescribed temperature, an electrode at a prescribed
potential) by :math:`K_{kw}`, carrying :math:`K_{kw} (x_k - x_w)` into the plane; some nodes may be *fixed*
(prescribed values). The balance of the free nodes :math:`F` (with the fixed ones :math:`D`) is

.. math::

    A x_F = b, \qquad A = L_{FF} + \mathrm{diag}\Big(\sum_w K_{kw}\Big), \qquad
    b = -L_{FD} x_D + \sum_w K_{kw} x_w \; (+ \text{sources}),

the diagonal term holding the sum of the plane conductances of each node, with :math:`L` the weighted graph
Laplacian (:func:`laplacian`). :math:`A` is symmetric positive semidefinite, and definite on every connected group of
free nodes that reaches a fixed node or a plane (an *anchored* group, :meth:`BoundedLaplacian.components`); a group
that reaches none floats: its values are undetermined.

:class:`BoundedLaplacian` assembles this once as CSR matrices and rewrites their entries in place when only the
conductances change (:meth:`~BoundedLaplacian.refresh`: contacts whose necks grow, particles that move a little).
The thermal network (:class:`dem.network.heat.Network`) and the Kirchhoff current solve (:mod:`dem.network.current`)
are both built on it; :func:`solve_anchored` is the steady solve the current uses. :meth:`~BoundedLaplacian.flux` is
the net flow into every node at given node values, :math:`-(L x)_k + \sum_w K_{kw} (x_w - x_k)`: the conducted heat
of the lumped balance of particles that move (:class:`dem.engines.staggered.heat.LumpedHeat`), whose edges are the
pairs of a Verlet list, those not in contact with :math:`K = 0` (so the graph is refreshed in place until the list is
rebuilt). An edge with :math:`K = 0` carries nothing and joins nothing: :meth:`~BoundedLaplacian.components` counts
only edges with :math:`K > 0`.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from dem.network.linsolve import make_solver

COMPILED_ASSEMBLY_FROM = 300_000  # nodes from which the Laplacian and its blocks are written compiled
# (dem.network.laplacian_kernels), as large a network as loads numba for its bonds and its solve anyway
COMPILED_GROUPS_FROM = 300_000  # free nodes from which the groups are found compiled (dem.network.groups): a network
# this large loads numba for its solve anyway (dem.network.amg_cycle.COMPILED_FROM)


def laplacian(n: int, i: np.ndarray, j: np.ndarray, K: np.ndarray) -> sp.csr_matrix:
    r"""Weighted graph Laplacian :math:`L_{ii} = \sum_j K_{ij}`, :math:`L_{ij} = -K_{ij}` (symmetric, rows sum to zero).

    Parameters
    ----------
    n : int
        Number of nodes.
    i, j : array_like
        (M,) int, the edges' nodes.
    K : array_like
        (M,) edge conductances (W/K for heat, S for current).

    Returns
    -------
    scipy.sparse.csr_matrix
        The (n, n) Laplacian (the unit of ``K``).
    """
    i, j, K = np.asarray(i, dtype=np.int64), np.asarray(j, dtype=np.int64), np.asarray(K, dtype=float)
    diag = np.bincount(i, K, n) + np.bincount(j, K, n)
    m = len(i)
    if m and (np.any(i >= j) or np.any(i[1:] * n + j[1:] <= i[:-1] * n + j[:-1])):  # not canonical: summed places
        rows = np.concatenate([i, j, np.arange(n)])
        cols = np.concatenate([j, i, np.arange(n)])
        vals = np.concatenate([-K, -K, diag])
        return sp.csr_matrix((vals, (rows, cols)), shape=(n, n))
    # canonical edges (i < j, sorted by (i, j), each once): row r is its lower entries (the edges (i, r), by i), the
    # diagonal, its upper entries (the edges (r, j), by j), each written where it belongs, without a sort
    up, lo = np.bincount(i, minlength=n), np.bincount(j, minlength=n)
    first = np.concatenate(([0], np.cumsum(lo + up + 1)))
    index = np.int32 if first[-1] < 2**31 else np.int64
    indices, data = np.empty(first[-1], dtype=index), np.empty(first[-1])
    rank = np.arange(m)
    # the edges by (j, i): the column order of the upper triangle, which a CSR -> CSC conversion counts out
    by_j = sp.csr_matrix((rank, j, np.concatenate(([0], np.cumsum(up)))), shape=(n, n)).tocsc().data
    at = first[j[by_j]] + rank - (np.cumsum(lo) - lo)[j[by_j]]
    indices[at], data[at] = i[by_j], -K[by_j]
    at = first[:-1] + lo
    indices[at], data[at] = np.arange(n), diag
    at = first[i] + lo[i] + 1 + rank - (np.cumsum(up) - up)[i]
    indices[at], data[at] = j, -K
    L = sp.csr_matrix((data, indices, first.astype(index)), shape=(n, n))
    L.has_sorted_indices = True
    return L


class BoundedLaplacian:
    """The matrices of the module docstring for ``n`` nodes, edges ``(i, j)`` with conductances ``K``, the
    ``fixed`` nodes (bool mask) and plane bonds ``(plane_node, plane_index)`` with conductances ``K_plane`` to
    ``n_planes`` planes.

    Attributes: ``free``, ``fixed`` (node indices), ``L`` (all nodes), ``L_FF``, ``L_FD`` (CSR), ``plane_diag``
    (per free node: the sum of its plane conductances), ``fixed_diag`` (per free node: the sum of its conductances to
    fixed nodes); the matrices and sums are made when first asked for (:meth:`flux` needs none of them).

    Parameters
    ----------
    n : int
        Number of nodes.
    i, j : array_like
        (M,) int, the edges' nodes.
    K : array_like
        (M,) edge conductances (W/K for heat, S for current).
    fixed : array_like or None
        (n,) bool, the nodes at prescribed values; None: none.
    plane_node : array_like
        (B,) int, the node of each plane bond.
    plane_index : array_like
        (B,) int, the plane of each plane bond.
    K_plane : array_like
        (B,) plane bond conductances (same unit).
    n_planes : int
        Number of planes.
    """

    def __init__(self, n: int, i, j, K, fixed, plane_node, plane_index, K_plane, n_planes: int):
        self.n, self.n_planes = int(n), int(n_planes)
        fixed = np.zeros(self.n, dtype=bool) if fixed is None else np.asarray(fixed, dtype=bool)
        self.free = np.flatnonzero(~fixed)
        self.fixed = np.flatnonzero(fixed)
        self._set(i, j, K, plane_node, plane_index, K_plane)
        self._matrices = None  # (L, L_FF, L_FD), assembled when first asked for (the flux needs none)
        self._slots = None  # where each place of the Laplacian sits in L, L_FF, L_FD: built by the first rewrite
        self._place_of = None  # the place of each Laplacian entry (edges both ways, then the diagonal)
        self._stale = False  # the conductances changed since the matrices were written

    def _set(self, i, j, K, plane_node, plane_index, K_plane):
        self.i, self.j = np.asarray(i, dtype=np.int64), np.asarray(j, dtype=np.int64)
        self.K = np.asarray(K, dtype=float)
        self.plane_node = np.asarray(plane_node, dtype=np.int64)
        self.plane_index = np.asarray(plane_index, dtype=np.int64)
        self.K_plane = np.asarray(K_plane, dtype=float)
        self._diags = None  # (plane_diag, fixed_diag) of these conductances, when first asked for

    def _current(self):
        """``(L, L_FF, L_FD)`` of the conductances as they are: assembled the first time, afterwards rewritten in
        place (same sparsity) when :meth:`refresh` changed the conductances."""
        if self._matrices is None:
            self._matrices = self._compiled(whole=not len(self.fixed)) if self.n >= COMPILED_ASSEMBLY_FROM else None
        if self._matrices is None:
            L = laplacian(self.n, self.i, self.j, self.K)
            if len(self.fixed):
                rows = L[self.free]
                self._matrices = (L, rows[:, self.free].tocsr(), rows[:, self.fixed].tocsr())
            else:
                self._matrices = (L, L, sp.csr_matrix((self.n, 0)))
        elif self._stale:
            n = self.n
            if self._slots is None:
                # the distinct places (row, col) of the entries (an edge listed twice, or a loop on the diagonal,
                # puts two entries in one place); an index matrix with the Laplacian's sparsity holds place p as p + 1
                rows = np.concatenate([self.i, self.j, np.arange(n)])
                cols = np.concatenate([self.j, self.i, np.arange(n)])
                places, self._place_of = np.unique(rows * n + cols, return_inverse=True)
                index = sp.csr_matrix((np.arange(1.0, len(places) + 1.0), (places // n, places % n)), shape=(n, n))
                if len(self.fixed):
                    part = index[self.free]
                    parts = (index, part[:, self.free].tocsr(), part[:, self.fixed].tocsr())
                else:
                    parts = (index, index, sp.csr_matrix((n, 0)))
                self._slots = [m.data.astype(np.int64) - 1 for m in parts]
                L = parts[0].copy()
                self._matrices = (L, L if not len(self.fixed) else parts[1].copy(), parts[2].copy())
            diag = np.bincount(self.i, self.K, n) + np.bincount(self.j, self.K, n)
            values = np.bincount(self._place_of, np.concatenate([-self.K, -self.K, diag]))  # summed per place
            for matrix, slots in zip(self._matrices, self._slots):
                matrix.data[:] = values[slots]
        self._stale = False
        return self._matrices

    def _compiled(self, whole: bool):
        """Written row by row from canonical edges (:mod:`dem.network.laplacian_kernels`: the Laplacian and scipy's
        selection of its blocks to the bit, without a temporary of the edges' length): ``(L, L, empty L_FD)`` where
        ``whole`` (no fixed node: ``L_FF`` is ``L``), else ``(None, L_FF, L_FD)``, ``L`` written when first asked for
        (:meth:`_laplacian`: a steady solve reads only the blocks); None where the edges are not canonical."""
        from dem.network.laplacian_kernels import count_rows, write_rows  # compiled: a smaller network loads no numba

        n, nf, blocks = self.n, len(self.free), not whole
        index = np.int32 if 2 * len(self.i) + n < 2**31 else np.int64
        fixed = np.zeros(n, dtype=bool)
        fixed[self.fixed] = True
        position = np.empty(n, dtype=index)
        position[self.free] = np.arange(nf, dtype=index)
        position[self.fixed] = np.arange(len(self.fixed), dtype=index)
        pointers = [np.zeros(size + 1 if wanted else 1, dtype=index) for size, wanted in ((n, whole), (nf, blocks),
                                                                                          (nf, blocks))]
        if not count_rows(n, self.i, self.j, position, fixed, whole, *pointers):
            return None
        parts = []  # (row pointers, column indices, values) of L, L_FF, L_FD
        for indptr in pointers:
            np.cumsum(indptr, out=indptr)
            parts.append((indptr, np.empty(indptr[-1], dtype=index), np.empty(indptr[-1])))
        write_rows(n, self.i, self.j, self.K, position, fixed, whole, *parts[0], *parts[1], *parts[2])
        matrices = []
        for (indptr, indices, data), shape, wanted in zip(parts, ((n, n), (nf, nf), (nf, len(self.fixed))),
                                                          (whole, blocks, blocks)):
            matrices.append(sp.csr_matrix((data, indices, indptr), shape=shape, copy=False) if wanted else None)
            if wanted:
                matrices[-1].has_sorted_indices = True
        return (matrices[0], matrices[0], sp.csr_matrix((n, 0))) if whole else tuple(matrices)

    def _laplacian(self):
        """``L``, written now where the blocks were written without it."""
        if self._current()[0] is None:
            self._matrices = (self._compiled(whole=True)[0], *self._matrices[1:])
        return self._matrices[0]

    L = property(_laplacian, doc="The weighted graph Laplacian of all nodes (CSR).")
    L_FF = property(lambda self: self._current()[1], doc="Its free-free block (CSR).")
    L_FD = property(lambda self: self._current()[2], doc="Its free-fixed block (CSR).")

    def _diagonals(self):
        if self._diags is None:
            plane = np.bincount(self.plane_node, self.K_plane, self.n).astype(float)[self.free]
            self._diags = (plane, -np.asarray(self.L_FD.sum(axis=1)).ravel())
        return self._diags

    plane_diag = property(lambda self: self._diagonals()[0],
                          doc="The sum of each free node's plane conductances.")
    fixed_diag = property(lambda self: self._diagonals()[1],
                          doc="The sum of each free node's conductances to fixed nodes.")

    def same_edges(self, i, j, plane_node, plane_index) -> bool:
        """Whether these edges and plane bonds are those of the assembled matrices (same order).

        Parameters
        ----------
        i, j : array_like
            (M,) int, the edges' nodes.
        plane_node : array_like
            (B,) int, the node of each plane bond.
        plane_index : array_like
            (B,) int, the plane of each plane bond.

        Returns
        -------
        bool
            True where all four arrays equal the assembled ones.
        """
        return all(a is b or np.array_equal(a, b) for a, b in ((i, self.i), (j, self.j),
                                                               (plane_node, self.plane_node),
                                                               (plane_index, self.plane_index)))

    def refresh(self, i, j, K, plane_node, plane_index, K_plane) -> None:
        """New conductances on the same edges and plane bonds, in the same order: the matrices keep their sparsity
        and only their entries are rewritten (no re-assembly, no new sparsity analysis), when next asked for.

        Parameters
        ----------
        i, j : array_like
            (M,) int, the edges' nodes.
        K : array_like
            (M,) edge conductances (W/K for heat, S for current).
        plane_node : array_like
            (B,) int, the node of each plane bond.
        plane_index : array_like
            (B,) int, the plane of each plane bond.
        K_plane : array_like
            (B,) plane bond conductances (same unit).

        Raises
        ------
        ValueError
            The edges or plane bonds are not the assembled ones.
        """
        if not self.same_edges(i, j, plane_node, plane_index):
            raise ValueError("BoundedLaplacian.refresh: the edges changed; build a new one")
        self._set(i, j, K, plane_node, plane_index, K_plane)
        self._stale = True

    @property
    def laplacian_diagonal(self) -> np.ndarray:
        """Diagonal of ``L_FF`` (the part of ``A`` that edges make; for the choice of linear solver)."""
        return self.L_FF.diagonal()

    def matrix(self, extra_diag=None, shared: bool = False) -> sp.csr_matrix:
        r""":math:`A = L_{FF} + \mathrm{diag}(\text{plane conductances} + \text{extra\_diag})`, CSR.

        Parameters
        ----------
        extra_diag : array_like or None
            Per free node, more on the diagonal (e.g. ``C/dt`` or an ambient's conductance; the unit of ``K``);
            None: nothing.
        shared : bool
            True: ``L_FF`` itself where the sum would be its copy (nothing added to its diagonal, no zero entry
            for the sum to drop), for a caller that neither writes into ``A`` nor keeps it past a :meth:`refresh`
            (no fresh matrix: at :math:`10^6` nodes 143 MB the kernel clears); False: always a new matrix.

        Returns
        -------
        scipy.sparse.csr_matrix
            ``A`` on the free nodes.
        """
        extra = self.plane_diag if extra_diag is None else self.plane_diag + extra_diag
        if shared and not np.any(extra) and np.all(self.L_FF.data):
            return self.L_FF
        return (self.L_FF + sp.diags(extra)).tocsr()

    def plane_rhs(self, x_planes) -> np.ndarray:
        """``sum_w K_kw x_w`` per free node: what the planes at values ``x_planes`` drive into it.

        Parameters
        ----------
        x_planes : array_like
            The planes' values (K for heat, V for current).

        Returns
        -------
        numpy.ndarray
            Per free node (W for heat, A for current).
        """
        x_planes = np.asarray(x_planes, dtype=float)
        if not len(self.plane_node):
            return np.zeros(len(self.free))
        return np.bincount(self.plane_node, self.K_plane * x_planes[self.plane_index], self.n)[self.free]

    def boundary_rhs(self, x_fixed, x_planes) -> np.ndarray:
        """``b = -L_FD x_D + sum_w K_kw x_w`` per free node.

        Parameters
        ----------
        x_fixed : array_like
            The fixed nodes' values (K or V), in the order of ``fixed``.
        x_planes : array_like
            The planes' values (K for heat, V for current).

        Returns
        -------
        numpy.ndarray
            ``b`` per free node (W for heat, A for current).
        """
        b = self.plane_rhs(x_planes)
        if len(self.fixed):
            b = b - self.L_FD @ np.asarray(x_fixed, dtype=float)
        return b

    def components(self, anchor_extra=None):
        """Connected groups of free nodes: ``(count, label per free node, anchored per group)``; a group is
        anchored when one of its nodes is joined to a fixed node, a plane or (``anchor_extra > 0``) an ambient.
        Only edges with ``K > 0`` join nodes (an edge with ``K = 0``, an open contact, is none).

        Parameters
        ----------
        anchor_extra : array_like or None
            Per free node, a conductance to an ambient (> 0 anchors its group); None: none.

        Returns
        -------
        tuple
            ``(count, label, anchored)``: the number of groups, each free node's group, and a bool per group.
        """
        if np.all(self.K > 0.0):
            # every edge joins: the free block's sparsity is the graph (its diagonal loops), symmetric, so its
            # groups are those of its pattern; a large one's by union-find compiled (a fifth of scipy's time), a
            # smaller one's as its strongly connected components, without the transpose an undirected search makes
            L_FF = self.L_FF
            if len(self.free) >= COMPILED_GROUPS_FROM:
                from dem.network.groups import groups  # compiled: a smaller network loads no numba

                n_comp, label = groups(L_FF.indptr, L_FF.indices)
            else:
                n_comp, label = connected_components(L_FF, directed=True, connection="strong")
        else:
            where = np.full(self.n, -1, dtype=np.int64)
            where[self.free] = np.arange(len(self.free))
            a, b = where[self.i], where[self.j]
            live = (self.K > 0.0) & (a >= 0) & (b >= 0)
            nf = len(self.free)
            graph = sp.csr_matrix((np.ones(int(live.sum())), (a[live], b[live])), shape=(nf, nf))
            n_comp, label = connected_components(graph, directed=False)
        anchor = self.fixed_diag + self.plane_diag
        if anchor_extra is not None:
            anchor = anchor + anchor_extra
        anchored = np.zeros(n_comp, dtype=bool)
        anchored[label[anchor > 0]] = True
        return n_comp, label, anchored

    def flux(self, x, x_planes, out=None) -> np.ndarray:
        """Net flow into every node (fixed ones too) at node values ``x`` (all nodes) with the planes at
        ``x_planes``: ``-(L x)_k + sum_w K_kw (x_w - x_k)`` (W for heat: the conducted heat ``Q_k``). Summed edge by
        edge in the order of the edges, then the plane bonds (:func:`dem.network.flux.edge_flux`), from the conductances as they
        are (right after :meth:`refresh`, without the matrices). ``out``: an array of ``n`` to write into.

        Parameters
        ----------
        x : array_like
            (n,) the values of all nodes (K or V).
        x_planes : array_like
            The planes' values (K for heat, V for current).
        out : numpy.ndarray or None
            (n,) an array to write into; None: a new one.

        Returns
        -------
        numpy.ndarray
            (n,) the net flow into each node (W for heat, A for current).
        """
        from dem.network.flux import edge_flux  # compiled: imported by the moving engines only (a static run loads no numba)

        out = np.empty(self.n) if out is None else out
        edge_flux(self.i, self.j, self.K, self.plane_node, self.plane_index, self.K_plane,
                  np.asarray(x, dtype=float), np.asarray(x_planes, dtype=float), out)
        return out

    def full(self, x_free, x_fixed) -> np.ndarray:
        """Values on all nodes from those of the free and the fixed nodes.

        Parameters
        ----------
        x_free : array_like
            The free nodes' values, in the order of ``free``.
        x_fixed : array_like
            The fixed nodes' values, in the order of ``fixed``.

        Returns
        -------
        numpy.ndarray
            (n,) the values of all nodes.
        """
        x = np.empty(self.n)
        x[self.free] = x_free
        x[self.fixed] = x_fixed
        return x


def solve_anchored(system: BoundedLaplacian, rhs: np.ndarray, subset: np.ndarray | None = None, linear: str = "auto",
                   rtol: float = 1e-12, solver=None, previous=None):
    """Solve ``A x = rhs`` on the free nodes listed by ``subset`` (positions in ``system.free``; all when None),
    e.g. the anchored groups, where ``A`` is definite. Returns ``(x on the subset, solver)``; pass the solver back
    to reuse its factorisation for another right-hand side of the same matrix, or as ``previous`` for a matrix
    that changed a little (its AMG hierarchy serves again, :func:`dem.network.linsolve.make_solver`).

    Parameters
    ----------
    system : BoundedLaplacian
        The network.
    rhs : numpy.ndarray
        The right-hand side per free node (W for heat, A for current).
    subset : numpy.ndarray or None
        Positions in ``system.free`` to solve on; None: all.
    linear : str
        The linear solver (``dem.network.linsolve.BACKENDS``, or ``"auto"``).
    rtol : float
        Relative residual tolerance of an iterative solver.
    solver : object or None
        A solver of this very matrix to reuse; None: make one.
    previous : object or None
        A solver of a matrix that changed a little, whose AMG hierarchy serves again; None: none.

    Returns
    -------
    tuple
        ``(x, solver)``: the values on the subset (K or V) and the solver used.
    """
    if subset is not None and len(subset) == 0:
        return np.zeros(0), solver
    if solver is None:
        A, diag = system.matrix(), system.laplacian_diagonal
        if subset is not None and len(subset) != len(system.free):
            A, diag = A[subset][:, subset], diag[subset]
        solver = make_solver(A, linear, diag, rtol, previous)
    r = rhs if subset is None or len(subset) == len(system.free) else rhs[subset]
    if len(r) == 0:
        return np.zeros(0), solver
    return solver.solve(r), solver
