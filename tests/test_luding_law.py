"""The Luding 2005 sintering contact law (dem.laws.contact.luding and its sub-models): every branch against closed forms written out here.

The kernels are numba-compiled with ``cache=True``: the first run of this file compiles them (about 10 s cold on
2 cores); later runs load the cache.
"""

import math
from dataclasses import replace
from typing import NamedTuple

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq as _brentq

from dem.laws.contact import luding
from dem.laws.contact.normal import luding as luding_normal
from dem.laws.contact.state import sintering
from dem.laws.contact.tangential import luding as luding_tangential
from dem.laws.contact.luding import LUDING_TABLE1 as MAT

P = MAT.params()
K1, K2, KC = MAT.k1, MAT.k2, MAT.kc
A = 1e-3                     # radius of an equal pair (Table 1: a0 = 1 mm)
DF = MAT.fluid_overlap * A   # delta_fluid = phi * 2 R_eff = phi * a
DMF = K2 * DF / (K2 - K1)    # delta_max^fluid (text above eq. 7)


def brentq(fun, a, b):
    """A root to full double precision (scipy's default xtol is 2e-12 absolute: far too loose for overlaps)."""
    return _brentq(fun, a, b, xtol=1e-300, rtol=4 * np.finfo(float).eps)


def k2_hand(dmax):
    """Eq. (7) written out."""
    return K2 if dmax >= DMF else K1 + (K2 - K1) * dmax / DMF


class Normal(NamedTuple):
    f: float
    delta_max: float
    delta_0: float
    f_min: float
    k2: float
    kc: float


def normal(*args):
    """normal_force with its results by name (indices in the order f, delta_max, delta_0, f_min, k2, kc)."""
    f, delta_max, fmin, k2, kc, d0 = luding_normal.normal_force(*args)
    return Normal(f, delta_max, d0, fmin, k2, kc)


def drive(deltas, s=1.0, s_last=None, dmax=0.0, params=P, df=DF, rates=None):
    """Run normal_force through a list of overlaps at factor ``s`` (list or scalar); return the per-step tuples."""
    out = []
    s_list = s if isinstance(s, (list, tuple)) else [s] * len(deltas)
    prev = s_list[0] if s_last is None else s_last
    for k, d in enumerate(deltas):
        res = normal(d, 0.0 if rates is None else rates[k], s_list[k], dmax, prev, df, params)
        dmax, prev = res[1], s_list[k]
        out.append(res)
    return out


# ------------------------------------------------------------------------------------------ material
def test_table1_material_and_params_layout():
    p = MAT.params()
    assert p.shape == (luding.N_PARAMS,) and p.dtype == np.float64
    assert p[luding.P_K2] == 2e5 and p[luding.P_K1] / p[luding.P_K2] == 0.5 and p[luding.P_KC] / p[luding.P_K2] == 0.5
    assert p[luding.P_KT_RATIO] == 0.2 and p[luding.P_GAMMA_N] == 0.2 and p[luding.P_GAMMA_T] == 0.05
    assert p[luding.P_MU] == 0.5 and p[luding.P_MU_WALL] == 0.0 and p[luding.P_T_MELT] == 120 and p[luding.P_T_VAR] == 10
    assert p[luding.P_EXPANSION] == 1e-4 and p[luding.P_FLUID_OVERLAP] == 0.2 and p[luding.P_T0] == 1e3
    assert p[luding.P_BRITTLE_SLIDING] == 1.0 and p[luding.P_DENSITY] == 2000
    assert p[luding.P_WALL_SINTERING] == 0.0  # the walls of Sec. 4 keep the cold law


def test_a_contact_table_may_leave_out_wall_sintering_and_then_walls_sinter():
    from dataclasses import asdict

    from dem.laws.fields import material_from_table

    table = {k: v for k, v in asdict(MAT).items() if k != "wall_sintering"}
    assert material_from_table(luding.LudingMaterial, "luding", table).wall_sintering is True
    assert material_from_table(luding.LudingMaterial, "luding", {**table, "wall_sintering": False}) == MAT
    with pytest.raises(ValueError, match=r"\[contact\] k2: required"):
        material_from_table(luding.LudingMaterial, "luding", {k: v for k, v in table.items() if k != "k2"})


@pytest.mark.parametrize("field, value, words", [
    ("k1", 3e5, ["k1", "3", "<= k2"]),
    ("k2", -1.0, ["k2", "-1.0", "> 0"]),
    ("kc", -1.0, ["kc", ">= 0"]),
    ("kt_ratio", -0.1, ["kt_ratio", ">= 0"]),
    ("gamma_n", float("nan"), ["gamma_n", "finite"]),
    ("mu", -0.5, ["mu", ">= 0"]),
    ("T_var", 0.0, ["T_var", "> 0"]),
    ("expansion", -1e-4, ["expansion", ">= 0"]),
    ("fluid_overlap", 1.0, ["fluid_overlap", "(0, 1)"]),
    ("fluid_overlap", 0.0, ["fluid_overlap", "(0, 1)"]),
    ("t0", 0.0, ["t0", "> 0"]),
    ("density", -2000.0, ["density", "> 0"]),
    ("brittle_sliding", 1, ["brittle_sliding", "true or false"]),
    ("wall_sintering", "no", ["wall_sintering", "true or false"]),
    ("T_melt", "hot", ["T_melt", "finite number"]),
])
def test_material_refuses_bad_values_naming_them(field, value, words):
    with pytest.raises(ValueError) as info:
        replace(MAT, **{field: value})
    assert all(w in str(info.value) for w in words), str(info.value)


def test_temperature_where_the_radius_vanishes_is_refused():
    assert MAT.lowest_temperature == pytest.approx(120.0 - 1e4)
    MAT.check_temperatures([20.0, 200.0])
    with pytest.raises(ValueError, match=r"T\[1\] = -10000.0.*eq. 9"):
        MAT.check_temperatures([20.0, -1e4])
    replace(MAT, expansion=0.0).check_temperatures([-1e9])


# ------------------------------------------------------------------------------------------ temperature, time
@pytest.mark.parametrize("T, printed", [(118.0, "0.6"), (122.0, "0.4"), (130.0, "0.12"), (160.0, "3e-04")])
def test_k1_factor_matches_the_papers_values(T, printed):
    """Sec. 3.3.1: T_melt = 120 °C, T_var = 10 °C gives 0.6, 0.4, 0.12 and 3e-4 (to the printed digits)."""
    s = sintering.k1_factor(T, 120.0, 10.0)
    if "e" in printed:
        assert f"{s:.0e}" == printed
    else:
        assert round(s, len(printed) - 2) == float(printed)
    assert s == pytest.approx(0.5 * (1.0 + math.tanh((120.0 - T) / 10.0)), rel=1e-14)


def test_k1_factor_stays_positive_far_above_melting():
    s = sintering.k1_factor(400.0, 120.0, 10.0)  # 1 + tanh(-28) is 0 in double precision
    assert 0.0 < s == pytest.approx(math.exp(-56.0), rel=1e-12)
    assert sintering.k1_factor(-1e4, 120.0, 10.0) == 1.0


def eq11(k0, K, t, t0):
    """Eq. (11) (heating, k0 > K) and its mirror for k0 < K: u(t) = u0/(1 + |u0| t/t0), u = 1 - k/K."""
    u0 = 1.0 - k0 / K
    if u0 < 0:
        return K * (1.0 - 1.0 / (1.0 / u0 - t / t0))  # eq. (11) as printed
    return K * (1.0 - u0 / (1.0 + u0 * t / t0))


@pytest.mark.parametrize("t0", [10.0, 0.1, 1e3])
@pytest.mark.parametrize("dt_over_t0", [1e-3, 0.1, 3.0])
@pytest.mark.parametrize("k0, K", [(1.0, 0.6), (0.3, 0.9), (1.0, 3e-4)])
def test_relax_k1_steps_reproduce_eq11(t0, dt_over_t0, k0, K):
    """Fig. 6 case (k1(T0) = 1 -> 0.6, t0 = 10 s) and others: stepping with any dt follows eq. (11) to round-off."""
    dt = dt_over_t0 * t0
    k, t = k0, 0.0
    for _ in range(200):
        k = sintering.relax_k1(k, K, dt, t0, False)
        t += dt
        assert k == pytest.approx(eq11(k0, K, t, t0), rel=1e-12, abs=1e-15)
    assert min(k0, K) <= k <= max(k0, K)


@pytest.mark.parametrize("k0, K", [(1.0, 0.6), (0.1, 0.9)])
def test_relax_k1_against_eq12_integrated_numerically(k0, K):
    """An independent solve of eq. (12) (adaptive Runge-Kutta, tight tolerances) against relax_k1 stepped at
    t0/7 and against eq. (11)."""
    from scipy.integrate import solve_ivp

    t0 = 10.0
    times = np.arange(1, 36) * t0 / 7
    sol = solve_ivp(lambda t, k: (K - k) * abs(K - k) / (K * t0), (0.0, times[-1]), [k0], t_eval=times,
                    rtol=1e-12, atol=1e-14, method="DOP853")
    k = k0
    for t, reference in zip(times, sol.y[0]):
        k = sintering.relax_k1(k, K, t0 / 7, t0, False)
        assert k == pytest.approx(reference, rel=1e-9)
        assert reference == pytest.approx(eq11(k0, K, t, t0), rel=1e-9)


def test_relax_k1_rate_is_eq12():
    """d k/dt = (K - k)|K - k|/(K t0), from the step's own change over a small dt."""
    for k, K in ((1.0, 0.6), (0.2, 0.7)):
        dt, t0 = 1e-6, 10.0
        rate = (sintering.relax_k1(k, K, dt, t0, False) - k) / dt
        assert rate == pytest.approx((K - k) * abs(K - k) / (K * t0), rel=1e-5)


def test_relax_k1_rapid_freeze_and_hot_limit():
    """Cooling with k1(T) > k1(T, t): k1(T, t) = k1(T) at once (end of Sec. 3.4); heating never jumps."""
    assert sintering.relax_k1(0.2, 0.9, 1e-9, 1e3, True) == 0.9
    assert sintering.relax_k1(0.2, 0.9, 1e-9, 1e3, False) < 0.2 + 1e-9
    assert sintering.relax_k1(0.9, 0.2, 1e-9, 1e3, True) > 0.9 - 1e-9  # cooling but K < k: eq. 12 applies
    assert sintering.relax_k1(0.9, 0.0, 1e-3, 1e3, False) == 0.0       # K -> 0: the rate 1/K diverges
    assert sintering.relax_k1(0.0, 0.0, 1e-3, 1e3, False) == 0.0


def test_radius_at_eq9():
    assert sintering.radius_at(1e-3, 80.0, 120.0, 1e-4) == pytest.approx(1e-3 * (1.0 - 1e-4 * 40.0), rel=1e-15)
    assert sintering.radius_at(1e-3, 120.0, 120.0, 1e-4) == 1e-3


def test_time_step_eq6_and_overcritical_damping():
    m = 2000.0 * math.pi * (0.5e-3) ** 2 * 6e-3  # smallest Table-1 disk, h = 6 mm
    m12 = m / 2
    omega = math.sqrt(K2 / m12 - (0.2 / (2 * m12)) ** 2)
    assert luding_normal.time_step(K2, 0.2, m12) == pytest.approx(math.pi / (50 * omega), rel=1e-14)
    with pytest.raises(ValueError, match="overcritical"):
        luding_normal.time_step(K2, 2.0 * math.sqrt(K2 * m12) * 1.0001, m12)
    with pytest.raises(ValueError, match="m_min"):
        luding_normal.time_step(K2, 0.2, 0.0)


# ------------------------------------------------------------------------------------------ eq. 7, 13, 15
def test_k2_of_delta_max_below_and_above_the_fluid_limit():
    assert luding_normal.delta_max_fluid(DF, P) == pytest.approx(DMF, rel=1e-15)
    assert DMF == pytest.approx(4e-4)  # k2/(k2 - k1) = 2 for Table 1
    for dmax in (0.0, 1e-5, 1e-4, 3.99e-4, 4e-4, 1e-3):
        assert luding_normal.k2_of_delta_max(dmax, DF, P) == pytest.approx(k2_hand(dmax), rel=1e-15)
    assert luding_normal.k2_of_delta_max(1e-4, DF, P) == pytest.approx(1.25e5)
    assert luding_normal.k2_of_delta_max(0.0, DF, P) == K1


def test_pair_delta_fluid():
    assert luding_normal.pair_delta_fluid(1e-3, 1e-3, 0.2) == pytest.approx(0.2e-3, rel=1e-15)
    assert luding_normal.pair_delta_fluid(1e-3, 3e-3, 0.2) == pytest.approx(0.2 * 2 * 0.75e-3, rel=1e-15)


@pytest.mark.parametrize("dmax", [2e-5, 1e-4, 3e-4])
def test_loading_then_unloading_gives_delta0_deltamin_fmin(dmax):
    """Cold contact loaded to delta_max: delta_0 = (1 - k1/k2) delta_max, delta_min = (k2 - k1)/(k2 + kc)
    delta_max, f_min = -kc delta_min (eq. 15), the force zero at delta_0 and on -kc delta at delta_min."""
    k2m = k2_hand(dmax)
    kcm = k2m / K2 * KC  # eq. 13 at k1(T, t) = k1
    d0 = (1 - K1 / k2m) * dmax
    dmin = (k2m - K1) / (k2m + kcm) * dmax
    fmin = -(k2m - K1) / (1 + k2m / kcm) * dmax
    path = drive(list(np.linspace(0.0, dmax, 11)[1:]))
    assert [r[0] for r in path] == pytest.approx(list(K1 * np.linspace(0.0, dmax, 11)[1:]), rel=1e-13)
    f, dm, d0_k, fmin_k, k2_k, kc_k = path[-1]
    assert (dm, k2_k) == (dmax, pytest.approx(k2m, rel=1e-14))
    assert d0_k == pytest.approx(d0, rel=1e-13) and fmin_k == pytest.approx(fmin, rel=1e-13)
    assert kc_k == pytest.approx(kcm, rel=1e-14)
    assert luding_normal.delta_0(dmax, 1.0, DF, P) == pytest.approx(d0, rel=1e-13)
    assert luding_normal.delta_min(dmax, 1.0, DF, P) == pytest.approx(dmin, rel=1e-13)
    assert luding_normal.f_min(dmax, 1.0, DF, P) == pytest.approx(fmin, rel=1e-13)
    assert luding_normal.kc_of(dmax, 0.4, DF, P) == pytest.approx(0.4 * kcm, rel=1e-14)
    # unloading on the k2 line: zero force at delta_0, f_min at delta_min, history unchanged
    for d, expected in ((0.5 * (dmax + d0), k2m * (0.5 * (dmax + d0) - d0)), (d0, 0.0), (dmin, fmin)):
        res = normal(d, 0.0, 1.0, dmax, 1.0, DF, P)
        # at delta_min the force sits on the -kc line: round-off may re-derive delta_max there (to 1e-13)
        assert res[0] == pytest.approx(expected, rel=1e-10, abs=1e-12 * K1 * dmax)
        assert res[1] == pytest.approx(dmax, rel=1e-13)


def test_normal_force_returns_its_documented_order():
    f, dm, fmin, k2m, kcm, d0 = luding_normal.normal_force(5e-5, 0.0, 1.0, 1e-4, 1.0, DF, P)
    k2h = k2_hand(1e-4)
    assert (dm, k2m, kcm) == (1e-4, pytest.approx(k2h), pytest.approx(k2h / K2 * KC))
    assert d0 == pytest.approx((1 - K1 / k2h) * 1e-4) and f == pytest.approx(k2h * (5e-5 - d0))
    assert fmin == pytest.approx(-kcm * k2h * d0 / (k2h + kcm))


def test_viscous_force_and_open_contact():
    base = normal(1e-5, 0.0, 1.0, 2e-5, 1.0, DF, P)
    moving = normal(1e-5, -0.3, 1.0, 2e-5, 1.0, DF, P)
    assert moving[0] - base[0] == pytest.approx(MAT.gamma_n * -0.3, rel=1e-12)
    assert moving[1:] == base[1:]
    opened = normal(-1e-7, 5.0, 0.7, 2e-5, 1.0, DF, P)
    assert opened[0] == 0.0 and opened[1] == 2e-5


# ------------------------------------------------------------------------------------------ tension branch
def test_tension_branch_and_reloading_from_it():
    """Unloading past delta_min holds the force on -kc(T, t, delta_max) delta; delta_0 moves to delta (1 + kc/k2)
    (kc/k2 of eq. 13 is k1(T, t) kc/(k1 k2) whatever delta_max), delta_max to the root of
    (1 - k1/k2(x)) x = delta_0; reloading follows the new k2 line up to the k1 line at the new delta_max."""
    for s in (1.0, 0.5):
        dmax = 1e-4
        d = 0.3 * luding_normal.delta_min(dmax, s, DF, P)
        f, dm, d0, fmin, k2m, kcm = normal(d, 0.0, s, dmax, s, DF, P)
        d0_hand = d * (1 + s * KC / K2)
        root = brentq(lambda x: (1 - s * K1 / k2_hand(x)) * x - d0_hand, 0.0, dmax)
        assert d0 == pytest.approx(d0_hand, rel=1e-14) and dm == pytest.approx(root, rel=1e-12)
        assert k2m == pytest.approx(k2_hand(root), rel=1e-12) and kcm == pytest.approx(s * k2_hand(root) / K2 * KC)
        assert f == pytest.approx(-kcm * d, rel=1e-12) and dm < dmax
        # reloading: on k2(dm)(delta - d0) until the k1(T, t) line at dm, then on the k1(T, t) line
        for x in np.linspace(d, dm, 7)[1:]:
            r = normal(x, 0.0, s, dm, s, DF, P)
            assert r[0] == pytest.approx(k2m * (x - d0), rel=1e-9) and r[1] == dm
        r = normal(1.2 * dm, 0.0, s, dm, s, DF, P)
        assert r[0] == pytest.approx(s * K1 * 1.2 * dm, rel=1e-12) and r[1] == 1.2 * dm


# ------------------------------------------------------------------------------------------ Fig. 5
def test_heating_keeps_delta_max_and_cooling_keeps_delta0():
    """Fig. 5: a contact loaded cold to delta_max and partly unloaded; heating (k1(T, t) 1 -> 0.4) keeps delta_max, so
    delta_0 = (1 - 0.4 k1/k2(delta_max)) delta_max; cooling back keeps that delta_0 and delta_max grows to the root of
    (1 - k1/k2(x)) x = delta_0 (a quadratic, checked against brentq); k2 follows delta_max (eq. 7)."""
    dmax = 1e-4
    k2m = k2_hand(dmax)
    d0_hot = (1 - 0.4 * K1 / k2m) * dmax
    d = 0.5 * (d0_hot + dmax)
    drive(list(np.linspace(0, dmax, 5)[1:]) + [d])
    hot = normal(d, 0.0, 0.4, dmax, 1.0, DF, P)
    assert hot[1] == dmax and hot[2] == pytest.approx(d0_hot, rel=1e-14)
    assert hot[4] == pytest.approx(k2m, rel=1e-15) and hot[5] == pytest.approx(0.4 * k2m / K2 * KC, rel=1e-14)
    assert hot[0] == pytest.approx(k2m * (d - d0_hot), rel=1e-12)
    cold = normal(d, 0.0, 1.0, hot[1], 0.4, DF, P)
    root = brentq(lambda x: (1 - K1 / k2_hand(x)) * x - d0_hot, dmax, DMF)
    assert cold[2] == pytest.approx(d0_hot, rel=1e-13) and cold[1] == pytest.approx(root, rel=1e-13)
    assert cold[1] > dmax and cold[0] == pytest.approx(k2_hand(root) * (d - d0_hot), rel=1e-12)
    # a cycle close to melting leaves a contact that looks more strongly loaded (Sec. 3.3.2): stronger attraction
    assert cold[3] < luding_normal.f_min(dmax, 1.0, DF, P)


def test_heating_at_the_old_force_free_overlap_pulls_up_to_the_cohesion_line():
    """Held at its cold force-free overlap, a heated contact finds delta_0 beyond it: the k2 line would pull harder
    than -kc(T, t, delta_max) delta allows, so the force is held on the tension branch."""
    dmax = 1e-4
    d0_cold = (1 - K1 / k2_hand(dmax)) * dmax
    f, dm, d0, fmin, k2m, kcm = normal(d0_cold, 0.0, 0.4, dmax, 1.0, DF, P)
    assert k2_hand(dmax) * (d0_cold - (1 - 0.4 * K1 / k2_hand(dmax)) * dmax) < -kcm * d0_cold
    assert f == pytest.approx(-kcm * d0_cold, rel=1e-13) and d0 == pytest.approx(d0_cold * (1 + 0.4 * KC / K2))


def test_delta_max_for_delta0_is_stable_in_both_root_forms():
    for s in (0.0, 0.3, 1.0):
        for d0 in (1e-12, 1e-7, 5e-5, 1.9e-4, 3e-4):
            x = luding_normal.delta_max_for_delta_0(d0, s, DF, P)
            residual = (1 - s * K1 / luding_normal.k2_of_delta_max(x, DF, P)) * x - d0
            assert abs(residual) <= 4e-16 * max(x, d0)
    assert luding_normal.delta_max_for_delta_0(0.0, 1.0, DF, P) == 0.0


def test_prestressed_heating_shifts_delta_max_only_after_k1_line_drops_below_the_force():
    """Sec. 3.3.1: in a pre-stressed contact delta_max moves only once k1(T) delta_max falls below the confining
    force; with the overlap held, heating only moves delta_0 (force relaxes); pushing beyond delta_max reloads
    on the hot k1(T, t) line."""
    dmax = 1e-4
    r = normal(dmax, 0.0, 0.6, dmax, 1.0, DF, P)
    assert r[1] == dmax and r[0] == pytest.approx(0.6 * K1 * dmax, rel=1e-12)
    r = normal(1.1 * dmax, 0.0, 0.6, dmax, 0.6, DF, P)
    assert r[1] == 1.1 * dmax and r[0] == pytest.approx(0.6 * K1 * 1.1 * dmax, rel=1e-12)


# ------------------------------------------------------------------------------------------ fluid branch
def test_fluid_branch_cold():
    """Loading beyond delta_max^fluid: delta_0 = delta_fluid, slope k2, delta_max frozen at delta_max^fluid."""
    path = drive([1e-4, 3e-4, 5e-4, 8e-4, 6e-4, 3e-4])
    for (f, dm, d0, fmin, k2m, kcm), d in zip(path[2:], [5e-4, 8e-4, 6e-4, 3e-4]):
        assert dm == pytest.approx(DMF, rel=1e-14) and d0 == pytest.approx(DF, rel=1e-14) and k2m == K2
        assert f == pytest.approx(K2 * (d - DF), rel=1e-12)
        assert fmin == pytest.approx(-KC * K2 * DF / (K2 + KC), rel=1e-12)
    big = normal(1e-3, 0.0, 1.0, 0.0, 1.0, DF, P)  # one step from nothing into the fluid
    assert big[1] == pytest.approx(DMF, rel=1e-14) and big[0] == pytest.approx(K2 * (1e-3 - DF), rel=1e-12)


def test_fluid_branch_hot_then_cooled():
    """Hot loading reaches delta_0 = delta_fluid at the root of (1 - s k1/k2(x)) x = delta_fluid (delta_max frozen
    there, slope k2(delta_max)); cooling keeps delta_0 = delta_fluid and brings delta_max to delta_max^fluid."""
    s = 0.5
    root = brentq(lambda x: (1 - s * K1 / k2_hand(x)) * x - DF, 0.0, DMF)
    path = drive([1e-4, 2e-4, 3e-4, 4e-4], s=s)
    f, dm, d0, *_ = path[-1]
    assert dm == pytest.approx(root, rel=1e-12) and d0 == pytest.approx(DF, rel=1e-14)
    assert f == pytest.approx(k2_hand(root) * (4e-4 - DF), rel=1e-12) and f > s * K1 * 4e-4
    cooled = normal(4e-4, 0.0, 1.0, dm, s, DF, P)
    assert cooled[1] == pytest.approx(DMF, rel=1e-12) and cooled[2] == pytest.approx(DF, rel=1e-12)
    assert cooled[0] == pytest.approx(K2 * (4e-4 - DF), rel=1e-12)
    reheated = normal(4e-4, 0.0, 0.2, cooled[1], 1.0, DF, P)  # delta_0 capped: stays fluid
    assert reheated[1] == cooled[1] and reheated[2] == DF


# ------------------------------------------------------------------------------------------ invariants
@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(1e-9, 6e-4), st.floats(0.0, 1.0)), min_size=1, max_size=40))
def test_random_histories_stay_in_the_cone(steps):
    """Any history of overlaps and factors: -kc(T, t, delta_max) delta <= f, f <= k1(T, t) delta unless on the
    fluid branch, delta_0 <= delta_fluid, delta_max >= 0 and f_min <= 0 (no damping)."""
    dmax, s_last = 0.0, steps[0][1]
    for d, s in steps:
        f, dmax, d0, fmin, k2m, kcm = normal(d, 0.0, s, dmax, s_last, DF, P)
        s_last = s
        scale = K2 * 6e-4 * 1e-12
        assert f >= -kcm * d - scale
        fluid = d0 >= DF * (1 - 1e-12)
        assert f <= s * K1 * d + scale or fluid
        assert 0.0 <= d0 <= DF and dmax >= 0.0 and fmin <= 0.0
        assert K1 <= k2m <= K2 and kcm == pytest.approx(s * k2m / K2 * KC)


# ------------------------------------------------------------------------------------------ energy
@pytest.mark.parametrize("dmax", [5e-5, 3e-4])
def test_cycle_dissipates_the_area_of_the_hysteresis_loop(dmax):
    """Without cohesion (kc = 0) and damping, a cycle 0 -> delta_max -> 0 returns along f = 0 below delta_0: the work
    done on the contact is the triangle (1/2) k1 delta_max delta_0 between the k1 and the k2 line. The path has
    grid points at the kinks (delta_max, delta_0), so the trapezoid rule is exact on its straight pieces."""
    p = replace(MAT, kc=0.0).params()
    d0 = (1 - K1 / k2_hand(dmax)) * dmax
    path = np.concatenate([np.linspace(0.0, dmax, 301), np.linspace(dmax, d0, 201)[1:],
                           np.linspace(d0, 0.0, 101)[1:]])
    res = drive(list(path[1:]), params=p)
    force = np.array([0.0] + [r[0] for r in res])
    work = float(np.sum(np.diff(path) * (force[1:] + force[:-1]) / 2.0))  # the trapezoid rule (numpy 1.26 and 2)
    assert work == pytest.approx(0.5 * K1 * dmax * d0, rel=1e-12)
    assert np.all(force[-100:] == 0.0)
    # the retreating force-free overlap drags delta_max down with it (as sqrt(delta_0): k2(x) -> k1 for small x)
    last = res[-2]
    root = brentq(lambda x: (1 - K1 / k2_hand(x)) * x - path[-2], 0.0, dmax)
    assert last[2] == pytest.approx(path[-2], rel=1e-14) and last[1] == pytest.approx(root, rel=1e-13)


# ------------------------------------------------------------------------------------------ tangential
N_Z = (0.0, 0.0, 1.0)


def test_relative_velocity_eq18_signs():
    # i above j (n = +z from j to i), i moving down onto j: approaching, delta_dot > 0
    vt, ddot = luding_tangential.relative_velocity((0.0, 0.0, -2.0), (0.0, 0.0, 0.0), (0.0,) * 3, (0.0,) * 3, 1e-3, 1e-3, N_Z)
    assert ddot == 2.0 and vt == (0.0, 0.0, 0.0)
    # rolling without slip: i spins +y, j spins -y, i moves +x with a w: contact points move together
    a, w = 1e-3, 10.0
    vt, ddot = luding_tangential.relative_velocity((a * w, 0.0, 0.0), (-a * w, 0.0, 0.0), (0.0, w, 0.0), (0.0, w, 0.0), a, a, N_Z)
    # v_ij = 2 a w x + a (z x w y) + a (z x w y) = 2aw x - 2aw x = 0
    assert vt == pytest.approx((0.0, 0.0, 0.0), abs=1e-15) and ddot == 0.0
    # spin only: the surface of i at the contact (below its centre) moves with -a w_y x ... (n x w) a
    vt, _ = luding_tangential.relative_velocity((0.0,) * 3, (0.0,) * 3, (0.0, 1.0, 0.0), (0.0,) * 3, 2.0, 0.0, N_Z)
    assert vt == pytest.approx((-2.0, 0.0, 0.0))  # a n x w = 2 (z x y) = -2 x


def test_sticking_then_sliding_at_mu_times_fn_minus_fmin():
    """Sticking: f_t = -k_t xi - gamma_t v_t, xi += v_t dt. Sliding: |f_t| = mu(T, t)(f_n - f_min) exactly,
    along the test force, and xi' (eq. 21) puts the next test force on the Coulomb limit."""
    s, f_n, fmin, k2m, dt = 0.8, 0.5, -0.2, 1.5e5, 1e-5
    kt, gt = MAT.kt_ratio * k2m, MAT.gamma_t
    f_c = s * MAT.mu * (f_n - fmin)
    xi, vt = (0.0, 0.0, 0.0), (1e-2, 0.0, 0.0)
    history = []
    for _ in range(400):
        ft, xi_new, sliding, fn_out = luding_tangential.tangential_force(xi, N_Z, vt, f_n, fmin, k2m, s, dt, P, False)
        history.append((ft, xi, sliding))
        if not sliding:
            assert ft == pytest.approx((-kt * xi[0] - gt * vt[0], 0.0, 0.0), rel=1e-14)
            assert xi_new == pytest.approx((xi[0] + vt[0] * dt, 0.0, 0.0), rel=1e-14)
        else:
            assert math.hypot(*ft) == pytest.approx(f_c, rel=1e-14) and ft[0] < 0
            assert xi_new[0] == pytest.approx(-(ft[0] + gt * vt[0]) / kt, rel=1e-14)
            nxt = luding_tangential.tangential_force(xi_new, N_Z, (0.0,) * 3, f_n, fmin, k2m, s, dt, P, False)
            assert nxt[0][0] == pytest.approx(-kt * xi_new[0], rel=1e-14)  # = f_C t + gamma_t v_t
            assert fn_out == f_n
            break
        xi = xi_new
    assert not history[0][2] and history[-1][2], "sticking first, then sliding"
    # the first sliding step: the sticking force just before was within f_C
    assert math.hypot(*history[-2][0]) <= f_c


def test_brittle_sliding_drops_cohesion_footnote5():
    s, fmin, k2m = 1.0, -0.3, 1.5e5
    big_xi = (1e-3, 0.0, 0.0)
    ft, _, sliding, fn_out = luding_tangential.tangential_force(big_xi, N_Z, (0.0,) * 3, -0.1, fmin, k2m, s, 1e-6, P, False)
    assert sliding and fn_out == 0.0 and math.hypot(*ft) == pytest.approx(MAT.mu * (-0.1 - fmin), rel=1e-14)
    p = replace(MAT, brittle_sliding=False).params()
    _, _, sliding, fn_out = luding_tangential.tangential_force(big_xi, N_Z, (0.0,) * 3, -0.1, fmin, k2m, s, 1e-6, p, False)
    assert sliding and fn_out == -0.1
    small = luding_tangential.tangential_force((1e-9, 0.0, 0.0), N_Z, (0.0,) * 3, -0.1, fmin, k2m, s, 1e-6, P, False)
    assert not small[2] and small[3] == -0.1  # sticking keeps cohesion


def test_no_tangential_force_beyond_cohesion_failure_and_wall_friction():
    out = luding_tangential.tangential_force((1e-6, 2e-6, 0.0), N_Z, (1.0, 0.0, 0.0), -0.4, -0.3, 1e5, 1.0, 1e-6, P, False)
    assert out[0] == (0.0, 0.0, 0.0) and out[1] == (0.0, 0.0, 0.0)
    # Table 1: mu_wall = 0, so a wall contact slides with no tangential force
    ft, xi, sliding, _ = luding_tangential.tangential_force((1e-6, 0.0, 0.0), N_Z, (0.0,) * 3, 1.0, 0.0, 1e5, 1.0, 1e-6, P, True)
    assert sliding and ft == (0.0, 0.0, 0.0)
    # friction follows k1(T, t) (eq. 24)
    hot = luding_tangential.tangential_force((1.0, 0.0, 0.0), N_Z, (0.0,) * 3, 1.0, 0.0, 1e5, 0.25, 1e-6, P, False)
    assert math.hypot(*hot[0]) == pytest.approx(0.25 * MAT.mu * 1.0, rel=1e-14)


def test_spring_projected_when_the_normal_rotates():
    """Eq. (16): xi loses its component along the new normal before the test force is formed."""
    theta = 0.1
    n = (math.sin(theta), 0.0, math.cos(theta))
    xi = (1e-6, 0.0, 0.0)
    ft, xi_new, sliding, _ = luding_tangential.tangential_force(xi, n, (0.0,) * 3, 10.0, 0.0, 1e5, 1.0, 1e-6, P, False)
    projected = np.array(xi) - np.array(n) * (np.array(n) @ np.array(xi))
    assert not sliding and xi_new == pytest.approx(tuple(projected), rel=1e-14, abs=1e-22)
    assert abs(np.dot(xi_new, n)) < 1e-22
    assert ft == pytest.approx(tuple(-MAT.kt_ratio * 1e5 * projected), rel=1e-14, abs=1e-20)


def test_k1_equal_k2_is_the_elastic_limit():
    """k1 = k2: no plastic deformation (delta_0 = 0, k2(delta_max) = k2, delta_max^fluid infinite) in the cold
    limit; the force is k2 delta on loading and unloading alike."""
    m = luding.LudingMaterial(**{**{f: getattr(luding.LUDING_TABLE1, f) for f in luding.LUDING_TABLE1.__dataclass_fields__},
                              "k1": 2e5, "kc": 0.0, "gamma_n": 0.0})
    p = m.params()
    s = 1.0
    dm = 0.0
    for delta in (1e-6, 3e-6, 2e-6, 0.5e-6):
        f, dm, f_min, k2m, kcm, d0 = luding_normal.normal_force(delta, 0.0, s, dm, s, 2e-4, p)
        assert f == pytest.approx(2e5 * delta, rel=1e-14) and d0 == 0.0 and k2m == 2e5 and f_min == 0.0
    assert dm == 3e-6
