"""The exact flux element of a cut sphere (verification.neck_element) against the closed form (the uncut ball whose
two polar caps are uniform-flux faces, its resistance between them from the Legendre series), and the network of
such elements (verification.neck_node_bound): its bordering, its hook into dem.network.necks, and the study."""

import numpy as np
import pytest

from verification import neck_element as E


@pytest.mark.parametrize("alpha, tolerance", [(0.3, 1e-3), (0.7, 2e-4)])
def test_two_caps_against_the_legendre_series(alpha, tolerance):
    pytest.importorskip("ngsolve")
    res = E.cap_ball(alpha)
    R = res["R"][0.0]
    assert R[0, 1] == pytest.approx(R[1, 0], rel=1e-12)
    between = R[0, 0] + R[1, 1] - 2 * R[0, 1]
    exact = E.cap_ball_exact(alpha)
    # Galerkin's discrete energy is above the exact minimum: the FE's resistance is below the series', and close
    assert 0.0 < 1.0 - between / exact < tolerance
    assert res["volume"] == pytest.approx(4.0 / 3.0 * np.pi, rel=1e-4)


@pytest.mark.parametrize("kwargs, word", [({"arms": [1.2]}, "arms"), ({"betas": (0.5,)}, "beta"),
                                          ({"maxh": 0.0}, "maxh"), ({"order": 0}, "order"),
                                          ({"normals": [[0.0, 0.0, 2.0]]}, "normals")])
def test_bad_input_is_one_line_naming_the_parameter(kwargs, word):
    args = {"normals": [[0.0, 0.0, 1.0]], "arms": [0.9], **kwargs}
    with pytest.raises(ValueError, match=word) as err:
        E.cut_element(**args)
    assert "\n" not in str(err.value)


def test_the_bordered_element_holds_r_between_any_two_necks():
    """The element's resistance between necks b and c (the centre floating) is R_bb + R_cc - 2 R_bc; its rows sum
    to zero."""
    from verification.neck_node_bound import bordered

    rng = np.random.default_rng(3)
    A = rng.normal(size=(4, 4))
    R = A @ A.T + 4 * np.eye(4)
    E4 = bordered(R)
    assert np.allclose(E4.sum(axis=1), 0.0, atol=1e-12) and np.allclose(E4, E4.T)
    for b, c in ((0, 1), (2, 3), (1, 3)):
        inflow = np.zeros(5)
        inflow[b], inflow[c] = 1.0, -1.0
        T = np.linalg.lstsq(E4, inflow, rcond=None)[0]
        assert T[b] - T[c] == pytest.approx(R[b, b] + R[c, c] - 2 * R[b, c], rel=1e-10)


def test_the_elements_hook_gives_every_fcc_particle_its_twelve_planes(monkeypatch):
    """Stub elements R = rho 1 on an FCC cell: each particle sees its 12 <110> planes at 1 - h/2, and the network is
    the pipe network of bond conductance G = kappa r / (2 rho), k_eff = 4 G / L (24 bonds per cubic cell, sum of
    d_z^2 = 4 L^2)."""
    from fem_neck import lattice
    from verification.lattices import dem_periodic
    from verification.neck_node_bound import ExactElements

    h, rho = 0.2, 0.37
    seen = []

    def stub(self, normals, arms, beta):
        seen.append((np.array(normals), np.array(arms)))
        return rho * np.eye(len(arms))

    monkeypatch.setattr(ExactElements, "resistance", stub)
    cell = lattice.lattice_cell("fcc", h, neck="union")
    k = dem_periodic(cell, "shared-body", neck="union", nodes="necks", elements=ExactElements((0.0,), {}).builder(0.0))
    assert len(seen) == cell.n == 4
    directions = {tuple(v) for v in np.round(np.sqrt(2) * seen[0][0], 9) + 0.0}
    for normals, arms in seen:
        assert np.allclose(arms, 1 - h / 2)
        assert {tuple(v) for v in np.round(np.sqrt(2) * normals, 9) + 0.0} == directions
    assert len(directions) == 12 and all(sorted(np.abs(d)) == [0.0, 1.0, 1.0] for d in directions)
    assert k == pytest.approx(4 * (1.0 / (2 * rho)) / cell.period[2], rel=1e-10)


@pytest.mark.slow
def test_the_quick_study_finds_the_bounds_below_the_fe(tmp_path):
    pytest.importorskip("ngsolve")
    import json

    from verification import neck_node_bound as S
    from verification.report import check_section_result

    res = check_section_result("neck_node_bound", S.run(tmp_path, quick=True))
    assert all(measured <= limit for _, measured, limit in res["targets"])
    (row,) = json.loads((tmp_path / "neck_node_bound.json").read_text())
    for beta, k in row["bound"].items():
        assert k < row["fe"]["lower"]
        assert row["coarse"][beta] > k  # Galerkin: the coarser element conducts more
