"""The ``fit`` law: each half at its own a/r_i from a fit.json, halves in series."""

import json

import numpy as np
import pytest

from dem import make_scene, run
from dem.laws.conductance import ConductanceSpec
from fem_neck import law as fem_law
from fem_neck.geometry import neck_radius


def test_fit_law_from_json_unequal_pair(tmp_path):
    law = fem_law.ConductanceLaw(A=0.3, B=-0.2, C=0.1, E=0.05)
    path = tmp_path / "fit.json"
    path.write_text(json.dumps({"slope": 1.07, "law": law.to_dict()}))
    r = np.array([1e-3, 3e-3])
    x = [[0, 0, 0], [0, 0, 3.94e-3]]
    a = neck_radius(1e-3, 3e-3, 0.06e-3)
    halves = [394 * np.pi * ri * law.k_over_kcyl(a / ri) for ri in r]
    series = 1 / (1 / halves[0] + 1 / halves[1])
    assert halves[0] != pytest.approx(halves[1], rel=1e-3)  # the halves differ: a/r_i differs
    for unequal, expected in ((False, series), (True, series * fem_law.unequal_factor(1e-3, 3e-3, a))):
        spec = ConductanceSpec(law="fit", fit_file=str(path), unequal=unequal)
        res = run(make_scene(x, r, [1.0, 0.0], fixed=[True, True], mode="steady", conductance=spec))
        assert res.summary["boundary_heat_flow"]["particles"]["1"] == pytest.approx(expected, rel=1e-12)


def test_missing_fit_file_is_a_value_error(tmp_path):
    with pytest.raises(ValueError, match="fit file"):
        ConductanceSpec(law="fit", fit_file=str(tmp_path / "none.json"))
