"""The mechanics benchmark (benchmarks/mechanics.py) on tiny sizes, so that its code cannot rot: every study runs and
writes its rows, figures and summary keys; no timing is asserted."""

import csv
import math
from dataclasses import replace

import pytest

from sinterheat.threads import cores

from benchmarks import mechanics

TINY = mechanics.Sizes(disks=40, compaction_time=0.02, cells=(3, 3, 3), steps_2d=100, steps_3d=50, warmup=10,
                       rounds=1, kernel_contacts=1000, fresh_cache=False, thermal_scenes=("lattice",),
                       thermal_rounds=1, full_size=False, schedule=(20, 1e-3))

LAMMPS_LOG = """LAMMPS (22 Jul 2025 - Update 4)
Per MPI rank memory allocation (min/avg/max) = 10.07 | 10.07 | 10.07 Mbytes
   Step         KinEng       c_rotation     c_contacts
         0   0              0              700
        10   1.5e-08        2.5e-09        692
Loop time of 0.01 on 1 procs for 10 steps with 108 atoms

50.0% CPU use with 1 MPI tasks x 1 OpenMP threads
Per MPI rank memory allocation (min/avg/max) = 10.07 | 10.07 | 10.07 Mbytes
   Step         KinEng       c_rotation     c_contacts
        10   1.5e-08        2.5e-09        692
       110   1e-07          2e-08          690
Loop time of 0.0216 on 1 procs for 100 steps with 108 atoms

80.0% CPU use with 1 MPI tasks x 1 OpenMP threads

MPI task timing breakdown:
Section |  min time  |  avg time  |  max time  |%varavg| %total
---------------------------------------------------------------
Pair    | 0.0108     | 0.0108     | 0.0108     |   0.0 | 50.00
Neigh   | 0          | 0          | 0          |   0.0 |  0.00
Modify  | 0.00216    | 0.00216    | 0.00216    |   0.0 | 10.00
Other   |            | 0.00864    |            |       | 40.00

Total # of neighbors = 432
Ave neighs/atom = 4
Neighbor list builds = 3
Dangerous builds = 0
"""


class StandInSection:
    """What ``benchmarks`` hands a subject (verification.report.Section), reduced to what the subject calls."""

    def __init__(self, folder):
        self.out_dir, self.summary, self.targets, self.texts, self.figures = folder, {}, [], [], []

    def folder(self):
        self.out_dir.mkdir(parents=True, exist_ok=True)
        return self.out_dir

    def csv(self, stem, rows):
        path = self.folder() / f"{stem}.csv"
        with path.open("w", newline="") as fh:
            writer = csv.DictWriter(fh, fieldnames=list(dict.fromkeys(k for row in rows for k in row)))
            writer.writeheader()
            writer.writerows(rows)
        return path

    def figure(self, fig, stem):
        path = self.folder() / f"{stem}.png"
        fig.savefig(path)
        self.figures.append(path)
        return path

    def add_text(self, heading, text, figures=()):
        self.texts.append((heading, text, list(figures)))

    def target(self, label, measured, limit, unit=""):
        self.targets.append((label, measured, limit))
        return "not measured" if measured is None else ("pass" if measured <= limit else "fail")


def test_lammps_log_is_read_from_its_last_run():
    out = mechanics.parse_lammps_log(LAMMPS_LOG)
    assert (out["particles"], out["steps"], out["rebuilds"], out["listed_per_particle"]) == (108, 100, 3, 4.0)
    assert out["wall_ns_per_particle_step"] == pytest.approx(0.0216 / (100 * 108) * 1e9)
    assert out["ns_per_particle_step"] == pytest.approx(0.8 * 0.0216 / (100 * 108) * 1e9)  # CPU time: 80 % use
    assert out["breakdown"]["Pair"] == pytest.approx(0.8 * 0.0108 / (100 * 108) * 1e9)
    assert out["kinetic_energy"] == pytest.approx(1.2e-7)
    assert out["contacts_per_particle"] == pytest.approx(690 / 2 / 108)  # contact/atom counts both atoms
    with pytest.raises(ValueError, match="no loop time"):
        mechanics.parse_lammps_log("ERROR: Unknown pair style")


def test_linear_limit_is_the_luding_law_without_plasticity_and_cohesion():
    lin = mechanics.linear_limit(mechanics.LUDING_TABLE1)
    assert (lin.k1, lin.k2, lin.kc, lin.brittle_sliding) == (2e5, 2e5, 0.0, False)
    assert (lin.mu, lin.gamma_n, lin.gamma_t) == (0.5, 0.2, 0.05)
    from dem.laws.contact.state.sintering import k1_factor

    assert k1_factor(mechanics.T_RUN, lin.T_melt, lin.T_var) == 1.0  # no softening at the run's temperature


@pytest.mark.slow  # the benchmark's whole quick path, every row (~2 min)
def test_quick_path_on_tiny_sizes_writes_every_row(tmp_path):
    section = StandInSection(tmp_path / "mechanics")
    mechanics.run(section, quick=True, sizes=TINY, cache=tmp_path / "cache")
    s = section.summary
    for key in ("contact_ns_per_particle_step_2d", "contact_ns_per_particle_step_3d",
                "contact_linear_ns_per_particle_step_3d", "luding_kernels_ns_per_contact"):
        assert s[key] > 0 and math.isfinite(s[key]), key
    assert s["mechanics_particles"] == {"2d": 40, "3d": 108}
    assert s["mechanics_listed_per_particle"]["ours, Luding, 3D"] > 0
    with_lammps = mechanics.lammps_command() is not None
    assert (s["lammps_ns_per_particle_step_3d"] is not None) == with_lammps
    if with_lammps:  # the same packing, masses, time step and normal law: the same trajectory without friction
        assert s["lammps_frictionless_kinetic_energy_rel_diff"] < 1e-6
        assert s["mechanics_contacts_per_particle"][mechanics.GRANULAR] == pytest.approx(
            s["mechanics_contacts_per_particle"]["ours, linear, 3D"], rel=0.05)
    assert set(s["mechanics_stage_ns_3d"]) == {"whole step", "without pairs", "rebuilds", "pairs", "force pass alone",
                                               "material state alone"}
    assert s["mechanics_compile_seconds"]["cached"] > 0
    assert s["thermal_only_engine_modules"] == []  # a thermal-only run loads no numba, no engine
    targets = {label: measured for label, measured, _ in section.targets}
    counts = [k for k in (1, 2) if k <= cores()]
    assert sum(label.startswith("ours (") for label in targets) == 2 + (len(counts) > 1)  # Luding, linear; 2 cores
    assert all(targets[label] is None for label in targets if label.startswith("ours ("))  # not at full size
    assert targets["engine modules imported by a thermal-only run"] == 0
    assert [h for h, _, _ in section.texts] == ["The time loop: ours and LAMMPS side by side",
                                                "Where our time goes (3D, Luding)",
                                                "Every core: threads against MPI ranks",
                                                "Compile cost and the Luding kernels",
                                                "Thermal-only scenes keep their path",
                                                "The whole sintering schedule"]
    schedule = s["sintering_schedule"]
    assert schedule["n"] == 20 and schedule["steps"] > 0 and 0 < schedule["volume_fraction"] < 1
    assert targets["the whole sintering schedule (Luding 2005 Fig. 7), N = 300, t_s = 1 s"] is None
    assert {p.name for p in section.figures} == {"mechanics_loop.png"}
    rows = list(csv.DictReader((section.out_dir / "mechanics_loop.csv").open()))
    assert len(rows) == 3 + 2 * with_lammps
    threaded = list(csv.DictReader((section.out_dir / "mechanics_threads.csv").open()))
    ranks = [k for k in counts if mechanics.lammps_command(k) is not None]
    assert [(r["run"], int(r["cores"])) for r in threaded] == [
        *((f"ours, {law}, {k} thread{'s' * (k > 1)}", k) for k in counts for law in ("linear", "Luding")),
        *((f"LAMMPS granular, {k} rank{'s' * (k > 1)}", k) for k in ranks)]
    assert all(float(r["wall_ns_per_particle_step"]) > 0 for r in threaded)
    assert all(r["threaded_loop"] == "False" for r in threaded if r["run"].startswith("ours"))  # 108: too few
    assert sorted(p.name for p in (tmp_path / "cache").iterdir()) == sorted(
        [f"biaxial_{mechanics.PREPARATION}_n40_t0.02_s1.npz", f"periodic_{mechanics.PREPARATION}_3x3x3_z6.5_s0.npz"])


@pytest.mark.slow  # the study's loop on the packings it first prepares; the log parser and linear limit: quick
def test_lammps_rows_are_skipped_with_a_note_when_it_is_absent(tmp_path, monkeypatch):
    monkeypatch.setattr(mechanics, "lammps_command", lambda ranks=1: None)
    section = StandInSection(tmp_path / "mechanics")
    mechanics.study_loop(section, replace(TINY, steps_2d=10, steps_3d=10), tmp_path / "cache")
    assert section.summary["lammps_ns_per_particle_step_3d"] is None
    assert section.summary["contact_over_lammps_3d"] is None
    assert "LAMMPS is not installed" in section.texts[0][1]
    assert all(measured is None for _, measured, _ in section.targets)
