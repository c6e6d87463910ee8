"""3D FE of periodic cells (fem_neck.lattice): bounds that bracket independent references, geometry, refusals."""

import math
import sys

import numpy as np
import pytest

from fem_neck import lattice
from fem_neck.geometry import neck_radius, overlap_for_neck
from verification.lattices import REFERENCES

COARSE = lattice.mesh_sizes(0.1)


def _chain_cell(h_over_r):
    """An infinite straight chain along z (one sphere per period, neighbours in x and y far apart)."""
    return lattice.PeriodicCell([[0.0, 0.0, 0.0]], [1.0], [4.0, 4.0, 2.0 - h_over_r], name="chain")


def _chain_reference(h_over_r):
    """k_eff / kappa of the chain cell from the axisymmetric hp-FE pair conductance (fem_neck.conduction, exact to
    1e-8 here), an independent solver: per period the chain is one pair bond, k_eff = K d / (P_x P_y)."""
    from fem_neck.conduction import pair_conductance

    return pair_conductance(1.0, 1.0, h_over_r, kappa=1.0, rtol=1e-8).K * (2.0 - h_over_r) / 16.0


@pytest.mark.parametrize("order", [1, 2, 5])
def test_an_order_without_a_measured_first_mesh_is_refused_by_name(order):
    with pytest.raises(ValueError, match=rf"order = {order}: must be one of 3, 4 \(the orders whose first mesh"):
        lattice.effective_conductivity(_chain_cell(0.08), rtol=1e-3, order=order)


@pytest.mark.parametrize("order", [2, 3])
def test_chain_cell_bounds_bracket_the_axisymmetric_pair(order):
    # The chain's mirror cell is a quarter of a semisphere with its half neck: both bounds must bracket the
    # axisymmetric reference, and their gap must be 1-3x the upper bound's true error (the two errors are alike).
    h = 0.08
    cm = lattice.build_cell_mesh(_chain_cell(h), **COARSE)
    b = lattice.solve_bounds(cm, order, workers=1)
    k_ref = _chain_reference(h)
    assert b.lower < k_ref < b.upper
    assert 1.0 < (b.upper - b.lower) / (b.upper - k_ref) < 3.0
    assert b.gap < (2e-2 if order == 2 else 4e-3)
    assert cm.wedge == 0.5  # x <-> y symmetric: the sixteenth of the period is meshed
    assert b.flux_defect < 1e-12  # the equilibrated flux's normal component is continuous to round-off
    assert abs(b.volume_error) < 1e-7  # the mapped tetrahedra fill the exact solid (quadrature of degree 10)


def test_sc_cell_bounds_bracket_the_reference_and_sit_next_to_the_pair_network():
    # In a simple cubic lattice under a z gradient the x and y necks carry no heat: k_eff is the chain's K/d up to
    # the side necks' effect on the half bodies (+0.02 % for the network at h/r = 0.08).
    from fem_neck.conduction import pair_conductance

    h = 0.08
    cell = lattice.lattice_cell("sc", h)
    cm = lattice.build_cell_mesh(cell, **COARSE)
    b = lattice.solve_bounds(cm, 3, workers=1)
    network = pair_conductance(1.0, 1.0, h, kappa=1.0, rtol=1e-8).K / (2.0 - h)
    assert b.lower < REFERENCES[("sc", 0.08)] < b.upper
    assert abs(b.upper / network - 1.0) < 2e-3
    assert cm.volume_cad / cm.volume_exact == pytest.approx(1.0, abs=1e-7)  # the union conserves volume


def test_mapped_mesh_fills_the_exact_solid():
    # every boundary vertex, edge and face point lies on its sphere, cylinder or plane; the straight tetrahedra
    # alone miss the curved solid by ~1e-3 of its volume, the mapped ones by the quadrature error only
    from fem_neck import primal
    from fem_neck.simplex import triangle_quadrature, face_points

    cm = lattice.build_cell_mesh(lattice.lattice_cell("bcc", 0.1), **COARSE)
    mesh = cm.curved
    straight = np.abs(np.linalg.det(mesh.affine_jacobians())).sum() / 6.0
    assert abs(straight / cm.volume_exact - 1.0) > 1e-4
    assert primal.volume(mesh, 16) / cm.volume_exact == pytest.approx(1.0, abs=1e-7)
    st, _ = triangle_quadrature(4)
    owner = np.repeat(np.arange(len(mesh.tets)), 4)
    local = np.tile(np.arange(4), len(mesh.tets))
    on_boundary = np.isin(mesh.t2f.ravel(), mesh.boundary_faces)
    surface_of = dict(zip(mesh.boundary_faces.tolist(), mesh.face_surface.tolist()))
    for el, l in zip(owner[on_boundary][:400], local[on_boundary][:400]):
        x, _ = mesh.map(np.array([el]), face_points(l, st))
        surface = mesh.surfaces[surface_of[int(mesh.t2f[el, l])]]
        assert surface.distance(x[0]).max() < 1e-12


@pytest.mark.slow
def test_collinear_necks_share_one_cylinder():
    # opposite bonds of a lattice put two necks of one sphere on one cylinder: one surface, so that the edges between
    # its patches are surface edges (at BCC a/r = 0.52 the mesher splits the cylinder there)
    from fem_neck import curved

    a, b = curved.cylinder([0, 0, 0], [1, 1, 1], 0.5), curved.cylinder([-1, -1, -1], [-1, -1, -1], 0.5)
    assert len(curved.distinct([a, b, curved.cylinder([0, 0, 0.1], [1, 1, 1], 0.5)], 1e-9)) == 2
    cm = lattice.build_cell_mesh(lattice.lattice_cell("bcc", overlap_for_neck(1.0, 1.0, 0.52)),
                                 **lattice.mesh_sizes(0.0155))
    assert len(cm.curved.tets) > 0


@pytest.mark.slow
def test_finer_quadrature_moves_the_bounds_by_less_than_1e7():
    from fem_neck import dual, primal

    cm = lattice.build_cell_mesh(lattice.lattice_cell("fcc", 0.08), **COARSE)
    m = cm.curved
    low = [dual.solve(m, 2, cm.hot, cm.cold, degree=d).lower for d in (6, 12)]
    assert low[0] == pytest.approx(low[1], rel=1e-7)
    up = [primal.solve(m, 3, cm.hot, cm.cold, degree=d).energy for d in (6, 12)]
    assert up[0] == pytest.approx(up[1], rel=1e-7)


def test_the_lower_bound_is_admissible_whatever_the_face_solvers_iterate():
    # the face system stopped far from its solution (residual > 1e-5) still gives a flux whose normal component is
    # continuous to round-off (the equilibration), so its P^2/E* lies below the reference -- and below the bound of
    # the iterate solved to its settled energy, the best flux of the same space
    from fem_neck import dual

    cm = lattice.build_cell_mesh(lattice.lattice_cell("sc", 0.08), **COARSE)
    scale = cm.height / cm.area
    crude = dual.solve(cm.curved, 2, cm.hot, cm.cold, etol=1e-2)
    settled = dual.solve(cm.curved, 2, cm.hot, cm.cold)
    assert crude.residual > 1e-5 and crude.iterations < settled.iterations
    assert crude.flux_defect < 1e-12 and settled.flux_defect < 1e-12
    assert crude.lower < settled.lower * (1.0 + 1e-12)
    assert settled.lower * scale < REFERENCES[("sc", 0.08)]


@pytest.mark.slow
def test_the_lower_bounds_cg_started_from_the_upper_bounds_temperature_takes_fewer_steps_to_the_same_bound():
    from fem_neck import dual, primal

    cm = lattice.build_cell_mesh(lattice.lattice_cell("bcc", 0.08), **COARSE)
    up = primal.solve(cm.curved, 3, cm.hot, cm.cold)
    cold = dual.solve(cm.curved, 2, cm.hot, cm.cold)
    warm = dual.solve(cm.curved, 2, cm.hot, cm.cold, start=lambda: dual.trace_multipliers(cm.curved, 3, up.u, 2))
    assert warm.iterations < 0.75 * cold.iterations
    assert warm.lower == pytest.approx(cold.lower, rel=1e-9)


@pytest.mark.slow
def test_a_lower_bound_that_fails_before_it_reads_the_temperature_is_reported_not_waited_for(monkeypatch):
    # the upper bound hands its temperature (here > 64 kB, more than a pipe holds) to the lower bound's process
    # after solving; had that process failed first, a blocking hand-over would wait for ever (the alarm fails it)
    import signal

    from fem_neck import dual

    def broken(*args, **kwargs):
        raise ValueError("the face system failed")

    cm = lattice.build_cell_mesh(lattice.lattice_cell("bcc", 0.08), **lattice.mesh_sizes(0.05))
    monkeypatch.setattr(dual, "face_system", broken)  # (the forked process has it too)

    def waited(signum, frame):
        raise TimeoutError("solve_bounds waited for the failed lower bound")

    previous = signal.signal(signal.SIGALRM, waited)
    signal.alarm(60)
    try:
        with pytest.raises(ValueError, match="the face system failed"):
            lattice.solve_bounds(cm, 4, workers=2)
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    assert cm.curved.kept is None  # the Jacobians the two bounds shared go with the failed solve


def test_primal_cg_stops_when_the_energy_has_settled():
    # the upper bound's CG stops on its energy (an upper bound whatever the iterate): within the tolerance of the
    # energy solved to round-off, above it, in fewer iterations
    from fem_neck import primal

    cm = lattice.build_cell_mesh(_chain_cell(0.08), **COARSE)
    loose = primal.solve(cm.curved, 3, cm.hot, cm.cold)
    tight = primal.solve(cm.curved, 3, cm.hot, cm.cold, etol=1e-15)
    assert loose.energy == pytest.approx(tight.energy, rel=10 * primal.ENERGY_RTOL)
    assert loose.energy >= tight.energy * (1.0 - 1e-12)  # CG lowers the energy (up to its round-off)
    assert loose.iterations < tight.iterations


def test_primal_reports_its_first_iterate_settled_to_a_looser_tolerance_once():
    # the temperature the lower bound's CG starts from: an earlier iterate, within the looser tolerance of the final
    # energy, and the final CG unchanged by the report
    from fem_neck import primal

    cm = lattice.build_cell_mesh(_chain_cell(0.08), **COARSE)
    reports = []
    plain = primal.solve(cm.curved, 3, cm.hot, cm.cold, etol=1e-12)
    final = primal.solve(cm.curved, 3, cm.hot, cm.cold, etol=1e-12, early=(1e-4, reports.append))
    assert len(reports) == 1 and final.energy == plain.energy and final.iterations == plain.iterations
    u = reports[0]
    assert u.shape == final.u.shape and 0.0 < np.max(np.abs(u - final.u)) < 1e-2
    hot = primal.face_dofs(cm.curved, primal.lagrange(3), cm.hot)
    np.testing.assert_array_equal(u[hot], 1.0)                               # the held values


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="prctl is Linux's")
def test_the_bounds_run_without_transparent_huge_pages_and_give_them_back():
    import ctypes

    from fem_neck.lattice.bounds import small_pages

    prctl = ctypes.CDLL(None).prctl
    before = prctl(42, 0, 0, 0, 0)                                             # PR_GET_THP_DISABLE
    with small_pages():
        assert prctl(42, 0, 0, 0, 0) == 1
    assert prctl(42, 0, 0, 0, 0) == before


def _coarse_first_mesh(monkeypatch):
    """A first-mesh rule for p = 3 that believes the bounds 5x closer than they are: the first mesh is too coarse."""
    size0, rtol0, neck_order, margin = lattice.FIRST_MESH[3]
    monkeypatch.setitem(lattice.FIRST_MESH, 3, (size0, rtol0 / 5.0, neck_order, margin))


def test_effective_conductivity_refines_to_its_tolerance(monkeypatch):
    _coarse_first_mesh(monkeypatch)
    res = lattice.effective_conductivity(_chain_cell(0.02), rtol=1e-3, workers=1)
    assert len(res.levels) >= 2 and res.levels[0]["gap"] > 1e-3  # the first mesh was too coarse
    assert res.converged and res.error_estimate <= 1e-3
    assert res.k_lower_over_kappa <= _chain_reference(0.02) <= res.k_eff_over_kappa == res.k_upper_over_kappa
    assert res.phi == pytest.approx(4 / 3 * math.pi / (16 * 1.98), rel=1e-12)
    assert res.k_eff_over_kappa < res.phi  # Wiener: no microstructure beats the parallel bound


def test_first_mesh_is_coarser_for_larger_necks_and_looser_tolerances():
    # the mean neck of a lattice is its pair neck
    assert lattice.mean_neck_ratio(lattice.lattice_cell("bcc", 0.08)) == pytest.approx(neck_radius(1, 1, 0.08))
    small, large = (lattice.first_neck_size(1e-4, x, 4) for x in (0.2, 0.4))
    assert large / small == pytest.approx(2.0 ** (lattice.FIRST_MESH[4][2] / lattice.GAP_ORDER), rel=1e-12)
    # not extrapolated below the smallest neck measured: a smaller neck gets the a/r = 0.2 mesh
    assert lattice.first_neck_size(1e-4, 0.1, 4) == small
    assert lattice.first_neck_size(2e-4, 0.2, 4) / small == pytest.approx(2.0 ** (1 / lattice.GAP_ORDER), rel=1e-12)
    # p = 3: its own dependence on the neck
    assert (lattice.first_neck_size(1e-3, 0.4, 3) / lattice.first_neck_size(1e-3, 0.2, 3)
            == pytest.approx(2.0 ** (lattice.FIRST_MESH[3][2] / lattice.GAP_ORDER), rel=1e-12))
    # first_rtol inverts it (what the refusal names)
    assert lattice.first_rtol(lattice.first_neck_size(1e-4, 0.3, 4), 0.3, 4) == pytest.approx(1e-4, rel=1e-12)


def test_a_run_that_would_not_fit_is_refused_with_the_rtol_that_would():
    with pytest.raises(ValueError, match=r"GB available; rtol = \d\.\de-\d\d would fit") as info:
        lattice.effective_conductivity(_chain_cell(0.2), rtol=1e-6, max_memory=0.8e9, workers=1)
    fit = float(str(info.value).split("rtol = ")[-1].split()[0])
    assert 1e-6 < fit < 1e-2
    with pytest.raises(ValueError, match="more than the 0.1 GB available"):
        lattice.effective_conductivity(_chain_cell(0.2), rtol=1e-3, max_memory=0.1e9, workers=1)


@pytest.mark.parametrize("cell, size_neck", [(_chain_cell(0.02), 0.03), (lattice.lattice_cell("sc", 0.08), 0.1),
                                             (lattice.lattice_cell("bcc", 0.02), 0.03),
                                             (lattice.lattice_cell("fcc", 0.08), 0.3)])
@pytest.mark.slow
def test_tetrahedra_predicted_before_meshing_on_the_safe_side(cell, size_neck):
    # the prediction (from the cell and the sizes alone) is at least the mesh's tetrahedra, and not wildly more
    predicted = lattice.predicted_tetrahedra(lattice.neck_circles(cell), size_neck)
    meshed = len(lattice.build_cell_mesh(cell, **lattice.mesh_sizes(size_neck)).curved.tets)
    assert meshed <= predicted < 2.0 * meshed


def _no_meshing(*args, **kwargs):
    raise AssertionError("a mesh was made")


def test_a_first_mesh_that_would_not_fit_is_refused_before_meshing(monkeypatch):
    # BCC h/r = 0.02 at 1e-5: the first mesh is predicted from the cell and refused before gmsh is called, naming
    # the estimate and an rtol whose first mesh is predicted to fit
    monkeypatch.setattr(lattice.driver, "build_cell_mesh", _no_meshing)
    cell = lattice.lattice_cell("bcc", 0.02)
    with pytest.raises(ValueError, match=r"bcc: the first mesh \(neck size 0.00\d+ a, ~\d+ tetrahedra\) needs "
                                         r"~\d+\.\d GB, more than the 1.0 GB available; rtol = \d\.\de-\d\d would fit"):
        lattice.effective_conductivity(cell, rtol=1e-5, max_memory=1e9)
    with pytest.raises(ValueError) as info:
        lattice.effective_conductivity(cell, rtol=1e-5, max_memory=1e9)
    fit = float(str(info.value).split("rtol = ")[-1].split()[0])
    assert 1e-5 < fit < 1e-3
    with pytest.raises(AssertionError, match="a mesh was made"):  # at that rtol the first mesh is let through
        lattice.effective_conductivity(cell, rtol=fit * 1.05, max_memory=1e9)
    # at p = 4 (given) the rtol that fits is p = 4's
    with pytest.raises(ValueError) as info:
        lattice.effective_conductivity(cell, rtol=1e-5, order=4, max_memory=1e9)
    fit = float(str(info.value).split("rtol = ")[-1].split()[0])
    with pytest.raises(AssertionError, match="a mesh was made"):
        lattice.effective_conductivity(cell, rtol=fit * 1.05, order=4, max_memory=1e9)
    with pytest.raises(ValueError, match=r"0.4 GB available; no rtol fits: even neck size 0.3 a needs ~0\.\d GB"):
        lattice.effective_conductivity(cell, rtol=1e-3, max_memory=0.4e9)


def test_a_finer_mesh_that_would_not_fit_is_refused_before_meshing(monkeypatch):
    # the chain at h/r = 0.02 needs a second mesh for 1e-3 (from a first mesh too coarse); with memory for the first
    # only, that one is refused
    _coarse_first_mesh(monkeypatch)
    cell = _chain_cell(0.02)
    first = lattice.first_neck_size(1e-3, lattice.mean_neck_ratio(cell), 3)
    budget = lattice.memory_estimate(1.05 * lattice.predicted_tetrahedra(lattice.neck_circles(cell), first), 3)
    build, meshes = lattice.build_cell_mesh, []

    def counting(cell, **sizes):
        meshes.append(sizes["size_neck"])
        return build(cell, **sizes)

    monkeypatch.setattr(lattice.driver, "build_cell_mesh", counting)
    with pytest.raises(ValueError, match=r"chain: rtol = 0.001 needs a finer mesh than the \d+ tetrahedra whose bounds "
                                         r"are \d\.\d\de-03 apart; that mesh \(neck size [\d.]+ a, ~\d+ tetrahedra\) "
                                         r"needs ~0.5 GB, more than the 0.5 GB available; rtol = \d\.\de-03 would fit"):
        lattice.effective_conductivity(cell, rtol=1e-3, max_memory=budget, workers=1)
    assert meshes == [first]


@pytest.mark.slow
@pytest.mark.parametrize("case", sorted(REFERENCES))
def test_lattices_to_1e4_bracket_the_reference_with_a_sharp_estimate(case):
    kind, h = case
    res = lattice.effective_conductivity(lattice.lattice_cell(kind, h), rtol=1e-4)
    ref = REFERENCES[case]
    assert res.converged and res.error_estimate <= 1e-4
    assert len(res.levels) == 1  # the first mesh, sized from rtol and the neck, meets rtol: no mesh is wasted
    assert res.k_lower_over_kappa < ref < res.k_upper_over_kappa
    assert (res.k_upper_over_kappa - res.k_lower_over_kappa) / (res.k_upper_over_kappa - ref) < 3.0
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
    (["--kind", "sc", "--h-over-r", "0.08", "--max-memory", "0"], "max_memory = 0"),
    (["--kind", "sc", "--h-over-r", "0.08", "--rtol", "1e-6", "--max-memory", "0.8"], "would fit"),
    (["--kind", "bcc", "--h-over-r", "0.02", "--rtol", "1e-5", "--max-memory", "1"], "GB, more than the 1.0 GB"),
    (["--kind", "hcp", "--h-over-r", "0.08"], "invalid choice"),
])
def test_lattice_cli_refuses_bad_input_in_one_line(capsys, monkeypatch, argv, match):
    # every refusal comes before any mesh is made
    from fem_neck.cli import main

    monkeypatch.setattr(lattice.driver, "build_cell_mesh", _no_meshing)
    try:
        rc = main(["lattice", *argv])
    except SystemExit as exc:  # argparse's own refusals
        rc = exc.code
    err = capsys.readouterr().err
    assert rc == 2 and len(err.strip().splitlines()) == 1 and match in err and "Traceback" not in err


def test_lattice_cli_json_and_files(capsys, tmp_path):
    import json

    from fem_neck.cli import main

    rc = main(["lattice", "--kind", "sc", "--h-over-r", "0.2", "--rtol", "0.01", "--json", "--out", str(tmp_path)])
    out = json.loads(capsys.readouterr().out)
    assert rc == 0 and out["converged"] and out["error_estimate"] <= 0.01
    assert out["k_lower_over_kappa"] <= out["k_eff_over_kappa"] < out["phi"]
    assert out["coordination"] == 6 and abs(out["network_rel_error"]) < 0.01  # SC: the network holds
    assert {p.name for p in tmp_path.iterdir()} == {"lattice.json", "cell.vtu"}


def test_the_fe_cache_key_covers_every_module_the_lattice_fe_imports():
    """verification.lattices keys its FE cache by a hash of fe_files(): every fem_neck module that the lattice
    package imports (also inside functions) and every module of the package itself must be among them."""
    import ast
    import pathlib

    from verification.lattices import fe_files

    root = pathlib.Path(lattice.__file__).parents[1]
    hashed = set(fe_files())
    package = sorted((root / "lattice").glob("*.py"))
    assert set(package) <= hashed
    imported = set()
    for path in package:
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("fem_neck."):
                names = [node.module] + [f"{node.module}.{alias.name}" for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module == "fem_neck":
                names = [f"fem_neck.{alias.name}" for alias in node.names]
            else:
                continue
            for name in names:
                parts = name.split(".")[1:]
                for candidate in (root.joinpath(*parts).with_suffix(".py"), root.joinpath(*parts, "__init__.py")):
                    if candidate.exists():
                        imported.add(candidate)
    assert root / "cluster.py" in imported and root / "dual.py" in imported  # (the imports were read)
    assert imported - hashed == set()
