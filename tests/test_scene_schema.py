"""The scene schema is one table: the parser checks every key against it, the README's key table is made from it,
and keys the scene's engine does not read are refused, naming the engine."""

import copy
import pathlib
import re
from dataclasses import fields

import pytest

from dem.geometry.walls import Wall
from dem.laws.ambient import Convection, Radiation
from dem.laws.conductance import ConductanceSpec
from dem.scene import OutputSpec, SolverSpec, builtin_scenes, load_scene, parse_scene, schema
from dem.scene.packing_files import SCENE_KEYS
from dem.scene.parse import GENERATOR_KEYS as KIND_KEYS
from dem.scene.zohdi import ELECTRODE_KEYS, ZohdiStepping

ROOT = pathlib.Path(__file__).resolve().parents[1]


def test_the_readme_key_table_is_the_schema():
    text = (ROOT / "README.md").read_text()
    table = re.search(r"<!-- schema-table:[^\n]*-->\n(.*?)<!-- /schema-table -->", text, re.S)
    assert table, "README.md: no schema table between <!-- schema-table --> markers"
    assert table.group(1) == schema.markdown(), "README.md's key table differs from dem.scene.schema.markdown()"


@pytest.mark.parametrize("table, names", [
    ("solver", {f.name for f in fields(SolverSpec)} | {f.name for f in fields(ZohdiStepping)}),
    ("output", {f.name for f in fields(OutputSpec)}),
    ("conductance", {f.name for f in fields(ConductanceSpec)}),
    ("convection", {f.name for f in fields(Convection)}),
    ("radiation", {f.name for f in fields(Radiation)}),
    ("walls", {f.name for f in fields(Wall)} | ELECTRODE_KEYS),
    ("particles", set(SCENE_KEYS)),
    ("generator", set().union(*KIND_KEYS.values())),
])
def test_every_field_the_parser_reads_is_in_the_schema(table, names):
    assert names <= schema.keys(table), sorted(names - schema.keys(table))


def test_every_builtin_scene_passes_the_schema_of_its_engine():
    for name in builtin_scenes():
        assert load_scene(name).engine in schema.ENGINE_NAMES


STATIC = {"material": {"conductivity": 1.0, "density": 1.0, "specific_heat": 1.0},
          "particles": {"position": [[0, 0, 0], [1.9, 0, 0]], "radius": [1.0, 1.0], "temperature": [0.0, 1.0]}}
LUDING = {"scene": {"physics": ["mechanical"]}, "material": {"density": 2000.0},
          "particles": {"position": [[0, 0, 0], [2.1e-3, 0, 0]], "radius": [1e-3, 1e-3], "temperature": [20.0, 20.0]},
          "contact": {"law": "luding", "k1": 1e5, "k2": 2e5, "kc": 1e5, "kt_ratio": 0.2, "gamma_n": 0.2,
                      "gamma_t": 0.05, "mu": 0.5, "mu_wall": 0.0, "T_melt": 120.0, "T_var": 10.0, "expansion": 1e-4,
                      "fluid_overlap": 0.2, "t0": 1e3, "brittle_sliding": True},
          "solver": {"mode": "transient", "t_end": 1e-3}}


@pytest.mark.parametrize("base, table, key, value, message", [
    (STATIC, "solver", "skin", 1e-4, r"\[solver\] skin: not read by the static engine \(read by verlet, staggered"),
    (STATIC, "gravity", "acceleration", [0, 0, -9.81], r"\[gravity\]: not read by the static engine"),
    (LUDING, "solver", "max_steps", 10, r"\[solver\] max_steps: not read by the verlet engine \(read by static"),
    (LUDING, "solver", "rtol", 1e-4, r"\[solver\] rtol: not read by the verlet engine"),
    (LUDING, "solver", "phi", 0.5, r"\[solver\] phi: not read by the verlet engine \(read by staggered"),
    (LUDING, "electrical", "scheme", "kirchhoff", r"\[electrical\]: not read by the verlet engine"),
    (LUDING, "output", "every", 2, r"\[output\] every: not read by the verlet engine"),
    (LUDING, "solver", "skinn", 1e-4, r"\[solver\] skinn: unknown key \(allowed: .*\bskin\b"),
])
def test_a_key_the_engine_does_not_read_is_refused_naming_it(base, table, key, value, message):
    doc = copy.deepcopy(base)
    doc.setdefault(table, {})[key] = value
    with pytest.raises(ValueError, match=message):
        parse_scene(doc)


def test_the_engine_a_scene_names_is_checked():
    doc = copy.deepcopy(LUDING)
    doc["solver"]["engine"] = "staggered"
    with pytest.raises(ValueError, match=r'engine = "staggered": steps particles that do not rotate'):
        parse_scene(doc)
    doc["solver"]["engine"] = "static"
    with pytest.raises(ValueError, match=r"engine = 'static': particles that move"):
        parse_scene(doc)
    doc["solver"]["engine"] = "verlet"
    assert parse_scene(doc).engine == "verlet"


def test_a_phase_may_change_any_field_of_the_law_but_the_density():
    doc = copy.deepcopy(LUDING)
    doc["phases"] = [{"start": 1e-4, "kt_ratio": 0.3, "T_melt": 110.0}]
    assert parse_scene(doc).motion.phases == ((1e-4, {"kt_ratio": 0.3, "T_melt": 110.0}),)
    doc["phases"] = [{"start": 1e-4, "density": 1000.0}]
    with pytest.raises(ValueError, match=r"\[phases\]\[0\] density: unknown key"):
        parse_scene(doc)
    doc["phases"] = [{"start": 1e-4, "k1": 3e5}]
    with pytest.raises(ValueError, match=r"\[phases\]\[0\] k1 = 300000.0: must be <= k2"):
        parse_scene(doc)


def test_every_contact_law_documents_every_field_of_its_material():
    from dem.laws.contact import CONTACT_LAWS, law_module

    for name in CONTACT_LAWS:
        law = law_module(name)
        documented = [k for keys, _, _ in law.SCHEMA_ROWS for k in keys]
        assert sorted(documented) == sorted(f.name for f in fields(law.Material)), name
