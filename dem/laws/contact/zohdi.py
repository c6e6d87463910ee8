r"""The contact material of Zohdi 2014 (eqs. 2-21 and Sec. 7) and the parameters of its implicit stepping (eqs.
22-30, 45-49).

:class:`ZohdiMaterial` holds the material in SI units, named by the paper's symbols; :meth:`ZohdiMaterial.params`
packs it into the float64 array the Zohdi sub-models take (indices ``Z_*``). The law is the composition
(:data:`dem.laws.contact.CONTACT_LAWS`) of the power-law normal force on the contact area
(:mod:`dem.laws.contact.normal.zohdi`, eqs. 2-15, Sec. 7), the bonds (:mod:`dem.laws.contact.adhesion.zohdi`, eqs.
18-19), the sliding friction (:mod:`dem.laws.contact.tangential.zohdi`, eqs. 5-6, 16-17) and the drag
(:mod:`dem.laws.contact.drag.zohdi`, eq. 20). The adaptive trapezoidal fixed-point scheme the paper steps it with
is the staggered engine's (:mod:`dem.engines.staggered`, its parameters :class:`dem.scene.staggered.ZohdiStepping`).

Conventions (Zohdi 2014, eqs. 3-4): :math:`n_{ij} = (r_j - r_i)/|r_j - r_i|` points from i to j (the engines'
:math:`n` is the opposite, from j to i); the strain :math:`E_{ij} = (|r_i - r_j| - (R_i + R_j))/(R_i + R_j)` is
negative in contact; the contact force on i is :math:`-K_p |E|^{p_p} A_{ij} n_{ij}` (it pushes i away from j), the
bond force :math:`+K_b |E|^{p_b} A_{ij} n_{ij}` pulls it back. The particles do not rotate (Sec. 2: "the effects of
their rotation ... unimportant").

A wall is the plane :math:`n_w \cdot x = q_w` (normal into the packing); its contact force on particle k is
:math:`K_w E^{p_w} A_k n_w` with :math:`E = (R_k - \mathrm{dist})/R_k` (eq. 14: the overlap over the radius, as a
pair's strain is its overlap over :math:`R_i + R_j`) and :math:`A_k = \pi (R_k^2 - \mathrm{dist}^2)` the circle the
plane cuts from the sphere (the lens of eqs. 7-12 with the plane for the second particle).

Friction (eqs. 5-6): :math:`\mu_d |F_{con}|\, t` with :math:`t = (v_j - v_i)/|v_j - v_i|` the whole relative
velocity, as the paper writes it (so friction also opposes the approach of two particles, which is what makes their
collisions inelastic: the law has no normal damping). At a wall only the tangential velocity counts (eq. 17). The
direction is regularised, :math:`t = \Delta v/\sqrt{|\Delta v|^2 + v_{slip}^2}`: a unit vector while sliding faster
than ``v_slip``, proportional to the slip below it, so that the fixed-point map stays continuous where the relative
velocity passes through zero.

Bonds (eqs. 18-19): a pair whose strain reaches :math:`E^*` is bonded from the next step on (the flag is the pair's
history, committed when a step is accepted) and stays bonded while it touches. Within a step the flags are fixed: a
bond switched on between two iterates makes the force jump by :math:`K_b {E^*}^{p_b} A`, and the fixed-point
iteration then stalls at the size of that jump instead of converging.

Units (Sec. 7 states them: "K_po = 10^7 N/m^2"): the contact force :math:`K_p |E|^{p_p} A_c` is in newtons with the
contact area :math:`A_c` in m^2 and the strain :math:`E` dimensionless, so ``K_p``, ``K_w`` and ``K_b`` are in N/m^2
(Pa). Temperatures are absolute (K): the softening :math:`K = \max(K_0 (1 - \theta/\theta^*), K_{lim})` of Sec. 7
needs :math:`\theta = 0` to mean absolute zero.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

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
    r"""The contact material of Zohdi 2014 (paper's symbols; SI units; module docstring).

    Normal contact :math:`K_p |E_{ij}|^{p_p} A_{ij}` (eqs. 2-12, :math:`E_{ij} = (|r_i - r_j| - (R_i + R_j))/(R_i +
    R_j)`, the lens area :math:`A_{ij} = \pi (R_i^2 - L_i^2)`); wall contact :math:`K_w |E_{iw}|^{p_w} A_i` (eqs.
    13-15, :math:`E_{iw}` the overlap over the radius, :math:`A_i` the circle the wall cuts from the sphere); thermal
    softening :math:`K = \max(K_0 (1 - \theta/\theta^*), K_{lim})` (Sec. 7; for a pair, :math:`\theta` is the mean
    of the two); an adhesive bond :math:`K_b |E_{ij}|^{p_b} A_{ij}` (eq. 19), activated once :math:`|E_{ij}| \ge
    E^*` and kept while the particles touch; sliding friction :math:`\mu_d |F_{con}|` against the relative velocity
    (eqs. 5-6; against the tangential one at a wall, eqs. 16-17), its direction regularised below ``v_slip``; drag
    :math:`-c_{env}^o\, 6 \pi R v` (eq. 20, Sec. 7); ``density``.

    Parameters
    ----------
    K_p : float
        :math:`K_{p0}`, the particle-particle contact stiffness when cold (N/m^2), > 0 (eq. 2).
    p_p : float
        The exponent of the particle contact law, > 0 (eq. 2).
    K_p_lim : float
        :math:`K_p^{lim}`, the softened floor of ``K_p`` (N/m^2), in ``[0, K_p]`` (Sec. 7).
    K_w : float
        :math:`K_{w0}`, the particle-wall contact stiffness when cold (N/m^2), > 0 (eq. 13).
    p_w : float
        The exponent of the wall contact law, > 0 (eq. 13).
    K_w_lim : float
        :math:`K_w^{lim}`, the softened floor of ``K_w`` (N/m^2), in ``[0, K_w]`` (Sec. 7).
    theta_star : float
        :math:`\theta^*`, the softening temperature (K, absolute), > 0 (Sec. 7).
    K_b : float
        The bond stiffness (N/m^2), >= 0 (eq. 19).
    p_b : float
        The exponent of the bond law, > 0 (eq. 19).
    E_star : float
        :math:`E^*`, the strain magnitude that activates a bond, >= 0 (eqs. 18-19).
    mu_d : float
        The dynamic friction coefficient of particles and walls, >= 0 (eqs. 5, 16).
    c_env : float
        :math:`c_{env}^o` of the drag :math:`c_{env} = c_{env}^o\, 6 \pi R` (kg/(m s)), >= 0 (eq. 20, Sec. 7).
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
        return params_of(self)

    def stiffness(self, theta, wall: bool = False):
        r""":math:`\max(K_0 (1 - \theta/\theta^*), K_{lim})` (Sec. 7), N/m^2.

        Parameters
        ----------
        theta : float or array_like
            Temperatures (K, absolute); for a pair the mean of the two.
        wall : bool
            Whether the wall's stiffness (``K_w``, ``K_w_lim``) is wanted rather than the particles' (``K_p``,
            ``K_p_lim``).

        Returns
        -------
        numpy.ndarray
            The softened stiffness (N/m^2).
        """
        k0, floor = (self.K_w, self.K_w_lim) if wall else (self.K_p, self.K_p_lim)
        return np.maximum(k0 * (1.0 - np.asarray(theta, dtype=float) / self.theta_star), floor)


def params_of(material) -> np.ndarray:
    """The parameter block of the Zohdi sub-models (indices ``Z_*``).

    Parameters
    ----------
    material : ZohdiMaterial
        The material.

    Returns
    -------
    numpy.ndarray
        (``N_PARAMS``,) the block.
    """
    m = material
    out = np.empty(N_PARAMS)
    out[Z_KP], out[Z_PP], out[Z_KP_LIM] = m.K_p, m.p_p, m.K_p_lim
    out[Z_KW], out[Z_PW], out[Z_KW_LIM] = m.K_w, m.p_w, m.K_w_lim
    out[Z_THETA_STAR], out[Z_KB], out[Z_PB], out[Z_E_STAR] = m.theta_star, m.K_b, m.p_b, m.E_star
    out[Z_MU], out[Z_C_ENV], out[Z_V_SLIP], out[Z_DENSITY] = m.mu_d, m.c_env, m.v_slip, m.density
    return out


Material = ZohdiMaterial
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
