"""The closing pores' cap calibrated on FE cells that ``python -m verification densification`` does not check.

The ``shared-body`` law on the union of spheres caps each particle's mean conductivity where the pores around it
close (:mod:`dem.laws.closing_pores`) with two numbers, ``beta`` (how fast the pores' slope grows with their
thinness) and ``psi0`` (the shape up to which pores keep the Wiener cap). They are chosen here: the periodic-cell FE
(:mod:`fem_neck.lattice`, two-sided bounds) of union cells that are none of the densification study's cases --
simple, body- and face-centred cubic lattices at other overlaps, and random mirror packings of other seeds and
solid fractions (:func:`verification.packings.union_packing`) -- against the DEM on the same periodic cells, on a
grid of ``beta`` and ``psi0``; the pair with the least root-mean-square relative error over the cells is written,
with the cells, their FE and the errors, into ``closing_pores.json`` (the file the law ships as
``dem/laws/closing_pores.json``).
"""

from __future__ import annotations

import itertools
import json
import pathlib
import time

import numpy as np

from fem_neck import lattice
from verification.lattices import FECache, dem_periodic, solve_cells
from verification.report import jsonable

# union cells none of which the densification study checks (its overlaps and its seeds 1-3)
OVERLAPS = {"sc": (0.35, 0.42, 0.45, 0.47, 0.52, 0.55, 0.57, 0.58, 0.62, 0.65),
            "bcc": (0.22, 0.24, 0.25, 0.26, 0.27, 0.28, 0.29, 0.31, 0.32, 0.33, 0.34, 0.36, 0.38),
            "fcc": (0.12, 0.14, 0.15, 0.16, 0.18, 0.22, 0.24, 0.25, 0.26, 0.28, 0.31, 0.33)}
RANDOM = ((4, 0.9), (5, 0.93), (6, 0.85), (7, 0.7))  # (seed, phi aimed at) of the union mirror packings
QUICK_OVERLAPS, QUICK_RANDOM = {"sc": (0.55,), "fcc": (0.25,)}, ()
RANDOM_SPHERES = 4  # union_packing(n): 8 n spheres per period
RTOL, RANDOM_RTOL, QUICK_RTOL = 1e-3, 2e-3, 1e-2
BETAS = np.round(np.arange(0.4, 1.21, 0.1), 10)  # the grid of the calibration
PSI0S = np.round(np.arange(2.5, 4.51, 0.25), 10)


def cells(quick: bool = False) -> dict:
    """The calibration cells: FE cache key -> (cell, kind, rtol)."""
    from verification.packings import union_packing

    out = {}
    for kind, hs in (QUICK_OVERLAPS if quick else OVERLAPS).items():
        rtol = QUICK_RTOL if quick else RTOL
        for h in hs:
            out[f"{kind} union h/r={h:g} rtol={rtol:g}"] = (lattice.lattice_cell(kind, h, neck="union"), kind, rtol)
    for seed, phi in (QUICK_RANDOM if quick else RANDOM):
        out[f"union packing seed={seed} phi={phi:g} rtol={RANDOM_RTOL:g}"] = (
            union_packing(RANDOM_SPHERES, phi, seed=seed), "random", RANDOM_RTOL)
    return out


def calibrate(fe: dict, networks) -> dict:
    """The grid point of least root-mean-square relative error.

    Parameters
    ----------
    fe : dict
        Case -> the FE's ``k_eff / kappa``.
    networks : callable
        ``networks(beta, psi0)`` -> case -> the DEM's ``k_eff / kappa`` with that cap.

    Returns
    -------
    dict
        ``beta``, ``psi0``, ``rms`` and ``worst`` (relative errors, dimensionless) and ``errors`` per case.
    """
    best = None
    for beta, psi0 in itertools.product(BETAS, PSI0S):
        k = networks(float(beta), float(psi0))
        errors = {case: k[case] / fe[case] - 1.0 for case in fe}
        rms = float(np.sqrt(np.mean(np.square(list(errors.values())))))
        if best is None or rms < best["rms"]:
            best = {"beta": float(beta), "psi0": float(psi0), "rms": rms,
                    "worst": float(max(abs(e) for e in errors.values())), "errors": errors}
    return best


def run(out_dir: pathlib.Path, quick: bool = False) -> dict:
    """Solve the calibration cells' FE (cached in ``fe_cache.json``), calibrate, write ``closing_pores.json``; the
    section contract of :mod:`verification.report`.

    Parameters
    ----------
    out_dir : pathlib.Path
        The section's folder.
    quick : bool
        Two lattice cells at a coarse tolerance, no random packing.

    Returns
    -------
    dict
        ``title``, ``markdown``, ``summary`` and ``figures``.
    """
    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    cache = FECache(out_dir / "fe_cache.json")
    table = cells(quick)
    fe = {}
    for rtol in sorted({rtol for _, _, rtol in table.values()}):
        group = {key: cell for key, (cell, _, tol) in table.items() if tol == rtol}
        fe.update({key: r["k"] for key, r in zip(group, solve_cells(group, rtol, cache))})

    def networks(beta, psi0):
        return {key: dem_periodic(cell, "shared-body", neck="union", closing_pores={"beta": beta, "psi0": psi0})
                for key, (cell, _, _) in table.items()}

    best = calibrate(fe, networks)
    without = {key: k / fe[key] - 1.0 for key, k in networks(0.0, 1.0).items()}  # beta = 0: the Wiener cap
    record = {"beta": best["beta"], "psi0": best["psi0"],
              "command": "python -m verification closing-pores" + (" --quick" if quick else ""),
              "grid": {"beta": BETAS.tolist(), "psi0": PSI0S.tolist()}, "objective": "least rms relative error",
              "rms": best["rms"], "worst": best["worst"],
              "cells": {key.rsplit(" rtol", 1)[0]: {"kind": kind, "phi": cell.phi, "rtol": rtol, "k_fe": fe[key],
                                                    "rel_err": best["errors"][key], "rel_err_wiener_cap": without[key]}
                        for key, (cell, kind, rtol) in table.items()}}
    (out_dir / "closing_pores.json").write_text(json.dumps(jsonable(record), indent=1) + "\n")
    lines = ["| cell | phi | k_FE / kappa | Wiener cap | calibrated cap |", "|---|---|---|---|---|"]
    for case, c in record["cells"].items():
        lines.append(f"| {case} | {c['phi']:.4f} | {c['k_fe']:.5f} | {100 * c['rel_err_wiener_cap']:+.2f} % | "
                     f"{100 * c['rel_err']:+.2f} % |")
    md = [__doc__.split("\n\n", 1)[1].strip(), "",
          f"Calibrated: beta = {best['beta']:g}, psi0 = {best['psi0']:g} (rms {100 * best['rms']:.2f} %, worst "
          f"{100 * best['worst']:.2f} %); written to closing_pores.json.", "", "\n".join(lines), "",
          f"Run time {time.perf_counter() - t0:.0f} s (FE results cached in fe_cache.json)."]
    summary = {"closing pores beta": best["beta"], "closing pores psi0": best["psi0"],
               "closing pores rms rel err": best["rms"], "closing pores worst rel err": best["worst"]}
    return {"title": "The closing pores' cap calibrated on FE cells the densification study does not check",
            "markdown": "\n".join(md), "summary": summary, "figures": []}
