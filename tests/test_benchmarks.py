"""``python -m benchmarks``: subjects, options, exit codes, and reports whose links resolve (the timings themselves
are the benchmarks' business, never asserted here)."""

import importlib.machinery
import json
import subprocess
import sys
import types

import pytest

from benchmarks import SUBJECTS
from benchmarks import cli
from benchmarks.neck import plain_newton, random_bonds
from fem_neck import neck_radius
from test_verification_report import assert_report_links_resolve


def _run(*args, timeout=600):
    return subprocess.run([sys.executable, "-m", "benchmarks", *args], capture_output=True, text=True,
                          timeout=timeout)


@pytest.mark.parametrize("args", [["nonsense"], ["neck", "--bogus"], ["neck", "--out"]])
@pytest.mark.slow
def test_bad_options_one_line_exit_2(args):
    proc = _run(*args)
    assert proc.returncode == 2 and proc.stdout == ""
    assert len(proc.stderr.strip().splitlines()) == 1 and "Traceback" not in proc.stderr


def test_every_subject_has_the_interface():
    import importlib

    for name, module in SUBJECTS.items():
        mod = importlib.import_module(module)
        assert isinstance(mod.TITLE, str) and callable(mod.run), name


def test_plain_newton_baseline_finds_the_same_roots():
    r_i, r_j, h = random_bonds(2000)
    a = neck_radius(r_i, r_j, h)
    assert abs(plain_newton(r_i, r_j, h) / a - 1).max() < 1e-14


@pytest.fixture
def fake_subject(monkeypatch):
    """A subject ``fake`` whose behaviour the test sets: ``seen`` records the options that reached ``run``."""
    seen = {}
    mod = types.ModuleType("fake_subject")
    mod.__spec__ = importlib.machinery.ModuleSpec(mod.__name__, None)
    mod.TITLE = "Fake timings"

    def run(section, quick):
        from matplotlib.figure import Figure

        seen["quick"] = quick
        if "seconds" not in seen:
            raise RuntimeError("the timed call failed")
        fig = Figure(figsize=(2, 2))
        fig.subplots().plot([0, 1], [0, 1])
        figure = section.figure(fig, "line")
        section.add_text("A study", "text", figures=[figure])
        section.figure(Figure(figsize=(2, 2)), "unlinked")
        section.summary["fake_seconds"] = seen["seconds"]
        section.target("fake under a second", seen["seconds"], 1.0, "s")

    mod.run = run
    monkeypatch.setitem(sys.modules, mod.__name__, mod)
    monkeypatch.setitem(SUBJECTS, "fake", mod.__name__)
    monkeypatch.setenv("TQDM_DISABLE", "")  # main() sets it for --no-progress; monkeypatch restores it
    return seen


def test_options_reach_run_and_json_is_the_summary(fake_subject, tmp_path, capsys):
    fake_subject["seconds"] = 0.25
    code = cli.main(["fake", "--quick", "--json", "--no-progress", "--out", str(tmp_path)])
    out, err = capsys.readouterr()
    assert code == 0 and fake_subject["quick"] is True, err
    assert json.loads(out) == {"fake_seconds": 0.25} == json.loads((tmp_path / "summary.json").read_text())
    run = json.loads((tmp_path / "run.json").read_text())
    assert run["sections"]["fake"]["status"] == "ok"
    assert_report_links_resolve(tmp_path)


def test_a_missed_target_fails_the_command(fake_subject, tmp_path, capsys):
    fake_subject["seconds"] = 2.5
    code = cli.main(["fake", "--no-progress", "--out", str(tmp_path)])
    out, err = capsys.readouterr()
    assert code == 1
    assert "fail" in out.splitlines()[0] and "fake under a second" in out
    assert err.strip() == "python -m benchmarks: fake: fail: target missed: fake under a second"
    md = (tmp_path / "report.md").read_text()
    assert "| [Fake timings](#fake-timings) | fail: target missed: fake under a second |" in md
    assert "| fake | fake under a second | 2.5 s | <= 1 s | FAIL |" in md
    assert json.loads((tmp_path / "run.json").read_text())["sections"]["fake"]["status"] == "fail"
    assert_report_links_resolve(tmp_path)


def test_a_subject_that_raises_is_an_error(fake_subject, tmp_path, capsys):
    code = cli.main(["fake", "--no-progress", "--out", str(tmp_path)])  # no "seconds": run raises
    assert code == 1
    out, err = capsys.readouterr()
    assert "error" in out and "RuntimeError: the timed call failed" in err
    assert "Traceback" in (tmp_path / "fake" / "error.txt").read_text()


@pytest.mark.slow
def test_neck_quick_writes_a_report_that_opens(tmp_path):
    out = tmp_path / "res"
    proc = _run("neck", "--quick", "--json", "--no-progress", "--out", str(out))
    assert proc.returncode in (0, 1), proc.stderr[-2000:]  # 1: the machine was too busy for the target
    summary = json.loads(proc.stdout)
    for key in ("neck_newton_over_plain", "neck_newton_seconds", "neck_plain_newton_seconds", "neck_bonds"):
        assert key in summary
    assert_report_links_resolve(out)


def test_ngsolve_startup_setting_reaches_1e_minus_4_at_the_reference_cases():
    pytest.importorskip("ngsolve")
    from benchmarks.fe import FE_CASES, NGSOLVE_STARTUP, ngsolve_semisphere
    from verification.cases import SEMISPHERE_BY_H

    for h_over_r in FE_CASES:
        row = SEMISPHERE_BY_H[h_over_r]
        k, _ = ngsolve_semisphere(row.a_over_r, **NGSOLVE_STARTUP)
        assert abs(k / row.K_over_Kcyl - 1) < 1e-4, h_over_r


@pytest.mark.slow
def test_whole_processes_count_the_cpu_of_grandchildren_and_not_of_sleep():
    """The start-up comparison's clock: a command's CPU time includes the processes it waited for (a grandchild
    that spins ~0.3 s), a sleeping one costs wall time only, and the ratio is the median of the paired rounds."""
    from benchmarks.timing import paired_ratio, whole_processes

    spin = "import time; t = time.process_time()\nwhile time.process_time() - t < 0.3: pass"
    parent = f"import subprocess, sys; subprocess.run([sys.executable, '-c', {spin!r}], check=True)"
    runs = {"spin": lambda: subprocess.run([sys.executable, "-c", parent], check=True).returncode,
            "sleep": lambda: subprocess.run([sys.executable, "-c", "import time; time.sleep(0.3)"]).returncode}
    times, values = whole_processes(runs, rounds=2, warmup=0)
    assert values == {"spin": 0, "sleep": 0}
    assert all(len(times[name][kind]) == 2 for name in runs for kind in ("cpu", "wall"))
    assert min(times["spin"]["cpu"]) >= 0.3 and min(times["spin"]["wall"]) >= 0.3
    assert max(times["sleep"]["cpu"]) < 0.25 <= min(times["sleep"]["wall"])
    assert paired_ratio([2.0, 4.0, 9.0], [1.0, 2.0, 3.0]) == 2.0  # rounds 2, 2, 3: their median, not 15 / 6


def test_the_fit_commands_start_without_the_thread_counts_the_benchmarks_set(monkeypatch):
    """``python -m benchmarks`` sets the BLAS thread variables for its own studies; the commands timed side by side
    start without them (as from a shell), the rest of the environment kept."""
    from benchmarks.fit import shell_environment
    from sinterheat import threads

    monkeypatch.setenv("SINTERHEAT_BENCH_PROBE", "kept")
    for variable in (threads.ENVIRONMENT, *threads.BLAS_VARIABLES):  # as sinterheat.threads.use sets them
        monkeypatch.setenv(variable, "2")
    env = shell_environment()
    assert env["SINTERHEAT_BENCH_PROBE"] == "kept"
    assert not {threads.ENVIRONMENT, *threads.BLAS_VARIABLES} & set(env)
