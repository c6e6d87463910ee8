"""The contact material of Zohdi 2014 (eqs. 2-21 and Sec. 7) and the parameters of its implicit stepping (eqs.
22-30, 45-49).

:class:`ZohdiMaterial` holds the material in SI units, named by the paper's symbols; :meth:`ZohdiMaterial.params`
packs it into the float64 array the compiled kernels take (indices ``Z_*``); the plug-in kernels at the end give the
engines' loops its forces (:mod:`dem.laws.contact`). The adaptive trapezoidal fixed-point scheme the paper steps it with
is the staggered engine's (:mod:`dem.engines.staggered`, its parameters :class:`dem.scene.staggered.ZohdiStepping`).

Conventions (Zohdi 2014, eqs. 3-4): ``n_ij = (r_j - r_i)/|r_j - r_i|`` points from i to j (the engines' ``n`` is the
opposite, from j to i); the strain ``E_ij = (|r_i - r_j| - (R_i + R_j))/(R_i + R_j)`` is negative in contact; the
contact force on i is ``-K_p |E|^p_p A_ij n_ij`` (it pushes i away from j), the bond force ``+K_b |E|^p_b A_ij n_ij``
pulls it back. The particles do not rotate (Sec. 2: "the effects of their rotation ... unimportant").

A wall is the plane ``n_w . x = q_w`` (normal into the packing); its contact force on particle k is ``K_w E^p_w A_k
n_w`` with ``E = (R_k - dist)/R_k`` (eq. 14: the overlap over the radius, as a pair's strain is its overlap over R_i +
R_j) and ``A_k = pi (R_k^2 - dist^2)`` the circle the plane cuts from the sphere (the lens of eqs. 7-12 with the plane
for the second particle).

Friction (eqs. 5-6): ``mu_d |F_con| t`` with ``t = (v_j - v_i)/|v_j - v_i|`` the whole relative velocity, as the
paper writes it (so friction also opposes the approach of two particles, which is what makes their collisions
inelastic: the law has no normal damping). At a wall only the tangential velocity counts (eq. 17). The direction is
regularised, ``t = dv / sqrt(|dv|^2 + v_slip^2)``: a unit vector while sliding faster than ``v_slip``, proportional
to the slip below it, so that the fixed-point map stays continuous where the relative velocity passes through zero.

Bonds (eqs. 18-19): a pair whose strain reaches ``E*`` is bonded from the next step on (the flag is the pair's
history, committed when a step is accepted) and stays bonded while it touches. Within a step the flags are fixed: a
bond switched on between two iterates makes the force jump by ``K_b E*^p_b A``, and the fixed-point iteration then
stalls at the size of that jump instead of converging.

Units (Sec. 7 states them: "K_po = 10^7 N/m^2"): the contact force ``K_p |E|^p_p A_c`` is in newtons with the
contact area ``A_c`` in m^2 and the strain ``E`` dimensionless, so ``K_p``, ``K_w`` and ``K_b`` are in N/m^2 (Pa).
Temperatures are absolute (K): the softening ``K = max(K_0 (1 - theta/theta*), K_lim)`` of Sec. 7 needs theta = 0
to mean absolute zero.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from dem.laws.fields import check_fields

# Indices into ZohdiMaterial.params()
Z_KP = 0           # K_p0, particle-particle contact stiffness, cold (N/m^2, eq. 2)
Z_PP = 1           # p_p, exponent of the particle contact law (eq. 2)
Z_KP_LIM = 2       # K_p^lim, the softened floor (N/m^2, Sec. 7)
Z_KW = 3           # K_w0, particle-wall stiffness, cold (N/m^2, eq. 13)
Z_PW = 4           # p_w (eq. 13)
Z_KW_LIM = 5       # K_w^lim (N/m^2, Sec. 7)
Z_THETA_STAR = 6   # theta*, the softening temperature (K, Sec. 7)
Z_KB = 7           # K_b, bond stiffness (N/m^2, eq. 19)
Z_PB = 8           # p_b (eq. 19)
Z_E_STAR = 9       # E*, the critical interpenetration that activates a bond (eqs. 18-19)
Z_MU = 10          # mu_d, dynamic friction, particles and walls (eqs. 5, 16)
Z_C_ENV = 11       # c_env^o: drag c_env = c_env^o 6 pi R (kg/(m s), eq. 20 and Sec. 7)
Z_V_SLIP = 12      # regularisation speed of the friction direction (m/s)
Z_DENSITY = 13     # particle density (kg/m^3)
N_PARAMS = 14

_POSITIVE = {"K_p": "N/m^2", "p_p": "", "K_w": "N/m^2", "p_w": "", "theta_star": "K", "p_b": "", "v_slip": "m/s",
             "density": "kg/m^3"}
_NONNEGATIVE = {"K_p_lim": "N/m^2", "K_w_lim": "N/m^2", "K_b": "N/m^2", "E_star": "", "mu_d": "", "c_env": "kg/(m s)"}


@dataclass(frozen=True)
class ZohdiMaterial:
    """The contact material of Zohdi 2014 (paper's symbols; SI units; module docstring).

    Normal contact ``K_p |E_ij|^p_p A_ij`` (eqs. 2-12, ``E_ij = (|r_i - r_j| - (R_i + R_j)) / (R_i + R_j)``, the lens
    area ``A_ij = pi (R_i^2 - L_i^2)``); wall contact ``K_w |E_iw|^p_w A_i`` (eqs. 13-15, ``E_iw`` the overlap over
    the radius, ``A_i`` the circle the wall cuts from the sphere); thermal softening ``K = max(K_0 (1 -
    theta/theta*), K_lim)`` (Sec. 7; for a pair, theta is the mean of the two); an adhesive bond ``K_b |E_ij|^p_b
    A_ij`` (eq. 19), activated once ``|E_ij| >= E_star`` and kept while the particles touch; sliding friction
    ``mu_d |F_con|`` against the relative velocity (eqs. 5-6; against the tangential one at a wall, eqs. 16-17),
    its direction regularised below ``v_slip``; drag ``-c_env 6 pi R v`` (eq. 20, Sec. 7); ``density``.

    Parameters
    ----------
    K_p : float
        K_p0, the particle-particle contact stiffness when cold (N/m^2), > 0 (eq. 2).
    p_p : float
        The exponent of the particle contact law, > 0 (eq. 2).
    K_p_lim : float
        K_p^lim, the softened floor of K_p (N/m^2), in ``[0, K_p]`` (Sec. 7).
    K_w : float
        K_w0, the particle-wall contact stiffness when cold (N/m^2), > 0 (eq. 13).
    p_w : float
        The exponent of the wall contact law, > 0 (eq. 13).
    K_w_lim : float
        K_w^lim, the softened floor of K_w (N/m^2), in ``[0, K_w]`` (Sec. 7).
    theta_star : float
        theta*, the softening temperature (K, absolute), > 0 (Sec. 7).
    K_b : float
        The bond stiffness (N/m^2), >= 0 (eq. 19).
    p_b : float
        The exponent of the bond law, > 0 (eq. 19).
    E_star : float
        E*, the strain magnitude that activates a bond, >= 0 (eqs. 18-19).
    mu_d : float
        The dynamic friction coefficient of particles and walls, >= 0 (eqs. 5, 16).
    c_env : float
        c_env^o of the drag ``c_env = c_env^o 6 pi R`` (kg/(m s)), >= 0 (eq. 20, Sec. 7).
    v_slip : float
        The regularisation speed of the friction direction (m/s), > 0.
    density : float
        Particle density (kg/m^3), > 0.

    Raises
    ------
    ValueError
        A field is out of its range, or a floor exceeds its cold stiffness; the message names it.
    """

    K_p: float
    p_p: float
    K_p_lim: float
    K_w: float
    p_w: float
    K_w_lim: float
    theta_star: float
    K_b: float
    p_b: float
    E_star: float
    mu_d: float
    c_env: float
    v_slip: float
    density: float

    law = "zohdi"

    def __post_init__(self):
        check_fields(self, "contact", _POSITIVE, _NONNEGATIVE)
        for cold, floor in (("K_p", "K_p_lim"), ("K_w", "K_w_lim")):
            if getattr(self, floor) > getattr(self, cold):
                raise ValueError(f"contact.{floor} = {getattr(self, floor)!r}: must be <= {cold} = "
                                 f"{getattr(self, cold)!r} N/m^2 (the softened stiffness never exceeds the cold one)")

    def params(self) -> np.ndarray:
        """The material as the float64 array the kernels take (indices ``Z_*`` of this module)."""
        out = np.empty(N_PARAMS)
        out[Z_KP], out[Z_PP], out[Z_KP_LIM] = self.K_p, self.p_p, self.K_p_lim
        out[Z_KW], out[Z_PW], out[Z_KW_LIM] = self.K_w, self.p_w, self.K_w_lim
        out[Z_THETA_STAR], out[Z_KB], out[Z_PB], out[Z_E_STAR] = self.theta_star, self.K_b, self.p_b, self.E_star
        out[Z_MU], out[Z_C_ENV], out[Z_V_SLIP], out[Z_DENSITY] = self.mu_d, self.c_env, self.v_slip, self.density
        return out

    def stiffness(self, theta, wall: bool = False):
        """``max(K_0 (1 - theta/theta*), K_lim)`` (Sec. 7), N/m^2.

        Parameters
        ----------
        theta : float or array_like
            Temperatures (K, absolute); for a pair the mean of the two.
        wall : bool
            Whether the wall's stiffness (K_w, K_w^lim) is wanted rather than the particles' (K_p, K_p^lim).

        Returns
        -------
        numpy.ndarray
            The softened stiffness (N/m^2).
        """
        k0, floor = (self.K_w, self.K_w_lim) if wall else (self.K_p, self.K_p_lim)
        return np.maximum(k0 * (1.0 - np.asarray(theta, dtype=float) / self.theta_star), floor)


# ------------------------------------------------------------------------------------------ the plug-in
# What the engines' compiled loops call (:mod:`dem.laws.contact` lists the names every contact law defines).
NAME = "zohdi"
Material = ZohdiMaterial
PAIR_HISTORY = ("bonded",)  # 1: the bond of eq. 19 acts (activated by an accepted step that reached E*)
WALL_HISTORY = ()
PARTICLE_STATE = ()
PAIR_CONSTANTS = ()  # (pair_constants)
SPINS = False  # the particles do not rotate (Sec. 2)
SCHEMA_ROWS = (  # the scene keys of the material (dem.scene.schema): keys, type and unit, meaning
    (("K_p", "p_p", "K_p_lim"), "N/m², -, N/m²; required", "particle contact force K_p |E|^p_p A (eqs. 2-12), softened "
     "to max(K_p (1 - θ/θ*), K_p_lim) (Sec. 7)"),
    (("K_w", "p_w", "K_w_lim"), "N/m², -, N/m²; required", "the same for a wall (eqs. 13-15)"),
    (("theta_star",), "K, required", "θ*, the softening temperature (Sec. 7; absolute temperatures)"),
    (("K_b", "p_b", "E_star"), "N/m², -, -; required", "the bond K_b |E|^p_b A (eq. 19), activated once |E| ≥ E* "
     "(eq. 18)"),
    (("mu_d", "c_env", "v_slip"), "-, kg/(m s), m/s; required", "dynamic friction (eqs. 5, 16), drag c_env^o of c_env "
     "= c_env^o 6πR (eq. 20, Sec. 7), the friction's regularisation speed"),
    (("density",), "kg/m³, the `[material]` density", "particle density"),
)
DRAG = True  # eq. 20
JIT = {"cache": True, "error_model": "numpy"}
IN_LOOP = {**JIT, "inline": "always"}


def initial_state(material: ZohdiMaterial, T: np.ndarray, mass: np.ndarray) -> np.ndarray:
    """No state per particle: the temperatures themselves soften the contacts.

    Parameters
    ----------
    material : ZohdiMaterial
        The contact material (not read by this hook).
    T : numpy.ndarray
        (N,) initial temperatures (only their count is read).
    mass : numpy.ndarray
        (N,) masses (kg; not read).

    Returns
    -------
    numpy.ndarray
        An (N, 0) array.
    """
    return np.zeros((len(T), 0))


def reference_radius(material: ZohdiMaterial, radius: np.ndarray, T: np.ndarray) -> np.ndarray:
    """The radii do not change with temperature.

    Parameters
    ----------
    material : ZohdiMaterial
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


def largest_reach(material: ZohdiMaterial, radius: np.ndarray) -> float:
    """The law acts on touching particles only.

    Parameters
    ----------
    material : ZohdiMaterial
        The contact material (not read by this hook).
    radius : numpy.ndarray
        (N,) radii (m; not read).

    Returns
    -------
    float
        0.0: the largest gap (m) across which the law acts.
    """
    return 0.0


def time_steps(material: ZohdiMaterial, mass, inertia, radius, m_mean: float):
    """The law is stepped by the implicit scheme of the paper (:mod:`dem.engines.staggered`), not by velocity
    Verlet.

    Parameters
    ----------
    material : ZohdiMaterial
        The contact material.
    mass, inertia, radius : numpy.ndarray
        (N,) masses (kg), moments of inertia (kg m^2) and radii (m), as every law's ``time_steps`` takes them.
    m_mean : float
        The mass of a particle of the mean radius (kg).

    Raises
    ------
    ValueError
        Always: this law has no velocity-Verlet step.
    """
    raise ValueError("[contact] law = \"zohdi\": runs on the staggered implicit scheme of Zohdi 2014 (its [solver] "
                     "keys dt, dt_max, phi, iterations, tolerance), not on velocity-Verlet steps")


@njit(**JIT)
def softened(k0, k_lim, theta, theta_star):
    """``max(K_0 (1 - theta/theta*), K_lim)`` (Zohdi 2014, Sec. 7)."""
    return max(k0 * (1.0 - theta / theta_star), k_lim)


@njit(**JIT)
def lens_area(ri, rj, d):
    """``pi a^2 = pi (R_i^2 - L_i^2)``, ``L_i = (d - (R_j^2 - R_i^2)/d)/2`` (Zohdi 2014, eqs. 7-12); 0 apart."""
    if d >= ri + rj or d <= 0.0:
        return 0.0
    li = 0.5 * (d - (rj * rj - ri * ri) / d)
    return math.pi * max(ri * ri - li * li, 0.0)


@njit(**IN_LOOP)
def pair_force(c, i, j, hist_in, hist, state, T, delta, d, n, vr, vn, ri, rj, planar, dt, params, const):
    """Force on particle i of the pair ``c`` = (i, j) at centre distance ``d``: the contact force on the lens area
    (eqs. 2-12) softened by the pair's mean temperature (Sec. 7), less the bond's pull where the pair is bonded
    (eq. 19, ``hist_in[c, 0]``), and the friction ``mu_d |F_con|`` against the relative velocity ``-vr`` (eqs. 5-6,
    regularised). The bond flag written to ``hist[c, 0]`` is set once the strain reaches ``E*`` (eq. 18)."""
    area = lens_area(ri, rj, d)
    if area == 0.0:
        hist[c, 0] = 0.0
        return 0.0, 0.0, 0.0, 0.0
    strain = delta / (ri + rj)  # |E_ij| (eq. 3)
    stiffness = softened(params[Z_KP], params[Z_KP_LIM], 0.5 * (T[i] + T[j]), params[Z_THETA_STAR])
    f_con = stiffness * strain ** params[Z_PP] * area  # eq. 2
    bond = hist_in[c, 0] != 0.0  # eq. 19, activated by an earlier accepted step (eq. 18)
    f_n = f_con - (params[Z_KB] * strain ** params[Z_PB] * area if bond else 0.0)
    u0, u1, u2 = -vr[0], -vr[1], -vr[2]  # v_j - v_i (eq. 6)
    scale = params[Z_MU] * f_con / math.sqrt(u0 * u0 + u1 * u1 + u2 * u2 + params[Z_V_SLIP] ** 2)
    hist[c, 0] = 1.0 if bond or strain >= params[Z_E_STAR] else 0.0
    return f_n, scale * u0, scale * u1, scale * u2


@njit(**IN_LOOP)
def pair_constants(ri, rj, params):
    """No numbers of the radii alone are kept per pair (``PAIR_CONSTANTS`` is empty): two zeros."""
    return 0.0, 0.0


@njit(**IN_LOOP)
def forget_pair(c, hist_in, hist):
    """A pair that separated forgets its bond."""
    had = hist_in[c, 0] != 0.0
    hist[c, 0] = 0.0
    return had


@njit(**IN_LOOP)
def wall_force(k, m, hist_in, hist, state, T, delta, dist, n, vr, vn, rk, dt, params):
    """Force on particle k from wall m at the distance ``dist`` of its centre: the wall law on the circle the plane
    cuts from the sphere (eqs. 13-15), softened by the particle's temperature, and the friction against the
    tangential velocity (eqs. 16-17)."""
    strain = delta / rk  # eq. 14
    stiffness = softened(params[Z_KW], params[Z_KW_LIM], T[k], params[Z_THETA_STAR])
    f_con = stiffness * strain ** params[Z_PW] * math.pi * max(rk * rk - dist * dist, 0.0)  # eq. 13
    n0, n1, n2 = n
    t0, t1, t2 = vr[0] - vn * n0, vr[1] - vn * n1, vr[2] - vn * n2  # the wall slides along none of these
    scale = params[Z_MU] * f_con / math.sqrt(t0 * t0 + t1 * t1 + t2 * t2 + params[Z_V_SLIP] ** 2)  # eqs. 16-17
    return f_con, -scale * t0, -scale * t1, -scale * t2


@njit(**IN_LOOP)
def forget_wall(k, m, hist_in, hist):
    """Wall contacts carry nothing."""
    return False


@njit(**IN_LOOP)
def reach(c, hist, ri, rj, params):
    """The law acts on touching pairs only."""
    return 0.0


@njit(**IN_LOOP)
def wall_reach(k, m, hist, rk, params):
    """A wall contact acts while it overlaps."""
    return 0.0


@njit(**JIT)
def update_particles(elapsed, T0, T_rate, T, radius, radius_ref, state, uniform, params, t0, dt):
    """The temperatures ``T0 + T_rate elapsed``; the radii do not change (returns False)."""
    n = T.shape[0]
    for k in range(n):
        T[k] = T0[0] + T_rate[0] * elapsed if uniform else T0[k] + T_rate[k] * elapsed
    return False


@njit(**IN_LOOP)
def drag(k, radius, params):
    """``c_env = c_env^o 6 pi R`` (eq. 20 with Sec. 7's drag on a sphere), kg/s."""
    return params[Z_C_ENV] * 6.0 * math.pi * radius[k]
