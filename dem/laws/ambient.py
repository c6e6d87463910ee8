r"""Heat sources and boundaries of the particle heat balance (Rojek 2022, eq. 3).

:math:`Q_i = \sum_j Q_{ij}^{cond} + Q_i^{int} + Q_i^{conv} + Q_i^{rad}`. Besides the pipes (``dem.network.heat``) a
particle exchanges heat with

* its internal source :math:`Q_i^{int}` (W, ``Particles.heat``),
* an ambient by convection :math:`Q_i^{conv} = h A_i (T_\infty - T_i)` (:class:`Convection`),
* an ambient by radiation :math:`Q_i^{rad} = \varepsilon \sigma A_i (T_\infty^4 - T_i^4)` in absolute temperature
  (:class:`Radiation`),
* isothermal plane walls it touches (:class:`dem.geometry.walls.Wall` with a temperature; the contact conductance
  comes from the conductance law).

Particles held at a fixed temperature are a mask of :class:`dem.geometry.particles.Particles`. Every term is linear in
``T_i`` except radiation, which the solvers use linearised about the current temperature
(:func:`linear_sink_terms`); a scene without radiation never evaluates :math:`T^4`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from dem.geometry.particles import check_temperature

STEFAN_BOLTZMANN = 5.670374419e-8  # W/(m^2 K^4), CODATA 2018 (exact)
KELVIN_OFFSET = {"K": 0.0, "C": 273.15}
RADIATION_T_MAX = 1e4  # K: no solid particle exists above; beyond ~1e5 K the steady Newton on T^4 stalls
HEAT_TRANSFER_MAX = 1e10  # W/(m^2 K), convection coefficient (boiling water is ~1e5)


EXPOSED = "exposed"  # area_fraction: the exposed fraction of each surface (dem.geometry.exposure), computed from the packing


def _area(name: str, fraction, radius: np.ndarray) -> np.ndarray:
    if isinstance(fraction, str):
        raise ValueError(f"{name}.area_fraction = {fraction!r}: resolve {EXPOSED!r} against the packing first "
                         f"(Sources.resolved)")
    try:
        frac = np.broadcast_to(np.asarray(fraction, dtype=float), radius.shape)
    except (TypeError, ValueError):
        frac = np.full(radius.shape, np.nan)
    if not np.all(np.isfinite(frac)) or np.any((frac < 0) | (frac > 1)):
        raise ValueError(f"{name}.area_fraction = {fraction!r}: must be \"{EXPOSED}\" or in [0, 1] (scalar or one "
                         f"per particle)")
    return frac * 4.0 * np.pi * radius**2


@dataclass(frozen=True)
class Convection:
    r""":math:`Q_i^{conv} = h A_i (T_\infty - T_i)` with :math:`A_i = f \, 4 \pi r_i^2` (``area_fraction`` f): by
    default the exposed part of each surface (``"exposed"``, :mod:`dem.geometry.exposure`); ``area_fraction = 1`` opts
    in to the whole surface.

    Parameters
    ----------
    h : float
        Heat transfer coefficient (W/(m^2 K)), in ``[0, HEAT_TRANSFER_MAX]``.
    T_inf : float
        Ambient temperature (the scene's unit, K or degC).
    area_fraction : str or float or array_like
        The fraction of each particle's surface :math:`4 \pi r^2` exposed, in ``[0, 1]`` (a number or one per particle),
        or ``"exposed"`` (computed from the packing, :meth:`Sources.resolved`).

    Raises
    ------
    ValueError
        A field is out of its range; the message names it (``convection.<field>``).
    """

    h: float
    T_inf: float
    area_fraction: object = EXPOSED

    def __post_init__(self):
        _check_fraction("convection", self.area_fraction)
        if not (np.isfinite(self.h) and 0 <= self.h <= HEAT_TRANSFER_MAX):
            raise ValueError(f"convection.h = {self.h!r}: must be in [0, {HEAT_TRANSFER_MAX:g}] (W/(m^2 K))")
        check_temperature("convection.T_inf", self.T_inf)

    def coefficient(self, radius: np.ndarray) -> np.ndarray:
        """``h A_i`` in W/K.

        Parameters
        ----------
        radius : numpy.ndarray
            (N,) particle radii (m).

        Returns
        -------
        numpy.ndarray
            (N,) ``h A_i`` (W/K).

        Raises
        ------
        ValueError
            The area fraction is still ``"exposed"`` (not resolved) or out of ``[0, 1]``.
        """
        return self.h * _area("convection", self.area_fraction, radius)


@dataclass(frozen=True)
class Radiation:
    r""":math:`Q_i^{rad} = \varepsilon \sigma A_i (T_\infty^4 - T_i^4)`; temperatures in ``unit`` ("K" or "C",
    required), :math:`T^4` in kelvin.

    Parameters
    ----------
    emissivity : float
        Emissivity :math:`\varepsilon` of the particles' surfaces, in ``[0, 1]``.
    T_inf : float
        Ambient temperature (in ``unit``), between absolute zero and ``RADIATION_T_MAX``.
    area_fraction : str or float or array_like
        The fraction of each particle's surface :math:`4 \pi r^2` exposed, in ``[0, 1]`` (a number or one per particle),
        or ``"exposed"`` (computed from the packing, :meth:`Sources.resolved`).
    unit : str
        The unit of the scene's temperatures, ``"K"`` or ``"C"`` (required).

    Raises
    ------
    ValueError
        A field is missing or out of its range; the message names it (``radiation.<field>``).
    """

    emissivity: float
    T_inf: float
    area_fraction: object = EXPOSED
    unit: str | None = None

    def __post_init__(self):
        _check_fraction("radiation", self.area_fraction)
        if not (np.isfinite(self.emissivity) and 0 <= self.emissivity <= 1):
            raise ValueError(f"radiation.emissivity = {self.emissivity!r}: must be in [0, 1]")
        if self.unit is None:
            raise ValueError("radiation.unit: required: \"K\" or \"C\", the unit of the scene's temperatures (T^4 is "
                             "taken in kelvin, so 20 C and 20 K radiate very differently)")
        if not isinstance(self.unit, str) or self.unit not in KELVIN_OFFSET:
            raise ValueError(f"radiation.unit = {self.unit!r}: must be one of {', '.join(KELVIN_OFFSET)}")
        if not (np.isfinite(self.T_inf) and 0 <= self.T_inf + KELVIN_OFFSET[self.unit] <= RADIATION_T_MAX):
            raise ValueError(f"radiation.T_inf = {self.T_inf!r}: must be finite and in "
                             f"[{0.0 - KELVIN_OFFSET[self.unit]:g}, {RADIATION_T_MAX - KELVIN_OFFSET[self.unit]:g}] "
                             f"{self.unit} (absolute zero to {RADIATION_T_MAX:g} K)")

    def kelvin(self, T):
        """Temperatures in kelvin.

        Parameters
        ----------
        T : float or array_like
            Temperatures in :attr:`unit`.

        Returns
        -------
        numpy.ndarray
            The same temperatures in K.
        """
        return np.asarray(T, dtype=float) + KELVIN_OFFSET[self.unit]

    def coefficient(self, radius: np.ndarray) -> np.ndarray:
        r""":math:`\varepsilon \sigma A_i` in W/K^4.

        Parameters
        ----------
        radius : numpy.ndarray
            (N,) particle radii (m).

        Returns
        -------
        numpy.ndarray
            (N,) :math:`\varepsilon \sigma A_i` (W/K^4).

        Raises
        ------
        ValueError
            The area fraction is still ``"exposed"`` (not resolved) or out of ``[0, 1]``.
        """
        return self.emissivity * STEFAN_BOLTZMANN * _area("radiation", self.area_fraction, radius)


def _check_fraction(name: str, fraction) -> None:
    if isinstance(fraction, str) and fraction != EXPOSED:
        raise ValueError(f"{name}.area_fraction = {fraction!r}: must be \"{EXPOSED}\" (the default) or a number "
                         f"in [0, 1] (1: the whole surface)")


@dataclass(frozen=True)
class Sources:
    """The ambient exchanges of a scene; ``None`` means the term is absent (and never evaluated).

    Parameters
    ----------
    convection : Convection or None
        Convection to an ambient; None: none.
    radiation : Radiation or None
        Radiation to an ambient; None: none.
    """

    convection: Convection | None = None
    radiation: Radiation | None = None

    def resolved(self, position: np.ndarray, radius: np.ndarray, keep: np.ndarray) -> "Sources":
        """The same exchanges with every ``"exposed"`` area fraction replaced by the fractions of the particles
        ``keep`` (indices) computed from the packing (:func:`dem.geometry.exposure.exposed_fraction`, once for both).

        Parameters
        ----------
        position : numpy.ndarray
            (N, 3) centres of the whole packing (m).
        radius : numpy.ndarray
            (N,) radii of the whole packing (m).
        keep : numpy.ndarray
            Indices of the particles the exchanges apply to (the free ones, say).

        Returns
        -------
        Sources
            The exchanges with numeric area fractions (itself where none was ``"exposed"``).
        """
        if not any(s is not None and isinstance(s.area_fraction, str) for s in (self.convection, self.radiation)):
            return self
        from dem.geometry.exposure import exposed_fraction

        fraction = exposed_fraction(position, radius)[keep]
        swap = {k: replace(s, area_fraction=fraction) for k, s in (("convection", self.convection),
                                                                    ("radiation", self.radiation))
                if s is not None and isinstance(s.area_fraction, str)}
        return replace(self, **swap)

    @property
    def names(self) -> list[str]:
        """The sources given (``convection``, ``radiation``), in that order."""
        return [k for k in ("convection", "radiation") if getattr(self, k) is not None]


def linear_sink_terms(sources: Sources, radius: np.ndarray, T_lin: np.ndarray | None) -> dict:
    r"""Ambient exchange as :math:`Q_i = b_i - g_i T_i` (W): ``{name: (g, b)}`` for each term the scene has.

    Convection is linear: :math:`g = h A`, :math:`b = h A T_\infty`. Radiation is linearised about ``T_lin``
    (:math:`T_0`, a Newton step of :math:`T^4`): :math:`T^4 \approx 4 T_0^3 T - 3 T_0^4` in kelvin, so
    :math:`g = 4 \varepsilon \sigma A T_0^3 \ge 0` keeps the system matrix symmetric positive definite and the implicit
    integrators unconditionally stable.

    Parameters
    ----------
    sources : Sources
        The exchanges, with resolved area fractions.
    radius : numpy.ndarray
        (N,) particle radii (m).
    T_lin : numpy.ndarray or None
        (N,) the temperatures radiation is linearised about (the scene's unit); read only with radiation.

    Returns
    -------
    dict
        ``{name: (g, b)}``: ``g`` (N,) in W/K and ``b`` (N,) in W, for ``"convection"`` and ``"radiation"`` where
        present.
    """
    terms = {}
    if sources.convection is not None:
        g = sources.convection.coefficient(radius)
        terms["convection"] = (g, g * sources.convection.T_inf)
    if sources.radiation is not None:
        rad = sources.radiation
        coef = rad.coefficient(radius)
        t0 = np.maximum(rad.kelvin(T_lin), 0.0)
        g = 4.0 * coef * t0**3
        terms["radiation"] = (g, coef * (rad.kelvin(rad.T_inf) ** 4 + 3.0 * t0**4) - g * rad.kelvin(0.0))
    return terms
