"""The net flow into every node of a network, compiled: :meth:`dem.network.laplacian.BoundedLaplacian.flux` (the
particles that move evaluate it at every iteration of their steps). Apart from the Laplacian's module so that a static
run, which never asks for it, loads no numba."""

from __future__ import annotations

from numba import njit


@njit(cache=True)
def edge_flux(i, j, K, plane_node, plane_index, K_plane, x, x_planes, out):
    """``out_k = -(L x)_k + sum_w K_kw (x_w - x_k)`` (:meth:`~dem.network.laplacian.BoundedLaplacian.flux`):
    every edge's flow ``K_c (x_i - x_j)`` leaves i and enters j, in the order of the edges; then every plane bond's
    flow ``K_kw (x_k - x_w)`` leaves k."""
    for k in range(out.shape[0]):
        out[k] = 0.0
    for c in range(i.shape[0]):
        if K[c] == 0.0:  # an open contact carries nothing
            continue
        flow = K[c] * (x[i[c]] - x[j[c]])
        out[i[c]] -= flow
        out[j[c]] += flow
    for e in range(plane_node.shape[0]):
        k = plane_node[e]
        out[k] -= K_plane[e] * (x[k] - x_planes[plane_index[e]])
