"""The finished runs of the sintering section read back: time series, contacts and snapshots, and what is derived
from them (the joined history of Fig. 7, the compression test's failure and stiffness, the three-particle control,
the coordination number without rattlers and away from the walls). :class:`Missing` is raised for a run that is not there.
"""

from __future__ import annotations

import csv
import functools
import math
import pathlib

import numpy as np

from dem.laws.contact.luding import LUDING_TABLE1
from dem.laws.contact.state.sintering import radius_at
from verification.luding.protocol import T_PREPARE, Times
from verification.luding import runs as sr


class Missing(LookupError):
    """A statement needs a run this grid does not hold (or that failed)."""


def read_csv(path: pathlib.Path) -> dict:
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
        """The time series of ``task`` with ``t`` counted from the stage's start (its first row): a stage run from
        a saved state goes on with the state's clock."""
        self.res(task.kind, task.n, task.p, task.t_s, task.seed, task.variant)
        s = read_csv(self.root / task.folder / "timeseries.csv")
        s["t"] = s["t"] - s["t"][0]
        return s

    @functools.lru_cache(maxsize=None)
    def arrays(self, task: sr.Task) -> dict:
        self.res(task.kind, task.n, task.p, task.t_s, task.seed, task.variant)
        with np.load(self.root / task.folder / "analysis.npz") as f:
            return {k: f[k] for k in f.files}

    def state(self, task: sr.Task) -> dict:
        """The state saved at the end of ``task`` (:func:`dem.scene.state_file.load`)."""
        from dem.scene import state_file

        self.res(task.kind, task.n, task.p, task.t_s, task.seed, task.variant)
        return state_file.load(self.root / task.folder / "state.npz")

    def contacts(self, kind, n, p, t_s) -> dict:
        return self.arrays(self.task(kind, n, p, t_s))

    def history(self, n, p, t_s) -> dict:
        """The time series of preparation, sintering and cooling joined on the time axis of Fig. 7 (a continued
        stage's first row, which repeats the previous stage's last, is dropped), with the material density
        ``mass_fraction`` = M/(rho_p(80 °C) V): the solid fraction times (a(80 °C)/a(T))^2 of eq. 9 (Table 1's
        material, one temperature for every particle, as the protocol's schedule gives it)."""
        mat = LUDING_TABLE1
        times = Times(t_s=t_s)
        parts = [(self.series(self.task(sr.PREPARE, n, p)), 0.0, 0),
                 (self.series(self.task(sr.SINTER, n, p, t_s)), times.t_heat, 1),
                 (self.series(self.task(sr.COOL, n, p, t_s)), times.t_cool, 1)]
        keys = [k for k in parts[0][0] if all(k in s for s, _, _ in parts)]
        out = {k: np.concatenate([s[k][skip:] + (offset if k == "t" else 0.0) for s, offset, skip in parts])
               for k in keys}
        cold, hot = (radius_at(1.0, T, mat.T_melt, mat.expansion) for T in (T_PREPARE, out["T_mean"]))
        out["mass_fraction"] = out["volume_fraction"] * (cold / hot) ** 2
        return out

    def compression(self, n, p, t_s, variant: str = "", seed: int = 1) -> dict:
        """eps_zz = 1 - z/z0, sigma_zz (top wall), sigma_xx (right wall), nu; the failure (:func:`failure`) and the
        stiffness, the slope of sigma_zz against eps_zz while the stress rises from p to half way to failure."""
        s = self.series(self.task(sr.COMPRESS, n, p, t_s, seed, variant))
        before = self.res(sr.COOL, n, p, t_s, seed)
        z = -s["q_top"]
        eps = 1.0 - z / z[0]
        szz, sxx = s["wall_top"].copy(), s["wall_right"].copy()
        szz[0], sxx[0] = before["wall_stress"]["top"], before["wall_stress"]["right"]  # forces of the saved state
        k = failure(szz)
        rise = np.arange(len(szz)) <= max(2, int(np.argmax(szz[:k + 1] >= szz[0] + 0.5 * (szz[k] - szz[0]))))
        stiffness = float(np.polyfit(eps[rise], szz[rise], 1)[0])
        width = -(s["q_right"] + s["q_left"])
        work = np.concatenate([[0.0], np.cumsum(0.5 * (szz[1:] * width[1:] + szz[:-1] * width[:-1]) * np.diff(-z))])
        return {"eps": eps, "szz": szz, "sxx": sxx, "nu": s["volume_fraction"], "t": s["t"],
                "failure_stress": float(szz[k]), "failure_strain": float(eps[k]), "stiffness": stiffness,
                "kinetic_over_work": float(np.max(s["kinetic_energy"][:k + 1]) / work[k]) if work[k] > 0 else math.nan}

    def placement_failures(self, n, p, t_s, key: str) -> list[float]:
        """``key`` (``"failure_stress"`` or ``"failure_strain"``) of :meth:`compression` for each of the protocol's
        placements :data:`verification.luding.runs.PLACEMENTS`, one per placement."""
        return [self.compression(n, p, t_s, seed=seed)[key] for seed in sr.PLACEMENTS]

    def chain_densification(self, n, p, seed=1, variant: str = "") -> float:
        """Densification nu(t_f)/nu(t_heat) - 1 of one sample prepared, sintered for the longest t_s and cooled."""
        return (self.res(sr.COOL, n, p, self.t_max, seed, variant)["volume_fraction"]
                / self.res(sr.PREPARE, n, p, seed=seed, variant=variant)["volume_fraction"] - 1.0)

    def densification(self, p) -> list[float]:
        """:meth:`chain_densification` of the protocol's placements :data:`verification.luding.runs.PLACEMENTS` (N max),
        one per placement."""
        return [self.chain_densification(self.n_max, p, seed) for seed in sr.PLACEMENTS]

    def three(self, p, variant: str = "", seeds=None, t_s=None) -> list[float]:
        """Densification nu(t_f)/nu(t_heat) - 1 of the three-particle controls (one per seed), sintered for ``t_s``
        (default the longest)."""
        out = []
        for seed in self.grid.three_seeds if seeds is None else seeds:
            task = self.task(sr.SCHEDULE, 3, p, self.t_max if t_s is None else t_s, seed, variant)
            s = self.series(task)
            out.append(float(s["volume_fraction"][-1] / at(s, task.times.t_heat)["volume_fraction"] - 1.0))
        return out


def failure(stress) -> int:
    """Index of the failure of a stress-strain curve: the largest stress reached before the stress first falls
    below half of it (the first load drop); the largest of all when it never does."""
    stress = np.asarray(stress, dtype=float)
    peak = 0
    for k, value in enumerate(stress):
        if value > stress[peak]:
            peak = k
        elif value < 0.5 * stress[peak]:
            return peak
    return int(np.argmax(stress))


def at(series: dict, t: float) -> dict:
    """The row of ``series`` nearest to time ``t``."""
    k = int(np.argmin(np.abs(series["t"] - t)))
    return {key: v[k] for key, v in series.items()}


def without_rattlers(i, j, n: int) -> tuple[float, int]:
    """``(2 M'/N', N - N')``: the coordination number of the particles left after removing, again and again, those
    with fewer than two particle contacts (rattlers cannot carry a load), and how many were removed."""
    keep = np.ones(n, dtype=bool)
    while True:
        both = keep[i] & keep[j]
        degree = np.bincount(i[both], minlength=n) + np.bincount(j[both], minlength=n)
        drop = keep & (degree < 2)
        if not np.any(drop):
            return (2.0 * np.count_nonzero(both) / max(1, np.count_nonzero(keep))), int(n - np.count_nonzero(keep))
        keep &= ~drop


def bulk_coordination(a: dict, k: int = 0) -> tuple[float, int]:
    """``(C, n)``: the mean number of pair contacts of the ``n`` particles of snapshot ``k`` of an ``analysis.npz``
    (:func:`verification.luding.runs.snapshot`) that touch no wall."""
    x, r, i, j = a[f"snap{k}_x"], a[f"snap{k}_radius"], a[f"snap{k}_i"], a[f"snap{k}_j"]
    gap = x @ a[f"snap{k}_wall_normal"].T - a[f"snap{k}_wall_q"][None, :]
    bulk = ~np.any(gap < r[:, None], axis=1)
    degree = np.bincount(i, minlength=len(r)) + np.bincount(j, minlength=len(r))
    return float(np.mean(degree[bulk])), int(np.count_nonzero(bulk))
