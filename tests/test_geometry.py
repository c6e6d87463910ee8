"""Neck geometry against the paper's numbers, closed forms, independent root finds and its invariants."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from fem_neck import coble_radius, max_overlap, neck_geometry, neck_radius, overlap_for_neck
from fem_neck.geometry import equal_neck_radius
from verification.cases import SEC6, SEC43, SEMISPHERE

MM = 1e-3


# --- Rojek 2022, Section 4.3 and Section 6 (6-digit values printed in the paper) -------------------------------
@pytest.mark.parametrize(
    "h, method, expected",
    [
        (0.2 * MM, "newton", SEC43["newton"].value),
        (0.2 * MM, "coble", SEC43["coble"].value),
        (0.2 * MM, "first", SEC43["first"].value),
        (0.06 * MM, "newton", SEC6["a"].value),
    ],
)
def test_paper_section_4_3(h, method, expected):
    assert neck_radius(1 * MM, 3 * MM, h, method=method) == pytest.approx(expected, abs=0.6e-6 * MM)


@pytest.mark.parametrize(
    "h_over_r, a_over_r",  # verification.cases.SEMISPHERE (from eqs 19-20 to 12 digits)
    [(row.h_over_r, row.a_over_r) for row in SEMISPHERE],
)
def test_equal_spheres_reference_table(h_over_r, a_over_r):
    assert neck_radius(1.0, 1.0, h_over_r) == pytest.approx(a_over_r, rel=1e-11)
    assert equal_neck_radius(1.0, h_over_r) == pytest.approx(a_over_r, rel=1e-11)


def test_equal_radii_newton_matches_closed_form_to_round_off():
    r = np.geomspace(1e-6, 1.0, 50)
    h = np.outer(r, np.concatenate([np.geomspace(1e-9, 0.5, 40), [0.6, 0.66, 2.0 / 3.0]])).ravel()
    r = np.repeat(r, 43)
    a_newton = neck_radius(r, r, h)
    a_closed = equal_neck_radius(r, h)
    assert np.max(np.abs(a_newton / a_closed - 1.0)) < 8 * np.finfo(float).eps


def test_equal_spheres_range_ends_at_two_thirds_r():
    assert max_overlap(2.0, 2.0) == pytest.approx(4.0 / 3.0, rel=1e-15)
    assert neck_radius(2.0, 2.0, 4.0 / 3.0) == pytest.approx(2.0, rel=1e-12)
    with pytest.raises(ValueError, match=r"h = 1\.4.*0 < h <= 1\.333"):
        neck_radius(2.0, 2.0, 1.4)


def _z_raw(a, r_i, r_j, h):
    """Rojek 2022 eq. (27) exactly as printed, with eqs. (24), (28), (29)."""
    h_ci = r_i - np.sqrt(r_i**2 - a**2)
    h_cj = r_j - np.sqrt(r_j**2 - a**2)
    h_n = h_ci + h_cj - h
    return 3 * a**2 * h_n - h_cj**2 * (3 * r_j - h_cj) - h_ci**2 * (3 * r_i - h_ci)


def test_independent_root_find_random_cases():
    """Brent's method on the raw eq. (27), bracketed away from the trivial root a = 0."""
    rng = np.random.default_rng(20221)
    r_i = rng.uniform(0.5, 2.0, 300)
    r_j = r_i * rng.uniform(1.0, 10.0, 300)
    a_true = np.minimum(r_i, r_j) * rng.uniform(0.05, 0.9, 300)
    h = overlap_for_neck(r_i, r_j, a_true)
    a = neck_radius(r_i, r_j, h)
    for k in range(len(a)):
        ri, rj, hk = r_i[k], r_j[k], h[k]
        r_min = min(ri, rj)
        # Z < 0 while the neck length h_n(a) <= 0; the non-trivial root lies between that point and r_min
        lo = brentq(lambda x: ri - np.sqrt(ri**2 - x**2) + rj - np.sqrt(rj**2 - x**2) - hk, 1e-12 * r_min, r_min)
        ref = brentq(_z_raw, lo, r_min, args=(ri, rj, hk), xtol=1e-15, rtol=4 * np.finfo(float).eps)
        assert a[k] == pytest.approx(ref, rel=1e-9)
        assert a[k] == pytest.approx(a_true[k], rel=1e-12)


def test_vectorised_equals_scalar_calls_and_scalar_returns_float():
    r_i = np.array([1.0, 2.0, 0.3])
    r_j = np.array([3.0, 2.0, 3.0])
    h = np.array([0.2, 0.5, 0.01])
    a = neck_radius(r_i, r_j, h)
    assert isinstance(neck_radius(1.0, 3.0, 0.2), float)
    assert [neck_radius(*args) for args in zip(r_i, r_j, h)] == pytest.approx(list(a), rel=1e-15)


def test_full_geometry_is_consistent():
    g = neck_geometry(1 * MM, 3 * MM, 0.2 * MM)
    assert g.z_i + g.h_n + g.z_j == pytest.approx(g.d, rel=1e-14)
    assert g.d == pytest.approx(3.8 * MM)
    assert g.h_n == pytest.approx(g.h_ci + g.h_cj - g.h, rel=1e-14)  # eq. (24)
    assert g.r_i**2 == pytest.approx(g.a**2 + (g.r_i - g.h_ci) ** 2, rel=1e-14)  # eq. (25)
    v_cyl = np.pi * g.a**2 * g.h_n
    v_caps = np.pi * (g.h_ci**2 * (g.r_i - g.h_ci / 3) + g.h_cj**2 * (g.r_j - g.h_cj / 3))
    assert abs(v_cyl - v_caps) / v_cyl < 1e-13  # eq. (22)
    assert g.volume_residual < 1e-14
    assert 1 <= g.iterations <= 10


@pytest.mark.parametrize(
    "args, match",
    [
        ((-1.0, 1.0, 0.1), r"r_i = -1: must be finite and > 0"),
        ((1.0, np.nan, 0.1), r"r_j = nan"),
        ((1.0, 1.0, 0.0), r"h = 0: valid range 0 < h <= 0\.666"),
        ((1.0, 3.0, 0.7), r"h = 0\.7: valid range"),
        ((np.array([1.0, 1.0]), 1.0, np.array([0.1, -0.1])), r"h\[1\] = -0\.1"),
        ((1.0, np.inf, 0.1), r"r_j = inf"),
    ],
)
def test_bad_input_names_parameter_and_range(args, match):
    with pytest.raises(ValueError, match=match):
        neck_radius(*args)


def test_unknown_method_rejected():
    with pytest.raises(ValueError, match="method = 'exact'"):
        neck_radius(1.0, 1.0, 0.1, method="exact")


# --- properties --------------------------------------------------------------------------------------------
radius = st.floats(min_value=1e-6, max_value=1e-1)
ratio = st.floats(min_value=1.0, max_value=100.0)
fraction = st.floats(min_value=1e-8, max_value=1.0)


@st.composite
def pairs(draw):
    r_i = draw(radius)
    r_j = r_i * draw(ratio)
    if draw(st.booleans()):
        r_i, r_j = r_j, r_i
    h = draw(fraction) * float(max_overlap(r_i, r_j))
    return r_i, r_j, h


@settings(max_examples=300, deadline=None)
@given(pairs())
def test_volume_conserved_and_neck_below_smaller_radius(pair):
    g = neck_geometry(*pair)
    assert g.volume_residual < 1e-12
    assert 0 < g.a <= min(pair[0], pair[1])
    assert g.h_n >= 0


@settings(max_examples=300, deadline=None)
@given(pairs(), st.floats(min_value=0.01, max_value=0.99))
def test_neck_grows_with_overlap(pair, shrink):
    r_i, r_j, h = pair
    assert neck_radius(r_i, r_j, shrink * h) < neck_radius(r_i, r_j, h)


@settings(max_examples=300, deadline=None)
@given(pairs())
def test_coble_and_first_iterate_over_estimate_the_volume_conserving_neck(pair):
    a = neck_radius(*pair)
    assert coble_radius(*pair) >= a * (1 - 1e-14)
    assert neck_radius(*pair, method="first") >= a * (1 - 1e-14)
    assert neck_radius(*pair, method="first") <= max(coble_radius(*pair), min(pair[0], pair[1])) * (1 + 1e-14)


@settings(max_examples=200, deadline=None)
@given(pairs(), st.floats(min_value=1e-3, max_value=1e3))
def test_symmetric_in_the_two_radii_and_scale_free(pair, scale):
    r_i, r_j, h = pair
    a = neck_radius(r_i, r_j, h)
    assert neck_radius(r_j, r_i, h) == pytest.approx(a, rel=1e-13)
    assert neck_radius(scale * r_i, scale * r_j, scale * h) == pytest.approx(scale * a, rel=1e-13)


@settings(max_examples=200, deadline=None)
@given(pairs())
def test_overlap_for_neck_inverts_neck_radius(pair):
    r_i, r_j, h = pair
    assert overlap_for_neck(r_i, r_j, neck_radius(r_i, r_j, h)) == pytest.approx(h, rel=1e-12)


def test_bracketing_fallback_converges_from_a_start_left_of_the_root(monkeypatch):
    """Were the start ever left of the root where Z' <= 0 (Z < 0 too), Newton restarts from the smaller radius and
    never diverges."""
    import fem_neck.geometry as geometry

    r_i = np.full(5, 1.0)
    r_j = np.array([1.0, 2.0, 3.0, 10.0, 100.0])
    h = 0.5 * max_overlap(r_i, r_j)
    expected = neck_radius(r_i, r_j, h)
    monkeypatch.setattr(geometry, "newton_start", lambda r_i, r_j, h, h_max: 1e-3 * np.sqrt(h))
    g = neck_geometry(r_i, r_j, h)
    assert np.allclose(g.a, expected, rtol=1e-13, atol=0)
    assert np.all(g.volume_residual < 1e-12)


def test_large_arrays_solved_in_blocks_match_small_calls():
    """neck_radius of > _CHUNK bonds runs block by block: same roots as the unblocked solve (to round-off), the
    broadcast shape kept, and a bad entry named by its index in the whole input."""
    from fem_neck import geometry

    rng = np.random.default_rng(5)
    r_j = 1e-3 * rng.uniform(1.0, 10.0, (300, 100))  # 30 000 bonds against one r_i: broadcast
    h = max_overlap(1e-3, r_j) * rng.uniform(1e-6, 1.0, r_j.shape)
    a = neck_radius(1e-3, r_j, h)
    assert a.shape == (300, 100) and r_j.size > geometry._CHUNK
    rows = np.concatenate([neck_radius(1e-3, r_j[k:k + 10], h[k:k + 10]).ravel() for k in range(0, 300, 10)])
    assert np.max(np.abs(a.ravel() - rows) / rows) <= 4 * np.finfo(float).eps
    h_bad = h.copy()
    h_bad[250, 7] = -1.0
    with pytest.raises(ValueError, match=r"h\[25007\]"):
        neck_radius(1e-3, r_j, h_bad)


def test_compiled_blocks_are_the_numpy_blocks_to_the_bit(monkeypatch):
    """From ``_COMPILED_MIN`` bonds on, neck_radius runs its blocks compiled on numba's threads: the numpy route's radii
    to the bit (radius ratios 1 to 1e120, overlaps from 1e-12 of the range to its end, blocks of mixed bonds), on one
    thread or two, and a bad entry still named by its index in the whole input."""
    import numba

    from fem_neck import geometry

    rng = np.random.default_rng(11)
    m = 3 * geometry._CHUNK + 1234
    r_i = 1e-4 * rng.uniform(0.5, 2.0, m)
    r_j = r_i * np.where(rng.random(m) < 0.9, rng.uniform(0.2, 5.0, m), 10.0 ** rng.uniform(-120, 120, m))
    h = max_overlap(r_i, r_j) * np.where(rng.random(m) < 0.5, rng.uniform(1e-12, 1.0, m), 1.0)
    numpy_route = neck_radius(r_i, r_j, h)
    monkeypatch.setattr(geometry, "_COMPILED_MIN", geometry._CHUNK)
    threads = numba.get_num_threads()
    try:
        for n in {1, min(2, numba.config.NUMBA_NUM_THREADS)}:
            numba.set_num_threads(n)
            assert np.array_equal(neck_radius(r_i, r_j, h), numpy_route)
    finally:
        numba.set_num_threads(threads)
    k = np.arange(m) == 40000
    for args, named in (((r_i, r_j, np.where(k, 2.0 * h, h)), r"h\[40000\]"),
                        ((r_i, r_j, np.where(k, np.nan, h)), r"h\[40000\]"),
                        ((np.where(k, -1.0, r_i), r_j, h), r"r_i\[40000\]")):
        with pytest.raises(ValueError, match=named):
            neck_radius(*args)


@pytest.mark.parametrize("ratio", [1.0, 1.5, 3.0, 10.0, 1e3, 1e8])
def test_newton_start_is_close_and_newton_needs_few_iterations(ratio):
    """The start (a cubic model of G in a^2, exact at both ends of the range) is within 1.5 % of the root over the
    whole range, so Newton stops after at most 4 iterations (Coble's start, off by up to 10 %, needs 6)."""
    from fem_neck import geometry

    h = max_overlap(1.0, ratio) * np.geomspace(1e-9, 1.0, 2000)
    ri, rj = np.ones_like(h), np.full_like(h, ratio)
    a = neck_radius(ri, rj, h)
    start = geometry.newton_start(ri, rj, h, float(max_overlap(1.0, ratio)))
    assert np.max(np.abs(start / a - 1.0)) < 0.015
    assert neck_geometry(ri, rj, h).iterations <= 4
