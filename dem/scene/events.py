"""A prescribed temperature history: piecewise linear in time, uniform over the particles (Luding 2005, Fig. 7).

The paper heats and cools the whole sample by prescription ("heat conduction and equilibration take place
instantaneously", Sec. 3.4) and, during sintering, shortens the relaxation time ``t0`` of eqs. 11-12 so that the
long-time behaviour fits into a short simulation (Sec. 4.1). A :class:`TemperatureSchedule` holds both: the knots
``(time, value)`` and one relaxation time per segment between knots. Before the first knot and after the last the
temperature is constant (and the last segment's relaxation time holds).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class TemperatureSchedule:
    """A piecewise linear temperature history with one relaxation time per segment (module docstring).

    Parameters
    ----------
    time : tuple of float
        The knots' times (s), strictly increasing, at least one.
    value : tuple of float
        The temperature at each knot (the scene's unit, K or degC).
    relaxation_time : tuple of float
        The relaxation time ``t0`` of eqs. 11-12 on each segment between knots (s, > 0): ``len(time) - 1`` of them
        (one with a single knot).

    Raises
    ------
    ValueError
        A field has a bad length or value (the message names it).
    """

    time: tuple
    value: tuple
    relaxation_time: tuple

    def __post_init__(self):
        t = np.asarray(self.time, dtype=float)
        T = np.asarray(self.value, dtype=float)
        if t.ndim != 1 or len(t) < 1 or not np.all(np.isfinite(t)):
            raise ValueError(f"[temperature] time = {list(self.time)!r}: must be a non-empty list of finite times (s)")
        if np.any(np.diff(t) <= 0):
            k = int(np.flatnonzero(np.diff(t) <= 0)[0]) + 1
            raise ValueError(f"[temperature] time[{k}] = {t[k]:g}: times must increase strictly")
        if T.shape != t.shape or not np.all(np.isfinite(T)):
            raise ValueError(f"[temperature] value: must be {len(t)} finite temperatures (one per time)")
        t0 = np.asarray(self.relaxation_time, dtype=float)
        if t0.shape != (max(len(t) - 1, 1),) or not np.all(np.isfinite(t0)) or np.any(t0 <= 0):
            raise ValueError(f"[temperature] relaxation_time = {list(self.relaxation_time)!r}: must be one number > 0 "
                             f"(s) or {max(len(t) - 1, 1)} of them (one per segment between the times)")

    @classmethod
    def build(cls, time, value, relaxation_time) -> "TemperatureSchedule":
        """Scalars or lists; a scalar ``relaxation_time`` applies to every segment.

        Parameters
        ----------
        time : float or sequence of float
            The knots' times (s).
        value : float or sequence of float
            The temperature at each knot (K or degC).
        relaxation_time : float or sequence of float
            One relaxation time (s) for every segment, or one per segment.

        Returns
        -------
        TemperatureSchedule
            The schedule.

        Raises
        ------
        ValueError
            The lists do not fit together, or a value is bad.
        """
        time = tuple(np.atleast_1d(np.asarray(time, dtype=float)).tolist())
        segments = max(len(time) - 1, 1)
        t0 = np.atleast_1d(np.asarray(relaxation_time, dtype=float))
        t0 = np.full(segments, t0[0]) if t0.size == 1 else t0
        return cls(time, tuple(np.atleast_1d(np.asarray(value, dtype=float)).tolist()), tuple(t0.tolist()))

    def segment(self, t: float) -> int:
        """Index of the segment ``[time[k], time[k+1])`` holding ``t`` (clamped to the first and last).

        Parameters
        ----------
        t : float
            Time (s).

        Returns
        -------
        int
            The segment's index, from 0.
        """
        k = int(np.searchsorted(self.time, t, side="right")) - 1
        return min(max(k, 0), max(len(self.time) - 2, 0))

    def at(self, t: float) -> float:
        """The temperature at ``t``, interpolated linearly between the knots, constant outside them.

        Parameters
        ----------
        t : float
            Time (s).

        Returns
        -------
        float
            The temperature (K or degC).
        """
        return float(np.interp(t, self.time, self.value))

    def rate(self, t: float) -> float:
        """dT/dt on the segment that starts at or before ``t`` (0 outside the knots).

        Parameters
        ----------
        t : float
            Time (s).

        Returns
        -------
        float
            The heating rate (K/s).
        """
        if len(self.time) < 2 or t < self.time[0] or t >= self.time[-1]:
            return 0.0
        k = self.segment(t)
        return (self.value[k + 1] - self.value[k]) / (self.time[k + 1] - self.time[k])

    def relaxation(self, t: float) -> float:
        """The relaxation time of the segment holding ``t``.

        Parameters
        ----------
        t : float
            Time (s).

        Returns
        -------
        float
            ``t0`` (s).
        """
        return self.relaxation_time[self.segment(t)]

