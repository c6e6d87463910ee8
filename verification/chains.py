"""Collinear chains: the DEM pipe network against the FE of the same chain.

Each chain is N = 2..8 spheres on one axis with mixed radii (ratios up to 5) and mixed necks, given as
``a / min(r_k, r_k+1)`` per bond; the overlaps follow from the volume-conserving neck
(:func:`fem_neck.geometry.overlap_for_neck`). Both sides hold the two end particles at fixed temperatures:

* FE (:func:`fem_neck.conduction.chain_conductance`): axisymmetric conduction through the whole chain with T fixed
  on the outer equatorial planes of the end particles (their halves beyond the centre are cut off, as in the
  paper's Fig. 12/17 problems), every other surface insulated; the conductance to the FE's tolerance with its
  error estimate;
* DEM (:func:`dem.run` on :func:`dem.make_scene`): the end particles fixed at 1 and 0, steady solve of the pipe
  network, ``K = Q / Delta T`` from the heat flow into the cold particle, once per conductance law.

A pipe's half-conductance is defined from the particle's centre plane to the neck, which is where the FE holds
the end temperatures, so the two problems agree exactly when the pipe model is exact; the difference measures
the surrogate (uniform particle temperature, the law's K(a), independent halves). ``quick`` runs three short
chains.
"""

from __future__ import annotations

import json
import pathlib
from dataclasses import dataclass

import numpy as np
from matplotlib.figure import Figure

from dem import COPPER
from fem_neck.geometry import overlap_for_neck
from verification.report import md_table, save_figure

TITLE = "DEM against FE: collinear chains"
LAWS = ("rojek", "argento-bouvard", "fit", "zohdi")
KAPPA = COPPER.conductivity  # 394 W/(m K), copper as in Rojek 2022
RTOL = 1e-4
MM = 1e-3


@dataclass(frozen=True)
class Chain:
    """A chain: ``radii`` (m) and the neck of each bond as ``a / min(r_k, r_k+1)``."""

    name: str
    radii: tuple
    neck_ratios: tuple

    @property
    def necks(self) -> np.ndarray:
        r = np.asarray(self.radii)
        return np.asarray(self.neck_ratios) * np.minimum(r[:-1], r[1:])

    @property
    def overlaps(self) -> np.ndarray:
        r = np.asarray(self.radii)
        return np.array([overlap_for_neck(a, b, n) for a, b, n in zip(r[:-1], r[1:], self.necks)])

    def positions(self) -> np.ndarray:
        """Centres on the z axis: ``d_k = r_k + r_k+1 - h_k`` (Rojek 2022, eq. 21)."""
        r = np.asarray(self.radii)
        z = np.concatenate([[0.0], np.cumsum(r[:-1] + r[1:] - self.overlaps)])
        return np.column_stack([np.zeros_like(z), np.zeros_like(z), z])


def random_chain(name: str, n: int, seed: int, ratio: float = 5.0, neck=(0.1, 0.8)) -> Chain:
    """A seeded chain of ``n`` radii uniform in [1, ratio] mm and necks a/r_min uniform in ``neck``."""
    rng = np.random.default_rng(seed)
    radii = tuple(float(x) for x in rng.uniform(1.0, ratio, n) * MM)
    return Chain(name, radii, tuple(float(x) for x in np.round(rng.uniform(*neck, n - 1), 3)))


QUICK_CHAINS = (
    Chain("pair 1:3 (Rojek Sec. 6)", (1 * MM, 3 * MM), (0.419186,)),
    Chain("3: 1-2-1 mm", (1 * MM, 2 * MM, 1 * MM), (0.3, 0.6)),
    Chain("4: 2-1-5-3 mm", (2 * MM, 1 * MM, 5 * MM, 3 * MM), (0.2, 0.5, 0.7)),
)
FULL_CHAINS = QUICK_CHAINS + (
    Chain("2: equal, small neck", (1 * MM, 1 * MM), (0.05,)),
    Chain("3: equal, small and large necks", (1 * MM, 1 * MM, 1 * MM), (0.1, 0.8)),
    Chain("5: equal, growing necks", (1 * MM,) * 5, (0.1, 0.3, 0.5, 0.7)),
    Chain("6: alternating 1:5", (1 * MM, 5 * MM) * 3, (0.2, 0.4, 0.6, 0.8, 0.3)),
    random_chain("7: random (seed 7)", 7, seed=7),
    random_chain("8: random (seed 8)", 8, seed=8),
)


def dem_conductance(chain: Chain, law: str) -> float:
    """Steady DEM conductance (W/K) of the chain with its end particles held at 1 and 0."""
    from dem import make_scene, run

    n = len(chain.radii)
    t = np.zeros(n)
    t[0] = 1.0
    fixed = np.zeros(n, dtype=bool)
    fixed[[0, -1]] = True
    result = run(make_scene(chain.positions(), np.asarray(chain.radii), t, fixed=fixed, materials=(COPPER,),
                            law=law, mode="steady"))
    if result.summary["bonds"] != n - 1:
        raise ValueError(f"chain {chain.name!r}: the DEM found {result.summary['bonds']} bonds, expected {n - 1}")
    return float(result.summary["boundary_heat_flow"]["particles"][str(n - 1)])


def fe_conductance(chain: Chain, rtol: float):
    from fem_neck.conduction import chain_conductance

    return chain_conductance(np.asarray(chain.radii), chain.overlaps, KAPPA, rtol=rtol)


def _figure(rows, out_dir: pathlib.Path) -> pathlib.Path:
    fig = Figure(figsize=(10, 4.5), layout="constrained")
    ax1, ax2 = fig.subplots(1, 2)
    x = np.arange(len(rows))
    width = 0.8 / len(LAWS)
    for k, law in enumerate(LAWS):
        err = [100.0 * r["rel_error"][law] for r in rows]
        ax1.bar(x + (k - (len(LAWS) - 1) / 2) * width, err, width, label=law)
        ax2.semilogy([r["min_neck"] for r in rows], [max(abs(e), 1e-3) for e in err], "o", label=law)
    ax1.set_xticks(x, [r["chain"].split(":")[0] for r in rows], rotation=30, fontsize=8)
    ax1.set(ylabel="(K_DEM - K_FE) / K_FE [%]", title="Chains: DEM against FE, per conductance law")
    ax1.axhline(0.0, color="k", lw=0.5)
    ax2.set(xlabel="smallest neck a / r_min in the chain", ylabel="|relative error| [%]",
            title="error against the smallest neck")
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    return save_figure(fig, out_dir / "chains_dem_vs_fe.png", dpi=120)


def run(out_dir: pathlib.Path, quick: bool = False) -> dict:
    """FE and DEM of every chain (three in quick mode); table, figure and summary ``chains.<chain>.<law>``."""
    import sys

    from tqdm import tqdm

    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    chains = QUICK_CHAINS if quick else FULL_CHAINS
    rows, summary = [], {}
    for chain in tqdm(chains, desc="chains", file=sys.stderr, leave=False):
        fe = fe_conductance(chain, RTOL)
        k_dem = {law: dem_conductance(chain, law) for law in LAWS}
        rel = {law: k_dem[law] / fe.K - 1.0 for law in LAWS}
        rows.append({"chain": chain.name, "radii_mm": [r / MM for r in chain.radii],
                     "neck_ratios": list(chain.neck_ratios), "min_neck": min(chain.neck_ratios), "K_fe": fe.K,
                     "fe_error_estimate": fe.error_estimate, "K_dem": k_dem, "rel_error": rel})
        for law in LAWS:
            summary[f"chains.{chain.name}.{law}"] = {"K_dem": k_dem[law], "K_fe": fe.K, "rel_error": rel[law],
                                                     "fe_error_estimate": fe.error_estimate}
    fig_path = _figure(rows, out_dir)
    table = md_table(
        ["chain", "radii [mm]", "necks a/r_min", "K_FE [W/K] (est. rel. error)"]
        + [f"K_DEM {law} (rel. error)" for law in LAWS],
        [(r["chain"], ", ".join(f"{x:.3g}" for x in r["radii_mm"]), ", ".join(f"{x:g}" for x in r["neck_ratios"]),
          f"{r['K_fe']:.6g} ({r['fe_error_estimate']:.1e})")
         + tuple(f"{r['K_dem'][law]:.5g} ({100 * r['rel_error'][law]:+.2f} %)" for law in LAWS) for r in rows],
    )
    worst = {law: max(rows, key=lambda r: abs(r["rel_error"][law])) for law in LAWS}
    lines = [f"- `{law}`: relative error from {100 * min(r['rel_error'][law] for r in rows):+.2f} % to "
             f"{100 * max(r['rel_error'][law] for r in rows):+.2f} % (worst: {worst[law]['chain']})" for law in LAWS]
    md = "\n".join([
        f"Copper (κ = {KAPPA:g} W/(m K)); FE to rtol {RTOL:g} with the end temperatures on the end particles' "
        "outer equatorial planes; DEM steady solve with the end particles fixed. Relative error = "
        "K_DEM / K_FE − 1.",
        "",
        table,
        "",
        *lines,
        "",
        "`zohdi` (κ A_c / |x_i − x_j|, Zohdi 2014 eq. 33) conducts through a rod of the contact's cross-section "
        "over the whole centre distance and ignores the spreading of heat into the spheres, so it cannot follow "
        "sintered necks; the linear laws (eqs. 40, 42) miss the small-neck limit 4κa and the bend above "
        "a/r ≈ 0.7, which the `fit` law (the FE's full-range law, each half at its own a/r_i) captures.",
    ])
    (out_dir / "chains.json").write_text(json.dumps(rows, indent=1) + "\n")
    return {"title": TITLE, "markdown": md, "summary": summary, "figures": [fig_path]}
