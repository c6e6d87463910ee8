r"""Current through the contacts of a packing and the Joule heat it makes: two schemes side by side.

Electrodes are walls: a particle touching an electrified wall exchanges current with it. Two ways to compute the
current:

* :func:`kirchhoff` -- the physical one (Kirchhoff's laws): a potential on every particle, each contact a conductance
  :math:`G` (the thermal neck law with the electrical conductivity :math:`\sigma` in place of :math:`\kappa`,
  :func:`dem.laws.conductance.bond_conductances`), electrodes at a fixed potential (V) or driving a fixed total current
  (A into the packing). One sparse solve (the same network solve as the heat,
  :class:`dem.network.laplacian.BoundedLaplacian`) gives the potentials; every contact carries
  :math:`I = G (\phi_i - \phi_j)` and makes the Joule heat :math:`I^2 / G`, shared by its two particles in proportion to
  the resistances of their halves (a wall contact's heat is made in the particle's half). The current is conserved at
  every particle, and the Joule heat of all contacts equals the power the electrodes deliver, :math:`\sum_e V_e I_e`
  (Tellegen's theorem), to round-off. A fixed-current electrode is solved by superposition: a unit-potential solve per
  such electrode with the same factorisation, then the small system :math:`Y V = I` for their potentials.
* :func:`area_weighted_current` -- the scheme of Zohdi 2014 (eqs. 40-43, Remarks 2 and 4): a scalar "current"
  :math:`J_i` per particle; a particle touching an electrified wall takes the wall's value :math:`J^\mathrm{ext}`
  (Remark 2), every other one the contact-area-weighted mean of its neighbours,
  :math:`J_i = \sum_j A_{ij} J_j / \sum_j A_{ij}` (eq. 43), found by Gauss-Seidel sweeps ("the solution method sweeps
  through the system, particle by particle, updating the variables as it progresses"). Joule heating
  :math:`H_i = a J_i^2 V_i / \sigma_i` (eq. 35).

Where they agree, and where not: eq. (43) is the discrete Laplace equation with weights :math:`A_{ij}` and the wall
particles held at :math:`J^\mathrm{ext}` -- the equation Kirchhoff's potential obeys with conductances :math:`G_{ij}`
and electrodes at fixed potentials. The converged :math:`J` therefore *is* a potential (:func:`kirchhoff` with
:math:`G = A` and the wall particles fixed reproduces it to round-off); in a chain of equal contacts both are linear
from one end to the other (Remark 4: each interior value the mean of its neighbours). But Zohdi reads :math:`J` as a
current magnitude: two walls at the same :math:`J^\mathrm{ext}` make every connected particle carry
:math:`J^\mathrm{ext}` (Kirchhoff: no potential difference, no current), the heat is made in the particles by
:math:`J^2` rather than at the necks by :math:`I^2/G` (where the narrow
necks get most of it), the weights ignore the neck length and the conductivity, and nothing conserves charge.

Particles in a group that touches no electrode carry no current in both schemes (Kirchhoff: their potential is
undetermined; they are reported as floating).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from dem.laws.conductance import bond_conductances
from dem.network.laplacian import BoundedLaplacian, solve_anchored

SCHEMES = ("kirchhoff", "zohdi")


@dataclass(frozen=True)
class Electrodes:
    """The electrified walls: ``names``, and per electrode either a ``potential`` (V) or a ``current`` (A, into the
    packing; Zohdi's scheme: the wall's ``J_ext``), the other NaN. ``walls``: their indices in the scene's walls.

    Parameters
    ----------
    names : tuple of str
        The electrified walls' names.
    walls : tuple of int
        Their indices in the scene's walls.
    potential : numpy.ndarray
        (E,) each electrode's potential (V), NaN for one that drives a current.
    current : numpy.ndarray
        (E,) each electrode's current into the packing (A; Zohdi's scheme: ``J_ext``), NaN for one at a potential.
    """

    names: tuple
    walls: tuple
    potential: np.ndarray
    current: np.ndarray

    def __len__(self) -> int:
        return len(self.names)

    @property
    def fixed_potential(self) -> np.ndarray:
        """(E,) bool: the electrodes held at a potential (the others drive a current)."""
        return np.isfinite(self.potential)


@dataclass
class CurrentFlow:
    """A Kirchhoff solution.

    ``potential`` (N,) V, NaN on floating particles; ``pair_current`` (M,) A from i to j; ``wall_current`` (B,) A
    from each electrode into the particle of its contact; ``electrode_potential`` and ``electrode_current`` (E,) V
    and A into the packing (NaN potential: an electrode with no path); ``joule_particles`` (N,) W made in each
    particle; ``joule_heat`` (W, all contacts) and ``electrode_power`` (W, ``sum V_e I_e``); ``floating``: indices
    of particles in groups that touch no electrode with a path; ``no_path``: names of fixed-current electrodes that
    reach no electrode at a fixed potential (they carry no current); ``residual``: the largest current imbalance at a
    particle relative to the largest contact current (or, when almost none flows, to 1e-12 of the largest electrode
    conductance times the largest electrode potential). ``solver``: the linear solver of the particles' matrix, for
    the next refresh to reuse (``kirchhoff(previous=...)``; None when no particle has a path).

    Parameters
    ----------
    potential : numpy.ndarray
        (N,) particle potentials (V), NaN on floating particles.
    pair_current : numpy.ndarray
        (M,) current of each pair contact from i to j (A).
    wall_current : numpy.ndarray
        (B,) current from each electrode into the particle of its contact (A).
    electrode_potential : numpy.ndarray
        (E,) electrode potentials (V); NaN for an electrode with no path.
    electrode_current : numpy.ndarray
        (E,) current of each electrode into the packing (A).
    joule_particles : numpy.ndarray
        (N,) Joule heat made in each particle (W).
    joule_heat : float
        Joule heat of all contacts (W).
    electrode_power : float
        Power the electrodes deliver, ``sum V_e I_e`` (W).
    floating : numpy.ndarray
        Indices of the particles in groups that touch no electrode with a path.
    no_path : tuple of str
        Names of the fixed-current electrodes that reach no electrode at a fixed potential.
    residual : float
        The largest current imbalance at a particle, relative (dimensionless).
    solver : object
        The particles' linear solver, for the next refresh; None when no particle has a path.
    """

    potential: np.ndarray
    pair_current: np.ndarray
    wall_current: np.ndarray
    electrode_potential: np.ndarray
    electrode_current: np.ndarray
    joule_particles: np.ndarray
    joule_heat: float
    electrode_power: float
    floating: np.ndarray
    no_path: tuple
    residual: float
    solver: object = None

    @property
    def closed(self) -> bool:
        """Whether any current flows (a group of particles joins two electrodes)."""
        return bool(np.any(self.electrode_current != 0.0))


def _grounded(n, i, j, plane_node, plane_index, electrodes: Electrodes):
    """Which particles and which electrodes are connected (through particles and electrodes) to an electrode at a
    fixed potential: ``(particle mask, electrode mask, lone)``, ``lone`` the electrode each particle of a group
    that reaches exactly one electrode shares its potential with (-1 elsewhere): such a group carries no current."""
    n_e = len(electrodes)
    rows = np.concatenate([i, plane_node])
    cols = np.concatenate([j, n + plane_index])
    graph = sp.csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(n + n_e, n + n_e))
    n_comp, label = connected_components(graph, directed=False)
    grounded_labels = np.unique(label[n + np.flatnonzero(electrodes.fixed_potential)])
    reached = np.isin(label, grounded_labels)
    electrode_label = label[n:]
    count = np.bincount(electrode_label, minlength=n_comp)
    owner = np.full(n_comp, -1)
    owner[electrode_label] = np.arange(n_e)
    lone = np.where(count[label[:n]] == 1, owner[label[:n]], -1)
    return reached[:n], reached[n:], lone


def kirchhoff(n: int, i, j, G, share, plane_node, plane_index, G_plane, electrodes: Electrodes,
              linear: str = "auto", previous=None) -> CurrentFlow:
    """Potentials and currents of ``n`` particles joined by contacts ``(i, j)`` of conductance ``G`` (S; ``share``:
    the fraction of each contact's resistance on the side of i) and to the electrodes by ``(plane_node,
    plane_index)`` of conductance ``G_plane`` (module docstring). At least one electrode must be at a fixed
    potential (the reference). ``previous``: the ``solver`` of an earlier solution of (about) the same network, whose
    AMG hierarchy then serves again (:func:`dem.network.linsolve.make_solver`).

    Parameters
    ----------
    n : int
        Number of particles.
    i, j : array_like
        (M,) int, the particles of each pair contact.
    G : array_like
        (M,) the pair contacts' conductances (S).
    share : array_like
        (M,) the fraction of each pair contact's resistance on the side of i.
    plane_node : array_like
        (B,) int, the particle of each electrode contact.
    plane_index : array_like
        (B,) int, the electrode (its position in :class:`Electrodes`) of each electrode contact.
    G_plane : array_like
        (B,) the electrode contacts' conductances (S).
    electrodes : Electrodes
        The electrodes.
    linear : str
        The linear solver (``dem.network.linsolve.BACKENDS``, or ``"auto"``).
    previous : object or None
        The ``solver`` of an earlier :class:`CurrentFlow` to reuse; None: a new one.

    Returns
    -------
    CurrentFlow
        The potentials, currents and Joule heat.

    Raises
    ------
    ValueError
        No electrode is at a fixed potential.
    """
    i, j = np.asarray(i, dtype=np.int64), np.asarray(j, dtype=np.int64)
    plane_node, plane_index = np.asarray(plane_node, dtype=np.int64), np.asarray(plane_index, dtype=np.int64)
    G, G_plane, share = (np.asarray(x, dtype=float) for x in (G, G_plane, share))
    n_e = len(electrodes)
    if not np.any(electrodes.fixed_potential):
        raise ValueError("[electrical] no electrode at a fixed potential: give one wall a potential (e.g. "
                         "potential = 0.0, the ground) as the reference of the others")
    on_particles, on_electrodes, lone = _grounded(n, i, j, plane_node, plane_index, electrodes)
    driven = ~electrodes.fixed_potential
    no_path = tuple(name for name, d, r in zip(electrodes.names, driven, on_electrodes) if d and not r)
    floating = np.flatnonzero(~on_particles)
    # solve on the grounded particles only; bonds to electrodes without a path belong to floating groups
    system = BoundedLaplacian(n, i, j, G, None, plane_node, plane_index, G_plane, n_e)
    subset = np.flatnonzero(on_particles)
    V = np.where(electrodes.fixed_potential, electrodes.potential, 0.0)
    x0, solver = solve_anchored(system, system.plane_rhs(V), subset, linear, previous=previous)
    potential = np.full(n, np.nan)
    potential[subset] = x0
    active = np.flatnonzero(driven & on_electrodes)
    if len(active):
        def into_packing(x_particles, x_electrodes):
            flows = G_plane * (x_electrodes[plane_index] - np.nan_to_num(x_particles[plane_node]))
            return np.bincount(plane_index, flows, n_e)[active]

        unit = []
        for m in active:
            e = np.zeros(n_e)
            e[m] = 1.0
            x_m, _ = solve_anchored(system, system.plane_rhs(e), subset, solver=solver)
            full = np.zeros(n)
            full[subset] = x_m
            unit.append((full, e))
        full0 = np.where(on_particles, potential, 0.0)
        I0 = into_packing(full0, V)
        Y = np.column_stack([into_packing(x, e) for x, e in unit])
        V[active] = np.linalg.solve(Y, electrodes.current[active] - I0)
        potential[subset] = x0 + sum(V[m] * x[subset] for m, (x, _) in zip(active, unit))
    held = (lone >= 0) & on_particles  # a group reaching one electrode only: at its potential, exactly
    potential[held] = V[lone[held]]
    electrode_potential = np.where(electrodes.fixed_potential | on_electrodes, V, np.nan)
    x = np.nan_to_num(potential)  # floating particles carry nothing: their contacts join equal (zero) values
    c = contact_currents(n, i, j, G, share, plane_node, plane_index, G_plane, x, V, on_particles[plane_node])
    pair_current, wall_current, heat_pairs, heat_walls, joule_particles = c
    electrode_current = np.bincount(plane_index, wall_current, n_e)
    balance = (np.bincount(plane_node, wall_current, n) - np.bincount(i, pair_current, n)
               + np.bincount(j, pair_current, n))
    # relative to the largest contact current, or (when almost none flows) to the largest G |V|
    scale = max(float(np.max(np.abs(pair_current), initial=0.0)), float(np.max(np.abs(wall_current), initial=0.0)),
                1e-12 * float(np.max(G_plane, initial=0.0)) * float(np.max(np.abs(V), initial=0.0)))
    residual = float(np.max(np.abs(balance), initial=0.0)) / scale if scale > 0 else 0.0
    power = float(np.nansum(np.where(np.isfinite(electrode_potential), electrode_potential, 0.0) * electrode_current))
    return CurrentFlow(potential, pair_current, wall_current, electrode_potential, electrode_current, joule_particles,
                       float(heat_pairs.sum() + heat_walls.sum()), power, floating, no_path, residual, solver)


@dataclass
class ElectrodeBonds:
    """The current's network on the bonds of a packing: per pair bond its conductance ``G`` (S) and ``share`` (the
    fraction of its resistance on the side of i); the wall bonds to an electrode, ``(plane_node, plane_index)`` (the
    particle, the electrode's position in :class:`Electrodes`) of conductance ``G_plane`` (S), and ``on_electrode``
    (which of the bonds' wall bonds they are: a wall that is no electrode carries no current).

    Parameters
    ----------
    G : numpy.ndarray
        (M,) pair bond conductances (S).
    share : numpy.ndarray
        (M,) the fraction of each pair bond's resistance on the side of i.
    plane_node : array_like
        (B,) int, the particle of each electrode contact.
    plane_index : array_like
        (B,) int, the electrode (its position in :class:`Electrodes`) of each electrode contact.
    G_plane : array_like
        (B,) the electrode contacts' conductances (S).
    on_electrode : numpy.ndarray
        Bool per wall bond of the packing: True for those to an electrode.
    """

    G: np.ndarray
    share: np.ndarray
    plane_node: np.ndarray
    plane_index: np.ndarray
    G_plane: np.ndarray
    on_electrode: np.ndarray


def electrode_bonds(particles, bonds, walls, spec, electrodes: Electrodes, box=None) -> ElectrodeBonds:
    r"""The electrical conductances of ``bonds`` (:func:`dem.laws.conductance.bond_conductances` with the particles'
    electrical conductivity for :math:`\kappa`, without the interface conductance) and their wall bonds to the
    electrodes among ``walls``.

    Parameters
    ----------
    particles : dem.geometry.particles.Particles
        The particles, with their materials' electrical conductivity (S/m).
    bonds : dem.geometry.bonds.Bonds
        The pair and wall bonds.
    walls : sequence of dem.geometry.walls.Wall
        The scene's walls (the bonds' wall indices refer to them).
    spec : dem.laws.conductance.ConductanceSpec
        The conductance law (its interface conductance is left out).
    electrodes : Electrodes
        The electrodes.
    box : dem.geometry.periodic.PeriodicBox or None
        The periodic box of the bonds; None without one.

    Returns
    -------
    ElectrodeBonds
        The network of the current.
    """
    G, G_walls, share = bond_conductances(replace(spec, contact_conductance=None), particles, bonds,
                                          particles.electrical_conductivity, shares=True, box=box, walls=tuple(walls))
    electrode_of_wall = np.full(len(walls), -1, dtype=np.int64)
    electrode_of_wall[list(electrodes.walls)] = np.arange(len(electrodes))
    electrode = electrode_of_wall[bonds.wall_index]
    on = electrode >= 0
    return ElectrodeBonds(G, share, bonds.wall_particle[on], electrode[on], G_walls[on], on)


def circuit(electrodes: Electrodes, electrode_potential, electrode_current, joule_heat: float,
            electrode_power: float) -> dict:
    """What the summary says of a current: each electrode's potential (V) and current into the packing (A), the
    ``total_current`` that enters (A, the sum of the positive ones), the Joule heat of all contacts and the power the
    electrodes deliver (W; equal, Tellegen's theorem), and between two electrodes the ``resistance`` (Ohm) of the
    packing, their potential difference over the current.

    Parameters
    ----------
    electrodes : Electrodes
        The electrodes.
    electrode_potential : array_like
        (E,) electrode potentials (V).
    electrode_current : array_like
        (E,) electrode currents into the packing (A).
    joule_heat : float
        Joule heat of all contacts (W).
    electrode_power : float
        Power the electrodes deliver (W).

    Returns
    -------
    dict
        The summary's ``circuit`` entry.
    """
    current = np.asarray(electrode_current, dtype=float)
    total = float(current[current > 0].sum())
    out = {"electrodes": {name: {"potential": float(v), "current": float(i)} for name, v, i in
                          zip(electrodes.names, electrode_potential, current)},
           "total_current": total, "joule_heat": float(joule_heat), "electrode_power": float(electrode_power)}
    if len(electrodes) == 2 and total > 0:
        out["resistance"] = float(abs(electrode_potential[0] - electrode_potential[1]) / total)
    return out


def require_paths(flow: CurrentFlow, electrodes: Electrodes, plane_index, when: str = "") -> None:
    """A ``ValueError`` if an electrode driving a non-zero current has no path to one at a fixed potential
    (``plane_index``: the electrode of each wall bond; ``when``: e.g. the time, for the message).

    Parameters
    ----------
    flow : CurrentFlow
        The solution.
    electrodes : Electrodes
        The electrodes.
    plane_index : array_like
        (B,) int, the electrode of each electrode contact.
    when : str
        Text placed after the current in the message (``" at t = 1 s"``, say).

    Raises
    ------
    ValueError
        An electrode driving a non-zero current has no path to one at a fixed potential.
    """
    driven = [name for name in flow.no_path if electrodes.current[electrodes.names.index(name)] != 0.0]
    if driven:
        k = electrodes.names.index(driven[0])
        touches = "only a group that reaches none" if np.any(np.asarray(plane_index) == k) else "no particle"
        raise ValueError(f"walls.{driven[0]}.current = {electrodes.current[k]:g} A{when}: no path through the "
                         f"particles to an electrode at a fixed potential (the wall touches {touches}); a fixed "
                         f"current needs a closed circuit -- give the wall a potential (an open circuit then carries "
                         f"nothing) or start it in contact")


def refuse_floating(floating: np.ndarray, when: str = "") -> None:
    """The ``ValueError`` of ``[electrical] floating = "error"`` if any particle is ``floating`` (indices; ``when``:
    e.g. ``"at t = 1 s "``).

    Parameters
    ----------
    floating : numpy.ndarray
        Indices of the floating particles.
    when : str
        Text placed before the count in the message (``"at t = 1 s "``, say).

    Raises
    ------
    ValueError
        ``floating`` is not empty (the message lists up to ten of them).
    """
    if len(floating):
        shown = ", ".join(str(int(k)) for k in floating[:10]) + (", ..." if len(floating) > 10 else "")
        raise ValueError(f"[electrical] floating = \"error\": {when}{len(floating)} particle(s) touch no electrode "
                         f"through their contacts (floating: their potential is undetermined and they carry no "
                         f"current): {shown}")


def contact_currents(n: int, i, j, G, share, plane_node, plane_index, G_plane, x, V, live):
    """The currents at the potentials ``x`` (per particle) with the electrodes at ``V``: ``(pair_current`` A from i
    to j, ``wall_current`` A from each electrode into its particle (0 where ``live`` is False), the Joule heat
    :math:`I^2/G` of each pair and wall contact, and the Joule heat made in each particle``)``: a pair contact's shared
    by its particles in proportion to the resistances of their halves (``share``: i's), a wall contact's in its
    particle (module docstring).

    Parameters
    ----------
    n : int
        Number of particles.
    i, j : array_like
        (M,) int, the particles of each pair contact.
    G : array_like
        (M,) the pair contacts' conductances (S).
    share : array_like
        (M,) the fraction of each pair contact's resistance on the side of i.
    plane_node : array_like
        (B,) int, the particle of each electrode contact.
    plane_index : array_like
        (B,) int, the electrode (its position in :class:`Electrodes`) of each electrode contact.
    G_plane : array_like
        (B,) the electrode contacts' conductances (S).
    x : numpy.ndarray
        (N,) particle potentials (V).
    V : numpy.ndarray
        (E,) electrode potentials (V).
    live : numpy.ndarray
        (B,) bool, whether each electrode contact carries current.

    Returns
    -------
    tuple of numpy.ndarray
        ``(pair_current, wall_current, heat_pairs, heat_walls, joule_particles)``: A, A, W, W, W.
    """
    pair_current = G * (x[i] - x[j])
    wall_current = np.where(live, G_plane * (V[plane_index] - x[plane_node]), 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        heat_pairs = np.where(G > 0, pair_current**2 / G, 0.0)
        heat_walls = np.where(G_plane > 0, wall_current**2 / G_plane, 0.0)
    joule_particles = (np.bincount(i, share * heat_pairs, n) + np.bincount(j, (1.0 - share) * heat_pairs, n)
                       + np.bincount(plane_node, heat_walls, n))
    return pair_current, wall_current, heat_pairs, heat_walls, joule_particles


def wall_values(n: int, plane_node, plane_index, values) -> tuple[np.ndarray, np.ndarray]:
    """``(touching, value)``: which particles touch an electrified wall and the wall's value each takes (the mean
    of the walls' values when it touches several; Zohdi 2014, Remark 2).

    Parameters
    ----------
    n : int
        Number of particles.
    plane_node : array_like
        (B,) int, the particle of each electrode contact.
    plane_index : array_like
        (B,) int, the electrode (its position in :class:`Electrodes`) of each electrode contact.
    values : array_like
        (E,) each electrode's value.

    Returns
    -------
    tuple of numpy.ndarray
        ``touching`` (N,) bool and ``value`` (N,), 0 where not touching.
    """
    plane_node = np.asarray(plane_node, dtype=np.int64)
    count = np.bincount(plane_node, minlength=n)
    total = np.bincount(plane_node, np.asarray(values, dtype=float)[plane_index], n)
    touching = count > 0
    return touching, np.where(touching, total / np.maximum(count, 1), 0.0)


@dataclass
class AreaWeightedCurrent:
    """Zohdi's scheme: ``J`` (N,) per particle, the Gauss-Seidel ``sweeps`` taken, the last sweep's largest
    ``change`` (relative to the largest wall value), whether it reached the tolerance, and the ``floating``
    particles.

    Parameters
    ----------
    J : numpy.ndarray
        (N,) Zohdi's current per particle (the unit of ``J_ext``).
    sweeps : int
        Gauss-Seidel sweeps taken.
    change : float
        The last sweep's largest change, relative to the largest ``|J_ext|``.
    converged : bool
        Whether that change met the tolerance.
    floating : numpy.ndarray
        Indices of the particles in groups that touch no electrified wall (they carry no current).
    """

    J: np.ndarray
    sweeps: int
    change: float
    converged: bool
    floating: np.ndarray  # particles in groups that touch no electrified wall (they carry no current)


def area_weighted_current(n: int, i, j, area, plane_node, plane_index, J_ext, J0=None, tol: float = 1e-8,
                          max_sweeps: int = 10_000) -> AreaWeightedCurrent:
    """The current of Zohdi 2014, eqs. (42)-(43) with Remark 2 (module docstring): particles touching an electrified
    wall take its value ``J_ext`` (per electrode), the others the area-weighted mean of their neighbours, by
    Gauss-Seidel sweeps from ``J0`` (the previous solution: a warm start; zeros when None) until no value changes by
    more than ``tol`` times the largest ``|J_ext|``. Groups that touch no electrified wall carry no current.

    Parameters
    ----------
    n : int
        Number of particles.
    i, j : array_like
        (M,) int, the particles of each pair contact.
    area : array_like
        (M,) contact areas :math:`A_{ij}` of the pair contacts (m^2), the weights of eq. (43).
    plane_node : array_like
        (B,) int, the particle of each electrode contact.
    plane_index : array_like
        (B,) int, the electrode (its position in :class:`Electrodes`) of each electrode contact.
    J_ext : array_like
        (E,) each electrode's value ``J_ext``.
    J0 : array_like or None
        (N,) the previous solution, a warm start; None: zeros.
    tol : float
        The largest change per sweep at which the sweeps stop, relative to the largest ``|J_ext|``.
    max_sweeps : int
        The most sweeps.

    Returns
    -------
    AreaWeightedCurrent
        The solution.
    """
    from dem.network.gauss_seidel import gauss_seidel  # compiled: loaded by the schemes that sweep

    i, j = np.asarray(i, dtype=np.int64), np.asarray(j, dtype=np.int64)
    area = np.asarray(area, dtype=float)
    touching, value = wall_values(n, plane_node, plane_index, J_ext)
    rows = np.concatenate([i, j])
    cols = np.concatenate([j, i])
    adjacency = sp.csr_matrix((np.concatenate([area, area]), (rows, cols)), shape=(n, n))
    _, label = connected_components(adjacency, directed=False)
    electrified = np.isin(label, np.unique(label[touching]))
    J = np.zeros(n) if J0 is None else np.array(J0, dtype=float)
    J[touching] = value[touching]
    J[~electrified] = 0.0
    scale = float(np.max(np.abs(np.asarray(J_ext, dtype=float)), initial=0.0))
    free = np.flatnonzero(electrified & ~touching).astype(np.int64)
    floating = np.flatnonzero(~electrified)
    if scale == 0.0 or len(free) == 0:
        J[free] = 0.0 if scale == 0.0 else J[free]
        return AreaWeightedCurrent(J, 0, 0.0, True, floating)
    sweeps, change = gauss_seidel(adjacency.indptr.astype(np.int64), adjacency.indices.astype(np.int64),
                                  adjacency.data, free, J, tol * scale, max_sweeps)
    return AreaWeightedCurrent(J, int(sweeps), change / scale, change <= tol * scale, floating)


def zohdi_joule(J, volume, sigma, absorption: float) -> np.ndarray:
    r""":math:`H_i = a J_i^2 V_i / \sigma_i` (Zohdi 2014, eq. 35), W.

    Parameters
    ----------
    J : array_like
        (N,) Zohdi's current per particle.
    volume : array_like
        (N,) particle volumes (m^3).
    sigma : array_like
        (N,) electrical conductivities (S/m).
    absorption : float
        The absorbed fraction a, in ``[0, 1]``.

    Returns
    -------
    numpy.ndarray
        (N,) the Joule heat of each particle (W, with J in A/m^2).
    """
    return absorption * np.asarray(J) ** 2 * np.asarray(volume) / np.asarray(sigma)


def check_scheme(scheme: str) -> str:
    """``scheme`` if it is one of ``SCHEMES``.

    Parameters
    ----------
    scheme : str
        ``"kirchhoff"`` or ``"zohdi"``.

    Returns
    -------
    str
        ``scheme``.

    Raises
    ------
    ValueError
        ``scheme`` is not one of ``SCHEMES``.
    """
    if scheme not in SCHEMES:
        raise ValueError(f"[electrical] scheme = {scheme!r}: must be one of {', '.join(SCHEMES)}")
    return scheme


def check_absorption(a) -> float:
    """``a`` as a float if it is a number in ``[0, 1]``.

    Parameters
    ----------
    a : float
        The absorbed fraction of eq. (35).

    Returns
    -------
    float
        ``a``.

    Raises
    ------
    ValueError
        ``a`` is not a finite number in ``[0, 1]``.
    """
    if not isinstance(a, (int, float)) or isinstance(a, bool) or not math.isfinite(a) or not 0.0 <= a <= 1.0:
        raise ValueError(f"[electrical] absorption = {a!r}: must be in [0, 1] (Zohdi 2014, eq. 35)")
    return float(a)
