"""A contact law as a named choice of sub-models, and what the engines read of it.

A :class:`Composition` names one sub-model per slot; each sub-model is one small module of a slot's folder
(``normal/``, ``damping/``, ``tangential/``, ``adhesion/``, ``state/``, ``drag/``). :class:`Law` puts one together:
the histories, the particle state, the Python hooks the engines call before they run (``initial_state``,
``time_steps``, ...), the material and its parameters. The compiled kernels are put together at compile time by
:mod:`dem.laws.contact.binding`.

A sub-model module defines (SI units; ``at`` is ``(c,)`` for pair ``c`` or ``(k, m)`` for particle k on wall m, and
``col`` the first of its columns in the contact's history, both indices into the history arrays ``hist_in`` (read)
and ``hist`` (written); ``contact`` is ``(delta, d, n, vr, vn)``: the overlap, the distance of the centres (of the
centre from the wall), the unit normal from j (the wall) to i, the relative surface velocity and its normal part;
every kernel ``numba.njit`` with ``inline="always"``):

* every slot: ``PARAMS``, ``(pack, size)``: the function that packs a material into the float64 block its kernels
  read and the block's length, or None (sub-models with one pack function share one block: a paper's material is
  one block); ``FIELDS``, the material fields it reads,
  each ``name: (kind, unit)`` with kind ``"positive"``, ``"nonnegative"``, ``"number"`` or ``"flag"``, optionally
  ``check(material)`` (a range the kinds do not say: ``ValueError`` naming the field), and ``SCHEMA_ROWS``, their
  rows of the scene schema (:mod:`dem.scene.schema`); ``PAIR_HISTORY`` and ``WALL_HISTORY``,
  the names of its history columns (the slots' columns follow each other in the order normal, damping, tangential,
  adhesion), and ``forget(at, col, hist_in, hist)`` (the contact opened; whether it had a history);
* ``normal``: ``pair(at, col, hist_in, hist, state, T, i, j, contact, ri, rj, p, const)`` and ``wall(at, col,
  hist_in, hist, state, T, k, contact, rk, p)`` -> ``(f_el, k_n, a, f_min, soft, r_eff)``: the elastic (and
  plastic) normal force, the contact's stiffness (N/m), its size (a contact radius, m, or area, m^2), the largest
  attraction (N, <= 0), the factor that softens friction with temperature (1 without) and the effective radius;
  ``pair_constants(ri, rj, p)`` and ``PAIR_CONSTANTS`` (numbers of the radii alone kept per pair); optionally
  ``GUARDS`` (a contact without its history has no other, and the other slots' ``forget`` is to zero their
  columns: an open contact is forgotten with one read, a closed one's other columns zeroed unread); ``STATE``, the
  ``state`` sub-model it reads particles' state from (None: none); ``time_steps(material, mass, inertia, radius,
  m_mean)`` -> ``(dt, stable)``;
* ``damping``: ``pair`` of ``(state, i, j, f_el, delta_dot, k_n, p)`` and ``wall`` of
  ``(state, k, f_el, delta_dot, k_n, p)``, each -> ``(f_n, eta)``: the normal force with its viscous part and the
  viscous coefficient (kg/s); ``STATE``;
* ``adhesion``: ``pair(at, col, hist_in, hist, contact, f_el, k_n, a, r_eff, ri, rj, p)`` and ``wall(at, col,
  hist_in, hist, contact, f_el, k_n, a, rk, p)`` -> ``(f_el, k_n, a, load)``: the normal force with the adhesion,
  and the load friction resists (without adhesion that load is ``f_n - f_min``); ``reach(at, col, hist)``, how far
  beyond touching the contact acts, and ``largest_reach(material, radius)``; ``NORMALS``, the normal sub-models it
  applies to;
* ``tangential``: ``pair`` of ``(at, col, hist_in, hist, contact, planar, f_n, load, k_n, a, eta, soft, dt, p)``
  and ``wall`` of ``(at, col, hist_in, hist, contact, f_n, load, k_n, a, eta, soft, dt, p)``, each -> ``(f_n, ft0,
  ft1, ft2)``; ``SPINS``
  (its forces make torques);
* ``state``: ``PARTICLE_STATE``, ``initial_state(material, T, mass)``, ``reference_radius(material, radius, T)`` and
  ``update_particles(elapsed, T0, T_rate, T, radius, radius_ref, state, uniform, p, t0, dt)`` (compiled, not
  inlined; returns whether a radius changed);
* ``drag``: ``drag(k, radius, p)``, the drag coefficient of particle k (kg/s).
"""

from __future__ import annotations

import dataclasses
import importlib

import numpy as np

from dem.laws.fields import check_fields

SLOTS = ("normal", "damping", "tangential", "adhesion", "state", "drag")
_HISTORY_SLOTS = ("normal", "damping", "tangential", "adhesion")  # the order of their history columns


@dataclasses.dataclass(frozen=True)
class Composition:
    """A contact law as the sub-model of each slot (module names within the slot's folder of
    :mod:`dem.laws.contact`; None: the slot is empty).

    Parameters
    ----------
    normal : str
        The normal force (``normal/``).
    tangential : str
        The tangential force (``tangential/``).
    state : str
        What each particle carries and what temperature does to it (``state/``).
    damping : str or None
        The viscous part of the normal force (``damping/``).
    adhesion : str or None
        An adhesion on the normal force (``adhesion/``).
    drag : str or None
        A drag on every particle (``drag/``).
    material : str or None
        The module whose ``Material`` dataclass (and ``SCHEMA_ROWS``) the law takes; None: a dataclass of the
        sub-models' ``FIELDS`` (and their ``SCHEMA_ROWS``).
    """

    normal: str
    tangential: str
    state: str
    damping: str | None = None
    adhesion: str | None = None
    drag: str | None = None
    material: str | None = None


def _module(slot: str, name: str | None):
    return None if name is None else importlib.import_module(f"dem.laws.contact.{slot}.{name}")


def _generated_material(law: "Law", modules) -> type:
    """A frozen dataclass of the sub-models' ``FIELDS`` (the scene's ``density`` last), checked as
    :func:`dem.laws.fields.check_fields` checks a material."""
    fields = {}
    for module in modules:
        fields.update(module.FIELDS)
    fields.setdefault("density", ("positive", "kg/m^3"))
    positive = {key: unit for key, (kind, unit) in fields.items() if kind == "positive"}
    nonnegative = {key: unit for key, (kind, unit) in fields.items() if kind == "nonnegative"}
    flags = tuple(key for key, (kind, _) in fields.items() if kind == "flag")

    checks = [module.check for module in modules if hasattr(module, "check")]

    def post_init(self):
        check_fields(self, "contact", positive, nonnegative, flags=flags)
        for check in checks:
            check(self)

    def params(self):
        return law.params(self)

    name = law.NAME
    return dataclasses.make_dataclass(
        f"{name}_material", [(key, bool if kind == "flag" else float) for key, (kind, _) in fields.items()],
        namespace={"__post_init__": post_init, "params": params, "law": name,
                   "__doc__": f"Material of the contact law {name!r}: the fields of its sub-models."},
        frozen=True)


class Law:
    """The contact law ``name`` of :data:`dem.laws.contact.CONTACT_LAWS`, put together from its sub-models (module
    docstring): what the engines read of a law (``NAME``, ``Material``, the histories' and the state's column names,
    ``SPINS``, ``DRAG``, ``SCHEMA_ROWS`` and the Python hooks).

    Parameters
    ----------
    name : str
        The law's name.
    composition : Composition
        Its sub-models.

    Raises
    ------
    ValueError
        An adhesion on a normal sub-model it does not apply to, or a sub-model that reads a state the composition
        does not carry.
    """

    def __init__(self, name: str, composition: Composition):
        self.NAME = name
        self.composition = composition
        self.modules = {slot: _module(slot, getattr(composition, slot)) for slot in SLOTS}
        normal, adhesion, state = self.modules["normal"], self.modules["adhesion"], self.modules["state"]
        if adhesion is not None and composition.normal not in adhesion.NORMALS:
            raise ValueError(f"contact law {name!r}: adhesion {composition.adhesion!r} applies to the normal "
                             f"sub-models {', '.join(adhesion.NORMALS)}, not {composition.normal!r}")
        for slot in ("normal", "damping"):
            needs = getattr(self.modules[slot], "STATE", None) if self.modules[slot] is not None else None
            if needs is not None and needs != composition.state:
                raise ValueError(f"contact law {name!r}: {slot} {getattr(composition, slot)!r} reads the particle "
                                 f"state {needs!r}, the composition carries {composition.state!r}")
        present = [module for module in self.modules.values() if module is not None]
        self.blocks = list(dict.fromkeys(module.PARAMS for module in present if module.PARAMS is not None))
        self.PAIR_HISTORY, self.WALL_HISTORY, self.columns = (), (), {}
        for slot in _HISTORY_SLOTS:
            module = self.modules[slot]
            if module is not None:
                self.columns[slot] = (len(self.PAIR_HISTORY), len(self.WALL_HISTORY))
                self.PAIR_HISTORY += module.PAIR_HISTORY
                self.WALL_HISTORY += module.WALL_HISTORY
        self.PARTICLE_STATE = state.PARTICLE_STATE
        self.PAIR_CONSTANTS = normal.PAIR_CONSTANTS
        self.SPINS = self.modules["tangential"].SPINS
        self.DRAG = self.modules["drag"] is not None
        if composition.material is not None:
            material_module = importlib.import_module(composition.material)
            self.Material, self.SCHEMA_ROWS = material_module.Material, material_module.SCHEMA_ROWS
        else:
            self.Material = _generated_material(self, present)
            rows = {}
            for module in present:
                rows.update({keys: (unit, meaning) for keys, unit, meaning in module.SCHEMA_ROWS})
            rows.setdefault(("density",), ("kg/m³, the `[material]` density", "particle density"))
            self.SCHEMA_ROWS = tuple((keys, unit, meaning) for keys, (unit, meaning) in rows.items())
        self.initial_state, self.reference_radius = state.initial_state, state.reference_radius
        self.time_steps = normal.time_steps

    def __repr__(self) -> str:
        return f"Law({self.NAME!r}, {self.composition!r})"

    def block(self, slot: str) -> int:
        """The index of the parameter block the sub-model of ``slot`` reads.

        Parameters
        ----------
        slot : str
            One of ``SLOTS`` (a slot that is not empty).

        Returns
        -------
        int
            The block's index among the law's blocks, in the order :meth:`params` packs them.
        """
        return self.blocks.index(self.modules[slot].PARAMS)

    def params(self, material) -> np.ndarray:
        """The material as the float64 array the compiled loops take: the blocks of the sub-models, one after the
        other.

        Parameters
        ----------
        material : object
            The law's material.

        Returns
        -------
        numpy.ndarray
            The parameters.
        """
        return np.concatenate([np.asarray(pack(material), dtype=float) for pack, size in self.blocks])

    def largest_reach(self, material, radius: np.ndarray) -> float:
        """The farthest beyond touching any contact of these particles acts (m): the adhesion's, 0 without one.

        Parameters
        ----------
        material : object
            The law's material.
        radius : numpy.ndarray
            (N,) radii (m).

        Returns
        -------
        float
            The largest gap across which a contact acts (m).
        """
        adhesion = self.modules["adhesion"]
        return 0.0 if adhesion is None else adhesion.largest_reach(material, radius)
