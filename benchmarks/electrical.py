"""Speed of the Zohdi 2014 engine: the Section 7 example, the cost of its steps against the velocity-Verlet loop of
the Luding engine, and the Kirchhoff solve against the paper's current iteration at equal accuracy.

The ``electrical`` subject of ``python -m benchmarks`` (:func:`run`) measures, in one process:

* ``section7`` -- the built-in scene ``zohdi-compaction`` (1000 spheres, 1 s, Sec. 7) run end to end (the wall time
  of :meth:`dem.engines.staggered.engine.StaggeredEngine.run`, no outputs written), with its steps, fixed-point iterations,
  restarts and step sizes, and the three phases of Fig. 9 (volume fraction when the wall first carries current,
  the largest, the last; mean temperature then);
* ``step_cost`` -- on the compacted packing of that run (t = 0.79 s, both electrodes touching): ns per particle of
  one fixed-point iteration of the mechanics (forces and update, compiled), of one iteration of the heat balance,
  of one refresh of the current, and of one velocity-Verlet step of the Luding 2005 loop (:mod:`dem.engines.verlet.loop`) on
  the same positions; best of R;
* ``current_solve`` -- on the same packing, the Laplace problem of Zohdi's eq. (43) (contact areas as weights, the
  particles touching the electrodes held at 1 and 0) solved by the generic network solve (sparse direct) and by
  the paper's Gauss-Seidel sweeps from zero until they are within 1e-3, 1e-6 and 1e-9 of it; and the physical
  Kirchhoff solve of :mod:`dem.network.current` (bonds, conductances, potentials, Joule heat);
* ``current_scaling`` -- the same two solves to 1e-6 on random sintered packings of 1000 to 16 000 particles
  (:func:`dem.geometry.generators.random_packing`, bottom layer at 0, top layer at 1): the sweeps grow with the square of
  the height, the direct solve with its fill-in.

:func:`section7_row` is the row a benchmark table needs (seconds, steps, iterations, restarts, ns per
particle-iteration); its seconds are held against :data:`SECTION7_LIMIT`. Timings on a shared machine are noisy:
compare the ratios measured here side by side.
"""

from __future__ import annotations

import time

import numpy as np

from verification.report import md_table

TITLE = "Electrically aided sintering (Zohdi 2014): the Section 7 example, step cost, current solves"
SECTION7_LIMIT = 60.0  # s: the Section 7 example end to end


def _scene():
    from dem.scene import load_scene

    return load_scene("zohdi-compaction")


def section7_row() -> dict:
    """The Section 7 example run end to end: wall time and what it took (module docstring)."""
    from dem.engines.staggered.engine import StaggeredEngine

    scene = _scene()
    rows = []
    start = time.perf_counter()
    sim = StaggeredEngine(scene)
    built = time.perf_counter()
    sim.run(lambda: rows.append(sim.record()))
    seconds = time.perf_counter() - start
    n = sim.mechanics.state.n
    contact = next(r for r in rows if (r.get("joule_heat") or 0.0) > 1.0)  # the wall reaches the powder
    release = max(r["t"] for r in rows if r["t"] <= 0.8 + 1e-9)
    at = {r["t"]: r for r in rows}
    return {"particles": n, "seconds": seconds, "setup_seconds": built - start, "steps": sim.steps,
            "iterations": sim.iterations, "restarts": sim.restarts,
            "iterations_per_step": sim.iterations / sim.steps, "dt_min": min(sim.dt_taken),
            "dt_max": max(sim.dt_taken), "dt_mean": float(np.mean(sim.dt_taken)),
            "us_per_particle_step": 1e6 * seconds / (n * sim.steps),
            "ns_per_particle_iteration": 1e9 * seconds / (n * sim.iterations),
            "phases": {"poured": {"t": contact["t"], "volume_fraction": contact["volume_fraction"],
                                  "T_mean": contact["T_mean"]},
                       "compacted": {"t": release, "volume_fraction": max(r["volume_fraction"] for r in rows),
                                     "T_mean": at[release]["T_mean"]},
                       "released": {"t": rows[-1]["t"], "volume_fraction": rows[-1]["volume_fraction"],
                                    "T_mean": rows[-1]["T_mean"], "T_peak": max(r["T_mean"] for r in rows)}},
            "energy_error": sim.thermal.energy_error(), "joule_energy": sim.current.joule_energy,
            "electrode_energy": sim.current.electrode_energy}


def _best(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def compacted(t: float = 0.79):
    """The Section 7 run stepped to ``t`` (the powder pressed, both electrodes touching)."""
    from dem.engines.staggered.engine import StaggeredEngine

    sim = StaggeredEngine(_scene())
    while sim.t < t:
        sim.step()
    return sim


def step_cost(sim, repeat: int = 5, luding_steps: int = 200) -> dict:
    """ns per particle of the pieces of a Zohdi step and of a Luding velocity-Verlet step, same packing."""
    from dem.laws.contact.luding import LUDING_TABLE1
    from dem.engines.verlet.mechanics import MechanicalModel
    from dem.engines.state import MotionState

    mech, th, cur = sim.mechanics, sim.thermal, sim.current
    n = mech.state.n
    dt = 1e-5  # tiny: the iterate stays within the Verlet list, the cost is the same at any step
    x0, v0 = mech.state.x.copy(), mech.state.v.copy()

    def iteration():
        mech.begin(sim.t, dt)
        mech.iterate(dt, 0.5, mech.state.T)
        mech.restart()

    T = th.T.copy()
    H = cur.heating
    mechanics = _best(iteration, repeat)
    mech.begin(sim.t, dt)
    mech.iterate(dt, 0.5, T)
    heat = _best(lambda: th.iterate(dt, 0.5, mech, T, H), repeat)
    mech.restart()
    refresh = _best(lambda: cur.refresh(mech, sim.t), repeat)
    mech.state.x[:], mech.state.v[:] = x0, v0
    state = MotionState.create(3, x0, mech.state.radius, LUDING_TABLE1.density, np.full(n, 20.0))
    luding = MechanicalModel(state, mech.walls, LUDING_TABLE1.params(), 1e-7, mech.skin, (-9.81, 0.0, 0.0))
    luding.advance(2, np.array([20.0]), np.zeros(1))  # compiled (or loaded) before timing
    verlet = _best(lambda: luding.advance(luding_steps, np.array([20.0]), np.zeros(1)), repeat) / luding_steps
    pairs = len(mech.pi)
    return {"particles": n, "listed_pairs": pairs, "contacts": len(mech.contacts()[0]),
            "ns_per_particle": {"zohdi_mechanics_iteration": 1e9 * mechanics / n,
                                "zohdi_heat_iteration": 1e9 * heat / n, "current_refresh": 1e9 * refresh / n,
                                "luding_verlet_step": 1e9 * verlet / n},
            "iterations_per_step": sim.iterations / sim.steps,
            "zohdi_iteration_over_luding_step": mechanics / verlet}


def current_solve(sim, repeat: int = 3) -> dict:
    """The area-weighted Laplace problem of eq. (43) by the network solve and by Gauss-Seidel sweeps to 1e-3, 1e-6,
    1e-9 of it; the physical Kirchhoff refresh for comparison (module docstring)."""
    from dem.network.current import area_weighted_current
    from dem.engines.staggered.heat import contact_bonds

    mech, cur = sim.mechanics, sim.current
    n = mech.state.n
    now, b = contact_bonds(cur.particles, mech, mech.state.x, mech.state.T, cur.electrodes.walls, "lens", "clip")
    area = np.pi * b.a**2
    J_ext = np.where(cur.electrodes.fixed_potential, cur.electrodes.potential, 0.0)
    J_ext = J_ext / max(np.max(np.abs(J_ext)), 1e-300)  # 1 at the driven wall, 0 at the ground

    def direct():
        return _direct(n, b, area, b.wall_particle, b.wall_index, J_ext)

    reference, free = direct()
    seconds_direct = _best(direct, repeat)
    sweeps = {}
    for accuracy in (1e-3, 1e-6, 1e-9):
        res, tol = _sweeps_to(n, b, area, b.wall_particle, b.wall_index, J_ext, reference, free, accuracy)
        seconds = _best(lambda: area_weighted_current(n, b.i, b.j, area, b.wall_particle, b.wall_index, J_ext, None,
                                                      tol, 10**7), repeat)
        error = float(np.max(np.abs(res.J[free] - reference[free]), initial=0.0))
        sweeps[f"{accuracy:g}"] = {"sweeps": res.sweeps, "error": error, "seconds": seconds,
                                   "over_direct": seconds / seconds_direct}
    kirchhoff = _best(lambda: cur.refresh(mech, sim.t), repeat) if cur.scheme == "kirchhoff" else None
    return {"unknowns": int(len(free)), "contacts": int(b.n_pairs), "seconds_direct": seconds_direct,
            "gauss_seidel": sweeps, "seconds_kirchhoff_refresh": kirchhoff}


def _direct(n, b, area, node, index, values):
    """The area-weighted Laplace problem of eq. 43 (bonds ``b``, weights ``area``) with the potential of particle
    ``node[k]`` held at ``values[index[k]]``, solved directly on the components that hold a fixed particle: the
    potentials and the free particles solved for."""
    from dem.network.laplacian import BoundedLaplacian, solve_anchored

    fixed = np.zeros(n, dtype=bool)
    fixed[node] = True
    value = np.zeros(n)
    value[node] = values[index]
    system = BoundedLaplacian(n, b.i, b.j, area, fixed, [], [], [], 0)
    _, label, anchored = system.components()
    subset = np.flatnonzero(anchored[label])
    x, _ = solve_anchored(system, system.boundary_rhs(value[system.fixed], []), subset, "direct")
    value[system.free[subset]] = x
    return value, system.free[subset]


def _sweeps_to(n, b, area, plane_node, plane_index, values, reference, free, accuracy):
    """Gauss-Seidel sweeps of eq. (43) from zero until within ``accuracy`` of ``reference``: ``(result, tol)``."""
    from dem.network.current import area_weighted_current

    tol = accuracy
    while True:  # the stopping rule is on the change per sweep; tighten it until the error is within the accuracy
        res = area_weighted_current(n, b.i, b.j, area, plane_node, plane_index, values, None, tol, 10**7)
        if float(np.max(np.abs(res.J[free] - reference[free]), initial=0.0)) <= accuracy or tol < 1e-16:
            return res, tol
        tol /= 10.0


def current_scaling(sizes=(1000, 4000, 16000), accuracy: float = 1e-6, repeat: int = 3) -> list:
    """Direct network solve against Gauss-Seidel sweeps of eq. (43) on random packings (module docstring)."""
    from dem.geometry.bonds import find_bonds
    from dem.network.current import area_weighted_current
    from dem.geometry.generators import random_packing
    from dem.geometry.particles import Particles

    rows = []
    for size in sizes:
        layout = random_packing(size, 1e-3, 0.1, seed=1)
        n = len(layout.radius)
        particles = Particles.from_arrays(layout.position, layout.radius, np.zeros(n))
        b = find_bonds(particles, (), "lens", "clip")
        area = np.pi * b.a**2
        plane_node = np.concatenate([layout.bottom, layout.top])
        plane_index = np.concatenate([np.zeros(len(layout.bottom), int), np.ones(len(layout.top), int)])
        values = np.array([0.0, 1.0])

        def direct():
            return _direct(n, b, area, plane_node, plane_index, values)

        reference, free = direct()
        seconds_direct = _best(direct, repeat)
        res, tol = _sweeps_to(n, b, area, plane_node, plane_index, values, reference, free, accuracy)
        seconds_sweeps = _best(lambda: area_weighted_current(n, b.i, b.j, area, plane_node, plane_index, values, None,
                                                             tol, 10**7), repeat)
        rows.append({"particles": n, "height_in_diameters": float(np.ptp(layout.position[:, 2]) / 2e-3 + 1.0),
                     "unknowns": int(len(free)),
                     "seconds_direct": seconds_direct, "sweeps": res.sweeps, "seconds_sweeps": seconds_sweeps,
                     "sweeps_over_direct": seconds_sweeps / seconds_direct})
    return rows


def run(section, quick: bool) -> None:
    """The studies of the module docstring into ``section`` (:mod:`benchmarks`' subject interface); ``quick``:
    fewer repeats and the current scaling to 4000 particles."""
    repeat = 2 if quick else 5
    row = section7_row()
    section.summary["zohdi_section7"] = row
    section.target("the Section 7 example (1000 spheres, 1 s) end to end", row["seconds"], SECTION7_LIMIT, "s")
    sim = compacted()
    cost = step_cost(sim, repeat)
    solve = current_solve(sim, repeat)
    scaling = current_scaling(sizes=(1000, 4000) if quick else (1000, 4000, 16000), repeat=min(repeat, 3))
    section.summary.update(zohdi_step_cost=cost, zohdi_current_solve=solve, zohdi_current_scaling=scaling)
    section.csv("current_scaling", scaling)
    phases = row["phases"]
    section.add_text("The Section 7 example", (
        f"{row['particles']} spheres, 1 s: {row['seconds']:.1f} s end to end, {row['steps']} steps, "
        f"{row['iterations']} fixed-point iterations ({row['iterations_per_step']:.1f} per step), {row['restarts']} "
        f"restarts, steps {row['dt_min']:.2g} ... {row['dt_max']:.2g} s. Volume fraction poured "
        f"{phases['poured']['volume_fraction']:.3f}, pressed {phases['compacted']['volume_fraction']:.3f}, released "
        f"{phases['released']['volume_fraction']:.3f}; energy error {row['energy_error']:.1e}, Joule energy "
        f"{row['joule_energy']:.4g} J = electrode energy {row['electrode_energy']:.4g} J."))
    section.add_text("Cost per particle against the Luding loop", (
        f"On the pressed packing ({cost['particles']} spheres, {cost['contacts']} contacts, {cost['listed_pairs']} "
        f"listed pairs), best of {repeat}; a step takes {cost['iterations_per_step']:.1f} iterations.\n\n"
        + md_table(["piece", "ns per particle"], [[k, v] for k, v in cost["ns_per_particle"].items()])))
    section.add_text("The network solve against the paper's current iteration (eq. 43)", md_table(
        ["particles", *[k for k in scaling[0] if k != "particles"]],
        [[r["particles"], *[r[k] for k in r if k != "particles"]] for r in scaling]))
