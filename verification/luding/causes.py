"""Why ours differs from Luding 2005, Sec. 4: the runs that isolate each cause, and one contact cooled by hand.

Three mechanisms stand behind the statements that did not hold (:mod:`verification.luding.statements`):

1. *Densification and the three-particle control* -- the preparation (:data:`verification.luding.runs.VARIANTS`:
   the paper's frictionless one and its variants against the protocol's frictional one) and the walls of the
   control (contacts that sinter like pairs, or keep the cold law);
2. *Cool-down* -- the protocol's cool-down against the same with the box held and without thermal contraction
   (delta a_T = 0), and :func:`contact_cooling`: one pair contact sintered under a force and cooled with its centres
   held, by the kernels of the law against the closed form of eqs. 4, 7, 9, 10, 13 and Fig. 5;
3. *Microstructure numbers* -- the coordination number with the wall contacts counted, and of the particles
   touching no wall, beside the one of the statements; the compression test of an unsintered sample carried on
   to 15 % strain.

:func:`section` writes the tables of these runs (the grid's ``isolation`` decides which ran) and their summary.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
from scipy.optimize import brentq

from dem.laws.contact.luding import LUDING_TABLE1
from verification.luding.protocol import MEAN_RADIUS, RADIUS_SPREAD, T0_SINTER, T_PREPARE, T_SINTER
from verification.luding import runs as sr
from verification.report import md_table
from verification.luding.statements import pct
from verification.luding.study import Missing, Study, at, bulk_coordination

# ------------------------------------------------------------------------------------------------ one contact


def _k1_factor(T, material) -> float:
    """k1(T)/k1 (eq. 10)."""
    return 0.5 * (1.0 + math.tanh((material.T_melt - T) / material.T_var))


def _k2(delta_max, delta_fluid, material) -> float:
    """k2(delta_max) (eq. 7)."""
    dmf = material.k2 * delta_fluid / (material.k2 - material.k1)
    return material.k2 if delta_max >= dmf else material.k1 + (material.k2 - material.k1) * delta_max / dmf


def cooled_force(delta_0: float, delta: float, s: float, delta_fluid: float, material) -> tuple[float, float]:
    """The force of a contact whose force-free overlap ``delta_0`` was kept through a cooling to the stiffness
    factor ``s = k1(T)/k1`` (Fig. 5 right), at overlap ``delta``: delta_max from ``(1 - s k1/k2(x)) x = delta_0``
    (eqs. 4, 7), ``f = k2(delta_max) (delta - delta_0)`` unless that is below ``-kc delta`` (eq. 13), where the
    force stays on the tension branch. Returns ``(f, delta_max)`` (f = 0 for an open contact)."""
    if delta <= 0.0:
        return 0.0, 0.0
    x = brentq(lambda x: (1.0 - s * material.k1 / _k2(x, delta_fluid, material)) * x - delta_0, delta_0,
               100.0 * delta_0 + 1e-12, xtol=1e-18, rtol=1e-15)
    k2 = _k2(x, delta_fluid, material)
    kc = s * k2 / material.k2 * material.kc
    return max(k2 * (delta - delta_0), -kc * delta), x


def contact_cooling(force: float, material=LUDING_TABLE1, radius: float = 1.0e-3, t_s: float = 1.0,
                    rows: int = 600) -> dict:
    """One pair of equal disks (radius ``radius`` at T_melt, eq. 9) pressed by ``force`` at 80 °C, heated to
    140 °C and sintered for ``t_s`` with t0 = 0.1 s under that force (the overlap on the loading line f/k1(T, t)),
    then cooled to 80 °C three ways: the centres held (the overlap falls by 2 [a(140) - a(T)], eq. 9), the centres
    held without thermal expansion, and the force held (the centres follow). The kernels of the law
    (:func:`dem.cli.contact.drive_pair`) give the forces; :func:`cooled_force` predicts the centres-held ones."""
    from dem.cli.contact import drive_pair
    from dem.laws.contact.normal import luding as luding_normal
    from dem.laws.contact.state import sintering

    mat = replace(material, t0=T0_SINTER)
    delta_fluid = luding_normal.pair_delta_fluid(radius, radius, mat.fluid_overlap)
    s = [sintering.k1_factor(T_PREPARE, mat.T_melt, mat.T_var)]
    t = [0.0]
    target = sintering.k1_factor(T_SINTER, mat.T_melt, mat.T_var)
    for tk in np.linspace(t_s / rows, t_s, rows):
        s.append(sintering.relax_k1(s[-1], target, tk - t[-1], mat.t0, False))
        t.append(tk)
    s = np.array(s)
    hot_t = 1.0 + np.array(t)
    hot_T = np.r_[T_PREPARE, np.full(rows, T_SINTER)]
    hot_overlap = force / (s * mat.k1)  # on the loading line k1(T, t) delta = force (eq. 4)
    cool_T = np.linspace(T_SINTER, T_PREPARE, 61)[1:]
    cool_t = hot_t[-1] + np.arange(1, len(cool_T) + 1) * 1e-3
    shrink = 2.0 * radius * mat.expansion * (T_SINTER - cool_T)  # a(T) of eq. 9, both particles

    def drive(overlap_cool, m):
        t_all = np.r_[0.0, hot_t, cool_t]
        return drive_pair(m, radius, t_all, np.r_[0.0, hot_overlap, overlap_cool],
                          np.r_[T_PREPARE, hot_T, cool_T], damping=False)

    held = drive(hot_overlap[-1] - shrink, mat)
    k = 1 + len(hot_t) - 1  # the last hot row
    hot = {"force": float(held["force"][k]), "delta_max": float(held["delta_max"][k]),
           "delta_0": float(held["delta_0"][k]), "overlap": float(hot_overlap[-1]), "k1_factor": float(s[-1])}
    no_exp = drive(np.full(len(cool_T), hot_overlap[-1]), replace(mat, expansion=0.0))
    s_cold = _k1_factor(T_PREPARE, mat)
    cold_overlap = hot["overlap"] - shrink[-1]
    predicted, _ = cooled_force(hot["delta_0"], cold_overlap, s_cold, delta_fluid, mat)
    predicted_no_exp, _ = cooled_force(hot["delta_0"], hot["overlap"], s_cold, delta_fluid, mat)
    crossing = np.flatnonzero(held["force"][k:] < 0.0)
    return {"force": force, "hot": hot, "shrink": float(shrink[-1]), "cold_overlap": float(cold_overlap),
            "held": float(held["force"][-1]), "held_predicted": float(predicted),
            "no_expansion": float(no_exp["force"][-1]), "no_expansion_predicted": float(predicted_no_exp),
            "tension_from": float(cool_T[crossing[0] - 1]) if len(crossing) else None,
            "f_min_cold": float(held["f_min"][-1])}


# ------------------------------------------------------------------------------------------------ the tables
INTERIOR_MARGIN = 2.0 * MEAN_RADIUS * (1.0 + RADIUS_SPREAD)  # m: the largest diameter of Table 1's disks


def interior_fraction(saved: dict, margin: float = INTERIOR_MARGIN, spacing: float = 2.0e-5) -> float:
    """Solid fraction of a saved 2D state (:func:`dem.scene.state_file.load`) of the box of Fig. 1 in its interior,
    the part more than ``margin`` (m) from every wall: the share of the points of a square grid of ``spacing`` (m)
    there that lie inside a disk (the wall layer, where a wall orders or props the particles, left out)."""
    names, q = list(saved["wall_names"]), saved["wall_q"]
    lo = np.array([q[names.index("left")], q[names.index("bottom")]]) + margin  # q = n . point: -x, -z for right, top
    hi = -np.array([q[names.index("right")], q[names.index("top")]]) - margin
    if np.any(hi - lo < spacing):
        raise ValueError(f"margin = {margin!r}: leaves no interior in a box of {hi - lo + 2 * margin} m")
    xs, zs = (np.arange(a + 0.5 * spacing, b, spacing) for a, b in zip(lo, hi))
    inside = np.zeros((len(xs), len(zs)), dtype=bool)
    for (cx, cz), r in zip(saved["x"][:, [0, 2]], saved["radius"]):
        ix = slice(np.searchsorted(xs, cx - r), np.searchsorted(xs, cx + r))
        iz = slice(np.searchsorted(zs, cz - r), np.searchsorted(zs, cz + r))
        inside[ix, iz] |= (xs[ix, None] - cx) ** 2 + (zs[None, iz] - cz) ** 2 < r * r
    return float(np.mean(inside))



def _densification(st: Study, n, p, variant="", seed=1) -> tuple[float, float, float]:
    """``(rise in the first 10 ms after t_heat, nu(t_f), nu(t_f)/nu(t_heat) - 1)`` of a chain."""
    dens = st.chain_densification(n, p, seed, variant)
    cool = st.res(sr.COOL, n, p, st.t_max, seed, variant)["volume_fraction"]
    s = st.series(st.task(sr.SINTER, n, p, st.t_max, seed, variant))
    return float(at(s, 0.01)["volume_fraction"] - s["volume_fraction"][0]), cool, dens


PREP_LABELS = {"": "protocol: friction μ = 0.5 on particles and walls", "frictionless": "frictionless (the paper's "
               "text)", "frictionless-fast": "frictionless, speeds 1 m/s", "frictionless-slow": "frictionless, "
               "walls 10× slower (γ_w = 2 kg/s)", "frictionless-cohesive": "frictionless with cohesion (no "
               "brittle sliding)", "frictionless-wall-friction": "frictionless particles, walls μ_w = 0.5",
               "no-wall-friction": "particles μ = 0.5, walls frictionless", "slow": "protocol, walls 10× slower "
               "(γ_w = 2 kg/s)"}


def preparations() -> list[tuple[str, str, int]]:
    """``(variant, label, seed)`` of every preparation: the protocol's, each of :data:`PREP_LABELS`, and the
    protocol's other placements (:data:`verification.luding.runs.PREP_SEEDS`)."""
    return ([(variant, label, 1) for variant, label in PREP_LABELS.items()]
            + [("", f"protocol, placement (seed) {seed}", seed) for seed in sr.PREP_SEEDS])


def sintered_preparations(st: Study, n, p) -> list[tuple[str, sr.Task]]:
    """``(label, task)`` of the longest sintering of each preparation and placement (:func:`preparations`) that the
    grid ran for ``n`` particles at ``p``."""
    tasks = [(label, st.task(sr.SINTER, n, p, st.t_max, seed, variant)) for variant, label, seed in preparations()]
    return [(label, task) for label, task in tasks if "error" not in st.results.get(task, {"error": "not run"})]


def _run_key(n, p, variant: str, seed: int) -> str:
    return f"n{n}-p{p:g}-{variant or 'protocol'}" + (f"-seed{seed}" if seed != 1 else "")


def preparation_table(st: Study) -> tuple[str, dict]:
    """ν(t_heat) of every preparation run (the protocol's other placements, :data:`verification.luding.runs.PREP_SEEDS`,
    as rows of their own), ν half way through it (has it settled?), ν of its interior (:func:`interior_fraction`),
    and the densification of those sintered for the longest t_s and cooled."""
    rows, summary = [], {}
    for n in st.grid.n:
        for p in st.grid.p:
            for variant, label, seed in preparations():
                key = _run_key(n, p, variant, seed)
                task = st.task(sr.PREPARE, n, p, seed=seed, variant=variant)
                try:
                    nu = st.res(sr.PREPARE, n, p, seed=seed, variant=variant)["volume_fraction"]
                    half = at(st.series(task), 0.5 * task.times.t_heat)["volume_fraction"]
                    saved = st.state(task)
                except Missing:
                    continue
                try:
                    inner = interior_fraction(saved)
                except ValueError:  # a box smaller than two margins: no interior
                    inner = math.nan
                try:
                    jump, end, dens = _densification(st, n, p, variant, seed)
                    cells = [f"{jump:+.4f}", f"{end:.4f}", pct(dens)]
                    summary[key] = {"nu_heat": nu, "nu_interior": inner, "nu_f": end, "densification": dens}
                except Missing:
                    cells = ["—", "—", "—"]
                    summary[key] = {"nu_heat": nu, "nu_interior": inner}
                rows.append([n, f"{p:g}", label, f"{half:.4f}", f"{nu:.4f}",
                             "—" if math.isnan(inner) else f"{inner:.4f}"] + cells)
    if not rows:
        raise Missing("preparation runs")
    return md_table(["N", "p (N/m)", "preparation", "ν(t_heat / 2)", "ν(t_heat)",
                     f"ν(t_heat) more than {1e3 * INTERIOR_MARGIN:g} mm from every wall",
                     "ν in the first 10 ms after t_heat", f"ν(t_f), t_s = {st.t_max:g}", "densification"],
                    rows), summary


def three_table(st: Study) -> tuple[str, dict]:
    rows, summary = [], {}
    labels = {"": "protocol: walls keep the cold law, no wall friction while preparing, t_heat = 0.5 s",
              "walls-sinter": "walls sinter like pairs", "short-prep": "prepared for 0.2 s only",
              "control-wall-friction": "wall friction μ_w = 0.5 while preparing (as the large samples)",
              "no-heating": "kept at 80 °C throughout (the drift of the prepared disks)",
              "no-expansion": "δa_T = 0 (no thermal expansion, eq. 9)"}
    for p in st.grid.p:
        for variant, label in labels.items():
            got = []
            for seed in st.grid.three_seeds:
                task = st.task(sr.SCHEDULE, 3, p, st.t_max, seed, variant)
                try:
                    s = st.series(task)
                except Missing:
                    continue
                start, end = at(s, task.times.t_heat), at(s, s["t"][-1])
                changed = bool(np.any(s["coordination"][s["t"] >= task.times.t_heat] != start["coordination"]))
                got.append((end["volume_fraction"] / start["volume_fraction"] - 1.0, changed))
            if not got:
                continue
            d = [x for x, _ in got]
            rows.append([f"{p:g}", label, f"{task.times.t_heat:g}", pct(float(np.mean(d))),
                         ", ".join(pct(x) for x in d), sum(c for _, c in got)])
            summary[f"p{p:g}-{variant or 'protocol'}"] = {"mean": float(np.mean(d)), "seeds": d}
    if not rows:
        raise Missing("three-particle runs")
    return md_table(["p (N/m)", "control", "t_heat (s)", "densification (mean)", "per seed",
                     "runs whose contacts changed after t_heat"], rows), summary


def three_ts_table(st: Study) -> tuple[str, dict]:
    """The three-particle control of the first placement sintered for every t_s: the stiffness factor s = k1(T,
    t)/k1 at t_cool (eqs. 10-12), the densification at each p and their ratio, and the pair contacts' overlaps at
    t_f against the creep f/(k1 s) of their forces (eq. 4 on the loading line k1(T, t); their sums): a law whose
    creep is linear in the force densifies the same three disks p_max/p_min times more at p_max."""
    rows, summary = [], {}
    lo, hi = min(st.grid.p), max(st.grid.p)
    for t_s in st.grid.t_s:
        got = {}
        for p in (lo, hi):
            task = st.task(sr.SCHEDULE, 3, p, t_s)
            try:
                s, a = st.series(task), st.arrays(task)
            except Missing:
                continue
            factor = float(at(s, task.times.t_cool)["k1_factor"])
            x, r, i, j = a["snap0_x"], a["snap0_radius"], a["snap0_i"], a["snap0_j"]
            overlap = float(np.sum(r[i] + r[j] - np.linalg.norm(x[i] - x[j], axis=1)))
            creep = float(np.sum(a["snap0_fn"]) / (LUDING_TABLE1.k1 * factor))
            got[p] = {"k1_factor": factor, "densification": st.three(p, seeds=(1,), t_s=t_s)[0],
                      "overlap": overlap, "creep": creep}
        if len(got) < 2:
            continue
        d_lo, d_hi = got[lo]["densification"], got[hi]["densification"]
        rows.append([f"{t_s:g}", f"{got[lo]['k1_factor']:.4f}", pct(d_lo), pct(d_hi), f"{d_hi / d_lo:.1f}",
                     f"{1e6 * got[lo]['overlap']:.2f}", f"{1e6 * got[lo]['creep']:.2f}"])
        summary[f"ts{t_s:g}"] = got
    if not rows:
        raise Missing("three-particle runs for every t_s")
    return md_table(["t_s (s)", "s = k1(T, t)/k1 at t_cool", f"densification p = {lo:g}", f"p = {hi:g}", "ratio",
                     f"Σ pair overlaps at t_f, p = {lo:g} (µm)", "Σ f/(k1 s) (µm)"], rows), summary


COOL_LABELS = {"": "protocol: walls follow p, δa_T = 1e-4 /K", "cool-no-expansion": "walls follow p, δa_T = 0",
               "held": "walls held, δa_T = 1e-4 /K", "held-no-expansion": "walls held, δa_T = 0",
               "cool-expansion-x3": "walls follow p, δa_T = 3e-4 /K while cooling",
               "cool-expansion-x5": "walls follow p, δa_T = 5e-4 /K while cooling",
               "expansion-text": "walls follow p, δa_T = 2.5e-4 /K through the whole protocol (Sec. 3.2's text)"}


def box_area(row: dict) -> float:
    """Area (m^2) of the box of Fig. 1 in one row of a time series (the right and top walls' offsets are -x, -z)."""
    return (row["q_right"] + row["q_left"]) * (row["q_top"] + row["q_bottom"])


def cool_down(s: dict, t_cool: float) -> dict:
    """The cool-down of a time series ``s`` from ``t_cool`` to its last row: the solid fraction at the current radii
    at both ends, the relative change of the box's area and of the particles' area (the solid fraction times the
    box), and the least and largest stress on the top wall in between (N/m). The material density M/(rho_p V)
    changes as the inverse of the box."""
    start, end = at(s, t_cool), at(s, s["t"][-1])
    box = box_area(end) / box_area(start)
    during = s["t"] > start["t"]  # a stage's first row is its saved state's, with no wall load yet
    return {"nu_cool": float(start["volume_fraction"]), "nu_f": float(end["volume_fraction"]), "box": box - 1.0,
            "particles": box * end["volume_fraction"] / start["volume_fraction"] - 1.0,
            "top_min": float(np.min(s["wall_top"][during])), "top_max": float(np.max(s["wall_top"][during]))}


def cooling_density_table(st: Study) -> tuple[str, dict]:
    """The density through the cool-down (t_cool to t_f) of the longest-sintered sample cooled four ways from one
    state and with the expansion of Sec. 3.2's text (:data:`COOL_LABELS`), and of the paper's control without
    thermal expansion through the whole schedule: does the box follow the particles' contraction (eq. 9)?"""
    rows, summary = [], {}
    runs = [(label, st.task(sr.COOL, st.n_max, p, st.t_max, variant=variant), 0.0)
            for p in st.grid.p for variant, label in COOL_LABELS.items()]
    controls = [st.task(sr.SCHEDULE, n, p, st.t_max, variant="no-expansion") for n in st.grid.n for p in st.grid.p]
    runs += [("δa_T = 0 from the start (the paper's control), walls follow p", task, task.times.t_cool)
             for task in controls]
    for label, task, t_cool in runs:
        n, p, variant = task.n, task.p, task.variant
        try:
            r = st.res(task.kind, n, p, st.t_max, variant=variant)
            c = cool_down(st.series(task), t_cool)
        except Missing:
            continue
        m_f = r["mass_fraction"]
        m_cool = m_f * (1.0 + c["box"])
        rows.append([n, f"{p:g}", label, f"{c['nu_cool']:.4f} → {c['nu_f']:.4f}", f"{m_cool:.4f} → {m_f:.4f}",
                     f"{100 * c['box']:+.3f} %", f"{100 * c['particles']:+.3f} %",
                     f"{c['top_min']:.0f}-{c['top_max']:.0f}", f"{r['wall_stress']['top']:.0f}"])
        summary[f"n{n}-p{p:g}-{variant or 'protocol'}"] = {**c, "mass_cool": m_cool, "mass_f": m_f}
    if not rows:
        raise Missing("cool-down runs")
    return md_table(["N", "p (N/m)", "cool-down", "ν at the current radii, t_cool → t_f", "ν = M/(ρ_p V)",
                     "box area", "particles' area", "σ_zz top while cooling (N/m)", "σ_zz top at t_f"], rows), summary


def cooling_table(st: Study) -> tuple[str, dict]:
    rows, summary = [], {}
    for p in st.grid.p:
        for variant, label in COOL_LABELS.items():
            task = st.task(sr.COOL, st.n_max, p, st.t_max, variant=variant)
            try:
                fn, hot = st.arrays(task)["fn"], st.arrays(task.parent)["fn"]
            except Missing:
                continue
            q1, q99 = np.percentile(fn, [1, 99])
            rows.append([f"{p:g}", label, f"{q1:.3g}", f"{q99:.3g}", f"{-q1 / q99:.2f}",
                         f"{100 * np.mean(fn < 0):.0f} %", f"{np.std(fn):.3g}", f"{np.std(hot):.3g}"])
            summary[f"p{p:g}-{variant or 'protocol'}"] = {"q1": float(q1), "q99": float(q99),
                                                          "attractive": float(np.mean(fn < 0))}
    if len(rows) <= len(st.grid.p):
        raise Missing("cool-down variants")
    return md_table(["p (N/m)", "cool-down", "1 % quantile of f_n (N)", "99 % quantile (N)",
                     "ratio", "attractive", "std cold (N)", "std hot (N)"], rows), summary


def contact_table() -> tuple[str, dict]:
    rows, summary = [], {}
    for p in (10.0, 100.0):
        force = 2.0 * 1.0e-3 * p  # the paper's mean contact force f ~ 2 a p (Sec. 4)
        c = contact_cooling(force)
        rows.append([f"{p:g}", f"{force:g}", f"{1e6 * c['hot']['overlap']:.2f}", f"{1e6 * c['hot']['delta_0']:.2f}",
                     f"{1e6 * c['shrink']:.2f}", f"{c['held']:.4g}", f"{c['held_predicted']:.4g}",
                     "—" if c["tension_from"] is None else f"{c['tension_from']:.0f}",
                     f"{c['no_expansion']:.4g}", f"{c['no_expansion_predicted']:.4g}", f"{force:g}"])
        summary[f"p{p:g}"] = c
    return md_table(["p (N/m)", "f0 = 2 a p (N)", "δ hot (µm)", "δ0 hot (µm)", "shrink 2Δa (µm)",
                     "f cold, centres held (N)", "predicted (N)", "tension from (°C)",
                     "f cold, held, δa_T = 0 (N)", "predicted (N)", "f cold, force held (N)"], rows), summary


def coordination_table(st: Study) -> tuple[str, dict]:
    """C after the longest sintering of every preparation and placement the grid sintered (:func:`_preparations`):
    pair contacts only, with the wall contacts, and of the particles touching no wall."""
    rows, summary = [], {}
    for n in st.grid.n:
        for p in st.grid.p:
            paper = 4.0 if p == 10.0 else {100: 4.5, 300: 4.8}.get(n)
            for label, task in sintered_preparations(st, n, p):
                a = st.arrays(task)
                s = json.loads((st.root / task.folder / "summary.json").read_text())
                c, cw = 2.0 * s["contacts"] / n, (2.0 * s["contacts"] + s["wall_contacts"]) / n
                bulk, inside = bulk_coordination(a)
                rows.append([n, f"{p:g}", "—" if paper is None else f"{paper:g}", label, f"{c:.2f}",
                             s["wall_contacts"], f"{cw:.2f}", f"{bulk:.2f} ({inside})"])
                summary[_run_key(n, p, task.variant, task.seed)] = {"pairs_only": c, "with_walls": cw, "bulk": bulk}
    if not rows:
        raise Missing("sintered runs")
    return md_table(["N", "p (N/m)", "paper", "preparation", "C = 2 M/N (pairs)", "wall contacts M_w",
                     "(2 M + M_w)/N", "C of the particles touching no wall (how many)"], rows), summary


def failure_table(st: Study) -> tuple[str, dict]:
    """The shortest-sintered sample at p = 100 compressed to 6 % (the test) and to 15 %: σ_zz in strain windows and
    the failure (:func:`verification.luding.study.failure`) of each."""
    n, t_s = st.n_max, st.t_min
    rows, summary = [], {}
    windows = ((0.0, 0.02), (0.02, 0.06), (0.06, 0.15))
    for variant, label in (("", "the test, to 6 %"), ("long", "to 15 %")):
        c = st.compression(n, 100.0, t_s, variant)
        eps, szz = c["eps"], c["szz"]
        cells = []
        for lo, hi in windows:
            inside = (eps > lo) & (eps <= hi + 1e-9)
            cells.append(f"{np.min(szz[inside]):.0f}-{np.max(szz[inside]):.0f}" if np.any(inside) else "—")
        rows.append([label] + cells + [f"{c['failure_strain']:.4f}", f"{c['failure_stress']:.0f}"])
        summary[variant or "test"] = {"failure_strain": c["failure_strain"], "failure_stress": c["failure_stress"]}
    return md_table(["compression (N = %d, p = 100, t_s = %g)" % (n, t_s), "σ_zz for ε ≤ 0.02 (N/m)",
                     "0.02 < ε ≤ 0.06", "0.06 < ε ≤ 0.15", "ε_f", "σ_f (N/m)"], rows), summary


def placement_failure_table(st: Study) -> tuple[str, dict]:
    """The failure strain and stress of every placement :data:`verification.luding.runs.PLACEMENTS` (each prepared, sintered
    for t_s, cooled and compressed), for every N, p and t_s of the grid, and their mean (what the statements read)."""
    rows, summary = [], {}
    for n in st.grid.n:
        for p in st.grid.p:
            for t_s in st.grid.t_s:
                eps, sig = (st.placement_failures(n, p, t_s, key) for key in ("failure_strain", "failure_stress"))
                rows.append([str(n), f"{p:g}", f"{t_s:g}", ", ".join(f"{x:.4f}" for x in eps), f"{np.mean(eps):.4f}",
                             ", ".join(f"{x:.0f}" for x in sig), f"{np.mean(sig):.0f}"])
                summary[f"n{n}-p{p:g}-ts{t_s:g}"] = {"failure_strain": eps, "failure_stress": sig}
    return md_table(["N", "p (N/m)", "t_s (s)", "ε_f per placement", "ε_f mean", "σ_f per placement (N/m)",
                     "σ_f mean (N/m)"], rows), summary


# ------------------------------------------------------------------------------------------------ the section
def _part(build, st=None) -> tuple[str, dict]:
    try:
        return build(st) if st is not None else build()
    except Missing as exc:
        return f"*not run in this grid ({exc})*", {}


def section(st: Study) -> tuple[str, dict]:
    """The subsection of the isolating runs: a table per mechanism with what it shows; the summary entries."""
    prep, prep_s = _part(preparation_table, st)
    three, three_s = _part(three_table, st)
    three_ts, three_ts_s = _part(three_ts_table, st)
    cool_nu, cool_nu_s = _part(cooling_density_table, st)
    cool, cool_s = _part(cooling_table, st)
    contact, contact_s = _part(contact_table)
    coord, coord_s = _part(coordination_table, st)
    fail, fail_s = _part(failure_table, st)
    placed, placed_s = _part(placement_failure_table, st)
    md = [
        "**1. Preparation and densification.** Each preparation runs to t_heat = 0.2 s at 80 °C; the protocol's "
        "and the frictionless one then sinter for the longest t_s and cool down. ν half way through the "
        "preparation against ν(t_heat): has the packing settled? ν of the interior, more than the largest diameter "
        f"({1e3 * INTERIOR_MARGIN:g} mm) from every wall: is a loose sample loose inside or at its walls? ν in the "
        "first 10 ms after t_heat is the immediate effect of switching the wall friction off (and the particle "
        "friction on).",
        "", prep, "",
        "**Three-particle control (Sec. 4.1.3).** Three disks through the whole schedule; the wall contacts either "
        "keep the cold law of the wall material (k1(T, t) = k1: no softening, no creep) or soften with the particle's "
        "k1(T, t) like the pair contacts. A run whose contacts changed after t_heat rearranged: it is no control. "
        "Kept at 80 °C, the prepared disks do not move (their drift is the baseline); without thermal expansion the "
        "densification is the same, since t_heat and t_f are both at 80 °C and the radii of eq. 9 return.",
        "", three, "",
        "*The control against t_s* (first placement): the densification is the pair contacts' creep under the "
        "wall's load, the overlap growing to f/(k1 s) on the loading line of eq. 4 as k1(T, t) = s k1 relaxes "
        "(eqs. 10-12); the wall contacts keep the cold law and the elastic overlap f/k2 stays below a micrometre.",
        "", three_ts, "",
        "**2. Cool-down.** The longest-sintered sample cooled from 140 to 80 °C six ways from the same state "
        f"(N = {st.n_max}: the walls following p or held, Table 1's δa_T, none, and three and five times Table 1's "
        "while cooling, the reference radii of eq. 9 set so that each particle keeps its size at t_cool), the same sample prepared, sintered and cooled with the expansion Sec. 3.2's text "
        "describes (\"one per-cent\" between 80 and 120 °C: δa_T = 2.5e-4 /K, against Table 1's 1e-4 /K), and the "
        "paper's control run with δa_T = 0 through the whole schedule. The density at both ends of the cool-down "
        "counted two ways, the box's and the particles' change of area over it, and the stress on the top wall while "
        "cooling: where the box shrinks with the particles, the solid fraction at the "
        "current radii stays and the material density M/(ρ_p V) rises by the particles' contraction (eq. 9: 2 δa_T "
        "60 K = 1.2 % of the area).",
        "", cool_nu, "",
        "The normal forces at t_f of these cool-downs (std hot: at t_cool, before each). Ratio: minus the 1 % "
        "quantile of the normal force over its 99 % quantile (the paper: almost equally strong, ratio ≈ 1).",
        "", cool, "",
        "*One contact, by hand.* A pair of disks of radius 1 mm (at T_melt) pressed by the paper's mean contact "
        "force f0 = 2 a p at 80 °C, sintered at 140 °C for 1 s (t0 = 0.1 s) under that force, then cooled to 80 °C "
        "with its centres held (the overlap falls by 2 [a(140) − a(80)] = 2 a δa_T 60 K, eq. 9), with them held and "
        "δa_T = 0, and with the force held. The kernels of the law against the closed form: δ0 kept (Fig. 5 right), "
        "δmax from (1 − k1(T)/k2(δmax)) δmax = δ0 with eqs. 7 and 10, f = k2(δmax)(δ − δ0) bounded by −kc δ "
        "(eq. 13); 0 where the overlap is gone.",
        "", contact, "",
        "**3. Coordination number.** C counts the pair contacts per particle (every particle, no wall contacts), after "
        "the longest sintering of every preparation and placement sintered; beside it the count with each wall "
        "contact added once, and C of the particles that touch no wall. Does another preparation or placement "
        "reach the paper's C?",
        "", coord, "",
        f"*Failure against the placement.* Each of the {len(sr.PLACEMENTS)} random placements of every N and p "
        "prepared, sintered for each t_s, cooled and compressed (ε̇_zz = 1/s): the failure strain and stress of "
        "each and their mean, which the statements read. Where the placements' ε_f at one t_s differ by more than "
        "the mean changes from one t_s to the next, one sample cannot order ε_f with t_s.",
        "", placed, "",
        "*Failure strain.* The shortest-sintered sample at p = 100 in the compression test (ε̇_zz = 1/s) and in the "
        "same test carried on to 15 %: σ_zz in three windows of strain, and the failure as the statements define it "
        "(the largest σ_zz before it first falls below half of it).",
        "", fail,
    ]
    return "\n".join(md), {"preparation": prep_s, "three_particles": three_s, "three_particles_ts": three_ts_s,
                           "cooling_density": cool_nu_s,
                           "cooling": cool_s, "contact": contact_s, "coordination": coord_s, "failure": fail_s,
                           "failure_placements": placed_s}
