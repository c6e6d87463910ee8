"""The full-range law of the union's half body (fem_neck.law with neck = "union", fem_neck/data/fit_union.json,
``python -m fem_neck fit --neck union``): its limits, against FE it was not fitted to, and the fit file's neck."""

import csv
import json

import numpy as np
import pytest

from fem_neck import fit, law
from fem_neck.cli import main
from fem_neck.conduction import semisphere_conductance


@pytest.fixture(scope="module")
def union():
    return law.ConductanceLaw.default(neck="union")


def test_default_is_the_shipped_union_fit_and_the_cylinder_default_is_unchanged(union):
    assert union.neck == "union" and union.A == law.A_LOG_UNION == pytest.approx(1.0 / np.pi, rel=1e-15)
    assert union == law.ConductanceLaw.from_json(law.DEFAULT_FIT_UNION)
    cylinder = law.ConductanceLaw.default()
    assert cylinder is law.ConductanceLaw.default(neck="cylinder") and cylinder.neck == "cylinder"
    assert cylinder == law.ConductanceLaw.from_json(law.DEFAULT_FIT) and cylinder.A == law.A_LOG
    with pytest.raises(ValueError, match="neck = 'lens': must be one of cylinder, union"):
        law.ConductanceLaw.default(neck="lens")


def test_small_neck_limit_with_the_balls_log(union):
    # K -> 4 kappa a, and P_u = 1 + x ln(1/x)/pi + O(x): the ball's Neumann log alone
    x = np.array([1e-9, 1e-7, 1e-5, 1e-3])
    ratio = union.k_over_kcyl(x) / (4 / np.pi * x)
    assert np.all(np.diff(np.abs(ratio - 1.0)) > 0) and abs(ratio[0] - 1.0) < 1e-7
    p = 1.0 / ratio
    assert np.all(np.abs(p - 1.0 - x * np.log(1.0 / x) / np.pi) < 0.01 * x)  # the rest is O(x)
    assert np.all(np.abs(p - 1.0 - law.A_LOG * x * np.log(1.0 / x)) > 0.07 * x * np.log(1.0 / x))  # not 5/(4 pi)
    assert union.k_over_kcyl(0.0) == 0.0


def test_thin_disk_limit(union):
    """At x = 1 the half body has no thickness: f = inf, and a union half in series is no resistance. Near it
    1/f -> (pi/4)(1 + B + C + E) s, s = sqrt(1 - x^2), within 1.2 % of the exact 1-D slab, 1/f -> s."""
    assert union.k_over_kcyl(1.0) == np.inf
    assert law.half_conductance(2.0, 1e-3, 1e-3, union) == np.inf
    k_other = law.half_conductance(2.0, 2e-3, 1e-3, union)
    assert law.pair_conductance(2.0, 1e-3, 2e-3, 1e-3, union, unequal=False) == pytest.approx(k_other, rel=1e-15)
    assert np.isinf(law.pair_conductance(2.0, 1e-3, 1e-3, 1e-3, union))
    s = np.array([1e-6, 1e-4])
    slope = 1.0 / (union.k_over_kcyl(np.sqrt(1.0 - s * s)) * s)
    assert slope == pytest.approx(np.pi / 4 * (1 + union.B + union.C + union.E), rel=1e-3)
    assert abs(slope[0] - 1.0) < 0.012


# a/r between and beyond the sweep's points (0.97 k / 35), solved here to 1e-6: the law's error as the fit file and
# the guide state it (within the fit range: its max_rel_residual < 1e-3; beyond 0.97, within 0.6 % up to 0.995)
UNSEEN = [0.0005, 0.004, 0.015, 0.07, 0.2, 0.35, 0.5, 0.65, 0.8, 0.9, 0.955]
BEYOND = [0.98, 0.99, 0.995]


@pytest.mark.parametrize("x", UNSEEN + BEYOND)
def test_law_against_fe_it_was_not_fitted_to(union, x):
    fe = semisphere_conductance(x, rtol=1e-6, neck="union")
    assert fe.converged
    error = abs(union.k_over_kcyl(x) / fe.K_over_Kcyl - 1.0)
    assert error < (1e-3 if x <= union.fit_range[1] else 6e-3)
    if x <= union.fit_range[1]:
        assert error < 1.2 * union.max_rel_residual + 1e-5


def test_shipped_union_fit_file(union):
    data = json.loads(law.DEFAULT_FIT_UNION.read_text())
    assert data["neck"] == "union" and data["solver"] == fit.SOLVER and data["unconverged"] == []
    assert data["law"]["form"] == law.FORM_UNION == union.form
    table = np.array(data["law"]["table"])
    assert union.k_over_kcyl(table[:, 0]) == pytest.approx(table[:, 1], rel=1e-12)
    pts = np.array(data["points"])
    assert pts.shape[0] >= 40 and pts[:, 0].min() <= 0.001 + 1e-12 and pts[:, 0].max() >= 0.97 - 1e-12
    misfit = np.abs(union.k_over_kcyl(pts[:, 0]) / pts[:, 1] - 1)
    assert misfit.max() == pytest.approx(union.max_rel_residual, rel=1e-9) and misfit.max() < 1e-3
    assert max(data["error_estimates"]) <= data["rtol"]


def test_fit_file_records_its_neck_and_a_law_refuses_the_other(tmp_path, union):
    cylinder = law.ConductanceLaw.default()
    assert cylinder.require_neck("cylinder") is cylinder and union.require_neck("union") is union
    with pytest.raises(ValueError, match=r"fit file = '.*fit\.json': fitted for neck = 'cylinder', cannot be used for "
                                         r"neck = 'union' \(fit one with: python -m fem_neck fit --neck union\)"):
        cylinder.require_neck("union")
    with pytest.raises(ValueError, match="fitted for neck = 'union', cannot be used for neck = 'cylinder'"):
        union.require_neck("cylinder")
    # a file without a neck was written before the union existed: a neck-cylinder fit
    data = json.loads(law.DEFAULT_FIT_UNION.read_text())
    del data["neck"]
    (tmp_path / "old.json").write_text(json.dumps(data))
    assert law.ConductanceLaw.from_json(tmp_path / "old.json").neck == "cylinder"
    data["neck"] = "lens"
    (tmp_path / "bad.json").write_text(json.dumps(data))
    with pytest.raises(ValueError, match="fit file = .*bad.json.*neck = 'lens' must be one of cylinder, union"):
        law.ConductanceLaw.from_json(tmp_path / "bad.json")
    with pytest.raises(ValueError, match="neck"):
        law.ConductanceLaw(1.0, 0.0, 0.0, 0.0, neck="lens")


def test_fit_law_for_the_union_recovers_known_parameters():
    truth = law.ConductanceLaw(law.A_LOG_UNION, 0.01, 0.3, -0.05, neck="union")
    x, _ = fit.sweep_points(40)
    got = fit.fit_law(x, truth.k_over_kcyl(x), neck="union")
    assert got.neck == "union" and got.A == law.A_LOG_UNION
    assert [got.B, got.C, got.E] == pytest.approx([0.01, 0.3, -0.05], abs=1e-9)
    # the cylinder's lambda(x) is not in the union's law: a cylinder fit of the same points is far off
    assert fit.fit_law(x, truth.k_over_kcyl(x)).max_rel_residual > 0.01


@pytest.mark.slow
def test_small_union_fit_run_and_its_csv(tmp_path, capsys):
    out = tmp_path / "fit"
    first = fit.run_fit(6, 1e-4, out, workers=1, progress=False, plot_png=False, neck="union")
    on_disk = json.loads((out / "fit.json").read_text())
    assert on_disk["neck"] == "union" and law.ConductanceLaw.from_json(out / "fit.json").neck == "union"
    rows = list(csv.DictReader((out / "fit.csv").open(newline="")))
    assert [r["neck"] for r in rows] == ["union"] * 6
    for x, k in first["points"]:  # the union conducts more than the semisphere with its neck cylinder
        assert k > semisphere_conductance(x, rtol=1e-4).K_over_Kcyl
    # the cylinder's points are not the union's: a cylinder run in the same folder solves all six again
    cyl = fit.run_fit(6, 1e-4, out, workers=1, progress=False, plot_png=False)
    assert cyl["reused"] == {"points": 0, "of": 6, "not_matching": 6} and cyl["neck"] == "cylinder"
    assert main(["fit", "--points", "6", "--workers", "1", "--out", str(out), "--json", "--neck", "union"]) == 0
    cap = capsys.readouterr()
    assert json.loads(cap.out)["reused"] == {"points": 0, "of": 6, "not_matching": 6}
    assert "another solver, method, neck or tolerance were not reused (this run: hp, union, rtol 0.0001)" in cap.err
    with pytest.raises(SystemExit) as exc:  # argparse's one-line error
        main(["fit", "--neck", "lens"])
    assert exc.value.code == 2 and "invalid choice: 'lens'" in capsys.readouterr().err


@pytest.mark.slow
def test_union_sweep_reproduces_the_shipped_fit(tmp_path, union):
    """``python -m fem_neck fit --neck union``'s sweep, solved again: the shipped parameters and residual."""
    result = fit.run_fit(40, 1e-4, None, workers=2, progress=False, neck="union")
    again = law.ConductanceLaw.from_dict(result["law"], neck="union")
    assert [again.B, again.C, again.E] == pytest.approx([union.B, union.C, union.E], rel=1e-6)
    assert result["law"]["max_rel_residual"] == pytest.approx(union.max_rel_residual, rel=1e-4)
