"""The shared-body law on the union of spheres: half bodies narrowed to the cut sphere (dem.laws.cut_body), the
necks' factors with the cap on the mean of each particle's tensor, and necks hidden inside a third sphere."""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from dem import make_scene, run
from dem.geometry.periodic import PeriodicBox
from dem.laws.conductance import ConductanceSpec
from dem.laws.cut_body import cut_body_resistance
from fem_neck.lattice import BASIS, EDGE_OVER_SPACING, union_max_h_over_r

AXES = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=float)


def sc_slender_difference(l: float) -> float:
    """kappa Delta R of the SC cell's half body (unit sphere cut at +-l across x and y), by quad: the section is the
    disk of radius rho = sqrt(1 - z^2) less four segments rho^2 acos(l / rho) - l sqrt(rho^2 - l^2) (rho < l sqrt 2),
    dA/drho = 2 pi rho - 8 rho acos(l / rho)."""
    def integrand(z):
        rho = math.sqrt(1.0 - z * z)
        cut = rho > l
        seg = rho * rho * math.acos(l / rho) - l * math.sqrt(rho * rho - l * l) if cut else 0.0
        area = math.pi * rho * rho - 4.0 * seg
        d_area = (2.0 * math.pi * rho - (8.0 * rho * math.acos(l / rho) if cut else 0.0)) * (-z / rho)
        slope_c = d_area / (2.0 * math.sqrt(math.pi * area))  # d sqrt(A / pi) / dz
        slope_b = -z / rho
        return (1.0 + 0.5 * slope_c**2) / area - (1.0 + 0.5 * slope_b**2) / (math.pi * rho * rho)
    return quad(integrand, 0.0, l, points=[math.sqrt(1.0 - l * l)], limit=200, epsabs=1e-14)[0]


@pytest.mark.parametrize("h", [0.1, 0.3, 0.5])
def test_cut_body_resistance_of_the_simple_cubic_cell_against_quadrature(h):
    l = 1.0 - h / 2.0
    exact = sc_slender_difference(l)
    errors = [abs(cut_body_resistance(np.ones(1), np.zeros(6, dtype=int), AXES, np.full(6, l), samples=n) / exact - 1)
              for n in (32, 128)]
    assert np.max(errors[0]) < 1e-2 and np.max(errors[1]) < 1e-3  # the default grid, and a grid four times finer:
    assert np.max(errors[1]) < np.max(errors[0]) / 10  # second order


def test_no_other_plane_across_the_half_body_adds_nothing():
    """A chain: the middle sphere's two necks are opposite, neither plane crosses the other's half body; a lone
    neck (a pair) has no other plane at all."""
    dR = cut_body_resistance(np.ones(3), np.array([1, 1, 0, 2]), AXES[[0, 1, 0, 1]], np.full(4, 0.9))
    assert dR.tolist() == [0.0, 0.0, 0.0, 0.0]


def test_the_cut_body_never_resists_less_than_the_ball():
    """Removing material never lowers a body's resistance (Rayleigh's monotonicity). A BCC particle at h/r = 0.27: its
    six second neighbours' planes lie near the surface, where the ball's profile steepens without bound and the cut's,
    clipped by the eight first neighbours' planes, does not: the slender expansion's slope term alone would make
    those half bodies resist less than the ball's (-0.015 / kappa r). They get no correction, the first neighbours'
    ends a positive one."""
    h = 0.27
    first = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) / math.sqrt(3)
    second = np.vstack([np.eye(3), -np.eye(3)])
    planes = np.r_[np.full(8, (2 - h) / 2), np.full(6, (2 - h) / math.sqrt(3))]
    dR = cut_body_resistance(np.ones(1), np.zeros(14, dtype=int), np.vstack([first, second]), planes)
    assert np.all(dR[:8] > 0) and dR[8:].tolist() == [0.0] * 6


def test_a_neck_inside_a_third_sphere_is_no_neck_and_carries_nothing():
    """Spheres 0 and 1 overlap, but their lens lies inside the big sphere 2 between them: the union has no face
    between 0 and 1, and its bond gets K = 0 while the others carry the heat."""
    x = np.array([[-0.9, 0.0, 0.0], [0.9, 0.0, 0.0], [0.0, 0.0, 0.3]]) * 1e-3
    radius = np.array([1.0, 1.0, 1.2]) * 1e-3
    scene = make_scene(x, radius, [1.0, 0.0, 0.5], fixed=[True, True, False], mode="steady",
                       conductance=ConductanceSpec(law="shared-body", neck="union"))
    engine = run(scene).engine
    pairs = list(zip(engine.bonds.i.tolist(), engine.bonds.j.tolist()))
    K = dict(zip(pairs, engine.K_pairs))
    assert K[(0, 1)] == 0.0 and K[(0, 2)] > 0 and K[(1, 2)] > 0


def union_lattice(kind: str, h: float, law: str = "shared-body"):
    d = 2.0 - h
    edge = EDGE_OVER_SPACING[kind] * d * 1e-3
    x = np.asarray(BASIS[kind]) * edge + 0.1 * edge
    box = PeriodicBox(np.full(3, edge), drop=[0.0, 0.0, 1.0])
    scene = make_scene(x, np.full(len(x), 1e-3), np.zeros(len(x)), box=box, mode="steady",
                       conductance=ConductanceSpec(law=law, neck="union"))
    return run(scene).summary["effective_conductivity"] / 394.0


# Union lattices' k_eff / kappa, FE lower and upper bounds at rtol 1e-3 (python -m verification densification)
FE = {("sc", 0.3): (0.60303, 0.60335), ("sc", 0.4): (0.74196, 0.74242), ("bcc", 0.2): (0.69075, 0.69117),
      ("fcc", 0.1): (0.65161, 0.65204)}


@pytest.mark.parametrize("kind, h", list(FE))
def test_union_lattices_within_one_percent_of_their_fe_up_to_phi_085(kind, h):
    lower, upper = FE[(kind, h)]
    k = union_lattice(kind, h)
    assert lower * 0.99 < k < upper * 1.01


def test_the_cut_body_is_what_brings_the_simple_cubic_lattice_to_its_fe():
    """SC isolates the cut body (its necks' factors are 1): without the narrowing the law is +2.35 % at h/r = 0.3."""
    lower, upper = FE[("sc", 0.3)]
    assert union_lattice("sc", 0.3, law="fit") > 1.02 * upper  # the union half bodies alone
    assert union_lattice("sc", 0.3) < 1.003 * upper


@pytest.mark.parametrize("kind", ["sc", "bcc", "fcc"])
def test_never_above_the_wiener_bound_up_to_the_covering_radius(kind):
    from fem_neck.lattice import lattice_cell

    for h in np.linspace(0.05, 0.98 * union_max_h_over_r(kind), 6):
        assert union_lattice(kind, float(h)) <= lattice_cell(kind, float(h), neck="union").phi * (1 + 1e-12)
