"""verification.paper and verification.cases: the paper's printed numbers, reproduced (geometry parts; fast)."""

import matplotlib.image
import numpy as np
import pytest

from fem_neck.geometry import neck_radius
from verification import cases, paper


def test_z_function_vanishes_at_the_neck_radius():
    # Rojek 2022, eq. (27): Z(a) = 0 at the volume-conserving neck; negative left, positive right of it (Fig. 9)
    r_i, r_j = cases.SEC43_RADII
    h = cases.SEC43_OVERLAP
    a = neck_radius(r_i, r_j, h)
    scale = 3 * a**2 * r_i  # size of the terms of eq. (27)
    assert abs(paper.z_function(a, r_i, r_j, h)) < 1e-13 * scale
    assert paper.z_function(0.99 * a, r_i, r_j, h) < 0 < paper.z_function(1.01 * a, r_i, r_j, h)


def test_sec43_printed_digits(tmp_path):
    part = paper.neck_sec43(tmp_path)
    for m in ("newton", "coble", "first"):
        entry = part.summary[f"paper.sec43.a_{m}"]
        assert abs(entry["ours"] - entry["theirs"]) <= 0.5e-9  # 6 printed digits in mm
    assert abs(part.summary["paper.sec43.coble_error_percent"]["ours"] - 4.47) < 0.005
    assert abs(part.summary["paper.sec43.first_error_percent"]["ours"] - 0.48) < 0.005
    assert matplotlib.image.imread(part.figures[0]).shape[0] > 100


def test_equal_necks_and_coble_error(tmp_path):
    part = paper.neck_equal(tmp_path)
    assert part.summary["paper.fig06.newton_vs_eqs19_20"]["rel_error"] < 1e-14
    # Coble's neck is exact to first order: sqrt(2 r h) vs a^2 = 2 r h_c - h_c^2 with h_c = h + O(h^2)
    assert paper.coble_error_equal(1e-6) == pytest.approx(0.0, abs=1e-5)
    assert np.all(np.diff(paper.coble_error_equal(np.linspace(0.01, 2 / 3, 50))) > 0)
    assert paper.coble_error_equal(2 / 3) == pytest.approx(np.sqrt(4 / 3) - 1, rel=1e-12)  # a = r at h = 2r/3


def test_unequal_figure(tmp_path):
    part = paper.neck_unequal(tmp_path)
    assert "r_j/r_i" in part.markdown and matplotlib.image.imread(part.figures[0]).ndim == 3


def test_reference_entries_cite_sources():
    assert cases.FIG13_A_OVER_R[0.02].rel_error(cases.SEMISPHERE_BY_H[0.02].a_over_r) == pytest.approx(-4.47e-5, rel=1e-2)
    for ref in (*cases.SEC43.values(), *cases.SEC6.values(), cases.SLOPE_ROJEK, cases.SLOPE_ARGENTO_BOUVARD):
        assert "Rojek" in ref.source and ref.value > 0
    # the printed model value of Sec. 6 follows from eq. (43)/(45) and the printed neck
    a = cases.SEC6["a"].value
    assert 1.064 * 394 * np.pi * a / 2 == pytest.approx(cases.SEC6["K_model"].value, abs=1e-6)
