"""k_eff through densification: the union of spheres from a loose packing to nearly full density, FE beside DEM.

Sintered compacts densify far past the point where the necks of a particle meet; there the pair-neck readings have
no answer and the packing is read as the union of its spheres (:mod:`fem_neck.geometry.union`, Arzt's truncated
spheres). This study follows ``k_eff / kappa`` against the solid fraction ``phi`` of that geometry:

* **Lattices**: simple, body- and face-centred cubic cells of equal spheres whose nearest neighbours overlap by
  ``h`` (``--neck union`` of ``python -m fem_neck lattice``), from ``phi`` ~0.56 (SC, ``h/r = 0.05``) to ~0.97;
  the periodic-cell FE (:mod:`fem_neck.lattice`, two-sided bounds) against the DEM's laws on the same periodic
  cell with ``conductance.neck = "union"``, and the ``shared-body`` law's particle solved exactly with a node per
  neck (``conductance.nodes = "necks"``, :mod:`dem.network.necks`: the column ``shared-body (neck nodes)``), and
  with the Trefftz element of each cut sphere in place of the law's (``conductance.element = "trefftz"``,
  :mod:`dem.network.trefftz_element`: the column ``shared-body (neck nodes, trefftz element)``).
* **Random packings**: mirror packings of overlapping spheres (:func:`verification.packings.union_packing`, radii
  +-15 %), FE and DEM alike.
* **A Luding-sintered compact**: the built-in ``hot-wall-sintering`` scene (Luding 2005's contact, pressed and
  heated from one wall), its ``k_eff`` between the walls as it densifies (DEM only, its own pair-neck reading,
  each particle handed over to the union once its necks meet: :mod:`dem.engines.handover`).

Beside them: the Wiener bound ``phi`` and the Hashin-Shtrikman upper bound ``2 phi / (3 - phi)`` (no isotropic
microstructure of solid and insulating pores conducts more), the ``argento-bouvard`` law (Argento & Bouvard 1996: a
network of truncated spheres with the contact conductance fitted to their FE, Rojek 2022 eq. 42) on the union
lattices, and the correlation of Koh & Fortini (1973) for measured sintered metals, ``k / kappa = (1 - e) / (1 + 11
e^2)`` with the porosity ``e = 1 - phi``.
"""

from __future__ import annotations

import json
import pathlib
import time

import numpy as np

from dem.laws.verified_range import evidence_name
from dem.network.elements import SceneElements
from fem_neck import lattice
from verification.lattices import FECache, dem_periodic, solve_cells
from verification.report import jsonable, save_figure

#: The DEM's networks on union necks, by their name in :data:`dem.laws.verified_range.EVIDENCE`: each a conductance
#: law, the network's nodes (``conductance.nodes``) and the particles' elements (``conductance.element``).
COLUMNS = {evidence_name(law, nodes, element): (law, nodes, element) for law, nodes, element in
           (("argento-bouvard", "particles", "law"), ("fit", "particles", "law"), ("shared-body", "particles", "law"),
            ("shared-body", "necks", "law"), ("shared-body", "necks", "trefftz"))}
OVERLAPS = {"sc": (0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6), "bcc": (0.05, 0.1, 0.2, 0.3, 0.35),
            "fcc": (0.05, 0.1, 0.2, 0.3)}
QUICK_OVERLAPS = {"sc": (0.3,), "bcc": (0.2,), "fcc": (0.1,)}
RANDOM = ((1, 0.6), (2, 0.8), (3, 0.95))  # (seed, phi aimed at) of the union mirror packings
RANDOM_SPHERES = 4  # union_packing(n): 8 n spheres per period
RTOL, QUICK_RTOL, RANDOM_RTOL = 1e-3, 1e-2, 2e-3
COMPACT = "hot-wall-sintering"


def koh_fortini(phi):
    """Koh & Fortini (1973): ``k / kappa = (1 - e) / (1 + 11 e^2)`` of sintered metals with porosity ``e = 1 - phi``.

    Parameters
    ----------
    phi : float or array_like
        Solid fraction (dimensionless).

    Returns
    -------
    float or numpy.ndarray
        ``k_eff / kappa`` (dimensionless).
    """
    e = 1.0 - np.asarray(phi, dtype=float)
    return (1.0 - e) / (1.0 + 11.0 * e * e)


def hashin_shtrikman(phi):
    """The Hashin-Shtrikman upper bound of ``k_eff / kappa`` for an isotropic mixture of solid (fraction ``phi``)
    and insulating pores: ``2 phi / (3 - phi)``.

    Parameters
    ----------
    phi : float or array_like
        Solid fraction (dimensionless).

    Returns
    -------
    float or numpy.ndarray
        The bound (dimensionless).
    """
    phi = np.asarray(phi, dtype=float)
    return 2.0 * phi / (3.0 - phi)


def standing(cell: lattice.PeriodicCell) -> dict:
    """Where the cell's union necks stand (:mod:`dem.laws.verified_range`): ``widest_neck``, the largest ``a / r``
    of a particle whose necks do not meet (0 if none), and ``meeting``, how many particles carry necks that meet.

    Parameters
    ----------
    cell : fem_neck.lattice.cells.PeriodicCell
        The periodic packing, read as the union of its spheres.

    Returns
    -------
    dict
        ``{"widest_neck": float, "meeting": int}``.
    """
    from dem.geometry.bonds import find_bonds
    from dem.geometry.necks import meeting_in, widest_necks
    from dem.geometry.particles import Material, Particles
    from dem.geometry.periodic import PeriodicBox

    box = PeriodicBox(cell.period)
    particles = Particles.from_arrays(cell.centres, cell.radii, np.zeros(cell.n), materials=(Material(1.0, 1.0, 1.0,
                                                                                                        "unit"),))
    bonds = find_bonds(particles, contact="union", box=box)
    meeting = meeting_in(particles, [], bonds, box)
    apart = widest_necks(particles.radius, bonds)[~meeting]
    return {"widest_neck": float(apart.max()) if len(apart) else 0.0, "meeting": int(np.count_nonzero(meeting))}


def outside_evidence(row: dict, law: str) -> float:
    """How far the row's relative error of ``law`` lies outside the interval the FE evidence of
    :data:`dem.laws.verified_range.EVIDENCE` declares for the row's necks (0 inside; the worst range the row
    reached: necks that meet, else necks wider than the law's ``verified_width``, else its ``verified`` interval).

    Parameters
    ----------
    row : dict
        A row of the study (``rel``, ``widest_neck``, ``meeting``).
    law : str
        The network, a key of ``EVIDENCE`` and of :data:`COLUMNS`.

    Returns
    -------
    float
        The distance outside the interval (dimensionless).
    """
    from dem.laws.verified_range import EVIDENCE

    evidence = EVIDENCE[law]
    if row["meeting"]:
        low, high = evidence.meeting
    elif row["widest_neck"] > evidence.verified_width:
        low, high = evidence.apart
    else:
        low, high = evidence.verified
    rel = row["rel"][law]
    return max(low - rel, rel - high, 0.0)


def _rows(cells: dict, rtol: float, cache: FECache, kinds: list) -> list:
    rows = []
    for (key, cell), kind, fe in zip(cells.items(), kinds, solve_cells(cells, rtol, cache)):
        nets = {name: dem_periodic(cell, law, neck="union", nodes=nodes,
                                   elements=SceneElements(element) if nodes == "necks" else None)
                for name, (law, nodes, element) in COLUMNS.items()}
        rows.append({"case": key.rsplit(" rtol", 1)[0], "kind": kind, "phi": cell.phi, "fe": fe, "network": nets,
                     **standing(cell),
                     "rel": {law: v / fe["k"] - 1.0 for law, v in nets.items()},
                     "wiener": cell.phi, "hashin_shtrikman": float(hashin_shtrikman(cell.phi)),
                     "koh_fortini": float(koh_fortini(cell.phi))})
    return rows


def lattice_rows(overlaps: dict, rtol: float, cache: FECache) -> list:
    """The union lattices of ``overlaps`` (kind -> h/r values): FE, the DEM laws and the bounds, one row each."""
    cases = [(kind, h) for kind, hs in overlaps.items() for h in hs]
    cells = {f"{kind} union h/r={h:g} rtol={rtol:g}": lattice.lattice_cell(kind, h, neck="union") for kind, h in cases}
    return _rows(cells, rtol, cache, [kind for kind, _ in cases])


def random_rows(cases, rtol: float, cache: FECache) -> list:
    """The union mirror packings ``(seed, phi)`` of ``cases``: FE, the DEM laws and the bounds, one row each."""
    from verification.packings import union_packing

    cells = {f"union packing seed={seed} phi={phi:g} rtol={rtol:g}": union_packing(RANDOM_SPHERES, phi, seed=seed)
             for seed, phi in cases}
    return _rows(cells, rtol, cache, ["random"] * len(cases))


def compact_curve(out_dir: pathlib.Path) -> dict:
    """``k_eff / kappa`` against the volume fraction of the ``hot-wall-sintering`` compact as it sinters (the
    DEM's own run, its rows of ``timeseries.csv``), and how many of its particles end with necks that meet."""
    import csv

    from dem import load_scene, run

    folder = out_dir / COMPACT
    summary = run(load_scene(COMPACT), folder, progress=False, overwrite=True).summary
    kappa = float(load_scene(COMPACT).particles.materials[0].conductivity)
    phi, k = [], []
    with open(folder / "timeseries.csv") as f:
        for row in csv.DictReader(f):
            if row.get("effective_conductivity") not in (None, "", "nan"):
                phi.append(float(row["volume_fraction"]))
                k.append(float(row["effective_conductivity"]) / kappa)
    return {"phi": phi, "k": k, "particles_necks_meeting": summary.get("particles_necks_meeting"),
            "particles": summary.get("particles"), "law": summary.get("law")}


def _figure(rows: list, compact: dict | None, out_dir: pathlib.Path) -> list:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colours = {"sc": "tab:blue", "bcc": "tab:orange", "fcc": "tab:green", "random": "tab:red"}
    markers = {"argento-bouvard": "^", "fit": "s", "shared-body": "o", "shared-body (neck nodes)": "x",
               "shared-body (neck nodes, trefftz element)": "+"}
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 5.6))
    grid = np.linspace(0.5, 1.0, 101)
    ax1.plot(grid, grid, "k-", lw=1, label="Wiener bound phi")
    ax1.plot(grid, hashin_shtrikman(grid), "k--", lw=1, label="Hashin-Shtrikman 2 phi / (3 - phi)")
    ax1.plot(grid, koh_fortini(grid), "k:", lw=1.5, label="Koh & Fortini (1973), sintered metals")
    for kind in ("sc", "bcc", "fcc", "random"):
        sel = sorted((r for r in rows if r["kind"] == kind), key=lambda r: r["phi"])
        if not sel:
            continue
        phi = [r["phi"] for r in sel]
        ax1.plot(phi, [r["fe"]["k"] for r in sel], "-" if kind != "random" else "none", marker="D", ms=5,
                 color=colours[kind], label=f"{kind.upper() if kind != 'random' else 'random'} FE")
        for law in COLUMNS:
            ax1.plot(phi, [r["network"][law] for r in sel], ls="none", marker=markers[law], mfc="none", ms=6,
                     color=colours[kind])
            ax2.plot(phi, [100 * r["rel"][law] for r in sel], ls=":" if kind != "random" else "none",
                     marker=markers[law], mfc="none", color=colours[kind], label=f"{kind} {law}")
    if compact and compact["phi"]:
        ax1.plot(compact["phi"], compact["k"], color="tab:purple", lw=2,
                 label=f"{COMPACT} (DEM, {compact['law']}, pair necks handed over)")
    for law in COLUMNS:
        ax1.plot([], [], ls="none", marker=markers[law], mfc="none", color="grey", label=f"DEM {law}, union necks")
    ax1.set_xlabel("solid fraction phi")
    ax1.set_ylabel("k_eff / kappa")
    ax1.set_xlim(0.5, 1.0)
    ax1.set_ylim(0.0, 1.02)
    ax1.legend(fontsize=7, loc="upper left")
    ax1.set_title("k_eff through densification (union of spheres)")
    ax2.axhline(0.0, color="grey", lw=0.8)
    ax2.set_yscale("symlog", linthresh=1.0)
    for y in (-1.0, 1.0):
        ax2.axhline(y, color="grey", lw=0.6, ls="--")
    ax2.set_xlabel("solid fraction phi")
    ax2.set_ylabel("k_network / k_FE - 1  (%)")
    ax2.set_title("DEM laws on union necks against the FE (dashed: +-1 %)")
    ax2.legend(fontsize=6, ncol=2)
    fig.tight_layout()
    return [save_figure(fig, out_dir / "densification.png")]


def _table(rows: list) -> str:
    head = ("| packing | phi | k_FE / kappa [lower, upper] | " + " | ".join(COLUMNS)
            + " | HS bound | Koh & Fortini |")
    lines = [head, "|" + "---|" * (5 + len(COLUMNS))]
    for r in rows:
        fe = r["fe"]
        lines.append(f"| {r['case']} | {r['phi']:.4f} | {fe['k']:.5f} [{fe['lower']:.5f}, {fe['upper']:.5f}] | "
                     + " | ".join(f"{100 * r['rel'][law]:+.2f} %" for law in COLUMNS)
                     + f" | {r['hashin_shtrikman']:.4f} | {r['koh_fortini']:.4f} |")
    return "\n".join(lines)


def run(out_dir: pathlib.Path, quick: bool = False) -> dict:
    """Run the study into ``out_dir``; returns the section contract of :mod:`verification.report`.

    Parameters
    ----------
    out_dir : pathlib.Path
        The section's folder (FE results cached in its ``fe_cache.json``).
    quick : bool
        One cell per lattice at a coarse tolerance, no random packings, no compact.

    Returns
    -------
    dict
        ``title``, ``markdown``, ``summary`` and ``figures``.
    """
    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    cache = FECache(out_dir / "fe_cache.json")
    t0 = time.perf_counter()
    rows = lattice_rows(QUICK_OVERLAPS if quick else OVERLAPS, QUICK_RTOL if quick else RTOL, cache)
    compact = None
    if not quick:
        rows += random_rows(RANDOM, RANDOM_RTOL, cache)
        compact = compact_curve(out_dir)
    (out_dir / "densification.json").write_text(json.dumps(jsonable({"rows": rows, "compact": compact}), indent=1))
    figures = _figure(rows, compact, out_dir)
    summary = {}
    for r in rows:
        summary[f"densification {r['case']}"] = {"phi": r["phi"], "k_fe": r["fe"]["k"],
                                                 "fe_error_estimate": r["fe"]["error_estimate"],
                                                 **{f"rel_err_{law}": r["rel"][law] for law in COLUMNS}}
    for law in COLUMNS:
        summary[f"densification worst |rel err| {law}"] = max(abs(r["rel"][law]) for r in rows)
    targets = [(f"{law}: distance of the worst case outside the FE evidence declared in dem.laws.verified_range",
                max(outside_evidence(r, law) for r in rows), 0.0) for law in COLUMNS]
    summary["densification FE above the HS bound"] = sum(r["fe"]["lower"] > r["hashin_shtrikman"] for r in rows)
    if compact is not None:
        summary["compact particles with necks that meet"] = compact["particles_necks_meeting"]
    md = [__doc__.split("\n\n", 1)[1].strip(), "",
          "Relative errors are the DEM network over the FE minus one. FE gap "
          f"{QUICK_RTOL if quick else RTOL:g} on the lattices (random packings {RANDOM_RTOL:g})"
          + (" -- quick run: one cell per lattice." if quick else "."), "", _table(rows), ""]
    if compact is not None:
        md.append(f"The `{COMPACT}` compact: {len(compact['phi'])} rows of k_eff, ending with "
                  f"{compact['particles_necks_meeting']} of {compact['particles']} particles whose necks meet.")
    md.append(f"Run time {time.perf_counter() - t0:.0f} s (FE results cached in fe_cache.json).")
    return {"title": "k_eff through densification: the union of spheres, FE beside DEM", "markdown": "\n".join(md),
            "summary": summary, "figures": figures, "targets": targets}
