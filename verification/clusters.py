"""3D clusters: the pipe-network DEM against full 3D finite-element conduction.

Clusters (radii ~1 mm, copper kappa = 394 W/(m K); relative errors do not depend on either):

* ``triangle`` -- three equal spheres bonded in a ring, plus two *leads*;
* ``tetrahedron`` -- four equal spheres, all six bonds, plus two leads;
* ``bent chain`` -- five spheres of radii 1.0, 1.6, 0.8, 1.3, 1.0 mm along a non-planar zigzag (bond angles 135, 90,
  120 degrees, with torsion);
* ``random`` -- 10-20 spheres of radii 0.6-1.4 mm grown by seeded random attachment, a third of them placed in the
  pocket of two bonded neighbours so that rings and coordination numbers up to 4-5 occur.

Boundary conditions. Heat enters and leaves through two one-bond particles cut by the plane through their centre
normal to their bond (``fem_neck.cluster.Terminal(kind="plane")``), held at 1 K and 0 K. Such a half particle is
exactly the body that defines the pipe's half-conductance (Rojek 2022, Fig. 12 and eq. 36), so the DEM -- that
particle held at its temperature, with that bond's law -- represents the boundary exactly: any difference is the
surrogate's own error (the law and the lumped particle temperature), not a boundary artefact. The triangle and the
tetrahedron have no one-bond particle, so each gets two leads: equal spheres bonded to two of its particles,
pointing away from the centroid. For the compact clusters a second variant holds two particles' *centre balls*
(radius r/4) instead -- a "centre temperature", which the pipe network does not represent exactly; its rows show how
much that choice alone costs.

Measured: the effective conductance ``K = Q/(T_hot - T_cold)`` and each free particle's mean temperature (volume
average over the particle's own share, ``4/3 pi r^3``), FE against the DEM steady network for each conductance law.
The FE error bar (full run) comes from three mesh levels, every size 1.6x apart
(:func:`fem_neck.cluster.cluster_conductance`, :func:`fem_neck.accuracy.mesh_sequence_estimate`): the last change
over the slower of the observed and the neck-corner convergence rate, times 1.25. Checked against axisymmetric
chains and pairs (``tests/test_cluster.py``), it covers the true FE error of K by 1.2-3.2x and that of the
particle mean temperatures by 2.2-6.2x. A network error is *resolved* when it exceeds the FE error. The error map puts the per-particle temperature error against
the particle's coordination number and its mean neck size a/r.

The pseudo-law ``fe-pair`` gives every pipe the axisymmetric FE conductance of its own pair
(``fem_neck.conduction.pair_conductance``, between equatorial disks): no law error is left, so its error is that of
the pipe-network idea itself -- several necks sharing one particle, one temperature per particle.
"""

from __future__ import annotations

import functools
import pathlib
import time
from dataclasses import dataclass, replace

import numpy as np

from fem_neck.cluster import Cluster, Terminal, cluster_conductance
from fem_neck.geometry import overlap_for_neck
from sinterheat.interrupt import where
from verification.report import save_figure

KAPPA = 394.0
R0 = 1.0e-3
MESH_QUICK = {"size_neck": 0.3, "size_far": 0.5, "curvature": 12, "neck_cells": 0.5, "levels": 1}
MESH_FULL = {"size_neck": 0.2, "size_far": 0.35, "curvature": 16, "neck_cells": 2.0, "levels": 3}  # finest level


@dataclass(frozen=True)
class Case:
    """One cluster with its boundary: ``name``, ``family``, the :class:`Cluster` and its two terminals."""

    name: str
    family: str
    cluster: Cluster
    terminals: tuple


def _place(c_host, r_host, r_new, a, direction):
    """Centre of a sphere of radius ``r_new`` bonded to the host with neck radius ``a`` along ``direction``."""
    d = r_host + r_new - overlap_for_neck(r_host, r_new, a)
    return c_host + d * direction / np.linalg.norm(direction)


def with_leads(centres, radii, bonds, hosts, a_over_r):
    """Add a lead sphere (equal to its host) to each of ``hosts``, along centroid -> host; return the cluster and
    the indices of the two leads."""
    centres = [np.asarray(c, dtype=float) for c in centres]
    radii = list(radii)
    bonds = [tuple(b) for b in bonds]
    centroid = np.mean(centres, axis=0)
    leads = []
    for host in hosts:
        r = radii[host]
        centres.append(_place(centres[host], r, r, a_over_r * r, centres[host] - centroid))
        radii.append(r)
        bonds.append((host, len(radii) - 1))
        leads.append(len(radii) - 1)
    return Cluster(np.array(centres), np.array(radii), np.array(bonds)), leads


def triangle(a_over_r: float, leads: bool = True) -> Case:
    """Three equal spheres in a ring (bond angle 60 degrees; necks must stay below a/r = 0.5)."""
    r = R0
    d = 2 * r - overlap_for_neck(r, r, a_over_r * r)
    centres = d / np.sqrt(3.0) * np.array([[np.cos(t), np.sin(t), 0.0] for t in np.radians([90, 210, 330])])
    bonds = [(0, 1), (1, 2), (2, 0)]
    return _compact("triangle", centres, [r] * 3, bonds, a_over_r, leads)


def tetrahedron(a_over_r: float, leads: bool = True) -> Case:
    """Four equal spheres, all six bonds (bond angle 60 degrees)."""
    r = R0
    d = 2 * r - overlap_for_neck(r, r, a_over_r * r)
    verts = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], dtype=float)
    centres = verts * d / np.linalg.norm(verts[0] - verts[1])
    bonds = [(p, q) for p in range(4) for q in range(p + 1, 4)]
    return _compact("tetrahedron", centres, [r] * 4, bonds, a_over_r, leads)


def _compact(family, centres, radii, bonds, a_over_r, leads):
    if leads:
        cluster, (hot, cold) = with_leads(centres, radii, bonds, (0, 1), a_over_r)
        terminals = (Terminal(hot, 1.0), Terminal(cold, 0.0))
        name = f"{family} a/r={a_over_r:g} (leads)"
    else:
        cluster = Cluster(np.asarray(centres), np.asarray(radii), np.asarray(bonds))
        terminals = (Terminal(0, 1.0, "core"), Terminal(1, 0.0, "core"))
        name = f"{family} a/r={a_over_r:g} (centre balls)"
    return Case(name, family + ("" if leads else " (centre balls)"), cluster, terminals)


def bent_chain(a_over_r: float) -> Case:
    """Five spheres of mixed radii along a non-planar zigzag; ``a_over_r`` is relative to each bond's smaller radius."""
    radii = R0 * np.array([1.0, 1.6, 0.8, 1.3, 1.0])
    dirs = np.array([[0, 0, 1], [np.sin(np.radians(45)), 0, np.cos(np.radians(45))], [1, 0, 0],
                     [np.cos(np.radians(60)), np.sin(np.radians(60)), 0]], dtype=float)
    centres = [np.zeros(3)]
    for k, u in enumerate(dirs):
        a = a_over_r * min(radii[k], radii[k + 1])
        centres.append(_place(centres[-1], radii[k], radii[k + 1], a, u))
    cluster = Cluster(np.array(centres), radii, np.array([(k, k + 1) for k in range(4)]))
    return Case(f"bent chain a/r={a_over_r:g}", "bent chain", cluster, (Terminal(0, 1.0), Terminal(4, 0.0)))


def random_cluster(n: int, seed: int, a_range=(0.15, 0.55), r_range=(0.6, 1.4), max_tries: int = 2000) -> Case:
    """``n`` spheres grown by seeded random attachment (mixed radii and necks, some rings); terminals: the two
    one-bond particles farthest apart (the cluster is regrown until there are two)."""
    rng = np.random.default_rng(seed)
    for _ in range(50):
        radii = [R0 * rng.uniform(*r_range)]
        centres = [np.zeros(3)]
        bonds = []
        tries = 0
        while len(radii) < n and tries < max_tries:
            tries += 1
            r_new = R0 * rng.uniform(*r_range)
            host = int(rng.integers(len(radii)))
            a = rng.uniform(*a_range) * min(r_new, radii[host])
            new_bonds = [(host, len(radii))]
            partners = [q for p, q in bonds if p == host] + [p for p, q in bonds if q == host]
            if partners and rng.uniform() < 0.35:
                # a pocket: bond to the host and to one of its neighbours (a ring of three)
                other = int(rng.choice(partners))
                a2 = rng.uniform(*a_range) * min(r_new, radii[other])
                c = _pocket(centres[host], radii[host], centres[other], radii[other], r_new, a, a2, rng)
                if c is None:
                    continue
                new_bonds.append((other, len(radii)))
            else:
                c = _place(centres[host], radii[host], r_new, a, rng.normal(size=3))
            trial = Cluster(np.array(centres + [c]), np.array(radii + [r_new]), np.array(bonds + new_bonds))
            try:  # keep unbonded spheres and neighbouring necks apart, so the meshes stay reasonable
                trial.validate(gap=0.1 * R0, angle_margin=np.radians(8))
            except ValueError:
                continue
            centres.append(c)
            radii.append(r_new)
            bonds += new_bonds
        cluster = Cluster(np.array(centres), np.array(radii), np.array(bonds))
        leaves = np.flatnonzero(cluster.degree() == 1)
        if len(radii) == n and len(leaves) >= 2:
            dist = np.linalg.norm(cluster.centres[leaves][:, None] - cluster.centres[leaves][None], axis=2)
            p, q = np.unravel_index(np.argmax(dist), dist.shape)
            return Case(f"random n={n} seed={seed}", "random", cluster,
                        (Terminal(int(leaves[p]), 1.0), Terminal(int(leaves[q]), 0.0)))
    raise RuntimeError(f"random cluster n={n} seed={seed}: could not grow a valid cluster")


def _pocket(c1, r1, c2, r2, r_new, a1, a2, rng):
    """A centre at distance d1 from c1 and d2 from c2 (both bonds' neck radii a1, a2), random on that circle."""
    d1 = r1 + r_new - overlap_for_neck(r1, r_new, a1)
    d2 = r2 + r_new - overlap_for_neck(r2, r_new, a2)
    axis = c2 - c1
    L = np.linalg.norm(axis)
    axis /= L
    x = (d1**2 - d2**2 + L**2) / (2 * L)
    rho2 = d1**2 - x**2
    if rho2 <= 0:
        return None
    perp = np.cross(axis, rng.normal(size=3))
    perp /= np.linalg.norm(perp)
    return c1 + x * axis + np.sqrt(rho2) * perp


def all_cases(quick: bool) -> list[Case]:
    """The clusters of the study (quick: one neck size per family and a 10-particle random cluster)."""
    if quick:
        return [triangle(0.3), tetrahedron(0.3), bent_chain(0.4), random_cluster(10, seed=1)]
    out = []
    for x in (0.15, 0.3, 0.45):
        out += [triangle(x), tetrahedron(x)]
    out += [triangle(0.3, leads=False), tetrahedron(0.3, leads=False)]
    out += [bent_chain(x) for x in (0.15, 0.3, 0.45, 0.6)]
    out += [random_cluster(n, seed=seed) for n, seed in ((12, 1), (14, 3), (16, 2), (20, 4))]
    return out


# ---------------------------------------------------------------------------------------------------------------
# The DEM side
# ---------------------------------------------------------------------------------------------------------------

LAWS = ("rojek", "argento-bouvard", "fit", "shared-body", "zohdi")


NETWORK_ONLY = "fe-pair"  # every pipe gets the FE conductance of its own pair: no law error, only the network's


def available_laws() -> tuple:
    """The laws of :data:`LAWS` that can be evaluated here (``fit`` and ``shared-body`` need the shipped fit file)."""
    from fem_neck import law as laws

    try:
        laws.ConductanceLaw.default()
    except ValueError:
        return tuple(x for x in LAWS if x not in ("fit", "shared-body"))
    return LAWS


def compared_laws() -> tuple:
    """What the clusters are compared with: the network-only pseudo-law, then the available DEM laws."""
    return (NETWORK_ONLY,) + available_laws()


@functools.lru_cache(maxsize=None)
def fe_pair_conductance(r_i: float, r_j: float, h: float) -> float:
    """Steady axisymmetric FE conductance of one sintered pair between its equatorial disks (W/K), cached."""
    from fem_neck import conduction

    return float(conduction.pair_conductance(r_i, r_j, h, kappa=KAPPA).K)


def dem_steady(cluster: Cluster, terminals, law: str) -> tuple[float, np.ndarray]:
    """The DEM's steady pipe network of the same cluster (Rojek 2022, eqs. 2-4 with dT/dt = 0): the effective
    conductance (W/K) and every particle's temperature.

    The DEM finds the bonds itself from the overlaps (:func:`dem.network.heat.build_network`); they must be the cluster's.
    The terminals are its fixed particles. ``law`` is a DEM conductance law, or :data:`NETWORK_ONLY`.
    """
    from dem.laws.conductance import ConductanceSpec
    from dem.geometry.particles import Material, Particles
    from dem.network.heat import boundary_heat_flow, build_network, steady

    T0 = np.zeros(cluster.n)
    fixed = np.zeros(cluster.n, dtype=bool)
    for t in terminals:
        T0[t.particle] = t.T
        fixed[t.particle] = True
    copper = Material(KAPPA, 8960.0, 385.0, "copper")
    particles = Particles.from_arrays(cluster.centres, cluster.radii, T0, materials=(copper,), fixed=fixed)
    net = build_network(particles, spec=ConductanceSpec(law="rojek" if law == NETWORK_ONLY else law))
    bonds = net.bonds
    found = {(int(i), int(j)) for i, j in zip(bonds.i, bonds.j)}
    if found != {tuple(sorted(map(int, b))) for b in cluster.bonds}:
        raise RuntimeError(f"the DEM found bonds {sorted(found)}, the cluster has {cluster.bonds.tolist()}")
    if law == NETWORK_ONLY:
        net = replace(net, K_pairs=np.array([
            fe_pair_conductance(float(cluster.radii[i]), float(cluster.radii[j]), float(h))
            for i, j, h in zip(bonds.i, bonds.j, bonds.h)]))
    T = steady(net).T
    into = boundary_heat_flow(net, T)["particles"]
    t_hot = max(t.T for t in terminals)
    t_cold = min(t.T for t in terminals)
    Q = -sum(into[t.particle] for t in terminals if t.T == t_hot)
    return Q / (t_hot - t_cold), T


# ---------------------------------------------------------------------------------------------------------------
# The comparison
# ---------------------------------------------------------------------------------------------------------------


def fe_solve(case: Case, quick: bool) -> dict:
    """FE of one case: ``K`` and particle means on the finest level, with their error estimates (full run)."""
    t0 = time.perf_counter()
    res = cluster_conductance(case.cluster, case.terminals, kappa=KAPPA, **(MESH_QUICK if quick else MESH_FULL))
    nan = float("nan")
    return {"K": res.K, "T": res.particle_T, "dofs": res.solution.dofs, "cmesh": res.cmesh, "sol": res.solution,
            "error": nan if res.error_estimate is None else res.error_estimate,
            "T_error": nan if res.T_error_estimate is None else res.T_error_estimate,
            "observed_order": nan if res.sequence is None or res.sequence.observed_order is None
            else res.sequence.observed_order,
            "seconds": time.perf_counter() - t0}


def particle_neck_ratio(cluster: Cluster) -> np.ndarray:
    """Mean a/r_k over each particle's bonds."""
    a = cluster.necks().a
    i, j = cluster.bonds.T
    total = np.bincount(i, a / cluster.radii[i], cluster.n) + np.bincount(j, a / cluster.radii[j], cluster.n)
    return total / np.maximum(cluster.degree(), 1)


def compare(case: Case, fe: dict, names: tuple) -> tuple[dict, list]:
    """Per-case and per-particle FE vs DEM errors for every law in ``names``."""
    cl = case.cluster
    fixed = {t.particle for t in case.terminals}
    free = np.array([k for k in range(cl.n) if k not in fixed])
    dT = max(t.T for t in case.terminals) - min(t.T for t in case.terminals)
    i, j = cl.bonds.T
    a = cl.necks().a
    row = {"case": case.name, "family": case.family, "n": cl.n, "bonds": len(i),
           "a_over_r_mean": float(np.mean(a / np.minimum(cl.radii[i], cl.radii[j]))),
           "z_max": int(cl.degree().max()), "K_fe": fe["K"], "fe_error": fe["error"], "fe_T_error": fe["T_error"],
           "fe_observed_order": fe["observed_order"], "dofs": fe["dofs"], "fe_seconds": fe["seconds"], "laws": {}}
    particles = []
    z = cl.degree()
    ratio = particle_neck_ratio(cl)
    for law in names:
        K_dem, T_dem = dem_steady(cl, case.terminals, law)
        err = (T_dem[free] - fe["T"][free]) / dT
        row["laws"][law] = {"K_dem": K_dem, "K_rel_err": K_dem / fe["K"] - 1.0,
                            "T_max_err": float(np.max(np.abs(err))), "T_rms_err": float(np.sqrt(np.mean(err**2)))}
        particles += [{"case": case.name, "family": case.family, "law": law, "particle": int(k), "z": int(z[k]),
                       "a_over_r": float(ratio[k]), "T_fe": float(fe["T"][k]), "T_dem": float(T_dem[k]),
                       "err": float(e)} for k, e in zip(free, err)]
    return row, particles


def _table(rows, names) -> str:
    """One row per cluster: the FE K with its error estimate, each law's K error with the FE error beside it
    (``±``), and the largest particle-temperature error with the FE's own temperature error estimate."""
    head = ("| cluster | n | bonds | z max | mean a/r | K_FE (W/K) | FE error | "
            + " | ".join(f"K {law} rel. err" for law in names) + " | FE T error | "
            + " | ".join(f"max abs dT {law}" for law in names) + " |")
    lines = [head, "|" + "---|" * (8 + 2 * len(names))]
    for r in rows:
        known = np.isfinite(r["fe_error"])  # not in a quick run (one mesh level)
        pm = f" ± {r['fe_error']:.2%}" if known else ""
        fe_K = f"{r['fe_error']:.2%}" if known else "—"
        fe_T = f"{r['fe_T_error']:.4f}" if known else "—"
        lines.append(f"| {r['case']} | {r['n']} | {r['bonds']} | {r['z_max']} | {r['a_over_r_mean']:.3f} | "
                     f"{r['K_fe']:.5g} | {fe_K} | "
                     + " | ".join(f"{r['laws'][law]['K_rel_err']:+.2%}{pm}" for law in names) + " | "
                     + f"{fe_T} | "
                     + " | ".join(f"{r['laws'][law]['T_max_err']:.3f}" for law in names) + " |")
    return "\n".join(lines)


def conclusions(rows, law: str = NETWORK_ONLY) -> str:
    """Per family: the range of ``law``'s K error, the largest FE error beside it, and how many of the clusters'
    errors the FE resolves (error larger than the FE's own estimate)."""
    lines = [f"| family | K {law} rel. err (range) | FE error (largest) | resolved |", "|---|---|---|---|"]
    for fam in dict.fromkeys(r["family"] for r in rows):
        sel = [r for r in rows if r["family"] == fam]
        err = [r["laws"][law]["K_rel_err"] for r in sel]
        fe = [r["fe_error"] for r in sel]
        resolved = sum(abs(e) > f for e, f in zip(err, fe))
        lines.append(f"| {fam} | {min(err):+.2%} … {max(err):+.2%} | {max(fe):.2%} | {resolved} of {len(sel)} |")
    return "\n".join(lines)


Z_BINS = ((1, 1), (2, 2), (3, 3), (4, 4), (5, 99))
A_BINS = ((0.0, 0.25), (0.25, 0.4), (0.4, 1.0))


def error_map(particles, law: str) -> str:
    """Markdown table: RMS particle-temperature error (units of the imposed difference) by coordination number and
    mean neck size, for one law (centre-ball variants excluded: their boundary is not exact)."""
    sel = [p for p in particles if p["law"] == law and "centre balls" not in p["family"]]
    lines = ["| coordination z | " + " | ".join(f"a/r in [{lo:g}, {hi:g})" for lo, hi in A_BINS) + " |",
             "|---|" + "---|" * len(A_BINS)]
    for zlo, zhi in Z_BINS:
        cells = []
        for lo, hi in A_BINS:
            errs = [p["err"] for p in sel if zlo <= p["z"] <= zhi and lo <= p["a_over_r"] < hi]
            cells.append(f"{np.sqrt(np.mean(np.square(errs))):.4f} (n={len(errs)})" if errs else "-")
        label = str(zlo) if zlo == zhi else f">= {zlo}"
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def _figures(rows, particles, out_dir: pathlib.Path, names) -> list:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figs = []
    markers = {"triangle": "^", "tetrahedron": "s", "bent chain": "o", "random": "*"}
    fig, axes = plt.subplots(1, len(names), figsize=(4 * len(names), 3.6), sharey=False)
    for ax, law in zip(axes, names):
        for fam, mk in markers.items():
            sel = [r for r in rows if r["family"] == fam]
            if sel:
                fe = [100 * r["fe_error"] for r in sel]  # NaN in a quick run: no bar drawn
                ax.errorbar([r["a_over_r_mean"] for r in sel], [100 * r["laws"][law]["K_rel_err"] for r in sel],
                            yerr=fe, fmt=mk, label=fam, ms=8, capsize=3)
        sel = [r for r in rows if "centre balls" in r["family"]]
        if sel:
            ax.plot([r["a_over_r_mean"] for r in sel], [100 * r["laws"][law]["K_rel_err"] for r in sel],
                    "x", color="k", label="centre-ball boundary")
        ax.axhline(0, color="grey", lw=0.8)
        ax.set_title(f"law: {law}")
        ax.set_xlabel("mean neck size a/r")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("K_DEM / K_FE - 1  (%), bars: FE error")
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    figs.append(save_figure(fig, out_dir / "clusters_K_error.png"))

    fig, axes = plt.subplots(1, len(names), figsize=(4 * len(names), 3.6), layout="constrained")
    for ax, law in zip(axes, names):
        sel = [p for p in particles if p["law"] == law and "centre balls" not in p["family"]]
        if sel:
            jitter = np.random.default_rng(0).uniform(-0.15, 0.15, len(sel))
            sc = ax.scatter(np.array([p["z"] for p in sel]) + jitter, [100 * p["err"] for p in sel],
                            c=[p["a_over_r"] for p in sel], cmap="viridis", vmin=0.1, vmax=0.6, s=18)
        ax.axhline(0, color="grey", lw=0.8)
        ax.set_title(f"law: {law}")
        ax.set_xlabel("coordination number z")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("(T_DEM - T_FE) / dT  (%)")
    if particles:
        fig.colorbar(sc, ax=axes, label="particle mean a/r", shrink=0.8)
    figs.append(save_figure(fig, out_dir / "clusters_T_error_map.png"))
    return figs


def render_cluster(fe: dict, path: pathlib.Path, title: str) -> pathlib.Path:
    """Off-screen pyvista render of the FE temperature on the cluster surface (PNG)."""
    import pyvista

    pyvista.OFF_SCREEN = True
    mesh = fe["cmesh"].mesh
    nv = mesh.p.shape[1]
    cells = np.hstack([np.full((mesh.t.shape[1], 1), 4), mesh.t.T]).ravel()
    grid = pyvista.UnstructuredGrid(cells, np.full(mesh.t.shape[1], pyvista.CellType.TETRA, dtype=np.uint8),
                                    mesh.p.T * 1e3)
    grid.point_data["T (K)"] = fe["sol"].u[:nv]
    plotter = pyvista.Plotter(off_screen=True, window_size=(900, 700))
    plotter.add_mesh(grid.extract_surface(algorithm="dataset_surface"), scalars="T (K)", cmap="coolwarm",
                     show_edges=False,
                     scalar_bar_args={"title": "T (K)"})
    plotter.add_text(title, font_size=10)
    plotter.view_isometric()
    plotter.screenshot(str(path))
    plotter.close()
    return path


def run(out_dir: pathlib.Path, quick: bool = False) -> dict:
    """Run the cluster study into ``out_dir``; returns the section contract of :mod:`verification.report`."""
    import json

    from tqdm import tqdm

    from verification.report import jsonable

    names = compared_laws()
    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    rows, particles, summary = [], [], {}
    last_random = None
    cases = all_cases(quick)
    for k, case in enumerate(tqdm(cases, desc="3D clusters", unit="cluster", leave=False)):
        where().update(step=f"cluster {k + 1} of {len(cases)} ({case.name})")
        fe = fe_solve(case, quick)
        row, parts = compare(case, fe, names)
        rows.append(row)
        particles += parts
        summary[f"cluster {case.name}"] = {
            "K_fe": row["K_fe"], "K_fe_error_estimate": row["fe_error"],
            **{f"K_rel_err_{law}": row["laws"][law]["K_rel_err"] for law in names},
            **{f"T_max_err_{law}": row["laws"][law]["T_max_err"] for law in names}}
        if case.family == "random":
            last_random = (case, fe)
    (out_dir / "clusters.json").write_text(json.dumps(jsonable({"cases": rows, "particles": particles}), indent=1))
    figures = _figures(rows, particles, out_dir, names)
    if last_random is not None:
        case, fe = last_random
        figures.append(render_cluster(fe, out_dir / "cluster_random_T.png", f"{case.name}: FE temperature"))
    worst = {law: max(abs(r["laws"][law]["K_rel_err"]) for r in rows if "centre balls" not in r["family"])
             for law in names}
    summary.update({f"clusters worst K rel err {law}": worst[law] for law in names})
    if not quick:
        summary["clusters worst FE error estimate"] = max(r["fe_error"] for r in rows)
    md = [__doc__.split("\n\n", 1)[1].strip(), "",
          "Relative errors are DEM minus FE over FE; temperature errors are in units of the imposed difference "
          "(1 K). FE: P2 on curved tetrahedra, "
          + ("one mesh level (quick: no FE error estimate)." if quick else
             "three mesh levels; the FE error estimate of K stands beside every K error (±), that of the particle "
             "temperatures in the column FE T error."),
          "", _table(rows, names), ""]
    if not quick:
        md += ["### The network error against the FE error", "",
               f"Law `{NETWORK_ONLY}` (every pipe its own FE pair conductance: what is left is the network's error). "
               "A network error is resolved when it exceeds the FE error. The FE K converges from above (in every "
               "check against axisymmetric pairs and chains), so against the exact solution the network error lies "
               "between the listed value and that value plus the FE error.", "", conclusions(rows), ""]
    md += ["### Error map: RMS particle-temperature error by coordination number and neck size", ""]
    for law in [x for x in (NETWORK_ONLY, "fit", "rojek") if x in names]:
        md += [f"Law `{law}`:", "", error_map(particles, law), ""]
    md += [f"![K error]({figures[0].name})", "", f"![T error map]({figures[1].name})", ""]
    if last_random is not None:
        md += [f"![random cluster]({figures[2].name})", ""]
    return {"title": "DEM vs FE: 3D clusters", "markdown": "\n".join(md), "summary": summary, "figures": figures}
