"""The main command, ``python -m fem_neck fit``: the sweep in this process, and the whole command as a user runs it
beside NGSolve solving the same points.

* The fit sweep (``fem_neck.fit.run_fit``, 44 points to 1e-4 on both cores, into a fresh folder).
* The whole process of ``python -m fem_neck fit --json --out DIR`` (fresh folder; imports, 40 solves, fit.json,
  fit.csv and fit.png), its CPU time (user + system of it and the processes it waited for) and wall time, medians
  of several rounds after a warm-up; with NGSolve installed (optional extra ``pip install .[peers]``), alternating
  with the whole process of NGSolve solving the same 40 a/r (:func:`benchmarks.fe.ngsolve_sweep` at
  :data:`benchmarks.fe.NGSOLVE_STARTUP`), and the medians of the round-by-round ratios by CPU and by wall time
  (targets: at most 1 each). Both run as from a shell that sets no thread counts (:func:`shell_environment`).
"""

from __future__ import annotations

import json
import os
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np

from benchmarks.fe import NGSOLVE_STARTUP
from benchmarks.timing import available, paired_ratio, whole_processes
from sinterheat import threads
from verification.report import records_table

TITLE = "The main command: python -m fem_neck fit"
STARTUP_POINTS = 40  # the main command's default sweep
STARTUP_ROUNDS = 5  # counted rounds of the side-by-side start-up (after one warm-up)
LIMITS = {"fit_seconds": 15.0, "startup_cpu_ratio": 1.0, "startup_wall_ratio": 1.0}


def study_fit(section, quick: bool) -> None:
    from fem_neck.fit import run_fit

    points = 12 if quick else 44
    with tempfile.TemporaryDirectory() as tmp:  # fresh folder: run_fit resumes from an existing fit.csv
        t0 = time.perf_counter()
        fit = run_fit(n_points=points, rtol=1e-4, out=pathlib.Path(tmp), progress=False)
        seconds = time.perf_counter() - t0
    section.summary.update({"fit_seconds": seconds, "fit_points": points, "fit_solve_seconds": fit.get("solve_seconds")})
    row = {"points": points, "rtol": 1e-4, "seconds": seconds, "solve_seconds": fit.get("solve_seconds"),
           "slope": fit.get("slope"), "unconverged": len(fit.get("unconverged", []))}
    section.csv("fit", [row])
    note = " Quick mode: 12 points, so this is not the target's figure (>= 40 points)." if quick else ""
    section.add_text(
        "Fit sweep",
        f"`fem_neck.fit.run_fit(n_points={points}, rtol=1e-4)` into a fresh folder (process pool over both cores, "
        f"including fit.json/csv/png).{note}\n\n" + records_table([row]))


def shell_environment() -> dict:
    """This process's environment without the thread counts (``SINTERHEAT_THREADS`` and the BLAS variables of
    :data:`sinterheat.threads.BLAS_VARIABLES`) that ``python -m benchmarks`` sets for its own studies
    (:func:`sinterheat.threads.use`): the commands timed side by side start as a user starts them from a shell."""
    return {k: v for k, v in os.environ.items() if k not in (threads.ENVIRONMENT, *threads.BLAS_VARIABLES)}


def study_startup(section, quick: bool) -> None:
    """The main command as a user runs it, a whole fresh process each time, beside NGSolve solving the same points
    (when installed): CPU time (of the process and every process it waited for) and wall time, medians over the
    rounds, and the median of the round-by-round ratios."""
    label = f"`python -m fem_neck fit` / NGSolve sweep of the same {STARTUP_POINTS} points, whole processes"
    setting = NGSOLVE_STARTUP
    rounds = 2 if quick else STARTUP_ROUNDS
    worker = (f"from benchmarks.fe import ngsolve_sweep; ngsolve_sweep({STARTUP_POINTS}, {setting['order']}, "
              f"{setting['maxh']}, {setting['hp_levels']})")
    env = shell_environment()
    with tempfile.TemporaryDirectory() as tmp:
        runs = iter(range(10**6))

        def ours():
            out = pathlib.Path(tmp) / f"fit{next(runs)}"  # a fresh folder every time (no resume)
            subprocess.run([sys.executable, "-m", "fem_neck", "fit", "--json", "--out", str(out)], check=True,
                           capture_output=True, env=env)
            return json.loads((out / "fit.json").read_text())

        def theirs():
            proc = subprocess.run([sys.executable, "-c", worker], check=True, capture_output=True, text=True, env=env)
            return json.loads(proc.stdout.splitlines()[-1])

        peers = {"fit": ours, "ngsolve": theirs} if available("ngsolve") else {"fit": ours}
        times, values = whole_processes(peers, rounds)
    median = {name: {kind: float(np.median(t[kind])) for kind in ("cpu", "wall")} for name, t in times.items()}
    ours_text = (f"`python -m fem_neck fit --json --out DIR` into a fresh folder (imports, {STARTUP_POINTS} hp solves "
                 f"to 1e-4 on both cores, fit.json, fit.csv, fit.png) **{median['fit']['cpu']:.2f} s CPU, "
                 f"{median['fit']['wall']:.2f} s wall**")
    section.summary.update({"startup_fit_seconds": median["fit"]["wall"],
                            "startup_fit_cpu_seconds": median["fit"]["cpu"]})
    rows = [{"command": "python -m fem_neck fit --json --out DIR", "cpu_seconds": median["fit"]["cpu"],
             "wall_seconds": median["fit"]["wall"], "points": len(values["fit"]["points"])}]
    how = (f"Whole processes, one uncounted warm-up and {rounds} counted rounds, medians; CPU time is user + system "
           f"of the process and every process it waited for (its workers and its plotting process); both started "
           f"as from a shell that sets no thread counts")
    if "ngsolve" not in peers:
        section.csv("startup", rows)
        section.add_text("Start-up of the main command",
                         f"{how}: {ours_text}. NGSolve is not installed (optional extra: `pip install .[peers]`): "
                         "the side-by-side ratios are skipped.")
        section.target(label + ", CPU time", None, LIMITS["startup_cpu_ratio"])
        section.target(label + ", wall time", None, LIMITS["startup_wall_ratio"])
        return
    k_ours = [k for _, k in values["fit"]["points"]]
    k_ng = values["ngsolve"]["K_over_Kcyl"]
    deviation = max(abs(b / a - 1.0) for a, b in zip(k_ours, k_ng))
    ratio = {kind: paired_ratio(times["fit"][kind], times["ngsolve"][kind]) for kind in ("cpu", "wall")}
    section.summary.update({"startup_ngsolve_seconds": median["ngsolve"]["wall"],
                            "startup_ngsolve_cpu_seconds": median["ngsolve"]["cpu"],
                            "startup_fit_over_ngsolve": ratio["wall"], "startup_fit_over_ngsolve_cpu": ratio["cpu"]})
    section.csv("startup", rows + [{"command": f"NGSolve sweep (order {setting['order']}, maxh {setting['maxh']}, "
                                               f"{setting['hp_levels']} hp levels)",
                                    "cpu_seconds": median["ngsolve"]["cpu"], "wall_seconds": median["ngsolve"]["wall"],
                                    "points": len(k_ng)}])
    section.add_text(
        "Start-up of the main command",
        f"{how}, alternating with NGSolve: {ours_text}; NGSolve solving the same {STARTUP_POINTS} a/r in one process "
        f"(import, geometry, mesh, solve at order {setting['order']}, maxh {setting['maxh']}, "
        f"{setting['hp_levels']} hp levels, which reaches 1e-4 at the three reference cases; no estimate, no files) "
        f"**{median['ngsolve']['cpu']:.2f} s CPU, {median['ngsolve']['wall']:.2f} s wall**; median of the "
        f"round-by-round ratios **{ratio['cpu']:.2f} by CPU time, {ratio['wall']:.2f} by wall time**. The two "
        f"sweeps agree to {deviation:.1e} (largest relative difference over the points).")
    section.target(label + ", CPU time", ratio["cpu"], LIMITS["startup_cpu_ratio"])
    section.target(label + ", wall time", ratio["wall"], LIMITS["startup_wall_ratio"])


def run(section, quick: bool) -> None:
    section.summary.update({"fit_seconds": None, "startup_fit_seconds": None, "startup_fit_cpu_seconds": None,
                            "startup_ngsolve_seconds": None, "startup_ngsolve_cpu_seconds": None,
                            "startup_fit_over_ngsolve": None, "startup_fit_over_ngsolve_cpu": None})
    study_fit(section, quick)
    section.target("the full fit, >= 40 points to 1e-4, both cores", None if quick else section.summary["fit_seconds"],
                   LIMITS["fit_seconds"], "s")
    study_startup(section, quick)
