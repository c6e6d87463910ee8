r"""Mesh convergence of the semisphere conductance (Rojek 2022, Fig. 15 analogue).

Series: P1 and P2 elements on meshes graded toward the re-entrant corner (size = grading x distance) and on
uniform meshes, plus P2 with straight-sided boundary triangles (to show what the curved boundary buys), and the hp
series: orders 2 to 9 on one geometric quadrilateral mesh with the exact sphere (:mod:`fem_neck.hpmesh`), which
converges exponentially (``hp_error_ratio_per_order``: median factor by which the error falls per order). Each
triangle level reports the raw reaction conductance (no geometry correction).

:func:`study` runs it all: ``extrapolated`` is the Aitken (Richardson with a fitted exponent) limit of the three finest
graded P2 levels (:func:`aitken`); ``observed_order`` is the exponent ``q`` of :math:`|K - K_{ref}| \sim N^{-q}` in the
dofs :math:`N` over those levels (:func:`observed_order`), with ``K_ref`` an hp solve to rtol 1e-9 (``reference``).
"""

from __future__ import annotations

import json
import math
import pathlib
import sys

import numpy as np

GRADINGS = (0.6, 0.45, 0.3, 0.2, 0.13, 0.09)
UNIFORM_SIZES = (0.2, 0.1, 0.05, 0.025, 0.0125)
SERIES = (  # (label, order, graded, curved)
    ("P1 graded", 1, True, False),
    ("P2 graded", 2, True, True),
    ("P2 graded, straight boundary", 2, True, False),
    ("P1 uniform", 1, False, False),
    ("P2 uniform", 2, False, True),
)
HP_SERIES = "hp, geometric mesh, exact sphere"
HP_ORDERS = tuple(range(2, 10))
HP_LEVELS = 4
REFERENCE_RTOL = 1e-9  # the hp solve the errors are measured against


def aitken(k1: float, k2: float, k3: float) -> float:
    r"""Limit of a sequence converging geometrically:
    :math:`k_3 - (k_3 - k_2)^2 / \left((k_3 - k_2) - (k_2 - k_1)\right)`.

    Parameters
    ----------
    k1, k2, k3 : float
        Three successive values of the sequence, coarsest first (here ``K/K_cyl`` of the three finest graded P2 levels,
        dimensionless). Returns ``k3`` when the second difference vanishes.
    """
    denominator = (k3 - k2) - (k2 - k1)
    return k3 if denominator == 0.0 else k3 - (k3 - k2) ** 2 / denominator


def observed_order(dofs, values, reference: float) -> float:
    """Least-squares slope ``q`` of ``log|K - K_ref|`` against ``-log dofs`` (NaN from fewer than two errors).

    Parameters
    ----------
    dofs : array_like of int
        Unknowns of each level.
    values : array_like of float
        The quantity at each level (here ``K/K_cyl``, dimensionless).
    reference : float
        The value the errors are measured against (here the hp solve to rtol 1e-9), in the unit of ``values``.
    """
    err = np.abs(np.asarray(values) - reference)
    keep = err > 0
    if keep.sum() < 2:
        return float("nan")
    return float(-np.polyfit(np.log(np.asarray(dofs, dtype=float)[keep]), np.log(err[keep]), 1)[0])


def error_ratio_per_order(values, reference: float) -> float:
    """Median factor by which the error falls from one order to the next (above the round-off floor 1e-12).

    Parameters
    ----------
    values : sequence of float
        The quantity at successive orders, lowest first (here ``K/K_cyl`` of the hp series, dimensionless).
    reference : float
        The value the relative errors are measured against, in the unit of ``values`` (non-zero).
    """
    err = np.array([abs(v - reference) / reference for v in values])
    keep = (err[:-1] > 1e-12) & (err[1:] > 1e-12)
    return float(np.median(err[:-1][keep] / err[1:][keep])) if keep.any() else float("nan")


def levels_count() -> int:
    """Number of solves of :func:`mesh_levels` (for a progress bar)."""
    return sum(len(GRADINGS if graded else UNIFORM_SIZES) for _, _, graded, _ in SERIES) + len(HP_ORDERS)


def mesh_levels(a_over_r: float, progress=None) -> list[dict]:
    """One row per solve of every series (module docstring); ``progress.update()`` after each, if given.

    Parameters
    ----------
    a_over_r : float
        Neck radius over sphere radius ``a/r`` of the semisphere (dimensionless, in ``(0, 1)``).
    progress : object, optional
        Anything with an ``update()`` method (a tqdm bar), called once after each solve.
    """
    from fem_neck import conduction, hpmesh, shapes, spectral
    from sinterheat.interrupt import where

    levels, here, total = [], where(), levels_count()
    for label, order, graded, curved in SERIES:
        for step in GRADINGS if graded else UNIFORM_SIZES:
            here.update(step=f"level {len(levels) + 1} of {total} ({label})")
            sizes = shapes.SizeField(grading=step) if graded else shapes.SizeField(uniform=step)
            profile = shapes.semisphere_mesh(a_over_r, sizes=sizes)
            sol = conduction.solve_profile(profile, order=order, curved=curved)
            levels.append({
                "series": label, "order": order, "grading": "graded" if graded else "uniform", "curved": curved,
                "size_parameter": step, "dofs": sol.dofs, "h_min": profile.h_min,
                "elements_across_neck": int(profile.mesh.boundaries["top"].size),
                "K_over_Kcyl": sol.K_reaction / math.pi, "K_over_Kcyl_corrected": sol.K / math.pi,
            })
            if progress is not None:
                progress.update()
    mesh, shape = hpmesh.semisphere_quad_mesh(a_over_r, HP_LEVELS)
    fixed = hpmesh.end_disks(mesh, shape)
    for order in HP_ORDERS:
        here.update(step=f"level {len(levels) + 1} of {total} ({HP_SERIES}, order {order})")
        sol = spectral.conductance(mesh, order, fixed)
        levels.append({
            "series": HP_SERIES, "order": order, "grading": "geometric", "curved": True,
            "size_parameter": hpmesh.SIGMA, "dofs": sol.dofs, "h_min": None, "elements_across_neck": None,
            "K_over_Kcyl": sol.K_over_kappa / math.pi, "K_over_Kcyl_corrected": sol.K_over_kappa / math.pi,
        })
        if progress is not None:
            progress.update()
    return levels


def study(a_over_r: float, out=None, *, progress: bool = True, title: str | None = None) -> dict:
    """The whole study at ``a_over_r``: every level, the Aitken limit, observed orders, the hp error ratio and the
    reference. With ``out``, writes ``converge.png`` and ``converge.json`` there (``plot`` names the PNG).

    Parameters
    ----------
    a_over_r : float
        Neck radius over sphere radius ``a/r`` of the semisphere (dimensionless, in ``(0, 1)``).
    out : str or pathlib.Path, optional
        Folder for ``converge.png`` and ``converge.json`` (created if missing); None writes nothing.
    progress : bool
        Show a progress bar on stderr (tqdm; off when stderr is not a terminal).
    title : str, optional
        Title of the plot's left panel; default ``semisphere a/r=...``.
    """
    from tqdm import tqdm

    from fem_neck import conduction
    from fem_neck.geometry import overlap_for_neck

    try:
        reference = conduction.semisphere_conductance(a_over_r, rtol=REFERENCE_RTOL)
        with tqdm(total=levels_count(), desc="converge", file=sys.stderr, disable=None if progress else True) as bar:
            levels = mesh_levels(a_over_r, bar)
    except RuntimeError as exc:  # a mesh gmsh cannot make: reported like bad input
        raise ValueError(str(exc)) from exc
    k_ref = reference.K_over_Kcyl

    def series(label):
        return [lv for lv in levels if lv["series"] == label]

    orders = {label: observed_order([lv["dofs"] for lv in series(label)][-3:],
                                    [lv["K_over_Kcyl"] for lv in series(label)][-3:], k_ref)
              for label, *_ in SERIES}
    summary = {
        "h_over_r": float(overlap_for_neck(1.0, 1.0, a_over_r)), "a_over_r": a_over_r, "levels": levels,
        "extrapolated": aitken(*[lv["K_over_Kcyl"] for lv in series("P2 graded")[-3:]]),
        "observed_order": orders["P2 graded"], "observed_orders": orders,
        "hp_error_ratio_per_order": error_ratio_per_order([lv["K_over_Kcyl"] for lv in series(HP_SERIES)], k_ref),
        "reference": k_ref, "reference_error_estimate": reference.error_estimate, "plot": None,
    }
    if out is not None:
        out = pathlib.Path(out)
        out.mkdir(parents=True, exist_ok=True)
        summary["plot"] = str(out / "converge.png")
        plot(levels, k_ref, out / "converge.png", title or f"semisphere a/r={a_over_r:.4g}")
        (out / "converge.json").write_text(json.dumps(summary, indent=2) + "\n")
    return summary


def plot(levels, reference: float, path, title: str) -> None:
    """K/K_cyl against elements across the neck, and the relative error against dofs, per series.

    Parameters
    ----------
    levels : list of dict
        The rows of :func:`mesh_levels`.
    reference : float
        ``K/K_cyl`` the errors are measured against (dimensionless), drawn as a horizontal line.
    path : str or pathlib.Path
        The PNG file to write.
    title : str
        Title of the left panel.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(12, 4.8), layout="tight")
    FigureCanvasAgg(fig)
    left, right = fig.subplots(1, 2)
    for label in [s[0] for s in SERIES] + [HP_SERIES]:
        rows = [lv for lv in levels if lv["series"] == label]
        style = "-^" if label == HP_SERIES else "-o" if "graded" in label else "--s"
        if label != HP_SERIES:
            left.semilogx([lv["elements_across_neck"] for lv in rows], [lv["K_over_Kcyl"] for lv in rows], style,
                          label=label, ms=4)
        err = [max(abs(lv["K_over_Kcyl"] - reference) / reference, 1e-16) for lv in rows]
        right.loglog([lv["dofs"] for lv in rows], err, style, label=label, ms=4)
    left.axhline(reference, color="k", lw=0.8, label=f"reference {reference:.9f}")
    left.set_xlabel("elements across the neck (facets on the neck-end disk)")
    left.set_ylabel("K / K_cyl")
    left.set_title(title)
    right.set_xlabel("degrees of freedom")
    right.set_ylabel("|K - K_ref| / K_ref")
    right.set_title("relative error (reaction, no geometry correction)")
    for ax in (left, right):
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.savefig(path, dpi=120)
