"""The Hertz-Mindlin contact of elastic spheres: Hertz's normal force with a viscoelastic damping that gives a chosen
coefficient of restitution, Mindlin's tangential stiffness and Coulomb sliding -- the contact law of most DEM codes
for dry, cohesionless grains, as a plug-in of the engines' compiled loops (:mod:`dem.laws.contact`).

Conventions as in every contact law here: ``n`` points from j to i, the overlap ``delta = a_i + a_j - |x_i - x_j|``
is positive in contact, the forces are those on i. Two spheres of radii a_i, a_j and masses m_i, m_j of one material
(Young's modulus E, Poisson's ratio nu) touch with ``R* = a_i a_j/(a_i + a_j)``, ``m* = m_i m_j/(m_i + m_j)``,
``1/E* = 2 (1 - nu^2)/E`` and ``1/G* = 2 (2 - nu)/G``, ``G = E/(2 (1 + nu))``. A wall is a partner of infinite
radius and mass made of the same material: ``R* = a_k``, ``m* = m_k``, the same E* and G* (as LAMMPS's ``fix
wall/gran`` takes a wall).

* **Normal** (Hertz 1882; Johnson, Contact Mechanics, 1985, Sec. 4.2): the contact radius ``a = sqrt(R*
  delta)`` and ``F_el = 4/3 E* a delta = 4/3 E* sqrt(R*) delta^(3/2)``.
* **Damping** (Tsuji, Tanaka & Ishida 1992, Powder Technol. 71, 239): ``F_d = eta_n d(delta)/dt`` with
  ``eta_n = alpha sqrt(m* k_n)``, ``k_n = F_el/delta = 4/3 E* a``: the damping grows as ``delta^(1/4)``, so the
  coefficient of restitution of a head-on collision does not depend on the impact speed. Antypov & Elliott 2011
  (EPL 94, 50004) solved that collision exactly: ``e = exp(-pi b / sqrt(1 - b^2))``, ``b = alpha/sqrt(5)``, i.e.
  ``alpha = sqrt(5) (-ln e)/sqrt(pi^2 + ln^2 e)`` (:func:`dem.laws.contact.damping.tsuji.damping_coefficient`): the material takes ``e`` itself.
  (This is the damping of LAMMPS's ``damping coeff_restitution`` and of EDEM's Hertz-Mindlin, ``2 sqrt(5/6) beta
  sqrt(m* S_n)`` with ``S_n = 2 E* a``.) The normal force ``F_n = F_el + F_d`` is not cut at zero: at the end of a
  damped contact it pulls briefly, as in Tsuji's model and in LAMMPS.
* **Tangential** (Mindlin 1949; Mindlin & Deresiewicz 1953, J. Appl. Mech. 20, 327; the "no-slip" form of Di Renzo
  & Di Maio 2004): a spring ``xi`` (the tangential displacement of the contact) of stiffness ``k_t = 8 G* a``, turned
  into the current tangent plane keeping its length, advanced by the tangential surface velocity ``v_t dt``; the
  force ``F_t = -k_t xi - eta_t v_t`` with ``eta_t = tangential_damping * eta_n`` (LAMMPS's ``x_gamma,t``). Coulomb:
  where ``|F_t| > mu F_n`` (``mu_wall`` at a wall; no friction while F_n pulls) the contact slides, ``F_t`` is
  scaled to ``mu F_n`` and the spring set to what gives that force, ``xi = -(F_t + eta_t v_t)/k_t`` (as LAMMPS's
  ``tangential mindlin``).

The time step (:func:`time_steps`): ``dt = "auto"`` is a tenth of the Rayleigh time ``T_R = pi a sqrt(rho/G)/(0.1631
nu + 0.8766)`` of the smallest particle (the time a Rayleigh wave takes across it; LIGGGHTS's ``check/timestep/gran``
warns above fractions of it); a Hertz contact of an impact speed of 1 m/s lasts several T_R.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from dem.laws.contact.damping import tsuji
from dem.laws.contact.normal import hertz
from dem.laws.contact.tangential import mindlin
from dem.laws.fields import check_fields

# Indices into HertzMindlinMaterial.params() (the JKR law extends the list: dem.laws.contact.jkr)
P_KN = 0            # 4/3 E*: F_el = P_KN a delta (Pa)
P_KT = 1            # 8 G*: k_t = P_KT a (Pa)
P_ALPHA = 2         # alpha of eta_n = alpha sqrt(m* k_n), from the restitution coefficient
P_XT = 3            # eta_t / eta_n
P_MU = 4            # particle-particle friction coefficient
P_MU_WALL = 5       # particle-wall friction coefficient
P_DENSITY = 6       # particle density (kg/m^3)
N_PARAMS = 7

RAYLEIGH_FRACTION = 0.1  # dt = "auto": this fraction of the Rayleigh time
STABLE_OVERLAP = 0.1     # the stable step is that of an overlap of this fraction of R* (module docstring)

_POSITIVE = {"youngs_modulus": "Pa", "restitution": "", "density": "kg/m^3"}
_NONNEGATIVE = {"tangential_damping": "", "mu": "", "mu_wall": ""}


@dataclass(frozen=True)
class HertzMindlinMaterial:
    """Material of the Hertz-Mindlin contact (SI units; module docstring): ``youngs_modulus`` E and
    ``poisson_ratio`` nu of the particles (and of the walls); ``restitution``, the coefficient of restitution e of a
    head-on collision (0 < e <= 1; 1: no damping); ``tangential_damping`` eta_t/eta_n; ``mu``, ``mu_wall`` the
    friction coefficients between particles and with a wall; ``density``.

    Parameters
    ----------
    youngs_modulus : float
        Young's modulus E of the particles and walls (Pa), > 0.
    poisson_ratio : float
        Poisson's ratio nu, in ``(-1, 0.5)``.
    restitution : float
        Coefficient of restitution e of a head-on collision, in ``(0, 1]`` (1: no damping).
    tangential_damping : float
        eta_t / eta_n, the tangential over the normal damping coefficient, >= 0.
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
        if not -1.0 < self.poisson_ratio < 0.5:
            raise ValueError(f"contact.poisson_ratio = {self.poisson_ratio!r}: must be in (-1, 0.5) (an isotropic "
                             f"elastic solid)")
        if not self.restitution <= 1.0:
            raise ValueError(f"contact.restitution = {self.restitution!r}: must be in (0, 1] (the coefficient of "
                             f"restitution of a head-on collision; 1: elastic)")

    @property
    def effective_modulus(self) -> float:
        """E* of two particles of the material (and of a particle on a wall), ``E/(2 (1 - nu^2))``, Pa."""
        return self.youngs_modulus / (2.0 * (1.0 - self.poisson_ratio**2))

    @property
    def shear_modulus(self) -> float:
        """G = E/(2 (1 + nu)), Pa."""
        return self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))

    @property
    def effective_shear_modulus(self) -> float:
        """G* of two particles of the material, ``G/(2 (2 - nu))``, Pa."""
        return self.shear_modulus / (2.0 * (2.0 - self.poisson_ratio))

    def params(self) -> np.ndarray:
        """The material as the float64 array the kernels take (indices ``P_*`` of this module)."""
        out = np.empty(N_PARAMS)
        out[P_KN] = 4.0 / 3.0 * self.effective_modulus
        out[P_KT] = 8.0 * self.effective_shear_modulus
        out[P_ALPHA] = tsuji.damping_coefficient(self.restitution)
        out[P_XT], out[P_MU], out[P_MU_WALL] = self.tangential_damping, self.mu, self.mu_wall
        out[P_DENSITY] = self.density
        return out

    def rayleigh_time(self, radius: float) -> float:
        """``T_R = pi a sqrt(rho/G)/(0.1631 nu + 0.8766)`` of a particle of radius ``a`` (s).

        Parameters
        ----------
        radius : float
            The particle's radius a (m).

        Returns
        -------
        float
            The Rayleigh time (s).
        """
        return (math.pi * radius * math.sqrt(self.density / self.shear_modulus)
                / (0.1631 * self.poisson_ratio + 0.8766))


def time_steps(material: HertzMindlinMaterial, mass: np.ndarray, inertia: np.ndarray, radius: np.ndarray,
               m_mean: float) -> tuple[float, float]:
    """``(dt, stable)``: ``dt = "auto"`` is ``RAYLEIGH_FRACTION`` of the Rayleigh time of the smallest particle
    (module docstring). Hertz's stiffness ``k = dF/d delta = 2 E* a`` grows with the overlap, so no step is stable at
    every overlap: ``stable`` is the largest velocity-Verlet step, ``2/(omega + eta_n/(2 m*))``, for the lightest
    pair at an overlap of ``STABLE_OVERLAP`` R* (beyond the small strains Hertz's law is for), with its
    stiffest mode: normal, ``2 E* a``, or tangential with rotation, ``8 G* a (1 + m a^2/I)``.

    Parameters
    ----------
    material : HertzMindlinMaterial
        The contact material.
    mass : numpy.ndarray
        (N,) masses (kg).
    inertia : numpy.ndarray
        (N,) moments of inertia (kg m^2).
    radius : numpy.ndarray
        (N,) radii (m).
    m_mean : float
        The mass of a particle of the mean radius (kg; not read by this law).

    Returns
    -------
    tuple of (float, float)
        The step ``dt = "auto"`` takes (at most ``stable``) and ``stable`` (s).
    """
    order = np.argsort(mass)
    lo, hi = order[0], order[1] if len(mass) > 1 else order[0]
    m_eff = mass[lo] * mass[hi] / (mass[lo] + mass[hi]) if len(mass) > 1 else float(mass[lo])
    r_eff = radius[lo] * radius[hi] / (radius[lo] + radius[hi]) if len(mass) > 1 else float(radius[lo])
    a = r_eff * math.sqrt(STABLE_OVERLAP)
    rotational = 1.0 + float(np.max(mass * radius**2 / inertia))
    k_max = max(2.0 * material.effective_modulus * a, 8.0 * material.effective_shear_modulus * a * rotational)
    eta = tsuji.damping_coefficient(material.restitution) * math.sqrt(m_eff * 4.0 / 3.0 * material.effective_modulus * a)
    stable = 2.0 / (math.sqrt(k_max / m_eff) + eta / (2.0 * m_eff))
    return min(RAYLEIGH_FRACTION * material.rayleigh_time(float(np.min(radius))), stable), stable


JIT = {"cache": True, "error_model": "numpy"}
IN_LOOP = {**JIT, "inline": "always"}  # the kernels of the force loop, inlined there by numba


@njit(**IN_LOOP)
def hertz_force(delta, delta_dot, r_eff, m_eff, params):
    """Hertz's force with its damping: ``(F_n, a, eta_n)`` -- ``F_n = 4/3 E* a delta + eta_n d(delta)/dt``, the
    contact radius ``a = sqrt(R* delta)`` (:func:`dem.laws.contact.normal.hertz.stiffness`) and ``eta_n = alpha
    sqrt(m* 4/3 E* a)`` (:func:`dem.laws.contact.damping.tsuji.viscosity`) for the overlap ``delta > 0`` and its rate
    ``delta_dot`` (> 0 approaching)."""
    k_n, a = hertz.stiffness(delta, r_eff, params[P_KN])
    eta = tsuji.viscosity(params[P_ALPHA], m_eff, k_n)
    return k_n * delta + eta * delta_dot, a, eta


# ------------------------------------------------------------------------------------------ the plug-in
# What the engines' compiled loops call (:mod:`dem.laws.contact` lists the names every contact law defines).
NAME = "hertz_mindlin"
Material = HertzMindlinMaterial
PAIR_HISTORY = ("xi_x", "xi_y", "xi_z")  # the tangential spring
WALL_HISTORY = PAIR_HISTORY
PARTICLE_STATE = ("mass",)  # each particle's mass (kg): the damping needs m*
PAIR_CONSTANTS = ()  # (pair_constants)
SPINS = True
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
DRAG = False


def initial_state(material, T: np.ndarray, mass: np.ndarray) -> np.ndarray:
    """Each particle's mass, the state the kernels read m* from.

    Parameters
    ----------
    material : HertzMindlinMaterial
        The contact material (not read by this hook).
    T : numpy.ndarray
        (N,) initial temperatures (only their count is read).
    mass : numpy.ndarray
        (N,) masses (kg).

    Returns
    -------
    numpy.ndarray
        (N, 1) the masses (kg).
    """
    return np.array(mass, dtype=float).reshape(len(T), 1)


def reference_radius(material, radius: np.ndarray, T: np.ndarray) -> np.ndarray:
    """The radii do not change with temperature.

    Parameters
    ----------
    material : HertzMindlinMaterial
        The contact material (not read by this hook).
    radius : numpy.ndarray
        (N,) radii (m).
    T : numpy.ndarray
        (N,) temperatures (not read).

    Returns
    -------
    numpy.ndarray
        (N,) a copy of ``radius`` (m).
    """
    return np.array(radius, dtype=float)


def largest_reach(material, radius: np.ndarray) -> float:
    """The law acts on overlapping particles only.

    Parameters
    ----------
    material : HertzMindlinMaterial
        The contact material (not read by this hook).
    radius : numpy.ndarray
        (N,) radii (m; not read).

    Returns
    -------
    float
        0.0: the largest gap (m) across which the law acts.
    """
    return 0.0


@njit(**IN_LOOP)
def pair_force(c, i, j, hist_in, hist, state, T, delta, d, n, vr, vn, ri, rj, planar, dt, params, const):
    """Force on particle i of the pair ``c`` = (i, j) at overlap ``delta`` (module docstring); the spring is read
    from row ``c`` of ``hist_in`` and written to row ``c`` of ``hist``. ``planar``: 2D disks in the x-z plane."""
    mi, mj = state[i, 0], state[j, 0]
    f_n, a, eta = hertz_force(delta, -vn, ri * rj / (ri + rj), mi * mj / (mi + mj), params)
    n0, n1, n2 = n
    ft, xi = mindlin.mindlin_force((hist_in[c, 0], 0.0 if planar else hist_in[c, 1], hist_in[c, 2]), n,
                           (vr[0] - vn * n0, vr[1] - vn * n1, vr[2] - vn * n2), params[P_KT] * a,
                           params[P_XT] * eta, params[P_MU] * max(f_n, 0.0), dt)
    hist[c, 0], hist[c, 1], hist[c, 2] = xi
    return f_n, ft[0], ft[1], ft[2]


@njit(**IN_LOOP)
def pair_constants(ri, rj, params):
    """No numbers of the radii alone are kept per pair (``PAIR_CONSTANTS`` is empty): two zeros."""
    return 0.0, 0.0


@njit(**IN_LOOP)
def forget_pair(c, hist_in, hist):
    """A pair that opened forgets its spring; whether it had one."""
    had = hist_in[c, 0] != 0.0 or hist_in[c, 1] != 0.0 or hist_in[c, 2] != 0.0
    hist[c, 0], hist[c, 1], hist[c, 2] = 0.0, 0.0, 0.0
    return had


@njit(**IN_LOOP)
def wall_force(k, m, hist_in, hist, state, T, delta, dist, n, vr, vn, rk, dt, params):
    """Force on particle k from wall m: the pair law with ``R* = a_k``, ``m* = m_k`` and ``mu_wall``; the spring
    in ``[k, m]``."""
    f_n, a, eta = hertz_force(delta, -vn, rk, state[k, 0], params)
    n0, n1, n2 = n
    ft, xi = mindlin.mindlin_force((hist_in[k, m, 0], hist_in[k, m, 1], hist_in[k, m, 2]), n,
                           (vr[0] - vn * n0, vr[1] - vn * n1, vr[2] - vn * n2), params[P_KT] * a,
                           params[P_XT] * eta, params[P_MU_WALL] * max(f_n, 0.0), dt)
    hist[k, m, 0], hist[k, m, 1], hist[k, m, 2] = xi
    return f_n, ft[0], ft[1], ft[2]


@njit(**IN_LOOP)
def forget_wall(k, m, hist_in, hist):
    """A wall contact that opened forgets its spring; whether it had one."""
    had = hist_in[k, m, 0] != 0.0 or hist_in[k, m, 1] != 0.0 or hist_in[k, m, 2] != 0.0
    hist[k, m, 0], hist[k, m, 1], hist[k, m, 2] = 0.0, 0.0, 0.0
    return had


@njit(**IN_LOOP)
def reach(c, hist, ri, rj, params):
    """The law acts on overlapping pairs only."""
    return 0.0


@njit(**IN_LOOP)
def wall_reach(k, m, hist, rk, params):
    """The law acts on overlapping wall contacts only."""
    return 0.0


@njit(**JIT)
def update_particles(elapsed, T0, T_rate, T, radius, radius_ref, state, uniform, params, t0, dt):
    """The temperatures ``T0 + T_rate elapsed``; the law does not depend on them. Returns that no radius
    changed."""
    n = T.shape[0]
    for k in range(n):
        T[k] = T0[0] + T_rate[0] * elapsed if uniform else T0[k] + T_rate[k] * elapsed
    return False


@njit(**IN_LOOP)
def drag(k, radius, params):
    """No drag."""
    return 0.0
