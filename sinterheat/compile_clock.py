"""The CPU time numba spends compiling kernels or loading them from its cache, apart from the work that calls them.

A kernel's first call in a process compiles it (tens of seconds for the larger ones on a cold cache) or loads it from
numba's on-disk cache (:mod:`sinterheat.jit_cache`); a figure such as "the CPU time of building the elements" would
otherwise count that once-per-process cost as the work's own. numba holds its compiler lock for both and says so by
its ``numba:compiler_lock`` events (``numba.core.event``, numba's event API), which :func:`compiling` listens to.
"""

from __future__ import annotations

import contextlib
import threading
import time

from numba.core import event


class CompileClock(event.Listener):
    """A listener to numba's ``numba:compiler_lock`` events that keeps, for each time a thread held the lock, that
    thread's CPU time while it did (``time.thread_time``, from its outermost acquiring to its last release: waiting
    for the lock costs none). numba calls ``on_start`` as a thread acquires the lock and ``on_end`` as it releases
    it (``numba.core.event.Listener``).

    Attributes
    ----------
    seconds : list of float
        The CPU time of each holding, s.
    """

    def __init__(self):
        self.seconds = []
        self.held = threading.local()  # per thread, its depth of acquiring and its CPU time at the outermost

    def on_start(self, ev):
        """The lock acquired.

        Parameters
        ----------
        ev : object
            numba's event (a ``numba.core.event.Event``; not read).
        """
        depth = getattr(self.held, "depth", 0)
        if depth == 0:
            self.held.start = time.thread_time()
        self.held.depth = depth + 1

    def on_end(self, ev):
        """The lock released.

        Parameters
        ----------
        ev : object
            numba's event (a ``numba.core.event.Event``; not read).
        """
        self.held.depth -= 1
        if self.held.depth == 0:
            self.seconds.append(time.thread_time() - self.held.start)

    @property
    def total(self) -> float:
        """The CPU time of all the holdings, s."""
        return float(sum(self.seconds))


@contextlib.contextmanager
def compiling():
    """A :class:`CompileClock` listening while the body runs.

    Yields
    ------
    CompileClock
        The clock; its ``total`` is the CPU time numba held its compiler lock for inside the body, s.
    """
    clock = CompileClock()
    with event.install_listener("numba:compiler_lock", clock):
        yield clock
