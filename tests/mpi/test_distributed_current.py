"""A current between electrodes through a static packing on several MPI ranks against the serial run of the same
scene in the same process: the same potentials, contact Joule heat, electrode currents and resistance to the
solver's tolerance (1e-8 relative), and the temperatures the heat then makes."""

import numpy as np
import pytest

from dem.driver import run
from dem.engines.static import StaticEngine
from dem.parallel import comm as mpi
from dem.network.current import electrode_bonds, kirchhoff
from dem.scene import load_scene, parse_scene

COMM = mpi.world()

COPPER = {"conductivity": 394.0, "density": 8960.0, "specific_heat": 385.0, "electrical_conductivity": 5.96e7}
V_LIVE = 1e-3  # V


def plates_packing(n=3000, seed=5, **electrical):
    """A random sintered packing (with rattlers: groups that touch no electrode) between two plates at 1 and 0 C
    that are electrodes too, the live one at ``V_LIVE``."""
    generator = {"kind": "random", "n": n, "radius": 50e-6, "overlap": 0.1, "seed": seed}
    plated = parse_scene({"material": COPPER, "generator": {**generator, "boundary": "plates", "hot": 1.0,
                                                               "cold": 0.0}})
    walls = [{"name": w.name, "point": list(map(float, w.point)), "normal": list(map(float, w.normal)),
              "temperature": w.temperature, "potential": v} for w, v in zip(plated.walls, (V_LIVE, 0.0))]
    return parse_scene({"scene": {"physics": ["thermal", "electrical"]}, "material": COPPER,
                        "generator": {**generator, "temperature": 0.5}, "walls": walls, "electrical": electrical,
                        "solver": {"mode": "steady", "floating": "mean"}})


def gathered(engine, local: np.ndarray) -> np.ndarray:
    """A per-particle array of the distributed engine (over its held particles) in the scene's order."""
    out = np.empty(engine.full_scene.particles.n)
    for index, values in COMM.allgather((engine.owned, local[engine.mine])):
        out[index] = values
    return out


def assert_same_circuit(ours: dict, theirs: dict, rel: float = 1e-8):
    assert ours["electrodes"].keys() == theirs["electrodes"].keys()
    for name, e in ours["electrodes"].items():
        assert e["potential"] == theirs["electrodes"][name]["potential"]
        assert e["current"] == pytest.approx(theirs["electrodes"][name]["current"], rel=rel)
    for key in ("total_current", "joule_heat", "electrode_power", "resistance"):
        assert ours[key] == pytest.approx(theirs[key], rel=rel)


def test_joule_chain_equals_the_serial_run():
    scene = load_scene("joule-chain")
    result = run(scene)
    ref = StaticEngine(scene)
    ref.run()
    assert result.summary["ranks"] == COMM.Get_size()
    assert_same_circuit(result.summary["electrical"], ref.summary()["electrical"])
    assert np.max(np.abs(result.engine.gathered_temperatures() - ref.T)) < 1e-8 * 1.891  # the rise above the walls


def test_packing_potentials_joule_heat_and_temperatures_equal_the_serial_run():
    scene = plates_packing()
    result = run(scene)
    engine = result.engine
    ref = StaticEngine(scene)
    ref.run()
    assert_same_circuit(result.summary["electrical"], ref.summary()["electrical"])
    # the potentials and the Joule heat of every particle against the serial Kirchhoff solve, made here
    p, e = scene.particles, scene.electrical
    wires = electrode_bonds(p, ref.bonds, scene.walls, scene.conductance, e.electrodes)
    flow = kirchhoff(p.n, ref.bonds.i, ref.bonds.j, wires.G, wires.share, wires.plane_node, wires.plane_index,
                     wires.G_plane, e.electrodes)
    live = np.isfinite(flow.potential)
    assert 0 < len(flow.floating) and live.sum() > 0.9 * p.n  # rattlers, and a packing that conducts
    phi = gathered(engine, engine.potential)
    assert np.max(np.abs(phi[live] - flow.potential[live])) < 1e-8 * V_LIVE
    assert np.all(phi[~live] == 0.0)  # a floating group at its mean initial value: carries nothing
    joule = gathered(engine, engine.joule)
    assert np.max(np.abs(joule - flow.joule_particles)) < 1e-8 * flow.joule_particles.max()
    assert np.sum(joule) == pytest.approx(flow.joule_heat, rel=1e-8)
    assert np.max(np.abs(engine.gathered_temperatures() - ref.T)) < 1e-8 * np.ptp(ref.T)
    assert result.summary["energy_error"] < 1e-9


def test_floating_error_names_the_same_particles():
    scene = plates_packing(n=1500, floating="error")
    with pytest.raises(ValueError) as serial_error:
        StaticEngine(scene)
    with pytest.raises(ValueError) as ours:
        run(scene)
    assert "touch no electrode" in str(ours.value)
    assert str(ours.value) == " ".join(str(serial_error.value).split())


def test_an_electrode_driving_a_current_is_refused_up_front():
    scene = load_scene("joule-chain")
    e = scene.electrical.electrodes
    driven = type(e)(e.names, e.walls, np.array([0.0, np.nan]), np.array([np.nan, 40.0]))
    import dataclasses

    scene = dataclasses.replace(scene, electrical=dataclasses.replace(scene.electrical, electrodes=driven))
    with pytest.raises(ValueError, match="walls.live.current: an electrode driving a fixed current does not run "
                                         "under MPI"):
        run(scene)
