"""Luding 2005's protocol as scenes (verification.luding.protocol) and the fragment counter
(verification.luding.fragments)."""

import math

import numpy as np
import pytest

from verification.luding import protocol as sp
from dem.engines.verlet.engine import VerletEngine
from verification.luding.fragments import clusters, fragments, tension_capacity
from dem.laws.contact.luding import LUDING_TABLE1 as MAT
from dem.scene import parse_scene
from dem.driver import run


def test_schedule_scene_has_the_times_temperatures_and_box_of_sec_4_1():
    t_s = 0.05
    scene = parse_scene(sp.schedule_doc(150, 100.0, t_s))
    m = scene.motion
    assert scene.contact == MAT and m.dimension == 2 and m.height == 6e-3
    assert scene.solver.t_end == pytest.approx(0.2 + 0.1 + t_s + 0.1 + 0.1)
    sched = m.verlet.schedule
    assert sched.time == pytest.approx((0.0, 0.2, 0.3, 0.3 + t_s, 0.4 + t_s, 0.5 + t_s))
    assert sched.value == (80.0, 80.0, 140.0, 140.0, 80.0, 80.0)
    assert sched.relaxation_time == (1e3, 1e3, 0.1, 1e3, 1e3)  # t0 = 0.1 s only while sintering (Table 1)
    (s0, prep), (s1, after) = m.phases
    assert (s0, s1) == (0.0, 0.2)
    assert list(prep.values()) == [MAT.mu, MAT.mu] and list(after.values()) == [MAT.mu, MAT.mu_wall]  # walls off
    walls = {w.name: w for w in m.walls}
    assert walls["left"].motion == walls["bottom"].motion == "fixed"
    for name in ("right", "top"):
        w = walls[name]
        assert (w.motion, w.pressure, w.mass, w.damping) == ("stress", 100.0, 0.01, 0.2)
    side = walls["right"].point[0]
    assert side == walls["top"].point[2] == pytest.approx(math.sqrt(150 * math.pi * 1e-6 * (1 + 0.25 / 3) / 0.3))
    assert sp.box_side(3, 0.3) == pytest.approx(2 * 1.5e-3 * (math.sqrt(3) + 1))  # a few particles: room for them
    r = scene.particles.radius
    assert r.min() >= 0.5e-3 and r.max() <= 1.5e-3


@pytest.mark.slow
def test_stage_scenes_continue_from_a_state(tmp_path):
    times = sp.Times(t_s=0.004, t_heat=0.004, heat=0.002, cool=0.002, relax=0.002)
    prep = run(parse_scene(sp.preparation_doc(12, 100.0, times=times)), tmp_path / "prep")
    state = str(tmp_path / "prep" / "state.npz")
    sinter = parse_scene(sp.sintering_doc(state, 100.0, 0.004, times=times, cooling=True))
    t_heat = prep.summary["t"]  # the clock goes on from the prepared state's
    assert 0 <= t_heat - times.t_heat < prep.summary["dt"]  # the first step at or after t_end
    assert sinter.start_time == t_heat and sinter.solver.t_end == pytest.approx(t_heat + 0.002 + 0.004 + 0.004)
    assert sinter.motion.verlet.schedule.time[0] == t_heat
    assert sinter.motion.verlet.schedule.value == (80.0, 140.0, 140.0, 80.0, 80.0)
    assert sinter.motion.phases == ()  # Table 1 friction from the start (t_heat)
    saved_right = prep.engine.mechanics.w.q[2]
    assert {w.name: w for w in sinter.motion.walls}["right"].offset == saved_right
    from dem.scene import state_file

    saved = state_file.load(state)
    z0 = -sp.wall_offset(saved, "top")
    comp = parse_scene(sp.compression_doc(state, 10.0, z0=z0, strain_rate=2.0, strain=0.04))
    top = {w.name: w for w in comp.motion.walls}["top"]
    assert (top.motion, top.velocity, comp.solver.t_end) == ("strain", pytest.approx(2.0 * z0),
                                                            pytest.approx(t_heat + 0.02))
    vib = parse_scene(sp.vibration_doc(state, sp.floor_height(saved)))
    (floor,) = vib.motion.walls
    assert (floor.motion, floor.frequency, floor.amplitude) == ("vibrate", 100.0, 2e-4)
    assert floor.offset == pytest.approx(np.min(saved["x"][:, 2] - saved["radius"]))
    assert vib.motion.gravity == (0.0, 0.0, -9.81) and vib.solver.t_end == pytest.approx(t_heat + 0.1)


@pytest.mark.parametrize("call, words", [
    (lambda: sp.schedule_doc(10, 0.0, 0.1), "p = 0.0: must be a finite pressure > 0"),
    (lambda: sp.schedule_doc(10, 10.0, -1.0), "t_s = -1.0: must be a finite time > 0"),
    (lambda: sp.preparation_doc(0, 10.0), "n = 0: must be an integer >= 1"),
    (lambda: sp.preparation_doc(10, 10.0, fill=0.7), "fill = 0.7: must be in (0, 0.5)"),
    (lambda: sp.compression_doc("s.npz", 10.0, z0=0.03, strain=1.5), "strain = 1.5: must be < 1"),
    (lambda: sp.vibration_doc("s.npz", 0.0, duration=0.0), "duration = 0.0: must be a finite number > 0"),
])
def test_bad_protocol_input_names_the_parameter(call, words):
    with pytest.raises(ValueError, match=None) as err:
        call()
    assert words in str(err.value)


@pytest.mark.slow
def test_tiny_schedule_sinters_and_cools_back():
    times = sp.Times(t_s=0.02, t_heat=0.03, heat=0.01, cool=0.01, relax=0.01)
    sim = VerletEngine(parse_scene(sp.schedule_doc(16, 100.0, 0.02, times=times)))
    rows = []
    sim.run(lambda: rows.append((sim.mechanics.t, sim.volume_fraction(), float(np.mean(sim.mechanics.particle_column("k1_factor"))))))
    t, nu, k1 = map(np.array, zip(*rows))
    at = lambda time: int(np.argmin(abs(t - time)))  # noqa: E731
    k1_80 = 1.0 / (1.0 + math.exp(-2.0 * (120.0 - 80.0) / 10.0))  # eq. 10
    assert k1[at(times.t_heat)] == pytest.approx(k1_80, rel=1e-9)
    a, b = at(times.t_sinter + 0.005), at(times.t_cool - 0.005)  # two rows while sintering at 140 C, t0 = 0.1 s
    K = 1.0 / (1.0 + math.exp(-2.0 * (120.0 - 140.0) / 10.0))
    assert k1[b] == pytest.approx(K * (1 - 1 / (1 / (1 - k1[a] / K) - (t[b] - t[a]) / 0.1)), rel=1e-9)  # eq. 11
    assert k1[b] < 0.2
    assert k1[-1] == pytest.approx(k1_80, rel=1e-6)  # cooling freezes at once (Sec. 3.4, end)
    assert nu[-1] > nu[at(times.t_heat)] + 0.01  # sintering densifies


@pytest.mark.slow  # 2D disks: Luding's force loop for them (35-40 s for numba to compile in a fresh clone)
def test_an_interval_starting_just_before_a_knot_takes_the_next_segment():
    """The knot at 1 ms lies at 3333.33 steps of 0.3 us: the interval after it starts at step 3333, 0.1 us early,
    and must still follow the segment after the knot (140 C held), not extend the heating ramp beyond it."""
    doc = {"scene": {"physics": ["mechanical"], "dimension": 2, "height": 6e-3}, "material": {"density": 2000.0},
           "particles": {"position": [[0, 0, 0], [5e-3, 0, 0]], "radius": [1e-3, 1e-3], "temperature": [80.0] * 2},
           "contact": sp.contact_table(MAT), "temperature": {"time": [0.0, 1e-3, 2e-3], "value": [80.0, 140.0, 140.0]},
           "solver": {"mode": "transient", "t_end": 2e-3, "dt": 3e-7}, "output": {"interval": 5e-4}}
    sim = VerletEngine(parse_scene(doc))
    rows = []
    sim.run(lambda: rows.append((sim.mechanics.t, sim.mechanics.state.T[0])))
    assert round(1e-3 / 3e-7) * 3e-7 < 1e-3
    assert max(T for _, T in rows) == pytest.approx(140.0, abs=1e-9)
    assert rows[-1][1] == 140.0


def test_clusters_label_by_decreasing_size():
    labels, sizes = clusters(7, [0, 1, 4], [1, 2, 5])
    assert sizes.tolist() == [3, 2, 1, 1]
    assert labels[0] == labels[1] == labels[2] == 0 and labels[4] == labels[5] == 1
    assert sorted(labels[[3, 6]].tolist()) == [2, 3]


@pytest.mark.slow  # 2D disks: Luding's force loop for them (35-40 s for numba to compile in a fresh clone)
def test_tension_capacity_is_eq_15_and_fragments_split_at_the_threshold():
    """Two pressed pairs, one hard (overlap 20 um) one light (0.2 um), and a lone disk: capacities by eq. 15."""
    a, h = 1e-3, 6e-3
    d1, d2 = 2e-5, 2e-7
    x = [[0, 0, 0], [2 * a - d1, 0, 0], [0, 0, 5 * a], [2 * a - d2, 0, 5 * a], [0, 0, 10 * a]]
    doc = {"scene": {"physics": ["mechanical"], "dimension": 2, "height": h}, "material": {"density": 2000.0},
           "particles": {"position": x, "radius": [a] * 5, "temperature": [80.0] * 5},
           "contact": sp.contact_table(MAT), "solver": {"mode": "transient", "t_end": 1e-6}}
    mech = VerletEngine(parse_scene(doc)).mechanics
    i, j, cap = tension_capacity(mech)
    s = 1.0 / (1.0 + math.exp(-2.0 * (120.0 - 80.0) / 10.0))
    dmf = MAT.k2 * MAT.fluid_overlap * a / (MAT.k2 - MAT.k1)
    for delta, c in zip((d1, d2), cap):
        k2 = MAT.k1 + (MAT.k2 - MAT.k1) * delta / dmf  # eq. 7
        kc = s * k2 / MAT.k2 * MAT.kc                  # eq. 13
        assert c == pytest.approx((k2 - s * MAT.k1) / (1 + k2 / kc) * delta, rel=1e-12)  # eq. 15
    assert fragments(mech, min_tension=0.0)[1].tolist() == [2, 2, 1]
    assert fragments(mech, min_tension=0.5 * (cap[0] + cap[1]))[1].tolist() == [2, 1, 1, 1]
    weight = 9.81 * mech.state.mass[0]
    assert cap[1] < weight < cap[0]  # the default threshold: the weight of the lighter particle
    assert fragments(mech)[1].tolist() == [2, 1, 1, 1]
    with pytest.raises(ValueError, match="min_tension = -1.0"):
        fragments(mech, min_tension=-1.0)


@pytest.mark.parametrize("name, doc", [("luding-table1", lambda: sp.schedule_doc(300, 100.0, 0.1)),
                                       ("luding-three-particles", lambda: sp.control_doc(100.0, 1.0))])
def test_builtin_scenes_are_the_protocols_schedule(name, doc):
    from dem.scene import load_scene

    builtin, made = load_scene(name), parse_scene(doc())
    assert builtin.contact == made.contact == MAT
    assert np.array_equal(builtin.particles.position, made.particles.position)
    assert np.array_equal(builtin.particles.radius, made.particles.radius)
    a, b = builtin.motion, made.motion
    assert np.array_equal(a.velocity, b.velocity)
    def walls(m):
        return [(w.name, w.motion, w.point.tolist(), w.normal.tolist(), w.pressure, w.mass, w.damping) for w in m.walls]

    assert walls(a) == walls(b) and len(a.walls) == 4
    assert (a.verlet.schedule, a.phases, a.dt, a.dimension, a.height) == (b.verlet.schedule, b.phases, b.dt, b.dimension,
                                                                           b.height)
    assert builtin.solver.t_end == made.solver.t_end


def test_preparation_takes_table1_friction_on_particles_and_walls_unless_told():
    assert sp.preparation_doc(10, 10.0)["phases"] == [{"start": 0.0, "mu": MAT.mu, "mu_wall": MAT.mu}]
    assert sp.preparation_doc(10, 10.0, prep_mu=0.0)["phases"] == [{"start": 0.0, "mu": 0.0, "mu_wall": 0.0}]
    assert sp.preparation_doc(10, 10.0, prep_mu_wall=0.0)["phases"][0]["mu_wall"] == 0.0
    with pytest.raises(ValueError, match=r"prep_mu = -0.1: must be a finite friction coefficient >= 0"):
        sp.preparation_doc(10, 10.0, prep_mu=-0.1)
    with pytest.raises(ValueError, match=r"prep_mu_wall = nan"):
        sp.schedule_doc(10, 10.0, 0.1, prep_mu_wall=float("nan"))
