"""Neck radius over random bonds: Coble (Rojek 2022, eqs. 11-12), the first Newton iterate (eq. 34) and the full
Newton (eqs. 27-33) of ``fem_neck.neck_radius``, against a plain vectorised numpy Newton on eq. (27) written here.

A DEM whose particles move calls ``neck_radius`` for every contact at every thermal update, so it must be no slower
than the textbook loop (target: ratio <= 1, timed side by side).
"""

from __future__ import annotations

import numpy as np

from benchmarks.timing import best_time, side_by_side
from fem_neck.geometry import coble_radius, max_overlap, neck_radius
from verification.report import records_table

TITLE = "Neck radius over random bonds"
RATIO_LIMIT = 1.0  # neck_radius / plain numpy Newton, side by side
ROUNDS = 5


def random_bonds(n: int, seed: int = 0):
    """``n`` random bonds: r_i in [10, 100] um, r_j/r_i in [1, 10], h uniform in (0, 0.95 max_overlap]."""
    rng = np.random.default_rng(seed)
    r_i = rng.uniform(10e-6, 100e-6, n)
    r_j = r_i * rng.uniform(1.0, 10.0, n)
    h = max_overlap(r_i, r_j) * rng.uniform(1e-3, 0.95, n)
    return r_i, r_j, h


def plain_newton(r_i, r_j, h, tol: float = 4.0 * np.finfo(float).eps, max_iterations: int = 60):
    """The baseline: textbook vectorised Newton on eq. (27) from Coble's start (eq. 33).

    ``Z(a) = 3 a^2 h_n - h_ci^2 (3 r_i - h_ci) - h_cj^2 (3 r_j - h_cj)`` with ``h_c = r - sqrt(r^2 - a^2)`` and
    ``Z'(a) = 6 a h_n`` (eq. 31 simplified); every bond iterates until the largest relative step is below ``tol``.
    No safeguards beyond clipping to the smaller radius.
    """
    r_min = np.minimum(r_i, r_j)
    a = np.minimum(np.sqrt(4.0 * r_i * r_j / (r_i + r_j) * h), r_min)
    for _ in range(max_iterations):
        h_ci = r_i - np.sqrt(r_i * r_i - a * a)
        h_cj = r_j - np.sqrt(r_j * r_j - a * a)
        h_n = h_ci + h_cj - h
        z = 3.0 * a * a * h_n - h_ci * h_ci * (3.0 * r_i - h_ci) - h_cj * h_cj * (3.0 * r_j - h_cj)
        step = z / (6.0 * a * h_n)
        a = np.minimum(a - step, r_min)
        if np.max(np.abs(step) / a) <= tol:
            break
    return a


def run(section, quick: bool) -> None:
    from matplotlib.figure import Figure

    n = 1_000_000  # quick too: the whole study takes a few seconds, and the target is set at this size
    r_i, r_j, h = random_bonds(n)
    repeat = 3
    neck_radius(r_i[:10], r_j[:10], h[:10])  # warm
    best, roots = side_by_side({"newton": lambda: neck_radius(r_i, r_j, h, method="newton"),
                                "plain": lambda: plain_newton(r_i, r_j, h)}, ROUNDS)
    a_ref = roots["newton"]
    rows = []
    for label, key, fn in [
        ("coble (eqs 11-12)", None, lambda: coble_radius(r_i, r_j, h)),
        ("first iterate (eq 34)", None, lambda: neck_radius(r_i, r_j, h, method="first")),
        ("newton (fem_neck.neck_radius)", "newton", None),
        ("plain numpy newton (baseline)", "plain", None),
    ]:
        t, a = (best[key], roots[key]) if key else best_time(fn, repeat)
        err = np.abs(a - a_ref) / a_ref
        rows.append({"method": label, "bonds": n, "seconds": t, "ns_per_bond": 1e9 * t / n,
                     "max_rel_error": float(err.max()), "median_rel_error": float(np.median(err))})
    section.csv("neck_radius", rows)
    ratio = best["newton"] / best["plain"]
    section.summary.update({"neck_bonds": n, "neck_newton_seconds": best["newton"],
                            "neck_plain_newton_seconds": best["plain"], "neck_newton_over_plain": ratio})

    fig = Figure(figsize=(5.5, 3.8))
    ax = fig.subplots()
    for row in rows:
        ax.loglog(row["seconds"], max(row["max_rel_error"], 1e-17), "o")
        ax.annotate(row["method"], (row["seconds"], max(row["max_rel_error"], 1e-17)), fontsize=7)
    ax.set_xlabel(f"wall time for {n:.0e} bonds [s]")
    ax.set_ylabel("max relative error of a (vs Newton)")
    ax.set_title("Neck radius: error against time")
    figure = section.figure(fig, "neck_radius")
    section.add_text(
        "Error against time",
        f"{n} random bonds (r_i in [10,100] um, r_j/r_i in [1,10], h up to 0.95 of the model's range, seed 0); "
        f"best of {repeat} (Newton and the baseline: best of {ROUNDS}, alternating); error relative to the "
        "converged Newton root. `neck_radius` runs the same Newton on blocks of 16 384 bonds, so its temporaries "
        "stay in the processor's cache.\n\n"
        + records_table(rows, ["method", "seconds", "ns_per_bond", "max_rel_error", "median_rel_error"])
        + f"\n\n`fem_neck.neck_radius` / plain numpy Newton = **{ratio:.2f}**, side by side; the two roots differ "
        f"by at most {rows[3]['max_rel_error']:.1e} relative.",
        figures=[figure],
    )
    section.target("`neck_radius` / plain numpy Newton, side by side", ratio, RATIO_LIMIT)
