"""Transient: the lumped-capacity pipe pair against an axisymmetric FE transient of the same pair.

The pair is insulated; particle i starts at 1 K, particle j at 0 K (uniform in each particle's own share of the
solid, the neck split by cap volume: :mod:`fem_neck.transient`). The DEM's lumped model (Rojek 2022, eqs. 2-4,
``C_i dT_i/dt = K (T_j - T_i)``, ``C = rho c 4/3 pi r^3``) makes the particle-temperature difference decay as
``exp(-lambda t)``, ``lambda = K (1/C_i + 1/C_j)``. The FE gives the difference of the particle *mean*
temperatures. Two lumped curves are compared with it:

* ``K = K_FE`` -- the steady FE pair conductance between the equatorial disks (what every pipe law approximates):
  the difference to the FE transient is the error of *lumping* alone (uniform particle temperature, small Biot);
* ``K`` from the DEM's laws -- the error a DEM user actually gets (lumping plus law); ``zohdi`` is left out here,
  its lens contact area makes the pipe 75-95 % too weak for sintered necks (cluster section).

Reported per neck size: the late-time rate ratio ``lambda_1 / lambda - 1`` (``lambda_1``: the FE's slowest
non-zero mode, from the generalized eigenproblem), the largest error of the normalised difference over time and
when it occurs, and the error at fixed fractions of the lumped time constant ``tau = 1/lambda``. The pair's Biot
number is ``Bi = K_FE / (kappa r_min)``: the neck's conductance over the particle's own (``~kappa r``). Copper:
kappa = 394 W/(m K), rho = 8960 kg/m^3, c = 385 J/(kg K); the unequal pair of Rojek 2022, Sec. 6 (r_i = 1 mm,
r_j = 3 mm) over a range of necks, and equal 1 mm spheres. Times are in units of ``tau`` of the lumped model with
``K_FE``, so the results hold for any material and size (the heat equation scales with ``r^2 rho c / kappa``).
"""

from __future__ import annotations

import pathlib
import time
from dataclasses import replace

import numpy as np

from fem_neck.geometry import overlap_for_neck
from fem_neck.transient import first_decay_rate, lumped_pair, pair_mesh, solve_transient, time_grid
from verification.report import save_figure

KAPPA, RHO, CP = 394.0, 8960.0, 385.0
T_FRACTIONS = (0.001, 0.01, 0.1, 1.0, 3.0)
HOLDS = 0.01  # "the lumped model holds" while its normalised difference is within 1 % of the FE's


def cases(quick: bool) -> list[tuple[str, float, float, float]]:
    """(name, r_i, r_j, a/r of the smaller sphere)."""
    if quick:
        return [(f"unequal 1:3 a/r_i={x:g}", 1e-3, 3e-3, x) for x in (0.1, 0.42, 0.8)]
    out = [(f"unequal 1:3 a/r_i={x:g}", 1e-3, 3e-3, x) for x in (0.05, 0.1, 0.2, 0.42, 0.6, 0.8)]
    out += [(f"equal a/r={x:g}", 1e-3, 1e-3, x) for x in (0.1, 0.2, 0.4, 0.6, 0.8)]
    return out


def steady_conductance(r_i: float, r_j: float, h: float) -> float:
    """Steady FE conductance of the pair between its equatorial disks (W/K)."""
    from fem_neck import conduction

    return float(conduction.pair_conductance(r_i, r_j, h, kappa=KAPPA).K)


def dem_laws() -> tuple:
    """The DEM conductance laws to compare (``zohdi`` left out, module docstring)."""
    from verification.clusters import available_laws

    return tuple(law for law in available_laws() if law != "zohdi")


def dem_pair(r_i: float, r_j: float, h: float, law: str, t_end: float, K: float | None = None):
    """The DEM's lumped pair (particle i at 1 K, j at 0 K, insulated) integrated to ``t_end`` by its own
    Crank-Nicolson with ``dt = "auto"`` (``rtol`` 1e-5: the curve is interpolated linearly onto the FE times, so it
    needs dense points, not only accurate ones; 1e-3 gives ~26 points and 5e-3 interpolation error). ``law`` is a
    DEM conductance law; ``K`` (W/K) overrides the pipe conductance. Returns ``(K, t, T)`` with ``T`` of shape
    (len(t), 2)."""
    from dem.laws.conductance import ConductanceSpec
    from dem.geometry.particles import Material, Particles
    from dem.network.heat import build_network, integrate

    d = r_i + r_j - h
    particles = Particles.from_arrays([[0.0, 0.0, 0.0], [0.0, 0.0, d]], [r_i, r_j], [1.0, 0.0],
                                      materials=(Material(KAPPA, RHO, CP, "copper"),))
    net = build_network(particles, spec=ConductanceSpec(law=law))
    if K is not None:
        net = replace(net, K_pairs=np.array([K]))
    times, temps = [], []
    integrate(net, "crank-nicolson", dt="auto", t_end=t_end, rtol=1e-5,
              observer=lambda step, t, T, flows: (times.append(t), temps.append(T.copy())))
    return float(net.K_pairs[0]), np.array(times), np.array(temps)


def study_case(r_i, r_j, x, quick: bool, laws: tuple, refine: int = 1) -> dict:
    """FE transient and lumped curves of one pair; returns curves and metrics. ``refine`` divides the mesh size
    and the time steps (for the FE's own error check)."""
    t0 = time.perf_counter()
    a = x * min(r_i, r_j)
    h = overlap_for_neck(r_i, r_j, a)
    pm = pair_mesh(r_i, r_j, h, size_max=(0.15 if quick else 0.06) / refine, size_min=0.05 / refine)
    C = RHO * CP * 4.0 / 3.0 * np.pi * np.array([r_i**3, r_j**3])
    K_fe = steady_conductance(r_i, r_j, h)
    lam = K_fe * (1.0 / C[0] + 1.0 / C[1])
    tau = 1.0 / lam
    tau_int = RHO * CP * min(r_i, r_j) ** 2 / KAPPA  # internal diffusion time of the smaller sphere
    dt0 = 1e-4 * min(tau, tau_int)
    steps = time_grid(5.0 * tau, dt0 / refine, tau / (25.0 if quick else 60.0) / refine, (6 if quick else 8) * refine)
    res = solve_transient(pm, KAPPA, RHO, CP, 1.0, 0.0, steps)
    lam1 = first_decay_rate(pm, KAPPA, RHO, CP)
    d_fe = (res.T_mean[:, 0] - res.T_mean[:, 1]) / (res.T_mean[0, 0] - res.T_mean[0, 1])
    curves, K, dem_check = {}, {}, 0.0
    for name in ("FE steady K",) + tuple(laws):
        law, k_override = ("rojek", K_fe) if name == "FE steady K" else (name, None)
        K[name], t_dem, T_dem = dem_pair(r_i, r_j, h, law, res.t[-1], k_override)
        # the DEM run on the FE's times; its integrator against the closed form of the same lumped model
        curves[name] = np.column_stack([np.interp(res.t, t_dem, T_dem[:, k]) for k in (0, 1)])
        exact = lumped_pair(t_dem, 1.0, 0.0, *C, K[name])
        dem_check = max(dem_check, float(np.max(np.abs((T_dem[:, 0] - T_dem[:, 1]) - (exact[:, 0] - exact[:, 1])))))
    metrics = {}
    for name, T in curves.items():
        err = (T[:, 0] - T[:, 1]) - d_fe
        k = int(np.argmax(np.abs(err)))
        fails = np.abs(err) > HOLDS
        metrics[name] = {
            "K": K[name], "rate_ratio_minus_1": lam1 / (K[name] * (1 / C[0] + 1 / C[1])) - 1.0,
            "max_abs_err": float(np.abs(err[k])), "t_of_max_over_tau": float(res.t[k] / tau),
            "err_at": {f"{f:g}": float(np.interp(f * tau, res.t, err)) for f in T_FRACTIONS},
            "fails_from_to_over_tau": ([float(res.t[fails][0] / tau), float(res.t[fails][-1] / tau)]
                                       if fails.any() else None)}
    return {"r_i": r_i, "r_j": r_j, "a_over_r": x, "a": a, "h": h, "tau": tau, "tau_internal": tau_int,
            "biot": K_fe / (KAPPA * min(r_i, r_j)),
            "lambda_1": lam1, "K_needed": lam1 / (1 / C[0] + 1 / C[1]), "dofs": res.dofs, "steps": len(steps),
            "energy_drift": float(np.ptp(res.energy) / abs(res.energy[0])), "metrics": metrics,
            "dem_vs_closed_form": dem_check,
            "t_over_tau": res.t / tau, "d_fe": d_fe, "curves": {n: T[:, 0] - T[:, 1] for n, T in curves.items()},
            "seconds": time.perf_counter() - t0}


def _figures(results, out_dir: pathlib.Path) -> list:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figs = []
    unequal = [(n, r) for n, r in results if r["r_i"] != r["r_j"]]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4))
    colors = plt.cm.viridis(np.linspace(0, 0.9, len(unequal)))
    for (name, r), col in zip(unequal, colors):
        t = r["t_over_tau"][1:]
        ax1.semilogx(t, r["d_fe"][1:], color=col, label=f"FE, a/r_i={r['a_over_r']:g}")
        ax1.semilogx(t, r["curves"]["FE steady K"][1:], "--", color=col)
        ax2.semilogx(t, 100 * (r["curves"]["FE steady K"][1:] - r["d_fe"][1:]), color=col,
                     label=f"a/r_i={r['a_over_r']:g}")
    ax1.set_xlabel("t / tau")
    ax1.set_ylabel("(T_i - T_j) / initial")
    ax1.set_title("pair 1:3 mm: FE (solid) vs lumped with K_FE (dashed)")
    ax1.legend(fontsize=7)
    ax2.axhspan(-100 * HOLDS, 100 * HOLDS, color="grey", alpha=0.2, label="+-1 %")
    ax2.set_xlabel("t / tau")
    ax2.set_ylabel("lumped - FE (% of initial difference)")
    ax2.set_title("lumping error over time")
    ax2.legend(fontsize=7)
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
    fig.tight_layout()
    figs.append(save_figure(fig, out_dir / "transient_pair_curves.png"))

    fig, axes = plt.subplots(1, 2, figsize=(11, 4), sharey=True)
    for ax, fam in zip(axes, ("unequal", "equal")):
        sel = sorted((r for n, r in results if (r["r_i"] != r["r_j"]) == (fam == "unequal")),
                     key=lambda r: r["a_over_r"])
        if len(sel) < 2:
            ax.set_visible(False)
            continue
        grid = np.geomspace(1e-3, 5.0, 200)
        err = np.array([np.interp(grid, r["t_over_tau"], r["curves"]["FE steady K"] - r["d_fe"]) for r in sel])
        x = [r["a_over_r"] for r in sel]
        mesh = ax.pcolormesh(grid, x, 100 * np.abs(err), shading="nearest", cmap="magma_r", vmin=0)
        cs = ax.contour(grid, x, 100 * np.abs(err), levels=[1, 2, 5], colors="w", linewidths=1)
        ax.clabel(cs, fmt="%g %%", fontsize=7)
        ax.set_xscale("log")
        ax.set_xlabel("t / tau")
        ax.set_title(f"{fam} pair: |lumped - FE|, K = K_FE")
        fig.colorbar(mesh, ax=ax, label="% of initial difference")
    axes[0].set_ylabel("a / r (smaller sphere)")
    fig.tight_layout()
    figs.append(save_figure(fig, out_dir / "transient_error_map.png"))

    fig, ax = plt.subplots(figsize=(6, 4))
    names = list(results[0][1]["metrics"])
    for fam, marker in (("unequal", "o"), ("equal", "s")):
        sel = [r for n, r in results if (r["r_i"] != r["r_j"]) == (fam == "unequal")]
        if not sel:
            continue
        for name, ls in zip(names, ("-", "--", ":", "-.")):
            ax.plot([r["a_over_r"] for r in sel], [100 * r["metrics"][name]["rate_ratio_minus_1"] for r in sel],
                    marker=marker, ls=ls, label=f"{fam}, K: {name}")
    ax.axhline(0, color="grey", lw=0.8)
    ax.set_xlabel("a / r (smaller sphere)")
    ax.set_ylabel("lambda_1,FE / lambda_lumped - 1 (%)")
    ax.set_title("late-time decay rate: FE vs lumped")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    figs.append(save_figure(fig, out_dir / "transient_rate_error.png"))
    return figs


def run(out_dir: pathlib.Path, quick: bool = False) -> dict:
    """Run the transient study into ``out_dir``; returns the section contract of :mod:`verification.report`."""
    import json

    from tqdm import tqdm

    from verification.report import jsonable

    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    laws = dem_laws()
    results = []
    for name, r_i, r_j, x in tqdm(cases(quick), desc="transient pairs", unit="pair", leave=False):
        results.append((name, study_case(r_i, r_j, x, quick, laws)))
    # the FE's own error (full run): the paper's pair again with the mesh and all time steps halved
    name, r_i, r_j, x = next(c for c in cases(quick) if "0.42" in c[0])
    fe_check = rate_check = float("nan")
    if not quick:
        coarse = dict(results)[name]
        fine = study_case(r_i, r_j, x, quick, laws, refine=2)
        fe_check = float(np.max(np.abs(np.interp(coarse["t_over_tau"], fine["t_over_tau"], fine["d_fe"])
                                       - coarse["d_fe"])))
        rate_check = abs(fine["lambda_1"] / coarse["lambda_1"] - 1)
    (out_dir / "transient.json").write_text(json.dumps(jsonable(
        {n: {k: v for k, v in r.items() if k not in ("t_over_tau", "d_fe", "curves")} for n, r in results}),
        indent=1))
    figures = _figures(results, out_dir)
    names = list(results[0][1]["metrics"])
    head = ("| pair | a/r | Bi | tau (s) | tau_int (s) | K_FE (W/K) | K needed (W/K) | "
            + " | ".join(f"rate err, K {n}" for n in names) + " | "
            + " | ".join(f"max err (t/tau), K {n}" for n in names) + " |")
    lines = [head, "|" + "---|" * (7 + 2 * len(names))]
    summary = {"transient FE check (mesh and steps halved)": {"max_change": fe_check, "lambda_1_change": rate_check}}
    for n, r in results:
        m = r["metrics"]
        lines.append(f"| {n} | {r['a_over_r']:g} | {r['biot']:.3f} | {r['tau']:.3g} | {r['tau_internal']:.3g} | "
                     f"{m['FE steady K']['K']:.5g} | {r['K_needed']:.5g} | "
                     + " | ".join(f"{m[k]['rate_ratio_minus_1']:+.1%}" for k in names) + " | "
                     + " | ".join(f"{m[k]['max_abs_err']:.3f} ({m[k]['t_of_max_over_tau']:.2g})" for k in names)
                     + " |")
        summary[f"transient {n}"] = {f"rate_err_{k}": m[k]["rate_ratio_minus_1"] for k in names}
        summary[f"transient {n}"].update({f"max_err_{k}": m[k]["max_abs_err"] for k in names})
    err_head = "| pair | " + " | ".join(f"t = {f:g} tau" for f in T_FRACTIONS) + " | fails (> 1 %) for t/tau in |"
    err_lines = [err_head, "|---|" + "---|" * (len(T_FRACTIONS) + 1)]
    for n, r in results:
        m = r["metrics"]["FE steady K"]
        span = m["fails_from_to_over_tau"]
        err_lines.append(f"| {n} | " + " | ".join(f"{100 * m['err_at'][f'{f:g}']:+.2f} %" for f in T_FRACTIONS)
                         + " | " + (f"[{span[0]:.2g}, {span[1]:.2g}]" if span else "never") + " |")
    md = [__doc__.split("\n\n", 1)[1].strip(), "",
          f"FE: P2, implicit (backward Euler start, then Crank-Nicolson); {sum(r['steps'] for _, r in results)} "
          f"steps in all; energy drift at most {max(r['energy_drift'] for _, r in results):.1e} (relative). "
          + ("FE error check (full run only): skipped in --quick. " if quick else
             f"FE error check on {name}: halving the mesh size and every time step changes the normalised "
             f"difference by at most {fe_check:.1e} and lambda_1 by {rate_check:.1e}. ")
          + "The lumped curves are DEM runs "
          "(`dem.network.heat.integrate`, Crank-Nicolson, dt = auto, rtol 1e-5; with K = K_FE the DEM pipe is given that "
          "conductance), interpolated onto the FE times; they match the lumped closed form to "
          f"{max(r['dem_vs_closed_form'] for _, r in results):.1e} of the initial difference.",
          "'rate err' is lambda_1,FE / lambda_lumped - 1: positive means the FE pair equilibrates faster than the "
          "lumped model predicts. 'K needed' is the conductance that would make the lumped late-time rate exact. "
          "'max err' is the largest difference of the normalised particle-temperature difference (lumped - FE) "
          "over the run, in units of the initial difference, with the time where it occurs.", "",
          "\n".join(lines), "",
          "### Lumping error (K = K_FE) over time, lumped - FE, % of the initial difference", "",
          "\n".join(err_lines), "",
          f"![curves]({figures[0].name})", "", f"![error map]({figures[1].name})", "",
          f"![rate]({figures[2].name})", ""]
    return {"title": "DEM vs FE: transient pair (lumped capacity)", "markdown": "\n".join(md),
            "summary": summary, "figures": figures}
