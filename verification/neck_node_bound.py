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
profile :math:`\beta = 1/4` lets a neck's flux crowd toward its rim as the exact flux does; with two dipole modes per
neck as well (:mod:`dem.network.necks`, "Flux modes": the flux may tilt across the face, the same function from both
particles, so the argument holds as it stands) the network carries three numbers per neck.

Cells: simple, body- and face-centred cubic lattices of equal spheres overlapping by ``h``
(``python -m fem_neck lattice --neck union``), and the random mirror packings of the densification study at
:math:`\phi` 0.6, 0.8 and 0.95 (:func:`verification.packings.union_packing`, seeds 1, 2, 3: 32 spheres, radii within
15 %), whose FE is that study's (gap 2e-3). One element FE serves every body congruent to another under the cube's symmetries (a
lattice's translates, a mirror packing's images; :class:`ExactElements`). The elements are P3 on a mesh refined
toward every edge (:data:`DISC`); Galerkin's resistance lies below the exact one, so a coarser element
(:data:`COARSE`) gives a network above the finer one's, and their difference is the column ``element step``: what is
left of the bound's discretisation is below it. Beside them the ``shared-body`` law's own network with a node per
neck: where it falls below a bound it is below the union's ``k_eff`` by at least their difference (reported, not a
target of this study: the law's error is the densification study's). And the network of the compiled Trefftz element
with the same three flux modes (:mod:`dem.network.trefftz_element`: solid harmonics to degree 10, each monopole's
diagonal moved by what that degree misses on the chain particle), with its cost per particle: an estimate, not a
bound, whose target is 1 % of the FE on every cell. It needs no NGSolve: where NGSolve is missing the exact-element
columns are left out and the FE comes from ``fe_cache.json``.
"""

from __future__ import annotations

import importlib.util
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
COLUMNS = ((0.0, 1), (0.25, 1), (0.25, 3))  # (profile, flux modes per neck) of the study's networks
DISC = {"order": 3, "maxh": 0.25, "hp_levels": 2}  # the element FE (verification.neck_element.cut_element)
COARSE = {"order": 2, "maxh": 0.3, "hp_levels": 1}
RTOL, QUICK_RTOL = 1e-3, 1e-2  # the periodic-cell FE's gap (the densification study's)
TREFFTZ = "Trefftz element L=10, 3 modes"  # the compiled element's column
TREFFTZ_TARGET = 0.01  # its network within 1 % of the FE on every cell


def bordered(R: np.ndarray, modes: int = 1) -> np.ndarray:
    r"""The element of a particle with resistance ``R`` over its necks' ``modes`` flux modes and its centre
    (:mod:`dem.network.necks`, "Flux modes"): :math:`Y = R^{-1}` bordered as
    :func:`dem.network.necks.bordered` borders it.

    Parameters
    ----------
    R : numpy.ndarray
        (modes z, modes z) resistance, K/W, symmetric positive definite.
    modes : int
        Flux modes per neck.

    Returns
    -------
    numpy.ndarray
        The conductance matrix, W/K (local nodes: the necks' modes, then the centre).
    """
    Y = np.linalg.inv(R)
    from dem.network.necks import bordered as border

    return border(0.5 * (Y + Y.T), modes)


def _symmetries() -> np.ndarray:
    """The 48 signed permutations of the axes (the cube's symmetries), identity first."""
    import itertools

    ops = [np.eye(3)[list(p)] * np.array(s)[:, None] for p in itertools.permutations(range(3))
           for s in itertools.product((1.0, -1.0), repeat=3)]
    return np.array(ops)


class ExactElements:
    """The particles' exact flux elements (:func:`verification.neck_element.cut_element`) for the flux profiles
    ``betas``, with ``modes`` flux modes per neck (1: the monopole; 3: with the two dipoles), one FE per distinct cut
    body up to the cube's symmetries (a mirror packing's images, a lattice's translates), built into the network by
    :meth:`builder` (the ``elements`` hook of :func:`dem.network.necks.neck_network`).

    Parameters
    ----------
    betas : sequence of float
        The flux profiles' exponents.
    disc : dict
        The element FE's ``order``, ``maxh`` and ``hp_levels``.
    modes : int
        Flux modes per neck, 1 or 3.
    """

    OPS = _symmetries()

    def __init__(self, betas, disc: dict, modes: int = 1):
        if modes not in (1, 3):
            raise ValueError(f"modes = {modes}: must be 1 (the monopole) or 3 (with the two dipoles)")
        self.betas, self.disc, self.modes = tuple(betas), dict(disc), modes
        self.bodies = {}  # planes (sorted, rounded) -> {beta: R of the unit body in that order, its canonical frames}
        self.ndof = []

    def resistance(self, normals: np.ndarray, arms: np.ndarray, beta: float, frames=None) -> np.ndarray:
        """``R`` of the unit body cut by ``normals . x <= arms`` (units of the radius), faces in the planes' order;
        with ``frames`` (z, 2, 3) the dipoles' directions on each face (``modes`` 3: ``3 z x 3 z``, mode ``3 b + d``).
        The FE runs once per body up to a symmetry ``S`` of the cube: on ``S``'s image, the body whose key is
        least, its dipoles along :func:`dem.network.necks.neck_frames` of its normals; a dipole along ``t`` on
        this body is one along ``S t`` there."""
        from dem.network.necks import neck_frames

        planes = np.column_stack([normals, arms])
        keys = []
        for S in self.OPS:
            rounded = np.round(np.column_stack([normals @ S.T, arms]), 9) + 0.0  # (+ 0.0: no negative zero)
            order = np.lexsort(rounded.T[::-1])
            keys.append((rounded[order].tobytes(), order))
        best = min(range(len(keys)), key=lambda k: keys[k][0])
        key, order = keys[best]
        S = self.OPS[best]
        if key not in self.bodies:
            from verification.neck_element import cut_element

            image = planes[order, :3] @ S.T
            canonical = neck_frames(image) if self.modes == 3 else None
            res = cut_element(image, arms[order], self.betas, frames=canonical, **self.disc)
            self.bodies[key] = (res["R"], canonical)
            self.ndof.append(res["ndof"])
        R_all, canonical = self.bodies[key]
        back = np.argsort(order)
        if frames is None:  # the monopoles alone
            return R_all[beta][::self.modes, ::self.modes][np.ix_(back, back)]
        # the modes of face b are those of the image's face back[b], the dipoles turned onto this body's frames
        z = len(arms)
        C = np.zeros((3 * z, 3 * z))
        for b in range(z):
            c = back[b]
            C[3 * b, 3 * c] = 1.0
            C[3 * b + 1:3 * b + 3, 3 * c + 1:3 * c + 3] = (frames[b] @ S.T) @ canonical[c].T
        return C @ R_all[beta] @ C.T

    def builder(self, beta: float, modes: int = 1):
        """The ``elements`` hook of :func:`dem.network.necks.neck_network` giving every particle its exact element
        for the profile ``beta`` (no trace cap: the element is exact) with ``modes`` flux modes per neck (1, or 3
        where the FE has them), the dipoles along each bond's :func:`dem.network.necks.neck_frames` (the same on both
        its particles)."""
        if modes not in (1, self.modes):
            raise ValueError(f"modes = {modes}: these elements have 1 or {self.modes}")
        from dem.laws.shared_body import ParticleElements, particle_elements
        from dem.network.necks import neck_frames

        def build(n, radius, bonds, vectors, k_i, k_j, k_wall, conductivity, wall_normals, volume=None):
            if bonds.n_walls:
                raise ValueError("the exact elements: periodic cells only (a wall's neck has no cut body here)")
            el = particle_elements(n, radius, bonds, vectors, k_i, k_j, k_wall, conductivity, wall_normals, volume)
            m, M = len(bonds.i), modes
            unit = vectors / np.linalg.norm(vectors, axis=1)[:, None]
            frames = neck_frames(vectors)
            blocks, start = [], [0]
            for k in range(n):
                ends = el.ends[el.offsets[k]:el.offsets[k + 1]]
                if len(ends):
                    on_i = ends < m
                    b = np.where(on_i, ends, ends - m)
                    normals = np.where(on_i[:, None], unit[b], -unit[b])
                    arms = np.where(on_i, bonds.l_i[b], bonds.l_j[b]) / radius[k]
                    R = (self.resistance(normals, arms, beta) if M == 1 else
                         self.resistance(normals, arms, beta, frames[b]))
                    blocks.append(bordered(R / (conductivity[k] * radius[k]), M).ravel())
                else:
                    blocks.append(np.zeros(1))
                start.append(start[-1] + len(blocks[-1]))
            return ParticleElements(el.offsets, el.ends, np.array(start), np.concatenate(blocks),
                                    np.zeros(n, dtype=bool), np.ones(n), M)

        return build


def bounds(cell: lattice.PeriodicCell, disc: dict) -> dict:
    """The exact-element networks' ``k_eff / kappa`` of the periodic cell along z, per column of :data:`COLUMNS`
    (one FE per body gives them all: the monopoles' ``R`` is the three modes' own block), and the element FE's size.

    Parameters
    ----------
    cell : fem_neck.lattice.cells.PeriodicCell
        The periodic packing, read as the union of its spheres.
    disc : dict
        The element FE (:data:`DISC`).

    Returns
    -------
    dict
        ``{column: k_eff / kappa}`` under ``k`` (dimensionless), the element FE's ``ndof`` (list, one per body).
    """
    elements = ExactElements(BETAS, disc, modes=3)
    k = {_column(beta, modes): dem_periodic(cell, "shared-body", neck="union", nodes="necks",
                                            elements=elements.builder(beta, modes)) for beta, modes in COLUMNS}
    return {"k": k, "ndof": elements.ndof}


def ngsolve_present() -> bool:
    """Whether NGSolve can be imported (the exact elements' FE)."""
    return importlib.util.find_spec("ngsolve") is not None


def trefftz(cell: lattice.PeriodicCell) -> dict:
    """The network of the compiled Trefftz element (:func:`dem.network.trefftz_element.trefftz_elements`) on the
    periodic cell: ``k`` its ``k_eff / kappa`` along z, ``ms_per_particle`` the CPU time of its elements per particle
    (ms), ``plain`` the particles that kept the law's element."""
    from dem.network.trefftz_element import chain_shift, trefftz_elements

    chain_shift(0.5)  # the shift table, built once per process (about a second): not a particle's cost
    built = {}

    def timed(*args, **kwargs):
        t0 = time.process_time()
        el = trefftz_elements(*args, **kwargs)
        built.update(seconds=time.process_time() - t0, n=len(el.plain), plain=int(el.plain.sum()))
        return el

    k = dem_periodic(cell, "shared-body", neck="union", nodes="necks", elements=timed)
    return {"k": k, "ms_per_particle": 1e3 * built["seconds"] / built["n"], "plain": built["plain"]}


def _column(beta: float, modes: int) -> str:
    return ("uniform flux" if beta == 0 else f"profile beta={beta:g}") + (" + dipoles" if modes == 3 else "")


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
    from verification.densification import RANDOM, RANDOM_RTOL, RANDOM_SPHERES
    from verification.packings import union_packing

    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    rtol = QUICK_RTOL if quick else RTOL
    cache = FECache(out_dir / "fe_cache.json")
    cases = [(kind, h) for kind, hs in (QUICK_OVERLAPS if quick else OVERLAPS).items() for h in hs]
    cells = {f"{kind} union h/r={h:g} rtol={rtol:g}": lattice.lattice_cell(kind, h, neck="union") for kind, h in cases}
    fes = solve_cells(cells, rtol, cache)
    if not quick:
        packings = {f"union packing seed={seed} phi={phi:g} rtol={RANDOM_RTOL:g}":
                    union_packing(RANDOM_SPHERES, phi, seed=seed) for seed, phi in RANDOM}
        fes += solve_cells(packings, RANDOM_RTOL, cache)
        cells.update(packings)
    exact = ngsolve_present()  # the exact elements' FE; the rest needs none (the FE cells from the cache)
    names = [_column(beta, modes) for beta, modes in COLUMNS] if exact else []
    rows = []
    for (key, cell), fe in zip(cells.items(), fes):
        fine, coarse = (bounds(cell, DISC), bounds(cell, COARSE)) if exact else ({"k": {}, "ndof": []}, {"k": {}})
        law = dem_periodic(cell, "shared-body", neck="union", nodes="necks")
        rows.append({"case": key.rsplit(" rtol", 1)[0], "phi": cell.phi, "fe": fe, "bound": fine["k"],
                     "coarse": coarse["k"], "ndof": fine["ndof"], "law": law, "trefftz": trefftz(cell),
                     "rel": {c: fine["k"][c] / fe["upper"] - 1.0 for c in names},
                     "step": {c: coarse["k"][c] / fine["k"][c] - 1.0 for c in names}})
    (out_dir / "neck_node_bound.json").write_text(json.dumps(jsonable(rows), indent=1))
    lines = ["| cell | phi | FE k/kappa [lower, upper] | " + " | ".join(f"{c} (element step)" for c in names)
             + f" | shared-body (neck nodes) | {TREFFTZ} | its ms per particle |", "|" + "---|" * (6 + len(names))]
    for r in rows:
        fe = r["fe"]
        lines.append(f"| {r['case']} | {r['phi']:.3f} | {fe['k']:.5f} [{fe['lower']:.5f}, {fe['upper']:.5f}] | "
                     + "".join(f"{100 * r['rel'][c]:+.2f} % ({100 * r['step'][c]:+.2f} %) | " for c in names)
                     + f"{100 * (r['law'] / fe['upper'] - 1):+.2f} % | "
                     + f"{100 * (r['trefftz']['k'] / fe['upper'] - 1):+.2f} % | {r['trefftz']['ms_per_particle']:.0f} |")
    # the element step on top: the bound's own discretisation (Galerkin: its network conducts a little too much)
    targets = [(f"{c}: the exact-element network, raised by its element step, over the FE's upper bound minus one "
                "(worst cell)", max(r["rel"][c] + max(r["step"][c], 0.0) for r in rows), 0.0) for c in names]
    # an estimate, not a bound: within the target of either FE bound, and never above the Wiener bound phi
    targets.append((f"{TREFFTZ}: the network's distance from the FE's bounds (worst cell)",
                    max(max(r["trefftz"]["k"] / r["fe"]["upper"] - 1.0, 1.0 - r["trefftz"]["k"] / r["fe"]["lower"])
                        for r in rows), TREFFTZ_TARGET))
    targets.append((f"{TREFFTZ}: the network over the Wiener bound minus one (worst cell)",
                    max(r["trefftz"]["k"] / r["phi"] - 1.0 for r in rows), 0.0))
    below = [r["case"] for r in rows if r["bound"] and r["law"] < max(r["bound"].values())]
    summary = {f"neck-node bound {r['case']}": {"phi": r["phi"], "k_fe_upper": r["fe"]["upper"],
                                                **{f"rel_{c}": r["rel"][c] for c in names},
                                                **{f"element_step_{c}": r["step"][c] for c in names},
                                                f"rel_{TREFFTZ}": r["trefftz"]["k"] / r["fe"]["upper"] - 1.0,
                                                f"ms_per_particle_{TREFFTZ}": r["trefftz"]["ms_per_particle"]}
               for r in rows}
    if exact:
        summary["neck-node bound: cells where the shared-body law's neck-node network is below the bound"] = len(below)
    md = [__doc__.split("\n\n", 1)[1].strip(), "",
          f"Each entry: the network over the FE's upper bound minus one (FE gap {rtol:g} on the lattices"
          + ("" if quick else f", {RANDOM_RTOL:g} on the random packings")
          + f"); in brackets the element step, the network of the coarser element ({COARSE}) over that of the "
          f"study's ({DISC}) minus one; last column the shipped law's network, the same way.", "", "\n".join(lines), "",
          ("NGSolve is missing: the exact elements' columns were not run." if not exact else
           "The shared-body law's neck-node network lies below the best bound, so below the union's k_eff by at least "
           f"the difference, on: {', '.join(below)}." if below else
           "The shared-body law's neck-node network lies above every bound on every cell."), "",
          f"Run time {time.perf_counter() - t0:.0f} s (FE results cached in fe_cache.json)."]
    return {"title": "The neck-node network of exact flux elements: a lower bound on the union's k_eff",
            "markdown": "\n".join(md), "summary": summary, "figures": [], "targets": targets}
