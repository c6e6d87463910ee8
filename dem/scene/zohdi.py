r"""The keys of a scene that runs Zohdi 2014: ``[contact] law = "zohdi"``, the implicit stepping in ``[solver]``, the
current in ``[electrical]`` and the electrodes in ``[[walls]]``.

* ``[contact]`` -- ``law = "zohdi"`` and the :class:`~dem.laws.contact.zohdi.ZohdiMaterial` fields (the paper's
  symbols: ``K_p``, ``p_p``, ``K_p_lim``, ``K_w``, ``p_w``, ``K_w_lim``, ``theta_star``, ``K_b``, ``p_b``,
  ``E_star``, ``mu_d``, ``c_env``, ``v_slip``; ``density`` defaults to the ``[material]`` one);
* ``[solver]`` -- ``dt`` (the first step, s), ``dt_max`` (:math:`\Delta t_{lim}`, default ``dt``), ``phi``,
  ``iterations`` (K_d), ``tolerance`` (TOL), ``order`` (p), ``growth``, ``shrink``, ``dt_min`` (:class:`ZohdiStepping`);
* ``[electrical]`` -- ``scheme`` (``"kirchhoff"`` or ``"zohdi"``), ``absorption`` (a of eq. 35), ``floating``
  (``"allow"``: particles touching no electrode carry no current; ``"error"``: stop, naming them), and for Zohdi's
  iteration ``tolerance`` (largest change per sweep relative to the largest wall value) and ``sweeps`` (at most
  per refresh);
* ``[[walls]]`` -- ``potential`` (V) or ``current`` (A into the packing; Zohdi's scheme: the wall's J_ext) makes a
  wall an electrode; ``[material] electrical_conductivity`` (S/m) is :math:`\sigma`;
* ``[output]`` -- ``fraction_axis`` (``"x"``, ``"y"`` or ``"z"``): the axis along which the powder stands on its
  bottom wall and is pressed by its top wall; the run's ``volume_fraction`` is then that of the volume between the
  bottom wall and the lowest point the top wall has reached (Sec. 7, Remark 1), and ``bed_fraction`` the bulk
  fraction of the bed up to its surface; ``frames`` (PNG renderings over the run, in the style of Fig. 8).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from dem.network.current import Electrodes, check_absorption, check_scheme

LEAST_FACTOR = 0.05  # the step factor Phi never goes below this (one restart shrinks the step at most 20 x)
DEFAULT_SKIN = 0.5  # x the mean radius: a step of the implicit scheme moves particles far more than a Verlet step
ELECTRODE_KEYS = {"potential", "current"}


@dataclass(frozen=True)
class ZohdiStepping:
    r"""The implicit scheme of Zohdi 2014: trapezoidal weight ``phi`` (eqs. 22-24; 0 explicit, 1/2 the trapezoid, 1
    backward), the fixed-point iteration within a step to ``tolerance`` (TOL of eqs. 47-48, for positions and
    temperatures) in a target of ``iterations`` (:math:`K_d`) iterations, the exponent ``order`` (p of eq. 30, 2 for
    this second-order system), the first step ``dt`` and its upper bound ``dt_max`` (:math:`\Delta t_{lim}`) and, beyond
    the paper, bounds on the step factor :math:`\Phi`: an accepted step grows by at most ``growth`` (>= 1), a restart
    shrinks it by at least ``shrink`` (in [LEAST_FACTOR, 1)) and at most ``LEAST_FACTOR`` -- eq. (30) assumes the error
    falls as :math:`(S \, \Delta t^p)^K`; where an iteration stalls instead (a force that is steep in the velocity, such
    as friction below ``v_slip``), :math:`\Phi` of a failed step is close to 1 and the restarts would creep -- and a
    floor ``dt_min`` below which a step that cannot converge stops the run.

    Parameters
    ----------
    dt : float
        The first step (s), > 0.
    dt_max : float
        The upper bound :math:`\Delta t_{lim}` of the step (s), >= ``dt``.
    phi : float
        The trapezoidal weight, in ``[0, 1]`` (eqs. 22-24).
    iterations : int
        :math:`K_d`, the target number of fixed-point iterations per step (eq. 30), >= 2.
    tolerance : float
        TOL, the relative change at which the fixed-point iteration stops (eqs. 47-48), > 0.
    order : float
        p of eq. (30), > 0.
    growth : float
        The largest factor by which an accepted step grows, >= 1.
    shrink : float
        The least factor by which a restarted step shrinks, in ``[LEAST_FACTOR, 1)``.
    dt_min : float
        The smallest step (s), in ``(0, dt]``: a step that cannot converge above it stops the run.

    Raises
    ------
    ValueError
        A field is not finite or out of its range (the message names it, ``[solver] <key>``).
    """

    dt: float
    dt_max: float
    phi: float = 0.5
    iterations: int = 10
    tolerance: float = 5e-4
    order: float = 2.0
    growth: float = 1.25
    shrink: float = 0.5
    dt_min: float = 1e-9

    def __post_init__(self):
        def bad(name, rule):
            raise ValueError(f"[solver] {name} = {getattr(self, name)!r}: {rule}")

        for f in fields(self):
            value = getattr(self, f.name)
            if (not isinstance(value, (int, float, np.floating, np.integer)) or isinstance(value, bool)
                    or not math.isfinite(value)):
                bad(f.name, "must be a finite number")
        if not 0.0 <= self.phi <= 1.0:
            bad("phi", "must be in [0, 1] (the trapezoidal weight of Zohdi 2014, eq. 22)")
        if not isinstance(self.iterations, (int, np.integer)) or self.iterations < 2:
            bad("iterations", "must be an integer >= 2 (K_d, the target number of fixed-point iterations, eq. 30: "
                "the first iterate's relative change is 1 by construction, so one iteration never meets a tolerance)")
        if self.tolerance <= 0.0:
            bad("tolerance", "must be > 0 (TOL of the fixed-point iteration, eqs. 47-48)")
        if self.order <= 0.0:
            bad("order", "must be > 0 (p of eq. 30; 2 for a second-order system)")
        if self.dt <= 0.0:
            bad("dt", "must be > 0 (s, the first step)")
        if self.dt_max < self.dt:
            bad("dt_max", f"must be >= dt = {self.dt!r} s (the upper bound Delta t_lim of the step)")
        if self.growth < 1.0:
            bad("growth", "must be >= 1 (the largest factor by which a step may grow)")
        if not LEAST_FACTOR <= self.shrink < 1.0:
            bad("shrink", f"must be in [{LEAST_FACTOR}, 1) (a restarted step shrinks at least by this factor)")
        if not 0.0 < self.dt_min <= self.dt:
            bad("dt_min", f"must be in (0, dt = {self.dt!r}] s")

    def factor(self, error: float, K: int) -> float:
        r"""The step factor :math:`\Phi_K` of eq. (30) / Algorithm 1 (4c) for the relative iteration error ``error``
        :math:`D_K` after ``K`` iterations: :math:`(\mathrm{TOL}/D_0)^{1/(p K_d)} / (D_K/D_0)^{1/(p K)}` with
        :math:`D_0 = 1` (the first iterate's relative
        change is 1 by construction), clipped to ``[LEAST_FACTOR, growth]``.

        Parameters
        ----------
        error : float
            The relative change of the last iterate (D_K, dimensionless).
        K : int
            The number of iterations done, >= 1.

        Returns
        -------
        float
            :math:`\Phi_K`, the factor the next step is multiplied by.
        """
        if error <= 0.0:
            return self.growth
        p = self.order
        phi = self.tolerance ** (1.0 / (p * self.iterations)) / error ** (1.0 / (p * K))
        return min(self.growth, max(LEAST_FACTOR, phi))

    def restart_factor(self, phi: float) -> float:
        r"""The factor of a restarted step: :math:`\Phi_K`, but at least ``shrink`` and at most ``LEAST_FACTOR``.

        Parameters
        ----------
        phi : float
            :math:`\Phi_K` of the failed step (:meth:`factor`).

        Returns
        -------
        float
            The factor the restarted step is multiplied by, in ``[LEAST_FACTOR, shrink]``.
        """
        return max(LEAST_FACTOR, min(phi, self.shrink))


STEPPING_KEYS = {f.name for f in fields(ZohdiStepping)}


@dataclass(frozen=True)
class ElectricalSpec:
    """The ``[electrical]`` table and the electrodes of the ``[[walls]]``.

    Parameters
    ----------
    scheme : str
        How the current is solved: ``"kirchhoff"`` or ``"zohdi"`` (module docstring).
    absorption : float
        The fraction a of the Joule heat the particles absorb (Zohdi 2014, eq. 35), in ``[0, 1]``.
    electrodes : dem.network.current.Electrodes
        The electrified walls, each at a potential (V) or a current (A).
    tolerance : float
        Zohdi's iteration: the largest change per sweep relative to the largest wall value at which it stops, > 0.
    sweeps : int
        Zohdi's iteration: the most sweeps per refresh, >= 1.
    floating : str
        ``"allow"`` (particles touching no electrode carry no current) or ``"error"`` (stop, naming them).
    """

    scheme: str
    absorption: float
    electrodes: Electrodes
    tolerance: float = 1e-8
    sweeps: int = 10_000
    floating: str = "allow"


def _number(table, section, key, default=None):
    if key not in table:
        return default
    v = table[key]
    if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v):
        raise ValueError(f"[{section}] {key} = {v!r}: must be a finite number")
    return v


def parse_stepping(table: dict) -> ZohdiStepping:
    """The stepping parameters of ``[solver]`` (``dt`` required).

    Parameters
    ----------
    table : dict
        The ``[solver]`` table.

    Returns
    -------
    ZohdiStepping
        The stepping; ``dt_max`` defaults to ``dt``.

    Raises
    ------
    ValueError
        ``dt`` is missing or not a number, or a key is out of its range.
    """
    if "dt" not in table:
        raise ValueError("[solver] dt: required with [contact] law = \"zohdi\" (the first step, s)")
    if isinstance(table["dt"], str):
        raise ValueError(f"[solver] dt = {table['dt']!r}: with law = \"zohdi\" a number (s, the first step; the "
                         f"fixed-point iteration adapts it)")
    values = {k: _number(table, "solver", k) for k in STEPPING_KEYS if k in table}
    values.setdefault("dt_max", values["dt"])
    if "iterations" in values and float(values["iterations"]).is_integer():
        values["iterations"] = int(values["iterations"])
    return ZohdiStepping(**values)


def parse_electrical(doc: dict, walls, physics) -> ElectricalSpec | None:
    """The current's scheme and electrodes, or None without ``"electrical"`` physics (where electrode keys are
    refused).

    Parameters
    ----------
    doc : dict
        The parsed TOML document (its ``[electrical]`` table and ``[[walls]]``).
    walls : sequence of dem.geometry.walls.Wall
        The scene's walls, in the order of ``[[walls]]``.
    physics : sequence of str
        The scene's ``[scene] physics``.

    Returns
    -------
    ElectricalSpec or None
        The current's spec, or None without ``"electrical"`` physics.

    Raises
    ------
    ValueError
        A bad key, electrode keys without ``"electrical"`` physics, no electrode, or (Kirchhoff's scheme) no
        electrode at a fixed potential.
    """
    tables = doc.get("walls", [])
    names = [w.name for w in walls]
    marked = [(k, t) for k, t in enumerate(tables) if isinstance(t, dict) and set(t) & ELECTRODE_KEYS]
    if "electrical" not in physics:
        if marked:
            raise ValueError(f"[walls][{marked[0][0]}] {sorted(set(marked[0][1]) & ELECTRODE_KEYS)[0]}: only with "
                             f"\"electrical\" in [scene] physics")
        if "electrical" in doc:
            raise ValueError("[electrical]: only with \"electrical\" in [scene] physics")
        return None
    table = doc.get("electrical", {})
    if not isinstance(table, dict):
        raise ValueError("[electrical]: must be a table")
    scheme = check_scheme(table.get("scheme", "kirchhoff"))
    if scheme == "zohdi" and "mechanical" not in physics:
        raise ValueError("[electrical] scheme = \"zohdi\": the paper's iteration runs with moving particles; a "
                         "static packing takes scheme = \"kirchhoff\"")
    absorption = check_absorption(table.get("absorption", 1.0))
    tolerance = _number(table, "electrical", "tolerance", 1e-8)
    if tolerance <= 0:
        raise ValueError(f"[electrical] tolerance = {tolerance!r}: must be > 0 (largest change per sweep relative to "
                         f"the largest wall value)")
    sweeps = table.get("sweeps", 10_000)
    if not isinstance(sweeps, int) or isinstance(sweeps, bool) or sweeps < 1:
        raise ValueError(f"[electrical] sweeps = {sweeps!r}: must be an integer >= 1")
    floating = table.get("floating", "allow")
    if floating not in ("allow", "error"):
        raise ValueError(f"[electrical] floating = {floating!r}: must be \"allow\" (groups touching no electrode carry "
                         f"no current) or \"error\" (stop, naming them)")
    if not marked:
        raise ValueError("[[walls]] potential or current: \"electrical\" physics needs at least one electrode (a wall "
                         "with a potential in V or a current in A)")
    potential, current, which = [], [], []
    for k, t in marked:
        keys = set(t) & ELECTRODE_KEYS
        if len(keys) > 1:
            raise ValueError(f"[walls][{k}]: give potential or current, not both")
        if scheme == "zohdi" and "potential" in keys:
            raise ValueError(f"[walls][{k}] potential: scheme = \"zohdi\" takes each electrified wall's current "
                             f"J_ext (Zohdi 2014, Remark 2), not a potential")
        value = _number(t, f"walls][{k}", keys.pop())
        potential.append(value if "potential" in t else np.nan)
        current.append(value if "current" in t else np.nan)
        which.append(k)
    electrodes = Electrodes(tuple(names[k] for k in which), tuple(which), np.array(potential, dtype=float),
                            np.array(current, dtype=float))
    if scheme == "kirchhoff" and not np.any(electrodes.fixed_potential):
        raise ValueError("[[walls]] potential: scheme = \"kirchhoff\" needs one electrode at a fixed potential (e.g. "
                         "potential = 0.0 on the grounded wall) as the reference")
    return ElectricalSpec(scheme, absorption, electrodes, float(tolerance), sweeps, floating)


def zohdi_motion(doc: dict, particles, solver, physics, start, walls, gravity, velocity, phases, wall_phases,
                 dimension):
    """The :class:`~dem.scene.motion.MotionSpec` of a scene with ``[contact] law = "zohdi"``.

    Parameters
    ----------
    doc : dict
        The parsed TOML document (its ``[solver]`` and ``[output]`` tables).
    particles : dem.geometry.particles.Particles
        The scene's particles (their mean radius sets the default skin, m).
    solver : dem.scene.parse.SolverSpec
        The scene's solver (its ``t_end``, s, sets the default output interval).
    physics : sequence of str
        The scene's ``[scene] physics`` (not read here).
    start : dict or None
        A saved state (not read here: the spec starts from the scene's particles).
    walls : tuple of dem.geometry.walls.Wall
        The scene's walls.
    gravity : tuple of float
        The gravitational acceleration [x, y, z] (m/s^2).
    velocity : numpy.ndarray or None
        (N, 3) initial velocities (m/s); None: at rest.
    phases : tuple
        The ``[[phases]]`` material changes (not read here: this law takes none).
    wall_phases : tuple
        ``(start time (s), {wall name: inward velocity (m/s)})``, sorted by start.
    dimension : int
        The scene's dimension; must be 3.

    Returns
    -------
    dem.scene.motion.MotionSpec
        The moving part of the scene.

    Raises
    ------
    ValueError
        ``dimension`` is not 3, or a bad ``[solver]`` or ``[output]`` key.
    """
    from dem.scene.motion import MotionSpec, _num

    if dimension != 3:
        raise ValueError("[scene] dimension: law = \"zohdi\" moves spheres (dimension = 3)")
    solver_table = doc.get("solver", {})
    stepping = parse_stepping(solver_table)
    skin = _num(solver_table, "solver", "skin", DEFAULT_SKIN * float(np.mean(particles.radius)), positive=True)
    out = doc.get("output", {})
    output_interval = _num(out, "output", "interval", solver.t_end / 100, positive=True)
    vtu_interval = _num(out, "output", "vtu_interval", 0.0, nonnegative=True)
    frames = out.get("frames", 0)
    if not isinstance(frames, int) or isinstance(frames, bool) or not 0 <= frames <= 1000:
        raise ValueError(f"[output] frames = {frames!r}: must be an integer in [0, 1000] (PNG renderings)")
    control = None
    if "fraction_axis" in out:
        axis = out["fraction_axis"]
        if axis not in ("x", "y", "z"):
            raise ValueError(f"[output] fraction_axis = {axis!r}: must be \"x\", \"y\" or \"z\"")
        control = "xyz".index(axis)
        ends = [w for w in walls if abs(abs(w.normal[control]) - 1.0) < 1e-12]
        if sorted(np.sign(w.normal[control]) for w in ends) != [-1.0, 1.0]:
            raise ValueError(f"[output] fraction_axis = {axis!r}: needs one wall facing +{axis} (the bottom) and one "
                             f"facing -{axis} (the top, which presses)")
    return MotionSpec(dimension, None, velocity, None, walls, gravity, None, stepping.dt, math.inf, skin, 0.0,
                      "trapezoidal", output_interval, vtu_interval, phases=(), start=None, wall_phases=wall_phases,
                      stepping=stepping, control=control, frames=frames)
