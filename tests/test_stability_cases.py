"""Fast stress cases from ``verification.stability`` (the full suite: ``python -m verification stability``).

Known defects found by the suite were kept here as ``xfail`` until fixed; none is open.
"""

import pathlib
import subprocess
import sys

import pytest

from verification.stability import cli_case, geometry_cases


def test_neck_geometry_stress_cases():
    failed = [f"{c.name}: {c.outcome}" for c in geometry_cases() if not c.passed]
    assert not failed, failed


@pytest.mark.parametrize("argv", [
    ["fem_neck", "neck", "--ri", "nan", "--rj", "1e-3", "--h", "1e-5", "--json"],
    ["fem_neck", "semisphere", "--h-over-r", "0.7", "--json"],
    ["fem_neck", "semisphere", "--h-over-r", "0.1", "--rtol", "0", "--json"],
    ["fem_neck", "pair", "--ri", "1e-3", "--rj", "-3e-3", "--h", "6e-5", "--kappa", "394", "--json"],
    ["dem", "run", "no-such-scene", "--json"],
])
def test_cli_bad_input_is_one_line_exit_2(argv):
    case = cli_case(" ".join(argv), argv, "error", timeout=120)
    assert case.passed, case.outcome


def test_neck_cli_huge_radii():
    case = cli_case("huge radii", ["fem_neck", "neck", "--ri", "1e300", "--rj", "1e300", "--h", "1e299", "--json"],
                    "either")
    assert case.passed, case.outcome


def test_semisphere_neck_below_supported_range_explained():
    case = cli_case("tiny neck", ["fem_neck", "semisphere", "--a-over-r", "5e-5", "--json"], "error")
    assert case.passed and "a_over_r" in case.outcome, case.outcome


def test_dem_generator_huge_n_refused(tmp_path: pathlib.Path):
    scene = tmp_path / "huge.toml"
    scene.write_text('[material]\nconductivity = 394.0\ndensity = 8960.0\nspecific_heat = 385.0\n'
                     '[generator]\nkind = "random"\nn = 1000000000000\nradius = 5e-5\noverlap = 0.1\n'
                     'boundary = "plates"\nhot = 1.0\ncold = 0.0\n[conductance]\nlaw = "rojek"\n'
                     '[solver]\nmode = "steady"\nfloating = "mean"\n')
    proc = subprocess.run([sys.executable, "-m", "dem", "run", str(scene), "--json"], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr[-300:]


@pytest.mark.parametrize("argv", [["fem_neck", "semisphere", "--h-over-r", "0.2"], ["dem", "run", "pair"]])
def test_out_is_an_existing_file(tmp_path: pathlib.Path, argv):
    afile = tmp_path / "afile"
    afile.write_text("")
    case = cli_case("--out file", argv + ["--out", str(afile), "--json"], "error", timeout=120)
    assert case.passed, case.outcome
