"""Moving particles in a periodic box (the verlet engine): contacts across the faces by the minimum image, particles
wrapped back into the box, momentum conserved, a collision across a face the same as in the middle of the box, heat
across a face the same as in the middle, and the inputs that cannot work refused in one line."""

import copy

import numpy as np
import pytest

from dem import parse_scene, run
from dem.engines.verlet.engine import VerletEngine

L = 6e-3  # m, the period along x, y and z
LUDING = {"law": "luding", "k1": 1.0e3, "k2": 2.0e3, "kc": 1.0e3, "kt_ratio": 0.2, "gamma_n": 1e-4,
          "gamma_t": 5e-5, "mu": 0.5, "mu_wall": 0.0, "T_melt": 1000.0, "T_var": 10.0, "expansion": 1.0e-4,
          "fluid_overlap": 0.2, "t0": 1.0e3, "brittle_sliding": True}
GAS = {"scene": {"physics": ["mechanical"]}, "material": {"density": 7800.0}, "contact": LUDING,
       "generator": {"kind": "box", "n": 40, "radius": 5e-4, "radius_spread": 0.1, "seed": 2, "speed": 0.5,
                     "box": [[0.0, 0.0, 0.0], [L, L, L]]},
       "periodic": {"lengths": [L, L, L]}, "solver": {"mode": "transient", "t_end": 0.01}}


def pair(x_a: float, x_b: float, v: float = 0.0, thermal: bool = False) -> dict:
    """Two particles of radius 0.5 mm on the x axis at ``x_a`` and ``x_b``, approaching at ``v`` each."""
    return {"scene": {"physics": ["mechanical", "thermal"] if thermal else ["mechanical"]},
           "material": {"density": 7800.0, "conductivity": 50.0, "specific_heat": 500.0},
           "contact": LUDING,
           "particles": {"position": [[x_a, 3e-3, 3e-3], [x_b, 3e-3, 3e-3]], "radius": [5e-4, 5e-4],
                         "temperature": [100.0, 20.0], "velocity": [[v, 0.0, 0.0], [-v, 0.0, 0.0]]},
           "periodic": {"lengths": [L, L, L]}, "solver": {"mode": "transient", "t_end": 0.02}}


def test_momentum_is_conserved_through_collisions_across_the_faces():
    scene = parse_scene(copy.deepcopy(GAS))
    engine = VerletEngine(scene)
    s = engine.mechanics.state
    p0 = s.momentum().copy()
    scale = float(np.sum(s.mass * np.linalg.norm(s.v, axis=1)))
    x0 = s.x.copy()
    engine.run()
    travelled = np.abs(s.x - x0)
    assert engine.mechanics.rebuilds > 0 and np.max(travelled) > 0.5 * L  # particles crossed the faces
    assert np.all((s.x >= -L) & (s.x < 2 * L))  # wrapped back (within one rebuild's travel)
    assert np.max(np.abs(s.momentum() - p0)) <= 1e-13 * scale


def test_a_collision_across_a_face_is_the_collision_in_the_middle():
    # particle 0 approaches particle 1 from its +x side in both: through the x faces (1.1 mm apart: 0 at 0.3 mm,
    # the image of 1 at -0.8 mm) and in the middle of the box
    across = run(parse_scene(pair(0.3e-3, L - 0.8e-3, v=-0.2)))
    middle = run(parse_scene(pair(3.3e-3, 2.2e-3, v=-0.2)))
    v_across = across.engine.mechanics.state.v[:, 0]
    v_middle = middle.engine.mechanics.state.v[:, 0]
    assert not np.isclose(v_across[0], -0.2)  # they collided
    np.testing.assert_allclose(v_across, v_middle, rtol=1e-9, atol=1e-12)


def test_a_contact_across_a_face_is_drawn_to_the_image_not_across_the_box():
    engine = VerletEngine(parse_scene(pair(0.3e-3, L - 0.6e-3)))  # touching through the x faces: 0.9 mm < 2 R
    points, lines, fields = engine.links()
    assert len(lines) == 1 and len(points) == 3  # the two particles and the image of the partner
    np.testing.assert_allclose(points[lines[0, 1]], [-0.6e-3, 3e-3, 3e-3], atol=1e-15)
    assert np.linalg.norm(points[lines[0, 1]] - points[lines[0, 0]]) == pytest.approx(0.9e-3)
    middle = VerletEngine(parse_scene(pair(3.3e-3, 2.4e-3)))
    assert len(middle.links()[0]) == 2 and middle.links()[1].tolist() == [[0, 1]]  # no image where none crosses


@pytest.mark.slow
def test_heat_crosses_a_face_as_it_crosses_the_middle():
    touching = 0.9e-3  # centre distance (m): overlap 0.1 mm
    across = run(parse_scene(pair(0.2e-3, L - touching + 0.2e-3, thermal=True)))
    middle = run(parse_scene(pair(3.2e-3, 3.2e-3 - touching, thermal=True)))
    assert across.T[0] < 99.9 and across.T[1] > 20.1  # heat flowed (while the contact pushed them apart)
    np.testing.assert_allclose(across.T, middle.T, rtol=1e-9)


def test_what_cannot_work_is_refused_in_one_line():
    doc = copy.deepcopy(GAS)
    doc["walls"] = [{"name": "floor", "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]}]
    with pytest.raises(ValueError, match=r"walls.floor: .* periodic axis z"):
        parse_scene(doc)
    doc = copy.deepcopy(GAS)
    doc["walls"] = [{"name": "floor", "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]}]
    doc["periodic"]["axes"] = ["x", "y"]
    assert parse_scene(doc).box.periodic == (True, True, False)  # a floor under a box periodic along x and y


def test_a_resumed_run_ends_as_the_uninterrupted_one_bit_for_bit():
    """Resumed from a checkpoint taken while a particle is outside the box (wrapped only at the next rebuild of the
    list), the run goes on as the uninterrupted one: the list built on restart leaves the saved positions as they
    were."""
    import io

    whole = VerletEngine(parse_scene(copy.deepcopy(GAS)))
    whole.run()
    part = VerletEngine(parse_scene(copy.deepcopy(GAS)))
    box = part.scene.box
    taken = []

    def checkpoint(make, final):
        x = part.mechanics.state.x
        if not taken and np.any((x < box.origin) | (x >= box.origin + box.lengths)):
            buffer = io.BytesIO()
            np.savez(buffer, **make())
            buffer.seek(0)
            with np.load(buffer, allow_pickle=False) as f:
                taken.append({k: f[k] for k in f.files})
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        part.run(checkpoint=checkpoint)
    assert taken
    resumed = VerletEngine(parse_scene(copy.deepcopy(GAS)), restart=taken[0])
    resumed.run()
    for name in ("x", "v", "w"):
        assert np.array_equal(getattr(resumed.mechanics.state, name), getattr(whole.mechanics.state, name)), name
