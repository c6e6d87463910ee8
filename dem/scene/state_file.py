"""A sample's state on disk: every run leaves one (``state.npz``), and another run starts from it.

:func:`moving_arrays` gives the state of particles that move as a dict of arrays: everything a run needs to go on as
if it had not stopped -- positions, velocities, angular velocities, the forces and torques of the last step (velocity
Verlet starts a step from them), masses, moments of inertia, reference radii, temperatures and ids of the particles,
the contact law's state of each particle and its history of every listed pair and particle-wall pair, each wall's
name, offset, velocity and acceleration, the time, the step count, the time step and the run's counters. A static
packing's state holds its particles only (positions, radii, temperatures, materials, ids, the time). Either holds the
periodic box the particles are in, if any (its lengths, periodic axes and origin, :func:`box_arrays`; a temperature
drop per period is the scene's, not the sample's). :func:`save`
writes either (with the engine's name), :func:`load` reads it back as a dict, refusing files that are not such a
state.

A scene starts from a saved state with ``[start] state = "file.npz"`` (Luding 2005, Sec. 4: a prepared sample is
sintered, a sintered sample is tested; a sintered compact's effective conductivity is measured): its particles come
from the file (with its periodic box, :func:`saved_box`), its walls from the scene, where a wall with the name of a saved wall starts at the saved offset (so the
box stays as it was) and moves by the scene's law. The run's clock and counters go on from the state's: the scene's
times (``t_end``, ``[[phases]]``, ``[temperature]``) are on that clock. Particles that move take their velocities and
contact histories along when the scene has the state's contact law; a static packing takes positions, radii and
temperatures and finds its bonds from the overlaps.
"""

from __future__ import annotations

import pathlib

import numpy as np

from dem.geometry.periodic import PeriodicBox
from dem.output.atomic import read_npz, write_aside

FORMAT = "dem-state-2"
FORMAT_1 = "dem-moving-state-1"  # the Luding law's histories as separate arrays (read and converted)
COMMON_KEYS = ("engine", "t", "steps", "x", "radius", "T", "id")
MOVING_KEYS = ("v", "w", "f", "tau", "mass", "inertia", "radius_ref", "particle_state", "contact_law", "pi", "pj",
               "p_hist", "w_hist", "wall_names", "wall_q", "wall_normal", "wall_dq", "wall_acc", "dimension",
               "height", "dt")
COUNTERS = ("neighbour_rebuilds", "network_assemblies", "network_refreshes")


def moving_arrays(engine) -> dict:
    """The state of an engine with moving particles (its ``mechanics``: state, walls, contact law, histories) as a
    dict of arrays (module docstring).

    Parameters
    ----------
    engine : object
        An engine of moving particles (:mod:`dem.engines.verlet`): its name, time, steps, scene and ``mechanics``
        (:class:`dem.engines.verlet.mechanics.MechanicalModel`).

    Returns
    -------
    dict
        The state's arrays, SI units.
    """
    mech = engine.mechanics
    s = mech.state
    data = {"engine": np.array(engine.name), "t": np.array(engine.t), "steps": np.array(engine.steps),
            "x": s.x, "radius": s.radius, "T": s.T, "id": engine.scene.particles.id,
            "material": engine.scene.particles.material,
            "v": s.v, "w": s.w, "f": s.f, "tau": s.tau, "mass": s.mass, "inertia": s.inertia,
            "radius_ref": s.radius_ref, "particle_state": mech.particle_state, "contact_law": np.array(mech.law.NAME),
            "pi": mech.pi, "pj": mech.pj, "p_hist": mech.p_hist, "w_hist": mech.w_hist,
            "wall_names": np.array([w.name for w in mech.walls], dtype=str), "wall_q": mech.w.q,
            "wall_normal": mech.w.normal,
            "wall_dq": mech.w.dq, "wall_acc": mech.w.acc, "dimension": np.array(s.dimension),
            "height": np.array(np.nan if s.height is None else s.height), "dt": np.array(engine.dt),
            "neighbour_rebuilds": np.array(mech.rebuilds), **box_arrays(mech.periodic_box)}
    thermal = getattr(engine, "thermal", None)
    if thermal is not None and hasattr(thermal, "assemblies"):
        data.update(network_assemblies=np.array(thermal.assemblies), network_refreshes=np.array(thermal.refreshes))
    return data


def box_arrays(box: PeriodicBox | None) -> dict:
    """The periodic box ``box`` as arrays of a state (none without a box).

    Parameters
    ----------
    box : dem.geometry.periodic.PeriodicBox or None
        The box, or None.

    Returns
    -------
    dict
        Its lengths (m), periodic axes and origin (m) as arrays; empty without a box.
    """
    if box is None:
        return {}
    return {"box_lengths": box.lengths, "box_periodic": np.array(box.periodic), "box_origin": box.origin}


def saved_box(data: dict) -> PeriodicBox | None:
    """The periodic box of a loaded state (:func:`box_arrays`), or None.

    Parameters
    ----------
    data : dict
        A loaded state (:func:`load`).

    Returns
    -------
    dem.geometry.periodic.PeriodicBox or None
        The box, or None where the state has none.
    """
    if "box_lengths" not in data:
        return None
    return PeriodicBox(data["box_lengths"], tuple(bool(p) for p in data["box_periodic"]), data["box_origin"])


def save(data: dict, path) -> pathlib.Path:
    """Write the state ``data`` (an engine's ``state()``) to ``path`` (``.npz``), written aside and renamed: an
    interrupted save never leaves half a state.

    Parameters
    ----------
    data : dict
        The state's arrays.
    path : str or pathlib.Path
        The ``.npz`` file to write (its folder is made).

    Returns
    -------
    pathlib.Path
        The file written.
    """
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    return write_aside(path, lambda fh: np.savez(fh, format=np.array(FORMAT), **data), "wb")


def load(path) -> dict:
    """The saved state at ``path`` as a dict (arrays, with its scalars and names as Python values; ``moving`` says
    whether it has the velocities and histories of particles that move); ``ValueError`` naming the file when it is
    not one.

    Parameters
    ----------
    path : str or pathlib.Path
        The ``.npz`` file (a run's ``state.npz``).

    Returns
    -------
    dict
        The state (SI units).

    Raises
    ------
    ValueError
        The file cannot be read, is not a saved state, or is incomplete.
    """
    path = pathlib.Path(path)
    data = read_npz(path, "[start] state")
    if str(data.get("format", "")) == FORMAT_1:
        data = _from_format_1(data)
    if str(data.get("format", "")) != FORMAT:
        raise ValueError(f"[start] state = {str(path)!r}: not a saved state (format {FORMAT}, or a run's state.npz)")
    moving = "v" in data
    missing = [k for k in COMMON_KEYS + (MOVING_KEYS if moving else ()) if k not in data]
    if missing:
        raise ValueError(f"[start] state = {str(path)!r}: incomplete (no {missing[0]})")
    return normalised(data)


def _from_format_1(data: dict) -> dict:
    """A state of the first format (the Luding 2005 law's velocity-Verlet run, its histories as separate arrays,
    no ids) in today's."""
    out = {k: v for k, v in data.items() if k not in ("k1f", "p_dmax", "p_k1last", "p_xi", "w_dmax", "w_k1last",
                                                      "w_xi")}
    out.update(format=np.array(FORMAT), engine=np.array("verlet"), contact_law=np.array("luding"),
               particle_state=data["k1f"][:, None], p_hist=np.column_stack([data["p_dmax"], data["p_k1last"],
                                                                             data["p_xi"]]),
               w_hist=np.concatenate([data["w_dmax"][..., None], data["w_k1last"][..., None], data["w_xi"]], axis=-1))
    out.setdefault("id", np.arange(len(data["x"])))
    out.setdefault("wall_normal", np.zeros((len(data["wall_names"]), 3)))  # not kept then: no box from them
    return out


def normalised(data: dict) -> dict:
    """The scalars and names of a loaded state (or checkpoint) as Python values.

    Parameters
    ----------
    data : dict
        The loaded arrays, changed in place.

    Returns
    -------
    dict
        ``data``, with ``moving`` set.
    """
    data["engine"] = str(data["engine"])
    data["t"], data["steps"] = float(data["t"]), int(data["steps"])
    data["moving"] = "v" in data
    if data["moving"]:
        data["height"] = None if not np.isfinite(data["height"]) else float(data["height"])
        data["dimension"] = int(data["dimension"])
        data["wall_names"] = [str(x) for x in data["wall_names"]]
        data["contact_law"] = str(data["contact_law"])
    for key in COUNTERS:
        if key in data:
            data[key] = int(data[key])
    return data
