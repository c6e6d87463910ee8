"""What a DEM run folder holds: the plots a researcher looks at first, and a PVD collection listing every VTU."""

import re

import pytest

from dem import run
from dem.scene import parse_scene

SPECIMEN = {"material": {"conductivity": 394.0, "density": 8960.0, "specific_heat": 385.0},
            "generator": {"kind": "lattice", "shape": [3, 3, 6], "radius": 1e-3, "overlap": 0.1,
                          "boundary": "plates", "hot": 1.0, "cold": 0.0},
            "solver": {"mode": "transient", "integrator": "implicit", "dt": 0.01, "t_end": 0.2},
            "output": {"vtu_every": 3}}


@pytest.mark.slow
def test_transient_specimen_writes_its_plots_and_lists_every_snapshot(tmp_path):
    res = run(parse_scene(SPECIMEN), out=tmp_path)
    assert {"temperature.png", "heat_flow.png", "profile.png"} <= {p.name for p in tmp_path.glob("*.png")}
    assert set(res.summary["plots"]) == {"temperature.png", "heat_flow.png", "profile.png"}
    vtus = sorted(p.name for p in tmp_path.glob("particles_*.vtu"))
    listed = re.findall(r'file="(particles_\d+\.vtu)"', (tmp_path / "particles.pvd").read_text())
    assert len(vtus) == 8 and listed == vtus  # steps 0, 3, 6, ..., 18 and the last (20)


def test_steady_specimen_profile_carries_k_eff(tmp_path):
    doc = {**SPECIMEN, "solver": {"mode": "steady"}}
    res = run(parse_scene(doc), out=tmp_path)
    assert res.summary["effective_conductivity"] > 0
    assert (tmp_path / "profile.png").exists() and not (tmp_path / "temperature.png").exists()


@pytest.mark.slow
def test_unequal_pair_beyond_the_equal_spheres_neck_range_writes_summary_and_state(tmp_path):
    """r = 0.4 and 0.5 mm overlapping by 0.25 mm between a hot and a cold wall (out_of_range = "clip"): beyond the
    neck model's range for this pair (0.225 mm), inside 2/3 of the smaller radius (0.267 mm, the equal spheres'
    limit the neck profile used to cap at). The run writes its summary, profile and state."""
    import json
    import pathlib
    import tomllib

    import numpy as np

    import dem
    from fem_neck.geometry import max_overlap

    doc = tomllib.loads((pathlib.Path(dem.__file__).parent / "scene" / "builtin" / "hot-wall-sintering.toml")
                        .read_text())
    del doc["generator"]
    doc["particles"] = {"position": [[3e-3, 3e-3, 0.4e-3], [3e-3, 3e-3, 1.05e-3]], "radius": [0.4e-3, 0.5e-3],
                        "temperature": [80.0, 80.0]}
    doc["walls"][1]["point"] = [0.0, 0.0, 1.55e-3]
    doc["solver"]["t_end"] = 2e-3
    assert 0.25e-3 > max_overlap(0.4e-3, 0.5e-3) > 0.2249e-3
    result = run(parse_scene(doc), tmp_path)
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert "output_errors" not in summary and "stopped" not in summary and summary["steps"] == result.summary["steps"]
    assert (tmp_path / "state.npz").exists() and (tmp_path / "profiles.csv").exists()
    necks = [a for a in summary["profile"]["neck_over_radius"] if a is not None]
    assert necks and all(0.0 < a < 1.0 for a in necks) and np.isfinite(summary["effective_conductivity"])
