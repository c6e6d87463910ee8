"""FE conductance of the semisphere (Rojek 2022, Fig. 12): error against time, NGSolve on the same problem (also the
sweep that the main command is timed against, :mod:`benchmarks.fit`), and the periodic cells.

* Error against time: P1-P4 on uniform/graded gmsh triangle meshes, the hp spectral elements (p = 2-9 on one
  geometric mesh) and both estimator-driven paths (hp, the default, and gmsh) at h/r = 0.02, 0.08, 0.4, against the
  12-digit reference table (:data:`verification.cases.SEMISPHERE`); the fastest setting to reach 1e-3, 1e-4, 1e-5.
* NGSolve (optional extra ``pip install .[peers]``; skipped with a note when absent): H1 order p on a netgen/OCC
  mesh curved to order p, hp-refined toward the re-entrant corner; its cheapest setting for each tolerance, and the
  headline 1e-4 solve timed side by side with ours.
* Periodic cells: ``python -m fem_neck lattice --rtol 1e-4`` on SC, BCC and FCC at h/r = 0.02 and 0.08 as a whole
  process (wall time, peak memory, true error against :data:`verification.lattices.REFERENCES`, the estimate over
  the true error), and NGSolve on the same cell (:func:`verification.ngsolve_cell.ngsolve_cell`) at the lowest order
  whose error is no larger than ours, timed in the same round.
"""

from __future__ import annotations

import json
import math
import pathlib
import subprocess
import sys
import tempfile
import time

from benchmarks.timing import available, best_time, fastest, package_version, side_by_side
from verification.cases import REFERENCE_TABLE, SEMISPHERE_BY_H
from verification.report import records_table

TITLE = "FE conductance of the semisphere"
FE_CASES = (0.02, 0.08, 0.4)  # h/r of the FE studies
HEADLINE_H_OVER_R = 0.08  # the "one semisphere" of fe_seconds_to_1e-4 / ngsolve_seconds_to_1e-4
TOLERANCES = (1e-3, 1e-4, 1e-5)
HP_LEVELS = 4  # corner refinements of the fixed hp settings (their own error is < 1e-9, see fem_neck.accuracy)
SIDE_BY_SIDE_ROUNDS = 15
# NGSolve's setting of the start-up comparison: it reaches 1e-4 at all three h/r (error 3.2e-5) and was the cheapest
# such setting of a full study on a quiet machine; fixed, so that the comparison does not follow timing noise
NGSOLVE_STARTUP = {"order": 3, "maxh": 0.3, "hp_levels": 2}
LIMITS = {"fe_seconds_to_1e-4": 0.5, "fe_over_ngsolve": 1.0, "lattice_seconds": 60.0, "lattice_gb": 4.0,
          "lattice_estimate_ratio": 3.0, "lattice_over_ngsolve": 2.0}
LATTICE_RTOL = 1e-4
NGSOLVE_ORDERS = (3, 4, 5)  # NGSolve's orders tried for equal accuracy (hp levels = order, maxh 0.5)


def reference(h_over_r: float) -> tuple[float, float]:
    """``(a/r, K/K_cyl)`` of the reference row ``h_over_r``."""
    row = SEMISPHERE_BY_H[h_over_r]
    return row.a_over_r, row.K_over_Kcyl


# ------------------------------------------------------------------------------------------------------ NGSolve
def ngsolve_semisphere(a_over_r: float, order: int, maxh: float = 0.3, hp_levels: int = 2,
                       hp_factor: float = 0.125) -> tuple[float, int]:
    """``(K/K_cyl, ndof)`` of the semisphere with a neck of radius ``a_over_r``, solved by NGSolve.

    Sphere radius 1: T = 1 on the equatorial disk, T = 0 on the neck's end disk at the mid-plane z = 1 - h/2,
    insulated elsewhere; axisymmetric (weight rho in the bilinear form), H1 elements of order p on a netgen/OCC mesh
    curved to order p, ``hp_levels`` geometric refinements toward the re-entrant corner. ``K/K_cyl = 2 pi E / pi``
    with ``E = u^T A u`` the energy (kappa = 1, Delta T = 1).
    """
    import ngsolve as ngs
    from netgen import occ

    from fem_neck.geometry import overlap_for_neck

    ngs.ngsglobals.msg_level = 0
    a = float(a_over_r)
    z_i = math.sqrt((1.0 - a) * (1.0 + a))
    z_top = 1.0 - 0.5 * overlap_for_neck(1.0, 1.0, a)
    shape = occ.Circle((0, 0), 1.0).Face() * occ.Rectangle(1.0, z_i).Face()
    shape = shape + occ.MoveTo(0, z_i).Rectangle(a, z_top - z_i).Face()
    shape.edges.Min(occ.Y).name = "equator"
    shape.edges.Max(occ.Y).name = "neck"
    shape.vertices.Nearest((a, z_i, 0)).hpref = 1
    mesh = ngs.Mesh(occ.OCCGeometry(shape, dim=2).GenerateMesh(maxh=maxh))
    if hp_levels:
        mesh.RefineHP(levels=hp_levels, factor=hp_factor)
    mesh.Curve(order)
    fes = ngs.H1(mesh, order=order, dirichlet="equator|neck")
    u, v = fes.TnT()
    form = ngs.BilinearForm(ngs.x * ngs.grad(u) * ngs.grad(v) * ngs.dx).Assemble()
    temp = ngs.GridFunction(fes)
    temp.Set(1.0, definedon=mesh.Boundaries("equator"))
    rhs = -form.mat * temp.vec
    temp.vec.data += form.mat.Inverse(fes.FreeDofs(), inverse="sparsecholesky") * rhs
    return 2.0 * ngs.InnerProduct(temp.vec, form.mat * temp.vec), fes.ndof


def ngsolve_sweep(n_points: int, order: int, maxh: float, hp_levels: int) -> None:
    """Worker of the start-up comparison: NGSolve on the fit's ``n_points`` a/r, one JSON line of K/K_cyl."""
    from fem_neck.fit import sweep_points

    x, _ = sweep_points(n_points)
    print(json.dumps({"a_over_r": x.tolist(),
                      "K_over_Kcyl": [ngsolve_semisphere(float(a), order, maxh, hp_levels)[0] for a in x]}))


def study_ngsolve(section, quick: bool) -> None:
    """NGSolve's error against time and its cheapest settings; the headline timed side by side with ours."""
    if not available("ngsolve"):
        section.add_text("Peer: NGSolve", "NGSolve is not installed (optional extra: `pip install .[peers]`); "
                                          "skipped.")
        return
    from matplotlib.figure import Figure

    orders = (2, 4, 6) if quick else (1, 2, 3, 4, 5, 6, 8)
    maxhs = (0.3,) if quick else (0.5, 0.3, 0.15)
    levels = (0, 2) if quick else (0, 2, 4)
    ngsolve_semisphere(reference(0.08)[0], 2)  # warm (imports, OCC)
    rows = []
    for h_over_r in FE_CASES:
        a, k_ref = reference(h_over_r)
        for order in orders:
            for maxh in maxhs:
                for lv in levels:
                    t, (k, ndof) = best_time(lambda: ngsolve_semisphere(a, order, maxh, lv), 2)
                    rows.append({"h_over_r": h_over_r, "order": order, "maxh": maxh, "hp_levels": lv,
                                 "ndof": ndof, "K_over_Kcyl": k, "rel_error": abs(k - k_ref) / k_ref, "seconds": t})
        section.csv("ngsolve_semisphere", rows)
    settings = {}  # a-priori: the cheapest (order, maxh, levels) that reaches each tolerance at every h/r
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
    section.csv("ngsolve_fastest", best)
    head = next((b for b in best if b["tolerance"] == 1e-4 and b["kind"].startswith("a-priori")), None)
    setting = None if head is None else {k: head[k] for k in ("order", "maxh", "hp_levels")}
    section.summary["ngsolve_setting_1e-4"] = setting
    side = None if setting is None else headline_side_by_side(setting)
    section.summary["ngsolve_seconds_to_1e-4"] = None if side is None else side["ngsolve_seconds"]
    section.summary["fe_over_ngsolve_side_by_side"] = None if side is None else side["ratio"]

    fig = Figure(figsize=(13, 3.8))
    axes = fig.subplots(1, len(FE_CASES), sharey=True)
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
    figure = section.figure(fig, "ngsolve_semisphere")
    section.add_text(
        "Peer: NGSolve on the semisphere",
        f"NGSolve {package_version('ngsolve')}: H1 order p on a netgen/OCC mesh curved to order p, hp-refined toward "
        "the re-entrant corner (factor 0.125), sparse Cholesky, axisymmetric weight rho; K from the energy. Time per "
        "solve includes geometry, meshing, assembly and solve (warm, best of 2). Sweep: p in "
        f"{list(orders)}, maxh in {list(maxhs)}, hp levels in {list(levels)}. Error against {REFERENCE_TABLE}.\n\n"
        + records_table(best, ["tolerance", "h_over_r", "kind", "order", "maxh", "hp_levels", "ndof", "rel_error",
                               "seconds"])
        + f"\n\nHeadline `ngsolve_seconds_to_1e-4` (h/r = {HEADLINE_H_OVER_R}, the a-priori setting above, no error "
        "estimate), timed side by side with ours (`semisphere_conductance(rtol=1e-4)`, which also solves the order "
        f"below for its estimate): {SIDE_BY_SIDE_ROUNDS} alternating rounds, best of each: "
        + (f"NGSolve {side['ngsolve_seconds'] * 1e3:.2f} ms (error {side['ngsolve_error']:.1e}), ours "
           f"{side['fe_seconds'] * 1e3:.2f} ms (error {side['fe_error']:.1e}, estimate {side['fe_estimate']:.1e}), "
           f"**ratio ours/NGSolve = {side['ratio']:.2f}**" if side else "not reached"),
        figures=[figure],
    )


def headline_side_by_side(setting: dict) -> dict:
    """NGSolve's a-priori 1e-4 setting and our default 1e-4 solve, alternately (same machine state), best of each
    over :data:`SIDE_BY_SIDE_ROUNDS` rounds, on the headline semisphere."""
    from fem_neck import conduction

    a, k_ref = reference(HEADLINE_H_OVER_R)
    best, values = side_by_side({
        "fe": lambda: conduction.semisphere_conductance(a, rtol=1e-4),
        "ngsolve": lambda: ngsolve_semisphere(a, setting["order"], setting["maxh"], setting["hp_levels"]),
    }, SIDE_BY_SIDE_ROUNDS)
    res, (k_ng, _) = values["fe"], values["ngsolve"]
    return {"fe_seconds": best["fe"], "ngsolve_seconds": best["ngsolve"], "ratio": best["fe"] / best["ngsolve"],
            "fe_error": abs(res.K_over_Kcyl - k_ref) / k_ref, "fe_estimate": res.error_estimate,
            "ngsolve_error": abs(k_ng - k_ref) / k_ref}


# ------------------------------------------------------------------------------------------ error against time
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


def fe_study_configs(quick: bool) -> list[tuple[int, str, float]]:
    """(order, mesh kind, size) of the FE sweep."""
    if quick:
        return ([(p, "hp", HP_LEVELS) for p in (3, 4, 5)] + [(p, "uniform", s) for p in (1, 2) for s in (0.1, 0.05)]
                + [(p, "graded", g) for p in (1, 2, 3) for g in (0.4, 0.2)])
    configs = [(p, "hp", HP_LEVELS) for p in range(2, 10)]
    configs += [(p, "uniform", s) for p in (1, 2) for s in (0.1, 0.05, 0.025, 0.0125)]
    configs += [(p, "graded", g) for p in (1, 2, 3, 4) for g in (0.45, 0.3, 0.2, 0.12, 0.08)]
    return configs + [(1, "graded", g) for g in (0.05, 0.03)] + [(2, "graded", 0.05)]


def study_error_against_time(section, quick: bool) -> None:
    from matplotlib.figure import Figure
    from tqdm import tqdm

    from fem_neck import conduction

    conduction.semisphere_conductance(0.4)  # warm: imports, gmsh, scikit-fem caches
    configs = fe_study_configs(quick)
    rtols = (1e-3, 1e-4) if quick else (1e-3, 1e-4, 1e-5, 1e-6)
    rows = []
    bar = tqdm(total=len(FE_CASES) * (len(configs) + len(rtols)), desc="benchmarks fe", file=sys.stderr,
               disable=not sys.stderr.isatty())
    for h_over_r in FE_CASES:
        a_over_r, k_ref = reference(h_over_r)
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
        section.csv("fe_semisphere", rows)
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
        by_setting = {}  # one fixed setting meeting tol at all three h/r (what a default must do blind)
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
    section.csv("fe_fastest", fastest_rows)

    a_head, k_head = reference(HEADLINE_H_OVER_R)  # headline: warm default solve (rtol = 1e-4) of one semisphere
    t_head, res = best_time(lambda: conduction.semisphere_conductance(a_head, rtol=1e-4), 20)
    t_gmsh, _ = best_time(lambda: conduction.semisphere_conductance(a_head, rtol=1e-4, method="gmsh"), 3)
    err_head = abs(res.K_over_Kcyl - k_head) / k_head
    section.summary.update({"fe_seconds_to_1e-4": t_head, "fe_gmsh_path_seconds_to_1e-4": t_gmsh,
                            "fe_rel_error_at_rtol_1e-4": err_head,
                            "fe_error_estimate_at_rtol_1e-4": res.error_estimate})

    fig = Figure(figsize=(13, 4))
    axes = fig.subplots(1, len(FE_CASES), sharey=True)
    for ax, h_over_r in zip(axes, FE_CASES):
        sel = [r for r in rows if r["h_over_r"] == h_over_r]
        for path in dict.fromkeys(r["path"] for r in sel):
            pts = sorted((r["seconds"], max(r["rel_error"], 1e-12)) for r in sel if r["path"] == path)
            style = ("s--" if "uniform" in path else "r^-" if "hp" in path and "rtol" not in path
                     else "k*-" if "hp)" in path else "m*-" if "rtol" in path else "o-")
            ax.loglog(*zip(*pts), style, ms=4, label=path)
        for tol in TOLERANCES:
            ax.axhline(tol, color="0.75", lw=0.7)
        ax.set_title(f"h/r = {h_over_r} (a/r = {reference(h_over_r)[0]:.4f})")
        ax.set_xlabel("wall time (mesh + solve) [s]")
    axes[0].set_ylabel("relative error of K/K_cyl")
    axes[-1].legend(fontsize=6)
    figure = section.figure(fig, "fe_error_vs_time")
    section.add_text(
        "Error against time",
        f"Reference: {REFERENCE_TABLE} (rows h/r = {', '.join(map(str, FE_CASES))}). A triangle setting is "
        "one gmsh mesh plus one scikit-fem solve (curved isoparametric boundary for P>=2), warm, best of "
        f"{1 if quick else 2}: 'uniform' has element size `size`, 'graded' has size h_min + `size` x distance to "
        f"the re-entrant corner. 'Pp hp' is one hp mesh ({HP_LEVELS} geometric corner refinements, exact sphere, "
        "fem_neck.hpmesh) plus one spectral solve of order p (best of 3). `semisphere_conductance(rtol, method)` "
        "is the estimator-driven path: hp (the default) raises p on one mesh until orders p-1 and p agree to rtol; "
        "gmsh solves orders p-1 and p on one graded mesh and shrinks the grading until they agree. Full table: "
        "`fe_semisphere.csv`.\n\nFastest setting reaching each tolerance:\n\n"
        + records_table(fastest_rows, ["tolerance", "h_over_r", "kind", "path", "size", "rtol", "dofs", "rel_error",
                                       "seconds"])
        + f"\n\nHeadline `fe_seconds_to_1e-4` (warm `semisphere_conductance(a/r = {a_head:.6f}, rtol=1e-4)`, "
        f"h/r = {HEADLINE_H_OVER_R}, best of 20): **{t_head * 1e3:.2f} ms**, true error {err_head:.1e}, estimate "
        f"{res.error_estimate:.1e}, order {res.order}, {res.dofs} dofs. The gmsh path to the same rtol: "
        f"{t_gmsh * 1e3:.1f} ms (ratio {t_gmsh / t_head:.0f}).",
        figures=[figure],
    )


# ------------------------------------------------------------------------------------------------- periodic cells
def lattice_process(kind: str, h_over_r: float, rtol: float) -> dict:
    """``python -m fem_neck lattice --json`` as a fresh process: its output, wall seconds and peak memory (GB)."""
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "fem_neck", "lattice", "--kind", kind, "--h-over-r", str(h_over_r),
                        "--rtol", str(rtol), "--json", "--out", tmp], capture_output=True, check=True)
        seconds = time.perf_counter() - t0
        out = json.loads((pathlib.Path(tmp) / "lattice.json").read_text())
    # peak_memory_gb: the process's peak plus its lower-bound child's (fem_neck.lattice.budget.peak_memory)
    return {**out, "wall_seconds": seconds, "peak_gb": out["peak_memory_gb"]}


def study_lattice(section, quick: bool) -> None:
    """Our periodic-cell FE to 1e-4 against the references, and NGSolve at equal accuracy in the same round."""
    from fem_neck import lattice
    from verification.lattices import REFERENCES

    cases = [("sc", 0.08)] if quick else sorted(REFERENCES)
    have_ngsolve = available("ngsolve")
    rows = []
    for kind, h in cases:
        ref = REFERENCES[(kind, h)]
        ours = lattice_process(kind, h, LATTICE_RTOL)
        cell = lattice.lattice_cell(kind, h)
        t0 = time.perf_counter()  # in this process, warm like NGSolve below: geometry, meshes, both bounds
        lattice.effective_conductivity(cell, rtol=LATTICE_RTOL)
        warm = time.perf_counter() - t0
        error = ours["k_eff_over_kappa"] / ref - 1.0
        row = {"case": f"{kind.upper()} h/r={h:g}", "reference": ref, "k_upper": ours["k_upper_over_kappa"],
               "k_lower": ours["k_lower_over_kappa"], "rel_error": error, "error_estimate": ours["error_estimate"],
               "estimate_over_error": ours["error_estimate"] / abs(error) if error else None,
               "bracketed": ours["k_lower_over_kappa"] < ref < ours["k_upper_over_kappa"],
               "order": ours["order"], "elements": ours["elements"], "seconds": ours["wall_seconds"],
               "peak_gb": ours["peak_gb"], "warm_seconds": warm}
        if have_ngsolve:
            from verification.ngsolve_cell import ngsolve_cell

            for order in NGSOLVE_ORDERS:
                ng = ngsolve_cell(cell, order)
                if abs(ng["k"] / ref - 1.0) <= abs(error):
                    row.update({"ngsolve_order": order, "ngsolve_ndof": ng["ndof"],
                                "ngsolve_rel_error": ng["k"] / ref - 1.0, "ngsolve_seconds": ng["seconds"],
                                "ours_over_ngsolve": warm / ng["seconds"]})
                    break
        rows.append(row)
        section.csv("lattice", rows)
    worst = {"seconds": max(r["seconds"] for r in rows), "peak_gb": max(r["peak_gb"] for r in rows),
             "estimate_over_error": max(r["estimate_over_error"] or 0.0 for r in rows),
             "ours_over_ngsolve": max((r.get("ours_over_ngsolve") or 0.0 for r in rows), default=0.0) or None}
    section.summary.update({f"lattice_worst_{k}": v for k, v in worst.items()})
    section.summary["lattice_all_bracketed"] = all(r["bracketed"] for r in rows)
    section.add_text(
        "Periodic cells: ours against the references and NGSolve",
        f"`python -m fem_neck lattice --kind K --h-over-r H --rtol {LATTICE_RTOL:g} --json` as a whole process "
        "(imports, meshes, both bounds; wall time `seconds` and peak memory of the process and its solver child), "
        "then `effective_conductivity(cell, rtol)` again in this process, warm (`warm_seconds`: geometry, meshes, "
        "both bounds). Reference: NGSolve of order 6 on its own hp mesh (`verification.lattices.REFERENCES`). "
        f"NGSolve: the lowest order of {list(NGSOLVE_ORDERS)} (hp levels = order, maxh 0.5, warm: geometry, mesh, "
        "solve) whose error is no larger than ours, timed right after ours; it gives no error bound. "
        "`ours_over_ngsolve` = warm_seconds / ngsolve_seconds.\n\n"
        + records_table(rows, ["case", "reference", "k_lower", "k_upper", "bracketed", "rel_error", "error_estimate",
                               "estimate_over_error", "order", "elements", "seconds", "peak_gb", "warm_seconds",
                               "ngsolve_order",
                               "ngsolve_rel_error", "ngsolve_seconds", "ours_over_ngsolve"]))
    section.target(f"lattice cells to rtol {LATTICE_RTOL:g}: slowest whole run", worst["seconds"],
                   LIMITS["lattice_seconds"], "s")
    section.target("lattice cells: largest peak memory", worst["peak_gb"], LIMITS["lattice_gb"], "GB")
    section.target("lattice cells: largest estimate over true error", worst["estimate_over_error"],
                   LIMITS["lattice_estimate_ratio"])
    section.target("lattice cells: ours / NGSolve at equal accuracy (largest)", worst["ours_over_ngsolve"],
                   LIMITS["lattice_over_ngsolve"])


def run(section, quick: bool) -> None:
    section.summary.update({"fe_seconds_to_1e-4": None, "ngsolve_seconds_to_1e-4": None,
                            "fe_over_ngsolve_side_by_side": None})
    study_error_against_time(section, quick)
    section.target("semisphere K to 1e-4 (warm, h/r = 0.08)", section.summary["fe_seconds_to_1e-4"],
                   LIMITS["fe_seconds_to_1e-4"], "s")
    study_ngsolve(section, quick)
    section.target("semisphere: ours / NGSolve, side by side", section.summary["fe_over_ngsolve_side_by_side"],
                   LIMITS["fe_over_ngsolve"])
    study_lattice(section, quick)
