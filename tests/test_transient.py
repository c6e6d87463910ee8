"""Transient axisymmetric FE of the insulated pair (fem_neck.transient): conservation, equilibrium, decay rate."""

import numpy as np
import pytest

from fem_neck.transient import first_decay_rate, lumped_pair, pair_mesh, solve_transient, time_grid
from verification.cases import SEMISPHERE_BY_H

KAPPA, RHO, C = 394.0, 8960.0, 385.0  # copper
R_I, R_J, H = 1e-3, 3e-3, 0.06e-3  # Rojek 2022, Sec. 6


@pytest.fixture(scope="module")
def pair():
    pm = pair_mesh(R_I, R_J, H, size_max=0.15)
    tau = RHO * C * R_J**2 / KAPPA  # internal diffusion time of the large sphere, ~0.08 s
    res = solve_transient(pm, KAPPA, RHO, C, 1.0, 0.0, time_grid(12 * tau, 1e-6 * tau, 0.04 * tau, 4))
    return pm, res


@pytest.mark.slow
def test_mesh_volume_and_split(pair):
    pm, res = pair
    # each particle owns 4/3 pi r^3 (neck split by cap volume); straight-sided triangles inscribe the circles
    assert np.allclose(res.C / (RHO * C), 4 / 3 * np.pi * np.array([R_I**3, R_J**3]), rtol=1e-2)
    assert pm.volume_exact == pytest.approx(4 / 3 * np.pi * (R_I**3 + R_J**3), rel=1e-14)
    assert float(pm.geometry.z_i) < pm.z_split < float(pm.geometry.z_i + pm.geometry.h_n)


@pytest.mark.slow
def test_energy_is_conserved(pair):
    _, res = pair
    stored = res.T_mean @ res.C  # sum_i C_i Tbar_i: insulated, so constant
    assert np.ptp(stored) / stored[0] < 1e-9
    assert np.ptp(res.energy) / res.energy[0] < 1e-9


def test_late_time_equilibrium_and_maximum_principle(pair):
    _, res = pair
    T_eq = res.C[0] * res.T_mean[0, 0] / res.C.sum() + res.C[1] * res.T_mean[0, 1] / res.C.sum()
    assert res.T_mean[-1] == pytest.approx([T_eq, T_eq], abs=1e-8)
    # monotone approach (Crank-Nicolson leaves ringing at round-off level near equilibrium only)
    assert np.all(np.diff(res.T_mean[:, 0]) <= 1e-8) and np.all(np.diff(res.T_mean[:, 1]) >= -1e-8)


def test_time_stepping_decays_at_the_first_eigenvalue(pair):
    # independent: the generalized eigenproblem (A, M) against the slope of log(dT) from the time integration
    pm, res = pair
    lam1 = first_decay_rate(pm, KAPPA, RHO, C)
    dT = res.T_mean[:, 0] - res.T_mean[:, 1]
    sel = (dT < 1e-2) & (dT > 1e-5)
    slope = -np.polyfit(res.t[sel], np.log(dT[sel]), 1)[0]
    assert slope == pytest.approx(lam1, rel=2e-2)


def test_small_neck_tends_to_the_lumped_model():
    # Equal spheres, reference semisphere rows (verification.cases): K_pair = f kappa pi r / 2.
    # The lumped decay rate K (1/C_i + 1/C_j) and the FE's lambda_1 differ by O(a/r) (the pipe K is defined
    # between equatorial disks, the lumped one between particle means): the gap must shrink with the neck.
    gaps = []
    for h_over_r, f in ((hr, SEMISPHERE_BY_H[hr].K_over_Kcyl) for hr in (0.02, 0.2)):
        pm = pair_mesh(1.0, 1.0, h_over_r, size_max=0.15)
        lam_lumped = f * np.pi / 2 * 2 / (4 / 3 * np.pi)
        gaps.append(first_decay_rate(pm, 1.0, 1.0, 1.0) / lam_lumped - 1)
    assert 0 < gaps[0] < gaps[1] < 0.3
    assert gaps[0] < 0.1


def test_lumped_pair_closed_form():
    t = np.linspace(0, 5, 11)
    T = lumped_pair(t, 1.0, 0.0, 2.0, 3.0, 0.7)
    assert np.allclose(T @ [2.0, 3.0], 2.0)  # energy
    assert np.allclose(T[:, 0] - T[:, 1], np.exp(-0.7 * (1 / 2 + 1 / 3) * t))
