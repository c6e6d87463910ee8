"""Run time against error: neck radius, FE conductance, the fit, the DEM solvers, and the peers (issue 6).

``run(out_dir, quick=False)`` measures, section by section, and writes as it goes into ``out_dir``: one CSV per
study, one PNG per study, ``bench.md`` (the tables) and ``bench.json`` (the summary). Every timing is wall time on
this machine, warm (a first untimed call pays imports and JIT-like caches), best of a few repeats where cheap.

Sections (each one is skipped with a stated reason when the module it measures is missing):

* neck radius: Coble, first Newton iterate and full Newton over random bonds (10^6; 10^5 in quick mode), and
  ``fem_neck.neck_radius`` against a plain vectorised numpy Newton on eq. (27) written here (issue 2: ratio <= 2);
* FE: relative error of ``K/K_cyl`` against wall time for P1-P4 on uniform/graded gmsh triangle meshes, the hp
  spectral elements (p = 2-9 on one geometric mesh) and both estimator-driven paths (hp, the default, and gmsh),
  at h/r = 0.02, 0.08, 0.4, against the 12-digit reference table of ``shared/reference/README.md``
  (:data:`REFERENCE`); the fastest setting to reach 1e-3, 1e-4 and 1e-5;
* the fit sweep (``fem_neck.fit``);
* DEM: explicit/implicit/Crank-Nicolson error against time on a transient packing (reference: a fine-step
  Crank-Nicolson run), steady cost against N (time and peak memory per N in a fresh subprocess; growth exponent),
  and implicit 10^5 particles x 1000 steps;
* peers (optional extra ``pip install .[peers]``): NGSolve on the same semisphere (time to 1e-4; the headline ratio
  is timed in alternating rounds with ours, :func:`side_by_side`) and OpenPNM steady Fourier conduction on the same
  network as the DEM steady solve, side by side in this run (:mod:`verification.peers`).
"""

from __future__ import annotations

import csv
import math
import sys
import json
import os
import pathlib
import time
from dataclasses import dataclass, field

import numpy as np

from fem_neck.geometry import coble_radius, max_overlap, neck_radius
from verification.report import jsonable, save_figure
from verification.report import md_table as report_table

# shared/reference/README.md, "Semisphere with a cylindrical neck": independent hp-FE (curved elements, p <= 14),
# energy upper bound and dual lower bound agree to ~1e-12. Keys h/r -> (a/r, K/K_cyl).
REFERENCE = {
    0.02: (0.199331088562, 0.216136324118),
    0.08: (0.394592534534, 0.412739950539),
    0.2: (0.610588366343, 0.655577629373),
    0.4: (0.829667696190, 0.992974073489),
}
REFERENCE_SOURCE = (
    "shared/reference/README.md: independent high-order FE (curved elements, hp-graded to the corner, p up to 14), "
    "energy and dual bounds agree to ~1e-12"
)

TARGETS = {  # issue 6, section 2
    "fe_seconds_to_1e-4": 0.5,
    "fit_seconds": 15.0,
    "dem_steady_1e6_seconds": 30.0,
    "dem_transient_1e5x1000_seconds": 60.0,
}


def best_time(fn, repeat: int = 3):
    """Smallest wall time of ``repeat`` calls of ``fn()`` and the last return value."""
    best, value = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        value = fn()
        best = min(best, time.perf_counter() - t0)
    return best, value


@dataclass
class Report:
    """Collects the tables, figures and summary of a run and rewrites ``bench.md``/``<name>.json`` after each section."""

    out_dir: pathlib.Path
    title: str
    name: str
    summary: dict = field(default_factory=dict)
    sections: list = field(default_factory=list)
    figures: list = field(default_factory=list)

    def __post_init__(self):
        self.out_dir = pathlib.Path(self.out_dir)
        self.out_dir.mkdir(parents=True, exist_ok=True)

    def csv(self, stem: str, rows: list[dict]) -> pathlib.Path:
        self.out_dir.mkdir(parents=True, exist_ok=True)
        path = self.out_dir / f"{stem}.csv"
        if rows:
            columns = list(dict.fromkeys(k for row in rows for k in row))
            with path.open("w", newline="") as fh:
                writer = csv.DictWriter(fh, fieldnames=columns)
                writer.writeheader()
                writer.writerows(rows)
        return path

    def figure(self, fig, stem: str) -> pathlib.Path:
        self.out_dir.mkdir(parents=True, exist_ok=True)
        path = save_figure(fig, self.out_dir / f"{stem}.png", bbox_inches="tight")
        self.figures.append(str(path))
        return path

    def section(self, heading: str, text: str) -> None:
        self.sections.append(f"### {heading}\n\n{text.strip()}\n")
        self.flush()

    @property
    def markdown(self) -> str:
        """The sections (level-3 headings; ``verification.report`` puts the title above them)."""
        return "\n".join(self.sections)

    def flush(self) -> None:
        self.out_dir.mkdir(parents=True, exist_ok=True)
        (self.out_dir / f"{self.name}.md").write_text(f"# {self.title}\n\n{self.markdown}")
        (self.out_dir / f"{self.name}.json").write_text(json.dumps(jsonable(self.summary), indent=1))

    def result(self) -> dict:
        self.flush()
        return {"title": self.title, "markdown": self.markdown, "summary": self.summary, "figures": self.figures}


def md_table(rows: list[dict], columns: list[str] | None = None, fmt: str = "{:.4g}") -> str:
    """A markdown table of dict ``rows`` (columns: given, or every key in order of appearance)."""
    if not rows:
        return "(no rows)"
    columns = columns or list(dict.fromkeys(k for row in rows for k in row))
    return report_table(columns, [[row.get(c) for c in columns] for row in rows], fmt)


def verdict(value, target) -> str:
    if value is None:
        return "not measured"
    return "PASS" if value <= target else "FAIL"


# --------------------------------------------------------------------------------------------------------------
# 1. Neck radius
# --------------------------------------------------------------------------------------------------------------
def random_bonds(n: int, seed: int = 0):
    """``n`` random bonds: r_i in [10, 100] um, r_j/r_i in [1, 10], h uniform in (0, 0.95 max_overlap]."""
    rng = np.random.default_rng(seed)
    r_i = rng.uniform(10e-6, 100e-6, n)
    r_j = r_i * rng.uniform(1.0, 10.0, n)
    h = max_overlap(r_i, r_j) * rng.uniform(1e-3, 0.95, n)
    return r_i, r_j, h


def plain_newton(r_i, r_j, h, tol: float = 4.0 * np.finfo(float).eps, max_iterations: int = 60):
    """The baseline of issue 2: textbook vectorised Newton on eq. (27) from Coble's start (eq. 33).

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


def bench_neck(report: Report, quick: bool) -> None:
    import matplotlib.pyplot as plt

    n = 100_000 if quick else 1_000_000
    r_i, r_j, h = random_bonds(n)
    repeat = 3
    neck_radius(r_i[:10], r_j[:10], h[:10])  # warm
    # interleaved, so that load from other processes hits both alike
    t_ref = t_plain = np.inf
    for _ in range(5):
        t, a_ref = best_time(lambda: neck_radius(r_i, r_j, h, method="newton"), 1)
        t_ref = min(t_ref, t)
        t, a_plain = best_time(lambda: plain_newton(r_i, r_j, h), 1)
        t_plain = min(t_plain, t)
    rows = []
    for label, fn in [
        ("coble (eqs 11-12)", lambda: coble_radius(r_i, r_j, h)),
        ("first iterate (eq 34)", lambda: neck_radius(r_i, r_j, h, method="first")),
        ("newton (fem_neck.neck_radius)", lambda: a_ref),
        ("plain numpy newton (baseline)", lambda: a_plain),
    ]:
        if label.startswith("newton"):
            t, a = t_ref, a_ref
        elif label.startswith("plain"):
            t, a = t_plain, a_plain
        else:
            t, a = best_time(fn, repeat)
        err = np.abs(a - a_ref) / a_ref
        rows.append({"method": label, "bonds": n, "seconds": t, "ns_per_bond": 1e9 * t / n,
                     "max_rel_error": float(err.max()), "median_rel_error": float(np.median(err))})
    report.csv("neck_radius", rows)
    ratio = t_ref / t_plain
    report.summary["neck_bonds"] = n
    report.summary["neck_newton_seconds"] = t_ref
    report.summary["neck_plain_newton_seconds"] = t_plain
    report.summary["neck_newton_over_plain"] = ratio

    fig, ax = plt.subplots(figsize=(5.5, 3.8))
    for row in rows:
        ax.loglog(row["seconds"], max(row["max_rel_error"], 1e-17), "o")
        ax.annotate(row["method"], (row["seconds"], max(row["max_rel_error"], 1e-17)), fontsize=7)
    ax.set_xlabel(f"wall time for {n:.0e} bonds [s]")
    ax.set_ylabel("max relative error of a (vs Newton)")
    ax.set_title("Neck radius: error against time")
    report.figure(fig, "neck_radius")
    report.section(
        "Neck radius over random bonds",
        f"{n} random bonds (r_i in [10,100] um, r_j/r_i in [1,10], h up to 0.95 of the model's range, seed 0); "
        f"best of {repeat} (Newton and the baseline: best of 5, interleaved); error relative to the converged Newton root.\n\n"
        + md_table(rows, ["method", "seconds", "ns_per_bond", "max_rel_error", "median_rel_error"])
        + f"\n\n`fem_neck.neck_radius` / plain numpy Newton = **{ratio:.2f}** (issue 2 requires <= 2: "
        f"{'PASS' if ratio <= 2 else 'FAIL'}); the two roots differ by at most "
        f"{rows[3]['max_rel_error']:.1e} relative.",
    )


# --------------------------------------------------------------------------------------------------------------
# 4a. Peer: NGSolve on the semisphere
# --------------------------------------------------------------------------------------------------------------
FE_CASES = (0.02, 0.08, 0.4)  # h/r of the FE studies (issue 6)
HEADLINE_H_OVER_R = 0.08  # the "one semisphere" of fe_seconds_to_1e-4 / ngsolve_seconds_to_1e-4
TOLERANCES = (1e-3, 1e-4, 1e-5)


def fastest(rows: list[dict], tol: float, key: str = "rel_error") -> dict | None:
    """The row with the smallest ``seconds`` among those with ``key <= tol`` (None if none)."""
    ok = [row for row in rows if row[key] is not None and row[key] <= tol]
    return min(ok, key=lambda row: row["seconds"]) if ok else None


def bench_ngsolve(report: Report, quick: bool) -> None:
    import matplotlib.pyplot as plt

    from verification import peers

    if not peers.available()["ngsolve"]:
        report.summary["ngsolve_seconds_to_1e-4"] = None
        report.section("Peer: NGSolve", "NGSolve is not installed (optional extra: `pip install .[peers]`); skipped.")
        return
    orders = (2, 4, 6) if quick else (1, 2, 3, 4, 5, 6, 8)
    maxhs = (0.3,) if quick else (0.5, 0.3, 0.15)
    levels = (0, 2) if quick else (0, 2, 4)
    peers.ngsolve_semisphere(0.08, 2)  # warm (imports, OCC)
    rows = []
    for h_over_r in FE_CASES:
        k_ref = REFERENCE[h_over_r][1]
        for order in orders:
            for maxh in maxhs:
                for lv in levels:
                    t, (k, ndof) = best_time(lambda: peers.ngsolve_semisphere(h_over_r, order, maxh, lv), 2)
                    rows.append({"h_over_r": h_over_r, "order": order, "maxh": maxh, "hp_levels": lv,
                                 "ndof": ndof, "K_over_Kcyl": k, "rel_error": abs(k - k_ref) / k_ref, "seconds": t})
        report.csv("ngsolve_semisphere", rows)
    # a-priori setting: the cheapest (order, maxh, levels) that reaches each tolerance at every h/r
    settings = {}
    for row in rows:
        settings.setdefault((row["order"], row["maxh"], row["hp_levels"]), []).append(row)
    best = []
    for tol in TOLERANCES:
        for h_over_r in FE_CASES:
            row = fastest([r for r in rows if r["h_over_r"] == h_over_r], tol)
            best.append({"tolerance": tol, "h_over_r": h_over_r, "kind": "oracle (best per case)",
                         **({} if row is None else {k: row[k] for k in ("order", "maxh", "hp_levels", "ndof",
                                                                         "rel_error", "seconds")})})
        ok = [(max(r["seconds"] for r in rs), key, rs) for key, rs in settings.items()
              if len(rs) == len(FE_CASES) and max(r["rel_error"] for r in rs) <= tol]
        if ok:
            _, key, rs = min(ok, key=lambda item: item[0])
            head = next(r for r in rs if r["h_over_r"] == HEADLINE_H_OVER_R)
            best.append({"tolerance": tol, "h_over_r": "all three", "kind": "a-priori (one setting for all)",
                         "order": key[0], "maxh": key[1], "hp_levels": key[2], "ndof": head["ndof"],
                         "rel_error": max(r["rel_error"] for r in rs), "seconds": head["seconds"]})
    report.csv("ngsolve_fastest", best)
    head = next((b for b in best if b["tolerance"] == 1e-4 and b["kind"].startswith("a-priori")), None)
    report.summary["ngsolve_setting_1e-4"] = None if head is None else {k: head[k] for k in ("order", "maxh",
                                                                                            "hp_levels")}
    side = None if head is None else side_by_side(head)
    report.summary["ngsolve_seconds_to_1e-4"] = None if side is None else side["ngsolve_seconds"]
    report.summary["fe_over_ngsolve_side_by_side"] = None if side is None else side["ratio"]
    fig, axes = plt.subplots(1, len(FE_CASES), figsize=(13, 3.8), sharey=True)
    for ax, h_over_r in zip(axes, FE_CASES):
        for order in orders:
            sel = [r for r in rows if r["h_over_r"] == h_over_r and r["order"] == order]
            ax.loglog([r["seconds"] for r in sel], [max(r["rel_error"], 1e-16) for r in sel], "o", ms=4,
                      label=f"p={order}")
        for tol in TOLERANCES:
            ax.axhline(tol, color="0.7", lw=0.7)
        ax.set_title(f"NGSolve, h/r = {h_over_r}")
        ax.set_xlabel("wall time [s]")
    axes[0].set_ylabel("relative error of K/K_cyl")
    axes[-1].legend(fontsize=7)
    report.figure(fig, "ngsolve_semisphere")
    report.section(
        "Peer: NGSolve on the semisphere",
        f"NGSolve {_version('ngsolve')}: H1 order p on a netgen/OCC mesh curved to order p, hp-refined toward the "
        "re-entrant corner (factor 0.125), sparse Cholesky, axisymmetric weight rho; K from the energy. Time per "
        "solve includes geometry, meshing, assembly and solve (warm, best of 2). Sweep: p in "
        f"{list(orders)}, maxh in {list(maxhs)}, hp levels in {list(levels)}. Error against {REFERENCE_SOURCE}.\n\n"
        + md_table(best, ["tolerance", "h_over_r", "kind", "order", "maxh", "hp_levels", "ndof", "rel_error",
                          "seconds"])
        + f"\n\nHeadline `ngsolve_seconds_to_1e-4` (h/r = {HEADLINE_H_OVER_R}, the a-priori setting above, no error "
        "estimate), timed side by side with ours (`semisphere_conductance(rtol=1e-4)`, which also solves the order "
        f"below for its estimate): {SIDE_BY_SIDE_ROUNDS} alternating rounds, best of each: "
        + (f"NGSolve {side['ngsolve_seconds'] * 1e3:.2f} ms (error {side['ngsolve_error']:.1e}), ours "
           f"{side['fe_seconds'] * 1e3:.2f} ms (error {side['fe_error']:.1e}, estimate {side['fe_estimate']:.1e}), "
           f"**ratio ours/NGSolve = {side['ratio']:.2f}**" if side else "not reached"),
    )


SIDE_BY_SIDE_ROUNDS = 15


def side_by_side(setting: dict) -> dict:
    """Time NGSolve's a-priori 1e-4 setting and our default 1e-4 solve alternately (same machine state), best of
    each over :data:`SIDE_BY_SIDE_ROUNDS` rounds, on the headline semisphere."""
    from fem_neck import conduction
    from verification import peers

    a_head, k_ref = REFERENCE[HEADLINE_H_OVER_R]
    ours, theirs = np.inf, np.inf
    for _ in range(SIDE_BY_SIDE_ROUNDS):
        t, res = best_time(lambda: conduction.semisphere_conductance(a_head, rtol=1e-4), 1)
        ours = min(ours, t)
        t, (k_ng, _) = best_time(lambda: peers.ngsolve_semisphere(HEADLINE_H_OVER_R, setting["order"],
                                                                   setting["maxh"], setting["hp_levels"]), 1)
        theirs = min(theirs, t)
    return {"fe_seconds": ours, "ngsolve_seconds": theirs, "ratio": ours / theirs,
            "fe_error": abs(res.K_over_Kcyl - k_ref) / k_ref, "fe_estimate": res.error_estimate,
            "ngsolve_error": abs(k_ng - k_ref) / k_ref}


def _version(package: str) -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(package)
    except PackageNotFoundError:
        return "(not installed)"


# --------------------------------------------------------------------------------------------------------------
# 2. FE conductance of the semisphere: error against time
# --------------------------------------------------------------------------------------------------------------
def _fe_config(a_over_r: float, order: int, mesh: str, size: float) -> tuple[float, int]:
    """One mesh + one solve: ``(K/K_cyl, dofs)``. ``mesh`` is ``"uniform"`` (element size ``size``) or
    ``"graded"`` (size = h_min + ``size`` * distance to the corner, the fem_neck.shapes default field)."""
    from fem_neck import conduction, shapes

    if mesh == "uniform":
        profile = shapes.semisphere_mesh(a_over_r, sizes=shapes.SizeField(uniform=size))
    else:
        profile = shapes.semisphere_mesh(a_over_r, grading=size)
    sol = conduction.solve_profile(profile, order, curved=order > 1)
    return sol.K / math.pi, sol.dofs


def _hp_config(a_over_r: float, order: int, levels: int) -> tuple[float, int]:
    """One hp mesh (``levels`` corner refinements) + one solve of order ``order``: ``(K/K_cyl, dofs)``."""
    from fem_neck import hpmesh, spectral

    mesh, shape = hpmesh.semisphere_quad_mesh(a_over_r, levels)
    sol = spectral.conductance(mesh, order, hpmesh.end_disks(mesh, shape))
    return sol.K_over_kappa / math.pi, sol.dofs


HP_LEVELS = 4  # corner refinements of the fixed hp settings (their own error is < 1e-9, see fem_neck.accuracy)


def fe_study_configs(quick: bool) -> list[tuple[int, str, float]]:
    """(order, mesh kind, size) of the FE sweep."""
    if quick:
        return ([(p, "hp", HP_LEVELS) for p in (3, 4, 5)] + [(p, "uniform", s) for p in (1, 2) for s in (0.1, 0.05)]
                + [(p, "graded", g) for p in (1, 2, 3) for g in (0.4, 0.2)])
    uniform = [(p, "hp", HP_LEVELS) for p in range(2, 10)]
    uniform += [(1, "uniform", s) for s in (0.1, 0.05, 0.025, 0.0125)]
    uniform += [(2, "uniform", s) for s in (0.1, 0.05, 0.025, 0.0125)]
    graded = [(p, "graded", g) for p in (1, 2, 3, 4) for g in (0.45, 0.3, 0.2, 0.12, 0.08)]
    graded += [(1, "graded", g) for g in (0.05, 0.03)] + [(2, "graded", 0.05)]
    return uniform + graded


def bench_fe(report: Report, quick: bool) -> None:
    import matplotlib.pyplot as plt

    try:
        from fem_neck import conduction
    except ImportError as exc:
        report.summary["fe_seconds_to_1e-4"] = None
        report.section("FE conductance", f"not available: {exc}")
        return
    from tqdm import tqdm

    conduction.semisphere_conductance(0.4)  # warm: imports, gmsh, scikit-fem caches
    configs = fe_study_configs(quick)
    rtols = (1e-3, 1e-4) if quick else (1e-3, 1e-4, 1e-5, 1e-6)
    rows = []
    bar = tqdm(total=len(FE_CASES) * (len(configs) + len(rtols)), desc="bench FE", file=sys.stderr,
               disable=not sys.stderr.isatty())
    for h_over_r in FE_CASES:
        a_over_r, k_ref = REFERENCE[h_over_r]
        for order, kind, size in configs:
            solve = _hp_config if kind == "hp" else _fe_config
            args = (a_over_r, order, size) if kind == "hp" else (a_over_r, order, kind, size)
            t, (k, dofs) = best_time(lambda: solve(*args), 3 if kind == "hp" else 1 if quick else 2)
            rows.append({"h_over_r": h_over_r, "path": f"P{order} {kind}", "order": order, "mesh": kind,
                         "size": size, "dofs": dofs, "K_over_Kcyl": k, "rel_error": abs(k - k_ref) / k_ref,
                         "error_estimate": None, "seconds": t})
            bar.update()
        for rtol in rtols:
            for method in ("hp", "gmsh"):
                t, res = best_time(lambda: conduction.semisphere_conductance(a_over_r, rtol=rtol, method=method),
                                   5 if method == "hp" else 1 if rtol < 1e-5 else 3)
                rows.append({"h_over_r": h_over_r, "path": f"semisphere_conductance(rtol, method={method})",
                             "order": res.order, "mesh": f"{method}, estimator-driven", "size": res.grading,
                             "rtol": rtol, "dofs": res.dofs, "K_over_Kcyl": res.K_over_Kcyl,
                             "rel_error": abs(res.K_over_Kcyl - k_ref) / k_ref, "error_estimate": res.error_estimate,
                             "seconds": t})
            bar.update()
        report.csv("fe_semisphere", rows)
    bar.close()

    fastest_rows = []
    for tol in TOLERANCES:
        for h_over_r in FE_CASES:
            sel = [r for r in rows if r["h_over_r"] == h_over_r]
            fixed = [r for r in sel if r["error_estimate"] is None]
            for label, cand in (("any fixed setting", fixed),
                                ("any fixed triangle setting", [r for r in fixed if r["mesh"] != "hp"]),
                                *((f"semisphere_conductance(rtol=tolerance, method={m})",
                                   [r for r in sel if r["error_estimate"] is not None and r["rtol"] == tol
                                    and r["path"].endswith(f"={m})")]) for m in ("hp", "gmsh"))):
                row = fastest(cand, tol) if label.startswith("any") else (cand[0] if cand else None)
                fastest_rows.append({"tolerance": tol, "h_over_r": h_over_r, "kind": label,
                                     **({"path": "not reached" if cand else "not run"} if row is None else
                                        {k: row.get(k) for k in ("path", "size", "rtol", "dofs", "rel_error",
                                                             "seconds")})})
        # one fixed setting meeting tol at all three h/r (what a default must do without knowing the answer)
        by_setting = {}
        for r in rows:
            if r["error_estimate"] is None:
                by_setting.setdefault((r["order"], r["mesh"], r["size"]), []).append(r)
        ok = [(max(x["seconds"] for x in rs), key, rs) for key, rs in by_setting.items()
              if len(rs) == len(FE_CASES) and max(x["rel_error"] for x in rs) <= tol]
        if ok:
            _, key, rs = min(ok, key=lambda item: item[0])
            fastest_rows.append({"tolerance": tol, "h_over_r": "all three", "kind": "one fixed setting",
                                 "path": f"P{key[0]} {key[1]}", "size": key[2],
                                 "dofs": max(x["dofs"] for x in rs), "rel_error": max(x["rel_error"] for x in rs),
                                 "seconds": max(x["seconds"] for x in rs)})
    report.csv("fe_fastest", fastest_rows)

    # headline: warm default solve (rtol = 1e-4) of one semisphere
    a_head, k_head = REFERENCE[HEADLINE_H_OVER_R]
    t_head, res = best_time(lambda: conduction.semisphere_conductance(a_head, rtol=1e-4), 20)
    t_gmsh, _ = best_time(lambda: conduction.semisphere_conductance(a_head, rtol=1e-4, method="gmsh"), 3)
    err_head = abs(res.K_over_Kcyl - k_head) / k_head
    report.summary["fe_seconds_to_1e-4"] = t_head
    report.summary["fe_gmsh_path_seconds_to_1e-4"] = t_gmsh
    report.summary["fe_rel_error_at_rtol_1e-4"] = err_head
    report.summary["fe_error_estimate_at_rtol_1e-4"] = res.error_estimate

    fig, axes = plt.subplots(1, len(FE_CASES), figsize=(13, 4), sharey=True)
    for ax, h_over_r in zip(axes, FE_CASES):
        sel = [r for r in rows if r["h_over_r"] == h_over_r]
        for path in dict.fromkeys(r["path"] for r in sel):
            pts = sorted((r["seconds"], max(r["rel_error"], 1e-12)) for r in sel if r["path"] == path)
            style = ("s--" if "uniform" in path else "r^-" if "hp" in path and "rtol" not in path
                     else "k*-" if "hp)" in path else "m*-" if "rtol" in path else "o-")
            ax.loglog(*zip(*pts), style, ms=4, label=path)
        for tol in TOLERANCES:
            ax.axhline(tol, color="0.75", lw=0.7)
        ax.set_title(f"h/r = {h_over_r} (a/r = {REFERENCE[h_over_r][0]:.4f})")
        ax.set_xlabel("wall time (mesh + solve) [s]")
    axes[0].set_ylabel("relative error of K/K_cyl")
    axes[-1].legend(fontsize=6)
    report.figure(fig, "fe_error_vs_time")
    report.section(
        "FE conductance of the semisphere: error against time",
        f"Reference: {REFERENCE_SOURCE} (table rows h/r = {', '.join(map(str, FE_CASES))}). A triangle setting is "
        "one gmsh mesh plus one scikit-fem solve (curved isoparametric boundary for P>=2), warm, best of "
        f"{1 if quick else 2}: 'uniform' has element size `size`, 'graded' has size h_min + `size` x distance to "
        f"the re-entrant corner. 'Pp hp' is one hp mesh ({HP_LEVELS} geometric corner refinements, exact sphere, "
        "fem_neck.hpmesh) plus one spectral solve of order p (best of 3). `semisphere_conductance(rtol, method)` "
        "is the estimator-driven path: hp (the default) raises p on one mesh until orders p-1 and p agree to rtol; "
        "gmsh solves orders p-1 and p on one graded mesh and shrinks the grading until they agree. Full table: "
        "`fe_semisphere.csv`.\n\n"
        "Fastest setting reaching each tolerance:\n\n"
        + md_table(fastest_rows, ["tolerance", "h_over_r", "kind", "path", "size", "rtol", "dofs", "rel_error",
                                  "seconds"])
        + f"\n\nHeadline `fe_seconds_to_1e-4` (warm `semisphere_conductance(a/r = {a_head:.6f}, rtol=1e-4)`, "
        f"h/r = {HEADLINE_H_OVER_R}, best of 20): **{t_head * 1e3:.2f} ms**, true error {err_head:.1e}, estimate "
        f"{res.error_estimate:.1e}, order {res.order}, {res.dofs} dofs (target <= {TARGETS['fe_seconds_to_1e-4']} s: "
        f"{verdict(t_head, TARGETS['fe_seconds_to_1e-4'])}). The gmsh path to the same rtol: {t_gmsh * 1e3:.1f} ms "
        f"(ratio {t_gmsh / t_head:.0f}).",
    )


# --------------------------------------------------------------------------------------------------------------
# 3. The fit sweep
# --------------------------------------------------------------------------------------------------------------
def bench_fit(report: Report, quick: bool) -> None:
    import tempfile

    try:
        from fem_neck.fit import run_fit
    except ImportError as exc:
        report.summary["fit_seconds"] = None
        report.section("Fit sweep", f"not available: {exc}")
        return
    points = 12 if quick else 44
    with tempfile.TemporaryDirectory() as tmp:  # fresh folder: run_fit resumes from an existing fit.csv
        t0 = time.perf_counter()
        fit = run_fit(n_points=points, rtol=1e-4, out=pathlib.Path(tmp), progress=False)
        seconds = time.perf_counter() - t0
    report.summary["fit_seconds"] = seconds
    report.summary["fit_points"] = points
    report.summary["fit_cpu_seconds"] = fit.get("cpu_seconds")
    row = {"points": points, "rtol": 1e-4, "seconds": seconds, "cpu_seconds_in_solves": fit.get("cpu_seconds"),
           "slope": fit.get("slope"), "unconverged": len(fit.get("unconverged", []))}
    report.csv("fit", [row])
    note = ("" if not quick else " Quick mode: 12 points, so this is not the target's figure (>= 40 points).")
    report.section(
        "Fit sweep",
        f"`fem_neck.fit.run_fit(n_points={points}, rtol=1e-4)` into a fresh folder (process pool over both cores, "
        f"including fit.json/csv/png).{note}\n\n"
        + md_table([row]) + f"\n\nTarget <= {TARGETS['fit_seconds']:g} s with >= 40 points: "
        + (verdict(seconds, TARGETS["fit_seconds"]) if not quick else "not measured in quick mode"),
    )


# --------------------------------------------------------------------------------------------------------------
def add_arguments(parser) -> None:
    """Options of ``python -m verification bench`` beyond the common ones."""
    parser.add_argument("--stability", action="store_true",
                        help="also run the stability stress suite (adds stress_cases to the summary)")


def run(out_dir: pathlib.Path, quick: bool = False, stability: bool = False) -> dict:
    """Run every bench section into ``out_dir`` (see the module docstring); return the section result."""
    report = Report(out_dir, "Run time against error (bench)", "bench")
    from verification import peers

    have = peers.available()
    report.summary.update({"fe_seconds_to_1e-4": None, "ngsolve_seconds_to_1e-4": None, "fit_seconds": None,
                           "dem_steady_seconds": {}, "openpnm_seconds": None,
                           "dem_transient_1e5x1000_seconds": None})
    report.section(
        "Setup",
        f"{'Quick' if quick else 'Full'} run on {os.cpu_count()} cores; peers (optional extra `pip install .[peers]`): "
        + ", ".join(f"{k} {'installed ' + _version(k) if v else 'absent (skipped)'}" for k, v in have.items())
        + ". Wall times are warm; other processes on the machine inflate them (load average at start: "
        + f"{os.getloadavg()[0]:.1f}).",
    )
    for step in (bench_neck, bench_fe, bench_ngsolve, bench_fit, bench_dem):
        step(report, quick)
    if stability:
        from verification import stability as stab

        result = stab.run(pathlib.Path(out_dir) / "stability", quick=quick)
        report.summary["stress_cases"] = result["summary"]["stress_cases"]
        report.figures += result["figures"]
        report.sections.append(result["markdown"])
    report.section("Targets", targets_table(report.summary))
    return report.result()


def targets_table(summary: dict) -> str:
    steady = summary.get("dem_steady_seconds") or {}
    big = max((int(k) for k in steady), default=None)
    rows = [
        {"target": "semisphere to 1e-4 (warm)", "limit_s": TARGETS["fe_seconds_to_1e-4"],
         "measured_s": summary.get("fe_seconds_to_1e-4")},
        {"target": "fit, >= 40 points to 1e-4", "limit_s": TARGETS["fit_seconds"],
         "measured_s": summary.get("fit_seconds") if summary.get("fit_points", 0) >= 40 else None},
        {"target": "DEM steady, 10^6 particles", "limit_s": TARGETS["dem_steady_1e6_seconds"],
         "measured_s": steady[str(big)] if big is not None and big >= 10**6 else None},
        {"target": "DEM implicit, 10^5 x 1000 steps", "limit_s": TARGETS["dem_transient_1e5x1000_seconds"],
         "measured_s": summary.get("dem_transient_1e5x1000_seconds")},
    ]
    for row in rows:
        row["verdict"] = verdict(row["measured_s"], row["limit_s"])
    peers_rows = [
        {"target": "semisphere: no slower than NGSolve (ratio ours/NGSolve <= 1, side by side)",
         "ratio": summary.get("fe_over_ngsolve_side_by_side")},
        {"target": "DEM steady: no slower than OpenPNM (ratio ours/OpenPNM <= 1)",
         "ratio": _ratio(summary.get("dem_steady_same_network_seconds"), summary.get("openpnm_seconds"))},
        {"target": "neck_radius vs plain numpy Newton (ratio <= 2)", "ratio": summary.get("neck_newton_over_plain")},
    ]
    for row, limit in zip(peers_rows, (1.0, 1.0, 2.0)):
        row["verdict"] = verdict(row["ratio"], limit)
    note = f" (largest steady N measured: {big})" if big is not None and big < 10**6 else ""
    return md_table(rows) + note + "\n\n" + md_table(peers_rows, fmt="{:.3g}")


def _ratio(a, b):
    return None if a is None or b is None else a / b


# --------------------------------------------------------------------------------------------------------------
# 3. DEM: transient accuracy, steady scaling, the 10^5 x 1000 implicit run; 4b. OpenPNM on the same network
# --------------------------------------------------------------------------------------------------------------
PACKING = {"radius": 50e-6, "overlap": 0.15}  # copper, mean radius 50 um, mean relative overlap 0.15 (rojek law)


def packing_network(n: int, seed: int = 0, connected_only: bool = False, t_hot: float = 1.0):
    """A random sintered packing of ~n copper particles (``dem.generators.random_packing``) between a hot bottom
    layer (fixed at ``t_hot``) and a cold top layer (fixed at 0), free particles starting at 0, rojek law.

    ``connected_only`` keeps only the particles connected to a fixed layer (what a pore-network code can solve).
    Returns ``(network, timings)`` with the seconds of the packing, the bonds and the network assembly.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    from dem.bonds import find_bonds
    from dem.generators import random_packing
    from dem.laws.conductance import ConductanceSpec, bond_conductances
    from dem.particles import Particles
    from dem.thermal import Network

    times = {}
    t0 = time.perf_counter()
    lay = random_packing(n, PACKING["radius"], PACKING["overlap"], seed=seed)
    times["packing_seconds"] = time.perf_counter() - t0
    n = len(lay.radius)
    fixed = np.zeros(n, dtype=bool)
    fixed[lay.bottom] = True
    fixed[lay.top] = True
    temp = np.zeros(n)
    temp[lay.bottom] = t_hot
    pos, rad = lay.position, lay.radius
    if connected_only:
        particles = Particles.from_arrays(pos, rad, temp, fixed=fixed)
        bonds = find_bonds(particles)
        _, label = connected_components(coo_matrix((np.ones(bonds.n_pairs), (bonds.i, bonds.j)), shape=(n, n)),
                                        directed=False)
        keep = np.isin(label, np.unique(label[fixed]))
        pos, rad, temp, fixed = pos[keep], rad[keep], temp[keep], fixed[keep]
    t0 = time.perf_counter()
    particles = Particles.from_arrays(pos, rad, temp, fixed=fixed)
    bonds = find_bonds(particles)
    times["bonds_seconds"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    k_pairs, k_walls = bond_conductances(ConductanceSpec("rojek"), particles, bonds)
    net = Network(particles, bonds, k_pairs, k_walls, np.zeros(0))
    times["network_seconds"] = time.perf_counter() - t0
    return net, times


def _peak_rss_mib() -> float:
    """Peak resident memory of this process in MiB: ``VmHWM`` (reset by exec, unlike ``ru_maxrss``, which a
    forked child inherits from its parent)."""
    try:
        for line in pathlib.Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return float(line.split()[1]) / 1024.0
    except OSError:
        pass
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def steady_worker(n: int) -> None:
    """Subprocess body: one steady solve of a packing of ~n particles; prints one JSON line."""
    from dem.thermal import steady

    base = _peak_rss_mib()
    net, times = packing_network(n)
    t0, c0 = time.perf_counter(), time.process_time()
    res = steady(net, floating="mean")
    times["solve_seconds"] = time.perf_counter() - t0
    times["solve_cpu_seconds"] = time.process_time() - c0
    times["steady_seconds"] = times["bonds_seconds"] + times["network_seconds"] + times["solve_seconds"]
    print(json.dumps({"particles": net.particles.n, "bonds": int(net.bonds.n_pairs), "solver": res.solver,
                      "floating_groups": res.floating, "peak_rss_mib": _peak_rss_mib(),
                      "baseline_rss_mib": base, **times}))


def openpnm_worker(n: int) -> None:
    """Subprocess body: ours and OpenPNM on the same connected network of ~n particles; prints one JSON line."""
    from dem.thermal import Network, steady
    from verification.peers import openpnm_steady

    net, _ = packing_network(n, connected_only=True)
    p, b = net.particles, net.bonds
    t0 = time.perf_counter()  # ours: assembly of the network matrix from the bonds + steady solve
    net = Network(p, b, net.K_pairs, net.K_walls, net.wall_temperature)
    res = steady(net)
    ours = time.perf_counter() - t0
    T_pnm, times = openpnm_steady(p.position, b.i, b.j, net.K_pairs, p.fixed, p.temperature)
    print(json.dumps({"particles": p.n, "bonds": int(b.n_pairs), "ours_seconds": ours, "ours_solver": res.solver,
                      "openpnm_setup_seconds": times["setup_seconds"],
                      "openpnm_solve_seconds": times["solve_seconds"],
                      "openpnm_seconds": times["setup_seconds"] + times["solve_seconds"],
                      "openpnm_solver": times["solver"],
                      "max_abs_difference": float(np.max(np.abs(T_pnm - res.T)))}))


def run_worker(func: str, n: int, timeout: float) -> dict:
    """Run ``func(n)`` of this module in a fresh interpreter (own peak memory); its JSON line, or an error."""
    import subprocess

    code = f"from verification.bench import {func}; {func}({int(n)})"
    try:
        proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"particles": n, "error": f"timeout after {timeout:g} s"}
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("{")]
    if proc.returncode != 0 or not lines:
        tail = (proc.stderr.strip().splitlines() or ["no output"])[-1]
        return {"particles": n, "error": f"exit {proc.returncode}: {tail[:200]}"}
    return json.loads(lines[-1])


def growth_exponent(n, t) -> float | None:
    """Least-squares slope of log t against log n."""
    n, t = np.asarray(n, float), np.asarray(t, float)
    ok = (n > 0) & (t > 0)
    return float(np.polyfit(np.log(n[ok]), np.log(t[ok]), 1)[0]) if ok.sum() >= 2 else None


def bench_dem_accuracy(report: Report, quick: bool) -> None:
    import matplotlib.pyplot as plt

    from dem.thermal import integrate, stable_limit

    net, _ = packing_network(500 if quick else 2000, seed=1)
    limit = stable_limit(net)
    t_end = 200 * limit
    t_ref, ref = best_time(lambda: integrate(net, "crank-nicolson", dt=limit / 16, t_end=t_end), 1)
    check = integrate(net, "crank-nicolson", dt=limit / 8, t_end=t_end)
    ref_error = float(np.max(np.abs(check.T - ref.T)) / 3.0)  # CN is 2nd order: error(dt/16) ~ diff / 3
    rows = []
    factors = {"explicit": (0.9, 0.45, 0.225, 0.1125),
               "implicit": (0.5, 2, 8, 32), "crank-nicolson": (0.5, 2, 8, 32)}
    for integrator, facs in factors.items():
        for f in facs:
            t, res = best_time(lambda: integrate(net, integrator, dt=f * limit, t_end=t_end), 1)
            rows.append({"integrator": integrator, "dt": f"{f:g} x limit", "steps": res.steps,
                         "error": float(np.max(np.abs(res.T - ref.T))), "energy_error": res.energy_error,
                         "seconds": t})
        for rtol in (1e-2, 1e-3, 1e-4):
            t, res = best_time(lambda: integrate(net, integrator, dt="auto", rtol=rtol, t_end=t_end), 1)
            rows.append({"integrator": integrator, "dt": f"auto, rtol {rtol:g}", "steps": res.steps,
                         "error": float(np.max(np.abs(res.T - ref.T))), "energy_error": res.energy_error,
                         "seconds": t})
    report.csv("dem_transient_accuracy", rows)
    fig, ax = plt.subplots(figsize=(6, 4))
    for integrator, marker in zip(factors, "os^"):
        sel = [r for r in rows if r["integrator"] == integrator]
        ax.loglog([r["seconds"] for r in sel], [max(r["error"], 1e-16) for r in sel], marker, label=integrator)
    ax.set_xlabel("wall time [s]")
    ax.set_ylabel("max |T - T_ref| (hot plate 1, cold 0)")
    ax.set_title(f"DEM transient, {net.particles.n} particles, t_end = 200 x explicit limit")
    ax.legend(fontsize=8)
    report.figure(fig, "dem_transient_accuracy")
    report.section(
        "DEM transient: error against time",
        f"Random sintered packing ({net.particles.n} copper particles, mean radius {PACKING['radius']:g} m, mean "
        f"relative overlap {PACKING['overlap']}, rojek law), bottom layer fixed at 1, top at 0, free particles "
        f"starting at 0; explicit stable limit {limit:.4g} s (dem.thermal.stable_limit); t_end = 200 x limit. "
        f"Reference: Crank-Nicolson at dt = limit/16 ({t_ref:.2f} s; its own error ~{ref_error:.1e} from the "
        "dt/8 run). Error: max over particles of |T - T_ref|.\n\n"
        + md_table(rows, ["integrator", "dt", "steps", "error", "energy_error", "seconds"]),
    )


def bench_dem_scaling(report: Report, quick: bool) -> None:
    import matplotlib.pyplot as plt

    sizes = (1_000, 10_000) if quick else (1_000, 10_000, 100_000, 1_000_000)
    rows = []
    for n in sizes:
        rows.append(run_worker("steady_worker", n, timeout=900))
        report.csv("dem_steady_scaling", rows)
    good = [r for r in rows if "error" not in r]
    report.summary["dem_steady_seconds"] = {str(r["particles"]): r["steady_seconds"] for r in good}
    report.summary["dem_steady_peak_rss_mib"] = {str(r["particles"]): r["peak_rss_mib"] for r in good}
    big = [r for r in good if r["particles"] >= 10_000]
    big = big if len(big) >= 2 else good
    exp_t = growth_exponent([r["particles"] for r in big], [r["steady_seconds"] for r in big])
    exp_m = growth_exponent([r["particles"] for r in big],
                            [max(r["peak_rss_mib"] - r["baseline_rss_mib"], 1e-3) for r in big])
    report.summary["dem_steady_time_exponent"] = exp_t
    report.summary["dem_steady_memory_exponent"] = exp_m
    if good:
        fig, ax = plt.subplots(figsize=(5.5, 4))
        ns = [r["particles"] for r in good]
        for key in ("bonds_seconds", "solve_seconds", "steady_seconds"):
            ax.loglog(ns, [r[key] for r in good], "o-", label=key.replace("_seconds", ""))
        ax2 = ax.twinx()
        ax2.loglog(ns, [r["peak_rss_mib"] for r in good], "k--", label="peak RSS [MiB]")
        ax2.set_ylabel("peak RSS [MiB]")
        ax.set_xlabel("particles")
        ax.set_ylabel("wall time [s]")
        ax.legend(fontsize=8, loc="upper left")
        report.figure(fig, "dem_steady_scaling")
    big_n = max((r["particles"] for r in good), default=0)
    big_t = next((r["steady_seconds"] for r in good if r["particles"] == big_n), None)
    report.section(
        "DEM steady solve: cost against N",
        "Each N in a fresh subprocess: random sintered packing with hot/cold fixed layers; `steady_seconds` = bonds "
        "(k-d tree + neck radii) + conductances and network assembly + `dem.thermal.steady` (floating = \"mean\" "
        "for the few particles the packing leaves unbonded); the packing generation is listed apart. Peak memory "
        "is the process's maximum RSS (getrusage), baseline after imports alongside.\n\n"
        + md_table(rows, ["particles", "bonds", "packing_seconds", "bonds_seconds", "network_seconds",
                          "solve_seconds", "solve_cpu_seconds", "steady_seconds", "solver", "peak_rss_mib", "baseline_rss_mib", "error"])
        + ("\n\nGrowth exponent: too few points." if exp_t is None or exp_m is None else
           f"\n\nGrowth exponents (least squares over N = {', '.join(str(r['particles']) for r in big)}): time ~ N^{exp_t:.2f}, memory above baseline ~ N^{exp_m:.2f}.")
        + (f"\n\nTarget: 10^6 particles in <= {TARGETS['dem_steady_1e6_seconds']:g} s: "
           f"{verdict(big_t, TARGETS['dem_steady_1e6_seconds'])} ({big_t:.1f} s)" if big_n >= 10**6 else ""),
    )


def bench_openpnm(report: Report, quick: bool) -> None:
    from verification import peers

    if not peers.available()["openpnm"]:
        report.summary["openpnm_seconds"] = None
        report.section("Peer: OpenPNM", "OpenPNM is not installed (optional extra: `pip install .[peers]`); skipped.")
        return
    # 10^6 is left out: OpenPNM's default PARDISO factorisation of the 3D network passed 14 GiB resident after
    # 8 minutes on this machine (stopped), which would starve everything else of memory.
    sizes = (1_000, 10_000) if quick else (10_000, 100_000)
    rows = []
    for n in sizes:
        rows.append(run_worker("openpnm_worker", n, timeout=600))
        report.csv("openpnm_same_network", rows)
        if "error" in rows[-1]:
            break
    good = [r for r in rows if "error" not in r]
    for r in good:
        r["ratio_ours_over_openpnm"] = r["ours_seconds"] / r["openpnm_seconds"]
    head = max(good, key=lambda r: r["particles"]) if good else None
    report.summary["openpnm_seconds"] = None if head is None else head["openpnm_seconds"]
    report.summary["dem_steady_same_network_seconds"] = None if head is None else head["ours_seconds"]
    report.summary["openpnm_particles"] = None if head is None else head["particles"]
    report.section(
        "Peer: OpenPNM on the same network",
        f"OpenPNM {_version('openpnm')} `FourierConduction` (its default solver) on exactly our network: the "
        "particles connected to the fixed layers, our bonds as throats, our bond conductances as "
        "`throat.thermal_conductance`, the hot/cold layers as value boundary conditions; each N in a fresh "
        "subprocess. Ours = network assembly + `dem.thermal.steady`; OpenPNM = network/phase/algorithm set-up + "
        "`run()`. The two solutions agree to `max_abs_difference` (temperatures in [0, 1]). N = 10^6 is not run: "
        "OpenPNM's default PARDISO factorisation passed 14 GiB resident after 8 minutes there (stopped by hand).\n\n"
        + md_table(rows, ["particles", "bonds", "ours_seconds", "ours_solver", "openpnm_setup_seconds",
                          "openpnm_solve_seconds", "openpnm_seconds", "openpnm_solver", "ratio_ours_over_openpnm",
                          "max_abs_difference", "error"])
        + ("" if head is None else f"\n\nHeadline (N = {head['particles']}): ours {head['ours_seconds']:.3g} s, "
           f"OpenPNM {head['openpnm_seconds']:.3g} s, ratio {head['ratio_ours_over_openpnm']:.2f}."),
    )


def transient_worker(n: int) -> None:
    """Subprocess body: implicit Euler, ~n particles x 1000 steps at dt = 10 x the cheap explicit bound."""
    from dem.thermal import integrate

    net, times = packing_network(n)
    cap, diag = net.particles.capacity, np.asarray(net.L.diagonal())
    bound = 2.0 * float(np.min(cap[diag > 0] / diag[diag > 0]))  # 2 min C_i / sum_j K_ij
    dt = 10.0 * bound
    t0, c0 = time.perf_counter(), time.process_time()
    res = integrate(net, "implicit", dt=dt, t_end=1000 * dt)
    seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    print(json.dumps({"particles": net.particles.n, "bonds": int(net.bonds.n_pairs), "steps": res.steps, "dt": dt,
                      "cheap_explicit_bound": bound, "solver": res.solver, "energy_error": res.energy_error,
                      "integrate_seconds": seconds, "integrate_cpu_seconds": cpu, "setup_seconds": times["bonds_seconds"] + times["network_seconds"],
                      "peak_rss_mib": _peak_rss_mib()}))


def bench_dem_transient_big(report: Report, quick: bool) -> None:
    n = 10_000 if quick else 100_000
    row = run_worker("transient_worker", n, timeout=1200)
    report.csv("dem_transient_big", [row])
    seconds = row.get("integrate_seconds")
    if not quick:
        report.summary["dem_transient_1e5x1000_seconds"] = seconds
    report.summary["dem_transient_big"] = row
    report.section(
        "DEM transient: implicit, 10^5 particles x 1000 steps" + (" (quick: 10^4)" if quick else ""),
        "Random sintered packing with hot/cold fixed layers; backward Euler (`dem.thermal.integrate`, linear "
        "backend auto) at dt = 10 x the cheap explicit bound 2 min C_i / sum_j K_ij, 1000 steps, in a fresh "
        "subprocess; `integrate_seconds` excludes building the bonds (`setup_seconds`).\n\n"
        + md_table([row], ["particles", "bonds", "steps", "dt", "solver", "integrate_seconds",
                           "integrate_cpu_seconds", "setup_seconds",
                           "energy_error", "peak_rss_mib", "error"])
        + (f"\n\nTarget <= {TARGETS['dem_transient_1e5x1000_seconds']:g} s: "
           f"{verdict(seconds, TARGETS['dem_transient_1e5x1000_seconds'])}" if not quick else ""),
    )


def bench_dem(report: Report, quick: bool) -> None:
    try:
        import dem.generators  # noqa: F401
        import dem.thermal  # noqa: F401
    except ImportError as exc:
        report.section("DEM", f"not available: {exc}")
        return
    for step in (bench_dem_accuracy, bench_dem_scaling, bench_openpnm, bench_dem_transient_big):
        step(report, quick)
