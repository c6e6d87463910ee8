"""3D FE of periodic cells read as the union of their spheres (fem_neck.lattice, neck = "union"): the range, the
exact volume, bounds that bracket and converge, an independent bound, refusals."""

import math

import numpy as np
import pytest

from fem_neck import lattice
from fem_neck.geometry.union import lens

# the deep holes of the cubic lattices (units of the cube edge): the points farthest from every centre
HOLES = {"sc": (0.5, 0.5, 0.5), "bcc": (0.5, 0.25, 0.0), "fcc": (0.5, 0.0, 0.0)}
# overlaps at which the necks of a particle meet (SC from h/r = 0.586, BCC 0.367, FCC 0.268), phi 0.96-0.97
DENSE = {"sc": 0.6, "bcc": 0.32, "fcc": 0.3}


@pytest.mark.parametrize("kind", lattice.KINDS)
def test_union_fills_space_at_the_covering_radius(kind):
    # at the largest overlap the deep hole is one radius from its nearest centre, and the exact volume of the cut
    # spheres is the whole period; just below it a pore is left
    h = lattice.union_max_h_over_r(kind)
    edge = lattice.EDGE_OVER_SPACING[kind] * (2.0 - h)
    sites = np.asarray(lattice.BASIS[kind])
    shifts = np.array([[x, y, z] for x in (-1, 0, 1) for y in (-1, 0, 1) for z in (-1, 0, 1)])
    centres = (sites[:, None, :] + shifts[None]).reshape(-1, 3) * edge
    hole = np.asarray(HOLES[kind]) * edge
    assert np.min(np.linalg.norm(centres - hole, axis=1)) == pytest.approx(1.0, rel=1e-12)
    assert lattice.lattice_cell(kind, h * (1 - 1e-12), neck="union").phi == pytest.approx(1.0, abs=1e-9)
    assert lattice.lattice_cell(kind, 0.95 * h, neck="union").phi < 1.0 - 1e-5


@pytest.mark.parametrize("kind, h_max", [("sc", 0.8453), ("bcc", 0.4508), ("fcc", 0.5858)])
def test_union_range_is_refused_in_one_line_outside(kind, h_max):
    assert lattice.union_max_h_over_r(kind) == pytest.approx(h_max, abs=1e-4)
    for h in (lattice.union_max_h_over_r(kind), 0.9, lattice.UNION_MIN_H_OVER_R * 0.99, -0.1, float("nan")):
        with pytest.raises(ValueError, match=r"^h_over_r = .*: valid range 0.02 <= h/r < .* for the union of") as e:
            lattice.lattice_cell(kind, h, neck="union")
        assert "\n" not in str(e.value)
    # beyond the pair necks' range (where they touch), within the union's
    lattice.lattice_cell(kind, 0.99 * lattice.union_max_h_over_r(kind), neck="union")
    with pytest.raises(ValueError, match="necks of one particle touch"):
        lattice.lattice_cell(kind, DENSE[kind])
    with pytest.raises(ValueError, match=r"neck = 'cylinder': must be one of newton, union"):
        lattice.lattice_cell(kind, 0.1, neck="cylinder")


def test_union_phi_counts_each_lens_once_where_necks_stay_apart():
    # below the meeting of necks the union is the spheres less one lens per bond (the lens of two unit spheres
    # 2 - h apart: two caps of height h/2)
    for kind, h in (("sc", 0.3), ("bcc", 0.2), ("fcc", 0.15)):
        cell = lattice.lattice_cell(kind, h, neck="union")
        caps = 2.0 * math.pi * (h / 2) ** 2 * (3.0 - h / 2) / 3.0
        bonds = lattice.COORDINATION[kind] * cell.n / 2
        assert cell.phi == pytest.approx((cell.n * 4.0 / 3.0 * math.pi - bonds * caps) / np.prod(cell.period),
                                         rel=1e-12)
    assert lattice.union_neck_ratio(0.3) == pytest.approx(lens(1.0, 1.0, 1.7).a, rel=1e-15)
    assert lattice.union_neck_ratio(0.3) == pytest.approx(math.sqrt(0.3 - 0.3**2 / 4), rel=1e-12)


@pytest.mark.parametrize("kind", lattice.KINDS)
def test_union_mesh_fills_the_exact_union_where_necks_meet(kind):
    # the CAD solid and the mapped tetrahedra have the exact volume of the cut spheres (fem_neck.geometry.union);
    # the circles are graded: the finest tetrahedra sit at them
    cell = lattice.lattice_cell(kind, DENSE[kind], neck="union")
    cm = lattice.build_cell_mesh(cell, **lattice.mesh_sizes(0.2))
    from fem_neck import primal

    assert cm.volume_exact == pytest.approx(cell.phi * np.prod(cell.period) / 8 * cm.wedge, rel=1e-15)
    assert cm.volume_cad / cm.volume_exact == pytest.approx(1.0, abs=1e-7)
    assert primal.volume(cm.curved) / cm.volume_exact == pytest.approx(1.0, abs=2e-8)
    assert not any(s.kind == "cylinder" for s in cm.curved.surfaces)


@pytest.mark.slow
def test_union_bounds_bracket_and_close_as_the_mesh_is_refined():
    # BCC where its necks meet: two meshes; every lower bound lies below every upper bound, the gap
    # falls with the neck size, and both lie under the Hashin-Shtrikman upper bound of an isotropic solid with pores
    # (cubic symmetry makes k_eff isotropic): 2 phi / (3 - phi)
    cell = lattice.lattice_cell("bcc", DENSE["bcc"], neck="union")
    runs = [lattice.solve_bounds(lattice.build_cell_mesh(cell, **lattice.mesh_sizes(size)), order, workers=1)
            for size, order in ((0.2, 3), (0.05, 3))]
    assert max(b.lower for b in runs) < min(b.upper for b in runs)
    assert runs[1].gap < 0.5 * runs[0].gap
    assert all(abs(b.volume_error) < 2e-8 and b.flux_defect < 1e-11 for b in runs)
    assert min(b.upper for b in runs) < 2.0 * cell.phi / (3.0 - cell.phi) < cell.phi


def _union_chain(h_over_r):
    """An infinite straight chain along z read as the union (neighbours in x and y far apart): each sphere is cut by
    the planes z = +-(1 - h/2), a body of revolution."""
    return lattice.PeriodicCell([[0.0, 0.0, 0.0]], [1.0], [4.0, 4.0, 2.0 - h_over_r], name="chain", neck="union")


def _union_chain_reference(h_over_r):
    """k_eff / kappa of the union chain from an independent solver: the axisymmetric FE (fem_neck.conduction, gmsh
    triangles graded toward the circle, isoparametric P4; P3 and grading 0.15 agree to 1e-8) of the half body, the
    unit sphere from its equator to the plane z = l = 1 - h/2; per period the chain is two half bodies in series,
    k_eff = (K_half / 2) d / (P_x P_y)."""
    from fem_neck import conduction, shapes

    l = 1.0 - h_over_r / 2.0
    a = math.sqrt((1.0 - l) * (1.0 + l))
    profile = shapes.profile_mesh((1.0, 0.0), [("arc", (a, l), 0.0, 1.0, "sphere0")], [[a, l]],
                                  sizes=shapes.SizeField(grading=0.3))
    return conduction.solve_profile(profile, 4).K / 2.0 * (2.0 - h_over_r) / 16.0


@pytest.mark.parametrize("h", [0.1, 0.3])
def test_union_chain_bounds_bracket_the_axisymmetric_truncated_sphere(h):
    # the mirror cell holds an eighth of the sphere cut by the cold plane at its circle: both bounds bracket the
    # independent axisymmetric value, their gap is 1.8-1.9 times the upper bound's error (measured), and the
    # exact volume is the sphere less its two caps
    cell = _union_chain(h)
    assert cell.phi == pytest.approx((4 / 3 * math.pi - 2 * math.pi * (h / 2) ** 2 * (3 - h / 2) / 3) / (16 * (2 - h)),
                                     rel=1e-13)
    b = lattice.solve_bounds(lattice.build_cell_mesh(cell, **lattice.mesh_sizes(0.1)), 3, workers=1)
    ref = _union_chain_reference(h)
    assert b.lower < ref < b.upper
    assert 1.0 < (b.upper - b.lower) / (b.upper - ref) < 3.0
    assert b.gap < 1e-2


@pytest.mark.slow
def test_union_chain_to_1e4_brackets_the_axisymmetric_truncated_sphere():
    res = lattice.effective_conductivity(_union_chain(0.3), rtol=1e-4)
    ref = _union_chain_reference(0.3)
    assert res.converged and res.k_lower_over_kappa < ref < res.k_upper_over_kappa
    assert (res.k_upper_over_kappa - res.k_lower_over_kappa) / (res.k_upper_over_kappa - ref) < 3.0


def test_union_first_mesh_and_prediction_use_the_unions_own_rule():
    cell = lattice.lattice_cell("fcc", 0.1, neck="union")
    neck = lattice.mean_neck_ratio(cell)
    assert neck == pytest.approx(lattice.union_neck_ratio(0.1), rel=1e-12)
    union, pair = lattice.first_neck_size(1e-3, neck, 3, "union"), lattice.first_neck_size(1e-3, neck, 3)
    assert union < pair  # the sharper edge needs a finer mesh for the same gap
    assert lattice.first_rtol(union, neck, 3, "union") == pytest.approx(1e-3, rel=1e-12)
    # a denser cell (less pore) is closer to uniform: a coarser mesh gives the same gap
    dense = lattice.first_neck_size(1e-3, neck, 3, "union", pore=0.03)
    assert dense / union == pytest.approx(10.0 ** (lattice.UNION_PORE_ORDER / lattice.UNION_GAP_ORDER), rel=1e-12)
    assert lattice.first_rtol(dense, neck, 3, "union", pore=0.03) == pytest.approx(1e-3, rel=1e-12)
    circles = lattice.neck_circles(cell)
    assert circles.neck == "union" and len(circles.a) == len(lattice.local_cluster(
        lattice.PeriodicCell(cell.centres, cell.radii, cell.period), cell.period / 2).bonds)
    predicted = lattice.predicted_tetrahedra(circles, 0.1)
    meshed = len(lattice.build_cell_mesh(cell, **lattice.mesh_sizes(0.1)).curved.tets)
    assert meshed <= predicted < 2.5 * meshed


def test_union_run_to_a_loose_tolerance_and_its_refusals():
    res = lattice.effective_conductivity(lattice.lattice_cell("sc", 0.3, neck="union"), rtol=1e-2, workers=1)
    assert res.converged and res.error_estimate <= 1e-2
    assert res.k_lower_over_kappa <= res.k_eff_over_kappa < 2.0 * res.phi / (3.0 - res.phi)
    with pytest.raises(ValueError, match=r"GB available; rtol = \d\.\de-\d\d would fit"):
        lattice.effective_conductivity(lattice.lattice_cell("fcc", 0.1, neck="union"), rtol=1e-6, max_memory=1e9)
    inside = lattice.PeriodicCell([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0]], [1.0, 0.5], [1.9, 1.9, 1.9], neck="union")
    with pytest.raises(ValueError, match="particle 1 lies inside particle 0"):
        lattice.check_cell(inside)


def test_a_mesh_whose_curved_element_folds_is_followed_by_one_twice_as_fine(monkeypatch):
    # (a random union packing of 80 spheres folds at neck size 0.1, too coarse for its small patches of sphere)
    from fem_neck.curved import FoldedMesh

    solve, sizes = lattice.solve_bounds, []

    def folding_once(cm, *args):
        sizes.append(cm.curved.tets.shape[0])
        if len(sizes) == 1:
            raise FoldedMesh("a curved element folds")
        return solve(cm, *args)

    monkeypatch.setattr(lattice.driver, "solve_bounds", folding_once)
    levels = []
    res = lattice.effective_conductivity(lattice.lattice_cell("sc", 0.3, neck="union"), rtol=1e-2, workers=1,
                                         progress=levels.append)
    assert res.converged and len(sizes) == 2 and sizes[1] > sizes[0] and len(res.levels) == 1
    first, second = (float(text.split()[2]) for text in levels)
    assert second == pytest.approx(first / 2, rel=1e-2)
    sizes.clear()
    with pytest.raises(FoldedMesh):  # on the last mesh allowed: reported
        lattice.effective_conductivity(lattice.lattice_cell("sc", 0.3, neck="union"), rtol=1e-2, workers=1,
                                       max_meshes=1)


@pytest.mark.parametrize("argv, match", [
    (["--kind", "sc", "--neck", "union", "--h-over-r", "0.85"], "valid range 0.02 <= h/r < 0.845299"),
    (["--kind", "fcc", "--neck", "union", "--h-over-r", "0.01"], "valid range 0.02 <= h/r < 0.585786"),
    (["--kind", "bcc", "--neck", "union", "--a-over-r", "0.9"], "a_over_r = 0.9: valid range 0.141067 <= a/r"),
    (["--kind", "sc", "--neck", "cylinder", "--h-over-r", "0.1"], "invalid choice"),
])
def test_union_cli_refuses_bad_input_in_one_line(capsys, monkeypatch, argv, match):
    from fem_neck.cli import main

    def no_meshing(*args, **kwargs):
        raise AssertionError("a mesh was made")

    monkeypatch.setattr(lattice.driver, "build_cell_mesh", no_meshing)
    try:
        rc = main(["lattice", *argv])
    except SystemExit as exc:
        rc = exc.code
    err = capsys.readouterr().err
    assert rc == 2 and len(err.strip().splitlines()) == 1 and match in err and "Traceback" not in err


def test_union_cli_json(capsys):
    import json

    from fem_neck.cli import main

    rc = main(["lattice", "--kind", "fcc", "--neck", "union", "--a-over-r", "0.6", "--rtol", "0.01", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert rc == 0 and out["converged"] and out["neck"] == "union"
    assert out["a_over_r"] == pytest.approx(0.6, rel=1e-12) and out["h_over_r"] == pytest.approx(0.4, rel=1e-12)
    assert out["phi"] == pytest.approx(lattice.lattice_cell("fcc", 0.4, neck="union").phi, rel=1e-14)
    assert out["k_lower_over_kappa"] <= out["k_eff_over_kappa"] < out["phi"]
    assert "k_network_fit_over_kappa" not in out
