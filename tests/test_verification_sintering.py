"""The sintering section (Luding 2005, Sec. 4): its statements table, its grid of runs and their resumption."""

import json
import pathlib
from dataclasses import asdict

import numpy as np
import pytest

from verification import sintering as S
from verification import sintering_runs as sr
from verification import sintering_statements as T
from verification import sintering_study as Y
from verification.cli import COMMANDS
from verification.report import check_section_result, jsonable

TINY = sr.Grid(n=(12,), p=(10.0, 100.0), t_s=(1e-4, 2e-3), three_seeds=(1,), no_expansion=False, n3d=12)


def test_registered_as_a_command():
    assert COMMANDS["sintering"][0] == ("sintering",)


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


def test_rattlers_are_peeled_off_until_every_particle_has_two_contacts():
    # a triangle 0-1-2 with a tail 2-3-4 and a lone particle 5: the tail peels off (4 first, then 3)
    i, j = np.array([0, 1, 0, 2, 3]), np.array([1, 2, 2, 3, 4])
    c, removed = Y.without_rattlers(i, j, 6)
    assert (c, removed) == (2.0, 3)


def test_failure_is_the_peak_before_the_first_load_drop():
    assert Y.failure([10, 40, 55, 50, 20, 80, 90]) == 2  # 20 < 55/2: failed at 55, the later 90 is rubble
    assert Y.failure([10, 20, 30, 25, 28, 35, 20]) == 5  # never below half: the largest
