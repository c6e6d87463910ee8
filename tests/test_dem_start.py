"""Runs that start from another run's state: a static scene measures the effective conductivity of a compact that a
moving run pressed, and the clock goes on from the state's."""

import json

import numpy as np
import pytest

from dem import Material, make_scene, run
from dem.geometry.walls import Wall
from dem.laws.conductance import ConductanceSpec
from dem.scene import parse_scene, state_file
from verification.luding import protocol as sp


@pytest.fixture(scope="module")
def pressed(tmp_path_factory):
    """A 3D box of 40 spheres pressed at 200 kPa by three stress walls (Luding 2005's preparation, in 3D)."""
    out = tmp_path_factory.mktemp("pressed")
    doc = sp.preparation_doc(40, 2.0e5, times=sp.Times(t_s=0.01, t_heat=0.05), dimension=3)
    result = run(parse_scene(doc), out)
    return out / "state.npz", result


def conductivity_doc(state, law="fit") -> dict:
    return {"material": {"conductivity": 20.0, "density": 2000.0, "specific_heat": 500.0},
            "start": {"state": str(state)},
            "walls": [{"name": "bottom", "point": [0, 0, 0], "normal": [0, 0, 1], "temperature": 1.0},
                      {"name": "top", "point": [0, 0, 1], "normal": [0, 0, -1], "temperature": 0.0}],
            "conductance": {"law": law, "out_of_range": "clip"}, "solver": {"mode": "steady", "floating": "mean"}}


@pytest.mark.slow
def test_a_static_scene_reports_the_effective_conductivity_of_a_pressed_compact(pressed, tmp_path):
    state, moving = pressed
    saved = state_file.load(state)
    assert saved["moving"] and saved["engine"] == "verlet" and saved["t"] == moving.summary["t"]
    result = run(parse_scene(conductivity_doc(state)), tmp_path / "k")
    s = result.summary
    assert s["engine"] == "static" and s["started_from"] == {"t": saved["t"], "steps": saved["steps"]}
    assert s["bonds"] > 0 and s["wall_bonds"] > 0
    # by hand: the same particles and walls at the saved offsets, Q L / (A dT) with the box's saved cross-section
    q = dict(zip(saved["wall_names"], saved["wall_q"]))
    walls = [Wall("bottom", [0, 0, q["bottom"]], [0, 0, 1], 1.0), Wall("top", [0, 0, -q["top"]], [0, 0, -1], 0.0)]
    by_hand = run(make_scene(saved["x"], saved["radius"], saved["T"], walls=walls, materials=(Material(20.0, 2000.0,
                                                                                                       500.0),),
                             conductance=ConductanceSpec(law="fit", out_of_range="clip"), mode="steady",
                             floating="mean"))
    length = -(q["bottom"] + q["top"])
    area = (-(q["left"] + q["right"])) * (-(q["front"] + q["back"]))
    expected = -by_hand.summary["boundary_heat_flow"]["walls"]["bottom"] * length / (area * 1.0)
    assert s["effective_conductivity"] == pytest.approx(expected, rel=1e-12)
    assert 0 < s["effective_conductivity"] < 20.0  # below the solid's: a loose compact of small contacts
    # the state the static run leaves is a state too
    again = state_file.load(tmp_path / "k" / "state.npz")
    assert not again["moving"] and np.array_equal(again["x"], saved["x"])
    assert json.loads((tmp_path / "k" / "summary.json").read_text())["effective_conductivity"] == \
        s["effective_conductivity"]


@pytest.mark.slow
def test_a_run_from_a_state_goes_on_from_its_clock(pressed, tmp_path):
    state, moving = pressed
    saved = state_file.load(state)
    doc = sp.cooling_doc(str(state), 2.0e5, times=sp.Times(t_s=0.01, cool=0.002, relax=0.002), dimension=3)
    scene = parse_scene(doc)
    assert scene.start_time == saved["t"] and scene.solver.t_end == pytest.approx(saved["t"] + 0.004)
    result = run(scene, tmp_path / "c")
    assert result.summary["t"] == pytest.approx(saved["t"] + 0.004, abs=result.summary["dt"])
    assert result.summary["steps"] > saved["steps"] and result.summary["neighbour_rebuilds"] >= \
        saved["neighbour_rebuilds"]
    rows = (tmp_path / "c" / "timeseries.csv").read_text().splitlines()
    header = rows[0].split(",")
    first = dict(zip(header, rows[1].split(",")))
    assert float(first["t"]) == pytest.approx(saved["t"]) and int(first["step"]) == saved["steps"]


def test_a_state_must_end_before_the_scene_does(pressed):
    state, _ = pressed
    doc = sp.cooling_doc(str(state), 2.0e5, times=sp.Times(t_s=0.01, cool=0.002, relax=0.002), dimension=3)
    doc["solver"]["t_end"] = 0.001
    with pytest.raises(ValueError, match=r"t_end = 0.001 s: must be beyond the saved state's time"):
        parse_scene(doc)
