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

import matplotlib.pyplot as plt
import numpy as np

from dem import parse_scene, run

# SI units, temperatures in degC
CONTACT = {"law": "luding", "k1": 1.0e4, "k2": 2.0e4, "kc": 1.0e4,
           "kt_ratio": 0.2, "gamma_n": 0.02, "gamma_t": 0.005,
           "mu": 0.5, "mu_wall": 0.0, "T_melt": 120.0, "T_var": 10.0,
           "expansion": 0.0, "fluid_overlap": 0.2, "t0": 0.02,
           "brittle_sliding": True}
MATERIAL = {"conductivity": 20.0, "density": 1000.0, "specific_heat": 20.0}
L, H = 4.0e-3, 12.0e-3  # m, the box's width and height
SIDES = [{"name": "x-", "point": [0, 0, 0], "normal": [1, 0, 0]},
         {"name": "x+", "point": [L, 0, 0], "normal": [-1, 0, 0]},
         {"name": "y-", "point": [0, 0, 0], "normal": [0, 1, 0]},
         {"name": "y+", "point": [0, L, 0], "normal": [0, -1, 0]}]
PRESS = {"name": "top", "point": [0, 0, H], "normal": [0, 0, -1],
         "motion": "stress", "pressure": 2000.0,  # Pa
         "mass": 1.0e-4, "damping": 0.25}  # kg, kg/s
FLOOR = {"name": "bottom", "point": [0, 0, 0], "normal": [0, 0, 1]}
GRAVITY = {"acceleration": [0.0, 0.0, -9.81]}  # m/s^2
folder = Path(tempfile.mkdtemp(prefix="pack_sinter_measure_"))

# 1. press: poured at 80 degC, pressed until t = 0.08 s
press = run(parse_scene({
    "scene": {"name": "press", "physics": ["mechanical"]},
    "material": MATERIAL, "contact": CONTACT,
    "generator": {"kind": "box", "n": 60, "radius": 0.5e-3,
                  "radius_spread": 0.2, "seed": 3, "temperature": 80.0,
                  "box": [[0, 0, 0], [L, L, H]]},
    "walls": [FLOOR, PRESS, *SIDES], "gravity": GRAVITY,
    "solver": {"mode": "transient", "t_end": 0.08},
}), folder / "press")
t_pressed = press.summary["t"]

# 2. sinter: from the pressed state, heated to 160 degC in 0.02 s and
# held for 0.06 s (the clock goes on from 0.08 s)
sinter = run(parse_scene({
    "scene": {"name": "sinter", "physics": ["mechanical"]},
    "material": MATERIAL, "contact": CONTACT,
    "start": {"state": str(folder / "press" / "state.npz")},
    "walls": [FLOOR, PRESS, *SIDES], "gravity": GRAVITY,
    "temperature": {"time": [t_pressed, t_pressed + 0.02, t_pressed + 0.08],
                    "value": [80.0, 160.0, 160.0]},
    "solver": {"mode": "transient", "t_end": t_pressed + 0.08},
}), folder / "sinter")


# 3. measure: the steady effective conductivity of each compact between a
# hot floor and a cold top wall
def k_eff(stage: str) -> float:
    hot = {**FLOOR, "temperature": 1.0}
    cold = {"name": "top", "point": [0, 0, H], "normal": [0, 0, -1],
            "temperature": 0.0}
    measured = run(parse_scene({
        "scene": {"name": f"k_eff of the {stage} compact"},
        "material": MATERIAL,
        "start": {"state": str(folder / stage / "state.npz")},
        "walls": [hot, cold],
        "conductance": {"law": "fit", "out_of_range": "clip"},
        "solver": {"mode": "steady", "floating": "mean"},
    }), folder / f"{stage}-k")
    return measured.summary["effective_conductivity"]  # W/(m K)


k_pressed, k_sintered = k_eff("press"), k_eff("sinter")
for stage, result, k in (("pressed", press, k_pressed),
                         ("sintered", sinter, k_sintered)):
    print(f"{stage + ':':9} volume fraction "
          f"{result.summary['volume_fraction']:.3f}, k_eff = {k:.3f} W/(m K)")

# %%
# The compact's volume fraction through the two moving stages (each stage's
# ``timeseries.csv``), under the imposed temperature: pressed below the
# melting range it stays loose; heated past ``T_melt`` the contacts soften
# (k1 falls, eq. 10) and the same pressure closes the pores, so the necks,
# and with them k_eff, grow.
series = [np.genfromtxt(folder / stage / "timeseries.csv", delimiter=",",
                        names=True) for stage in ("press", "sinter")]
fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
for stage, data, k in zip(("pressed", "sintered"), series,
                          (k_pressed, k_sintered)):
    ax.plot(data["t"], data["volume_fraction"],
            label=f"{stage}: k_eff = {k:.2f} W/(m K)")
ax.set_xlabel("time t (s)")
ax.set_ylabel("volume fraction (-)")
ax.legend(loc="upper left")
temperature = ax.twinx()
temperature.plot(np.concatenate([data["t"] for data in series]),
                 np.concatenate([data["T_mean"] for data in series]),
                 "k:", lw=1)
temperature.set_ylabel("temperature, dotted (degC)")
plt.show()
