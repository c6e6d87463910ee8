r"""A particle's element with three flux modes per neck from a Trefftz (Ritz) solve of its cut body.

The body is the particle's sphere cut by the planes of its necks (:mod:`fem_neck.geometry.union`: the union of
spheres, each cut by its radical planes). Per neck three flux modes (:mod:`dem.network.necks`, "Flux modes"): the
monopole :math:`w / W` with the uniform sink :math:`1/V` that balances it, and the dipoles
:math:`w (\xi_d - \bar\xi_d) / (a W)` along :func:`dem.network.necks.neck_frames`, with the profile
:math:`w = (a^2 - \rho^2)^{-1/4}` on the neck's disc of radius ``a`` (:math:`W = \int w`, :math:`\bar\xi_d` the
``w``-weighted mean). The temperature is sought among the real solid harmonics of degree 1 to ``L`` and
:math:`|x|^2` (the sink's particular field); the Ritz (Galerkin) equations :math:`K c = B` need only boundary
integrals, since every basis function is harmonic but :math:`|x|^2`, whose Laplacian is constant:
:math:`K_{ab} = \int_{\partial\Omega} \phi_a \partial_n \phi_b`, the sphere's part by orthogonality (:math:`\int
\phi_a \partial_n \phi_b = l \delta_{ab}` on the unit sphere) less the caps the planes cut off plus the faces; the
loads are the modes' moments of the basis on the faces. :math:`R = B^T K^{-1} B` is the element's resistance over its
``3 z`` modes (units :math:`1 / (\kappa r)`), below the exact one (Ritz).

Quadrature: on a face, polar coordinates about a point inside the clipped disc, one panel between consecutive
vertices of its boundary, graded toward the rim by :math:`t = 1 - (1 - s)^4` along each ray (the profile's
:math:`(a^2 - \rho^2)^{-1/4}` becomes a smooth :math:`(1 - s)^2`) and in angle by :math:`(1 - \cos \pi s)/2` toward the
vertices (an unclipped disc: equal steps in angle, which do not depend on its orientation); on a cap, rings in the polar angle about the plane's normal between the angles where other caps' rims
cross it, each ring's arcs outside the earlier caps by Gauss-Legendre. The rule of degree ``L`` (:func:`rule`) has
``L + 2`` radii and ``L + 4`` angles per face panel, ``L + 4`` rings per cap panel and ``2 L + 6`` points per full ring.

A small neck's own resistance converges slowly in ``L`` (the self term of a near-singular flux). Each monopole's
diagonal is therefore moved by what the same ``L`` and rule miss on the chain particle (two opposite necks of the
same radius, where the union law's half :math:`1 / (\pi K/K_{cyl})` is the exact half, :mod:`fem_neck.law`):
:math:`R_{bb} \mathrel{+}= h_\mathrm{law}(a_b/r) - h_L(a_b/r)`, with :math:`h_L` the chain's Trefftz half
:math:`(R_{00} + R_{33} - 2 R_{03}) / 2` (:func:`chain_shift`). Nothing else is adjusted: the correction is made of
single-particle problems only. A particle whose shifted ``R`` is not positive definite keeps the law's element on its
monopoles (:func:`dem.laws.shared_body.particle_elements`) and its unshifted dipole block, marked ``plain``.

**The quadrature's check.** The rule of degree ``L`` is not enough for every cut body: where faces meet at small
angles or a cap is cut into slivers, the high harmonics are integrated badly and ``R`` can come out wrong by percents
(a monopole's diagonal even above the exact one, which a Ritz ``R`` never is). Two identities of harmonic functions
tell it from the same points at no extra cost: Green's identity makes the harmonics' block of the stiffness
symmetric, :math:`\oint \phi_a \partial_n \phi_b = \oint \phi_b \partial_n \phi_a`, and each harmonic's flux
vanishes, :math:`\oint \partial_n \phi_a = 0`. Measured on the solution (``C`` the Ritz coefficients of the ``3 z``
modes, ``h`` the harmonics' rows), the defect is the larger of the skew part's energy
:math:`|C_h^T (K - K^T)_{hh} C_h|_{bc} / \sqrt{R_{bb} R_{cc}}` and the modes' fluxes :math:`|\oint \partial_n
u_b|` (of their unit heat). A particle whose defect exceeds :data:`DEFECT` is computed again with the rule's counts
times 1.5, then 2 (:data:`REFINE`); one that still fails keeps the law's element like a particle whose ``R`` is not
positive definite. On the 296 particles of the 39 union cells at ``L`` 10 the defect tracks the change of the
monopole diagonals under a doubled rule: the 18 particles above 2e-3 (three distinct ones of the random packings,
3e-3 to 2e-2) move by 0.5 to 1.7 %, every other one by at most 0.11 % (its defect at most 8e-4; the lattices'
particles' at most 2e-4), and 1.5 times the rule brings all 18 below the threshold (and within 0.011 % of the doubled
rule's diagonals). A refined particle keeps the degree's own shift: the chain particle's half moves by at most 3e-4 of
itself between the rules (at a/r 0.9; below 1e-7 up to a/r 0.7). The volume
(:math:`\oint x \cdot n = 3 V` against :func:`fem_neck.geometry.union.cut_spheres`) is within 6e-8 on all of them,
so it tells nothing at this degree and is not computed.

**The centre.** :math:`Y = R^{-1}` (units :math:`\kappa r`) carries the heat that passes through the particle; its
centre would be the body's mean temperature with a uniform sink (:func:`dem.network.necks.bordered`). The element
keeps that through-flow, :math:`Y_0 = Y - Y e e^T Y / (e^T Y e)` (``e`` 1 on the monopoles: the Schur complement on
the modes of ``Y`` bordered by its sums), and joins the centre to the monopoles by the law's halves :math:`K_b` (the
half conductances the law's element takes from its centre, :func:`dem.laws.shared_body.particle_elements`), the
dipoles not touching it:

.. math::

    E = \begin{pmatrix} Y_0 + k k^T / \textstyle\sum K & -k \\ -k^T & \sum K \end{pmatrix},
    \qquad k = K \text{ on the monopoles, } 0 \text{ on the dipoles}.

Eliminating a free centre without a source leaves :math:`Y_0` either way, so a network of free particles is the same;
the path matters where the centre's net flow is not zero (a particle held at a temperature, a source, its heat
capacity). It is the law's because the law's evidence is that: a held particle whose centre fed its necks through
:math:`R^{-1} \mathbf 1` conducted 4-8 % too little on finite clusters held by layers of fixed particles, where the
halves' path sat within 1.2 % of exact elements (:func:`dem.laws.shared_body.particle_elements`).

A wall bond's face is a plane cut like a neck's: normal into the wall, arm ``wall_l / r``, dipoles along
:func:`dem.network.necks.neck_frames` of that normal; the network sets its three modes (the monopole at the wall's
temperature, the dipoles' moments 0: the wall is isothermal, :mod:`dem.network.necks`). Its monopole takes the same
chain shift: a particle between two walls at its necks' planes is the chain particle, since the neck plane of a
symmetric pair is isothermal by symmetry.

**On every core.** The particles' elements are independent, and :func:`trefftz_elements` computes them on a pool of
threads (``workers``, by default :func:`sinterheat.threads.count`: ``--threads``, ``SINTERHEAT_THREADS``, else every
core the process may run on; one where there is one Trefftz particle). Threads suffice: the compiled kernels (the
quadrature's points, the basis) run without the GIL (``nogil``), and so do numpy's and scipy's BLAS and LAPACK calls
and array operations, which are most of the rest. BLAS is held to one thread for the whole pool
(:func:`sinterheat.threads.one_blas_thread`: the BLAS library's setting is the process's, not a thread's), and the
tables every particle reads (the chain's shift, the union law) are built before the threads start. The elements are
computed in parallel and put together in particle order, each by the same operations as on one thread: the result is
the serial loop's bit for bit.
"""

from __future__ import annotations

import functools
import math
from collections import namedtuple
from concurrent.futures import ThreadPoolExecutor

import numba
import numpy as np
from scipy.interpolate import CubicSpline
from scipy.linalg.blas import dsyrk

from dem.geometry.bonds import Bonds
from dem.laws.shared_body import ParticleElements, particle_elements
from dem.network.necks import bordered, neck_frames
from fem_neck.law import ConductanceLaw
from sinterheat import threads
from sinterheat.threads import one_blas_thread

DEGREE = 10  #: the harmonics' largest degree L, within 1 % of the union's FE on every lattice and random cell checked
BETA = 0.25  # the flux profile's exponent, w = (a^2 - rho^2)^-BETA
CHAIN_GRID = (0.04, 0.995, 0.005)  # a/r of the chain's shift table: first, last, step (outside it: solved directly)
TWO_PI = 2.0 * np.pi
DEFECT = 2e-3  #: the quadrature's largest defect (module docstring, "The quadrature's check")
REFINE = (1.0, 1.5, 2.0)  #: the rule's factors tried in turn where the defect is larger


def rule(L: int, refine: float = 1.0) -> tuple:
    """The quadrature for a degree (module docstring).

    Parameters
    ----------
    L : int
        The harmonics' largest degree.
    refine : float
        Each count times this, rounded up (1: the degree's own rule).

    Returns
    -------
    tuple of int
        ``(n_rho, n_psi, n_theta, n_phi)``: the radii and angles per face panel, the rings per cap panel and the
        points per full ring.
    """
    return tuple(math.ceil(refine * c) for c in (L + 2, L + 4, L + 4, 2 * L + 6))


@functools.lru_cache(maxsize=None)
def _gauss_table(mmax: int):
    """Gauss-Legendre on [0, 1]: nodes and weights ``(mmax + 1, mmax)``, row ``m`` the ``m``-point rule."""
    T = np.zeros((mmax + 1, mmax))
    Wt = np.zeros((mmax + 1, mmax))
    for m in range(1, mmax + 1):
        t, w = np.polynomial.legendre.leggauss(m)
        T[m, :m] = 0.5 * (t + 1)
        Wt[m, :m] = 0.5 * w
    return T, Wt


@numba.njit(cache=True)
def _plane_frame(n):
    """Two unit vectors spanning the plane of normal ``n`` (the quadrature's coordinates; the modes' frames are the
    bonds')."""
    h = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    t1 = np.cross(n, h)
    t1 /= np.sqrt(t1 @ t1)
    return t1, np.cross(n, t1)


@numba.njit(cache=True)
def _inside(p0, p1, a, lines, nl):
    """Whether the face point ``(p0, p1)`` lies in the disc of radius ``a`` and on the inner side of every line."""
    tol = 1e-10
    if p0 * p0 + p1 * p1 > a * a * (1 + tol) + tol:
        return False
    for k in range(nl):
        if lines[k, 0] * p0 + lines[k, 1] * p1 > lines[k, 2] + tol:
            return False
    return True


@numba.njit(cache=True, nogil=True)
def _face_points(j, normals, d, tr, wr, tp, wp, P, W, w, start):
    """Append face ``j``'s quadrature (module docstring) at ``P[start:]``: points, area weights ``W``, profile ``w``;
    returns the end (``start``: the face has no area)."""
    n = normals[j]
    e1, e2 = _plane_frame(n)
    a = math.sqrt(max(1 - d[j] ** 2, 0.0))
    m = len(d)
    lines = np.zeros((m, 3))
    nl = 0
    for k in range(m):  # the other planes' traces in the face's plane: alpha p0 + beta p1 <= gamma
        if k == j:
            continue
        al = normals[k] @ e1
        be = normals[k] @ e2
        ga = d[k] - d[j] * (normals[k] @ n)
        reach = math.hypot(al, be)
        if reach < 1e-14:
            if ga < 0:
                return start
            continue
        if ga >= a * reach:
            continue
        lines[nl, 0] = al / reach
        lines[nl, 1] = be / reach
        lines[nl, 2] = ga / reach
        nl += 1
    verts = np.zeros((2 * nl + nl * nl, 2))
    nv = 0
    for u in range(nl):  # where the lines cross the rim
        al, be, ga = lines[u, 0], lines[u, 1], lines[u, 2]
        if abs(ga) < a:
            h = math.sqrt(a * a - ga * ga)
            for s in (h, -h):
                p0 = al * ga - be * s
                p1 = be * ga + al * s
                if _inside(p0, p1, a, lines, nl):
                    verts[nv, 0] = p0
                    verts[nv, 1] = p1
                    nv += 1
    for u in range(nl):  # and one another
        for v in range(u):
            det = lines[u, 0] * lines[v, 1] - lines[u, 1] * lines[v, 0]
            if abs(det) < 1e-14:
                continue
            p0 = (lines[u, 2] * lines[v, 1] - lines[u, 1] * lines[v, 2]) / det
            p1 = (lines[u, 0] * lines[v, 2] - lines[u, 2] * lines[v, 0]) / det
            if _inside(p0, p1, a, lines, nl):
                verts[nv, 0] = p0
                verts[nv, 1] = p1
                nv += 1
    c0 = 0.0
    c1 = 0.0
    if nl > 0:  # the centre of the polar coordinates: the mean of the vertices and of the rim's kept points
        if nv < 2:
            return start
        cnt = nv
        c0 = verts[:nv, 0].sum()
        c1 = verts[:nv, 1].sum()
        for i in range(64):
            ang = TWO_PI * i / 64
            p0 = a * math.cos(ang)
            p1 = a * math.sin(ang)
            if _inside(p0, p1, a, lines, nl):
                c0 += p0
                c1 += p1
                cnt += 1
        if cnt < 3 and not _inside(0.0, 0.0, a, lines, nl):
            return start
        c0 /= cnt
        c1 /= cnt
    cut = np.zeros(nv + 1)  # the panels' edges: the vertices' angles about the centre
    nc = 0
    if nv:
        raw = np.empty(nv)
        for i in range(nv):
            raw[i] = np.round(math.atan2(verts[i, 1] - c1, verts[i, 0] - c0) % TWO_PI, 14)
        raw.sort()
        for i in range(nv):
            if nc == 0 or raw[i] != cut[nc - 1]:
                cut[nc] = raw[i]
                nc += 1
    graded = nc > 0
    if nc == 0:
        cut[0] = 0.0
        nc = 1
    cc = c0 * c0 + c1 * c1
    q = start
    for pi in range(nc):
        lo = cut[pi]
        hi = cut[pi + 1] if pi + 1 < nc else cut[0] + TWO_PI
        if hi - lo < 1e-13:
            continue
        for ip in range(len(tp)):
            if graded:
                tpg = 0.5 * (1 - math.cos(math.pi * tp[ip]))
                wpg = 0.5 * math.pi * math.sin(math.pi * tp[ip]) * wp[ip]
            else:  # the whole circle: equal steps, exact for trigonometric polynomials below len(tp)
                tpg = (ip + 0.5) / len(tp)
                wpg = 1.0 / len(tp)
            psi = lo + (hi - lo) * tpg
            ex = math.cos(psi)
            ey = math.sin(psi)
            ce = ex * c0 + ey * c1
            rho = -ce + math.sqrt(ce * ce + a * a - cc)
            for k in range(nl):
                den = ex * lines[k, 0] + ey * lines[k, 1]
                if den > 1e-300:
                    rho = min(rho, (lines[k, 2] - lines[k, 0] * c0 - lines[k, 1] * c1) / den)
            rho = max(rho, 0.0)
            for ir in range(len(tr)):
                sr = 1 - (1 - tr[ir]) ** 4
                wsr = 4 * (1 - tr[ir]) ** 3 * wr[ir]
                rr = rho * sr
                s0 = c0 + rr * ex
                s1 = c1 + rr * ey
                for x in range(3):
                    P[q, x] = d[j] * n[x] + s0 * e1[x] + s1 * e2[x]
                W[q] = (hi - lo) * wpg * rho * wsr * rr
                w[q] = max(a * a - s0 * s0 - s1 * s1, 1e-300) ** -BETA
                q += 1
    return q


@numba.njit(cache=True)
def _rim_crossings(ni, ci, nk, ck, n, th_j, out, no):
    """Append to ``out[no:]`` the polar angles about ``n`` (below ``th_j``) of the two points where the rims of the
    caps ``(ni, ci)`` and ``(nk, ck)`` cross on the sphere; returns the new count."""
    g = ni @ nk
    den = 1 - g * g
    if den < 1e-14:
        return no
    al = (ci - ck * g) / den
    be = (ck - ci * g) / den
    p0 = al * ni + be * nk
    rest = 1 - p0 @ p0
    if rest < 0:
        return no
    t = np.cross(ni, nk)
    t /= math.sqrt(t @ t)
    h = math.sqrt(rest)
    for sgn in (1.0, -1.0):
        p = p0 + sgn * h * t
        b = math.acos(min(max(p @ n, -1.0), 1.0))
        if 0 < b < th_j:
            out[no] = b
            no += 1
    return no


@numba.njit(cache=True, nogil=True)
def _cap_points(j, normals, d, tt, wt, GT, GW, n_phi, P, W, start):
    """Append cap ``j`` (the sphere beyond plane ``j``) less the caps before it at ``P[start:]``, area weights ``W``
    (module docstring); returns the end."""
    n = normals[j]
    e1, e2 = _plane_frame(n)
    th_j = math.acos(min(max(d[j], -1.0), 1.0))
    br = np.zeros(4 + 2 * j + j * j)  # the ring panels' edges in the polar angle
    br[0] = 0.0
    br[1] = th_j
    nb = 2
    gam_ = np.zeros(j)
    ph_ = np.zeros(j)
    for i in range(j):
        gam_[i] = math.acos(min(max(normals[i] @ n, -1.0), 1.0))
        ph_[i] = math.atan2(normals[i] @ e2, normals[i] @ e1)
        thi = math.acos(d[i])
        for b in (abs(gam_[i] - thi), gam_[i] + thi):
            if 0 < b < th_j:
                br[nb] = b
                nb += 1
        for k in range(i):
            nb = _rim_crossings(normals[i], d[i], normals[k], d[k], n, th_j, br, nb)
    brs = np.sort(br[:nb])
    ivs = np.zeros((2 * j + 2, 2))
    q = start
    for bi in range(nb - 1):
        lo = brs[bi]
        hi = brs[bi + 1]
        if hi - lo < 1e-13:
            continue
        for it in range(len(tt)):
            t = lo + (hi - lo) * 0.5 * (1 - math.cos(math.pi * tt[it]))
            wj = (hi - lo) * 0.5 * math.pi * math.sin(math.pi * tt[it]) * wt[it]
            st = math.sin(t)
            ct = math.cos(t)
            ni_ = 0
            full = False
            for i in range(j):  # the arcs of this ring inside cap i
                A = ct * math.cos(gam_[i])
                B = st * math.sin(gam_[i])
                if B < 1e-15:
                    if A >= d[i]:
                        full = True
                    continue
                cw = (d[i] - A) / B
                if cw <= -1:
                    full = True
                    continue
                if cw >= 1:
                    continue
                hw = math.acos(cw)
                s = (ph_[i] - hw) % TWO_PI
                e = s + 2 * hw
                if e > TWO_PI:
                    ivs[ni_, 0] = s
                    ivs[ni_, 1] = TWO_PI
                    ni_ += 1
                    ivs[ni_, 0] = 0.0
                    ivs[ni_, 1] = e - TWO_PI
                    ni_ += 1
                else:
                    ivs[ni_, 0] = s
                    ivs[ni_, 1] = e
                    ni_ += 1
            if full:
                continue
            if ni_ == 0:  # the full ring: equal steps
                for k in range(n_phi):
                    ph = TWO_PI * (k + 0.5) / n_phi
                    cp = math.cos(ph)
                    sp = math.sin(ph)
                    for x in range(3):
                        P[q, x] = ct * n[x] + st * (cp * e1[x] + sp * e2[x])
                    W[q] = wj * st * TWO_PI / n_phi
                    q += 1
                continue
            order = np.argsort(ivs[:ni_, 0])
            kept = np.zeros((ni_ + 1, 2))
            nk = 0
            pos = 0.0
            for o in order:
                s, e = ivs[o, 0], ivs[o, 1]
                if s > pos:
                    kept[nk, 0] = pos
                    kept[nk, 1] = s
                    nk += 1
                pos = max(pos, e)
            if pos < TWO_PI:
                kept[nk, 0] = pos
                kept[nk, 1] = TWO_PI
                nk += 1
            if nk > 1 and kept[0, 0] == 0.0 and kept[nk - 1, 1] == TWO_PI:  # one arc through 0
                kept[0, 0] = kept[nk - 1, 0] - TWO_PI
                nk -= 1
            for ka in range(nk):
                s, e = kept[ka, 0], kept[ka, 1]
                mm = max(3, int(math.ceil(n_phi * (e - s) / TWO_PI)) + 2)
                for k in range(mm):
                    ph = s + (e - s) * GT[mm, k]
                    cp = math.cos(ph)
                    sp = math.sin(ph)
                    for x in range(3):
                        P[q, x] = ct * n[x] + st * (cp * e1[x] + sp * e2[x])
                    W[q] = wj * st * (e - s) * GW[mm, k]
                    q += 1
    return q


@numba.njit(cache=True, nogil=True)
def _harmonics(P, L, nrm, V, DN, radial):
    """The real solid harmonics of degree 1 to ``L``, normalised to :math:`\\int_{S^2} \\phi^2 = 1`, then
    :math:`|x|^2` at the points ``P`` (N, 3): values into ``V`` (N, (L + 1)^2) and derivatives along ``nrm`` (N, 3)
    into ``DN``; ``radial``: the points on the unit sphere with ``nrm = P``, where the derivative is the degree times
    the value (Euler)."""
    R = np.zeros((L + 1, L + 1), dtype=np.complex128)
    G = np.zeros((L + 1, L + 1, 3), dtype=np.complex128)
    coef = np.zeros((L + 1, L + 1))
    for l in range(1, L + 1):
        for m in range(l + 1):
            c = math.sqrt((2 * l + 1) / (4 * math.pi) * math.exp(math.lgamma(l + m + 1) + math.lgamma(l - m + 1)))
            coef[l, m] = c if m == 0 else c * math.sqrt(2.0)
    for p in range(P.shape[0]):
        x, y, z = P[p, 0], P[p, 1], P[p, 2]
        r2 = x * x + y * y + z * z
        wq = complex(x, y)
        R[0, 0] = 1.0
        for m in range(L + 1):  # R_l^m = r^l P_l^m e^{i m phi} / (l + m)!, recurrences in l at fixed m
            if m > 0:
                R[m, m] = -wq / (2 * m) * R[m - 1, m - 1]
            if m + 1 <= L:
                R[m + 1, m] = z * R[m, m]
            for l in range(m + 2, L + 1):
                R[l, m] = ((2 * l - 1) * z * R[l - 1, m] - r2 * R[l - 2, m]) / ((l - m) * (l + m))
            if radial:
                continue
            if m > 0:  # the gradient, by the same recurrences differentiated
                G[m, m, 0] = -(R[m - 1, m - 1] + wq * G[m - 1, m - 1, 0]) / (2 * m)
                G[m, m, 1] = -(1j * R[m - 1, m - 1] + wq * G[m - 1, m - 1, 1]) / (2 * m)
                G[m, m, 2] = -(wq * G[m - 1, m - 1, 2]) / (2 * m)
            if m + 1 <= L:
                for c in range(3):
                    G[m + 1, m, c] = z * G[m, m, c]
                G[m + 1, m, 2] += R[m, m]
            for l in range(m + 2, L + 1):
                den = (l - m) * (l + m)
                for c in range(3):
                    G[l, m, c] = ((2 * l - 1) * z * G[l - 1, m, c] - 2 * P[p, c] * R[l - 2, m]
                                  - r2 * G[l - 2, m, c]) / den
                G[l, m, 2] += (2 * l - 1) * R[l - 1, m] / den
        b = 0
        nx, ny, nz = nrm[p, 0], nrm[p, 1], nrm[p, 2]
        for l in range(1, L + 1):
            for m in range(l + 1):
                c = coef[l, m]
                g = l * R[l, m] if radial else G[l, m, 0] * nx + G[l, m, 1] * ny + G[l, m, 2] * nz
                V[p, b] = c * R[l, m].real
                DN[p, b] = c * g.real
                b += 1
                if m > 0:
                    V[p, b] = c * R[l, m].imag
                    DN[p, b] = c * g.imag
                    b += 1
        V[p, b] = r2
        DN[p, b] = 2 * (x * nx + y * ny + z * nz)


def degrees(L: int) -> np.ndarray:
    """The degree of each basis function of :func:`harmonics`, as floats (the last, :math:`|x|^2`: 2).

    Parameters
    ----------
    L : int
        The harmonics' largest degree.

    Returns
    -------
    numpy.ndarray
        :math:`(L + 1)^2` degrees.
    """
    return np.concatenate([np.repeat(np.arange(1, L + 1), 2 * np.arange(1, L + 1) + 1), [2]]).astype(float)


def harmonics(P: np.ndarray, L: int, nrm=None):
    r"""The basis (module docstring) at points ``P``: the real solid harmonics of degree 1 to ``L`` (for each ``l``
    ``m = 0``, then the real and imaginary parts of ``m = 1 .. l``), normalised to :math:`\int_{S^2} \phi^2 = 1`,
    then :math:`|x|^2`.

    Parameters
    ----------
    P : numpy.ndarray
        (N, 3) points, in units of the radius.
    L : int
        The largest degree, >= 1.
    nrm : numpy.ndarray, optional
        (N, 3) unit vectors for the derivatives; default ``P`` (the points on the unit sphere, derivative along the
        radius by Euler's relation).

    Returns
    -------
    tuple of numpy.ndarray
        Values and derivatives along ``nrm``, each of N rows and :math:`(L + 1)^2` columns.
    """
    P = np.ascontiguousarray(P, dtype=float)
    V = np.empty((len(P), (L + 1) ** 2))
    DN = np.empty_like(V)
    _harmonics(P, L, P if nrm is None else np.ascontiguousarray(nrm, dtype=float), V, DN, nrm is None)
    return V, DN


def quadrature(normals: np.ndarray, arms: np.ndarray, L: int, refine: float = 1.0):
    """The boundary quadrature of the unit sphere cut by ``normals . x <= arms`` (module docstring), rule of
    :func:`rule` ``(L, refine)``.

    Parameters
    ----------
    normals : numpy.ndarray
        (z, 3) the planes' unit normals, outward.
    arms : numpy.ndarray
        (z,) the planes' distances from the centre, in units of the radius, in (-1, 1).
    L : int
        The degree whose rule is used.
    refine : float
        The rule's counts times this (:func:`rule`).

    Returns
    -------
    dict
        ``caps``: (points (N, 3), area weights (N,)) of the free sphere surface taken as the whole sphere less the
        caps (the points are those of the caps, to be subtracted); ``faces``: (points, area weights, profile ``w``),
        ``offsets`` (z + 1,) of each face's points.
    """
    normals = np.ascontiguousarray(normals, dtype=float)
    arms = np.ascontiguousarray(arms, dtype=float)
    n_rho, n_psi, n_theta, n_phi = rule(L, refine)
    m = len(arms)
    T, Wt = _gauss_table(n_phi + 8)
    capmax = sum((4 + 2 * j + j * j) * n_theta * (n_phi + 6 * (j + 1)) for j in range(m))
    Pc, Wc = np.empty((capmax, 3)), np.empty(capmax)
    nc = 0
    for j in range(m):
        nc = _cap_points(j, normals, arms, T[n_theta, :n_theta], Wt[n_theta, :n_theta], T, Wt, n_phi, Pc, Wc, nc)
    facemax = (2 * m + m * m + 1) * n_psi * n_rho
    Pf, Wf, wf = np.empty((m * facemax, 3)), np.empty(m * facemax), np.empty(m * facemax)
    offsets = np.zeros(m + 1, dtype=np.int64)
    for j in range(m):
        offsets[j + 1] = _face_points(j, normals, arms, T[n_rho, :n_rho], Wt[n_rho, :n_rho], T[n_psi, :n_psi],
                                      Wt[n_psi, :n_psi], Pf, Wf, wf, offsets[j])
    nf = offsets[m]
    return {"caps": (Pc[:nc], Wc[:nc]), "faces": (Pf[:nf], Wf[:nf], wf[:nf]), "offsets": offsets}


def resistance(normals: np.ndarray, arms: np.ndarray, frames: np.ndarray, L: int = DEGREE, refine: float = 1.0):
    r"""The Ritz resistance of the unit sphere (:math:`\kappa = r = 1`) cut by the planes :math:`n_b \cdot x \le d_b`
    over three flux modes per plane (module docstring; no shift).

    Parameters
    ----------
    normals : numpy.ndarray
        (z, 3) the necks' unit normals, outward.
    arms : numpy.ndarray
        (z,) the necks' distances from the centre over the radius, in (-1, 1).
    frames : numpy.ndarray
        (z, 2, 3) each neck's dipole directions (:func:`dem.network.necks.neck_frames`).
    L : int
        The harmonics' largest degree, >= 2.
    refine : float
        The quadrature's counts times this (:func:`rule`).

    Returns
    -------
    numpy.ndarray or None
        ``R`` (3 z, 3 z), mode ``3 b + d`` (``d = 0`` the monopole), units :math:`1/(\kappa r)`; None if a plane
        leaves no face (its neck lies in another's cap).
    """
    return _ritz(normals, arms, frames, L, refine)[0]


def _ritz(normals, arms, frames, L, refine):
    """:func:`resistance` and its quadrature's defect (module docstring, "The quadrature's check"): ``(R, defect)``,
    ``(None, inf)`` where a plane leaves no face."""
    normals = np.ascontiguousarray(normals, dtype=float)
    quad = quadrature(normals, arms, L, refine)
    (Pc, Wc), (Pf, Wf, wf), fs = quad["caps"], quad["faces"], quad["offsets"]
    z = len(arms)
    if np.any(fs[1:] == fs[:-1]):
        return None, np.inf
    normal_f = np.repeat(normals, np.diff(fs), axis=0)
    Vc, _ = harmonics(Pc, L)
    Vf, DNf = harmonics(Pf, L, normal_f)
    deg = degrees(L)
    # K: the sphere's diag(deg) less the caps' (on the sphere d_n phi = deg phi: one SYRK) plus the faces'
    A = Vc * np.sqrt(Wc)[:, None]
    G = dsyrk(1.0, A, trans=1, lower=0)
    G = np.triu(G) + np.triu(G, 1).T
    K = (Vf * Wf[:, None]).T @ DNf - G * deg[None, :]
    K[np.arange(len(deg) - 1), np.arange(len(deg) - 1)] += deg[:-1]
    xn = np.einsum("pc,pc->p", Pf, normal_f)
    # |x|^2 against itself: int |grad|x|^2|^2 = 4 int |x|^2 = 4/5 int |x|^2 x.n over the boundary
    K[-1, -1] = 16 * np.pi / 5 + 4.0 / 5.0 * (np.sum(Wf * Vf[:, -1] * xn) - np.sum(Wc * Vc[:, -1]))
    K[:-1, -1] = K[-1, :-1]
    h = len(deg) - 1  # the harmonics: Green's identity makes their block of K symmetric and their fluxes 0
    skew = K[:h, :h] - K[:h, :h].T
    flux = Wf @ DNf[:, :h] - deg[:h] * (Wc @ Vc[:, :h])
    K = 0.5 * (K + K.T)
    # the sink: the basis' mean over the body, int phi = int phi x.n / (deg + 3) (phi homogeneous of degree deg)
    vol_b = ((Vf * (Wf * xn)[:, None]).sum(0) - (Vc * Wc[:, None]).sum(0)) / (deg + 3)
    vol_b[-1] += 4 * np.pi / 5
    volume = 4 * np.pi / 3 + (np.sum(Wf * xn) - np.sum(Wc)) / 3
    B = np.empty((len(deg), 3 * z))
    for b in range(z):
        sl = slice(fs[b], fs[b + 1])
        ww = Wf[sl] * wf[sl]
        total = ww.sum()
        rel = Pf[sl] - arms[b] * normals[b]
        a = math.sqrt(max(1 - arms[b] ** 2, 0.0))
        S = np.empty((len(ww), 3))
        S[:, 0] = 1.0
        for k in range(2):
            xi = rel @ frames[b][k]
            S[:, 1 + k] = (xi - (ww * xi).sum() / total) / a
        B[:, 3 * b:3 * b + 3] = Vf[sl].T @ (S * (ww / total)[:, None])
        B[:, 3 * b] -= vol_b / volume
    C = np.linalg.solve(K, B)
    R = B.T @ C
    root = np.sqrt(np.abs(np.diag(R)))
    defect = max((np.abs(C[:h].T @ skew @ C[:h]) / np.outer(root, root)).max(), np.abs(flux @ C[:h]).max())
    return 0.5 * (R + R.T), defect


def law_half(a_over_r):
    """The chain particle's exact half resistance, the union law's :math:`1/(\\pi K/K_{cyl})` (:mod:`fem_neck.law`).

    Parameters
    ----------
    a_over_r : float or array_like
        The neck radius over the particle's, in (0, 1).

    Returns
    -------
    numpy.ndarray
        The half resistance, units :math:`1/(\\kappa r)`.
    """
    return 1.0 / (np.pi * np.asarray(_union_law().k_over_kcyl(np.asarray(a_over_r, dtype=float)), dtype=float))


@functools.lru_cache(maxsize=None)
def _union_law():
    return ConductanceLaw.default("union")


def chain_half(a_over_r: float, L: int = DEGREE) -> float:
    """The chain particle's Trefftz half (two opposite necks): :math:`(R_{00} + R_{33} - 2 R_{03}) / 2` of
    :func:`resistance`.

    Parameters
    ----------
    a_over_r : float
        The necks' radius over the particle's, in (0, 1).
    L : int
        The harmonics' largest degree.

    Returns
    -------
    float
        The half resistance, units :math:`1/(\\kappa r)`.
    """
    arm = math.sqrt(1 - a_over_r ** 2)
    normals = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]])
    R = resistance(normals, np.array([arm, arm]), neck_frames(normals), L)
    return 0.5 * (R[0, 0] + R[3, 3] - 2 * R[0, 3])


@functools.lru_cache(maxsize=None)
def _chain_table(L: int) -> CubicSpline:
    """The chain's Trefftz half on :data:`CHAIN_GRID`, a cubic spline; computed once per ``L`` in the process (about
    200 two-neck elements: about a second of CPU at ``L`` 10)."""
    first, last, step = CHAIN_GRID
    q = np.round(np.arange(first, last + step / 2, step), 9)
    with one_blas_thread():
        return CubicSpline(q, [chain_half(x, L) for x in q])


def chain_shift(a_over_r, L: int = DEGREE) -> np.ndarray:
    """What a degree misses on the chain particle's half (module docstring): the law's half less the Trefftz half.

    Parameters
    ----------
    a_over_r : float or array_like
        The neck radii over the particle's, in (0, 1).
    L : int
        The harmonics' largest degree.

    Returns
    -------
    numpy.ndarray
        The shifts, units :math:`1/(\\kappa r)`, one per neck.
    """
    q = np.atleast_1d(np.asarray(a_over_r, dtype=float))
    first, last, _ = CHAIN_GRID
    table = _chain_table(L)
    inside = (q >= first) & (q <= last)
    trefftz = np.where(inside, table(np.clip(q, first, last)), 0.0)
    for k in np.flatnonzero(~inside):
        trefftz[k] = chain_half(float(q[k]), L)
    return law_half(q) - trefftz


def _positive_definite(R: np.ndarray) -> bool:
    try:
        np.linalg.cholesky(R)
    except np.linalg.LinAlgError:
        return False
    return True


def trefftz_elements(n: int, radius: np.ndarray, bonds: Bonds, vectors: np.ndarray, k_i: np.ndarray,
                     k_j: np.ndarray, k_wall: np.ndarray, conductivity: np.ndarray, wall_normals: np.ndarray,
                     volume=None, L: int = DEGREE, where=None, workers=None) -> TrefftzElements:
    r"""The particles' Trefftz elements with three flux modes per neck (module docstring), the ``elements`` hook of
    :func:`dem.network.necks.neck_network` (the arguments of :func:`dem.laws.shared_body.particle_elements`, whose
    ends it keeps: the faces of each particle's cut body), on every particle or on those of ``where``; the others
    keep the law's element with one mode per neck, which the network pads with zero dipole rows and columns on a
    neck it shares with a Trefftz particle (:mod:`dem.network.necks`, "Flux modes": there the Trefftz particle's
    dipoles carry no flux).

    Parameters
    ----------
    n : int
        Number of particles.
    radius : numpy.ndarray
        Particle radii, m.
    bonds : Bonds
        The pair and wall bonds (all live), with their centre-to-contact distances ``l_i``, ``l_j`` and ``wall_l``
        (m).
    vectors : numpy.ndarray
        ``x_j - x_i`` of every pair bond (m, 3), m.
    k_i, k_j : numpy.ndarray
        Half conductances of every pair bond on the side of ``i`` and of ``j``, W/K: the centre's path to the
        monopoles (module docstring, "The centre"), and the fallback's.
    k_wall : numpy.ndarray
        Half conductance of every wall bond, W/K (as ``k_i``).
    conductivity : numpy.ndarray
        Per particle, its material's conductivity, W/(m K).
    wall_normals : numpy.ndarray
        Unit normal of every wall bond's wall, pointing into the packing.
    volume : numpy.ndarray, optional
        Per particle, the solid it holds, m^3 (the fallback's trace cap).
    L : int
        The harmonics' largest degree, 6 to 16 (:data:`DEGREE` is the verified one).
    where : numpy.ndarray or None
        (n,) bool: the particles that get the Trefftz element; None: all.
    workers : int or None
        The threads that compute the elements, >= 1, at most one per Trefftz particle (module docstring, "On every
        core"); None: :func:`sinterheat.threads.count` (``--threads``, ``SINTERHEAT_THREADS``, else every core this
        process may run on). The elements are the same bit for bit on any number.

    Returns
    -------
    TrefftzElements
        ``modes`` 3 (with ``where``: per particle, 3 on the Trefftz particles and 1 on the others); ``plain`` marks
        the Trefftz particles that kept the law's monopole element (their shifted ``R`` not positive definite, or
        their quadrature failing its check at the finest rule) and the others whose interactions the law dropped;
        ``shrink`` is 1 on the Trefftz particles (no trace cap) and the law's trace cap on the others; ``refine``
        the rule's factor per particle (``refine > 1``: refined by the check; 1 on the law's particles).
    """
    if not 6 <= L <= 16:
        raise ValueError(f"L = {L}: the Trefftz element's degree must be in 6..16")
    workers = threads.count() if workers is None else workers
    if isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or workers < 1:
        raise ValueError(f"workers = {workers!r}: must be an integer >= 1 (None: every core this process may use)")
    chosen = np.ones(n, dtype=bool) if where is None else np.asarray(where)
    if chosen.dtype != bool or chosen.shape != (n,):
        raise ValueError(f"where: {chosen.dtype} of shape {chosen.shape}: must be a bool mask of the {n} particles")
    law = particle_elements(n, radius, bonds, vectors, k_i, k_j, k_wall, conductivity, wall_normals, volume)
    unit = vectors / np.linalg.norm(vectors, axis=1)[:, None]
    into_wall = -np.reshape(np.asarray(wall_normals, dtype=float), (-1, 3))
    frames = neck_frames(vectors)
    cut = CutBodies(law, np.concatenate([unit, -unit, into_wall]),
                    np.concatenate([bonds.l_i, bonds.l_j, bonds.wall_l]),
                    np.concatenate([frames, frames, neck_frames(into_wall)]), np.concatenate([k_i, k_j, k_wall]),
                    radius, conductivity, L)
    plain = np.where(chosen, False, law.plain)
    refine = np.ones(n)
    blocks = [law.values[law.start[k]:law.start[k + 1]] for k in range(n)]  # the law's element, one mode per neck
    trefftz = np.flatnonzero(chosen)
    for k, (E, plain_k, refine_k) in zip(trefftz, _particle_elements(trefftz, cut, workers)):
        blocks[k], plain[k], refine[k] = E.ravel(), plain_k, refine_k
    start = np.cumsum([0] + [len(b) for b in blocks])
    modes = 3 if chosen.all() else np.where(chosen, 3, 1)  # one number where every particle has the three
    return TrefftzElements(law.offsets, law.ends, start, np.concatenate(blocks), plain,
                           np.where(chosen, 1.0, law.shrink), modes, refine)


TrefftzElements = namedtuple("TrefftzElements", ParticleElements._fields + ("refine",))
TrefftzElements.__doc__ = """:class:`~dem.laws.shared_body.ParticleElements` with ``modes`` 3 and, per particle,
``refine``: the factor of the quadrature's rule its element was computed with (1: the degree's own; above 1: refined
by the quadrature's check, module docstring)."""


CutBodies = namedtuple("CutBodies", ["law", "normals", "arms", "frames", "halves", "radius", "conductivity", "L"])
CutBodies.__doc__ = """What :func:`particle_element` reads of a packing (the arguments of :func:`trefftz_elements`):
``law`` the law's elements (:func:`dem.laws.shared_body.particle_elements`: each particle's ends and the fallback);
per bond end (pair bonds on ``i``, on ``j``, then the wall bonds) the unit normal of its plane out of its particle
(into the wall for a wall's), the plane's distance from the particle's centre (m) and the neck's dipole frame
(:func:`dem.network.necks.neck_frames` of the bond's vector from ``i`` to ``j``, of the normal into a wall) and
the law's half conductance from the centre to the neck (W/K); ``radius`` (m) and ``conductivity`` (W/(m K)) per
particle, ``L`` the harmonics' largest degree."""


def _particle_elements(particles: np.ndarray, cut: CutBodies, workers: int) -> list:
    """:func:`particle_element` of each of ``particles``, in their order, on up to ``workers`` threads (module
    docstring, "On every core")."""
    workers = min(workers, len(particles))
    if workers > 1:  # the tables every particle reads, built once before the threads share them
        _chain_table(cut.L)
        _union_law()
    with one_blas_thread():  # process-wide (the BLAS library's own setting): one thread in every worker
        if workers <= 1:
            return [particle_element(k, cut) for k in particles]
        with ThreadPoolExecutor(workers, thread_name_prefix="trefftz") as pool:
            futures = [pool.submit(particle_element, k, cut) for k in particles]
            try:
                return [f.result() for f in futures]
            except BaseException:
                pool.shutdown(cancel_futures=True)
                raise


def particle_element(k: int, cut: CutBodies) -> tuple:
    """Particle ``k``'s Trefftz element (module docstring) over its ends' three flux modes and its centre.

    Parameters
    ----------
    k : int
        The particle.
    cut : CutBodies
        The packing's planes and halves per bond end, the law's elements and the degree.

    Returns
    -------
    tuple
        ``(E, plain, refine)``: the element, W/K, ``(3 z + 1, 3 z + 1)`` (local nodes: mode ``d`` of end ``p`` at
        ``3 p + d``, then the centre; a particle without necks: ``(1, 1)``, zero), whether it kept the law's element
        on its monopoles (its shifted ``R`` not positive definite, or its quadrature failing the check at the finest
        rule), and the factor of the rule it was computed with (:data:`REFINE`).
    """
    law, L = cut.law, cut.L
    ends = law.ends[law.offsets[k]:law.offsets[k + 1]]
    z = len(ends)
    if not z:
        return np.zeros((1, 1)), False, 1.0
    arms = cut.arms[ends] / cut.radius[k]
    for refine in REFINE:  # the quadrature's check (module docstring)
        R, defect = _ritz(cut.normals[ends], arms, cut.frames[ends], L, refine)
        if R is None:
            raise ValueError(f"the Trefftz element: particle {k} has a neck with no face (inside another's cap)")
        if defect <= DEFECT:
            break
    shifted = R.copy()
    shifted[::3, ::3][np.diag_indices(z)] += chain_shift(np.sqrt(1 - arms ** 2), L)
    scale = cut.conductivity[k] * cut.radius[k]
    if defect <= DEFECT and _positive_definite(shifted):
        Y = np.linalg.inv(shifted / scale)
        return _joined(0.5 * (Y + Y.T), cut.halves[ends]), False, refine
    # the law's element on the monopoles (its own centre path), the unshifted dipoles beside them
    E = law.values[law.start[k]:law.start[k + 1]].reshape(z + 1, z + 1)
    Y = np.zeros((3 * z, 3 * z))
    Y[::3, ::3] = E[:z, :z]
    dip = np.flatnonzero(np.arange(3 * z) % 3)
    Y[np.ix_(dip, dip)] = np.linalg.inv(R[np.ix_(dip, dip)] / scale)
    return bordered(0.5 * (Y + Y.T), 3), True, refine


def _joined(Y: np.ndarray, halves: np.ndarray) -> np.ndarray:
    r"""The element of a particle from its conductance ``Y`` over the modes (W/K) and its necks' halves ``K`` (W/K):
    :math:`Y_0 + k k^T / \sum K` bordered by :math:`-k` and :math:`\sum K` (module docstring, "The centre"), ``k``
    the halves on the monopoles and 0 on the dipoles, :math:`Y_0` the Schur complement on the modes of
    :func:`dem.network.necks.bordered` ``(Y, 3)``."""
    row = Y[:, ::3].sum(axis=1)
    k = np.zeros(len(Y))
    k[::3] = halves
    return bordered(Y - np.outer(row, row) / row[::3].sum() + np.outer(k, k) / k.sum(), 3)
