"""Reference numbers the verification compares against, each with its source.

``PAPER`` holds what Rojek, Kasztelan & Tharmaraj (2022) print (``/work/shared/seeds/000_…``); ``REFERENCE`` holds
independently computed numbers (``/work/shared/reference/README.md``). Every entry is a :class:`Reference`: the value,
its unit and where it comes from (section, figure or equation), so a report can cite each number it compares with.
"""

from __future__ import annotations

from dataclasses import dataclass

ROJEK_2022 = "Rojek, Kasztelan & Tharmaraj 2022"
REFERENCE_TABLE = "shared/reference/README.md (independent hp-FE, upper/lower bounds agree to ~1e-12)"


@dataclass(frozen=True)
class Reference:
    """A number to compare with: ``value`` in ``unit`` as printed in ``source``."""

    value: float
    unit: str
    source: str

    def rel_error(self, ours: float) -> float:
        """Relative difference ``(ours - value) / value``."""
        return (float(ours) - self.value) / self.value


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
SEC5_RADIUS = 10.0e-3  # m
SEC5_KAPPA = 394.0  # W/(m K)
FIG13_H_OVER_R = (0.02, 0.08, 0.2, 0.4)
FIG13_A_OVER_R = {
    hr: Reference(v, "-", f"{ROJEK_2022}, Fig. 13/14 captions")
    for hr, v in zip(FIG13_H_OVER_R, (0.19934, 0.3946, 0.610573, 0.829653))
}
FIG15_H_OVER_R = 0.08  # Fig. 15: convergence study at h/r = 0.08 (a/r = 0.3946); the paper prints no value

# Linear laws K/K_cyl = c a/r, K_cyl = kappa pi r (eqs. 38-39).
SLOPE_ROJEK = Reference(1.064, "-", f"{ROJEK_2022}, eq. (40), fitted on a/r up to ~0.7")
SLOPE_ARGENTO_BOUVARD = Reference(1.112, "-", f"{ROJEK_2022}, eq. (42) (= 1/0.899, Argento & Bouvard 1996, eq. 41)")
SLOPE_DIFFERENCE_PERCENT = Reference(3.0, "%", f"{ROJEK_2022}, Sec. 5 ('around 3%')")
LINEAR_RANGE_A_OVER_R = 0.7  # "up to nearly a/r = 0.7 has a linear character" (Sec. 5)

# --- Independent reference: semisphere K/K_cyl (equal spheres) --------------------------------------------------------
REFERENCE = {
    hr: {
        "a_over_r": Reference(a, "-", f"{REFERENCE_TABLE}, row h/r = {hr} (eqs. 19-20)"),
        "K_over_Kcyl": Reference(k, "-", f"{REFERENCE_TABLE}, row h/r = {hr}"),
    }
    for hr, a, k in (
        (0.02, 0.199331088562, 0.216136324118),
        (0.08, 0.394592534534, 0.412739950539),
        (0.2, 0.610588366343, 0.655577629373),
        (0.4, 0.829667696190, 0.992974073489),
    )
}

# --- Figures with curves only (no printed numbers); the parameters the paper used ---------------------------------
FIG10_RADIUS_RATIOS = (1.0, 2.0, 3.0, 5.0, 10.0)  # r_j / r_i, Figs. 10-11 (the paper's legend values are not in the text)
