r"""The conductances of a moving run's contacts through the hand-over from a pair-neck reading to the union of
spheres (:mod:`dem.geometry.handover`): the state the hand-over carries through a run (the steps of each particle's
hand-over, the solid radii) and the bonds it reads, shared by the engines whose particles move
(:mod:`dem.engines.contact_heat`, :mod:`dem.engines.staggered.heat`).

A bond's conductance is ``(1 - w) K_pair + w K_union``: ``K_pair`` the scene's law on the scene's pair-neck reading of
the particles' radii, ``K_union`` the same law on the union reading (:func:`dem.laws.conductance.bond_conductances`
with ``neck = "union"``) of the solid radii, ``w`` the bond's hand-over weight
(:func:`dem.geometry.handover.bond_weights`). Where no particle is handed over, the bonds are the pair reading's
alone, computed as without the hand-over. Under ``out_of_range = "drop"`` ``K_pair`` is the drop reading's: 0 on a
bond past the pair reading's range, whose union part still conducts.

**Neck nodes** (``[conductance] nodes = "necks"``, :mod:`dem.network.necks`). A neck node has no conductance to blend:
each particle is an element over its centre and its necks. Through the hand-over the network's nodes are the pair
reading's necks, and each particle's element is :math:`(1 - w) E_\mathrm{pair} + w E_\mathrm{union}`
(:func:`blend_elements`), ``w`` the particle's own weight: :math:`E_\mathrm{pair}` its element on the pair reading of
its radius, :math:`E_\mathrm{union}` on the union reading of the grown spheres (its solid radius, its neighbours'), both
over the same necks (a neck the union hides inside a third sphere has no part in the latter, and no node once both its
particles are handed over: no element has it then). Under ``out_of_range = "drop"`` a pair neck past its range has no
part in :math:`E_\mathrm{pair}` (the pair reading drops it, as the one-node law's ``K_pair`` is 0 there and its
``K_union`` weighed in) and keeps its part in :math:`E_\mathrm{union}`: it has a node once one of its particles has
begun its hand-over, and none before. A sum of elements with positive weights is an element (symmetric, positive
semidefinite, rows summing to zero), so the network stays well posed, and it moves by a hundredth of the difference of
the readings a step, as the one-node law's conductances do. The weight is the particle's, not its bond's (the larger of
its two particles', which the one-node law must take for one conductance per bond): a particle not yet on the way keeps
its pair element even on a bond to a handed-over neighbour, whose own element reads that neck as the union. Where every
particle is handed over the network is the union reading's of the grown spheres; where none is, the pair reading's,
computed as without the hand-over.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from fem_neck.geometry import max_overlap
from fem_neck.geometry.cut_kernels import ends_by_particle

from dem.geometry.bonds import find_bonds
from dem.geometry.handover import advance, bond_weights, solid_radii, weights
from dem.geometry.necks import PAIR_READINGS, necks_meeting
from dem.laws.conductance import ConductanceSpec, bond_conductances
from dem.laws.shared_body import ParticleElements, particle_elements
from dem.network.necks import NeckNetwork, neck_network


@dataclass(frozen=True)
class Reading:
    """The union reading of a step's contacts through the hand-over (:meth:`Handover.bonds`).

    Parameters
    ----------
    bonds : dem.geometry.bonds.Bonds
        The union bonds of the grown spheres: the contacts of the pair reading, in its order.
    grown : dem.geometry.particles.Particles
        The particles with their solid radii (m).
    w_pair, w_wall : numpy.ndarray
        The pair and wall bonds' hand-over weights (:func:`dem.geometry.handover.bond_weights`).
    past, past_wall : numpy.ndarray
        The pair and wall bonds past the pair reading's range, whatever the weights (bool).
    """

    bonds: object
    grown: object
    w_pair: np.ndarray
    w_wall: np.ndarray
    past: np.ndarray
    past_wall: np.ndarray


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

    def _readings(self, now, walls, pairs, box, update: bool):
        """The two readings of the contacts ``pairs``: ``(bonds, None)`` where no particle is handed over (the bonds
        under the scene's reading and ``out_of_range``, as without the hand-over), else ``(pair, union)``: the pair
        reading clipped to its range and the union reading of the grown spheres (``union.grown``, their solid radii),
        the same contacts in the same order (the arguments are those of :meth:`bonds`)."""
        spec = self.spec
        if not update and not np.any(self.steps):  # nothing handed over and nothing to update: the pair reading
            return find_bonds(now, walls, spec.contact, spec.out_of_range, pairs=pairs, box=box), None
        pair = find_bonds(now, walls, spec.contact, "clip", pairs=pairs, box=box)
        vectors = pair.vectors(now.position, box)
        normals = np.array([w.normal for w in walls], dtype=float).reshape(-1, 3)[pair.wall_index]
        if update:
            self.steps = advance(self.steps, necks_meeting(now.radius, pair, vectors, normals))
        if not np.any(self.steps):  # nothing handed over: the pair reading alone, as without the hand-over
            return (pair if spec.out_of_range == "clip" else
                    find_bonds(now, walls, spec.contact, spec.out_of_range, pairs=pairs, box=box)), None
        w_pair, w_wall = bond_weights(self.weight, pair)
        # bonds past the pair reading's range where it still has weight: the scene's out_of_range policy
        past = pair.h > max_overlap(now.radius[pair.i], now.radius[pair.j])
        past_wall = pair.wall_h > now.radius[pair.wall_particle] / 3.0
        # the pair reading has weight on a bond while the bond's weight is below 1, with a node per neck while the
        # weight of either of its particles is (each particle's element is its own blend)
        pair_part = np.minimum(self.weight[pair.i], self.weight[pair.j]) if spec.nodes == "necks" else w_pair
        weighed, weighed_wall = past & (pair_part < 1.0), past_wall & (w_wall < 1.0)
        if spec.out_of_range == "error" and (np.any(weighed) or np.any(weighed_wall)):
            find_bonds(now, walls, spec.contact, "error", pairs=(pair.i[weighed], pair.j[weighed]), box=box)
        solid = solid_radii(now.radius, self.weight > 0.0, pair.i, pair.j, vectors, pair.wall_particle, normals,
                            pair.wall_l, start=self.solid_radius)
        if update:
            self.solid_radius = solid
        grown = replace(now, radius=solid)
        union = find_bonds(grown, walls, "union", "error", pairs=pairs, box=box)
        n = now.n  # the grown spheres may touch a wall the particle does not: the contacts' wall bonds only
        union = union.subset(slice(None), np.isin(union.wall_index * n + union.wall_particle,
                                                   pair.wall_index * n + pair.wall_particle))
        return pair, Reading(union, grown, w_pair, w_wall, past, past_wall)

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
        pair, union = self._readings(now, walls, pairs, box, update)
        if union is None:
            return (pair, *bond_conductances(spec, now, pair, box=box, walls=tuple(walls)))
        if spec.out_of_range == "drop":  # the pair reading's conductances without its necks past its range (0 there)
            K_pair, K_wall = np.zeros(pair.n_pairs), np.zeros(pair.n_walls)
            on, on_walls = np.flatnonzero(~union.past), np.flatnonzero(~union.past_wall)
            K_pair[on], K_wall[on_walls] = bond_conductances(spec, now, pair.subset(on, on_walls), box=box,
                                                             walls=walls)
        else:
            K_pair, K_wall = bond_conductances(spec, now, pair, box=box, walls=walls)
        K_union, K_wall_union = bond_conductances(replace(spec, neck="union"), union.grown, union.bonds, box=box,
                                                  walls=walls)
        w_pair, w_wall = union.w_pair, union.w_wall
        K_pair = (1.0 - w_pair) * K_pair + w_pair * K_union
        K_wall = (1.0 - w_wall) * K_wall + w_wall * K_wall_union
        read, read_wall = w_pair >= 0.5, w_wall >= 0.5
        u = union.bonds
        bonds = replace(pair, a=np.where(read, u.a, pair.a), l_i=np.where(read, u.l_i, pair.l_i),
                        l_j=np.where(read, u.l_j, pair.l_j), wall_a=np.where(read_wall, u.wall_a, pair.wall_a),
                        wall_l=np.where(read_wall, u.wall_l, pair.wall_l))
        return bonds, K_pair, K_wall

    def neck_network(self, now, walls, pairs, box, update: bool = False) -> NeckNetwork:
        """The network with a node per neck (:mod:`dem.network.necks`) of the contacts ``pairs`` and the walls
        ``walls`` through the hand-over (module docstring, "Neck nodes").

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
            a snapshot reads them as they are).

        Returns
        -------
        dem.network.necks.NeckNetwork
            The network: its nodes the pair reading's necks that some particle's element has (module docstring),
            each particle's element blended by its weight.

        Raises
        ------
        ValueError
            As :meth:`bonds`, the pair reading having weight on a neck while either of its particles' weight is
            below 1.
        """
        spec = self.spec
        pair, union = self._readings(now, walls, pairs, box, update)
        if union is None:
            return neck_network(spec, now, pair, box=box, walls=walls)
        kept = {}

        def union_elements(*args):  # the union's elements, kept with their bonds (args[2]) for the blend
            kept["elements"], kept["bonds"] = particle_elements(*args), args[2]
            return kept["elements"]

        union_net = neck_network(replace(spec, neck="union"), union.grown, union.bonds, box=box, walls=walls,
                                 elements=union_elements)
        # the necks each reading's elements have: the union's its live ones (not those hidden inside a third
        # sphere), the pair reading's all but, under out_of_range = "drop", those past its range (as the one-node
        # law's pair conductance there is 0)
        drop = spec.out_of_range == "drop"
        in_pair = (~union.past if drop else np.ones(pair.n_pairs, dtype=bool),
                   ~union.past_wall if drop else np.ones(pair.n_walls, dtype=bool))
        in_union = np.zeros(pair.n_pairs, dtype=bool), np.zeros(pair.n_walls, dtype=bool)
        in_union[0][union_net.live], in_union[1][union_net.live_walls] = True, True
        weight = self.weight

        def held(k, side):  # whether particle k's blended element has the neck: (1 - w) E_pair + w E_union
            return ((weight[k] < 1.0) & in_pair[side]) | ((weight[k] > 0.0) & in_union[side])

        # a neck no element has (hidden inside a third sphere between handed-over particles, or dropped by the
        # pair reading where neither particle is on the way): no node
        without = ~(held(pair.i, 0) | held(pair.j, 0)), ~held(pair.wall_particle, 1)
        dropped = pair.subset(np.flatnonzero(~in_pair[0]), np.flatnonzero(~in_pair[1]))

        def blended(n, r, sub, vectors, k_i, k_j, k_w, kappa, normals, volume):
            keys = _end_keys(sub, n)  # the pair elements over the necks the pair reading keeps
            m = sub.n_pairs
            out = np.isin(keys, _end_keys(dropped, n))
            on, on_walls = np.flatnonzero(~out[:m]), np.flatnonzero(~out[2 * m:])
            E_pair = particle_elements(n, r, sub.subset(on, on_walls), vectors[on], k_i[on], k_j[on], k_w[on_walls],
                                       kappa, normals[on_walls], volume)
            return blend_elements(E_pair, sub.subset(on, on_walls), kept["elements"], kept["bonds"], weight, sub)

        return neck_network(spec, now, pair, box=box, walls=walls, elements=blended, without=without)

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


def _end_keys(bonds, n: int) -> np.ndarray:
    """A key per bond end of ``bonds`` in the order of :class:`dem.laws.shared_body.ParticleElements`' ends (the
    pair bonds on ``i``, on ``j``, then the wall bonds) that names the same end in any subset of the same contacts:
    ``3 id + side``, ``id`` the pair ``i n + j`` or the wall bond ``wall n + particle``."""
    pair = bonds.i.astype(np.int64) * n + bonds.j
    wall = bonds.wall_index.astype(np.int64) * n + bonds.wall_particle
    return np.concatenate([3 * pair, 3 * pair + 1, 3 * wall + 2])


def blend_elements(pair: ParticleElements, pair_bonds, union: ParticleElements, union_bonds, weight: np.ndarray,
                   bonds=None) -> ParticleElements:
    """Each particle's element through the hand-over (module docstring, "Neck nodes"): ``(1 - w) E_pair + w E_union``
    over the network's ends, ``w`` the particle's hand-over weight; an end one reading does not have (a neck inside a
    third sphere, a pair neck dropped past its range) takes nothing from it.

    Parameters
    ----------
    pair : dem.laws.shared_body.ParticleElements
        The elements under the pair reading (W/K).
    pair_bonds : dem.geometry.bonds.Bonds
        The bonds of their ends (the live ones of the pair reading).
    union : dem.laws.shared_body.ParticleElements
        The elements under the union reading of the grown spheres (W/K).
    union_bonds : dem.geometry.bonds.Bonds
        The bonds of their ends (the live ones of the union reading: the same contacts or fewer).
    weight : numpy.ndarray
        Per particle, its hand-over weight (0 to 1).
    bonds : dem.geometry.bonds.Bonds or None
        The bonds of the blend's ends, those of both readings' ends or more (the network's); None: ``pair_bonds``.

    Returns
    -------
    dem.laws.shared_body.ParticleElements
        The blended elements, on the ends of ``bonds``.

    Raises
    ------
    ValueError
        An end of either reading that ``bonds`` does not have.
    """
    n = len(weight)
    if bonds is None:
        offsets, ends = pair.offsets, pair.ends
    else:
        offsets, ends = ends_by_particle(n, np.concatenate((bonds.i, bonds.j, bonds.wall_particle)))
    keys = _end_keys(pair_bonds if bonds is None else bonds, n)
    size = np.diff(offsets) + 1
    start = np.zeros(n + 1, dtype=np.int64)
    start[1:] = np.cumsum(size * size)
    w = np.asarray(weight, dtype=float)
    values = np.zeros(start[-1])
    at, owner = _places(offsets, ends, start, keys, pair, _end_keys(pair_bonds, n))
    values[at] = pair.values * (1.0 - w[owner])
    at, owner = _places(offsets, ends, start, keys, union, _end_keys(union_bonds, n))
    values[at] += w[owner] * union.values
    plain = np.where(w >= 1.0, union.plain, np.where(w > 0.0, pair.plain | union.plain, pair.plain))
    return pair._replace(offsets=offsets, ends=ends, start=start, values=values, plain=plain,
                         shrink=(1.0 - w) * pair.shrink + w * union.shrink)


def _places(offsets, ends, start, keys, part: ParticleElements, part_keys):
    """Where each value of the elements ``part`` goes in elements laid out by ``offsets``, ``ends`` and ``start``
    (:class:`dem.laws.shared_body.ParticleElements`) over the ends whose keys (:func:`_end_keys`) are ``keys``, an end
    of ``part`` found by its key ``part_keys``: ``(index, owner)``, the index in the layout's values and the
    particle of each value of ``part``."""
    n = len(offsets) - 1
    z, z_part = np.diff(offsets), np.diff(part.offsets)
    # the local place of each end in its particle's block, found by its key
    local = np.empty(len(ends), dtype=np.int64)
    local[ends] = np.arange(len(ends)) - np.repeat(offsets[:-1], z)
    order = np.argsort(keys)
    at = np.searchsorted(keys, part_keys, sorter=order)
    found = (at < len(order)) & (keys[order[np.minimum(at, len(order) - 1)]] == part_keys)
    if not np.all(found):
        raise ValueError("the hand-over's readings have a neck that the network has not")
    place = np.append(local[order[at]][part.ends], -1)  # per local end of part (in element order), its place
    # every entry of part (particle k, local p, q) to its place in k's block
    size_part, size = z_part + 1, z + 1
    owner = np.repeat(np.arange(n), size_part * size_part)
    entry = np.arange(len(part.values)) - part.start[:-1][owner]
    p, q = entry // size_part[owner], entry % size_part[owner]
    first = part.offsets[:-1][owner]
    row = np.where(p == z_part[owner], z[owner], place[np.where(p == z_part[owner], -1, first + p)])
    col = np.where(q == z_part[owner], z[owner], place[np.where(q == z_part[owner], -1, first + q)])
    return start[:-1][owner] + row * size[owner] + col, owner
