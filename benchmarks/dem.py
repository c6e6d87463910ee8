"""The DEM's thermal solvers on random sintered packings: transient error against time, steady cost against N (to
10^7 particles), the linear solvers behind both, our AMG beside PETSc's (when petsc4py imports), implicit 10^5
particles x 1000 steps, and OpenPNM on the same network (optional extra ``pip install .[peers]``; skipped with a
note when absent).

Large runs go to fresh subprocesses (:func:`benchmarks.timing.run_worker`), so that each has its own peak memory.
"""

from __future__ import annotations

import time

import numpy as np

from benchmarks.timing import (available, best_time, emit, growth_exponent, package_version, peak_rss_mib, ratio,
                               run_worker, worker_sweep)
from verification.report import records_table

TITLE = "DEM thermal solvers"
PACKING = {"radius": 50e-6, "overlap": 0.15}  # copper, mean radius 50 um, mean relative overlap 0.15 (rojek law)
# dem_steady_1e6_seconds: bonds + network + solve on two cores. The run is bound by memory traffic, so the target holds
# where memory streams about 30 GB/s; on a machine that streams 10 GB/s it takes about twice as long (benchmarks guide)
LIMITS = {"dem_steady_1e6_seconds": 3.0, "dem_steady_1e6_peak_gib": 8.0,
          "dem_steady_1e7_peak_gib": 20.0, "dem_transient_1e5x1000_seconds": 60.0,
          "dem_over_openpnm": 1.0, "dem_amg_over_petsc": 1.0}


def packing_network(n: int, seed: int = 0, connected_only: bool = False, t_hot: float = 1.0):
    """A random sintered packing of ~n copper particles (``dem.geometry.generators.random_packing``) between a hot bottom
    layer (fixed at ``t_hot``) and a cold top layer (fixed at 0), free particles starting at 0, rojek law.

    ``connected_only`` keeps only the particles connected to a fixed layer (what a pore-network code can solve).
    Returns ``(network, timings)`` with the seconds of the packing, the bonds and the network assembly.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    from dem.geometry.bonds import find_bonds
    from dem.geometry.generators import random_packing
    from dem.geometry.particles import Particles
    from dem.network.heat import build_network

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
        bonds = find_bonds(Particles.from_arrays(pos, rad, temp, fixed=fixed))
        _, label = connected_components(coo_matrix((np.ones(bonds.n_pairs), (bonds.i, bonds.j)), shape=(n, n)),
                                        directed=False)
        keep = np.isin(label, np.unique(label[fixed]))
        pos, rad, temp, fixed = pos[keep], rad[keep], temp[keep], fixed[keep]
    t0 = time.perf_counter()
    particles = Particles.from_arrays(pos, rad, temp, fixed=fixed)
    bonds = find_bonds(particles)
    times["bonds_seconds"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    net = build_network(particles, bonds=bonds)
    times["network_seconds"] = time.perf_counter() - t0
    return net, times


# ------------------------------------------------------------------------------------------- fresh-process workers
def steady_worker(n: int) -> None:
    """One steady solve of a packing of ~n particles; one JSON line."""
    from dem.network.heat import steady

    base = peak_rss_mib()
    net, times = packing_network(n)
    t0, c0 = time.perf_counter(), time.process_time()
    res = steady(net, floating="mean")
    times["solve_seconds"] = time.perf_counter() - t0
    times["solve_cpu_seconds"] = time.process_time() - c0
    times["steady_seconds"] = times["bonds_seconds"] + times["network_seconds"] + times["solve_seconds"]
    peak = peak_rss_mib()
    emit({"particles": net.particles.n, "bonds": int(net.bonds.n_pairs), "solver": res.solver,
          "floating_groups": res.floating, "peak_rss_mib": peak, "baseline_rss_mib": base,
          "bytes_per_particle": (peak - base) * 2**20 / net.particles.n, **times})


def openpnm_steady(coords, i, j, conductance, fixed, t_fixed) -> tuple[np.ndarray, dict]:
    """Steady Fourier conduction in OpenPNM on the network (coords, bonds i-j, throat conductances [W/K]).

    ``fixed`` is a boolean mask of pores held at ``t_fixed`` (array over all pores; only fixed entries are read).
    Returns the pore temperatures and ``{"setup_seconds", "solve_seconds", "solver"}`` (building the
    network/phase/algorithm, and ``run()`` with OpenPNM's default solver, whose name is ``solver``).
    """
    import logging

    import openpnm as op

    logging.getLogger("openpnm").setLevel(logging.ERROR)
    t0 = time.perf_counter()
    ws = op.Workspace()
    ws.clear()
    net = op.network.Network(coords=np.asarray(coords, float), conns=np.column_stack([i, j]).astype(np.int64))
    phase = op.phase.Phase(network=net)
    phase["throat.thermal_conductance"] = np.asarray(conductance, float)
    alg = op.algorithms.FourierConduction(network=net, phase=phase)
    pores = np.flatnonzero(fixed)
    alg.set_value_BC(pores=pores, values=np.asarray(t_fixed, float)[pores])
    t1 = time.perf_counter()
    alg.run()
    t2 = time.perf_counter()
    temperature = np.array(alg["pore.temperature"])
    ws.clear()
    return temperature, {"setup_seconds": t1 - t0, "solve_seconds": t2 - t1, "solver": ws.settings.default_solver}


def openpnm_worker(n: int) -> None:
    """Ours and OpenPNM on the same connected network of ~n particles; one JSON line."""
    from dataclasses import replace

    from dem.network.heat import steady

    net, _ = packing_network(n, connected_only=True)
    p, b = net.particles, net.bonds
    t0 = time.perf_counter()  # ours: assembly of the network matrix from the bonds + steady solve
    net = replace(net)
    res = steady(net)
    ours = time.perf_counter() - t0
    T_pnm, times = openpnm_steady(p.position, b.i, b.j, net.K_pairs, p.fixed, p.temperature)
    emit({"particles": p.n, "bonds": int(b.n_pairs), "ours_seconds": ours, "ours_solver": res.solver,
          "openpnm_setup_seconds": times["setup_seconds"], "openpnm_solve_seconds": times["solve_seconds"],
          "openpnm_seconds": times["setup_seconds"] + times["solve_seconds"], "openpnm_solver": times["solver"],
          "max_abs_difference": float(np.max(np.abs(T_pnm - res.T)))})


def amg_peers_worker(n: int) -> None:
    """Our AMG before and after its tuning and PETSc's (when importable) on the steady network of ~n particles,
    side by side (:mod:`benchmarks.amg_peers`); one JSON line."""
    from benchmarks.amg_peers import side_by_side_rows

    net, _ = packing_network(n)
    _, label, anchored = net.graph.components()
    solve = np.flatnonzero(anchored[label])  # what dem.network.heat.steady solves (floating particles apart)
    A = net.matrix({})[solve][:, solve].tocsr()
    b = net.rhs({})[solve]
    rows = side_by_side_rows(A, b, rounds=3)
    emit({"particles": net.particles.n, "unknowns": A.shape[0], "nonzeros": int(A.nnz), "rows": rows})


def cheap_explicit_bound(net) -> float:
    """``2 min C_i / sum_j K_ij`` over bonded particles: a cheap lower bound of the explicit stable step."""
    cap, diag = net.particles.capacity, np.asarray(net.L.diagonal())
    return 2.0 * float(np.min(cap[diag > 0] / diag[diag > 0]))


def transient_worker(n: int) -> None:
    """Implicit Euler, ~n particles x 1000 steps at dt = 10 x the cheap explicit bound; one JSON line."""
    from dem.network.heat import integrate

    net, times = packing_network(n)
    bound = cheap_explicit_bound(net)
    dt = 10.0 * bound
    t0, c0 = time.perf_counter(), time.process_time()
    res = integrate(net, "implicit", dt=dt, t_end=1000 * dt)
    seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    emit({"particles": net.particles.n, "bonds": int(net.bonds.n_pairs), "steps": res.steps, "dt": dt,
          "cheap_explicit_bound": bound, "solver": res.solver, "energy_error": res.energy_error,
          "integrate_seconds": seconds, "integrate_cpu_seconds": cpu,
          "setup_seconds": times["bonds_seconds"] + times["network_seconds"], "peak_rss_mib": peak_rss_mib()})


# ---------------------------------------------------------------------------------------------------------- studies
def study_transient_accuracy(section, quick: bool) -> None:
    from matplotlib.figure import Figure

    from dem.network.heat import integrate, stable_limit

    net, _ = packing_network(500 if quick else 2000, seed=1)
    limit = stable_limit(net)
    t_end = 200 * limit
    t_ref, ref = best_time(lambda: integrate(net, "crank-nicolson", dt=limit / 16, t_end=t_end), 1)
    check = integrate(net, "crank-nicolson", dt=limit / 8, t_end=t_end)
    ref_error = float(np.max(np.abs(check.T - ref.T)) / 3.0)  # CN is 2nd order: error(dt/16) ~ diff / 3
    rows = []
    factors = {"explicit": (0.9, 0.45, 0.225, 0.1125), "implicit": (0.5, 2, 8, 32), "crank-nicolson": (0.5, 2, 8, 32)}
    for integrator, facs in factors.items():
        runs = [(f"{f:g} x limit", {"dt": f * limit}) for f in facs]
        runs += [(f"auto, rtol {rtol:g}", {"dt": "auto", "rtol": rtol}) for rtol in (1e-2, 1e-3, 1e-4)]
        for label, options in runs:
            t, res = best_time(lambda: integrate(net, integrator, t_end=t_end, **options), 1)
            rows.append({"integrator": integrator, "dt": label, "steps": res.steps, "rejected": res.rejected,
                         "error": float(np.max(np.abs(res.T - ref.T))), "energy_error": res.energy_error,
                         "solver": res.solver, "seconds": t})
    section.csv("dem_transient_accuracy", rows)
    fig = Figure(figsize=(6, 4))
    ax = fig.subplots()
    for integrator, marker in zip(factors, "os^"):
        sel = [r for r in rows if r["integrator"] == integrator]
        ax.loglog([r["seconds"] for r in sel], [max(r["error"], 1e-16) for r in sel], marker, label=integrator)
    ax.set_xlabel("wall time [s]")
    ax.set_ylabel("max |T - T_ref| (hot plate 1, cold 0)")
    ax.set_title(f"DEM transient, {net.particles.n} particles, t_end = 200 x explicit limit")
    ax.legend(fontsize=8)
    figure = section.figure(fig, "dem_transient_accuracy")
    section.add_text(
        "DEM transient: error against time",
        f"Random sintered packing ({net.particles.n} copper particles, mean radius {PACKING['radius']:g} m, mean "
        f"relative overlap {PACKING['overlap']}, rojek law), bottom layer fixed at 1, top at 0, free particles "
        f"starting at 0; explicit stable limit {limit:.4g} s (dem.network.heat.stable_limit); t_end = 200 x limit. "
        f"Reference: Crank-Nicolson at dt = limit/16 ({t_ref:.2f} s; its own error ~{ref_error:.1e} from the "
        "dt/8 run). Error: max over particles of |T - T_ref|; `auto` is the error-controlled step "
        "(dem.network.heat.integrate).\n\n"
        + records_table(rows, ["integrator", "dt", "steps", "rejected", "error", "energy_error", "solver", "seconds"]),
        figures=[figure],
    )


def study_linear_solvers(section, quick: bool) -> None:
    """The backends of ``dem.network.linsolve`` on the matrices the DEM solves, with the choice of ``"auto"``."""
    import scipy.sparse as sp

    from dem.network.linsolve import BACKENDS, DIRECT_MAX, choose_backend
    from dem.network.heat import integrate

    sizes = (2_000, 5_000) if quick else (2_000, 5_000, 10_000, 20_000, 50_000)
    direct_max = 25_000  # SuperLU's fill-in: ~1 s at 2e4 unknowns, ~15 s at 5e4
    rows = []
    for n in sizes:
        net, _ = packing_network(n, seed=1)
        A0, r0 = net.matrix({}), net.rhs({})
        bound = cheap_explicit_bound(net)
        cases = [("steady", A0, r0)] + [
            (f"C/dt + A, dt = {f:g}x bound", A0 + sp.diags(net.C / (f * bound)), r0 + net.C / (f * bound) * 0.5)
            for f in (1, 10, 100, 1000)]
        for label, A, b in cases:
            row = {"unknowns": net.n_free, "matrix": label, "auto": choose_backend(A, net.base_diag)}
            for name, solver_class in BACKENDS.items():
                if name == "direct" and net.n_free > direct_max:
                    continue
                t0 = time.perf_counter()
                solver = solver_class(A, rtol=1e-10)
                setup = time.perf_counter() - t0
                solve, _ = best_time(lambda: solver.solve(b), 1)
                row[f"{name}_setup_s"], row[f"{name}_solve_s"] = setup, solve
                if name != "direct":
                    row[f"{name}_iterations"] = solver.iterations
            rows.append(row)
        section.csv("dem_linear_solvers", rows)
    runs = []
    net, _ = packing_network(2_000 if quick else 5_000, seed=1)
    dt = 10.0 * cheap_explicit_bound(net)
    for linear in ("direct", "cg", "amg"):
        t, res = best_time(lambda: integrate(net, "implicit", dt=dt, t_end=200 * dt, linear=linear), 1)
        runs.append({"unknowns": net.n_free, "run": "implicit, dt = 10x bound, 200 steps", "linear": linear,
                     "seconds": t, "energy_error": res.energy_error})
    for linear in ("direct", "cg"):
        t, res = best_time(lambda: integrate(net, "crank-nicolson", dt="auto", rtol=1e-3, t_end=200 * dt,
                                             linear=linear), 1)
        runs.append({"unknowns": net.n_free, "run": f"Crank-Nicolson, auto, rtol 1e-3 ({res.steps} steps)",
                     "linear": linear, "seconds": t, "energy_error": res.energy_error})
    section.csv("dem_linear_solvers_runs", runs)
    columns = ["unknowns", "matrix", "auto", "direct_setup_s", "direct_solve_s", "cg_solve_s", "cg_iterations",
               "amg_setup_s", "amg_solve_s", "amg_iterations"]
    section.add_text(
        "DEM linear solvers",
        "The backends of `dem.network.linsolve` on random sintered packings between fixed plates (rojek law, seed 1), "
        "solving to rtol 1e-10 from zero: seconds of the setup (factorisation or multigrid hierarchy) and of one "
        "solve, CG/AMG iterations. `steady`: the network matrix A; `C/dt + A`: an implicit step with dt in units "
        "of the cheap explicit bound 2 min C_i / L_ii. `auto` is the backend `\"auto\"` picks (Jacobi-CG when the "
        f"capacity term makes the matrix diagonally dominant enough, else direct up to {DIRECT_MAX} unknowns and "
        f"AMG above); direct is not run above {direct_max} unknowns.\n\n"
        + records_table(rows, columns, fmt="{:.3g}")
        + "\n\nWhole runs on the same decay (`dem.network.heat.integrate`):\n\n" + records_table(runs, fmt="{:.3g}"),
    )


def study_steady_scaling(section, quick: bool) -> None:
    from matplotlib.figure import Figure

    sizes = (1_000, 10_000) if quick else (1_000, 10_000, 100_000, 1_000_000, 10_000_000)
    rows = worker_sweep(section, "dem_steady_scaling", "benchmarks.dem", "steady_worker", sizes, timeout=1800)
    good = [r for r in rows if "error" not in r]
    section.summary["dem_steady_seconds"] = {str(r["particles"]): r["steady_seconds"] for r in good}
    section.summary["dem_steady_peak_rss_mib"] = {str(r["particles"]): r["peak_rss_mib"] for r in good}
    big = [r for r in good if r["particles"] >= 10_000]
    big = big if len(big) >= 2 else good
    exp_t = growth_exponent([r["particles"] for r in big], [r["steady_seconds"] for r in big])
    exp_m = growth_exponent([r["particles"] for r in big],
                            [max(r["peak_rss_mib"] - r["baseline_rss_mib"], 1e-3) for r in big])
    section.summary["dem_steady_time_exponent"] = exp_t
    section.summary["dem_steady_memory_exponent"] = exp_m
    figures = []
    if good:
        fig = Figure(figsize=(5.5, 4))
        ax = fig.subplots()
        ns = [r["particles"] for r in good]
        for key in ("bonds_seconds", "solve_seconds", "steady_seconds"):
            ax.loglog(ns, [r[key] for r in good], "o-", label=key.replace("_seconds", ""))
        ax2 = ax.twinx()
        ax2.loglog(ns, [r["peak_rss_mib"] for r in good], "k--", label="peak RSS [MiB]")
        ax2.set_ylabel("peak RSS [MiB]")
        ax.set_xlabel("particles")
        ax.set_ylabel("wall time [s]")
        ax.legend(fontsize=8, loc="upper left")
        figures.append(section.figure(fig, "dem_steady_scaling"))
    section.add_text(
        "DEM steady solve: cost against N",
        "Each N in a fresh subprocess: random sintered packing with hot/cold fixed layers; `steady_seconds` = bonds "
        "(cells or k-d trees + neck radii) + conductances and network assembly + `dem.network.heat.steady` (floating = \"mean\" "
        "for the few particles the packing leaves unbonded); the packing generation is listed apart. Peak memory "
        "is the process's maximum RSS, the baseline after imports alongside, and the peak above the baseline per "
        "particle (`dem.memory.BYTES_PER_PARTICLE` is what a run is refused by). 10^7 particles run where the "
        "machine has the memory (`dem.memory.check`; the row holds the refusal otherwise).\n\n"
        + records_table(rows, ["particles", "bonds", "packing_seconds", "bonds_seconds", "network_seconds",
                               "solve_seconds", "solve_cpu_seconds", "steady_seconds", "solver", "peak_rss_mib",
                               "baseline_rss_mib", "bytes_per_particle", "error"])
        + ("\n\nGrowth exponent: too few points." if exp_t is None or exp_m is None else
           f"\n\nGrowth exponents (least squares over N = {', '.join(str(r['particles']) for r in big)}): time ~ "
           f"N^{exp_t:.2f}, memory above baseline ~ N^{exp_m:.2f}."),
        figures=figures,
    )
    million = next((r for r in good if r["particles"] >= 10**6), None)
    section.target("DEM steady solve, 10^6 particles", None if million is None else million["steady_seconds"],
                   LIMITS["dem_steady_1e6_seconds"], "s")
    section.target("DEM steady solve, 10^6 particles: peak memory",
                   None if million is None else million["peak_rss_mib"] / 1024.0, LIMITS["dem_steady_1e6_peak_gib"],
                   "GiB")
    ten = next((r for r in good if r["particles"] >= 10**7), None)
    section.target("DEM steady solve, 10^7 particles: peak memory (a 24 GB machine)",
                   None if ten is None else ten["peak_rss_mib"] / 1024.0, LIMITS["dem_steady_1e7_peak_gib"], "GiB")


def study_amg_peers(section, quick: bool) -> None:
    """Our AMG before and after its tuning, and PETSc's algebraic multigrids when petsc4py imports, on the steady
    network of the bench packing (:mod:`benchmarks.amg_peers`)."""
    from benchmarks.amg_peers import HYPRE

    n = 20_000 if quick else 1_000_000
    record = run_worker("benchmarks.dem", "amg_peers_worker", n, timeout=3600)
    rows = record.get("rows", [])
    section.csv("dem_amg_peers", rows or [record])
    by_name = {r["solver"]: r for r in rows}
    ours, petsc = by_name.get("amg"), [r for r in rows if r["solver"].startswith("petsc")]
    fastest = min(petsc, key=lambda r: r["seconds"]) if petsc else None
    section.summary["dem_amg_peers"] = record
    section.summary["dem_amg_seconds"] = None if ours is None else ours["seconds"]
    section.summary["dem_amg_over_previous"] = (None if ours is None else
                                                ours["seconds"] / by_name["amg_previous"]["seconds"])
    section.summary["dem_amg_over_fastest_petsc"] = None if ours is None else ours["over_fastest_petsc"]
    section.summary["dem_amg_cpu_over_fastest_petsc"] = None if ours is None else ours["cpu_over_fastest_petsc"]
    hypre = ", ".join(f"{k.removeprefix('pc_hypre_')} {v}" for k, v in HYPRE.items())
    section.add_text(
        "DEM steady network: AMG side by side" + (" (quick: 2e4 particles)" if quick else ""),
        f"The steady network of the bench packing (~{n:.0e} particles, rojek law, hot/cold fixed layers: "
        f"{record.get('unknowns', '?')} unknowns, {record.get('nonzeros', '?')} nonzeros) solved from zero to "
        "|b - A x| <= 1e-10 |b| by: `amg`, our CG + smoothed aggregation (`dem.network.linsolve.AMGSolver`); "
        "`amg_reused`, the same on the hierarchy of an earlier matrix of the network (entries changed by up to 10 %, "
        "as between refreshes; no setup); "
        "`amg_previous`, the same CG with pyamg's default smoothed aggregation as the project used it before "
        "(max_coarse 500); and, when petsc4py imports (run `python -m benchmarks dem` in an environment with "
        f"PETSc), PETSc's CG + ML, + hypre BoomerAMG ({hypre}) and + GAMG (defaults), on one rank. Setup "
        "(hierarchy; PETSc: matrix copy + KSPSetUp) and solve apart, and the total in wall and CPU seconds; three "
        "alternating rounds, best of each, in one fresh process; ratios over ours and over the fastest PETSc.\n\n"
        + records_table(rows or [record], ["solver", "setup_seconds", "solve_seconds", "seconds", "cpu_seconds",
                                           "iterations", "relative_residual", "max_difference_to_amg", "over_amg",
                                           "over_fastest_petsc", "cpu_over_amg", "cpu_over_fastest_petsc", "error"],
                          fmt="{:.3g}")
        + ("" if petsc else "\n\npetsc4py is not importable here: the PETSc rows are left out."),
    )
    section.target("DEM steady network, 10^6 particles: our AMG / PETSc's fastest AMG (one rank)",
                   None if quick or fastest is None or ours is None else ours["over_fastest_petsc"],
                   LIMITS["dem_amg_over_petsc"])


def study_openpnm(section, quick: bool) -> None:
    if not available("openpnm"):
        section.summary["openpnm_seconds"] = None
        section.add_text("Peer: OpenPNM", "OpenPNM is not installed (optional extra: `pip install .[peers]`); "
                                          "skipped.")
        section.target("DEM steady: ours / OpenPNM on the same network", None, LIMITS["dem_over_openpnm"])
        return
    # 10^6 is left out: OpenPNM's default PARDISO factorisation of the 3D network passed 14 GiB resident after
    # 8 minutes on a 2-core machine (stopped), which would starve everything else of memory.
    sizes = (1_000, 10_000) if quick else (10_000, 100_000)
    rows = worker_sweep(section, "openpnm_same_network", "benchmarks.dem", "openpnm_worker", sizes, timeout=600,
                        stop_at_error=True)
    good = [r for r in rows if "error" not in r]
    for r in good:
        r["ratio_ours_over_openpnm"] = r["ours_seconds"] / r["openpnm_seconds"]
    head = max(good, key=lambda r: r["particles"]) if good else None
    section.summary["openpnm_seconds"] = None if head is None else head["openpnm_seconds"]
    section.summary["dem_steady_same_network_seconds"] = None if head is None else head["ours_seconds"]
    section.summary["openpnm_particles"] = None if head is None else head["particles"]
    section.add_text(
        "Peer: OpenPNM on the same network",
        f"OpenPNM {package_version('openpnm')} `FourierConduction` (its default solver) on exactly our network: the "
        "particles connected to the fixed layers, our bonds as throats, our bond conductances as "
        "`throat.thermal_conductance`, the hot/cold layers as value boundary conditions; each N in a fresh "
        "subprocess. Ours = network assembly + `dem.network.heat.steady`; OpenPNM = network/phase/algorithm set-up + "
        "`run()`. The two solutions agree to `max_abs_difference` (temperatures in [0, 1]). N = 10^6 is not run: "
        "OpenPNM's default PARDISO factorisation passed 14 GiB resident after 8 minutes there.\n\n"
        + records_table(rows, ["particles", "bonds", "ours_seconds", "ours_solver", "openpnm_setup_seconds",
                               "openpnm_solve_seconds", "openpnm_seconds", "openpnm_solver", "ratio_ours_over_openpnm",
                               "max_abs_difference", "error"])
        + ("" if head is None else f"\n\nHeadline (N = {head['particles']}): ours {head['ours_seconds']:.3g} s, "
           f"OpenPNM {head['openpnm_seconds']:.3g} s, ratio {head['ratio_ours_over_openpnm']:.2f}."),
    )
    section.target("DEM steady: ours / OpenPNM on the same network",
                   ratio(section.summary["dem_steady_same_network_seconds"], section.summary["openpnm_seconds"]),
                   LIMITS["dem_over_openpnm"])


def study_transient_big(section, quick: bool) -> None:
    n = 10_000 if quick else 100_000
    row = run_worker("benchmarks.dem", "transient_worker", n, timeout=1200)
    section.csv("dem_transient_big", [row])
    seconds = row.get("integrate_seconds")
    if not quick:
        section.summary["dem_transient_1e5x1000_seconds"] = seconds
    section.summary["dem_transient_big"] = row
    section.add_text(
        "DEM transient: implicit, 10^5 particles x 1000 steps" + (" (quick: 10^4)" if quick else ""),
        "Random sintered packing with hot/cold fixed layers; backward Euler (`dem.network.heat.integrate`, linear "
        "backend auto) at dt = 10 x the cheap explicit bound 2 min C_i / sum_j K_ij, 1000 steps, in a fresh "
        "subprocess; `integrate_seconds` excludes building the bonds (`setup_seconds`).\n\n"
        + records_table([row], ["particles", "bonds", "steps", "dt", "solver", "integrate_seconds",
                                "integrate_cpu_seconds", "setup_seconds", "energy_error", "peak_rss_mib", "error"]),
    )
    section.target("DEM implicit, 10^5 particles x 1000 steps", None if quick else seconds,
                   LIMITS["dem_transient_1e5x1000_seconds"], "s")


def run(section, quick: bool) -> None:
    section.summary.update({"dem_steady_seconds": {}, "openpnm_seconds": None,
                            "dem_transient_1e5x1000_seconds": None})
    for study in (study_transient_accuracy, study_steady_scaling, study_linear_solvers, study_amg_peers,
                  study_openpnm, study_transient_big):
        study(section, quick)
