"""The documentation's own machinery (``docs/_ext``), without building the site (CI builds it after the tests)."""

import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "docs" / "_ext"))

import api_check  # noqa: E402
import gallery_order  # noqa: E402


def test_public_objects_are_the_functions_and_classes_each_module_defines():
    names = set(api_check.public_objects("fem_neck"))
    assert {"fem_neck.geometry.neck_radius", "fem_neck.conduction.Result", "fem_neck.cli.main"} <= names
    assert "fem_neck.geometry._validated" not in names  # private
    assert "fem_neck.neck_radius" not in names  # re-exported by the package: documented where it is defined
    assert "fem_neck.cluster.neck_geometry" not in names  # imported into the module, not defined there
    assert not any(".__main__" in name for name in names)  # importing it would run the command


def test_gallery_order_lists_the_fe_examples_first_and_puts_unlisted_ones_last():
    key = gallery_order.ExampleOrder(str(ROOT / "examples"))
    ordered = sorted(["transient_pair.py", "zzz_new.py", "aaa_new.py", "semisphere.py"], key=key)
    assert ordered == ["semisphere.py", "transient_pair.py", "aaa_new.py", "zzz_new.py"]
    assert set(gallery_order.ORDER) == {p.name for p in (ROOT / "examples").glob("*.py")}  # every example placed


def test_every_module_with_public_objects_has_its_automodule():
    """What api_check finds in a build, found without one: every module of a documented package that defines a public
    function or class is named by an ``automodule`` directive of docs/reference/ (dem's modules included)."""
    import re

    text = "\n".join(p.read_text() for p in (ROOT / "docs" / "reference").rglob("*.rst"))
    placed = set(re.findall(r"^\.\. automodule:: (\S+)$", text, re.M))
    for package in ("fem_neck", "dem", "sinterheat"):
        modules = {name.rpartition(".")[0] for name in api_check.public_objects(package)}
        assert modules - placed == set(), package
    assert {"dem.scene.schema.display_rows", "dem.driver.run", "dem.laws.contact.jkr.JKRMaterial"} <= set(
        api_check.public_objects("dem"))
