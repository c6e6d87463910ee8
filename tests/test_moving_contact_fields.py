"""The snapshots of a moving run with thermal physics carry each contact's neck radius, conductance and heat flow and
each particle's heat flow: checked against the neck model and the law at each contact's overlap, and against the
contacts' own balance."""

import math

import meshio
import pytest
import numpy as np

from dem import run
from dem.scene import parse_scene
from fem_neck import neck_radius
from test_dem_coupled import MATERIAL, pile


@pytest.mark.slow
def test_contacts_carry_neck_conductance_and_heat_flow(tmp_path):
    res = run(parse_scene(pile(t_end=0.003, law="rojek")), out=tmp_path / "run")
    last = sorted((tmp_path / "run").glob("contacts_*.vtu"))[-1]
    contacts = meshio.read(last)
    particles = meshio.read(tmp_path / "run" / last.name.replace("contacts_", "particles_"))
    lines = contacts.cells_dict["line"]
    data = {k: v[0] for k, v in contacts.cell_data.items()}
    r = particles.point_data["radius"]
    i, j = lines[:, 0], lines[:, 1]
    assert len(i) >= 6
    # the volume-conserving neck of each contact's overlap (Rojek 2022, eqs. 27-33), and the rojek law on it: each
    # half 1.064 kappa pi a, in series
    np.testing.assert_allclose(data["neck_radius"], neck_radius(r[i], r[j], data["overlap"]), rtol=1e-12)
    K = 1.064 * MATERIAL["conductivity"] * math.pi * data["neck_radius"] / 2.0
    np.testing.assert_allclose(data["conductance"], K, rtol=1e-12)
    T = res.engine.thermal.T  # the network's temperatures at the last snapshot
    np.testing.assert_allclose(data["heat_flow"], K * (T[i] - T[j]), rtol=1e-10, atol=1e-15)
    assert np.abs(data["heat_flow"]).max() > 1e-3  # W: heat does flow up from the floor
    # each particle's heat flow: what its contacts bring, plus its wall's where it touches the hot floor
    balance = np.bincount(j, data["heat_flow"], len(r)) - np.bincount(i, data["heat_flow"], len(r))
    q = particles.point_data["heat_flow"]
    z = particles.points[:, 2]
    above = z > 1.5 * r
    assert above.any() and (~above).any()
    np.testing.assert_allclose(q[above], balance[above], rtol=1e-10, atol=1e-15)
    assert np.all(q[~above] > balance[~above])  # the floor at 150 heats the bottom layer (at 80 and up)


@pytest.mark.parametrize("nodes", ["particles", "necks"])
@pytest.mark.slow
def test_a_snapshot_at_the_end_of_a_thermal_step_reads_its_bonds(tmp_path, monkeypatch, nodes):
    """The shared-body law on the union: the cut spheres' halves (union_halves, the costly part of its conductances)
    are computed once per thermal step, and the snapshots taken at its end (particles and contacts: two reads) reuse
    them; only the snapshot at the start, before any step, computes its own."""
    import dem.laws.conductance
    import dem.network.necks

    calls = []
    for module in (dem.laws.conductance, dem.network.necks):
        original = module.union_halves
        monkeypatch.setattr(module, "union_halves", lambda *a, _f=original, **k: calls.append(1) or _f(*a, **k))
    doc = pile(t_end=0.002, law="shared-body", thermal_interval=2.5e-4)
    doc["conductance"].update(neck="union", nodes=nodes)
    doc["output"] = {"interval": 2.5e-4, "vtu_interval": 2.5e-4}
    res = run(parse_scene(doc), out=tmp_path / "run")
    th = res.engine.thermal
    snapshots = len(list((tmp_path / "run").glob("particles_*.vtu")))
    assert snapshots == 9 and th.assemblies + th.refreshes == 8
    assert len(calls) == 8 + 1
