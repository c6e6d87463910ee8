"""Packings in parts (:mod:`dem.scene.packing_files.parts`), without MPI: read whole, the packing written, to the bit;
read in part, each rank's owned particles partition the packing and its halo is the one the whole packing gives
(:func:`dem.geometry.bisection.halo` over every particle), periodic faces included, from fewer blocks than all;
a scene read in part has the whole scene's specimen; what cannot run in parts is refused in one line."""

import json

import numpy as np
import pytest

from dem.cli import main
from dem.geometry.generators import random_packing
from dem.geometry.bisection import HALO_MARGIN, bisection, halo
from dem.geometry.periodic import PeriodicBox
from dem.scene import load_scene
from dem.scene.packing_files import Packing, read_packing
from dem.scene.packing_files.parts import read_index, read_part, read_whole, write_parts

MATERIALS = '[[materials]]\nname = "copper"\nconductivity = 394.0\ndensity = 8960.0\nspecific_heat = 385.0\n' \
            '[[materials]]\nname = "steel"\nconductivity = 50.0\ndensity = 7850.0\nspecific_heat = 470.0\n'


def _packing(n=1500, periodic=False, seed=3) -> Packing:
    lay = random_packing(n, 1e-4, 0.1, seed=seed, periodic=periodic)
    rng = np.random.default_rng(seed)
    count = len(lay.radius)
    lo = hi = axes = None
    if periodic:
        lo, hi, axes = np.zeros(3), np.asarray(lay.period, dtype=float), (True, True, True)
    return Packing(np.arange(count, dtype=np.int64)[::-1] + 7, lay.position, lay.radius,
                   temperature=rng.random(count), fixed=rng.random(count) < 0.1, material=rng.integers(0, 2, count),
                   density=np.full(count, 8960.0), box_lo=lo, box_hi=hi, periodic=axes)


def test_read_whole_is_the_packing_written(tmp_path):
    p = _packing(periodic=True)
    write_parts(tmp_path / "p.parts", p, 13)
    q = read_whole(tmp_path / "p.parts")
    for key in ("id", "position", "radius", "temperature", "fixed", "material", "density", "box_lo", "box_hi"):
        assert np.array_equal(getattr(q, key), getattr(p, key)), key
    assert q.periodic == p.periodic and q.format == "parts"
    assert read_packing(tmp_path / "p.parts").n == p.n  # the packing files' reader reads it by its name
    index = read_index(tmp_path / "p.parts")
    assert index.blocks == 13 and index.count.sum() == p.n and index.count.max() - index.count.min() <= 13
    assert index.fixed == int(p.fixed.sum())


@pytest.mark.parametrize("periodic", [False, True])
@pytest.mark.parametrize("ranks", [1, 2, 5])
@pytest.mark.slow
def test_each_rank_holds_its_blocks_and_the_halo_of_the_whole(tmp_path, periodic, ranks):
    p = _packing(periodic=periodic)
    write_parts(tmp_path / "p.parts", p, 40)
    box = PeriodicBox(p.box_hi - p.box_lo, p.periodic, p.box_lo) if periodic else None
    parts = [read_part(tmp_path / "p.parts", ranks, r, box) for r in range(ranks)]
    owner = np.full(p.n, -1)
    for r, (_, part) in enumerate(parts):
        mine = part.held[part.owner == r]
        assert np.all(owner[mine] == -1)  # owned by one rank only
        owner[mine] = r
    assert np.all(owner >= 0)
    counts = np.bincount(owner, minlength=ranks)
    assert counts.max() <= 1.5 * p.n / ranks  # whole blocks, balanced by their counts
    reach = 2.0 * p.radius.max() * HALO_MARGIN
    for r, (packing, part) in enumerate(parts):
        expected = np.union1d(np.flatnonzero(owner == r),
                              halo(p.position, owner, r, reach, None if box is None else box.lengths,
                                   None if box is None else box.mask))
        assert np.array_equal(part.held, expected)
        assert np.array_equal(part.owner, owner[part.held])
        assert np.array_equal(packing.position, p.position[part.held]) and np.array_equal(packing.id, p.id[part.held])
        assert part.n == p.n and part.ranks == ranks
        if ranks == 5 and not periodic:  # no rank opens every block, nor holds every particle
            assert part.blocks_read < 40 and len(part.held) < p.n


def test_blocks_are_shared_by_weight():
    x = np.array([[0.0, 0, 0], [1.0, 0, 0], [2.0, 0, 0], [3.0, 0, 0]])
    assert bisection(x, 2, weights=np.array([3.0, 1.0, 1.0, 1.0])).tolist() == [0, 1, 1, 1]
    assert bisection(x, 2, weights=np.ones(4)).tolist() == bisection(x, 2).tolist() == [0, 0, 1, 1]
    assert bisection(x, 4, weights=np.array([100.0, 1.0, 1.0, 1.0])).tolist() == [0, 1, 2, 3]  # a point per part


def _scene(tmp_path, extra: str = "", ends: str = "walls") -> str:
    """A packing in 24 blocks between hot and cold walls, or (``ends = "layers"``) with its bottom and top layers
    held at 1 and 0 in the file, and the scene of it."""
    lay = random_packing(1200, 1e-4, 0.1, seed=5)
    x, n = lay.position, len(lay.radius)
    text = MATERIALS + '[particles]\nfile = "p.parts"\n'
    if ends == "walls":
        packing = Packing(np.arange(n), x, lay.radius)
        lo, hi = float(x[:, 2].min() - 0.5e-4), float(x[:, 2].max() + 0.5e-4)
        text += ('temperature = 0.5\n' + extra +
                 f'[[walls]]\nname = "hot"\npoint = [0, 0, {lo!r}]\nnormal = [0, 0, 1]\ntemperature = 1.0\n'
                 f'[[walls]]\nname = "cold"\npoint = [0, 0, {hi!r}]\nnormal = [0, 0, -1]\ntemperature = 0.0\n')
    else:
        text += extra
        fixed, T = np.zeros(n, dtype=bool), np.full(n, 0.5)
        fixed[lay.bottom] = fixed[lay.top] = True
        T[lay.bottom], T[lay.top] = 1.0, 0.0
        packing = Packing(np.arange(n), x, lay.radius, temperature=T, fixed=fixed)
    write_parts(tmp_path / "p.parts", packing, 24)
    (tmp_path / "s.toml").write_text(text + '[solver]\nmode = "steady"\nfloating = "mean"\n')
    return str(tmp_path / "s.toml")


def test_a_scene_read_in_part_has_the_whole_scenes_specimen(tmp_path):
    path = _scene(tmp_path, 'material = "steel"\n')
    whole = load_scene(path)
    assert whole.specimen.hot_end == ("wall", "hot")
    for r in range(3):
        s = load_scene(path, part=(3, r))
        assert s.specimen == whole.specimen and s.particle_count == whole.particles.n
        assert np.array_equal(s.particles.position, whole.particles.position[s.part.held])
        assert np.all(s.particles.material == 1) and np.all(s.particles.temperature == 0.5)


def test_held_layers_are_the_ends_over_the_whole_packing(tmp_path):
    path = _scene(tmp_path, ends="layers")
    whole = load_scene(path)
    assert whole.specimen.hot_end == ("group", "held at 1")
    for r in range(4):
        s = load_scene(path, part=(4, r))
        assert s.specimen == whole.specimen
        assert np.array_equal(s.part.fixed_places, np.flatnonzero(whole.particles.fixed))
        assert not np.all(np.isin(np.flatnonzero(whole.particles.fixed), s.part.held))  # not all of them held here
        assert np.array_equal(s.particles.fixed, whole.particles.fixed[s.part.held])


@pytest.mark.parametrize("extra, message", [
    ("fixed = true\n", "[particles] fixed: not for a packing read in parts"),
    ("length_unit = 0.001\n", "length_unit: not for a packing in parts"),
    ('[[groups]]\nname = "top"\nlayer = "top"\nthickness = 1e-4\nfixed = true\n', "[[groups]]: not on a packing read"),
])
def test_what_a_part_cannot_hold_is_refused_in_one_line(tmp_path, extra, message):
    path = _scene(tmp_path, extra)
    with pytest.raises(ValueError, match=r"^s\.toml: .*" + message.replace("(", r"\(").replace(")", r"\)")
                       .replace("[", r"\[").replace("]", r"\]")) as exc:
        load_scene(path, part=(2, 0))
    assert "\n" not in str(exc.value)


def test_more_ranks_than_blocks_are_refused(tmp_path):
    path = _scene(tmp_path)
    with pytest.raises(ValueError, match="25 ranks: the packing in parts has 24 blocks.*--blocks 25"):
        load_scene(path, part=(25, 0))


def test_the_cli_converts_to_parts_and_back(tmp_path, capsys):
    (tmp_path / "p.csv").write_text("x,y,z,radius,temperature\n0,0,0,1e-4,1\n1.9e-4,0,0,1e-4,2\n3.8e-4,0,0,1e-4,3\n")
    assert main(["convert", str(tmp_path / "p.csv"), str(tmp_path / "p.parts"), "--blocks", "2", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["blocks"] == 2 and out["particles"] == 3 and out["output_format"] == "packing in parts"
    assert main(["convert", str(tmp_path / "p.parts"), str(tmp_path / "q.csv")]) == 0
    assert np.array_equal(read_packing(tmp_path / "q.csv").temperature, [1.0, 2.0, 3.0])
    for args, message in (([str(tmp_path / "p.csv"), str(tmp_path / "r.parts"), "--blocks", "4"],
                           "blocks = 4: must be an integer from 1 to the particle count 3"),
                          ([str(tmp_path / "p.csv"), str(tmp_path / "r.csv"), "--blocks", "2"],
                           "--blocks = 2: for OUT = NAME.parts only")):
        capsys.readouterr()
        assert main(["convert", *args]) == 2
        err = capsys.readouterr().err
        assert message in err and len(err.strip().splitlines()) == 1
