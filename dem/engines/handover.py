"""The conductances of a moving run's contacts through the hand-over from a pair-neck reading to the union of
spheres (:mod:`dem.geometry.handover`): the state the hand-over carries through a run (the steps of each particle's
hand-over, the solid radii) and the bonds it reads, shared by the engines whose particles move
(:mod:`dem.engines.contact_heat`, :mod:`dem.engines.staggered.heat`).

A bond's conductance is ``(1 - w) K_pair + w K_union``: ``K_pair`` the scene's law on the scene's pair-neck reading of
the particles' radii, ``K_union`` the same law on the union reading (:func:`dem.laws.conductance.bond_conductances`
with ``neck = "union"``) of the solid radii, ``w`` the bond's hand-over weight
(:func:`dem.geometry.handover.bond_weights`). Where no particle is handed over, the bonds are the pair reading's
alone, computed as without the hand-over.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from fem_neck.geometry import max_overlap

from dem.geometry.bonds import find_bonds
from dem.geometry.handover import advance, bond_weights, solid_radii, weights
from dem.geometry.necks import PAIR_READINGS, necks_meeting
from dem.laws.conductance import ConductanceSpec, bond_conductances
from dem.network.heat import bonds_and_conductances


class Handover:
    """The hand-over of a run's particles (module docstring).

    Parameters
    ----------
    spec : dem.laws.conductance.ConductanceSpec
        The scene's conductance law and pair-neck reading.
    radius : numpy.ndarray
        The particles' radii at the start, m (the solid radii before any hand-over).
    """

    def __init__(self, spec: ConductanceSpec, radius: np.ndarray):
        self.spec = spec
        self.steps = np.zeros(len(radius), dtype=np.int64)  # per particle, the steps of its hand-over so far
        self.solid_radius = np.asarray(radius, dtype=float).copy()  # m: the last solution where the weight is > 0

    @staticmethod
    def applies(spec: ConductanceSpec, dimension: int) -> bool:
        """Whether a run hands particles over: a law on a pair-neck reading (``newton``, ``first``, ``coble``), in 3D.

        Parameters
        ----------
        spec : dem.laws.conductance.ConductanceSpec
            The scene's conductance law and neck reading.
        dimension : int
            The run's dimension, 2 or 3.

        Returns
        -------
        bool
            Whether it does.
        """
        return spec.law != "zohdi" and spec.neck in PAIR_READINGS and dimension == 3

    @property
    def weight(self) -> np.ndarray:
        """Per particle its hand-over weight (:func:`dem.geometry.handover.weights`: 0 the pair reading, 1 the
        union)."""
        return weights(self.steps)

    def solid_radii(self, radius: np.ndarray) -> np.ndarray:
        """Per particle its solid radius as the last update left it, m: ``radius`` where not handed over.

        Parameters
        ----------
        radius : numpy.ndarray
            The particles' radii now, m.

        Returns
        -------
        numpy.ndarray
            The solid radii, m.
        """
        return np.where(self.steps > 0, self.solid_radius, radius)

    def state(self) -> dict:
        """The arrays a checkpoint keeps: ``handover_steps`` and ``solid_radius``."""
        return {"handover_steps": self.steps.copy(), "solid_radius": self.solid_radius.copy()}

    def restore(self, saved: dict) -> None:
        """Go on from a checkpoint's arrays (:meth:`state`); a checkpoint written before the hand-over has none.

        Parameters
        ----------
        saved : dict
            The checkpoint's arrays.
        """
        if "handover_steps" in saved:
            self.steps = np.array(saved["handover_steps"], dtype=np.int64)
            self.solid_radius = np.array(saved["solid_radius"], dtype=float)

    def bonds(self, now, walls, pairs, box, update: bool = False):
        """The bonds of the contacts ``pairs`` and the walls ``walls`` and their conductances (module docstring).

        Parameters
        ----------
        now : dem.geometry.particles.Particles
            The particles now: positions (m), radii (m), materials.
        walls : sequence of dem.geometry.walls.Wall
            The walls that carry a temperature, where they are now.
        pairs : tuple of numpy.ndarray
            ``(i, j)``: the contacts.
        box : dem.geometry.periodic.PeriodicBox or None
            The periodic box; None without one.
        update : bool
            Whether to advance the hand-overs and keep the solid radii of this configuration (a thermal step does;
            an iterate or a snapshot reads them as they are).

        Returns
        -------
        tuple
            ``(bonds, K_pairs, K_walls)``: the bonds (each with the neck of the reading of its larger weight) and
            their conductances (W/K).

        Raises
        ------
        ValueError
            A bond beyond the pair reading's range while that reading still has weight, under
            ``out_of_range = "error"``; a conductance that is not finite.
        """
        spec = self.spec
        if not update and not np.any(self.steps):  # nothing handed over and nothing to update: the pair reading
            return bonds_and_conductances(now, walls, spec, pairs=pairs, box=box)
        pair = find_bonds(now, walls, spec.contact, "clip", pairs=pairs, box=box)
        vectors = pair.vectors(now.position, box)
        normals = np.array([w.normal for w in walls], dtype=float).reshape(-1, 3)[pair.wall_index]
        if update:
            self.steps = advance(self.steps, necks_meeting(now.radius, pair, vectors, normals))
        if not np.any(self.steps):  # nothing handed over: the pair reading alone, as without the hand-over
            return bonds_and_conductances(now, walls, spec, pairs=pairs, box=box,
                                          bonds=pair if spec.out_of_range == "clip" else None)
        weight = self.weight
        w_pair, w_wall = bond_weights(weight, pair)
        K_pair, K_wall = bond_conductances(spec, now, pair, box=box, walls=walls)
        # bonds past the pair reading's range where it still has weight: the scene's out_of_range policy
        past = (pair.h > max_overlap(now.radius[pair.i], now.radius[pair.j])) & (w_pair < 1.0)
        past_wall = (pair.wall_h > now.radius[pair.wall_particle] / 3.0) & (w_wall < 1.0)
        if spec.out_of_range == "error" and (np.any(past) or np.any(past_wall)):
            find_bonds(now, walls, spec.contact, "error", pairs=(pair.i[past], pair.j[past]), box=box)
        if spec.out_of_range == "drop":
            K_pair[past], K_wall[past_wall] = 0.0, 0.0
        solid = solid_radii(now.radius, weight > 0.0, pair.i, pair.j, vectors, pair.wall_particle, normals,
                            pair.wall_l, start=self.solid_radius)
        if update:
            self.solid_radius = solid
        grown = replace(now, radius=solid)
        union = find_bonds(grown, walls, "union", "error", pairs=pairs, box=box)
        n = now.n  # the grown spheres may touch a wall the particle does not: the contacts' wall bonds only
        union = union.subset(slice(None), np.isin(union.wall_index * n + union.wall_particle,
                                                   pair.wall_index * n + pair.wall_particle))
        K_union, K_wall_union = bond_conductances(replace(spec, neck="union"), grown, union, box=box, walls=walls)
        K_pair = (1.0 - w_pair) * K_pair + w_pair * K_union
        K_wall = (1.0 - w_wall) * K_wall + w_wall * K_wall_union
        read, read_wall = w_pair >= 0.5, w_wall >= 0.5
        bonds = replace(pair, a=np.where(read, union.a, pair.a), l_i=np.where(read, union.l_i, pair.l_i),
                        l_j=np.where(read, union.l_j, pair.l_j), wall_a=np.where(read_wall, union.wall_a, pair.wall_a),
                        wall_l=np.where(read_wall, union.wall_l, pair.wall_l))
        return bonds, K_pair, K_wall

    def account(self, bonds) -> dict:
        """The summary's entries of the hand-over, for :func:`dem.laws.verified_range.neck_account`: ``readings`` (bonds
        per reading, those with bonds: the union where a bond's weight is at least 1/2) and ``handed_over``
        (particles), and ``handing_over`` (particles on the way).

        Parameters
        ----------
        bonds : dem.geometry.bonds.Bonds
            The bonds of the contacts now, under the pair reading.

        Returns
        -------
        dict
            ``{"readings": dict, "handed_over": int, "handing_over": int}``.
        """
        union = np.concatenate(bond_weights(self.weight, bonds)) >= 0.5
        counts = {bonds.contact: int(np.count_nonzero(~union)), "union": int(np.count_nonzero(union))}
        readings = {k: v for k, v in counts.items() if v} or {bonds.contact: 0}
        return {"readings": readings,
                "handed_over": int(np.count_nonzero(self.weight == 1.0)),
                "handing_over": int(np.count_nonzero((self.weight > 0.0) & (self.weight < 1.0)))}
