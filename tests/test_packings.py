"""Random mirror packings (verification.packings): the soft energy's gradient, and valid mirror-symmetric cells."""

import numpy as np
import pytest
from scipy.optimize import check_grad

from fem_neck.lattice import check_cell, mirror_symmetry
from verification import packings


def test_energy_gradient_matches_finite_differences():
    rng = np.random.default_rng(4)
    n = 5
    r8 = np.tile(rng.uniform(0.9, 1.1, n), 8)
    period = np.full(3, 5.0)
    x = rng.uniform(0.1, 2.4, (n, 3))
    bonds = packings._bond_list(x, r8, period, 1.3)
    none = (np.zeros(0, int), np.zeros(0, int), np.zeros((0, 3), int))
    for args in ((r8, period, none, (0.0, 0.0), 0.0), (r8, period, bonds, (0.02, 0.1), 0.05)):
        flat = np.append(x.ravel(), 0.01)
        e, g = packings._energy(flat, *args)
        assert e > 0
        err = check_grad(lambda v: packings._energy(v, *args)[0], lambda v: packings._energy(v, *args)[1], flat)
        assert err < 1e-5 * np.linalg.norm(g)


def test_images_are_the_three_mirrors():
    x = np.array([[0.3, 0.7, 1.1]])
    images = packings._images(x, np.full(3, 4.0))
    assert len(images) == 8
    assert {tuple(np.round(p, 12)) for p in images} == {(a, b, c) for a in (0.3, 3.7) for b in (0.7, 3.3)
                                                         for c in (1.1, 2.9)}


@pytest.mark.slow
def test_mirror_packing_is_a_valid_symmetric_cell():
    cell = packings.mirror_packing(4, seed=0)
    assert cell.n == 32
    assert mirror_symmetry(cell)[0]
    check_cell(cell)
    i, j, _ = cell.bonds()
    assert np.bincount(np.concatenate([i, j]), minlength=cell.n).min() >= 1


@pytest.mark.slow
def test_union_packing_is_a_valid_symmetric_union_and_its_bounds_close_to_0_2_percent():
    from fem_neck import lattice
    from fem_neck.geometry.union import lens

    cell = packings.union_packing(3, 0.8, seed=0)
    assert cell.n == 24 and cell.neck == "union" and mirror_symmetry(cell)[0]
    assert abs(cell.phi - 0.8) < 0.02
    i, j, s = cell.bonds()
    d = np.linalg.norm(cell.centres[j] + s * cell.period - cell.centres[i], axis=1)
    assert np.all(lens(cell.radii[i], cell.radii[j], d).a >= 0.99 * 0.2 * np.minimum(cell.radii[i], cell.radii[j]))
    res = lattice.effective_conductivity(cell, rtol=2e-3)
    assert res.converged and res.error_estimate <= 2e-3
    assert res.k_lower_over_kappa <= res.k_eff_over_kappa < res.phi  # Wiener (a random cell need not be isotropic)
