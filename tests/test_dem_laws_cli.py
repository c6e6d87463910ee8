"""``python -m dem laws``: the conductance laws and the contact laws, each with the keys a scene gives it -- keys the
scene reader takes for that law (and, for the conductance laws' own keys, refuses for the others)."""

import json
import subprocess
import sys

import pytest

from dem.laws.conductance import LAWS, ConductanceSpec, law_keys
from dem.laws.contact import CONTACT_LAWS, law_module
from dem.scene.schema import check, keys

OWN = {"slope": 1.0, "fit_file": None, "unequal": False}  # keys that only some conductance laws read


def listed() -> dict:
    out = subprocess.run([sys.executable, "-m", "dem", "laws", "--json"], capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


@pytest.mark.slow
def test_every_conductance_and_contact_law_is_listed_with_its_keys():
    laws = listed()
    for name in LAWS:
        assert laws[name].startswith("[conductance] ")
        assert laws[name].endswith("keys: " + ", ".join(law_keys(name)))
    for name in CONTACT_LAWS:
        entry = laws[name if name not in LAWS else f"{name} (contact)"]
        assert entry.startswith("[contact] ")
        law_fields = entry.split("; keys: ")[1].split(", ")
        engine = "verlet" if name != "zohdi" else "staggered"
        # every key is one the scene takes for that law
        check({"contact": {"law": name, **{k: 1.0 for k in law_fields}}}, engine, law_module(name))
    assert {"hertz_mindlin", "jkr", "luding"} <= set(laws)


@pytest.mark.parametrize("law", LAWS)
def test_conductance_keys_are_those_the_law_reads(law):
    assert set(law_keys(law)) <= keys("conductance")
    for key, value in OWN.items():
        if key == "fit_file":
            continue  # its default (None) is taken by every law; a path is refused by the others
        if key in law_keys(law):
            ConductanceSpec(law=law, **{key: value})
        elif key == "slope":
            with pytest.raises(ValueError, match="slope"):
                ConductanceSpec(law=law, **{key: value})
    if "fit_file" not in law_keys(law):
        with pytest.raises(ValueError, match="fit_file"):
            ConductanceSpec(law=law, fit_file="fit.json")
