"""``python -m fem_neck converge``: mesh convergence of the semisphere conductance (Rojek 2022, Fig. 15 analogue).

Series: P1 and P2 elements on meshes graded toward the re-entrant corner (size = grading x distance) and on
uniform meshes, plus P2 with straight-sided boundary triangles (to show what the curved boundary buys), and the hp series: orders
2 to 9 on one geometric quadrilateral mesh with the exact sphere (``fem_neck.hpmesh``), which converges
exponentially (``hp_error_ratio_per_order``: median factor by which the error falls per order). Each triangle level
reports the raw reaction conductance (no geometry correction). ``extrapolated`` is the Aitken (Richardson with a
fitted exponent) limit of the three finest graded P2 levels; ``observed_order`` is the exponent ``q`` of
``|K - K_ref| ~ dofs^-q`` over those levels, with ``K_ref`` an hp solve to rtol 1e-9 (``reference``).
"""

from __future__ import annotations

import math

import numpy as np

from fem_neck.cli import add_output_options

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
LEVEL_COUNT = sum(len(GRADINGS if graded else UNIFORM_SIZES) for _, _, graded, _ in SERIES) + len(HP_ORDERS)


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "converge", help="mesh convergence of the semisphere conductance (Fig. 15 analogue)",
        description=__doc__.splitlines()[0] + " Writes converge.png and converge.json into --out (default: .).")
    size = p.add_mutually_exclusive_group(required=True)
    size.add_argument("--h-over-r", type=float, metavar="X", help="overlap over r, 0 < X < 2/3")
    size.add_argument("--a-over-r", type=float, metavar="X", help="neck radius over r, 0 < X < 1")
    add_output_options(p)
    p.set_defaults(run=run)


def aitken(k1: float, k2: float, k3: float) -> float:
    """Limit of a sequence converging geometrically: ``k3 - (k3 - k2)^2 / ((k3 - k2) - (k2 - k1))``."""
    denominator = (k3 - k2) - (k2 - k1)
    return k3 if denominator == 0.0 else k3 - (k3 - k2) ** 2 / denominator


def observed_order(dofs, values, reference: float) -> float:
    """Least-squares slope ``q`` of ``log|K - K_ref|`` against ``-log dofs``."""
    err = np.abs(np.asarray(values) - reference)
    keep = err > 0
    if keep.sum() < 2:
        return float("nan")
    return float(-np.polyfit(np.log(np.asarray(dofs, dtype=float)[keep]), np.log(err[keep]), 1)[0])


def _levels(a: float, progress):
    from fem_neck import conduction, shapes
    from fem_neck.interrupt import where

    levels = []
    here = where()
    for label, order, graded, curved in SERIES:
        steps = GRADINGS if graded else UNIFORM_SIZES
        for step in steps:
            here.update(step=f"level {len(levels) + 1} of {LEVEL_COUNT} ({label})")
            sizes = shapes.SizeField(grading=step) if graded else shapes.SizeField(uniform=step)
            profile = shapes.semisphere_mesh(a, sizes=sizes)
            sol = conduction.solve_profile(profile, order=order, curved=curved)
            levels.append({
                "series": label, "order": order, "grading": "graded" if graded else "uniform", "curved": curved,
                "size_parameter": step, "dofs": sol.dofs, "h_min": profile.h_min,
                "elements_across_neck": int(profile.mesh.boundaries["top"].size),
                "K_over_Kcyl": sol.K_reaction / math.pi, "K_over_Kcyl_corrected": sol.K / math.pi,
            })
            progress.update()
    from fem_neck import hpmesh, spectral

    mesh, shape = hpmesh.semisphere_quad_mesh(a, HP_LEVELS)
    fixed = hpmesh.end_disks(mesh, shape)
    for order in HP_ORDERS:
        here.update(step=f"level {len(levels) + 1} of {LEVEL_COUNT} (hp order {order})")
        sol = spectral.conductance(mesh, order, fixed)
        levels.append({
            "series": HP_SERIES, "order": order, "grading": "geometric", "curved": True,
            "size_parameter": hpmesh.SIGMA, "dofs": sol.dofs, "h_min": None, "elements_across_neck": None,
            "K_over_Kcyl": sol.K_over_kappa / math.pi, "K_over_Kcyl_corrected": sol.K_over_kappa / math.pi,
        })
        progress.update()
    return levels


def _error_ratio(rows, reference: float) -> float:
    """Median factor by which the error falls from one order to the next (above the round-off floor 1e-12)."""
    err = np.array([abs(lv["K_over_Kcyl"] - reference) / reference for lv in rows])
    keep = (err[:-1] > 1e-12) & (err[1:] > 1e-12)
    return float(np.median(err[:-1][keep] / err[1:][keep])) if keep.any() else float("nan")


def _plot(levels, reference: float, path, title: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.8))
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
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def run(args) -> dict:
    import json
    import pathlib

    from tqdm import tqdm

    from fem_neck import conduction
    from fem_neck.cli.solve import semisphere_case

    h, a = semisphere_case(args)
    try:
        reference = conduction.semisphere_conductance(a, rtol=1e-9)
        with tqdm(total=LEVEL_COUNT, desc="converge", file=__import__("sys").stderr, disable=None) as progress:
            levels = _levels(a, progress)
    except RuntimeError as exc:
        raise ValueError(str(exc)) from exc
    k_ref = reference.K_over_Kcyl
    p2 = [lv for lv in levels if lv["series"] == "P2 graded"]
    orders = {label: observed_order([lv["dofs"] for lv in levels if lv["series"] == label][-3:],
                                    [lv["K_over_Kcyl"] for lv in levels if lv["series"] == label][-3:], k_ref)
              for label, *_ in SERIES}
    out = pathlib.Path(args.out or ".")
    out.mkdir(parents=True, exist_ok=True)
    summary = {
        "h_over_r": h, "a_over_r": a, "levels": levels,
        "extrapolated": aitken(*[lv["K_over_Kcyl"] for lv in p2[-3:]]),
        "observed_order": orders["P2 graded"], "observed_orders": orders,
        "hp_error_ratio_per_order": _error_ratio([lv for lv in levels if lv["series"] == HP_SERIES], k_ref),
        "reference": k_ref, "reference_error_estimate": reference.error_estimate,
        "plot": str(out / "converge.png"),
    }
    _plot(levels, k_ref, out / "converge.png", f"semisphere h/r={h:.4g}, a/r={a:.4g}")
    (out / "converge.json").write_text(json.dumps(summary, indent=2) + "\n")
    return summary
