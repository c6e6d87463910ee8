r"""Solve to a tolerance: the order-difference error estimate and the grading controller.

The conductance is computed on one graded mesh with two element orders, ``p - 1`` and ``p`` (curved, isoparametric
boundary). The reported value is the order-``p`` one; its error estimate is the relative difference of the two,

.. math::

    \epsilon = |K_p - K_{p-1}| / K_p,

which is the error of the order ``p - 1`` solve up to a factor :math:`1 + e_p / e_{p-1}`. On graded meshes :math:`e_p`
is 10-40x smaller than :math:`e_{p-1}` (measured), so the estimate bounds the reported value's error with a wide margin:
it is honest by construction and pessimistic by that ratio. If the estimate exceeds the tolerance the grading
factor (element size per distance to the nearest re-entrant corner) is reduced by the observed rate of the order
``p - 1`` error, :math:`e \sim g^{\mathrm{RATE}}` in the grading :math:`g`, and the pair is solved again on a new mesh.

Mesh sequences (3D clusters, and any 3D FE whose error is set by the re-entrant neck edges). Where raising the order
is not available, the same body is meshed at ``levels`` sizes that all shrink by one ``ratio`` per level (element
size at the necks, away from them, on curved surfaces: every size of the mesh, so that the sequence is a refinement
and not a re-grading) and solved with one element order. Energy-type values (a conductance from the Dirichlet
energy or the reaction, a volume mean of the temperature) then converge like :math:`\mathrm{size}^q` with ``q`` at
least the corner exponent's :math:`2 \lambda` (the re-entrant neck edge of interior angle :math:`\pi + \arccos(a/r)`
has :math:`\lambda = \pi / (\pi + \arccos(a/r))`, :func:`corner_exponent`; the 3D edge along the neck circle has the 2D
exponent), and faster before the asymptotic range. :func:`mesh_sequence_estimate` turns the last change into the
error of the finest value,

.. math::

    \epsilon = S \, \frac{|v_{L-1} - v_L|}{\rho - 1}, \qquad \rho = \min(\rho_{obs}, q^{2 \lambda}),

with ``S`` the ``SAFETY`` factor, ``q`` the ``ratio`` and :math:`\rho_{obs} = (v_{L-2} - v_{L-1}) / (v_{L-1} - v_L)`
the observed rate with three levels (two levels take the corner rate).
Taking the slower of the observed and the asymptotic rate keeps the estimate honest before the asymptotic range
(observed faster: the corner rate is the safe one) and when it is slower than the corner alone would explain.
A sequence that does not contract (``observed <= 1``: the changes grow or change sign) has no rate; its estimate is
the larger change over :math:`q^{2 \lambda} - 1` and it is flagged ``monotone = False``. Conforming primal FE
converges from above (the Dirichlet energy is minimal for the exact field), which the measurements confirm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fem_neck.hpmesh import SIGMA
from fem_neck.law import check_neck

# Conservative exponent of the order p-1 error in the grading factor (observed on the reference semispheres:
# P1 ~2, P2 3-4, P3 4.5-6), and the grading that meets the reference tolerance in one round.
RATE = {2: 2.0, 3: 3.0, 4: 4.5}
REFERENCE_GRADING = {2: (0.05, 1e-4), 3: (0.3, 1e-4), 4: (0.3, 1e-6)}
MAX_ROUNDS = 6
ORDERS = (2, 3, 4)
COARSEST_GRADING = 0.45
FINEST_GRADING = 0.02


def check_rtol(rtol) -> float:
    """Validate a relative tolerance: finite, ``1e-9 <= rtol < 1``.

    Parameters
    ----------
    rtol : float
        The relative tolerance (dimensionless).

    Returns
    -------
    float
        ``rtol`` as a float.

    Raises
    ------
    ValueError
        ``rtol`` is not finite or lies outside ``[1e-9, 1)``.
    """
    value = float(rtol)
    if not (np.isfinite(value) and 1e-9 <= value < 1.0):
        raise ValueError(f"rtol = {rtol!r}: valid range 1e-9 <= rtol < 1")
    return value


def default_order(rtol: float) -> int:
    """The fastest order pair for a tolerance (measured on the reference semispheres): P2/P3 down to 3e-5, then
    P3/P4, whose estimator (the P3 solve) reaches 1e-6 on meshes ~5x smaller than P2 needs.

    Parameters
    ----------
    rtol : float
        Relative tolerance of the conductance, ``1e-9 <= rtol < 1``.

    Returns
    -------
    int
        The order ``p`` of the reported solve: 3 or 4.
    """
    return 3 if rtol >= 3e-5 else 4


def check_order(order, rtol: float) -> int:
    """The order ``p`` of the reported solve of the order pair ``p - 1``, ``p``: ``order``, or the default for
    ``rtol`` (:func:`default_order`).

    Parameters
    ----------
    order : int or None
        The order asked for, one of ``ORDERS``; None: the default for ``rtol``.
    rtol : float
        Relative tolerance of the conductance, ``1e-9 <= rtol < 1``.

    Returns
    -------
    int
        The order.

    Raises
    ------
    ValueError
        ``order`` is not one of ``ORDERS``.
    """
    if order is None:
        return default_order(rtol)
    if order not in ORDERS:
        raise ValueError(f"order = {order!r}: must be one of {', '.join(map(str, ORDERS))} (the order of the "
                         "reported solve; the estimate compares it with one order lower)")
    return int(order)


def initial_grading(rtol: float, order: int) -> float:
    """Starting grading factor, calibrated so the default tolerance is met in one round for the reference cases.

    Parameters
    ----------
    rtol : float
        Relative tolerance of the conductance, ``1e-9 <= rtol < 1``.
    order : int
        The order of the reported solve, one of ``ORDERS``.

    Returns
    -------
    float
        The grading factor (element size per distance to the nearest re-entrant corner, dimensionless), within
        ``[FINEST_GRADING, COARSEST_GRADING]``.
    """
    base, tol = REFERENCE_GRADING[order]
    return float(np.clip(base * (rtol / tol) ** (1.0 / RATE[order]), FINEST_GRADING, COARSEST_GRADING))


def relative_difference(k_high: float, k_low: float) -> float:
    """The order-difference error estimate ``|K_p - K_(p-1)| / |K_p|`` (module docstring).

    Parameters
    ----------
    k_high : float
        The order-``p`` value (any unit, nonzero).
    k_low : float
        The order-``p - 1`` value (same unit).

    Returns
    -------
    float
        The relative difference (dimensionless).
    """
    return abs(k_high - k_low) / abs(k_high)


def next_grading(grading: float, rtol: float, estimate: float, order: int) -> float:
    r"""Shrink the grading so that :math:`\epsilon \, (g_{new}/g_{old})^{\mathrm{RATE}}` (``estimate`` :math:`\epsilon`)
    lands at ~0.7 rtol; at least 15 %, at most 3x.

    Parameters
    ----------
    grading : float
        The grading factor of the last round (dimensionless).
    rtol : float
        Relative tolerance of the conductance, ``1e-9 <= rtol < 1``.
    estimate : float
        The last round's error estimate (relative, > 0).
    order : int
        The order of the reported solve, one of ``ORDERS``.

    Returns
    -------
    float
        The next grading factor, not below ``FINEST_GRADING``.
    """
    factor = (0.7 * rtol / estimate) ** (1.0 / RATE[order])
    return float(max(FINEST_GRADING, grading * min(0.85, max(1.0 / 3.0, factor))))


def solve_to_tolerance(solve_pair, rtol: float, order: int):
    """Call ``solve_pair(grading, order) -> (K_p, K_(p-1), payload)`` with finer gradings until the estimate meets
    ``rtol``. Returns ``(K_p, estimate, grading, payload, rounds, converged)``; when refining stops paying (the
    finest grading, an estimate that no longer halves, or a mesh too fine for double precision -- tiny necks at
    rtol < 1e-6) the best round so far is returned with ``converged = False`` and its honest estimate.

    Parameters
    ----------
    solve_pair : callable
        ``solve_pair(grading, order) -> (K_p, K_(p-1), payload)``: the value at orders ``p`` and ``p - 1`` on the
        mesh of that grading, and anything the caller wants back; a ``RuntimeError`` ends the refinement.
    rtol : float
        Relative tolerance of the conductance, ``1e-9 <= rtol < 1``.
    order : int
        The order ``p`` of the reported solve, one of ``ORDERS``.

    Returns
    -------
    tuple
        ``(K_p, estimate, grading, payload, rounds, converged)`` of the best round.

    Raises
    ------
    RuntimeError
        The first round's ``solve_pair`` raised it.
    """
    grading = initial_grading(rtol, order)
    best = None
    for rounds in range(1, MAX_ROUNDS + 1):
        try:
            k_high, k_low, payload = solve_pair(grading, order)
        except RuntimeError:
            if best is None:
                raise
            break
        estimate = relative_difference(k_high, k_low)
        if best is not None and estimate > 0.5 * best[1]:
            break
        best = (k_high, estimate, grading, payload, rounds)
        if estimate <= rtol:
            return (*best, True)
        if grading <= FINEST_GRADING * (1 + 1e-12):
            break
        grading = next_grading(grading, rtol, estimate, order)
    return (*best, False)


# The hp path (fem_neck.hpmesh + fem_neck.spectral): one geometric mesh, the order raised until two consecutive
# orders agree. Measured on a/r = 1e-4 .. 0.995: the order-p error falls ~10-20x per order, so the difference of
# orders p - 1 and p bounds the order-p error with that margin. The corner refinement is chosen a priori so that
# its own error (which raising p does not remove) stays 100x below rtol: each level divides it by
# SIGMA^(-2 lambda) >= 13 (lambda >= 2/3 the corner exponent); 2 levels already give <= 1e-7 (measured).
HP_MAX_ORDER = 11


def hp_start_order(rtol: float) -> int:
    """First reported order: the one whose difference to ``p - 1`` typically meets ``rtol`` (about 1.2 decades per
    order at a/r = 0.39: p = 4 for 1e-4, 6 for 1e-6).

    Parameters
    ----------
    rtol : float
        Relative tolerance of the conductance, ``1e-9 <= rtol < 1``.

    Returns
    -------
    int
        The order, in ``[2, HP_MAX_ORDER]``.
    """
    return int(np.clip(np.ceil((np.log10(1.0 / rtol) + 0.3) / 1.2), 2, HP_MAX_ORDER))


def check_hp_order(order, rtol: float) -> int:
    """The first order the hp path reports: ``order``, or the default for ``rtol`` (:func:`hp_start_order`).

    Parameters
    ----------
    order : int or None
        The order asked for, ``2 <= order <= HP_MAX_ORDER``; None: the default for ``rtol``.
    rtol : float
        Relative tolerance of the conductance, ``1e-9 <= rtol < 1``.

    Returns
    -------
    int
        The order.

    Raises
    ------
    ValueError
        ``order`` is not an integer in ``[2, HP_MAX_ORDER]``.
    """
    if order is None:
        return hp_start_order(rtol)
    if not (isinstance(order, (int, np.integer)) and 2 <= order <= HP_MAX_ORDER):
        raise ValueError(f"order = {order!r}: valid range 2 <= order <= {HP_MAX_ORDER} for method 'hp' (the first "
                         "order tried; the estimate compares it with one order lower)")
    return int(order)


# The corner cell's relative error at L = 2 levels (measured, largest at the smallest necks): 1e-7 at the re-entrant
# corner of the neck cylinder; 3e-5 where the union's isothermal disk meets the sphere (2.8e-5 at a/r = 1e-3, 8e-6
# at 0.3), whose exponent is lower. Each further level divides it by sigma^(-2 lambda) (measured: 5.9 per level for
# the union's small necks, lambda = 1/2).
HP_CORNER_ERROR = {"cylinder": 1e-7, "union": 3e-5}


def hp_corner_levels(a_over_r: float, rtol: float, sigma: float = SIGMA, neck: str = "cylinder") -> int:
    r"""Geometric refinement levels toward the corner: the corner cell's error
    :math:`\sim c \, \sigma^{2 \lambda (L - 2)}` (``c`` = ``HP_CORNER_ERROR`` of the ``neck``, measured at L = 2) pushed
    100x below ``rtol``.

    Parameters
    ----------
    a_over_r : float
        Neck radius over particle radius, ``a/r`` in ``[0, 1]`` (dimensionless).
    rtol : float
        Relative tolerance of the conductance, ``1e-9 <= rtol < 1``.
    sigma : float
        The geometric grading ratio of the corner refinement, in ``(0, 1)`` (each level's cell over the last's).
    neck : str
        The half body (:data:`fem_neck.law.NECKS`): ``"cylinder"`` or ``"union"``.

    Returns
    -------
    int
        The number of refinement levels, >= 2.

    Raises
    ------
    ValueError
        ``neck`` is not one of :data:`fem_neck.law.NECKS`.
    """
    lam = corner_exponent(a_over_r, neck)
    decades = max(0.0, np.log10(HP_CORNER_ERROR[neck] / (0.01 * rtol)))
    return int(2 + np.ceil(decades / (-2.0 * lam * np.log10(sigma))))


def corner_exponent(a_over_r, neck: str = "cylinder"):
    r"""Singular exponent :math:`\lambda` of the temperature at the neck's rim, which varies like :math:`\rho^\lambda`
    there.

    ``neck = "cylinder"``: the re-entrant corner where a cylindrical neck of radius ``a`` meets a sphere of radius ``r``
    (interior angle :math:`\pi + \arccos(a/r)`, both faces insulated), :math:`\lambda = \pi / (\pi + \arccos(a/r))`: 2/3
    for a vanishing neck, 1 (no singularity) at :math:`a = r`. ``neck = "union"``: the corner where the isothermal neck
    disk meets the insulated sphere (interior angle :math:`\omega = \pi/2 + \arccos(a/r)`, mixed Dirichlet/Neumann, so
    :math:`\lambda = \pi / (2 \omega) = \pi / (\pi + 2 \arccos(a/r))`): 1/2 for a vanishing neck (the rim of a disk on a
    half-space), 1 at ``a = r``.

    Parameters
    ----------
    a_over_r : float or array_like
        Neck radius over particle radius, ``a/r`` (dimensionless; clipped to ``[0, 1]``).
    neck : str
        The half body (:data:`fem_neck.law.NECKS`): ``"cylinder"`` or ``"union"``.

    Returns
    -------
    float or numpy.ndarray
        ``lambda`` (dimensionless), in ``[2/3, 1]`` for the cylinder and ``[1/2, 1]`` for the union.

    Raises
    ------
    ValueError
        ``neck`` is not one of :data:`fem_neck.law.NECKS`.
    """
    angle = np.arccos(np.clip(a_over_r, 0.0, 1.0))
    return np.pi / (np.pi + (2.0 if check_neck(neck) == "union" else 1.0) * angle)


MESH_RATIO = 1.6  #: sizes shrink by this factor per level of a mesh sequence
SAFETY = 1.25  #: on the extrapolated error of a mesh sequence (Roache's factor for three or more levels)


@dataclass(frozen=True)
class SequenceEstimate:
    r"""The error of the finest value of a mesh sequence (:func:`mesh_sequence_estimate`).

    ``relative``: ``error / |value|``. ``amplification = SAFETY / (rate - 1)`` turns the last change of any other
    quantity solved on the same meshes (e.g. particle temperatures) into its error estimate.

    Parameters
    ----------
    value : float
        The finest value of the sequence (the unit of the values, e.g. W/K).
    error : float
        Absolute error estimate of ``value`` (same unit).
    rate : float
        The error ratio per level used (dimensionless, > 1).
    observed_rate : float or None
        The ratio of the last two changes, from three levels; None with two, or when the sequence does not contract.
    observed_order : float or None
        :math:`\log(\rho_{obs}) / \log(q)` (``observed_rate`` over ``ratio``), the observed convergence order in the
        mesh size; None where there is no observed rate.
    corner_order : float
        :math:`2 \lambda`, the order the re-entrant corner allows.
    monotone : bool
        Whether the sequence contracts (its changes shrink without changing sign).
    """

    value: float
    error: float
    rate: float
    observed_rate: float | None
    observed_order: float | None
    corner_order: float
    monotone: bool

    @property
    def relative(self) -> float:
        """The error estimate over the value's magnitude (dimensionless; inf for a zero value)."""
        return self.error / abs(self.value) if self.value else math.inf

    @property
    def amplification(self) -> float:
        """The factor ``SAFETY / (rate - 1)`` from the last change to the error estimate."""
        return SAFETY / (self.rate - 1.0)


def mesh_levels(levels: int, ratio: float = MESH_RATIO) -> list[float]:
    r"""Size factors of a mesh sequence, coarsest first, the finest 1: :math:`q^{n-1}, \ldots, q, 1` (``ratio`` q,
    ``levels`` n).

    Parameters
    ----------
    levels : int
        Number of meshes: 1, 2 or 3.
    ratio : float
        The factor (> 1) by which every element size shrinks per level.

    Returns
    -------
    list of float
        The factors multiplying the finest mesh's sizes.

    Raises
    ------
    ValueError
        ``levels`` is not 1, 2 or 3.
    """
    if levels not in (1, 2, 3):
        raise ValueError(f"levels = {levels!r}: must be 1, 2 or 3")
    return [ratio ** k for k in range(levels - 1, -1, -1)]


def mesh_sequence_estimate(values, exponent: float, ratio: float = MESH_RATIO) -> SequenceEstimate:
    r"""Error of the last of 2 or 3 values solved on meshes whose every size shrinks by ``ratio`` per level.

    ``exponent``: the smallest corner exponent ``lambda`` of the body (:func:`corner_exponent`; 1 if it has no
    re-entrant corner). See the module docstring for the formula and why it bounds the error.

    Parameters
    ----------
    values : sequence of float
        The 2 or 3 values, coarsest mesh first (any unit, e.g. W/K).
    exponent : float
        The smallest corner exponent :math:`\lambda` of the body, :math:`0.5 \le \lambda \le 1`.
    ratio : float
        The factor (> 1) by which every element size shrinks per level.

    Returns
    -------
    SequenceEstimate
        The finest value and its error estimate.

    Raises
    ------
    ValueError
        Not 2 or 3 values, or ``exponent`` outside ``[0.5, 1]``.
    """
    v = [float(x) for x in values]
    if len(v) not in (2, 3):
        raise ValueError(f"values: {len(v)} given, a mesh sequence estimate needs 2 or 3")
    if not 0.5 <= exponent <= 1.0:
        raise ValueError(f"exponent = {exponent!r}: valid range 0.5 <= lambda <= 1")
    corner = ratio ** (2.0 * exponent)
    last = v[-2] - v[-1]
    observed = None
    monotone = True
    rate = corner
    if len(v) == 3:
        before = v[0] - v[1]
        if last != 0.0:
            observed = before / last
            monotone = observed > 1.0
            if monotone:
                rate = min(observed, corner)
        elif before != 0.0:
            monotone = False
    change = abs(last) if monotone else max(abs(v[0] - v[1]), abs(last))
    order = math.log(observed) / math.log(ratio) if observed is not None and observed > 1.0 else None
    return SequenceEstimate(value=v[-1], error=SAFETY * change / (rate - 1.0), rate=rate,
                            observed_rate=observed if monotone else None, observed_order=order,
                            corner_order=2.0 * exponent, monotone=monotone)
