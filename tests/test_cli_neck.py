"""``python -m fem_neck neck``: JSON output, and one-line errors with exit code 2 for bad input."""

import json
import subprocess
import sys

import pytest

from verification.cases import SEC43


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "fem_neck", *args], capture_output=True, text=True, timeout=120)


def test_neck_json_has_the_documented_keys_and_paper_value():
    proc = run_cli("neck", "--ri", "1e-3", "--rj", "3e-3", "--h", "0.2e-3", "--json")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    for key in ("a", "h_ci", "h_cj", "h_n", "iterations", "volume_residual"):
        assert key in out
    assert out["a"] == pytest.approx(SEC43["newton"].value, abs=1e-9)
    assert out["volume_residual"] < 1e-12


@pytest.mark.parametrize("method, expected", [("coble", SEC43["coble"].value), ("first", SEC43["first"].value)])
def test_neck_methods(method, expected):
    proc = run_cli("neck", "--ri", "1e-3", "--rj", "3e-3", "--h", "0.2e-3", "--method", method, "--json")
    assert json.loads(proc.stdout)["a"] == pytest.approx(expected, abs=1e-9)


@pytest.mark.parametrize(
    "args, words",
    [
        (["--ri", "-1e-3", "--rj", "3e-3", "--h", "0.2e-3"], "r_i = -0.001"),
        (["--ri", "nan", "--rj", "3e-3", "--h", "0.2e-3"], "r_i = nan"),
        (["--ri", "1e-3", "--rj", "3e-3", "--h", "2e-3"], "valid range 0 < h <="),
        (["--ri", "1e-3", "--rj", "3e-3", "--h", "0.2e-3", "--method", "exact"], "invalid choice"),
        (["--ri", "1e-3", "--rj", "3e-3", "--h", "0.2e-3", "--bogus"], "unrecognized arguments"),
        (["--ri", "one", "--rj", "3e-3", "--h", "0.2e-3"], "invalid float value"),
    ],
)
@pytest.mark.slow
def test_bad_input_is_one_line_and_exit_2(args, words):
    proc = run_cli("neck", *args)
    assert proc.returncode == 2
    assert proc.stdout == ""
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and words in lines[0]
    assert "Traceback" not in proc.stderr
