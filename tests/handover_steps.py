"""The record the hand-over's moving-run tests keep (tests/test_handover.py, tests/test_neck_nodes_handover.py): the
change of a conductance across every thermal step that hands particles over."""

import numpy as np


def record_handovers(engine, conductance, also=None) -> tuple[list, list]:
    """Have ``engine`` record, at every thermal step that hands particles over, the relative change of
    ``conductance(engine, steps)`` across it (the same contacts, the hand-over steps before and after the step) and
    what ``also(before)`` returns, ``before`` the conductance before the step.

    Parameters
    ----------
    engine : dem.engines.verlet.engine.VerletEngine
        The engine, not yet run; its thermal step is wrapped.
    conductance : callable
        ``conductance(engine, steps)``: a conductance (W/K) of the contacts now with the hand-over steps ``steps``.
    also : callable or None
        Called after each such step with the conductance before it (W/K); None: nothing more is kept.

    Returns
    -------
    tuple of list
        ``(jumps, also_kept)``: the relative changes (dimensionless) and what ``also`` returned, filled as the engine
        runs.
    """
    th, step = engine.thermal, engine.thermal.step
    jumps, kept = [], []

    def recorded(mech, dt):
        before = th.handover.steps.copy()
        step(mech, dt)
        if np.any(th.handover.steps != before):
            old = conductance(engine, before)
            jumps.append(conductance(engine, th.handover.steps) / old - 1.0)
            if also is not None:
                kept.append(also(old))

    th.step = recorded
    return jumps, kept
