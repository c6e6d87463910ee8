"""The half body of the union of spheres (``neck = "union"``: the sphere from its equator to the plane of the neck
circle, no neck cylinder) against its exact volume, its closed-form limits and the independent triangle path."""

import math

import numpy as np
import pytest

from fem_neck import accuracy, conduction, hpmesh, shapes, spectral

SWEEP = np.concatenate([np.geomspace(1e-4, 0.1, 7), np.linspace(0.15, 0.95, 17), [0.59999, 0.60001, 0.99, 0.999]])


@pytest.mark.parametrize("a", SWEEP)
def test_mesh_is_valid_and_exact_in_volume(a):
    """Positive Jacobians, the body's exact volume (the sphere between z = 0 and z_i, nothing above), and the
    isothermal end disk is the cap base: every vertex at z_i lies on the disk x <= a."""
    for levels in (0, 6):
        mesh, shape = hpmesh.semisphere_quad_mesh(a, levels, neck="union")
        assert shape.t == 0.0
        volume, det_min = spectral.measure(mesh, order=6)
        assert det_min > 0.0
        z_i = math.sqrt(1.0 - a * a)
        assert volume == pytest.approx(math.pi * (z_i - z_i**3 / 3.0), rel=1e-13)
        top = hpmesh.end_disks(mesh, shape)[1.0]
        assert np.all(mesh.points[top, 0] <= a) and np.any(mesh.points[top, 0] == 0.0)


def test_corner_exponent_of_the_mixed_corner():
    """The isothermal disk meets the insulated sphere at the interior angle pi/2 + arccos(a/r): lambda = pi/(2 omega),
    the disk's rim on a half-space (1/2) for a vanishing neck, no singularity (1) at a = r."""
    x = np.array([0.0, 0.5, 1.0])
    omega = 0.5 * np.pi + np.arccos(x)
    assert accuracy.corner_exponent(x, "union") == pytest.approx(np.pi / (2.0 * omega), rel=1e-14)
    assert accuracy.corner_exponent(x, "union") == pytest.approx([0.5, 0.6, 1.0], rel=1e-14)
    assert accuracy.corner_exponent(x) == pytest.approx([2 / 3, 0.75, 1.0], rel=1e-14)  # the cylinder's, unchanged
    assert accuracy.hp_corner_levels(1e-3, 1e-4, neck="union") > accuracy.hp_corner_levels(1e-3, 1e-4)
    with pytest.raises(ValueError, match="neck"):
        accuracy.corner_exponent(0.5, "cone")


@pytest.mark.parametrize("a", [1e-3, 0.05, 0.3, 0.6, 0.61, 0.9, 0.99])
@pytest.mark.slow
def test_converges_at_the_requested_tolerance(a):
    """The graded hp mesh with the levels chosen for the union's corner meets rtol = 1e-4 against a 1e-8 solve."""
    reference = conduction.semisphere_conductance(a, rtol=1e-8, neck="union")
    assert reference.converged
    res = conduction.semisphere_conductance(a, rtol=1e-4, neck="union")
    assert res.converged and res.error_estimate <= 1e-4
    assert abs(res.K_over_Kcyl / reference.K_over_Kcyl - 1.0) <= 1e-4


@pytest.mark.parametrize("a", [1e-3, 0.3, 0.9])
@pytest.mark.slow
def test_hp_agrees_with_the_triangle_path(a):
    hp = conduction.semisphere_conductance(a, rtol=1e-6, neck="union")
    tri = conduction.semisphere_conductance(a, rtol=1e-4, method="gmsh", neck="union")
    assert tri.converged
    assert tri.K_over_Kcyl == pytest.approx(hp.K_over_Kcyl, rel=1e-4)
    assert shapes.semisphere_profile(a, neck="union")[3] == []  # no neck cylinder in the profile


def test_small_neck_is_the_constriction_limit_with_the_balls_log():
    """K -> 4 kappa a with the first correction of the sphere: 1/f = pi/(4x) (1 + x ln(1/x)/pi + O(x)). The log's
    coefficient, fitted to FE between a/r = 3e-4 and 3e-3, is 1/pi (the ball's Neumann function), not the
    cylinder's 5/(4 pi) (which adds the thin half neck's 1/(4 pi))."""
    x = np.array([3e-4, 1e-3, 3e-3])
    f = np.array([conduction.semisphere_conductance(xi, rtol=1e-8, neck="union").K_over_Kcyl for xi in x])
    p = 4.0 * x / (np.pi * f)  # P(x) = (1/f) / (pi/(4x))
    assert np.all(np.abs(p - 1.0) < 0.006)  # the constriction limit 4 kappa a
    assert np.all(np.abs(p - 1.0 - x * np.log(1.0 / x) / np.pi) < 0.01 * x)  # ... with the log, to O(x)
    coef, *_ = np.linalg.lstsq(np.stack([np.log(1.0 / x), np.ones_like(x)], axis=1), (p - 1.0) / x, rcond=None)
    assert coef[0] == pytest.approx(1.0 / np.pi, abs=2e-3)
    assert abs(coef[0] - 5.0 / (4.0 * np.pi)) > 0.07


def test_thin_disk_limit_is_the_one_dimensional_slab():
    """As a/r -> 1 the half body is a slab of thickness s = z_i/r between the equator and the neck's disk: its 1-D
    resistance with the cross-section pi (r^2 - z^2), int_0^z_i dz / (kappa pi (r^2 - z^2)) = atanh(s)/(kappa pi r),
    is the exact limit, 1/f = atanh(s) + O(s^4) (the sphere's tilt from the vertical is O(s) in a rim strip of width
    O(s)); the plain slab, s, misses the area's change, O(s^3)."""
    x = np.array([0.97, 0.99, 0.995, 0.999])
    s = np.sqrt(1.0 - x * x)
    f = np.array([conduction.semisphere_conductance(xi, rtol=1e-8, neck="union").K_over_Kcyl for xi in x])
    gap = 1.0 / f - np.arctanh(s)
    assert np.all(gap > 0.0)  # the 1-D flux is the one of least resistance in the exact cross-sections
    assert np.all(gap < 0.2 * s**4)
    assert np.all(np.abs(1.0 / (f * s) - 1.0) < 0.4 * s * s)  # 1/f -> s
