"""Conductance laws of a sintered neck: K/K_cyl as a function of a/r (numpy only; the DEM imports this module).

``x = a/r`` is the neck radius over the particle radius and ``K_cyl = kappa*pi*r`` (Rojek 2022, eqs. 38-39) the
conductance of a cylinder of radius r and length r. A *law* is any object with ``k_over_kcyl(x)``; from it

* :func:`half_conductance` -- the conductance of one particle's half of a sintered pair, ``K_i = kappa pi r_i
  f(a/r_i)`` (eq. 43 when f is linear), and
* :func:`pair_conductance` -- the thermal pipe of a pair, the two halves in series, each with its own ``a/r_i``:
  ``K_ij = K_i K_j / (K_i + K_j)`` (Rojek 2022, eq. 9), for the full-range law times the small FE correction for
  unequal radii :func:`unequal_factor`.

The laws:

* :class:`LinearLaw` -- ``f(x) = c x``; :data:`ROJEK` is c = 1.064 (Rojek 2022, eq. 40), :data:`ARGENTO_BOUVARD`
  c = 1/0.899 = 1.112 (eqs. 41-42).
* :class:`ConductanceLaw` -- the full-range law fitted to FE by ``python -m fem_neck fit`` and read from its
  ``fit.json`` (:meth:`ConductanceLaw.from_json`; :meth:`ConductanceLaw.default` is the fit shipped in
  ``fem_neck/data/fit.json``). It splits the half body's resistance (in units of ``1/(kappa pi r)``) into the neck
  cylinder and the sphere segment::

      1/f(x) = lambda(x) + (pi / (4 x)) P(x)

  - ``lambda(x) = (h_n/2) / (r x^2)`` is the exact resistance of the half neck, a cylinder of radius a and length
    ``h_n/2`` (eqs. 16-20): with ``s = sqrt(1 - x^2)`` and ``h_c = x^2/(1 + s)``,
    ``lambda = (3 - h_c) / (3 (2 - h_c) (1 + s))``, from 1/4 at x -> 0 to 2/3 at x = 1.
  - ``pi/(4x)`` is the spreading resistance ``1/(4 kappa a)`` of an isothermal disk on a half-space, and
    ``P(x) = 1 + A x ln(1/x) + B x + C x^2 + E x^3 - (1 + B + C + E)(1 - s)`` the sphere segment's correction to it.
    P(0) = 1: the half-conductance tends to the constriction limit ``4 kappa a`` (f -> (4/pi) x). The ``x ln(1/x)``
    term is the next order of the small-neck expansion, with the coefficient :data:`A_LOG` = 5/(4 pi) derived, not
    fitted: 1/pi from the sphere (the Neumann function of a ball has a logarithmic part, so a small contact on a
    sphere of radius r adds ``ln(r/a)/(4 pi kappa r)`` to ``1/(4 kappa a)``), plus 1/(4 pi) from the thin half neck
    (length ``l = a x/4``) carrying the isothermal disk's rim-singular flux ``q ~ (a^2 - rho^2)^(-1/2)``, which
    adds ``(l/(4 pi kappa a^2)) ln(a/l)`` to its 1-D resistance. The FE sweep gives 0.398 +- 0.002 for this
    coefficient between a/r = 3e-4 and 1e-2 (5/(4 pi) = 0.3979).
    ``s = z_i / r`` is the thickness of the segment left between the equator and the cap base; it vanishes at
    x = 1, where P(1) = 0 and the half body is a cylinder of radius r and length 2r/3, ``f(1) = 3/2`` exactly.
"""

from __future__ import annotations

import functools
import json
import pathlib
from dataclasses import dataclass, field

import numpy as np

FORM = "1/f = lambda(x) + pi/(4x) * (1 + A x ln(1/x) + B x + C x^2 + E x^3 - (1 + B + C + E)(1 - sqrt(1 - x^2)))"
PARAMETERS = ("A", "B", "C", "E")
A_LOG = 5.0 / (4.0 * np.pi)  #: the x ln(1/x) coefficient of P(x) (module docstring); the fit keeps A = A_LOG
DEFAULT_FIT = pathlib.Path(__file__).with_name("data") / "fit.json"


def check_neck_ratio(a_over_r, name: str = "a_over_r") -> np.ndarray:
    """``a/r`` as a float array, raising ``ValueError`` unless every entry is finite and in ``[0, 1]``."""
    x = np.asarray(a_over_r, dtype=float)
    bad = ~np.isfinite(x) | (x < 0.0) | (x > 1.0)
    if np.any(bad):
        value = x[bad].flat[0] if x.ndim else float(x)
        raise ValueError(f"{name} = {value!r}: must be in [0, 1] (the neck cannot be wider than the particle)")
    return x


def _out(value):
    return float(value) if np.ndim(value) == 0 else value


def neck_resistance(a_over_r):
    """``lambda(x)``: resistance of the half neck of an equal pair in units of ``1/(kappa pi r)`` (eqs. 16-20).

    The half neck is a cylinder of radius ``a = x r`` and length ``h_n/2``; ``lambda = h_n / (2 r x^2)``, finite at
    x -> 0 (1/4) and 2/3 at x = 1.
    """
    x = check_neck_ratio(a_over_r)
    s = np.sqrt(1.0 - x * x)
    h_c = x * x / (1.0 + s)  # cap height / r, eq. (20) solved for h_c without cancellation
    return _out((3.0 - h_c) / (3.0 * (2.0 - h_c) * (1.0 + s)))


@dataclass(frozen=True)
class LinearLaw:
    """``K/K_cyl = slope * a/r`` (Rojek 2022, eq. 40; Argento & Bouvard 1996 via eqs. 41-42)."""

    slope: float
    name: str = "linear"

    def k_over_kcyl(self, a_over_r):
        return _out(self.slope * check_neck_ratio(a_over_r))


ROJEK = LinearLaw(1.064, "Rojek 2022, eq. (40)")  #: K/K_cyl = 1.064 a/r
ARGENTO_BOUVARD = LinearLaw(1.0 / 0.899, "Argento & Bouvard 1996, eq. (42)")  #: K/K_cyl = (1/0.899) a/r


@dataclass(frozen=True)
class ConductanceLaw:
    """The full-range law ``f(x) = K/K_cyl`` (module docstring), valid on ``0 <= a/r <= 1``.

    ``fit_range`` is the a/r interval of the FE points it was fitted to and ``max_rel_residual`` its largest
    relative misfit there; outside the fit range the law follows its exact limits (x -> 0 and x = 1).
    """

    A: float
    B: float
    C: float
    E: float
    fit_range: tuple = (0.001, 0.97)
    max_rel_residual: float = float("nan")
    name: str = "full-range"
    source: str = field(default="", compare=False)

    @property
    def parameters(self) -> dict:
        return {p: getattr(self, p) for p in PARAMETERS}

    def segment_correction(self, a_over_r):
        """``P(x)``: sphere-segment resistance over the half-space disk value ``1/(4 kappa a)``; P(0)=1, P(1)=0."""
        x = check_neck_ratio(a_over_r)
        s = np.sqrt(1.0 - x * x)
        x_log = -x * np.log(np.where(x > 0.0, x, 1.0))
        p = (1.0 + self.A * x_log + self.B * x + self.C * x**2 + self.E * x**3
             - (1.0 + self.B + self.C + self.E) * (x * x / (1.0 + s)))
        return _out(p)

    def k_over_kcyl(self, a_over_r):
        """``K/K_cyl = x / (x lambda(x) + (pi/4) P(x))``; vectorised, 0 at x = 0, 3/2 at x = 1."""
        x = check_neck_ratio(a_over_r)
        return _out(x / (x * neck_resistance(x) + 0.25 * np.pi * self.segment_correction(x)))

    def table(self, n: int = 200) -> list:
        """``n`` rows ``[a_over_r, K_over_Kcyl]``, log-spaced below 0.01 and uniform above, over the fit range."""
        lo, hi = self.fit_range
        n_log = max(2, n // 5)
        x = np.concatenate([np.geomspace(lo, min(0.01, hi), n_log, endpoint=False),
                            np.linspace(min(0.01, hi), hi, n - n_log)])
        return [[float(a), float(k)] for a, k in zip(x, np.atleast_1d(self.k_over_kcyl(x)))]

    def to_dict(self) -> dict:
        """The ``law`` entry of fit.json (without the table, which the fit adds)."""
        return {"form": FORM, "parameters": self.parameters, "range": list(self.fit_range),
                "max_rel_residual": self.max_rel_residual}

    @classmethod
    def from_dict(cls, law: dict, source: str = "") -> "ConductanceLaw":
        try:
            params = {p: float(law["parameters"][p]) for p in PARAMETERS}
        except (KeyError, TypeError) as exc:
            raise ValueError(f"law = {law!r}: must hold 'parameters' {PARAMETERS} of the form {FORM!r}") from exc
        return cls(**params, fit_range=tuple(law.get("range", (0.001, 0.97))),
                   max_rel_residual=float(law.get("max_rel_residual", float("nan"))), source=source)

    @classmethod
    def from_json(cls, path) -> "ConductanceLaw":
        """The law in a fit.json written by ``python -m fem_neck fit`` (its ``law`` entry)."""
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
        try:
            return cls.from_dict(data["law"], source=str(path))
        except ValueError as exc:
            raise ValueError(f"fit file = {str(path)!r}: {exc}") from None

    @classmethod
    def default(cls) -> "ConductanceLaw":
        """The fit shipped with the package (``fem_neck/data/fit.json``), read once."""
        return _default_law()


@functools.lru_cache(maxsize=1)
def _default_law() -> ConductanceLaw:
    return ConductanceLaw.from_json(DEFAULT_FIT)


def _positive(name, value):
    v = np.asarray(value, dtype=float)
    if np.any(~np.isfinite(v) | (v <= 0.0)):
        raise ValueError(f"{name} = {value!r}: must be finite and > 0")
    return v


def half_conductance(kappa, r, a, law=None):
    """``K_i = kappa pi r f(a/r)`` in W/K: one particle's half of a sintered pair (Rojek 2022, eq. 43 for f linear).

    ``law`` defaults to :meth:`ConductanceLaw.default`. Vectorised over kappa, r and a (``0 <= a <= r``).
    """
    law = ConductanceLaw.default() if law is None else law
    kappa, r = _positive("kappa", kappa), _positive("r", r)
    a = np.asarray(a, dtype=float)
    return _out(kappa * np.pi * r * np.asarray(law.k_over_kcyl(check_neck_ratio(a / r, "a/r"))))


# Unequal pairs (``python -m fem_neck unequal``, FE of r_j/r_i = 1..10, a/r_i = 0.01..0.95): the series of halves
# over-estimates K by up to 1.3 %, by ``c (a/r_min) ln(r_max/r_min)`` to within 0.12 % (c = 0.00540 fitted).
UNEQUAL_C = 0.0054


def unequal_factor(r_i, r_j, a, c: float = UNEQUAL_C):
    """``1 / (1 + c (a/r_min) ln(r_max/r_min))``: the FE correction of the series of halves for unequal radii.

    The halves of :func:`pair_conductance` are solved with an isothermal neck cross-section; in an unequal pair that
    plane is not isothermal, and freeing it lowers K (Dirichlet's principle: the series of halves is an upper
    bound). ``c`` is fitted over 1 <= r_max/r_min <= 10 (``python -m fem_neck unequal``); 1 for equal radii.
    """
    r_i, r_j = _positive("r_i", r_i), _positive("r_j", r_j)
    r_min, r_max = np.minimum(r_i, r_j), np.maximum(r_i, r_j)
    x = check_neck_ratio(np.asarray(a, dtype=float) / r_min, "a/r_min")
    return _out(1.0 / (1.0 + c * x * np.log(r_max / r_min)))


def pair_conductance(kappa, r_i, r_j, a, law=None, unequal: bool = True):
    """``K_ij = K_i K_j / (K_i + K_j)`` with ``K_i = kappa pi r_i f(a/r_i)`` (Rojek 2022, eq. 9); vectorised.

    Each half takes its own ``a/r`` (its own half neck too: the neck length of the volume-conserving model splits
    exactly into the two equal-pair half necks, ``h_n = h_n(r_i, r_i)/2 + h_n(r_j, r_j)/2``). With the linear law
    both halves equal ``c kappa pi a`` (eqs. 43-45). With the full-range law and ``unequal`` (default) the series is
    multiplied by :func:`unequal_factor`; the linear laws are the papers' models and are never corrected.
    """
    law = ConductanceLaw.default() if law is None else law
    k_i = np.asarray(half_conductance(kappa, r_i, a, law))
    k_j = np.asarray(half_conductance(kappa, r_j, a, law))
    total = k_i + k_j
    k = np.divide(k_i * k_j, total, out=np.zeros_like(total), where=total > 0)
    if unequal and isinstance(law, ConductanceLaw):
        k = k * unequal_factor(r_i, r_j, a)
    return _out(k)
