"""What a DEM run folder holds: the plots a researcher looks at first, and a PVD collection listing every VTU."""

import re

from dem import run
from dem.scene import parse_scene

SPECIMEN = {"material": {"conductivity": 394.0, "density": 8960.0, "specific_heat": 385.0},
            "generator": {"kind": "lattice", "shape": [3, 3, 6], "radius": 1e-3, "overlap": 0.1,
                          "boundary": "plates", "hot": 1.0, "cold": 0.0},
            "solver": {"mode": "transient", "integrator": "implicit", "dt": 0.01, "t_end": 0.2},
            "output": {"vtu_every": 3}}


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
