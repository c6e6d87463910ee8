r"""The exact flux element of one cut sphere by FE (NGSolve, the optional extra ``pip install .[peers]``): the particle
of a network with a node per neck, with a prescribed flux profile on each neck face.

A particle of the union of spheres is its sphere cut by the radical planes of its overlapping neighbours
(:mod:`fem_neck.geometry.union`): the body :math:`\Omega = \{|x| \le 1, \; n_b \cdot x \le l_b\}` (lengths in units of
its radius ``r``, conductivity :math:`\kappa = 1`), whose neck faces are the flat parts of its boundary; the rest of
its sphere is insulated. A unit flux into face ``j``, spread over it with the density

.. math::

    w_j(x) / \int_{F_j} w_j, \qquad w_j = (a_j^2 - \rho_j^2)^{-\beta},

(:math:`\rho_j` the distance from the centre of the neck's disc in its plane, :math:`a_j = \sqrt{1 - l_j^2}` the
disc's radius: the same function seen from both particles of the neck; :math:`\beta = 0` uniform flux), and taken
out by a uniform sink :math:`1/|\Omega|`, raises the ``w``-weighted mean temperature of face ``i`` above the volume
mean by :math:`R_{ij}`. Galerkin: :math:`a(u, v) = \int \nabla u \cdot \nabla v`, :math:`\ell_j(v) = \int_{F_j} w_j v
/ \int_{F_j} w_j - \int_\Omega v / |\Omega|`, :math:`R_{ij} = \ell_i(u_j)`: symmetric, the element's resistance
matrix over its necks with the volume-mean temperature as its centre (:mod:`dem.network.necks`). ``R`` is
dimensionless; the particle's, in K/W, is :math:`R / (\kappa r)`.

**Dipoles.** With two directions :math:`t_1, t_2` in each face's plane (``frames``; the network's are
:func:`dem.network.necks.neck_frames`, the bond's, the same for both particles of a neck), each face carries two
more flux modes (:mod:`dem.network.necks`, "Flux modes"): the densities :math:`w_j (\xi - \bar\xi) / (a_j \int_{F_j}
w_j)`, :math:`\xi = t_d \cdot x` and :math:`\bar\xi` its ``w``-weighted mean over the face, which carry no net heat
and so no sink; the face's dipole temperature is read with the same function. ``R`` is then ``3 z x 3 z``, mode
``3 b + d`` of face ``b`` (the monopole ``d = 0``), and the check is the uncut ball's caps again, a dipole on each
(:func:`cap_ball_dipole_exact`, the series in :math:`P_l^1`).

The FE: the body built in netgen's OCC kernel, meshed with ``maxh`` (in units of ``r``), refined geometrically toward
every edge (``RefineHP``, where two faces or a face and the sphere meet: the flux is singular there), curved to order
``order`` and solved with H1 elements of that order: one sparse Cholesky factorisation with one vertex held (the
right-hand sides are compatible on the curved mesh because the face integrals and the volume are taken on it), one
solve per face and profile. Galerkin's discrete energy lies above the exact minimum, so the FE's ``R`` lies below
the exact one (its conductance above): :func:`cap_ball` against :func:`cap_ball_exact` measures by how much.
"""

from __future__ import annotations

import numpy as np


HP_FACTOR = 0.2  # the geometric refinement's ratio of each layer toward an edge to the last


def _solve(shape, names: list, discs: list, betas: tuple, order: int, maxh: float, hp_levels: int,
           frames=None) -> dict:
    """``{beta: R}`` over the named boundaries ``names`` of an OCC solid; ``discs`` per name ``(n, l, a)``: the
    neck's unit normal, plane distance and disc radius (units of ``r``; only ``a`` is used for ``beta = 0``); with
    ``frames`` (per name two unit vectors in its plane) three modes per face, the monopole and the two dipoles."""
    import ngsolve as ngs
    from netgen import occ

    ngs.ngsglobals.msg_level = 0
    for edge in shape.edges:
        if edge.mass > 1e-9:
            edge.hpref = 1
    mesh = ngs.Mesh(occ.OCCGeometry(shape).GenerateMesh(maxh=maxh))
    if hp_levels:
        mesh.RefineHP(levels=hp_levels, factor=HP_FACTOR)
    mesh.Curve(order)
    fes = ngs.H1(mesh, order=order)
    u, v = fes.TnT()
    form = ngs.BilinearForm(ngs.grad(u) * ngs.grad(v) * ngs.dx).Assemble()
    free = ngs.BitArray(fes.ndof)
    free.Set()
    free.Clear(0)
    inverse = form.mat.Inverse(free, inverse="sparsecholesky")
    volume = ngs.Integrate(ngs.CoefficientFunction(1.0), mesh)
    sol = ngs.GridFunction(fes)
    out = {}
    for beta in betas:
        loads = []
        for b, (name, disc) in enumerate(zip(names, discs)):
            if beta == 0:
                w = ngs.CoefficientFunction(1.0)
            else:
                n, l, a = disc
                d = [ngs.x - l * n[0], ngs.y - l * n[1], ngs.z - l * n[2]]
                along = d[0] * n[0] + d[1] * n[1] + d[2] * n[2]
                gap = a * a - (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] - along * along)
                w = ngs.IfPos(gap - 1e-8 * a * a, gap, 1e-8 * a * a) ** (-beta)  # the rim: an integrable singularity
            face = mesh.Boundaries(name)
            total = ngs.Integrate(w, mesh, ngs.BND, definedon=face, order=2 * order + 8)
            load = ngs.LinearForm(fes)
            load += (1.0 / total) * w * v * ngs.ds(definedon=face, bonus_intorder=8) - (1.0 / volume) * v * ngs.dx
            load.Assemble()
            loads.append(load.vec)
            for t in ([] if frames is None else frames[b]):  # the dipoles: no net heat, no sink
                xi = t[0] * ngs.x + t[1] * ngs.y + t[2] * ngs.z
                mean = ngs.Integrate(w * xi, mesh, ngs.BND, definedon=face, order=2 * order + 8) / total
                load = ngs.LinearForm(fes)
                load += (1.0 / (disc[2] * total)) * w * (xi - mean) * v * ngs.ds(definedon=face, bonus_intorder=8)
                load.Assemble()
                loads.append(load.vec)
        z = len(loads)
        R = np.zeros((z, z))
        for j in range(z):
            sol.vec.data = inverse * loads[j]
            for i in range(z):
                R[i, j] = ngs.InnerProduct(loads[i], sol.vec)
        out[beta] = 0.5 * (R + R.T)
    return {"R": out, "volume": float(volume), "ndof": int(fes.ndof)}


def _check(order: int, maxh: float, hp_levels: int, betas) -> None:
    if int(order) != order or order < 1:
        raise ValueError(f"order = {order}: must be an integer >= 1")
    if not 0 < maxh <= 2:
        raise ValueError(f"maxh = {maxh}: must be in (0, 2] (units of the radius)")
    if int(hp_levels) != hp_levels or hp_levels < 0:
        raise ValueError(f"hp_levels = {hp_levels}: must be an integer >= 0")
    for beta in betas:
        if not 0 <= beta < 0.5:
            raise ValueError(f"beta = {beta}: must be in [0, 0.5) (the flux density (a^2 - rho^2)^-beta)")


def cut_element(normals, arms, betas=(0.0,), order: int = 3, maxh: float = 0.25, hp_levels: int = 2,
                frames=None) -> dict:
    """The flux elements of the unit ball cut by the planes ``normals[b] . x <= arms[b]``, every plane a neck face
    (module docstring).

    Parameters
    ----------
    normals : array_like
        (z, 3) unit normals of the neck planes, out of the particle.
    arms : array_like
        (z,) distances from the centre to the planes, in units of the radius (in (-1, 1)).
    betas : sequence of float
        The flux profiles' exponents ``beta`` in ``[0, 1/2)`` (0: uniform flux).
    order : int
        Polynomial order of the H1 elements and of the curved geometry.
    maxh : float
        Largest element size before the refinement, in units of the radius.
    hp_levels : int
        Levels of geometric refinement toward the edges.
    frames : array_like or None
        (z, 2, 3) per plane two orthonormal vectors in it, the directions of its two dipole modes (module docstring;
        :func:`dem.network.necks.neck_frames`); None: the monopoles alone.

    Returns
    -------
    dict
        ``R``: ``{beta: (z, z) array}`` (dimensionless; K/W after dividing by ``kappa r``, faces in the order of
        the planes; with ``frames`` ``(3 z, 3 z)``, mode ``3 b + d`` of face ``b``: its monopole ``d = 0``, its
        dipole along ``frames[b, d - 1]``); ``volume``: the body's volume on the curved mesh (units of ``r^3``);
        ``ndof``.

    Raises
    ------
    ValueError
        A bad argument, or a plane that bounds the body with no area (a neck hidden by the other planes).
    """
    normals = np.reshape(np.asarray(normals, dtype=float), (-1, 3))
    arms = np.asarray(arms, dtype=float)
    _check(order, maxh, hp_levels, betas)
    if len(arms) != len(normals) or not len(arms):
        raise ValueError(f"normals, arms: {len(normals)} normals and {len(arms)} arms; need as many, at least one")
    if np.any(np.abs(np.linalg.norm(normals, axis=1) - 1.0) > 1e-9):
        raise ValueError("normals: must be unit vectors")
    if np.any(np.abs(arms) >= 1.0):
        raise ValueError(f"arms = {arms.tolist()}: each must be in (-1, 1) (a plane that cuts the unit ball)")
    if frames is not None:
        frames = _check_frames(frames, normals)
    from netgen import occ

    shape = occ.Sphere(occ.Pnt(0, 0, 0), 1.0)
    for n, l in zip(normals, arms):  # the half space beyond the plane: a box over z >= 0 turned onto n, moved out by l
        box = occ.Box(occ.Pnt(-3, -3, 0), occ.Pnt(3, 3, 3))
        axis = np.cross([0.0, 0.0, 1.0], n)
        s = np.linalg.norm(axis)
        if s > 1e-12:
            box = box.Rotate(occ.Axis(occ.Pnt(0, 0, 0), occ.Vec(*(axis / s))), np.degrees(np.arctan2(s, n[2])))
        elif n[2] < 0:
            box = box.Rotate(occ.Axis(occ.Pnt(0, 0, 0), occ.Vec(1, 0, 0)), 180)
        shape = shape - box.Move(occ.Vec(*(l * n)))
    for face in shape.faces:
        c = np.array([face.center.x, face.center.y, face.center.z])
        off = np.abs(normals @ c - arms)
        b = int(np.argmin(off))
        if off[b] < 1e-9:
            face.name = f"neck{b}"
    names = [f"neck{b}" for b in range(len(arms))]
    hidden = [b for b, name in enumerate(names) if name not in {f.name for f in shape.faces}]
    if hidden:
        raise ValueError(f"normals, arms: the planes {hidden} bound the cut body with no area (hidden necks)")
    discs = [(n, l, np.sqrt(1.0 - l * l)) for n, l in zip(normals, arms)]
    return _solve(shape, names, discs, tuple(betas), order, maxh, hp_levels, frames)


def _check_frames(frames, normals: np.ndarray) -> np.ndarray:
    """``frames`` as a (z, 2, 3) array, refused unless each is two orthonormal vectors in its plane."""
    frames = np.asarray(frames, dtype=float)
    if frames.shape != (len(normals), 2, 3):
        raise ValueError(f"frames: shape {frames.shape}; must be ({len(normals)}, 2, 3), two vectors per plane")
    gram = np.einsum("bij,bkj->bik", frames, frames)
    if np.any(np.abs(gram - np.eye(2)) > 1e-9) or np.any(np.abs(np.einsum("bij,bj->bi", frames, normals)) > 1e-9):
        raise ValueError("frames: each must be two orthonormal vectors in its plane (normal to its normal)")
    return frames


def cap_ball(alpha: float, order: int = 3, maxh: float = 0.25, hp_levels: int = 2, dipoles: bool = False) -> dict:
    """The closed-form check of :func:`cut_element`'s solver: the uncut unit ball whose two polar caps (half angle
    ``alpha``, rad) are the faces, uniform flux (:func:`cap_ball_exact`); with ``dipoles`` also the two dipoles
    along x and y on each cap (:func:`cap_ball_dipole_exact`).

    Parameters
    ----------
    alpha : float
        The caps' half angle, rad, in (0, pi/2).
    order, maxh, hp_levels
        As :func:`cut_element`.
    dipoles : bool
        Three modes per cap (the monopole, the dipoles along x and y, the rim radius ``sin alpha`` for ``a``).

    Returns
    -------
    dict
        As :func:`cut_element` (``R`` under ``beta = 0``; faces north, south).
    """
    if not 0 < alpha < np.pi / 2:
        raise ValueError(f"alpha = {alpha}: must be in (0, pi/2) rad")
    _check(order, maxh, hp_levels, ())
    from netgen import occ

    c = np.cos(alpha)
    ball = occ.Sphere(occ.Pnt(0, 0, 0), 1.0)
    north_box, south_box = occ.Box(occ.Pnt(-2, -2, c), occ.Pnt(2, 2, 2)), occ.Box(occ.Pnt(-2, -2, -2), occ.Pnt(2, 2, -c))
    shape = occ.Glue([ball * north_box, ball - north_box - south_box, ball * south_box])
    for face in shape.faces:
        p = np.array([face.center.x, face.center.y, face.center.z])
        if abs(abs(p[2]) - c) < 1e-9 and np.hypot(p[0], p[1]) < 1e-9:
            continue  # the flat discs inside the ball that the glue keeps
        if p[2] > c - 1e-9:
            face.name = "north"
        elif p[2] < -c + 1e-9:
            face.name = "south"
    discs = [((0.0, 0.0, 1.0), c, np.sin(alpha)), ((0.0, 0.0, -1.0), c, np.sin(alpha))]
    frames = [np.eye(3)[:2]] * 2 if dipoles else None
    return _solve(shape, ["north", "south"], discs, (0.0,), order, maxh, hp_levels, frames)


def cap_ball_exact(alpha: float, terms: int = 20000) -> float:
    r""":math:`R_{NN} + R_{SS} - 2 R_{NS}` of :func:`cap_ball` from the Legendre series: the resistance between the
    caps for a unit flux in at one and out at the other (the sink cancels),

    .. math::

        \frac{2}{2 \pi (1 - \cos\alpha)^2} \sum_{l \text{ odd}}
        \frac{\left(P_{l-1}(\cos\alpha) - P_{l+1}(\cos\alpha)\right)^2}{l (2 l + 1)}.

    Parameters
    ----------
    alpha : float
        The caps' half angle, rad.
    terms : int
        The series' last degree (its terms fall as ``l^-3``: 20000 leaves about 1e-9 relative).

    Returns
    -------
    float
        The resistance (dimensionless; ``kappa = r = 1``).
    """
    from scipy.special import eval_legendre

    c = np.cos(alpha)
    l = np.arange(1, terms + 1, 2)
    d = eval_legendre(l - 1, c) - eval_legendre(l + 1, c)
    return 2.0 * np.sum(d * d / (l * (2 * l + 1))) / (2 * np.pi * (1 - c) ** 2)


def cap_ball_dipole_exact(alpha: float, terms: int = 20000) -> tuple[float, float]:
    r"""The x-dipoles of :func:`cap_ball` with ``dipoles``: ``(R_NN, R_NS)``, the north cap's dipole moment of the
    temperature for a unit dipole on the north cap, and the south cap's, from the series in :math:`P_l^1`.

    The flux :math:`g = \sin\theta \cos\varphi / (a W)` on the north cap (:math:`a = \sin\alpha`, ``W`` the cap's
    area :math:`2 \pi (1 - \cos\alpha)`; the mean of ``x`` over the cap is 0) has the coefficients :math:`G_l =
    I_l / (a W N_l)` on :math:`P_l^1(\mu) \cos\varphi`, :math:`I_l = \int_{\cos\alpha}^1 \sqrt{1 - \mu^2}
    P_l^1(\mu) d\mu`, :math:`N_l = \frac{2}{2 l + 1} \frac{(l + 1)!}{(l - 1)!}`; the harmonic field
    :math:`\sum_l G_l r^l P_l^1 \cos\varphi / l` has that normal flux, and its moment against ``g`` is

    .. math::

        R_{NN} = \sum_{l \ge 1} \frac{\pi I_l^2}{l N_l (a W)^2}, \qquad
        R_{NS} = \sum_{l \ge 1} (-1)^{l + 1} \frac{\pi I_l^2}{l N_l (a W)^2}

    (the south cap's :math:`I_l` is :math:`(-1)^{l+1} I_l`: :math:`P_l^1` has the parity of :math:`l + 1`). With
    :math:`P_l^1 = -\sqrt{1 - \mu^2} P_l'` and parts, :math:`I_l = (1 - c^2) P_l(c) - 2 \int_c^1 \mu P_l`,
    :math:`c = \cos\alpha`, where :math:`\mu P_l = ((l + 1) P_{l+1} + l P_{l-1}) / (2 l + 1)` and
    :math:`\int_c^1 P_k = (P_{k-1}(c) - P_{k+1}(c)) / (2 k + 1)`.

    Parameters
    ----------
    alpha : float
        The caps' half angle, rad, in (0, pi/2).
    terms : int
        The series' last degree (its terms fall as ``l^-3``).

    Returns
    -------
    tuple of float
        ``(R_NN, R_NS)``, dimensionless (``kappa = r = 1``).
    """
    from scipy.special import eval_legendre

    if not 0 < alpha < np.pi / 2:
        raise ValueError(f"alpha = {alpha}: must be in (0, pi/2) rad")
    c = np.cos(alpha)
    l = np.arange(1, terms + 1)

    def integral(k):  # int_c^1 P_k
        return np.where(k == 0, 1.0 - c, (eval_legendre(np.maximum(k - 1, 0), c) - eval_legendre(k + 1, c))
                        / (2 * k + 1))

    moment = ((l + 1) * integral(l + 1) + l * integral(l - 1)) / (2 * l + 1)
    I = (1 - c * c) * eval_legendre(l, c) - 2 * moment
    N = 2.0 / (2 * l + 1) * l * (l + 1)
    aW = np.sin(alpha) * 2 * np.pi * (1 - c)
    term = np.pi * I * I / (l * N * aW ** 2)
    return float(term.sum()), float(np.sum(np.where(l % 2 == 1, term, -term)))
