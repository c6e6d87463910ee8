r"""The Hertz-Mindlin contact of elastic spheres: Hertz's normal force with a viscoelastic damping that gives a chosen
coefficient of restitution, Mindlin's tangential stiffness and Coulomb sliding -- the contact law of most DEM codes
for dry, cohesionless grains: its material, the parameter block its sub-models read and its scene keys. The law is the
composition (:data:`dem.laws.contact.CONTACT_LAWS`) of :mod:`dem.laws.contact.normal.hertz`,
:mod:`dem.laws.contact.damping.tsuji`, :mod:`dem.laws.contact.tangential.mindlin` and
:mod:`dem.laws.contact.state.mass`.

Conventions as in every contact law here: :math:`n` points from j to i, the overlap :math:`\delta = a_i + a_j - |x_i
- x_j|` is positive in contact, the forces are those on i. Two spheres of radii :math:`a_i`, :math:`a_j` and masses
:math:`m_i`, :math:`m_j` of one material (Young's modulus E, Poisson's ratio :math:`\nu`) touch with :math:`R^* = a_i
a_j/(a_i + a_j)`, :math:`m^* = m_i m_j/(m_i + m_j)`, :math:`1/E^* = 2 (1 - \nu^2)/E` and :math:`1/G^* = 2 (2 -
\nu)/G`, :math:`G = E/(2 (1 + \nu))`. A wall is a partner of infinite radius and mass made of the same material:
:math:`R^* = a_k`, :math:`m^* = m_k`, the same :math:`E^*` and :math:`G^*` (as LAMMPS's ``fix wall/gran`` takes a
wall).

* **Normal** (Hertz 1882; Johnson, Contact Mechanics, 1985, Sec. 4.2): the contact radius :math:`a = \sqrt{R^*
  \delta}` and :math:`F_{el} = \frac{4}{3} E^* a \delta = \frac{4}{3} E^* \sqrt{R^*} \delta^{3/2}`.
* **Damping** (Tsuji, Tanaka & Ishida 1992, Powder Technol. 71, 239): :math:`F_d = \eta_n\, d\delta/dt` with
  :math:`\eta_n = \alpha \sqrt{m^* k_n}`, :math:`k_n = F_{el}/\delta = \frac{4}{3} E^* a`: the damping grows as
  :math:`\delta^{1/4}`, so the coefficient of restitution of a head-on collision does not depend on the impact
  speed. Antypov & Elliott 2011 (EPL 94, 50004) solved that collision exactly: :math:`e = \exp(-\pi b/\sqrt{1 -
  b^2})`, :math:`b = \alpha/\sqrt{5}`, i.e. :math:`\alpha = \sqrt{5}\,(-\ln e)/\sqrt{\pi^2 + \ln^2 e}`
  (:func:`dem.laws.contact.damping.tsuji.damping_coefficient`): the material takes ``e`` itself. (This is the damping
  of LAMMPS's ``damping coeff_restitution`` and of EDEM's Hertz-Mindlin, :math:`2 \sqrt{5/6}\, \beta \sqrt{m^*
  S_n}` with :math:`S_n = 2 E^* a`.) The normal force :math:`F_n = F_{el} + F_d` is not cut at zero: at the end of a
  damped contact it pulls briefly, as in Tsuji's model and in LAMMPS.
* **Tangential** (Mindlin 1949; Mindlin & Deresiewicz 1953, J. Appl. Mech. 20, 327; the "no-slip" form of Di Renzo
  & Di Maio 2004): a spring :math:`\xi` (the tangential displacement of the contact) of stiffness :math:`k_t = 8 G^*
  a`, turned into the current tangent plane keeping its length, advanced by the tangential surface velocity
  :math:`v_t\, dt`; the force :math:`F_t = -k_t \xi - \eta_t v_t` with :math:`\eta_t` the ``tangential_damping``
  times :math:`\eta_n` (LAMMPS's ``x_gamma,t``). Coulomb: where :math:`|F_t| > \mu F_n` (``mu_wall`` at a wall; no
  friction while :math:`F_n` pulls) the contact slides, :math:`F_t` is scaled to :math:`\mu F_n` and the spring set to
  what gives that force, :math:`\xi = -(F_t + \eta_t v_t)/k_t` (as LAMMPS's ``tangential mindlin``).

The time step (:func:`dem.laws.contact.normal.hertz.time_steps`): ``dt = "auto"`` is a tenth of the Rayleigh time
:math:`T_R = \pi a \sqrt{\rho/G}/(0.1631 \nu + 0.8766)` of the smallest particle (the time a Rayleigh wave takes
across it; LIGGGHTS's ``check/timestep/gran`` warns above fractions of it); a Hertz contact of an impact speed of 1 m/s
lasts several :math:`T_R`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from dem.laws.contact import law_module
from dem.laws.fields import check_fields

_POSITIVE = {"youngs_modulus": "Pa", "restitution": "", "density": "kg/m^3"}
_NONNEGATIVE = {"tangential_damping": "", "mu": "", "mu_wall": ""}


@dataclass(frozen=True)
class HertzMindlinMaterial:
    r"""Material of the Hertz-Mindlin contact (SI units; module docstring): ``youngs_modulus`` E and
    ``poisson_ratio`` :math:`\nu` of the particles (and of the walls); ``restitution``, the coefficient of restitution
    e of a head-on collision (:math:`0 < e \le 1`; 1: no damping); ``tangential_damping`` :math:`\eta_t/\eta_n`;
    ``mu``, ``mu_wall`` the
    friction coefficients between particles and with a wall; ``density``.

    Parameters
    ----------
    youngs_modulus : float
        Young's modulus E of the particles and walls (Pa), > 0.
    poisson_ratio : float
        Poisson's ratio :math:`\nu`, in ``(-1, 0.5)``.
    restitution : float
        Coefficient of restitution e of a head-on collision, in ``(0, 1]`` (1: no damping).
    tangential_damping : float
        :math:`\eta_t/\eta_n`, the tangential over the normal damping coefficient, >= 0.
    mu : float
        Particle-particle friction coefficient, >= 0.
    mu_wall : float
        Particle-wall friction coefficient, >= 0.
    density : float
        Particle density (kg/m^3), > 0.

    Raises
    ------
    ValueError
        A field is out of its range; the message names it (``contact.<field>``).
    """

    youngs_modulus: float
    poisson_ratio: float
    restitution: float
    tangential_damping: float
    mu: float
    mu_wall: float
    density: float

    law = "hertz_mindlin"

    def __post_init__(self):
        check_fields(self, "contact", _POSITIVE, _NONNEGATIVE)
        check_poisson_ratio(self)
        check_restitution(self)

    @property
    def effective_modulus(self) -> float:
        r""":math:`E^*` of two particles of the material (and of a particle on a wall), :math:`E/(2 (1 - \nu^2))`,
        Pa."""
        return effective_modulus(self)

    @property
    def shear_modulus(self) -> float:
        r""":math:`G = E/(2 (1 + \nu))`, Pa."""
        return shear_modulus(self)

    @property
    def effective_shear_modulus(self) -> float:
        r""":math:`G^*` of two particles of the material, :math:`G/(2 (2 - \nu))`, Pa."""
        return effective_shear_modulus(self)

    def params(self) -> np.ndarray:
        """The material as the float64 array the compiled loops take: its law's blocks
        (:meth:`dem.laws.contact.composition.Law.params`)."""
        return law_module(self.law).params(self)

    def rayleigh_time(self, radius: float) -> float:
        r""":math:`T_R = \pi a \sqrt{\rho/G}/(0.1631 \nu + 0.8766)` of a particle of radius ``a`` (s).

        Parameters
        ----------
        radius : float
            The particle's radius a (m).

        Returns
        -------
        float
            The Rayleigh time (s).
        """
        return rayleigh_time(self, radius)


def check_poisson_ratio(material) -> None:
    r"""Poisson's ratio of an isotropic elastic solid, :math:`-1 < \nu < 0.5`.

    Parameters
    ----------
    material : object
        A material with the field ``poisson_ratio``.

    Raises
    ------
    ValueError
        ``poisson_ratio`` is out of its range.
    """
    if not -1.0 < material.poisson_ratio < 0.5:
        raise ValueError(f"contact.poisson_ratio = {material.poisson_ratio!r}: must be in (-1, 0.5) (an isotropic "
                         f"elastic solid)")


def check_restitution(material) -> None:
    """The coefficient of restitution of a head-on collision, ``0 < e <= 1``.

    Parameters
    ----------
    material : object
        A material with the field ``restitution``.

    Raises
    ------
    ValueError
        ``restitution`` is out of its range.
    """
    if not 0.0 < material.restitution <= 1.0:
        raise ValueError(f"contact.restitution = {material.restitution!r}: must be in (0, 1] (the coefficient of "
                         f"restitution of a head-on collision; 1: elastic)")


def effective_modulus(material) -> float:
    r""":math:`E^*` of two particles of a material with ``youngs_modulus`` E and ``poisson_ratio`` :math:`\nu` (and of
    a particle on a wall of it), :math:`E/(2 (1 - \nu^2))`, Pa.

    Parameters
    ----------
    material : object
        A material with the fields ``youngs_modulus`` (Pa) and ``poisson_ratio``.

    Returns
    -------
    float
        E* (Pa).
    """
    return material.youngs_modulus / (2.0 * (1.0 - material.poisson_ratio**2))


def shear_modulus(material) -> float:
    r""":math:`G = E/(2 (1 + \nu))` of a material with ``youngs_modulus`` E and ``poisson_ratio`` :math:`\nu`, Pa.

    Parameters
    ----------
    material : object
        A material with the fields ``youngs_modulus`` (Pa) and ``poisson_ratio``.

    Returns
    -------
    float
        G (Pa).
    """
    return material.youngs_modulus / (2.0 * (1.0 + material.poisson_ratio))


def effective_shear_modulus(material) -> float:
    r""":math:`G^*` of two particles of a material with ``youngs_modulus`` E and ``poisson_ratio`` :math:`\nu`,
    :math:`G/(2 (2 - \nu))`, Pa.

    Parameters
    ----------
    material : object
        A material with the fields ``youngs_modulus`` (Pa) and ``poisson_ratio``.

    Returns
    -------
    float
        G* (Pa).
    """
    return shear_modulus(material) / (2.0 * (2.0 - material.poisson_ratio))


def rayleigh_time(material, radius: float) -> float:
    r""":math:`T_R = \pi a \sqrt{\rho/G}/(0.1631 \nu + 0.8766)` of a particle of radius ``a`` (s).

    Parameters
    ----------
    material : object
        A material with the fields ``youngs_modulus`` (Pa), ``poisson_ratio`` and ``density`` (kg/m^3).
    radius : float
        The particle's radius a (m).

    Returns
    -------
    float
        The Rayleigh time (s).
    """
    return (math.pi * radius * math.sqrt(material.density / shear_modulus(material))
            / (0.1631 * material.poisson_ratio + 0.8766))


Material = HertzMindlinMaterial
SCHEMA_ROWS = (  # the scene keys of the material (dem.scene.schema): keys, type and unit, meaning
    (("youngs_modulus", "poisson_ratio"), "Pa, -; required, E > 0, -1 < ν < 0.5",
     "E and ν of the particles and the walls: Hertz's F = 4/3 E* √R* δ^(3/2), E* = E/(2(1 - ν²)) (Johnson 1985, "
     "Sec. 4.2); Mindlin's tangential stiffness 8 G* a, G* = G/(2(2 - ν))"),
    (("restitution",), "0 < e ≤ 1, required", "the coefficient of restitution of a head-on collision, at every "
     "impact speed: Tsuji's damping η_n = α √(m* k_n) with α from e (Antypov & Elliott 2011)"),
    (("tangential_damping",), "≥ 0, required", "η_t/η_n, the damping of the tangential spring"),
    (("mu", "mu_wall"), "≥ 0, required", "particle-particle and particle-wall Coulomb friction, ‖F_t‖ ≤ μ F_n"),
    (("density",), "kg/m³, the `[material]` density", "particle density"),
)
