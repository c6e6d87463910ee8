"""Luding, Manetsberger & Müllers 2005, Section 4, reproduced with the engine for moving particles.

The samples of Sec. 4 (Table 1, the bi-axial box of Fig. 1, the schedule of Fig. 7; :mod:`dem.sinter_protocol`)
are prepared, sintered for t_s, cooled and tested over the grid of :mod:`verification.sintering_runs` (N = 100 and
300, p = 10 and 100 N/m, t_s from 1e-4 to 1 s; ``--quick``: N = 100 and three t_s), in parallel and resumed where a
previous run stopped. The section draws the paper's figures from the runs -- nu(t), k1(t), the coordination number
and the wall stress (Figs. 8-11), the overlap and normal-force distributions after sintering and after cool-down
(Figs. 12-15), density and stress against strain in the compression test (Figs. 16-19), snapshots of the
compression and vibration tests (Figs. 20-22) -- runs the three-particle control of Sec. 4.1.3, the same protocol
in 3D with heated walls (necks, density and effective conductivity together), and writes every quantitative
statement of Section 4 beside our number (:func:`statements`; summary key ``statements``: ``statement``,
``paper``, ``ours``, ``holds``).
"""

from __future__ import annotations

import csv
import functools
import math
import pathlib
from dataclasses import asdict, dataclass

import numpy as np

from dem.sinter_protocol import T_PREPARE, Times
from verification import sintering_runs as sr
from verification.report import md_table, save_figure

TITLE = "Sintering mechanics: Luding, Manetsberger & Müllers 2005, Section 4"
DPI = 110


class Missing(LookupError):
    """A statement needs a run this grid does not hold (or that failed)."""


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


# ------------------------------------------------------------------------------------------------ the data
def _read_csv(path: pathlib.Path) -> dict:
    with path.open() as fh:
        rows = list(csv.DictReader(fh))
    return {k: np.array([float(r[k]) if r[k] not in ("", None) else np.nan for r in rows]) for k in rows[0]}


class Study:
    """The finished runs of one grid, read on demand (every accessor raises :class:`Missing` for a run that is not
    there)."""

    def __init__(self, root: pathlib.Path, grid: sr.Grid, results: dict):
        self.root = pathlib.Path(root)
        self.grid = grid
        self.results = results
        self.n_max, self.t_max, self.t_min = max(grid.n), max(grid.t_s), min(grid.t_s)

    def task(self, kind, n, p, t_s=None, seed=1, variant="") -> sr.Task:
        return sr.Task(kind, n, float(p), t_s, seed, variant)

    def res(self, kind, n, p, t_s=None, seed=1, variant="") -> dict:
        r = self.results.get(self.task(kind, n, p, t_s, seed, variant))
        if r is None or "error" in r:
            raise Missing(f"{kind} n={n} p={p:g} t_s={t_s}")
        return r

    @functools.lru_cache(maxsize=None)
    def series(self, task: sr.Task) -> dict:
        self.res(task.kind, task.n, task.p, task.t_s, task.seed, task.variant)
        return _read_csv(self.root / task.folder / "timeseries.csv")

    @functools.lru_cache(maxsize=None)
    def arrays(self, task: sr.Task) -> dict:
        self.res(task.kind, task.n, task.p, task.t_s, task.seed, task.variant)
        with np.load(self.root / task.folder / "analysis.npz") as f:
            return {k: f[k] for k in f.files}

    def contacts(self, kind, n, p, t_s) -> dict:
        return self.arrays(self.task(kind, n, p, t_s))

    def history(self, n, p, t_s) -> dict:
        """The time series of preparation, sintering and cooling joined on the time axis of Fig. 7 (a continued
        stage's first row, which repeats the previous stage's last, is dropped)."""
        times = Times(t_s=t_s)
        parts = [(self.series(self.task(sr.PREPARE, n, p)), 0.0, 0),
                 (self.series(self.task(sr.SINTER, n, p, t_s)), times.t_heat, 1),
                 (self.series(self.task(sr.COOL, n, p, t_s)), times.t_cool, 1)]
        keys = [k for k in parts[0][0] if all(k in s for s, _, _ in parts)]
        out = {k: np.concatenate([s[k][skip:] + (offset if k == "t" else 0.0) for s, offset, skip in parts])
               for k in keys}
        scale = 1.0 - 1e-4 * (120.0 - out["T_mean"])  # eq. 9 with Table 1's delta a_T
        out["mass_fraction"] = out["volume_fraction"] * ((1.0 - 1e-4 * (120.0 - T_PREPARE)) / scale) ** 2
        return out

    def compression(self, n, p, t_s) -> dict:
        """eps_zz = 1 - z/z0, sigma_zz (top wall), sigma_xx (right wall), nu; failure stress and strain at the peak
        of sigma_zz; stiffness, the slope of sigma_zz against eps_zz up to half the failure strain."""
        s = self.series(self.task(sr.COMPRESS, n, p, t_s))
        before = self.res(sr.COOL, n, p, t_s)
        z = -s["q_top"]
        eps = 1.0 - z / z[0]
        szz, sxx = s["wall_top"].copy(), s["wall_right"].copy()
        szz[0], sxx[0] = before["wall_stress"]["top"], before["wall_stress"]["right"]  # forces of the saved state
        k = int(np.argmax(szz))
        rise = eps <= 0.5 * eps[k]
        stiffness = float(np.polyfit(eps[rise], szz[rise], 1)[0]) if np.count_nonzero(rise) >= 3 else math.nan
        return {"eps": eps, "szz": szz, "sxx": sxx, "nu": s["volume_fraction"], "t": s["t"],
                "failure_stress": float(szz[k]), "failure_strain": float(eps[k]), "stiffness": stiffness}

    def three(self, p) -> list[float]:
        """Densification nu(t_f)/nu(t_heat) - 1 of the three-particle controls (one per seed)."""
        out = []
        times = Times(t_s=self.t_max)
        for seed in self.grid.three_seeds:
            s = self.series(self.task(sr.SCHEDULE, 3, p, self.t_max, seed))
            out.append(float(s["volume_fraction"][-1] / _at(s, times.t_heat)["volume_fraction"] - 1.0))
        return out


def _at(series: dict, t: float) -> dict:
    k = int(np.argmin(np.abs(series["t"] - t)))
    return {key: v[k] for key, v in series.items()}


def _pct(x: float) -> str:
    return f"{100.0 * x:.2f} %"


def _within(value: float, target: float, tol: float) -> bool:
    return bool(abs(value - target) <= tol)


def _monotone(values, slack: float) -> bool:
    """Non-decreasing up to ``slack`` between neighbours."""
    return bool(np.all(np.diff(np.asarray(values, dtype=float)) >= -slack))


def _spearman(x, y) -> float:
    rx, ry = np.argsort(np.argsort(x)), np.argsort(np.argsort(y))
    return float(np.corrcoef(rx, ry)[0, 1]) if len(x) > 2 else math.nan


# ------------------------------------------------------------------------------------------------ statements
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
    """Sec. 4.1.2: the preparation gives nu ~ 0.8."""
    rows = [(n, p, st.res(sr.PREPARE, n, p)["volume_fraction"]) for n in st.grid.n for p in st.grid.p]
    return Statement("Sec. 4.1.2, Fig. 9", "The initial preparation leads to a rather low density", "ν ≈ 0.8",
                     ", ".join(f"{v:.3f} (N={n}, p={p:g})" for n, p, v in rows),
                     all(_within(v, 0.8, 0.03) for _, _, v in rows), "±0.03")


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
    nu0, nu10, nu50, nu1 = (_at(h, t)["volume_fraction"] for t in (times.t_sinter, times.t_sinter + 0.1 * t_s,
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
    """Sec. 4.1.4: nu almost 0.92 after the longest sintering at p = 100 (t = 1.3)."""
    r = st.res(sr.SINTER, st.n_max, 100.0, st.t_max)
    return Statement("Sec. 4.1.4, Fig. 9", f"After the longest sintering (t_s = {st.t_max:g}, p = 100, N = "
                     f"{st.n_max}) the density is almost 0.92", "≈ 0.92",
                     f"{r['volume_fraction']:.4f} (mass density {r['mass_fraction']:.4f})",
                     _within(r["volume_fraction"], 0.92, 0.015), "±0.015 (solid fraction at the current radii)")


def _nu_after_cooling(st: Study):
    """Sec. 4.1.4: nu almost 0.94 after cool-down."""
    r = st.res(sr.COOL, st.n_max, 100.0, st.t_max)
    return Statement("Sec. 4.1.4, Fig. 9", "Only after cool-down the maximum density of almost 0.94 is reached (negative "
                     "thermal expansion)", "≈ 0.94", f"{r['volume_fraction']:.4f}",
                     _within(r["volume_fraction"], 0.94, 0.015), "±0.015",
                     "the cool-down shrinks particles and box alike (eq. 9): the solid fraction stays; see the text")


def _cooling_increase(st: Study):
    """Sec. 4.1.2/4.1.4: cool-down adds a final small increase in density."""
    a, b = st.res(sr.SINTER, st.n_max, 100.0, st.t_max), st.res(sr.COOL, st.n_max, 100.0, st.t_max)
    d_nu, d_m = b["volume_fraction"] - a["volume_fraction"], b["mass_fraction"] - a["mass_fraction"]
    return Statement("Sec. 4.1.2, Fig. 9", "Cooling down adds a final small increase in density", "small increase",
                     f"mass density {d_m:+.4f}; solid fraction at current radii {d_nu:+.4f}", bool(d_m > 0),
                     "mass density (mass / (ρ_p(80 °C) V)) rises", "the rise is the particles' thermal contraction: "
                     "the solid fraction counted with the current radii does not see it")


def _densification(st: Study):
    """Sec. 4.1.3: densification about 5 % (p = 10) and 16 % (p = 100)."""
    out = []
    for p, paper in ((10.0, 0.05), (100.0, 0.16)):
        d = st.res(sr.COOL, st.n_max, p, st.t_max)["volume_fraction"] / st.res(sr.PREPARE, st.n_max, p)[
            "volume_fraction"] - 1.0
        out.append(Statement("Sec. 4.1.3", f"Sintering densifies by about {100 * paper:g} % at p = {p:g}",
                             _pct(paper), f"{_pct(d)} (N={st.n_max}, t_s={st.t_max:g}; ν(t_f)/ν(t_heat) − 1)",
                             _within(d, paper, 0.3 * paper), "±30 % of the paper's value"))
    return out


def _three_particles(st: Study):
    """Sec. 4.1.3: three-particle control densifies by about 0.2 % (p = 10) and 8 % (p = 100)."""
    out = []
    for p, paper in ((10.0, 0.002), (100.0, 0.08)):
        d = st.three(p)
        out.append(Statement("Sec. 4.1.3", f"Three particles (no rearrangement) densify by about {100 * paper:g} % "
                             f"at p = {p:g}", _pct(paper), f"{_pct(float(np.mean(d)))} (seeds: "
                             f"{', '.join(_pct(x) for x in d)})", _within(float(np.mean(d)), paper,
                                                                         max(0.3 * paper, 0.005)),
                             "±30 % of the paper's value or ±0.5 points", "our walls sinter too: with three particles "
                             "the wall contacts are half the contacts; see the text"))
    return out


def _reorganisation_matters_more_at_low_p(st: Study):
    """Sec. 4.1.3: reorganisations matter more at low pressure (control / full smaller at p = 10)."""
    ratio = {}
    for p in (10.0, 100.0):
        full = st.res(sr.COOL, st.n_max, p, st.t_max)["volume_fraction"] / st.res(sr.PREPARE, st.n_max, p)[
            "volume_fraction"] - 1.0
        ratio[p] = float(np.mean(st.three(p))) / full
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
            tol = 0.3 if p == 10.0 else 0.25
            out.append(Statement("Sec. 4.2, Fig. 10", f"Coordination number after sintering (t_s = {st.t_max:g}), "
                                 f"N = {n}, p = {p:g}", f"≈ {paper:g}", f"{c:.2f}", _within(c, paper, tol),
                                 f"±{tol:g}", "we count every particle, rattlers included, and no wall contacts"))
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
    return Statement("Sec. 4.3.3", "The activated friction μ_t = f_t/(f_n − f_min) never exceeds μ(T, t)", "≤ μ(T, t)",
                     f"largest μ_t/μ(T, t) over {contacts} contacts of every final state: {worst:.12f}", bool(worst <= 1 + 1e-9),
                     "≤ 1 + 1e-9")


def _full_friction_rarer(st: Study):
    """Sec. 4.3.3: fully activated friction becomes less probable for longer sintering (after cool-down)."""
    parts, ok = [], True
    for p in st.grid.p:
        frac = []
        for t in (st.t_min, st.t_max):
            a = st.contacts(sr.COOL, st.n_max, p, t)
            good = np.isfinite(a["mu_t"]) & (a["mu_T"] > 0)
            frac.append(float(np.mean(a["mu_t"][good] >= 0.99 * a["mu_T"][good])))
        ok &= frac[1] < frac[0]
        parts.append(f"p={p:g}: {100 * frac[0]:.0f} % → {100 * frac[1]:.0f} %")
    return Statement("Sec. 4.3.3", "Contacts with fully activated friction (μ_t ≈ μ(T, t)) become less probable for "
                     "longer sintering", "less probable", "; ".join(parts) + " (μ_t ≥ 0.99 μ(T, t), after cool-down)",
                     bool(ok), "smaller fraction after the longest sintering")


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
    """Sec. 4.4.1-4.4.2, Figs. 17, 19: failure stress and strain grow with t_s and p."""
    out = []
    for key, name in (("failure_stress", "failure stress"), ("failure_strain", "failure strain")):
        parts, ok = [], True
        for n in st.grid.n:
            for p in st.grid.p:
                v = [st.compression(n, p, t)[key] for t in st.grid.t_s]
                rho = _spearman(np.asarray(st.grid.t_s), np.asarray(v))
                ok &= v[-1] > v[0] and (not np.isfinite(rho) or rho > 0.5)
                parts.append(f"N={n}, p={p:g}: {v[0]:.3g} → {v[-1]:.3g} (rank corr. {rho:.2f})")
        out.append(Statement("Sec. 4.4.1, Figs. 17, 19", f"The {name} increases with the sintering time",
                             "increases", "; ".join(parts), bool(ok),
                             "longest above shortest and Spearman rank correlation with t_s > 0.5"))
        wins, total = 0, 0
        for n in st.grid.n:
            for t in st.grid.t_s:
                total += 1
                wins += st.compression(n, 100.0, t)[key] > st.compression(n, 10.0, t)[key]
        out.append(Statement("Sec. 4.4.1, Figs. 17, 19", f"The {name} increases with the confining pressure",
                             "increases", f"larger at p = 100 in {wins} of {total} (N, t_s)",
                             wins >= 0.75 * total, "in at least 3/4 of the samples"))
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
                     "slope fitted up to half the failure strain")


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
    count = len(sr.FIG20_TIMES) + 1
    attractive = [int(np.count_nonzero(a[f"snap{k}_fn"] < 0)) for k in range(count)]
    frag = st.res(sr.COMPRESS, n, p, st.t_max)
    before = st.res(sr.COOL, n, p, st.t_max)
    return Statement("Sec. 4.4.3, Fig. 20", f"During compression (N = {n}, p = {p:g}, t_s = {st.t_max:g}) the lines of "
                     "strong attraction are destroyed and the sample fragments", "qualitative",
                     f"attractive contacts {attractive[0]} at t = {sr.FIG20_TIMES[0]:g} s → {attractive[-2]} at "
                     f"{sr.FIG20_TIMES[-1]:g} s; fragments {before['fragments']} before, {frag['fragments']} after "
                     f"(largest {frag['largest_fragment']})", bool(attractive[-2] < attractive[0]
                                                                    and frag["fragments"] > before["fragments"]),
                     "fewer attractive contacts, more fragments")


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
        ax[2, 0].plot(h100["t"], h100["volume_fraction"], color=c)
        ax[3, 0].plot(h10["t"], h10["volume_fraction"], color=c)
    ax[0, 0].set_ylabel("T (°C)")
    ax[1, 0].set_ylabel("k1(T, t) / k1")
    ax[1, 0].set_yscale("log")
    ax[2, 0].set_ylabel("ν (p = 100)")
    ax[3, 0].set_ylabel("ν (p = 10)")
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
                a = [st.res(sr.SINTER, n, p, t)["volume_fraction"] for t in st.grid.t_s]
                b = [st.res(sr.COOL, n, p, t)["volume_fraction"] for t in st.grid.t_s]
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
        a.set_ylabel("ν")
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
            ax[row, 1].set_ylabel(f"σ_zz (N/m)")
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
    from dem.plots import draw_packing

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
    """3D beyond the paper: nu, coordination, mean temperature and k_eff against time while sintering and cooling
    between heated walls."""
    n = st.grid.n3d
    s1 = st.series(st.task(sr.SINTER3D, n, sr.P3D))
    s2 = st.series(st.task(sr.COOL3D, n, sr.P3D))
    t = np.concatenate([s1["t"], s2["t"][1:] + sr.SINTER3D_TIME])
    fig, ax = _figure(4, 1, width=6.0, height=1.9, sharex=True)
    for a, key, label in zip(ax[:, 0], ("volume_fraction", "coordination", "T_mean", "effective_conductivity"),
                             ("ν", "C", "T mean (°C)", "k_eff (W/(m K))")):
        a.plot(t, np.concatenate([s1[key], s2[key][1:]]))
        a.set_ylabel(label, fontsize=8)
        a.axvline(sr.SINTER3D_TIME, color="k", ls=":", lw=0.7)
    ax[-1, 0].set_xlabel("t (s) from the start of heating (dotted: the walls cool)")
    fig.suptitle(f"3D, {n} spheres: walls at {sr.HOT3D[0]:g}/{sr.HOT3D[1]:g} °C, then {sr.COOL_3D[0]:g}/"
                 f"{sr.COOL_3D[1]:g} °C", fontsize=8)
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
                rows.append([n, f"{p:g}", f"{t_s:g}", f"{prep['volume_fraction']:.4f}", f"{a['volume_fraction']:.4f}",
                             f"{b['volume_fraction']:.4f}", f"{b['volume_fraction'] / prep['volume_fraction'] - 1:.2%}",
                             f"{a['coordination']:.2f}", f"{a['k1_factor']:.3g}", f"{c['failure_stress']:.0f}",
                             f"{c['failure_strain']:.4f}", f"{c['stiffness']:.3g}",
                             f"{v['largest_fragment']}/{v['fragments']}"])
    return md_table(["N", "p (N/m)", "t_s (s)", "ν(t_heat)", "ν(t_cool)", "ν(t_f)", "densification", "C(t_cool)",
                     "k1/k1(t_cool)", "σ_f (N/m)", "ε_f", "stiffness (N/m)", "vibration: largest/fragments"], rows)


def _statements_table(items: list[Statement]) -> str:
    rows = [[k + 1, s.source, s.statement, s.paper, s.ours, "yes" if s.holds else "**no**", s.tolerance]
            for k, s in enumerate(items)]
    return md_table(["#", "where", "statement", "paper", "ours", "holds", "tolerance"], rows)


def _three_table(st: Study) -> str:
    rows = []
    for p in st.grid.p:
        for seed in st.grid.three_seeds:
            try:
                s = st.series(st.task(sr.SCHEDULE, 3, p, st.t_max, seed))
            except Missing:
                continue
            times = Times(t_s=st.t_max)
            a, b = _at(s, times.t_heat), _at(s, s["t"][-1])
            rows.append([f"{p:g}", seed, f"{a['volume_fraction']:.4f}", f"{b['volume_fraction']:.4f}",
                         f"{b['volume_fraction'] / a['volume_fraction'] - 1:.2%}", f"{a['coordination']:.2f}"])
    return md_table(["p (N/m)", "seed", "ν(t_heat)", "ν(t_f)", "densification", "C at t_heat (1.33: a chain, 2: a triangle)"], rows)


def _three_d(st: Study) -> tuple[str, dict]:
    n = st.grid.n3d
    rows, summary = [], {}
    for kind, label in ((sr.PREPARE3D, "prepared (80 °C)"), (sr.SINTER3D, f"sintered, walls {sr.HOT3D[0]:g}/"
                                                                            f"{sr.HOT3D[1]:g} °C"),
                        (sr.COOL3D, f"cooled, walls {sr.COOL_3D[0]:g}/{sr.COOL_3D[1]:g} °C")):
        r = st.res(kind, n, sr.P3D)
        a = st.arrays(st.task(kind, n, sr.P3D))
        neck = a.get("neck_over_radius", np.zeros(0))
        rows.append([label, f"{r['volume_fraction']:.4f}", f"{r['coordination']:.2f}",
                     f"{np.mean(neck):.3f}" if len(neck) else "—", f"{np.percentile(neck, 90):.3f}" if len(neck) else "—",
                     "—" if r["effective_conductivity"] is None else f"{r['effective_conductivity']:.3g}",
                     f"{r['seconds']:.0f}"])
        summary[kind] = {"volume_fraction": r["volume_fraction"], "coordination": r["coordination"],
                         "neck_over_radius_mean": float(np.mean(neck)) if len(neck) else None,
                         "effective_conductivity": r["effective_conductivity"]}
    return md_table(["stage", "ν", "C", "neck a/r (mean)", "a/r (90 %)", "k_eff (W/(m K))", "CPU s"], rows), summary


def _speed(st: Study) -> tuple[str, dict]:
    n, p, t_s = st.n_max, max(st.grid.p), st.t_max
    parts = [st.res(kind, n, p, t_s if kind != sr.PREPARE else None) for kind in (sr.PREPARE, sr.SINTER, sr.COOL)]
    seconds = sum(r["seconds"] for r in parts)
    steps = sum(r["steps"] for r in parts)
    ns = 1e9 * seconds / (steps * n)
    stage_seconds = ", ".join(f"{r['seconds']:.1f}" for r in parts)
    text = (f"The whole schedule for N = {n}, p = {p:g}, t_s = {t_s:g} ({Times(t_s=t_s).t_f:g} s simulated, {steps} "
            f"steps of {Times(t_s=t_s).t_f / steps:.3g} s) took {seconds:.1f} s in three stages "
            f"({stage_seconds} s: preparation, heating and sintering, cooling and "
            f"relaxation), {ns:.0f} ns per particle-step, in a worker process sharing the machine with the other "
            f"runs of this grid (and whatever else ran). The target is 60 s; "
            f"`python -m verification.sintering_runs 300 100 1` times it in one process alone.")
    return text, {"seconds": seconds, "steps": steps, "ns_per_particle_step": ns, "n": n, "p": p, "t_s": t_s}


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
        three_d_table, three_d = _three_d(st)
    except Missing as exc:
        three_d_table, three_d = f"*not run: {exc}*", {}
    try:
        speed_text, speed = _speed(st)
    except Missing as exc:
        speed_text, speed = f"*not run: {exc}*", {}
    cpu = sum(r.get("seconds", 0.0) for r in results.values())
    md = [
        f"The protocol of Sec. 4 with Table 1 ({len(results)} runs, {cpu / 60:.1f} min of CPU in worker processes, "
        f"resumed from `runs/`): N = {', '.join(map(str, grid.n))}; p = {', '.join(f'{p:g}' for p in grid.p)} N/m; "
        f"t_s = {', '.join(f'{t:g}' for t in grid.t_s)} s{' (--quick)' if quick else ''}. "
        f"**{holding} of {len(items)} statements hold** within the tolerances given beside them.",
        "",
        PROTOCOL_TEXT,
        "",
        "### Every quantitative statement of Section 4",
        "",
        _statements_table(items),
        "",
    ]
    if skipped:
        md += ["Not checked by this grid: " + "; ".join(skipped) + ".", ""]
    if failed:
        md += ["Runs that failed: " + "; ".join(f"`{k}`: {v}" for k, v in failed.items()) + ".", ""]
    md += [DISCUSSION_TEXT, "", "### The runs", "", _grid_table(st), "",
           "### The three-particle control (Sec. 4.1.3)", "", _three_table(st), "",
           "### Beyond the paper: 3D spheres sintered between heated walls", "", THREE_D_TEXT.format(n=grid.n3d), "", three_d_table, "",
           "### Speed", "", speed_text, ""]
    summary = {"statements": [{k: v for k, v in asdict(s).items()} for s in items],
               "sintering.statements_holding": holding, "sintering.statements_total": len(items),
               "sintering.not_checked": skipped, "sintering.failed_runs": failed, "sintering.speed": speed,
               "sintering.3d": three_d}
    return {"title": TITLE, "markdown": "\n".join(md), "summary": summary, "figures": figures}


PROTOCOL_TEXT = """\
**Protocol** (`dem.sinter_protocol`, every stage a scene; the runs in `runs/<stage>/<sample>/`). Disks of height
6 mm, a0 = 1 mm, radii uniform in a0 (1 ± 0.5), Table 1's material (`LUDING_TABLE1`), placed at random (solid
fraction 0.3) with speeds of 0.01 m/s in a square box whose left and bottom walls are fixed and whose right and top
walls are stress-controlled at p (eq. 1, m_w = 0.01 kg, γ_w = 0.2 kg/s). *Preparation* at 80 °C, frictionless,
walls included, for 0.2 s; at t_heat friction μ = 0.5 on (μ_w = 0 as in Table 1), *heating* to 140 °C in 0.1 s,
*sintering* for t_s with t0 = 0.1 s, *cooling* to 80 °C in 0.1 s and *relaxation* for 0.1 s (Sec. 4.1, t0 = 10³ s
outside sintering). The state after sintering (t_cool) and after relaxation (t_f) are saved; the cooled one starts
both tests. *Compression* (Sec. 4.4): right wall at σ_xx = p, top wall moving in at ε̇_zz = 1/s to ε_zz = 0.06, so
that the times of Fig. 20 are strains. *Vibration* (Figs. 21-22): the box walls removed, the sample on a floor
vibrating at 100 Hz with 0.2 mm amplitude for 0.1 s in gravity. ν is the solid fraction of the walls' box with the
current radii (eq. 9); the *mass density* divides the sample's mass by ρ_p at 80 °C times the box volume.
*Fragments* (`dem.fragments`): clusters joined by closed contacts whose tension capacity −f_min (eq. 15) holds at
least the weight of the lighter particle (a disk resting on another under its weight has a capacity ~10⁻⁹ of it, a
sintered contact ~10³-10⁴ of it). Stiffness: the slope of σ_zz against ε_zz up to half the failure strain (the
peak of σ_zz)."""

DISCUSSION_TEXT = """\
**Where ours differs, and why.**

- *Preparation's wall friction.* The paper switches "the wall friction" off at t_heat and reports a slight immediate
  densification from it; it does not say what the wall friction was before. We prepare frictionless, walls included:
  frictional walls acting on frictionless disks spin the wall disks up, a rotational energy (1e-4 J for 100 disks at
  p = 100) that nothing dissipates until the friction comes on. So nothing happens at t_heat here.
- *Density after cool-down (0.94).* Cooling from 140 to 80 °C shrinks every radius by 0.6 % (eq. 9). In our runs
  the box follows the particles: the solid fraction counted with the current radii stays where sintering left it,
  while the mass density (mass over ρ_p(80 °C) V) rises by the 1.2 % of the contraction. The paper's "almost 0.94
  after cool-down, due to negative thermal expansion" is about 2 % above its 0.92 after sintering, which neither of
  our measures reproduces; the paper does not say which volume it divides by.
- *Three-particle control.* With three particles half of the contacts are wall contacts, and our walls take the
  same sintering law as the particles (the paper gives μ_w for them and nothing else): the wall contacts sinter to
  their fluid overlap δ_fluid = 0.2 a_i as the particle pairs do, so our control densifies by more than the paper's
  (its numbers are "estimated", data not shown).
- *Coordination numbers* count every particle (rattlers too) and no wall contacts; the paper does not say.
- *Failure.* σ_zz is the top wall's force over the box width; failure is its largest value. The paper's tests ran
  at a strain rate it does not give; at 1/s the sample is quasi-static (the kinetic energy stays below 1e-4 of the
  work done) until it fails."""

THREE_D_TEXT = f"""\
The same protocol in 3D with the thermal network on: {{n}} spheres (a0 = 1 mm ± {sr.SPREAD3D:g}, Table 1's
material) prepared frictionless at 80 °C in a cube under {sr.P3D:g} Pa (three fixed walls, three stress walls; the
mean contact force of the paper's p = 100 N/m), then, instead of the prescribed schedule, the bottom wall held at
{sr.HOT3D[0]:g} °C and the top wall at {sr.HOT3D[1]:g} °C for {sr.SINTER3D_TIME:g} s (t0 = 0.1 s), the particles'
temperatures computed by the pipe network on their contacts (conductance law `fit`, Rojek's necks from the
overlaps; κ = {sr.CONDUCTIVITY3D:g} W/(m K), heat capacity scaled down to c = {sr.SPECIFIC_HEAT3D:g} J/(kg K) so
that heat crosses the sample in milliseconds, as t0 scales the sintering), then walls at {sr.COOL_3D[0]:g} and
{sr.COOL_3D[1]:g} °C for {sr.COOL3D_TIME:g} s. The effective conductivity is that of a steady solve of the network
between the two walls as it is. The network's temperatures are constant over each thermal step, so the engine sees
no cooling rate and would not freeze k1 on cooling (Sec. 3.4, end); the cooling stage uses t0 = {sr.T0_COOL3D:g} s
so that k1(T, t) follows k1(T) at once, as the freeze would."""
