"""The exact flux element of a cut sphere (verification.neck_element) against the closed form (the uncut ball whose
two polar caps are uniform-flux faces, its resistance between them from the Legendre series), and the network of
such elements (verification.neck_node_bound): its bordering, its hook into dem.network.necks, and the study."""

import numpy as np
import pytest

from verification import neck_element as E


@pytest.mark.parametrize("alpha, tolerance, dipole_tolerance", [(0.3, 1e-3, 3e-3), (0.7, 2e-4, 5e-4)])
def test_two_caps_against_the_legendre_series(alpha, tolerance, dipole_tolerance):
    """The monopoles against the series in P_l, the dipoles (along x and y on each cap) against the one in P_l^1."""
    pytest.importorskip("ngsolve")
    res = E.cap_ball(alpha, dipoles=True)
    R = res["R"][0.0]
    assert R.shape == (6, 6) and np.max(np.abs(R - R.T)) < 1e-12 * np.abs(R).max()
    M = R[::3, ::3]  # the monopoles
    between = M[0, 0] + M[1, 1] - 2 * M[0, 1]
    exact = E.cap_ball_exact(alpha)
    # Galerkin's discrete energy is above the exact minimum: the FE's resistance is below the series', and close
    assert 0.0 < 1.0 - between / exact < tolerance
    own, across = E.cap_ball_dipole_exact(alpha)
    for d in (1, 2, 4, 5):  # each dipole's own moment: below the series, and close (Galerkin again)
        assert 0.0 < 1.0 - R[d, d] / own < dipole_tolerance
    for d in (1, 2):  # the other cap's moment, parallel dipoles; crossed ones and the monopoles do not couple
        assert R[d, d + 3] == pytest.approx(across, rel=dipole_tolerance)
        assert abs(R[d, 3 - d]) + abs(R[d, 6 - d]) < 1e-3 * own
    assert np.max(np.abs(R[0, [1, 2, 4, 5]])) < 1e-3 * own
    assert res["volume"] == pytest.approx(4.0 / 3.0 * np.pi, rel=1e-4)


@pytest.mark.parametrize("kwargs, word", [({"arms": [1.2]}, "arms"), ({"betas": (0.5,)}, "beta"),
                                          ({"maxh": 0.0}, "maxh"), ({"order": 0}, "order"),
                                          ({"normals": [[0.0, 0.0, 2.0]]}, "normals"),
                                          ({"frames": [[[1.0, 0.0, 0.0]]]}, "frames"),
                                          ({"frames": [[[1.0, 0.0, 0.0], [0.6, 0.8, 0.0]]]}, "frames"),
                                          ({"frames": [[[0.0, 0.6, 0.8], [1.0, 0.0, 0.0]]]}, "frames")])
def test_bad_input_is_one_line_naming_the_parameter(kwargs, word):
    args = {"normals": [[0.0, 0.0, 1.0]], "arms": [0.9], **kwargs}
    with pytest.raises(ValueError, match=word) as err:
        E.cut_element(**args)
    assert "\n" not in str(err.value)


def test_the_bordered_element_holds_r_between_any_two_necks():
    """The element's resistance between necks b and c (the centre floating) is R_bb + R_cc - 2 R_bc; its rows sum
    to zero."""
    from verification.neck_node_bound import bordered

    rng = np.random.default_rng(3)
    A = rng.normal(size=(4, 4))
    R = A @ A.T + 4 * np.eye(4)
    E4 = bordered(R)
    assert np.allclose(E4.sum(axis=1), 0.0, atol=1e-12) and np.allclose(E4, E4.T)
    for b, c in ((0, 1), (2, 3), (1, 3)):
        inflow = np.zeros(5)
        inflow[b], inflow[c] = 1.0, -1.0
        T = np.linalg.lstsq(E4, inflow, rcond=None)[0]
        assert T[b] - T[c] == pytest.approx(R[b, b] + R[c, c] - 2 * R[b, c], rel=1e-10)


def test_the_elements_hook_gives_every_fcc_particle_its_twelve_planes(monkeypatch):
    """Stub elements R = rho 1 on an FCC cell: each particle sees its 12 <110> planes at 1 - h/2, and the network is
    the pipe network of bond conductance G = kappa r / (2 rho), k_eff = 4 G / L (24 bonds per cubic cell, sum of
    d_z^2 = 4 L^2)."""
    from fem_neck import lattice
    from verification.lattices import dem_periodic
    from verification.neck_node_bound import ExactElements

    h, rho = 0.2, 0.37
    seen = []

    def stub(self, normals, arms, beta):
        seen.append((np.array(normals), np.array(arms)))
        return rho * np.eye(len(arms))

    monkeypatch.setattr(ExactElements, "resistance", stub)
    cell = lattice.lattice_cell("fcc", h, neck="union")
    k = dem_periodic(cell, "shared-body", neck="union", nodes="necks", elements=ExactElements((0.0,), {}).builder(0.0))
    assert len(seen) == cell.n == 4
    directions = {tuple(v) for v in np.round(np.sqrt(2) * seen[0][0], 9) + 0.0}
    for normals, arms in seen:
        assert np.allclose(arms, 1 - h / 2)
        assert {tuple(v) for v in np.round(np.sqrt(2) * normals, 9) + 0.0} == directions
    assert len(directions) == 12 and all(sorted(np.abs(d)) == [0.0, 1.0, 1.0] for d in directions)
    assert k == pytest.approx(4 * (1.0 / (2 * rho)) / cell.period[2], rel=1e-10)


@pytest.mark.slow
def test_the_quick_study_finds_the_bounds_below_the_fe(tmp_path):
    pytest.importorskip("ngsolve")
    import json

    from verification import neck_node_bound as S
    from verification.report import check_section_result

    res = check_section_result("neck_node_bound", S.run(tmp_path, quick=True))
    assert all(measured <= limit for _, measured, limit in res["targets"])
    (row,) = json.loads((tmp_path / "neck_node_bound.json").read_text())
    for column, k in row["bound"].items():
        assert k < row["fe"]["lower"]
        assert row["coarse"][column] > k  # Galerkin: the coarser element conducts more
    # Thomson: the three modes' admissible fields hold the monopoles', so their network conducts at least as much
    assert row["bound"]["profile beta=0.25 + dipoles"] >= row["bound"]["profile beta=0.25"] * (1 - 1e-12)


SEED_1_FE = (0.2283995488604121, 0.22858733113730098)  # the FE's (lower, upper) bounds on seed 1 at phi 0.6, gap 2e-3


@pytest.mark.slow
def test_the_dipoles_bring_the_loose_packings_bound_within_one_percent_of_the_fe():
    """The random mirror packing seed 1 at phi 0.6 (the densification study's): one number per neck leaves its
    exact-element network 3 % below the FE, the two dipoles per neck bring it within 1 %, still below the FE's lower
    bound (the FE's bounds at gap 2e-3, as the densification study has them)."""
    pytest.importorskip("ngsolve")
    from verification.densification import RANDOM_SPHERES
    from verification.neck_node_bound import DISC, bounds
    from verification.packings import union_packing

    k = bounds(union_packing(RANDOM_SPHERES, 0.6, seed=1), DISC)["k"]
    lower, upper = SEED_1_FE
    one, three = k["profile beta=0.25"], k["profile beta=0.25 + dipoles"]
    assert three < lower and one < three
    assert three > 0.99 * upper and one < 0.98 * upper


def test_a_mirror_images_three_modes_are_the_cached_bodys_turned():
    """The dipoles of a body's mirror image, taken from the cached FE of the body by the symmetry that maps them and
    turned onto the image's frames, against an FE of the image itself in those frames (another mesh: agreement to
    the discretisation), and the network's frames are the bonds' (a turn of the frames leaves the monopoles)."""
    pytest.importorskip("ngsolve")
    from dem.network.necks import neck_frames
    from verification.neck_node_bound import ExactElements

    coarse = {"order": 2, "maxh": 0.5, "hp_levels": 1}
    normals = np.array([[0.0, 0.0, 1.0], [0.8, 0.0, -0.6], [0.0, -0.6, -0.8]])
    arms = np.array([0.8, 0.75, 0.85])
    S = np.diag([-1.0, 1.0, 1.0])[[1, 0, 2]]  # a mirror and a swap of axes: not a rotation
    image = normals @ S.T
    frames = neck_frames(np.array([[0.3, 0.2, 1.0], [1.0, 0.1, -0.6], [-0.4, -0.6, -0.8]]))  # any in-plane frames
    frames = frames - np.einsum("bij,bj->bi", frames, image)[:, :, None] * image[:, None, :]  # onto the image's planes
    frames[:, 0] /= np.linalg.norm(frames[:, 0], axis=1)[:, None]
    frames[:, 1] = np.cross(image, frames[:, 0])
    elements = ExactElements((0.0,), coarse, modes=3)
    elements.resistance(normals, arms, 0.0, neck_frames(normals))  # the FE of the body (or of its least image)
    assert len(elements.ndof) == 1
    mapped = elements.resistance(image, arms, 0.0, frames)
    assert len(elements.ndof) == 1  # the image came from the cache
    direct = E.cut_element(image, arms, (0.0,), frames=frames, **coarse)["R"][0.0]
    assert np.max(np.abs(mapped - direct)) < 1e-2 * np.abs(direct).max()
    assert np.max(np.abs(direct[1::3, 1::3])) > 0.05 * np.abs(direct).max()  # the dipoles are not nothing
    monopoles = elements.resistance(image, arms, 0.0)
    assert np.allclose(monopoles, mapped[::3, ::3], rtol=0, atol=1e-14)


def _chain_flow(axis, spheres: int, elements, modes: int):
    """The heat flow across the period (W, per 1 K per period along z) of a straight periodic chain of unit spheres
    overlapping by 0.3 r along ``axis`` (in the x-z plane), ``spheres`` per period, with exact elements; and the
    necks' nodes."""
    from dem.geometry.bonds import find_bonds
    from dem.geometry.particles import Material, Particles
    from dem.geometry.periodic import PeriodicBox
    from dem.laws.conductance import ConductanceSpec
    from dem.network.necks import neck_network, steady_necks

    d = 1.7
    u = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    period = np.array([spheres * d * u[0] or 4.0, 4.0, spheres * d * u[2]])
    box = PeriodicBox(period, drop=[0.0, 0.0, 1.0])
    x = np.arange(spheres)[:, None] * d * u + 0.5
    particles = Particles.from_arrays(x, np.ones(spheres), np.zeros(spheres),
                                      materials=(Material(1.0, 1.0, 1.0, "unit"),))
    spec = ConductanceSpec(law="shared-body", neck="union", nodes="necks")
    net = neck_network(spec, particles, find_bonds(particles, contact=spec.contact, box=box), box=box,
                       elements=elements.builder(0.25, modes))
    assert len(net.live) == spheres  # the chain's own bonds: the parallel chains do not touch
    res = steady_necks(net)
    return res.periodic_heat_flow, res.T_necks


def test_a_chain_across_the_gradient_carries_its_heat_along_itself_and_its_dipoles_nothing():
    """A straight chain tilted 45 degrees from the drop (along z) in the x-z plane: the drop's transverse part drives
    nothing in the chain (its bodies are symmetric about its axis), so the dipoles stay at 0, the three modes carry
    what one does, and the heat flows along the chain: as much across the period along x as along z, a third of what
    the same chain upright carries (three bonds per period against one)."""
    pytest.importorskip("ngsolve")
    from verification.neck_node_bound import ExactElements

    coarse = {"order": 2, "maxh": 0.3, "hp_levels": 1}
    elements = ExactElements((0.25,), coarse, modes=3)
    tilted, necks = _chain_flow([1.0, 0.0, 1.0], 3, elements, 3)
    one, _ = _chain_flow([1.0, 0.0, 1.0], 3, elements, 1)
    along, _ = _chain_flow([0.0, 0.0, 1.0], 1, elements, 1)
    assert len(elements.ndof) == 2  # the tilted body and the upright one
    # (the coarse mesh couples a symmetric body's monopole and dipoles by ~1e-3 of its R)
    assert np.max(np.abs(necks.reshape(-1, 3)[:, 1:])) < 1e-3 * np.ptp(necks.reshape(-1, 3)[:, 0])
    assert tilted[2] == pytest.approx(one[2], rel=1e-5)
    assert tilted[0] == pytest.approx(tilted[2], rel=1e-9) and abs(tilted[1]) < 1e-12 * tilted[2]
    # 1 K per period along z: each of the tilted chain's three bonds takes 1/3 K, the upright chain's one bond 1 K
    # (another mesh of the body turned: agreement to the discretisation)
    assert 3 * tilted[2] == pytest.approx(along[2], rel=2e-3)
