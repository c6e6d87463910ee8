"""Numerical stability stress tests (issue 6, section 3): ``python -m verification stability``.

Each stress case runs one scenario at the edge of the models' range and records ``name``, ``outcome`` (what
happened, one line) and ``passed``. A case passes when the code either answers correctly (to its stated accuracy,
or against a closed form) or refuses with a clear ``ValueError``/one-line CLI error -- never a silent NaN, a blow-up,
a hang or a traceback. An unexpected exception is a failed case, recorded with its type and message.

Groups: neck geometry (a/r from 1e-4 to the model's limit, radius ratios to 100, bad input); explicit time steps at
0.5x/0.99x/1.01x/2x the stable limit; extreme networks (conductance contrast 1e8, isolated particles, disconnected
clusters with and without fixed temperatures, 10^6 bonds with duplicates); FE degenerate geometries; and CLI abuse
of ``python -m dem`` / ``python -m fem_neck`` in subprocesses (exit 2 with one line, no NaN, no hang).
The property-based (hypothesis) tests over random scenes live in ``tests/test_stability_properties.py``.
"""

from __future__ import annotations

import json
import math
import pathlib
import subprocess
import sys
import tempfile
import time
from dataclasses import asdict, dataclass

import numpy as np

from fem_neck.geometry import max_overlap, neck_geometry, neck_radius, overlap_for_neck
from verification.bench import Report, md_table


@dataclass
class StressCase:
    name: str
    outcome: str
    passed: bool
    seconds: float = 0.0


def run_case(name: str, fn) -> StressCase:
    """Run ``fn() -> (passed, outcome)``; an exception escaping ``fn`` is a failure naming the exception."""
    t0 = time.perf_counter()
    try:
        passed, outcome = fn()
    except Exception as exc:  # the point of a stress test: record, don't crash the suite
        passed, outcome = False, f"unexpected {type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}"
    return StressCase(name, outcome, bool(passed), time.perf_counter() - t0)


def expect_value_error(fn, *needles) -> tuple[bool, str]:
    """Pass when ``fn()`` raises ``ValueError`` whose message contains every needle (case-insensitive)."""
    try:
        value = fn()
    except ValueError as exc:
        msg = str(exc)
        ok = all(n.lower() in msg.lower() for n in needles) and "\n" not in msg.strip()
        return ok, f"ValueError: {msg}" + ("" if ok else f" (expected mention of {needles})")
    return False, f"accepted, returned {value!r:.80}"


# --------------------------------------------------------------------------------------------------------------
# Neck geometry
# --------------------------------------------------------------------------------------------------------------
def geometry_cases() -> list[StressCase]:
    cases = []

    def roundtrip(ratio):
        def fn():
            r_i = 1e-3
            r_j = ratio * r_i
            a = r_i * np.concatenate([np.logspace(-4, 0, 81)[:-1], [1.0 - 1e-12, 1.0]])
            h = overlap_for_neck(r_i, r_j, a)
            geo = neck_geometry(r_i, r_j, h)
            err = np.abs(geo.a - a) / a
            ok = (np.all(np.isfinite(geo.a)) and err.max() < 1e-9 and geo.volume_residual.max() < 1e-12
                  and np.all(geo.a <= min(r_i, r_j)))
            return ok, (f"a/r_i 1e-4..1 ({a.size} necks): max rel error of a {err.max():.1e}, "
                        f"max volume residual {geo.volume_residual.max():.1e}, iterations {geo.iterations}")
        return fn

    for ratio in (1.0, 10.0, 100.0):
        cases.append(run_case(f"neck a/r 1e-4 to limit, r_j/r_i = {ratio:g}", roundtrip(ratio)))

    def beyond_limit():
        h_max = max_overlap(1e-3, 3e-3)
        return expect_value_error(lambda: neck_radius(1e-3, 3e-3, h_max * (1 + 1e-9)), "h")

    cases.append(run_case("neck h just beyond the model's range", beyond_limit))
    for label, args, needle in [
        ("neck NaN radius", (float("nan"), 1e-3, 1e-5), "r_i"),
        ("neck negative radius", (1e-3, -1e-3, 1e-5), "r_j"),
        ("neck zero overlap", (1e-3, 1e-3, 0.0), "h"),
        ("neck infinite overlap", (1e-3, 1e-3, float("inf")), "h"),
        ("neck one bad bond among 10^5", (np.full(100_000, 1e-3), np.full(100_000, 1e-3),
                                          np.r_[np.full(99_999, 1e-5), -1.0]), "h[99999]"),
    ]:
        cases.append(run_case(label, lambda args=args, needle=needle: expect_value_error(
            lambda: neck_radius(*args), needle)))
    return cases


# --------------------------------------------------------------------------------------------------------------
# FE degenerate geometries
# --------------------------------------------------------------------------------------------------------------
def _fe_outcome(res, rtol) -> tuple[bool, str]:
    ok = bool(res.converged and np.isfinite(res.K) and res.error_estimate <= rtol)
    return ok, (f"K/K_cyl = {res.K_over_Kcyl:.8g}, estimate {res.error_estimate:.1e} (rtol {rtol:g}), "
                f"converged {res.converged}, {res.dofs} dofs, {res.seconds:.2f} s")


def _solve_or_refuse(fn, check=None, rtol: float = 1e-4) -> tuple[bool, str]:
    """Pass when ``fn()`` returns a converged result (and ``check(res)`` holds) or raises a ValueError that
    explains itself; a bare gmsh error or any other exception fails."""
    try:
        res = fn()
    except ValueError as exc:
        return True, f"refused: {exc}"
    except RuntimeError as exc:
        msg = str(exc)
        explained = "gmsh" in msg and not msg.rstrip().endswith(("Could not create line", "Could not create arc"))
        return explained, f"{type(exc).__name__}: {msg}" + ("" if explained else " (not explained: why, what range)")
    ok, text = _fe_outcome(res, rtol)
    if check is not None and ok:
        ok, extra = check(res)
        text += f"; {extra}"
    return ok, text


def fe_cases(quick: bool) -> list[StressCase]:
    from fem_neck import conduction

    cases = []
    cases.append(run_case("FE semisphere neck below the supported range, a/r = 5e-5", lambda: expect_value_error(
        lambda: conduction.semisphere_conductance(5e-5, rtol=1e-4), "a_over_r")))
    small = (1e-4, 3e-4) if quick else (1e-4, 3e-4, 1e-3)
    for a in small:
        def near_constriction(res, a=a):
            ratio = res.K_over_Kcyl / (4 * a / math.pi)  # K -> 4 kappa a (isothermal disk on a half-space)
            return abs(ratio - 1) < 0.01, f"K / (4 kappa a) = {ratio:.5f}"
        cases.append(run_case(f"FE semisphere tiny neck a/r = {a:g}", lambda a=a, c=near_constriction:
                              _solve_or_refuse(lambda: conduction.semisphere_conductance(a, rtol=1e-4), c)))
    for a in (0.999, 0.999999):
        def towards_cylinder(res):  # a = r: the body is a cylinder of height 2r/3, K/K_cyl = 1.5 exactly
            return 1.3646 < res.K_over_Kcyl <= 1.5 * (1 + 1e-4), "between K(a/r=0.97) and the a = r limit 1.5"
        cases.append(run_case(f"FE semisphere a -> r, a/r = {a}", lambda a=a, c=towards_cylinder:
                              _solve_or_refuse(lambda: conduction.semisphere_conductance(a, rtol=1e-4), c)))
    cases.append(run_case("FE semisphere a/r = 1 exactly", lambda: _solve_or_refuse(
        lambda: conduction.semisphere_conductance(1.0, rtol=1e-4),
        lambda res: (abs(res.K_over_Kcyl - 1.5) < 1e-4, "closed form 1.5"))))
    r_i, r_j = 1e-3, 3e-3
    h_max = float(max_overlap(r_i, r_j))
    for frac in (1 - 1e-6, 1.0):
        def near_ri(res):
            a = res.necks[0]
            return a / r_i > 0.99, f"a/r_i = {a / r_i:.6f}"
        cases.append(run_case(f"FE unequal pair a ~ r_i (h = {frac:.7g} h_max, r_j/r_i = 3)",
                              lambda frac=frac, c=near_ri: _solve_or_refuse(
                                  lambda: conduction.pair_conductance(r_i, r_j, frac * h_max, 394.0, rtol=1e-4), c)))
    cases.append(run_case("FE pair h/r -> 0 (h = 1e-12 r)", lambda: _solve_or_refuse(
        lambda: conduction.pair_conductance(1e-3, 1e-3, 1e-15, 394.0, rtol=1e-4))))
    cases.append(run_case("FE pair radius ratio 100", lambda: _solve_or_refuse(
        lambda: conduction.pair_conductance(1e-5, 1e-3, 0.5 * float(max_overlap(1e-5, 1e-3)), 394.0, rtol=1e-3),
        rtol=1e-3)))
    return cases


# --------------------------------------------------------------------------------------------------------------
# DEM: explicit step limit and extreme networks
# --------------------------------------------------------------------------------------------------------------
def _network(particles, K=None, pairs=None):
    from dem.bonds import find_bonds
    from dem.laws.conductance import ConductanceSpec, bond_conductances
    from dem.thermal import Network

    bonds = find_bonds(particles, pairs=pairs)
    k_pairs, k_walls = bond_conductances(ConductanceSpec("rojek"), particles, bonds)
    return Network(particles, bonds, k_pairs if K is None else K(k_pairs), k_walls, np.zeros(0))


def _lattice(shape, spacing=1e-4, seed=0, temperature=None, fixed=None, keep=None):
    """Particles on a cubic lattice, radii 0.52-0.6 spacing (every neighbour bonded, in the neck model's range)."""
    from dem.particles import Particles

    rng = np.random.default_rng(seed)
    grid = np.stack(np.meshgrid(*[np.arange(k) for k in shape], indexing="ij"), -1).reshape(-1, 3) * spacing
    if keep is not None:
        grid = grid[keep(grid / spacing)]
    n = len(grid)
    radius = spacing * rng.uniform(0.52, 0.6, n)
    temp = rng.uniform(0.0, 100.0, n) if temperature is None else temperature(grid / spacing)
    fix = None if fixed is None else fixed(grid / spacing)
    return Particles.from_arrays(grid, radius, temp, fixed=fix)


def dem_cases(quick: bool) -> list[StressCase]:
    from dem.thermal import integrate, stable_limit, steady

    cases = []
    net = _network(_lattice((8, 8, 6), seed=1))
    limit = stable_limit(net)
    C = net.particles.capacity

    for factor in (0.5, 0.99, 1.01, 2.0):
        def explicit(factor=factor):
            norms = []

            def observer(step, t, T, flows):
                dev = T - (C @ T) / C.sum()
                norms.append(float(np.sqrt(C @ dev**2)))

            try:
                res = integrate(net, "explicit", dt=factor * limit, t_end=300 * limit, observer=observer)
            except ValueError as exc:
                ok = factor > 1 and "limit" in str(exc)
                return ok, f"refused: {str(exc)[:160]}"
            growth = max(np.diff(norms).max() / norms[0], 0.0)
            ok = factor <= 1 and np.all(np.isfinite(res.T)) and growth <= 1e-12
            return ok, (f"ran {res.steps} steps: C-norm of the deviation {norms[0]:.3g} -> {norms[-1]:.3g}, "
                        f"largest growth per step {growth:.1e}, T in [{res.T.min():.3g}, {res.T.max():.3g}]"
                        + ("" if factor <= 1 else " -- ran above the limit: silent blow-up risk"))
        cases.append(run_case(f"DEM explicit dt = {factor} x stable limit ({limit:.3g} s)", explicit))

    def explicit_auto():
        res = integrate(net, "explicit", dt="auto", t_end=300 * limit)
        T0 = net.particles.temperature
        ok = bool(np.all(np.isfinite(res.T)) and res.dt_max <= limit and res.T.min() >= T0.min() - 1e-9
                  and res.T.max() <= T0.max() + 1e-9)
        return ok, f"{res.steps} steps, dt_max = {res.dt_max / limit:.3f} x limit, T in [{res.T.min():.4g}, " \
                   f"{res.T.max():.4g}] (initial [{T0.min():.4g}, {T0.max():.4g}])"
    cases.append(run_case("DEM explicit dt = auto stays below the limit", explicit_auto))

    def contrast(n_shape, label):
        def fn():
            import scipy.sparse.linalg as spl

            particles = _lattice(n_shape, seed=2, temperature=lambda g: np.where(g[:, 2] == 0, 100.0, 0.0),
                                 fixed=lambda g: (g[:, 2] == 0) | (g[:, 2] == g[:, 2].max()))
            rng = np.random.default_rng(3)
            net2 = _network(particles, K=lambda k: k * 10.0 ** (8.0 * rng.random(len(k))))
            res = steady(net2)
            A, b = net2.matrix({}), net2.rhs({})
            x = res.T[net2.free]
            if particles.n <= 20_000:  # independent direct solve
                err = float(np.max(np.abs(x - spl.spsolve(A.tocsc(), b))))
                check = f"max |T - T_spsolve| = {err:.2e} K"
            else:  # too large for a direct reference: the residual, scaled by the diagonal
                err = float(np.max(np.abs(A @ x - b) / A.diagonal()))
                check = f"max |A T - r| / A_ii = {err:.2e} K"
            inside = res.T.min() >= -1e-9 and res.T.max() <= 100 + 1e-9
            ok = err <= 1e-6 * 100 and inside
            return ok, (f"{particles.n} particles, K spread {net2.K_pairs.max() / net2.K_pairs.min():.2g}, "
                        f"solver {res.solver}: {check}, T in [{res.T.min():.4g}, {res.T.max():.4g}]")
        return run_case(f"DEM steady, conductance contrast 1e8 ({label})", fn)

    cases.append(contrast((10, 10, 10), "direct backend"))
    cases.append(contrast((40, 40, 20) if quick else (60, 60, 30), "iterative backend"))

    def two_materials():  # chain of 4, kappa contrast 1e8: series conductance to round-off
        from dem.particles import Material, Particles

        mats = (Material(394.0, 8960.0, 385.0, "copper"), Material(394e-8, 8960.0, 385.0, "insulator"))
        pos = np.array([[0, 0, 0], [0, 0, 1.9e-4], [0, 0, 3.8e-4], [0, 0, 5.7e-4]])
        particles = Particles.from_arrays(pos, np.full(4, 1e-4), [100.0, 0, 0, 0.0], materials=mats,
                                          material=[0, 1, 0, 0], fixed=[True, False, False, True])
        net2 = _network(particles)
        res = steady(net2)
        K = 1.0 / np.sum(1.0 / net2.K_pairs)
        q = res.flows["fixed"] if False else K * 100.0
        drop = 100.0 - np.cumsum(q / net2.K_pairs)[:-1]
        err = float(np.max(np.abs(res.T[1:3] - drop)) / 100.0)
        return err < 1e-9, f"K contrast {net2.K_pairs.max() / net2.K_pairs.min():.2g}: max relative error of the " \
                           f"free temperatures against the series solution {err:.1e}"
    cases.append(run_case("DEM steady chain, conductivity contrast 1e8 vs series closed form", two_materials))

    def isolated():
        from dem.particles import Particles

        block = _lattice((3, 3, 3), seed=4)
        lone_pos = np.array([[1e-2, 0, 0], [2e-2, 0, 0], [3e-2, 0, 0]])
        particles = Particles.from_arrays(np.vstack([block.position, lone_pos]), np.r_[block.radius, [5e-5] * 3],
                                          np.r_[block.temperature, [500.0, -20.0, 7.0]])
        net2 = _network(particles)
        T0 = particles.temperature
        out = []
        for integ in ("explicit", "implicit", "crank-nicolson"):
            res = integrate(net2, integ, dt="auto", t_end=1e-2)
            kept = np.allclose(res.T[-3:], T0[-3:], rtol=4 * np.finfo(float).eps, atol=0.0)
            out.append((integ, bool(kept), res.energy_error))
        ok = all(kept and e < 1e-10 for _, kept, e in out)
        return ok, "3 particles without bonds: " + "; ".join(
            f"{k}: temperature unchanged (to round-off) {kept}, energy error {e:.0e}" for k, kept, e in out)
    cases.append(run_case("DEM particles with no bonds (transient)", isolated))

    def clusters(with_fixed):
        def fn():
            keep = lambda g: g[:, 0] != 3  # noqa: E731  two blocks of 3 x 3 x 3, no bond between them
            if with_fixed:
                fixed = lambda g: (g[:, 2] == 0) | (g[:, 2] == 2)  # noqa: E731
            else:
                fixed = lambda g: ((g[:, 2] == 0) | (g[:, 2] == 2)) & (g[:, 0] < 3)  # noqa: E731
            temperature = lambda g: np.where(g[:, 2] == 0, 10.0, 0.0) + np.where(g[:, 0] > 3, 50.0, 0.0)  # noqa
            particles = _lattice((7, 3, 3), keep=keep, seed=5, temperature=temperature, fixed=fixed)
            net2 = _network(particles)
            try:
                res = steady(net2)
            except ValueError as exc:
                msg = str(exc)
                ok = (not with_fixed) and "singular" in msg and "connected group" in msg
                return ok, f"refused: {msg[:170]}"
            right = particles.position[:, 0] > 3.5e-4
            ok = with_fixed and res.T[right].min() >= 50 - 1e-9 and res.T[~right].max() <= 10 + 1e-9
            return ok, f"solved: left block T in [{res.T[~right].min():.3g}, {res.T[~right].max():.3g}], right " \
                       f"block in [{res.T[right].min():.3g}, {res.T[right].max():.3g}]"
        return fn
    cases.append(run_case("DEM disconnected clusters, each with fixed temperatures (steady)", clusters(True)))
    cases.append(run_case("DEM disconnected clusters, one without fixed temperature (steady)", clusters(False)))

    def steady_energy_error():
        particles = _lattice((4, 4, 6), seed=6, temperature=lambda g: np.where(g[:, 2] == 0, 1.0, 0.0),
                             fixed=lambda g: (g[:, 2] == 0) | (g[:, 2] == 5))
        res = steady(_network(particles))
        return res.energy_error < 1e-8, (f"hot/cold fixed layers: energy_error = {res.energy_error:.3g}, flows "
                                         f"{ {k: float(f'{v:.3g}') for k, v in res.flows.items()} }")
    cases.append(run_case("DEM steady energy_error with hot and cold fixed layers", steady_energy_error))

    def duplicates():
        shape = (30, 30, 30) if quick else (64, 64, 64)
        particles = _lattice(shape, seed=7, temperature=lambda g: np.where(g[:, 2] == 0, 1.0, 0.0),
                             fixed=lambda g: (g[:, 2] == 0) | (g[:, 2] == g[:, 2].max()))
        base = _network(particles)
        i, j = base.bonds.i, base.bonds.j
        rng = np.random.default_rng(8)
        extra = rng.integers(0, len(i), len(i) // 2)
        ii = np.concatenate([i, j, i[extra]])  # every bond, every bond reversed, half again
        jj = np.concatenate([j, i, j[extra]])
        t0 = time.perf_counter()
        dup = _network(particles, pairs=(ii, jj))
        secs = time.perf_counter() - t0
        same = dup.bonds.n_pairs == base.bonds.n_pairs
        dT = float(np.max(np.abs(steady(dup).T - steady(base).T)))
        return same and dT < 1e-9, (f"{len(ii):,} listed bonds ({len(i):,} unique) -> {dup.bonds.n_pairs:,} bonds in "
                                    f"{secs:.1f} s; steady T differs by {dT:.1e}")
    cases.append(run_case(f"DEM {'2e5' if quick else '1e6+'} bonds with duplicates and reversed pairs",
                          duplicates))

    def ratio_100():
        from dem.particles import Particles

        r_i, r_j = 1e-5, 1e-3
        h = 0.3 * float(max_overlap(r_i, r_j))
        particles = Particles.from_arrays([[0, 0, 0], [0, 0, r_i + r_j - h]], [r_i, r_j], [100.0, 0.0])
        net2 = _network(particles)
        Cp = particles.capacity
        rate = net2.K_pairs[0] * (1 / Cp[0] + 1 / Cp[1])
        t_end = 3.0 / rate
        out = []
        for integ in ("explicit", "implicit", "crank-nicolson"):
            res = integrate(net2, integ, dt="auto", t_end=t_end)
            diff = (res.T[0] - res.T[1]) / 100.0
            out.append((integ, abs(diff - np.exp(-rate * t_end)), res.energy_error, res.steps))
        ok = all(e < 2e-2 and ee < 1e-10 for _, e, ee, _ in out)
        return ok, "; ".join(f"{k}: |dT/dT0 - exp| = {e:.1e}, energy {ee:.0e}, {s} steps" for k, e, ee, s in out)
    cases.append(run_case("DEM pair, radius ratio 100, dt = auto, decay vs closed form", ratio_100))
    return cases


# --------------------------------------------------------------------------------------------------------------
# CLI abuse
# --------------------------------------------------------------------------------------------------------------
def cli_case(name: str, argv: list[str], expect: str = "error", timeout: float = 120.0, cwd=None) -> StressCase:
    """Run ``python -m <argv>``; ``expect`` is ``"error"`` (exit 2, one line on stderr), ``"ok"`` (exit 0, finite
    JSON when ``--json``) or ``"either"``. Never: a traceback, NaN/Infinity in the output, a hang (``timeout``)."""

    def fn():
        try:
            proc = subprocess.run([sys.executable, "-m", *argv], capture_output=True, text=True, timeout=timeout,
                                  cwd=cwd)
        except subprocess.TimeoutExpired:
            return False, f"hang: no exit within {timeout:g} s"
        err_lines = [ln for ln in proc.stderr.splitlines() if ln.strip() and not _is_progress(ln)]
        if "Traceback" in proc.stderr:
            return False, f"exit {proc.returncode} with a traceback: {err_lines[-1] if err_lines else ''}"[:300]
        has_nan = any(tok in proc.stdout for tok in ("NaN", "nan,", "Infinity", " inf"))
        if proc.returncode == 2:
            one = len(err_lines) == 1
            ok = expect in ("error", "either") and one
            msg = err_lines[0] if err_lines else "(empty stderr)"
            return ok, f"exit 2: {msg}"[:300] + ("" if one else f" (+{len(err_lines) - 1} more stderr lines)")
        if proc.returncode == 0:
            if has_nan:
                return False, "exit 0 but NaN/Infinity in the output"
            if "--json" in argv:
                try:
                    json.loads(proc.stdout)
                except json.JSONDecodeError:
                    return False, "exit 0 but stdout is not one JSON object"
            return expect in ("ok", "either"), f"exit 0: {proc.stdout.strip()[:200]}"
        return False, f"exit {proc.returncode}: {(err_lines[-1] if err_lines else proc.stdout.strip())[:250]}"

    return run_case(name, fn)


def _is_progress(line: str) -> bool:
    return "it/s]" in line or "s/it]" in line or "%|" in line


def fem_neck_cli_cases() -> list[StressCase]:
    m = ["fem_neck"]
    specs = [
        ("neck: NaN radius", ["neck", "--ri", "nan", "--rj", "1e-3", "--h", "1e-5", "--json"], "error"),
        ("neck: negative radius", ["neck", "--ri", "-1e-3", "--rj", "1e-3", "--h", "1e-5", "--json"], "error"),
        ("neck: text radius", ["neck", "--ri", "abc", "--rj", "1e-3", "--h", "1e-5"], "error"),
        ("neck: overlap beyond range", ["neck", "--ri", "1e-3", "--rj", "1e-3", "--h", "1e-3", "--json"], "error"),
        ("neck: missing option", ["neck", "--ri", "1e-3"], "error"),
        ("neck: unknown method", ["neck", "--ri", "1", "--rj", "1", "--h", "0.1", "--method", "x"], "error"),
        ("neck: radius ratio 1e6", ["neck", "--ri", "1e-9", "--rj", "1e-3", "--h", "1e-10", "--json"], "either"),
        ("neck: huge radii", ["neck", "--ri", "1e300", "--rj", "1e300", "--h", "1e299", "--json"], "either"),
        ("semisphere: NaN", ["semisphere", "--h-over-r", "nan", "--json"], "error"),
        ("semisphere: negative", ["semisphere", "--h-over-r", "-0.1", "--json"], "error"),
        ("semisphere: beyond 2/3", ["semisphere", "--h-over-r", "0.7", "--json"], "error"),
        ("semisphere: rtol 0", ["semisphere", "--h-over-r", "0.1", "--rtol", "0", "--json"], "error"),
        ("semisphere: rtol negative", ["semisphere", "--h-over-r", "0.1", "--rtol", "-1", "--json"], "error"),
        ("semisphere: rtol 1e-14", ["semisphere", "--h-over-r", "0.1", "--rtol", "1e-14", "--json"], "either"),
        ("semisphere: rtol 10", ["semisphere", "--h-over-r", "0.1", "--rtol", "10", "--json"], "either"),
        ("semisphere: h/r 1e-9", ["semisphere", "--h-over-r", "1e-9", "--json"], "either"),
        ("pair: rj negative", ["pair", "--ri", "1e-3", "--rj", "-3e-3", "--h", "6e-5", "--kappa", "394",
                               "--json"], "error"),
        ("pair: kappa 0", ["pair", "--ri", "1e-3", "--rj", "3e-3", "--h", "6e-5", "--kappa", "0", "--json"],
         "error"),
        ("pair: h beyond range", ["pair", "--ri", "1e-3", "--rj", "3e-3", "--h", "1e-3", "--kappa", "394",
                                  "--json"], "error"),
        ("chain: lengths disagree", ["chain", "--radii", "1e-3,1e-3,1e-3", "--overlaps", "1e-4", "--kappa", "394",
                                     "--json"], "error"),
        ("chain: empty radii", ["chain", "--radii", "", "--overlaps", "", "--kappa", "394", "--json"], "error"),
        ("chain: garbage list", ["chain", "--radii", "1e-3,x", "--overlaps", "1e-4", "--kappa", "394"], "error"),
        ("neck: radii 1e600 apart (a sphere on a plane: answered, no overflow)",
         ["neck", "--ri", "1e-300", "--rj", "1e300", "--h", "1e-301", "--json"], "ok"),
        ("chain: 200 spheres (refused up front, not a 10-minute solve)",
         ["chain", "--radii", ",".join(["1e-3"] * 200), "--overlaps", ",".join(["1e-4"] * 199), "--kappa", "394",
          "--json"], "error"),
        ("fit: 10^12 points (refused before allocating)", ["fit", "--points", "1000000000000", "--json"], "error"),
        ("fit: zero points", ["fit", "--points", "0", "--json"], "error"),
        ("fit: negative points", ["fit", "--points", "-5", "--json"], "error"),
        ("unknown command", ["frobnicate"], "error"),
    ]
    afile = pathlib.Path(tempfile.gettempdir()) / "stability-out-is-a-file"
    afile.write_text("")
    cluster = pathlib.Path(tempfile.gettempdir()) / "stability-cluster.json"
    cluster.write_text(json.dumps({"centres": [[0, 0, 0], [0, 0, 1.92e-3]], "radii": [1e-3, 1e-3],
                                   "bonds": [[0.5, 1]], "terminals": [{"particle": 0, "T": 1.0},
                                                                      {"particle": 1, "T": 0.0}]}))
    specs.append(("cluster: fractional bond index", ["cluster", str(cluster), "--json"], "error"))
    specs.append(("cluster: --size-far 1e-300 (a mesh that never ends)", ["cluster", str(cluster), "--size-far",
                                                                          "1e-300", "--json"], "error"))
    specs.append(("semisphere: --out is an existing file", ["semisphere", "--h-over-r", "0.2", "--out", str(afile),
                                                           "--json"], "error"))
    return [cli_case(f"fem_neck CLI {name}", m + argv, expect) for name, argv, expect in specs]


SCENE_OK = """
[material]
conductivity = 394.0
density = 8960.0
specific_heat = 385.0
[particles]
position = [[0.0, 0.0, 0.0], [0.0, 0.0, 3.94e-3]]
radius = [1.0e-3, 3.0e-3]
temperature = [100.0, 0.0]
[conductance]
law = "rojek"
[solver]
mode = "transient"
integrator = "{integrator}"
dt = {dt}
t_end = {t_end}
"""


def dem_cli_cases(scene_dir: pathlib.Path) -> list[StressCase]:
    """Bad scenes for ``python -m dem run``; each is written to ``scene_dir`` first."""
    scene_dir.mkdir(parents=True, exist_ok=True)
    base = SCENE_OK.format(integrator="implicit", dt="1.0e-3", t_end="0.01")
    bad = {
        "malformed TOML": base.replace("radius = [", "radius = [[", 1),
        "unknown key": base.replace("[conductance]", "[conductance]\nfoo = 1"),
        "unknown section": base + "\n[bogus]\nx = 1\n",
        "missing conductivity": base.replace("conductivity = 394.0\n", ""),
        "negative radius": base.replace("radius = [1.0e-3", "radius = [-1.0e-3"),
        "NaN radius": base.replace("radius = [1.0e-3", "radius = [nan"),
        "NaN temperature": base.replace("temperature = [100.0", "temperature = [nan"),
        "inf temperature": base.replace("temperature = [100.0", "temperature = [inf"),
        "lengths disagree": base.replace("radius = [1.0e-3, 3.0e-3]", "radius = [1.0e-3]"),
        "empty particle list": base.replace("position = [[0.0, 0.0, 0.0], [0.0, 0.0, 3.94e-3]]", "position = []")
        .replace("radius = [1.0e-3, 3.0e-3]", "radius = []").replace("temperature = [100.0, 0.0]", "temperature = []"),
        "position not 3D": base.replace("[0.0, 0.0, 3.94e-3]]", "[0.0, 3.94e-3]]"),
        "overlap beyond neck range": base.replace("3.94e-3]]", "2.1e-3]]"),
        "coincident particles": base.replace("3.94e-3]]", "0.0]]"),
        "negative dt": base.replace("dt = 1.0e-3", "dt = -1.0e-3"),
        "zero dt": base.replace("dt = 1.0e-3", "dt = 0.0"),
        "dt as text": base.replace("dt = 1.0e-3", 'dt = "fast"'),
        "negative t_end": base.replace("t_end = 0.01", "t_end = -1.0"),
        "unknown integrator": base.replace('integrator = "implicit"', 'integrator = "rk4"'),
        "unknown law": base.replace('law = "rojek"', 'law = "magic"'),
        "unknown mode": base.replace('mode = "transient"', 'mode = "quasi"'),
        "negative density": base.replace("density = 8960.0", "density = -8960.0"),
        "explicit dt 1e3x the limit": SCENE_OK.format(integrator="explicit", dt="1.0", t_end="10.0"),
        "steady without fixed temperature": base.replace('mode = "transient"', 'mode = "steady"'),
    }
    gen = base.split("[particles]")[0] + """[generator]
kind = "random"
n = {n}
radius = 5.0e-5
overlap = {overlap}
seed = 1
boundary = "plates"
hot = 1.0
cold = 0.0
[conductance]
law = "rojek"
[solver]
mode = "steady"
floating = "mean"
"""
    bad.update({
        "generator n = 0": gen.format(n=0, overlap=0.1),
        "generator n = 1e12": gen.format(n="1000000000000", overlap=0.1),
        "generator n = 2.5": gen.format(n=2.5, overlap=0.1),
        "generator overlap 0.7 (beyond 2/3)": gen.format(n=100, overlap=0.7),
        "generator overlap negative": gen.format(n=100, overlap=-0.1),
        "chain generator overlap 5 (was: no bonds)": gen.format(n=3, overlap=5.0).replace('"random"', '"chain"')
        .replace("seed = 1\n", ""),
        "lattice shape overflowing int64": gen.replace('kind = "random"\nn = {n}', 'kind = "lattice"\nshape = '
                                                       '[9223372036854775807, 2, 2]').replace("seed = 1\n", "")
        .format(overlap=0.1),
        "radiation negative emissivity": base + "\n[radiation]\nemissivity = -0.5\nT_inf = 20.0\n",
        "convection NaN h": base + "\n[convection]\nh = nan\nT_inf = 20.0\n",
        "duplicate key": base.replace("t_end = 0.01", "t_end = 0.01\nt_end = 0.02"),
        "binary garbage": "\x00\x01\x02 = [[[",
        "radiation with a temperature below absolute zero": base.replace("temperature = [100.0", "temperature = [-400.0")
        + '\n[radiation]\nemissivity = 0.5\nT_inf = 20.0\nunit = "C"\n',
        "radiation ambient at 1e80 K (was NaN)": base.replace('mode = "transient"', 'mode = "steady"')
        + "\n[radiation]\nemissivity = 1.0\nT_inf = 1e80\n",
        "text for a number (slope)": base.replace('law = "rojek"', 'law = "rojek"\nslope = "x"'),
        "conductivity 1e300": base.replace("conductivity = 394.0", "conductivity = 1e300"),
        "temperatures +-1e308": base.replace("temperature = [100.0, 0.0]", "temperature = [1e308, -1e308]"),
        "lens clip, coincident particles": base.replace("3.94e-3]]", "0.0]]").replace(
            'law = "rojek"', 'law = "zohdi"\nout_of_range = "clip"'),
        "lens clip, centre behind a wall": base.replace('law = "rojek"', 'law = "zohdi"\nout_of_range = "clip"')
        + "\n[[walls]]\npoint = [0.0, 0.0, 0.5e-3]\nnormal = [0.0, 0.0, 1.0]\ntemperature = 1.0\n",
        "rtol 1e-300 with dt auto": base.replace("dt = 1.0e-3", 'dt = "auto"\nrtol = 1e-300'),
        "1e6 fixed steps (default max_steps 1e5)": base.replace("dt = 1.0e-3", "dt = 1.0e-5").replace(
            "t_end = 0.01", "t_end = 10.0"),
    })
    long_run = {
        "generator single particle, steady": gen.format(n=1, overlap=0.1),
        "radiation, explicit auto": SCENE_OK.format(integrator="explicit", dt='"auto"', t_end="1.0")
        + "\n[radiation]\nemissivity = 1.0\nT_inf = 20.0\n".replace("[particles]", "[particles]"),
        "implicit auto, t_end 1e6 s": SCENE_OK.format(integrator="implicit", dt='"auto"', t_end="1.0e6"),
        # would take ~1e12 steps: must be refused or capped, never a hang
        "explicit t_end 1e9 s": SCENE_OK.format(integrator="explicit", dt="1.0e-6", t_end="1.0e9"),
        "lens clip, sphere inside a sphere": base.replace("3.94e-3]]", "1.0e-4]]").replace(
            "radius = [1.0e-3, 3.0e-3]", "radius = [1.0e-3, 1.0e-5]").replace(
            'law = "rojek"', 'law = "zohdi"\nout_of_range = "clip"'),
        "singular implicit step (capacities 1e-56 J/K, dt 1e6 s)": SCENE_OK.format(
            integrator="implicit", dt="1.0e6", t_end="1.0e6").replace("conductivity = 394.0", "conductivity = 1e10")
        .replace("density = 8960.0", "density = 1e-10").replace("specific_heat = 385.0", "specific_heat = 1e-10")
        .replace("[[0.0, 0.0, 0.0], [0.0, 0.0, 3.94e-3]]", "[[0.0, 0.0, 0.0], [0.0, 0.0, 1.9e-12]]")
        .replace("radius = [1.0e-3, 3.0e-3]", "radius = [1.0e-12, 1.0e-12]"),
    }
    cases = []
    for name, text in {**bad, **long_run}.items():
        path = scene_dir / (name.replace(" ", "_").replace("/", "_") + ".toml")
        path.write_text(text)
        expect = "error" if name in bad else "either"
        cases.append(cli_case(f"dem CLI {name}", ["dem", "run", str(path), "--json", "--out",
                                                  str(scene_dir / "out")], expect, timeout=60.0))
    cases.append(cli_case("dem CLI missing scene file", ["dem", "run", str(scene_dir / "nope.toml"), "--json"]))
    cases.append(cli_case("dem CLI scene is a directory", ["dem", "run", str(scene_dir), "--json"]))
    cases.append(cli_case("dem CLI no arguments", ["dem"]))
    cases.append(cli_case("dem CLI --out is an existing file", ["dem", "run", str(_write(scene_dir / "good.toml", base)),
                                                               "--json", "--out", str(_write(scene_dir / "afile",
                                                                                             ""))]))
    cases.append(cli_case("dem CLI good scene runs", ["dem", "run", str(_write(scene_dir / "good.toml", base)),
                                                      "--json", "--out", str(scene_dir / "out")], "ok"))
    return cases


def _write(path: pathlib.Path, text: str) -> pathlib.Path:
    path.write_text(text)
    return path


# --------------------------------------------------------------------------------------------------------------
def run(out_dir: pathlib.Path, quick: bool = False) -> dict:
    """Run every stress case; write ``stress_cases.csv``, ``stability.md``/``stability.json``; return the section."""
    report = Report(out_dir, "Numerical stability stress tests", "stability")
    all_cases: list[StressCase] = []
    groups = [
        ("Neck geometry", geometry_cases),
        ("FE degenerate geometries", lambda: fe_cases(quick)),
        ("DEM time steps and extreme networks", lambda: dem_cases(quick)),
        ("CLI abuse: python -m fem_neck", fem_neck_cli_cases),
        ("CLI abuse: python -m dem run", lambda: dem_cli_cases(pathlib.Path(out_dir) / "scenes")),
    ]
    for heading, make in groups:
        cases = make()
        all_cases += cases
        rows = [{"case": c.name, "passed": "yes" if c.passed else "**NO**", "outcome": c.outcome.replace("|", "/"),
                 "seconds": c.seconds} for c in cases]
        report.csv("stress_cases", [asdict(c) for c in all_cases])
        report.summary["stress_cases"] = [{"name": c.name, "outcome": c.outcome, "passed": c.passed}
                                          for c in all_cases]
        report.section(f"{heading}: {sum(c.passed for c in cases)}/{len(cases)} passed",
                       md_table(rows, ["case", "passed", "outcome", "seconds"], fmt="{:.2f}"))
    failed = [c.name for c in all_cases if not c.passed]
    report.summary["stress_passed"] = len(all_cases) - len(failed)
    report.summary["stress_failed"] = len(failed)
    report.sections.insert(0, f"{len(all_cases) - len(failed)} of {len(all_cases)} stress cases passed."
                              + (f" Failed: {', '.join(failed)}." if failed else "") + "\n")
    return report.result()
