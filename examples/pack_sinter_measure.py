"""
Pack, press and sinter, then measure
====================================

The whole pipeline in one script, each stage a scene that starts from the state the one before left:

1. **press**: 60 spheres poured into a 4 mm × 4 mm box fall under gravity and are pressed by a top wall at 2 kPa
   (velocity Verlet with the Luding 2005 contact law, below its melting range: the contacts stay elastic-plastic);
2. **sinter**: the pressed compact heated past the melting range (Luding 2005, eq. 10: k1(T) falls, the contacts
   relax to larger overlaps) and held, under the same pressure;
3. **measure**: a static scene on each compact's particles between a hot and a cold wall (the walls start where the
   moving run left them): the effective conductivity of the pressed and of the sintered compact, from the pipe
   network through the volume-conserving necks (Rojek 2022) with the FE-verified neck law.

The scenes are the dict form of TOML scene files (``python -m dem run FILE.toml`` reads the same keys); each stage
writes its folder (summary, time series, VTU snapshots, ``state.npz``) into a temporary directory here.
"""

import tempfile
from pathlib import Path

from dem import parse_scene, run

CONTACT = {"law": "luding", "k1": 1.0e4, "k2": 2.0e4, "kc": 1.0e4, "kt_ratio": 0.2, "gamma_n": 0.02,
           "gamma_t": 0.005, "mu": 0.5, "mu_wall": 0.0, "T_melt": 120.0, "T_var": 10.0, "expansion": 0.0,
           "fluid_overlap": 0.2, "t0": 0.02, "brittle_sliding": True}  # SI units, temperatures in degC
MATERIAL = {"conductivity": 20.0, "density": 1000.0, "specific_heat": 20.0}
SIDES = [{"name": "x-", "point": [0.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0]},
         {"name": "x+", "point": [4.0e-3, 0.0, 0.0], "normal": [-1.0, 0.0, 0.0]},
         {"name": "y-", "point": [0.0, 0.0, 0.0], "normal": [0.0, 1.0, 0.0]},
         {"name": "y+", "point": [0.0, 4.0e-3, 0.0], "normal": [0.0, -1.0, 0.0]}]
PRESS = {"name": "top", "point": [0.0, 0.0, 12.0e-3], "normal": [0.0, 0.0, -1.0], "motion": "stress",
         "pressure": 2000.0, "mass": 1.0e-4, "damping": 0.25}  # Pa, kg, kg/s
FLOOR = {"name": "bottom", "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]}
folder = Path(tempfile.mkdtemp(prefix="pack_sinter_measure_"))

# 1. press: poured at 80 degC, pressed until t = 0.08 s
press = run(parse_scene({
    "scene": {"name": "press", "physics": ["mechanical"]},
    "material": MATERIAL, "contact": CONTACT,
    "generator": {"kind": "box", "n": 60, "radius": 0.5e-3, "radius_spread": 0.2, "seed": 3, "temperature": 80.0,
                  "box": [[0.0, 0.0, 0.0], [4.0e-3, 4.0e-3, 12.0e-3]]},
    "walls": [FLOOR, PRESS, *SIDES], "gravity": {"acceleration": [0.0, 0.0, -9.81]},
    "solver": {"mode": "transient", "t_end": 0.08},
}), folder / "press")
t_pressed = press.summary["t"]

# 2. sinter: from the pressed state, heated to 160 degC in 0.02 s and held for 0.06 s (the clock goes on from 0.08 s)
sinter = run(parse_scene({
    "scene": {"name": "sinter", "physics": ["mechanical"]},
    "material": MATERIAL, "contact": CONTACT, "start": {"state": str(folder / "press" / "state.npz")},
    "walls": [FLOOR, PRESS, *SIDES], "gravity": {"acceleration": [0.0, 0.0, -9.81]},
    "temperature": {"time": [t_pressed, t_pressed + 0.02, t_pressed + 0.08], "value": [80.0, 160.0, 160.0]},
    "solver": {"mode": "transient", "t_end": t_pressed + 0.08},
}), folder / "sinter")


# 3. measure: the steady effective conductivity of each compact between a hot floor and a cold top wall
def k_eff(stage: str) -> float:
    measured = run(parse_scene({
        "scene": {"name": f"k_eff of the {stage} compact"},
        "material": MATERIAL, "start": {"state": str(folder / stage / "state.npz")},
        "walls": [{**FLOOR, "temperature": 1.0}, {"name": "top", "point": [0.0, 0.0, 12.0e-3],
                                                  "normal": [0.0, 0.0, -1.0], "temperature": 0.0}],
        "conductance": {"law": "fit", "out_of_range": "clip"}, "solver": {"mode": "steady", "floating": "mean"},
    }), folder / f"{stage}-k")
    return measured.summary["effective_conductivity"]


k_pressed, k_sintered = k_eff("press"), k_eff("sinter")
print(f"pressed:  volume fraction {press.summary['volume_fraction']:.3f}, k_eff = {k_pressed:.3f} W/(m K)")
print(f"sintered: volume fraction {sinter.summary['volume_fraction']:.3f}, k_eff = {k_sintered:.3f} W/(m K)")
print(f"the stages' folders: {folder}")
