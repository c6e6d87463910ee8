"""The snapshots of a moving run with thermal physics carry each contact's neck radius, conductance and heat flow and
each particle's heat flow: checked against the neck model and the law at each contact's overlap, and against the
contacts' own balance."""

import math

import meshio
import numpy as np

from dem import run
from dem.scene import parse_scene
from fem_neck import neck_radius
from test_dem_coupled import MATERIAL, pile


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
