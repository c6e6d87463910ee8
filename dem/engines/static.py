"""The submodels a scene can ask for, and where new ones plug in.

A scene names its physics (``[scene] physics = ["thermal"]``); only those are built. Each entry of
:data:`REGISTRY` is a class constructed from the :class:`~dem.scene.parse.Scene` that builds its own state, and whose
``run(observer, progress)`` returns a summary dict. The thermal model of a static packing builds its bonds once,
never moves a particle and allocates no mechanical state.

Particles that move (``"mechanical"``, the Luding 2005 contact law) run in the engine of :mod:`dem.engines.verlet.engine`, where
the thermal network follows the contacts as the necks grow; with ``[contact] law = "zohdi"`` the staggered scheme of
Zohdi 2014 (:mod:`dem.engines.staggered.engine`) runs the mechanics, the heat and the current (``"electrical"``).
"""

from __future__ import annotations

import numpy as np

from dem.network.heat import boundary_heat_flow, build_network, integrate, periodic_heat_flow, steady

WORK_PER_STEP_LIMIT = 3000  # particle-steps allowed per unit of solver.max_steps (default 1e5: 3e8, ~1 min)
SECONDS_PER_PARTICLE_STEP = 2e-7  # implicit, 2 cores: 1e-7 (10^6-particle lattice) to 6e-7 (random packing, bench)

PLANNED: dict = {}  # names reserved for submodels still to come: refused with what they will be
MOVING = ("mechanical", "electrical")  # built by the engines for moving particles (dem.engines.verlet, dem.engines.staggered), not here


class ThermalModel:
    """The pipe network of Rojek 2022 (eqs. 1-9) on bonds found once from the scene's geometry."""

    name = "thermal"

    def __init__(self, scene):
        self.scene = scene
        if scene.solver.mode == "transient":
            self._check_work()  # before the bond search: a refused run costs nothing
        self.network = build_network(scene.particles, scene.walls, scene.conductance, scene.sources, box=scene.box)
        self.bonds, self.K_pairs, self.K_walls = self.network.bonds, self.network.K_pairs, self.network.K_walls

    def run(self, observer=None, progress=None, resume=None, checkpoint=None) -> dict:
        """Solve (steady) or integrate (transient); ``resume``/``checkpoint``: :func:`dem.network.heat.integrate`."""
        try:
            return self._run(observer, progress, resume, checkpoint)
        except RuntimeError as exc:  # e.g. SuperLU "Factor is exactly singular": explain it as a property of the scene
            raise ValueError(self._singular_message(exc)) from None

    def _check_work(self) -> None:
        """Refuse a fixed-step run whose particle-steps exceed ``WORK_PER_STEP_LIMIT * max_steps`` up front, with a
        time estimate (:data:`SECONDS_PER_PARTICLE_STEP`)."""
        s, n = self.scene.solver, self.scene.particles.n
        if s.dt == "auto":
            return  # the step count is not known in advance; max_steps bounds it while running
        work = s.t_end / s.dt * n
        if work > WORK_PER_STEP_LIMIT * s.max_steps:
            raise ValueError(f"solver: t_end / dt = {s.t_end / s.dt:.3g} steps x {n} particles = {work:.3g} "
                             f"particle-steps (about {SECONDS_PER_PARTICLE_STEP * work:.3g} s) exceeds "
                             f"{WORK_PER_STEP_LIMIT} x solver.max_steps = {WORK_PER_STEP_LIMIT * s.max_steps:.3g}; "
                             f"raise max_steps to run it anyway, or use a larger dt, a shorter t_end or fewer "
                             f"particles")

    def _singular_message(self, exc: Exception) -> str:
        """Why a factorisation failed: the capacities vanish next to the conductances in ``C/dt + theta A``."""
        s, p = self.scene.solver, self.scene.particles
        diag = np.bincount(self.bonds.i, self.K_pairs, p.n) + np.bincount(self.bonds.j, self.K_pairs, p.n)
        diag += np.bincount(self.bonds.wall_particle, self.K_walls, p.n)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            tau = float(np.min(p.capacity / diag, initial=np.inf))
        step = s.t_end if s.dt == "auto" else s.dt
        what = "solver.t_end (the largest step dt = \"auto\" can take)" if s.dt == "auto" else "solver.dt"
        return (f"the linear system became numerically singular ({' '.join(str(exc).split())}): {what} = "
                f"{step:.6g} s against a smallest particle time constant C/K = {tau:.6g} s, so the capacities are "
                f"lost to round-off; use a step (or t_end) below about 1e12 times that time constant, or "
                f"mode = \"steady\"" if s.mode == "transient" else
                f"the steady linear system is numerically singular ({' '.join(str(exc).split())}); check that "
                f"conductances, ambient coefficients and fixed temperatures are within a few orders of magnitude "
                f"of each other")

    def _run(self, observer=None, progress=None, resume=None, checkpoint=None) -> dict:
        s = self.scene.solver
        out = {"law": self.scene.conductance.law, "contact": self.bonds.contact,
               "bonds_clipped": self.bonds.clipped, "bonds_dropped": self.bonds.dropped,
               "wall_bonds": self.bonds.n_walls}
        if s.mode == "steady":
            res = steady(self.network, s.floating, s.linear)
            self.T = res.T
            if observer is not None:
                observer(0, 0.0, res.T[self.network.free], res.flows)
            out.update(t=0.0, steps=0, energy_error=res.energy_error, heat_flow=res.flows, linear_solver=res.solver,
                       newton_iterations=res.iterations, floating_groups=res.floating)
            if len(self.network.fixed) or len(self.scene.walls):
                out["boundary_heat_flow"] = self._boundary(res.T)
            if self.scene.box is not None:
                out["periodic_heat_flow"] = periodic_heat_flow(self.network, res.T).tolist()
        else:
            res = integrate(self.network, s.integrator, s.dt, s.t_end, s.rtol, s.linear, s.max_steps, observer,
                            progress, resume=resume, checkpoint=checkpoint)
            self.T = res.T
            out.update(t=res.t, steps=res.steps, energy_error=res.energy_error, heat_in=res.heat_in,
                       integrator=s.integrator, dt=s.dt, dt_min=res.dt_min, dt_max=res.dt_max,
                       rejected_steps=res.rejected, stable_limit=res.stable_limit, linear_solver=res.solver,
                       factorizations=res.factorizations, max_principle_violation=res.max_principle_violation)
        return out

    def _boundary(self, T: np.ndarray) -> dict:
        flows = boundary_heat_flow(self.network, T)
        out = {"walls": {w.name: float(q) for w, q in zip(self.scene.walls, flows["walls"])},
               "fixed_total": float(sum(flows["particles"].values()))}
        if len(flows["particles"]) <= 1000:
            out["particles"] = {str(k): v for k, v in flows["particles"].items()}
        return out

    def bond_heat_flow(self) -> tuple[np.ndarray, np.ndarray]:
        """Heat flow (W) along each pair bond from i to j, and from each wall-bonded particle into its wall."""
        b, T = self.bonds, self.T
        wall_T = self.network.wall_temperature[b.wall_index]
        return self.K_pairs * (T[b.i] - T[b.j] + self.network.jump), self.K_walls * (T[b.wall_particle] - wall_T)


REGISTRY = {"thermal": ThermalModel}
PHYSICS_NAMES = (*REGISTRY, *MOVING)


def check_physics(names) -> None:
    """Every name a submodel that exists (``thermal``, ``mechanical``, ``electrical``); planned and unknown ones are
    refused; ``electrical`` runs with moving particles."""
    available = (*REGISTRY, *MOVING)
    for name in names:
        if name in PLANNED:
            raise ValueError(f"[scene] physics = {name!r}: not implemented yet ({PLANNED[name]}); available: "
                             f"{', '.join(available)}")
        if name not in available:
            raise ValueError(f"[scene] physics = {name!r}: unknown (available: {', '.join(available)})")
    if not names:
        raise ValueError(f"[scene] physics: names no submodel (available: {', '.join(available)})")
    if "electrical" in names and "mechanical" not in names:
        raise ValueError("[scene] physics: \"electrical\" runs with moving particles: [\"mechanical\", \"thermal\", "
                         "\"electrical\"] with [contact] law = \"zohdi\" (the current on a static packing: "
                         "dem.network.current.kirchhoff)")


def build(scene) -> list:
    """The submodels of a static scene (only ``thermal``), in order; unknown or planned names raise ValueError."""
    check_physics(scene.physics)
    return [REGISTRY[name](scene) for name in scene.physics]
