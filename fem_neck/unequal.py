r"""Unequal radii: does the pair conductance depend on the neck radius only (Rojek 2022, eq. 43)?

FE of sintered pairs (``fem_neck.conduction.pair_conductance``, :math:`r_i = 1`, :math:`\kappa = 1`) for radius ratios
:math:`q = r_j/r_i` and necks :math:`a/r_i`, compared with

* ``eq43``: the paper's model, :math:`K = 1.064 \kappa \pi a / 2` whatever the radii (eqs. 43-45);
* ``halves``: the full-range law per half at its own ``a/r`` in series (eq. 9), without correction;
* ``corrected``: the same times :func:`fem_neck.law.unequal_factor`, whose coefficient ``c`` this study fits:
  ``K_halves / K_FE - 1 ~ c (a/r_i) ln q`` (least squares).

``a_only_spread`` measures the claim itself: at each neck, the spread of the FE conductance over the ratios
relative to the equal pair. Results go to unequal.json, unequal.csv and unequal.png.
"""

from __future__ import annotations

import csv
import json
import pathlib
import time

import numpy as np

from fem_neck import law as laws
from fem_neck.geometry import overlap_for_neck
from sinterheat.pool import run_jobs

RATIOS = (1.0, 2.0, 3.0, 5.0, 10.0)
NECKS = (0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95)
PAPER_CASE = {"r_i": 1e-3, "r_j": 3e-3, "h": 0.06e-3, "kappa": 394.0, "K_paper_fe": 0.278033,
              "K_paper_eq45": 0.276035}  # Rojek 2022, Section 6


def _solve_pair(r_i: float, r_j: float, h: float, kappa: float, rtol: float) -> dict:
    """Worker: one FE pair solve (child process)."""
    from fem_neck.conduction import pair_conductance

    res = pair_conductance(r_i, r_j, h, kappa, rtol=rtol)
    return {"r_i": r_i, "r_j": r_j, "h": h, "kappa": kappa, "a": float(res.necks[0]), "K_fe": float(res.K),
            "error_estimate": float(res.error_estimate), "dofs": int(res.dofs), "seconds": float(res.seconds)}


def _parse_list(name: str, values, lo: float, hi: float) -> tuple:
    try:
        out = tuple(float(v) for v in values)
    except (TypeError, ValueError):
        raise ValueError(f"{name} = {values!r}: must be numbers") from None
    if not out or any(not (lo <= v <= hi) for v in out):
        raise ValueError(f"{name} = {values!r}: each must be in [{lo}, {hi}]")
    return out


def study(ratios=RATIOS, necks=NECKS, rtol: float = 1e-4, out=None, *, workers: int | None = None,
          progress: bool = True, paper_rtol: float = 1e-6) -> dict:
    """Run the study (module docstring); with ``out`` write unequal.json, unequal.csv and unequal.png.

    Parameters
    ----------
    ratios : sequence of float
        Radius ratios :math:`q = r_j/r_i` to solve (dimensionless, each in ``[1, 100]``).
    necks : sequence of float
        Neck radii ``a/r_i`` to solve (dimensionless, each in ``[0.001, 0.99]``).
    rtol : float
        Relative error the FE solves of the grid are converged to (dimensionless, in ``(0, 0.1)``).
    out : str or pathlib.Path, optional
        Folder for unequal.json, unequal.csv and unequal.png (created if missing); None writes nothing.
    workers : int, optional
        Processes solving at once (:func:`sinterheat.pool.run_jobs`); default one per core.
    progress : bool
        Show a progress bar on stderr.
    paper_rtol : float
        Relative error the solve of the paper's case (Rojek 2022, Section 6: ``r_i`` = 1 mm, ``r_j`` = 3 mm,
        ``h`` = 0.06 mm, ``kappa`` = 394 W/(m K)) is converged to (dimensionless).
    """
    ratios = _parse_list("ratios", ratios, 1.0, 100.0)
    necks = _parse_list("necks", necks, 1e-3, 0.99)
    if not (isinstance(rtol, float) and 0.0 < rtol < 0.1):
        raise ValueError(f"rtol = {rtol!r}: must be a float in (0, 0.1)")
    t0 = time.perf_counter()
    jobs = [(_solve_pair, (1.0, q, float(overlap_for_neck(1.0, q, x)), 1.0, rtol)) for q in ratios for x in necks]
    p = PAPER_CASE
    jobs.append((_solve_pair, (p["r_i"], p["r_j"], p["h"], p["kappa"], paper_rtol)))
    results = list(run_jobs(jobs, workers, desc="unequal pairs", unit="solve", progress=progress))
    paper = next(r for r in results if r["kappa"] == p["kappa"])
    rows = sorted((r for r in results if r is not paper), key=lambda r: (r["r_j"], r["a"]))

    q = np.array([r["r_j"] for r in rows])
    x = np.array([r["a"] for r in rows])
    k_fe = np.array([r["K_fe"] for r in rows])
    full = laws.ConductanceLaw.default()
    k_eq43 = np.asarray(laws.pair_conductance(1.0, 1.0, q, x, laws.ROJEK))
    k_halves = np.asarray(laws.pair_conductance(1.0, 1.0, q, x, full, unequal=False))
    dev = k_halves / k_fe - 1.0
    f = x * np.log(q)
    c = float(f @ dev / (f @ f)) if np.any(f > 0) else 0.0
    k_corr = k_halves / (1.0 + c * f)
    for r, *vals in zip(rows, k_eq43, k_halves, k_corr):
        for name, v in zip(("eq43", "halves", "corrected"), vals):
            r[f"K_{name}"] = float(v)
            r[f"dev_{name}"] = float(v / r["K_fe"] - 1.0)
    spread = {}
    x_round = np.round(x, 9)
    for xi in sorted(set(x_round.tolist())):
        m = x_round == xi
        base = k_fe[m & (q == 1.0)]
        if base.size:
            spread[f"{xi:g}"] = float((k_fe[m].max() - k_fe[m].min()) / base[0])
    paper_law = laws.pair_conductance(p["kappa"], p["r_i"], p["r_j"], paper["a"], full)
    result = {
        "ratios": list(ratios), "necks_a_over_ri": list(necks), "rtol": rtol,
        "max_abs_dev": {name: float(np.max(np.abs([r[f"dev_{name}"] for r in rows])))
                        for name in ("eq43", "halves", "corrected")},
        "max_abs_dev_per_ratio": {f"{qq:g}": {name: float(np.max(np.abs([r[f"dev_{name}"] for r in rows
                                                                          if r["r_j"] == qq])))
                                             for name in ("eq43", "halves", "corrected")} for qq in ratios},
        "correction": {"form": "K_ij = K_i K_j/(K_i + K_j) / (1 + c (a/r_min) ln(r_max/r_min))", "c": c,
                       "c_in_law": laws.UNEQUAL_C},
        "a_only_spread": spread,
        "paper_case": {**PAPER_CASE, "a": paper["a"], "K_fe": paper["K_fe"], "rtol": paper_rtol,
                       "error_estimate": paper["error_estimate"], "K_law": float(paper_law),
                       "rel_diff_fe_vs_paper_fe": paper["K_fe"] / p["K_paper_fe"] - 1.0},
        "cases": rows,
        "seconds": time.perf_counter() - t0,
    }
    if out is not None:
        out = pathlib.Path(out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "unequal.json").write_text(json.dumps(result, indent=1) + "\n")
        with (out / "unequal.csv").open("w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
        plot(rows, ratios, out / "unequal.png")
    return result


def plot(rows, ratios, path) -> None:
    """Relative deviation from FE of the halves law (solid), corrected (dotted) and eq. 43 (inset scale).

    Parameters
    ----------
    rows : list of dict
        The ``cases`` rows of :func:`study` (``r_j``, ``a`` and the ``dev_*`` deviations).
    ratios : sequence of float
        The radius ratios ``r_j/r_i`` to draw, one colour each.
    path : str or pathlib.Path
        The PNG file to write.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11, 4.4), constrained_layout=True)
    for k, q in enumerate(ratios):
        sel = [r for r in rows if r["r_j"] == q]
        x = [r["a"] for r in sel]
        ax.plot(x, [100 * r["dev_halves"] for r in sel], "o-", ms=3, color=f"C{k}", label=f"r_j/r_i = {q:g}")
        ax.plot(x, [100 * r["dev_corrected"] for r in sel], ":", color=f"C{k}")
        ax2.plot(x, [100 * r["dev_eq43"] for r in sel], "s-", ms=3, color=f"C{k}", label=f"r_j/r_i = {q:g}")
    ax.set(xlabel="a / r_i", ylabel="model / FE - 1 [%]",
           title="full-range law per half (solid), with unequal correction (dotted)")
    ax2.set(xlabel="a / r_i", ylabel="model / FE - 1 [%]", title="Rojek 2022 eq. 43-45 (K from a only)")
    ax.axhline(0, color="k", lw=0.5)
    ax2.axhline(0, color="k", lw=0.5)
    ax.legend(fontsize=8)
    ax2.legend(fontsize=8)
    fig.savefig(path, dpi=120)
    plt.close(fig)
