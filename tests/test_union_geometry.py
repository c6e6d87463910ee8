"""The union of spheres (fem_neck.geometry.union): necks, cut-sphere volumes and areas, meeting necks.

Checked against closed forms (the lens of two spheres, the space-filling cells at the covering radius), against
OpenCASCADE's volume and area of the fused spheres (an independent solve), and against the lattices' known meeting
overlaps."""

import math

import numpy as np
import pytest

from fem_neck.geometry import neck_radius
from fem_neck.geometry.union import angular_radius, cut_spheres, lens, necks_meet
from fem_neck.lattice import BASIS, EDGE_OVER_SPACING, PeriodicCell, max_h_over_r


def union_cell(kind: str, d: float) -> PeriodicCell:
    """The cubic cell of unit spheres whose nearest neighbours are ``d`` apart."""
    edge = EDGE_OVER_SPACING[kind] * d
    basis = np.asarray(BASIS[kind]) * edge
    return PeriodicCell(basis, np.ones(len(basis)), np.full(3, edge), name=kind)


def cell_cut(cell: PeriodicCell):
    i, j, s = cell.bonds()
    return cut_spheres(cell.radii, i, j, cell.centres[j] + s * cell.period - cell.centres[i])


def test_lens_of_equal_and_unequal_spheres():
    got = lens(1.0, 1.0, 1.5)
    assert got.l_i == got.l_j == 0.75 and got.a == pytest.approx(math.sqrt(1 - 0.75**2), rel=1e-15)
    got = lens(2.0, 1.0, 2.5)  # both circles: r_i^2 - l_i^2 = r_j^2 - l_j^2
    assert got.l_i + got.l_j == pytest.approx(2.5, rel=1e-15)
    assert 4.0 - got.l_i**2 == pytest.approx(1.0 - got.l_j**2, rel=1e-14)


@pytest.mark.parametrize("r_j, d", [(1.0, 2.0), (1.0, 3.5), (0.5, 1.5), (0.5, 0.5)])
def test_lens_refuses_spheres_apart_or_nested(r_j, d):
    with pytest.raises(ValueError, match=r"d = .*\|r_i - r_j\| < d < r_i \+ r_j"):
        lens(1.0, r_j, d)
    with pytest.raises(ValueError, match=r"d = -1: must be finite and > 0"):
        lens(1.0, r_j, -1.0)


def test_a_pair_is_two_spheres_less_their_lens():
    r_i, r_j, d = 1.0, 0.8, 1.5
    cut = cut_spheres([r_i, r_j], [0], [1], [[d, 0.0, 0.0]])
    lens_volume = math.pi * (r_i + r_j - d) ** 2 * (d * d + 2 * d * r_j - 3 * r_j**2 + 2 * d * r_i + 6 * r_i * r_j
                                                    - 3 * r_i**2) / (12 * d)
    assert cut.volume.sum() == pytest.approx(4 / 3 * math.pi * (r_i**3 + r_j**3) - lens_volume, rel=1e-14)
    assert cut.face_i[0] == pytest.approx(math.pi * lens(r_i, r_j, d).a ** 2, rel=1e-14)
    assert not cut.meeting.any()


@pytest.mark.parametrize("kind, covering, cell_volume", [
    ("sc", 2 / math.sqrt(3), lambda d: d**3),                      # cubes
    ("bcc", 4 / math.sqrt(5) * math.sqrt(3) / 2, lambda d: (2 * d / math.sqrt(3)) ** 3 / 2),  # truncated octahedra
    ("fcc", math.sqrt(2), lambda d: d**3 / math.sqrt(2)),         # rhombic dodecahedra
])
def test_lattices_fill_space_at_the_covering_radius_and_leave_pores_beyond(kind, covering, cell_volume):
    """At the covering distance every cut sphere is its whole Voronoi cell (no free surface); a little farther
    apart the pores open (volume below the cell's, free surface above nil); a little closer nothing changes."""
    for factor in (1.0, 0.99):
        cut = cell_cut(union_cell(kind, covering * factor))
        assert np.allclose(cut.volume, cell_volume(covering * factor), rtol=1e-13, atol=0)
        assert np.all(np.abs(cut.free_area) < 1e-12) and cut.meeting.all()
    cut = cell_cut(union_cell(kind, covering * 1.001))
    assert np.all(cut.volume < cell_volume(covering * 1.001)) and np.all(cut.free_area > 0)
    assert np.allclose(cut.face_i, cut.face_j, rtol=1e-12, atol=1e-15)


def test_volume_and_area_of_a_dense_cluster_match_opencascade():
    """Eight unequal spheres whose necks all meet: the cut spheres' volumes and free areas add up to the volume and
    area OpenCASCADE finds for the fused spheres (its own accuracy is ~1e-9)."""
    from fem_neck.shapes import gmsh_session

    x = np.array([[0, 0, 0], [1.3, 0, 0], [-1.25, 0.1, 0], [0, 1.35, 0.05], [0.1, -1.2, 0], [0, 0.1, 1.3],
                  [0.05, 0, -1.4], [0.9, 0.9, 0.2]], dtype=float)
    r = np.array([1.0, 0.95, 1.05, 1.0, 0.9, 1.1, 1.0, 0.85])
    i, j = np.triu_indices(len(r), 1)
    v = x[j] - x[i]
    near = np.linalg.norm(v, axis=1) < r[i] + r[j]
    cut = cut_spheres(r, i[near], j[near], v[near])
    assert cut.meeting.all()
    with gmsh_session() as gmsh:
        occ = gmsh.model.occ
        balls = [(3, occ.addSphere(*x[k], r[k])) for k in range(len(r))]
        union, _ = occ.fuse(balls[:1], balls[1:])
        occ.synchronize()
        volume = sum(occ.getMass(3, tag) for _, tag in union)
        area = sum(occ.getMass(2, tag) for _, tag in gmsh.model.getBoundary(union, combined=True, oriented=False))
    assert cut.volume.sum() == pytest.approx(volume, rel=2e-8)
    assert cut.free_area.sum() == pytest.approx(area, rel=2e-8)


def test_free_area_and_faces_are_the_volume_derivatives():
    """Growing one radius by dr adds (A_free + sum_b A_b r / d_b) dr to its cut sphere (the faces move by r dr /
    d): checked by central differences on a cluster whose necks meet."""
    x = np.array([[0, 0, 0], [1.4, 0, 0], [0.7, 1.2, 0], [0.6, 0.4, 1.2]], dtype=float)
    r = np.array([1.0, 0.9, 1.1, 0.95])
    i, j = np.triu_indices(4, 1)
    v = x[j] - x[i]
    d = np.linalg.norm(v, axis=1)
    cut = cut_spheres(r, i, j, v)
    assert cut.meeting[0]
    step = 1e-6
    grown = [cut_spheres(r + s * np.eye(4)[0], i, j, v).volume[0] for s in (step, -step)]
    mine = i == 0
    expected = cut.free_area[0] + np.sum(cut.face_i[mine] * r[0] / d[mine])
    assert (grown[0] - grown[1]) / (2 * step) == pytest.approx(expected, rel=1e-7)


@pytest.mark.parametrize("kind", ["sc", "bcc", "fcc"])
def test_pair_necks_meet_where_the_lattice_pair_model_ends(kind):
    """With the pair-neck reading (circles seen at arcsin(a / r)) the necks of a lattice particle meet from the
    overlap at which fem_neck.lattice stops (max_h_over_r)."""
    for h, meet in ((max_h_over_r(kind) * 0.999, False), (max_h_over_r(kind) * 1.001, True)):
        cell = union_cell(kind, 2.0 - h)
        i, j, s = cell.bonds()
        vectors = cell.centres[j] + s * cell.period - cell.centres[i]
        a = neck_radius(1.0, 1.0, h)
        angle = np.full(2 * len(i), float(angular_radius(a, math.sqrt(1 - a * a))))
        got = necks_meet(cell.n, np.concatenate([i, j]), np.vstack([vectors, -vectors]), angle)
        assert got.tolist() == [meet] * cell.n


def test_union_necks_meet_from_the_lattice_angle():
    """In the union the SC necks (90 deg apart) meet when their cones' half-angle reaches 45 deg: d = sqrt(2) r."""
    for d, meet in ((math.sqrt(2) * 1.001, False), (math.sqrt(2) * 0.999, True)):
        cut = cell_cut(union_cell("sc", d))
        assert cut.meeting.tolist() == [meet]


def test_a_centre_beyond_its_radical_plane_is_refused():
    with pytest.raises(ValueError, match=r"pair \(0, 1\).*centre beyond their radical plane"):
        cut_spheres([0.5, 1.0], [0], [1], [[0.7, 0, 0]])
