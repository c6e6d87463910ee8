"""Named groups of particles ([[groups]], dem.scene.groups): regions, ids, types and layers choose the particles the
hand-counted way; what a group gives its particles matches the per-particle lists; held groups are the ends of the
effective conductivity; bad groups get one line."""

import numpy as np
import pytest

from dem import run
from dem.scene import parse_scene

R = 1e-4
D = 1.9e-4  # the lattice generator's neighbour distance at overlap 0.1
MATERIAL = {"conductivity": 394.0, "density": 8960.0, "specific_heat": 385.0}


def lattice_doc(groups=(), **solver):
    """A 3 x 3 x 3 simple cubic lattice (centres 0, D, 2D along each axis after the generator's offset)."""
    return {"materials": [{"name": "copper", **MATERIAL}, {"name": "bronze", **MATERIAL, "conductivity": 60.0}],
            "generator": {"kind": "lattice", "shape": [3, 3, 3], "radius": R, "overlap": 0.1},
            "groups": list(groups), "solver": {"mode": "steady", **solver}}


def chosen(table: dict) -> np.ndarray:
    """The lattice's particles (their offsets from the lowest centre, in units of D) the group holds."""
    scene = parse_scene(lattice_doc([{"name": "g", "fixed": True, "temperature": 1.0, **table}]))
    p = scene.particles
    return np.round((p.position[p.fixed] - p.position.min(axis=0)) / D).astype(int)


def test_selectors_choose_by_hand():
    doc = parse_scene(lattice_doc())
    lo = doc.particles.position.min(axis=0)
    mid = (lo + D).tolist()
    assert len(chosen({"region": "slab", "axis": "z", "lo": lo[2] + 0.5 * D})) == 18
    assert len(chosen({"region": "slab", "axis": "x", "hi": lo[0] + 0.5 * D})) == 9
    box = chosen({"region": "box", "lo": (lo - 0.1 * D).tolist(), "hi": (lo + 1.1 * D).tolist()})
    assert len(box) == 8 and box.max() == 1
    sphere = chosen({"region": "sphere", "center": mid, "radius": 1.01 * D})
    assert len(sphere) == 7 and np.all(np.abs(sphere - 1).sum(axis=1) <= 1)  # the centre and its 6 neighbours
    assert len(chosen({"region": "cylinder", "axis": "z", "center": mid, "radius": 1.01 * D})) == 15
    assert len(chosen({"region": "cylinder", "axis": "z", "center": mid, "radius": 1.01 * D,
                       "lo": mid[2] - 0.5 * D, "hi": mid[2] + 0.5 * D})) == 5
    top = chosen({"layer": "top", "thickness": 0.5 * D})
    assert len(top) == 9 and np.all(top[:, 2] == 2)
    assert np.all(chosen({"layer": "bottom", "axis": "y", "thickness": 1.5 * D})[:, 1] <= 1)
    assert len(chosen({"ids": [0, [5, 7], 26]})) == 5
    assert len(chosen({"ids": [[0, 26]], "layer": "top", "thickness": 0.5 * D})) == 9  # selectors intersect


def test_types_and_materials():
    """A group gives the middle layer bronze; a later group selects it by type (2) and by name."""
    give = {"name": "middle", "region": "slab", "axis": "z", "lo": -1.0, "hi": 1.0, "layer": "bottom",
            "thickness": 1.5 * D, "material": "bronze"}
    scene = parse_scene(lattice_doc([give]))
    assert np.bincount(scene.particles.material).tolist() == [9, 18]
    for types in ([2], ["bronze"]):
        scene = parse_scene(lattice_doc([give, {"name": "b", "types": types, "heat": 1e-3}]))
        assert np.all((scene.particles.heat > 0) == (scene.particles.material == 1))


def test_held_groups_match_the_lists_and_carry_the_heat():
    """Holding the bottom and top layers by groups gives the same run as the per-particle lists, the groups' names
    in boundary_heat_flow and the specimen; with 1 mW in each middle particle and both ends at the same temperature
    the held groups take all of it (9 mW in)."""
    groups = [{"name": "bottom", "layer": "bottom", "thickness": 0.5 * D, "temperature": 100.0, "fixed": True},
              {"name": "top", "layer": "top", "thickness": 0.5 * D, "temperature": 0.0, "fixed": True}]
    by_groups = run(parse_scene(lattice_doc(groups)))
    p = parse_scene(lattice_doc()).particles
    z = p.position[:, 2]
    T = np.where(z == z.min(), 100.0, 0.0)
    listed = {"materials": lattice_doc()["materials"], "solver": {"mode": "steady"},
              "particles": {"position": p.position.tolist(), "radius": p.radius.tolist(), "temperature": T.tolist(),
                            "fixed": ((z == z.min()) | (z == z.max())).tolist()}}
    by_lists = run(parse_scene(listed))
    np.testing.assert_allclose(by_groups.T, by_lists.T, rtol=1e-12)
    s = by_groups.summary
    assert s["specimen"]["hot"] == "group bottom" and s["specimen"]["cold"] == "group top"
    assert s["effective_conductivity"] == pytest.approx(by_lists.summary["effective_conductivity"], rel=1e-12)
    assert s["boundary_heat_flow"]["groups"]["bottom"] == pytest.approx(
        by_lists.summary["boundary_heat_flow"]["groups"]["held at 100"], rel=1e-12)
    middle = {"name": "middle", "ids": [[0, 26]], "heat": 1e-3}  # every particle; the held ones take no heat
    s = run(parse_scene(lattice_doc([middle, groups[0], {**groups[1], "temperature": 100.0}]))).summary
    assert sum(s["boundary_heat_flow"]["groups"].values()) == pytest.approx(9e-3, rel=1e-9)
    assert "effective_conductivity" not in s  # both ends at one temperature: no specimen


@pytest.mark.parametrize("table, message", [
    ({"name": "g"}, r"\[groups\]\[0\] \(g\): needs a selector"),
    ({"region": "slab", "lo": 0.0}, r"\[groups\]\[0\] name: required"),
    ({"name": "g", "region": "cone"}, r"region = 'cone': must be one of slab, box, sphere, cylinder"),
    ({"name": "g", "region": "slab", "axis": "w", "lo": 0.0}, r"axis = 'w': must be"),
    ({"name": "g", "region": "slab", "axis": "z"}, r"needs lo and/or hi"),
    ({"name": "g", "region": "sphere", "center": [0, 0, 0], "radius": -1.0}, r"radius = -1.0: must be a finite number > 0"),
    ({"name": "g", "region": "slab", "axis": "z", "lo": 1.0}, r"selects no particle"),
    ({"name": "g", "ids": [[5, 2]]}, r"ids: entry \[5, 2\]: must be an id or a range"),
    ({"name": "g", "types": [3]}, r"types: 3: must be a LAMMPS type 1..2"),
    ({"name": "g", "layer": "middle", "thickness": 1.0}, r"layer = 'middle': must be \"top\" or \"bottom\""),
    ({"name": "g", "ids": [0], "fixed": 1}, r"fixed = 1: must be true or false"),
    ({"name": "g", "ids": [0], "material": "steel"}, r"material\[0\] = 'steel': unknown"),
    ({"name": "g", "ids": [0], "colour": "red"}, r"\[groups\]\[0\] colour: unknown key"),
])
def test_bad_groups_get_one_line(table, message):
    with pytest.raises(ValueError, match=message):
        parse_scene(lattice_doc([table]))


def test_group_names_are_unique():
    with pytest.raises(ValueError, match=r"\[groups\]\[1\] \(a\) name: used by an earlier group"):
        parse_scene(lattice_doc([{"name": "a", "ids": [0]}, {"name": "a", "ids": [1]}]))
