"""The effective conductivity of any static packing with two ends (dem.scene.specimen): between held groups, a wall and
a group, two walls; on explicit particles, packing files and periodic boxes; checked against closed forms of a simple
cubic block and against the run's own heat flows."""

import json

import numpy as np
import pytest

from dem import make_scene, run
from dem.cli.run import console
from dem.geometry.periodic import PeriodicBox
from dem.geometry.walls import Wall
from dem.scene import load_scene
from dem.scene.packing_files import packing_from_particles, write_csv
from dem.scene.specimen import find_specimen, held_groups

R = 1e-4  # m
D = 2 * R - 0.1 * R  # centre distance of the block's neighbours (h/r = 0.1)


def block(n: int, m: int):
    """A simple cubic block of n x n columns of m particles along z, the bottom layer held at 1, the top at 0."""
    g = np.arange
    X, Y, Z = np.meshgrid(g(n) * D, g(n) * D, g(m) * D, indexing="ij")
    x = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    bottom, top = np.isclose(x[:, 2], 0.0), np.isclose(x[:, 2], (m - 1) * D)
    T = np.full(len(x), 0.5)
    T[bottom], T[top] = 1.0, 0.0
    return x, T, bottom, top


def own_k_eff(summary: dict) -> float:
    """Q L / (A dT) from the run's own heat flow out of the hot end and the specimen's length and area."""
    sp = summary["specimen"]
    kind, name = sp["hot"].split(" ", 1)
    q = -summary["boundary_heat_flow"]["walls" if kind == "wall" else "groups"][name]
    return q * sp["length"] / (sp["area"] * 1.0)


def test_held_layers_of_a_simple_cubic_block_give_the_columns_conductance():
    """Held layers are isothermal, so only the n^2 columns carry heat: Q = n^2 K dT / (m - 1) with K the bonds'
    conductance, L = (m - 1) D between the layers' centres, A the particles' extent ((n - 1) D + 2R)^2."""
    n, m = 3, 5
    x, T, bottom, top = block(n, m)
    res = run(make_scene(x, np.full(len(x), R), T, fixed=bottom | top, law="rojek", mode="steady"))
    K = res.thermal.K_pairs
    assert np.ptp(K) < 1e-12 * K[0]  # every bond the same
    s = res.summary
    assert s["specimen"] == {"axis": "z", "length": pytest.approx((m - 1) * D, rel=1e-12),
                             "area": pytest.approx(((n - 1) * D + 2 * R) ** 2, rel=1e-12),
                             "hot": "group held at 1", "cold": "group held at 0"}
    assert s["effective_conductivity"] == pytest.approx(n * n * K[0] * D / ((n - 1) * D + 2 * R) ** 2, rel=1e-9)
    assert s["effective_conductivity"] == pytest.approx(own_k_eff(s), rel=1e-12)
    assert s["boundary_heat_flow"]["groups"]["held at 1"] == pytest.approx(-n * n * K[0] / (m - 1), rel=1e-9)


def test_a_periodic_box_gives_its_area():
    """The block periodic along x and y (its period n D): the bonds across the faces carry nothing (isothermal
    layers), the area is the box's, k_eff = K / D."""
    n, m = 3, 4
    x, T, bottom, top = block(n, m)
    box = PeriodicBox([n * D, n * D, 10 * m * D], (True, True, False), [-D / 2, -D / 2, -D])
    res = run(make_scene(x, np.full(len(x), R), T, fixed=bottom | top, law="rojek", mode="steady", box=box))
    K = res.thermal.K_pairs
    assert res.summary["specimen"]["area"] == pytest.approx((n * D) ** 2, rel=1e-12)
    assert res.summary["effective_conductivity"] == pytest.approx(K[0] / D, rel=1e-9)


def test_a_wall_and_a_held_layer():
    """A hot wall below the block, the top layer held: each column is the wall bond and m - 1 pair bonds in series;
    L from the wall's plane to the top layer's centres."""
    n, m = 2, 4
    x, T, bottom, top = block(n, m)
    T[bottom] = 0.5
    wall = Wall("floor", [0.0, 0.0, -0.95 * R], [0.0, 0.0, 1.0], 1.0)
    res = run(make_scene(x, np.full(len(x), R), T, fixed=top, walls=[wall], law="rojek", mode="steady"))
    K, K_w = res.thermal.K_pairs[0], res.thermal.K_walls
    assert len(K_w) == n * n and np.ptp(K_w) < 1e-12 * K_w[0]
    column = 1.0 / (1.0 / K_w[0] + (m - 1) / K)
    length = (m - 1) * D + 0.95 * R
    s = res.summary
    assert s["specimen"]["hot"] == "wall floor" and s["specimen"]["length"] == pytest.approx(length, rel=1e-12)
    expected = n * n * column * length / ((n - 1) * D + 2 * R) ** 2
    assert s["effective_conductivity"] == pytest.approx(expected, rel=1e-9)
    assert s["effective_conductivity"] == pytest.approx(own_k_eff(s), rel=1e-12)


def test_no_specimen_without_two_ends_apart():
    """Three held temperatures, or two held groups that interleave along every axis, make no specimen."""
    x, T, bottom, top = block(2, 3)
    p = make_scene(x, np.full(len(x), R), T, fixed=bottom | top).particles
    assert find_specimen(p, ()) is not None
    T3 = T.copy()
    T3[np.flatnonzero(bottom)[0]] = 2.0
    assert find_specimen(make_scene(x, np.full(len(x), R), T3, fixed=bottom | top).particles, ()) is None
    checker = (np.arange(len(x)) % 2 == 0)
    Tc = np.where(checker, 1.0, 0.0)
    mixed = make_scene(x, np.full(len(x), R), Tc, fixed=np.ones(len(x), bool)).particles
    assert len(held_groups(mixed)) == 2 and find_specimen(mixed, ()) is None


def test_a_packing_file_scene_writes_k_eff_and_profile(tmp_path):
    """A CSV packing with its layers held (the file's fixed and temperature columns): the summary has the effective
    conductivity, its specimen and the groups' heat flows; the folder a profile; the console one total per group, not one number per held particle."""
    n, m = 3, 4
    x, T, bottom, top = block(n, m)
    write_csv(tmp_path / "bed.csv", packing_from_particles(
        make_scene(x, np.full(len(x), R), T, fixed=bottom | top).particles))
    (tmp_path / "bed.toml").write_text('[material]\nconductivity = 394.0\ndensity = 8960.0\nspecific_heat = 385.0\n'
                                       '[particles]\nfile = "bed.csv"\n[solver]\nmode = "steady"\n')
    res = run(load_scene(tmp_path / "bed.toml"), out=tmp_path / "out")
    s = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert s["effective_conductivity"] == pytest.approx(own_k_eff(s), rel=1e-12)
    assert s["effective_conductivity"] == pytest.approx(res.summary["effective_conductivity"], rel=1e-15)
    assert (tmp_path / "out" / "profile.png").stat().st_size > 0
    assert len(s["boundary_heat_flow"]["particles"]) == 2 * n * n
    shown = console(s)["boundary_heat_flow"]
    assert "particles" not in shown and shown["groups"] == s["boundary_heat_flow"]["groups"]
    assert list(shown["groups"]) == ["held at 0", "held at 1"]
