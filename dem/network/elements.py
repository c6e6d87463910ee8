"""The particles' elements a scene asks for in the network with a node per neck (``[conductance] element``,
:class:`dem.laws.conductance.ConductanceSpec`), and what building them took, for the run's summary.

``element = "law"`` gives each particle the ``shared-body`` law's element
(:func:`dem.laws.shared_body.particle_elements`, one flux mode per neck); ``element = "trefftz"`` the Trefftz element
of its cut sphere with three flux modes per neck (:func:`dem.network.trefftz_element.trefftz_elements`), which keeps
the law's element on its monopoles where its own is not positive definite (``plain``), and whose time is said before
they are built where it is large (:func:`dem.memory.element_estimate`; on MPI ranks, each building its own particles',
once by rank 0 for all of them). Either is the ``elements`` hook of :func:`dem.network.necks.neck_network`;
:func:`scene_elements` is the one place that calls it.
"""

from __future__ import annotations

import functools
import time

import numpy as np

from dem.geometry.necks import pairs_meeting
from dem.laws.conductance import ConductanceSpec
from dem.memory import announce, element_estimate
from sinterheat import threads


class SceneElements:
    """The ``elements`` hook of :func:`dem.network.necks.neck_network` for ``[conductance] element`` (module
    docstring), keeping what it built.

    Parameters
    ----------
    element : str
        ``"law"`` or ``"trefftz"`` (``dem.laws.conductance.ELEMENTS``).
    own : numpy.ndarray or None
        Per particle, whether it is this process's own (an MPI rank's, :mod:`dem.network.distributed_necks`): the
        Trefftz element is then built for these only, the law's one-mode element for the rest of the halo (the
        elements of the own particles' partners come from their owners,
        :func:`dem.network.distributed_necks.shared_elements`); None: every particle's is built.
    comm : object or None
        With ``own``, the MPI communicator of the ranks that each build their own particles' elements (an
        ``mpi4py.MPI.Comm``): the hook is then called on every rank together, and what building them takes is said
        once, by rank 0, for all the ranks (:func:`dem.memory.element_estimate` of every rank's share, gathered on
        every rank even where its share raised, which raises after the gather: within
        :func:`dem.parallel.comm.agree` no rank is left waiting); None: no MPI.

    Attributes
    ----------
    built : dem.laws.shared_body.ParticleElements or None
        The elements of the last call; None before it.
    seconds : float
        The CPU time of the last call's build (this process's, all its threads': the Trefftz elements are built on
        :func:`sinterheat.threads.count` threads), ``compile_seconds`` left out, s.
    compile_seconds : float
        The CPU time of the last call's threads while they held numba's compiler lock: compiling the kernels the
        build calls for the first time in this process, or loading them from numba's cache (0 once they are loaded;
        :func:`sinterheat.compile_clock.compiling`), s.
    """

    def __init__(self, element: str, own: np.ndarray | None = None, comm=None):
        self.element = element
        self.own = None if own is None else np.asarray(own, dtype=bool)
        self.comm = comm
        self.built = None
        self.seconds = self.compile_seconds = 0.0

    def __call__(self, n, radius, bonds, vectors, k_i, k_j, k_wall, conductivity, wall_normals, volume=None):
        """The particles' elements (:func:`dem.laws.shared_body.particle_elements`'s arguments); the Trefftz elements'
        time estimated from the necks first and said where it is large (:func:`dem.memory.element_estimate`,
        :func:`dem.memory.announce`; with ``comm``, by rank 0 for all the ranks).

        Parameters
        ----------
        n : int
            Number of particles.
        radius : numpy.ndarray
            Particle radii, m.
        bonds : dem.geometry.bonds.Bonds
            The live pair and wall bonds, with their neck radii and centre-to-contact distances, m.
        vectors : numpy.ndarray
            ``x_j - x_i`` of every pair bond, m.
        k_i, k_j : numpy.ndarray
            The law's half conductances of every pair bond on the side of ``i`` and of ``j``, W/K.
        k_wall : numpy.ndarray
            The law's half conductance of every wall bond, W/K.
        conductivity : numpy.ndarray
            Per particle, its material's conductivity, W/(m K).
        wall_normals : numpy.ndarray
            The unit normal of every wall bond's wall, into the packing.
        volume : numpy.ndarray or None
            Per particle, the solid it holds, m^3, whose Wiener bound caps the trace of its tensor; None: its
            sphere's.

        Returns
        -------
        dem.laws.shared_body.ParticleElements
            The elements.
        """
        args = (n, radius, bonds, vectors, k_i, k_j, k_wall, conductivity, wall_normals, volume)
        if self.element == "trefftz":
            from dem.network.trefftz_element import trefftz_elements

            build = trefftz_elements if self.own is None else functools.partial(trefftz_elements, where=self.own)
            chosen = slice(None) if self.own is None else self.own
            try:  # the gather is made on every rank whatever raised before it, which is raised after it
                necks = bonds.necks_per_particle(n)[chosen]
                meeting = pairs_meeting(radius, bonds, vectors, wall_normals)[chosen]
                share, failed = (len(necks), int(necks.sum()), int(meeting.sum()), threads.count()), None
            except Exception as exc:
                share, failed = None, exc
            shares = [share] if self.comm is None else self.comm.gather(share)  # (None but on rank 0)
            if failed is not None:
                raise failed
            if shares is not None and None not in shares:  # (a rank whose share failed raises instead)
                announce(element_estimate(*zip(*shares)))
        else:
            from dem.laws.shared_body import particle_elements as build
        from sinterheat.compile_clock import compiling  # (numba: imported by the build anyway)

        start = time.process_time()
        with compiling() as clock:
            self.built = build(*args)
        self.compile_seconds = clock.total
        self.seconds = time.process_time() - start - self.compile_seconds
        return self.built

    def account(self) -> dict:
        """The summary's entries: ``element`` (its name) and, for ``"trefftz"``, ``element_particles`` (the
        particles with necks that carry it), ``element_plain`` (those that kept the law's element on their
        monopoles), ``element_refined`` (those whose quadrature failed its check and was refined),
        ``element_seconds`` (the CPU time of building them, s) and ``element_compile_seconds`` (that of compiling
        numba's kernels for it or loading them from its cache, s: ``seconds`` and ``compile_seconds``); with ``own``,
        of the own particles (a rank's part of the sums over the ranks).

        Returns
        -------
        dict
            The entries.
        """
        if self.element == "law" or self.built is None:
            return {"element": self.element}
        el = self.built
        with_necks = (np.diff(el.offsets) > 0) & (True if self.own is None else self.own)
        plain = np.asarray(el.plain, dtype=bool)
        return {"element": self.element, "element_particles": int(np.count_nonzero(with_necks & ~plain)),
                "element_plain": int(np.count_nonzero(with_necks & plain)),
                "element_refined": int(np.count_nonzero(with_necks & (np.asarray(el.refine) > 1.0))),
                "element_seconds": self.seconds, "element_compile_seconds": self.compile_seconds}


def scene_elements(spec: ConductanceSpec, own: np.ndarray | None = None, comm=None) -> SceneElements:
    """The ``elements`` hook of :func:`dem.network.necks.neck_network` that ``spec.element`` names (module docstring).

    Parameters
    ----------
    spec : dem.laws.conductance.ConductanceSpec
        The conductance law, its neck reading, nodes and element.
    own : numpy.ndarray or None
        Per particle, whether it is this process's own (:class:`SceneElements`); None: all.
    comm : object or None
        The MPI communicator of the ranks that build their own particles' elements (:class:`SceneElements`); None:
        no MPI.

    Returns
    -------
    SceneElements
        The hook, which keeps what it built.
    """
    return SceneElements(spec.element, own, comm)
