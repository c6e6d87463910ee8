"""FE conductance of sintered necks against reference numbers, identities and independent solves.

Reference values: ``verification.cases`` -- the semisphere table (independent hp-FE, 12 digits) and the
flux-tube constriction (Rohsenow et al. 1998).
"""

import math
import pickle

import numpy as np
import pytest

from fem_neck import conduction, shapes
from fem_neck.geometry import equal_neck_radius

from verification.cases import FLUX_TUBE_CONSTRICTION
from verification.cases import SEMISPHERE as REFERENCE  # (h/r, a/r, K/K_cyl)


@pytest.mark.parametrize("h_over_r, a_ref, k_ref", REFERENCE)
def test_semisphere_reference_default_tolerance(h_over_r, a_ref, k_ref):
    a = float(equal_neck_radius(1.0, h_over_r))
    assert a == pytest.approx(a_ref, rel=1e-11)
    res = conduction.semisphere_conductance(a)
    err = abs(res.K_over_Kcyl - k_ref) / k_ref
    assert res.converged and res.error_estimate <= 1e-4
    assert err <= 3.0 * res.error_estimate
    assert err <= 3e-4
    assert res.K == pytest.approx(math.pi * res.K_over_Kcyl, rel=1e-15)  # r = 1, kappa = 1


def test_semisphere_reaches_1e_minus_6():
    h_over_r, a, k_ref = REFERENCE[0]
    res = conduction.semisphere_conductance(a, rtol=1e-6)
    assert res.error_estimate <= 1e-6
    assert abs(res.K_over_Kcyl - k_ref) / k_ref <= 1e-6


@pytest.mark.parametrize("order, rtol", [(2, 1e-3), (3, 3e-4)])
def test_estimate_is_honest_for_each_order(order, rtol):
    """The estimate of a loose gmsh-path solve must cover its true error (within 3x), a/r = 0.61 reference."""
    _, a, k_ref = REFERENCE[2]
    res = conduction.semisphere_conductance(a, rtol=rtol, order=order, method="gmsh")
    assert res.order == order
    assert abs(res.K_over_Kcyl - k_ref) / k_ref <= 3.0 * res.error_estimate


@pytest.mark.parametrize("a_over_r", [0.001, 0.03, 0.3, 0.95])
def test_estimate_is_honest_against_fine_solve(a_over_r):
    fine = conduction.semisphere_conductance(a_over_r, rtol=1e-7)
    res = conduction.semisphere_conductance(a_over_r)
    assert res.error_estimate <= 1e-4
    assert abs(res.K - fine.K) / fine.K <= 3.0 * res.error_estimate + fine.error_estimate


def test_small_neck_tends_to_constriction_limit():
    """K -> 4 kappa a (isothermal disk on a half-space) as a/r -> 0; the leading correction is O(a/r)."""
    a = 0.01
    res = conduction.semisphere_conductance(a)
    assert 0.97 < res.K / (4.0 * a) < 1.0


def _facet_flux(profile, sol, boundary):
    """Q = 2 pi int kappa grad(T).n x ds on straight (affine) facets."""
    import skfem
    from skfem.helpers import dot, grad

    fb = skfem.FacetBasis(profile.mesh, sol.basis.elem, facets=profile.mesh.boundaries[boundary], intorder=8)

    @skfem.Functional
    def flux(w):
        return dot(grad(w["u"]), w.n) * w.x[0]

    return 2.0 * math.pi * flux.assemble(fb, u=fb.interpolate(sol.u))


def test_reaction_matches_facet_flux_and_energy():
    """Straight-sided mesh, so the facet normals are exact; measured: top 3e-6, bottom 1.3e-3 at grading 0.15."""
    profile = shapes.semisphere_mesh(0.4, grading=0.15)
    sol = conduction.solve_profile(profile, order=3, curved=False)
    top = _facet_flux(profile, sol, "top")
    bottom = _facet_flux(profile, sol, "bottom")
    assert top == pytest.approx(sol.K_reaction, rel=1e-5)
    # the equatorial disk's rim meets the inscribed (straight-sided) sphere: its flux converges only like h^2
    assert -bottom == pytest.approx(sol.K_reaction, rel=3e-3)
    energy = 2.0 * math.pi * float(sol.u @ (sol.matrix @ sol.u))
    assert energy == pytest.approx(sol.K_reaction, rel=1e-10)


def test_semisphere_volume_is_the_hemisphere():
    """Volume conservation of the neck model: the half body's volume is exactly 2 pi r^3 / 3."""
    import skfem

    profile = shapes.semisphere_mesh(0.5, grading=0.3)
    assert profile.volume == pytest.approx(2.0 * math.pi / 3.0, rel=1e-13)
    basis = skfem.Basis(shapes.curved_mesh(profile), skfem.ElementTriP2())

    @skfem.Functional
    def ring(w):
        return w.x[0]

    # quadratic boundary: O(h^4) deficit (measured -4.9e-6); the straight-sided mesh misses 7e-3
    assert 2.0 * math.pi * ring.assemble(basis) == pytest.approx(profile.volume, rel=2e-5)
    straight = skfem.Basis(profile.mesh, skfem.ElementTriP1())
    assert 2.0 * math.pi * ring.assemble(straight) < profile.volume * (1.0 - 1e-3)


def test_meshing_is_deterministic():
    first = shapes.semisphere_mesh(0.3)
    second = shapes.semisphere_mesh(0.3)
    assert np.array_equal(first.mesh.p, second.mesh.p) and np.array_equal(first.mesh.t, second.mesh.t)
    assert conduction.solve_profile(first, 3).K == conduction.solve_profile(second, 3).K


def test_symmetric_pair_is_half_the_semisphere_and_the_chain_of_two():
    h = 0.08
    a = float(equal_neck_radius(1.0, h))
    semi = conduction.semisphere_conductance(a)
    pair = conduction.pair_conductance(1.0, 1.0, h, 1.0)
    chain = conduction.chain_conductance([1.0, 1.0], [h], 1.0)
    assert pair.necks[0] == pytest.approx(a, rel=1e-12)
    assert pair.K == pytest.approx(semi.K / 2.0, rel=2.0 * (semi.error_estimate + pair.error_estimate))
    assert chain.K == pytest.approx(pair.K, rel=chain.error_estimate + pair.error_estimate)  # hp pair, gmsh chain
    assert chain.K == conduction.pair_conductance(1.0, 1.0, h, 1.0, method="gmsh").K  # the gmsh pair is the chain


def test_conductance_scales_with_length_and_kappa():
    small = conduction.pair_conductance(1e-3, 3e-3, 0.06e-3, 394.0)
    unit = conduction.pair_conductance(1.0, 3.0, 0.06, 1.0)
    assert small.K == pytest.approx(394.0 * 1e-3 * unit.K, rel=1e-12)


@pytest.mark.slow
def test_chain_of_three_is_two_bonds_in_series_with_a_shared_middle():
    """A symmetric chain r,r,r with equal overlaps: by symmetry the middle equator is isothermal, so the chain's
    resistance is exactly twice that of the pair."""
    pair = conduction.pair_conductance(1.0, 1.0, 0.05, 1.0)
    chain = conduction.chain_conductance([1.0, 1.0, 1.0], [0.05, 0.05], 1.0)
    assert chain.K == pytest.approx(pair.K / 2.0, rel=2.0 * (pair.error_estimate + chain.error_estimate))


def test_flux_tube_constriction():
    """Isothermal disk a = 1 into an insulated tube b = 2 (kappa = 1): extra resistance ~0.0849 K/W
    (:data:`verification.cases.FLUX_TUBE_CONSTRICTION`, Rohsenow et al. 1998 correlation, ~0.1 %). The disturbance decays like exp(-3.83 z / b): L = 3b suffices."""
    length = 6.0
    profile = shapes.profile_mesh((1.0, 0.0), [("line", (2.0, 0.0), "annulus"), ("line", (2.0, length), "wall")],
                                  [[1.0, 0.0]], sizes=shapes.SizeField(grading=0.3))
    sol = conduction.solve_profile(profile, order=3)
    extra = 1.0 / sol.K - length / (math.pi * 2.0**2)
    assert extra == pytest.approx(FLUX_TUBE_CONSTRICTION.value, rel=2e-3)


def test_result_pickles_without_the_field():
    res = conduction.semisphere_conductance(0.5, rtol=1e-3)
    back = pickle.loads(pickle.dumps(res))
    assert back.K == res.K and back.solution is None and res.solution is not None


@pytest.mark.parametrize("call", [
    lambda: conduction.semisphere_conductance(0.0),
    lambda: conduction.semisphere_conductance(1.0),
    lambda: conduction.semisphere_conductance(float("nan")),
    lambda: conduction.semisphere_conductance(0.5, rtol=-1.0),
    lambda: conduction.semisphere_conductance(0.5, order=12),
    lambda: conduction.semisphere_conductance(0.5, order=7, method="gmsh"),
    lambda: conduction.semisphere_conductance(0.5, method="fem"),
    lambda: conduction.pair_conductance(-1.0, 1.0, 0.1, 1.0),
    lambda: conduction.pair_conductance(1.0, 1.0, 0.7, 1.0),
    lambda: conduction.chain_conductance([1.0, 1.0, 1.0], [0.1], 1.0),
    lambda: conduction.chain_conductance([1.0, 1.0], [0.1], 0.0),
])
def test_bad_input_raises_value_error(call):
    with pytest.raises(ValueError):
        call()


@pytest.mark.slow
@pytest.mark.parametrize("rtol", [1e-3, 1e-4, 1e-5])
def test_estimate_is_honest_over_the_range(rtol):
    """Sweep a/r over 1e-3 .. 0.97 at several tolerances against solves to 1e-7."""
    for a_over_r in (1e-3, 0.01, 0.05, 0.1, 0.2, 0.4, 0.6, 0.8, 0.9, 0.97):
        fine = conduction.semisphere_conductance(a_over_r, rtol=1e-7)
        res = conduction.semisphere_conductance(a_over_r, rtol=rtol)
        assert res.converged and res.error_estimate <= rtol
        assert abs(res.K - fine.K) / fine.K <= 3.0 * res.error_estimate + fine.error_estimate


@pytest.mark.parametrize("overlaps, match", [
    ([1e-4, 3e-4], r"overlaps\[1\] = 0\.0003 \(radii 0\.003, 0\.0005\): valid range 0 < overlap <= 0\.000"),
    ([-1e-4, 1e-4], r"overlaps\[0\] = -0\.0001"),
    ([1e-4, float("nan")], r"overlaps\[1\] = nan"),
])
def test_chain_names_the_bad_bond(overlaps, match):
    from fem_neck.conduction import chain_conductance

    with pytest.raises(ValueError, match=match):
        chain_conductance([1e-3, 3e-3, 0.5e-3], overlaps, kappa=394.0)
