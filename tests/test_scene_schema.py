"""The scene schema is one table: the parser checks every key against it, the documentation's schema page is made
from it, and keys the scene's engine does not read are refused, naming the engine."""

import copy
import pathlib
import re
import sys
from dataclasses import fields

import pytest

from dem.geometry.walls import Wall
from dem.laws.ambient import Convection, Radiation
from dem.laws.conductance import ConductanceSpec
from dem.scene import OutputSpec, SolverSpec, builtin_scenes, load_scene, parse_scene, schema
from dem.scene.packing_files import SCENE_KEYS
from dem.scene.parse import GENERATOR_KEYS as KIND_KEYS
from dem.scene.electrical import ELECTRODE_KEYS
from dem.scene.staggered import ZohdiStepping

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "docs" / "_ext"))

import scene_schema  # noqa: E402  (the documentation's schema page: docs/_ext/scene_schema.py)


def test_the_schema_page_shows_every_table_and_key():
    """The documentation's schema page is the directive that renders the schema (docs/_ext/scene_schema.py): one
    section per table, every key of it, and under ``[contact]`` every field of every contact law's material."""
    from dem.laws.contact import CONTACT_LAWS, law_module

    page = (ROOT / "docs" / "reference" / "dem" / "schema.md").read_text()
    assert "```{scene-schema}\n```" in page, "docs/reference/dem/schema.md: the scene-schema directive went"
    sections = dict(scene_schema.sections())
    assert list(sections) == list(schema.TABLES)
    for table in schema.TABLES:
        missing = [key for key in schema.keys(table) if f"`{key}`" not in sections[table]]
        assert not missing, (table, missing)
    for name in CONTACT_LAWS:
        missing = [f.name for f in fields(law_module(name).Material) if f"`{f.name}`" not in sections["contact"]]
        assert f'`law = "{name}"`' in sections["contact"] and not missing, (name, missing)


def test_every_row_of_the_key_tables_has_its_four_cells():
    """A bar in a meaning (Zohdi's |E|) is escaped: unescaped, it would end the cell and cut the meaning short."""
    for table, text in scene_schema.sections():
        for line in text.splitlines():
            assert len(re.findall(r"(?<!\\)\|", line)) == 5, (table, line)


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
