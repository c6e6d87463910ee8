r"""Conductance of the thermal pipes: each bond's two halves (and an optional contact interface) in series.

Rojek 2022, Section 3: :math:`R_{ij} = R_i + R_j + R_c` (eq. 5), i.e.
:math:`K_{ij} = K_i K_j K_c / (K_i K_j + K_j K_c + K_i K_c)` (eq. 8), or eq. (9) without the interface. Every law is a
*half* conductance ``K_i`` of one particle's side of the contact, evaluated with that particle's own conductivity,
radius and contact; putting the halves in series makes the mixed-material rule the harmonic combination of the two
halves.

Laws (``ConductanceSpec.law``):

* ``"rojek"`` -- :math:`K_i = c \kappa_i \pi a` with :math:`c = 1.064` (eqs. 40, 43); equal materials give
  :math:`K_{ij} = K_i / 2` (eq. 45). ``slope`` overrides c.
* ``"argento-bouvard"`` -- the same with :math:`c = 1/0.899 = 1.112` (eqs. 41-42).
* ``"fit"`` -- the full-range FE law :math:`K_i = \kappa_i \pi r_i f(a/r_i)` read from a fit.json written by
  ``python -m fem_neck fit`` (``fit_file``; default: the fit shipped in ``fem_neck/data/fit.json``), each half at
  its own ``a/r_i``; for unequal radii the series is multiplied by the FE correction
  :func:`fem_neck.law.unequal_factor` (``unequal = true``, default), as :func:`fem_neck.law.pair_conductance` does.
* ``"shared-body"`` -- the ``fit`` law's halves, each particle's scaled by one factor for the necks that share its
  body (the particle as a multi-terminal conductor, from the Neumann function of the sphere;
  :mod:`dem.laws.shared_body`); pairs and chains get the ``fit`` law's numbers exactly.
* ``"zohdi"`` -- :math:`K_{ij} = \kappa A_c / |x_i - x_j|` with the lens contact area :math:`A_c = \pi a^2` (Zohdi 2014,
  eqs. 11-12, 33), written as halves :math:`K_i = \kappa_i \pi a^2 / L_i` (:math:`L_i + L_j = |x_i - x_j|`, eq. 9),
  which is eq. (33) exactly for one material. (Zohdi's footnote 4 averages two conductivities arithmetically; the halves
  in series are the harmonic combination this project uses for every law.)

A wall bond is one half (the particle's side; the wall is isothermal) in series with :math:`K_c`.

The ``zohdi`` law on the pairs and particle-wall pairs of a Verlet list, contact geometry included, is compiled
(:func:`dem.laws.lens_conductance.lens_list_conductances`, apart so that a static run loads no numba): particles that
move evaluate it at every fixed-point iteration of their step (:mod:`dem.engines.staggered.heat`), on the list as it
is, without building bonds.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from fem_neck import law as fem_law

from dem.geometry.bonds import OUT_OF_RANGE, Bonds
from dem.geometry.particles import Particles

LAWS = ("rojek", "argento-bouvard", "fit", "shared-body", "zohdi")
FIT_LAWS = ("fit", "shared-body")  # the laws built on the full-range fit (fit_file, unequal)
DESCRIPTIONS = {
    "rojek": "1.064 kappa pi a per half, halves in series (Rojek 2022, eqs. 40, 43-45)",
    "argento-bouvard": "1.112 kappa pi a per half, halves in series (Argento & Bouvard 1996; Rojek 2022, eq. 42)",
    "fit": "kappa pi r f(a/r) per half from the full-range FE fit (fit.json), halves in series, unequal-radii factor",
    "shared-body": "the fit law with each particle's halves scaled for the necks sharing its body (sphere Neumann "
                   "function; exact for pairs and chains, never above the Wiener bound)",
    "zohdi": "kappa pi a^2 / |x_i - x_j| with the lens contact circle (Zohdi 2014, eqs. 11-12, 33)",
}
NECK_MODELS = ("newton", "first", "coble", "union")
NODES = ("particles", "necks")  # the network's nodes: one per particle, or also one per neck (dem.network.necks)
#: each particle's element with a node per neck, the law's (dem.laws.shared_body.particle_elements) or the Trefftz
#: element of its cut sphere with three flux modes per neck (dem.network.trefftz_element)
ELEMENTS = ("law", "trefftz")


def law_keys(law: str) -> tuple:
    """The ``[conductance]`` keys the law ``law`` reads besides ``law`` (:class:`ConductanceSpec`).

    Parameters
    ----------
    law : str
        A law of ``LAWS``.

    Returns
    -------
    tuple of str
        The keys, the law's own first (``slope``; ``fit_file``, ``unequal``), then ``neck`` (all but
        ``"zohdi"``), ``contact_conductance`` and ``out_of_range``.
    """
    own = ("slope",) if law in ("rojek", "argento-bouvard") else ("fit_file", "unequal") if law in FIT_LAWS else ()
    return own + (() if law == "zohdi" else ("neck",)) + ("contact_conductance", "out_of_range")
LINEAR_SLOPES = {"rojek": fem_law.ROJEK.slope, "argento-bouvard": fem_law.ARGENTO_BOUVARD.slope}


@dataclass(frozen=True)
class ConductanceSpec:
    r"""Which law, and its options: ``slope`` (linear laws), ``fit_file`` (fit), ``neck`` model for the neck laws,
    ``contact_conductance`` :math:`K_c` in W/K (eq. 8; None = no interface resistance), ``out_of_range`` bond policy.

    Parameters
    ----------
    law : str
        The law, one of ``LAWS`` (module docstring).
    slope : float or None
        The coefficient c of :math:`K_i = c \kappa_i \pi a` (dimensionless, > 0), for ``"rojek"`` and
        ``"argento-bouvard"`` only; None: the law's own (1.064, 1.112).
    fit_file : str or None
        Path of a fit.json written by ``python -m fem_neck fit``, for ``"fit"`` and ``"shared-body"`` only; None:
        the fit shipped for the half body.
    neck : str
        The neck model giving the contact radius from the overlap, one of ``NECK_MODELS`` (``"newton"``,
        ``"first"``, ``"coble"``: :func:`fem_neck.geometry.neck_radius`; ``"union"``: the circle where the two
        spheres meet).
    contact_conductance : float or None
        Interface conductance :math:`K_c` in series with each bond (W/K, finite and > 0; Rojek 2022, eq. 8); None: no
        interface resistance.
    out_of_range : str
        What a bond whose overlap lies beyond the neck model's range does, one of
        ``dem.geometry.bonds.OUT_OF_RANGE``: ``"error"``, ``"clip"`` or ``"drop"``.
    unequal : bool
        Whether the fit laws multiply a pair of unequal radii by :func:`fem_neck.law.unequal_factor`.
    nodes : str
        The network's nodes, one of ``NODES``: ``"particles"`` (one per particle, each bond a conductance) or
        ``"necks"`` (a node per neck as well, each particle an element, :mod:`dem.network.necks`; ``shared-body``
        without ``contact_conductance`` only, under any neck reading).
    element : str
        Each particle's element with a node per neck, one of ``ELEMENTS``: ``"law"`` (the ``shared-body`` law's,
        :func:`dem.laws.shared_body.particle_elements`) or ``"trefftz"`` (the Trefftz element of its cut sphere with
        three flux modes per neck, :mod:`dem.network.trefftz_element`; built on the cut spheres, so only with
        ``law = "shared-body"``, ``nodes = "necks"`` and ``neck = "union"``).

    Raises
    ------
    ValueError
        An option is out of its range or given to a law that does not read it; a fit file that cannot be read
        or was fitted for the other half body.
    """

    law: str = "rojek"
    slope: float | None = None
    fit_file: str | None = None
    neck: str = "newton"
    contact_conductance: float | None = None
    out_of_range: str = "error"
    unequal: bool = True
    nodes: str = "particles"
    element: str = "law"

    def __post_init__(self):
        if self.law not in LAWS:
            raise ValueError(f"conductance.law = {self.law!r}: must be one of {', '.join(LAWS)}")
        if self.neck not in NECK_MODELS:
            raise ValueError(f"conductance.neck = {self.neck!r}: must be one of {', '.join(NECK_MODELS)}")
        if self.out_of_range not in OUT_OF_RANGE:
            raise ValueError(f"conductance.out_of_range = {self.out_of_range!r}: must be one of "
                             f"{', '.join(OUT_OF_RANGE)}")
        if self.slope is not None and (self.law not in LINEAR_SLOPES or not np.isfinite(self.slope)
                                       or self.slope <= 0):
            raise ValueError(f"conductance.slope = {self.slope!r}: must be > 0 and only with law rojek or "
                             f"argento-bouvard")
        if not isinstance(self.unequal, bool):
            raise ValueError(f"conductance.unequal = {self.unequal!r}: must be true or false")
        if self.fit_file is not None and self.law not in FIT_LAWS:
            raise ValueError(f"conductance.fit_file = {self.fit_file!r}: only with law = \"fit\" or \"shared-body\"")
        kc = self.contact_conductance
        if kc is not None and (not np.isfinite(kc) or kc <= 0):
            raise ValueError(f"conductance.contact_conductance = {kc!r}: must be finite and > 0 (W/K)")
        if self.nodes not in NODES:
            raise ValueError(f"conductance.nodes = {self.nodes!r}: must be one of {', '.join(NODES)}")
        if self.nodes == "necks" and (self.law != "shared-body" or kc is not None):
            raise ValueError(f"conductance.nodes = \"necks\": only with law = \"shared-body\" and no "
                             f"contact_conductance (here law = {self.law!r}, contact_conductance = {kc!r})")
        if self.element not in ELEMENTS:
            raise ValueError(f"conductance.element = {self.element!r}: must be one of {', '.join(ELEMENTS)}")
        if self.element == "trefftz" and (self.law, self.nodes, self.neck) != ("shared-body", "necks", "union"):
            raise ValueError(f"conductance.element = \"trefftz\": only with law = \"shared-body\", nodes = \"necks\" "
                             f"and neck = \"union\" (the element of each cut sphere; here law = {self.law!r}, nodes = "
                             f"{self.nodes!r}, neck = {self.neck!r})")
        if self.law in FIT_LAWS:
            self.fitted()  # a missing or malformed fit file, or one of the other half body, is reported when read

    @property
    def contact(self) -> str:
        """The contact geometry the law needs (:mod:`dem.geometry.bonds`)."""
        return "lens" if self.law == "zohdi" else self.neck

    def fitted(self):
        """The full-range law of the fit laws (:class:`fem_neck.law.ConductanceLaw`) for this neck reading: the
        union of spheres' half body (no neck cylinder) for ``neck = "union"``, the neck cylinder's otherwise;
        ``fit_file`` (default: the fit shipped for that half body) must have been fitted for it."""
        half_body = "union" if self.neck == "union" else "cylinder"
        return fit_law(self.fit_file, half_body).require_neck(half_body)


@functools.lru_cache(maxsize=8)
def fit_law(path: str | None, neck: str = "cylinder"):
    """The full-range law of a fit.json (:class:`fem_neck.law.ConductanceLaw`), read once per path; without a path
    the one shipped for the half body ``neck`` (``"cylinder"`` or ``"union"``).

    Parameters
    ----------
    path : str or None
        Path of a fit.json written by ``python -m fem_neck fit``; None: the shipped fit.
    neck : str
        The half body of the shipped fit (:data:`fem_neck.law.NECKS`), read only where ``path`` is None.

    Returns
    -------
    fem_neck.law.ConductanceLaw
        The law.

    Raises
    ------
    ValueError
        The file cannot be read or is malformed.
    """
    return fem_law.ConductanceLaw.default(neck) if path is None else fem_law.ConductanceLaw.from_json(path)


def half_conductance(spec: ConductanceSpec, kappa, r, a, length):
    """One particle's half of a contact in W/K (module docstring); ``length`` is the centre-to-contact distance.

    Vectorised: the arrays broadcast against each other.

    Parameters
    ----------
    spec : ConductanceSpec
        The law and its options.
    kappa : float or array_like
        The particle's thermal conductivity (W/(m K)), or electrical conductivity (S/m) for a conductance in S.
    r : float or array_like
        The particle's radius (m).
    a : float or array_like
        The contact (neck) radius (m).
    length : float or array_like
        Distance from the particle's centre to the contact plane (m), read by ``"zohdi"`` only.

    Returns
    -------
    numpy.ndarray
        The half conductance ``K_i`` (W/K; S with an electrical conductivity).
    """
    kappa, r, a, length = (np.asarray(x, dtype=float) for x in (kappa, r, a, length))
    if spec.law in LINEAR_SLOPES:                                                     # eqs. (43), (42)
        k = (spec.slope or LINEAR_SLOPES[spec.law]) * kappa
        if not isinstance(k, np.ndarray) or k.shape != np.broadcast_shapes(k.shape, a.shape):
            return k * np.pi * a  # a number, or a shape that a widens
        k *= np.pi  # in place: one fresh array of the bonds' length, not three
        return np.multiply(k, a, out=k)
    if spec.law in FIT_LAWS:
        return kappa * np.pi * r * np.asarray(spec.fitted().k_over_kcyl(np.minimum(a / r, 1.0)))
    with np.errstate(divide="ignore"):
        return kappa * np.pi * a * a / length                                         # Zohdi 2014, eq. (33)


def series(*halves):
    r"""Conductances in series, :math:`1 / \sum (1/K)` (Rojek 2022, eqs. 5-9); an infinite half adds no resistance.

    Parameters
    ----------
    *halves : float or array_like or None
        The conductances (W/K), broadcast against each other; a None is left out (no such part).

    Returns
    -------
    numpy.ndarray
        The series conductance (W/K).
    """
    halves = [np.asarray(k, dtype=float) for k in halves if k is not None]
    with np.errstate(divide="ignore"):  # summed in place: one fresh array of the bonds' length and one per further half
        resistance = np.divide(1.0, halves[0], out=np.empty(np.broadcast_shapes(*(k.shape for k in halves))))
        for k in halves[1:]:
            resistance += 1.0 / k
        return np.divide(1.0, resistance, out=resistance)[()]


def bond_conductances(spec: ConductanceSpec, particles: Particles, bonds: Bonds, conductivity=None,
                      shares: bool = False, *, box=None, walls=(), closing_pores: dict | None = None,
                      union: tuple | None = None):
    r"""``(K_pairs, K_walls)`` in W/K for every pair bond and wall bond.

    ``conductivity`` (per particle) replaces the materials' :math:`\kappa`: the same law with the electrical
    conductivity :math:`\sigma` gives each contact's electrical conductance in S (the neck is the same Laplace problem,
    :math:`\sigma` in place of :math:`\kappa`). With ``shares = True`` a third array gives each pair bond's fraction of
    its resistance on the side of particle i, :math:`R_i / (R_i + R_j)` (where that part of the bond's Joule heat is
    made). ``box``: the periodic box the bonds' image shifts refer to (:mod:`dem.geometry.periodic`); ``walls``: the
    walls of the wall bonds, whose normals the ``shared-body`` law needs; ``closing_pores``: the calibration of the
    closing pores' cap of ``shared-body`` under the union of spheres (:mod:`dem.laws.closing_pores`); ``union``: that
    law's halves on the cut spheres already computed (:func:`union_halves`, as the network with a node per neck has
    them), so that they are not computed again.

    Parameters
    ----------
    spec : ConductanceSpec
        The law and its options.
    particles : dem.geometry.particles.Particles
        The particles: radii (m), positions (m), materials' conductivities (W/(m K)).
    bonds : dem.geometry.bonds.Bonds
        The pair and wall bonds, with their contact radii (m) and centre-to-contact distances (m).
    conductivity : array_like or None
        (N,) a conductivity per particle in place of the materials' :math:`\kappa` (W/(m K), or S/m for electrical
        conductances in S); None: the materials'.
    shares : bool
        Whether to return each pair bond's share of its resistance on the side of particle i as well.
    box : dem.geometry.periodic.PeriodicBox or None
        The periodic box the bonds' image shifts refer to; None without one.
    walls : sequence of dem.geometry.walls.Wall
        The walls of the wall bonds (indexed by ``bonds.wall_index``), needed by ``"shared-body"``.
    closing_pores : dict or None
        ``{"beta": float, "psi0": float}`` of :func:`dem.laws.closing_pores.cap_ratio` (dimensionless); None: the
        shipped calibration (:data:`dem.laws.closing_pores.CALIBRATION`).
    union : tuple or None
        ``shared-body`` under ``neck = "union"``: what :func:`union_halves` returned for these particles and bonds
        (with ``conductivity`` None); None: computed here.

    Returns
    -------
    tuple of numpy.ndarray
        ``(K_pairs, K_walls)`` (W/K, or S), and with ``shares`` the share :math:`R_i / (R_i + R_j)` per pair bond
        (dimensionless).

    Raises
    ------
    ValueError
        ``"shared-body"`` has wall bonds but no walls, or a conductance is not finite and >= 0 (the law and the
        bond are named).
    """
    kappa = particles.conductivity if conductivity is None else np.asarray(conductivity, dtype=float)
    r = particles.radius
    kc = spec.contact_conductance
    k_i, k_j, k_w = bond_halves(spec, particles, bonds, kappa) if union is None else (None, None, None)
    if spec.law == "shared-body":
        from dem.laws.shared_body import neck_factors

        normals = wall_normals(bonds, walls)
        vectors = bonds.vectors(particles.position, box)
        if spec.neck == "union":
            if union is None:
                union = union_halves(particles, bonds, vectors, normals, kappa, k_i, k_j, k_w, closing_pores, box,
                                     walls)
            k_i, k_j, k_w = _shared_union_body(particles, bonds, vectors, normals, kappa, union)
        else:
            s_i, s_j, s_w = neck_factors(particles.n, r, bonds, vectors, k_i, k_j, k_w, kappa, normals)
            k_i, k_j, k_w = s_i * k_i, s_j * k_j, s_w * k_w
    k_pair = series(k_i, k_j)
    unequal = unequal_factor(spec, r, bonds)
    if unequal is not None:
        k_pair = k_pair * unequal
    k_pair, k_wall = series(k_pair, kc), series(k_w, kc)
    _check_finite(spec, k_pair, bonds.a, lambda k: f"bond ({bonds.i[k]}, {bonds.j[k]})")
    _check_finite(spec, k_wall, bonds.wall_a, lambda k: f"wall bond of particle {bonds.wall_particle[k]}")
    if not shares:
        return k_pair, k_wall
    with np.errstate(divide="ignore", invalid="ignore"):
        share = k_j / (k_i + k_j)  # R_i / (R_i + R_j); an infinite half (a centre on the contact plane) makes none
    share = np.where(np.isfinite(share), share, np.where(np.isinf(k_i), 0.0, 1.0))
    return k_pair, k_wall, share


def unequal_factor(spec: ConductanceSpec, radius: np.ndarray, bonds: Bonds):
    """The fit laws' correction of a pair of unequal radii (:func:`fem_neck.law.unequal_factor`, fitted to neck
    cylinders) on every pair bond's series conductance, where the law takes it: ``unequal = true`` on a pair-neck
    reading.

    Parameters
    ----------
    spec : ConductanceSpec
        The conductance law and its neck reading.
    radius : numpy.ndarray
        Per particle, its radius, m.
    bonds : Bonds
        The pair bonds (neck radii, m).

    Returns
    -------
    numpy.ndarray or None
        The factor per pair bond (dimensionless); None where the law takes none (or there are no pair bonds).
    """
    if spec.law in FIT_LAWS and spec.unequal and spec.neck != "union" and bonds.n_pairs:
        return fem_law.unequal_factor(radius[bonds.i], radius[bonds.j], bonds.a)
    return None


def bond_halves(spec: ConductanceSpec, particles: Particles, bonds: Bonds, kappa: np.ndarray):
    """The law's half conductances of every bond, each on its own (:func:`half_conductance`): of the pair bonds on
    ``i`` and on ``j``, and of the wall bonds.

    Parameters
    ----------
    spec : ConductanceSpec
        The conductance law and its neck reading.
    particles : dem.geometry.particles.Particles
        The particles (radii, m).
    bonds : Bonds
        The pair and wall bonds (neck radii and centre-to-contact distances, m).
    kappa : numpy.ndarray
        Per particle, its conductivity, W/(m K).

    Returns
    -------
    tuple of numpy.ndarray
        ``(k_i, k_j, k_w)``, W/K.
    """
    r = particles.radius
    k_i = half_conductance(spec, kappa[bonds.i], r[bonds.i], bonds.a, bonds.l_i)
    k_j = half_conductance(spec, kappa[bonds.j], r[bonds.j], bonds.a, bonds.l_j)
    p = bonds.wall_particle
    return k_i, k_j, half_conductance(spec, kappa[p], r[p], bonds.wall_a, bonds.wall_l)


def wall_normals(bonds: Bonds, walls) -> np.ndarray:
    """The unit normal (into the packing) of every wall bond's wall, ``(B, 3)``.

    Parameters
    ----------
    bonds : dem.geometry.bonds.Bonds
        The bonds (their ``wall_index``).
    walls : sequence of dem.geometry.walls.Wall
        The walls the wall bonds index.

    Returns
    -------
    numpy.ndarray
        ``(B, 3)`` unit normals.

    Raises
    ------
    ValueError
        There are wall bonds but no walls.
    """
    if bonds.n_walls and not len(walls):
        raise ValueError("conductance.law = \"shared-body\": the wall bonds' walls are needed (their normals)")
    return np.array([w.normal for w in walls])[bonds.wall_index] if bonds.n_walls else np.zeros((0, 3))


def _shared_union_body(particles: Particles, bonds: Bonds, vectors, normals, kappa, union: tuple):
    """The ``shared-body`` halves under the union of spheres: each half body of the union law narrowed to the
    particle's cut sphere (:mod:`dem.laws.cut_body`), then the factors of the necks sharing it
    (:mod:`dem.laws.shared_body`) with the cut sphere's volume in the cap on the mean of the particle's tensor,
    lowered where the pores around the particle close (:mod:`dem.laws.closing_pores`); a neck inside a third sphere
    (its half conductance 0) carries nothing and takes no part in the factors.

    Parameters
    ----------
    particles : dem.geometry.particles.Particles
        The particles (radii, m).
    bonds : Bonds
        The union bonds (lens radii and radical-plane distances, m).
    vectors : numpy.ndarray
        ``x_j - x_i`` of every pair bond, m.
    normals : numpy.ndarray
        The unit normal of every wall bond's wall, into the packing.
    kappa : numpy.ndarray
        Per particle, its conductivity, W/(m K).
    union : tuple
        What :func:`union_halves` returned for these particles and bonds: the narrowed halves (W/K), the live bonds'
        masks and the capped volumes (m^3).

    Returns
    -------
    tuple of numpy.ndarray
        The three arrays of half conductances, W/K.
    """
    from dem.laws.shared_body import neck_factors

    k_i, k_j, k_w, pairs, walls_live, volume = union
    live = bonds.subset(pairs, walls_live)
    s_i, s_j, s_w = neck_factors(particles.n, particles.radius, live, vectors[pairs], k_i[pairs], k_j[pairs],
                                 k_w[walls_live], kappa, np.reshape(normals, (-1, 3))[walls_live], volume,
                                 trace_cap=True)
    k_i, k_j, k_w = np.where(pairs, k_i, 0.0), np.where(pairs, k_j, 0.0), k_w.copy()
    k_i[pairs] *= s_i
    k_j[pairs] *= s_j
    k_w[walls_live] *= s_w
    return k_i, k_j, k_w


def union_halves(particles: Particles, bonds: Bonds, vectors, normals, kappa, k_i, k_j, k_w,
                 closing_pores: dict | None = None, box=None, walls=()):
    """The union law's half conductances narrowed to each particle's cut sphere (:mod:`dem.laws.cut_body`), which
    bonds are live (a neck inside a third sphere has a half 0 and is none) and each particle's capped volume (its cut
    sphere's, lowered where the pores around it close, :mod:`dem.laws.closing_pores`): what the ``shared-body``
    particle is made of under the union of spheres, with one node per particle (the factors of :mod:`dem.laws.shared_body`) or a
    node per neck (:mod:`dem.network.necks`).

    Parameters
    ----------
    particles : dem.geometry.particles.Particles
        The particles (radii, m).
    bonds : Bonds
        The union bonds (lens radii and radical-plane distances, m).
    vectors : numpy.ndarray
        ``x_j - x_i`` of every pair bond, m.
    normals : numpy.ndarray
        The unit normal of every wall bond's wall, into the packing.
    kappa : numpy.ndarray
        Per particle, its conductivity, W/(m K).
    k_i, k_j, k_w : numpy.ndarray
        The union law's half conductances of the pair bonds on ``i``, on ``j`` and of the wall bonds, W/K.
    closing_pores : dict or None
        The closing pores' ``beta`` and ``psi0`` (dimensionless); None: the shipped calibration.
    box : dem.geometry.periodic.PeriodicBox or None
        The periodic box of the packing (the particles' cells take their neighbours across its faces); None without.
    walls : sequence of dem.geometry.walls.Wall
        The walls (they bound the particles' cells where they come near).

    Returns
    -------
    tuple
        ``(k_i, k_j, k_w, pairs, walls, volume)``: the narrowed halves of all bonds (W/K), the masks of the live pair
        and wall bonds, and per particle the volume its tensor's trace is capped by (m^3).
    """
    from fem_neck.geometry.union import cut_spheres

    from dem.laws.closing_pores import calibration, cap_ratio, particle_cells, power_planes
    from dem.laws.cut_body import cut_body_resistance

    r = particles.radius
    unit = vectors / bonds.d[:, None]  # the bonds' lengths, found with them
    particle = np.concatenate([bonds.i, bonds.j, bonds.wall_particle])
    directions = np.vstack([unit, -unit, -np.reshape(normals, (-1, 3))])
    planes = np.concatenate([bonds.l_i, bonds.l_j, bonds.wall_l])
    ends = cut_body_resistance(r, particle, directions, planes) / kappa[particle]
    fit = closing_pores or calibration()
    caps = cap_ratio(*particle_cells(r, *power_planes(particles.position, r, box, walls)), fit["beta"], fit["psi0"])
    m = bonds.n_pairs
    with np.errstate(divide="ignore"):  # no extra resistance (0): an infinite conductance in series
        k_i, k_j, k_w = (series(k, 1.0 / dR) for k, dR in ((k_i, ends[:m]), (k_j, ends[m:2 * m]),
                                                         (k_w, ends[2 * m:])))
    pairs, live_walls = (k_i > 0.0) & (k_j > 0.0), k_w > 0.0
    volume = cut_spheres(r, bonds.i[pairs], bonds.j[pairs], vectors[pairs]).volume * caps
    return k_i, k_j, k_w, pairs, live_walls, volume


def _check_finite(spec: ConductanceSpec, K: np.ndarray, a: np.ndarray, name) -> None:
    """Every conductance a finite number >= 0 W/K; else the law (e.g. a fit_file with NaN parameters) is named."""
    bad = ~(np.isfinite(K) & (K >= 0.0))
    if np.any(bad):
        k = int(np.flatnonzero(bad)[0])
        source = f" from fit_file = {spec.fit_file!r}" if spec.law in FIT_LAWS else ""
        raise ValueError(f"conductance.law = {spec.law!r}{source} gives K = {float(K[k])!r} W/K for {name(k)} (neck radius "
                         f"a = {a[k]:.6g} m): conductances must be finite and >= 0")

