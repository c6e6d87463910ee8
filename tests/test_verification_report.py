"""verification.report: section contract, report files written per section, failures, missed targets and absent
modules, and image links that resolve from the report's folder, each figure once."""

import importlib.machinery
import json
import math
import pathlib
import sys
import types

import numpy as np
import pytest

from verification import report as rp


def _record(name, summary, status=rp.OK, error=""):
    return rp.Section(name, status, f"Title {name}", markdown=f"text of {name}", summary=summary, error=error)


def assert_report_links_resolve(out):
    """Every image link of ``out/report.md`` resolves from that folder, and every figure of run.json is linked
    exactly once."""
    md = (out / "report.md").read_text()
    links = rp.image_links(md)
    assert len(links) == len(set(links)), [k for k in links if links.count(k) > 1]
    for link in links:
        assert (out / link).is_file(), link
    run = json.loads((out / "run.json").read_text())
    figures = [f for sec in run["sections"].values() for f in sec["figures"]]
    assert sorted(figures) == sorted(links)


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
    assert bad.status == rp.ERROR and bad.error == "RuntimeError: solver diverged"
    assert "Traceback" in (tmp_path / "fake_bad" / "error.txt").read_text()
    assert good.status == rp.OK and rep.failed == [bad]
    md = (tmp_path / "report.md").read_text()
    assert "![f](fake_good/f.png)" in md  # figure linked relative to report.md
    assert json.loads((tmp_path / "summary.json").read_text()) == {"good.k": 0.5}
    assert_report_links_resolve(tmp_path)


def test_links_of_a_section_are_rebased_and_each_figure_shown_once(monkeypatch, tmp_path):
    """A section links its figures relative to its own folder (and returns them as paths relative to the working
    directory): report.md links each once, relative to itself."""
    def run(out_dir, quick=False):
        for stem in ("a", "b"):
            (out_dir / f"{stem}.png").write_bytes(b"png")
        rel = out_dir.resolve().relative_to(pathlib.Path.cwd().resolve())
        return {"title": "Linked", "markdown": "see ![a](./a.png)", "summary": {},
                "figures": [rel / "a.png", rel / "b.png", out_dir / "b.png"]}

    mod = types.ModuleType("verification.fake_linked")
    mod.__spec__ = importlib.machinery.ModuleSpec(mod.__name__, None)
    mod.run = run
    monkeypatch.setitem(sys.modules, mod.__name__, mod)
    monkeypatch.chdir(tmp_path)
    rep = rp.run_sections(["fake_linked"], pathlib.Path("out"), "all", progress=False)
    assert rep.sections[0].status == rp.OK
    md = (tmp_path / "out" / "report.md").read_text()
    assert rp.image_links(md) == ["fake_linked/a.png", "fake_linked/b.png"]
    assert_report_links_resolve(tmp_path / "out")


def test_missed_target_fails_the_section(tmp_path):
    rep = rp.Report(tmp_path, "x", quick=False, program="python -m benchmarks")
    sec = rep.section("s", "Timed")
    with sec.running():
        assert sec.target("fast enough", 0.5, 1.0, "s") == rp.PASS
        assert sec.target("not run here", None, 1.0) == rp.NOT_MEASURED
        assert sec.target("too slow", 2.0, 1.0, "s") == rp.FAIL
    assert sec.status == rp.FAIL and "too slow" in sec.error and rep.failed == [sec]
    md = (tmp_path / "report.md").read_text()
    assert "| s | fail: target missed: too slow |" not in md  # the status table names the section by title
    assert "| [Timed](#timed) | fail: target missed: too slow |" in md
    run = json.loads((tmp_path / "run.json").read_text())
    assert [t["verdict"] for t in run["sections"]["s"]["targets"]] == ["pass", "not measured", "fail"]


def test_md_table():
    t = rp.md_table(["a", "b"], [(1.23456789, None), ("x", 2)], fmt="{:.3g}")
    assert t.splitlines() == ["| a | b |", "|---|---|", "| 1.23 | — |", "| x | 2 |"]
