"""Cost of the Luding 2005 contact kernels (:mod:`dem.laws.luding`): compile time and nanoseconds per contact.

``python -m verification.bench_contact [--n N] [--repeat R] [--json]`` measures

* the compile time of every kernel (its first calls in a fresh process, after the import), then of a compiled loop
  calling them (what an engine's loop adds): cold, with an empty cache (``NUMBA_CACHE_DIR`` pointed at a new
  folder), and cached, in a second process on that folder;
* the cost of the combined normal + tangential kernels (:func:`~dem.laws.luding.normal_force` then
  :func:`~dem.laws.luding.tangential_force`, force and history written back to arrays) in a compiled loop over
  N random contacts (default 10^6) that visit every branch: loading, un/reloading, tension, fluid, heating and
  cooling, sticking and sliding. Best of R warm repeats, in ns per contact.

It also offers ``run(out_dir, quick)`` with the section contract of :mod:`verification.report`.
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np
from numba import njit

from dem.laws import luding, luding_kernels as law

FIRST_CALLS = """
import time
t = time.perf_counter()
from dem.laws import luding, luding_kernels as law
imported = time.perf_counter()
p = luding.LUDING_TABLE1.params()
law.radius_at(1e-3, 80.0, 120.0, 1e-4)
law.relax_k1(law.k1_factor(130.0, 120.0, 10.0), 0.5, 1e-3, 1e3, False)
law.delta_0(1e-4, 1.0, 2e-4, p), law.delta_min(1e-4, 1.0, 2e-4, p), law.f_min(1e-4, 1.0, 2e-4, p)
law.kc_of(1e-4, 1.0, 2e-4, p), law.delta_max_fluid(2e-4, p)
f = law.normal_force(1e-5, 0.0, 0.9, 2e-5, 1.0, 2e-4, p)
z = (0.0, 0.0, 1.0)
vt, ddot = law.relative_velocity((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 1e-3, 1e-3, z)
law.tangential_force((0.0, 0.0, 0.0), z, vt, f[0], f[2], f[3], 0.9, 1e-7, p, False)
kernels = time.perf_counter()
import numpy as np
from verification.bench_contact import contact_loop, random_contacts
args = (*random_contacts(10).values(), 1e-7, p, np.empty((10, 3)), np.empty((10, 3)), np.empty(10))
loaded = time.perf_counter()
contact_loop(*args)
print(imported - t, kernels - imported, time.perf_counter() - loaded)
"""


def compile_seconds() -> dict:
    """Seconds of the first calls of every kernel, cold (empty cache) and cached (second process); of the import of
    :mod:`dem.laws.luding` (numpy, numba) before them; of the first call of :func:`contact_loop` after them."""
    repo = pathlib.Path(__file__).resolve().parents[1]
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache, "PYTHONPATH": str(repo)}
        out = {}
        for key in ("cold", "cached"):
            proc = subprocess.run([sys.executable, "-c", FIRST_CALLS], env=env, capture_output=True, text=True,
                                  check=True)
            seconds_import, seconds_calls, seconds_loop = (float(x) for x in proc.stdout.split())
            out[key] = seconds_calls
            out[f"import_{key}"] = seconds_import
            out[f"loop_{key}"] = seconds_loop
    return out


def random_contacts(n: int, seed: int = 0) -> dict:
    """N equal-pair contacts (a = 1 mm) with histories, factors, normals, springs and velocities that visit every
    branch of the law."""
    rng = np.random.default_rng(seed)
    delta_max = rng.uniform(0.0, 6e-4, n)
    s = rng.uniform(0.2, 1.0, n)
    normal = rng.normal(size=(n, 3))
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    vt = rng.normal(0.0, 1e-2, (n, 3))
    vt -= np.sum(vt * normal, axis=1)[:, None] * normal
    return {"delta": delta_max * rng.uniform(0.0, 1.3, n), "delta_dot": rng.normal(0.0, 1e-3, n), "s": s,
            "delta_max": delta_max, "s_last": np.clip(s * rng.choice([0.99, 1.0, 1.01], n), 0.0, 1.0),
            "delta_fluid": np.full(n, 2e-4), "xi": rng.normal(0.0, 1e-6, (n, 3)), "normal": normal, "vt": vt}


@njit(cache=True, error_model="numpy")
def contact_loop(delta, delta_dot, s, delta_max, s_last, delta_fluid, xi, normal, vt, dt, params, force, xi_out,
                 delta_max_out):
    """Normal + tangential force of every contact (force on i, new spring, new delta_max) into the out arrays."""
    for c in range(delta.shape[0]):
        f, dm, fmin, k2m, kcm, d0 = law.normal_force(delta[c], delta_dot[c], s[c], delta_max[c], s_last[c],
                                                     delta_fluid[c], params)
        n = (normal[c, 0], normal[c, 1], normal[c, 2])
        ft, xi_new, sliding, f = law.tangential_force((xi[c, 0], xi[c, 1], xi[c, 2]), n,
                                                      (vt[c, 0], vt[c, 1], vt[c, 2]), f, fmin, k2m, s[c], dt,
                                                      params, False)
        for k in range(3):
            force[c, k] = f * n[k] + ft[k]
            xi_out[c, k] = xi_new[k]
        delta_max_out[c] = dm


def ns_per_contact(n: int = 10**6, repeat: int = 5) -> dict:
    data = random_contacts(n)
    params = luding.LUDING_TABLE1.params()
    force, xi_out, dm_out = np.empty((n, 3)), np.empty((n, 3)), np.empty(n)
    args = (*data.values(), 1e-7, params, force, xi_out, dm_out)
    contact_loop(*args)  # compile or load from the cache
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        contact_loop(*args)
        times.append(time.perf_counter() - t)
    return {"contacts": n, "ns_per_contact_best": 1e9 * min(times) / n,
            "ns_per_contact_median": 1e9 * float(np.median(times)) / n}


def measure(n: int = 10**6, repeat: int = 5) -> dict:
    return {"compile_seconds": compile_seconds(), **ns_per_contact(n, repeat), "cores": os.cpu_count(),
            "load_average": os.getloadavg()[0]}


def run(out_dir: pathlib.Path, quick: bool = False) -> dict:
    """Section contract of :mod:`verification.report`."""
    result = measure(10**5 if quick else 10**6)
    pathlib.Path(out_dir).mkdir(parents=True, exist_ok=True)
    c = result["compile_seconds"]
    text = (f"Luding 2005 kernels: compile {c['cold']:.2f} s cold, {c['cached']:.2f} s from the cache; normal + "
            f"tangential force {result['ns_per_contact_best']:.0f} ns per contact (best of 5 over "
            f"{result['contacts']} random contacts; median {result['ns_per_contact_median']:.0f} ns).")
    return {"title": "Contact kernels (Luding 2005)", "markdown": text, "summary": {"luding_kernels": result},
            "figures": []}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m verification.bench_contact", description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=10**6, help="random contacts (default 10^6)")
    parser.add_argument("--repeat", type=int, default=5, help="warm repeats (default 5)")
    parser.add_argument("--json", action="store_true", help="print one JSON object on stdout, nothing else")
    args = parser.parse_args(argv)
    if args.n < 1 or args.repeat < 1:
        parser.error(f"--n = {args.n}, --repeat = {args.repeat}: must be >= 1")
    result = measure(args.n, args.repeat)
    print(json.dumps(result) if args.json else "\n".join(f"{k}: {v}" for k, v in result.items()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
