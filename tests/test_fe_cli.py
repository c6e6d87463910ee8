"""``python -m fem_neck semisphere | pair | chain | converge``: JSON keys, files and exit codes."""

import json

import pytest

from fem_neck import convergence
from fem_neck.cli import main
from verification.cases import SEC6, SEMISPHERE_BY_H


def _run(capsys, argv):
    rc = main(argv)
    out = capsys.readouterr().out
    return rc, json.loads(out)


@pytest.mark.slow
def test_semisphere_json(capsys, tmp_path):
    rc, out = _run(capsys, ["semisphere", "--h-over-r", "0.08", "--json", "--out", str(tmp_path)])
    assert rc == 0
    assert {"h_over_r", "a_over_r", "K_over_Kcyl", "dofs", "error_estimate", "seconds"} <= out.keys()
    assert out["K_over_Kcyl"] == pytest.approx(SEMISPHERE_BY_H[0.08].K_over_Kcyl, rel=3e-4)
    assert {p.name for p in tmp_path.iterdir()} >= {"semisphere.vtu", "semisphere.png", "semisphere.json"}
    import meshio

    vtu = meshio.read(tmp_path / "semisphere.vtu")
    temperature = vtu.point_data["temperature"]
    assert temperature.min() == pytest.approx(0.0, abs=1e-6) and temperature.max() == pytest.approx(10.0, rel=1e-6)
    assert (vtu.point_data["heat_flux"] >= 0).all()


def test_semisphere_by_neck_radius(capsys):
    rc, out = _run(capsys, ["semisphere", "--a-over-r", repr(SEMISPHERE_BY_H[0.2].a_over_r), "--rtol", "1e-5", "--json"])
    assert rc == 0 and out["h_over_r"] == pytest.approx(0.2, rel=1e-9)
    assert out["K_over_Kcyl"] == pytest.approx(SEMISPHERE_BY_H[0.2].K_over_Kcyl, rel=3e-5)


def test_pair_json_paper_case(capsys):
    """Rojek 2022 Sec. 6: a = 0.419186 mm, model K_ij = 0.276035 W/K (eqs. 43-45)."""
    rc, out = _run(capsys, ["pair", "--ri", "1e-3", "--rj", "3e-3", "--h", "0.06e-3", "--kappa", "394", "--json"])
    assert rc == 0
    assert {"a", "K_fe", "K_model", "rel_diff", "error_estimate"} <= out.keys()
    assert out["a"] == pytest.approx(SEC6["a"].value, abs=1e-9)
    assert out["K_model"] == pytest.approx(SEC6["K_model"].value, abs=1e-6)
    assert out["rel_diff"] == pytest.approx((out["K_model"] - out["K_fe"]) / out["K_fe"], rel=1e-12)


def test_chain_json(capsys):
    rc, out = _run(capsys, ["chain", "--radii", "1e-3,1e-3,1e-3", "--overlaps", "5e-5,5e-5", "--kappa", "10",
                            "--json"])
    assert rc == 0
    assert {"necks", "K_fe", "K_model", "error_estimate"} <= out.keys()
    assert len(out["necks"]) == 2 and out["necks"][0] == out["necks"][1]


@pytest.mark.parametrize("argv", [
    ["semisphere", "--h-over-r", "-0.1"],
    ["semisphere", "--h-over-r", "0.7"],
    ["semisphere", "--a-over-r", "nan"],
    ["semisphere", "--a-over-r", "0.5", "--rtol", "0"],
    ["semisphere"],
    ["pair", "--ri", "-1e-3", "--rj", "1e-3", "--h", "1e-5", "--kappa", "1"],
    ["pair", "--ri", "1e-3", "--rj", "1e-3", "--h", "1e-3", "--kappa", "1"],
    ["chain", "--radii", "1,1", "--overlaps", "0.1,0.1", "--kappa", "1"],
    ["chain", "--radii", "1,x", "--overlaps", "0.1", "--kappa", "1"],
    ["converge", "--h-over-r", "1.5"],
])
def test_bad_input_exits_2_with_one_line(capsys, argv):
    try:
        rc = main(argv + ["--json"])
    except SystemExit as exc:  # argparse usage errors
        rc = exc.code
    captured = capsys.readouterr()
    assert rc == 2 and captured.out == ""
    assert len(captured.err.strip().splitlines()) == 1


@pytest.mark.slow
def test_converge_json_and_plot(capsys, tmp_path, monkeypatch):
    monkeypatch.setattr(convergence, "GRADINGS", (0.6, 0.45, 0.3))
    monkeypatch.setattr(convergence, "UNIFORM_SIZES", (0.2, 0.1))
    rc, out = _run(capsys, ["converge", "--h-over-r", "0.08", "--json", "--out", str(tmp_path)])
    assert rc == 0
    assert {"levels", "extrapolated", "observed_order"} <= out.keys()
    for level in out["levels"]:
        assert {"order", "grading", "dofs", "h_min", "elements_across_neck", "K_over_Kcyl"} <= level.keys()
    assert out["extrapolated"] == pytest.approx(SEMISPHERE_BY_H[0.08].K_over_Kcyl, rel=1e-4)
    assert (tmp_path / "converge.png").stat().st_size > 10_000


def test_unequal_writes_nothing_without_out(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    rc, result = _run(capsys, ["unequal", "--ratios", "2", "--necks", "0.2", "--workers", "1", "--json"])
    assert rc == 0 and "out" not in result and list(tmp_path.iterdir()) == []
    rc, result = _run(capsys, ["unequal", "--ratios", "2", "--necks", "0.2", "--workers", "1", "--json", "--out", "u"])
    assert rc == 0 and result["out"] == "u" and sorted(p.name for p in (tmp_path / "u").iterdir()) == [
        "unequal.csv", "unequal.json", "unequal.png"]
