"""The closing pores' cap of the shared-body law on the union of spheres (dem.laws.closing_pores): the particle's
cell against closed forms and its planes against a search of all pairs, the cap's properties and its bound on beta,
k_eff continuous where necks form, and the dense union lattices against their FE."""

import itertools
import json

import numpy as np
import pytest

from dem.laws.closing_pores import CALIBRATION, GAMMA, cap_ratio, largest_beta, particle_cells, power_planes
from fem_neck.geometry.union import cut_spheres
from fem_neck.lattice import lattice_cell
from verification.lattices import dem_periodic

AXES = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=float)
WIENER_CAP = {"beta": 0.0, "psi0": 1.0}  # slope 1 everywhere: the cap of the law before the closing pores


@pytest.mark.parametrize("l", [0.6, 0.75, 0.85])
def test_cell_of_the_simple_cubic_particle_against_closed_forms(l):
    """The unit sphere cut by six planes at +-l: its cell is the cube of side 2 l (its corners, l sqrt 3, inside the
    ball of 1.5); the solid and the free surface are the cut sphere's, exact from fem_neck.geometry.union.cut_spheres
    (its own particle, necks to six images)."""
    solid, pore, free = particle_cells(np.ones(1), np.zeros(6, dtype=int), AXES, np.full(6, l))
    exact = cut_spheres(np.ones(7), np.zeros(6, dtype=int), np.arange(1, 7), 2 * l * AXES)
    assert solid[0] == pytest.approx(exact.volume[0], rel=2e-3)
    # the quadrature's error against the cell and the sphere (at l = 0.6 the pore is 2.5e-4 of the cell)
    assert pore[0] == pytest.approx(8 * l**3 - exact.volume[0], abs=1e-4 * 8 * l**3)
    assert free[0] == pytest.approx(exact.free_area[0], abs=2e-3 * 4 * np.pi)


def _cap(h, big):
    """The volume of the cap of height h of a ball of radius big."""
    return np.pi * h * h * (3 * big - h) / 3


def test_loose_cells_against_closed_forms():
    """A lone sphere: its cell is the ball of (1 + GAMMA) r, its pore the shell (psi 2.72: round, rho = 1). A chain's
    particle (two opposite necks at +-0.9): the ball and the sphere each less two caps."""
    big = 1 + GAMMA
    solid, pore, free = particle_cells(np.ones(2), np.array([1, 1]), AXES[:2], np.full(2, 0.9))
    assert solid[0] == pytest.approx(4 / 3 * np.pi, rel=1e-12) and free[0] == pytest.approx(4 * np.pi, rel=1e-12)
    assert pore[0] == pytest.approx(4 / 3 * np.pi * (big**3 - 1), rel=1e-12)
    assert solid[1] == pytest.approx(4 / 3 * np.pi - 2 * _cap(0.1, 1.0), rel=2e-3)
    assert pore[1] == pytest.approx(4 / 3 * np.pi * big**3 - 2 * _cap(big - 0.9, big) - solid[1], rel=2e-3)
    assert free[1] == pytest.approx(4 * np.pi - 2 * 2 * np.pi * 0.1, rel=2e-3)
    assert free[0] / pore[0] ** (2 / 3) == pytest.approx(2.716, abs=1e-3)
    assert cap_ratio(solid, pore, free, 0.8, 3.0)[0] == 1.0


def test_cap_ratio_closed_form():
    """rho = (1 - c eps) / (1 - eps) with c = 1 + beta ln(psi / psi0) for thin pores, 1 for pores rounder than psi0
    and for no pore."""
    solid, pore = np.array([3.0, 3.0, 3.0]), np.array([0.1, 0.1, 0.0])
    free = np.array([4.0, 1.0, 0.0]) * 0.1 ** (2 / 3)  # psi = 4 and 1
    rho = cap_ratio(solid, pore, free, 0.8, 2.0)
    eps, c = 0.1 / 3.1, 1 + 0.8 * np.log(2.0)
    assert rho[0] == pytest.approx((1 - c * eps) / (1 - eps), rel=1e-14) and rho[1:].tolist() == [1.0, 1.0]


def _shell(t):
    """solid, pore and free surface of a unit sphere in a spherical cell of radius t <= 1 + GAMMA: the cell that
    reaches the bound of the module docstring, eps = 3 x / (3 x + 1) and psi = (4 pi)^(1/3) x^(-2/3)."""
    return np.array([4 / 3 * np.pi]), np.array([4 / 3 * np.pi * (t**3 - 1)]), np.array([4 * np.pi])


@pytest.mark.parametrize("psi0", [0.5, 1.0, 2.5, 3.0, 4.5])
def test_largest_beta_is_where_the_worst_cell_reaches_zero(psi0):
    """Below largest_beta every cell keeps rho > 0 (here the worst: a sphere in a spherical pore shell, scanned over
    its thickness); just above it that cell's cap is 0 or below, and cap_ratio refuses the calibration."""
    top = largest_beta(psi0)
    cells = [_shell(t) for t in np.linspace(1.0 + 1e-6, 1.0 + GAMMA, 4001)]
    near = min(cap_ratio(*cell, top * (1 - 1e-6), psi0)[0] for cell in cells)
    assert 0.0 < near < 1e-3
    a = (4 * np.pi) ** (1 / 3) / psi0
    x = min(((1 + GAMMA) ** 3 - 1) / 3, a**1.5 / np.e)  # the worst shell, past which rho would be < 0
    solid, pore, free = _shell((1 + 3 * x) ** (1 / 3))
    eps, psi = pore[0] / (pore[0] + solid[0]), free[0] / pore[0] ** (2 / 3)
    assert (1 + top * 1.000001 * np.log(psi / psi0)) * eps > 1.0
    with pytest.raises(ValueError, match="beta"):
        cap_ratio(solid, pore, free, top * 1.000001, psi0)


def test_shipped_and_calibration_grid_within_largest_beta():
    from verification.closing_pores import BETAS, PSI0S

    assert max(BETAS) < largest_beta(min(PSI0S))
    fit = json.loads(CALIBRATION.read_text())
    assert fit["beta"] < largest_beta(fit["psi0"])


@pytest.mark.parametrize("beta, psi0", [(-0.1, 3.0), (np.nan, 3.0), (0.8, 0.0), (0.8, np.inf), (5.0, 1.0)])
def test_bad_calibration_is_refused_in_one_line(beta, psi0):
    with pytest.raises(ValueError, match="beta|psi0") as err:
        cap_ratio(np.ones(1), np.ones(1), np.ones(1), beta, psi0)
    assert "\n" not in str(err.value)


def test_calibration_picks_the_grid_point_of_least_rms_error():
    from verification.closing_pores import BETAS, PSI0S, calibrate

    fe = {"a": 0.5, "b": 0.9}
    best = calibrate(fe, lambda beta, psi0: {case: k * (1 + (beta - BETAS[3]) ** 2 + 0.1 * (psi0 - PSI0S[5]) ** 2)
                                             for case, k in fe.items()})
    assert (best["beta"], best["psi0"]) == (BETAS[3], PSI0S[5]) and best["rms"] == 0.0


@pytest.mark.parametrize("kind, h", [("sc", 0.2), ("bcc", 0.1), ("fcc", 0.05), ("fcc", 0.1)])
def test_where_the_cap_does_not_bind_the_law_is_unchanged_bit_for_bit(kind, h):
    cell = lattice_cell(kind, h, neck="union")
    assert dem_periodic(cell, "shared-body", neck="union") == dem_periodic(cell, "shared-body", neck="union",
                                                                           closing_pores=WIENER_CAP)


def test_continuous_where_the_cap_begins_to_bind():
    """Simple cubic from h/r = 0.3 to 0.6, through the overlap where the calibrated cap takes over from the necks'
    own conductance: k_eff rises in steps that change slowly (a kink, no jump)."""
    hs = np.linspace(0.3, 0.6, 31)
    cells = [lattice_cell("sc", float(h), neck="union") for h in hs]
    k = np.array([dem_periodic(cell, "shared-body", neck="union") for cell in cells])
    free = np.array([dem_periodic(cell, "shared-body", neck="union", closing_pores=WIENER_CAP) for cell in cells])
    assert k[0] == free[0] and k[-1] < free[-1] * 0.98  # the cap binds at the end, not at the start
    steps = np.diff(k)
    assert np.all(steps > 0)
    assert np.all(steps[1:-1] < 1.2 * np.maximum(steps[:-2], steps[2:]))  # no step stands out from its neighbours


def test_shipped_calibration_saw_none_of_the_densification_cases():
    from verification import densification

    record = json.loads(CALIBRATION.read_text())
    assert record["beta"] >= 0 and record["psi0"] > 0 and record["command"] == "python -m verification closing-pores"
    checked = {f"{kind} union h/r={h:g}" for kind, hs in densification.OVERLAPS.items() for h in hs}
    checked |= {f"union packing seed={seed} phi={phi:g}" for seed, phi in densification.RANDOM}
    seeds = {seed for seed, _ in densification.RANDOM}
    assert record["cells"] and not set(record["cells"]) & checked
    assert not {int(case.split("seed=")[1].split()[0]) for case in record["cells"] if "seed=" in case} & seeds


def _brute_planes(position, radius, box, walls):
    """Every radical plane within (1 + GAMMA) r of a centre, over all images three periods deep, and the walls."""
    rows = []
    periods = [range(-3, 4) if p else range(1) for p in box.periodic]
    for k in range(len(radius)):
        for j in range(len(radius)):
            for s in itertools.product(*periods):
                v = position[j] + np.array(s) * box.lengths - position[k]
                d = np.linalg.norm(v)
                if d == 0:
                    continue
                l = (d * d + radius[k] ** 2 - radius[j] ** 2) / (2 * d)
                if l < (1 + GAMMA) * radius[k]:
                    rows.append((k, *(v / d), l))
        for w in walls:
            if w.distance(position[k]) < (1 + GAMMA) * radius[k]:
                rows.append((k, *(-w.normal), w.distance(position[k])))
    return np.array(sorted(np.round(rows, 9).tolist()))


@pytest.mark.parametrize("periodic", [(True, True, True), (True, True, False)])
def test_power_planes_finds_every_plane_within_reach(periodic):
    """The neighbour search (radius classes of a factor 2 apart, images of a box shorter than the reach) against all
    pairs and images: the same planes, the walls of a box open along z among them."""
    from dem.geometry.periodic import PeriodicBox
    from dem.geometry.walls import Wall

    rng = np.random.default_rng(3)
    box = PeriodicBox([3.0, 3.5, 4.0], periodic=periodic)
    position = rng.uniform(0, 1, (7, 3)) * box.lengths
    radius = rng.uniform(0.4, 1.3, 7)
    walls = () if all(periodic) else (Wall("bottom", [0, 0, -0.5], [0, 0, 1]), Wall("top", [0, 0, 4.5], [0, 0, -1]))
    particle, normals, planes = power_planes(position, radius, box, walls)
    found = np.array(sorted(np.round(np.column_stack([particle, normals, planes]), 9).tolist()))
    assert len(found) > 7 * 6
    np.testing.assert_allclose(found, _brute_planes(position, radius, box, walls), atol=2e-9)


BCC_ONSET = 2 - np.sqrt(3)  # h/r where the body-centred lattice's second neighbours touch


def test_continuous_where_a_new_neck_forms_on_the_bcc_lattice():
    """Second neighbours come into contact at h/r = 2 - sqrt 3: their plane moves in through the cell and reaches the
    sphere there, so k_eff does not step (the cell of the touching necks only, octahedron to truncated octahedron,
    made it jump by 2.1 %). What is left is the new necks' own conductance, growing as the root of their overlap, as
    under the Wiener cap: 0.057 % at +-1e-6, 0.0006 % at +-1e-10."""
    def k(h, fit=None):
        return dem_periodic(lattice_cell("bcc", h, neck="union"), "shared-body", neck="union", closing_pores=fit)

    for gap in (1e-6, 1e-10):
        below, above = k(BCC_ONSET - gap), k(BCC_ONSET + gap)
        assert above / below - 1 == pytest.approx(k(BCC_ONSET + gap, WIENER_CAP) / k(BCC_ONSET - gap, WIENER_CAP) - 1,
                                                  abs=1e-6)
    assert 0 < above / below - 1 < 1e-5


def test_continuous_where_a_pair_of_a_disordered_packing_comes_into_contact():
    """Sixteen spheres of a body-centred packing at h/r 0.26, radii +-5 % and centres moved by 0.02 r at random: one
    sphere grows until it touches the nearest sphere it did not touch. k_eff just before and just after the new neck
    agree (the cell of the touching necks only made it step by 0.16 % here, one neck of the eight second neighbours)."""
    import dataclasses

    from fem_neck.lattice.cells import PeriodicCell

    base = lattice_cell("bcc", 0.26, neck="union")
    rng = np.random.default_rng(1)
    shifts = np.array(list(itertools.product(range(2), repeat=3)))
    centres = (base.centres[None] + shifts[:, None] * base.period).reshape(-1, 3)
    n = len(centres)
    cell = PeriodicCell(centres + rng.normal(0, 0.02, (n, 3)), 1 + rng.uniform(-0.05, 0.05, n), 2 * base.period,
                        neck="union")
    gap = min(d - cell.radii[0] - cell.radii[j] for j in range(n) for s in itertools.product((-1, 0, 1), repeat=3)
              if (d := np.linalg.norm(cell.centres[j] + np.array(s) * cell.period - cell.centres[0]))
              > cell.radii[0] + cell.radii[j])

    def grown(extra):
        radii = cell.radii.copy()
        radii[0] += gap + extra
        return dem_periodic(dataclasses.replace(cell, radii=radii), "shared-body", neck="union")

    assert abs(grown(1e-10) / grown(-1e-10) - 1) < 1e-5


# Dense union lattices' k_eff / kappa, FE lower and upper bounds at rtol 1e-3 (python -m verification densification):
# the closing-pore regime, where the Wiener cap left the law 2-6 % above
DENSE_FE = {("sc", 0.5): (0.86540, 0.86610), ("sc", 0.6): (0.95057, 0.95094), ("bcc", 0.3): (0.91274, 0.91332),
            ("bcc", 0.35): (0.97803, 0.97880), ("fcc", 0.2): (0.85719, 0.85774), ("fcc", 0.3): (0.95403, 0.95479)}


@pytest.mark.parametrize("kind, h", list(DENSE_FE))
def test_dense_union_lattices_within_one_percent_of_their_fe(kind, h):
    lower, upper = DENSE_FE[(kind, h)]
    cell = lattice_cell(kind, h, neck="union")
    k = dem_periodic(cell, "shared-body", neck="union")
    assert lower * 0.99 < k < upper * 1.01
    assert k <= cell.phi  # Wiener


@pytest.mark.slow
@pytest.mark.parametrize("kind, h", [("bcc", 0.3), ("fcc", 0.2)])
def test_closing_pore_cells_against_a_fresh_fe(kind, h):
    """The periodic-cell FE of two closing-pore cells solved here (rtol 1e-3, about 10 s each): the law within 1 %,
    where the Wiener cap is 4-6 % above."""
    from fem_neck.lattice import effective_conductivity

    cell = lattice_cell(kind, h, neck="union")
    fe = effective_conductivity(cell, rtol=1e-3)
    k = dem_periodic(cell, "shared-body", neck="union")
    assert fe.k_lower_over_kappa * 0.99 < k < fe.k_upper_over_kappa * 1.01
    assert dem_periodic(cell, "shared-body", neck="union", closing_pores=WIENER_CAP) > fe.k_upper_over_kappa * 1.03
