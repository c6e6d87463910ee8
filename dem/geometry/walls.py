"""Plane walls that move: fixed, stress-controlled (Luding 2005, eq. 1), strain-controlled, vibrating.

A wall is the plane ``n . x = q`` with unit normal ``n`` pointing into the packing; it moves along its normal only,
so its state is the offset ``q`` and the normal velocity ``dq/dt`` (positive: the wall moves into the packing).

* ``"fixed"`` -- never moves.
* ``"stress"`` -- ``m_w d^2q/dt^2 = p L - F_w - gamma_w dq/dt`` (Luding 2005, eq. 1): the external pressure ``p``
  times the wall's extent ``L`` pushes it in, the particles push it out with the normal force ``F_w`` they exert on
  it, and the damping ``gamma_w`` (kg/s) calms it. In 2D (disks of height h) ``p`` is a force per length (N/m, as in
  the paper) and ``L`` the distance between the two walls perpendicular to the wall in the x-z plane; in 3D ``p`` is
  a stress (Pa) and ``L`` the area between the four perpendicular walls. Stress walls therefore need an axis-aligned
  box: a wall facing each way along every perpendicular in-plane axis.
* ``"strain"`` -- moves in at the constant ``velocity`` (m/s); a compression at strain rate ``e`` of a box of
  initial height ``z0`` is ``velocity = e z0`` (Luding 2005, Sec. 4.4: ``eps_zz = 1 - z/z0``).
* ``"vibrate"`` -- ``q(t) = q0 + A sin(2 pi f t)``: a vibrating base (Luding 2005, Figs. 21-22).

A wall may also carry a ``temperature`` (an isothermal plane of the thermal network, as :class:`dem.laws.ambient.Wall`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from dem.laws.ambient import _temperature, _unit_vector, _vector

MOTIONS = {"fixed": 0, "stress": 1, "strain": 2, "vibrate": 3}


def _nonnegative(name: str, value, positive: bool = False) -> float:
    if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value) or value < 0 \
            or (positive and value == 0):
        raise ValueError(f"{name} = {value!r}: must be a finite number {'> 0' if positive else '>= 0'}")
    return float(value)


@dataclass(frozen=True)
class MovingWall:
    """One plane wall (module docstring). ``pressure`` N/m (2D) or Pa (3D); ``mass`` kg; ``damping`` kg/s;
    ``velocity`` m/s; ``amplitude`` m; ``frequency`` Hz; ``temperature`` optional (thermal runs)."""

    name: str
    point: np.ndarray
    normal: np.ndarray
    motion: str = "fixed"
    pressure: float = 0.0
    mass: float = 0.0
    damping: float = 0.0
    velocity: float = 0.0
    amplitude: float = 0.0
    frequency: float = 0.0
    temperature: float | None = None

    def __post_init__(self):
        pre = f"walls.{self.name}"
        object.__setattr__(self, "point", _vector(f"{pre}.point", self.point))
        object.__setattr__(self, "normal", _unit_vector(f"{pre}.normal", self.normal))
        if self.motion not in MOTIONS:
            raise ValueError(f"{pre}.motion = {self.motion!r}: must be one of {', '.join(MOTIONS)}")
        if self.motion == "stress":
            _nonnegative(f"{pre}.pressure", self.pressure)
            _nonnegative(f"{pre}.mass", self.mass, positive=True)
            _nonnegative(f"{pre}.damping", self.damping)
        if self.motion == "strain" and (not isinstance(self.velocity, (int, float)) or isinstance(self.velocity, bool)
                                        or not math.isfinite(self.velocity)):
            raise ValueError(f"{pre}.velocity = {self.velocity!r}: must be a finite number (m/s, positive inward)")
        if self.motion == "vibrate":
            _nonnegative(f"{pre}.amplitude", self.amplitude)
            _nonnegative(f"{pre}.frequency", self.frequency)
        if self.temperature is not None:
            _temperature(f"{pre}.temperature", self.temperature)

    @property
    def offset(self) -> float:
        return float(self.normal @ self.point)


@dataclass
class WallArrays:
    """The walls' state and parameters as arrays for the compiled loop (mutated in place)."""

    normal: np.ndarray     # (W, 3)
    q: np.ndarray          # (W,) offsets n . x = q
    dq: np.ndarray         # (W,) normal velocities (inward positive)
    acc: np.ndarray        # (W,) accelerations of stress walls
    mode: np.ndarray       # (W,) int, MOTIONS
    pressure: np.ndarray
    mass: np.ndarray
    damping: np.ndarray
    q0: np.ndarray
    amplitude: np.ndarray
    frequency: np.ndarray
    span: np.ndarray       # (W, 4) int: (lo, hi) wall indices bounding each of two perpendicular axes, -1: none
    force: np.ndarray      # (W,) normal force the particles exert on each wall (N, pushing outward > 0)

    @classmethod
    def build(cls, walls, dimension: int) -> "WallArrays":
        n_w = len(walls)
        normal = np.array([w.normal for w in walls], dtype=float).reshape(n_w, 3)
        q = np.array([w.offset for w in walls], dtype=float)
        mode = np.array([MOTIONS[w.motion] for w in walls], dtype=np.int64)
        dq = np.array([w.velocity if w.motion == "strain" else 0.0 for w in walls], dtype=float)
        freq = np.array([w.frequency for w in walls], dtype=float)
        amp = np.array([w.amplitude for w in walls], dtype=float)
        dq += np.where(mode == MOTIONS["vibrate"], 2.0 * np.pi * freq * amp, 0.0)
        arrays = cls(normal, q, dq, np.zeros(n_w), mode, np.array([w.pressure for w in walls], dtype=float),
                     np.array([w.mass for w in walls], dtype=float), np.array([w.damping for w in walls], dtype=float),
                     q.copy(), amp, freq, -np.ones((n_w, 4), dtype=np.int64), np.zeros(n_w))
        for k, wall in enumerate(walls):
            try:
                arrays.span[k] = _span(walls, k, dimension)
            except ValueError:
                if wall.motion == "stress":  # a stress wall needs its extent; the others report a force then
                    raise
        return arrays

    def extent(self, lo: int, hi: int) -> float:
        """Distance between two opposite axis-aligned walls."""
        return -(self.q[lo] + self.q[hi])


def _axis(normal: np.ndarray) -> int | None:
    """The axis an axis-aligned normal points along, else None."""
    k = int(np.argmax(np.abs(normal)))
    return k if abs(abs(normal[k]) - 1.0) < 1e-12 else None


def _span(walls, k: int, dimension: int) -> list[int]:
    """Indices of the walls bounding the perpendicular axes of stress wall ``k`` (module docstring)."""
    wall = walls[k]
    axis = _axis(wall.normal)
    if axis is None:
        raise ValueError(f"walls.{wall.name}: a stress-controlled wall must be axis-aligned (normal along x, y or z)")
    perpendicular = [a for a in range(3) if a != axis and not (dimension == 2 and a == 1)]
    out = []
    for a in perpendicular:
        lo = [m for m, w in enumerate(walls) if _axis(w.normal) == a and w.normal[a] > 0]
        hi = [m for m, w in enumerate(walls) if _axis(w.normal) == a and w.normal[a] < 0]
        if len(lo) != 1 or len(hi) != 1:
            raise ValueError(f"walls.{wall.name}: a stress-controlled wall needs one wall facing each way along the "
                             f"{'xyz'[a]} axis (the box that gives its {'length' if dimension == 2 else 'area'})")
        out += [lo[0], hi[0]]
    return out + [-1] * (4 - len(out))
