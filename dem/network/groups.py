"""The connected groups of a large network's graph, compiled: one pass of union-find over a symmetric sparsity
pattern, where scipy's search (``scipy.sparse.csgraph.connected_components``) makes a transposed copy (undirected) or
a stack of the strongly connected components' search (directed, of a symmetric pattern) at several times the cost.
Apart so that a smaller network loads no numba."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _root(parent, a):
    while parent[a] != a:  # path halving
        parent[a] = parent[parent[a]]
        a = parent[a]
    return a


@njit(cache=True)
def groups(indptr, indices):
    """The connected groups of the graph whose edges are the entries of a CSR matrix with a symmetric sparsity
    pattern (the diagonal ignored). The root of a group is its smallest node.

    Parameters
    ----------
    indptr : numpy.ndarray
        (n + 1,) int, the matrix's row starts.
    indices : numpy.ndarray
        int, the matrix's column indices.

    Returns
    -------
    tuple
        ``(count, label)``: the number of groups and each node's group (int64), numbered in the order of the groups'
        smallest nodes, as scipy's undirected search numbers them.
    """
    n = indptr.shape[0] - 1
    parent = np.arange(n)
    for i in range(n):
        for e in range(indptr[i], indptr[i + 1]):
            j = np.int64(indices[e])
            if j > i:  # each edge once: the upper triangle of the symmetric pattern
                a, b = _root(parent, i), _root(parent, j)
                if a < b:
                    parent[b] = a
                elif b < a:
                    parent[a] = b
    label = np.empty(n, np.int64)
    count = 0
    for i in range(n):
        root = _root(parent, i)
        if root == i:
            label[i] = count
            count += 1
        else:
            label[i] = label[root]  # root < i: numbered already
    return count, label
