"""The material of the sintering contact law of Luding, Manetsberger & Müllers 2005 (Luding 2005): its fields, the
parameter block every Luding sub-model reads, the paper's Table 1 and the scene keys.

The law is a composition of sub-models (:data:`dem.laws.contact.CONTACT_LAWS`): the hysteretic sintering normal force
(:mod:`dem.laws.contact.normal.luding`, eqs. 4-15), its viscous damping (:mod:`dem.laws.contact.damping.luding`,
eq. 5), the tangential spring with friction (:mod:`dem.laws.contact.tangential.luding`, eqs. 14-24) and the
particles' thermal expansion and stiffness relaxation (:mod:`dem.laws.contact.state.sintering`, eqs. 9-12).

:class:`LudingMaterial` holds the material (SI units); :func:`params_of` packs it into the float64 array that every
Luding kernel takes as ``params`` (indices ``P_*`` below; the loops pass the same numbers as a tuple). Temperatures
only enter as differences (T - T_melt), so °C and K both work.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from dem.laws.fields import check_fields

# Indices into LudingMaterial.params()
P_K1 = 0               # k1, loading stiffness, cold limit (N/m)
P_K2 = 1               # k2, maximal un/reloading stiffness (N/m)
P_KC = 2               # kc, cohesion stiffness, cold limit (N/m)
P_KT_RATIO = 3         # alpha = k_t / k2(delta_max) (eq. 23)
P_GAMMA_N = 4          # gamma_0, normal viscous damping (kg/s, eq. 5)
P_GAMMA_T = 5          # gamma_t, tangential viscous damping (kg/s, eq. 19)
P_MU = 6               # particle-particle friction, cold limit (eq. 14, 24)
P_MU_WALL = 7          # particle-wall friction, cold limit
P_T_MELT = 8           # melting temperature (eq. 10)
P_T_VAR = 9            # width of the melting range (eq. 10)
P_EXPANSION = 10       # delta a_T, relative radius change per unit temperature (1/K, eq. 9)
P_FLUID_OVERLAP = 11   # delta_fluid / a (Sec. 3.1.3)
P_T0 = 12              # relaxation time of k1(T, t) (s, eq. 11-12)
P_BRITTLE_SLIDING = 13  # 1.0: no cohesion while sliding (footnote 5), 0.0: cohesion kept
P_DENSITY = 14         # particle density (kg/m^3)
P_WALL_SINTERING = 15  # 1.0: particle-wall contacts take k1(T, t) of the particle, 0.0: the cold-limit k1
N_PARAMS = 16

_FIELDS = {P_K1: "k1", P_K2: "k2", P_KC: "kc", P_KT_RATIO: "kt_ratio", P_GAMMA_N: "gamma_n", P_GAMMA_T: "gamma_t",
           P_MU: "mu", P_MU_WALL: "mu_wall", P_T_MELT: "T_melt", P_T_VAR: "T_var", P_EXPANSION: "expansion",
           P_FLUID_OVERLAP: "fluid_overlap", P_T0: "t0", P_BRITTLE_SLIDING: "brittle_sliding", P_DENSITY: "density",
           P_WALL_SINTERING: "wall_sintering"}

_NONNEGATIVE = {"kc": "N/m", "kt_ratio": "", "gamma_n": "kg/s", "gamma_t": "kg/s", "mu": "", "mu_wall": "",
                "expansion": "1/K"}
_POSITIVE = {"k1": "N/m", "k2": "N/m", "T_var": "K", "t0": "s", "density": "kg/m^3"}


@dataclass(frozen=True)
class LudingMaterial:
    r"""Material of the Luding 2005 contact law (SI units; temperatures in °C or K, only differences matter).

    ``k1`` loading stiffness and ``kc`` cohesion stiffness in the cold limit, ``k2`` the largest un/reloading
    stiffness (eq. 4, 7); ``kt_ratio`` :math:`\alpha = k_t/k_2(\delta_{max})` (eq. 23); ``gamma_n``
    :math:`\gamma_0` (eq. 5) and ``gamma_t`` (eq. 19) viscous damping; ``mu``, ``mu_wall`` friction coefficients in
    the cold limit (eq. 14, 24); ``T_melt``, ``T_var`` of :math:`k_1(T)` (eq. 10); ``expansion`` :math:`\delta a_T`
    (eq. 9); ``fluid_overlap`` :math:`\phi = \delta_{fluid}/a` (Sec. 3.1.3); ``t0`` the relaxation time of
    :math:`k_1(T, t)` (eq. 11-12); ``brittle_sliding``: a sliding contact keeps no cohesion, :math:`f_n \ge 0`
    (footnote 5); ``density`` of the particles; ``wall_sintering``: a particle-wall contact softens and sinters with
    the particle's :math:`k_1(T, t)` like a pair (true), or keeps the cold-limit :math:`k_1` of a wall that does not
    melt (false; Luding 2005 gives the walls no law beyond :math:`\mu_w`).

    Parameters
    ----------
    k1 : float
        Plastic loading stiffness in the cold limit (N/m), > 0 and <= ``k2`` (eq. 4).
    k2 : float
        Largest un/reloading stiffness (N/m), > 0 (eq. 7).
    kc : float
        Cohesion stiffness in the cold limit (N/m), >= 0.
    kt_ratio : float
        :math:`\alpha = k_t/k_2(\delta_{max})`, the tangential stiffness ratio (eq. 23), >= 0.
    gamma_n : float
        Normal viscous damping :math:`\gamma_0` (kg/s), >= 0 (eq. 5).
    gamma_t : float
        Tangential viscous damping (kg/s), >= 0 (eq. 19).
    mu : float
        Particle-particle friction coefficient in the cold limit, >= 0 (eq. 14).
    mu_wall : float
        Particle-wall friction coefficient in the cold limit, >= 0 (eq. 24).
    T_melt : float
        Melting temperature of k1(T) (degC or K; eq. 10).
    T_var : float
        Width of the melting transition of k1(T) (K), > 0 (eq. 10).
    expansion : float
        Thermal expansion coefficient :math:`\delta a_T` (1/K), >= 0 (eq. 9).
    fluid_overlap : float
        :math:`\phi = \delta_{fluid}/a`, in ``(0, 1)`` (Sec. 3.1.3).
    t0 : float
        Relaxation time of k1(T, t) (s), > 0 (eqs. 11-12).
    brittle_sliding : bool
        Whether a sliding contact keeps no cohesion, f_n >= 0 (footnote 5).
    density : float
        Particle density (kg/m^3), > 0.
    wall_sintering : bool
        Whether a particle-wall contact softens and sinters with the particle's k1(T, t) like a pair.

    Raises
    ------
    ValueError
        A field is out of its range, or ``k1 > k2``; the message names it (``contact.<field>``).
    """

    k1: float
    k2: float
    kc: float
    kt_ratio: float
    gamma_n: float
    gamma_t: float
    mu: float
    mu_wall: float
    T_melt: float
    T_var: float
    expansion: float
    fluid_overlap: float
    t0: float
    brittle_sliding: bool
    density: float
    wall_sintering: bool = True

    law = "luding"

    def __post_init__(self):
        check_fields(self, "contact", _POSITIVE, _NONNEGATIVE, flags=("brittle_sliding", "wall_sintering"))
        if self.k1 > self.k2:
            raise ValueError(f"contact.k1 = {self.k1!r}: must be <= k2 = {self.k2!r} N/m (Luding 2005, eq. 4: "
                             f"plastic loading is no stiffer than un/reloading)")
        if not 0.0 < self.fluid_overlap < 1.0:
            raise ValueError(f"contact.fluid_overlap = {self.fluid_overlap!r}: must be in (0, 1) "
                             f"(delta_fluid / radius; Luding 2005 uses 0.2)")

    def params(self) -> np.ndarray:
        """The material as the float64 array the kernels take (indices ``P_*`` of this module)."""
        return params_of(self)

    @property
    def lowest_temperature(self) -> float:
        """Where the radius of eq. (9) reaches zero, ``T_melt - 1/expansion`` (-inf without expansion)."""
        return self.T_melt - 1.0 / self.expansion if self.expansion > 0 else -math.inf

    def check_temperatures(self, T, name: str = "T") -> None:
        """Raise ``ValueError`` if a temperature lies at or below :attr:`lowest_temperature`, where eq. (9)
        gives a radius <= 0 (the linear expansion law no longer holds).

        Parameters
        ----------
        T : array_like
            Temperatures (degC or K, the unit of ``T_melt``).
        name : str
            The temperatures' name in the message.

        Raises
        ------
        ValueError
            A temperature lies at or below :attr:`lowest_temperature`.
        """
        T = np.asarray(T, dtype=float)
        bad = np.flatnonzero(T <= self.lowest_temperature)
        if bad.size:
            k = int(bad[0])
            raise ValueError(f"{name}[{k}] = {float(T.flat[k])!r}: must be > T_melt - 1/expansion = "
                             f"{self.lowest_temperature:.6g} (below it the radius a(T) of Luding 2005, eq. 9, is <= 0)")


# Luding 2005, Table 1 (Sec. 4): k2 = 2e5 N/m, k1/k2 = kc/k2 = 0.5, k_t/k2 = 0.2, gamma_0 = 0.2 kg/s,
# gamma_t = 0.05 kg/s, mu = 0.5, mu_w = 0, T_melt = 120 °C, T_var = 10 K, delta a_T = 1e-4 /K,
# delta_fluid/a0 = 0.2, t0 = 1e3 s (default; 0.1 s during sintering), rho = 2000 kg/m^3; f_n >= 0 while sliding
# (footnote 5: "In this study we assume ... f^n >= 0, (if sliding)"). The walls of Sec. 4 get only mu_w in the
# paper; here their contacts keep the cold-limit law (wall_sintering = False): only so does the three-particle
# control of Sec. 4.1.3 come near the paper's 8 % at p = 100 (walls that sinter like pairs triple it; python -m
# verification sintering, its isolating runs).
LUDING_TABLE1 = LudingMaterial(k1=1.0e5, k2=2.0e5, kc=1.0e5, kt_ratio=0.2, gamma_n=0.2, gamma_t=0.05, mu=0.5,
                               mu_wall=0.0, T_melt=120.0, T_var=10.0, expansion=1.0e-4, fluid_overlap=0.2, t0=1.0e3,
                               brittle_sliding=True, density=2000.0, wall_sintering=False)


def params_of(material) -> np.ndarray:
    """The parameter block of the Luding sub-models (indices ``P_*``): the material's fields, flags as 1.0 or 0.0; a
    field the material does not have (a composition that takes only some Luding sub-models) is 0.0, read by none of
    its sub-models.

    Parameters
    ----------
    material : object
        A material with (some of) the fields of :class:`LudingMaterial`.

    Returns
    -------
    numpy.ndarray
        (``N_PARAMS``,) the block.
    """
    out = np.zeros(N_PARAMS)
    for index, name in _FIELDS.items():
        out[index] = float(getattr(material, name, 0.0))
    return out


Material = LudingMaterial
SCHEMA_ROWS = (  # the scene keys of the material (dem.scene.schema): keys, type and unit, meaning
    (("k1", "k2", "kc"), "N/m, required", "loading, largest un/reloading and cohesion stiffness (cold limit), "
     "0 < k1 ≤ k2 (k1 = k2: elastic), kc ≥ 0 (eqs. 4, 7, 13)"),
    (("kt_ratio",), "≥ 0, required", "α = k_t/k2(δmax) (eq. 23)"),
    (("gamma_n", "gamma_t"), "kg/s, ≥ 0, required", "normal (eq. 5) and tangential (eq. 19) viscous damping"),
    (("mu", "mu_wall"), "≥ 0, required", "particle-particle and particle-wall friction, cold limit (eqs. 14, 24)"),
    (("T_melt", "T_var"), "required, T_var > 0", "k1(T) = k1[1 + tanh((T_melt - T)/T_var)]/2 (eq. 10); the scene's "
     "temperature unit"),
    (("expansion",), "1/K, ≥ 0, required", "δa_T of a(T) = a(T_melt)[1 - δa_T(T_melt - T)] (eq. 9)"),
    (("fluid_overlap",), "0 < φ < 1, required", "δ_fluid = φ·2R_eff for a pair (φa for equal radii), φa_i for a wall "
     "contact (Sec. 3.1.3)"),
    (("t0",), "s, > 0, required", "relaxation time of k1(T, t) (eqs. 11-12)"),
    (("brittle_sliding",), "bool, required", "a sliding contact keeps no cohesion, f_n ≥ 0 (footnote 5)"),
    (("density",), "kg/m³, the `[material]` density", "particle density"),
    (("wall_sintering",), "bool, default true", "a particle-wall contact softens and sinters with the particle's "
     "k1(T, t) like a pair (true), or keeps the cold-limit k1 of a wall that does not melt (false)"),
)
