r"""Plane walls, and the box they enclose -- one wall for every engine.

A wall is the plane ``n . x = q`` with unit normal ``n`` pointing into the packing, through ``point``. Particles that
touch it exchange heat with it when it carries a ``temperature`` (an isothermal plane of the thermal network: the
static scenes' plates, the heated walls of moving scenes), and push on it when they move. It moves along its normal
only, so its state is the offset ``q`` and the normal velocity ``dq/dt`` (positive: into the packing):

* ``"fixed"`` -- never moves.
* ``"stress"`` -- :math:`m_w \ddot q = p L - F_w - \gamma_w \dot q` (Luding 2005, eq. 1): the external pressure ``p``
  times the wall's extent ``L`` pushes it in, the particles push it out with the normal force ``F_w`` they exert on it,
  and the damping :math:`\gamma_w` (kg/s) calms it. In 2D (disks of height h) ``p`` is a force per length (N/m, as in
  the paper) and ``L`` the distance between the two walls perpendicular to the wall in the x-z plane; in 3D ``p`` is a
  stress (Pa) and ``L`` the area between the four perpendicular walls. Stress walls therefore need an axis-aligned box:
  a wall facing each way along every perpendicular in-plane axis, or a periodic box along it (whose period is the extent
  there: a stress wall presses a bed in a box periodic across it).
* ``"strain"`` -- moves in at the constant ``velocity`` (m/s); a compression at strain rate ``e`` of a box of
  initial height :math:`z_0` is a ``velocity`` of :math:`e z_0` (Luding 2005, Sec. 4.4: :math:`\varepsilon_{zz} = 1 - z/z_0`).
* ``"vibrate"`` -- :math:`q(t) = q_0 + A \sin(2 \pi f t)`: a vibrating base (Luding 2005, Figs. 21-22).

The box (:func:`box_axes`): along each axis, the wall facing +axis and the one facing -axis, where there is exactly
one of each; the box's extent along that axis is ``-(q_lo + q_hi)`` (:func:`extent`). Stress walls take their
extent from it, and the outputs their volume, cross-sections and lengths.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np

from dem.geometry.particles import check_temperature, check_unit_vector, check_vector

MOTIONS = {"fixed": 0, "stress": 1, "strain": 2, "vibrate": 3}


def _nonnegative(name: str, value, positive: bool = False) -> float:
    if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value) or value < 0 \
            or (positive and value == 0):
        raise ValueError(f"{name} = {value!r}: must be a finite number {'> 0' if positive else '>= 0'}")
    return float(value)


@dataclass(frozen=True)
class Wall:
    r"""One plane wall (module docstring). ``temperature`` (optional): an isothermal plane; ``motion`` and its
    parameters: ``pressure`` N/m (2D) or Pa (3D), ``mass`` kg, ``damping`` kg/s, ``velocity`` m/s, ``amplitude`` m,
    ``frequency`` Hz.

    Parameters
    ----------
    name : str
        The wall's name in the scene (error messages say ``walls.<name>``).
    point : array_like
        A point of the plane, [x, y, z] (m).
    normal : array_like
        Unit normal [x, y, z] pointing into the packing (dimensionless).
    temperature : float or None
        Temperature of an isothermal wall (the scene's unit, K or degC); None: the wall exchanges no heat.
    motion : str
        How the wall moves along its normal: ``"fixed"``, ``"stress"``, ``"strain"`` or ``"vibrate"`` (module
        docstring).
    pressure : float
        External pressure of a stress wall, ``p >= 0``: N/m in 2D, Pa in 3D.
    mass : float
        Mass ``m_w > 0`` of a stress wall (kg).
    damping : float
        Damping :math:`\gamma_w \ge 0` of a stress wall (kg/s).
    velocity : float
        Constant normal velocity of a strain wall, positive into the packing (m/s).
    amplitude : float
        Amplitude ``A >= 0`` of a vibrating wall (m).
    frequency : float
        Frequency ``f >= 0`` of a vibrating wall (Hz).

    Raises
    ------
    ValueError
        A parameter is malformed or out of its range; the message names it (``walls.<name>.<parameter>``).
    """

    name: str
    point: np.ndarray
    normal: np.ndarray
    temperature: float | None = None
    motion: str = "fixed"
    pressure: float = 0.0
    mass: float = 0.0
    damping: float = 0.0
    velocity: float = 0.0
    amplitude: float = 0.0
    frequency: float = 0.0

    def __post_init__(self):
        pre = f"walls.{self.name}"
        object.__setattr__(self, "point", check_vector(f"{pre}.point", self.point))
        object.__setattr__(self, "normal", check_unit_vector(f"{pre}.normal", self.normal))
        if self.temperature is not None:
            check_temperature(f"{pre}.temperature", self.temperature)
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

    @property
    def offset(self) -> float:
        """``q`` of the plane ``n . x = q``."""
        return float(self.normal @ self.point)

    def distance(self, position: np.ndarray) -> np.ndarray:
        """Signed distance of each point from the plane, ``n . x - q`` (positive on the packing's side).

        Parameters
        ----------
        position : numpy.ndarray
            Points, shape (N, 3) or (3,) (m).

        Returns
        -------
        numpy.ndarray
            The signed distances (m), shape (N,) or scalar.
        """
        return position @ self.normal - self.offset

    def at(self, offset: float) -> "Wall":
        """The same wall moved along its normal to the plane ``n . x = offset``.

        Parameters
        ----------
        offset : float
            The new offset ``q`` of the plane (m).

        Returns
        -------
        Wall
            A copy through the point ``offset * normal``.
        """
        return replace(self, point=self.normal * offset)


def check_inside(walls, position: np.ndarray, ids: np.ndarray | None = None) -> None:
    """Refuse a particle whose centre starts behind a wall (``n . x < q``: outside the box the walls enclose),
    naming the particle, the wall and how far behind it lies. Such a particle would be bonded to that wall with an
    overlap beyond its radius (a static network), or be reported as leaving the box at the first step (moving
    particles).

    Parameters
    ----------
    walls : sequence of Wall
        The walls.
    position : numpy.ndarray
        Particle centres, shape (N, 3) (m).
    ids : numpy.ndarray or None
        The particles' ids, shape (N,), named in the message where they differ from the index; None: indices only.

    Raises
    ------
    ValueError
        A centre lies behind a wall (``n . x < q``); the message names the particle, the wall and the depth (m).
    """
    if not walls or len(position) == 0:
        return
    normal = np.array([w.normal for w in walls])
    depth = np.array([w.offset for w in walls])[None, :] - np.asarray(position) @ normal.T  # > 0: behind
    behind = np.argwhere(depth > 0.0)
    if behind.size:
        k, m = (int(v) for v in behind[0])
        label = f"particle {k}" + (f" (id {int(ids[k])})" if ids is not None and int(ids[k]) != k else "")
        centre = ", ".join(f"{v:.6g}" for v in position[k])
        others = len(np.unique(behind[:, 0])) - 1
        more = f" (and {others} other particle{'s' if others > 1 else ''})" if others else ""
        raise ValueError(f"{label}: its centre [{centre}] m lies {depth[k, m]:.6g} m behind wall {walls[m].name!r}"
                         f"{more}: every particle must start on the packing's side of every wall (inside the box they "
                         f"enclose); move the particle or the wall")


def axis_of(normal: np.ndarray) -> int | None:
    """The axis an axis-aligned normal points along, else None.

    Parameters
    ----------
    normal : numpy.ndarray
        A unit normal [x, y, z] (dimensionless).

    Returns
    -------
    int or None
        0, 1 or 2 (x, y, z) where the normal lies along that axis (within 1e-12), else None.
    """
    k = int(np.argmax(np.abs(normal)))
    return k if abs(abs(normal[k]) - 1.0) < 1e-12 else None


def box_axes(walls) -> dict[int, tuple[int, int]]:
    """``{axis: (lo, hi)}``: along each axis the index of the one wall facing +axis (``lo``) and of the one facing
    -axis (``hi``), for the axes that have exactly one of each.

    Parameters
    ----------
    walls : sequence of Wall
        The walls.

    Returns
    -------
    dict
        ``{axis: (lo, hi)}``, indices into ``walls``.
    """
    out = {}
    for a in range(3):
        lo = [m for m, w in enumerate(walls) if axis_of(w.normal) == a and w.normal[a] > 0]
        hi = [m for m, w in enumerate(walls) if axis_of(w.normal) == a and w.normal[a] < 0]
        if len(lo) == 1 and len(hi) == 1:
            out[a] = (lo[0], hi[0])
    return out


def extent(q: np.ndarray, lo: int, hi: int) -> float:
    """Distance between two opposite axis-aligned walls at offsets ``q``.

    Parameters
    ----------
    q : numpy.ndarray
        The walls' offsets ``q`` of their planes ``n . x = q`` (m).
    lo : int
        Index of the wall facing +axis.
    hi : int
        Index of the wall facing -axis.

    Returns
    -------
    float
        ``-(q[lo] + q[hi])``, the distance between their planes (m).
    """
    return float(-(q[lo] + q[hi]))


class WallArrays(NamedTuple):
    """The walls' state and parameters as arrays for the compiled loops (mutated in place); W walls. A named tuple:
    the compiled loops take it as one argument (:mod:`dem.engines.records`).

    Parameters
    ----------
    normal : numpy.ndarray
        (W, 3) unit normals pointing into the packing.
    q : numpy.ndarray
        (W,) offsets of the planes ``n . x = q`` (m).
    dq : numpy.ndarray
        (W,) normal velocities, positive into the packing (m/s).
    acc : numpy.ndarray
        (W,) normal accelerations of stress walls (m/s^2).
    mode : numpy.ndarray
        (W,) int, each wall's motion as its code in ``MOTIONS``.
    pressure : numpy.ndarray
        (W,) a stress wall's pressure (N/m in 2D, Pa in 3D) times the product of the box's periods (m) along its
        periodic in-plane axes.
    mass : numpy.ndarray
        (W,) stress-wall masses (kg).
    damping : numpy.ndarray
        (W,) stress-wall damping coefficients (kg/s).
    q0 : numpy.ndarray
        (W,) the offsets at the start, about which vibrating walls oscillate (m).
    amplitude : numpy.ndarray
        (W,) vibration amplitudes (m).
    frequency : numpy.ndarray
        (W,) vibration frequencies (Hz).
    span : numpy.ndarray
        (W, 4) int: the (lo, hi) indices of the walls bounding each of the wall's (up to two) perpendicular axes,
        -1 where none.
    force : numpy.ndarray
        (W,) normal force the particles exert on each wall, pushing outward positive (N).
    """

    normal: np.ndarray     # (W, 3)
    q: np.ndarray          # (W,) offsets n . x = q
    dq: np.ndarray         # (W,) normal velocities (inward positive)
    acc: np.ndarray        # (W,) accelerations of stress walls
    mode: np.ndarray       # (W,) int, MOTIONS
    pressure: np.ndarray   # (W,) of a stress wall, times the box's periods along its periodic in-plane axes
    mass: np.ndarray
    damping: np.ndarray
    q0: np.ndarray
    amplitude: np.ndarray
    frequency: np.ndarray
    span: np.ndarray       # (W, 4) int: (lo, hi) wall indices bounding each of two perpendicular axes, -1: none
    force: np.ndarray      # (W,) normal force the particles exert on each wall (N, pushing outward > 0)

    @classmethod
    def build(cls, walls, dimension: int, periods=None) -> "WallArrays":
        """The arrays of ``walls`` (``dimension`` 2 or 3); ``periods`` (3,) m: the periodic box's lengths, 0 along
        its non-periodic axes (None: no periodic box). Along a periodic in-plane axis a stress wall's extent is the
        period, folded into its ``pressure`` (the kernels multiply that by the extent between the walls).

        Parameters
        ----------
        walls : sequence of Wall
            The walls.
        dimension : int
            2 (disks in the x-z plane) or 3.
        periods : array_like or None
            (3,) the periodic box's lengths (m), 0 along its non-periodic axes; None: no periodic box.

        Returns
        -------
        WallArrays
            The arrays, walls at rest except strain and vibrating ones.

        Raises
        ------
        ValueError
            A stress wall is not axis-aligned or lacks the box (walls or periods) that gives its extent.
        """
        periods = np.zeros(3) if periods is None else np.asarray(periods, dtype=float)
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
        box = box_axes(walls)
        for k, wall in enumerate(walls):
            axis = axis_of(wall.normal)
            perpendicular = [a for a in range(3) if a != axis and not (dimension == 2 and a == 1)]
            bounded = [a for a in perpendicular if periods[a] == 0.0]  # by walls; the others by the box's period
            if wall.motion == "stress":  # a stress wall needs its extent; the others report a force then
                if axis is None:
                    raise ValueError(f"walls.{wall.name}: a stress-controlled wall must be axis-aligned (normal "
                                     f"along x, y or z)")
                missing = [a for a in bounded if a not in box]
                if missing:
                    raise ValueError(f"walls.{wall.name}: a stress-controlled wall needs one wall facing each way "
                                     f"along the {'xyz'[missing[0]]} axis, or a periodic {'xyz'[missing[0]]} axis "
                                     f"(the box that gives its {'length' if dimension == 2 else 'area'})")
            if axis is not None and all(a in box for a in bounded):
                pairs = [m for a in bounded for m in box[a]]
                arrays.span[k] = pairs + [-1] * (4 - len(pairs))
                arrays.pressure[k] *= float(np.prod([periods[a] for a in perpendicular if a not in bounded]))
        return arrays

    @staticmethod
    def periodic_extent(wall, dimension: int, periods) -> tuple[float, int]:
        """The product of the periods along ``wall``'s periodic in-plane axes (m or m^2; 1 for none) and their
        count.

        Parameters
        ----------
        wall : Wall
            The wall.
        dimension : int
            2 (disks in the x-z plane: y is not in-plane) or 3.
        periods : array_like or None
            (3,) the periodic box's lengths (m), 0 along its non-periodic axes; None: no periodic box.

        Returns
        -------
        tuple of (float, int)
            The product of the periods (m along one axis, m^2 along two; 1.0 for none) and how many there are.
        """
        axis = axis_of(wall.normal)
        periods = np.zeros(3) if periods is None else np.asarray(periods, dtype=float)
        along = [periods[a] for a in range(3) if a != axis and not (dimension == 2 and a == 1) and periods[a] > 0]
        return float(np.prod(along)), len(along)

    def extent(self, lo: int, hi: int) -> float:
        """Distance between two opposite axis-aligned walls.

        Parameters
        ----------
        lo : int
            Index of the wall facing +axis.
        hi : int
            Index of the wall facing -axis.

        Returns
        -------
        float
            The distance between their planes at their current offsets (m).
        """
        return extent(self.q, lo, hi)
