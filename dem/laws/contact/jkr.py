"""The adhesive contact of Johnson, Kendall & Roberts 1971 (Proc. R. Soc. Lond. A 324, 301): elastic spheres whose
surfaces stick with the work of adhesion w, with the damping and the Mindlin tangential contact of
:mod:`dem.laws.contact.hertz_mindlin` -- a plug-in of the engines' compiled loops (:mod:`dem.laws.contact`).

Conventions, R*, m*, E* and G* (a wall: a partner of infinite radius and mass of the same material) as in
:mod:`dem.laws.contact.hertz_mindlin`. ``w`` is the work of adhesion (J/m^2): the energy per unit area it takes to
part the two surfaces, ``w = gamma_1 + gamma_2 - gamma_12`` (Johnson 1985's Delta gamma; twice the surface energy
gamma of identical surfaces -- LAMMPS's ``jkr`` takes that gamma).

* **Normal** (Johnson, Contact Mechanics, 1985, Sec. 5.5, with P_1 = 4 E* a^3/(3 R*)): at contact
  radius a, the overlap ``delta = a^2/R* - sqrt(2 pi w a/E*)`` and the force ``F_el = 4 E* a^3/(3 R*) - sqrt(8 pi
  w E* a^3)``. At ``F_el = 0``, ``a_0^3 = 9 pi w R*^2/(2 E*)``. The largest pull, ``-3/2 pi w R*`` (the pull-off
  force of a load-controlled test), is reached at ``delta = -a^2/(3 R*)``, ``a^3 = 9 pi w R*^2/(8 E*)``.
  :func:`dem.laws.contact.adhesion.jkr.contact_radius` inverts the overlap in closed form: with ``s = sqrt(a)`` and ``c = sqrt(2 pi w/E*)`` it
  is the quartic ``s^4 - c R* s - delta R* = 0``, solved by Ferrari's method through its resolvent cubic ``y^3 +
  delta R* y - c^2 R*^2/8 = 0`` (one real root for every delta above the break, written without cancellation).
* **Contact and break**: two surfaces that touch (delta reaches 0) jump into contact (``F_el = -4/3 pi w R*`` at
  delta = 0) and then stay in contact when pulled apart, beyond touching, down to ``delta_c = -3 a_c^2/R* = -3/4
  (pi^2 w^2 R*/E*^2)^(1/3)``, ``a_c = a_0/6^(2/3)``, where d delta/da = 0: the end of the stable branch under
  displacement control (Johnson 1985, Sec. 5.5; Thornton & Ning 1998, Powder Technol. 99, 154), with ``F_el = -5/6
  pi w R*``; there the contact breaks and the force drops to zero. The pair's history keeps the pull-off distance
  ``-delta_c`` (0 until the pair first touches), the engines' ``reach``: the contact acts while the surfaces are
  closer than that.
* **Damping**: ``eta_n = alpha sqrt(m* k_n)`` with ``k_n = 4/3 E* a`` at the JKR contact radius a, alpha from the
  restitution coefficient as in Hertz-Mindlin (:func:`dem.laws.contact.damping.tsuji.damping_coefficient`): where
  adhesion is weak against the impact (``w -> 0``) a head-on collision rebounds with that e; slow impacts stick.
* **Tangential**: Mindlin's spring ``k_t = 8 G* a`` on the JKR contact radius, damping ``eta_t``, Coulomb sliding at
  ``mu (F_el + 2 P_c)``, ``P_c = 3/2 pi w R*`` (Thornton & Yin 1991, Powder Technol. 65, 153: adhesion adds to the
  load that friction resists; LAMMPS's critical force for ``jkr``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from dem.laws.contact import hertz_mindlin as hm
from dem.laws.contact.adhesion import jkr as adhesion
from dem.laws.contact.damping import tsuji
from dem.laws.contact.hertz_mindlin import HertzMindlinMaterial, P_ALPHA, P_KN, P_KT, P_MU, P_MU_WALL, P_XT
from dem.laws.contact.tangential import mindlin

IN_LOOP = {"cache": True, "error_model": "numpy", "inline": "always"}  # inlined into the engines' force loop

# Indices into JKRMaterial.params(): those of hertz_mindlin (P_*), then
J_E_STAR = hm.N_PARAMS      # E* (Pa)
J_W = hm.N_PARAMS + 1       # w, the work of adhesion (J/m^2)
J_C = hm.N_PARAMS + 2       # c = sqrt(2 pi w/E*) (m^(1/2))
N_PARAMS = hm.N_PARAMS + 3


@dataclass(frozen=True)
class JKRMaterial(HertzMindlinMaterial):
    """Material of the JKR contact: that of Hertz-Mindlin
    (:class:`~dem.laws.contact.hertz_mindlin.HertzMindlinMaterial`) and ``work_of_adhesion`` w > 0 (J/m^2; twice the
    surface energy of identical surfaces). ``restitution`` is that of a collision whose adhesion is negligible.

    Parameters
    ----------
    youngs_modulus : float
        Young's modulus E of the particles and walls (Pa), > 0.
    poisson_ratio : float
        Poisson's ratio nu, in ``(-1, 0.5)``.
    restitution : float
        Coefficient of restitution e of a head-on collision with negligible adhesion, in ``(0, 1]``.
    tangential_damping : float
        eta_t / eta_n, the tangential over the normal damping coefficient, >= 0.
    mu : float
        Particle-particle friction coefficient, >= 0.
    mu_wall : float
        Particle-wall friction coefficient, >= 0.
    density : float
        Particle density (kg/m^3), > 0.
    work_of_adhesion : float
        The work of adhesion w (J/m^2), > 0.

    Raises
    ------
    ValueError
        A field is out of its range; the message names it (``contact.<field>``).
    """

    work_of_adhesion: float

    law = "jkr"

    def __post_init__(self):
        super().__post_init__()
        if not self.work_of_adhesion > 0:
            raise ValueError(f"contact.work_of_adhesion = {self.work_of_adhesion!r}: must be > 0 (J/m^2; without "
                             f"adhesion use law = \"hertz_mindlin\")")

    def params(self) -> np.ndarray:
        """The material as the float64 array the kernels take (indices ``P_*`` of hertz_mindlin, ``J_*`` here)."""
        out = np.empty(N_PARAMS)
        out[:hm.N_PARAMS] = super().params()
        e_star = self.effective_modulus
        out[J_E_STAR], out[J_W] = e_star, self.work_of_adhesion
        out[J_C] = math.sqrt(2.0 * math.pi * self.work_of_adhesion / e_star)
        return out

    def pulloff_distance(self, r_eff):
        """How far beyond touching a contact of effective radius ``R*`` breaks, ``3/4 (pi^2 w^2 R*/E*^2)^(1/3)`` (m).

        Parameters
        ----------
        r_eff : float or array_like
            The effective radius ``R* = a_i a_j/(a_i + a_j)`` (m; a particle's radius on a wall).

        Returns
        -------
        float or numpy.ndarray
            ``-delta_c``, the pull-off distance (m).
        """
        return 0.75 * np.cbrt(math.pi**2 * self.work_of_adhesion**2 * r_eff / self.effective_modulus**2)


time_steps = hm.time_steps  # the same steps: at a contact radius a, the JKR stiffness is at most Hertz's 2 E* a


@njit(**IN_LOOP)
def jkr_force(delta, delta_dot, r_eff, m_eff, params):
    """The JKR force with its damping: ``(F_n, F_el, a, eta_n)`` -- ``F_n = F_el + eta_n d(delta)/dt``, ``F_el =
    4 E* a^3/(3 R*) - sqrt(8 pi w E* a^3)`` at the contact radius ``a`` of ``delta``
    (:mod:`dem.laws.contact.adhesion.jkr`), ``eta_n = alpha sqrt(m* 4/3 E* a)``
    (:func:`dem.laws.contact.damping.tsuji.viscosity`)."""
    c = params[J_C]
    a = adhesion.contact_radius(delta, r_eff, c)
    k_n = params[P_KN] * a
    f_el = adhesion.elastic_force(a, k_n, r_eff, params[J_E_STAR], c)
    eta = tsuji.viscosity(params[P_ALPHA], m_eff, k_n)
    return f_el + eta * delta_dot, f_el, a, eta


@njit(**IN_LOOP)
def pulloff_distance(r_eff, params):
    """``-delta_c = 3/4 (pi^2 w^2 R*/E*^2)^(1/3)`` (module docstring), m."""
    return adhesion.pulloff_distance(r_eff, params[J_W], params[J_E_STAR])


# ------------------------------------------------------------------------------------------ the plug-in
# What the engines' compiled loops call (:mod:`dem.laws.contact` lists the names every contact law defines).
NAME = "jkr"
Material = JKRMaterial
PAIR_HISTORY = ("xi_x", "xi_y", "xi_z", "pulloff")  # the tangential spring; the pull-off distance, 0 before contact
WALL_HISTORY = PAIR_HISTORY
PARTICLE_STATE = hm.PARTICLE_STATE  # each particle's mass: the damping needs m*
PAIR_CONSTANTS = hm.PAIR_CONSTANTS
SPINS = True
_JKR_ROWS = {  # where the meaning of a Hertz-Mindlin key differs with adhesion
    ("restitution",): ("0 < e ≤ 1, required", "the coefficient of restitution of a head-on collision whose adhesion "
                       "is negligible (slow ones stick)"),
    ("mu", "mu_wall"): ("≥ 0, required", "particle-particle and particle-wall Coulomb friction, ‖F_t‖ ≤ μ (F_n + "
                        "3πwR*) (Thornton & Yin 1991)"),
}
SCHEMA_ROWS = tuple((keys, *_JKR_ROWS.get(keys, (unit, meaning))) for keys, unit, meaning in hm.SCHEMA_ROWS) + (
    (("work_of_adhesion",), "J/m², > 0, required", "w, the energy per area that parts the surfaces (twice the surface "
     "energy of identical ones; LAMMPS's `jkr` takes the surface energy): pull-off force 3/2 πwR*, the contact "
     "breaks 3/4 (π²w²R*/E*²)^(1/3) beyond touching (Johnson, Kendall & Roberts 1971)"),
)
DRAG = False
initial_state = hm.initial_state
reference_radius = hm.reference_radius
update_particles = hm.update_particles
pair_constants = hm.pair_constants
drag = hm.drag


def largest_reach(material: JKRMaterial, radius: np.ndarray) -> float:
    """The pull-off distance of the largest particle on a wall (R* = its radius), the farthest any contact acts.

    Parameters
    ----------
    material : JKRMaterial
        The contact material.
    radius : numpy.ndarray
        (N,) radii (m).

    Returns
    -------
    float
        The largest gap across which a contact acts (m).
    """
    return float(material.pulloff_distance(float(np.max(radius))))


@njit(**IN_LOOP)
def _contact(xi, pulloff, delta, vn, n, vr, r_eff, m_eff, mu, dt, params):
    """The force of a contact and its new history: ``(f_n, f_t, xi, pulloff)``."""
    f_n, f_el, a, eta = jkr_force(delta, -vn, r_eff, m_eff, params)
    n0, n1, n2 = n
    ft, xi = mindlin.mindlin_force(xi, n, (vr[0] - vn * n0, vr[1] - vn * n1, vr[2] - vn * n2), params[P_KT] * a,
                           params[P_XT] * eta, mu * (f_el + 3.0 * math.pi * params[J_W] * r_eff), dt)
    return f_n, ft, xi, pulloff if pulloff > 0.0 else pulloff_distance(r_eff, params)


@njit(**IN_LOOP)
def pair_force(c, i, j, hist_in, hist, state, T, delta, d, n, vr, vn, ri, rj, planar, dt, params, const):
    """Force on particle i of the pair ``c`` = (i, j) at overlap ``delta`` (negative beyond touching, down to the
    break); spring and pull-off distance in row ``c`` of ``hist_in``/``hist``."""
    mi, mj = state[i, 0], state[j, 0]
    f_n, ft, xi, pulloff = _contact((hist_in[c, 0], 0.0 if planar else hist_in[c, 1], hist_in[c, 2]), hist_in[c, 3],
                                    delta, vn, n, vr, ri * rj / (ri + rj), mi * mj / (mi + mj), params[P_MU], dt,
                                    params)
    hist[c, 0], hist[c, 1], hist[c, 2] = xi
    hist[c, 3] = pulloff
    return f_n, ft[0], ft[1], ft[2]


@njit(**IN_LOOP)
def forget_pair(c, hist_in, hist):
    """A pair that broke forgets its spring and its contact; whether it had one."""
    had = hist_in[c, 3] != 0.0
    hist[c, 0], hist[c, 1], hist[c, 2], hist[c, 3] = 0.0, 0.0, 0.0, 0.0
    return had


@njit(**IN_LOOP)
def reach(c, hist, ri, rj, params):
    """Beyond touching, a pair that has touched acts down to its pull-off distance (0 before it touched)."""
    return hist[c, 3]


@njit(**IN_LOOP)
def wall_force(k, m, hist_in, hist, state, T, delta, dist, n, vr, vn, rk, dt, params):
    """Force on particle k from wall m: the pair law with ``R* = a_k``, ``m* = m_k`` and ``mu_wall``; history in
    ``[k, m]``."""
    f_n, ft, xi, pulloff = _contact((hist_in[k, m, 0], hist_in[k, m, 1], hist_in[k, m, 2]), hist_in[k, m, 3], delta,
                                    vn, n, vr, rk, state[k, 0], params[P_MU_WALL], dt, params)
    hist[k, m, 0], hist[k, m, 1], hist[k, m, 2] = xi
    hist[k, m, 3] = pulloff
    return f_n, ft[0], ft[1], ft[2]


@njit(**IN_LOOP)
def forget_wall(k, m, hist_in, hist):
    """A wall contact that broke forgets its spring and its contact; whether it had one."""
    had = hist_in[k, m, 3] != 0.0
    hist[k, m, 0], hist[k, m, 1], hist[k, m, 2], hist[k, m, 3] = 0.0, 0.0, 0.0, 0.0
    return had


@njit(**IN_LOOP)
def wall_reach(k, m, hist, rk, params):
    """As :func:`reach`, for particle k on wall m."""
    return hist[k, m, 3]
