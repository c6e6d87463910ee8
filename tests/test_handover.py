"""The hand-over from a pair-neck reading to the union of spheres (dem.geometry.handover): solid radii that keep the
particles' volumes, hand-overs over a number of thermal steps, and moving runs through the hand-over: volume kept,
k_eff continuous, unchanged where no necks meet, resumed bit for bit."""

import math
import pathlib
import tomllib

import numpy as np
import pytest
from scipy.optimize import brentq

import dem
from dem import parse_scene
from dem.engines.contact_heat import ContactThermalModel
from dem.engines.staggered.engine import StaggeredEngine
from dem.engines.verlet.engine import VerletEngine
from dem.geometry import handover
from dem.geometry.handover import HANDOVER_STEPS, advance, solid_radii, weights
from dem.network.heat import Network, bonds_and_conductances, boundary_heat_flow, steady
from fem_neck.geometry.union import angular_radius, cut_spheres, lens, necks_meet
from handover_steps import record_handovers

NONE = (np.zeros(0, np.int64), np.zeros((0, 3)), np.zeros(0))  # no walls


def cap(r, l):
    """Volume of the cap of a sphere of radius ``r`` beyond a plane at ``l`` from its centre."""
    return math.pi * (r - l) ** 2 * (2.0 * r + l) / 3.0


def test_two_equal_spheres_grow_to_the_closed_form():
    """Two equal spheres d apart, both grown: their plane stays at d/2, so 4/3 pi r_s^3 - cap(r_s, d/2) = 4/3 pi r^3."""
    r, d = 1e-3, 1.7e-3
    rs = solid_radii(np.array([r, r]), np.array([True, True]), np.array([0]), np.array([1]),
                     np.array([[d, 0.0, 0.0]]), *NONE)
    exact = brentq(lambda s: 4.0 / 3.0 * math.pi * s**3 - cap(s, d / 2) - 4.0 / 3.0 * math.pi * r**3, r, 2 * r,
                   xtol=1e-18, rtol=1e-15)
    assert rs == pytest.approx([exact, exact], rel=1e-13) and exact > 1.001 * r


def test_one_grown_sphere_moves_the_plane_toward_its_neighbour():
    """Only sphere 0 grows: its plane is at l = (d^2 + r_s^2 - r^2) / (2 d), and the neighbour keeps its radius."""
    r, d = 1e-3, 1.7e-3
    rs = solid_radii(np.array([r, r]), np.array([True, False]), np.array([0]), np.array([1]),
                     np.array([[d, 0.0, 0.0]]), *NONE)

    def volume(s):
        return 4.0 / 3.0 * math.pi * s**3 - cap(s, (d * d + s * s - r * r) / (2 * d))

    exact = brentq(lambda s: volume(s) - 4.0 / 3.0 * math.pi * r**3, r, 2 * r, xtol=1e-18, rtol=1e-15)
    assert rs[0] == pytest.approx(exact, rel=1e-13) and rs[1] == r


def test_a_wall_cuts_the_sphere_at_a_plane_that_does_not_move():
    r, dist = 1e-3, 0.8e-3
    rs = solid_radii(np.array([r]), np.array([True]), np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros((0, 3)),
                     np.array([0]), np.array([[0.0, 0.0, 1.0]]), np.array([dist]))
    exact = brentq(lambda s: 4.0 / 3.0 * math.pi * s**3 - cap(s, dist) - 4.0 / 3.0 * math.pi * r**3, r, 2 * r,
                   xtol=1e-18, rtol=1e-15)
    assert rs[0] == pytest.approx(exact, rel=1e-13)


def fcc_cluster(h_over_r: float, seed: int = 1):
    """Three FCC cells of spheres (radii 1 mm +-4 %, centres jittered 2 % of r) whose neighbours overlap by about
    ``h_over_r``: the pairs (i, j, x_j - x_i)."""
    rng = np.random.default_rng(seed)
    basis = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]])
    cells = np.array([[p, q, s] for p in range(3) for q in range(3) for s in range(3)])
    x = (cells[:, None, :] + basis[None]).reshape(-1, 3) * (2.0 - h_over_r) * math.sqrt(2.0) * 1e-3
    x += rng.normal(0.0, 0.02e-3, x.shape)
    r = rng.uniform(0.96e-3, 1.04e-3, len(x))
    i, j = np.triu_indices(len(x), 1)
    v = x[j] - x[i]
    touch = np.linalg.norm(v, axis=1) < r[i] + r[j]
    return r, i[touch], j[touch], v[touch]


def test_a_cluster_whose_necks_meet_keeps_its_volume():
    """FCC past the meeting of its lens necks (h/r = 0.3): grown, the cut spheres hold the spheres' volume to 1e-9 (each
    and in sum), where the ungrown ones have lost more than 3 % of it (each more than 1 %); a particle not grown keeps its radius."""
    r, i, j, v = fcc_cluster(0.3)
    neck = lens(r[i], r[j], np.linalg.norm(v, axis=1))
    meet = necks_meet(len(r), np.r_[i, j], np.vstack([v, -v]),
                      np.r_[angular_radius(neck.a, neck.l_i), angular_radius(neck.a, neck.l_j)])
    assert np.count_nonzero(meet) > len(r) // 2
    grow = np.ones(len(r), dtype=bool)
    grow[0] = False
    rs = solid_radii(r, grow, i, j, v, *NONE)
    kept = 4.0 / 3.0 * np.pi * r**3
    volume = cut_spheres(rs, i, j, v).volume
    assert np.max(np.abs(volume[grow] / kept[grow] - 1.0)) < 1e-9
    assert abs(volume[grow].sum() / kept[grow].sum() - 1.0) < 1e-9
    assert rs[0] == r[0] and np.all(rs[grow] > r[grow])
    ungrown = cut_spheres(r, i, j, v).volume[grow]
    assert np.all(ungrown < (1 - 1e-2) * kept[grow]) and ungrown.sum() < 0.97 * kept[grow].sum()


def test_a_handover_once_begun_goes_on_to_the_end():
    steps = np.array([0, 0, 3, HANDOVER_STEPS - 1, HANDOVER_STEPS])
    after = advance(steps, np.array([False, True, False, False, True]))
    assert after.tolist() == [0, 1, 4, HANDOVER_STEPS, HANDOVER_STEPS]
    assert weights(after).tolist() == [0.0, 1 / HANDOVER_STEPS, 4 / HANDOVER_STEPS, 1.0, 1.0]


LUDING = {"law": "luding", "k1": 1.0, "k2": 2.0, "kc": 1.0, "kt_ratio": 0.2, "gamma_n": 0.0, "gamma_t": 0.0,
          "mu": 0.0, "mu_wall": 0.0, "T_melt": 1000.0, "T_var": 10.0, "expansion": 0.0, "fluid_overlap": 0.2,
          "t0": 1.0e3, "brittle_sliding": True}


def squeezed(t_end: float, h_over_r: float = 0.08, rate: float = 20.0, law: str = "fit") -> dict:
    """63 spheres (r = 0.5 mm) on the FCC lattice points of a cube two cells wide, neighbours overlapping by
    ``h_over_r``, squeezed toward their centre at ``rate`` (1/s) against soft contacts: their necks meet after about
    1 ms, then the cluster springs back and they part. The bottom layer is held at 100 C, the top at 0 C."""
    g = np.arange(5) * 0.5
    p = np.array([[a, b, c] for a in g for b in g for c in g if round(2 * (a + b + c)) % 2 == 0])
    r = 5e-4
    x = p * (2.0 - h_over_r) * r * math.sqrt(2.0) + np.random.default_rng(3).normal(0.0, 0.01 * r, (len(p), 3))
    hot, cold = p[:, 2] == 0.0, p[:, 2] == 2.0
    return {"scene": {"physics": ["mechanical", "thermal"]},
            "material": {"density": 7800.0, "conductivity": 50.0, "specific_heat": 500.0}, "contact": LUDING,
            "particles": {"position": x.tolist(), "radius": [r] * len(x),
                          "temperature": np.where(hot, 100.0, np.where(cold, 0.0, 50.0)).tolist(),
                          "fixed": (hot | cold).tolist(), "velocity": (-rate * (x - x.mean(axis=0))).tolist()},
            "conductance": {"law": law}, "solver": {"mode": "transient", "t_end": t_end, "thermal_interval": 1e-4}}


def conductance(engine, steps) -> float:
    """The steady heat flow (W) from the hot layer to the cold one per kelvin, on the contacts now with the
    hand-over steps ``steps``."""
    th, mech = engine.thermal, engine.mechanics
    kept, th.handover.steps = th.handover.steps, steps
    bonds, K, K_walls = th.bonds(mech)
    th.handover.steps = kept
    net = Network(th._particles_now(mech, th.particles.radius), bonds, K, K_walls, np.zeros(0), th.sources, th.box)
    into = boundary_heat_flow(net, steady(net, floating="mean").T)["particles"]
    return -sum(q for k, q in into.items() if th.particles.temperature[k] == 100.0) / 100.0


def run_through(scene: dict):
    """Run ``scene``, recording at every thermal step that hands particles over the change of the conductance
    across it (:func:`handover_steps.record_handovers`) and the cut spheres of the particles on the way."""
    engine = VerletEngine(parse_scene(scene))
    th, mech = engine.thermal, engine.mechanics

    def volumes(_):
        bonds = engine.necks()[1]
        grown = th.handover.weight > 0.0
        cut = cut_spheres(np.where(grown, th.handover.solid_radius, mech.state.radius), bonds.i, bonds.j,
                          bonds.vectors(mech.state.x, th.box)).volume
        return cut[grown].sum(), (4.0 / 3.0 * np.pi * mech.state.radius[grown] ** 3).sum()

    jumps, kept = record_handovers(engine, conductance, volumes)
    engine.run()
    return engine, np.array(jumps), np.array(kept)


@pytest.mark.slow
def test_a_run_through_the_handover_keeps_the_volume_and_k_eff_continuous():
    """Squeezed harder, two thirds of the cluster's particles begin their hand-over, most of them together: at every
    step on the way the grown particles' cut spheres hold their volume to 1e-9, and the conductance between the hot
    and cold layers changes by at most 0.5 % across a step, with either law; the summary and the snapshots say who
    is on the way."""
    for law in ("fit", "rojek"):
        engine, jumps, volumes = run_through(squeezed(0.005, rate=30.0, law=law))
        th = engine.thermal
        started = th.handover.steps > 0
        assert np.count_nonzero(started) >= 40 and len(jumps) >= 60
        assert np.max(np.abs(volumes[:, 0] / volumes[:, 1] - 1.0)) < 1e-9
        assert np.max(np.abs(jumps)) < 5e-3, law
    summary = engine.summary()
    assert summary["particles_handed_over"] + summary["particles_handing_over"] == np.count_nonzero(started)
    fields = engine.particle_fields()
    grown = fields["solid_radius"] > 5e-4  # (a particle on the way that has lost its contacts is a whole sphere)
    assert np.array_equal(fields["handed_over"] > 0.0, started) and np.all(grown <= started) and np.any(grown)
    assert np.all(fields["solid_radius"] >= 5e-4)


@pytest.mark.slow
def test_handed_over_at_once_the_same_run_jumps(monkeypatch):
    """The steps are what keeps k_eff continuous: handed over at once, the same run jumps by more than 2 % (the fit
    law's union and cylinder readings of these contacts differ by 5-15 %), and with the rojek law (linear in a: 17-23
    %) by more than 0.5 % over half the steps."""
    monkeypatch.setattr(handover, "HANDOVER_STEPS", 1)
    jumps = run_through(squeezed(0.005, rate=30.0))[1]
    assert np.max(np.abs(jumps)) > 0.02
    monkeypatch.setattr(handover, "HANDOVER_STEPS", HANDOVER_STEPS // 2)
    jumps = run_through(squeezed(0.005, rate=30.0, law="rojek"))[1]
    assert np.max(np.abs(jumps)) > 5e-3


@pytest.mark.slow
def test_runs_whose_necks_never_meet_are_unchanged_to_the_bit(monkeypatch):
    """Squeezed less, the necks never meet: the run is the one without the hand-over, bit for bit."""
    scene = squeezed(0.003, h_over_r=0.04, rate=5.0)
    handed = VerletEngine(parse_scene(scene))
    handed.run()
    summary = handed.summary()
    assert not np.any(handed.thermal.handover.steps) and summary["particles_handed_over"] == 0
    assert summary["neck_readings"] == {"newton": summary["contacts"]}
    monkeypatch.setattr(ContactThermalModel, "hands_over", False)
    plain = VerletEngine(parse_scene(scene))
    plain.run()
    assert np.array_equal(handed.thermal.T, plain.thermal.T) and "particles_handed_over" not in plain.summary()


@pytest.mark.slow
def test_a_resumed_run_goes_on_handing_over_bit_for_bit():
    """Stopped while particles are on the way and their necks have parted again, the run resumes from its checkpoint
    and ends as the run that did not stop: the hand-overs go on, the solid radii start where they were."""
    whole = VerletEngine(parse_scene(squeezed(0.004)))
    whole.run()
    first = VerletEngine(parse_scene(squeezed(0.003)))
    first.run()
    th = first.thermal
    on_the_way = (th.handover.steps > 0) & (th.handover.steps < HANDOVER_STEPS)
    assert np.any(on_the_way & ~first.necks()[0])
    resumed = VerletEngine(parse_scene(squeezed(0.004)), restart=first.checkpoint())
    resumed.run()
    assert np.array_equal(resumed.thermal.T, whole.thermal.T)
    for name in ("steps", "solid_radius"):
        assert np.array_equal(getattr(resumed.thermal.handover, name), getattr(whole.thermal.handover, name)), name
    assert np.array_equal(resumed.mechanics.state.x, whole.mechanics.state.x)
    th, mech = whole.thermal, whole.mechanics
    grown = th.handover.steps > 0
    bonds = whole.necks()[1]
    cut = cut_spheres(np.where(grown, th.handover.solid_radius, mech.state.radius), bonds.i, bonds.j,
                      bonds.vectors(mech.state.x, th.box)).volume
    assert np.any(grown) and np.max(np.abs(cut[grown] / (4.0 / 3.0 * np.pi * mech.state.radius[grown] ** 3) - 1)) < 1e-9


def test_a_read_at_one_configuration_follows_the_state_of_the_handovers():
    """The bonds a moving run keeps for its configuration (the snapshots at the end of a step share one read) are
    read again where the hand-overs' state is another: with no steps the pair reading, with the run's own steps its
    reading again, as a read from scratch gives it; a second read in one state is the one kept."""
    engine = VerletEngine(parse_scene(squeezed(0.003)))
    engine.run()
    th, mech = engine.thermal, engine.mechanics
    own = th.handover.steps.copy()
    assert np.any(own > 0)
    first = th.bonds(mech)
    assert th.bonds(mech) is first
    th.handover.steps = np.zeros_like(own)
    pair = th.bonds(mech)
    now, walls = th._particles_now(mech, mech.state.radius), th._walls_now(mech)
    scratch = bonds_and_conductances(now, walls, th.spec, pairs=mech.contacts()[:2], box=th.box)
    assert all(np.array_equal(a, b) for a, b in zip(pair[1:], scratch[1:])) and not np.array_equal(pair[1], first[1])
    th.handover.steps = own
    again = th.bonds(mech)
    assert again is not first and all(np.array_equal(a, b) for a, b in zip(again[1:], first[1:]))


@pytest.mark.slow
def test_the_timeseries_gives_k_eff_on_pair_necks_beside_it():
    """A run with heated walls records beside k_eff the k_eff of its contacts all read as pair necks: the same number
    while no particle is handed over (the first milliseconds of hot-wall-sintering)."""
    text = (pathlib.Path(dem.__file__).parent / "scene" / "builtin" / "hot-wall-sintering.toml").read_text()
    engine = VerletEngine(parse_scene(tomllib.loads(text.replace("t_end = 0.15\n", "t_end = 0.004\n"))))
    engine.run()
    row = engine.record()
    assert not np.any(engine.thermal.handover.steps)
    assert row["effective_conductivity_pair_necks"] == row["effective_conductivity"] is not None


ZOHDI = {"law": "zohdi", "K_p": 1.0e3, "p_p": 1.0, "K_p_lim": 1.0e3, "K_w": 1.0e3, "p_w": 1.0, "K_w_lim": 1.0e3,
         "theta_star": 5000.0, "K_b": 0.0, "p_b": 1.0, "E_star": 0.9, "mu_d": 0.0, "c_env": 0.0, "v_slip": 0.1}


def squeezed_staggered(t_end: float) -> dict:
    """The squeezed cluster with Zohdi's soft contact, on the staggered engine, fixed steps."""
    scene = squeezed(t_end)
    scene["contact"] = ZOHDI
    scene["solver"] = {"mode": "transient", "t_end": t_end, "dt": 5e-5, "dt_max": 5e-5}
    return scene


@pytest.mark.slow
def test_the_staggered_engine_hands_over_and_resumes_bit_for_bit():
    """Zohdi's staggered scheme with the fit law on the volume-conserving necks: particles are handed over at its
    accepted steps, keep their volume, and a run resumed from its checkpoint while they are on the way ends as the
    one that did not stop."""
    whole = StaggeredEngine(parse_scene(squeezed_staggered(0.003)))
    whole.run()
    first = StaggeredEngine(parse_scene(squeezed_staggered(0.002)))
    first.run()
    steps = first.thermal.handover.steps
    assert np.any((steps > 0) & (steps < HANDOVER_STEPS))
    resumed = StaggeredEngine(parse_scene(squeezed_staggered(0.003)), restart=first.checkpoint())
    resumed.run()
    th, mech = whole.thermal, whole.mechanics
    assert np.array_equal(resumed.thermal.T, th.T)
    for name in ("steps", "solid_radius"):
        assert np.array_equal(getattr(resumed.thermal.handover, name), getattr(th.handover, name)), name
    grown = th.handover.steps > 0
    bonds = whole._pair_bonds()
    cut = cut_spheres(np.where(grown, th.handover.solid_radius, mech.state.radius), bonds.i, bonds.j,
                      bonds.vectors(mech.state.x, mech.periodic_box)).volume
    assert np.any(grown) and np.max(np.abs(cut[grown] / (4.0 / 3.0 * np.pi * mech.state.radius[grown] ** 3) - 1)) < 1e-9
    summary = whole.summary()
    assert summary["particles_handed_over"] + summary["particles_handing_over"] == np.count_nonzero(grown)
    assert np.array_equal(whole.particle_fields()["handed_over"], th.handover.weight)


@pytest.mark.parametrize("policy", ["drop", "clip"])
@pytest.mark.slow
def test_a_bond_past_its_range_on_the_way_blends_the_policys_pair_reading_with_the_union(policy):
    """The ``shared-body`` law squeezed until pair necks pass their range while their particles are on the way: the
    pair reading's conductances are those of the scene's ``out_of_range`` reading, the union's weighed in. Under
    ``"drop"`` the pair part of those bonds is 0 (whose clipped necks the law could not read), under ``"clip"`` the
    law's at their clipped necks (two of them on one particle divided by zero), and the run goes on with heat in heat
    out."""
    from dataclasses import replace

    from dem.geometry.bonds import find_bonds
    from dem.laws.conductance import bond_conductances
    from fem_neck.geometry import max_overlap

    scene = squeezed(0.00105, rate=300.0, law="shared-body")
    scene["conductance"]["out_of_range"] = policy
    engine = VerletEngine(parse_scene(scene))
    engine.run()
    th, mech = engine.thermal, engine.mechanics
    bonds, K, _ = th.bonds(mech)
    now = th._particles_now(mech, th.particles.radius)
    past = bonds.h > max_overlap(now.radius[bonds.i], now.radius[bonds.j])
    w = np.maximum(th.handover.weight[bonds.i], th.handover.weight[bonds.j])
    assert np.count_nonzero(past) >= 5 and np.all((w > 0.0) & (w < 1.0))
    grown = replace(now, radius=th.handover.solid_radii(now.radius))
    union = find_bonds(grown, (), "union", pairs=(bonds.i, bonds.j))
    K_union = bond_conductances(replace(th.handover.spec, neck="union"), grown, union)[0]
    read = find_bonds(now, (), "newton", policy, pairs=(bonds.i, bonds.j))
    K_pair = np.zeros(bonds.n_pairs)
    K_pair[~past if policy == "drop" else slice(None)] = bond_conductances(th.handover.spec, now, read)[0]
    assert K == pytest.approx((1.0 - w) * K_pair + w * K_union, rel=1e-9)
    assert np.all(np.isfinite(K)) and np.all(K > 0.0) and np.all((K_pair[past] > 0.0) == (policy == "clip"))
    assert engine.summary()["energy_error"] < 1e-12
