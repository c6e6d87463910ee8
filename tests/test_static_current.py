"""The current through a static packing between electrodes ("electrical" physics on the static engine) against
closed forms: a chain's series resistance and its Kohlrausch temperature, the Joule heat leaving through the walls,
and on a random packing the analogy of the two Laplacians (the same law with sigma for kappa: the electrical
conductance of the packing is sigma / kappa times its thermal conductance). And bad input."""

import math
import tomllib

import numpy as np
import pytest

from dem.driver import run
from dem.engines.static import StaticEngine
from dem.scene import load_scene, parse_scene
from dem.scene.parse import SCENE_DIR
from fem_neck import neck_radius

COPPER = {"conductivity": 394.0, "density": 8960.0, "specific_heat": 385.0, "electrical_conductivity": 5.96e7}


def test_chain_series_resistance_and_kohlrausch_temperature():
    """joule-chain: N equal spheres, every neck alike (the walls' too), Rojek's linear law (eq. 43, slope 1.064)
    per half: each sphere a resistance 2 / (1.064 sigma pi a), the chain N of them in series. The Joule heat is made
    evenly in the spheres and leaves through both walls at T_w; with the same law for heat, the middle of an even
    chain stands V^2 sigma / (8 kappa) above the walls (Kohlrausch's relation, here exact for the discrete chain)."""
    scene = load_scene("joule-chain")
    s = run(scene).summary
    e = s["electrical"]
    r, n, sigma, kappa, V = 1e-3, 10, 5.96e7, 394.0, 0.01
    a = neck_radius(r, r, 0.1 * r)
    R = n * 2.0 / (1.064 * sigma * math.pi * a)
    assert e["resistance"] == pytest.approx(R, rel=1e-12)
    assert e["total_current"] == pytest.approx(V / R, rel=1e-12)
    assert e["electrodes"]["live"]["current"] == pytest.approx(-e["electrodes"]["ground"]["current"], rel=1e-12)
    assert e["joule_heat"] == pytest.approx(V * V / R, rel=1e-12)
    assert e["electrode_power"] == pytest.approx(e["joule_heat"], rel=1e-12)  # Tellegen
    walls = s["boundary_heat_flow"]["walls"]
    assert walls["ground"] + walls["live"] == pytest.approx(e["joule_heat"], rel=1e-12)  # all of it leaves
    assert walls["ground"] == pytest.approx(walls["live"], rel=1e-12)  # symmetric
    assert s["T_max"] - 20.0 == pytest.approx(V * V * sigma / (8.0 * kappa), rel=1e-10)


def test_absorption_scales_the_heat_not_the_current():
    doc = _chain_doc(absorption=0.25)
    s = run(parse_scene(doc)).summary
    full = run(load_scene("joule-chain")).summary
    assert s["electrical"] == full["electrical"]
    assert s["T_max"] - 20.0 == pytest.approx(0.25 * (full["T_max"] - 20.0), rel=1e-10)


def _chain_doc(**electrical):
    doc = tomllib.loads((SCENE_DIR / "joule-chain.toml").read_text())
    if electrical:
        doc["electrical"] = electrical
    return doc


def plates_packing(n=400, seed=3, V=(0.0, 1e-3), T=(1.0, 0.0), absorption=1.0):
    """A random sintered packing between two plates that are electrodes too (the plates where the generator's
    ``boundary = "plates"`` puts them)."""
    generator = {"kind": "random", "n": n, "radius": 50e-6, "overlap": 0.1, "seed": seed}
    plated = parse_scene({"material": COPPER, "generator": {**generator, "boundary": "plates", "hot": 1.0,
                                                               "cold": 0.0}})
    walls = [{"name": w.name, "point": list(map(float, w.point)), "normal": list(map(float, w.normal)),
              "temperature": t, "potential": v} for w, t, v in zip(plated.walls, T, V)]
    return {"scene": {"physics": ["thermal", "electrical"]}, "material": COPPER,
            "generator": {**generator, "temperature": 0.5}, "walls": walls, "electrical": {"absorption": absorption},
            "solver": {"mode": "steady", "floating": "mean"}}


def test_electrical_conductance_is_sigma_over_kappa_times_the_thermal_one():
    """Both networks are the same Laplacian on the same bonds (the linear law is proportional to the
    conductivity): without absorbed heat, I / dV = (sigma / kappa) Q / dT between the same plates, with the
    current's own solve (:func:`dem.network.current.kirchhoff`) and the heat's (:func:`dem.network.heat.steady`)."""
    s = run(parse_scene(plates_packing(absorption=0.0))).summary
    Q = -s["boundary_heat_flow"]["walls"]["hot"]
    e = s["electrical"]
    assert Q > 0 and e["total_current"] > 0
    assert e["total_current"] / 1e-3 == pytest.approx(5.96e7 / 394.0 * Q / 1.0, rel=1e-8)


def test_potential_is_written_for_every_particle():
    engine = StaticEngine(parse_scene(plates_packing()))
    engine.run()
    phi = engine.particle_fields()["potential"]
    live = np.isfinite(phi)
    assert live.sum() > 0.9 * len(phi)
    assert np.all((phi[live] >= -1e-15) & (phi[live] <= 1e-3 * (1 + 1e-12)))


@pytest.mark.parametrize("change, message", [
    ({"scene": {"physics": ["electrical"]}}, r"\"electrical\" on a static packing heats it and runs with \"thermal\""),
    ({"electrical": {"scheme": "zohdi"}}, r"scheme = \"zohdi\": the paper's iteration runs with moving particles"),
    ({"electrical": {"sweeps": 10}}, r"\[electrical\] sweeps: not read by the static engine"),
])
def test_bad_input_is_named(change, message):
    doc = _chain_doc()
    doc.update(change)
    with pytest.raises(ValueError, match=message):
        parse_scene(doc)


def test_floating_error_names_the_particles():
    doc = _chain_doc(floating="error")
    doc["walls"][1]["point"] = [0.0, 0.0, 30e-3]  # off the chain: it reaches the ground only, no particle floats
    run(parse_scene(doc))
    doc["walls"][0]["point"] = [0.0, 0.0, -30e-3]  # off it too: all ten float
    with pytest.raises(ValueError, match=r"10 particle\(s\) touch no electrode .*: 0, 1, 2"):
        run(parse_scene(doc))
