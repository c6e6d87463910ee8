"""Every quantitative statement of Section 4 of Luding, Manetsberger & Müllers 2005, checked against the runs.

Each check reads a :class:`verification.luding.study.Study` and returns one :class:`Statement` (or a list): the
statement, the paper's value, ours, whether it holds and the tolerance judged fair; a check whose runs are not in
the grid raises :class:`Missing` and is listed as not checked.

*Density.* The paper's ν, "material density" (Fig. 9), is taken as the sample's mass over Table 1's particle density
times the box, ``nu = M/(rho_p V)``: its one formula for nu, ``N pi h a0^2/V`` (Sec. 3.1.3), with ``m = rho_p pi a0^2
h``, and ρ_p at 80 °C, where the protocol draws the radii (the paper does not say at which temperature ρ_p and a0
hold). The mass is conserved (eq. 8), so ν rises when the particles contract on cooling -- the rise the paper puts
down to "negative thermal expansion" (Sec. 4.1.4) -- whereas the solid fraction counted with the current radii a(T)
of eq. 9 stays, because the stress-controlled box follows the particles (the cool-down runs of
:mod:`verification.luding.causes`). At 80 °C the two are equal: they differ only for the hot sample.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from verification.luding.protocol import T_PREPARE, Times
from verification.luding import runs as sr
from verification.report import md_table
from verification.luding.study import Missing, Study, at, bulk_coordination, without_rattlers


@dataclass
class Statement:
    """One quantitative statement of the paper with our number: ``holds`` within ``tolerance``."""

    source: str
    statement: str
    paper: str
    ours: str
    holds: bool
    tolerance: str
    note: str = ""

    def __post_init__(self):
        self.holds = bool(self.holds)  # numpy comparisons give numpy booleans; the summary wants true or false


MATERIAL_DENSITY = "material density ν = M/(ρ_p V), ρ_p at 80 °C"  # the paper's nu (module docstring)


def pct(x: float) -> str:
    return f"{100.0 * x:.2f} %"


def _within(value: float, target: float, tol: float) -> bool:
    return bool(abs(value - target) <= tol)


def _monotone(values, slack: float) -> bool:
    """Non-decreasing up to ``slack`` between neighbours."""
    return bool(np.all(np.diff(np.asarray(values, dtype=float)) >= -slack))


def _spearman(x, y) -> float:
    rx, ry = np.argsort(np.argsort(x)), np.argsort(np.argsort(y))
    return float(np.corrcoef(rx, ry)[0, 1]) if len(x) > 2 else math.nan


def statements(st: Study) -> tuple[list[Statement], list[str]]:
    """Every quantitative statement of Section 4 that the grid can check, and those it cannot (one line each)."""
    out, skipped = [], []
    for check in CHECKS:
        try:
            result = check(st)
        except Missing as exc:
            skipped.append(f"{check.__doc__.strip().splitlines()[0]} (needs {exc})")
            continue
        out += result if isinstance(result, list) else [result]
    return out, skipped


def _prep_density(st: Study):
    """Sec. 4.1.2: the preparation gives nu ~ 0.8 (the mean over the grid's random placements of each N and p)."""
    rows = [(n, p, [st.res(sr.PREPARE, n, p, seed=seed)["volume_fraction"] for seed in sr.PLACEMENTS])
            for n in st.grid.n for p in st.grid.p]
    return Statement("Sec. 4.1.2, Fig. 9", "The initial preparation leads to a rather low density", "ν ≈ 0.8",
                     "; ".join(f"{np.mean(v):.3f} (N={n}, p={p:g}; placements {', '.join(f'{x:.3f}' for x in v)})"
                               for n, p, v in rows),
                     all(_within(float(np.mean(v)), 0.8, 0.03) for _, _, v in rows), "±0.03",
                     "the mean over the random placements the grid prepares, as the densification statements read: "
                     "one sample of N = 100 moves with its loose wall layer (the preparation runs)")


def _density_rises_with_ts(st: Study):
    """Sec. 4.1.2, Fig. 9: density rises with t_s."""
    parts, ok = [], True
    for n in st.grid.n:
        for p in st.grid.p:
            nu = [st.res(sr.SINTER, n, p, t)["volume_fraction"] for t in st.grid.t_s]
            ok &= _monotone(nu, 0.002) and nu[-1] - nu[0] > 0.01
            parts.append(f"N={n}, p={p:g}: {nu[0]:.3f} → {nu[-1]:.3f}")
    return Statement("Sec. 4.1.2, Fig. 9", "For increasing sintering time t_s the density after sintering increases",
                     "monotone in t_s", "; ".join(parts), ok, "non-decreasing within 0.002 between neighbouring "
                     "t_s, and +0.01 or more from the shortest to the longest")


def _densification_early(st: Study):
    """Sec. 4.1.2: the increase is strongest at the beginning of sintering and continues later."""
    n, p, t_s = st.n_max, max(st.grid.p), st.t_max
    h = st.history(n, p, t_s)
    times = Times(t_s=t_s)
    nu0, nu10, nu50, nu1 = (at(h, t)["volume_fraction"] for t in (times.t_sinter, times.t_sinter + 0.1 * t_s,
                                                                    times.t_sinter + 0.5 * t_s, times.t_cool))
    early = (nu10 - nu0) / (nu1 - nu0)
    return Statement("Sec. 4.1.2, Fig. 9", "The densification is strongest at the beginning of sintering but "
                     "continues for longer times", "qualitative",
                     f"first 10 % of t_s: {100 * early:.0f} % of the rise; last half: +{nu1 - nu50:.4f} "
                     f"(N={n}, p={p:g}, t_s={t_s:g})", bool(early > 0.5 and nu1 - nu50 > 0), "more than half of "
                     "the rise in the first tenth, and still rising in the second half")


def _density_rises_with_p(st: Study):
    """Sec. 4.1.4: larger confining pressure gives higher density."""
    lo, hi = min(st.grid.p), max(st.grid.p)
    pairs = [(st.res(sr.COOL, n, hi, t)["volume_fraction"], st.res(sr.COOL, n, lo, t)["volume_fraction"])
             for n in st.grid.n for t in st.grid.t_s]
    wins = sum(a > b for a, b in pairs)
    return Statement("Sec. 4.1.4", f"Larger confining pressure (p = {hi:g} against {lo:g}) leads to higher density",
                     "higher for every sample", f"higher in {wins} of {len(pairs)} (N, t_s)", wins == len(pairs),
                     "every sample")


def _nu_after_sintering(st: Study):
    """Sec. 4.1.4: the material density almost 0.92 after the longest sintering at p = 100 (t = 1.3)."""
    r = st.res(sr.SINTER, st.n_max, 100.0, st.t_max)
    return Statement("Sec. 4.1.4, Fig. 9", f"After the longest sintering (t_s = {st.t_max:g}, p = 100, N = "
                     f"{st.n_max}) the density is almost 0.92", "≈ 0.92",
                     f"{r['mass_fraction']:.4f} (solid fraction at the hot radii {r['volume_fraction']:.4f})",
                     _within(r["mass_fraction"], 0.92, 0.015), f"±0.015 ({MATERIAL_DENSITY})")


def _nu_after_cooling(st: Study):
    """Sec. 4.1.4: the material density almost 0.94 after cool-down."""
    r = st.res(sr.COOL, st.n_max, 100.0, st.t_max)
    return Statement("Sec. 4.1.4, Fig. 9", "Only after cool-down the maximum density of almost 0.94 is reached "
                     "(negative thermal expansion)", "≈ 0.94", f"{r['mass_fraction']:.4f}",
                     _within(r["mass_fraction"], 0.94, 0.015), f"±0.015 ({MATERIAL_DENSITY})",
                     "the contraction of eq. 9 raises ν by 2 δa_T (140 − 80 °C) ≈ 1.2 %, the paper's text by about "
                     "2 %; see the cool-down runs")


def _cooling_increase(st: Study):
    """Sec. 4.1.2/4.1.4: cool-down adds a final small increase in density."""
    a, b = st.res(sr.SINTER, st.n_max, 100.0, st.t_max), st.res(sr.COOL, st.n_max, 100.0, st.t_max)
    d_nu, d_m = b["volume_fraction"] - a["volume_fraction"], b["mass_fraction"] - a["mass_fraction"]
    return Statement("Sec. 4.1.2, Fig. 9", "Cooling down adds a final small increase in density", "small increase",
                     f"{d_m:+.4f} (solid fraction at the current radii {d_nu:+.4f})", bool(d_m > 0),
                     f"rises ({MATERIAL_DENSITY})", "the rise is the particles' thermal contraction: the box "
                     "follows the particles, so the solid fraction counted with the current radii does not see it")


def _densification(st: Study):
    """Sec. 4.1.3: densification about 5 % (p = 10) and 16 % (p = 100)."""
    out = []
    for p, paper in ((10.0, 0.05), (100.0, 0.16)):
        d = st.densification(p)
        mean = float(np.mean(d))
        out.append(Statement("Sec. 4.1.3", f"Sintering densifies by about {100 * paper:g} % at p = {p:g}",
                             pct(paper), f"{pct(mean)} (mean of the placements {', '.join(pct(x) for x in d)}; "
                             f"N={st.n_max}, t_s={st.t_max:g}; ν(t_f)/ν(t_heat) − 1)",
                             _within(mean, paper, 0.3 * paper), "±30 % of the paper's value",
                             f"the mean over the {len(d)} random placements the grid prepares: one sample's "
                             f"densification at p = 10 moves with its loose wall layer (the preparation runs)"))
    return out


def _three_particles(st: Study):
    """Sec. 4.1.3: three-particle control densifies by about 0.2 % (p = 10) and 8 % (p = 100)."""
    out = []
    for p, paper in ((10.0, 0.002), (100.0, 0.08)):
        d = st.three(p)
        out.append(Statement("Sec. 4.1.3", f"Three particles (no rearrangement) densify by about {100 * paper:g} % "
                             f"at p = {p:g}", pct(paper), f"{pct(float(np.mean(d)))} (seeds: "
                             f"{', '.join(pct(x) for x in d)})", _within(float(np.mean(d)), paper,
                                                                         max(0.3 * paper, 0.005)),
                             "±30 % of the paper's value or ±0.5 points",
                             "walls that keep the cold law, prepared for 0.5 s without wall friction "
                             "(verification.luding.protocol.control_doc); the isolating runs show walls that sinter"))
    return out


def _reorganisation_matters_more_at_low_p(st: Study):
    """Sec. 4.1.3: reorganisations matter more at low pressure (control / full smaller at p = 10)."""
    ratio = {}
    for p in (10.0, 100.0):
        ratio[p] = float(np.mean(st.three(p))) / float(np.mean(st.densification(p)))
    return Statement("Sec. 4.1.3", "For low confining pressure reorganisations are much more important than for high "
                     "pressure (the contact law's share of the densification is smaller)",
                     "share 0.2/5 = 0.04 (p = 10) against 8/16 = 0.5 (p = 100)",
                     f"share {ratio[10.0]:.2f} (p = 10) against {ratio[100.0]:.2f} (p = 100)",
                     bool(ratio[10.0] < ratio[100.0]), "smaller share at p = 10")


def _no_expansion(st: Study):
    """Sec. 4.1.3: without thermal expansion the outcome after cool-down does not change."""
    parts, ok = [], True
    n = min(st.grid.n)
    for p in st.grid.p:
        a = st.res(sr.COOL, n, p, st.t_max)["volume_fraction"]
        b = st.res(sr.SCHEDULE, n, p, st.t_max, variant="no-expansion")["volume_fraction"]
        ok &= _within(b, a, 0.01)
        parts.append(f"p={p:g}: {a:.4f} with, {b:.4f} without")
    return Statement("Sec. 4.1.3", "Without thermal expansion (δa_T = 0) the outcome after cool-down does not change "
                     "(densities slightly different)", "slightly different", "; ".join(parts) + f" (N={n})", ok,
                     "±0.01")


def _k1_history(st: Study):
    """Sec. 4.1.2, Fig. 8: k1 lower for longer t_s, back to its initial value after cooling."""
    n, p = st.n_max, max(st.grid.p)
    k_end = [st.res(sr.SINTER, n, p, t)["k1_factor"] for t in st.grid.t_s]
    k_cold = [st.res(sr.COOL, n, p, t)["k1_factor"] for t in st.grid.t_s]
    k80 = 1.0 / (1.0 + math.exp(-2.0 * (120.0 - T_PREPARE) / 10.0))
    back = max(abs(k / k80 - 1.0) for k in k_cold)
    return Statement("Sec. 4.1.2, Fig. 8", "The longer t_s, the lower k1(T, t) gets; on cooling k1 rises back to its "
                     "initial value", "qualitative",
                     f"k1(T,t)/k1 at t_cool: {', '.join(f'{k:.3g}' for k in k_end)} for t_s = "
                     f"{', '.join(f'{t:g}' for t in st.grid.t_s)}; after cooling within {back:.1e} of k1(80 °C)",
                     bool(np.all(np.diff(k_end) < 0) and back < 1e-5), "strictly decreasing; back within 1e-5")


def _coordination(st: Study):
    """Sec. 4.2, Fig. 10: C ~ 4 at p = 10; 4.5 (N = 100) and 4.8 (N = 300) at p = 100."""
    out = []
    for n in st.grid.n:
        for p, paper in ((10.0, 4.0), (100.0, {100: 4.5, 300: 4.8}.get(n))):
            if paper is None:
                continue
            c = st.res(sr.SINTER, n, p, st.t_max)["coordination"]
            a = st.contacts(sr.SINTER, n, p, st.t_max)
            c2, rattlers = without_rattlers(a["snap0_i"], a["snap0_j"], n)
            bulk, inside = bulk_coordination(a)
            tol = 0.3 if p == 10.0 else 0.25
            out.append(Statement("Sec. 4.2, Fig. 10", f"Coordination number after sintering (t_s = {st.t_max:g}), "
                                 f"N = {n}, p = {p:g}", f"≈ {paper:g}",
                                 f"{c:.2f} ({c2:.2f} without the {rattlers} particles with fewer than 2 contacts; "
                                 f"{bulk:.2f} for the {inside} touching no wall)",
                                 _within(c, paper, tol), f"±{tol:g} (every particle counted)",
                                 "every particle counted, rattlers included, and no wall contacts"))
    return out


def _coordination_order(st: Study):
    """Sec. 4.2: C higher at p = 100 than at p = 10, and higher for the larger sample."""
    c = {(n, p): st.res(sr.SINTER, n, p, st.t_max)["coordination"] for n in st.grid.n for p in st.grid.p}
    out = [Statement("Sec. 4.2, Fig. 10", "The larger confining stress leads to more contacts per particle",
                     "C(p=100) > C(p=10)", "; ".join(f"N={n}: {c[(n, 100.0)]:.2f} > {c[(n, 10.0)]:.2f}"
                                                    for n in st.grid.n),
                     all(c[(n, 100.0)] > c[(n, 10.0)] for n in st.grid.n), "for every N")]
    if len(st.grid.n) > 1:
        lo, hi = min(st.grid.n), max(st.grid.n)
        out.append(Statement("Sec. 4.2", "The smaller sample has somewhat fewer contacts (more wall particles)",
                             "4.5 (N=100) < 4.8 (N=300) at p = 100",
                             f"{c[(lo, 100.0)]:.2f} (N={lo}) against {c[(hi, 100.0)]:.2f} (N={hi})",
                             bool(c[(lo, 100.0)] < c[(hi, 100.0)]), "smaller for the smaller sample"))
    return out


def _coordination_dips(st: Study):
    """Sec. 4.2, Figs. 10-11: C sometimes decreases while the density increases."""
    dips, total, drops = 0, 0, []
    for n in st.grid.n:
        for p in st.grid.p:
            s = st.series(st.task(sr.SINTER, n, p, st.t_max))
            Times(t_s=st.t_max)
            during = s["t"] >= Times(t_s=st.t_max).heat
            nu, c = s["volume_fraction"][during], s["coordination"][during]
            dn, dc = np.diff(nu), np.diff(c)
            dips += int(np.count_nonzero((dc < 0) & (dn > 0)))
            total += len(dn)
            drops.append(float(max(0.0, -np.min(dn)) if len(dn) else 0.0))
    return Statement("Sec. 4.2, Figs. 10-11", "While the density increases continuously, the coordination number "
                     "sometimes decreases (reorganisations)", "sometimes",
                     f"{dips} of {total} output intervals while sintering (t_s = {st.t_max:g}, every N and p) have C "
                     f"falling while ν rises; largest drop of ν in an interval {max(drops):.1e}",
                     bool(dips > 0 and max(drops) < 2e-3), "at least one such interval; ν never drops by more than "
                     "0.002 in one")


def _overlap_mean(st: Study):
    """Sec. 4.3.1, Fig. 12: the mean overlap increases with the side stress and the sintering time."""
    n = st.n_max
    mean = {(p, t): float(np.mean(st.contacts(sr.SINTER, n, p, t)["overlap_rel"])) for p in st.grid.p
            for t in st.grid.t_s}
    by_t = all(_monotone([mean[(p, t)] for t in st.grid.t_s], 0.0) for p in st.grid.p)
    by_p = all(mean[(100.0, t)] > mean[(10.0, t)] for t in st.grid.t_s)
    return Statement("Sec. 4.3.1, Fig. 12", "The mean overlap increases with the side stress and the sintering time",
                     "increases with p and t_s", "; ".join(f"p={p:g}: " + ", ".join(f"{mean[(p, t)]:.2e}"
                                                                               for t in st.grid.t_s)
                                                          for p in st.grid.p) + f" (δ/(a1+a2), N={n})",
                     bool(by_t and by_p), "non-decreasing in t_s for each p, larger at p = 100 for each t_s")


def _overlap_width_on_cooling(st: Study):
    """Sec. 4.3.1, Fig. 13: after cool-down the overlap distribution is only slightly wider."""
    n, ratios = st.n_max, []
    for p in st.grid.p:
        a = st.contacts(sr.SINTER, n, p, st.t_max)["overlap_rel"]
        b = st.contacts(sr.COOL, n, p, st.t_max)["overlap_rel"]
        ratios.append(float(np.std(b) / np.std(a)))
    return Statement("Sec. 4.3.1, Fig. 13", "After cool-down the overlap distribution is only slightly wider",
                     "slightly wider", ", ".join(f"std ratio {r:.3f} (p={p:g})" for r, p in zip(ratios, st.grid.p)),
                     all(0.95 <= r <= 1.5 for r in ratios), "standard deviation ratio in [0.95, 1.5]")


def _forces_hot_and_cold(st: Study):
    """Sec. 4.3.2, Figs. 14-15: hot forces mostly repulsive and small; cooling broadens them both ways."""
    out = []
    for p in st.grid.p:
        a = st.contacts(sr.SINTER, st.n_max, p, st.t_max)["fn"]
        b = st.contacts(sr.COOL, st.n_max, p, st.t_max)["fn"]
        rep = float(np.mean(a > 0))
        out.append(Statement(f"Sec. 4.3.2, Fig. {14 if p == 10 else 15}", f"p = {p:g}: before cool-down the normal "
                             "forces are mostly repulsive and small; cooling broadens the distribution towards both "
                             "positive and negative forces", "qualitative",
                             f"hot: {100 * rep:.0f} % repulsive, range [{a.min():.3g}, {a.max():.3g}] N, std "
                             f"{a.std():.3g} N; cold: range [{b.min():.3g}, {b.max():.3g}] N, std {b.std():.3g} N",
                             bool(rep > 0.5 and b.min() < a.min() and b.max() > a.max() and b.std() > a.std()),
                             "more than half repulsive when hot; the cold range wider on both sides"))
    return out


def _forces_equal_strength(st: Study):
    """Abstract, Sec. 4.3.2: after cool-down attractive and repulsive forces are almost equally strong."""
    parts, ok = [], True
    for p in st.grid.p:
        b = st.contacts(sr.COOL, st.n_max, p, st.t_max)["fn"]
        q1, q99 = np.percentile(b, [1, 99])
        ratio = -q1 / q99
        ok &= 0.5 <= ratio <= 2.0
        parts.append(f"p={p:g}: 1 % quantile {q1:.3g} N, 99 % quantile {q99:.3g} N (ratio {ratio:.2f})")
    return Statement("Abstract, Sec. 4.3.2", "The sintered, cooled block has almost equally strong attractive and "
                     "repulsive contact forces", "≈ equal", "; ".join(parts), bool(ok),
                     "the strongest 1 % of each sign within a factor 2")


def _force_width_grows(st: Study):
    """Sec. 4.3.2: after cool-down the width grows with side stress and sintering time."""
    w = {(p, t): float(np.std(st.contacts(sr.COOL, st.n_max, p, t)["fn"])) for p in st.grid.p for t in st.grid.t_s}
    ok = all(w[(p, st.t_max)] > w[(p, st.t_min)] for p in st.grid.p) and all(w[(100.0, t)] > w[(10.0, t)]
                                                                            for t in st.grid.t_s)
    return Statement("Sec. 4.3.2, Figs. 14-15", "After cool-down the width of the force distribution increases with "
                     "the side stress and the sintering time", "increases",
                     "; ".join(f"p={p:g}: std " + ", ".join(f"{w[(p, t)]:.3g}" for t in st.grid.t_s) + " N"
                               for p in st.grid.p), ok, "longest t_s wider than shortest; p = 100 wider than p = 10 "
                     "at every t_s")


def _force_narrows(st: Study):
    """Sec. 4.3.2, Fig. 15 top: the force distribution becomes narrower with sintering."""
    parts, ok = [], True
    for p in st.grid.p:
        a = float(np.std(st.contacts(sr.SINTER, st.n_max, p, st.t_min)["fn"]))
        b = float(np.std(st.contacts(sr.SINTER, st.n_max, p, st.t_max)["fn"]))
        ok &= b < a
        parts.append(f"p={p:g}: std {a:.3g} N (t_s={st.t_min:g}) → {b:.3g} N (t_s={st.t_max:g})")
    return Statement("Sec. 4.3.2, Fig. 15", "The normal-force distribution becomes narrower with sintering (the "
                     "largest forces are destroyed)", "narrower", "; ".join(parts), bool(ok),
                     "smaller standard deviation after the longest sintering than after the shortest")


def _tangential_weaker(st: Study):
    """Sec. 4.3.3: longer sintering leads to weaker tangential forces (before cool-down)."""
    parts, ok = [], True
    for p in st.grid.p:
        a = float(np.mean(st.contacts(sr.SINTER, st.n_max, p, st.t_min)["ft"]))
        b = float(np.mean(st.contacts(sr.SINTER, st.n_max, p, st.t_max)["ft"]))
        ok &= b < a
        parts.append(f"p={p:g}: mean {a:.3g} → {b:.3g} N")
    return Statement("Sec. 4.3.3", "Longer sintering leads to weaker tangential forces", "weaker", "; ".join(parts),
                     bool(ok), "smaller mean after the longest sintering")


def _friction_bound(st: Study):
    """Sec. 4.3.3: mu_t = f_t/(f_n - f_min) never exceeds mu(T, t)."""
    worst, contacts = 0.0, 0
    for task, r in st.results.items():
        if "error" in r or task.kind in (sr.SCHEDULE,) or task.n < 4:
            continue
        a = st.arrays(task)
        ok = np.isfinite(a["mu_t"]) & (a["mu_T"] > 0)
        if np.any(ok):
            worst = max(worst, float(np.max(a["mu_t"][ok] / a["mu_T"][ok])))
            contacts += int(np.count_nonzero(ok))
    if contacts == 0:
        raise Missing("finished runs with contacts")
    return Statement("Sec. 4.3.3", "The activated friction μ_t = f_t/(f_n − f_min) never exceeds μ(T, t)",
                     "≤ μ(T, t)",
                     f"largest μ_t/μ(T, t) over {contacts} contacts of every final state: {worst:.12f}",
                     bool(worst <= 1 + 1e-9), "≤ 1 + 1e-9")


def _full_friction_rarer(st: Study):
    """Sec. 4.3.3: fully activated friction becomes less probable for longer sintering (after cool-down)."""
    parts, ok = [], True
    for p in st.grid.p:
        mean, full = [], []
        for t in (st.t_min, st.t_max):
            a = st.contacts(sr.COOL, st.n_max, p, t)
            good = np.isfinite(a["mu_t"]) & (a["mu_T"] > 0)
            ratio = a["mu_t"][good] / a["mu_T"][good]
            mean.append(float(np.mean(ratio)))
            full.append(float(np.mean(ratio >= 0.99)))
        ok &= mean[1] < mean[0] and full[1] <= full[0]
        parts.append(f"p={p:g}: mean μ_t/μ(T, t) {mean[0]:.3f} → {mean[1]:.3f}, fully activated "
                     f"{100 * full[0]:.1f} % → {100 * full[1]:.1f} %")
    return Statement("Sec. 4.3.3", "Contacts with fully activated friction (μ_t ≈ μ(T, t)) become less probable "
                     "for longer sintering (larger |f_min| after cool-down)", "less probable",
                     "; ".join(parts) + f" (t_s = {st.t_min:g} → {st.t_max:g}, after cool-down)", bool(ok),
                     "smaller mean activation and no larger fraction with μ_t ≥ 0.99 μ(T, t)")


def _compression_density(st: Study):
    """Sec. 4.4.1, Fig. 16: during compression the density first increases slightly, then decreases strongly."""
    parts, ok = [], True
    for n in st.grid.n:
        for p in st.grid.p:
            c = st.compression(n, p, st.t_max)
            nu = c["nu"]
            up, down = float(np.max(nu) - nu[0]), float(nu[0] - nu[-1])
            ok &= up > 0 and down > 0.01
            parts.append(f"N={n}, p={p:g}: +{up:.4f} then −{down:.4f}")
    return Statement("Sec. 4.4.1, Figs. 16, 18", "During compression the density slightly increases first and then "
                     "decreases strongly (dilatancy)", "qualitative", "; ".join(parts) + f" (t_s={st.t_max:g})",
                     bool(ok), "a rise, then a fall by more than 0.01 below the start")


def _compression_density_change_grows(st: Study):
    """Sec. 4.4.1: the longer the sintering, the stronger the change of density; negligible for the shortest."""
    parts, ok = [], True
    for n in st.grid.n:
        for p in st.grid.p:
            change = [float(np.ptp(st.compression(n, p, t)["nu"])) for t in (st.t_min, st.t_max)]
            ok &= change[1] > change[0]
            parts.append(f"N={n}, p={p:g}: range of ν {change[0]:.4f} (t_s={st.t_min:g}) against {change[1]:.4f}")
    return Statement("Sec. 4.4.1", "The longer the sample was sintered, the stronger the change in density under "
                     "compression", "stronger", "; ".join(parts), bool(ok), "larger range of ν for the longest t_s")


def _failure_grows(st: Study):
    """Sec. 4.4.1-4.4.2, Figs. 17, 19: failure stress and strain grow with t_s and p (the mean over the random
    placements the grid prepares, sinters and compresses for each N, p and t_s)."""
    out = []
    for key, name in (("failure_stress", "failure stress"), ("failure_strain", "failure strain")):
        mean = {(n, p, t): float(np.mean(st.placement_failures(n, p, t, key)))
                for n in st.grid.n for p in st.grid.p for t in st.grid.t_s}
        parts, ok = [], True
        for n in st.grid.n:
            for p in st.grid.p:
                v = [mean[n, p, t] for t in st.grid.t_s]
                rho = _spearman(np.asarray(st.grid.t_s), np.asarray(v))
                ok &= v[-1] > v[0] and (not np.isfinite(rho) or rho > 0.5)
                parts.append(f"N={n}, p={p:g}: {v[0]:.3g} → {v[-1]:.3g} (rank corr. {rho:.2f})")
        out.append(Statement("Sec. 4.4.1, Figs. 17, 19", f"The {name} increases with the sintering time",
                             "increases", "; ".join(parts), bool(ok),
                             "longest above shortest and Spearman rank correlation with t_s > 0.5",
                             f"the mean over the {len(sr.PLACEMENTS)} random placements (each in the isolating "
                             "runs' failure table)"))
        pairs = [(n, t) for n in st.grid.n for t in st.grid.t_s]
        wins = sum(mean[n, 100.0, t] > mean[n, 10.0, t] for n, t in pairs)
        out.append(Statement("Sec. 4.4.1, Figs. 17, 19", f"The {name} increases with the confining pressure",
                             "increases", f"larger at p = 100 in {wins} of {len(pairs)} (N, t_s)",
                             wins >= 0.75 * len(pairs), "in at least 3/4 of the samples",
                             f"the mean over the {len(sr.PLACEMENTS)} random placements"))
    return out


def _stiffness_ratio(st: Study):
    """Sec. 4.4.1-4.4.2: the stiffness about doubles when p grows tenfold."""
    ratios = [st.compression(n, 100.0, t)["stiffness"] / st.compression(n, 10.0, t)["stiffness"]
              for n in st.grid.n for t in st.grid.t_s]
    med = float(np.median(ratios))
    return Statement("Sec. 4.4.1-4.4.2, Figs. 17, 19", "The material stiffness (slope of σ_zz against ε_zz) is about "
                     "doubled when the confining stress grows tenfold", "≈ 2",
                     f"median {med:.2f} over {len(ratios)} (N, t_s); range {min(ratios):.2f}-{max(ratios):.2f}",
                     bool(1.5 <= med <= 2.7), "median in [1.5, 2.7]",
                     "slope fitted while σ_zz rises from p half way to failure")


def _strength_jump(st: Study):
    """Sec. 4.4.1: a large jump in strength between t_s = 0.02 and 0.05 at p = 10, not at p = 100."""
    if 0.02 not in st.grid.t_s or 0.05 not in st.grid.t_s:
        raise Missing("t_s = 0.02 and 0.05")
    n = min(st.grid.n)
    jump = {p: st.compression(n, p, 0.05)["failure_stress"] / st.compression(n, p, 0.02)["failure_stress"]
            for p in st.grid.p}
    return Statement("Sec. 4.4.1, Fig. 17", "A rather large jump in strength between t_s = 0.02 and 0.05 at p = 10, "
                     "not paralleled at p = 100", "jump at p = 10 only",
                     f"σ_f(0.05)/σ_f(0.02) = {jump[10.0]:.2f} (p=10), {jump[100.0]:.2f} (p=100), N={n}",
                     bool(jump[10.0] > 1.5 and jump[10.0] > jump[100.0]), "ratio > 1.5 at p = 10 and above p = 100's")


def _size_effects(st: Study):
    """Sec. 4.4.2, Figs. 18-19: the larger sample has larger densities, and fails at larger stress and strain."""
    if len(st.grid.n) < 2:
        raise Missing("two sample sizes")
    lo, hi = min(st.grid.n), max(st.grid.n)
    out = []
    nu = [(st.res(sr.COOL, hi, p, t)["volume_fraction"], st.res(sr.COOL, lo, p, t)["volume_fraction"])
          for p in st.grid.p for t in st.grid.t_s]
    wins = sum(a > b for a, b in nu)
    out.append(Statement("Sec. 4.4.2, Fig. 18", f"The larger sample (N = {hi}) shows somewhat larger densities",
                         "larger", f"larger in {wins} of {len(nu)} (p, t_s)", wins >= 0.75 * len(nu),
                         "in at least 3/4 of the samples"))
    for key, name in (("failure_stress", "stress"), ("failure_strain", "strain")):
        r = [st.compression(hi, p, t)[key] / st.compression(lo, p, t)[key] for p in st.grid.p for t in st.grid.t_s]
        med = float(np.median(r))
        out.append(Statement("Sec. 4.4.2, Fig. 19", f"The larger sample fails at a slightly larger {name}",
                             "slightly larger", f"median ratio N={hi}/N={lo}: {med:.2f}", bool(med > 1.0),
                             "median ratio > 1"))
    return out


def _fig20(st: Study):
    """Sec. 4.4.3, Fig. 20: compression destroys the lines of attraction and fragments the sample."""
    n, p = st.n_max, min(st.grid.p)
    a = st.arrays(st.task(sr.COMPRESS, n, p, st.t_max))
    first, last = 0, len(sr.FIG20_TIMES) - 1
    pull = [float(-np.sum(np.minimum(a[f"snap{k}_fn"], 0.0))) for k in (first, last)]
    contacts = [len(a[f"snap{k}_fn"]) for k in (first, last)]
    frag = st.res(sr.COMPRESS, n, p, st.t_max)
    before = st.res(sr.COOL, n, p, st.t_max)
    return Statement("Sec. 4.4.3, Fig. 20", f"During compression (N = {n}, p = {p:g}, t_s = {st.t_max:g}) the lines of "
                     "strong attraction are destroyed and the sample fragments", "qualitative",
                     f"total attraction {pull[0]:.2f} N in {contacts[0]} contacts at t = {sr.FIG20_TIMES[first]:g} "
                     f"s → {pull[1]:.2f} N in {contacts[1]} at {sr.FIG20_TIMES[last]:g} s; fragments "
                     f"{before['fragments']} before, {frag['fragments']} after (largest {frag['largest_fragment']})",
                     bool(pull[1] < pull[0] and contacts[1] < contacts[0] and frag["fragments"] > before["fragments"]),
                     "less total attraction and fewer contacts at the last snapshot than at the first; more fragments")


def _vibration(st: Study):
    """Figs. 21-22: t_s = 1 survives as one block; the shortest falls apart into single particles."""
    out = []
    for n in st.grid.n:
        for p in st.grid.p:
            a, b = st.res(sr.VIBRATE, n, p, st.t_max), st.res(sr.VIBRATE, n, p, st.t_min)
            out.append(Statement(f"Sec. 4.4.3, Fig. {21 if p == 10 else 22}",
                                 f"N = {n}, p = {p:g}: after t_s = {st.t_max:g} the sample survives the vibration test "
                                 "almost perfectly (corner particles may break off)", "one block",
                                 f"largest fragment {a['largest_fragment']} of {n}, {a['fragments']} fragments",
                                 a["largest_fragment"] >= 0.9 * n, "largest fragment ≥ 90 % of the particles"))
            out.append(Statement(f"Sec. 4.4.3, Fig. {21 if p == 10 else 22}",
                                 f"N = {n}, p = {p:g}: after t_s = {st.t_min:g} the sample consists of single "
                                 "particles only", "single particles",
                                 f"{b['single_particles']} single particles of {n}; largest fragment "
                                 f"{b['largest_fragment']}", b["single_particles"] >= 0.8 * n,
                                 "at least 80 % single particles"))
    return out


def _vibration_pieces(st: Study):
    """Figs. 21-22: intermediate sintering (0.02 at p = 10, 0.01 at p = 100) fragments into pieces."""
    out = []
    for p, t in ((10.0, 0.02), (100.0, 0.01)):
        if t not in st.grid.t_s:
            raise Missing(f"t_s = {t:g}")
        for n in st.grid.n:
            a = st.res(sr.VIBRATE, n, p, t)
            sizes = st.arrays(st.task(sr.VIBRATE, n, p, t))["fragment_sizes"]
            pieces = int(np.count_nonzero(sizes >= 2))
            out.append(Statement(f"Sec. 4.4.3, Fig. {21 if p == 10 else 22}",
                                 f"N = {n}, p = {p:g}: after t_s = {t:g} the sample fragments into pieces",
                                 "pieces", f"{pieces} pieces of 2 or more, largest {a['largest_fragment']} of {n}",
                                 bool(pieces >= 2 and a["largest_fragment"] < 0.9 * n),
                                 "two or more pieces, none with 90 % of the particles"))
    return out


def _vibration_order(st: Study):
    """Sec. 4.4.3: stability grows with sintering time and confining pressure."""
    parts, ok = [], True
    for n in st.grid.n:
        for p in st.grid.p:
            big = [st.res(sr.VIBRATE, n, p, t)["largest_fragment"] / n for t in st.grid.t_s]
            ok &= _monotone(big, 0.05)
            parts.append(f"N={n}, p={p:g}: " + ", ".join(f"{b:.2f}" for b in big))
    pressure = [(st.res(sr.VIBRATE, n, 100.0, t)["largest_fragment"], st.res(sr.VIBRATE, n, 10.0, t)[
        "largest_fragment"]) for n in st.grid.n for t in st.grid.t_s]
    wins = sum(a >= b for a, b in pressure)
    return Statement("Sec. 4.4.3", "The sample becomes more and more stable with increasing sintering time and "
                     "confining pressure", "more stable",
                     "largest fragment / N over t_s: " + "; ".join(parts) + f"; p = 100 at least as stable in {wins} "
                     f"of {len(pressure)}", bool(ok and wins >= 0.75 * len(pressure)),
                     "non-decreasing in t_s within 0.05; p = 100 at least as stable in 3/4 of the samples")


CHECKS = (_prep_density, _density_rises_with_ts, _densification_early, _density_rises_with_p, _nu_after_sintering,
          _nu_after_cooling, _cooling_increase, _densification, _three_particles,
          _reorganisation_matters_more_at_low_p, _no_expansion, _k1_history, _coordination, _coordination_order,
          _coordination_dips, _overlap_mean, _overlap_width_on_cooling, _forces_hot_and_cold, _forces_equal_strength,
          _force_width_grows, _force_narrows, _tangential_weaker, _friction_bound, _full_friction_rarer,
          _compression_density, _compression_density_change_grows, _failure_grows, _stiffness_ratio, _strength_jump,
          _size_effects, _fig20, _vibration, _vibration_pieces, _vibration_order)


def statements_table(items: list[Statement]) -> str:
    rows = [[k + 1, s.source, s.statement, s.paper, s.ours, "yes" if s.holds else "**no**", s.tolerance]
            for k, s in enumerate(items)]
    return md_table(["#", "where", "statement", "paper", "ours", "holds", "tolerance"], rows)
