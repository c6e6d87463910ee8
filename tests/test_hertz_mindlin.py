"""The Hertz-Mindlin contact law (dem.laws.contact.hertz_mindlin) against its closed forms, through its kernels and
through the engine: Hertz's force-overlap law, the peak overlap and duration of an elastic collision, the coefficient
of restitution its damping gives (Antypov & Elliott 2011), Mindlin's tangential stiffness, Coulomb sliding, energy
and momentum conservation, and bad input."""

import copy
import math
import re

import numpy as np
import pytest
from scipy.integrate import quad

from numba import njit

from dem.engines.verlet.engine import VerletEngine
from dem.laws.contact import hertz_mindlin as hm
from dem.laws.contact.binding import ContactLaw, pair_constants, pair_force, params_tuple, wall_force
from dem.laws.contact.damping import tsuji
from dem.scene import parse_scene

# This module's tests compile the Hertz-Mindlin law's own kernels and force loop (numba takes 10-30 s for them in a fresh
# clone), so it runs with the slow tests; the quick run moves particles under the default law, Luding's.
pytestmark = pytest.mark.slow

MATERIAL = {"youngs_modulus": 1.0e8, "poisson_ratio": 0.3, "restitution": 0.5, "tangential_damping": 1.0,
            "mu": 0.5, "mu_wall": 0.3}
DENSITY = 2500.0
E_STAR = MATERIAL["youngs_modulus"] / (2 * (1 - MATERIAL["poisson_ratio"] ** 2))
G_STAR = MATERIAL["youngs_modulus"] / (2 * (1 + MATERIAL["poisson_ratio"])) / (2 * (2 - MATERIAL["poisson_ratio"]))
T0, RATE = np.array([20.0]), np.zeros(1)


def contact(law="hertz_mindlin", **changes):
    return {"law": law, **MATERIAL, **changes}


def sphere_mass(r):
    return DENSITY * 4.0 / 3.0 * math.pi * r**3


def scene_doc(position, radius, velocity=None, contact=None, t_end=1e-3, dt=None, **extra):
    n = len(radius)
    doc = {"scene": {"physics": ["mechanical"]}, "material": {"density": DENSITY},
           "particles": {"position": [list(map(float, x)) for x in position], "radius": list(map(float, radius)),
                         "temperature": [20.0] * n},
           "contact": dict(contact or globals()["contact"]()), "solver": {"mode": "transient", "t_end": t_end}}
    if velocity is not None:
        doc["particles"]["velocity"] = [list(map(float, v)) for v in velocity]
    if dt is not None:
        doc["solver"]["dt"] = dt
    doc.update(extra)
    return doc


def hertz_collision(m_eff, r_eff, speed):
    """Peak overlap and duration of an elastic Hertz collision at the relative speed ``speed``: ``1/2 m* v^2 =
    8/15 E* sqrt(R*) delta_max^(5/2)``, ``t_c = 2 (delta_max/v) int_0^1 dx/sqrt(1 - x^(5/2))``."""
    delta_max = (15.0 * m_eff * speed**2 / (16.0 * E_STAR * math.sqrt(r_eff))) ** 0.4
    return delta_max, 2.0 * delta_max / speed * quad(lambda x: 1.0 / math.sqrt(1.0 - x**2.5), 0.0, 1.0)[0]


def head_on(law_contact, speed, r1=1e-3, r2=1e-3, steps=1000, dimension=3, height=None):
    """Two spheres approaching head on at the relative speed ``speed``, 1 % of r1 apart; ``steps`` steps per elastic
    contact duration; t_end: the approach and 1.5 contact durations."""
    m1, m2 = sphere_mass(r1), sphere_mass(r2)
    if dimension == 2:
        m1, m2 = DENSITY * math.pi * r1**2 * height, DENSITY * math.pi * r2**2 * height
    m_eff, r_eff = m1 * m2 / (m1 + m2), r1 * r2 / (r1 + r2)
    t_c = hertz_collision(m_eff, r_eff, speed)[1]
    gap = 0.01 * r1
    v1, v2 = speed * m2 / (m1 + m2), -speed * m1 / (m1 + m2)  # momentum zero
    doc = scene_doc([[0, 0, 0], [r1 + r2 + gap, 0, 0]], [r1, r2], [[v1, 0, 0], [v2, 0, 0]], law_contact,
                    t_end=gap / speed + 1.5 * t_c, dt=t_c / steps)
    if dimension == 2:
        doc["scene"].update(dimension=2, height=height)
    return VerletEngine(parse_scene(doc))


def run_recording(sim, n_steps=None):
    """Step one step at a time: times, positions, velocities, angular velocities, pair and wall normal forces."""
    mech = sim.mechanics
    n_steps = n_steps if n_steps is not None else math.ceil(sim.scene.solver.t_end / mech.dt - 1e-9)
    rows = {"t": [], "x": [], "v": [], "w": [], "fn": [], "w_fn": [], "w_ft": []}
    for _ in range(n_steps):
        mech.advance(1, T0, RATE)
        s = mech.state
        rows["t"].append(mech.t)
        rows["x"].append(s.x.copy())
        rows["v"].append(s.v.copy())
        rows["w"].append(s.w.copy())
        rows["fn"].append(mech.p_fn.copy() if len(mech.p_fn) else np.zeros(1))
        rows["w_fn"].append(mech.w_fn.copy())
        rows["w_ft"].append(mech.w_ft.copy())
    return {k: np.array(v) for k, v in rows.items()}


# ------------------------------------------------------------------------------------------ kernels
@njit
def _bound_pair(law, hist_in, hist, state, contact, ri, rj, dt, params):
    blocks = params_tuple(law, params)
    return pair_force(law, 0, 0, 1, hist_in, hist, state, np.zeros(2), contact, ri, rj, False, dt, blocks,
                      pair_constants(law, ri, rj, blocks))


@njit
def _bound_wall(law, hist_in, hist, state, contact, rk, dt, params):
    return wall_force(law, 0, 0, hist_in, hist, state, np.zeros(1), contact, rk, dt, params_tuple(law, params))


def law_pair(name, params, hist_in, hist, state, delta, n, vr, vn, r1, r2, dt):
    """The compiled force on i of pair 0 = (0, 1) under the law ``name`` (:mod:`dem.laws.contact.binding`)."""
    return _bound_pair(ContactLaw(name), hist_in, hist, state, (delta, r1 + r2 - delta, tuple(n), tuple(vr), vn),
                       r1, r2, dt, params)


def law_wall(name, params, hist_in, hist, state, delta, n, vr, vn, rk, dt):
    """The compiled force on particle 0 from wall 0 under the law ``name``."""
    return _bound_wall(ContactLaw(name), hist_in, hist, state, (delta, rk - delta, tuple(n), tuple(vr), vn), rk, dt,
                       params)


def _pair(params, delta, vn=0.0, vr=(0.0, 0.0, 0.0), r1=1e-3, r2=2e-3, xi=(0.0, 0.0, 0.0), dt=1e-6,
          n=(1.0, 0.0, 0.0)):
    """The kernel's force on i of one pair, and the spring it writes."""
    state = np.array([[sphere_mass(r1)], [sphere_mass(r2)]])
    hist_in = np.array([xi], dtype=float)
    hist = np.zeros_like(hist_in)
    out = law_pair("hertz_mindlin", params, hist_in, hist, state, delta, n, vr, vn, r1, r2, dt)
    return out, hist[0]


def test_hertz_force_is_four_thirds_e_star_sqrt_r_star_delta_to_three_halves():
    params = hm.HertzMindlinMaterial(**MATERIAL, density=DENSITY).params()
    r1, r2 = 1e-3, 2e-3
    r_eff = r1 * r2 / (r1 + r2)
    for delta in np.geomspace(1e-9, 1e-5, 9):
        (f_n, *_), _ = _pair(params, delta, r1=r1, r2=r2)
        assert f_n == pytest.approx(4.0 / 3.0 * E_STAR * math.sqrt(r_eff) * delta**1.5, rel=1e-14)
    # a wall: R* = the particle's radius
    state = np.array([[sphere_mass(r1)]])
    hist = np.zeros((1, 1, 3))
    f_n = law_wall("hertz_mindlin", params, hist, hist, state, 1e-6, (0.0, 0.0, 1.0), (0.0, 0.0, 0.0), 0.0, r1,
                   1e-6)[0]
    assert f_n == pytest.approx(4.0 / 3.0 * E_STAR * math.sqrt(r1) * 1e-6**1.5, rel=1e-14)


def test_damping_is_alpha_sqrt_m_star_k_n_times_the_overlap_rate():
    material = hm.HertzMindlinMaterial(**MATERIAL, density=DENSITY)
    params = material.params()
    r1, r2, delta, vn = 1e-3, 2e-3, 2e-6, -0.3  # approaching: d delta/dt = -vn > 0
    m1, m2 = sphere_mass(r1), sphere_mass(r2)
    a = math.sqrt(r1 * r2 / (r1 + r2) * delta)
    eta = tsuji.damping_coefficient(0.5) * math.sqrt(m1 * m2 / (m1 + m2) * 4.0 / 3.0 * E_STAR * a)
    damped = _pair(params, delta, vn=vn)[0][0]
    elastic = _pair(params, delta)[0][0]
    assert damped - elastic == pytest.approx(eta * -vn, rel=1e-12)
    # Antypov & Elliott 2011: alpha(e) and its inverse; e = 1 is no damping
    for e in (0.05, 0.3, 0.5, 0.9, 0.999):
        assert tsuji.restitution_of(tsuji.damping_coefficient(e)) == pytest.approx(e, rel=1e-12)
    assert tsuji.damping_coefficient(1.0) == 0.0


def test_mindlin_spring_has_stiffness_eight_g_star_a_and_turns_into_the_tangent_plane():
    params = hm.HertzMindlinMaterial(**{**MATERIAL, "tangential_damping": 0.0, "mu": 1e6}, density=DENSITY).params()
    r1, r2, delta, dt = 1e-3, 2e-3, 1e-6, 1e-6
    a = math.sqrt(r1 * r2 / (r1 + r2) * delta)
    vt = (0.0, 0.02, -0.01)
    (f_n, *ft), xi = _pair(params, delta, vr=vt, dt=dt)
    assert np.allclose(ft, -8.0 * G_STAR * a * np.array(vt) * dt, rtol=1e-13, atol=0)  # F_t = -k_t v_t dt
    assert np.allclose(xi, np.array(vt) * dt, rtol=1e-14, atol=0)
    # a spring left along a rotated frame: turned into the tangent plane with its length kept
    xi0 = (3e-7, 4e-7, 0.0)  # has a normal part along n = x
    (_, *ft), xi = _pair(params, delta, xi=xi0, dt=dt)
    assert xi[0] == 0.0 and np.linalg.norm(xi) == pytest.approx(5e-7, rel=1e-14)
    assert np.linalg.norm(ft) == pytest.approx(8.0 * G_STAR * a * 5e-7, rel=1e-13)


def test_coulomb_limit_caps_the_tangential_force_and_resets_the_spring():
    material = hm.HertzMindlinMaterial(**MATERIAL, density=DENSITY)
    params = material.params()
    delta, vt = 1e-6, (0.0, 0.5, 0.0)
    (f_n, *ft), xi = _pair(params, delta, vn=0.0, vr=vt, xi=(0.0, 1e-4, 0.0))  # a long spring: sliding
    assert np.linalg.norm(ft) == pytest.approx(MATERIAL["mu"] * f_n, rel=1e-13)
    assert ft[1] < 0  # against the slip
    a = math.sqrt(2e-3 / 3 * delta)
    m_eff = sphere_mass(1e-3) * sphere_mass(2e-3) / (sphere_mass(1e-3) + sphere_mass(2e-3))
    eta_t = MATERIAL["tangential_damping"] * tsuji.damping_coefficient(0.5) * math.sqrt(m_eff * 4 / 3 * E_STAR * a)
    assert xi[1] == pytest.approx(-(ft[1] + eta_t * vt[1]) / (8 * G_STAR * a), rel=1e-12)  # the force it gives
    (f_n, *ft), xi = _pair(params, delta, vn=5.0, vr=(0.0, 0.5, 5.0))  # separating fast: F_n < 0, no friction
    assert f_n < 0 and ft == [0.0, 0.0, 0.0]


# ------------------------------------------------------------------------------------------ through the engine
@pytest.mark.parametrize("r2", [1e-3, 2.5e-3])
def test_elastic_collision_peak_overlap_and_duration_are_hertz(r2):
    sim = head_on(contact(restitution=1.0, mu=0.0), 0.4, r2=r2, steps=2000)
    rec = run_recording(sim)
    m1, m2 = sphere_mass(1e-3), sphere_mass(r2)
    delta_max, t_c = hertz_collision(m1 * m2 / (m1 + m2), 1e-3 * r2 / (1e-3 + r2), 0.4)
    d = np.linalg.norm(rec["x"][:, 1] - rec["x"][:, 0], axis=1)
    overlap = 1e-3 + r2 - d
    assert overlap.max() == pytest.approx(delta_max, rel=1e-6)
    touching = rec["t"][overlap > 0]
    assert touching[-1] - touching[0] == pytest.approx(t_c, abs=2 * sim.mechanics.dt)
    v = rec["v"][-1]
    assert v[1, 0] - v[0, 0] == pytest.approx(0.4, rel=1e-7)  # elastic: the relative speed comes back


@pytest.mark.parametrize("e", [0.2, 0.5, 0.9])
@pytest.mark.parametrize("speed", [0.02, 2.0])
def test_restitution_of_a_head_on_collision_is_the_materials_at_every_speed(e, speed):
    """Antypov & Elliott 2011: ``alpha = sqrt(5) (-ln e)/sqrt(pi^2 + ln^2 e)`` gives e exactly, whatever the
    speed; measured from the velocities after the collision (1000 steps per contact: the step leaves at most 2.5e-4,
    falling with the step, 5e-5 at 4000 steps per contact)."""
    sim = head_on(contact(restitution=e), speed)
    sim.run()
    v = sim.mechanics.state.v
    assert len(sim.mechanics.contacts()[0]) == 0
    assert (v[1, 0] - v[0, 0]) / speed == pytest.approx(e, abs=4e-4)


def test_restitution_against_a_wall_and_between_disks():
    e, speed, r = 0.6, 0.5, 1e-3
    delta_max, t_c = hertz_collision(sphere_mass(r), r, speed)  # a wall: m* = m, R* = r
    doc = scene_doc([[0, 0, r + 0.01 * r]], [r], [[0, 0, -speed]], contact(restitution=e),
                    t_end=0.01 * r / speed + 1.5 * t_c, dt=t_c / 1000,
                    walls=[{"name": "floor", "point": [0, 0, 0], "normal": [0, 0, 1]}])
    sim = VerletEngine(parse_scene(doc))
    sim.run()
    assert sim.mechanics.state.v[0, 2] / speed == pytest.approx(e, abs=4e-4)
    disks = head_on(contact(restitution=e), speed, dimension=2, height=1e-3)
    disks.run()
    v = disks.mechanics.state.v
    assert (v[1, 0] - v[0, 0]) / speed == pytest.approx(e, abs=4e-4)


def _resting_sphere(r, material, v0=(0.0, 0.0, 0.0), t_end=0.01, g=9.81):
    """A sphere resting on a floor of its material at the Hertz overlap its weight makes, ``v0`` its velocity."""
    sag = (sphere_mass(r) * g / (4.0 / 3.0 * E_STAR * math.sqrt(r))) ** (2.0 / 3.0)
    doc = scene_doc([[0, 0, r - sag]], [r], [v0], material, t_end=t_end,
                    walls=[{"name": "floor", "point": [0, 0, 0], "normal": [0, 0, 1]}],
                    gravity={"acceleration": [0.0, 0.0, -g]})
    return VerletEngine(parse_scene(doc)), sag


def test_a_sliding_sphere_decelerates_at_mu_g_and_rolls_on_at_five_sevenths_of_its_speed():
    """A sphere launched without spin on a floor slides, ``v = v0 - mu g t``, while the friction's torque spins it
    up, ``d omega/dt = mu m g l/I`` (the lever arm ``l = r - delta/2``), until it rolls without slip, ``omega l = v``,
    at ``v0/(1 + I/(m l^2))`` (angular momentum about the contact point; 5/7 v0 for l = r), ``t ~ 2 v0/(7 mu g)``."""
    g, v0, r, mu = 9.81, 0.5, 1e-3, MATERIAL["mu_wall"]
    t_slide = 2 * v0 / (7 * mu * g)
    sim, sag = _resting_sphere(r, contact(), v0=(v0, 0.0, 0.0), t_end=1.5 * t_slide)
    mech = sim.mechanics
    lever, inertia = r - 0.5 * sag, 0.4 * sphere_mass(r) * r**2
    mech.advance(round(0.5 * t_slide / mech.dt), T0, RATE)
    assert mech.state.v[0, 0] == pytest.approx(v0 - mu * g * mech.t, rel=1e-5)
    assert mech.state.w[0, 1] == pytest.approx(mu * sphere_mass(r) * g * lever / inertia * mech.t, rel=1e-5)
    sim.run()
    s = mech.state
    assert s.v[0, 0] == pytest.approx(v0 / (1 + inertia / (sphere_mass(r) * lever**2)), rel=1e-5)
    assert s.w[0, 1] * lever == pytest.approx(s.v[0, 0], rel=1e-5)  # rolling: no slip at the contact


def test_a_stuck_contact_oscillates_with_mindlins_stiffness():
    """A sphere at rest on a floor, nudged sideways with friction too large to slide: the contact's spring k_t = 8
    G* a (a = sqrt(r delta)) swings the contact point with ``omega^2 = k_t (1/m + l^2/I)``, l = r - delta/2."""
    r = 1e-3
    material = contact(restitution=1.0, tangential_damping=0.0, mu_wall=100.0)
    sim, sag = _resting_sphere(r, material, v0=(1e-4, 0.0, 0.0))
    m = sphere_mass(r)
    k_t = 8.0 * G_STAR * math.sqrt(r * sag)
    omega = math.sqrt(k_t * (1.0 / m + (r - 0.5 * sag) ** 2 / (0.4 * m * r * r)))
    period = 2 * math.pi / omega
    sim.mechanics.dt = period / 2000
    rec = run_recording(sim, 8000)  # four periods
    f_t = rec["w_ft"][:, 0, 0, 0]
    crossings = rec["t"][1:][np.diff(np.sign(f_t)) != 0]
    assert len(crossings) >= 7
    assert np.mean(np.diff(crossings)) * 2 == pytest.approx(period, rel=2e-4)
    assert np.abs(f_t).max() == pytest.approx(1e-4 * k_t / omega, rel=2e-3)  # amplitude: slip speed / omega


def spheres_in_a_box(n, side, seed):
    """``n`` spheres (radii 0.6-1 mm) at random, apart, in a box of side ``side``; its six walls; the generator."""
    rng = np.random.default_rng(seed)
    x, r = [], []
    while len(x) < n:
        radius = rng.uniform(0.6e-3, 1.0e-3)
        p = rng.uniform(radius, side - radius, 3)
        if all(np.linalg.norm(p - q) > radius + s + 1e-4 for q, s in zip(x, r)):
            x.append(p)
            r.append(radius)
    walls = [{"name": f"{axis}{end}", "point": [side * end * (a == k) for k in range(3)],
              "normal": [(1 - 2 * end) * (a == k) for k in range(3)]}
             for a, axis in enumerate("xyz") for end in (0, 1)]
    return x, r, walls, rng


def _box_of_spheres(material, n=24, speed=0.5, seed=4, t_end=4e-3, side=8e-3):
    x, r, walls, rng = spheres_in_a_box(n, side, seed)
    return scene_doc(x, r, rng.normal(0.0, speed, (n, 3)), material, t_end=t_end, walls=walls)


def _hertz_energy(sim):
    """Kinetic energy and the elastic energy ``8/15 E* sqrt(R*) delta^(5/2)`` of every pair and wall contact."""
    mech = sim.mechanics
    s = mech.state
    i, j, overlap = mech.contacts()[:3]
    r_eff = s.radius[i] * s.radius[j] / (s.radius[i] + s.radius[j])
    k, _, wall_overlap, _ = mech.wall_contacts()
    elastic = 8 / 15 * E_STAR * (np.sum(np.sqrt(r_eff) * overlap**2.5)
                                 + np.sum(np.sqrt(s.radius[k]) * wall_overlap**2.5))
    return s.kinetic_energy() + elastic


def test_energy_is_conserved_without_damping_or_friction():
    sim = VerletEngine(parse_scene(_box_of_spheres(contact(restitution=1.0, mu=0.0, mu_wall=0.0))))
    mech = sim.mechanics
    mech.dt /= 4  # a quarter of dt = "auto" (a tenth of the Rayleigh time)
    energy0 = _hertz_energy(sim)
    collisions = 0
    for _ in range(40):
        mech.advance(100, T0, RATE)
        collisions += len(mech.contacts()[0]) + len(mech.wall_contacts()[0])
        assert _hertz_energy(sim) == pytest.approx(energy0, rel=1e-5)
    assert collisions > 20  # contacts were caught in the middle of a collision
    damped = VerletEngine(parse_scene(_box_of_spheres(contact(restitution=0.9, mu=0.0, mu_wall=0.0))))
    damped.mechanics.advance(4000, T0, RATE)
    assert _hertz_energy(damped) < 0.99 * energy0  # the check can fail: damping loses energy


def test_momentum_and_angular_momentum_are_conserved_with_friction_and_damping():
    rng = np.random.default_rng(7)
    doc = _box_of_spheres(contact(restitution=0.4, mu=0.8), n=30, t_end=5e-3)
    del doc["walls"]
    doc["particles"]["angular_velocity"] = rng.normal(0, 300.0, (30, 3)).tolist()
    x = np.array(doc["particles"]["position"])
    doc["particles"]["velocity"] = (0.3 * (4e-3 - x) / 4e-3 + rng.normal(0, 0.05, x.shape)).tolist()  # converge
    sim = VerletEngine(parse_scene(doc))
    s = sim.mechanics.state

    def angular(state):
        return np.sum(state.mass[:, None] * np.cross(state.x, state.v), axis=0) + np.sum(
            state.inertia[:, None] * state.w, axis=0)

    p0, l0 = s.momentum(), angular(s)
    contacts = 0
    for _ in range(20):
        sim.mechanics.advance(200, T0, RATE)
        contacts = max(contacts, len(sim.mechanics.contacts()[0]))
    assert contacts >= 5
    scale_p = np.sum(s.mass) * 0.3
    assert np.all(np.abs(s.momentum() - p0) < 1e-13 * scale_p)
    assert np.all(np.abs(angular(s) - l0) < 1e-12 * scale_p * 8e-3)


# ------------------------------------------------------------------------------------------ time step, input
def test_auto_step_is_a_tenth_of_the_rayleigh_time_and_a_larger_step_is_refused():
    doc = scene_doc([[0, 0, 0], [2.1e-3, 0, 0]], [1e-3, 0.5e-3], contact=contact())
    sim = VerletEngine(parse_scene(doc))
    G = MATERIAL["youngs_modulus"] / (2 * 1.3)
    rayleigh = math.pi * 0.5e-3 * math.sqrt(DENSITY / G) / (0.1631 * 0.3 + 0.8766)
    assert sim.mechanics.dt == pytest.approx(0.1 * rayleigh, rel=1e-14)
    doc["solver"]["dt"] = 20 * rayleigh
    with pytest.raises(ValueError, match="dt = .*above the stable step"):
        parse_scene(doc)


@pytest.mark.parametrize("change, message", [
    ({"poisson_ratio": 0.5}, r"\[contact\] poisson_ratio = 0.5: must be in \(-1, 0.5\)"),
    ({"restitution": 0.0}, r"\[contact\] restitution = 0.0: must be > 0"),
    ({"restitution": 1.5}, r"\[contact\] restitution = 1.5: must be in \(0, 1\]"),
    ({"youngs_modulus": -1.0}, r"\[contact\] youngs_modulus = -1.0: must be > 0 \(Pa\)"),
    ({"mu": float("nan")}, r"\[contact\] mu = nan: must be a finite number"),
])
def test_bad_material_is_refused_in_one_line_naming_the_key(change, message):
    phases = change.get("phases")
    material = {**contact(), **{k: v for k, v in change.items() if k != "phases"}}
    doc = copy.deepcopy(scene_doc([[0, 0, 0], [2.1e-3, 0, 0]], [1e-3, 1e-3], contact=material))
    if phases is not None:
        doc["phases"] = phases
    with pytest.raises(ValueError, match=message):
        parse_scene(doc)
    doc["contact"] = {k: v for k, v in contact().items() if k != "restitution"}
    with pytest.raises(ValueError, match=r"\[contact\] restitution: required"):
        parse_scene(doc)


@pytest.mark.parametrize("law", ["hertz_mindlin", "jkr"])
@pytest.mark.parametrize("where", ["contact", "phases"])
def test_a_luding_key_is_refused_in_one_line_naming_the_law(law, where):
    """A key of Luding's material (gamma_n, k1) in [contact] or in a phase of a Hertz-Mindlin or JKR scene: one line
    naming the key, the scene's law and the law that does take it."""
    material = contact(law, **({"work_of_adhesion": 0.1} if law == "jkr" else {}))
    doc = scene_doc([[0, 0, 0], [2.1e-3, 0, 0]], [1e-3, 1e-3], contact=material)
    for key, value in (("gamma_n", 0.1), ("k1", 1e5)):
        bad = copy.deepcopy(doc)
        if where == "contact":
            bad["contact"][key] = value
        else:
            bad["phases"] = [{"start": 0.0, "mu": 0.2, key: value}]
        with pytest.raises(ValueError) as raised:
            parse_scene(bad)
        prefix = r"\[contact\]" if where == "contact" else r"\[phases\]\[0\]"
        assert re.fullmatch(rf'{prefix} {key}: not a parameter of law = "{law}" \(.*; {key} is one of law = "luding"\)',
                            str(raised.value)), str(raised.value)
    good = copy.deepcopy(doc)
    good["phases"] = [{"start": 1e-4, "mu": 0.2, "restitution": 0.9}]
    assert parse_scene(good).motion.phases == ((1e-4, {"mu": 0.2, "restitution": 0.9}),)
