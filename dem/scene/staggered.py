r"""The keys only the staggered engine reads (:mod:`dem.engines.staggered`, Zohdi 2014's implicit scheme), as its own
spec (:class:`StaggeredSpec`): the implicit stepping in ``[solver]`` and the powder bed's axis and pictures in
``[output]``; the contact law is ``[contact] law = "zohdi"`` (:mod:`dem.laws.contact.zohdi`), the current
:mod:`dem.scene.electrical`.

* ``[solver]`` -- ``dt`` (the first step, s), ``dt_max`` (:math:`\Delta t_{lim}`, default ``dt``), ``phi``, ``iterations``
  (K_d), ``tolerance`` (TOL), ``order`` (p), ``growth``, ``shrink``, ``dt_min`` (:class:`ZohdiStepping`); ``skin``
  (m, default ``STAGGERED_SKIN`` x the mean radius);
* ``[output]`` -- ``fraction_axis`` (``"x"``, ``"y"`` or ``"z"``): the axis along which the powder stands on its
  bottom wall and is pressed by its top wall; the run's ``volume_fraction`` is then that of the volume between the
  bottom wall and the lowest point the top wall has reached (Sec. 7, Remark 1), and ``bed_fraction`` the bulk
  fraction of the bed up to its surface; ``frames`` (PNG renderings over the run, in the style of Fig. 8).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from dem.scene.schema import number

LEAST_FACTOR = 0.05  # the step factor Phi never goes below this (one restart shrinks the step at most 20 x)
STAGGERED_SKIN = 0.5  # x the mean radius: a step of the implicit scheme moves particles far more than a Verlet step


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
class StaggeredSpec:
    """What the staggered engine reads of a scene beyond the moving part every engine reads
    (:class:`dem.scene.motion.MotionSpec`).

    Parameters
    ----------
    stepping : ZohdiStepping
        The implicit stepping (Zohdi 2014, eqs. 22-30).
    control : int or None
        The axis (0, 1, 2) the powder bed stands and is pressed along (``[output] fraction_axis``); None: none.
    frames : int
        The number of rendered frames (PNG) over the run, in [0, 1000].
    """

    stepping: ZohdiStepping
    control: int | None = None
    frames: int = 0


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
    values = {k: number(table, "solver", k) for k in STEPPING_KEYS if k in table}
    values.setdefault("dt_max", values["dt"])
    if "iterations" in values and float(values["iterations"]).is_integer():
        values["iterations"] = int(values["iterations"])
    return ZohdiStepping(**values)


def parse_staggered(doc: dict, walls, dimension: int) -> StaggeredSpec:
    """The staggered engine's own keys of a scene (module docstring).

    Parameters
    ----------
    doc : dict
        The parsed TOML document (its ``[solver]`` and ``[output]`` tables).
    walls : tuple of dem.geometry.walls.Wall
        The scene's walls (the bottom and top of ``fraction_axis``).
    dimension : int
        The scene's dimension; must be 3.

    Returns
    -------
    StaggeredSpec
        The spec.

    Raises
    ------
    ValueError
        ``dimension`` is not 3, or a bad ``[solver]`` or ``[output]`` key.
    """
    if dimension != 3:
        raise ValueError("[scene] dimension: law = \"zohdi\" moves spheres (dimension = 3)")
    stepping = parse_stepping(doc.get("solver", {}))
    out = doc.get("output", {})
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
    return StaggeredSpec(stepping, control, frames)
