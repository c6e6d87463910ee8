r"""The conductance fit: an FE sweep of the semisphere with a neck over a/r, Rojek's linear fit and the full-range law.

* :func:`sweep_points` -- the a/r of the sweep: ``n // 8`` points log-spaced on [0.001, 0.02) for the small-neck
  end, the rest uniform in a/r on (0, 0.97] (``0.97 k / m``, k = 1..m), the sampling of Rojek 2022, Fig. 16.
* :func:`sweep` -- solves every point to the tolerance in a process pool or on a Dask cluster
  (:mod:`sinterheat.pool`; processes: gmsh is one global, thread-unsafe state per process), appending each result
  to ``fit.csv`` as it arrives so an interrupted run resumes where it stopped. A point is reused only when it was
  computed by the same solver and method to the same tolerance (:func:`reusable_points`; the CSV records all
  three); ``run_fit(..., fresh=True)`` recomputes every point.
* :func:`linear_slope` -- ``K/K_cyl = c a/r`` by least squares through the origin on the uniform points with
  ``a/r <= 0.7`` (Rojek 2022, eq. 40); :func:`slope_sensitivity` shows how c moves with the sampling.
* :func:`fit_law` -- B, C, E of :class:`fem_neck.law.ConductanceLaw` (:math:`A = 5/(4 \pi)` is derived), least squares
  on relative residuals.
* :func:`run_fit` -- all of it, writing ``fit.json`` (read by the DEM), ``fit.csv`` and ``fit.png`` (the Fig. 16
  analogue) into one folder; the figure is drawn by a process of its own that imports matplotlib while the sweep
  starts and then solves points beside this process, one of the sweep's workers (this process never imports
  matplotlib).

Every step takes ``neck``: ``"cylinder"`` (default) sweeps and fits the semisphere with Rojek's neck cylinder,
``"union"`` the half body of the union of spheres (no cylinder; :math:`A = 1/\pi`), and fit.json records which.

The FE solver is named by ``"module:function"`` (default :data:`SOLVER`, ``semisphere_conductance(a_over_r,
rtol, method=..., neck=...)`` returning an object with ``K_over_Kcyl``, ``error_estimate`` and ``dofs``), so worker
processes import it; ``method`` (default :data:`METHOD`) and ``neck`` are passed to it.
"""

from __future__ import annotations

import contextlib
import csv
import importlib
import json
import pathlib
import time
from dataclasses import asdict, dataclass

import numpy as np

from sinterheat.interrupt import where
from sinterheat.pool import ProcessPool, run_jobs
from fem_neck.law import (A_LOG, A_LOG_UNION, ARGENTO_BOUVARD, PARAMETERS, ROJEK, ConductanceLaw, check_neck,
                          half_neck_resistance)

SOLVER = "fem_neck.conduction:semisphere_conductance"  #: the FE solver of a sweep point
METHOD = "hp"  #: the discretisation passed to it
X_MAX = 0.97  # the sweep's largest a/r
X_SMALL = (0.001, 0.02)  # the log-spaced small-neck block
LINEAR_RANGE = 0.7  # Rojek 2022, Section 5: "up to nearly a/r = 0.7 ... linear"
PAPER_H_OVER_R = (0.02, 0.08, 0.2, 0.4)  # the four cases of Rojek 2022, Figs. 13-14
CSV_FIELDS = ("a_over_r", "K_over_Kcyl", "error_estimate", "dofs", "seconds", "rtol", "uniform", "solver", "method",
              "neck")


@dataclass(frozen=True)
class FitPoint:
    r"""One FE solve of the semisphere with a neck (or the union's half body): K/K_cyl at a/r to the tolerance
    ``rtol``.

    Parameters
    ----------
    a_over_r : float
        Neck radius over particle radius, ``a/r`` (dimensionless).
    K_over_Kcyl : float
        The half body's conductance over :math:`K_{cyl} = \kappa \pi r` (dimensionless).
    error_estimate : float
        The solver's relative error estimate of ``K_over_Kcyl``.
    dofs : int
        Degrees of freedom of the (finest) solve.
    seconds : float
        Wall time of the solve (s).
    rtol : float
        The relative tolerance it was solved to.
    uniform : bool
        Whether the point is part of the uniform-in-a/r sampling used by the linear fit.
    solver : str
        The ``"module:function"`` that solved it (empty: unknown, from an old CSV).
    method : str
        The method passed to the solver (empty: unknown).
    neck : str
        The half body solved (:data:`fem_neck.law.NECKS`).
    """

    a_over_r: float
    K_over_Kcyl: float
    error_estimate: float
    dofs: int
    seconds: float
    rtol: float
    uniform: bool  # part of the uniform-in-a/r sampling used by the linear fit
    solver: str = SOLVER  # "module:function" that solved it
    method: str = METHOD  # the method passed to the solver
    neck: str = "cylinder"  # the half body solved (fem_neck.law.NECKS)


def sweep_points(n: int) -> tuple[np.ndarray, np.ndarray]:
    r"""The sweep's a/r (sorted) and a mask of the uniform ones; ``n >= 4`` points in total.

    ``n // 8`` points log-spaced on [0.001, 0.02) (the constriction end, where the linear law fails) and
    :math:`m = n - \lfloor n / 8 \rfloor` uniform points :math:`0.97 k / m`, :math:`k = 1, \ldots, m`.

    Parameters
    ----------
    n : int
        Number of points, >= 4.

    Returns
    -------
    tuple of (numpy.ndarray, numpy.ndarray)
        The a/r (dimensionless, ascending) and a bool mask of the uniform ones.

    Raises
    ------
    ValueError
        ``n`` is not an integer >= 4.
    """
    if not isinstance(n, (int, np.integer)) or n < 4:
        raise ValueError(f"points = {n!r}: must be an integer >= 4")
    n_log = n // 8
    m = n - n_log
    small = np.geomspace(*X_SMALL, n_log, endpoint=False) if n_log else np.empty(0)
    uniform = X_MAX * np.arange(1, m + 1) / m
    x = np.concatenate([small, uniform])
    mask = np.concatenate([np.zeros(n_log, bool), np.ones(m, bool)])
    order = np.argsort(x, kind="stable")
    return x[order], mask[order]


def _key(x: float) -> str:
    return f"{x:.12g}"


def _solve_point(solver: str, method: str, neck: str, a_over_r: float, rtol: float) -> dict:
    """Worker: import the solver by name and solve one point (runs in a child process)."""
    module, func = solver.split(":")
    t0 = time.perf_counter()
    res = getattr(importlib.import_module(module), func)(a_over_r, rtol=rtol, method=method, neck=neck)
    return {"a_over_r": a_over_r, "K_over_Kcyl": float(res.K_over_Kcyl),
            "error_estimate": float(res.error_estimate), "dofs": int(res.dofs),
            "seconds": time.perf_counter() - t0, "rtol": rtol, "solver": solver, "method": method, "neck": neck}


def read_points(path) -> dict:
    """Points already in a ``fit.csv``, keyed by a/r (a CSV without solver and method columns -- written before
    they were recorded -- gives points of unknown provenance: empty ``solver`` and ``method``; one without a neck
    column was written before the union existed: ``neck = "cylinder"``).

    Parameters
    ----------
    path : str or pathlib.Path
        The ``fit.csv``; a missing file holds no points.

    Returns
    -------
    dict
        ``{a/r as text: FitPoint}``; unreadable rows (a half-written last line) are skipped.
    """
    path = pathlib.Path(path)
    if not path.exists():
        return {}
    out = {}
    with path.open(newline="") as fh:
        for row in csv.DictReader(fh):
            try:
                p = FitPoint(float(row["a_over_r"]), float(row["K_over_Kcyl"]), float(row["error_estimate"]),
                             int(row["dofs"]), float(row["seconds"]), float(row["rtol"]),
                             row["uniform"] in ("1", "True", "true"), row.get("solver") or "",
                             row.get("method") or "", row.get("neck") or "cylinder")
            except (KeyError, ValueError, TypeError):
                continue  # a half-written last line of an interrupted run
            out[_key(p.a_over_r)] = p
    return out


def reusable_points(path, rtol: float, solver: str = SOLVER, method: str = METHOD,
                    neck: str = "cylinder") -> tuple[dict, int]:
    """The points of a ``fit.csv`` computed by ``solver`` with ``method`` for ``neck`` to exactly ``rtol`` (keyed by
    a/r), and how many other points the file holds (other solver, method, neck or tolerance: they are not reused).

    Parameters
    ----------
    path : str or pathlib.Path
        The ``fit.csv``.
    rtol : float
        The tolerance the points must have been solved to.
    solver : str
        The FE solver as ``"module:function"`` (module docstring).
    method : str
        The discretisation passed to the solver (``"hp"``, say).
    neck : str
        The half body (:data:`fem_neck.law.NECKS`): ``"cylinder"`` (the semisphere with Rojek's neck cylinder) or
        ``"union"`` (the union of spheres).

    Returns
    -------
    tuple of (dict, int)
        ``{a/r as text: FitPoint}`` of the matching points, and the number of the others.
    """
    points = read_points(path)
    same = {k: p for k, p in points.items() if (p.solver, p.method, p.neck, p.rtol) == (solver, method, neck, rtol)}
    return same, len(points) - len(same)


def _csv_row(point: FitPoint) -> list:
    """Floats in full precision (``repr``), flags as 0/1, names as they are."""
    return [repr(v) if isinstance(v, float) else v if isinstance(v, str) else int(v) for v in asdict(point).values()]


def _append(path: pathlib.Path, point: FitPoint) -> None:
    new = not path.exists() or path.stat().st_size == 0
    with path.open("a", newline="") as fh:
        w = csv.writer(fh)
        if new:
            w.writerow(CSV_FIELDS)
        w.writerow(_csv_row(point))


def sweep(a_over_r, uniform, rtol: float = 1e-4, *, csv_path=None, workers: int | None = None,
          solver: str = SOLVER, method: str = METHOD, progress: bool = True, reuse=None,
          neck: str = "cylinder", alongside=None) -> list[FitPoint]:
    """Solve the semisphere (``neck = "cylinder"``) or the union's half body (``"union"``) at every a/r to ``rtol``
    on ``workers`` processes (default: all cores), or on the Dask cluster of :func:`sinterheat.pool.use_dask`.

    ``reuse``: points solved before, keyed by a/r (:func:`reusable_points`); those at the sweep's a/r are kept
    instead of solved. With ``csv_path`` the CSV is rewritten with the kept points and each new point is appended
    as soon as it is solved, so an interrupted sweep loses nothing. Returns the points sorted by a/r.

    Parameters
    ----------
    a_over_r : array_like
        The a/r to solve (dimensionless).
    uniform : array_like
        Bool per point: part of the uniform sampling of the linear fit.
    rtol : float
        Relative tolerance of every solve, in ``(0, 0.1)``.
    csv_path : str or pathlib.Path or None
        The CSV to (re)write as points arrive; None: none.
    workers : int or None
        Number of worker processes; None: all cores.
    solver : str
        The FE solver as ``"module:function"`` (module docstring).
    method : str
        The discretisation passed to the solver (``"hp"``, say).
    progress : bool
        Whether to show a progress bar on stderr.
    reuse : dict or None
        Points solved before, ``{a/r as text: FitPoint}`` (:func:`reusable_points`); None: none.
    neck : str
        The half body (:data:`fem_neck.law.NECKS`): ``"cylinder"`` (the semisphere with Rojek's neck cylinder) or
        ``"union"`` (the union of spheres).
    alongside : sinterheat.pool.ProcessPool or None
        A local pool already started (the figure's process of :func:`run_fit`) whose processes solve points beside
        this process, counted in ``workers`` (:func:`sinterheat.pool.run_jobs`); None: none.

    Returns
    -------
    list of FitPoint
        The points, sorted by a/r.

    Raises
    ------
    ValueError
        ``rtol`` is not a float in ``(0, 0.1)`` or ``neck`` is not one of :data:`fem_neck.law.NECKS`.
    """
    if not (isinstance(rtol, float) and 0.0 < rtol < 0.1):
        raise ValueError(f"rtol = {rtol!r}: must be a float in (0, 0.1)")
    check_neck(neck)
    x = np.asarray(a_over_r, dtype=float)
    uniform = np.asarray(uniform, dtype=bool)
    csv_path = pathlib.Path(csv_path) if csv_path is not None else None
    done = reuse or {}
    points = {_key(xi): done[_key(xi)] for xi in x if _key(xi) in done}
    todo = [(float(xi), bool(ui)) for xi, ui in zip(x, uniform) if _key(xi) not in points]
    here = where()
    if csv_path is not None:  # rewrite the CSV with the reused points only, then append as results arrive
        csv_path.parent.mkdir(parents=True, exist_ok=True)
        csv_path.unlink(missing_ok=True)
        for p in points.values():
            _append(csv_path, p)
        if points:
            here.update(out=csv_path.parent)
    if todo:
        importlib.import_module(solver.split(":")[0])  # fail early in the parent, and let fork start warm
    jobs = [(_solve_point, (solver, method, neck, xi, rtol)) for xi, _ in todo]
    uniform_of = {_key(xi): ui for xi, ui in todo}
    for res in run_jobs(jobs, workers, desc="fit sweep", unit="solve", progress=progress, done=len(points),
                        alongside=alongside):
        p = FitPoint(**res, uniform=uniform_of[_key(res["a_over_r"])])
        points[_key(p.a_over_r)] = p
        if csv_path is not None:
            _append(csv_path, p)
            here.update(out=csv_path.parent)
    return sorted(points.values(), key=lambda p: p.a_over_r)


def linear_slope(a_over_r, k_over_kcyl, x_max: float = LINEAR_RANGE) -> float:
    r"""Least-squares slope through the origin, :math:`c = \sum x f / \sum x^2` over :math:`a/r \le x_{max}` (eq. 40).

    Parameters
    ----------
    a_over_r : array_like
        The points' a/r (dimensionless).
    k_over_kcyl : array_like
        The points' K/K_cyl (dimensionless).
    x_max : float
        The largest a/r used (Rojek 2022's 0.7 by default).

    Returns
    -------
    float
        The slope c of ``K/K_cyl = c a/r`` (dimensionless).

    Raises
    ------
    ValueError
        No point has ``a/r <= x_max``.
    """
    x = np.asarray(a_over_r, dtype=float)
    f = np.asarray(k_over_kcyl, dtype=float)
    m = x <= x_max
    if not np.any(m):
        raise ValueError(f"x_max = {x_max!r}: no points with a/r <= x_max")
    return float(x[m] @ f[m] / (x[m] @ x[m]))


def _law_basis(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``P(x) = p0 + F @ (A, B, C, E)`` (the form of :class:`fem_neck.law.ConductanceLaw`)."""
    one_minus_s = x * x / (1.0 + np.sqrt(1.0 - x * x))
    p0 = 1.0 - one_minus_s
    F = np.stack([-x * np.log(x), x - one_minus_s, x**2 - one_minus_s, x**3 - one_minus_s], axis=1)
    return p0, F


def fit_law(a_over_r, k_over_kcyl, A: float | None = None, neck: str = "cylinder") -> ConductanceLaw:
    r"""Fit B, C, E of the full-range law for ``neck`` (A fixed, default the derived :data:`fem_neck.law.A_LOG` =
    :math:`5/(4 \pi)` for the neck cylinder, :data:`fem_neck.law.A_LOG_UNION` = :math:`1/\pi` for the union) to FE
    points, 0 < a/r < 1.

    Least squares on the relative residual: :math:`1/f - \lambda = \pi/(4x) P` is linear in the parameters; Gauss-Newton
    on the exact relative residual ``f_law/f_FE - 1`` from that linear start converges in a few steps.

    Parameters
    ----------
    a_over_r : array_like
        The FE points' a/r, in ``(0, 1)`` (dimensionless).
    k_over_kcyl : array_like
        The FE points' K/K_cyl (dimensionless, > 0).
    A : float or None
        The fixed :math:`x \ln(1/x)` coefficient; None: the derived one for ``neck``.
    neck : str
        The half body (:data:`fem_neck.law.NECKS`): ``"cylinder"`` (the semisphere with Rojek's neck cylinder) or
        ``"union"`` (the union of spheres).

    Returns
    -------
    fem_neck.law.ConductanceLaw
        The fitted law, with its fit range and largest relative residual.

    Raises
    ------
    ValueError
        Fewer points than the law has parameters, or ``neck`` is not one of :data:`fem_neck.law.NECKS`.
    """
    A = (A_LOG if check_neck(neck) == "cylinder" else A_LOG_UNION) if A is None else A
    x = np.asarray(a_over_r, dtype=float)
    f = np.asarray(k_over_kcyl, dtype=float)
    if x.size < len(PARAMETERS):
        raise ValueError(f"points = {x.size}: the law needs at least {len(PARAMETERS)} FE points")
    lam = np.asarray(half_neck_resistance(x, neck))
    p0, F = _law_basis(x)
    p0, F = p0 + A * F[:, 0], F[:, 1:]
    p_data = (1.0 / f - lam) * 4.0 * x / np.pi
    weight = f * np.pi / (4.0 * x)  # d(rel. residual)/dP to first order
    params, *_ = np.linalg.lstsq(F * weight[:, None], (p_data - p0) * weight, rcond=None)
    for _ in range(8):
        p = p0 + F @ params
        f_law = x / (x * lam + 0.25 * np.pi * p)
        r = f_law / f - 1.0
        jac = -(f_law**2 / f * np.pi / (4.0 * x))[:, None] * F
        step, *_ = np.linalg.lstsq(jac, -r, rcond=None)
        params = params + step
        if np.max(np.abs(step)) < 1e-13:
            break
    fit_range = (round(float(x.min()), 12), round(float(x.max()), 12))
    law = ConductanceLaw(A, *map(float, params), fit_range=fit_range, neck=neck)
    resid = np.asarray(law.k_over_kcyl(x)) / f - 1.0
    return ConductanceLaw(A, *map(float, params), fit_range=fit_range, max_rel_residual=float(np.abs(resid).max()),
                          neck=neck)


def slope_sensitivity(law: ConductanceLaw) -> dict:
    r"""The least-squares slope c of eq. (40) under other samplings, evaluated on the (FE-fitted) law.

    Keys: continuous uniform a/r on (0, 0.6], (0, 0.7], (0, 0.8]; uniform in h/r for a/r <= 0.7; the paper's four
    h/r of Figs. 13-14 (their a/r reach 0.83). The overlap h of two equal spheres gives a/r through the law's neck:
    the volume-conserving neck (eqs. 18-20) for ``law.neck = "cylinder"``, the circle where the spheres meet,
    :math:`a = \sqrt{h (r - h/4)}`, for the union.

    Parameters
    ----------
    law : fem_neck.law.ConductanceLaw
        The full-range law the samplings are evaluated on.

    Returns
    -------
    dict
        The slope c (dimensionless) under each sampling.
    """
    from fem_neck.geometry import neck_radius, overlap_for_neck
    from fem_neck.geometry.union import lens

    def cont(x):
        return linear_slope(x, law.k_over_kcyl(x), x_max=1.0)

    def a_over_r(h):
        return np.asarray(neck_radius(1.0, 1.0, h) if law.neck == "cylinder" else lens(1.0, 1.0, 2.0 - h).a)

    dense = lambda hi: np.linspace(hi / 4000, hi, 4000)  # noqa: E731 - midpoint-free uniform grid
    h_max = (overlap_for_neck(1.0, 1.0, LINEAR_RANGE) if law.neck == "cylinder"
             else 2.0 * LINEAR_RANGE**2 / (1.0 + np.sqrt(1.0 - LINEAR_RANGE**2)))  # a = 0.7: h = 2 (1 - sqrt(1 - a^2))
    x_h = a_over_r(np.linspace(h_max / 4000, h_max, 4000))
    x_paper = a_over_r(np.array(PAPER_H_OVER_R))
    return {
        "uniform_a_over_r_to_0.6": cont(dense(0.6)),
        "uniform_a_over_r_to_0.7": cont(dense(0.7)),
        "uniform_a_over_r_to_0.8": cont(dense(0.8)),
        "uniform_h_over_r_to_a_over_r_0.7": cont(x_h),
        "paper_four_cases": cont(x_paper),
    }


def plot(points: list[FitPoint], slope: float, law: ConductanceLaw, path) -> None:
    """The Fig. 16 analogue: FE points, the linear fits and the law; below, relative deviations from FE.

    Drawn on a bare Agg figure with fixed margins (no pyplot, no layout engine: they cost more than the 40 solves of
    the sweep).

    Parameters
    ----------
    points : list of FitPoint
        The FE points.
    slope : float
        The fitted linear slope c (dimensionless).
    law : fem_neck.law.ConductanceLaw
        The fitted full-range law.
    path : str or pathlib.Path
        The PNG file to write.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    x = np.array([p.a_over_r for p in points])
    f = np.array([p.K_over_Kcyl for p in points])
    xs = np.linspace(0.0, 1.0, 401)
    fig = Figure(figsize=(6.4, 7.2))
    FigureCanvasAgg(fig)
    ax, axr = fig.subplots(2, 1, height_ratios=(3, 2))
    fig.subplots_adjust(left=0.11, right=0.87, top=0.98, bottom=0.07, hspace=0.22)
    ax.plot(x, f, "o", ms=4, mfc="none", color="k", label="FE (this work)")
    ax.plot(xs, law.k_over_kcyl(xs), "-", color="C0", label="full-range law")
    ax.plot(xs, slope * xs, "--", color="C1", label=f"linear fit, c = {slope:.4f} (a/r <= {LINEAR_RANGE})")
    ax.plot(xs, ROJEK.slope * xs, ":", color="C2", label=f"Rojek 2022 eq. 40, c = {ROJEK.slope}")
    ax.plot(xs, ARGENTO_BOUVARD.slope * xs, "-.", color="C3",
            label=f"Argento-Bouvard eq. 42, c = {ARGENTO_BOUVARD.slope:.3f}")
    ax.plot(xs[:120], 4 / np.pi * xs[:120], lw=0.8, color="grey", label="constriction limit (4/pi) a/r")
    ax.set(xlabel="a/r", ylabel="K / K_cyl", xlim=(0, 1), ylim=(0, max(1.6, 1.1 * f.max())))  # union: f -> inf
    ax.legend(fontsize=8)
    axr.axhspan(-0.5, 0.5, color="C0", alpha=0.10, label="+-0.5 % target")
    axr.plot(x, 100 * (np.asarray(law.k_over_kcyl(x)) / f - 1.0), "o-", ms=3, lw=0.8, color="C0",
             label="full-range law")
    axr.set(xscale="log", xlabel="a/r", ylabel="law / FE - 1 [%]", ylim=(-0.6, 0.6))
    axr.xaxis.set_major_formatter(_decade_label)
    axl = axr.twinx()  # the linear laws miss by up to ~20 %: their own scale
    axl.plot(x, 100 * (slope * x / f - 1.0), "--", lw=0.8, color="C1", label="our linear fit (right axis)")
    axl.plot(x, 100 * (ROJEK.slope * x / f - 1.0), ":", lw=0.8, color="C2", label="Rojek eq. 40 (right axis)")
    axl.set_ylabel("linear law / FE - 1 [%]")
    handles = axr.get_legend_handles_labels()
    more = axl.get_legend_handles_labels()
    axr.legend(handles[0] + more[0], handles[1] + more[1], fontsize=8, loc="lower right")
    fig.savefig(path, dpi=130)


_SUPERSCRIPT = str.maketrans("-0123456789", "\u207b\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076\u2077\u2078\u2079")


def _decade_label(value: float, position=None) -> str:
    """A log axis' tick label, ``10`` and the exponent in Unicode superscripts (as matplotlib's mathtext labels
    look, without its parser, which costs a third of the figure): ``""`` between decades."""
    if not value > 0:
        return ""
    exponent = round(float(np.log10(value)))
    return "10" + str(exponent).translate(_SUPERSCRIPT) if np.isclose(value, 10.0**exponent) else ""


_MPLOT3D = "mpl_toolkits.mplot3d"  # matplotlib.projections imports it to register the 3D axes


def import_plotting() -> None:
    """Import what :func:`plot` needs (in the process that will draw, while the sweep solves: :func:`run_fit`).

    In a process that has not imported matplotlib yet, two parts of its import that no figure uses are left out,
    over a third of its CPU time: the signature and docstring of every artist class's ``set()`` (matplotlib builds
    them for ``help()`` by inspecting all the class's setters; ``set()`` itself works as before) and the 3D axes
    (``projection="3d"`` is then unavailable in this process). The figure drawn is the same to the pixel
    (tests/test_fit_law.py compares it with one drawn after a plain import). Where matplotlib is imported already,
    this imports nothing more than the two modules.
    """
    import sys
    import warnings

    if "matplotlib" in sys.modules:
        import matplotlib.backends.backend_agg  # noqa: F401
        import matplotlib.figure  # noqa: F401
        return
    from matplotlib.artist import Artist

    name = "_update_set_signature_and_docstring"
    original = Artist.__dict__.get(name)
    if original is not None:
        setattr(Artist, name, classmethod(lambda cls: None))
    sys.modules.setdefault(_MPLOT3D, None)  # None: importing it fails, which matplotlib turns into a warning
    try:
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", "Unable to import Axes3D")
            import matplotlib.backends.backend_agg  # noqa: F401
            import matplotlib.figure  # noqa: F401
    finally:
        if original is not None:
            setattr(Artist, name, original)
        if sys.modules.get(_MPLOT3D, False) is None:
            del sys.modules[_MPLOT3D]


@contextlib.contextmanager
def _plotter(draw: bool):
    """The process that draws fit.png (``None`` when ``draw`` is false): forked now, it imports matplotlib at once
    (:func:`import_plotting`) while this process starts the sweep, then solves points beside this one (one of the
    sweep's workers: :func:`sweep`), and takes :func:`plot` once the fit is known, while this process writes
    fit.json and fit.csv. A plotting error is raised by the ``result()`` of its job; an error here stops it at
    once."""
    if not draw:
        yield None
        return
    with ProcessPool(1, "fork") as plotter:
        plotter.submit(import_plotting)
        yield plotter


def run_fit(n_points: int = 40, rtol: float = 1e-4, out=None, *, workers: int | None = None,
            solver: str = SOLVER, method: str = METHOD, progress: bool = True, plot_png: bool = True,
            fresh: bool = False, neck: str = "cylinder") -> dict:
    """Sweep, fit and (with ``out``) write fit.json, fit.csv and fit.png; returns the content of fit.json.

    ``neck``: the half body swept and fitted, ``"cylinder"`` (the semisphere with Rojek's neck, default) or
    ``"union"`` (the union of spheres); fit.json records it as ``neck``, which
    :meth:`fem_neck.law.ConductanceLaw.from_json` reads. Points of an existing ``out/fit.csv`` solved by the same
    ``solver``, ``method`` and ``neck`` to the same ``rtol`` are reused unless ``fresh``; ``reused`` in the result
    says how many (``points``, ``of``, and ``not_matching``: the file's points from other settings, recomputed).

    Parameters
    ----------
    n_points : int
        Number of sweep points, >= 4 (:func:`sweep_points`).
    rtol : float
        Relative tolerance of every solve, in ``(0, 0.1)``.
    out : str or pathlib.Path or None
        The folder for fit.json, fit.csv and fit.png; None: nothing written.
    workers : int or None
        Number of worker processes; None: all cores.
    solver : str
        The FE solver as ``"module:function"`` (module docstring).
    method : str
        The discretisation passed to the solver (``"hp"``, say).
    progress : bool
        Whether to show a progress bar on stderr.
    plot_png : bool
        Whether to draw fit.png (with ``out``).
    fresh : bool
        Whether to recompute every point instead of reusing those of ``out/fit.csv``.
    neck : str
        The half body (:data:`fem_neck.law.NECKS`): ``"cylinder"`` (the semisphere with Rojek's neck cylinder) or
        ``"union"`` (the union of spheres).

    Returns
    -------
    dict
        The content of fit.json: the slope, the law, the points and their provenance.

    Raises
    ------
    ValueError
        A bad ``n_points``, ``rtol`` or ``neck``.
    """
    t0 = time.perf_counter()
    check_neck(neck)
    x, uniform = sweep_points(n_points)
    out = pathlib.Path(out) if out is not None else None
    csv_path = out / "fit.csv" if out is not None else None
    reuse, other = reusable_points(csv_path, rtol, solver, method, neck) if csv_path and not fresh else ({}, 0)
    importlib.import_module(solver.split(":")[0])  # before the figure's process is forked: it solves points too
    with _plotter(out is not None and plot_png) as plotter:
        points = sweep(x, uniform, rtol, csv_path=csv_path, workers=workers, solver=solver, method=method,
                       progress=progress, reuse=reuse, neck=neck, alongside=plotter)
        reused = sum(_key(xi) in reuse for xi in x)
        xa = np.array([p.a_over_r for p in points])
        fa = np.array([p.K_over_Kcyl for p in points])
        um = np.array([p.uniform for p in points])
        slope = linear_slope(xa[um], fa[um])
        law = fit_law(xa, fa, neck=neck)
        drawn = plotter.submit(plot, points, slope, law, out / "fit.png") if plotter is not None else None
        result = {
            "slope": slope,
            "sampling": f"least squares through the origin on the {int(np.sum(um & (xa <= LINEAR_RANGE)))} FE points "
                        f"uniform in a/r (0.97 k/m) with a/r <= {LINEAR_RANGE}, as Rojek 2022 Fig. 16 / eq. (40)",
            "slope_sensitivity": slope_sensitivity(law),
            "points": [[p.a_over_r, p.K_over_Kcyl] for p in points],
            "error_estimates": [p.error_estimate for p in points],
            "unconverged": [p.a_over_r for p in points if not p.error_estimate <= p.rtol],
            "rtol": rtol,
            "law": {**law.to_dict(), "table": law.table(200)},
            "paper": {"rojek_eq40": ROJEK.slope, "argento_bouvard_eq42": ARGENTO_BOUVARD.slope},
            "solver": solver,
            "method": method,
            "neck": neck,
            "reused": {"points": reused, "of": len(x), "not_matching": other},
            "solve_seconds": float(sum(p.seconds for p in points)),  # wall time summed over the points' solves
            "seconds": time.perf_counter() - t0,
        }
        if out is not None:
            (out / "fit.json").write_text(json.dumps(result, indent=1) + "\n")
            resid = np.asarray(law.k_over_kcyl(xa)) / fa - 1.0
            with (out / "fit.csv").open("w", newline="") as fh:  # final: sorted, with the law's residual
                w = csv.writer(fh)
                w.writerow(CSV_FIELDS + ("law", "law_rel_residual"))
                for p, r in zip(points, resid):
                    w.writerow(_csv_row(p) + [repr(float(p.K_over_Kcyl * (1 + r))), repr(float(r))])
        if drawn is not None:
            drawn.result()  # the plotter's error, if any, raised here
    return result


__all__ = ["FitPoint", "METHOD", "SOLVER", "fit_law", "import_plotting", "linear_slope", "plot",
           "read_points", "reusable_points", "run_fit", "slope_sensitivity", "sweep", "sweep_points"]
