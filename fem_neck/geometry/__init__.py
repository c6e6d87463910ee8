r"""Neck geometry of two sintered spheres (Rojek, Kasztelan & Tharmaraj 2022, Section 4).

Two spheres of radii :math:`r_i` and :math:`r_j` overlap by :math:`h = r_i + r_j - d` (eq. 21). Three models of the
neck:

* ``"coble"`` -- Coble's neck :math:`a = \sqrt{2 r^* h}` with the effective radius
  :math:`r^* = 2 r_i r_j / (r_i + r_j)` (eqs. 10-12). It does not conserve volume and over-estimates the neck.
* ``"newton"`` -- the volume-conserving cylindrical neck: a cylinder of radius ``a`` and height ``h_n`` whose
  volume equals the two spherical caps it replaces (eqs. 22-29). Solved by Newton's method on ``Z(a)`` (eqs. 27,
  31, 32); the paper starts from Coble's radius (eq. 33), we start from a closer one (:func:`newton_start`). For
  equal radii it reproduces the closed form of eqs. (18)-(20).
* ``"first"`` -- the first Newton iterate from Coble's start (eq. 34), a cheap approximation.

Numerics. With :math:`h_c(a) = r - \sqrt{r^2 - a^2}` (eqs. 28-29) the identity
:math:`\frac{d}{dh_c} \left[h_c^2 (3r - h_c)\right] = 3 a^2` reduces the derivative of eq. (31) to
:math:`Z'(a) = 6 a h_n`. Dividing eq. (27) by :math:`3 a^2` gives

.. math::

    G(a) = \frac{Z}{3 a^2} = \phi(h_{ci}; r_i) + \phi(h_{cj}; r_j) - h, \qquad
    \phi(h_c; r) = \frac{h_c (3r - 2h_c)}{3 (2r - h_c)},

strictly increasing in ``a`` on ``[0, min(r_i, r_j)]``: the root is unique, and :math:`h = \phi_i + \phi_j` inverts
the model (:func:`overlap_for_neck`, :func:`max_overlap`). ``Z`` is convex where ``h_n > 0``, so Newton started to the
right of the root decreases monotonically onto it, and a step from the left of the root (with ``Z' > 0``) lands to
its right. Where the start has ``Z' <= 0`` the iteration starts from the bracket's right end ``a = min(r_i, r_j)``
instead, so it never diverges. Cap heights are computed as :math:`a^2 / (r + \sqrt{r^2 - a^2})` so that small
necks keep full relative precision. Large arrays are solved in blocks of cache size (``_CHUNK`` bonds), each block
stopping as soon as its own bonds have converged; from ``_COMPILED_MIN`` bonds on the blocks run compiled on numba's
threads (:mod:`fem_neck.geometry.neck_kernels`), the same radii to the bit.

The model's range: a solution exists for ``0 < h <= max_overlap(r_i, r_j)``, where ``a`` reaches the smaller radius
(``2r/3`` for equal spheres, Section 4.2). Once two necks of one particle meet, no pair-neck model has an answer; the
union of the spheres (:mod:`fem_neck.geometry.union`) has one at every density.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

METHODS = ("newton", "first", "coble")
_MAX_ITERATIONS = 60
_RATIO_CAP = 1e100  # radius ratios above this are solved at this ratio (see _validated)
_STEP_TOL = 1e-8  # relative Newton step after which the iterate is at round-off (quadratic convergence)
_LIMIT_SLACK = 1e-12  # relative round-off tolerated beyond the model's largest overlap
_TINY = np.finfo(float).tiny
_CHUNK = 1 << 14  # neck_radius solves large arrays in blocks of this many bonds (cache-sized temporaries)
_COMPILED_MIN = 1 << 22  # from this many bonds on, neck_radius's blocks run compiled (fem_neck.geometry.neck_kernels):
# about 0.06 us of CPU less a bond, against about 0.5 s to load numba where nothing had (a bond search of 3e5
# particles or more has)


@dataclass(frozen=True)
class NeckGeometry:
    r"""The full geometry of a sintered pair (:func:`neck_geometry`; Rojek 2022, eqs. 21-29).

    Every length field is an array of the broadcast input shape (a float for scalar input), in the unit of the input
    lengths (m). The neck spans :math:`z_i \le z \le z_i + h_n` measured from centre ``i`` along the line of centres,
    and :math:`z_i + h_n + z_j = d`.

    Parameters
    ----------
    r_i, r_j : numpy.ndarray or float
        Radii of spheres ``i`` and ``j``, m.
    h : numpy.ndarray or float
        Overlap :math:`r_i + r_j - d` (eq. 21), m.
    a : numpy.ndarray or float
        Neck radius, m.
    h_ci, h_cj : numpy.ndarray or float
        Heights of the caps cut from sphere ``i`` and from sphere ``j`` (eqs. 28-29), m.
    h_n : numpy.ndarray or float
        Length of the neck (the cylinder), :math:`h_{ci} + h_{cj} - h` (eq. 24), m.
    d : numpy.ndarray or float
        Distance between the centres (eq. 21), m.
    z_i, z_j : numpy.ndarray or float
        Distance from centre ``i`` and from centre ``j`` to the base plane of its cap, :math:`\sqrt{r^2 - a^2}`, m.
    volume_residual : numpy.ndarray or float
        :math:`|V_{cyl} - V_{cap,i} - V_{cap,j}| / V_{cyl}`, how far the neck is from conserving volume (eq. 22),
        dimensionless: round-off for ``"newton"``, the model's error for ``"first"`` and ``"coble"``.
    iterations : int
        Newton iterations taken (0 for ``"coble"``, 1 for ``"first"``).
    method : str
        The neck model: ``"newton"``, ``"first"`` or ``"coble"`` (see :func:`neck_radius`).
    """

    r_i: np.ndarray
    r_j: np.ndarray
    h: np.ndarray
    a: np.ndarray
    h_ci: np.ndarray
    h_cj: np.ndarray
    h_n: np.ndarray
    d: np.ndarray
    z_i: np.ndarray
    z_j: np.ndarray
    volume_residual: np.ndarray
    iterations: int
    method: str


def check_positive(name: str, value, upper=None, upper_name: str | None = None) -> np.ndarray:
    """Return ``value`` as a float array, raising ``ValueError`` unless every entry is finite and ``> 0``.

    The message names the parameter, the first offending entry (its flat index for an array) and the valid range.

    Parameters
    ----------
    name : str
        The parameter's name, as the message shows it.
    value : float or array_like
        The value to check, in any unit (the bound's).
    upper : float or array_like, optional
        If given, also require ``value <= upper`` entry by entry (broadcast against ``value``), in ``value``'s unit.
    upper_name : str, optional
        What the bound ``upper`` is, shown in parentheses after the range (e.g. ``"the smaller radius"``).

    Returns
    -------
    numpy.ndarray
        ``value`` as a float array (0-d for a scalar).

    Raises
    ------
    ValueError
        One line, ``"name[k] = value: valid range ..."``, if an entry is not finite, not ``> 0`` or above ``upper``.
    """
    arr = np.asarray(value, dtype=float)
    ok = (arr > 0.0) & (arr < np.inf)  # False for NaN as well
    if upper is not None:
        ok &= arr <= upper
    if not np.all(ok):
        idx = np.flatnonzero(~ok)[0]
        shown = arr.flat[idx]
        where = "" if arr.ndim == 0 else f"[{idx}]"
        if upper is None:
            valid = "must be finite and > 0"
        else:
            bound = np.broadcast_to(upper, arr.shape).flat[idx]
            valid = f"valid range 0 < {name} <= {bound:.12g}" + (f" ({upper_name})" if upper_name else "")
        raise ValueError(f"{name}{where} = {shown:.9g}: {valid}")
    return arr


def cap_height(r, a):
    r"""Height of the spherical cap of radius ``r`` with base radius ``a``, :math:`r - \sqrt{r^2 - a^2}` (Rojek 2022,
    eqs. 28-29).

    Written as :math:`a q / (1 + \sqrt{(1 - q)(1 + q)})` with :math:`q = a / r` (:math:`= a^2 / (r + \sqrt{r^2 -
    a^2})`): small caps keep full relative precision and no square of a length is formed, so any radius a float holds
    works. Not checked: the caller keeps ``0 <= a <= r`` (for ``a > r`` the result, :math:`a^2 / r`, is no cap
    height).

    Parameters
    ----------
    r : float or array_like
        Radius of the sphere, m (any length unit, the same as ``a``'s).
    a : float or array_like
        Radius of the cap's base circle (the neck radius), m, ``0 <= a <= r``.

    Returns
    -------
    float or numpy.ndarray
        The cap height ``h_c``, m, ``0 <= h_c <= r``.
    """
    q = a / r
    return a * q / (1.0 + np.sqrt(np.maximum((1.0 - q) * (1.0 + q), 0.0)))


def _phi(h_c, r):
    """Cap height minus the share of the neck length it fills; ``sum(phi) = h`` at the volume-conserving root.
    ``h_c (3r - 2h_c) / (3(2r - h_c))``, written in ``h_c / r`` so that huge radii do not overflow."""
    s = h_c / r
    return h_c * (3.0 - 2.0 * s) / (3.0 * (2.0 - s))


def max_overlap(r_i, r_j):
    """Largest overlap ``h`` for which the cylindrical neck exists: ``a`` reaches ``min(r_i, r_j)``.

    Equal spheres: ``2r/3`` (from eq. 18 with ``h_c = r``, Rojek 2022, Section 4.2). Unequal: the smaller sphere's
    cap is a hemisphere, and ``h`` is eq. (27) solved for it at ``a = min(r_i, r_j)``.

    Parameters
    ----------
    r_i, r_j : float or array_like
        Radii of the two spheres, m (> 0; not checked); arrays broadcast.

    Returns
    -------
    float or numpy.ndarray
        The largest overlap, m.
    """
    r_i = np.asarray(r_i, dtype=float)
    r_j = np.asarray(r_j, dtype=float)
    r_min = np.minimum(r_i, r_j)
    r_max = np.maximum(r_i, r_j)
    return r_min / 3.0 + _phi(cap_height(r_max, r_min), r_max)


def overlap_for_neck(r_i, r_j, a):
    r"""Inverse of the volume-conserving neck: the overlap ``h`` at which the neck radius is ``a``.

    From :math:`G(a) = 0` (eq. 27 divided by :math:`3 a^2`, module docstring): :math:`h = \phi(h_{ci}) + \phi(h_{cj})`;
    for equal spheres :math:`h = 2 h_c (3r - 2h_c) / (3 (2r - h_c))`, which is eq. (18) solved for ``h``.

    Parameters
    ----------
    r_i, r_j : float or array_like
        Radii of the two spheres, m, finite and > 0; arrays broadcast.
    a : float or array_like
        Neck radius, m, ``0 < a <= min(r_i, r_j)``.

    Returns
    -------
    float or numpy.ndarray
        The overlap :math:`h = r_i + r_j - d` (eq. 21), m; a float for scalar input.

    Raises
    ------
    ValueError
        If a radius is not finite and > 0, or ``a`` is outside ``(0, min(r_i, r_j)]``.
    """
    r_i = check_positive("r_i", r_i)
    r_j = check_positive("r_j", r_j)
    a = check_positive("a", a, upper=np.minimum(r_i, r_j), upper_name="the smaller radius")
    h = _phi(cap_height(r_i, a), r_i) + _phi(cap_height(r_j, a), r_j)
    return float(h) if np.ndim(h) == 0 else h


def coble_radius(r_i, r_j, h):
    r"""Coble's neck radius :math:`\sqrt{2 r^* h}`, :math:`r^* = 2 r_i r_j / (r_i + r_j)` (Rojek 2022, eqs. 11-12).

    Not checked (:func:`neck_radius` with ``method="coble"`` checks its input); it does not conserve volume and
    over-estimates the neck (eqs. 10-12).

    Parameters
    ----------
    r_i, r_j : float or array_like
        Radii of the two spheres, m; arrays broadcast.
    h : float or array_like
        Overlap :math:`r_i + r_j - d` (eq. 21), m.

    Returns
    -------
    float or numpy.ndarray
        Coble's neck radius, m.
    """
    return np.sqrt(4.0 * r_i * r_j / (r_i + r_j) * h)


def equal_neck_radius(r, h):
    r"""Closed-form volume-conserving neck of two equal spheres (Rojek 2022, eqs. 18-20).

    The small root of eq. (18) (eq. 19) is written as :math:`2c / (b + \sqrt{b^2 - 16c})` with the discriminant
    factorised, :math:`9(2r+h)^2 - 96rh = (2r - 3h)(18r - 3h)`, so it is accurate for small and for limiting overlaps
    alike; the neck radius is then eq. (20). Not checked: :func:`neck_radius` of two equal radii gives the same
    neck with its input checked.

    Parameters
    ----------
    r : float or array_like
        Radius of both spheres, m.
    h : float or array_like
        Overlap :math:`2r - d` (eq. 13), m, :math:`0 < h \le 2r/3` (at :math:`2r/3` the neck reaches :math:`a = r`).

    Returns
    -------
    float or numpy.ndarray
        The neck radius ``a``, m.
    """
    r = np.asarray(r, dtype=float)
    h = np.asarray(h, dtype=float)
    disc = np.maximum((2.0 * r - 3.0 * h) * (18.0 * r - 3.0 * h), 0.0)
    h_c = 12.0 * r * h / (3.0 * (2.0 * r + h) + np.sqrt(disc))
    return np.sqrt(h_c * (2.0 * r - h_c))


def _z_and_slope(a, r_i, r_j, h):
    """``Z(a)`` of eq. (27) and ``Z'(a) = 6 a h_n`` (eq. 31), with the cap heights in cancellation-free form."""
    a2 = a * a
    h_ci = a2 / (r_i + np.sqrt((r_i - a) * (r_i + a)))
    h_cj = a2 / (r_j + np.sqrt((r_j - a) * (r_j + a)))
    h_n = h_ci + h_cj - h
    z = 3.0 * a2 * h_n - h_ci * h_ci * (3.0 * r_i - h_ci) - h_cj * h_cj * (3.0 * r_j - h_cj)
    return z, 6.0 * a * h_n


def _validated(r_i, r_j, h):
    """Checked, broadcast input in units of the smaller radius, that radius (the length scale) and the largest
    overlap in those units.

    The model is scale-free; working in units of ``min(r_i, r_j)`` keeps squares of lengths representable for
    any radius a float can hold.
    """
    r_i = check_positive("r_i", r_i)
    r_j = check_positive("r_j", r_j)
    h = np.asarray(h, dtype=float)
    if not (h.ndim == 0 and r_i.ndim == 0 and r_j.ndim == 0):
        r_i, r_j, h = np.broadcast_arrays(r_i, r_j, h)
    scale = np.minimum(r_i, r_j)
    # x / x is exactly 1: the smaller radius is exactly 1; the larger may overflow to inf (a plane), which every
    # scale-free formula here handles
    with np.errstate(over="ignore"):
        r_i, r_j = r_i / scale, r_j / scale
    h_s = h / scale
    r_max = np.maximum(r_i, r_j)
    h_max = 1.0 / 3.0 + _phi(cap_height(r_max, 1.0), r_max)  # max_overlap in these units (smaller radius 1)
    # An overlap at the limit computed in another way may exceed h_max by round-off: that is the limit itself.
    h_limit = h_max * (1.0 + _LIMIT_SLACK)
    if not np.all((h_s > 0.0) & (h_s <= h_limit)):  # False for NaN too
        check_positive("h", h, upper=h_limit * scale, upper_name="the neck reaches the smaller radius")
    return r_i, r_j, np.minimum(h_s, h_max), scale, h_max


def newton_start(r_i, r_j, h, h_max):
    r"""Start of the Newton iteration for ``"newton"``, in units of the smaller radius: a cheap root of a cubic model
    of ``G`` in :math:`u = a^2` that is exact at both ends of the range.

    :math:`G(u) = c_1 u + c_2 u^2 + O(u^3) - h` with :math:`c_1 = (1/r_i + 1/r_j)/4` (Coble's linearisation, eq. 11) and
    :math:`c_2 = (1/r_i^3 + 1/r_j^3)/24`; the model :math:`c_1 u + c_2 u^2 + c_3 u^3` takes :math:`c_3` so that
    :math:`u = 1` gives :math:`h_{max}`. Its root is approximated by the root of the quadratic
    :math:`c_1 u + (h_{max} - c_1) u^2 = h` (also exact at both ends) and one Newton step on the cubic. The start is
    within ~1 % of the root over the whole range (Coble's within ~10 %), which saves two of the six Newton iterations
    Coble's start needs.

    Parameters
    ----------
    r_i, r_j : float or numpy.ndarray
        Radii of the two spheres in units of the smaller one (dimensionless; the smaller is 1).
    h : float or numpy.ndarray
        Overlap in units of the smaller radius (dimensionless), ``0 < h <= h_max``.
    h_max : float or numpy.ndarray
        Largest overlap of the model (:func:`max_overlap`) in units of the smaller radius (dimensionless).

    Returns
    -------
    float or numpy.ndarray
        The starting neck radius in units of the smaller radius (dimensionless), ``<= 1``.
    """
    inv_i, inv_j = 1.0 / r_i, 1.0 / r_j
    c1 = 0.25 * (inv_i + inv_j)
    c2 = (inv_i * inv_i * inv_i + inv_j * inv_j * inv_j) * (1.0 / 24.0)
    q2 = h_max - c1  # > 0: h_max lies between 5/12 (r_j -> inf, +c1 1/4) and 2/3 (equal, c1 1/2)
    u = 2.0 * h / (c1 + np.sqrt(c1 * c1 + 4.0 * q2 * h))
    c3 = q2 - c2  # > 0, so the cubic model's slope is positive and its value at u is c3 u^2 (u - 1) <= 0
    u = u - c3 * u * u * (u - 1.0) / (c1 + u * (2.0 * c2 + 3.0 * c3 * u))
    return np.sqrt(np.minimum(u, 1.0))


def _solve(r_i, r_j, h, method, h_max):
    """Neck radius and Newton iteration count (Rojek 2022, eqs. 32-34) for the output of :func:`_validated`.

    Beyond a radius ratio of ~1e16 the larger sphere is a plane to double precision: the ratio is capped at
    ``_RATIO_CAP`` so that the Newton's squares of lengths stay finite, without changing any result."""
    r_i, r_j = np.minimum(r_i, _RATIO_CAP), np.minimum(r_j, _RATIO_CAP)
    if method == "coble":
        return coble_radius(r_i, r_j, h), 0
    if method == "first":  # eq. (34): one Newton step from Coble's radius, which may lie beyond the smaller one
        a = np.minimum(coble_radius(r_i, r_j, h), 1.0)
        z, slope = _z_and_slope(a, r_i, r_j, h)
        return a - z / slope, 1
    # Lengths are in units of the smaller radius (see _validated), so the bracket's right end is a = 1. Z is convex
    # where Z' = 6 a h_n > 0: a Newton step from there lands right of the root, and from the right the iteration
    # descends monotonically onto it. A start where Z' <= 0 is replaced by the bracket's right end, where Z >= 0.
    a = newton_start(r_i, r_j, h, h_max)
    for iterations in range(1, _MAX_ITERATIONS + 1):
        z, slope = _z_and_slope(a, r_i, r_j, h)
        if iterations == 1:
            flat = ~(slope > 0.0)
            if np.any(flat):
                a = np.where(flat, 1.0, a)
                z, slope = _z_and_slope(a, r_i, r_j, h)
        step = z / np.maximum(slope, _TINY)  # slope > 0 from here on, unless it underflows (z does too, then)
        a = np.minimum(a - step, 1.0)  # at the range's end round-off may step past the smaller radius
        # Quadratic convergence: after a relative step s the error is ~ s^2 (measured: 3.4e-8 -> 4e-15), so a
        # step below 1e-8 leaves the root at round-off and one more iteration would change nothing.
        if np.all(np.abs(step) <= _STEP_TOL * a):
            return a, iterations
    raise RuntimeError(f"neck radius: Newton did not converge in {_MAX_ITERATIONS} iterations")  # pragma: no cover


def neck_radius(r_i, r_j, h, method: str = "newton"):
    """Neck radius ``a`` of two spheres of radii ``r_i``, ``r_j`` overlapping by ``h``.

    Vectorised over arrays (broadcast together); a scalar call returns a float.

    Parameters
    ----------
    r_i, r_j : float or array_like
        Radii of the two spheres, m, finite and > 0.
    h : float or array_like
        Overlap ``r_i + r_j - d`` (Rojek 2022, eq. 21), m, ``0 < h <= max_overlap(r_i, r_j)``
        (:func:`max_overlap`, where the neck reaches the smaller radius).
    method : str, optional
        The neck model: ``"newton"`` the volume-conserving cylindrical neck (eqs. 22-33, solved to round-off; the
        default), ``"first"`` its first Newton iterate from Coble's radius (eq. 34), ``"coble"`` Coble's neck
        (eqs. 10-12).

    Returns
    -------
    float or numpy.ndarray
        The neck radius, m (the input's length unit).

    Raises
    ------
    ValueError
        For an unknown ``method``, a radius or overlap that is not finite and > 0, or ``h`` beyond
        :func:`max_overlap`.
    """
    if method not in METHODS:
        raise ValueError(f"method = {method!r}: must be one of {', '.join(METHODS)}")
    r_i, r_j, h = (np.asarray(v, dtype=float) for v in (r_i, r_j, h))
    if max(r_i.size, r_j.size, h.size) > _CHUNK:
        return _neck_radius_blocked(r_i, r_j, h, method)
    r_i, r_j, h, scale, h_max = _validated(r_i, r_j, h)
    a = _solve(r_i, r_j, h, method, h_max)[0] * scale
    return float(a) if np.ndim(a) == 0 else a


def _neck_radius_blocked(r_i, r_j, h, method):
    """:func:`neck_radius` of large arrays, ``_CHUNK`` bonds at a time: every temporary of the Newton stays in
    the processor's cache instead of being a fresh multi-megabyte array per operation (3-4x faster for 10^6
    bonds), and each block stops iterating as soon as its own bonds have converged."""
    R_i, R_j, H = (np.ascontiguousarray(v).ravel() for v in np.broadcast_arrays(r_i, r_j, h))
    a = np.empty(H.size)
    if method == "newton" and H.size >= _COMPILED_MIN:
        from fem_neck.geometry.neck_kernels import newton_blocks

        if np.any(newton_blocks(R_i, R_j, H, a)):
            _validated(r_i, r_j, h)  # the message names the first bad entry by its own index
            raise RuntimeError(  # pragma: no cover
                f"neck radius: Newton did not converge in {_MAX_ITERATIONS} iterations")
        return a.reshape(np.broadcast_shapes(r_i.shape, r_j.shape, h.shape))
    try:
        for start in range(0, H.size, _CHUNK):
            block = slice(start, start + _CHUNK)
            ri, rj, hb, scale, h_max = _validated(R_i[block], R_j[block], H[block])
            a[block] = _solve(ri, rj, hb, method, h_max)[0] * scale
    except ValueError:
        _validated(r_i, r_j, h)  # the whole input again: the message names the first bad entry by its own index
        raise
    return a.reshape(np.broadcast_shapes(r_i.shape, r_j.shape, h.shape))


def neck_geometry(r_i, r_j, h, method: str = "newton") -> NeckGeometry:
    """All of the neck geometry (Rojek 2022, eqs. 21-29); see :class:`NeckGeometry`.

    Parameters
    ----------
    r_i, r_j : float or array_like
        Radii of the two spheres, m, finite and > 0; arrays broadcast.
    h : float or array_like
        Overlap ``r_i + r_j - d`` (eq. 21), m, ``0 < h <= max_overlap(r_i, r_j)``.
    method : str, optional
        The neck model, as for :func:`neck_radius` (default ``"newton"``).

    Returns
    -------
    NeckGeometry
        Neck radius, cap heights, neck length, centre distance, the cap planes' distances from the centres and the
        volume residual, each of the broadcast input shape.

    Raises
    ------
    ValueError
        As :func:`neck_radius`.
    """
    if method not in METHODS:
        raise ValueError(f"method = {method!r}: must be one of {', '.join(METHODS)}")
    R_i, R_j, H = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (r_i, r_j, h)))
    r_i, r_j, h, scale, h_max = _validated(r_i, r_j, h)
    a, iterations = _solve(r_i, r_j, h, method, h_max)
    # |V_cyl - V_caps| / V_cyl = |Z| / (3 a^2 h_n) = |G| / h_n  (eq. 27 divided by 3 a^2), in units of r_min
    h_ci, h_cj = cap_height(r_i, a), cap_height(r_j, a)
    residual = np.abs(_phi(h_ci, r_i) + _phi(h_cj, r_j) - h) / np.abs(h_ci + h_cj - h)
    a = a * scale
    h_ci, h_cj = cap_height(R_i, a), cap_height(R_j, a)  # in metres from the inputs: finite for any radii
    return NeckGeometry(
        r_i=R_i[()], r_j=R_j[()], h=h * scale, a=a, h_ci=h_ci, h_cj=h_cj, h_n=h_ci + h_cj - h * scale,
        d=R_i[()] + R_j[()] - h * scale, z_i=_base_distance(R_i, a), z_j=_base_distance(R_j, a), volume_residual=residual,
        iterations=iterations, method=method,
    )


def _base_distance(r, a):
    """Distance from a sphere's centre to its cap base, ``sqrt(r^2 - a^2)`` written as ``r sqrt((1-q)(1+q))``."""
    q = a / r
    return r * np.sqrt(np.maximum((1.0 - q) * (1.0 + q), 0.0))
