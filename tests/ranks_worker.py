"""The runs that tests/test_dem_ranks.py compares, as one script for ``mpiexec -n N python ranks_worker.py CASE
OUT``: the same function runs the serial engine in the test's own process and the ranks engine here. Rank 0 writes
``OUT`` (``.npz``)."""

import copy
import sys

import numpy as np

L = 6e-3  # m, the period of the boxes
LUDING = {"law": "luding", "k1": 1.0e3, "k2": 2.0e3, "kc": 1.0e3, "kt_ratio": 0.2, "gamma_n": 1e-4,
          "gamma_t": 5e-5, "mu": 0.5, "mu_wall": 0.0, "T_melt": 1000.0, "T_var": 10.0, "expansion": 1.0e-4,
          "fluid_overlap": 0.2, "t0": 1.0e3, "brittle_sliding": True}
ELASTIC = {"law": "hertz_mindlin", "youngs_modulus": 1.0e7, "poisson_ratio": 0.3, "restitution": 1.0,
           "tangential_damping": 0.0, "mu": 0.0, "mu_wall": 0.0}
GAS = {"scene": {"physics": ["mechanical"]}, "material": {"density": 7800.0}, "contact": LUDING,
       "generator": {"kind": "box", "n": 60, "radius": 5e-4, "radius_spread": 0.1, "seed": 2, "speed": 0.5,
                     "box": [[0.0, 0.0, 0.0], [L, L, L]]},
       "periodic": {"lengths": [L, L, L]}, "solver": {"mode": "transient", "t_end": 0.004}}
COMPACTION_SIDE = 0.03  # m, the square box the disks start in (solid fraction ~0.35)
STRESS_WALL = {"motion": "stress", "pressure": 100.0, "mass": 0.01, "damping": 0.2}
COMPACTION = {  # 100 disks of Luding 2005's Table 1 sizes, stiffer-than-soft linear contact, pressed at 100 N/m
    "scene": {"physics": ["mechanical"], "dimension": 2, "height": 6e-3}, "material": {"density": 2000.0},
    "contact": {**LUDING, "k1": 2e4, "k2": 2e4, "kc": 0.0, "gamma_n": 2e-2, "gamma_t": 5e-3},
    "generator": {"kind": "box", "n": 100, "radius": 1e-3, "radius_spread": 0.5, "seed": 1, "speed": 0.01,
                  "box": [[0.0, 0.0, 0.0], [COMPACTION_SIDE, 0.0, COMPACTION_SIDE]], "temperature": 20.0},
    "walls": [{"name": "left", "point": [0.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0]},
              {"name": "bottom", "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]},
              {"name": "right", "point": [COMPACTION_SIDE, 0.0, 0.0], "normal": [-1.0, 0.0, 0.0], **STRESS_WALL},
              {"name": "top", "point": [0.0, 0.0, COMPACTION_SIDE], "normal": [0.0, 0.0, -1.0], **STRESS_WALL}],
    "solver": {"mode": "transient", "t_end": 0.1}}
SPACING = 9.75e-4  # m, the centres' spacing of a lattice of radius 5e-4 and overlap 0.05
KEFF = {  # heat from a hot to a cold wall through a lattice column, periodic across: an effective conductivity
    "scene": {"physics": ["mechanical", "thermal"]},
    "material": {"density": 7800.0, "conductivity": 40.0, "specific_heat": 450.0}, "contact": ELASTIC,
    "generator": {"kind": "lattice", "shape": [3, 3, 10], "radius": 5e-4, "overlap": 0.05, "temperature": 60.0},
    "periodic": {"lengths": [3 * SPACING, 3 * SPACING, 1.0], "axes": ["x", "y"]},
    "walls": [{"name": "hot", "point": [0.0, 0.0, -SPACING / 2], "normal": [0.0, 0.0, 1.0], "temperature": 100.0},
              {"name": "cold", "point": [0.0, 0.0, 9.5 * SPACING], "normal": [0.0, 0.0, -1.0], "temperature": 20.0}],
    "solver": {"mode": "transient", "t_end": 0.001, "thermal_interval": 1e-4}, "output": {"interval": 5e-4}}
CASES = {
    # frictional, damped, sintering law: momentum is what a periodic box conserves
    "gas": GAS,
    # elastic and frictionless (Hertz, e = 1): the energy of the collisions comes back
    "elastic": {**GAS, "contact": ELASTIC},
}
HEAT = {**GAS, "scene": {"physics": ["mechanical", "thermal"]},  # the elastic gas with heat through its contacts,
        "contact": ELASTIC,  # insulated (a law whose forces do not depend on the temperature: the serial motion)
        "material": {"density": 7800.0, "conductivity": 40.0, "specific_heat": 450.0},
        "generator": {**GAS["generator"], "n": 50, "radius": 6e-4, "speed": 0.2},
        "solver": {"mode": "transient", "t_end": 0.004, "thermal_interval": 1e-4}}
STIFF_SPECIFIC_HEAT = 1e-4  # J/(kg K): the contacts' time constants ~1e-7 s, far below the thermal interval
CHUNK = 100  # steps between the samples of a trace


def trace(engine_class, case: str, comm=None) -> dict:
    """Run ``CASES[case]`` on ``engine_class`` in chunks of :data:`CHUNK` steps; after each chunk the momentum, the
    kinetic energy and the global ids held by the ranks (every id once: none lost, none duplicated)."""
    from dem import parse_scene

    engine = engine_class(parse_scene(copy.deepcopy(CASES[case])))
    mech = engine.mechanics
    n_end = round(engine.scene.solver.t_end / mech.dt)
    T0, rate = np.array([20.0]), np.zeros(1)
    momentum, energy, ids_intact = [], [], []
    while mech.steps < n_end:
        mech.advance(min(CHUNK, n_end - mech.steps), T0, rate)
        whole = mech.gathered(everyone=True) if comm is not None else mech
        momentum.append(whole.state.momentum())
        energy.append(whole.state.kinetic_energy())
        if comm is not None:
            held = np.sort(np.concatenate(comm.allgather(mech.gid[mech.owned])))
            ids_intact.append(np.array_equal(held, np.arange(mech.n_global)))
    whole = mech.gathered(everyone=True) if comm is not None else mech
    s = whole.state
    return {"x": s.x, "v": s.v, "w": s.w, "f": s.f, "momentum": np.array(momentum), "energy": np.array(energy),
            "ids_intact": np.array(ids_intact), "mass": s.mass, "rebuilds": mech.rebuilds,
            "migrated": comm.allreduce(mech.migrated) if comm is not None else 0,
            "contacts": len(whole.contacts()[0])}


def builtin(name: str, t_end: float):
    """The built-in scene ``name`` ended at ``t_end``."""
    import tomllib

    from dem import parse_scene
    from dem.scene.parse import SCENE_DIR

    doc = tomllib.loads((SCENE_DIR / f"{name}.toml").read_text())
    doc["solver"]["t_end"] = t_end
    return parse_scene(doc, base_dir=SCENE_DIR)


def run_builtin(name: str, t_end: float, out) -> dict:
    """The built-in scene through the driver (the ranks engine under mpiexec), its folder written into ``out``:
    the final particles and the summary's numbers."""
    return run_scene(builtin(name, t_end), out)


def pressed(relative: float = 0.0):
    """:data:`COMPACTION` with the walls' pressure changed by ``relative`` (a few ulps: another sample of the
    same compaction, as two ranks' loads summed in another order are)."""
    from dem import parse_scene

    doc = copy.deepcopy(COMPACTION)
    for wall in doc["walls"][2:]:
        wall["pressure"] *= 1.0 + relative
    return parse_scene(doc)


def hot_and_cold(specific_heat: float = 450.0):
    """:data:`HEAT`, the particles' temperatures 20 to 100 (by id): heat flows wherever two of them touch;
    ``specific_heat`` (J/(kg K)) of the particles."""
    import dataclasses

    from dem import parse_scene

    doc = copy.deepcopy(HEAT)
    doc["material"]["specific_heat"] = specific_heat
    scene = parse_scene(doc)
    p = scene.particles
    T = 20.0 + 80.0 * (np.arange(p.n) * 37 % p.n) / p.n
    return dataclasses.replace(scene, particles=dataclasses.replace(p, temperature=T))


def short_compaction():
    """:data:`COMPACTION` to 0.01 s with an output every 1 ms (an interval, a checkpoint), in the first 10 % of the
    press: walls moving, particles crossing the slabs."""
    from dem import parse_scene

    doc = copy.deepcopy(COMPACTION)
    doc["solver"]["t_end"] = 0.01
    doc["output"] = {"interval": 1e-3}
    return parse_scene(doc)


RESUMED = {"compaction": short_compaction, "heat": hot_and_cold}  # the runs interrupted and resumed


def interrupted_and_resumed(scene, stop: float, out) -> dict:
    """``scene`` through the driver into ``out``, interrupted (KeyboardInterrupt on every rank, as Ctrl-C) after the
    interval that passes ``stop`` s, then resumed from its folder: the resumed run's :func:`run_scene`."""
    from dem.engines.distributed.verlet import RankVerletEngine

    original = RankVerletEngine.run

    def stopped(self, observe=None, progress=None, checkpoint=None):
        def advanced(t):
            if progress is not None:
                progress(t)
            if t >= stop:
                raise KeyboardInterrupt

        original(self, observe, advanced, checkpoint)

    RankVerletEngine.run = stopped
    try:
        run_scene(scene, out)
        raise AssertionError(f"the run was not interrupted at t = {stop} s")
    except KeyboardInterrupt:
        pass
    finally:
        RankVerletEngine.run = original
    return run_scene(scene, out, resume=True)


def run_scene(scene, out=None, resume: bool = False) -> dict:
    """``scene`` through the driver: the final particles and the summary's numbers."""
    from dem import run

    result = run(scene, out=out, resume=resume)
    s = result.engine.mechanics.state
    numbers = {k: v for k, v in result.summary.items() if isinstance(v, (int, float)) and k != "seconds"}
    return {"x": s.x, "v": s.v, "w": s.w, "f": s.f, "T": s.T, "summary_keys": np.array(list(numbers)),
            "summary_values": np.array(list(numbers.values()), dtype=float)}


if __name__ == "__main__":
    from mpi4py import MPI

    from dem import parse_scene
    from dem.engines.distributed.verlet import RankVerletEngine

    comm = MPI.COMM_WORLD
    if sys.argv[1] == "scene":  # scene NAME T_END FOLDER RESULT
        result = run_builtin(sys.argv[2], float(sys.argv[3]), sys.argv[4])
    elif sys.argv[1] == "compaction":  # compaction RESULT
        result = run_scene(pressed())
    elif sys.argv[1] == "heat":  # heat RESULT
        result = run_scene(hot_and_cold())
    elif sys.argv[1] == "stiff-heat":  # stiff-heat RESULT
        result = run_scene(hot_and_cold(STIFF_SPECIFIC_HEAT))
    elif sys.argv[1] == "keff":  # keff FOLDER RESULT
        result = run_scene(parse_scene(copy.deepcopy(KEFF)), sys.argv[2])
    elif sys.argv[1] == "whole":  # whole CASE FOLDER RESULT
        result = run_scene(RESUMED[sys.argv[2]](), sys.argv[3])
    elif sys.argv[1] == "resumed":  # resumed CASE STOP FOLDER RESULT
        result = interrupted_and_resumed(RESUMED[sys.argv[2]](), float(sys.argv[3]), sys.argv[4])
    else:  # CASE RESULT
        result = trace(RankVerletEngine, sys.argv[1], comm)
    if comm.Get_rank() == 0:
        np.savez(sys.argv[-1], ranks=comm.Get_size(), **result)
