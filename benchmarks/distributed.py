"""The steady network on several MPI ranks (:mod:`dem.engines.distributed`): strong scaling (one packing on 1 and 2
ranks) and weak scaling (the particles per rank kept: N on 1 rank, 2N on 2), with the setup and solve times, the
AMG's iterations and the memory of every rank, and a projection to 10^8 particles on a cluster.

Each run is ``mpiexec -n R python -c "...scaling_worker(N)"`` with ``DEM_MPI=1`` (so that one rank takes the
distributed route too), on the random sintered packing of ``python -m benchmarks dem`` (fixed hot and cold layers,
rojek law, floating = "mean"). The runs alternate over the rounds and the best of each is kept: the machine is
shared, and the load average at the start of each run is in the table. Needs mpiexec and petsc4py (the README block
after ``mpi-command``): without them the section says so and measures nothing.
"""

from __future__ import annotations

import json
import math
import os
import pathlib
import shutil
import subprocess
import sys
import time

from benchmarks.dem import PACKING, packing_network
from benchmarks.timing import available, emit, peak_rss_mib
from verification.report import records_table

TITLE = "Distributed network on PETSc: strong and weak scaling"
TARGET_PARTICLES = 10**8  # the projection's size
PER_RANK_PROJECTED = 10**6  # particles per rank in the projection (as measured on one rank)


def parts_scene(n: int, folder, blocks: int | None = None, boundary: str = "plates") -> pathlib.Path:
    """A random sintered packing of ~n copper particles between a hot and a cold wall (``boundary`` ``"plates"``
    of the scenes' generator) or with its bottom and top layers held hot and cold (``"fixed"``), rojek law, steady,
    floating = "mean", written in parts (:mod:`dem.scene.packing_files.parts`) as ``packing.parts`` in ``folder``
    with ``blocks`` blocks (None: the default), and the scene ``packing.toml`` that reads it; returns the scene's
    path."""
    from dem.scene.packing_files import packing_from_particles
    from dem.scene.packing_files.parts import write_parts
    from dem.scene.parse import parse_scene

    folder = pathlib.Path(folder)
    material = {"conductivity": 394.0, "density": 8960.0, "specific_heat": 385.0}
    generated = parse_scene({"material": material, "generator": {
        "kind": "random", "n": int(n), "radius": PACKING["radius"], "overlap": PACKING["overlap"], "seed": 0,
        "boundary": boundary, "hot": 1.0, "cold": 0.0}})
    write_parts(folder / "packing.parts", packing_from_particles(generated.particles), blocks)
    walls = "".join(f'[[walls]]\nname = "{w.name}"\npoint = {[float(v) for v in w.point]}\n'
                    f'normal = {[float(v) for v in w.normal]}\ntemperature = {float(w.temperature)!r}\n'
                    for w in generated.walls)
    (folder / "packing.toml").write_text(
        "[material]\n" + "".join(f"{k} = {v!r}\n" for k, v in material.items()) +
        '[particles]\nfile = "packing.parts"\n' + walls +
        '[conductance]\nlaw = "rojek"\n[solver]\nmode = "steady"\nfloating = "mean"\n')
    return folder / "packing.toml"


def scaling_worker(n: int, scene_file: str | None = None) -> None:
    """One steady solve of the ~n-particle packing on the ranks of this ``mpiexec``; rank 0 prints one JSON line.
    With ``scene_file`` (:func:`parts_scene`), that scene instead, each rank reading only its part of the packing
    (``packing_seconds``: the reading; ``held``: the particles each rank holds)."""
    from dem.engines.distributed.static import DistributedStaticEngine
    from dem.scene.parse import make_scene

    load = os.getloadavg()[0]
    t0 = time.perf_counter()
    if scene_file is None:
        net, _ = packing_network(n)
        p = net.particles
        scene = make_scene(p.position, p.radius, p.temperature, fixed=p.fixed, law="rojek", mode="steady",
                           floating="mean", name="packing")
    else:
        from dem.parallel.comm import world
        from dem.scene import load_scene

        comm = world()
        scene = load_scene(scene_file, part=(comm.Get_size(), comm.Get_rank()))
    t1 = time.perf_counter()
    engine = DistributedStaticEngine(scene)
    t2 = time.perf_counter()
    engine.run()
    t3 = time.perf_counter()
    comm = engine.comm
    times = comm.gather({"packing_seconds": t1 - t0, "setup_seconds": t2 - t1, "solve_seconds": t3 - t2,
                         "peak_rss_mib": peak_rss_mib(), "held": scene.particles.n})
    s = engine.summary()  # reduced over the ranks: every rank takes part
    if comm.Get_rank() == 0:
        emit({"particles": scene.particle_count, "ranks": engine.ranks, "bonds": s["bonds"],
              "solver": s["linear_solver"], "iterations": s["linear_iterations"], "load_average": load,
              **{key: max(t[key] for t in times) for key in ("packing_seconds", "setup_seconds", "solve_seconds")},
              "peak_rss_mib_per_rank": [round(t["peak_rss_mib"]) for t in times],
              "held_per_rank": [t["held"] for t in times], "T_mean": s["T_mean"],
              "effective_conductivity": s.get("effective_conductivity")})


def run_ranks(n: int, ranks: int, timeout: float, scene_file=None) -> dict:
    """:func:`scaling_worker` of ``n`` particles (or of the packing in parts of ``scene_file``) on ``ranks`` ranks in
    a fresh ``mpiexec``: its row, or one with ``error``."""
    file = None if scene_file is None else str(scene_file)
    code = f"from benchmarks.distributed import scaling_worker; scaling_worker({int(n)}, {file!r})"
    env = dict(os.environ, DEM_MPI="1")
    command = ["mpiexec", "-n", str(ranks), sys.executable, "-c", code]
    try:
        proc = subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=env)
    except subprocess.TimeoutExpired:
        return {"particles": n, "ranks": ranks, "error": f"timeout after {timeout:g} s"}
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("{")]
    if proc.returncode != 0 or not lines:
        tail = (proc.stderr.strip().splitlines() or ["no output"])[-1]
        return {"particles": n, "ranks": ranks, "error": f"exit {proc.returncode}: {tail[:200]}"}
    row = json.loads(lines[-1])
    row["total_seconds"] = row["setup_seconds"] + row["solve_seconds"]
    return row


def measure(n: int, rounds: int, timeout: float, written=None) -> dict:
    """The best of ``rounds`` alternating runs of each case: ``{(particles, ranks): row}`` for n on 1 and 2 ranks
    and 2n on 2 ranks; ``written(best)`` after every run (the rows so far, kept should the bench stop)."""
    cases = ((n, 1), (n, 2), (2 * n, 2))
    best: dict = {}
    for _ in range(rounds):
        for particles, ranks in cases:
            row = run_ranks(particles, ranks, timeout)
            key = (particles, ranks)
            if key not in best or ("error" not in row and row["total_seconds"] < best[key].get("total_seconds",
                                                                                             math.inf)):
                best[key] = row
            if written is not None:
                written(best)
    return best


def projection(one: dict, weak: dict, target: int = TARGET_PARTICLES,
               per_rank: int = PER_RANK_PROJECTED) -> dict:
    """10^8 particles on ``target / per_rank`` ranks from the measured runs: setup per rank as measured with
    ``per_rank`` particles on one rank (the bond search and assembly are local; the halo grows with the cell faces,
    0.5 % of the rows at 2 ranks), the solve as the one-rank solve scaled by the AMG's iterations, extrapolated in
    log N from n to 2n, and memory per rank as the one-rank run's. Communication beyond what two ranks show is not
    in it (a lower bound)."""
    ranks = target // per_rank
    n1, n2 = one["particles"], weak["particles"]
    growth = (weak["iterations"] - one["iterations"]) / math.log(n2 / n1) if weak["iterations"] else 0.0
    iterations = max(one["iterations"], one["iterations"] + growth * math.log(target / n1))
    scale = per_rank / n1
    setup = one["setup_seconds"] * scale
    solve = one["solve_seconds"] * scale * iterations / max(one["iterations"], 1)
    return {"particles": target, "ranks": ranks, "iterations": round(iterations, 1), "setup_seconds": setup,
            "solve_seconds": solve, "total_seconds": setup + solve,
            "weak_efficiency_measured": one["total_seconds"] / weak["total_seconds"],
            "peak_rss_mib_per_rank": round(max(one["peak_rss_mib_per_rank"]) * scale)}


def run(section, quick: bool) -> None:
    missing = [name for name in ("mpi4py", "petsc4py") if not available(name)] + \
        ([] if shutil.which("mpiexec") else ["mpiexec"])
    if missing:
        section.add_text("Not measured", f"{', '.join(missing)} not found: install the MPI extra (README: the block "
                                         f"after `mpi-command`) and run `python -m benchmarks mpi` in its venv.")
        return
    n = 100_000 if quick else 1_000_000
    best = measure(n, 1 if quick else 2, timeout=1800,
                   written=lambda rows: section.csv("distributed_scaling", [rows[key] for key in sorted(rows)]))
    rows = [best[key] for key in sorted(best)]
    one, two, weak = best[(n, 1)], best[(n, 2)], best[(2 * n, 2)]
    text = (records_table(rows, ["particles", "ranks", "bonds", "solver", "iterations", "packing_seconds",
                                 "setup_seconds", "solve_seconds", "total_seconds", "peak_rss_mib_per_rank",
                                 "load_average", "error"], fmt="{:.3g}"))
    if not any("error" in r for r in (one, two, weak)):
        speedup = one["total_seconds"] / two["total_seconds"]
        section.summary["distributed_speedup_2_ranks"] = speedup
        section.summary["distributed_weak_efficiency"] = one["total_seconds"] / weak["total_seconds"]
        section.target(f"two ranks against one on {n} particles (setup + solve, time ratio)",
                       two["total_seconds"] / one["total_seconds"], 1.0)
        section.target("mean temperature on 2 ranks against 1 (hot - cold = 1 K)",
                       abs(two["T_mean"] - one["T_mean"]), 1e-8, "K")
        projected = projection(one, weak)
        section.summary["distributed_projection"] = projected
        text += (f"\n\nStrong scaling: {speedup:.2f}x on two ranks. Weak scaling: {n} particles on one rank against "
                 f"{2 * n} on two, efficiency {projected['weak_efficiency_measured']:.2f}.\n\nProjection to "
                 f"{TARGET_PARTICLES:.0e} particles on {projected['ranks']} ranks of {PER_RANK_PROJECTED:.0e} "
                 f"(:func:`benchmarks.distributed.projection`): ~{projected['iterations']} AMG iterations, setup "
                 f"{projected['setup_seconds']:.3g} s + solve {projected['solve_seconds']:.3g} s, "
                 f"~{projected['peak_rss_mib_per_rank']} MiB per rank. The packing is generated on every rank (the "
                 f"`packing_seconds` column, not in the total): at 10^8 particles a scene must come from a packing "
                 f"in parts (python -m dem convert IN NAME.parts), of which each rank reads only its part.")
    section.add_text("Steady network on 1 and 2 ranks", text)
