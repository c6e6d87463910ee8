"""The sintering section (Luding 2005, Sec. 4): its statements table, its grid of runs and their resumption."""

import json
import pathlib

import numpy as np
import pytest

from verification import sintering as S
from verification import sintering_runs as sr
from verification.__main__ import COMMANDS
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
    assert sr.Task(sr.SCHEDULE, 3, 100.0, 1.0, seed=2, variant="no-expansion").sample == "n3-p100-ts1-seed2-no-expansion"
    full = sr.FULL.tasks()
    assert len(set(full)) == len(full)
    assert {(t.n, t.p) for t in full if t.kind == sr.COMPRESS} == {(100, 10.0), (100, 100.0), (300, 10.0), (300, 100.0)}


def test_every_statement_needs_runs_and_says_which():
    st = S.Study(pathlib.Path("nowhere"), TINY, {})
    items, skipped = S.statements(st)
    assert items == [] and len(skipped) == len(S.CHECKS)
    assert all("(needs " in line for line in skipped)


def test_statement_rows_carry_the_json_fields():
    s = S.Statement("Sec. 4.1.4", "density after sintering", "≈ 0.92", "0.915", True, "±0.015")
    row = jsonable(S.asdict(s))
    assert {"statement", "paper", "ours", "holds"} <= set(row) and row["holds"] is True
    table = S._statements_table([s])
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
