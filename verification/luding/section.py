"""Luding, Manetsberger & Müllers 2005, Section 4, reproduced with the engine for moving particles.

The samples of Sec. 4 (Table 1, the bi-axial box of Fig. 1, the schedule of Fig. 7; :mod:`verification.luding.protocol`)
are prepared, sintered for t_s, cooled and tested over the grid of :mod:`verification.luding.runs` (N = 100 and
300, p = 10 and 100 N/m, t_s from 1e-4 to 1 s; ``--quick``: N = 100 and three t_s), in parallel and resumed where a
previous run stopped. The section draws the paper's figures from the runs -- nu(t), k1(t), the coordination number
and the wall stress (Figs. 8-11), the overlap and normal-force distributions after sintering and after cool-down
(Figs. 12-15), density and stress against strain in the compression test (Figs. 16-19), snapshots of the
compression and vibration tests (Figs. 20-22) -- runs the three-particle control of Sec. 4.1.3, the same protocol
in 3D with heated walls (necks, density and effective conductivity together), and writes every quantitative
statement of Section 4 beside our number (:mod:`verification.luding.statements`; summary key ``statements``:
``statement``, ``paper``, ``ours``, ``holds``). Its prose -- the protocol, the conclusions and the notes beside the
numbers -- is the template ``prose.md`` beside this module, whose named fields the functions here fill.
"""

from __future__ import annotations

import math
import pathlib
import re
from dataclasses import asdict

import numpy as np

from dem.laws.contact.luding import LUDING_TABLE1
from verification.luding.protocol import Times
from verification.luding import runs as sr
from verification.report import md_table, save_figure
from verification.luding.causes import (INTERIOR_MARGIN, box_area, contact_cooling, cool_down, interior_fraction,
                                           section as causes_section, sintered_preparations)
from verification.luding.statements import pct, statements, statements_table
from verification.luding.study import Missing, Study, at, bulk_coordination, read_csv

TITLE = "Sintering mechanics: Luding, Manetsberger & Müllers 2005, Section 4"
DPI = 110


def prose_blocks(path: pathlib.Path) -> dict:
    """The blocks of a prose template by name: each follows its line ``<!-- name -->`` and ends before the next one
    (its trailing newlines dropped); their ``{field}`` are filled by ``str.format``.

    Parameters
    ----------
    path : pathlib.Path
        The template (Markdown).
    """
    parts = re.split(r"^<!-- (\S+) -->\n", path.read_text(encoding="utf-8"), flags=re.M)
    return {name: body.rstrip("\n") for name, body in zip(parts[1::2], parts[2::2])}


PROSE = prose_blocks(pathlib.Path(__file__).with_name("prose.md"))  # the section's prose (prose.md)


# ------------------------------------------------------------------------------------------------ figures
def _colours(values):
    import matplotlib

    cmap = matplotlib.colormaps["viridis"]
    return [cmap(x) for x in np.linspace(0.0, 0.9, len(values))]


def _figure(rows, cols, width=5.0, height=3.0, **kw):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width * cols, height * rows), layout="constrained")
    axes = fig.subplots(rows, cols, squeeze=False, **kw)
    return fig, axes


def fig_schedule(st: Study, out: pathlib.Path) -> list[pathlib.Path]:
    """Figs. 8 and 9: temperature, k1(T, t) and density against time for every t_s."""
    n = st.n_max
    fig, ax = _figure(4, 1, width=7.0, height=2.3, sharex=True)
    for t_s, c in zip(st.grid.t_s, _colours(st.grid.t_s)):
        try:
            h100, h10 = st.history(n, 100.0, t_s), st.history(n, 10.0, t_s)
        except Missing:
            continue
        ax[0, 0].plot(h100["t"], h100["T_mean"], color=c, label=f"t_s = {t_s:g} s")
        ax[1, 0].plot(h100["t"], h100["k1_factor"], color=c)
        ax[2, 0].plot(h100["t"], h100["mass_fraction"], color=c)
        ax[3, 0].plot(h10["t"], h10["mass_fraction"], color=c)
    ax[0, 0].set_ylabel("T (°C)")
    ax[1, 0].set_ylabel("k1(T, t) / k1")
    ax[1, 0].set_yscale("log")
    ax[2, 0].set_ylabel("ν = M/(ρ_p V) (p = 100)")
    ax[3, 0].set_ylabel("ν = M/(ρ_p V) (p = 10)")
    ax[2, 0].set_ylim(0.78, 0.95)  # the loose start (0.3) is off the scale, as in the paper
    ax[3, 0].set_ylim(0.78, 0.86)
    ax[2, 0].axhline(0.92, color="k", ls=":", lw=0.8)
    ax[2, 0].axhline(0.94, color="k", ls="--", lw=0.8)
    ax[3, 0].set_xlabel("t (s)")
    ax[0, 0].legend(fontsize=6, ncol=4)
    fig.suptitle(f"Figs. 8-9: N = {n}; dotted 0.92 and dashed 0.94 are the paper's densities after sintering and "
                 "cool-down", fontsize=8)
    return [save_figure(fig, out / "fig08_09_schedule.png", dpi=DPI)]


def fig_coordination(st: Study, out: pathlib.Path) -> list[pathlib.Path]:
    """Figs. 10 and 11: coordination number against time (t_s max), and nu, C/5, sigma_zz/p while sintering."""
    fig, ax = _figure(1 + len(st.grid.p), 1, width=7.0, height=2.4)
    times = Times(t_s=st.t_max)
    for n in st.grid.n:
        for p in st.grid.p:
            try:
                h = st.history(n, p, st.t_max)
            except Missing:
                continue
            ax[0, 0].plot(h["t"], h["coordination"], label=f"N = {n}, p = {p:g}")
    for ref in (4.0, 4.5, 4.8):
        ax[0, 0].axhline(ref, color="k", ls=":", lw=0.7)
    ax[0, 0].set_ylim(2.5, 5.5)
    ax[0, 0].set_ylabel("C")
    ax[0, 0].set_xlabel("t (s)")
    ax[0, 0].legend(fontsize=7, ncol=2)
    ax[0, 0].set_title(f"Fig. 10: coordination number, t_s = {st.t_max:g} s (dotted: the paper's 4, 4.5, 4.8)",
                       fontsize=8)
    for k, p in enumerate(st.grid.p, start=1):
        try:
            h = st.history(st.n_max, p, st.t_max)
        except Missing:
            continue
        keep = (h["t"] >= times.t_sinter) & (h["t"] <= times.t_cool)
        a = ax[k, 0]
        a.plot(h["t"][keep], h["volume_fraction"][keep], "s", ms=2, label="ν")
        a.plot(h["t"][keep], h["coordination"][keep] / 5.0, "o", ms=2, label="C / 5")
        a.plot(h["t"][keep], h["wall_top"][keep] / p, "-", lw=0.6, label="σ_zz / p")
        a.set_ylim(0.6, 1.2)
        a.legend(fontsize=7, ncol=3)
        a.set_title(f"Fig. 11: N = {st.n_max}, p = {p:g}, while sintering", fontsize=8)
        a.set_xlabel("t (s)")
    return [save_figure(fig, out / "fig10_11_coordination.png", dpi=DPI)]


def fig_density_ts(st: Study, out: pathlib.Path) -> list[pathlib.Path]:
    """Density after sintering and after cool-down against t_s, every (N, p)."""
    fig, ax = _figure(1, 2, width=5.0, height=3.4)
    for n in st.grid.n:
        for p, m in zip(st.grid.p, ("o", "s")):
            try:
                a = [st.res(sr.SINTER, n, p, t)["mass_fraction"] for t in st.grid.t_s]
                b = [st.res(sr.COOL, n, p, t)["mass_fraction"] for t in st.grid.t_s]
            except Missing:
                continue
            ls = "-" if n == st.n_max else "--"
            ax[0, 0].semilogx(st.grid.t_s, a, m + ls, ms=4, label=f"N = {n}, p = {p:g}")
            ax[0, 1].semilogx(st.grid.t_s, b, m + ls, ms=4, label=f"N = {n}, p = {p:g}")
    ax[0, 0].axhline(0.92, color="k", ls=":", lw=0.8)
    ax[0, 1].axhline(0.94, color="k", ls=":", lw=0.8)
    ax[0, 0].set_title("ν after sintering (t_cool); dotted: paper 0.92", fontsize=8)
    ax[0, 1].set_title("ν after cool-down (t_f); dotted: paper 0.94", fontsize=8)
    for a in ax[0]:
        a.set_xlabel("t_s (s)")
        a.set_ylabel("ν = M/(ρ_p V)")
        a.legend(fontsize=7)
    return [save_figure(fig, out / "density_vs_ts.png", dpi=DPI)]


def fig_distributions(st: Study, out: pathlib.Path) -> list[pathlib.Path]:
    """Figs. 12-15: overlap and normal-force distributions after sintering and after cool-down (N max)."""
    paths = []
    for key, label, name, figs in (("overlap_rel", "δ / (a1 + a2)", "fig12_13_overlap_pdf.png", "Figs. 12-13"),
                                   ("fn", "f_n (N)", "fig14_15_force_pdf.png", "Figs. 14-15")):
        fig, ax = _figure(2, len(st.grid.p), width=4.5, height=3.0)
        for col, p in enumerate(st.grid.p):
            for row, kind in enumerate((sr.SINTER, sr.COOL)):
                a = ax[row, col]
                for t_s, c in zip(st.grid.t_s, _colours(st.grid.t_s)):
                    try:
                        v = st.contacts(kind, st.n_max, p, t_s)[key]
                    except Missing:
                        continue
                    hist, edges = np.histogram(v, bins=30, density=True)
                    a.semilogy(0.5 * (edges[1:] + edges[:-1]), np.where(hist > 0, hist, np.nan), "o-", ms=2,
                               color=c, label=f"t_s = {t_s:g}")
                a.set_title(f"p = {p:g}, {'after sintering' if kind == sr.SINTER else 'after cool-down'}",
                            fontsize=8)
                a.set_xlabel(label)
                a.set_ylabel("pdf")
        ax[0, 0].legend(fontsize=6)
        fig.suptitle(f"{figs}: N = {st.n_max}", fontsize=8)
        paths.append(save_figure(fig, out / name, dpi=DPI))
    return paths


def fig_compression(st: Study, out: pathlib.Path) -> list[pathlib.Path]:
    """Figs. 16-19: density and vertical stress against the vertical strain."""
    fig, ax = _figure(len(st.grid.n) * len(st.grid.p), 2, width=4.8, height=2.6)
    row = 0
    for n in st.grid.n:
        for p in st.grid.p:
            for t_s, c in zip(st.grid.t_s, _colours(st.grid.t_s)):
                try:
                    r = st.compression(n, p, t_s)
                except Missing:
                    continue
                ax[row, 0].plot(r["eps"], r["nu"], color=c, lw=0.8, label=f"t_s = {t_s:g}")
                ax[row, 1].plot(r["eps"], r["szz"], color=c, lw=0.8)
                ax[row, 1].plot([r["failure_strain"]], [r["failure_stress"]], "x", color=c)
            ax[row, 0].set_ylabel(f"ν (N={n}, p={p:g})")
            ax[row, 1].set_ylabel("σ_zz (N/m)")
            row += 1
    for a in ax[-1]:
        a.set_xlabel("ε_zz = 1 − z/z0")
    ax[0, 0].legend(fontsize=6, ncol=2)
    fig.suptitle("Figs. 16-19: compression test (σ_xx = p held, the top wall at dε/dt = 1/s); x: failure",
                 fontsize=8)
    return [save_figure(fig, out / "fig16_19_compression.png", dpi=DPI)]


def wall_segments(snap: dict) -> list:
    """The walls of a 2D snapshot as ``((x0, z0), (x1, z1))`` lines (axis-aligned walls only)."""
    x, r = snap["x"], snap["radius"]
    lo, hi = x.min(axis=0) - r.max(), x.max(axis=0) + r.max()
    where = {0: [], 2: []}
    for normal, q in zip(snap["wall_normal"], snap["wall_q"]):
        a = int(np.argmax(np.abs(normal)))
        if a in where:
            where[a].append(q if normal[a] > 0 else -q)
    span = {a: (min(v), max(v)) if len(v) == 2 else (lo[a], hi[a]) for a, v in where.items()}
    out = []
    for a, other in ((0, 2), (2, 0)):
        for c in where[a]:
            ends = [[c, span[other][0]], [c, span[other][1]]] if a == 0 else [[span[other][0], c], [span[other][1], c]]
            out.append(tuple(tuple(e) for e in ends))
    return out


def _draw(ax, a: dict, k: int, title: str, stress_range=None):
    from verification.luding.picture import draw_packing

    snap = {key[len(f"snap{k}_"):]: v for key, v in a.items() if key.startswith(f"snap{k}_")}
    draw_packing(ax, snap["x"], snap["radius"], snap["mean_stress"], snap["i"], snap["j"], snap["fn"], snap["ft"],
                 wall_segments(snap), stress_range, title)


def fig_snapshots(st: Study, out: pathlib.Path) -> list[pathlib.Path]:
    """Figs. 20-22: compression snapshots and the samples after the vibration test."""
    paths = []
    n, p = st.n_max, min(st.grid.p)
    try:
        a = st.arrays(st.task(sr.COMPRESS, n, p, st.t_max))
        fig, ax = _figure(1, len(sr.FIG20_TIMES), width=3.2, height=3.4)
        for k, t in enumerate(sr.FIG20_TIMES):
            _draw(ax[0, k], a, k, f"t = {t:g} s (ε_zz = {t * sr.COMPRESSION_RATE:g})")
        fig.suptitle(f"Fig. 20: compression test, N = {n}, p = {p:g}, t_s = {st.t_max:g} (circles: mean stress blue "
                     "low to red high; lines: attractive blue, repulsive red; dots: tangential force)", fontsize=8)
        paths.append(save_figure(fig, out / "fig20_compression_snapshots.png", dpi=DPI))
    except Missing:
        pass
    fig, ax = _figure(len(st.grid.p), 3, width=3.6, height=3.0)
    for row, (p, mid) in enumerate(zip(st.grid.p, (0.02, 0.01))):
        mid = min(st.grid.t_s, key=lambda t: abs(math.log(t / mid)))
        for col, t_s in enumerate((st.t_min, mid, st.t_max)):
            try:
                a = st.arrays(st.task(sr.VIBRATE, n, p, t_s))
                r = st.res(sr.VIBRATE, n, p, t_s)
            except Missing:
                ax[row, col].set_axis_off()
                continue
            last = r["snapshots"] - 1
            _draw(ax[row, col], a, last, f"p = {p:g}, t_s = {t_s:g}: {r['fragments']} fragments, largest "
                                         f"{r['largest_fragment']}")
    fig.suptitle(f"Figs. 21-22: after the vibration test (100 Hz, 0.2 mm, 0.1 s, gravity), N = {n}", fontsize=8)
    paths.append(save_figure(fig, out / "fig21_22_vibration.png", dpi=DPI))
    return paths


def fig_3d(st: Study, out: pathlib.Path) -> list[pathlib.Path]:
    """3D beyond the paper: nu, coordination, temperatures and k_eff against time while sintering between heated
    walls, and the solid fraction and neck radius against the distance from the hot wall at the start and the end."""
    n = st.grid.n3d
    task = st.task(sr.SINTER3D, n, sr.P3D)
    s = st.series(task)
    fig, ax = _figure(4, 2, width=4.8, height=1.9)
    for a, key, label in zip(ax[:, 0], ("volume_fraction", "coordination", "T_mean", "effective_conductivity"),
                             ("ν", "C", "T (°C)", "k_eff (W/(m K))")):
        a.plot(s["t"], s[key])
        if key == "T_mean":
            a.fill_between(s["t"], s["T_min"], s["T_max"], alpha=0.3)
        a.set_ylabel(label, fontsize=8)
    ax[-1, 0].set_xlabel("t (s) from the start of heating")
    prof = read_csv(st.root / task.folder / "profiles.csv")
    for time, style in ((min(prof["t"]), "o--"), (max(prof["t"]), "o-")):
        rows = [k for k, tt in enumerate(prof["t"]) if tt == time]
        d = [1e3 * prof["distance"][k] for k in rows]
        ax[0, 1].plot(d, [prof["solid_fraction"][k] for k in rows], style, ms=3, label=f"t = {time:.3g} s")
        ax[1, 1].plot(d, [prof["neck_over_radius"][k] for k in rows], style, ms=3)
    ax[0, 1].set_ylabel("solid fraction", fontsize=8)
    ax[1, 1].set_ylabel("neck a/r (mean)", fontsize=8)
    ax[1, 1].set_xlabel("distance from the hot wall (mm)")
    ax[0, 1].legend(fontsize=7)
    for a in ax[2:, 1]:
        a.set_axis_off()
    fig.suptitle(f"3D, {n} spheres: bottom wall {sr.HOT3D[0]:g} °C, top wall {sr.HOT3D[1]:g} °C", fontsize=8)
    return [save_figure(fig, out / "sinter3d.png", dpi=DPI)]


# ------------------------------------------------------------------------------------------------ tables
def _grid_table(st: Study) -> str:
    rows = []
    for n in st.grid.n:
        for p in st.grid.p:
            for t_s in st.grid.t_s:
                try:
                    a, b = st.res(sr.SINTER, n, p, t_s), st.res(sr.COOL, n, p, t_s)
                    c, v = st.compression(n, p, t_s), st.res(sr.VIBRATE, n, p, t_s)
                    prep = st.res(sr.PREPARE, n, p)
                except Missing:
                    continue
                rows.append([n, f"{p:g}", f"{t_s:g}", f"{prep['mass_fraction']:.4f}", f"{a['mass_fraction']:.4f}",
                             f"{b['mass_fraction']:.4f}", pct(b['mass_fraction'] / prep['mass_fraction'] - 1),
                             f"{a['coordination']:.2f}", f"{a['k1_factor']:.3g}", f"{c['failure_stress']:.0f}",
                             f"{c['failure_strain']:.4f}", f"{c['stiffness']:.3g}",
                             f"{v['largest_fragment']}/{v['fragments']}"])
    return md_table(["N", "p (N/m)", "t_s (s)", "ν(t_heat)", "ν(t_cool)", "ν(t_f)", "densification", "C(t_cool)",
                     "k1/k1(t_cool)", "σ_f (N/m)", "ε_f", "stiffness (N/m)", "vibration: largest/fragments"], rows)


def _three_table(st: Study) -> str:
    rows = []
    for p in st.grid.p:
        for seed in st.grid.three_seeds:
            task = st.task(sr.SCHEDULE, 3, p, st.t_max, seed)
            try:
                s = st.series(task)
            except Missing:
                continue
            a, b = at(s, task.times.t_heat), at(s, s["t"][-1])
            rows.append([f"{p:g}", seed, f"{a['volume_fraction']:.4f}", f"{b['volume_fraction']:.4f}",
                         pct(b['volume_fraction'] / a['volume_fraction'] - 1), f"{a['coordination']:.2f}"])
    return md_table(["p (N/m)", "seed", "ν(t_heat)", "ν(t_f)", "densification",
                     "C at t_heat (1.33: a chain, 2: a triangle)"], rows)


def _three_d(st: Study) -> tuple[str, dict]:
    """The 3D subsection: what ran, the table of the two stages, the summary entries."""
    n = st.grid.n3d
    rows, summary = [], {}
    for kind, label in ((sr.PREPARE3D, "prepared (80 °C)"),
                        (sr.SINTER3D, f"sintered, walls {sr.HOT3D[0]:g}/{sr.HOT3D[1]:g} °C")):
        r = st.res(kind, n, sr.P3D)
        neck = st.arrays(st.task(kind, n, sr.P3D)).get("neck_over_radius", np.zeros(0))
        rows.append([label, f"{r['volume_fraction']:.4f}", f"{r['coordination']:.2f}",
                     f"{np.mean(neck):.3f}" if len(neck) else "—",
                     f"{np.percentile(neck, 90):.3f}" if len(neck) else "—",
                     "—" if r["effective_conductivity"] is None else f"{r['effective_conductivity']:.3g}",
                     f"{r['seconds']:.0f}"])
        summary[kind] = {"volume_fraction": r["volume_fraction"], "coordination": r["coordination"],
                         "neck_over_radius_mean": float(np.mean(neck)) if len(neck) else None,
                         "effective_conductivity": r["effective_conductivity"]}
    s = st.series(st.task(sr.SINTER3D, n, sr.P3D))
    hot = s["t"][np.argmax(s["T_mean"] >= 130.0)] if np.any(s["T_mean"] >= 130.0) else math.nan
    k = s["effective_conductivity"]
    text = (PROSE["three_d"].format(n=n, spread=sr.SPREAD3D, p=sr.P3D, hot=sr.HOT3D[0], cold=sr.HOT3D[1],
                                    time=sr.SINTER3D_TIME, kappa=sr.CONDUCTIVITY3D, c=sr.SPECIFIC_HEAT3D)
            + " " + PROSE["three_d.heating"].format(hot=hot, k0=k[np.isfinite(k)][0], k1=k[np.isfinite(k)][-1]))
    table = md_table(["stage", "ν", "C", "neck a/r (mean)", "a/r (90 %)", "k_eff (W/(m K))", "run s"], rows)
    return text + "\n\n" + table, summary


def _speed(st: Study) -> tuple[str, dict]:
    n, p, t_s = st.n_max, max(st.grid.p), st.t_max
    parts = [st.res(kind, n, p, t_s if kind != sr.PREPARE else None) for kind in (sr.PREPARE, sr.SINTER, sr.COOL)]
    seconds = sum(r["seconds"] for r in parts)
    steps = sum(r["steps"] for r in parts)
    ns = 1e9 * seconds / (steps * n)
    stage_seconds = ", ".join(f"{r['seconds']:.1f}" for r in parts)
    t_f = Times(t_s=t_s).t_f
    text = PROSE["speed"].format(n=n, p=p, t_s=t_s, t_f=t_f, steps=steps, dt=t_f / steps, seconds=seconds,
                                 stages=stage_seconds, ns=ns)
    return text, {"seconds": seconds, "steps": steps, "ns_per_particle_step": ns, "n": n, "p": p, "t_s": t_s}


def _control_creep(st: Study, s_end: float) -> str:
    """The first three-particle control at p = 10 read back: each pair contact's overlap at the end against the creep
    f/(k1 s) of its force (eqs. 4, 10-12), and the box's area lost between t_heat and the end against the rise of
    nu (the densification is the law's creep alone when the two agree and the disks did not move otherwise)."""
    task = st.task(sr.SCHEDULE, 3, 10.0, st.t_max)
    a, s = st.arrays(task), st.series(task)
    x, r, i, j = a["snap0_x"], a["snap0_radius"], a["snap0_i"], a["snap0_j"]
    overlap = r[i] + r[j] - np.linalg.norm(x[i] - x[j], axis=1)
    creep = a["snap0_fn"] / (LUDING_TABLE1.k1 * s_end)
    start, end = at(s, task.times.t_heat), at(s, s["t"][-1])
    area = [box_area(row) for row in (start, end)]
    return PROSE["control_creep"].format(overlaps=", ".join(f"{1e6 * v:.1f}" for v in overlap),
                                         creeps=", ".join(f"{1e6 * v:.1f}" for v in creep),
                                         area=pct(1.0 - area[1] / area[0]),
                                         rise=pct(end["volume_fraction"] / start["volume_fraction"] - 1.0))


def discussion(st: Study) -> str:
    """Where ours differs from the paper, and why: one bullet per point, with the numbers of these runs (the blocks
    of prose.md, filled here)."""
    bullets = []

    def add(build):
        try:
            bullets.append(build())
        except Missing:
            pass

    n = st.n_max

    def densification():
        prep = {p: st.res(sr.PREPARE, n, p)["volume_fraction"] for p in (10.0, 100.0)}
        dens = {p: st.densification(p) for p in (10.0, 100.0)}
        s = st.series(st.task(sr.SINTER, n, 10.0, st.t_max))
        jump = at(s, 0.01)["volume_fraction"] - s["volume_fraction"][0]
        text = PROSE["densification"].format(prep10=prep[10.0], prep100=prep[100.0], n=n, jump=jump,
                                             dens10=pct(dens[10.0][0]), dens100=pct(dens[100.0][0]))
        try:
            fr = st.res(sr.PREPARE, n, 10.0, variant="frictionless")["volume_fraction"]
            fd = st.res(sr.COOL, n, 10.0, st.t_max, variant="frictionless")["volume_fraction"] / fr - 1.0
            text += " " + PROSE["densification.frictionless"].format(start=fr, dens=pct(fd))
        except Missing:
            pass
        other = [st.res(sr.PREPARE, n, 10.0, seed=seed)["volume_fraction"] for seed in sr.PREP_SEEDS]
        text += " " + PROSE["densification.placements"].format(
            n=n, others=", ".join(f"{v:.3f}" for v in other), seeds=", ".join(str(seed) for seed in sr.PREP_SEEDS),
            prep10=prep[10.0], dens10=", ".join(pct(v) for v in dens[10.0][1:]),
            dens100=", ".join(pct(v) for v in dens[100.0]))
        try:
            inner = [interior_fraction(st.state(st.task(sr.PREPARE, n, 10.0, seed=seed))) for seed in sr.PLACEMENTS]
            text += " " + PROSE["densification.interior"].format(margin_mm=1e3 * INTERIOR_MARGIN,
                                                                 inner=", ".join(f"{v:.3f}" for v in inner))
        except (Missing, ValueError):  # ValueError: a box smaller than two margins
            pass
        return text

    def cooling():
        a = st.res(sr.SINTER, n, 100.0, st.t_max)
        b = st.res(sr.COOL, n, 100.0, st.t_max)
        c = cool_down(st.series(st.task(sr.COOL, n, 100.0, st.t_max)), 0.0)
        text = PROSE["cooling"].format(particles=pct(-c["particles"]), box=pct(-c["box"]), top_min=c["top_min"],
                                       top_max=c["top_max"], mass_hot=a["mass_fraction"], mass_cold=b["mass_fraction"],
                                       n=n, volume_hot=a["volume_fraction"], volume_cold=b["volume_fraction"])
        ends = []
        for variant, label in (("frictionless", "frictionless"), ("no-wall-friction", "with frictionless walls")):
            for m in st.grid.n:
                try:
                    ends.append((label, m, st.res(sr.PREPARE, m, 100.0, variant=variant)["mass_fraction"],
                                 st.res(sr.SINTER, m, 100.0, st.t_max, variant=variant)["mass_fraction"],
                                 st.res(sr.COOL, m, 100.0, st.t_max, variant=variant)["mass_fraction"]))
                except Missing:
                    pass
        if ends:
            text += " " + PROSE["cooling.preparations"].format(
                ends="; ".join(PROSE["cooling.preparation"].format(label=label, n=m, start=v0, sintered=v1, cooled=v2)
                               for label, m, v0, v1, v2 in ends),
                mass_prep=st.res(sr.PREPARE, n, 100.0)["mass_fraction"], mass_hot=a["mass_fraction"],
                mass_cold=b["mass_fraction"], n=n)
        try:
            e = cool_down(st.series(st.task(sr.COOL, n, 100.0, st.t_max, variant="expansion-text")), 0.0)
            r = st.res(sr.COOL, n, 100.0, st.t_max, variant="expansion-text")
            text += " " + PROSE["cooling.expansion_text"].format(before=r["mass_fraction"] * (1.0 + e["box"]),
                                                                 after=r["mass_fraction"])
        except Missing:
            pass
        try:
            task = st.task(sr.SCHEDULE, min(st.grid.n), 100.0, st.t_max, variant="no-expansion")
            z = cool_down(st.series(task), task.times.t_cool)
            text += " " + PROSE["cooling.no_expansion"].format(n=task.n, nu_cool=z["nu_cool"], nu_f=z["nu_f"])
        except Missing:
            pass
        return text

    def three():
        d = {p: st.three(p) for p in (10.0, 100.0)}
        s_end = st.res(sr.SINTER, n, 10.0, st.t_max)["k1_factor"]
        creep = 2.0 * 1e-3 * 10.0 / (1e5 * s_end)  # f/(k1 s) at f = 2 a0 p (eqs. 4, 10-12, Table 1)
        forces = np.concatenate([st.arrays(st.task(sr.SCHEDULE, 3, 10.0, st.t_max, seed))["fn"]
                                 for seed in st.grid.three_seeds])
        text = PROSE["three"].format(dens10=pct(float(np.mean(d[10.0]))), dens100=pct(float(np.mean(d[100.0]))),
                                     placements=len(d[10.0]))
        try:
            w = {p: st.three(p, "walls-sinter", st.grid.three_seeds[:1]) for p in (10.0, 100.0)}
            text += " " + PROSE["three.walls_sinter"].format(dens10=pct(w[10.0][0]), dens100=pct(w[100.0][0]))
        except Missing:
            pass
        try:
            ratio = {t: st.three(100.0, seeds=(1,), t_s=t)[0] / st.three(10.0, seeds=(1,), t_s=t)[0]
                     for t in st.grid.t_s if t >= 0.01}
            if not ratio:
                raise Missing("three-particle controls sintered for 0.01 s or longer")
            short = min(ratio)
            text += " " + PROSE["three.pressure"].format(
                ratios=" and ".join(f"{r:.1f}" for r in ratio.values()), times=" and ".join(f"{t:g}" for t in ratio),
                short=short, dens10=pct(st.three(10.0, seeds=(1,), t_s=short)[0]),
                dens100=pct(st.three(100.0, seeds=(1,), t_s=short)[0]))
        except Missing:
            pass
        return text + " " + PROSE["three.creep"].format(
            s_end=s_end, creep_um=1e6 * creep, line=pct(2 * creep / 6e-3), force=np.mean(forces[forces > 0]),
            dens10=pct(float(np.mean(d[10.0]))), control=_control_creep(st, s_end))

    def forces():
        rows = {}
        for variant in ("", "held", "cool-no-expansion", "held-no-expansion", "cool-expansion-x3",
                        "cool-expansion-x5"):
            try:
                fn = st.arrays(st.task(sr.COOL, n, 100.0, st.t_max, variant=variant))["fn"]
            except Missing:
                continue
            q1, q99 = np.percentile(fn, [1, 99])
            rows[variant] = (-q1 / q99, np.mean(fn < 0))
        if "" not in rows:
            raise Missing("cool-down")
        q1, q99 = np.percentile(st.arrays(st.task(sr.COOL, n, 100.0, st.t_max))["fn"], [1, 99])
        text = PROSE["forces"].format(n=n, t_s=st.t_max, q1=q1, q99=q99, attract=100 * rows[""][1])
        if {"held", "cool-no-expansion", "held-no-expansion"} <= set(rows):
            text += " " + PROSE["forces.held"].format(held=rows["held"][0], held_attract=100 * rows["held"][1],
                                                      held_no_expansion=rows["held-no-expansion"][0],
                                                      no_expansion=rows["cool-no-expansion"][0])
        if {"cool-expansion-x3", "cool-expansion-x5"} <= set(rows):
            text += " " + PROSE["forces.contraction"].format(
                x3=rows["cool-expansion-x3"][0], x5=rows["cool-expansion-x5"][0],
                x3_attract=100 * rows["cool-expansion-x3"][1], x5_attract=100 * rows["cool-expansion-x5"][1])
        c = contact_cooling(0.2)
        return text + " " + PROSE["forces.contact"].format(
            held=c["held"], shrink_um=1e6 * c["shrink"], elastic_um=1e6 * (c["hot"]["overlap"] - c["hot"]["delta_0"]))

    def coordination():
        c = {(m, p): st.res(sr.SINTER, m, p, st.t_max)["coordination"] for m in st.grid.n for p in st.grid.p}
        paper = {(100, 10.0): 4.0, (300, 10.0): 4.0, (100, 100.0): 4.5, (300, 100.0): 4.8}
        gap = [paper[k] - v for k, v in c.items() if k in paper]
        if not gap:
            raise Missing("N = 100 or 300")
        bulk = {(m, p): bulk_coordination(st.contacts(sr.SINTER, m, p, st.t_max))[0] for m in st.grid.n
                for p in st.grid.p}
        return PROSE["coordination"].format(
            gap_min=min(gap), gap_max=max(gap),
            ours=", ".join(f"{c[(m, p)]:.2f} for N = {m}, p = {p:g}" for m in st.grid.n for p in st.grid.p),
            bulk=", ".join(f"{bulk[(m, p)]:.2f}" for m in st.grid.n for p in st.grid.p)) + _spread()

    def _spread() -> str:
        found = {(m, p): [st.results[task]["coordination"] for _, task in sintered_preparations(st, m, p)]
                 for m in st.grid.n for p in st.grid.p}
        if all(len(v) < 2 for v in found.values()):
            return ""
        return " " + PROSE["coordination.samples"].format(
            ranges=", ".join(f"{min(v):.2f}-{max(v):.2f} for N = {m}, p = {p:g} ({len(v)} samples)"
                             for (m, p), v in found.items() if len(v) > 1))

    def failure():
        ratio = max(st.compression(m, p, st.t_max)["kinetic_over_work"] for m in st.grid.n for p in st.grid.p)
        late = [f"N = {m}: ε_f = {st.compression(m, 100.0, st.t_min)['failure_strain']:.3f}" for m in st.grid.n]
        text = PROSE["failure"].format(late=", ".join(late), t_s=st.t_min)
        try:
            c = st.compression(n, 100.0, st.t_min, "long")
            flow = c["szz"][c["eps"] > 0.02]
            text += "; " + PROSE["failure.flow"].format(low=np.min(flow), high=np.max(flow), strain=c["failure_strain"])
        except Missing:
            pass
        try:
            spread = {p: st.placement_failures(n, p, st.t_min, "failure_strain") for p in st.grid.p}
            ranges = ", ".join(f"{min(v):.4f}-{max(v):.4f} at p = {p:g}" for p, v in spread.items())
            text += ". " + PROSE["failure.placements"].format(t_s=st.t_min, n=n, ranges=ranges)
        except Missing:
            pass
        return text + ". " + PROSE["failure.rate"].format(percent=100 * ratio)

    def vibration():
        if 0.01 not in st.grid.t_s:
            raise Missing("t_s = 0.01")
        share = {p: [st.res(sr.VIBRATE, n, p, t)["largest_fragment"] / n for t in st.grid.t_s] for p in st.grid.p}
        half = {p: next((t for t, x in zip(st.grid.t_s, share[p]) if x >= 0.5), None) for p in st.grid.p}
        return PROSE["vibration"].format(
            times=" and ".join(f"{half[p]:g} (p = {p:g})" for p in st.grid.p if half[p] is not None),
            share=share[100.0][st.grid.t_s.index(0.01)])

    for build in (densification, cooling, three, forces, coordination, failure, vibration):
        add(build)
    return PROSE["discussion"] + "\n\n" + "\n".join(f"- {b}" for b in bullets)


# ------------------------------------------------------------------------------------------------ the section
def run(out_dir: pathlib.Path, quick: bool = False, workers: int = 2) -> dict:
    """Run the grid (resuming finished runs), draw the figures, check the statements."""
    out_dir = pathlib.Path(out_dir)
    grid = sr.QUICK if quick else sr.FULL
    results = sr.run_tasks(grid.tasks(), out_dir, workers=workers)
    st = Study(out_dir, grid, results)
    failed = {t.folder: r["error"] for t, r in results.items() if "error" in r}
    figures = []
    for draw in (fig_schedule, fig_coordination, fig_density_ts, fig_distributions, fig_compression, fig_snapshots,
                 fig_3d):
        try:
            figures += draw(st, out_dir)
        except Missing:
            continue
    items, skipped = statements(st)
    holding = sum(s.holds for s in items)
    try:
        three_d_text, three_d = _three_d(st)
    except Missing as exc:
        three_d_text, three_d = f"*not run: {exc}*", {}
    try:
        speed_text, speed = _speed(st)
    except Missing as exc:
        speed_text, speed = f"*not run: {exc}*", {}
    cpu = sum(r.get("seconds", 0.0) for r in results.values())
    md = [
        f"The protocol of Sec. 4 with Table 1 ({len(results)} runs, {cpu / 60:.1f} min of run time in worker "
        f"processes, resumed from `runs/`): N = {', '.join(map(str, grid.n))}; p = {', '.join(f'{p:g}' for p in grid.p)} N/m; "
        f"t_s = {', '.join(f'{t:g}' for t in grid.t_s)} s{' (--quick)' if quick else ''}. "
        f"**{holding} of {len(items)} statements hold** within the tolerances given beside them.",
        "",
        PROSE["protocol"],
        "",
        "### Every quantitative statement of Section 4",
        "",
        statements_table(items),
        "",
    ]
    if skipped:
        md += ["Not checked by this grid: " + "; ".join(skipped) + ".", ""]
    if failed:
        md += ["Runs that failed: " + "; ".join(f"`{k}`: {v}" for k, v in failed.items()) + ".", ""]
    causes_text, causes = causes_section(st)
    md += [discussion(st), "", "### The runs that isolate each cause", "", causes_text, "",
           "### The runs", "", _grid_table(st), "",
           "### The three-particle control (Sec. 4.1.3)", "", _three_table(st), "",
           "### Beyond the paper: 3D spheres sintered between heated walls", "", three_d_text, "",
           "### Speed", "", speed_text, ""]
    summary = {"statements": [{k: v for k, v in asdict(s).items()} for s in items],
               "sintering.statements_holding": holding, "sintering.statements_total": len(items),
               "sintering.not_checked": skipped, "sintering.failed_runs": failed, "sintering.speed": speed,
               "sintering.3d": three_d, "sintering.causes": causes}
    return {"title": TITLE, "markdown": "\n".join(md), "summary": summary, "figures": figures}
