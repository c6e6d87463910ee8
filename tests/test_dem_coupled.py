"""Moving particles coupled to the thermal network: conductances follow the overlaps, the heat balance stays exact
through contact changes, and a hot wall softens the contacts it heats (Luding 2005 eq. 10 with Rojek 2022's pipes)."""

import numpy as np
import pytest

from dem.engines.verlet.engine import VerletEngine
from dem.scene import parse_scene
from fem_neck import neck_radius

# no thermal expansion here: 4 K of heating would grow a radius by 4e-7 m, far beyond the weight's overlap of 4e-9 m
CONTACT = {"law": "luding", "k1": 1.0e4, "k2": 2.0e4, "kc": 1.0e4, "kt_ratio": 0.2, "gamma_n": 0.05,
           "gamma_t": 0.01, "mu": 0.5, "mu_wall": 0.0, "T_melt": 120.0, "T_var": 10.0, "expansion": 0.0,
           "fluid_overlap": 0.2, "t0": 0.01, "brittle_sliding": True}
MATERIAL = {"conductivity": 400.0, "density": 1000.0, "specific_heat": 10.0}  # fast: C/K ~ 10 ms


def pile(n_side=3, t_end=0.01, hot=150.0, law="fit", velocity=0.0, **solver):
    """``n_side^2`` spheres on a hot floor under gravity, a cold ceiling far above them."""
    r = 1e-3
    g = np.arange(n_side) * 2.0 * r  # touching: gravity closes the contacts
    x, z = np.meshgrid(g + r, g + r, indexing="ij")
    pos = np.column_stack([x.ravel(), np.zeros(x.size), z.ravel()])
    rng = np.random.default_rng(0)
    doc = {"scene": {"physics": ["mechanical", "thermal"]}, "material": dict(MATERIAL),
           "particles": {"position": pos.tolist(), "radius": [r] * len(pos), "temperature": [80.0] * len(pos),
                         "velocity": (velocity * rng.normal(size=pos.shape)).tolist()},
           "contact": dict(CONTACT),
           "walls": [{"name": "floor", "point": [0, 0, 0], "normal": [0, 0, 1], "temperature": hot}],
           "gravity": {"acceleration": [0.0, 0.0, -9.81]},
           "conductance": {"law": law, "out_of_range": "clip"},
           "solver": {"mode": "transient", "t_end": t_end, "integrator": "implicit", **solver}}
    return doc


def test_every_contact_conductance_is_the_law_at_its_overlap():
    sim = VerletEngine(parse_scene(pile(t_end=0.005)))
    sim.run()
    th, mech = sim.thermal, sim.mechanics
    i, j, overlap = mech.contacts()[:3]
    assert len(i) > 0 and th.net.bonds.n_walls > 0
    r = mech.state.radius
    a = neck_radius(r[i], r[j], overlap)
    assert np.allclose(th.net.bonds.a, a, rtol=1e-12)
    bonds, K_pairs, K_walls = th.bonds(mech)
    assert np.array_equal(K_pairs, th.net.K_pairs) and np.array_equal(K_walls, th.net.K_walls)


@pytest.mark.slow
def test_heat_balance_exact_through_contact_changes():
    """Particles shaken so that contacts open and close while heat flows in from the floor."""
    sim = VerletEngine(parse_scene(pile(t_end=0.01, velocity=0.05, thermal_interval=2e-4)))
    sim.run()
    th = sim.thermal
    assert th.assemblies > 3, "the contact set must have changed"
    assert th.refreshes > 0
    assert th.heat_in["walls"] > 0
    assert th.energy_error() < 1e-12


def test_temperatures_reach_the_mechanics_and_soften_the_hot_contacts():
    sim = VerletEngine(parse_scene(pile(t_end=0.02)))
    sim.run()
    s, mech = sim.mechanics.state, sim.mechanics
    assert np.array_equal(s.T, sim.thermal.T)
    bottom = s.x[:, 2] < 1.5e-3
    assert s.T[bottom].mean() > s.T[~bottom].mean() > 80.0
    # the stiffness factor relaxes towards k1(T) of eq. 10: lower where it is hotter
    assert mech.particle_column("k1_factor")[bottom].mean() < mech.particle_column("k1_factor")[~bottom].mean()
    assert sim.temperature_source == "network"


def test_prescribed_schedule_and_network_are_exclusive():
    doc = pile()
    doc["temperature"] = {"time": [0.0, 1.0], "value": [80.0, 140.0]}
    with pytest.raises(ValueError, match="schedule and a thermal network"):
        parse_scene(doc)


def test_two_dimensional_thermal_coupling_is_refused():
    doc = pile()
    doc["scene"].update(dimension=2, height=1e-3)
    with pytest.raises(ValueError, match="thermal coupling needs 3D spheres"):
        parse_scene(doc)


def test_overlap_beyond_the_neck_model_is_named():
    doc = pile(t_end=1e-4)
    doc["conductance"]["out_of_range"] = "error"
    pos = doc["particles"]["position"]
    pos[1][2] = pos[0][2] + 1.2e-3  # overlap 0.8 mm > 2r/3
    with pytest.raises(ValueError, match="particles 0 and 1.*h = 0.000795"):
        VerletEngine(parse_scene(doc)).run()


def test_cooling_by_the_network_freezes_the_contacts():
    """Hot particles on a cold floor: the network cools them, the mechanics sees the temperature fall (the rate of
    the network's last step) and the stiffness factor follows k1(T) at once (the rapid freeze of Sec. 3.4), instead
    of relaxing with t0."""
    doc = pile(t_end=0.01, hot=20.0)
    doc["particles"]["temperature"] = [150.0] * len(doc["particles"]["temperature"])
    doc["contact"]["t0"] = 1e6  # relaxing would take for ever: only the freeze can raise the factor
    sim = VerletEngine(parse_scene(doc))
    start = sim.mechanics.particle_column("k1_factor").copy()
    sim.run()
    assert np.all(sim.thermal.rate <= 0.0) and np.any(sim.thermal.rate < 0.0)
    cooled = sim.mechanics.state.T < 149.0
    assert np.any(cooled)
    assert np.all(sim.mechanics.particle_column("k1_factor")[cooled] > start[cooled])
