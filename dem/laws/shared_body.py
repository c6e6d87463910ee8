r"""The ``shared-body`` law: the pipe network corrected for the necks of one particle sharing its body.

The pipe network (Rojek 2022, eqs. 4-9) gives every bond two half-conductances in series, each calibrated on one
sintered pair: the half body from the particle's equatorial plane to the neck (eq. 36). That is exact for chains, but
a particle with necks in several directions passes heat between them through one body, and the network counts that
body once per bond: a dense packing conducts less than the network says (FCC by ~35 % at a/r = 0.4).

**The particle as a multi-terminal conductor.** Heat :math:`Q_c` entering a ball of radius ``r`` (conductivity
:math:`\kappa`) through small contacts ``c`` on its surface raises the temperature at contact ``b`` by
:math:`\sum_c R_{bc} Q_c` (with :math:`\sum Q = 0` in steady state). For point contacts :math:`R_{bc}` is the ball's
Neumann function between two surface points at the angle :math:`\gamma`; from its spherical-harmonic series,
:math:`\sum_{l \ge 1} \frac{2l+1}{l} P_l(\cos\gamma) / (4 \pi \kappa r)`, and the generating functions of
:math:`P_l` and :math:`P_l / l`:

.. math::

    G(\gamma) = \frac{1/s - 2 - \ln\left(s (1 + s)\right)}{4 \pi \kappa r}, \qquad
    s = \sin(\gamma / 2) = |n_b - n_c| / 2,

where the :math:`1/s` is twice the free-space source (a source on a surface), the logarithm the ball's finite size (the
term that gives the fit law its :math:`x \ln(1/x)`, :mod:`fem_neck.law`). A neck is not a point: its heat crosses the
disk of radius :math:`a_b` on the cap base plane, at :math:`z_b = \sqrt{r^2 - a_b^2}` from the centre, so the free-space
part is taken between the disk centres :math:`z_b n_b` (chord :math:`l_{bc} = |z_b n_b - z_c n_c|`), which is exact as
:math:`a \to 0` and brings wide necks closer. The model keeps the pair-calibrated half resistance :math:`R_b = 1 / K_b`
of the fit law on the diagonal (a neck's own constriction, its half neck and the sphere) and adds the interaction of
every other neck relative to the same two necks on opposite poles (:math:`l = z_b + z_c`, :math:`s = 1`):

.. math::

    R_{bb} = \frac{1}{K_b}, \qquad
    R_{bc} = \frac{2 r / l_{bc} - 2 r / (z_b + z_c) - \ln\left(s (1 + s) / 2\right)}{4 \pi \kappa r},

so that a particle whose necks are collinear (a pair, a chain) has :math:`R = \operatorname{diag}(1/K_b)`: today's
network exactly. Nothing is fitted; ``python -m verification lattices`` measures the residuals against periodic-cell
FE (the disk-centre chord removes most of what point contacts leave at large necks).

**Back to one temperature per particle.** The network keeps one node per particle, so the multi-terminal conductor
is reduced to one factor :math:`s_b` per neck on the fit law's half conductance :math:`K_b`. Neck ``b`` sits at
:math:`x_k + l_b n_b` (:math:`l_b` the centre-to-contact-plane distance); a uniform field ``g`` drives the flows
:math:`Q = Y N g` (``N`` the rows :math:`l_b n_b`, ``Y`` the conductance matrix of ``R`` on flows that sum to zero,
:math:`Y = R^{-1} - R^{-1} \mathbf{1} \mathbf{1}^T R^{-1} / (\mathbf{1}^T R^{-1} \mathbf{1})`). In the field along its
own neck, :math:`g = n_b`, neck ``b`` carries :math:`(Y N N^T)_{bb}`: the factor is that flow over the plain network's
(:math:`R = \operatorname{diag}(1/K_b)`):

.. math::

    s_b = \frac{(Y_R N N^T)_{bb}}{(Y_D N N^T)_{bb}}.

Summed over the necks these are the traces of the particle's conductivity tensors :math:`N^T Y N`: for a cubic
lattice, whose tensors are isotropic and whose necks are all alike, every :math:`s_b` is the ratio of the traces and
the reduction is exact; for the simple cubic lattice the interactions cancel in every uniform field (:math:`s = 1`,
the plain network, which the FE finds accurate). Necks close to one another share the body (:math:`s < 1`); two necks
closer than opposite poles, as in a bent chain, pass heat between them more easily than two equatorial half bodies
in series (:math:`s > 1`). Where the plain network's own flow in that field is nearly nil (other necks pointing the
same way) the particle's trace ratio is used instead; where the interactions outweigh the necks' own
resistances and leave no positive flow at all (necks far wider than the model's range, on a sphere its neighbours
have mostly swallowed), the particle keeps its plain halves (:math:`s = 1`) under the cap below.
Chains and pairs give :math:`s = 1` exactly: interactions below 1e-12 of the half resistances (collinear bonds to
round-off) count as none, so those results are today's ``fit`` law bit for bit.

**Never above the Wiener bound.** For the uniform field the network's energy is at most the sum over particles of
:math:`\sum_b s_b K_b l_b^2 (n_b \cdot g)^2` (the halves of a bond in series, Cauchy-Schwarz), and the Wiener bound
:math:`\phi \kappa` is the same field's energy in the solid, :math:`\kappa V_k |g|^2` per particle. So a particle's
factors are scaled down together wherever :math:`\lambda_{max}\left(\sum_b s_b K_b l_b^2 n_b n_b^T\right)` exceeds
:math:`\kappa V_k` (:math:`V_k = \frac{4}{3} \pi r^3`, the volume each particle keeps under the volume-conserving
neck): a periodic network then never conducts more than :math:`\phi \kappa`. The cap binds only where the necks
overlap (beyond the pair model); it is applied to particles with non-collinear necks.

**Under the union of spheres** (``neck = "union"``, :func:`dem.laws.conductance.bond_conductances`) the half bodies
are first narrowed to the cut sphere (:mod:`dem.laws.cut_body`), and the cap holds the *mean* of the particle's
tensor over three directions, its trace over 3, to :math:`\kappa V_k` with :math:`V_k` its cut sphere's volume
(:func:`fem_neck.geometry.union.cut_spheres`). In a random packing of overlapping spheres a particle's tensor is
anisotropic (its largest eigenvalue up to :math:`1.4 \kappa V_k` while its mean stays below), and capping the largest
eigenvalue particle by particle took 12-22 % off the k_eff of random union packings at :math:`\phi` 0.6-0.8 that the
FE does not lose; summed over the particles the trace cap keeps the mean of the network's three principal
conductivities at or below :math:`\phi \kappa` (on the cubic lattices, whose tensors are isotropic, the two caps
agree). Where the pores around a particle close, its cap is lowered below the Wiener bound by the pores' shape
(:mod:`dem.laws.closing_pores`: the ``volume`` passed here is then the cut sphere's times that ratio).

A wall bond is a neck too (toward the wall, the mirror pair's neck), so it takes part in its particle's factor.

The factors are computed per particle in one compiled loop (numba, the particles shared among the threads): a
Gaussian elimination of the ``z x z`` matrix ``R`` with four right-hand sides, without allocating.

**The particle as an element with a node per neck** (``[conductance] nodes = "necks"``, :mod:`dem.network.necks`).
Solved exactly, with a node per neck, the same conductor needs no factors: :func:`particle_elements` gives each
particle's conductance matrix over its necks and its centre (the inverse of ``R`` bordered by the centre, scaled down
by the same trace cap). There the free-space part of the interaction is taken between the necks' actual faces,
each the flat disc of radius :math:`a_b` at :math:`l_b n_b` clipped by the particle's other planes (the cut sphere's
face): :math:`2 r \langle 1 / |x - y| \rangle` over the two faces (uniform weight on each, :func:`face_interaction`)
in place of :math:`2 r / l_{bc}`, relative to the same two faces turned onto opposite poles (face ``c`` rotated
about :math:`n_c \times n_b` until :math:`n_c = -n_b`) in place of :math:`2 r / (z_b + z_c)`, so that collinear
necks still interact by nothing. Wide necks at right angles, whose faces come close along the edge where their
planes meet, are what the disc centres miss (the verification guide measures both against the FE).
"""

from __future__ import annotations

from collections import namedtuple

import numba
import numpy as np

from dem.geometry.bonds import Bonds
from fem_neck.geometry.cut_kernels import ends_by_particle

ROUNDOFF = 1e-12  # interactions below this x the smallest half resistance are round-off of collinear bonds

# What the compiled loop takes (named tuples of arrays: one argument each to numba)
PairNecks = namedtuple("PairNecks", ["i", "j", "vec", "a", "l_i", "l_j", "k_i", "k_j"])
PairNecks.__doc__ = """The pair bonds' necks (m bonds): particles ``i``, ``j`` (int), ``vec`` (m, 3) from ``i`` to the
partner (m), neck radii ``a`` (m), centre-to-contact distances ``l_i``, ``l_j`` (m), half conductances ``k_i``,
``k_j`` (W/K)."""
WallNecks = namedtuple("WallNecks", ["particle", "normal", "a", "l", "k"])
WallNecks.__doc__ = """The wall bonds' necks: the particle (int), the wall's unit ``normal`` into the packing, neck
radius ``a`` (m), centre-to-contact distance ``l`` (m), half conductance ``k`` (W/K)."""
Bodies = namedtuple("Bodies", ["radius", "kappa", "share"])
Bodies.__doc__ = """Per particle: ``radius`` (m), conductivity ``kappa`` (W/(m K)) and ``share``, the solid it holds
over its sphere's volume."""


@numba.njit(cache=True)
def interaction(normal_b, normal_c, base_b: float, base_c: float) -> float:
    r""":math:`4 \pi \kappa r R_{bc}` of two necks with unit normals ``normal_b``, ``normal_c`` and cap-base distances
    ``base_b``, ``base_c`` (in units of ``r``), relative to the same necks on opposite poles (module docstring)."""
    cos_g = normal_b[0] * normal_c[0] + normal_b[1] * normal_c[1] + normal_b[2] * normal_c[2]
    return _interaction(cos_g, base_b, base_c)


@numba.njit(cache=True)
def _interaction(cos_g: float, base_b: float, base_c: float) -> float:
    """:func:`interaction` from the cosine of the angle between the necks. A neck as wide as the particle (``a = r``,
    where ``out_of_range = "clip"`` sets a neck past the pair reading's range) has its disc centre at the particle's
    centre, from where the chord to another neck's disc centre is that neck's opposite-pole distance: its free-space
    part is 0, and between two such necks (chord and pole distance both 0) the same 0."""
    s2 = 0.5 * (1.0 - cos_g)
    if s2 >= 1.0:
        return 0.0
    s = np.sqrt(max(s2, 1e-24))
    chord = np.sqrt(max(base_b * base_b + base_c * base_c - 2.0 * base_b * base_c * cos_g, 1e-24))
    return 2.0 / chord - 2.0 / max(base_b + base_c, 1e-12) - np.log(s * (1.0 + s) * 0.5)


@numba.njit(cache=True)
def _solve_in_place(A, X, z):
    """Solve ``A[:z, :z] Y = X[:z]`` by Gaussian elimination with partial pivoting, overwriting ``X`` with ``Y`` (and
    ``A``); a small dense system per particle, solved without allocating."""
    m = X.shape[1]
    for c in range(z):
        p = c
        for r in range(c + 1, z):
            if abs(A[r, c]) > abs(A[p, c]):
                p = r
        if p != c:
            for k in range(z):
                A[c, k], A[p, k] = A[p, k], A[c, k]
            for k in range(m):
                X[c, k], X[p, k] = X[p, k], X[c, k]
        for r in range(c + 1, z):
            f = A[r, c] / A[c, c]
            for k in range(c, z):
                A[r, k] -= f * A[c, k]
            for k in range(m):
                X[r, k] -= f * X[c, k]
    for c in range(z - 1, -1, -1):
        for k in range(m):
            v = X[c, k]
            for j in range(c + 1, z):
                v -= A[c, j] * X[j, k]
            X[c, k] = v / A[c, c]


@numba.njit(cache=True)
def _own_flux(x, N, z, flux):
    """``flux[b] = (Y N)_b . N_b`` for every neck ``b`` from ``x = R^-1 [N 1]``:
    ``Y N = X_N - y (1^T X_N) / (1^T y)``."""
    ones = 0.0
    t0 = t1 = t2 = 0.0
    for b in range(z):
        ones += x[b, 3]
        t0 += x[b, 0]
        t1 += x[b, 1]
        t2 += x[b, 2]
    for b in range(z):
        y = x[b, 3] / ones
        flux[b] = (x[b, 0] - y * t0) * N[b, 0] + (x[b, 1] - y * t1) * N[b, 1] + (x[b, 2] - y * t2) * N[b, 2]


@numba.njit(cache=True, parallel=True)
def _factors(n_particles, pairs, walls, bodies, trace_cap):
    """The factor of every neck end (module docstring) of the ``n_particles`` particles ``bodies``
    (:class:`Bodies`): end ``e < m`` is pair bond ``e``'s half on its particle ``i``, ``m <= e < 2m`` its half on
    ``j`` (:class:`PairNecks`), and the rest the wall bonds' halves (:class:`WallNecks`). The neck ends are grouped
    by particle (a counting sort) and the particles shared among the threads in chunks."""
    i, j, wall_particle = pairs.i, pairs.j, walls.particle
    m, mw = len(i), len(wall_particle)
    total = 2 * m + mw
    out = np.ones(total)
    offsets, ends = ends_by_particle(n_particles, np.concatenate((i, j, wall_particle)))
    z_max = int(np.max(offsets[1:] - offsets[:-1])) if total else 0
    chunk = 4096
    for block in numba.prange((n_particles + chunk - 1) // chunk):
        _block_factors(block * chunk, min((block + 1) * chunk, n_particles), offsets, ends, pairs, walls, bodies,
                       trace_cap, z_max, out)
    return out


@numba.njit(cache=True)
def _gather_necks(k, ends, pairs, walls, bodies, normal, arm, q, half_r):
    """Particle ``k``'s necks (``ends``: its pair ends ``e < 2 m``, ``e - m`` on ``j``, then its wall bonds): the unit
    normal from its centre, over its radius the arm and the neck radius (at most 1), and :math:`4 \\pi \\kappa r`
    over the half conductance, into the first ``len(ends)`` rows of ``normal``, ``arm``, ``q`` and ``half_r``."""
    m = len(pairs.i)
    r = bodies.radius[k]
    for b in range(len(ends)):
        e = ends[b]
        if e < 2 * m:
            bond = e if e < m else e - m
            sign = 1.0 if e < m else -1.0
            length = np.sqrt(pairs.vec[bond, 0] ** 2 + pairs.vec[bond, 1] ** 2 + pairs.vec[bond, 2] ** 2)
            for c in range(3):
                normal[b, c] = sign * pairs.vec[bond, c] / length
            neck, arm[b] = pairs.a[bond], (pairs.l_i[bond] if e < m else pairs.l_j[bond]) / r
            half = pairs.k_i[bond] if e < m else pairs.k_j[bond]
        else:
            w = e - 2 * m
            for c in range(3):
                normal[b, c] = -walls.normal[w, c]
            neck, arm[b], half = walls.a[w], walls.l[w] / r, walls.k[w]
        q[b] = min(neck / r, 1.0)
        half_r[b] = 4.0 * np.pi * bodies.kappa[k] * r / half


@numba.njit(cache=True)
def _block_factors(first, last, offsets, ends, pairs, walls, bodies, trace_cap, z_max, out):
    """:func:`_factors` for the particles ``first:last``, with work arrays of their own."""
    radius, share = bodies.radius, bodies.share
    normal = np.empty((z_max, 3))
    base = np.empty(z_max)
    arm = np.empty(z_max)
    half_r = np.empty(z_max)
    R = np.empty((z_max, z_max))
    N = np.empty((z_max, 4))
    x = np.empty((z_max, 4))
    num = np.empty(z_max)
    den = np.empty(z_max)
    M = np.empty((3, 3))
    for k in range(first, last):
        lo, hi = offsets[k], offsets[k + 1]
        z = hi - lo
        if z < 2:
            continue
        r = radius[k]
        _gather_necks(k, ends[lo:hi], pairs, walls, bodies, normal, arm, base, half_r)
        for b in range(z):  # over r, the cap-base distance
            base[b] = np.sqrt((1.0 - base[b]) * (1.0 + base[b]))
        small = np.inf
        largest = 0.0
        for b in range(z):
            R[b, b] = half_r[b]
            small = min(small, half_r[b])
            for c in range(b):
                cos_g = normal[b, 0] * normal[c, 0] + normal[b, 1] * normal[c, 1] + normal[b, 2] * normal[c, 2]
                g = _interaction(cos_g, base[b], base[c])
                R[b, c] = g
                R[c, b] = g
                largest = max(largest, abs(g))
        if largest <= ROUNDOFF * small:
            continue  # collinear necks: the plain network, bit for bit
        for b in range(z):  # the neck positions l_b n_b, and ones
            for c in range(3):
                N[b, c] = arm[b] * normal[b, c]
                x[b, c] = N[b, c]
            N[b, 3] = 1.0
            x[b, 3] = 1.0
        _solve_in_place(R, x, z)  # R^-1 [N 1]
        _own_flux(x, N, z, num)
        for b in range(z):  # the same for the plain network, R = diag(half_r)
            for c in range(4):
                x[b, c] = N[b, c] / half_r[b]
        _own_flux(x, N, z, den)
        total_num = total_den = scale = 0.0
        for b in range(z):
            total_num += num[b]
            total_den += den[b]
            scale = max(scale, abs(den[b]))
        # the interactions outweighing the necks' own resistances (R not positive: necks far wider than the model's
        # range, on a sphere its neighbours have mostly swallowed) leave no positive flow: the plain halves
        positive = total_den > 0.0 and total_num > 0.0
        trace = total_num / total_den if positive else 1.0
        factor = num  # reused: the factors of particle k's necks
        for b in range(z):
            # a neck whose own flow the plain network barely moves (others pointing its way) takes the trace
            ok = positive and den[b] > 1e-6 * scale and num[b] > 0.0
            factor[b] = num[b] / den[b] if ok else trace
        # Wiener: sum_b s_b K_b l_b^2 n_b n_b^T at most kappa V_k (units K_b = 4 pi / half_r, V_k = 4/3 pi); its
        # trace bounds its largest eigenvalue, which is only computed when the trace exceeds the limit
        M[:, :] = 0.0
        for b in range(z):
            w = factor[b] * 4.0 * np.pi / half_r[b] * arm[b] ** 2
            for p in range(3):
                for c in range(3):
                    M[p, c] += w * normal[b, p] * normal[b, c]
        limit = 4.0 / 3.0 * np.pi * share[k]
        shrink = 1.0
        trace = M[0, 0] + M[1, 1] + M[2, 2]
        if trace_cap:  # the mean over three directions (union of spheres: module docstring)
            if trace > 3.0 * limit:
                shrink = 3.0 * limit / trace
        elif trace > limit:
            lam = np.linalg.eigvalsh(M)[2]
            if lam > limit:
                shrink = limit / lam
        for b in range(z):
            out[ends[lo + b]] = factor[b] * shrink


def neck_factors(n: int, radius: np.ndarray, bonds: Bonds, vectors: np.ndarray, k_i: np.ndarray, k_j: np.ndarray,
                 k_wall: np.ndarray, conductivity: np.ndarray, wall_normals: np.ndarray, volume=None,
                 trace_cap: bool = False):
    """The factors ``(s_i, s_j, s_wall)`` of every pair bond's two halves and every wall bond's half (module
    docstring) from the particles' necks: the pair bonds (``vectors`` from ``i`` to the partner, neck radii
    ``bonds.a``, half conductances ``k_i``, ``k_j`` in W/K) and the wall bonds (unit ``wall_normals`` pointing into
    the packing, ``bonds.wall_a``, half conductances ``k_wall``).

    Parameters
    ----------
    n : int
        Number of particles.
    radius : numpy.ndarray
        Particle radii, m.
    bonds : Bonds
        The pair and wall bonds with their neck radii (m) and centre-to-contact distances (m).
    vectors : numpy.ndarray
        ``x_j - x_i`` of every pair bond (m, 3), m.
    k_i, k_j : numpy.ndarray
        Half conductances of every pair bond on the side of ``i`` and of ``j``, W/K.
    k_wall : numpy.ndarray
        Half conductance of every wall bond, W/K.
    conductivity : numpy.ndarray
        Per particle, its material's conductivity, W/(m K).
    wall_normals : numpy.ndarray
        Unit normal of every wall bond's wall (pointing into the packing).
    volume : numpy.ndarray, optional
        Per particle, the solid it holds, m^3 (default: its sphere's, which the volume-conserving neck keeps; under
        the union of spheres its cut sphere's), whose Wiener bound caps its factors.
    trace_cap : bool
        Cap the mean of the particle's tensor over three directions (its trace / 3) instead of its largest
        eigenvalue (module docstring; the union of spheres).

    Returns
    -------
    tuple of numpy.ndarray
        The factors of the pair bonds' halves on ``i`` and on ``j`` and of the wall bonds' halves (dimensionless).
    """
    f = np.ascontiguousarray
    sphere = 4.0 / 3.0 * np.pi * np.asarray(radius, dtype=float) ** 3
    share = np.ones(n) if volume is None else np.asarray(volume, dtype=float) / sphere
    pairs = PairNecks(f(bonds.i, dtype=np.int64), f(bonds.j, dtype=np.int64), f(vectors, dtype=float),
                      f(bonds.a, dtype=float), f(bonds.l_i, dtype=float), f(bonds.l_j, dtype=float),
                      f(k_i, dtype=float), f(k_j, dtype=float))
    walls = WallNecks(f(bonds.wall_particle, dtype=np.int64), f(np.reshape(wall_normals, (-1, 3)), dtype=float),
                      f(bonds.wall_a, dtype=float), f(bonds.wall_l, dtype=float), f(k_wall, dtype=float))
    bodies = Bodies(f(radius, dtype=float), f(conductivity, dtype=float), f(share, dtype=float))
    out = _factors(n, pairs, walls, bodies, bool(trace_cap))
    m = bonds.n_pairs
    return out[:m], out[m:2 * m], out[2 * m:]


# ------------------------------------------------------------------------------- the particle with a node per neck
FACE_RINGS, FACE_ANGLES = 6, 24  # a face's quadrature: Gauss-Legendre rings in (rho / a)^2 (equal area), equal angles
_nodes, _weights = np.polynomial.legendre.leggauss(FACE_RINGS)
FACE_T, FACE_W = 0.5 * (_nodes + 1.0), 0.5 * _weights  # on [0, 1], weights summing to 1


@numba.njit(cache=True)
def _face_points(normal, arm, q, z, points, weights):
    """The quadrature of each of the ``z`` necks' faces (units of ``r``): the disc of radius ``q[b]`` at
    ``arm[b] normal[b]``, its points beyond another neck's plane weighted 0 (all kept where none is left), the
    weights summing to 1; into ``points`` (z, FACE_RINGS * FACE_ANGLES, 3) and ``weights``."""
    for b in range(z):
        n = normal[b]
        h = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        t1 = np.cross(n, h)
        t1 /= np.sqrt(t1[0] ** 2 + t1[1] ** 2 + t1[2] ** 2)
        t2 = np.cross(n, t1)
        total = 0.0
        for ring in range(FACE_RINGS):
            rho = q[b] * np.sqrt(FACE_T[ring])
            for k in range(FACE_ANGLES):
                angle = 2.0 * np.pi * (k + 0.5) / FACE_ANGLES
                p = ring * FACE_ANGLES + k
                keep = True
                for c in range(3):
                    points[b, p, c] = arm[b] * n[c] + rho * (np.cos(angle) * t1[c] + np.sin(angle) * t2[c])
                for o in range(z):
                    if o != b and (points[b, p, 0] * normal[o, 0] + points[b, p, 1] * normal[o, 1]
                                   + points[b, p, 2] * normal[o, 2]) > arm[o] + 1e-12:
                        keep = False
                        break
                weights[b, p] = FACE_W[ring] / FACE_ANGLES if keep else 0.0
                total += weights[b, p]
        if total == 0.0:  # a face the other planes clip away entirely: the whole disc
            for ring in range(FACE_RINGS):
                for k in range(FACE_ANGLES):
                    weights[b, ring * FACE_ANGLES + k] = FACE_W[ring] / FACE_ANGLES
            total = 1.0
        for p in range(FACE_RINGS * FACE_ANGLES):
            weights[b, p] /= total


@numba.njit(cache=True, fastmath={"reassoc", "nsz", "contract"})
def _mean_inverse_distance(x, wx, nx, y, wy, ny):
    """:math:`\\langle 1 / |x - y| \\rangle` over two weighted point sets, the first ``nx`` columns of ``x`` (3, .)
    and ``wx`` and the first ``ny`` of ``y`` and ``wy`` (the points of weight 0 left out); the inner sum in any order
    (SIMD lanes: round-off)."""
    total = 0.0
    for q in range(ny):
        y0, y1, y2 = y[0, q], y[1, q], y[2, q]
        inner = 0.0
        for p in range(nx):
            d2 = (x[0, p] - y0) ** 2 + (x[1, p] - y1) ** 2 + (x[2, p] - y2) ** 2
            inner += wx[p] / np.sqrt(max(d2, 1e-18))
        total += wy[q] * inner
    return total


@numba.njit(cache=True)
def _turn(u, v):
    """The rotation taking the unit vector ``u`` to ``v`` (about ``u x v``; the half turn about an axis normal to
    ``u`` where they are opposite, the identity where they agree)."""
    w = np.cross(u, v)
    sn = np.sqrt(w[0] ** 2 + w[1] ** 2 + w[2] ** 2)
    cs = u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
    if sn < 1e-12:
        if cs > 0.0:
            return np.eye(3)
        h = np.array([1.0, 0.0, 0.0]) if abs(u[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        w = np.cross(u, h)
        w /= np.sqrt(w[0] ** 2 + w[1] ** 2 + w[2] ** 2)
        return 2.0 * np.outer(w, w) - np.eye(3)
    w /= sn
    W = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    return np.eye(3) + sn * W + (1.0 - cs) * (W @ W)


@numba.njit(cache=True)
def _face_matrix(normal, arm, q, z, out):
    """:math:`4 \\pi \\kappa r R_{bc}` (``b != c``) of the faces' interaction (module docstring) into ``out``."""
    npts = FACE_RINGS * FACE_ANGLES
    points = np.empty((z, npts, 3))
    weights = np.empty((z, npts))
    _face_points(normal, arm, q, z, points, weights)
    # each face's points of weight > 0, coordinates in rows (3, count): the inner loop over them runs in SIMD lanes
    kept = np.zeros((z, 3, npts))
    kept_w = np.zeros((z, npts))
    count = np.zeros(z, dtype=np.int64)
    for b in range(z):
        for p in range(npts):
            if weights[b, p] != 0.0:
                k = count[b]
                for c in range(3):
                    kept[b, c, k] = points[b, p, c]
                kept_w[b, k] = weights[b, p]
                count[b] = k + 1
    turned = np.empty((3, npts))
    for b in range(z):
        for c in range(b):
            cos_g = normal[b, 0] * normal[c, 0] + normal[b, 1] * normal[c, 1] + normal[b, 2] * normal[c, 2]
            s = np.sqrt(max(0.5 * (1.0 - cos_g), 1e-24))
            near = _mean_inverse_distance(kept[b], kept_w[b], count[b], kept[c], kept_w[c], count[c])
            T = _turn(normal[c], -normal[b])
            for p in range(count[c]):
                for e in range(3):
                    turned[e, p] = T[e, 0] * kept[c, 0, p] + T[e, 1] * kept[c, 1, p] + T[e, 2] * kept[c, 2, p]
            far = _mean_inverse_distance(kept[b], kept_w[b], count[b], turned, kept_w[c], count[c])
            g = 2.0 * near - 2.0 * far - np.log(s * (1.0 + s) * 0.5)
            out[b, c] = g
            out[c, b] = g


def face_interaction(normals, arms, necks) -> np.ndarray:
    r""":math:`4 \pi \kappa r R_{bc}` of the faces' interaction between every two of a particle's necks (module
    docstring), all lengths in units of the particle's radius ``r``.

    Parameters
    ----------
    normals : array_like
        (z, 3) unit normals of the necks, from the centre outward.
    arms : array_like
        (z,) distance of each neck's plane from the centre, over ``r``.
    necks : array_like
        (z,) neck radii over ``r``.

    Returns
    -------
    numpy.ndarray
        (z, z) the interactions (dimensionless), 0 on the diagonal.
    """
    normals = np.ascontiguousarray(normals, dtype=float).reshape(-1, 3)
    out = np.zeros((len(normals), len(normals)))
    _face_matrix(normals, np.ascontiguousarray(arms, dtype=float), np.ascontiguousarray(necks, dtype=float),
                 len(normals), out)
    return out


@numba.njit(cache=True)
def _positive_definite(A, z) -> bool:
    """Whether ``A[:z, :z]`` (symmetric) is positive definite (a Cholesky factorisation of a copy succeeds)."""
    L = np.zeros((z, z))
    for c in range(z):
        d = A[c, c]
        for k in range(c):
            d -= L[c, k] ** 2
        if d <= 0.0:
            return False
        L[c, c] = np.sqrt(d)
        for r in range(c + 1, z):
            v = A[r, c]
            for k in range(c):
                v -= L[r, k] * L[c, k]
            L[r, c] = v / L[c, c]
    return True


@numba.njit(cache=True, parallel=True)
def _elements(n_particles, pairs, walls, bodies):
    """Every particle's element (:func:`particle_elements`): ``(offsets, ends, start, values, plain, shrink)``."""
    i, j, wall_particle = pairs.i, pairs.j, walls.particle
    m = len(i)
    offsets, ends = ends_by_particle(n_particles, np.concatenate((i, j, wall_particle)))
    size = offsets[1:] - offsets[:-1] + 1
    start = np.zeros(n_particles + 1, dtype=np.int64)
    start[1:] = np.cumsum(size * size)
    values = np.zeros(start[-1])
    plain = np.zeros(n_particles, dtype=np.bool_)
    shrink = np.ones(n_particles)
    radius, kappa, share = bodies.radius, bodies.kappa, bodies.share
    for k in numba.prange(n_particles):
        lo, hi = offsets[k], offsets[k + 1]
        z = hi - lo
        if z == 0:
            continue
        r = radius[k]
        normal = np.empty((z, 3))
        arm = np.empty(z)
        q = np.empty(z)
        half_r = np.empty(z)
        _gather_necks(k, ends[lo:hi], pairs, walls, bodies, normal, arm, q, half_r)
        R = np.zeros((z, z))
        if z > 1:
            _face_matrix(normal, arm, q, z, R)
            largest = 0.0
            small = np.inf
            for b in range(z):
                small = min(small, half_r[b])
                for c in range(z):
                    largest = max(largest, abs(R[b, c]))
            if largest <= ROUNDOFF * small:  # collinear necks: the plain halves
                R[:, :] = 0.0
        for b in range(z):
            R[b, b] = half_r[b]
        if not _positive_definite(R, z):  # interactions outweighing the necks' own resistances: the plain halves
            plain[k] = True
            R[:, :] = 0.0
            for b in range(z):
                R[b, b] = half_r[b]
        Y = np.eye(z)
        _solve_in_place(R.copy(), Y, z)  # R^-1, in units of 4 pi kappa r
        Y = 0.5 * (Y + Y.T)
        unit = 4.0 * np.pi * kappa[k] * r
        # the trace cap (module docstring) on the tensor N^T Y_c N of the centre-free conductance Y_c, N_b = l_b n_b
        row = Y.sum(axis=1)
        total = row.sum()
        trace = 0.0
        if z > 1 and total > 0.0:
            for b in range(z):
                for c in range(z):
                    dot = normal[b, 0] * normal[c, 0] + normal[b, 1] * normal[c, 1] + normal[b, 2] * normal[c, 2]
                    trace += (Y[b, c] - row[b] * row[c] / total) * arm[b] * arm[c] * dot
            trace *= unit * r * r
        limit = 3.0 * kappa[k] * 4.0 / 3.0 * np.pi * r ** 3 * share[k]
        if trace > limit:
            shrink[k] = limit / trace
        f = unit * shrink[k]
        coupled = False
        for b in range(z):
            for c in range(b):
                coupled = coupled or R[b, c] != 0.0
        if coupled:  # the centre joined to the necks by their halves (particle_elements' docstring)
            halves = 1.0 / half_r
            spread = halves.sum()
            for b in range(z):
                for c in range(z):
                    Y[b, c] += halves[b] * halves[c] / spread - row[b] * row[c] / total
            row = halves
            total = spread
        s = z + 1
        at = start[k]
        for b in range(z):  # local nodes: the necks in the order of ``ends``, then the centre
            for c in range(z):
                values[at + b * s + c] = f * Y[b, c]
            values[at + b * s + z] = -f * row[b]
            values[at + z * s + b] = -f * row[b]
        values[at + z * s + z] = f * total
    return offsets, ends, start, values, plain, shrink


ParticleElements = namedtuple("ParticleElements", ["offsets", "ends", "start", "values", "plain", "shrink", "modes"],
                              defaults=(1,))
ParticleElements.__doc__ = """Every particle's conductance matrix over its necks and its centre (:func:`particle_elements`).
The ends of particle ``k`` are ``ends[offsets[k]:offsets[k + 1]]`` (end ``e < m``: pair bond ``e``'s neck on its
``i``; ``m <= e < 2 m``: pair bond ``e - m``'s on its ``j``; the rest the wall bonds'), its ``(z + 1) x (z + 1)``
matrix (W/K; local nodes: those ends in order, then the centre) row by row at ``values[start[k]:start[k + 1]]``;
``plain`` marks the particles whose interactions were dropped (their ``R`` not positive definite) and ``shrink``
holds the trace cap's factor of each. ``modes`` is the number of flux modes per neck (1 here; an element with the
dipoles, :mod:`dem.network.necks` "Flux modes", has 3 and a ``(3 z + 1) x (3 z + 1)`` matrix whose local node
``3 p + d`` is mode ``d`` of its ``p``-th end): one number for all the particles, or an int array of one per
particle where their elements differ."""


def particle_elements(n: int, radius: np.ndarray, bonds: Bonds, vectors: np.ndarray, k_i: np.ndarray,
                      k_j: np.ndarray, k_wall: np.ndarray, conductivity: np.ndarray, wall_normals: np.ndarray,
                      volume=None) -> ParticleElements:
    r"""Each particle as an element with a node per neck and one at its centre (module docstring): with ``R`` the
    multi-terminal resistance (the half resistances :math:`1/K_b` on its diagonal, the faces' interaction between
    necks), the flows into the particle through its necks are :math:`Q = R^{-1} (T_\mathrm{necks} - T_c \mathbf 1)`
    and its centre takes :math:`-\sum Q`; the whole matrix is scaled down where the trace of the particle's tensor
    exceeds :math:`3 \kappa V_k`. A particle whose necks are collinear (a pair, a chain) has ``R`` diagonal: its
    halves in series, today's network. The arguments are those of :func:`neck_factors`.

    ``R`` describes flows through the necks that sum to zero (heat passing through the particle: the interactions
    are the sphere's Neumann function of such flows); the net flow between the centre and the necks (a particle held
    at a temperature, a heat source, its heat capacity) takes the one-node law's path, each neck's half
    :math:`K_b = 1/R_{bb}` from the centre. So the necks' block is :math:`Y_0 + K K^T / \sum K` with
    :math:`Y_0 = R^{-1} - R^{-1} \mathbf 1 \mathbf 1^T R^{-1} / (\mathbf 1^T R^{-1} \mathbf 1)` the centre-free
    conductance, the centre's column :math:`-K` and its diagonal :math:`\sum K`: eliminating a free centre with no
    source leaves :math:`Y_0`, what :math:`R^{-1}` bordered by its own sums leaves, so a network of free particles is
    the same either way; a held particle whose centre fed its necks through :math:`R^{-1} \mathbf 1` conducted 4-8 %
    too little on finite clusters held by layers of fixed particles (isolated against exact elements of the cut
    spheres and full FE of two clusters in a lab run; the one-node law's path sits within 1.2 % of the exact
    elements' there).

    Parameters
    ----------
    n : int
        Number of particles.
    radius : numpy.ndarray
        Particle radii, m.
    bonds : Bonds
        The pair and wall bonds (all live: a half conductance 0 has no element) with their neck radii (m) and
        centre-to-contact distances (m).
    vectors : numpy.ndarray
        ``x_j - x_i`` of every pair bond (m, 3), m.
    k_i, k_j : numpy.ndarray
        Half conductances of every pair bond on the side of ``i`` and of ``j``, W/K.
    k_wall : numpy.ndarray
        Half conductance of every wall bond, W/K.
    conductivity : numpy.ndarray
        Per particle, its material's conductivity, W/(m K).
    wall_normals : numpy.ndarray
        Unit normal of every wall bond's wall (pointing into the packing).
    volume : numpy.ndarray, optional
        Per particle, the solid it holds, m^3, whose Wiener bound caps the trace of its tensor (default: its
        sphere's).

    Returns
    -------
    ParticleElements
        The elements.
    """
    f = np.ascontiguousarray
    sphere = 4.0 / 3.0 * np.pi * np.asarray(radius, dtype=float) ** 3
    share = np.ones(n) if volume is None else np.asarray(volume, dtype=float) / sphere
    pairs = PairNecks(f(bonds.i, dtype=np.int64), f(bonds.j, dtype=np.int64), f(vectors, dtype=float),
                      f(bonds.a, dtype=float), f(bonds.l_i, dtype=float), f(bonds.l_j, dtype=float),
                      f(k_i, dtype=float), f(k_j, dtype=float))
    walls = WallNecks(f(bonds.wall_particle, dtype=np.int64), f(np.reshape(wall_normals, (-1, 3)), dtype=float),
                      f(bonds.wall_a, dtype=float), f(bonds.wall_l, dtype=float), f(k_wall, dtype=float))
    bodies = Bodies(f(radius, dtype=float), f(conductivity, dtype=float), f(share, dtype=float))
    return ParticleElements(*_elements(n, pairs, walls, bodies))
