"""verification.report: section contract, report files written per section, failures and absent modules."""

import importlib.machinery
import json
import math
import sys
import types

import numpy as np
import pytest

from verification import report as rp


def _record(name, summary, status=rp.OK, error=""):
    return rp.SectionRecord(name, status, f"Title {name}", markdown=f"text of {name}", summary=summary, error=error)


def test_files_rewritten_after_each_section(tmp_path):
    rep = rp.Report(tmp_path, "paper", quick=True)
    rep.add(_record("a", {"a.x": {"rel_error": 1e-3}}))
    assert json.loads((tmp_path / "summary.json").read_text()) == {"a.x": {"rel_error": 1e-3}}
    rep.add(_record("b", {"b.y": np.float64(2e-4), "a.x": 5.0}))
    summary = json.loads((tmp_path / "summary.json").read_text())
    # a later section never overwrites an earlier comparison of the same name
    assert summary == {"a.x": {"rel_error": 1e-3}, "b.y": 2e-4, "b:a.x": 5.0}
    md = (tmp_path / "report.md").read_text()
    assert "## Title a" in md and "## Title b" in md and "text of b" in md
    run = json.loads((tmp_path / "run.json").read_text())
    assert list(run["sections"]) == ["a", "b"] and run["quick"] is True


def test_jsonable_numpy_and_non_finite():
    out = rp.jsonable({"x": np.array([1.0, np.nan]), "y": np.int64(3), "z": math.inf})
    assert out == {"x": [1.0, None], "y": 3, "z": None}
    json.dumps(out, allow_nan=False)
    with pytest.raises(TypeError):
        rp.jsonable({"bad": object()})


def test_contract_checked():
    with pytest.raises(ValueError, match="lacks figures"):
        rp.check_section_result("s", {"title": "", "markdown": "", "summary": {}})
    with pytest.raises(ValueError, match="expected dict"):
        rp.check_section_result("s", None)


def test_absent_section_is_not_available(tmp_path):
    rec = rp.run_section("no_such_section_xyz", tmp_path, quick=True)
    assert rec.status == rp.NOT_AVAILABLE and "not available" in rec.error


@pytest.fixture
def fake_sections(monkeypatch, tmp_path):
    def add(name, run):
        mod = types.ModuleType(f"verification.{name}")
        mod.__spec__ = importlib.machinery.ModuleSpec(mod.__name__, None)
        mod.run = run
        monkeypatch.setitem(sys.modules, mod.__name__, mod)

    def good(out_dir, quick=False):
        fig = out_dir / "f.png"
        fig.write_bytes(b"png")
        return {"title": "Good", "markdown": "ok", "summary": {"good.k": 0.5}, "figures": [fig]}

    def bad(out_dir, quick=False):
        raise RuntimeError("solver diverged\nsecond line")

    add("fake_good", good)
    add("fake_bad", bad)


def test_failing_section_reported_and_run_goes_on(fake_sections, tmp_path):
    rep = rp.run_sections(["fake_bad", "fake_good"], tmp_path, "all", progress=False)
    bad, good = rep.sections
    assert bad.status == rp.FAILED and bad.error == "RuntimeError: solver diverged"
    assert "Traceback" in (tmp_path / "fake_bad" / "error.txt").read_text()
    assert good.status == rp.OK and rep.failed == [bad]
    md = (tmp_path / "report.md").read_text()
    assert "![f](fake_good/f.png)" in md  # figure linked relative to report.md
    assert json.loads((tmp_path / "summary.json").read_text()) == {"good.k": 0.5}


def test_md_table():
    t = rp.md_table(["a", "b"], [(1.23456789, None), ("x", 2)], fmt="{:.3g}")
    assert t.splitlines() == ["| a | b |", "|---|---|", "| 1.23 | — |", "| x | 2 |"]
