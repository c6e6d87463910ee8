"""Plots that compare: every temperature axis says its unit (``[scene] temperature_unit``), the wall loads of a run
share one unit, ``contact.png`` shows the temperature history. (Zohdi's frames in one colour range:
tests/test_zohdi.py.)"""

import pathlib
import tomllib

import matplotlib.axes
import pytest

import dem
from dem.cli import main
from dem.engines import engine_class
from dem.scene import load_scene
from dem.scene.parse import parse_scene

HOT_WALL = (pathlib.Path(dem.__file__).parent / "scene" / "builtin" / "hot-wall-sintering.toml").read_text()


@pytest.fixture
def labels(monkeypatch):
    """Every axis label the plots set, in order."""
    seen = []
    for name in ("set_xlabel", "set_ylabel"):
        original = getattr(matplotlib.axes.Axes, name)
        monkeypatch.setattr(matplotlib.axes.Axes, name,
                            lambda self, label, *args, _original=original, **kw: seen.append(label)
                            or _original(self, label, *args, **kw))
    return seen


def small_hot_wall(**changes) -> dict:
    doc = tomllib.loads(HOT_WALL.replace("n = 400", "n = 60").replace("t_end = 0.15", "t_end = 5e-3"))
    doc["output"] = {"interval": 1e-3}
    for table, values in changes.items():
        doc.setdefault(table, {}).update(values)
    return doc


@pytest.mark.parametrize("name, unit", [("hot-wall-sintering", "C"), ("packing", "C"), ("zohdi-compaction", "K")])
def test_temperature_unit_defaults(name, unit):
    assert load_scene(name).temperature_unit == unit


def test_temperature_unit_from_the_scene_or_radiation_and_refused_when_they_differ():
    doc = small_hot_wall(scene={"temperature_unit": "K"})
    assert parse_scene(doc).temperature_unit == "K"
    with pytest.raises(ValueError, match=r"\[scene\] temperature_unit = 'F': must be \"C\" or \"K\""):
        parse_scene(small_hot_wall(scene={"temperature_unit": "F"}))
    doc = small_hot_wall(radiation={"emissivity": 0.5, "T_inf": 20.0, "unit": "C"})
    assert parse_scene(doc).temperature_unit == "C"
    doc["scene"]["temperature_unit"] = "K"
    with pytest.raises(ValueError, match="differs from radiation.unit = 'C'"):
        parse_scene(doc)


@pytest.mark.slow
def test_moving_run_plots_say_the_temperature_unit_and_one_wall_load_unit(tmp_path, labels):
    result = dem.driver.run(parse_scene(small_hot_wall()), tmp_path)
    assert "timeseries.png" in result.summary["plots"]
    assert "temperature (°C)" in labels and "wall load (Pa)" in labels  # six box walls: stresses
    assert not any("temperature" in label and "(" not in label for label in labels)


def test_a_wall_outside_the_box_puts_every_wall_load_in_newtons():
    doc = small_hot_wall()
    engine = engine_class("verlet")(parse_scene(doc), None)
    assert engine.wall_load_unit() == "Pa"
    doc["walls"].append({"name": "slope", "point": [0.0, 0.0, 30e-3], "normal": [0.0, -0.6, -0.8]})
    engine = engine_class("verlet")(parse_scene(doc), None)
    engine.mechanics.w.force[:] = 2.0
    assert engine.wall_load_unit() == "N" and set(engine.wall_stress().values()) == {2.0}


def test_static_transient_plot_says_kelvin(tmp_path, labels):
    scene = load_scene("packing-transient")
    doc = tomllib.loads((pathlib.Path(dem.__file__).parent / "scene" / "builtin" / "packing-transient.toml")
                        .read_text())
    doc["generator"]["n"] = 300
    doc.setdefault("scene", {})["temperature_unit"] = "K"
    dem.driver.run(parse_scene(doc), tmp_path)
    assert scene.temperature_unit == "C" and "temperature (K)" in labels


def test_contact_png_shows_the_temperature_history(tmp_path, labels, capsys):
    history = tmp_path / "history.csv"
    history.write_text("t,overlap,T\n0,0,80\n1,1e-5,110\n2,2e-5,130\n")
    assert main(["contact", "luding-table1", "--history", str(history), "--out", str(tmp_path / "out")]) == 0
    assert "t (s)" in labels and "temperature (°C)" in labels and "$k_1(T,t)/k_1$" in labels
