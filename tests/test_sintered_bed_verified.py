"""The verified k_eff of a sintering run's end (verification.sintered_bed.k_eff_trefftz): the union of its spheres as
the hand-over grew them, with a node per neck and the Trefftz element of each cut sphere, equal to that network built
and solved here directly; and the gap of the run's own k_eff to it against its law_error_range."""

import numpy as np
import pytest

from dem import parse_scene
from dem.engines.verlet.engine import VerletEngine
from dem.geometry.bonds import find_bonds
from dem.laws.conductance import ConductanceSpec
from dem.network.necks import neck_network, steady_necks
from dem.network.trefftz_element import trefftz_elements
from test_handover import squeezed


def _boxed(t_end: float) -> dict:
    """The squeezed cluster of tests/test_handover.py squeezed across z only, between a hot floor (100 C) and a cold
    ceiling (0 C) that its bottom and top layers overlap by 5 % of r, in a box closed by four side walls; the
    ``shared-body`` law."""
    scene = squeezed(t_end, rate=30.0)
    p = scene["particles"]
    x, r = np.array(p["position"]), p["radius"][0]
    p["velocity"] = [[u, v, 0.0] for u, v, _ in p["velocity"]]
    p["fixed"] = [False] * len(x)
    p["temperature"] = [50.0] * len(x)
    low, high = x.min(axis=0) - 0.95 * r, x.max(axis=0) + 0.95 * r
    side = x.max(axis=0) - x.min(axis=0)
    walls = [{"name": "hot", "point": [0.0, 0.0, low[2]], "normal": [0.0, 0.0, 1.0], "temperature": 100.0},
             {"name": "cold", "point": [0.0, 0.0, high[2]], "normal": [0.0, 0.0, -1.0], "temperature": 0.0}]
    for axis in (0, 1):
        for sign, at in ((1.0, low[axis] - side[axis]), (-1.0, high[axis] + side[axis])):
            normal = [0.0, 0.0, 0.0]
            normal[axis] = sign
            point = [0.0, 0.0, 0.0]
            point[axis] = at
            walls.append({"name": f"side{axis}{int(sign)}", "point": point, "normal": normal})
    scene["walls"] = walls
    scene["conductance"] = {"law": "shared-body", "out_of_range": "clip"}
    return scene


@pytest.fixture(scope="module")
def ended():
    engine = VerletEngine(parse_scene(_boxed(0.0012)))
    engine.run()
    return engine


@pytest.mark.slow  # some 7 s of CPU: the run, and the Trefftz elements of 63 particles with twelve necks, twice
def test_the_verified_k_eff_is_the_trefftz_neck_network_of_the_grown_spheres_solved_directly(ended):
    """At the end some particles are handed over (their radii grown): the study's k_eff is the steady heat between the
    walls of neck_network(elements=trefftz_elements) on the grown spheres' union bonds of the run's contacts, over
    the walls' box."""
    from verification import sintered_bed

    th, mech = ended.thermal, ended.mechanics
    grown = th.handover.steps > 0
    assert np.count_nonzero(grown) > 5
    k_eff, account = sintered_bed.k_eff_trefftz(ended)

    radius = np.where(grown, th.handover.solid_radius, mech.state.radius)
    assert np.all(radius[grown] > mech.state.radius[grown])
    particles = th._particles_now(mech, radius)
    walls = th._walls_now(mech)
    bonds = find_bonds(particles, walls, "union", "error", pairs=mech.contacts()[:2], box=th.box)
    spec = ConductanceSpec(law="shared-body", neck="union", nodes="necks", element="trefftz")
    net = neck_network(spec, particles, bonds, walls=walls, elements=trefftz_elements)
    into = np.bincount(bonds.wall_index[net.live_walls], steady_necks(net).wall_flow, minlength=len(walls))
    assert abs(into[0] + into[1]) < 1e-9 * abs(into[0])  # what leaves the floor enters the ceiling
    height = walls[1].point[2] - walls[0].point[2]
    area = ended.box_volume() / height
    assert k_eff == pytest.approx(-into[0] * height / (area * 100.0), rel=1e-9)
    assert account["element"] == "trefftz" and account["element_particles"] > 0


def test_the_gap_of_the_run_to_it_is_read_against_its_law_error_range():
    """verified(): the gap is the run's k_eff over the verified one minus one, within its law_error_range or not."""
    from verification.sintered_bed import verified

    inside = verified(1.01, 1.0, {"element": "trefftz"}, [-0.037, 0.048])
    assert inside["gap"] == pytest.approx(0.01, rel=1e-12) and inside["within"] is True
    assert inside["own"] == 1.01 and inside["k_eff"] == 1.0 and inside["element"] == "trefftz"
    assert verified(0.95, 1.0, {}, [-0.037, 0.048])["within"] is False
    assert verified(1.05, 1.0, {}, [-0.037, 0.048])["within"] is False
    assert verified(1.0, 1.0, {}, None)["within"] is None


def test_the_report_says_the_gap_and_fails_a_run_outside_its_range():
    """report(): the summary carries the verified k_eff, the gap and whether it is within the range; a target fails a
    run whose gap lies outside it (by the distance outside), and the markdown line says so."""
    from verification.sintered_bed import report, verified

    def case(own, k_eff, pair_read=0):
        return {"summary": {"particles_necks_meeting": 3}, "k_eff": own, "wiener": 2.0, "largest_jump": None,
                "above_wiener": -0.5, "kappa": 2.0,
                "verified": verified(own, k_eff, {"element": "trefftz", "element_particles": 7, "element_plain": 1,
                                                  "element_seconds": 2.0}, [-0.037, 0.048], pair_read)}

    summary, targets, lines = report({"in": case(1.02, 1.0), "out": case(1.10, 1.0), "pair": case(1.3, 1.0, 5)})
    assert summary["in k_eff verified (trefftz)"] == 1.0 and summary["in gap within law_error_range"] is True
    assert summary["out gap to the verified k_eff"] == pytest.approx(0.10, rel=1e-12)
    gaps = {label.split(":")[0]: measured for label, measured, limit in targets if "law_error_range" in label}
    assert gaps["in"] == 0.0 and gaps["out"] == pytest.approx(0.10 - 0.048, rel=1e-12)
    assert "pair" not in gaps and summary["pair gap within law_error_range"] is False  # said, not held: geometries
    assert "+2.00 % from the verified 0.5000 kappa (within" in lines[0] and "outside" in lines[1]
    assert "5 particles still read as pair necks" in lines[2] and "pair necks" not in lines[0]
