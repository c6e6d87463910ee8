r"""A rigorous lower bound on the union's ``k_eff``: the network with a node per neck whose particles are exact
flux elements, against the periodic-cell FE's upper bound.

Each particle of the union of spheres is its sphere cut by its radical planes; the cut bodies tile the union,
neighbours share their neck face exactly, and the bodies' remaining sphere surface is the union's boundary. Give each
particle the exact element of its cut body for a prescribed flux profile on each neck face
(:mod:`verification.neck_element`: density :math:`\propto (a^2 - \rho^2)^{-\beta}` on the face, the same function
seen from both particles of the neck) and solve the network with a node per neck (:mod:`dem.network.necks`, the
``shared-body`` law's assembly with these elements in place of the law's). In every body put the exact Neumann field
with the network's neck flows on its faces: the field is divergence free in the union, its normal flux continuous
across every face and nil through the pores, and it carries the network's heat flow across the period. So it is an
admissible flux field, its complementary energy is the network's, and by Thomson's principle the network's
``k_eff`` is at most the union's: a lower bound for any profile, which the FE's upper bound
(:mod:`fem_neck.lattice`) must lie above. The uniform flux (:math:`\beta = 0`) is the crudest admissible field; the
profile :math:`\beta = 1/4` lets a neck's flux crowd toward its rim as the exact flux does.

Cells: simple, body- and face-centred cubic lattices of equal spheres overlapping by ``h``
(``python -m fem_neck lattice --neck union``); every particle of a lattice is a translate of the others, so one
element FE serves the cell. The elements are P3 on a mesh refined toward every edge (:data:`DISC`); Galerkin's
resistance lies below the exact one, so a coarser element (:data:`COARSE`) gives a network above the finer one's,
and their difference is the column ``element step``: what is left of the bound's discretisation is below it.
Beside them the ``shared-body`` law's own network with a node per neck: where it falls below a bound it is below the
union's ``k_eff`` by at least their difference (reported, not a target of this study: the law's error is the
densification study's).
"""

from __future__ import annotations

import json
import pathlib
import time

import numpy as np

from fem_neck import lattice
from verification.lattices import FECache, dem_periodic, solve_cells
from verification.report import jsonable

OVERLAPS = {"sc": (0.05, 0.2, 0.3), "bcc": (0.05, 0.2, 0.3), "fcc": (0.05, 0.2, 0.3)}
QUICK_OVERLAPS = {"sc": (0.3,)}
BETAS = (0.0, 0.25)  # the flux profiles' exponents
DISC = {"order": 3, "maxh": 0.25, "hp_levels": 2}  # the element FE (verification.neck_element.cut_element)
COARSE = {"order": 2, "maxh": 0.3, "hp_levels": 1}
RTOL, QUICK_RTOL = 1e-3, 1e-2  # the periodic-cell FE's gap (the densification study's)


def bordered(R: np.ndarray) -> np.ndarray:
    r"""The ``(z + 1) x (z + 1)`` element of a particle with resistance ``R`` over its necks and its centre
    (:mod:`dem.network.necks`): :math:`Y = R^{-1}` bordered by :math:`-Y \mathbf 1` and :math:`\mathbf 1^T Y \mathbf 1`.

    Parameters
    ----------
    R : numpy.ndarray
        (z, z) resistance, K/W, symmetric positive definite.

    Returns
    -------
    numpy.ndarray
        The conductance matrix, W/K (local nodes: the necks, then the centre).
    """
    Y = np.linalg.inv(R)
    Y = 0.5 * (Y + Y.T)
    row = Y.sum(axis=1)
    return np.block([[Y, -row[:, None]], [-row[None, :], np.array([[row.sum()]])]])


class ExactElements:
    """The particles' exact flux elements (:func:`verification.neck_element.cut_element`) for the flux profiles
    ``betas``, one FE per distinct cut body (its planes, whatever their order), built into the network by
    :meth:`builder` (the ``elements`` hook of :func:`dem.network.necks.neck_network`).

    Parameters
    ----------
    betas : sequence of float
        The flux profiles' exponents.
    disc : dict
        The element FE's ``order``, ``maxh`` and ``hp_levels``.
    """

    def __init__(self, betas, disc: dict):
        self.betas, self.disc = tuple(betas), dict(disc)
        self.bodies = {}  # planes (sorted, rounded) -> {beta: R of the unit body in that order}
        self.ndof = []

    def resistance(self, normals: np.ndarray, arms: np.ndarray, beta: float) -> np.ndarray:
        """``R`` of the unit body cut by ``normals . x <= arms`` (units of the radius), faces in the planes' order."""
        planes = np.column_stack([normals, arms])
        rounded = np.round(planes, 9) + 0.0  # (+ 0.0: no negative zero in the key)
        order = np.lexsort(rounded.T[::-1])
        key = rounded[order].tobytes()
        if key not in self.bodies:
            from verification.neck_element import cut_element

            res = cut_element(normals[order], arms[order], self.betas, **self.disc)
            self.bodies[key] = res["R"]
            self.ndof.append(res["ndof"])
        back = np.argsort(order)
        return self.bodies[key][beta][np.ix_(back, back)]

    def builder(self, beta: float):
        """The ``elements`` hook of :func:`dem.network.necks.neck_network` giving every particle its exact element
        for the profile ``beta`` (no trace cap: the element is exact)."""
        from dem.laws.shared_body import ParticleElements, particle_elements

        def build(n, radius, bonds, vectors, k_i, k_j, k_wall, conductivity, wall_normals, volume=None):
            if bonds.n_walls:
                raise ValueError("the exact elements: periodic cells only (a wall's neck has no cut body here)")
            el = particle_elements(n, radius, bonds, vectors, k_i, k_j, k_wall, conductivity, wall_normals, volume)
            values = el.values.copy()
            m = len(bonds.i)
            unit = vectors / np.linalg.norm(vectors, axis=1)[:, None]
            for k in range(n):
                ends = el.ends[el.offsets[k]:el.offsets[k + 1]]
                if not len(ends):
                    continue
                on_i = ends < m
                b = np.where(on_i, ends, ends - m)
                normals = np.where(on_i[:, None], unit[b], -unit[b])
                arms = np.where(on_i, bonds.l_i[b], bonds.l_j[b]) / radius[k]
                R = self.resistance(normals, arms, beta) / (conductivity[k] * radius[k])
                values[el.start[k]:el.start[k + 1]] = bordered(R).ravel()
            return ParticleElements(el.offsets, el.ends, el.start, values, np.zeros(n, dtype=bool), np.ones(n))

        return build


def bounds(cell: lattice.PeriodicCell, disc: dict) -> dict:
    """The exact-element networks' ``k_eff / kappa`` of the periodic cell along z, per flux profile of
    :data:`BETAS`, and the element FE's size.

    Parameters
    ----------
    cell : fem_neck.lattice.cells.PeriodicCell
        The periodic packing, read as the union of its spheres.
    disc : dict
        The element FE (:data:`DISC`).

    Returns
    -------
    dict
        ``{beta: k_eff / kappa}`` under ``k`` (dimensionless), the element FE's ``ndof`` (list, one per body).
    """
    elements = ExactElements(BETAS, disc)
    k = {beta: dem_periodic(cell, "shared-body", neck="union", nodes="necks", elements=elements.builder(beta))
         for beta in BETAS}
    return {"k": k, "ndof": elements.ndof}


def _profile(beta: float) -> str:
    return "uniform flux" if beta == 0 else f"profile beta={beta:g}"


def run(out_dir: pathlib.Path, quick: bool = False) -> dict:
    """Run the study into ``out_dir``; the section contract of :mod:`verification.report`.

    Parameters
    ----------
    out_dir : pathlib.Path
        The section's folder (the periodic-cell FE cached in its ``fe_cache.json``).
    quick : bool
        One cell (SC, h/r = 0.3), its FE at a coarse gap.

    Returns
    -------
    dict
        ``title``, ``markdown``, ``summary``, ``figures`` and ``targets``.
    """
    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    rtol = QUICK_RTOL if quick else RTOL
    cases = [(kind, h) for kind, hs in (QUICK_OVERLAPS if quick else OVERLAPS).items() for h in hs]
    cells = {f"{kind} union h/r={h:g} rtol={rtol:g}": lattice.lattice_cell(kind, h, neck="union") for kind, h in cases}
    rows = []
    for (key, cell), fe in zip(cells.items(), solve_cells(cells, rtol, FECache(out_dir / "fe_cache.json"))):
        fine, coarse = bounds(cell, DISC), bounds(cell, COARSE)
        law = dem_periodic(cell, "shared-body", neck="union", nodes="necks")
        rows.append({"case": key.rsplit(" rtol", 1)[0], "phi": cell.phi, "fe": fe, "bound": fine["k"],
                     "coarse": coarse["k"], "ndof": fine["ndof"], "law": law,
                     "rel": {beta: fine["k"][beta] / fe["upper"] - 1.0 for beta in BETAS},
                     "step": {beta: coarse["k"][beta] / fine["k"][beta] - 1.0 for beta in BETAS}})
    (out_dir / "neck_node_bound.json").write_text(json.dumps(jsonable(rows), indent=1))
    lines = ["| cell | phi | FE k/kappa [lower, upper] | " + " | ".join(
        f"{_profile(beta)} (element step)" for beta in BETAS) + " | shared-body (neck nodes) |",
        "|" + "---|" * (4 + len(BETAS))]
    for r in rows:
        fe = r["fe"]
        lines.append(f"| {r['case']} | {r['phi']:.3f} | {fe['k']:.5f} [{fe['lower']:.5f}, {fe['upper']:.5f}] | "
                     + " | ".join(f"{100 * r['rel'][beta]:+.2f} % ({100 * r['step'][beta]:+.2f} %)" for beta in BETAS)
                     + f" | {100 * (r['law'] / fe['upper'] - 1):+.2f} % |")
    # the element step on top: the bound's own discretisation (Galerkin: its network conducts a little too much)
    targets = [(f"{_profile(beta)}: the exact-element network, raised by its element step, over the FE's upper bound "
                "minus one (worst cell)", max(r["rel"][beta] + max(r["step"][beta], 0.0) for r in rows), 0.0)
               for beta in BETAS]
    below = [r["case"] for r in rows if r["law"] < max(r["bound"].values())]
    summary = {f"neck-node bound {r['case']}": {"phi": r["phi"], "k_fe_upper": r["fe"]["upper"],
                                                **{f"rel_{_profile(b)}": r["rel"][b] for b in BETAS},
                                                **{f"element_step_{_profile(b)}": r["step"][b] for b in BETAS}}
               for r in rows}
    summary["neck-node bound: cells where the shared-body law's neck-node network is below the bound"] = len(below)
    md = [__doc__.split("\n\n", 1)[1].strip(), "",
          f"Each entry: the network over the FE's upper bound minus one (FE gap {rtol:g}); in brackets the element "
          f"step, the network of the coarser element ({COARSE}) over that of the study's ({DISC}) minus one; last "
          "column the shipped law's network, the same way.", "", "\n".join(lines), "",
          ("The shared-body law's neck-node network lies below the best bound, so below the union's k_eff by at least "
           f"the difference, on: {', '.join(below)}." if below else
           "The shared-body law's neck-node network lies above both bounds on every cell."), "",
          f"Run time {time.perf_counter() - t0:.0f} s (FE results cached in fe_cache.json)."]
    return {"title": "The neck-node network of exact flux elements: a lower bound on the union's k_eff",
            "markdown": "\n".join(md), "summary": summary, "figures": [], "targets": targets}
