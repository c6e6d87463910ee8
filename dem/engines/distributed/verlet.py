"""Particles that move, across MPI ranks: spatial slabs, ghosts, migration (mpi4py).

Under ``mpiexec`` every rank reads the scene, keeps the particles of its slab (:mod:`dem.geometry.slabs`)
and runs the compiled loop of :mod:`dem.engines.verlet.loop` on its *local* particles: those it owns and, in the
same arrays, *ghosts* -- copies of the particles of other ranks within the halo ``2 r_max + skin`` of its slab. The
local particles are ordered by global id (the particle's index in the scene), so that a local pair ``i < j`` is
also a pair of lower global id first, as the serial list orders it.

Forces: a rank lists every pair with at least one owned partner; a pair across two slabs is thus computed on both
ranks, with the same inputs in the same order (ghosts are copies to the bit), and each keeps the force on its own
particle -- the force on a ghost is dropped. Both ranks carry the same history for such a pair. Particle-wall
contacts are computed for owned particles only; the walls' loads are summed over ranks every step, and a
stress-controlled wall's acceleration (Luding 2005, eq. 1) computed from the sum, the same on every rank.

Each step is one call of the compiled loop. A ghost's drift in it reproduces the owner's to the bit (same position,
velocity and force, same arithmetic); after the call the owners send their ghosts' positions, velocities, forces,
torques, radii, temperatures and law state (the second half kick of a ghost used the dropped force). When any rank
needs a new Verlet list, all rebuild: particles whose centre left the slab migrate to their new owner with
everything they carry (the law's particle state, the particle-wall histories), the pair histories (keyed by the
global ids of the pair) go to the new owners of both partners, ghosts are exchanged afresh and the list is built
from the local particles.

On one rank this is the serial run step by step, bit for bit. On more, each owned particle still sums its contacts
in the serial order (its local pairs are sorted by global id), so a periodic run is the serial one to the bit too;
with walls only the walls' loads differ, at round-off (the ranks' partial sums are added in another order), and a
stress wall's motion carries that difference into the packing.

Heat on moving contacts (:class:`RankContactThermal`): on one rank the serial network
(:class:`dem.engines.contact_heat.ContactThermalModel`, bit for bit); on more, each thermal step is one implicit
(or Crank-Nicolson) step of the network of every rank's contacts with an owned partner and of its owned particles'
wall contacts, solved on PETSc across the ranks (:meth:`dem.network.distributed.DistributedNetwork.integrate`, the
static engine's path), the ghosts being its halo. An owned particle has all its contacts on its rank (the list holds
every pair with an owned partner), so its row is the serial row; the solution equals the serial step's to the
linear solver's tolerance (to round-off with a direct solver in ``PETSC_OPTIONS``), and the step's heat balance holds
to round-off as in the serial step. The temperatures (and their rates) are kept for every particle of the scene on
every rank (one allgather of the owned values per thermal step: n floats per rank), so a migrating particle takes
nothing thermal with it. The effective conductivity of the contact network (a further steady solve at each output)
is that of the gathered sample (below): the serial network of its contacts, solved on rank 0 at an output time and on
every rank after the run.

The rows of ``timeseries.csv``, the summary, the plots and the checkpoints come from the sample gathered on rank 0 in
global order (:meth:`RankMechanics.gathered`); on several ranks each rank writes its piece of every snapshot (the
particles it owns, the contacts whose lower-id partner it owns) and rank 0 the ``.pvtu`` files that name them, listed
in the ``.pvd`` collections (:class:`dem.output.pieces.PieceWriter`). The checkpoints carry the slabs and the lists
as the ranks built them at their last rebuild (the positions they were built at, the particle-wall lists): a resumed
run (:meth:`RankMechanics.restore_lists`) takes again on every rank the particles, ghosts and lists it held then, and
goes on as the uninterrupted run does, on as many ranks as wrote the checkpoint (:func:`refuse_unsupported`). The
``staggered`` engine does not run under ``mpiexec``.
"""

from __future__ import annotations

import numpy as np

from dem.parallel import comm as mpi
from dem.parallel.comm import world
from dem.network.distributed import DistributedNetwork
from dem.engines.contact_heat import ContactThermalModel
from dem.engines.records import Steps
from dem.geometry.slabs import Slabs
from dem.engines.verlet.engine import VerletEngine
from dem.engines.verlet.loop import ESCAPED, NONFINITE, REBUILD, wall_acceleration
from dem.engines.verlet.mechanics import MechanicalModel, MechanicsError
from dem.engines.state import MotionState
from dem.geometry.neighbours import carry_history, verlet_pairs, wall_pairs
from dem.output.pieces import refuse_lammps_dump
from sinterheat import threads


def refuse_unsupported(scene, ranks: int, restart: dict | None = None) -> None:
    """A ``ValueError`` naming what a run on ``ranks`` ranks cannot do with ``scene`` (``restart``: the checkpoint
    it would resume from, which the same number of ranks must have written). An engine other than ``verlet`` under
    MPI is refused by the registry (:func:`dem.engines.engine_class`).

    Parameters
    ----------
    scene : dem.scene.parse.Scene
        The scene.
    ranks : int
        The number of MPI ranks.
    restart : dict or None
        The checkpoint to resume from; None: a fresh run.

    Raises
    ------
    ValueError
        The scene or the checkpoint cannot run on ``ranks`` ranks.
    """
    if ranks > 1 and scene.conductance.nodes != "particles":
        raise ValueError(f"[conductance] nodes = {scene.conductance.nodes!r}: on one rank only so far (this run has "
                         f"{ranks}); run without mpiexec or use nodes = \"particles\"")
    written = 1 if restart is None or "ranks" not in restart else int(restart["ranks"])
    if restart is not None and written != ranks:
        how = f"with mpiexec -n {written}" if written > 1 else "without mpiexec or with mpiexec -n 1"
        raise ValueError(f"--resume: the checkpoint was written by {written} rank(s), this run has {ranks}; resume "
                         f"{how}")


def _gather_rows(parts: list) -> np.ndarray:
    rows = [p for p in parts if len(p)]
    return np.concatenate(rows) if rows else parts[0]


class RankMechanics(MechanicalModel):
    """The mechanical submodel of one rank (module docstring):
    :class:`~dem.engines.verlet.mechanics.MechanicalModel` on the local particles,
    with the exchanges between ranks around each step and each rebuild."""

    def __init__(self, state: MotionState, walls, material, dt: float, skin: float, gravity=(0.0, 0.0, 0.0),
                 box=None, relaxation_time: float = 1e3, history=None, comm=None):
        """``state``: every particle of the scene (each rank reads them all and keeps its slab); ``comm``: the
        communicator (MPI's world by default); the rest as for
        :class:`~dem.engines.verlet.mechanics.MechanicalModel`.

        Parameters
        ----------
        state : dem.engines.state.MotionState
            Every particle of the scene (each rank keeps its slab).
        walls : sequence of dem.geometry.walls.Wall
            The walls.
        material : object
            The contact law's material (:mod:`dem.laws.contact`).
        dt : float
            The velocity-Verlet step (s).
        skin : float
            The Verlet list's skin (m), larger than the law's largest reach.
        gravity : array_like
            The gravitational acceleration [x, y, z] (m/s^2).
        box : dem.geometry.periodic.PeriodicBox or None
            The periodic box; None: none.
        relaxation_time : float
            The material's relaxation time (s; Luding 2005's ``t0``).
        history : dict or None
            A saved state to start the particle state and contact histories from; None: none.
        comm : object or None
            The MPI communicator (an ``mpi4py.MPI.Comm``); None: MPI's world.
        """
        self.comm = world() if comm is None else comm
        self.rank, self.size = self.comm.Get_rank(), self.comm.Get_size()
        self.gid = np.arange(state.n)
        self.owned = np.ones(state.n, dtype=bool)
        self.n_global = state.n
        self.slabs = self._slabs(state, box) if history is None or "rank_cuts" not in history else \
            Slabs(int(history["rank_axis"]), np.array(history["rank_cuts"], dtype=float),
                  float(history["rank_period"]), float(history["rank_origin"]))
        self.send_idx, self.recv_idx = {}, {}
        self.migrated = 0  # particles this rank took over from others at rebuilds
        super().__init__(state, walls, material, dt, skin, gravity, box, relaxation_time, history)

    def _slabs(self, state: MotionState, box) -> Slabs:
        """Slabs along the periodic axis if there is one among those the particles move along, else along the
        longest extent of the particles."""
        axes = state.axes
        periodic = [a for a in axes if box is not None and box.periodic[a]]
        if periodic:
            a = periodic[0]
            return Slabs.balanced(state.x[:, a], self.size, a, float(box.lengths[a]), float(box.origin[a]))
        a = axes[int(np.argmax(np.ptp(state.x[:, axes], axis=0)))] if state.n else 0
        return Slabs.balanced(state.x[:, a], self.size, a)

    # ------------------------------------------------------------------------------------------ particle rows
    def _arrays(self) -> list:
        """Every per-particle array, local order (a migrating particle takes them all)."""
        s = self.state
        return [s.x, s.v, s.w, s.f, s.tau, s.mass, s.inertia, s.radius, s.radius_ref, s.T, self.particle_state,
                self.w_hist, self.w_fn, self.w_ft]

    def _moving(self) -> list:
        """What changes from step to step: what a ghost is refreshed with."""
        s = self.state
        return [s.x, s.v, s.w, s.f, s.tau, s.radius, s.T, self.particle_state]

    @staticmethod
    def _pack(arrays: list, idx: np.ndarray) -> np.ndarray:
        """The rows ``idx`` of ``arrays`` side by side (no rows: a rank may own no particle at some moment)."""
        columns = [a[idx].reshape(len(idx), int(np.prod(a.shape[1:]))) for a in arrays]
        return np.hstack(columns) if columns else np.zeros((len(idx), 0))

    @staticmethod
    def _unpack(arrays: list, rows: np.ndarray, idx=None) -> list:
        """The columns of ``rows`` into ``arrays`` at ``idx`` (in place), or as new arrays shaped like them."""
        out, start = [], 0
        for a in arrays:
            width = int(np.prod(a.shape[1:], dtype=int))
            block = rows[:, start:start + width].reshape((len(rows),) + a.shape[1:])
            start += width
            if idx is None:
                out.append(np.ascontiguousarray(block))
            else:
                a[idx] = block
        return out

    def _set_particles(self, rows: np.ndarray, gid: np.ndarray, owned: np.ndarray) -> None:
        """The local particles from full rows (:meth:`_arrays` columns), ordered by global id."""
        order = np.argsort(gid, kind="stable")
        x, v, w, f, tau, mass, inertia, radius, radius_ref, T, ps, wh, wfn, wft = self._unpack(self._arrays(),
                                                                                             rows[order])
        s = self.state
        s.x, s.v, s.w, s.f, s.tau, s.mass, s.inertia = x, v, w, f, tau, mass, inertia
        s.radius, s.radius_ref, s.T = radius, radius_ref, T
        self.particle_state, self.w_hist, self.w_fn, self.w_ft = ps, wh, wfn, wft
        self.gid, self.owned = gid[order], owned[order]

    # ------------------------------------------------------------------------------------------------ list
    def _build_list(self, first: bool = False):
        """Migration, ghosts and the Verlet list (module docstring); ``first``: every rank holds every particle
        and keeps those of its slab."""
        s, box, comm = self.state, self.periodic_box, self.comm
        if box is not None:  # as the serial model: those that left the box back into it
            box.wrap_outside(s.x)
        dest = self.slabs.owner(s.x)
        rows = np.column_stack([self._pack(self._arrays(), np.arange(s.n)), self.gid])
        owned = np.flatnonzero(self.owned)
        r_max = mpi.maximum(comm, float(np.max(s.radius[owned], initial=0.0)))
        own_rows = rows[owned[dest[owned] == self.rank]]
        if not first:  # the particles that left the slab to their new owners; pair histories to both partners'
            leaving = [rows[owned[dest[owned] == r]] if r != self.rank else rows[:0] for r in range(self.size)]
            arrived = comm.alltoall(leaving)
            self.migrated += sum(len(a) for a in arrived)
            own_rows = _gather_rows([own_rows] + arrived)
            hist = np.column_stack([self.gid[self.pi], self.gid[self.pj], self.p_hist, self.p_fn, self.p_ft])
            hist = _gather_rows(comm.alltoall([hist[(dest[self.pi] == r) | (dest[self.pj] == r)]
                                               for r in range(self.size)]))
        # ghosts: the owned particles within the halo of another rank's slab
        halo = 2.0 * r_max + self.skin
        to = [self.slabs.within_halo(own_rows[:, :3], r, halo) if r != self.rank else np.zeros(0, dtype=np.int64)
              for r in range(self.size)]
        ghosts = comm.alltoall([own_rows[k] for k in to])
        local = _gather_rows([own_rows] + ghosts)
        gid = local[:, -1].astype(np.int64)
        self._set_particles(local[:, :-1], gid, np.arange(len(local)) < len(own_rows))
        own_gid = own_rows[:, -1].astype(np.int64)
        self.send_idx = {r: np.searchsorted(self.gid, own_gid[k]) for r, k in enumerate(to) if len(k)}
        self.recv_idx = {r: np.searchsorted(self.gid, g[:, -1].astype(np.int64)) for r, g in enumerate(ghosts)
                         if len(g)}
        # the list: pairs with an owned partner, their histories found by global ids
        expected = 0 if first else len(self.pi) + len(self.pi) // 8 + 16
        i, j = verlet_pairs(s.x, s.radius, self.skin, self.box, expected)
        keep = self.owned[i] | self.owned[j]
        i, j = i[keep], j[keep]
        n_hist = len(self.law.PAIR_HISTORY)
        if first:
            m = len(i)
            self.p_hist, self.p_fn, self.p_ft = np.zeros((m, n_hist)), np.zeros(m), np.zeros((m, 3))
        else:
            key = hist[:, 0].astype(np.int64) * self.n_global + hist[:, 1].astype(np.int64)
            key, first_row = np.unique(key, return_index=True)  # a pair across two slabs came from both
            hist = hist[first_row]
            self.p_hist, self.p_fn, self.p_ft = carry_history(
                key // self.n_global, key % self.n_global, self.gid[i], self.gid[j], hist[:, 2:2 + n_hist],
                hist[:, 2 + n_hist], hist[:, 3 + n_hist:])
            self.rebuilds += 1
        self._listed(i, j)

    def walls_moved(self):
        """The particle-wall list of the owned particles."""
        k, m = wall_pairs(self.state.x, self.state.radius, self.w.normal, self.w.q, self.skin)
        keep = self.owned[k]
        self.wk, self.wm = k[keep], m[keep]
        self.wq_ref = self.w.q.copy()

    def _restore(self, saved: dict):
        """A saved state's histories (global rows and pairs) for the local particles."""
        local = np.full(self.n_global, -1, dtype=np.int64)
        local[self.gid] = np.arange(len(self.gid))
        pi, pj = local[np.asarray(saved["pi"])], local[np.asarray(saved["pj"])]
        keep = (pi >= 0) & (pj >= 0)
        super()._restore({**saved, "pi": pi[keep], "pj": pj[keep], "p_hist": np.asarray(saved["p_hist"])[keep],
                          "particle_state": np.asarray(saved["particle_state"])[self.gid],
                          "w_hist": np.asarray(saved["w_hist"])[self.gid]})
        self._refresh_ghosts()

    def restore_lists(self, saved: dict) -> None:
        """A checkpoint of several ranks (:meth:`slab_arrays`, the lists gathered by :meth:`gathered`): every rank
        takes again the particles, ghosts and lists it held at the last rebuild -- its slab's particles at the
        positions the lists were built at, the pairs of the gathered list with a partner it owns -- then the
        particles' state as it is now, so that the run goes on as the uninterrupted one does (one rank: the serial
        model's restore).

        Parameters
        ----------
        saved : dict
            The checkpoint's arrays.
        """
        if self.size == 1:
            return super().restore_lists(saved)
        n, s = self.n_global, self.state

        def column(key):
            return np.array(saved[key], dtype=float)

        s.x, s.v, s.w, s.f, s.tau = column("list_x_ref"), column("v"), column("w"), column("f"), column("tau")
        s.mass, s.inertia, s.radius, s.radius_ref, s.T = (column(k) for k in ("mass", "inertia", "radius",
                                                                                "radius_ref", "T"))
        self.particle_state, self.w_hist = column("particle_state"), column("w_hist")
        self.w_fn, self.w_ft = np.zeros((n,) + self.w_fn.shape[1:]), np.zeros((n,) + self.w_ft.shape[1:])
        self.gid, self.owned = np.arange(n), np.ones(n, dtype=bool)
        self._build_list(first=True)  # ownership and ghosts as at the last rebuild
        local = np.full(n, -1, dtype=np.int64)
        local[self.gid] = np.arange(len(self.gid))
        i, j = local[np.asarray(saved["pi"])], local[np.asarray(saved["pj"])]
        mine = (i >= 0) & (j >= 0)
        mine[mine] = self.owned[i[mine]] | self.owned[j[mine]]
        self._listed(i[mine], j[mine])
        self.p_hist = np.array(saved["p_hist"], dtype=float)[mine]
        self.p_fn, self.p_ft = np.zeros(len(self.pi)), np.zeros((len(self.pi), 3))
        s.x[:] = np.asarray(saved["x"], dtype=float)[self.gid]
        k = local[np.asarray(saved["wall_list_k"], dtype=np.int64)]
        keep = (k >= 0) & self.owned[np.maximum(k, 0)]
        self.wk, self.wm = k[keep], np.asarray(saved["wall_list_m"], dtype=np.int64)[keep]
        self.wq_ref = np.array(saved["wall_list_q_ref"], dtype=float)

    def slab_arrays(self) -> dict:
        """The slabs and the rank count, for a checkpoint (a resumed run keeps its particles where they were)."""
        sl = self.slabs
        return {"rank_axis": np.array(sl.axis), "rank_cuts": sl.cuts, "rank_period": np.array(sl.period),
                "rank_origin": np.array(sl.origin), "ranks": np.array(self.size)}

    # ------------------------------------------------------------------------------------------- exchanges
    def _refresh_ghosts(self) -> None:
        """The ghosts' moving columns from their owners (:meth:`_moving`)."""
        from mpi4py import MPI

        arrays = self._moving()
        requests, buffers = [], {}
        for r, idx in self.recv_idx.items():
            buffers[r] = np.empty((len(idx), sum(int(np.prod(a.shape[1:], dtype=int)) for a in arrays)))
            requests.append(self.comm.Irecv(buffers[r], source=r, tag=7))
        for r, idx in self.send_idx.items():
            requests.append(self.comm.Isend(self._pack(arrays, idx), dest=r, tag=7))
        MPI.Request.Waitall(requests)
        for r, idx in self.recv_idx.items():
            self._unpack(arrays, buffers[r], idx)

    def _initial_forces(self):
        super()._initial_forces()
        w = self.w
        if len(w.force):
            w.force[:] = self.comm.allreduce(w.force, op=mpi.reduction("SUM"))
            for m in range(len(self.walls)):
                w.acc[m] = wall_acceleration(m, w)
        self._refresh_ghosts()

    def advance(self, n_steps: int, T0: np.ndarray, T_rate: np.ndarray, relaxation_time: float | None = None):
        """``n_steps`` steps, one call of the compiled loop each, with the exchanges between them (module
        docstring).

        Parameters
        ----------
        n_steps : int
            Number of steps.
        T0 : numpy.ndarray
            Temperatures now (K or degC): one per particle of the scene, or one for all.
        T_rate : numpy.ndarray
            Their rates (K/s), shaped as ``T0``.
        relaxation_time : float or None
            The relaxation time (s); None: the model's.

        Raises
        ------
        MechanicsError
            A particle's position or velocity became non-finite, or a particle left the box (a ValueError).
        """
        w = self.w
        heating = self._temperature_arguments(T0, T_rate, relaxation_time)
        first = self.steps
        h = 0.5 * self.dt
        for _ in range(n_steps):  # (the records anew at each step: a step's exchanges may replace the arrays)
            wdq_half = np.where(w.mode == 1, w.dq + h * w.acc, w.dq)
            _, status = self._advance(*self.records(), Steps(1, self.dt, self.steps, first, *heating), self._info)
            self.steps += 1
            status = self._agreed(status, wdq_half)
            if status == REBUILD:
                self._build_list()
            else:
                self._refresh_ghosts()

    def _agreed(self, status: int, wdq_half: np.ndarray) -> int:
        """After a step, in one reduction over the ranks: the walls' loads summed (and stress walls accelerated by
        the sum, eq. 1, from their velocity ``wdq_half`` after the step's first half kick, as the compiled loop does
        with its own load), and the status all ranks act on: a failure anywhere stops every rank with its message,
        a rebuild anywhere rebuilds everywhere."""
        w = self.w
        failed = status in (NONFINITE, ESCAPED)
        total = np.concatenate([[status == REBUILD, failed], w.force])
        self.comm.Allreduce(total.copy(), total, op=mpi.reduction("SUM"))  # buffers, not pickles: once per step
        w.force[:] = total[2:]
        h = 0.5 * self.dt
        for m in np.flatnonzero(w.mode == 1):
            w.dq[m] = wdq_half[m]  # eq. (1)'s damping acts on the half-kicked velocity, as in the loop
            w.acc[m] = wall_acceleration(m, w)
            w.dq[m] = wdq_half[m] + h * w.acc[m]
        if total[1] > 0:
            k, m = int(self._info[0]), int(self._info[1])
            status, k, m = min(f for f in self.comm.allgather((status, int(self.gid[k]), m) if failed else None)
                               if f is not None)
            if status == NONFINITE:
                raise MechanicsError(f"the run stopped at step {self.steps} (t = {self.t:.6g} s): particle {k} has "
                                     f"a non-finite position or velocity; the step dt = {self.dt:.6g} s is too large "
                                     f"or a parameter is extreme")
            raise MechanicsError(f"the run stopped at step {self.steps} (t = {self.t:.6g} s): particle {k} left the "
                                 f"box through wall {self.walls[m].name!r}; reduce dt or the wall speed, or enlarge "
                                 f"the box")
        return REBUILD if total[0] > 0 else status

    # --------------------------------------------------------------------------------------------- outputs
    def gathered(self, everyone: bool = False) -> MechanicalModel | None:
        """The whole sample as one serial model, in global order (its particles, the pairs each counted once, by
        the rank owning their lower-id partner), on rank 0 (or on every rank with ``everyone``); None elsewhere.

        Parameters
        ----------
        everyone : bool
            Whether every rank gets the gathered model, not rank 0 alone.

        Returns
        -------
        dem.engines.verlet.mechanics.MechanicalModel or None
            The serial model of the whole sample, or None on the other ranks.
        """
        own = np.flatnonzero(self.owned)
        rows = np.column_stack([self._pack(self._arrays(), own), self.x_ref[own], self.gid[own]])
        mine = self.owned[self.pi]
        pairs = np.column_stack([self.gid[self.pi[mine]], self.gid[self.pj[mine]], self.p_hist[mine],
                                 self.p_fn[mine], self.p_ft[mine]])
        wall_list = np.column_stack([self.gid[self.wk], self.wm])
        parts = self.comm.allgather((rows, pairs, wall_list)) if everyone else \
            self.comm.gather((rows, pairs, wall_list), root=0)
        if parts is None:
            return None
        rows = _gather_rows([p[0] for p in parts])
        rows = rows[np.argsort(rows[:, -1], kind="stable")]
        x_ref, rows = rows[:, -4:-1], np.column_stack([rows[:, :-4], rows[:, -1]])
        wall_list = _gather_rows([p[2] for p in parts])
        wall_list = wall_list[np.lexsort((wall_list[:, 1], wall_list[:, 0]))]
        pairs = _gather_rows([p[1] for p in parts])
        pairs = pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]
        view = MechanicalModel.__new__(MechanicalModel)
        view.__dict__.update({k: v for k, v in self.__dict__.items() if k not in ("comm", "state")})
        x, v, w, f, tau, mass, inertia, radius, radius_ref, T, ps, wh, wfn, wft = self._unpack(self._arrays(),
                                                                                             rows[:, :-1])
        s = self.state
        view.state = MotionState(s.dimension, s.height, x, v, w, f, tau, mass, inertia, radius, radius_ref, T)
        view.particle_state, view.w_hist, view.w_fn, view.w_ft = ps, wh, wfn, wft
        n_hist = len(self.law.PAIR_HISTORY)
        view.pi, view.pj = pairs[:, 0].astype(np.int64), pairs[:, 1].astype(np.int64)
        view.p_hist, view.p_fn = pairs[:, 2:2 + n_hist], pairs[:, 2 + n_hist]
        view.p_ft = np.ascontiguousarray(pairs[:, 3 + n_hist:])
        view.x_ref = np.ascontiguousarray(x_ref)  # the positions the lists were built at, and the walls' list
        view.wk, view.wm = (np.ascontiguousarray(wall_list[:, c], dtype=np.int64) for c in (0, 1))
        return view


class RankContactThermal(ContactThermalModel):
    """The heat of the contacts on several ranks (module docstring): ``T`` and ``rate`` over every particle of the
    scene on every rank, each thermal step solved on PETSc by all ranks together. No hand-over to the union
    (:mod:`dem.geometry.handover`): its solid radii are solved over the whole sample, which no rank holds.

    Parameters
    ----------
    particles : dem.geometry.particles.Particles
        The scene's particles at the start, all of them on every rank
        (:class:`dem.engines.contact_heat.ContactThermalModel`).
    walls : sequence of dem.geometry.walls.Wall
        The scene's walls.
    spec : dem.laws.conductance.ConductanceSpec
        The scene's contact geometry and conductance law.
    sources : dem.laws.ambient.Sources
        The heat exchanged with the surroundings, if any.
    integrator : str
        ``"implicit"`` or ``"crank-nicolson"``.
    linear : str
        The linear solver of each step.
    box : dem.geometry.periodic.PeriodicBox or None
        The periodic box; None without one.
    """

    hands_over = False

    def local(self, mechanics, values: np.ndarray) -> np.ndarray:
        """As :meth:`~dem.engines.contact_heat.ContactThermalModel.local`: a rank's particles (by their global ids),
        or all of them in a gathered sample (:meth:`RankMechanics.gathered`).

        Parameters
        ----------
        mechanics : RankMechanics or dem.engines.verlet.mechanics.MechanicalModel
            This rank's mechanics, or the gathered sample.
        values : numpy.ndarray
            One value per particle of the scene, any unit.

        Returns
        -------
        numpy.ndarray
            The values of the particles ``mechanics`` holds, in its order.
        """
        return values[mechanics.gid] if isinstance(mechanics, RankMechanics) else values

    def step(self, mechanics, dt: float) -> None:
        """Advance the temperatures by ``dt`` on the network of the contacts the ranks hold now.

        Parameters
        ----------
        mechanics : RankMechanics
            This rank's mechanics: its contacts now.
        dt : float
            The step (s).
        """
        comm = mechanics.comm
        bonds, K_pairs, K_walls = self.bonds(mechanics)
        walls = mechanics.owned[bonds.wall_particle]  # a ghost's wall contacts are its owner's
        self.net = self.network(mechanics, (bonds.subset(slice(None), walls), K_pairs, K_walls[walls]))
        owner = np.full(len(mechanics.gid), mechanics.rank)
        for rank, ghosts in mechanics.recv_idx.items():
            owner[ghosts] = rank
        part = DistributedNetwork(comm, self.net, mechanics.gid, owner)
        res = mpi.agree(comm, lambda: part.integrate(self.integrator, dt, dt))
        self.assemblies += 1
        self.startup_steps += res.startup_steps  # a stiff Crank-Nicolson step taken as implicit Euler
        for k, v in res.heat_in.items():
            self.heat_in[k] = self.heat_in.get(k, 0.0) + v
        T_local = res.T
        T = self.T.copy()
        own = mechanics.owned
        for index, values in comm.allgather((mechanics.gid[own], T_local[own])):
            T[index] = values
        self.rate = (T - self.T) / dt
        self.T = T


class RankVerletEngine(VerletEngine):
    """The verlet engine with its particles spread over the MPI ranks (module docstring). Outputs come from the
    sample gathered on rank 0 at every output time; after the run every rank holds the gathered sample, so the
    summary is the same everywhere."""

    mechanics_class = RankMechanics

    @classmethod
    def refuse(cls, scene, resume: bool) -> None:
        """A LAMMPS dump on several ranks, refused before the run's folder is touched
        (:func:`dem.output.pieces.refuse_lammps_dump`); a checkpoint of another number of ranks is refused once read
        (:func:`refuse_unsupported`).

        Parameters
        ----------
        scene : dem.scene.parse.Scene
            The scene.
        resume : bool
            Whether the run would go on from a checkpoint.

        Raises
        ------
        ValueError
            The one-line reason.
        """
        refuse_lammps_dump(scene)

    def __init__(self, scene, restart: dict | None = None):
        """As :class:`VerletEngine`; unless told (``SINTERHEAT_THREADS``, ``--threads``), each rank's contact loop
        takes its share of the cores, not all of them.

        Parameters
        ----------
        scene : dem.scene.parse.Scene
            The scene.
        restart : dict or None
            A checkpoint of this scene's run to go on from; None: start at the scene's start.

        Raises
        ------
        ValueError
            The scene or the checkpoint cannot run on this many ranks.
        """
        size = world().Get_size()
        refuse_unsupported(scene, size, restart)
        threads.share_among_ranks(size)
        if size > 1:
            self.thermal_class = RankContactThermal
        super().__init__(scene, restart)
        self.ranks_mechanics = self.mechanics  # this rank's particles (self.mechanics: the gathered sample at times)

    # the snapshots' pieces on several ranks (dem.output.pieces): the particles this rank owns, the contacts
    # whose lower-id partner it owns (each contact once)
    def positions(self) -> np.ndarray:
        """Centres (n, 3) of the particles this rank owns, m."""
        m = self.ranks_mechanics
        return super().positions() if m.size == 1 else m.state.x[m.owned]

    def particle_fields(self) -> dict:
        """The snapshot's point data of the particles this rank owns."""
        m = self.ranks_mechanics
        if m.size == 1:
            return super().particle_fields()
        shown, self.mechanics = self.mechanics, m
        try:
            fields = {**super().particle_fields(), "id": self.scene.particles.id[m.gid]}
        finally:
            self.mechanics = shown
        return {k: v[m.owned] for k, v in fields.items()}

    def links(self):
        """``(points, lines, fields)`` of the contacts this rank owns (each contact once)."""
        m = self.ranks_mechanics
        if m.size == 1:
            return super().links()
        shown, self.mechanics = self.mechanics, m
        try:
            points, lines, fields = super().links()
        finally:
            self.mechanics = shown
        once = m.owned[lines[:, 0]]
        return points, lines[once], {k: v[once] for k, v in fields.items()}

    def effective_conductivity(self, pair_necks: bool = False) -> float | None:
        """As :meth:`~dem.engines.verlet.engine.VerletEngine.effective_conductivity` on one rank; on more, of the
        gathered sample (rank 0's at an output time, every rank's after the run: the serial network of its contacts
        now), None on a rank that holds its slab only (module docstring).

        Parameters
        ----------
        pair_necks : bool
            Every contact read as a pair neck (one rank, which hands particles over to the union); several ranks
            hand none over, so their network is already that.

        Returns
        -------
        float or None
            k_eff (W/(m K)), or None.
        """
        m = self.ranks_mechanics
        if m.size == 1:
            return super().effective_conductivity(pair_necks)
        th = self.thermal
        if self.mechanics is m or th is None or th.net is None:
            return None
        slab_network, th.net = th.net, th.network(self.mechanics)
        try:
            return super().effective_conductivity()
        finally:
            th.net = slab_network

    def run(self, observe=None, progress=None, checkpoint=None) -> None:
        """As :meth:`~dem.engines.verlet.engine.VerletEngine.run`;
        ``observe`` sees the gathered sample (every rank calls it, rank 0 with its
        writer, the others with a callable that writes nothing); on several ranks every rank gathers each checkpoint
        (rank 0 has the ``checkpoint`` that keeps it), with the slabs (:meth:`RankMechanics.slab_arrays`).

        Parameters
        ----------
        observe : callable or None
            Called without arguments at the output times; None: not called.
        progress : callable or None
            Called with the simulated time (s); None: not called.
        checkpoint : callable or None
            Called as ``checkpoint(make, final)``; None: not called.
        """
        mech = self.mechanics
        gathered_checkpoints = mech.size > 1 and mpi.maximum(mech.comm, int(checkpoint is not None))

        def checkpointed(make, final: bool = False) -> None:
            view = mech.gathered()
            if view is not None:
                self.mechanics = view
                try:
                    data = {**make(), **mech.slab_arrays()}
                finally:
                    self.mechanics = mech
                checkpoint(lambda: data, final)

        def observed():
            view = mech.gathered()
            if view is None:  # another rank: its pieces of the snapshots (its writer's rows are rank 0's)
                return observe()
            self.mechanics = view
            try:
                observe()
            finally:
                self.mechanics = mech

        super().run(observed if observe is not None else None, progress,
                    checkpointed if gathered_checkpoints else checkpoint)
        self.mechanics = mech.gathered(everyone=True)
