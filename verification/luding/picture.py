"""A 2D packing with its contacts drawn in the style of Luding 2005, Figs. 20-22 (the pictures of the sintering
report)."""

from __future__ import annotations

import numpy as np


def draw_packing(ax, x, radius, mean_stress, i, j, fn, ft, walls=(), stress_range=None, title=None):
    """A 2D packing (x-z plane) in the style of Luding 2005, Figs. 20-22: circles coloured by the particle's mean
    stress (blue low, green medium, red high; ``stress_range`` (low, high) or the 5-95 % range), contacts
    ``(i, j)`` as lines blue where the normal force ``fn`` attracts and red where it repels, the tangential force
    ``ft`` as a black dot at the contact (area proportional to its magnitude), ``walls`` as thick blue lines (each
    ``((x0, z0), (x1, z1))``). Lengths in mm."""
    import matplotlib
    from matplotlib.collections import LineCollection, PatchCollection
    from matplotlib.patches import Circle

    x = np.asarray(x) * 1e3
    radius = np.asarray(radius) * 1e3
    lo, hi = stress_range if stress_range is not None else np.percentile(mean_stress, [5, 95])
    norm = matplotlib.colors.Normalize(lo, hi if hi > lo else lo + 1.0)
    colours = matplotlib.colormaps["jet"](norm(mean_stress))
    circles = PatchCollection([Circle((a, c), r) for (a, _, c), r in zip(x, radius)], facecolors="none",
                              edgecolors=colours, linewidths=0.8)
    ax.add_collection(circles)
    fn = np.asarray(fn)
    segments = np.stack([x[i][:, [0, 2]], x[j][:, [0, 2]]], axis=1) if len(i) else np.zeros((0, 2, 2))
    ax.add_collection(LineCollection(segments, colors=np.where(fn[:, None] < 0, [[0, 0, 1, 1]], [[1, 0, 0, 1]]),
                                     linewidths=0.7))
    if len(i):
        middle = segments.mean(axis=1)
        size = np.asarray(ft) / max(float(np.max(ft)), 1e-300) * 12.0
        ax.scatter(middle[:, 0], middle[:, 1], s=size, c="k", linewidths=0)
    for (a, b) in walls:
        ax.plot([a[0] * 1e3, b[0] * 1e3], [a[1] * 1e3, b[1] * 1e3], color="tab:blue", lw=3)
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("z (mm)")
    if title:
        ax.set_title(title, fontsize=8)
    return norm
