"""The memory a run needs, estimated from its particle count before anything large is allocated, and refused up
front when the machine does not have it (rather than a ``MemoryError`` deep inside a solve, or the kernel's
out-of-memory killer).

The figure is the peak of a steady solve of the benchmarks' random sintered packing (the bond search, the network,
the AMG hierarchy; ``python -m benchmarks dem``, whole process, maximum resident set): 1.58 GB for 10^6 particles
(5.5 * 10^6 bonds) and 13.7 GB for 10^7 (5.6 * 10^7 bonds), which ``BASE_BYTES + BYTES_PER_PARTICLE * n`` gives to
a per cent: about 240 bytes per bond at 5.6 bonds per particle, so a denser packing needs more in proportion.

Under the union of spheres (``[conductance] neck = "union"``) a particle costs five times that: the peak of a steady
solve of a random union packing at a solid fraction of 0.8 tiled to 2048, 6912, 16384 and 42592 particles (4.75
bonds each; whole process, maximum resident set) grows by 7.1 kB per particle with one node per particle and by 7.3 kB
with a node per neck (``nodes = "necks"``: a node per live bond more and each particle's element over its necks and
its centre), above about the same base.

With a node per neck on a pair-neck reading (``newton``, ``first``, ``coble``) a particle costs more again: the peak
of a run on the benchmarks' random sintered packing (copper, mean overlap h/r 0.15, 5.4 bonds per particle; whole
process, maximum resident set) at 2048, 6050, 16384 and 40656 particles grows by 21.8 kB per particle for a steady
solve and for ten implicit steps alike (1044 MiB at 40656), above a base of 0.21 GB, within 1.4 % at every size; a
moving run handing its particles over to the union (the velocity-Verlet engine, the same packing at r = 0.5 mm, whose
necks meet, three thermal steps with nine in ten particles on the way: the elements of both readings) grows by 51.4 kB
per particle at 500, 2048, 6050 and 16384 particles (1007 MiB at 16384), within 1.9 %.

The Trefftz element (``[conductance] element = "trefftz"``, :mod:`dem.network.trefftz_element`) costs far more time
than the network it goes into, and its time grows with each particle's necks and how many of them meet: it is
estimated from the live necks just before the elements are built (:func:`element_estimate`), and said where it is large
(:func:`announce`, heard on stderr where the driver reports the run's progress, :func:`announcing`). Nothing refuses a
run for its time: no limit bounds a steady solve's (the transient runs' work limit counts the steps, and the elements
are built once).
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import pathlib

import numpy as np

BYTES_PER_PARTICLE = 1.35e3
#: bytes per particle at the peak of a steady solve under the union of spheres, by the network's nodes (module
#: docstring)
UNION_BYTES_PER_PARTICLE = {"particles": 7.1e3, "necks": 7.3e3}
#: bytes per particle at the peak of a run with a node per neck on a pair-neck reading, static (steady or transient)
#: and moving through the hand-over (module docstring)
PAIR_NECK_NODES_BYTES_PER_PARTICLE = {"static": 21.8e3, "moving": 51.4e3}
# a steady solve of the benchmarks' 10^6-particle random packing (bonds, conductances, network, AMG-CG; python -m
# benchmarks dem) took 10.5 s on a quiet 2-core machine before the cell search and the row-by-row assembly, which
# take 0.74 of its CPU time side by side: about 7.8e-6 s per particle
SECONDS_PER_PARTICLE = 7.8e-6
#: seconds of CPU per particle of the ``shared-body`` law's steady solve on union necks (``neck = "union"``: the cut
#: bodies, the closing pores' cells and the factors) and with a node per neck (``nodes = "necks"``: the faces'
#: quadrature): bonds, conductances and solve of a random union packing at phi 0.8 tiled to 6912 particles (4.75 bonds
#: each), 0.41-0.46 ms per particle on the 2-core machine at load 5-7, and with a node per neck 0.83 ms against the
#: one node's 0.42 in the same process at load 17 (the faces' sums in SIMD lanes, the union halves computed once)
UNION_SECONDS_PER_PARTICLE = {"particles": 4.5e-4, "necks": 9.0e-4}
#: seconds of CPU per particle of a steady solve with a node per neck on a pair-neck reading (the elements over the
#: necks' faces, bonds and solve): 2.01-2.12 ms per particle on the random sintered packing of the module docstring
#: at 2048 to 40656 particles, 2-core machine at load 5-7
PAIR_NECK_NODES_SECONDS_PER_PARTICLE = 2.1e-3
#: seconds of CPU the Trefftz element (``[conductance] element = "trefftz"``, :mod:`dem.network.trefftz_element`, one
#: BLAS thread) takes per neck of a particle and per pair of its necks that meet (its faces and caps cut into more
#: panels): fitted to the elements' CPU time on fourteen periodic union packings (seven random mirror packings of 32
#: spheres, ``verification.packings.union_packing``, phi 0.6-0.95; three generated ones, ``[generator] kind =
#: "random"``, 72-256 particles, overlap 0.1-0.25; SC, BCC and FCC lattices at h/r 0.1-0.3 tiled to 16-32 particles;
#: 2-core machine at load 4-5), each packing weighing alike, which it gives within -17 % to +19 % (the necks alone,
#: 2.1 ms each, give 0.33 to 1.42 times it)
TREFFTZ_SECONDS = {"neck": 1.63e-3, "meeting pair": 1.93e-3}
ANNOUNCE_FROM = 1_000_000  # runs of this many particles or more say what they will take before they start
ANNOUNCE_SECONDS = 10.0  #: so do runs whose estimated steady solve takes this long (s)
BASE_BYTES = 0.23e9  # the interpreter, numpy, scipy and the compiled kernels (with the per-particle figure: the fit)
SMALL_BYTES = 64e6  # a run whose particles need less than this is never refused: the machine is not asked


def available_bytes() -> float | None:
    """The memory this process can still use: the kernel's ``MemAvailable``, or less under a cgroup limit; None
    where neither can be read (then nothing is refused)."""
    out = None
    try:
        for line in pathlib.Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                out = float(line.split()[1]) * 1024.0
    except (OSError, ValueError, IndexError):
        pass
    try:
        limit = pathlib.Path("/sys/fs/cgroup/memory.max").read_text().strip()
        if limit != "max":
            used = float(pathlib.Path("/sys/fs/cgroup/memory.current").read_text())
            out = min(out if out is not None else float("inf"), float(limit) - used)
    except (OSError, ValueError):
        pass
    if out is None and hasattr(os, "sysconf"):
        try:
            out = float(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
        except (ValueError, OSError):
            pass
    return out


def bytes_per_particle(neck: str = "newton", nodes: str = "particles", moving: bool = False) -> float:
    """The memory a particle takes at the peak of a run (module docstring).

    Parameters
    ----------
    neck : str
        The scene's neck reading (``[conductance] neck``); ``"union"`` costs :data:`UNION_BYTES_PER_PARTICLE`.
    nodes : str
        The network's nodes (``[conductance] nodes``: ``"particles"`` or ``"necks"``); a node per neck on a pair-neck
        reading costs :data:`PAIR_NECK_NODES_BYTES_PER_PARTICLE`.
    moving : bool
        Whether the particles move (with a node per neck on a pair-neck reading a run that hands them over to the
        union holds the elements of both readings).

    Returns
    -------
    float
        Bytes per particle.
    """
    if neck == "union":
        return UNION_BYTES_PER_PARTICLE[nodes]
    if nodes == "necks":
        return PAIR_NECK_NODES_BYTES_PER_PARTICLE["moving" if moving else "static"]
    return BYTES_PER_PARTICLE


def seconds_per_particle(neck: str = "newton", nodes: str = "particles") -> float:
    """The CPU time a particle takes in a steady solve on 2 cores (module docstring).

    Parameters
    ----------
    neck : str
        The scene's neck reading (``[conductance] neck``); ``"union"`` costs :data:`UNION_SECONDS_PER_PARTICLE`.
    nodes : str
        The network's nodes (``[conductance] nodes``: ``"particles"`` or ``"necks"``); a node per neck on a pair-neck
        reading costs :data:`PAIR_NECK_NODES_SECONDS_PER_PARTICLE`.

    Returns
    -------
    float
        Seconds per particle.
    """
    if neck == "union":
        return UNION_SECONDS_PER_PARTICLE[nodes]
    return PAIR_NECK_NODES_SECONDS_PER_PARTICLE if nodes == "necks" else SECONDS_PER_PARTICLE


def check(n: int, name: str, neck: str = "newton", nodes: str = "particles", moving: bool = False) -> None:
    """Refuse ``n`` particles (named ``name`` in the message, e.g. ``"[generator] n"``) when a run of them would need
    more memory than is available (module docstring).

    Parameters
    ----------
    n : int
        Number of particles.
    name : str
        What the message calls the count (``"[generator] n"``, say).
    neck : str
        The scene's neck reading (``[conductance] neck``: the union of spheres costs more per particle).
    nodes : str
        The network's nodes (``[conductance] nodes``: ``"particles"`` or ``"necks"``).
    moving : bool
        Whether the particles move (:func:`bytes_per_particle`).

    Raises
    ------
    ValueError
        A run of ``n`` particles needs more memory than the machine has available.
    """
    each = bytes_per_particle(neck, nodes, moving)
    if each * n < SMALL_BYTES:  # (the interpreter that asks holds its base already)
        return
    need = BASE_BYTES + each * n
    have = available_bytes()
    if have is not None and need > have:
        raise ValueError(f"{name}: a run of {n} particles needs about {need / 2**30:.3g} GiB (about "
                         f"{each / 1e3:.3g} kB per particle at the peak of {_peak(moving)}), and "
                         f"{max(have, 0.0) / 2**30:.3g} GiB are available on this machine: use at most about "
                         f"{max(int((have - BASE_BYTES) / each), 0)} particles")


def estimate(n: int, neck: str = "newton", nodes: str = "particles", moving: bool = False) -> str | None:
    """What a run of ``n`` particles will take, said before it starts where it is large (``n >= ANNOUNCE_FROM``, or a
    steady solve estimated at ``ANNOUNCE_SECONDS`` or more): the memory at the peak of a steady solve and its time on
    2 cores (module docstring); None for smaller runs.

    Parameters
    ----------
    n : int
        Number of particles.
    neck : str
        The scene's neck reading (``[conductance] neck``: :func:`seconds_per_particle`, :func:`bytes_per_particle`).
    nodes : str
        The network's nodes (``[conductance] nodes``: ``"particles"`` or ``"necks"``).
    moving : bool
        Whether the particles move (:func:`bytes_per_particle`).

    Returns
    -------
    str or None
        One line, or None for a small run.
    """
    rate = seconds_per_particle(neck, nodes)
    if n < ANNOUNCE_FROM and rate * n < ANNOUNCE_SECONDS:
        return None
    need = BASE_BYTES + bytes_per_particle(neck, nodes, moving) * n
    return (f"{n} particles: about {need / 2**30:.3g} GiB at the peak of {_peak(moving)} and about "
            f"{rate * n:.3g} s for it on 2 cores (a transient or moving run takes longer)")


def element_seconds(necks, meeting) -> float:
    """The CPU time of building the Trefftz elements of particles with ``necks`` necks each, ``meeting`` pairs of which
    meet (:data:`TREFFTZ_SECONDS`).

    Parameters
    ----------
    necks : array_like of int
        Per particle, its necks (or their sum over some particles).
    meeting : array_like of int
        Per particle, the pairs of its necks that meet (:func:`dem.geometry.necks.pairs_meeting`; or their sum).

    Returns
    -------
    float
        Seconds on one core.
    """
    return float(TREFFTZ_SECONDS["neck"] * np.sum(necks) + TREFFTZ_SECONDS["meeting pair"] * np.sum(meeting))


def element_estimate(particles, necks, meeting, workers) -> str | None:
    """What building the Trefftz elements will take (:func:`element_seconds`), said before it starts where it is large
    (``ANNOUNCE_SECONDS`` or more on one core in all); None for less. Given per process that builds a share of them:
    one without MPI; on MPI ranks, each building its own particles', one line for all of them, with the wall time of
    the busiest rank (the largest of the ranks' CPU times over their threads), which the solve waits for.

    Parameters
    ----------
    particles : array_like of int
        Per process, the particles whose elements it builds.
    necks : array_like of int
        Per process, the necks of those particles.
    meeting : array_like of int
        Per process, the pairs of those particles' necks that meet (:func:`dem.geometry.necks.pairs_meeting`).
    workers : array_like of int
        Per process, the threads that share its CPU time (:func:`dem.network.trefftz_element.trefftz_elements`'
        ``workers``), named in the line where more than one.

    Returns
    -------
    str or None
        One line, or None.
    """
    n, z, m, w = (np.asarray(v, dtype=np.int64) for v in (particles, necks, meeting, workers))
    each = np.array([element_seconds(*counts) for counts in zip(z, m)])  # per process, on one core
    seconds = element_seconds(z, m)
    if seconds < ANNOUNCE_SECONDS:
        return None
    counts = f"({z.sum() / n.sum():.3g} necks each on average, {int(m.sum())} pairs of necks meeting)"
    if len(n) == 1:
        return (f"the Trefftz elements of {int(n[0])} particles {counts}: about {seconds:.3g} s on one core"
                f"{f', shared by {w[0]} threads' if w[0] > 1 else ''}, before the solve")
    k = int(np.argmax(each / w))  # the busiest rank
    return (f"the Trefftz elements of {int(n.sum())} particles on {len(n)} ranks {counts}: about {seconds:.3g} s on "
            f"one core in all, about {each[k] / w[k]:.3g} s on the busiest rank"
            f"{f' (its {each[k]:.3g} s shared by {w[k]} threads)' if w[k] > 1 else ''}, before the solve")


_SAY = contextvars.ContextVar("say", default=None)


@contextlib.contextmanager
def announcing(say):
    """Within the block, :func:`announce` hands its lines to ``say`` (the driver's stderr where a run reports its
    progress); None: they are dropped.

    Parameters
    ----------
    say : callable or None
        Called with each line.
    """
    token = _SAY.set(say)
    try:
        yield
    finally:
        _SAY.reset(token)


def announce(line: str | None) -> None:
    """Say ``line`` where the run announces what it will take (:func:`announcing`); None or no listener: nothing.

    Parameters
    ----------
    line : str or None
        The line (an estimate).
    """
    say = _SAY.get()
    if line is not None and say is not None:
        say(line)


def _peak(moving: bool) -> str:
    """What the memory figure is the peak of, in the messages."""
    return "a moving run" if moving else "a steady solve"
