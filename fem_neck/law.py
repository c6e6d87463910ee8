r"""Conductance laws of a sintered neck: K/K_cyl as a function of a/r (numpy only; the DEM imports this module).

:math:`x = a/r` is the neck radius over the particle radius and :math:`K_{cyl} = \kappa \pi r` (Rojek 2022,
eqs. 38-39) the conductance of a cylinder of radius r and length r. A *law* is any object with ``k_over_kcyl(x)``;
from it

* :func:`half_conductance` -- the conductance of one particle's half of a sintered pair, :math:`K_i = \kappa \pi
  r_i f(a/r_i)` (eq. 43 when f is linear), and
* :func:`pair_conductance` -- the thermal pipe of a pair, the two halves in series, each with its own
  :math:`a/r_i`: :math:`K_{ij} = K_i K_j / (K_i + K_j)` (Rojek 2022, eq. 9), for the full-range law times the
  small FE correction for unequal radii :func:`unequal_factor`.

The laws:

* :class:`LinearLaw` -- :math:`f(x) = c x`; :data:`ROJEK` is c = 1.064 (Rojek 2022, eq. 40), :data:`ARGENTO_BOUVARD`
  :math:`c = 1/0.899 = 1.112` (eqs. 41-42).
* :class:`ConductanceLaw` -- the full-range law fitted to FE by ``python -m fem_neck fit`` and read from its
  ``fit.json`` (:meth:`ConductanceLaw.from_json`; :meth:`ConductanceLaw.default` is the fit shipped in
  ``fem_neck/data/fit.json``). It splits the half body's resistance (in units of :math:`1/(\kappa \pi r)`) into the
  neck cylinder and the sphere segment:

  .. math::

      \frac{1}{f(x)} = \lambda(x) + \frac{\pi}{4 x} P(x)

  - :math:`\lambda(x) = (h_n/2) / (r x^2)` is the exact resistance of the half neck, a cylinder of radius a and
    length :math:`h_n/2` (eqs. 16-20): with :math:`s = \sqrt{1 - x^2}` and :math:`h_c = x^2/(1 + s)`,
    :math:`\lambda = (3 - h_c) / (3 (2 - h_c) (1 + s))`, from 1/4 at x -> 0 to 2/3 at x = 1.
  - :math:`\pi/(4x)` is the spreading resistance :math:`1/(4 \kappa a)` of an isothermal disk on a half-space, and

    .. math::

        P(x) = 1 + A x \ln(1/x) + B x + C x^2 + E x^3 - (1 + B + C + E)(1 - s)

    the sphere segment's correction to it.
    P(0) = 1: the half-conductance tends to the constriction limit :math:`4 \kappa a` (:math:`f \to (4/\pi) x`).
    The :math:`x \ln(1/x)` term is the next order of the small-neck expansion, with the coefficient :data:`A_LOG` =
    :math:`5/(4 \pi)` derived, not fitted: :math:`1/\pi` from the sphere (the Neumann function of a ball has a
    logarithmic part, so a small contact on a sphere of radius r adds :math:`\ln(r/a)/(4 \pi \kappa r)` to
    :math:`1/(4 \kappa a)`), plus :math:`1/(4 \pi)` from the thin half neck (length :math:`l = a x/4`) carrying the
    isothermal disk's rim-singular flux :math:`q \sim (a^2 - \rho^2)^{-1/2}`, which adds
    :math:`(l/(4 \pi \kappa a^2)) \ln(a/l)` to its 1-D resistance. The FE sweep gives 0.398 +- 0.002 for this
    coefficient between :math:`a/r` = 3e-4 and 1e-2 (:math:`5/(4 \pi)` = 0.3979).
    :math:`s = z_i / r` is the thickness of the segment left between the equator and the cap base; it vanishes at
    x = 1, where P(1) = 0 and the half body is a cylinder of radius r and length 2r/3, :math:`f(1) = 3/2` exactly.

* The same law for the half body of the *union of spheres* (``ConductanceLaw(..., neck="union")``;
  :meth:`ConductanceLaw.default` ``(neck="union")`` is the fit shipped in ``fem_neck/data/fit_union.json``, written
  by ``python -m fem_neck fit --neck union``). A neck of the union is the circle where two spheres meet, in their
  radical plane at :math:`l = (d^2 + r_i^2 - r_j^2) / (2 d)` from centre i, of radius :math:`a = \sqrt{r_i^2 - l^2}`
  (:func:`fem_neck.geometry.union.lens`); the half body is the sphere between its equatorial plane and that plane,
  whose disk of radius a is isothermal, with no neck cylinder:

  .. math::

      \frac{1}{f(x)} = \frac{\pi}{4 x} P_u(x)

  with :math:`P_u` of the form of P and its own B, C, E. :math:`P_u(0) = 1` (the constriction limit
  :math:`4 \kappa a`). Its :math:`x \ln(1/x)` coefficient is :data:`A_LOG_UNION` = :math:`1/\pi`, the ball's
  Neumann log alone: there is no half neck to carry the disk's rim-singular flux (the rim now sees the sphere at the
  angle :math:`\pi/2 + \arccos(x)`, a change of the geometry of relative size x with a finite energy integral, which
  moves B, not A). The FE gives 0.3183 for this coefficient between :math:`a/r` = 3e-4 and 1e-2 (:math:`1/\pi` =
  0.31831), against 0.3980 for the neck cylinder. At x -> 1 the half body is a slab of thickness :math:`s = z_i / r`:
  its resistance vanishes and :math:`f \to \infty`; the exact limit, the 1-D resistance through the cross-sections
  :math:`\pi (r^2 - z^2)`, is :math:`1/f = \operatorname{atanh}(s) + O(s^4)`, and the form gives
  :math:`1/f \to (\pi/4)(1 + B + C + E) s` (:math:`P_u(1) = 0` from the last term). B, C, E are fitted freely, as for
  the cylinder: holding the slope at s -> 0 exact (:math:`1 + B + C + E = 4/\pi`) costs the form a factor 5 in accuracy
  over the sweep, so the fitted slope differs from 1 by what the fit's residual at x = 0.97 allows (see the fit file's
  ``max_rel_residual``, and the guide for the law's error beyond the fit range).
"""

from __future__ import annotations

import functools
import json
import pathlib
from dataclasses import dataclass, field

import numpy as np

FORM = "1/f = lambda(x) + pi/(4x) * (1 + A x ln(1/x) + B x + C x^2 + E x^3 - (1 + B + C + E)(1 - sqrt(1 - x^2)))"
FORM_UNION = "1/f = pi/(4x) * (1 + A x ln(1/x) + B x + C x^2 + E x^3 - (1 + B + C + E)(1 - sqrt(1 - x^2)))"
FORMS = {"cylinder": FORM, "union": FORM_UNION}  #: the law's form for each neck
PARAMETERS = ("A", "B", "C", "E")
A_LOG = 5.0 / (4.0 * np.pi)  #: the x ln(1/x) coefficient of P(x) (module docstring); the fit keeps A = A_LOG
A_LOG_UNION = 1.0 / np.pi  #: The same for the union's half body, the ball's log alone (module docstring).
DEFAULT_FIT = pathlib.Path(__file__).with_name("data") / "fit.json"
DEFAULT_FIT_UNION = DEFAULT_FIT.with_name("fit_union.json")


NECKS = ("cylinder", "union")  #: The half bodies a law is for, Rojek's volume-conserving neck cylinder or the union


def check_neck(neck) -> str:
    """``neck`` if it names a half body of :data:`NECKS`, else ``ValueError``.

    Parameters
    ----------
    neck : str
        The half body a law is for: ``"cylinder"`` (Rojek's volume-conserving neck cylinder) or ``"union"`` (the
        union of spheres).

    Returns
    -------
    str
        ``neck``, unchanged.

    Raises
    ------
    ValueError
        ``neck`` is not one of :data:`NECKS`.
    """
    if neck not in NECKS:
        raise ValueError(f"neck = {neck!r}: must be one of {', '.join(NECKS)}")
    return neck


def check_neck_ratio(a_over_r, name: str = "a_over_r") -> np.ndarray:
    """``a/r`` as a float array, raising ``ValueError`` unless every entry is finite and in ``[0, 1]``.

    Parameters
    ----------
    a_over_r : float or array_like
        Neck radius over particle radius, :math:`x = a/r` (dimensionless), any shape.
    name : str
        The name the error message gives the value (``"a/r_min"``, say).

    Returns
    -------
    numpy.ndarray
        ``a_over_r`` as floats, same shape.

    Raises
    ------
    ValueError
        An entry is not finite or lies outside ``[0, 1]`` (the message names the first one).
    """
    x = np.asarray(a_over_r, dtype=float)
    bad = ~np.isfinite(x) | (x < 0.0) | (x > 1.0)
    if np.any(bad):
        value = x[bad].flat[0] if x.ndim else float(x)
        raise ValueError(f"{name} = {value!r}: must be in [0, 1] (the neck cannot be wider than the particle)")
    return x


def _out(value):
    return float(value) if np.ndim(value) == 0 else value


def neck_resistance(a_over_r):
    r""":math:`\lambda(x)`: resistance of the half neck of an equal pair in units of :math:`1/(\kappa \pi r)` (eqs.
    16-20).

    The half neck is a cylinder of radius :math:`a = x r` and length :math:`h_n/2`; :math:`\lambda = h_n / (2 r x^2)`,
    finite at x -> 0 (1/4) and 2/3 at x = 1.

    Parameters
    ----------
    a_over_r : float or array_like
        Neck radius over particle radius, :math:`x = a/r` in ``[0, 1]`` (dimensionless).

    Returns
    -------
    float or numpy.ndarray
        :math:`\lambda(x)` (dimensionless: the resistance times :math:`\kappa \pi r`), a float for a scalar input.
    """
    x = check_neck_ratio(a_over_r)
    s = np.sqrt(1.0 - x * x)
    h_c = x * x / (1.0 + s)  # cap height / r, eq. (20) solved for h_c without cancellation
    return _out((3.0 - h_c) / (3.0 * (2.0 - h_c) * (1.0 + s)))


def half_neck_resistance(a_over_r, neck: str = "cylinder"):
    r"""The neck's part of the half body's resistance in units of :math:`1/(\kappa \pi r)`: :math:`\lambda(x)` of the
    half neck cylinder (:func:`neck_resistance`) for ``neck = "cylinder"``, 0 for the union (it has no neck cylinder).

    Parameters
    ----------
    a_over_r : float or array_like
        Neck radius over particle radius, :math:`x = a/r` in ``[0, 1]`` (dimensionless).
    neck : str
        The half body (:data:`NECKS`): ``"cylinder"`` or ``"union"``.

    Returns
    -------
    float or numpy.ndarray
        The half neck's resistance times :math:`\kappa \pi r` (dimensionless), a float for a scalar input.

    Raises
    ------
    ValueError
        ``a_over_r`` has an entry outside ``[0, 1]`` or not finite, or ``neck`` is not one of :data:`NECKS`.
    """
    x = check_neck_ratio(a_over_r)
    return neck_resistance(x) if check_neck(neck) == "cylinder" else _out(np.zeros_like(x))


@dataclass(frozen=True)
class LinearLaw:
    """``K/K_cyl = slope * a/r`` (Rojek 2022, eq. 40; Argento & Bouvard 1996 via eqs. 41-42).

    Parameters
    ----------
    slope : float
        The constant ``c`` of ``K/K_cyl = c a/r`` (dimensionless): 1.064 for Rojek 2022's eq. 40.
    name : str
        Where the law comes from, for reports and plots.
    """

    slope: float
    name: str = "linear"

    def k_over_kcyl(self, a_over_r):
        r""":math:`K/K_{cyl} = c x` (``slope`` c): the half-pair conductance over :math:`K_{cyl} = \kappa \pi r` (eq.
        40).

        Parameters
        ----------
        a_over_r : float or array_like
            Neck radius over particle radius, :math:`x = a/r` in ``[0, 1]`` (dimensionless).

        Returns
        -------
        float or numpy.ndarray
            ``K/K_cyl`` (dimensionless), a float for a scalar input.
        """
        return _out(self.slope * check_neck_ratio(a_over_r))


ROJEK = LinearLaw(1.064, "Rojek 2022, eq. (40)")  #: K/K_cyl = 1.064 a/r
ARGENTO_BOUVARD = LinearLaw(1.0 / 0.899, "Argento & Bouvard 1996, eq. (42)")  #: K/K_cyl = (1/0.899) a/r


@dataclass(frozen=True)
class ConductanceLaw:
    r"""The full-range law :math:`f(x) = K/K_{cyl}` (module docstring), valid on :math:`0 \le a/r \le 1`.

    Outside the fit range the law follows its exact limits (x -> 0 and x = 1).

    Parameters
    ----------
    A : float
        Coefficient of :math:`x \ln(1/x)` in :math:`P(x)` (dimensionless); the fit keeps the derived :data:`A_LOG`.
    B : float
        Coefficient of ``x`` in :math:`P(x)` (dimensionless, fitted).
    C : float
        Coefficient of :math:`x^2` in :math:`P(x)` (dimensionless, fitted).
    E : float
        Coefficient of :math:`x^3` in :math:`P(x)` (dimensionless, fitted).
    fit_range : tuple of float
        The ``(low, high)`` a/r interval of the FE points the law was fitted to (dimensionless).
    max_rel_residual : float
        The largest relative misfit to those FE points (dimensionless; NaN when unknown).
    name : str
        A label for reports and plots.
    source : str
        The fit.json it was read from ("" when made in memory); not compared between laws.
    neck : str
        The half body the law is for (:data:`NECKS`): ``"cylinder"`` (with the half neck's :math:`\lambda(x)`) or
        ``"union"`` (without; ``f -> inf`` as x -> 1).
    """

    A: float
    B: float
    C: float
    E: float
    fit_range: tuple = (0.001, 0.97)
    max_rel_residual: float = float("nan")
    name: str = "full-range"
    source: str = field(default="", compare=False)
    neck: str = "cylinder"

    def __post_init__(self):
        check_neck(self.neck)

    @property
    def parameters(self) -> dict:
        """``{"A": ..., "B": ..., "C": ..., "E": ...}``: the coefficients of :math:`P(x)`."""
        return {p: getattr(self, p) for p in PARAMETERS}

    @property
    def form(self) -> str:
        """The law's formula as text (:data:`FORMS` of its neck)."""
        return FORMS[self.neck]

    def segment_correction(self, a_over_r):
        r""":math:`P(x)`: sphere-segment resistance over the half-space disk value :math:`1/(4 \kappa a)`;
        :math:`P(0) = 1`, :math:`P(1) = 0`.

        Parameters
        ----------
        a_over_r : float or array_like
            Neck radius over particle radius, :math:`x = a/r` in ``[0, 1]`` (dimensionless).

        Returns
        -------
        float or numpy.ndarray
            :math:`P(x)` (dimensionless), a float for a scalar input.
        """
        x = check_neck_ratio(a_over_r)
        s = np.sqrt(1.0 - x * x)
        x_log = -x * np.log(np.where(x > 0.0, x, 1.0))
        p = (1.0 + self.A * x_log + self.B * x + self.C * x**2 + self.E * x**3
             - (1.0 + self.B + self.C + self.E) * (x * x / (1.0 + s)))
        return _out(p)

    def k_over_kcyl(self, a_over_r):
        r""":math:`K/K_{cyl} = x / (x \lambda(x) + (\pi/4) P(x))`; vectorised, 0 at :math:`x = 0`; at :math:`x = 1` 3/2
        (cylinder) or inf (union: the half body's thickness, and its resistance, vanish).

        Parameters
        ----------
        a_over_r : float or array_like
            Neck radius over particle radius, :math:`x = a/r` in ``[0, 1]`` (dimensionless).

        Returns
        -------
        float or numpy.ndarray
            :math:`K/K_{cyl}`, the half-pair conductance over :math:`\kappa \pi r` (dimensionless), a float for a scalar
            input.
        """
        x = check_neck_ratio(a_over_r)
        with np.errstate(divide="ignore"):
            return _out(x / (x * half_neck_resistance(x, self.neck) + 0.25 * np.pi * self.segment_correction(x)))

    def require_neck(self, neck: str) -> "ConductanceLaw":
        """This law if it was fitted for ``neck``; ``ValueError`` naming its fit file otherwise (a law of the
        neck-cylinder half body used for union necks, or the reverse).

        Parameters
        ----------
        neck : str
            The half body the caller will use the law for (:data:`NECKS`): ``"cylinder"`` or ``"union"``.

        Returns
        -------
        ConductanceLaw
            This law, unchanged.

        Raises
        ------
        ValueError
            ``neck`` is not one of :data:`NECKS`, or the law was fitted for the other half body.
        """
        if check_neck(neck) != self.neck:
            where = f"fit file = {self.source!r}" if self.source else "law"
            raise ValueError(f"{where}: fitted for neck = {self.neck!r}, cannot be used for neck = {neck!r} (fit one "
                             f"with: python -m fem_neck fit --neck {neck})")
        return self

    def table(self, n: int = 200) -> list:
        """``n`` rows ``[a_over_r, K_over_Kcyl]``, log-spaced below 0.01 and uniform above, over the fit range.

        Parameters
        ----------
        n : int
            Number of rows (a fifth of them, at least 2, below a/r = 0.01).

        Returns
        -------
        list of list of float
            ``[a/r, K/K_cyl]`` pairs (both dimensionless), a/r increasing.
        """
        lo, hi = self.fit_range
        n_log = max(2, n // 5)
        x = np.concatenate([np.geomspace(lo, min(0.01, hi), n_log, endpoint=False),
                            np.linspace(min(0.01, hi), hi, n - n_log)])
        return [[float(a), float(k)] for a, k in zip(x, np.atleast_1d(self.k_over_kcyl(x)))]

    def to_dict(self) -> dict:
        """The ``law`` entry of fit.json (without the table, which the fit adds).

        Returns
        -------
        dict
            ``form`` (the formula as text), ``parameters`` (:attr:`parameters`), ``range`` (:attr:`fit_range`) and
            ``max_rel_residual``.
        """
        return {"form": self.form, "parameters": self.parameters, "range": list(self.fit_range),
                "max_rel_residual": self.max_rel_residual}

    @classmethod
    def from_dict(cls, law: dict, source: str = "", neck: str = "cylinder") -> "ConductanceLaw":
        """The law of a fit.json ``law`` entry (:meth:`to_dict`'s form), for the half body ``neck`` (which the file
        records beside it).

        Parameters
        ----------
        law : dict
            ``parameters`` with ``A``, ``B``, ``C`` and ``E``; optional ``range`` (default ``(0.001, 0.97)``) and
            ``max_rel_residual`` (default NaN).
        source : str
            Where the entry was read from, kept as :attr:`source`.
        neck : str
            The half body the entry was fitted for (:data:`NECKS`).

        Returns
        -------
        ConductanceLaw

        Raises
        ------
        ValueError
            ``parameters`` or one of its four coefficients is missing or not a number.
        """
        try:
            params = {p: float(law["parameters"][p]) for p in PARAMETERS}
        except (KeyError, TypeError) as exc:
            raise ValueError(f"law = {law!r}: must hold 'parameters' {PARAMETERS} of the form "
                             f"{FORMS[check_neck(neck)]!r}") from exc
        return cls(**params, fit_range=tuple(law.get("range", (0.001, 0.97))),
                   max_rel_residual=float(law.get("max_rel_residual", float("nan"))), source=source, neck=neck)

    @classmethod
    def from_json(cls, path) -> "ConductanceLaw":
        """The law in a fit.json written by ``python -m fem_neck fit`` (its ``law`` entry, for the file's ``neck``;
        a file without one was fitted before the union existed, to the neck cylinder).

        Parameters
        ----------
        path : str or pathlib.Path
            The fit.json file.

        Returns
        -------
        ConductanceLaw
            With :attr:`source` the path.

        Raises
        ------
        ValueError
            The file cannot be read, is not JSON, has no ``law`` entry, its entry is incomplete or its ``neck`` is
            unknown (the message names the file).
        """
        path = pathlib.Path(path)
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, json.JSONDecodeError) as exc:
            raise ValueError(f"fit file = {str(path)!r}: cannot be read as JSON ({exc})") from exc
        except UnicodeDecodeError as exc:  # binary garbage: a ValueError of its own that names no file
            raise ValueError(f"fit file = {str(path)!r}: cannot be read as JSON (not UTF-8 text: byte "
                             f"{exc.start})") from None
        if not isinstance(data, dict) or "law" not in data:
            raise ValueError(f"fit file = {str(path)!r}: must be a JSON object with a 'law' entry")
        neck = data.get("neck", "cylinder")
        if neck not in NECKS:
            raise ValueError(f"fit file = {str(path)!r}: neck = {neck!r} must be one of {', '.join(NECKS)}")
        try:
            return cls.from_dict(data["law"], source=str(path), neck=neck)
        except ValueError as exc:
            raise ValueError(f"fit file = {str(path)!r}: {exc}") from None

    @classmethod
    def default(cls, neck: str = "cylinder") -> "ConductanceLaw":
        """The fit shipped with the package for ``neck``, read once: ``fem_neck/data/fit.json`` (the neck cylinder,
        default) or ``fem_neck/data/fit_union.json`` (the union of spheres).

        Parameters
        ----------
        neck : str
            The half body (:data:`NECKS`): ``"cylinder"`` (default) or ``"union"``.

        Returns
        -------
        ConductanceLaw
            The shipped law fitted for ``neck``.

        Raises
        ------
        ValueError
            ``neck`` is not one of :data:`NECKS`, or the shipped file cannot be read or was fitted for another neck.
        """
        return _default_law(check_neck(neck))


@functools.lru_cache(maxsize=len(NECKS))
def _default_law(neck: str) -> ConductanceLaw:
    return ConductanceLaw.from_json(DEFAULT_FIT if neck == "cylinder" else DEFAULT_FIT_UNION).require_neck(neck)


def _positive(name, value):
    v = np.asarray(value, dtype=float)
    if np.any(~np.isfinite(v) | (v <= 0.0)):
        raise ValueError(f"{name} = {value!r}: must be finite and > 0")
    return v


def half_conductance(kappa, r, a, law=None):
    r""":math:`K_i = \kappa \pi r f(a/r)` in W/K: one particle's half of a sintered pair (Rojek 2022, eq. 43 for f
    linear).

    Vectorised: the arguments broadcast against each other.

    Parameters
    ----------
    kappa : float or array_like
        Thermal conductivity of the particle's material, W/(m K), finite and > 0.
    r : float or array_like
        Particle radius, m, finite and > 0.
    a : float or array_like
        Neck radius, m, in ``[0, r]``.
    law : LinearLaw or ConductanceLaw, optional
        ``f(a/r) = K/K_cyl``; default :meth:`ConductanceLaw.default`.

    Returns
    -------
    float or numpy.ndarray
        ``K_i`` in W/K, a float for scalar inputs.

    Raises
    ------
    ValueError
        ``kappa`` or ``r`` not finite and positive, or ``a/r`` outside ``[0, 1]``.
    """
    law = ConductanceLaw.default() if law is None else law
    kappa, r = _positive("kappa", kappa), _positive("r", r)
    a = np.asarray(a, dtype=float)
    return _out(kappa * np.pi * r * np.asarray(law.k_over_kcyl(check_neck_ratio(a / r, "a/r"))))


# Unequal pairs (``python -m fem_neck unequal``, FE of r_j/r_i = 1..10, a/r_i = 0.01..0.95): the series of halves
# over-estimates K by up to 1.3 %, by ``c (a/r_min) ln(r_max/r_min)`` to within 0.12 % (c = 0.00540 fitted).
UNEQUAL_C = 0.0054


def unequal_factor(r_i, r_j, a, c: float = UNEQUAL_C):
    r""":math:`1 / (1 + c (a/r_{min}) \ln(r_{max}/r_{min}))`: the FE correction of the series of halves for unequal
    radii.

    The halves of :func:`pair_conductance` are solved with an isothermal neck cross-section; in an unequal pair that
    plane is not isothermal, and freeing it lowers K (Dirichlet's principle: the series of halves is an upper
    bound). ``c`` is fitted over 1 <= r_max/r_min <= 10 (``python -m fem_neck unequal``); 1 for equal radii.

    Parameters
    ----------
    r_i, r_j : float or array_like
        The two particle radii, m, finite and > 0.
    a : float or array_like
        Neck radius, m, in ``[0, min(r_i, r_j)]``.
    c : float
        The fitted coefficient (dimensionless), default ``UNEQUAL_C`` = 0.0054.

    Returns
    -------
    float or numpy.ndarray
        The factor (dimensionless, at most 1) that multiplies the series of halves; a float for scalar inputs.

    Raises
    ------
    ValueError
        A radius not finite and positive, or ``a/r_min`` outside ``[0, 1]``.
    """
    r_i, r_j = _positive("r_i", r_i), _positive("r_j", r_j)
    r_min, r_max = np.minimum(r_i, r_j), np.maximum(r_i, r_j)
    x = check_neck_ratio(np.asarray(a, dtype=float) / r_min, "a/r_min")
    return _out(1.0 / (1.0 + c * x * np.log(r_max / r_min)))


def pair_conductance(kappa, r_i, r_j, a, law=None, unequal: bool = True):
    r""":math:`K_{ij} = K_i K_j / (K_i + K_j)` with :math:`K_i = \kappa \pi r_i f(a/r_i)` (Rojek 2022, eq. 9);
    vectorised.

    Each half takes its own ``a/r`` (its own half neck too: the neck length of the volume-conserving model splits
    exactly into the two equal-pair half necks, ``h_n = h_n(r_i, r_i)/2 + h_n(r_j, r_j)/2``). With the linear law
    both halves equal :math:`c \kappa \pi a` (eqs. 43-45). With the full-range law and ``unequal`` (default) the series
    is multiplied by :func:`unequal_factor`; the linear laws are the papers' models and are never corrected.

    Parameters
    ----------
    kappa : float or array_like
        Thermal conductivity of the particles' material, W/(m K), finite and > 0.
    r_i, r_j : float or array_like
        The two particle radii, m, finite and > 0.
    a : float or array_like
        Neck radius, m, in ``[0, min(r_i, r_j)]``.
    law : LinearLaw or ConductanceLaw, optional
        ``f(a/r) = K/K_cyl`` of each half; default :meth:`ConductanceLaw.default`.
    unequal : bool
        Multiply the full-range law's series by :func:`unequal_factor` (ignored for a :class:`LinearLaw`).

    Returns
    -------
    float or numpy.ndarray
        ``K_ij`` in W/K (0 where both halves are 0), a float for scalar inputs.

    Raises
    ------
    ValueError
        ``kappa`` or a radius not finite and positive, or a neck wider than its particle.
    """
    law = ConductanceLaw.default() if law is None else law
    k_i = np.asarray(half_conductance(kappa, r_i, a, law))
    k_j = np.asarray(half_conductance(kappa, r_j, a, law))
    total = k_i + k_j
    with np.errstate(invalid="ignore"):
        k = np.divide(k_i * k_j, total, out=np.zeros_like(total), where=total > 0)
    k = np.where(np.isinf(k_i), k_j, np.where(np.isinf(k_j), k_i, k))  # a union half at a = r has no resistance
    if unequal and isinstance(law, ConductanceLaw):
        k = k * unequal_factor(r_i, r_j, a)
    return _out(k)
