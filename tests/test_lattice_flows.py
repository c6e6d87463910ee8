"""Per-neck flows and temperatures of the union cells' FE (fem_neck.lattice.flows): heat conserved particle by
particle, the necks' flows summing to the cell's flux, and the lattices' symmetric answers."""

import json

import numpy as np
import pytest

from fem_neck import lattice
from fem_neck.geometry.union import cut_spheres


def _solve(cell, rtol):
    res = lattice.effective_conductivity(cell, rtol=rtol, flows=True)
    dz = (cell.centres[res.flows.j] + res.flows.shift * cell.period - cell.centres[res.flows.i])[:, 2]
    return res, res.flows, dz


def _cut_volumes(cell):
    i, j, s = cell.bonds()
    return cut_spheres(cell.radii, i, j, cell.centres[j] + s * cell.period - cell.centres[i]).volume


@pytest.mark.slow
def test_mirror_packing_conserves_heat_per_particle_and_its_necks_carry_the_cells_flux():
    from verification.packings import _images

    # 16 spheres of radii 1.15 and 0.95, the 8 mirror images of two, phi 0.855: necks meeting, lenses hidden
    period = np.array([3.5, 3.5, 3.6])
    cell = lattice.PeriodicCell(_images(np.array([[0.5, 1.2, 1.15], [1.25, 0.5, 0.6]]), period),
                                np.tile([1.15, 0.95], 8), period, "two mirrored spheres", neck="union")
    res, f, dz = _solve(cell, 1e-2)
    k = res.k_eff_over_kappa
    scale = np.abs(f.flow).max()
    assert np.abs(f.residual).max() < 1e-4 * scale                     # every particle: inflow = outflow
    # the heat across a period face, as the hot faces' reactions and as the necks' flows times their z-lengths
    assert f.total / (cell.period[0] * cell.period[1]) == pytest.approx(k, rel=1e-9)
    assert np.sum(f.flow * dz) / np.prod(cell.period) == pytest.approx(k, rel=1e-4)
    assert (~f.face).any() and np.all(f.flow[~f.face] == 0.0)         # lenses inside a third sphere: no face
    assert np.all(np.isnan(f.face_temperature[~f.face])) and np.all(np.isfinite(f.face_temperature[f.face]))
    assert f.volume == pytest.approx(_cut_volumes(cell), rel=1e-2)
    # heat runs down the temperature: from each face to the particle of lower mean temperature
    drop = f.temperature[f.i] - (f.temperature[f.j] - f.shift[:, 2] * cell.period[2])
    strong = f.face & (np.abs(f.flow) > 0.05 * scale)
    assert np.all(np.sign(f.flow[strong]) == np.sign(drop[strong]))


@pytest.mark.parametrize("kind, h", [("sc", 0.3), ("fcc", 0.3)])
@pytest.mark.slow
def test_lattice_necks_by_symmetry(kind, h):
    """A Bravais lattice is symmetric under inversion through every site and every bond's midpoint, so the fluctuation
    of the temperature vanishes there: each face's mean temperature is -z of its centre and each particle's -z of its
    own (the FE's cell has only the mirror planes, not these symmetries); necks normal to the gradient carry nothing
    and the others all the same flow, k_eff A per neck crossing the period face."""
    cell = lattice.lattice_cell(kind, h, neck="union")
    res, f, dz = _solve(cell, 1e-3)
    k = res.k_eff_over_kappa
    P = cell.period
    assert np.sum(f.flow * dz) / np.prod(P) == pytest.approx(k, rel=1e-5)
    assert np.abs(f.residual).max() < 1e-6 * np.abs(f.flow).max()
    flat = np.abs(dz) < 1e-9
    assert np.abs(f.flow[flat]).max() < 1e-8 * np.abs(f.flow).max()
    q = f.flow[~flat] * np.sign(dz[~flat])
    assert q == pytest.approx(np.full(len(q), q[0]), rel=1e-6)
    crossing = np.sum(np.abs(dz[~flat])) / P[2]  # bonds crossing a period face
    assert q[0] * crossing == pytest.approx(k * P[0] * P[1], rel=1e-5)
    middle = cell.centres[f.i, 2] + 0.5 * dz
    assert f.face_temperature == pytest.approx(-middle, abs=1e-4 * P[2])  # (measured: 4e-6)
    assert f.temperature == pytest.approx(-cell.centres[:, 2], abs=1e-9 * P[2])
    assert f.volume == pytest.approx(_cut_volumes(cell), rel=1e-3)


@pytest.mark.slow
def test_flows_refused_on_pair_necks_and_cli_json(capsys):
    from fem_neck.cli import main

    with pytest.raises(ValueError, match="flows: per-neck flows are read on the union of spheres"):
        lattice.effective_conductivity(lattice.lattice_cell("sc", 0.1), rtol=1e-2, flows=True)
    rc = main(["lattice", "--kind", "sc", "--h-over-r", "0.1", "--flows"])
    err = capsys.readouterr().err
    assert rc == 2 and len(err.strip().splitlines()) == 1 and "add --neck union" in err
    rc = main(["lattice", "--kind", "bcc", "--neck", "union", "--h-over-r", "0.3", "--rtol", "0.01", "--flows",
               "--json"])
    out = json.loads(capsys.readouterr().out)
    assert rc == 0
    bonds = out["flows"]["bonds"]
    # BCC at h/r = 0.3 > 2 - sqrt 3: 8 first-neighbour bonds between its two sites, 3 second-neighbour ones of each
    assert len(bonds) == 14 and len(out["flows"]["particle_temperature"]) == 2
    second = [b for b in bonds if b["i"] == b["j"]]
    along_z = [b["flow"] for b in second if b["shift"] == [0, 0, 1]]
    assert len(second) == 6 and all(b["flow"] == 0.0 for b in second if b["shift"][2] == 0)  # normal to the gradient
    assert len(along_z) == 2 and along_z[0] > 0.0 and along_z[1] == pytest.approx(along_z[0], rel=1e-2)
    assert out["flows"]["total_flow"] == pytest.approx(out["k_eff_over_kappa"] * lattice.lattice_cell(
        "bcc", 0.3, neck="union").period[0] ** 2, rel=1e-9)
