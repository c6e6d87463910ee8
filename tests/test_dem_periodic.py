"""Periodic boxes in the DEM: bonds across the faces, the temperature drop per period, k_eff of infinite lattices."""

import numpy as np
import pytest

from dem.geometry.bonds import candidate_pairs, find_bonds
from dem.geometry.generators import lattice, random_packing
from dem.geometry.particles import Material, Particles
from dem.geometry.periodic import PeriodicBox, canonical_bonds
from dem.scene import make_scene, parse_scene
from dem.driver import run
from fem_neck.geometry import neck_radius
from fem_neck.law import pair_conductance

UNIT = Material(1.0, 1.0, 1.0, "unit")


def _bond_set(i, j, shift):
    return {(int(a), int(b), *map(int, s)) for a, b, s in zip(i, j, shift)}


def _explicit_tiling(position, radius, box, copies=1):
    """The box's particles tiled explicitly over (2 copies + 1)^3 periods: positions, owner, cell shift."""
    rng = range(-copies, copies + 1)
    cells = np.array([(a, b, c) for a in rng for b in rng for c in rng])
    x = (position[None] + (cells * box.lengths)[:, None]).reshape(-1, 3)
    owner = np.tile(np.arange(len(radius)), len(cells))
    cell = np.repeat(cells, len(radius), axis=0)
    return x, owner, cell


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_periodic_bonds_equal_those_of_an_explicit_larger_block(seed):
    rng = np.random.default_rng(seed)
    n = 60
    box = PeriodicBox([5.0, 4.0, 6.0], origin=[-1.0, 0.5, 0.0])
    x = box.origin + rng.uniform(0, 1, (n, 3)) * box.lengths + rng.integers(-2, 3, (n, 3)) * box.lengths
    r = rng.uniform(0.5, 0.9, n)
    bonds = find_bonds(Particles.from_arrays(x, r, np.zeros(n)), box=box, out_of_range="drop")
    # explicit: wrapped particles tiled 3 x 3 x 3; a bond (i, j, s) of the block is the pair of the centre copy of
    # i with the copy of j shifted by s, in the positions as given (the wrap counts added back)
    wrapped = box.wrap(x)
    xe, owner, cell = _explicit_tiling(wrapped, r, box)
    i, j = candidate_pairs(xe, r[owner])
    centre = np.all(cell[i] == 0, axis=1) | np.all(cell[j] == 0, axis=1)
    i, j = i[centre], j[centre]
    wrap = np.round((wrapped - x) / box.lengths).astype(int)
    shift = cell[j] - cell[i] + wrap[owner[j]] - wrap[owner[i]]
    expected = _bond_set(*canonical_bonds(owner[i], owner[j], shift))
    dropped = bonds.dropped
    assert len(expected) == bonds.n_pairs + dropped
    assert _bond_set(bonds.i, bonds.j, bonds.shifts) <= expected
    # every bond vector is the shortest one for these boxes (wider than two bonds)
    v = bonds.vectors(x, box)
    assert np.allclose(v, box.minimum_image(x[bonds.j] - x[bonds.i]))
    assert np.allclose(np.linalg.norm(v, axis=1), bonds.d)


def test_a_box_shorter_than_a_bond_bonds_particles_to_their_own_images():
    # one simple cubic cell: the sphere bonds to its own image along each axis (three bonds), and along a box of
    # 1.5 neighbour distances, two spheres bond to each other's images on both sides
    lay = lattice([1, 1, 1], 1.0, 0.1)
    box = PeriodicBox(lay.period, origin=lay.origin)
    b = find_bonds(Particles.from_arrays(lay.position, lay.radius, [0.0]), box=box)
    assert b.n_pairs == 3 and np.all(b.i == 0) and np.all(b.j == 0)
    assert sorted(map(tuple, b.shifts.tolist())) == [(0, 0, 1), (0, 1, 0), (1, 0, 0)]
    x = np.array([[0.0, 0.0, 0.0], [1.9, 0.0, 0.0]])
    box = PeriodicBox([3.8, 10.0, 10.0], (True, False, False))
    b = find_bonds(Particles.from_arrays(x, [1.0, 1.0], [0.0, 0.0]), box=box)
    assert _bond_set(b.i, b.j, b.shifts) == {(0, 1, 0, 0, 0), (0, 1, -1, 0, 0)}


def test_minimum_image_and_wrap():
    box = PeriodicBox([2.0, 3.0, 4.0], (True, False, True), origin=[1.0, 1.0, 1.0])
    assert np.allclose(box.minimum_image([[1.5, 2.5, -3.0]]), [[-0.5, 2.5, 1.0]])
    assert np.allclose(box.wrap([[0.5, -7.0, 9.5]]), [[2.5, -7.0, 1.5]])
    assert np.all(box.wrap([[1.0 - 1e-18, 0.0, 1.0]])[:, 0] < 3.0)


@pytest.mark.parametrize("kwargs, match", [
    ({"lengths": [1.0, 0.0, 1.0]}, "lengths"),
    ({"lengths": [1.0, 1.0, 1.0], "periodic": (True, True)}, "periodic"),
    ({"lengths": [1.0, 1.0, 1.0], "periodic": (True, True, False), "drop": [0, 0, 1.0]}, "drop"),
])
def test_bad_boxes_are_refused(kwargs, match):
    with pytest.raises(ValueError, match=match):
        PeriodicBox(**kwargs)


LATTICE_SUM = {"sc": 1.0, "bcc": np.sqrt(3.0), "fcc": 2.0 * np.sqrt(2.0)}  # k = c K_pair / d (uniform gradient)


@pytest.mark.parametrize("structure", ["sc", "bcc", "fcc"])
@pytest.mark.parametrize("shape", [[1, 1, 1], [2, 3, 2]])
def test_periodic_lattice_gives_the_lattice_sum(structure, shape):
    doc = {"material": {"conductivity": 2.0, "density": 1.0, "specific_heat": 1.0},
           "generator": {"kind": "lattice", "shape": shape, "radius": 1e-3, "overlap": 0.08, "structure": structure,
                         "boundary": "periodic", "hot": 3.0, "cold": 1.0},
           "conductance": {"law": "fit"}}
    s = run(parse_scene(doc)).summary
    d = 2e-3 - 0.08e-3
    K = pair_conductance(2.0, 1e-3, 1e-3, neck_radius(1e-3, 1e-3, 0.08e-3))
    assert s["effective_conductivity"] == pytest.approx(LATTICE_SUM[structure] * K / d, rel=1e-12)
    assert s["T_mean"] == pytest.approx(2.0, abs=1e-12)  # the mean of the initial gradient is kept
    assert abs(s["periodic_heat_flow"][0]) < 1e-12 and abs(s["periodic_heat_flow"][1]) < 1e-12
    assert s["energy_error"] < 1e-12


def test_periodic_random_packing_equals_its_doubled_block():
    lay = random_packing(40, 1.0, 0.1, seed=3, jitter=0.1, periodic=True)
    T0 = np.zeros(len(lay.radius))
    box = PeriodicBox(lay.period, drop=[0.0, 0.0, 1.0])
    one = run(make_scene(lay.position, lay.radius, T0, materials=(UNIT,), law="fit", box=box, floating="mean"))
    cells = np.array([(a, b, c) for a in (0, 1) for b in (0, 1) for c in (0, 1)])
    x2 = (lay.position[None] + (cells * lay.period)[:, None]).reshape(-1, 3)
    r2 = np.tile(lay.radius, len(cells))
    box2 = PeriodicBox(2 * lay.period, drop=[0.0, 0.0, 2.0])
    two = run(make_scene(x2, r2, np.zeros(len(r2)), materials=(UNIT,), law="fit", box=box2, floating="mean"))
    assert two.summary["bonds"] == 8 * one.summary["bonds"]
    assert two.summary["effective_conductivity"] == pytest.approx(one.summary["effective_conductivity"], rel=1e-9)
    assert abs(np.sum(lay.radius**3 * one.T)) < 1e-12 * np.sum(lay.radius**3)  # capacity-weighted mean kept at 0


def test_periodic_transient_keeps_the_heat_and_ends_in_the_steady_state():
    lay = lattice([2, 2, 2], 1.0, 0.1, "bcc")
    box = PeriodicBox(lay.period, origin=lay.origin, drop=[0.0, 0.0, 1.0])
    rng = np.random.default_rng(0)
    T0 = rng.uniform(0.0, 1.0, len(lay.radius))
    common = dict(materials=(UNIT,), law="fit", box=box)
    steady = run(make_scene(lay.position, lay.radius, T0, **common))
    trans = run(make_scene(lay.position, lay.radius, T0, mode="transient", integrator="implicit", dt=0.5,
                           t_end=200.0, **common))
    assert trans.summary["energy_error"] < 1e-9
    assert trans.summary["heat_in"]["periodic"] == pytest.approx(0.0, abs=1e-9)
    assert np.allclose(trans.T, steady.T, atol=1e-6)
    assert steady.T.mean() == pytest.approx(T0.mean(), abs=1e-12)


def test_periodic_table_in_a_scene_file():
    doc = {"material": {"conductivity": 1.0, "density": 1.0, "specific_heat": 1.0},
           "particles": {"position": [[0.0, 0.0, 0.0]], "radius": [1.0], "temperature": [0.0]},
           "periodic": {"lengths": [1.9, 1.9, 1.9], "drop": [0.0, 0.0, 1.0]}, "conductance": {"law": "fit"}}
    s = run(parse_scene(doc)).summary
    K = pair_conductance(1.0, 1.0, 1.0, neck_radius(1.0, 1.0, 0.1))
    assert s["bonds"] == 3
    assert s["effective_conductivity"] == pytest.approx(K / 1.9, rel=1e-12)


@pytest.mark.parametrize("table, match", [
    ({"lengths": [1.9, 1.9]}, r"\[periodic\] lengths"),
    ({"lengths": [1.9, 1.9, 1.9], "axes": ["w"]}, r"\[periodic\] axes"),
    ({"lengths": [1.9, 1.9, 1.9], "axes": ["x"], "drop": [0, 0, 1.0]}, r"\[periodic\].*drop"),
    ({"lengths": [1.9, 1.9, 1.9], "size": 2}, r"\[periodic\] size: unknown key"),
])
def test_bad_periodic_tables_are_named(table, match):
    doc = {"material": {"conductivity": 1.0, "density": 1.0, "specific_heat": 1.0},
           "particles": {"position": [[0.0, 0.0, 0.0]], "radius": [1.0], "temperature": [0.0]}, "periodic": table}
    with pytest.raises(ValueError, match=match):
        parse_scene(doc)


def test_periodic_generator_refusals():
    doc = {"material": {"conductivity": 1.0, "density": 1.0, "specific_heat": 1.0},
           "generator": {"kind": "chain", "n": 3, "radius": 1.0, "overlap": 0.1, "boundary": "periodic", "hot": 1.0,
                         "cold": 0.0}}
    with pytest.raises(ValueError, match="periodic"):
        parse_scene(doc)
    doc["generator"] = {"kind": "lattice", "shape": [2, 2, 2], "radius": 1.0, "overlap": 0.1, "structure": "hcp"}
    with pytest.raises(ValueError, match="structure"):
        parse_scene(doc)


def test_a_periodic_drop_drives_a_cell_beyond_its_initial_temperatures_and_is_not_refused():
    """The jumps across the box's faces drive the network as internal heat does: a cell started within 0.2 K settles
    to a spread of about the 1 K drop, which is right, not a maximum-principle violation (it had been refused: "the
    temperatures left the prescribed range")."""
    lay = lattice([2, 2, 2], 1.0, 0.1, "bcc")
    box = PeriodicBox(lay.period, origin=lay.origin, drop=[0.0, 0.0, 1.0])
    T0 = np.random.default_rng(1).uniform(0.0, 0.2, len(lay.radius))
    common = dict(materials=(UNIT,), law="fit", box=box)
    steady = run(make_scene(lay.position, lay.radius, T0, **common))
    trans = run(make_scene(lay.position, lay.radius, T0, mode="transient", integrator="implicit", dt=0.5,
                           t_end=200.0, **common))
    assert np.ptp(trans.T) > 0.5  # beyond the initial 0.2 K
    assert trans.summary["max_principle_violation"] is None and trans.summary["energy_error"] < 1e-9
    assert np.allclose(trans.T, steady.T, atol=1e-6)
