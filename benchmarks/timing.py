"""Timing helpers of the benchmarks: best-of timings, side-by-side rounds, fresh-process workers, peak memory."""

from __future__ import annotations

import json
import math
import pathlib
import subprocess
import sys
import time

import numpy as np


def best_time(fn, repeat: int = 3):
    """Smallest wall time of ``repeat`` calls of ``fn()`` and the last return value."""
    best, value = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        value = fn()
        best = min(best, time.perf_counter() - t0)
    return best, value


def side_by_side(fns: dict, rounds: int) -> tuple[dict, dict]:
    """Time every ``fns[name]()`` once per round, alternating, so that load from other processes hits all alike;
    returns the best time of each and its last return value."""
    best = {name: np.inf for name in fns}
    values = {}
    for _ in range(rounds):
        for name, fn in fns.items():
            t, values[name] = best_time(fn, 1)
            best[name] = min(best[name], t)
    return best, values


def fastest(rows: list[dict], tol: float, key: str = "rel_error") -> dict | None:
    """The row with the smallest ``seconds`` among those with ``key <= tol`` (None if none)."""
    ok = [row for row in rows if row[key] is not None and row[key] <= tol]
    return min(ok, key=lambda row: row["seconds"]) if ok else None


def growth_exponent(n, t) -> float | None:
    """Least-squares slope of log t against log n (None from fewer than two positive points)."""
    n, t = np.asarray(n, float), np.asarray(t, float)
    ok = (n > 0) & (t > 0)
    return float(np.polyfit(np.log(n[ok]), np.log(t[ok]), 1)[0]) if ok.sum() >= 2 else None


def ratio(a, b):
    return None if a is None or b is None else a / b


def peak_rss_mib() -> float:
    """Peak resident memory of this process in MiB: ``VmHWM`` (reset by exec, unlike ``ru_maxrss``, which a
    forked child inherits from its parent)."""
    try:
        for line in pathlib.Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return float(line.split()[1]) / 1024.0
    except OSError:
        pass
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def run_worker(module: str, func: str, n: int, timeout: float) -> dict:
    """Run ``module.func(n)`` in a fresh interpreter (its own peak memory) and return the JSON line it prints, or
    ``{"particles": n, "error": ...}``."""
    code = f"from {module} import {func}; {func}({int(n)})"
    try:
        proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"particles": n, "error": f"timeout after {timeout:g} s"}
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("{")]
    if proc.returncode != 0 or not lines:
        tail = (proc.stderr.strip().splitlines() or ["no output"])[-1]
        return {"particles": n, "error": f"exit {proc.returncode}: {tail[:200]}"}
    return json.loads(lines[-1])


def _sized_row(module: str, func: str, n: int, timeout: float) -> tuple[int, dict]:
    """A size sweep's job: ``n`` and its :func:`run_worker` row."""
    return n, run_worker(module, func, n, timeout)


def worker_sweep(section, name: str, module: str, func: str, sizes, timeout: float,
                 stop_at_error: bool = False) -> list[dict]:
    """:func:`run_worker` for each of ``sizes`` (ascending), independent jobs of :func:`sinterheat.pool.run_jobs`:
    one after another here (timings must not share the cores), all at once on a Dask cluster (each size on a worker
    of its own). The rows so far, in order of size, are written to ``section``'s CSV ``name`` after each (an
    interrupted bench keeps them); with ``stop_at_error`` the sizes above a failed one are left out (here: not run).
    Returns the rows, failed ones included (they hold ``error``)."""
    from sinterheat.pool import run_jobs

    rows, failed_at = {}, math.inf
    jobs = [(_sized_row, (module, func, n, timeout)) for n in sizes]
    for n, row in run_jobs(jobs, workers=1, desc=name, unit="size"):
        rows[n] = row
        if stop_at_error and "error" in row:
            failed_at = min(failed_at, n)
        section.csv(name, [rows[m] for m in sorted(rows) if m <= failed_at])
        if all(m in rows for m in sizes if m < failed_at) and failed_at < math.inf:
            break  # the sizes below the failed one are in: stop the others
    return [rows[m] for m in sorted(rows) if m <= failed_at]


def emit(record: dict) -> None:
    """A worker's result: one JSON line on stdout."""
    print(json.dumps(record))


def package_version(package: str) -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(package)
    except PackageNotFoundError:
        return "(not installed)"


def available(package: str) -> bool:
    """Whether ``package`` (an optional peer) is importable."""
    import importlib.util

    return importlib.util.find_spec(package) is not None


def children_cpu_seconds() -> float:
    """CPU time (user + system, s) of this process's children that have ended and been waited for, their own
    waited-for children included: the operating system's account, as ``/usr/bin/time`` reports a whole command."""
    import resource

    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def whole_processes(fns: dict, rounds: int, warmup: int = 1) -> tuple[dict, dict]:
    """Call every ``fns[name]()`` -- each runs one whole process and waits for it -- once per round, in turn, after
    ``warmup`` rounds that are not counted; returns ``{name: {"wall": [s per round], "cpu": [s per round]}}`` (wall
    clock; CPU time of the processes waited for, :func:`children_cpu_seconds`) and each one's last return value."""
    times = {name: {"wall": [], "cpu": []} for name in fns}
    values = {}
    for k in range(warmup + rounds):
        for name, fn in fns.items():
            cpu0, t0 = children_cpu_seconds(), time.perf_counter()
            values[name] = fn()
            wall, cpu = time.perf_counter() - t0, children_cpu_seconds() - cpu0
            if k >= warmup:
                times[name]["wall"].append(wall)
                times[name]["cpu"].append(cpu)
    return times, values


def paired_ratio(a, b) -> float:
    """Median of the round-by-round ratios ``a[k] / b[k]`` (two commands timed in turn, :func:`whole_processes`):
    the pairing keeps the ratio meaningful when the machine's speed drifts between rounds."""
    return float(np.median(np.asarray(a, float) / np.asarray(b, float)))
