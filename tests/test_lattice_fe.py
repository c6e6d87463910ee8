"""3D FE of periodic cells (fem_neck.lattice): bounds that bracket independent references, geometry, refusals."""

import math

import numpy as np
import pytest

from fem_neck import lattice
from fem_neck.geometry import neck_radius, overlap_for_neck

COARSE = lattice.level_sizes(0.0)


def _chain_cell(h_over_r):
    """An infinite straight chain along z (one sphere per period, neighbours in x and y far apart)."""
    return lattice.PeriodicCell([[0.0, 0.0, 0.0]], [1.0], [4.0, 4.0, 2.0 - h_over_r], name="chain")


def test_chain_cell_bounds_bracket_the_axisymmetric_pair():
    # The chain's mirror cell is a quarter of a semisphere with its half neck: its bounds must bracket the
    # axisymmetric hp-FE pair conductance (fem_neck.conduction, exact to 1e-8 here), an independent solver.
    from fem_neck.conduction import pair_conductance

    h = 0.08
    cell = _chain_cell(h)
    cm = lattice.build_cell_mesh(cell, **COARSE)
    b = lattice.solve_bounds(cm)
    K = pair_conductance(1.0, 1.0, h, kappa=1.0, rtol=1e-8).K
    # per period the chain is one pair bond: k_eff = K d / (P_x P_y); the cell carries Q = k_eff A / height
    k_ref = K * (2.0 - h) / 16.0
    scale = cm.height / cm.area
    assert b.lower * scale < k_ref < b.upper * scale
    assert (b.upper - b.lower) / b.upper < 2e-2  # coarse mesh: the bounds are ~1 % apart
    assert cm.wedge == 0.5  # x <-> y symmetric: the sixteenth of the period is meshed
    assert b.flux_defect < 1e-6  # the CR flux is divergence-free to the solver's tolerance


def test_sc_cell_bounds_bracket_and_sit_next_to_the_pair_network():
    # In a simple cubic lattice under a z gradient the x and y necks carry no heat: k_eff is the chain's K/d up to
    # the side necks' effect on the half bodies (measured +0.03 % for the network at h/r = 0.08).
    from fem_neck.conduction import pair_conductance

    h = 0.08
    cell = lattice.lattice_cell("sc", h)
    cm = lattice.build_cell_mesh(cell, **COARSE)
    b = lattice.solve_bounds(cm)
    scale = cm.height / cm.area
    network = pair_conductance(1.0, 1.0, h, kappa=1.0, rtol=1e-8).K / (2.0 - h)
    assert b.lower * scale < b.upper * scale
    assert abs(b.upper * scale / network - 1.0) < 2e-3
    assert b.lower * scale < network * (1 + 1e-3)
    assert b.volume_curved / cm.volume_exact == pytest.approx(1.0, abs=1e-5)  # curved P2 geometry
    assert cm.volume_cad / cm.volume_exact == pytest.approx(1.0, abs=1e-7)  # the union conserves volume


def test_two_meshes_give_consistent_bounds():
    # each mesh's bounds bracket the same exact value: the larger lower bound stays below the smaller upper bound
    cell = lattice.lattice_cell("bcc", 0.1)
    bounds = []
    for level in (-3.0, -1.5):
        cm = lattice.build_cell_mesh(cell, **lattice.level_sizes(level))
        b = lattice.solve_bounds(cm)
        bounds.append((b.lower * cm.height / cm.area, b.upper * cm.height / cm.area, b.elements))
    (lo0, up0, n0), (lo1, up1, n1) = bounds
    assert n1 > n0
    assert max(lo0, lo1) < min(up0, up1)
    assert up1 - lo1 < up0 - lo0  # the finer mesh narrows the gap


def test_effective_conductivity_refines_to_its_tolerance():
    res = lattice.effective_conductivity(_chain_cell(0.2), rtol=6e-3, start_level=-2.0)
    assert len(res.levels) >= 2 and res.levels[0]["gap"] > 6e-3  # the first mesh was too coarse
    assert res.converged and res.error_estimate <= 6e-3
    assert res.k_lower_over_kappa <= res.k_eff_over_kappa == res.k_upper_over_kappa
    assert res.phi == pytest.approx(4 / 3 * math.pi / (16 * 1.8), rel=1e-12)
    assert res.k_eff_over_kappa < res.phi  # Wiener: no microstructure beats the parallel bound


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["bcc", "fcc"])
def test_dense_lattices_to_1e3_below_the_wiener_bound(kind):
    res = lattice.effective_conductivity(lattice.lattice_cell(kind, 0.08), rtol=1e-3)
    coarse = lattice.effective_conductivity(lattice.lattice_cell(kind, 0.08), rtol=1.0, start_level=0.0)
    assert res.converged and res.error_estimate <= 1e-3
    assert max(res.k_lower_over_kappa, coarse.k_lower_over_kappa) < min(res.k_upper_over_kappa,
                                                                         coarse.k_upper_over_kappa)
    assert res.k_eff_over_kappa < res.phi


@pytest.mark.parametrize("kind, coordination", [("sc", 6), ("bcc", 8), ("fcc", 12)])
def test_lattice_cells_bonds_and_symmetry(kind, coordination):
    cell = lattice.lattice_cell(kind, 0.05)
    i, j, s = cell.bonds()
    assert len(i) == coordination * cell.n // 2
    e = cell.centres[j] + s * cell.period - cell.centres[i]
    assert np.allclose(np.linalg.norm(e, axis=1), 1.95)
    assert lattice.mirror_symmetry(cell) == (True, True, kind == "fcc")


@pytest.mark.parametrize("kind, a_limit", [("sc", math.sqrt(0.5)), ("bcc", math.sqrt(1 / 3)), ("fcc", 0.5)])
def test_lattice_refused_where_the_necks_of_a_particle_touch(kind, a_limit):
    # two necks at the angle theta touch when a/r = sin(theta/2): SC 90, BCC 70.53, FCC 60 degrees
    assert lattice.max_neck_ratio(kind) == pytest.approx(a_limit, rel=1e-12)
    h_limit = lattice.max_h_over_r(kind)
    assert neck_radius(1.0, 1.0, h_limit) == pytest.approx(a_limit, rel=1e-9)
    with pytest.raises(ValueError, match="necks of one particle touch"):
        lattice.lattice_cell(kind, h_limit * (1 + 1e-9))
    lattice.lattice_cell(kind, h_limit * (1 - 1e-6))
    # the general check refuses the same geometry, built without the lattice guard
    edge = lattice.EDGE_OVER_SPACING[kind] * (2.0 - h_limit * 1.01)
    cell = lattice.PeriodicCell(np.asarray(lattice.BASIS[kind]) * edge, np.ones(len(lattice.BASIS[kind])),
                                np.full(3, edge))
    with pytest.raises(ValueError, match="touch"):
        lattice.check_cell(cell)


def test_small_necks_and_asymmetric_cells_are_refused():
    with pytest.raises(ValueError, match="too thin to mesh"):
        lattice.lattice_cell("sc", overlap_for_neck(1.0, 1.0, 0.04))
    with pytest.raises(ValueError, match="kind"):
        lattice.lattice_cell("hcp", 0.05)
    cell = lattice.PeriodicCell([[0.0, 0.0, 0.0], [0.9, 0.3, 0.0]], [0.5, 0.5], [1.9, 1.9, 1.9])
    assert lattice.mirror_symmetry(cell)[0] is False
    with pytest.raises(ValueError, match="mirror"):
        lattice.build_cell_mesh(cell, **COARSE)
    with pytest.raises(ValueError, match="nothing conducts"):
        lattice.check_cell(lattice.PeriodicCell([[0.0, 0.0, 0.0]], [0.5], [2.0, 2.0, 2.0]))


@pytest.mark.parametrize("argv, match", [
    (["--kind", "fcc", "--h-over-r", "0.2"], "necks of one particle touch"),
    (["--kind", "bcc", "--a-over-r", "0.6"], "a_over_r = 0.6"),
    (["--kind", "sc", "--a-over-r", "0.01"], "a_over_r = 0.01"),
    (["--kind", "sc", "--h-over-r", "nan"], "h_over_r = nan"),
    (["--kind", "sc", "--h-over-r", "0.08", "--rtol", "0"], "rtol = 0"),
    (["--kind", "hcp", "--h-over-r", "0.08"], "invalid choice"),
])
def test_lattice_cli_refuses_bad_input_in_one_line(capsys, argv, match):
    from fem_neck.cli import main

    try:
        rc = main(["lattice", *argv])
    except SystemExit as exc:  # argparse's own refusals
        rc = exc.code
    err = capsys.readouterr().err
    assert rc == 2 and len(err.strip().splitlines()) == 1 and match in err


def test_lattice_cli_json_and_files(capsys, tmp_path):
    import json

    from fem_neck.cli import main

    rc = main(["lattice", "--kind", "sc", "--h-over-r", "0.2", "--rtol", "0.05", "--json", "--out", str(tmp_path)])
    out = json.loads(capsys.readouterr().out)
    assert rc == 0 and out["converged"] and out["error_estimate"] <= 0.05
    assert out["k_lower_over_kappa"] <= out["k_eff_over_kappa"] < out["phi"]
    assert out["coordination"] == 6 and abs(out["network_rel_error"]) < 0.01  # SC: the network holds
    assert {p.name for p in tmp_path.iterdir()} == {"lattice.json", "cell.vtu"}
