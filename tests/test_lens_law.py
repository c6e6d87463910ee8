"""The compiled zohdi lens law on a Verlet list (dem.laws.lens_conductance.lens_list_conductances) is the law of
find_bonds + bond_conductances on the touching pairs, with the out_of_range policies as find_bonds has them."""

import numpy as np
import pytest

from dem.geometry.bonds import find_bonds
from dem.geometry.particles import Particles
from dem.geometry.walls import Wall, WallArrays
from dem.laws.conductance import ConductanceSpec, bond_conductances
from dem.laws.lens_conductance import LENS_POLICY, lens_list_conductances

# unequal spheres: (0, 1) with the small centre inside the large sphere's cap (a lens out of range), (2, 3) a valid
# lens, 4 alone on the wall; 0 touches the wall too; the other listed pairs are apart
X = np.array([[0.0, 0.0, 0.0], [0.8, 0.0, 0.0], [0.0, 5.0, 0.0], [1.2, 5.0, 0.0], [0.0, 10.0, 0.0]])
R = np.array([1.0, 0.4, 1.0, 0.5, 0.3])
KAPPA = np.array([100.0, 50.0, 100.0, 20.0, 10.0])
PI, PJ = np.triu_indices(5, 1)
WALL = Wall("floor", [0.0, 0.0, -0.2], [0.0, 0.0, 1.0], 400.0)


def listed(policy, kc=None):
    K, K_w = np.empty(len(PI)), np.empty(5)
    bad = lens_list_conductances(X, R, KAPPA, np.inf if kc is None else kc, LENS_POLICY[policy],
                                 (PI.astype(np.int64), PJ.astype(np.int64)), WallArrays.build([WALL], 3),
                                 (np.arange(5, dtype=np.int64), np.zeros(5, dtype=np.int64)), K, K_w, np.zeros(3))
    return bad, K, K_w


def on_bonds(policy, kc=None):
    p = Particles.from_arrays(X, R, np.zeros(5))
    b = find_bonds(p, [WALL], "lens", policy)
    spec = ConductanceSpec(law="zohdi", out_of_range=policy, contact_conductance=kc)
    return b, *bond_conductances(spec, p, b, conductivity=KAPPA)


@pytest.mark.parametrize("policy", ["clip", "drop"])
@pytest.mark.parametrize("kc", [None, 3.0])
def test_listed_law_is_the_bonds_law(policy, kc):
    bad, K, K_w = listed(policy, kc)
    b, K_b, K_wb = on_bonds(policy, kc)
    assert bad == 0
    touching = K > 0.0
    assert touching.sum() == b.n_pairs == (2 if policy == "clip" else 1)
    assert np.array_equal(PI[touching], b.i) and np.array_equal(PJ[touching], b.j)
    assert np.allclose(K[touching], K_b, rtol=1e-13, atol=0.0)
    assert np.array_equal(np.flatnonzero(K_w), b.wall_particle) and np.allclose(K_w[K_w > 0], K_wb, rtol=1e-13)


def test_lens_out_of_range_is_left_to_find_bonds_to_name():
    bad, K, _ = listed("error")
    assert bad == 1 and K[0] == 0.0 and K[np.flatnonzero((PI == 2) & (PJ == 3))[0]] > 0.0
    with pytest.raises(ValueError, match="out_of_range"):
        on_bonds("error")
