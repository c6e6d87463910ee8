"""
One collision, two contact laws
===============================

Contact laws are plug-ins: the same scene with another ``[contact] law``. Two silica microspheres (r = 10 um) meet
head on. With ``law = "hertz_mindlin"`` they rebound with the coefficient of restitution the material names, at every
impact speed (Tsuji's damping with Antypov & Elliott's alpha(e)); with ``law = "jkr"`` and the work of adhesion of
the surfaces, slow ones stick and fast ones rebound, ever closer to that e. Only the ``[contact]`` table changes
(``python -m dem run FILE.toml`` reads the same keys).
"""

import math

import matplotlib.pyplot as plt

from dem import parse_scene, run

# Pa, -, -, eta_t/eta_n, friction with particles and with walls
silica = {"youngs_modulus": 7.0e10, "poisson_ratio": 0.17, "restitution": 0.8,
          "tangential_damping": 1.0, "mu": 0.3, "mu_wall": 0.3}
radius, density = 1.0e-5, 2200.0  # m, kg/m^3


def rebound(contact: dict, speed: float) -> tuple[float, bool]:
    """The relative speed after the collision over the one before (from the
    kinetic energy at the end), and whether the spheres are still in
    contact."""
    scene = parse_scene({
        "scene": {"physics": ["mechanical"]},
        "material": {"density": density},
        "particles": {
            "position": [[0.0, 0.0, 0.0], [2.001 * radius, 0.0, 0.0]],
            "radius": [radius, radius], "temperature": [20.0, 20.0],
            "velocity": [[speed / 2, 0.0, 0.0], [-speed / 2, 0.0, 0.0]]},
        "contact": contact,
        # s; dt = "auto": a tenth of the Rayleigh time
        "solver": {"mode": "transient", "t_end": 4.0e-6},
    })
    summary = run(scene).summary
    mass = density * 4.0 / 3.0 * math.pi * radius**3
    e = math.sqrt(summary["kinetic_energy"] / (mass * speed**2 / 4.0))
    return e, summary["contacts"] == 1


speeds = [0.005, 0.02, 0.05, 0.2, 1.0]  # m/s, relative
hertz_mindlin = {"law": "hertz_mindlin", **silica}
jkr = {"law": "jkr", **silica, "work_of_adhesion": 0.1}  # J/m^2
e_hertz_mindlin, _ = zip(*(rebound(hertz_mindlin, v) for v in speeds))
e_jkr, stuck = zip(*(rebound(jkr, v) for v in speeds))
print("speed (m/s)  Hertz-Mindlin  JKR (w = 0.1 J/m^2)")
for v, e_hm, e_sticky, together in zip(speeds, e_hertz_mindlin, e_jkr, stuck):
    shown = "stuck" if together else f"{e_sticky:.4f}"
    print(f"{v:11.3f}  {e_hm:13.4f}  {shown}")

# %%
# The rebound against the impact speed: Hertz-Mindlin's at the material's e throughout, JKR's stuck pairs at 0.
fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
ax.axhline(silica["restitution"], color="k", lw=1,
           label="the material's restitution e")
ax.plot(speeds, e_hertz_mindlin, "o", label='law = "hertz_mindlin"')
e_jkr_or_stuck = [0.0 if together else e for e, together in zip(e_jkr, stuck)]
ax.plot(speeds, e_jkr_or_stuck, "s-", label='law = "jkr" (w = 0.1 J/m²)')
ax.set_xscale("log")
ax.set_xlabel("impact speed, relative (m/s)")
ax.set_ylabel("coefficient of restitution (-)")
ax.set_ylim(-0.05, 1.0)
ax.legend(loc="lower right")
plt.show()
