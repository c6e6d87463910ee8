"""Packings stored in parts, so that each rank of a distributed run reads only its own part.

A packing in parts is a folder ``NAME.parts`` of blocks, ``block-NNNNN.npz`` (numpy's own format: arrays read one
by one, no other library), and ``index.json``, written last, which says what the blocks hold. The blocks are the
cells of a recursive coordinate bisection of the centres (:func:`dem.geometry.bisection.bisection`): compact
regions of (almost) equal counts. Each block holds its particles in the packing's order with their place in it
(``index``, from 0), ids, centres (m), radii (m) and the optional per-particle arrays of a
:class:`dem.scene.packing_files.packing.Packing` that the packing has. The index gives, per block, its file, its count,
the bounding box of its centres and its largest radius; for the packing, its count, its box and periodic axes, the
extent of its particles' surfaces and their largest radius. The particles held at their temperature (``fixed``), if
any, are also in ``held.npz`` (as a block): the ends of the specimen and the groups of ``boundary_heat_flow`` are
found over all of them (:mod:`dem.scene.specimen`), which every rank reads.

Read whole (:func:`read_whole`: what ``[particles] file`` reads on one process, and ``python -m dem convert``), a
packing in parts is the packing it was written from, in its order, to the bit. Read in part (:func:`read_part`),
rank ``r`` of ``R`` gets its blocks -- a bisection of the blocks' centres weighted by their counts -- and the
particles of the other blocks within one bond length (two largest radii) of the bounding box of its centres
(:func:`dem.geometry.bisection.halo`, periodic axes wrapped), having opened only the blocks whose boxes come that
close: every bond of an owned particle has its partner among those it holds, so the distributed static engine
(:mod:`dem.engines.distributed`) builds its rows from them alone. No rank holds the whole packing; the index (some
hundred bytes per block) is read by all.

Per-block ``.npz`` files rather than one HDF5 file: numpy reads them, so the MPI extra (Debian's petsc4py, which
needs numpy < 2) takes no further library, and a block is the unit a rank reads whole.
"""

from __future__ import annotations

import json
import math
import pathlib
from dataclasses import dataclass

import numpy as np

from dem.geometry.bisection import HALO_MARGIN, bisection, halo
from dem.output.atomic import write_aside
from dem.scene.packing_files.packing import Packing

SUFFIX = ".parts"
INDEX = "index.json"
HELD = "held.npz"  # the fixed particles of the whole packing
KIND = "sinterheat packing in parts"
VERSION = 1
OPTIONAL = ("temperature", "fixed", "material", "density", "velocity", "angular_velocity", "image")
BLOCK_PARTICLES = 2**16  # the default block holds about this many particles (some MB)
BLOCKS_MIN = 64  # ... and a packing of more than BLOCKS_MIN * MIN_PER_BLOCK particles has at least this many blocks
MIN_PER_BLOCK = 1000


def is_parts(path) -> bool:
    """Whether ``path`` names a packing in parts (a name ending ``.parts``).

    Parameters
    ----------
    path : str or pathlib.Path
        The path.

    Returns
    -------
    bool
        True for ``NAME.parts``.
    """
    return pathlib.Path(path).suffix.lower() == SUFFIX


def default_blocks(n: int) -> int:
    """The number of blocks :func:`write_parts` makes of ``n`` particles by default: about ``BLOCK_PARTICLES`` each,
    at least ``BLOCKS_MIN`` (so that up to that many ranks read balanced parts) while a block keeps
    ``MIN_PER_BLOCK`` particles, at least one.

    Parameters
    ----------
    n : int
        The number of particles.

    Returns
    -------
    int
        The number of blocks.
    """
    return max(1, min(max(BLOCKS_MIN, math.ceil(n / BLOCK_PARTICLES)), n // MIN_PER_BLOCK))


@dataclass(frozen=True)
class Index:
    """What ``index.json`` of a packing in parts says (module docstring).

    Parameters
    ----------
    n : int
        The number of particles.
    files : tuple of str
        Each block's file, in the folder.
    count : numpy.ndarray
        (B,) int, each block's particle count.
    lo, hi : numpy.ndarray
        (B, 3) the bounding box of each block's centres (m).
    radius_max : numpy.ndarray
        (B,) each block's largest radius (m).
    extent_lo, extent_hi : numpy.ndarray
        (3,) the extent of the particles' surfaces, ``min(x - r)`` and ``max(x + r)`` per axis (m).
    fields : tuple of str
        The optional per-particle arrays the blocks hold (names of
        :class:`dem.scene.packing_files.packing.Packing` fields).
    fixed : int
        How many particles the packing holds at their temperature (its ``fixed`` flags).
    box_lo, box_hi : numpy.ndarray or None
        (3,) the packing's box (m); None where it has none.
    periodic : tuple or None
        Three bools, the box's periodic axes; None where the packing could not say.
    """

    n: int
    files: tuple
    count: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    radius_max: np.ndarray
    extent_lo: np.ndarray
    extent_hi: np.ndarray
    fields: tuple
    fixed: int
    box_lo: np.ndarray | None
    box_hi: np.ndarray | None
    periodic: tuple | None

    @property
    def blocks(self) -> int:
        """The number of blocks."""
        return len(self.files)


def write_parts(path, packing: Packing, blocks: int | None = None) -> pathlib.Path:
    """Write ``packing`` as a packing in parts (module docstring): the folder ``path`` (made, or emptied of an older
    packing in parts), its blocks, then ``index.json``.

    Parameters
    ----------
    path : str or pathlib.Path
        The folder to write, a name ending ``.parts``.
    packing : dem.scene.packing_files.packing.Packing
        The packing (SI units).
    blocks : int or None
        The number of blocks, 1 ... the particle count; None: :func:`default_blocks`.

    Returns
    -------
    pathlib.Path
        The folder.

    Raises
    ------
    ValueError
        A name not ending ``.parts``, a path that is a file or a folder of something else, or a bad ``blocks``.
    """
    path = pathlib.Path(path)
    if not is_parts(path):
        raise ValueError(f"OUT = {str(path)!r}: a packing in parts is a folder named NAME{SUFFIX}")
    n = packing.n
    blocks = default_blocks(n) if blocks is None else blocks
    if isinstance(blocks, bool) or not isinstance(blocks, (int, np.integer)) or not 1 <= blocks <= n:
        raise ValueError(f"blocks = {blocks!r}: must be an integer from 1 to the particle count {n}")
    if path.exists() and not path.is_dir():
        raise ValueError(f"OUT = {str(path)!r}: is a file, not a folder")
    if path.is_dir():
        alien = [p.name for p in path.iterdir() if not (p.name in (INDEX, HELD) or p.name.startswith("block-"))]
        if alien:
            raise ValueError(f"OUT = {str(path)!r}: holds {alien[0]!r}, not a packing in parts; give another name")
        for old in path.iterdir():
            old.unlink()
    path.mkdir(parents=True, exist_ok=True)
    box = None if packing.box_lo is None else packing.box_hi - packing.box_lo
    lengths = None if box is None or packing.periodic is None else np.where(packing.periodic, box, np.inf)
    block = bisection(packing.position, int(blocks), lengths)
    fields = tuple(k for k in OPTIONAL if getattr(packing, k) is not None)
    members = np.argsort(block, kind="stable")  # each block's particles in the packing's order
    starts = np.searchsorted(block[members], np.arange(blocks + 1))
    entries = []
    for b in range(blocks):
        take = members[starts[b]:starts[b + 1]]
        name = f"block-{b:05d}.npz"
        _write_block(path / name, packing, take, fields)
        x = packing.position[take]
        entries.append({"file": name, "count": len(take), "lo": x.min(axis=0).tolist(), "hi": x.max(axis=0).tolist(),
                        "radius_max": float(packing.radius[take].max())})
    x, r = packing.position, packing.radius
    fixed = 0 if packing.fixed is None else int(np.count_nonzero(packing.fixed))
    if fixed:
        _write_block(path / HELD, packing, np.flatnonzero(packing.fixed), fields)
    index = {"kind": KIND, "version": VERSION, "particles": n, "fields": list(fields), "fixed": fixed,
             "extent_lo": (x - r[:, None]).min(axis=0).tolist(), "extent_hi": (x + r[:, None]).max(axis=0).tolist(),
             "box_lo": None if packing.box_lo is None else np.asarray(packing.box_lo, dtype=float).tolist(),
             "box_hi": None if packing.box_hi is None else np.asarray(packing.box_hi, dtype=float).tolist(),
             "periodic": None if packing.periodic is None else [bool(p) for p in packing.periodic],
             "blocks": entries}
    write_aside(path / INDEX, lambda fh: json.dump(index, fh, indent=1))
    return path


def _write_block(file, packing: Packing, take: np.ndarray, fields) -> None:
    """The particles ``take`` (places in ``packing``, ascending) as one ``.npz`` block."""
    arrays = {"index": take, "id": packing.id[take], "position": packing.position[take], "radius": packing.radius[take]}
    for k in fields:
        value = np.asarray(getattr(packing, k))[take]
        arrays[k] = value.astype(str) if value.dtype.kind == "O" else value
    write_aside(file, lambda fh: np.savez(fh, **arrays), "wb")


def read_index(path) -> Index:
    """The index of the packing in parts ``path`` (module docstring).

    Parameters
    ----------
    path : str or pathlib.Path
        The folder ``NAME.parts``.

    Returns
    -------
    Index
        What its ``index.json`` says.

    Raises
    ------
    ValueError
        No such folder, or no index of a packing in parts in it (one line naming the file).
    """
    file = pathlib.Path(path) / INDEX
    if not file.is_file():
        raise ValueError(f"{path}: no such packing in parts (a folder NAME{SUFFIX} with {INDEX}: python -m dem "
                         "convert IN NAME.parts writes one)")
    try:
        doc = json.loads(file.read_text(encoding="utf-8"))
        if doc.get("kind") != KIND or doc.get("version") != VERSION:
            raise ValueError(f"not the index of a packing in parts (version {VERSION})")
        blocks = doc["blocks"]
        box = [None if doc[k] is None else np.asarray(doc[k], dtype=float) for k in ("box_lo", "box_hi")]
        return Index(int(doc["particles"]), tuple(b["file"] for b in blocks),
                     np.array([b["count"] for b in blocks], dtype=np.int64),
                     np.array([b["lo"] for b in blocks], dtype=float).reshape(-1, 3),
                     np.array([b["hi"] for b in blocks], dtype=float).reshape(-1, 3),
                     np.array([b["radius_max"] for b in blocks], dtype=float),
                     np.asarray(doc["extent_lo"], dtype=float), np.asarray(doc["extent_hi"], dtype=float),
                     tuple(doc["fields"]), int(doc["fixed"]), box[0], box[1],
                     None if doc["periodic"] is None else tuple(bool(p) for p in doc["periodic"]))
    except (ValueError, KeyError, TypeError) as exc:
        raise ValueError(f"{file}: {exc if isinstance(exc, ValueError) else f'missing or bad entry {exc}'}") from None


def _load(file, index: Index, count: int) -> dict:
    """The arrays of one block file, which must hold ``count`` particles."""
    with np.load(file, allow_pickle=False) as data:
        arrays = {k: data[k] for k in ("index", "id", "position", "radius", *index.fields)}
    if len(arrays["index"]) != count:
        raise ValueError(f"{file}: holds {len(arrays['index'])} particles, the index says {count}")
    return arrays


def _read_blocks(path, index: Index, which) -> tuple[np.ndarray, np.ndarray, dict]:
    """The places in the packing (``index`` arrays), the block of each particle and the arrays of the blocks
    ``which``, in the packing's order."""
    path = pathlib.Path(path)
    parts = [_load(path / index.files[b], index, index.count[b]) for b in which]
    arrays = {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
    block = np.repeat(np.asarray(which, dtype=np.int64), index.count[np.asarray(which, dtype=np.int64)])
    order = np.argsort(arrays["index"], kind="stable")
    return arrays.pop("index")[order], block[order], {k: v[order] for k, v in arrays.items()}


def _packing(path, index: Index, arrays: dict) -> Packing:
    return Packing(**arrays, box_lo=index.box_lo, box_hi=index.box_hi, periodic=index.periodic, source=str(path),
                   format="parts")


def read_whole(path) -> Packing:
    """The whole packing in parts ``path``, in the order it was written from (module docstring).

    Parameters
    ----------
    path : str or pathlib.Path
        The folder ``NAME.parts``.

    Returns
    -------
    dem.scene.packing_files.packing.Packing
        The packing (SI units), its ``format`` ``"parts"``.

    Raises
    ------
    ValueError
        A missing or bad index or block.
    """
    index = read_index(path)
    places, _, arrays = _read_blocks(path, index, range(index.blocks))
    if not np.array_equal(places, np.arange(index.n)):
        raise ValueError(f"{path}: its blocks do not hold each of its {index.n} particles once")
    return _packing(path, index, arrays)


@dataclass(frozen=True)
class Part:
    """The part of a packing in parts that one rank holds (:func:`read_part`).

    Parameters
    ----------
    n : int
        The number of particles in the whole packing.
    ranks : int
        The number of ranks it was shared out among.
    held : numpy.ndarray
        (M,) int, the places in the packing (from 0) of the particles the rank holds, sorted.
    owner : numpy.ndarray
        (M,) int, the rank owning each held particle.
    extent_lo, extent_hi : numpy.ndarray
        (3,) the extent of the whole packing's surfaces (m), for the specimen's cross-section.
    blocks_read : int
        How many blocks the rank opened.
    fixed_places : numpy.ndarray
        (K,) int, the places in the packing of all its particles held at their temperature, sorted.
    fixed : object
        Those particles: a :class:`dem.scene.packing_files.packing.Packing` (:func:`read_part`), or the scene's
        :class:`dem.geometry.particles.Particles` of them (:func:`dem.scene.packing_files.scene.scene_particles`); None
        where there are none.
    """

    n: int
    ranks: int
    held: np.ndarray
    owner: np.ndarray
    extent_lo: np.ndarray
    extent_hi: np.ndarray
    blocks_read: int
    fixed_places: np.ndarray
    fixed: object = None


def block_owner(index: Index, ranks: int, lengths=None) -> np.ndarray:
    """The rank owning each block: a bisection of the blocks' centres weighted by their counts.

    Parameters
    ----------
    index : Index
        The packing's index.
    ranks : int
        The number of ranks, 1 ... the number of blocks.
    lengths : numpy.ndarray or None
        (3,) the box's lengths along its periodic axes, ``inf`` along the others (m); None: no box.

    Returns
    -------
    numpy.ndarray
        (B,) int, the rank of each block.

    Raises
    ------
    ValueError
        More ranks than blocks.
    """
    if ranks > index.blocks:
        raise ValueError(f"{ranks} ranks: the packing in parts has {index.blocks} blocks, one rank reads at least "
                         f"one; convert it again with --blocks {ranks} or more")
    return bisection(0.5 * (index.lo + index.hi), ranks, lengths, weights=index.count.astype(float))


def _near(lo: np.ndarray, hi: np.ndarray, region_lo: np.ndarray, region_hi: np.ndarray, lengths, periodic):
    """Mask over boxes ``[lo, hi]``: within the region on every axis, periodic axes wrapped (as
    :func:`dem.geometry.bisection.halo` tests a centre)."""
    near = np.ones(len(lo), dtype=bool)
    for a in range(3):
        inside = (hi[:, a] >= region_lo[a]) & (lo[:, a] <= region_hi[a])
        if periodic is not None and periodic[a]:
            L = lengths[a]
            for shift in (L, -L):
                inside |= (hi[:, a] + shift >= region_lo[a]) & (lo[:, a] + shift <= region_hi[a])
        near &= inside
    return near


def read_part(path, ranks: int, rank: int, box=None, bonds: int = 1) -> tuple[Packing, Part]:
    """The particles that rank ``rank`` of ``ranks`` holds of the packing in parts ``path`` (module docstring):
    those of its blocks and, of the other blocks, those within ``bonds`` bond lengths of its centres' bounding box;
    and the packing's fixed particles (``Part.fixed``).

    Parameters
    ----------
    path : str or pathlib.Path
        The folder ``NAME.parts``.
    ranks : int
        The number of ranks, 1 ... the number of blocks.
    rank : int
        This rank, 0 ... ``ranks - 1``.
    box : dem.geometry.periodic.PeriodicBox or None
        The scene's periodic box, whose periodic axes wrap; None: none.
    bonds : int
        The halo's reach in bond lengths, >= 1 (a network with a node per neck: ``dem.geometry.bisection.NECK_HALO``).

    Returns
    -------
    tuple of (dem.scene.packing_files.packing.Packing, Part)
        The held particles (in the packing's order) and where they are in it.

    Raises
    ------
    ValueError
        A bad index or block, or more ranks than blocks.
    """
    if not 0 <= rank < ranks:
        raise ValueError(f"rank = {rank}: must be from 0 to {ranks - 1}")
    index = read_index(path)
    lengths = None if box is None else np.where(box.mask, box.lengths, np.inf)
    owner = block_owner(index, ranks, lengths)
    mine = owner == rank
    reach = 2.0 * float(index.radius_max.max()) * HALO_MARGIN * bonds
    region_lo, region_hi = index.lo[mine].min(axis=0) - reach, index.hi[mine].max(axis=0) + reach
    read = np.flatnonzero(_near(index.lo, index.hi, region_lo, region_hi, None if box is None else box.lengths,
                                None if box is None else box.mask))
    places, block, arrays = _read_blocks(path, index, read)
    rank_of = owner[block]
    keep = np.union1d(np.flatnonzero(rank_of == rank),
                      halo(arrays["position"], np.where(rank_of == rank, rank, -1), rank, reach,
                           None if box is None else box.lengths, None if box is None else box.mask))
    fixed_places, fixed = np.zeros(0, dtype=np.int64), None
    if index.fixed:
        held = _load(pathlib.Path(path) / HELD, index, index.fixed)
        fixed_places = held.pop("index")
        fixed = _packing(path, index, held)
    part = Part(index.n, ranks, places[keep], rank_of[keep], index.extent_lo, index.extent_hi, len(read),
                fixed_places, fixed)
    return _packing(path, index, {k: v[keep] for k, v in arrays.items()}), part
