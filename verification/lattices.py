"""The pipe network against 3D FE of periodic packings: cubic lattices over their necks, and random packings.

Every packing here is periodic and mirror-symmetric, so the FE (:mod:`fem_neck.lattice`) solves its mirror cell
with two-sided bounds, and the DEM runs the same packing in a periodic box with a temperature drop per period along
z (:mod:`dem.geometry.periodic`): both give the infinite packing's ``k_eff`` along z with no wall or side effect, and any
difference is the network's own error.

* **Lattices**: simple, body- and face-centred cubic (coordination 6, 8, 12) over the necks their geometry allows,
  ``a/r`` from 0.1 up to where the necks of one particle touch (``sin`` of half the bond angle: 0.707, 0.577, 0.5).
* **Random packings**: :func:`verification.packings.mirror_packing` -- 80 spheres per period, radii +-15 %,
  jammed then sintered to a mean overlap ``h/r_min`` (coordination ~4-5, packing fraction ~0.4, necks
  ``a/r`` 0.15-0.6); none of them entered the ``shared-body`` law, which is derived, not fitted.

Compared: every DEM conductance law, and ``fe-pair``, the network whose every bond has the exact FE conductance of
its own pair (:func:`fem_neck.conduction.pair_conductance`): no law error is left there, so its error is that of the
pipe-network idea itself -- the necks of one particle sharing its body. ``phi kappa`` (the solid fraction) is the
Wiener bound: no microstructure conducts more.
"""

from __future__ import annotations

import functools
import hashlib
import json
import pathlib
import time

import numpy as np

from fem_neck import lattice
from fem_neck.geometry import overlap_for_neck
from verification.report import jsonable, save_figure

LAWS = ("rojek", "argento-bouvard", "fit", "shared-body", "zohdi")
NETWORK_ONLY = "fe-pair"
NECKS = {"sc": (0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.68),
         "bcc": (0.1, 0.2, 0.3, 0.4, 0.45, 0.52, 0.56),
         "fcc": (0.1, 0.2, 0.3, 0.35, 0.4, 0.44, 0.48)}
QUICK_NECKS = {"sc": (0.4,), "bcc": (0.4,), "fcc": (0.4,)}
RANDOM = ((1, 0.05), (2, 0.07), (3, 0.1))  # (seed, mean overlap h / r_min) of the mirror packings
RTOL, QUICK_RTOL = 3e-4, 1e-2  # gap of the FE bounds
RANDOM_RTOL = 2e-3
# k_eff / kappa of lattice cells from NGSolve (verification.ngsolve_cell: its own OCC geometry, mesh and hp refinement
# toward the neck circles, H1 of order p curved to order p, hp levels = p): the independent references of the
# periodic-cell FE. Order 6 for SC and BCC at h/r = 0.08 and SC at 0.02, order 5 for the others. Orders 4, 5, 6
# converge geometrically (each step 0.1-0.3 of the last): the order-6 values are within 1e-6 relative of the limit,
# the order-5 ones within 4e-6 (a fifth of their step from order 4).
REFERENCES = {("sc", 0.08): 0.3375947, ("sc", 0.02): 0.1714669, ("bcc", 0.08): 0.5280913, ("bcc", 0.02): 0.2816835,
              ("fcc", 0.08): 0.7056352, ("fcc", 0.02): 0.4121986}


# the modules and packages of fem_neck that the periodic-cell FE computes with: its own package, the cluster's meshing
# (size fields, tetrahedra), gmsh's session, the neck geometry, the curved mesh, both bounds' solvers and quadrature
FE_MODULES = ("lattice", "cluster", "shapes", "geometry", "curved", "primal", "dual", "pcg", "simplex")


def fe_files() -> list:
    """The source files of ``FE_MODULES`` (every module of a package), in a fixed order."""
    root = pathlib.Path(lattice.__file__).parents[1]
    files = []
    for name in FE_MODULES:
        package = root / name
        files += sorted(package.rglob("*.py")) if package.is_dir() else [root / f"{name}.py"]
    return files


def _code_version() -> str:
    """A hash of the FE code, so that cached FE results are recomputed when it changes."""
    return hashlib.sha1(b"".join(path.read_bytes() for path in fe_files())).hexdigest()[:12]


class FECache:
    """FE results by case and tolerance, kept in ``fe_cache.json`` of the section folder across runs."""

    def __init__(self, path: pathlib.Path):
        self.path = path
        self.data = json.loads(path.read_text()) if path.exists() else {}
        self.version = _code_version()

    def _full(self, key: str) -> str:
        return f"{key} @{self.version}"

    def __contains__(self, key: str) -> bool:
        return self._full(key) in self.data

    def put(self, key: str, value) -> None:
        """Store ``value`` under ``key`` and rewrite the file."""
        self.data[self._full(key)] = value
        self.path.write_text(json.dumps(jsonable(self.data), indent=1))

    def __getitem__(self, key: str):
        return self.data[self._full(key)]


def fe_cell(cell: lattice.PeriodicCell, rtol: float, workers: int = 2) -> dict:
    """``k_eff / kappa`` of the cell along z with its bounds
    (:func:`fem_neck.lattice.driver.effective_conductivity`, its two bounds in ``workers`` processes)."""
    res = lattice.effective_conductivity(cell, rtol=rtol, workers=workers)
    return {"k": res.k_eff_over_kappa, "lower": res.k_lower_over_kappa, "upper": res.k_upper_over_kappa,
            "error_estimate": res.error_estimate, "converged": res.converged, "elements": res.elements,
            "order": res.order, "meshes": len(res.levels), "seconds": res.seconds}


def _fe_job(key: str, cell: lattice.PeriodicCell, rtol: float) -> tuple[str, dict]:
    """One FE cell of the sweep, a pool's job: its cache key and :func:`fe_cell` (in a daemonic process -- a Dask
    worker -- both bounds in that process: it may not start another)."""
    import multiprocessing

    return key, fe_cell(cell, rtol, workers=1 if multiprocessing.current_process().daemon else 2)


def solve_cells(cells: dict, rtol: float, cache: FECache) -> list[dict]:
    """:func:`fe_cell` of every cell of ``cells`` (cache key -> cell), in their order; those not in ``cache`` are
    independent jobs of :func:`sinterheat.pool.run_jobs` -- here one after another, in this process (each FE
    already solves its two bounds in two processes), on a Dask cluster all at once -- each cached as it arrives."""
    from sinterheat.pool import run_jobs

    jobs = [(_fe_job, (key, cell, rtol)) for key, cell in cells.items() if key not in cache]
    for key, fe in run_jobs(jobs, workers=1, desc="lattice FE", unit="cell", done=len(cells) - len(jobs)):
        cache.put(key, fe)
    return [cache[key] for key in cells]


@functools.lru_cache(maxsize=None)
def fe_pair_conductance(r_i: float, r_j: float, h: float) -> float:
    """The axisymmetric FE conductance of one pair between its equatorial disks, kappa = 1 (W/K per W/(m K))."""
    from fem_neck.conduction import pair_conductance

    return float(pair_conductance(r_i, r_j, h, kappa=1.0, rtol=1e-8).K)


def dem_periodic(cell: lattice.PeriodicCell, law: str, neck: str = "newton",
                 closing_pores: dict | None = None, nodes: str = "particles", elements=None) -> float:
    """The DEM's ``k_eff / kappa`` of the periodic packing along z (drop of 1 K per period), for a conductance law
    or :data:`NETWORK_ONLY`, with the neck reading ``neck`` (``conductance.neck``), the network's ``nodes``
    (``conductance.nodes``: ``"necks"`` solves :mod:`dem.network.necks`, its particles' elements built by
    ``elements``, :func:`dem.network.necks.neck_network`'s) and, for ``shared-body`` on the union, the closing
    pores' calibration ``closing_pores`` (:func:`dem.laws.conductance.bond_conductances`)."""
    from dem.geometry.bonds import find_bonds
    from dem.laws.conductance import ConductanceSpec, bond_conductances
    from dem.geometry.particles import Material, Particles
    from dem.geometry.periodic import PeriodicBox
    from dem.network.heat import Network, periodic_heat_flow, steady

    box = PeriodicBox(cell.period, drop=[0.0, 0.0, 1.0])
    unit = Material(1.0, 1.0, 1.0, "unit")
    particles = Particles.from_arrays(cell.centres, cell.radii, np.zeros(cell.n), materials=(unit,))
    spec = ConductanceSpec(law="rojek" if law == NETWORK_ONLY else law, neck=neck, nodes=nodes)
    bonds = find_bonds(particles, contact=spec.contact, box=box)
    if nodes == "necks":
        from dem.network.necks import neck_network, steady_necks

        net = neck_network(spec, particles, bonds, box=box, closing_pores=closing_pores, elements=elements)
        return float(steady_necks(net).periodic_heat_flow[2] * box.lengths[2] / box.cross_section(2))
    if law == NETWORK_ONLY:
        K = np.array([fe_pair_conductance(*sorted((float(cell.radii[i]), float(cell.radii[j]))), float(h))
                      for i, j, h in zip(bonds.i, bonds.j, bonds.h)])
    else:
        K = bond_conductances(spec, particles, bonds, box=box, closing_pores=closing_pores)[0]
    net = Network(particles, bonds, K, np.zeros(0), np.zeros(0), box=box)
    T = steady(net, floating="mean").T
    return float(periodic_heat_flow(net, T)[2] * box.lengths[2] / box.cross_section(2))


def _rel(value: float, ref: float) -> float:
    return value / ref - 1.0


def lattice_rows(necks: dict, rtol: float, cache: FECache, names: tuple) -> list:
    cases = [(kind, x, overlap_for_neck(1.0, 1.0, x)) for kind, xs in necks.items() for x in xs]
    cells = {f"{kind} a/r={x:g} rtol={rtol:g}": lattice.lattice_cell(kind, h) for kind, x, h in cases}
    rows = []
    for (kind, x, h), cell, fe in zip(cases, cells.values(), solve_cells(cells, rtol, cache)):
        nets = {law: dem_periodic(cell, law) for law in names}
        rows.append({"case": f"{kind.upper()} a/r={x:g}", "kind": kind, "z": lattice.COORDINATION[kind],
                     "a_over_r": x, "h_over_r": h, "phi": cell.phi, "fe": fe, "network": nets,
                     "rel": {law: _rel(v, fe["k"]) for law, v in nets.items()}})
    return rows


def random_rows(cases, rtol: float, cache: FECache, names: tuple) -> list:
    from verification.packings import mirror_packing

    cells = {f"mirror packing seed={seed} overlap={overlap:g} rtol={rtol:g}": mirror_packing(10, overlap=overlap,
                                                                                         seed=seed)
             for seed, overlap in cases}
    rows = []
    for (seed, overlap), cell, fe in zip(cases, cells.values(), solve_cells(cells, rtol, cache)):
        i, j, s = cell.bonds()
        d = np.linalg.norm(cell.centres[j] + s * cell.period - cell.centres[i], axis=1)
        r_min = np.minimum(cell.radii[i], cell.radii[j])
        from fem_neck.geometry import neck_radius

        a = neck_radius(cell.radii[i], cell.radii[j], cell.radii[i] + cell.radii[j] - d) / r_min
        nets = {law: dem_periodic(cell, law) for law in names}
        rows.append({"case": f"random seed={seed} h/r={overlap:g}", "kind": "random", "n": cell.n, "bonds": len(i),
                     "z": 2.0 * len(i) / cell.n, "a_over_r": float(a.mean()), "a_range": [float(a.min()),
                                                                                          float(a.max())],
                     "phi": cell.phi, "fe": fe, "network": nets, "rel": {law: _rel(v, fe["k"]) for law, v in nets.items()}})
    return rows


def _table(rows, names) -> str:
    head = ("| packing | z | a/r | phi | k_FE / kappa [lower, upper] | "
            + " | ".join(f"{law}" for law in names) + " | Wiener phi/k_FE - 1 |")
    lines = [head, "|" + "---|" * (6 + len(names))]
    for r in rows:
        fe = r["fe"]
        a = (f"{r['a_over_r']:.3f}" if "a_range" not in r
             else f"{r['a_over_r']:.3f} ({r['a_range'][0]:.2f}-{r['a_range'][1]:.2f})")
        lines.append(f"| {r['case']} | {r['z']:.3g} | {a} | {r['phi']:.4f} | {fe['k']:.5f} [{fe['lower']:.5f}, "
                     f"{fe['upper']:.5f}] | " + " | ".join(f"{100 * r['rel'][law]:+.2f} %" for law in names)
                     + f" | {100 * _rel(r['phi'], fe['k']):+.1f} % |")
    return "\n".join(lines)


def _figure(rows, out_dir: pathlib.Path, names) -> list:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colours = {"sc": "tab:blue", "bcc": "tab:orange", "fcc": "tab:green", "random": "tab:red"}
    styles = {"fit": "--", NETWORK_ONLY: ":", "shared-body": "-"}
    shown = [law for law in styles if law in names]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 5.6))
    for kind in ("sc", "bcc", "fcc"):
        sel = sorted((r for r in rows if r["kind"] == kind), key=lambda r: r["a_over_r"])
        if not sel:
            continue
        x = [r["a_over_r"] for r in sel]
        for law in shown:
            ax1.plot(x, [100 * r["rel"][law] for r in sel], styles[law], marker="o", ms=3, color=colours[kind],
                     label=f"{kind.upper()} {law}")
        ax1.plot(x, [100 * _rel(r["phi"], r["fe"]["k"]) for r in sel], "-", lw=3, alpha=0.25, color=colours[kind],
                 label=f"{kind.upper()} Wiener bound phi kappa")
    rnd = [r for r in rows if r["kind"] == "random"]
    for law, marker in zip(shown, "v*s"):
        if rnd:
            ax1.plot([r["a_over_r"] for r in rnd], [100 * r["rel"][law] for r in rnd], marker, ls="none",
                     color=colours["random"], label=f"random {law}")
    ax1.axhline(0, color="grey", lw=0.8)
    for y in (-2, 2):
        ax1.axhline(y, color="grey", lw=0.6, ls="--")
    ax1.set_xlabel("a / r (random: mean over bonds)")
    ax1.set_ylabel("k_network / k_FE - 1  (%)")
    ax1.set_yscale("symlog", linthresh=2.0)
    ax1.set_title("network error against the periodic-cell FE (dashed: +-2 %)")
    ax1.legend(fontsize=6, ncol=3, loc="upper center", bbox_to_anchor=(0.5, -0.16))
    for law, marker in zip(shown, "o*s"):
        zs = [r["z"] for r in rows]
        sc = ax2.scatter(np.asarray(zs) + (shown.index(law) - 1) * 0.15, [100 * r["rel"][law] for r in rows],
                         c=[r["a_over_r"] for r in rows], cmap="viridis", vmin=0.1, vmax=0.7, marker=marker,
                         label=law)
    ax2.axhline(0, color="grey", lw=0.8)
    ax2.set_yscale("symlog", linthresh=2.0)
    for y in (-2, 2):
        ax2.axhline(y, color="grey", lw=0.6, ls="--")
    ax2.set_xlabel("coordination number z (random: mean)")
    ax2.set_ylabel("k_network / k_FE - 1  (%)")
    ax2.legend(fontsize=7)
    fig.colorbar(sc, ax=ax2, label="a / r")
    fig.tight_layout()
    return [save_figure(fig, out_dir / "lattices_network_error.png")]


def run(out_dir: pathlib.Path, quick: bool = False) -> dict:
    """Run the study into ``out_dir``; returns the section contract of :mod:`verification.report`."""
    from tqdm import tqdm

    names = (NETWORK_ONLY,) + LAWS
    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    cache = FECache(out_dir / "fe_cache.json")
    t0 = time.perf_counter()
    necks = QUICK_NECKS if quick else NECKS
    rows = []
    with tqdm(total=2, desc="lattices", leave=False) as bar:
        rows += lattice_rows(necks, QUICK_RTOL if quick else RTOL, cache, names)
        bar.update(1)
        if not quick:
            rows += random_rows(RANDOM, RANDOM_RTOL, cache, names)
        bar.update(1)
    (out_dir / "lattices.json").write_text(json.dumps(jsonable(rows), indent=1))
    figures = _figure(rows, out_dir, names)
    summary = {}
    for r in rows:
        summary[f"lattice {r['case']}"] = {"k_fe": r["fe"]["k"], "fe_error_estimate": r["fe"]["error_estimate"],
                                           **{f"rel_err_{law}": r["rel"][law] for law in names}}
    for law in names:
        summary[f"lattices worst |rel err| {law}"] = max(abs(r["rel"][law]) for r in rows)
    random = [r["fe"]["error_estimate"] for r in rows if r["kind"] == "random"]
    if random:
        summary["random packings widest FE gap"] = max(random)
    summary["lattices above Wiener bound shared-body"] = sum(
        (1.0 + r["rel"]["shared-body"]) * r["fe"]["k"] > r["phi"] for r in rows)
    md = [__doc__.split("\n\n", 1)[1].strip(), "",
          "Relative errors are network over FE minus one; the last column is how far the Wiener bound lies above "
          "the FE. FE: conforming P_p on tetrahedra that fill the exact solid (upper bound, the value) and the "
          "hybridised Raviart-Thomas flux of degree p - 1 (lower bound), refined toward the neck circles to a gap of "
          f"{QUICK_RTOL if quick else RTOL:g} (random packings {RANDOM_RTOL:g})"
          + (" -- quick run: one neck per lattice, no random packings." if quick else "."), "",
          _table(rows, names), "",
          f"Run time {time.perf_counter() - t0:.0f} s (FE results cached in fe_cache.json)."]
    return {"title": "Dense packings: the pipe network against periodic-cell FE", "markdown": "\n".join(md),
            "summary": summary, "figures": figures}
