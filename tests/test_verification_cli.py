"""``python -m verification``: options, exit codes, and the quick runs (``paper --quick`` here; ``all --quick``
is marked slow and must finish in under 3 minutes on 2 cores)."""

import json
import subprocess
import sys
import time

import matplotlib.image
import numpy as np
import pytest

from test_verification_report import assert_report_links_resolve
from verification import cli


def _run(*args, timeout=600):
    return subprocess.run([sys.executable, "-m", "verification", *args], capture_output=True, text=True,
                          timeout=timeout)


@pytest.mark.parametrize("args", [[], ["nonsense"], ["paper", "--bogus"], ["paper", "--out"]])
@pytest.mark.slow
def test_bad_options_one_line_exit_2(args):
    proc = _run(*args)
    assert proc.returncode == 2 and proc.stdout == ""
    assert len(proc.stderr.strip().splitlines()) == 1 and "Traceback" not in proc.stderr


def test_out_is_a_file(tmp_path):
    f = tmp_path / "file"
    f.write_text("x")
    proc = _run("paper", "--quick", "--out", str(f))
    assert proc.returncode == 2 and "not a directory" in proc.stderr and len(proc.stderr.splitlines()) == 1


def test_help_lists_commands():
    proc = _run("--help")
    assert proc.returncode == 0
    for name in cli.COMMANDS:
        assert name in proc.stdout


def _check_run(out, proc, sections):
    assert proc.returncode == 0, proc.stderr[-2000:]
    summary = json.loads(proc.stdout)  # --json: one object and nothing else on stdout
    assert summary == json.loads((out / "summary.json").read_text())
    run = json.loads((out / "run.json").read_text())
    assert list(run["sections"]) == list(sections)
    for name, sec in run["sections"].items():
        assert sec["status"] == "ok", (name, sec["error"])
        for fig in sec["figures"]:
            assert matplotlib.image.imread(out / fig).shape[0] > 50  # every figure opens
    assert_report_links_resolve(out)
    return summary, (out / "report.md").read_text()


@pytest.mark.slow
def test_paper_quick(tmp_path):
    out = tmp_path / "res"
    proc = _run("paper", "--quick", "--json", "--no-progress", "--out", str(out))
    summary, md = _check_run(out, proc, ["paper"])
    for printed in ("0.741466", "0.774597", "0.745039", "0.419186", "0.276035", "0.278033", "1.064", "1.112",
                    "0.19934", "0.3946", "0.610573", "0.829653"):
        assert printed in md, printed
    for key in ("paper.sec43.a_newton", "paper.sec6.K_fe", "paper.sec6.K_model_eq45", "paper.fig16.slope",
                "paper.fig13.K_over_Kcyl.h0.08", "paper.fig15.K_over_Kcyl_rtol1e-6"):
        assert isinstance(summary[key]["rel_error"], float), key
    assert abs(summary["paper.sec6.K_model_eq45"]["rel_error"]) < 1e-5  # eq. (45) reproduced
    for hr in (0.02, 0.08, 0.2, 0.4):  # the FE against the independent reference table
        assert abs(summary[f"paper.fig13.K_over_Kcyl.h{hr:g}"]["rel_error"]) < 3e-4
    assert abs(summary["paper.fig16.slope"]["rel_error"]) < 0.03  # ours vs 1.064, sampling-dependent


@pytest.mark.slow
def test_all_quick_under_three_minutes(tmp_path):
    out = tmp_path / "res"
    t0 = time.perf_counter()
    proc = _run("all", "--quick", "--json", "--no-progress", "--out", str(out))
    seconds = time.perf_counter() - t0
    summary, _ = _check_run(out, proc, ["paper", "chains", "clusters", "transient", "lattices"])
    assert any(k.startswith("chains.") for k in summary)
    assert seconds < 180.0, seconds


def test_densification_bounds_and_correlation_are_their_closed_forms():
    from verification import densification

    phi = np.array([0.6, 0.9, 1.0])
    assert np.allclose(densification.hashin_shtrikman(phi), 2 * phi / (3 - phi), rtol=0, atol=0)
    assert densification.hashin_shtrikman(1.0) == 1.0 and densification.koh_fortini(1.0) == 1.0
    assert densification.koh_fortini(0.9) == pytest.approx(0.9 / 1.11, rel=1e-15)  # e = 0.1: 0.9 / (1 + 0.11)


@pytest.mark.slow
def test_densification_quick(tmp_path):
    """One union cell per lattice: the FE below both bounds, the laws on union necks beside it, the figure opens."""
    out = tmp_path / "res"
    proc = _run("densification", "--quick", "--json", "--no-progress", "--out", str(out))
    summary, md = _check_run(out, proc, ["densification"])
    assert summary["densification FE above the HS bound"] == 0
    rows = [v for k, v in summary.items() if isinstance(v, dict) and "rel_err_fit" in v]
    assert len(rows) == 3 and all(r["fe_error_estimate"] < 1e-2 for r in rows)
    assert all(abs(r["rel_err_shared-body"]) < 0.03 for r in rows)
