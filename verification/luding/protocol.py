"""The sintering protocol of Luding, Manetsberger & Müllers 2005 (Sec. 4) as scene documents.

Each function returns a scene as a dict (the parsed form of a TOML scene; :func:`dem.scene.parse.parse_scene` takes it,
:func:`dem.driver.run` runs it) for one stage of the paper's protocol:

* :func:`preparation_doc` -- ``n`` disks (Table 1: a0 = 1 mm, radii uniform in a0 (1 +- w0), w0 = 0.5, height
  6 mm) placed at random with random velocities in a square box (random sequential addition, solid fraction
  ``fill``) and compressed by the bi-axial box of Fig. 1: left and bottom walls fixed, right and top walls
  stress-controlled (eq. 1, pressure ``p`` in N/m, wall mass 0.01 kg, damping 0.2 kg/s), at 80 °C, with friction
  on particles and walls (below), until ``t_heat``;
* :func:`sintering_doc` -- from a prepared state: friction on and wall friction off (Sec. 4.1.2: at t_heat "the wall
  friction is switched off"), heating to 140 °C in 0.1 s, sintering for ``t_s`` with the relaxation time
  t0 = 0.1 s of eqs. 11-12 (Table 1), and optionally the cooling to 80 °C in 0.1 s and the relaxation for 0.1 s
  (the times of Sec. 4.1, Fig. 7);
* :func:`cooling_doc` -- from a sintered state (at ``t_cool``): the cooling and the relaxation alone;
* :func:`schedule_doc` -- the whole of Fig. 7 in one scene (preparation, heating, sintering, cooling, relaxation);
* :func:`control_doc` -- the three-particle control of Sec. 4.1.3 (the schedule for three disks, prepared until
  they are at rest);
* :func:`compression_doc` -- the compression test of Sec. 4.4: the right wall holds ``sigma_xx = p``, the top wall
  moves down at a constant speed, ``eps_zz = 1 - z/z0`` rising at ``strain_rate``;
* :func:`vibration_doc` -- the vibration test of Figs. 21-22: the confining walls removed, the sample on a flat
  floor vibrating at 100 Hz with 0.2 mm amplitude for 0.1 s, in gravity;
* :func:`heated_walls_doc` -- beyond the paper: 3D spheres with the thermal network on, heated and cooled through
  two walls held at given temperatures instead of a prescribed schedule.

Ambiguities of the paper, resolved here (and overridable). *The preparation's friction.* The paper says it
"used frictionless particles for the initial compression", then switches "the wall friction" off at t_heat ("an
immediate effect, a slight increase in density") and reports nu ~ 0.80 after the preparation and densifications of
5 % (p = 10) and 16 % (p = 100). Its numbers and its wall friction follow from a preparation with friction, not
from a frictionless one, which packs 300 disks denser and then densifies far less at p = 10 (``python -m
verification sintering`` runs both, and frictionless variants with other speeds, compression rates, cohesion and
wall friction). The numbers are followed: ``prep_mu`` and ``prep_mu_wall`` default to Table 1's mu (the paper gives
the preparation's wall friction no value), and at t_heat the wall friction goes to Table 1's mu_w = 0 while the
particles keep mu. *The walls* keep the cold law (``LUDING_TABLE1.wall_sintering``). *The three-particle control*
(:func:`control_doc`) is prepared until it is at rest and without wall friction. The vibration floor is a new wall
placed where the lowest particle just touches it (the sample is set down on it; the sintered wall contacts of the
box stay behind).

``dimension = 3`` gives the same protocol for spheres in a cube (three fixed walls, three stress walls with
``p`` in Pa).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace

import numpy as np

from dem.laws.contact.luding import LUDING_TABLE1, LudingMaterial
from dem.scene import state_file

T_PREPARE = 80.0        # °C, preparation, cooled sample and tests (Sec. 4.1)
T_SINTER = 140.0        # °C, sintering (Sec. 4.1)
T0_SINTER = 0.1         # s, relaxation time of k1(T, t) while sintering (Table 1)
HEIGHT = 6.0e-3         # m, disk height h (Table 1)
MEAN_RADIUS = 1.0e-3    # m, a0 (Table 1)
RADIUS_SPREAD = 0.5     # w0 (Table 1)
WALL_MASS = 0.01        # kg, m_w (Table 1)
WALL_DAMPING = 0.2      # kg/s, gamma_w (Table 1)
CONTROL_T_HEAT = 0.5    # s, preparation of the three-particle control (control_doc)


@dataclass(frozen=True)
class Times:
    """The times of Sec. 4.1 (s): preparation until ``t_heat``, heating for ``heat`` (to t_sinter), sintering for
    ``t_s`` (to t_cool), cooling for ``cool`` (to t_relax), relaxation for ``relax`` (to t_f)."""

    t_s: float
    t_heat: float = 0.2
    heat: float = 0.1
    cool: float = 0.1
    relax: float = 0.1

    def __post_init__(self):
        for name in ("t_s", "t_heat", "heat", "cool", "relax"):
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value) \
                    or value <= 0:
                raise ValueError(f"{name} = {value!r}: must be a finite time > 0 (s)")

    @property
    def t_sinter(self) -> float:
        return self.t_heat + self.heat

    @property
    def t_cool(self) -> float:
        return self.t_sinter + self.t_s

    @property
    def t_relax(self) -> float:
        return self.t_cool + self.cool

    @property
    def t_f(self) -> float:
        return self.t_relax + self.relax


def _check_pressure(p) -> float:
    if not isinstance(p, (int, float)) or isinstance(p, bool) or not math.isfinite(p) or p <= 0:
        raise ValueError(f"p = {p!r}: must be a finite pressure > 0 (N/m for 2D disks, Pa for 3D spheres)")
    return float(p)


def contact_table(material: LudingMaterial = LUDING_TABLE1) -> dict:
    """The ``[contact]`` table of ``material`` (density goes to ``[material]``)."""
    return {"law": "luding", **{k: v for k, v in asdict(material).items() if k != "density"}}


FILL = {2: 0.3, 3: 0.2}  # solid fraction of the random placement (random sequential addition in a box jams near
                        # 0.5 in 2D and below 0.3 in 3D)


def box_side(n: int, fill: float, dimension: int = 2, mean_radius: float = MEAN_RADIUS,
             spread: float = RADIUS_SPREAD) -> float:
    """Edge of the square (cube) that ``n`` particles with radii uniform in ``a0 (1 +- w0)`` fill to the solid
    fraction ``fill`` on average (``<a^2> = a0^2 (1 + w0^2/3)``, ``<a^3> = a0^3 (1 + w0^2)``), and at least
    ``n^(1/d) + 1`` of the largest diameters, so that a few particles always find room."""
    if not isinstance(n, int) or isinstance(n, bool) or n < 1:
        raise ValueError(f"n = {n!r}: must be an integer >= 1")
    if not (isinstance(fill, (int, float)) and 0 < fill < 0.5):
        raise ValueError(f"fill = {fill!r}: must be in (0, 0.5) (random sequential addition jams near 0.5 in 2D "
                         f"and below 0.3 in 3D)")
    if dimension == 2:
        side = math.sqrt(n * math.pi * mean_radius**2 * (1 + spread**2 / 3) / fill)
    else:
        side = (n * 4.0 / 3.0 * math.pi * mean_radius**3 * (1 + spread**2) / fill) ** (1.0 / 3.0)
    return max(side, 2.0 * mean_radius * (1.0 + spread) * (n ** (1.0 / dimension) + 1.0))


def _axes(dimension: int) -> list[int]:
    return [0, 2] if dimension == 2 else [0, 1, 2]


def box_walls(side: float, p: float, dimension: int = 2, wall_mass: float = WALL_MASS,
              wall_damping: float = WALL_DAMPING) -> list[dict]:
    """The bi-axial box of Fig. 1: walls through the origin fixed (``left``, ``bottom``; 3D also ``front``),
    the opposite ones (``right``, ``top``; 3D also ``back``) stress-controlled at ``p`` (eq. 1)."""
    names = {0: ("left", "right"), 1: ("front", "back"), 2: ("bottom", "top")}
    walls = []
    for a in _axes(dimension):
        normal = [0.0, 0.0, 0.0]
        normal[a] = 1.0
        walls.append({"name": names[a][0], "point": [0.0, 0.0, 0.0], "normal": list(normal)})
    for a in _axes(dimension):
        normal, point = [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
        normal[a], point[a] = -1.0, side
        walls.append({"name": names[a][1], "point": point, "normal": normal, "motion": "stress", "pressure": p,
                      "mass": wall_mass, "damping": wall_damping})
    return walls


def _base(name: str, material: LudingMaterial, dimension: int, t_end: float, output_interval: float) -> dict:
    scene = {"name": name, "physics": ["mechanical"], "dimension": dimension}
    if dimension == 2:
        scene["height"] = HEIGHT
    return {"scene": scene, "material": {"density": material.density}, "contact": contact_table(material),
            "solver": {"mode": "transient", "t_end": t_end},
            "output": {"interval": output_interval, "vtu": False}}


def _continue_from(doc: dict, state: str) -> dict:
    """``doc`` (its times counted from the stage's start) started from the saved ``state``: the run's clock goes on
    from the state's (:mod:`dem.scene.state_file`), so ``t_end``, the schedule's knots and the phases' starts are
    moved by its time."""
    t0 = state_file.load(state)["t"]
    doc["start"] = {"state": str(state)}
    doc["solver"]["t_end"] = t0 + doc["solver"]["t_end"]
    if "temperature" in doc:
        doc["temperature"]["time"] = [t0 + t for t in doc["temperature"]["time"]]
    for phase in doc.get("phases", []):
        phase["start"] = t0 + phase["start"]
    return doc


def _prep_friction(material: LudingMaterial, prep_mu, prep_mu_wall) -> dict:
    """The ``[[phases]]`` entry of the preparation: friction ``prep_mu`` on the particles and ``prep_mu_wall`` on
    the walls, both Table 1's mu unless given (module docstring)."""
    mu = material.mu if prep_mu is None else prep_mu
    mu_wall = mu if prep_mu_wall is None else prep_mu_wall
    for name, value in (("prep_mu", mu), ("prep_mu_wall", mu_wall)):
        if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value) or value < 0:
            raise ValueError(f"{name} = {value!r}: must be a finite friction coefficient >= 0")
    return {"start": 0.0, "mu": float(mu), "mu_wall": float(mu_wall)}


def preparation_doc(n: int, p: float, *, seed: int = 1, times: Times | None = None, fill: float | None = None,
                    spread: float = RADIUS_SPREAD, speed: float = 0.01, prep_mu: float | None = None,
                    prep_mu_wall: float | None = None, material: LudingMaterial = LUDING_TABLE1,
                    dimension: int = 2, output_interval: float = 2.5e-3) -> dict:
    """The preparation (module docstring): random placement of radii uniform in ``a0 (1 +- spread)`` at solid
    fraction ``fill`` (default :data:`FILL`) with speeds ``speed`` (m/s), compression at ``p`` and 80 °C until
    ``times.t_heat`` with friction ``prep_mu`` on the particles and ``prep_mu_wall`` on the walls (default: Table 1's
    mu for both; 0 and 0 is the frictionless preparation the paper's text names)."""
    p = _check_pressure(p)
    phase = _prep_friction(material, prep_mu, prep_mu_wall)
    times = times or Times(t_s=1.0)
    side = box_side(n, FILL[dimension] if fill is None else fill, dimension, spread=spread)
    doc = _base(f"luding2005-preparation-n{n}-p{p:g}", material, dimension, times.t_heat, output_interval)
    hi = [side if a in _axes(dimension) else 0.0 for a in range(3)]
    doc["generator"] = {"kind": "box", "n": n, "radius": MEAN_RADIUS, "radius_spread": spread,
                        "box": [[0.0, 0.0, 0.0], hi], "speed": speed, "seed": seed, "temperature": T_PREPARE}
    doc["walls"] = box_walls(side, p, dimension)
    doc["phases"] = [phase]
    return doc


def _schedule(times: Times, material: LudingMaterial, cooling: bool, start: float = 0.0) -> dict:
    """``[temperature]`` from t_heat on, shifted to begin at ``start``: heating, sintering, then (``cooling``)
    cooling and relaxation; t0 = 0.1 s while sintering, the material's t0 elsewhere."""
    time = [start, start + times.heat, start + times.heat + times.t_s]
    value = [T_PREPARE, T_SINTER, T_SINTER]
    relax = [material.t0, T0_SINTER]
    if cooling:
        time += [time[-1] + times.cool, time[-1] + times.cool + times.relax]
        value += [T_PREPARE, T_PREPARE]
        relax += [material.t0, material.t0]
    return {"time": time, "value": value, "relaxation_time": relax}


def sintering_doc(state: str, p: float, t_s: float, *, cooling: bool = False, times: Times | None = None,
                  material: LudingMaterial = LUDING_TABLE1, dimension: int = 2,
                  output_interval: float = 2.5e-3) -> dict:
    """From the prepared ``state`` (a ``state.npz`` path, at t_heat): heating and sintering for ``t_s`` (to t_cool),
    and with ``cooling`` the cooling and relaxation too (to t_f)."""
    p = _check_pressure(p)
    times = times or Times(t_s=t_s)
    if times.t_s != t_s:
        raise ValueError(f"t_s = {t_s!r}: differs from times.t_s = {times.t_s!r}")
    t_end = times.heat + times.t_s + ((times.cool + times.relax) if cooling else 0.0)
    doc = _base(f"luding2005-sintering-p{p:g}-ts{t_s:g}", material, dimension, t_end, output_interval)
    doc["walls"] = box_walls(1.0, p, dimension)  # the saved walls keep their places (by name)
    doc["temperature"] = _schedule(times, material, cooling)
    return _continue_from(doc, state)


def cooling_doc(state: str, p: float, *, times: Times | None = None, material: LudingMaterial = LUDING_TABLE1,
                dimension: int = 2, walls_held: bool = False, output_interval: float = 2.5e-3) -> dict:
    """From a sintered ``state`` (at t_cool, 140 °C): cooling to 80 °C and relaxation (Sec. 4.1). With
    ``walls_held`` the stress-controlled walls stay where the state left them instead of following ``p`` (a
    control: the box cannot follow the particles' thermal contraction, eq. 9)."""
    p = _check_pressure(p)
    times = times or Times(t_s=1.0)
    doc = _base(f"luding2005-cooling-p{p:g}", material, dimension, times.cool + times.relax, output_interval)
    doc["walls"] = box_walls(1.0, p, dimension)
    if walls_held:
        doc["walls"] = [{key: w[key] for key in ("name", "point", "normal")} for w in doc["walls"]]
    doc["temperature"] = {"time": [0.0, times.cool, times.cool + times.relax], "value": [T_SINTER, T_PREPARE,
                                                                                          T_PREPARE],
                          "relaxation_time": [material.t0, material.t0]}
    return _continue_from(doc, state)


def schedule_doc(n: int, p: float, t_s: float, *, seed: int = 1, times: Times | None = None,
                 fill: float | None = None, speed: float = 0.01, prep_mu: float | None = None,
                 prep_mu_wall: float | None = None, material: LudingMaterial = LUDING_TABLE1,
                 output_interval: float = 5e-3) -> dict:
    """The whole of Fig. 7 in one 2D scene: preparation (:func:`preparation_doc`), then from t_heat Table 1's
    friction (the wall friction off), heating, sintering for ``t_s``, cooling and relaxation, to t_f."""
    times = times or Times(t_s=t_s)
    if times.t_s != t_s:
        raise ValueError(f"t_s = {t_s!r}: differs from times.t_s = {times.t_s!r}")
    doc = preparation_doc(n, p, seed=seed, times=times, fill=fill, speed=speed, prep_mu=prep_mu,
                          prep_mu_wall=prep_mu_wall, material=material, output_interval=output_interval)
    doc["scene"]["name"] = f"luding2005-schedule-n{n}-p{p:g}-ts{t_s:g}"
    doc["solver"]["t_end"] = times.t_f
    sched = _schedule(times, material, cooling=True, start=times.t_heat)
    doc["temperature"] = {"time": [0.0] + sched["time"], "value": [T_PREPARE] + sched["value"],
                          "relaxation_time": [material.t0] + sched["relaxation_time"]}
    doc["phases"].append({"start": times.t_heat, "mu": material.mu, "mu_wall": material.mu_wall})
    return doc


def control_doc(p: float, t_s: float, *, seed: int = 1, t_heat: float = CONTROL_T_HEAT,
                prep_mu: float | None = None, prep_mu_wall: float = 0.0,
                material: LudingMaterial = LUDING_TABLE1) -> dict:
    """The three-particle control of Sec. 4.1.3: :func:`schedule_doc` for three disks, "sintered in the same way as
    the larger samples", whose three particles "did not change their configuration". Two choices keep them so: the
    preparation lasts ``t_heat`` = 0.5 s (pressed by walls of 0.01 kg, three disks still bounce at 0.2 s and are at
    rest, with the same contacts, from 0.4 s on; the paper prepares "until a quasi-static situation is reached"),
    and the walls have no friction while preparing (``prep_mu_wall`` = 0: wall friction holds three disks in loose
    arches that collapse when it is switched off at t_heat, a rearrangement the control must not have)."""
    times = Times(t_s=t_s, t_heat=t_heat)
    doc = schedule_doc(3, p, t_s, seed=seed, times=times, prep_mu=prep_mu, prep_mu_wall=prep_mu_wall,
                       material=material)
    doc["scene"]["name"] = f"luding2005-control-p{p:g}-ts{t_s:g}"
    return doc


def compression_doc(state: str, p: float, *, strain_rate: float = 1.0, strain: float = 0.06, z0: float,
                    material: LudingMaterial = LUDING_TABLE1, output_interval: float = 5e-4) -> dict:
    """The compression test of Sec. 4.4 from a finished (2D) ``state``: left and bottom walls fixed, the right
    wall holding ``sigma_xx = p`` (eq. 1), the top wall moving down at ``strain_rate z0`` (m/s) until
    ``eps_zz = 1 - z/z0`` reaches ``strain``; ``z0`` is the top wall's height in the state (m)."""
    p = _check_pressure(p)
    for name, value in (("strain_rate", strain_rate), ("strain", strain), ("z0", z0)):
        if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value) or value <= 0:
            raise ValueError(f"{name} = {value!r}: must be a finite number > 0")
    if strain >= 1:
        raise ValueError(f"strain = {strain!r}: must be < 1 (eps_zz = 1 - z/z0)")
    doc = _base(f"luding2005-compression-p{p:g}", material, 2, strain / strain_rate, output_interval)
    walls = box_walls(1.0, p, 2)
    top = next(w for w in walls if w["name"] == "top")
    for key in ("pressure", "mass", "damping"):
        del top[key]
    top.update(motion="strain", velocity=strain_rate * z0)
    doc["walls"] = walls
    return _continue_from(doc, state)


def vibration_doc(state: str, floor: float, *, frequency: float = 100.0, amplitude: float = 2.0e-4,
                  duration: float = 0.1, gravity: float = 9.81, material: LudingMaterial = LUDING_TABLE1,
                  output_interval: float = 1e-3) -> dict:
    """The vibration test of Figs. 21-22 from a finished (2D) ``state``: no confining walls, a floor at height
    ``floor`` (m; where the sample's lowest particle touches it, :func:`floor_height`) vibrating as
    ``floor + amplitude sin(2 pi frequency t)`` for ``duration``, gravity ``-gravity`` along z."""
    for name, value in (("frequency", frequency), ("amplitude", amplitude), ("duration", duration),
                        ("gravity", gravity)):
        if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value) or value < 0 \
                or (value == 0 and name == "duration"):
            raise ValueError(f"{name} = {value!r}: must be a finite number {'> 0' if name == 'duration' else '>= 0'}")
    doc = _base("luding2005-vibration", material, 2, duration, output_interval)
    doc["walls"] = [{"name": "floor", "point": [0.0, 0.0, float(floor)], "normal": [0.0, 0.0, 1.0],
                     "motion": "vibrate", "amplitude": amplitude, "frequency": frequency}]
    doc["gravity"] = {"acceleration": [0.0, 0.0, -gravity]}
    return _continue_from(doc, state)


def heated_walls_doc(state: str, p: float, *, hot: float, cold: float, duration: float, t0: float,
                     conductivity: float, specific_heat: float, material: LudingMaterial = LUDING_TABLE1,
                     thermal_interval: float = 5e-4, output_interval: float = 5e-3) -> dict:
    """The 3D protocol with heat flow instead of a prescribed schedule: from a prepared or sintered 3D ``state``,
    the bottom wall held at ``hot`` and the top wall at ``cold`` (°C) for ``duration`` (s), the particles'
    temperatures computed by the pipe network on their contacts (``physics = ["mechanical", "thermal"]``,
    conductance law ``fit``), the stiffness relaxing with ``t0`` (s); ``conductivity`` (W/(m K)) and
    ``specific_heat`` (J/(kg K)) of the particles. The box stays under ``p`` (Pa) on its three stress walls."""
    p = _check_pressure(p)
    if not (isinstance(hot, (int, float)) and isinstance(cold, (int, float)) and hot != cold):
        raise ValueError(f"hot = {hot!r}, cold = {cold!r}: must be two different temperatures (°C)")
    doc = _base("luding2005-heated-walls-3d", replace(material, t0=t0), 3, duration, output_interval)
    doc["scene"]["physics"] = ["mechanical", "thermal"]
    doc["material"].update(conductivity=conductivity, specific_heat=specific_heat)
    walls = box_walls(1.0, p, 3)
    next(w for w in walls if w["name"] == "bottom")["temperature"] = hot
    next(w for w in walls if w["name"] == "top")["temperature"] = cold
    doc["walls"] = walls
    doc["conductance"] = {"law": "fit", "out_of_range": "clip"}
    doc["solver"].update(integrator="implicit", thermal_interval=thermal_interval)
    return _continue_from(doc, state)


def floor_height(saved: dict) -> float:
    """The height (m) at which a floor touches the lowest particle of a saved state (:func:`dem.scene.state_file.load`)."""
    return float(np.min(saved["x"][:, 2] - saved["radius"]))


def wall_offset(saved: dict, name: str) -> float:
    """Offset ``q`` of the saved wall ``name`` (for the top wall of Fig. 1, ``z = -q``)."""
    if name not in saved["wall_names"]:
        raise ValueError(f"wall {name!r}: not in the saved state (walls: {', '.join(saved['wall_names'])})")
    return float(saved["wall_q"][saved["wall_names"].index(name)])
