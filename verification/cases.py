"""Reference numbers: the one place in the repository that holds them, each with its provenance.

Tests, examples, the verification sections and the benchmarks import these; nothing else writes them out.

Where they come from
--------------------
*What the paper prints* (:data:`SEC43`, :data:`SEC6`, :data:`FIG13_A_OVER_R`, the slopes): J. Rojek, R. Kasztelan,
R. Tharmaraj, *Discrete element thermal conductance model for sintered particles* (2022); section, figure or
equation named in each entry. Known slips of the text: the a/r printed with Figs. 13-14 (0.19934, 0.610573,
0.829653) differ from the paper's own eqs. (19)-(20) in the fifth digit (we use the equations), and eq. (23) writes
r where r_i and r_j are meant (eq. 27 is right).

*The semisphere with a cylindrical neck* (:data:`SEMISPHERE`; equal spheres, K_cyl = kappa pi r, Rojek 2022
Fig. 12): computed with an independent high-order finite-element code (curved elements, hp-graded toward the
re-entrant corner, p up to 14); an upper bound (energy) and a lower bound (dual formulation) agree to ~1e-12
relative. The a/r are from eqs. (19)-(20) of the paper. Useful identities of that body: its volume is exactly
2 pi r^3 / 3 (volume conservation), and the conductance from the energy u.A.u / Delta T^2 equals the one from the
reaction at the fixed-temperature dofs to round-off.

*Other anchors*:

* an isothermal disk of radius a on a half-space has the spreading resistance 1/(4 kappa a), so the
  half-conductance of a very small neck tends to 4 kappa a (:data:`CONSTRICTION_LIMIT`; Batchelor & O'Brien 1977
  give 2 kappa a for the whole sphere-sphere pair);
* an isothermal disk (radius a = 1) feeding a semi-infinite insulated circular flux tube (radius b = 2), kappa = 1:
  the extra (constriction) resistance beyond the 1-D tube value is about 0.0849 K/W, a correlation good to
  ~0.1 % (Rohsenow et al., Handbook of Heat Transfer, 1998) (:data:`FLUX_TUBE_CONSTRICTION`);
* the paper's neck radii and pair conductance of Sections 4.3 and 6 (:data:`SEC43`, :data:`SEC6`);
* Luding, Manetsberger & Muellers 2005, Sec. 3.3.1: with T_melt = 120 C and T_var = 10 K the stiffness factor
  k1(T)/k1 is 0.6 at 118 C, 0.4 at 122 C, 0.12 at 130 C and 3e-4 at 160 C (:data:`LUDING_STIFFNESS_FACTOR`);
* LAMMPS granular ``heat radius`` conducts Q = 2 k a Delta T with a from the overlap (a = sqrt(R_eff delta)); the
  Rojek pipe K_ij = 0.532 pi kappa a corresponds to k = 0.8357 kappa there (:data:`LAMMPS_HEAT_RADIUS_K`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

ROJEK_2022 = "Rojek, Kasztelan & Tharmaraj 2022"
LUDING_2005 = "Luding, Manetsberger & Muellers 2005"
REFERENCE_TABLE = ("independent hp-FE (curved elements, hp-graded to the corner, p up to 14; energy upper and dual "
                   "lower bounds agree to ~1e-12), verification.cases.SEMISPHERE")


@dataclass(frozen=True)
class Reference:
    """A number to compare with: ``value`` in ``unit`` as printed in ``source``."""

    value: float
    unit: str
    source: str

    def rel_error(self, ours: float) -> float:
        """Relative difference ``(ours - value) / value``."""
        return (float(ours) - self.value) / self.value


# --- The semisphere with a cylindrical neck (equal spheres), 12 digits ------------------------------------------------
class SemisphereRow(NamedTuple):
    """One row of the reference table: overlap h/r, neck radius a/r (eqs. 19-20) and K/K_cyl (K_cyl = kappa pi r)."""

    h_over_r: float
    a_over_r: float
    K_over_Kcyl: float


SEMISPHERE = (
    SemisphereRow(0.02, 0.199331088562, 0.216136324118),
    SemisphereRow(0.08, 0.394592534534, 0.412739950539),
    SemisphereRow(0.2, 0.610588366343, 0.655577629373),
    SemisphereRow(0.4, 0.829667696190, 0.992974073489),
)
SEMISPHERE_BY_H = {row.h_over_r: row for row in SEMISPHERE}

REFERENCE = {  # the same table as References, for reports that cite each number
    row.h_over_r: {
        "a_over_r": Reference(row.a_over_r, "-", f"{REFERENCE_TABLE}, row h/r = {row.h_over_r} (eqs. 19-20)"),
        "K_over_Kcyl": Reference(row.K_over_Kcyl, "-", f"{REFERENCE_TABLE}, row h/r = {row.h_over_r}"),
    }
    for row in SEMISPHERE
}

# --- Other anchors -------------------------------------------------------------------------------------------------
CONSTRICTION_LIMIT = Reference(4.0, "kappa a", "isothermal disk on a half-space: spreading resistance 1/(4 kappa a); "
                                               "a small neck's half-conductance tends to 4 kappa a")
FLUX_TUBE_CONSTRICTION = Reference(0.0849, "K/W", "isothermal disk a = 1 into an insulated flux tube b = 2, kappa = 1: "
                                                  "extra resistance, Rohsenow et al. 1998 (correlation, ~0.1 %)")
LUDING_STIFFNESS_T_MELT, LUDING_STIFFNESS_T_VAR = 120.0, 10.0  # C, K
LUDING_STIFFNESS_FACTOR = {  # temperature [C] -> k1(T)/k1
    t: Reference(v, "-", f"{LUDING_2005}, Sec. 3.3.1 (T_melt = 120 C, T_var = 10 K)")
    for t, v in ((118.0, 0.6), (122.0, 0.4), (130.0, 0.12), (160.0, 3e-4))
}
LAMMPS_HEAT_RADIUS_K = Reference(0.8357, "kappa", "LAMMPS granular 'heat radius' Q = 2 k a dT matching the Rojek pipe "
                                                  "K_ij = 0.532 pi kappa a")

# --- Section 4.3 (unequal pair, Fig. 9): r_i = 1 mm, r_j = 3 mm, h = 0.2 mm ---------------------------------------
SEC43_RADII = (1.0e-3, 3.0e-3)  # m
SEC43_OVERLAP = 0.2e-3  # m
SEC43 = {
    "newton": Reference(0.741466e-3, "m", f"{ROJEK_2022}, Sec. 4.3 (Newton, eq. 32, 6 digits)"),
    "coble": Reference(0.774597e-3, "m", f"{ROJEK_2022}, Sec. 4.3 (Coble, eqs. 11-12)"),
    "first": Reference(0.745039e-3, "m", f"{ROJEK_2022}, Sec. 4.3 (first iterate, eq. 34)"),
}
SEC43_PERCENT_ERRORS = {
    "coble": Reference(4.47, "%", f"{ROJEK_2022}, Sec. 4.3 ('error 4.47%')"),
    "first": Reference(0.48, "%", f"{ROJEK_2022}, Sec. 4.3 ('an error of 0.48%')"),
}

# --- Section 6 (unequal pair, Fig. 17): r_i = 1 mm, r_j = 3 mm, h = 0.06 mm, copper ---------------------------------
SEC6_RADII = (1.0e-3, 3.0e-3)  # m
SEC6_OVERLAP = 0.06e-3  # m
SEC6_KAPPA = 394.0  # W/(m K)
SEC6 = {
    "a": Reference(0.419186e-3, "m", f"{ROJEK_2022}, Sec. 6 (Newton, 6 digits)"),
    "K_half": Reference(0.55207, "W/K", f"{ROJEK_2022}, Sec. 6 (K_i = K_j from eq. 43)"),
    "K_model": Reference(0.276035, "W/K", f"{ROJEK_2022}, Sec. 6 (eq. 45)"),
    "K_fe": Reference(0.278033, "W/K", f"{ROJEK_2022}, Sec. 6 (Abaqus, converged, axisymmetric quads)"),
}

# --- Section 5: semisphere with a neck (Fig. 12), r = 10 mm, copper, 10 degC / 0 degC --------------------------------
FIG13_H_OVER_R = tuple(row.h_over_r for row in SEMISPHERE)
FIG13_A_OVER_R = {
    hr: Reference(v, "-", f"{ROJEK_2022}, Fig. 13/14 captions")
    for hr, v in zip(FIG13_H_OVER_R, (0.19934, 0.3946, 0.610573, 0.829653))
}
FIG15_H_OVER_R = 0.08  # Fig. 15: convergence study at h/r = 0.08 (a/r = 0.3946); the paper prints no value

# Linear laws K/K_cyl = c a/r, K_cyl = kappa pi r (eqs. 38-39).
SLOPE_ROJEK = Reference(1.064, "-", f"{ROJEK_2022}, eq. (40), fitted on a/r up to ~0.7")
SLOPE_ARGENTO_BOUVARD = Reference(1.112, "-", f"{ROJEK_2022}, eq. (42) (= 1/0.899, Argento & Bouvard 1996, eq. 41)")
SLOPE_DIFFERENCE_PERCENT = Reference(3.0, "%", f"{ROJEK_2022}, Sec. 5 ('around 3%')")

# --- Figures with curves only (no printed numbers); the parameters the paper used ---------------------------------
FIG10_RADIUS_RATIOS = (1.0, 2.0, 3.0, 5.0, 10.0)  # r_j / r_i, Figs. 10-11 (the paper's legend values are not in the text)
