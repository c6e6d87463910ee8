"""The sintering section (Luding 2005, Sec. 4): its statements table, its grid of runs and their resumption."""

import json
import pathlib
from dataclasses import asdict

import numpy as np
import pytest

from verification.cli import COMMANDS
from verification.luding import causes as cooling
from verification.luding import runs as sr
from verification.luding import section as S
from verification.luding import statements as T
from verification.luding import study as Y
from verification.report import check_section_result, jsonable, section_available, section_module

TINY = sr.Grid(n=(12,), p=(10.0, 100.0), t_s=(1e-4, 2e-3), three_seeds=(1,), no_expansion=False, n3d=12)


def test_registered_as_a_command():
    assert COMMANDS["sintering"][0] == ("sintering",)
    assert section_module("sintering") == S.__name__ and section_available("sintering")


def test_tasks_start_from_their_parents_and_name_their_folders():
    task = sr.Task(sr.VIBRATE, 100, 10.0, 0.02)
    assert task.folder == "runs/vibrate/n100-p10-ts0.02"
    assert task.parent == sr.Task(sr.COOL, 100, 10.0, 0.02)
    assert task.parent.parent.parent == sr.Task(sr.PREPARE, 100, 10.0)
    chain = sr.with_parents([task, sr.Task(sr.COMPRESS, 100, 10.0, 0.02)])
    assert [t.kind for t in chain] == [sr.PREPARE, sr.SINTER, sr.COOL, sr.VIBRATE, sr.COMPRESS]
    control = sr.Task(sr.SCHEDULE, 3, 100.0, 1.0, seed=2, variant="no-expansion")
    assert control.sample == "n3-p100-ts1-seed2-no-expansion"
    full = sr.FULL.tasks()
    assert len(set(full)) == len(full)
    assert {(t.n, t.p) for t in full if t.kind == sr.COMPRESS} == {(100, 10.0), (100, 100.0), (300, 10.0), (300, 100.0)}


def test_every_statement_needs_runs_and_says_which():
    st = Y.Study(pathlib.Path("nowhere"), TINY, {})
    items, skipped = T.statements(st)
    assert items == [] and len(skipped) == len(T.CHECKS)
    assert all("(needs " in line for line in skipped)


def test_statement_rows_carry_the_json_fields():
    s = T.Statement("Sec. 4.1.4", "density after sintering", "≈ 0.92", "0.915", True, "±0.015")
    row = jsonable(asdict(s))
    assert {"statement", "paper", "ours", "holds"} <= set(row) and row["holds"] is True
    table = T.statements_table([s])
    assert "| 1 | Sec. 4.1.4 | density after sintering | ≈ 0.92 | 0.915 | yes | ±0.015 |" in table


@pytest.mark.slow
def test_tiny_grid_runs_resumes_and_fills_the_contract(tmp_path, monkeypatch):
    monkeypatch.setattr(sr, "QUICK", TINY)
    result = check_section_result("sintering", S.run(tmp_path, quick=True))
    statements = result["summary"]["statements"]
    assert statements and all(isinstance(s["holds"], bool) for s in statements)
    assert json.loads(json.dumps(jsonable(result["summary"])))["statements"] == jsonable(statements)
    assert all(pathlib.Path(f).stat().st_size > 10_000 for f in result["figures"])
    finished = sorted(tmp_path.glob("runs/*/*/result.json"))
    stamps = [p.stat().st_mtime_ns for p in finished]
    again = S.run(tmp_path, quick=True)  # everything finished: nothing runs again
    assert [p.stat().st_mtime_ns for p in finished] == stamps
    assert again["summary"]["statements"] == statements
    vib = json.loads((tmp_path / sr.Task(sr.VIBRATE, 12, 10.0, 1e-4).folder / "result.json").read_text())
    assert vib["volume_fraction"] is None and vib["fragments"] >= 1 and np.isfinite(vib["seconds"])
    cool = sr.Task(sr.COOL, 12, 100.0, 2e-3)
    st = Y.Study(tmp_path, TINY, {t: sr.load_result(tmp_path, t) for t in (cool, cool.parent)})
    c = cooling.cool_down(st.series(cool), 0.0)
    assert c["particles"] == pytest.approx((0.996 / 1.002) ** 2 - 1.0, rel=1e-9)  # eq. 9: a(80 °C)/a(140 °C)
    hot, cold = st.res(sr.SINTER, 12, 100.0, 2e-3), st.res(sr.COOL, 12, 100.0, 2e-3)
    assert cold["mass_fraction"] * (1.0 + c["box"]) == pytest.approx(hot["mass_fraction"], rel=1e-12)  # M conserved


def test_rattlers_are_peeled_off_until_every_particle_has_two_contacts():
    # a triangle 0-1-2 with a tail 2-3-4 and a lone particle 5: the tail peels off (4 first, then 3)
    i, j = np.array([0, 1, 0, 2, 3]), np.array([1, 2, 2, 3, 4])
    c, removed = Y.without_rattlers(i, j, 6)
    assert (c, removed) == (2.0, 3)


def test_failure_is_the_peak_before_the_first_load_drop():
    assert Y.failure([10, 40, 55, 50, 20, 80, 90]) == 2  # 20 < 55/2: failed at 55, the later 90 is rubble
    assert Y.failure([10, 20, 30, 25, 28, 35, 20]) == 5  # never below half: the largest


def test_isolating_variants_start_where_they_should():
    held = sr.Task(sr.COOL, 100, 100.0, 1.0, variant="held")
    assert held.parent == sr.Task(sr.SINTER, 100, 100.0, 1.0)  # the cool-down alone changes: the protocol's state
    fr = sr.Task(sr.COOL, 100, 10.0, 1.0, variant="frictionless")
    assert fr.parent.parent == sr.Task(sr.PREPARE, 100, 10.0, variant="frictionless")
    assert sr.Task(sr.SCHEDULE, 3, 10.0, 1.0).times.t_heat == 0.5
    assert sr.Task(sr.SCHEDULE, 3, 10.0, 1.0, variant="short-prep").times.t_heat == 0.2
    assert sr.Task(sr.PREPARE, 100, 10.0).times.t_heat == 0.2
    for grid in (sr.QUICK, sr.FULL):
        tasks = grid.isolating_tasks()
        assert tasks and len(set(tasks)) == len(tasks) and all(t.variant in sr.VARIANTS or t.seed in sr.PREP_SEEDS
                                                                or t.n == 3 for t in tasks)
    assert TINY.isolating_tasks() == []
    quick, full = set(sr.QUICK.isolating_tasks()), set(sr.FULL.isolating_tasks())
    assert {t.kind for t in quick} == {sr.PREPARE, sr.SCHEDULE} and quick < full  # --quick: the cheap ones alone
    assert all(t.n == 3 for t in quick if t.kind == sr.SCHEDULE)
    assert sr.Task(sr.COOL, 300, 100.0, 1.0, variant="held") in full
    assert sr.Task(sr.SCHEDULE, 3, 100.0, 1.0, 1, "walls-sinter") in full
    for grid in (sr.QUICK, sr.FULL):  # the densification statements read every placement of N max
        assert {sr.Task(sr.COOL, max(grid.n), p, max(grid.t_s), seed) for p in grid.p for seed in sr.PLACEMENTS} \
            <= set(sr.with_parents(grid.tasks()))
        # and the failure statements every placement's compression test, for every N, p and t_s
        assert {sr.Task(sr.COMPRESS, n, p, t, seed) for n in grid.n for p in grid.p for t in grid.t_s
                for seed in sr.PLACEMENTS} <= set(grid.tasks())


def test_scene_docs_of_the_variants(tmp_path, monkeypatch):
    from verification.luding import protocol as sp

    prep = sr.scene_doc(sr.Task(sr.PREPARE, 20, 10.0, variant="frictionless-slow"), tmp_path)
    assert prep["phases"] == [{"start": 0.0, "mu": 0.0, "mu_wall": 0.0}]
    assert {w["damping"] for w in prep["walls"] if w.get("motion") == "stress"} == {2.0}
    assert sr.scene_doc(sr.Task(sr.PREPARE, 20, 10.0), tmp_path)["phases"] == [{"start": 0.0, "mu": 0.5,
                                                                                  "mu_wall": 0.5}]
    assert sr.scene_doc(sr.Task(sr.PREPARE, 20, 10.0, variant="frictionless-cohesive"),
                        tmp_path)["contact"]["brittle_sliding"] is False
    control = sr.scene_doc(sr.Task(sr.SCHEDULE, 3, 100.0, 1.0, 1, "walls-sinter"), tmp_path)
    assert control["contact"]["wall_sintering"] is True and control["temperature"]["time"][1] == 0.5
    assert control["phases"][0] == {"start": 0.0, "mu": 0.5, "mu_wall": 0.0}
    assert max(control["temperature"]["value"]) == 140.0
    cold = sr.scene_doc(sr.Task(sr.SCHEDULE, 3, 10.0, 1.0, 1, "no-heating"), tmp_path)
    assert set(cold["temperature"]["value"]) == {80.0}  # kept at the preparation's temperature
    assert cold["temperature"]["time"] == control["temperature"]["time"]  # on the same schedule otherwise
    monkeypatch.setattr(sp.state_file, "load", lambda path: {"t": 1.3})  # a sintered state's clock
    held = sp.cooling_doc("s.npz", 100.0, walls_held=True)
    assert all("motion" not in w for w in held["walls"]) and len(held["walls"]) == 4
    assert held["solver"]["t_end"] == pytest.approx(1.5) and held["temperature"]["time"][0] == 1.3


def test_the_density_statements_read_the_material_density():
    """Sec. 4.1.4's 0.92 after sintering and 0.94 after cool-down are one measure, M/(rho_p V): hot, the solid
    fraction at the current radii is larger by (a(140 °C)/a(80 °C))^2 and would pass where the material density fails."""
    hot = {"volume_fraction": 0.9151, "mass_fraction": 0.9151 * (0.996 / 1.002) ** 2}
    cold = {"volume_fraction": 0.9300, "mass_fraction": 0.9300}
    grid = sr.Grid(n=(300,), p=(100.0,), t_s=(1.0,), three_seeds=(1,), no_expansion=False, n3d=12)
    st = Y.Study(pathlib.Path("nowhere"), grid, {sr.Task(sr.SINTER, 300, 100.0, 1.0): hot,
                                                 sr.Task(sr.COOL, 300, 100.0, 1.0): cold})
    after_sintering, after_cooling, rise = T._nu_after_sintering(st), T._nu_after_cooling(st), T._cooling_increase(st)
    assert not after_sintering.holds and after_sintering.ours.startswith("0.9042 ")
    assert after_cooling.holds and after_cooling.ours == "0.9300"
    assert rise.holds and rise.ours.startswith("+0.0258 ")


def test_the_densification_statements_read_the_mean_over_the_placements():
    """One sample of N = 100 at p = 10 densifies by 3-8 % with its wall layer: the statement reads the mean of the
    placements, and says each."""
    grid = sr.Grid(n=(100,), p=(10.0, 100.0), t_s=(1.0,), three_seeds=(1,), no_expansion=False, n3d=12)
    nu = {10.0: ([0.76, 0.78, 0.78], [0.82, 0.82, 0.80]), 100.0: ([0.775, 0.776, 0.774], [0.898, 0.899, 0.900])}
    results = {}
    for p, (start, end) in nu.items():
        for seed, a, b in zip(sr.PLACEMENTS, start, end):
            results[sr.Task(sr.PREPARE, 100, p, seed=seed)] = {"volume_fraction": a}
            results[sr.Task(sr.COOL, 100, p, 1.0, seed)] = {"volume_fraction": b}
    st = Y.Study(pathlib.Path("nowhere"), grid, results)
    assert st.densification(10.0) == pytest.approx([0.82 / 0.76 - 1, 0.82 / 0.78 - 1, 0.80 / 0.78 - 1], rel=1e-12)
    low, high = T._densification(st)
    mean = np.mean([0.82 / 0.76, 0.82 / 0.78, 0.80 / 0.78]) - 1.0  # 5.3 %: holds, where the first alone (7.9 %) fails
    assert low.holds and low.ours.startswith(f"{100 * mean:.2f} % (mean of the placements 7.89 %, 5.13 %, 2.56 %")
    assert high.holds
    del results[sr.Task(sr.COOL, 100, 10.0, 1.0, 3)]
    with pytest.raises(Y.Missing):  # a placement missing: no statement from the others
        T._densification(Y.Study(pathlib.Path("nowhere"), grid, results))


def test_the_failure_statements_read_the_mean_over_the_placements():
    """The failure strain of barely sintered samples differs more between placements than between t_s: the
    statements read the mean of the placements (here the quick grid's numbers, rounded)."""
    grid = sr.Grid(n=(100,), p=(10.0, 100.0), t_s=(1e-4, 0.01, 1.0), three_seeds=(1,), no_expansion=False, n3d=12)
    strain = {10.0: {1e-4: [0.0015, 0.0016, 0.0018], 0.01: [0.0014, 0.0019, 0.0017], 1.0: [0.0069, 0.0051, 0.0057]},
              100.0: {1e-4: [0.009, 0.023, 0.023], 0.01: [0.016, 0.014, 0.010], 1.0: [0.036, 0.057, 0.039]}}
    st = Y.Study(pathlib.Path("nowhere"), grid, {})

    def compression(n, p, t_s, variant="", seed=1):
        e = strain[p][t_s][sr.PLACEMENTS.index(seed)]
        return {"failure_strain": e, "failure_stress": 1e5 * e}

    st.compression = compression
    assert st.placement_failures(100, 100.0, 1e-4, "failure_strain") == [0.009, 0.023, 0.023]
    stress_t, stress_p, strain_t, strain_p = T._failure_grows(st)
    # p = 10: the first placement alone falls from t_s = 1e-4 to 0.01 (rank correlation 0.5), the mean rises
    assert "N=100, p=10: 0.00163 → 0.0059 (rank corr. 1.00)" in strain_t.ours
    # p = 100: the mean falls from 0.0183 to 0.0133 between t_s = 1e-4 and 0.01
    assert "N=100, p=100: 0.0183 → 0.044 (rank corr. 0.50)" in strain_t.ours and not strain_t.holds
    assert strain_p.holds and strain_p.ours == "larger at p = 100 in 3 of 3 (N, t_s)"
    assert stress_p.holds and not stress_t.holds  # the stress here is the strain scaled: the same order


def test_the_coordination_table_lists_every_preparation_and_placement_the_grid_sintered():
    grid = sr.Grid(n=(100,), p=(10.0,), t_s=(1.0,), three_seeds=(1,), no_expansion=False, n3d=12)
    done = {sr.Task(sr.SINTER, 100, 10.0, 1.0): {}, sr.Task(sr.SINTER, 100, 10.0, 1.0, 3): {},
            sr.Task(sr.SINTER, 100, 10.0, 1.0, variant="frictionless"): {},
            sr.Task(sr.SINTER, 100, 10.0, 1.0, 2): {"error": "failed"}}
    st = Y.Study(pathlib.Path("nowhere"), grid, done)
    listed = cooling.sintered_preparations(st, 100, 10.0)
    assert [task for _, task in listed] == [sr.Task(sr.SINTER, 100, 10.0, 1.0),
                                            sr.Task(sr.SINTER, 100, 10.0, 1.0, variant="frictionless"),
                                            sr.Task(sr.SINTER, 100, 10.0, 1.0, 3)]  # the failed placement left out
    assert listed[1][0] == cooling.PREP_LABELS["frictionless"] and listed[2][0] == "protocol, placement (seed) 3"
    assert cooling.sintered_preparations(st, 100, 100.0) == []


def test_the_interior_fraction_leaves_the_wall_layer_out():
    """A disk of radius 1 mm in the middle of a 10 mm box: pi r^2 over the 4 mm x 4 mm interior 3 mm from the walls;
    one touching a wall adds nothing; a margin that leaves no interior is refused by name."""
    saved = {"x": np.array([[5e-3, 0.0, 5e-3], [1e-3, 0.0, 5e-3]]), "radius": np.array([1e-3, 1e-3]),
             "wall_names": ["left", "bottom", "right", "top"], "wall_q": np.array([0.0, 0.0, -10e-3, -10e-3])}
    assert cooling.interior_fraction(saved, 3e-3, spacing=1e-5) == pytest.approx(np.pi * 1e-6 / 16e-6, rel=2e-3)
    assert cooling.interior_fraction(saved, 0.0, spacing=1e-5) == pytest.approx(2 * np.pi * 1e-6 / 1e-4, rel=2e-3)
    with pytest.raises(ValueError, match="margin = 0.006"):
        cooling.interior_fraction(saved, 6e-3)


def test_the_cool_down_splits_into_the_box_and_the_particles_area():
    side = np.array([30e-3, 29.97e-3, 29.94e-3])  # the box shrinks by 1 - 0.998^2 from the first row to the last
    s = {"t": np.array([0.0, 0.1, 0.2]), "q_left": np.zeros(3), "q_bottom": np.zeros(3), "q_right": -side,
         "q_top": -side, "volume_fraction": np.array([0.90, 0.91, 0.92]), "wall_top": np.array([0.0, 99.0, 101.0])}
    c = cooling.cool_down(s, 0.0)
    assert c["box"] == pytest.approx(0.998**2 - 1.0, rel=1e-12)
    assert c["particles"] == pytest.approx(0.998**2 * 0.92 / 0.90 - 1.0, rel=1e-12)  # solid area = nu times box
    assert (c["nu_cool"], c["nu_f"], c["top_min"], c["top_max"]) == (0.90, 0.92, 99.0, 101.0)  # no load in row 0


def test_frozen_radii_keep_each_particle_its_size(tmp_path):
    from dataclasses import replace

    from dem.laws.contact.luding import LUDING_TABLE1
    from dem.laws.contact.state.sintering import radius_at

    state = tmp_path / "state.npz"
    radius, T = np.array([1.002e-3, 0.5e-3]), np.array([140.0, 140.0])
    np.savez(state, radius=radius, radius_ref=np.array([1e-3, 0.499e-3]), T=T, x=np.zeros((2, 3)))
    out = np.load(sr._frozen_radii(state, tmp_path / "frozen" / "start.npz", replace(LUDING_TABLE1, expansion=0.0)))
    assert np.array_equal(out["radius_ref"], out["radius"]) and np.array_equal(out["x"], np.zeros((2, 3)))
    five = replace(LUDING_TABLE1, expansion=5e-4)  # eq. 9 with the new delta a_T gives the saved radii back at 140 °C
    out = np.load(sr._frozen_radii(state, tmp_path / "five" / "start.npz", five))
    assert radius_at(out["radius_ref"], T, five.T_melt, five.expansion) == pytest.approx(radius, rel=1e-14)
    assert radius_at(out["radius_ref"], 80.0, five.T_melt, five.expansion) == pytest.approx(radius * 0.98 / 1.01)


def test_a_contact_cooled_with_its_centres_held_goes_into_tension_as_eqs_9_10_13_predict():
    from verification.luding.causes import contact_cooling

    strong = contact_cooling(0.2)  # the paper's mean contact force at p = 100 N/m
    assert strong["hot"]["force"] == pytest.approx(0.2, rel=1e-12)
    assert strong["shrink"] == pytest.approx(2 * 1e-3 * 1e-4 * 60.0, rel=1e-12)  # eq. 9, both radii, 60 K
    assert strong["held"] == pytest.approx(strong["held_predicted"], rel=1e-9)
    assert strong["held"] < -5 * 0.2  # attraction far beyond the force it carried hot
    assert strong["no_expansion"] == pytest.approx(strong["no_expansion_predicted"], rel=1e-9)
    assert strong["no_expansion"] > 0.2  # without contraction: repulsive, stiffer (k2(delta_max) grew)
    weak = contact_cooling(0.02)  # p = 10: the overlap (10 um) is gone before 80 C
    assert weak["cold_overlap"] < 0 and weak["held"] == 0.0 == weak["held_predicted"]


def test_a_stage_run_from_a_state_is_read_on_its_own_clock(tmp_path):
    """A stage started from a saved state goes on with the state's clock; the study counts each stage's time from
    its start, so the joined history of Fig. 7 puts the sintering at t_heat, not at twice it."""
    rows = {sr.PREPARE: (0.0, 0.1, 0.2), sr.SINTER: (0.2, 0.25, 0.3), sr.COOL: (0.3, 0.4, 0.5)}
    results = {}
    for kind, times in rows.items():
        task = sr.Task(kind, 12, 10.0, None if kind == sr.PREPARE else 1e-4)
        folder = tmp_path / task.folder
        folder.mkdir(parents=True)
        (folder / "timeseries.csv").write_text("t,volume_fraction,T_mean\n" + "".join(f"{t},0.8,80\n" for t in times))
        results[task] = {"t": times[-1]}
    st = Y.Study(tmp_path, TINY, results)
    assert st.series(sr.Task(sr.SINTER, 12, 10.0, 1e-4))["t"].tolist() == pytest.approx([0.0, 0.05, 0.1])
    t_heat, t_cool = sr.Task(sr.SINTER, 12, 10.0, 1e-4).times.t_heat, sr.Times(t_s=1e-4).t_cool
    assert st.history(12, 10.0, 1e-4)["t"].tolist() == pytest.approx([0.0, 0.1, 0.2, t_heat + 0.05, t_heat + 0.1,
                                                                       t_cool + 0.1, t_cool + 0.2])


def test_the_prose_template_has_every_block_the_section_fills_and_no_other(tmp_path):
    import re

    used = set(re.findall(r'PROSE\["([^"]+)"\]', pathlib.Path(S.__file__).read_text()))
    assert used == set(S.PROSE)
    assert S.PROSE["discussion"] == "**Where ours differs, and why.**"  # (blocks end before their blank lines)
    template = tmp_path / "t.md"
    template.write_text("<!-- a comment\nover two lines -->\n\n<!-- one -->\nx = {x:.2f}\n\n<!-- two -->\n y\nz\n")
    blocks = S.prose_blocks(template)
    assert blocks == {"one": "x = {x:.2f}", "two": " y\nz"} and blocks["one"].format(x=1) == "x = 1.00"
