"""A moving-particle state on disk: save a prepared or sintered sample, start another run from it.

``save(sim, path)`` writes one ``.npz`` with everything a run needs to go on as if it had not stopped: positions,
velocities, angular velocities, the forces and torques of the last step (velocity Verlet starts a step from them),
masses, moments of inertia, reference radii, temperatures and stiffness factors of the particles; the contact history of every listed pair (``delta_max``, the factor of the last step, the tangential
spring) and of every particle-wall pair; each wall's name, offset, velocity and acceleration; the time, the step
count and the time step. ``load(path)`` reads it back as a dict (refusing files that are not such a state).

A scene starts from a saved state with ``[start] state = "file.npz"`` (Luding 2005, Sec. 4: a prepared sample is
sintered, a sintered sample is tested): its particles come from the file, its walls from the scene, where a wall
with the name of a saved wall starts at the saved offset (so the box stays as it was) and moves by the scene's
law. The run's clock starts at zero.
"""

from __future__ import annotations

import pathlib

import numpy as np

FORMAT = "dem-moving-state-1"
PARTICLE_KEYS = ("x", "v", "w", "f", "tau", "mass", "inertia", "radius", "radius_ref", "T", "k1f")
PAIR_KEYS = ("pi", "pj", "p_dmax", "p_k1last", "p_xi")
WALL_KEYS = ("w_dmax", "w_k1last", "w_xi")


def arrays(sim) -> dict:
    """The state of ``sim`` (a :class:`dem.engines.verlet.engine.Simulation`) as a dict of arrays (what :func:`save` writes; a
    checkpoint adds the thermal network's temperatures and heat balance)."""
    mech = sim.mechanics
    s = mech.state
    data = {"format": np.array(FORMAT), "dimension": np.array(s.dimension),
            "height": np.array(np.nan if s.height is None else s.height), "t": np.array(mech.t),
            "steps": np.array(mech.steps), "dt": np.array(mech.dt),
            "wall_names": np.array([w.name for w in mech.walls], dtype=str), "wall_q": mech.w.q,
            "wall_dq": mech.w.dq, "wall_acc": mech.w.acc}
    data.update({k: getattr(s, k) for k in PARTICLE_KEYS if hasattr(s, k)})
    data["k1f"] = mech.k1f
    data.update({k: getattr(mech, k) for k in PAIR_KEYS + WALL_KEYS})
    if sim.thermal is not None:
        th = sim.thermal
        data.update(thermal_T=th.T, thermal_rate=th.rate, thermal_energy0=np.array(th.energy0),
                    heat_keys=np.array(list(th.heat_in), dtype=str),
                    heat_values=np.array(list(th.heat_in.values()), dtype=float))
    return data


def save(sim, path) -> pathlib.Path:
    """Write the state of ``sim`` (a :class:`dem.engines.verlet.engine.Simulation`) to ``path`` (``.npz``)."""
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    data = arrays(sim)
    tmp = path.with_name(path.name + ".part")
    with tmp.open("wb") as fh:  # written aside, then renamed: an interrupted save never leaves half a state
        np.savez(fh, **data)
    tmp.replace(path)
    return path


def load(path) -> dict:
    """The saved state at ``path`` as a dict of arrays; ``ValueError`` naming the file when it is not one."""
    path = pathlib.Path(path)
    try:
        with np.load(path, allow_pickle=False) as f:
            data = {k: f[k] for k in f.files}
    except (OSError, ValueError) as exc:
        raise ValueError(f"[start] state = {str(path)!r}: cannot be read as a saved state ({exc})") from None
    if str(data.get("format", "")) != FORMAT:
        raise ValueError(f"[start] state = {str(path)!r}: not a saved moving-particle state (format {FORMAT})")
    missing = [k for k in PARTICLE_KEYS + PAIR_KEYS + WALL_KEYS if k not in data]
    if missing:
        raise ValueError(f"[start] state = {str(path)!r}: incomplete (no {missing[0]})")
    return normalised(data)


def normalised(data: dict) -> dict:
    """The scalars and names of a loaded state as Python values."""
    data["height"] = None if not np.isfinite(data["height"]) else float(data["height"])
    data["dimension"] = int(data["dimension"])
    data["wall_names"] = [str(x) for x in data["wall_names"]]
    return data
