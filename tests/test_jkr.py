"""The JKR adhesive contact law (dem.laws.contact.jkr) against Johnson-Kendall-Roberts's closed forms, through its
kernels and through the engine: the force-overlap curve, the pull-off force 3/2 pi w R*, the contact persisting beyond
touching until it breaks at 3/4 (pi^2 w^2 R*/E*^2)^(1/3), the speed needed to part an adhered pair (the energy of the
JKR curve), energy conservation, a sphere hanging from a ceiling, and bad input."""

import copy
import math

import numpy as np
import pytest
from numba import njit
from scipy.optimize import brentq, minimize_scalar

from dem.driver import run
from dem.engines.verlet.engine import VerletEngine
from dem.laws.contact import jkr, law_module
from dem.laws.contact.adhesion import jkr as adhesion
from dem.laws.contact.binding import ContactLaw, forget_pair, reach
from dem.scene import parse_scene, state_file
from test_hertz_mindlin import (DENSITY, E_STAR, MATERIAL, contact, head_on, law_pair, run_recording, scene_doc,
                                sphere_mass)

# This module's tests compile the JKR law's own kernels and force loop (numba takes 10-30 s for them in a fresh
# clone), so it runs with the slow tests; the quick run moves particles under the default law, Luding's.
pytestmark = pytest.mark.slow

W = 0.1  # J/m^2, the work of adhesion
R = 1e-3
C = math.sqrt(2 * math.pi * W / E_STAR)


def jkr_contact(**changes):
    return contact("jkr", **{"work_of_adhesion": W, **changes})


def overlap(a, r_eff):
    """``delta = a^2/R* - sqrt(2 pi w a/E*)`` (Johnson 1985, Sec. 5.5)."""
    return a * a / r_eff - C * math.sqrt(a)


def force(a, r_eff):
    """``F = 4 E* a^3/(3 R*) - sqrt(8 pi w E* a^3)`` (Johnson 1985, Sec. 5.5)."""
    return 4 * E_STAR * a**3 / (3 * r_eff) - math.sqrt(8 * math.pi * W * E_STAR * a**3)


def energy(a, r_eff):
    """The elastic and surface energy along the curve, ``U`` with ``dU/d delta = F``: ``E* (8 a^5/(15 R*^2) - 4 c
    a^(7/2)/(3 R*) + c^2 a^2/2)``, ``c = sqrt(2 pi w/E*)`` (F d delta/da integrated in a)."""
    return E_STAR * (8 * a**5 / (15 * r_eff**2) - 4 * C * a**3.5 / (3 * r_eff) + C * C * a * a / 2)


def radii(r_eff):
    """``a_0`` (zero force) and ``a_c = a_0/6^(2/3)`` (the break, d delta/da = 0)."""
    a0 = (9 * math.pi * W * r_eff**2 / (2 * E_STAR)) ** (1 / 3)
    return a0, a0 / 6 ** (2 / 3)


def _force_at(params, delta, r1=R, r2=2 * R, vn=0.0, hist=None, vr=(0.0, 0.0, 0.0)):
    state = np.array([[sphere_mass(r1)], [sphere_mass(r2)]])
    hist_in = np.zeros((1, 4)) if hist is None else np.array([hist], dtype=float)
    out_hist = np.zeros_like(hist_in)
    out = law_pair("jkr", params, hist_in, out_hist, state, delta, (1.0, 0.0, 0.0), vr, vn, r1, r2, 1e-7)
    return out, out_hist[0]


@pytest.fixture(scope="module")
def params():
    return jkr.JKRMaterial(**MATERIAL, density=DENSITY, work_of_adhesion=W).params()


# ------------------------------------------------------------------------------------------ kernels
def test_force_overlap_curve_is_jkrs(params):
    r_eff = 2 * R / 3
    a0, a_c = radii(r_eff)
    for a in np.concatenate([np.linspace(1.05 * a_c, a0, 7), np.geomspace(a0, 200 * a0, 7)]):
        (f_n, *_), _ = _force_at(params, overlap(a, r_eff))
        assert f_n == pytest.approx(force(a, r_eff), rel=1e-9, abs=1e-12 * force(a0 * 2, r_eff))
    assert adhesion.contact_radius(overlap(3 * a0, r_eff), r_eff, C) == pytest.approx(3 * a0, rel=1e-13)
    # zero force at delta_0 = a_0^2/(3 R*); far in, Hertz: a -> sqrt(R* delta)
    assert _force_at(params, a0 * a0 / (3 * r_eff))[0][0] == pytest.approx(0.0, abs=1e-12 * force(2 * a0, r_eff))
    delta = 1e4 * a0 * a0 / r_eff
    assert adhesion.contact_radius(delta, r_eff, C) / math.sqrt(r_eff * delta) == pytest.approx(1.0, abs=0.02)


def test_pull_off_force_is_three_halves_pi_w_r_star(params):
    r_eff = 2 * R / 3
    pulloff = 0.75 * (math.pi**2 * W**2 * r_eff / E_STAR**2) ** (1 / 3)
    best = minimize_scalar(lambda d: _force_at(params, d)[0][0], bounds=(-pulloff, 0.0), method="bounded",
                           options={"xatol": 1e-6 * pulloff})
    p_c = 1.5 * math.pi * W * r_eff
    assert best.fun == pytest.approx(-p_c, rel=1e-9)
    a_min = (9 * math.pi * W * r_eff**2 / (8 * E_STAR)) ** (1 / 3)  # where the pull is largest
    assert best.x == pytest.approx(-a_min**2 / (3 * r_eff), rel=1e-4)
    assert _force_at(params, 0.0)[0][0] == pytest.approx(-8 / 9 * p_c, rel=1e-12)  # snap-in at touching
    assert _force_at(params, -pulloff)[0][0] == pytest.approx(-5 / 9 * p_c, rel=1e-6)  # at the break


def test_the_contact_reaches_beyond_touching_to_the_pull_off_distance_once_it_touched(params):
    r_eff = 2 * R / 3
    pulloff = 0.75 * (math.pi**2 * W**2 * r_eff / E_STAR**2) ** (1 / 3)
    assert pulloff == pytest.approx(3 * radii(r_eff)[1] ** 2 / r_eff, rel=1e-12)  # -delta_c = 3 a_c^2/R*
    hist = np.zeros((1, 4))
    law = ContactLaw("jkr")
    assert _reach(law, hist) == 0.0  # not yet touched: no force at a distance
    _, written = _force_at(params, 1e-8)
    assert _reach(law, written[None, :]) == pytest.approx(pulloff, rel=1e-14)
    out = np.zeros((1, 4))
    assert _forget(law, written[None, :], out) and not out.any()
    material = jkr.JKRMaterial(**MATERIAL, density=DENSITY, work_of_adhesion=W)
    assert law_module("jkr").largest_reach(material, np.array([R, 2 * R])) == pytest.approx(
        material.pulloff_distance(2 * R), rel=1e-14)


@njit
def _reach(law, hist):
    return reach(law, 0, hist, R, 2 * R, ())


@njit
def _forget(law, hist_in, hist):
    return forget_pair(law, 0, hist_in, hist)


def test_friction_limit_adds_twice_the_pull_off_force(params):
    """Thornton & Yin 1991: sliding at ``mu (F_el + 2 P_c)``; in tension the contact still resists sliding."""
    r_eff = 2 * R / 3
    a0, _ = radii(r_eff)
    (f_n, *ft), _ = _force_at(params, 0.0, vr=(0.0, 1.0, 0.0), hist=(0.0, 1e-3, 0.0, 1e-7))
    assert f_n < 0
    assert np.linalg.norm(ft) == pytest.approx(MATERIAL["mu"] * (f_n + 3 * math.pi * W * r_eff), rel=1e-12)


# ------------------------------------------------------------------------------------------ through the engine
def adhered_doc(speed, dt_per_period=400, t_end=2e-3):
    """Two spheres of radius R at rest in contact at the zero-force overlap delta_0, pulled apart at the relative
    speed ``speed`` (momentum zero), undamped; the step a ``dt_per_period``-th of the contact's small oscillation."""
    r_eff = R / 2
    a0, _ = radii(r_eff)
    delta0 = a0 * a0 / (3 * r_eff)
    period = 2 * math.pi * math.sqrt(sphere_mass(R) / 2 / (2 * E_STAR * a0))
    return scene_doc([[0, 0, 0], [2 * R - delta0, 0, 0]], [R, R], [[-speed / 2, 0, 0], [speed / 2, 0, 0]],
                     jkr_contact(restitution=1.0), t_end=t_end, dt=period / dt_per_period)


def adhered_pair(speed, dt_per_period=400, t_end=2e-3):
    """The pair of :func:`adhered_doc` as a simulation, its R*, a_0 and delta_0."""
    r_eff = R / 2
    a0, _ = radii(r_eff)
    return VerletEngine(parse_scene(adhered_doc(speed, dt_per_period, t_end))), r_eff, a0, a0 * a0 / (3 * r_eff)


def _work_to_part(r_eff):
    """The energy that parts an adhered pair from rest at delta_0: ``U(a_c) - U(a_0)``."""
    a0, a_c = radii(r_eff)
    return energy(a_c, r_eff) - energy(a0, r_eff)


def test_energy_of_the_jkr_curve_is_its_force_integrated():
    r_eff = R / 2
    a0, a_c = radii(r_eff)
    for a in (1.2 * a_c, a0, 4 * a0):  # dU/d delta = F
        h = 1e-6 * a
        slope = (energy(a + h, r_eff) - energy(a - h, r_eff)) / (overlap(a + h, r_eff) - overlap(a - h, r_eff))
        assert slope == pytest.approx(force(a, r_eff), rel=1e-6)


def test_a_pair_parts_above_the_speed_the_jkr_curve_demands_and_stays_below_it():
    """From rest at delta_0, the pair parts iff ``1/2 m* v^2 > U(a_c) - U(a_0)``; it then flies apart at
    ``v_f = sqrt(v^2 - 2 W/m*)``, and the contact broke at delta_c, beyond touching."""
    r_eff, m_eff = R / 2, sphere_mass(R) / 2
    threshold = math.sqrt(2 * _work_to_part(r_eff) / m_eff)
    speed = 1.5 * threshold
    sim, _, _, _ = adhered_pair(speed)
    rec = run_recording(sim, 3000)
    d = rec["x"][:, 1, 0] - rec["x"][:, 0, 0]
    acting = rec["fn"][:, 0] != 0.0
    assert acting[0] and not acting[-1]
    last = np.flatnonzero(acting)[-1]
    pulloff = 0.75 * (math.pi**2 * W**2 * r_eff / E_STAR**2) ** (1 / 3)
    assert 2 * R - d[last] > -pulloff and 2 * R - d[last + 1] <= -pulloff  # broke at delta_c, after touching
    assert d[last] > 2 * R  # beyond touching
    v = rec["v"][-1, 1, 0] - rec["v"][-1, 0, 0]
    assert v == pytest.approx(math.sqrt(speed**2 - threshold**2), rel=2e-4)
    for factor, parts in ((1.02, True), (0.98, False)):  # 2 % either side of the threshold
        near, _, _, _ = adhered_pair(factor * threshold)
        near.run()
        assert (near.mechanics.pair_column("pulloff")[0] == 0.0) == parts
        assert (near.mechanics.p_fn[0] == 0.0) == parts


def test_energy_is_conserved_while_adhered_without_damping():
    r_eff, m_eff = R / 2, sphere_mass(R) / 2
    speed = 0.9 * math.sqrt(2 * _work_to_part(r_eff) / m_eff)
    sim, _, a0, _ = adhered_pair(speed)
    rec = run_recording(sim, 3000)
    total = []
    for x, v in zip(rec["x"], rec["v"]):
        delta = 2 * R - (x[1, 0] - x[0, 0])
        a = adhesion.contact_radius(delta, r_eff, C)
        total.append(0.5 * m_eff * (v[1, 0] - v[0, 0]) ** 2 + energy(a, r_eff))
    total = np.array(total) - energy(a0, r_eff)
    assert np.ptp(total) < 1e-4 * total[0]  # velocity Verlet: O(dt^2)
    assert np.all(rec["fn"][:, 0] != 0.0)


def test_a_run_continued_from_its_state_keeps_a_stretched_contact_and_ends_as_the_uninterrupted_run(tmp_path):
    """Saved while the contact is stretched beyond touching (the pull-off distance is in the pair's history, which
    the state carries), the continued run ends bit for bit where the uninterrupted run ends."""
    speed = 1.5 * math.sqrt(2 * _work_to_part(R / 2) / (sphere_mass(R) / 2))
    doc = adhered_doc(speed)
    dt = doc["solver"]["dt"]
    first, rest = 60, 140  # 60 steps: 0.12 um beyond touching, still pulling; the contact breaks at step ~75
    run(parse_scene({**doc, "solver": {**doc["solver"], "t_end": first * dt}}), out=tmp_path / "first")
    saved = state_file.load(tmp_path / "first" / "state.npz")
    assert 2 * R - (saved["x"][1, 0] - saved["x"][0, 0]) < 0 and saved["p_hist"][0, 3] > 0
    continued = {k: v for k, v in doc.items() if k != "particles"}
    continued.update(start={"state": str(tmp_path / "first" / "state.npz")},
                     solver={**doc["solver"], "t_end": (first + rest) * dt})  # the clock goes on from the state
    run(parse_scene(continued), out=tmp_path / "continued")
    run(parse_scene({**doc, "solver": {**doc["solver"], "t_end": (first + rest) * dt}}), out=tmp_path / "whole")
    a, b = (state_file.load(tmp_path / name / "state.npz") for name in ("continued", "whole"))
    assert np.array_equal(a["x"], b["x"]) and np.array_equal(a["v"], b["v"])
    assert b["p_hist"][0, 3] == 0.0 and b["x"][1, 0] - b["x"][0, 0] > 2 * R + 4e-7  # it did break, later


def test_weak_adhesion_rebounds_with_the_materials_restitution():
    sim = head_on(contact("jkr", restitution=0.5, work_of_adhesion=1e-7), 2.0)
    sim.run()
    v = sim.mechanics.state.v
    assert (v[1, 0] - v[0, 0]) / 2.0 == pytest.approx(0.5, abs=1e-3)


@pytest.mark.parametrize("load, stays", [(0.98, True), (1.02, False)])
def test_a_sphere_hangs_from_a_ceiling_while_its_weight_is_below_the_pull_off_force(load, stays):
    """A ceiling of the material holds a sphere (R* = its radius) whose weight is below ``3/2 pi w R``: it hangs at
    the overlap where the JKR force carries its weight (negative: beyond touching); a sphere 2 % heavier falls."""
    p_c = 1.5 * math.pi * W * R
    g = load * p_c / sphere_mass(R)
    a_min = (9 * math.pi * W * R**2 / (8 * E_STAR)) ** (1 / 3)
    a0 = radii(R)[0]
    weight = min(load, 1.0) * p_c
    a = brentq(lambda a: force(a, R) + weight, a_min, a0, xtol=1e-15)  # the stable branch under load
    delta = overlap(a, R)
    doc = scene_doc([[0, 0, -(R - delta)]], [R], contact=jkr_contact(restitution=0.3), t_end=0.01,
                    walls=[{"name": "ceiling", "point": [0, 0, 0], "normal": [0, 0, -1]}],
                    gravity={"acceleration": [0.0, 0.0, -g]})
    sim = VerletEngine(parse_scene(doc))
    sim.mechanics.w_hist[0, 0, 3] = jkr.JKRMaterial(**MATERIAL, density=DENSITY, work_of_adhesion=W).pulloff_distance(R)
    sim.run()
    z = sim.mechanics.state.x[0, 2]
    if stays:
        assert delta < 0 and z == pytest.approx(-(R - delta), rel=1e-6)
        assert sim.mechanics.w_fn[0, 0] == pytest.approx(-sphere_mass(R) * g, rel=1e-6)
    else:
        assert z < -2 * R  # fell
        assert sim.mechanics.w_hist[0, 0, 3] == 0.0


def test_a_skin_below_the_pull_off_distance_is_refused():
    doc = scene_doc([[0, 0, 0], [2.1e-3, 0, 0]], [R, R], contact=jkr_contact())
    doc["solver"]["skin"] = 1e-8
    with pytest.raises(ValueError, match=r"\[solver\] skin = 1e-08 m: must exceed .* pull-off distance"):
        VerletEngine(parse_scene(doc))


@pytest.mark.parametrize("value, message", [(0.0, "must be > 0"), (-1.0, "must be > 0"),
                                            (float("inf"), "must be a finite number")])
def test_bad_work_of_adhesion_is_refused_naming_it(value, message):
    doc = copy.deepcopy(scene_doc([[0, 0, 0], [2.1e-3, 0, 0]], [R, R], contact=jkr_contact(work_of_adhesion=value)))
    with pytest.raises(ValueError, match=rf"\[contact\] work_of_adhesion = {value!r}: {message}"):
        parse_scene(doc)
