"""verification.chains: chain geometry, the DEM side against an independent series sum, one FE-vs-DEM pair."""

import numpy as np
import pytest

from fem_neck.geometry import neck_radius
from verification import chains


@pytest.mark.parametrize("chain", chains.FULL_CHAINS, ids=lambda c: c.name)
def test_chain_geometry(chain):
    r = np.asarray(chain.radii)
    assert 2 <= len(r) <= 8 and r.max() / r.min() <= 5.0
    z = chain.positions()[:, 2]
    np.testing.assert_allclose(np.diff(z), r[:-1] + r[1:] - chain.overlaps, rtol=1e-14)
    # the overlaps give back the requested necks (volume-conserving model)
    np.testing.assert_allclose(neck_radius(r[:-1], r[1:], chain.overlaps), chain.necks, rtol=1e-9)


def test_dem_chain_is_series_of_rojek_pipes():
    # Rojek 2022, eqs. (43), (45) per bond, bonds in series: an independent closed form of the DEM steady solve
    chain = chains.Chain("t", (1e-3, 2e-3, 1.5e-3, 1e-3), (0.3, 0.5, 0.2))
    k_bond = 1.064 * chains.KAPPA * np.pi * chain.necks / 2.0
    assert chains.dem_conductance(chain, "rojek") == pytest.approx(1.0 / np.sum(1.0 / k_bond), rel=1e-10)


def test_fe_against_dem_fit_law_on_sec6_pair():
    chain = chains.QUICK_CHAINS[0]
    fe = chains.fe_conductance(chain, 1e-4)
    assert fe.error_estimate < 1e-4
    # our converged FE of Rojek's Sec. 6 pair (0.2791677 W/K, see the paper part), far from 0.278033 (Abaqus)
    assert fe.K == pytest.approx(0.2791677, rel=2e-5)
    assert chains.dem_conductance(chain, "fit") == pytest.approx(fe.K, rel=5e-3)
