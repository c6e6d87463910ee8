r"""The current of a scene (``"electrical"`` physics, read by the static and the staggered engines): the
``[electrical]`` table and the electrodes among the ``[[walls]]``.

* ``[electrical]`` -- ``scheme`` (``"kirchhoff"`` or ``"zohdi"``), ``absorption`` (a of Zohdi 2014, eq. 35),
  ``floating`` (``"allow"``: particles touching no electrode carry no current; ``"error"``: stop, naming them), and for
  Zohdi's iteration ``tolerance`` (largest change per sweep relative to the largest wall value) and ``sweeps`` (at most
  per refresh);
* ``[[walls]]`` -- ``potential`` (V) or ``current`` (A into the packing; Zohdi's scheme: the wall's J_ext) makes a
  wall an electrode; ``[material] electrical_conductivity`` (S/m) is :math:`\sigma`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dem.network.current import Electrodes, check_absorption, check_scheme
from dem.scene.schema import number

ELECTRODE_KEYS = {"potential", "current"}


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
    tolerance = number(table, "electrical", "tolerance", 1e-8)
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
        value = number(t, f"walls][{k}", keys.pop())
        potential.append(value if "potential" in t else np.nan)
        current.append(value if "current" in t else np.nan)
        which.append(k)
    electrodes = Electrodes(tuple(names[k] for k in which), tuple(which), np.array(potential, dtype=float),
                            np.array(current, dtype=float))
    if scheme == "kirchhoff" and not np.any(electrodes.fixed_potential):
        raise ValueError("[[walls]] potential: scheme = \"kirchhoff\" needs one electrode at a fixed potential (e.g. "
                         "potential = 0.0 on the grounded wall) as the reference")
    return ElectricalSpec(scheme, absorption, electrodes, float(tolerance), sweeps, floating)
