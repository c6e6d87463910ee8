"""The conductance laws (fem_neck.law) and the fit (fem_neck.fit): limits, reference values, the fit machinery."""

import csv
import json
import pathlib
import subprocess
import sys

import numpy as np
import pytest

from fem_neck import fit, law
from fem_neck.cli import main
from fem_neck.geometry import neck_geometry, overlap_for_neck

from verification.cases import SEC6, SEMISPHERE

ROOT = pathlib.Path(__file__).resolve().parents[1]
REFERENCE = [(row.a_over_r, row.K_over_Kcyl) for row in SEMISPHERE]  # independent hp-FE, 12 digits


@pytest.fixture(scope="module")
def default():
    return law.ConductanceLaw.default()


def test_small_neck_limit_is_the_isothermal_disk(default):
    # K -> 4 kappa a (disk on a half-space, verification.cases.CONSTRICTION_LIMIT), i.e. K/K_cyl -> (4/pi) a/r
    x = np.array([1e-9, 1e-7, 1e-5])
    ratio = default.k_over_kcyl(x) / (4 / np.pi * x)
    assert ratio == pytest.approx(1.0, abs=2e-4)
    assert np.all(np.diff(np.abs(ratio - 1.0)) > 0)  # approaches 1 as x -> 0
    assert default.k_over_kcyl(0.0) == 0.0
    assert law.half_conductance(394.0, 1e-3, 1e-9, default) == pytest.approx(4 * 394.0 * 1e-9, rel=2e-5)


def test_full_neck_is_a_cylinder_of_length_two_thirds_r(default):
    # a = r: the half body is a cylinder of radius r and length h_n/2 = 2r/3 -> K/K_cyl = 3/2 for any parameters
    assert default.k_over_kcyl(1.0) == pytest.approx(1.5, rel=1e-14)
    assert law.ConductanceLaw(1.0, 2.0, -3.0, 0.5).k_over_kcyl(1.0) == pytest.approx(1.5, rel=1e-14)


@pytest.mark.parametrize("x, k", REFERENCE)
def test_default_law_matches_reference_values(default, x, k):
    assert default.k_over_kcyl(x) == pytest.approx(k, rel=5e-3)  # the law's target (0.5 %)
    assert default.k_over_kcyl(x) == pytest.approx(k, rel=5e-4)  # what the fit actually achieves


def test_law_is_monotone_and_above_the_linear_law_at_both_ends(default):
    x = np.linspace(0.0, 1.0, 20001)
    assert np.all(np.diff(default.k_over_kcyl(x)) > 0)
    assert default.k_over_kcyl(0.01) > law.ROJEK.k_over_kcyl(0.01) * 1.15  # the linear law misses small necks
    assert default.k_over_kcyl(0.95) > law.ROJEK.k_over_kcyl(0.95) * 1.2  # and the bend above a/r = 0.7


def test_neck_resistance_is_the_half_neck_cylinder():
    x = np.array([0.01, 0.2, 0.6, 0.9, 0.999])
    g = neck_geometry(1.0, 1.0, overlap_for_neck(1.0, 1.0, x))
    assert law.neck_resistance(x) == pytest.approx(g.h_n / 2 / x**2, rel=1e-9)
    assert law.neck_resistance(1e-12) == pytest.approx(0.25, rel=1e-9)
    assert law.neck_resistance(1.0) == pytest.approx(2 / 3, rel=1e-14)


def test_fit_json_table_matches_the_closed_form(default):
    data = json.loads(law.DEFAULT_FIT.read_text())
    table = np.array(data["law"]["table"])
    assert table.shape[0] >= 100 and table.shape[1] == 2
    assert default.k_over_kcyl(table[:, 0]) == pytest.approx(table[:, 1], rel=1e-12)
    assert data["law"]["max_rel_residual"] < 5e-3
    pts = np.array(data["points"])
    assert pts.shape[0] >= 40 and pts[:, 0].min() <= 0.001 + 1e-12 and pts[:, 0].max() >= 0.97 - 1e-12
    assert np.max(np.abs(default.k_over_kcyl(pts[:, 0]) / pts[:, 1] - 1)) < 5e-3
    assert 1.0 < data["slope"] < 1.15


def test_paper_pair_with_the_linear_law():
    # Rojek 2022, Sec. 6: r_i = 1 mm, r_j = 3 mm, a = 0.419186 mm, kappa = 394 -> 0.276035 W/K
    assert law.pair_conductance(394.0, 1e-3, 3e-3, SEC6["a"].value, law.ROJEK) == pytest.approx(SEC6["K_model"].value,
                                                                                                 rel=2e-6)
    assert law.ARGENTO_BOUVARD.slope == pytest.approx(1.112, abs=5e-4)


def test_pair_is_the_series_of_halves(default):
    a, ri, rj = 0.3e-3, 1e-3, 4e-3
    ki, kj = law.half_conductance(2.0, ri, a, default), law.half_conductance(2.0, rj, a, default)
    series = 1 / (1 / ki + 1 / kj)
    assert law.pair_conductance(2.0, ri, rj, a, default, unequal=False) == pytest.approx(series, rel=1e-14)
    corrected = series / (1 + law.UNEQUAL_C * 0.3 * np.log(4.0))
    assert law.pair_conductance(2.0, ri, rj, a, default) == pytest.approx(corrected, rel=1e-14)
    assert law.pair_conductance(2.0, rj, ri, a, default) == pytest.approx(corrected, rel=1e-14)  # symmetric
    assert law.pair_conductance(2.0, ri, ri, a, default) == pytest.approx(ki / 2, rel=1e-14)  # equal: no correction
    assert law.pair_conductance(2.0, ri, rj, a, law.ROJEK) == pytest.approx(1.064 * 2.0 * np.pi * a / 2, rel=1e-14)
    k = law.pair_conductance(1.0, np.array([1.0, 1.0]), np.array([1.0, 2.0]), np.array([0.0, 0.5]), default)
    assert k[0] == 0.0 and k[1] > 0


@pytest.mark.parametrize("call", [lambda L: L.k_over_kcyl(1.2), lambda L: L.k_over_kcyl(-0.1),
                                  lambda L: L.k_over_kcyl(np.nan), lambda L: law.half_conductance(-1, 1, 0.5, L),
                                  lambda L: law.half_conductance(1, 1e-3, 2e-3, L)])
def test_bad_input_is_a_value_error(default, call):
    with pytest.raises(ValueError, match="must be"):
        call(default)


def test_from_json_errors(tmp_path):
    with pytest.raises(ValueError, match="fit file"):
        law.ConductanceLaw.from_json(tmp_path / "missing.json")
    (tmp_path / "bad.json").write_text(json.dumps({"law": {"parameters": {"A": 1}}}))
    with pytest.raises(ValueError, match="parameters"):
        law.ConductanceLaw.from_json(tmp_path / "bad.json")


def test_fit_law_recovers_known_parameters():
    truth = law.ConductanceLaw(0.4, -0.03, 0.38, -0.07)
    x, _ = fit.sweep_points(40)
    got = fit.fit_law(x, truth.k_over_kcyl(x), A=0.4)
    assert [got.A, got.B, got.C, got.E] == pytest.approx([0.4, -0.03, 0.38, -0.07], abs=1e-9)
    assert got.max_rel_residual < 1e-12
    assert fit.fit_law(x, truth.k_over_kcyl(x)).A == law.A_LOG == pytest.approx(0.3978873577)


def test_linear_slope_and_sampling():
    x, uniform = fit.sweep_points(40)
    assert len(x) == 40 and uniform.sum() == 35 and np.all(np.diff(x) > 0)
    assert x.min() == pytest.approx(0.001) and x.max() == pytest.approx(0.97)
    assert np.allclose(np.diff(x[uniform]), 0.97 / 35)
    assert fit.linear_slope(x, 1.3 * x) == pytest.approx(1.3, rel=1e-14)
    assert fit.linear_slope([0.5, 0.8], [1.0, 100.0]) == pytest.approx(2.0)  # 0.8 > 0.7 is left out
    with pytest.raises(ValueError, match="points"):
        fit.sweep_points(3)


@pytest.mark.slow
def test_small_fit_run_writes_files_and_resumes(tmp_path):
    out = tmp_path / "fit"
    first = fit.run_fit(8, 1e-4, out, workers=2, progress=False)
    assert {p.name for p in out.iterdir()} >= {"fit.json", "fit.csv", "fit.png"}
    assert len(first["points"]) == 8 and first["unconverged"] == []
    assert 1.02 < first["slope"] < 1.12  # comparable with Rojek's 1.064 (uniform sampling, a/r <= 0.7)
    on_disk = json.loads((out / "fit.json").read_text())
    assert law.ConductanceLaw.from_json(out / "fit.json").k_over_kcyl(0.5) == pytest.approx(
        law.ConductanceLaw.from_dict(on_disk["law"]).k_over_kcyl(0.5))
    for x, k in REFERENCE:  # even an 8-point fit interpolates the reference values well
        assert law.ConductanceLaw.from_dict(on_disk["law"]).k_over_kcyl(x) == pytest.approx(k, rel=5e-3)
    assert first["reused"] == {"points": 0, "of": 8, "not_matching": 0}


def _tamper(csv_path, factor):
    """Scale every K/K_cyl in a fit.csv by ``factor``: a reused point then shows it, a recomputed one does not."""
    rows = list(csv.DictReader(csv_path.open(newline="")))
    for row in rows:
        row["K_over_Kcyl"] = repr(float(row["K_over_Kcyl"]) * factor)
    with csv_path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    return rows


@pytest.mark.slow
def test_fit_reuses_only_points_of_the_same_solver_and_tolerance(tmp_path, capsys):
    out = tmp_path / "fit"
    first = fit.run_fit(6, 1e-4, out, workers=1, progress=False, plot_png=False)
    truth = np.array(first["points"])
    _tamper(out / "fit.csv", 2.0)
    # same solver, method and tolerance: all six are reused (the tampered values come back)
    again = fit.run_fit(6, 1e-4, out, workers=1, progress=False, plot_png=False)
    assert again["reused"] == {"points": 6, "of": 6, "not_matching": 0}
    assert np.allclose(np.array(again["points"])[:, 1], 2.0 * truth[:, 1], rtol=1e-15)
    # another tolerance or method: nothing is reused, every point is solved again
    for options in ({"rtol": 1e-5}, {"method": "gmsh"}):
        _tamper(out / "fit.csv", 2.0)
        rtol = options.get("rtol", 1e-4)
        other = fit.run_fit(6, rtol, out, workers=1, progress=False, plot_png=False, method=options.get("method", "hp"))
        assert other["reused"] == {"points": 0, "of": 6, "not_matching": 6}
        assert np.allclose(np.array(other["points"])[:, 1], truth[:, 1], rtol=1e-4)
    # an older fit.csv without solver and method columns: provenance unknown, not reused
    rows = _tamper(out / "fit.csv", 1.0)
    with (out / "fit.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=[k for k in rows[0] if k not in ("solver", "method")], extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    assert fit.run_fit(6, 1e-4, out, workers=1, progress=False, plot_png=False)["reused"]["points"] == 0
    # the CLI says it on stderr, keeps stdout one JSON object, and --fresh recomputes
    _tamper(out / "fit.csv", 2.0)
    assert main(["fit", "--points", "6", "--workers", "1", "--out", str(out), "--json"]) == 0
    cap = capsys.readouterr()
    assert json.loads(cap.out)["reused"] == {"points": 6, "of": 6, "not_matching": 0}
    assert "reused 6 of 6 points from fit.csv; --fresh recomputes\n" in cap.err
    assert main(["fit", "--points", "6", "--workers", "1", "--out", str(out), "--json", "--fresh"]) == 0
    cap = capsys.readouterr()
    fresh = json.loads(cap.out)
    assert fresh["reused"]["points"] == 0 and "reused" not in cap.err
    assert np.allclose(np.array(fresh["points"])[:, 1], truth[:, 1], rtol=1e-12)


def test_cli_rejects_bad_input(capsys):
    assert main(["fit", "--points", "3"]) == 2
    assert main(["fit", "--rtol", "0.5"]) == 2
    assert "error" in capsys.readouterr().err


@pytest.mark.slow
def test_unequal_pairs_against_fe(tmp_path):
    from fem_neck.unequal import study

    res = study([1, 3], [0.5], 1e-4, tmp_path, workers=2, progress=False, paper_rtol=1e-5)
    assert {p.name for p in tmp_path.iterdir()} >= {"unequal.json", "unequal.csv", "unequal.png"}
    dev = res["max_abs_dev_per_ratio"]
    assert dev["1"]["halves"] < 5e-4  # equal pair = two semispheres: the law's own accuracy
    assert 1e-3 < dev["3"]["halves"] < 5e-3  # the series of halves over-estimates an unequal pair (upper bound) ...
    assert dev["3"]["corrected"] < 1e-3  # ... and the fitted correction removes most of it
    assert res["a_only_spread"]["0.5"] > 0.01  # eq. 43's "K depends on a only" is off by percents
    paper = res["paper_case"]  # Rojek 2022 Sec. 6: r_i = 1 mm, r_j = 3 mm, h = 0.06 mm, kappa = 394
    assert paper["a"] == pytest.approx(SEC6["a"].value, rel=2e-6)
    assert paper["K_law"] == pytest.approx(paper["K_fe"], rel=2e-3)


@pytest.mark.slow
def test_fit_command_draws_its_figure_without_importing_matplotlib(tmp_path):
    """The command's own process never imports matplotlib (its import, longer than the whole sweep, runs in the
    plotting process on the other core while this one imports the solver), and fit.png is still written."""
    out = tmp_path / "fit"
    script = ("import json, sys; from fem_neck.cli import main; "
              f"code = main(['fit', '--points', '4', '--workers', '2', '--out', {str(out)!r}, '--json']); "
              "print(json.dumps({'code': code, 'loaded': sorted(m for m in sys.modules if m.startswith("
              "('matplotlib', 'PIL')))}))")
    proc = subprocess.run([sys.executable, "-c", script], cwd=ROOT, capture_output=True, text=True, timeout=120)
    seen = json.loads(proc.stdout.splitlines()[-1])
    assert seen == {"code": 0, "loaded": []}, proc.stderr[-2000:]
    assert (out / "fit.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert len(json.loads((out / "fit.json").read_text())["points"]) == 4


_DRAW = """
import json, sys
import numpy as np
from fem_neck import fit, law
if sys.argv[1] == "light":
    fit.import_plotting()
else:
    import matplotlib.backends.backend_agg, matplotlib.figure
from matplotlib.artist import Artist
from matplotlib.lines import Line2D
saved = json.loads(law.DEFAULT_FIT.read_text())
points = [fit.FitPoint(x, k, 1e-6, 500, 0.01, 1e-4, True) for x, k in saved["points"]]
fit.plot(points, saved["slope"], law.ConductanceLaw.default(), sys.argv[2])
method = Artist.__dict__["_update_set_signature_and_docstring"].__func__
print(json.dumps({"mplot3d": "mpl_toolkits.mplot3d" in sys.modules, "set_doc": Line2D.set.__doc__ is not None,
                  "restored": method.__qualname__ == "Artist._update_set_signature_and_docstring"}))
"""


@pytest.mark.slow
def test_the_light_plotting_import_draws_the_same_figure(tmp_path):
    """fit.png drawn after :func:`fem_neck.fit.import_plotting` in a fresh process (matplotlib's set() signatures and
    3D axes left out) is the figure of a plain import to the pixel, and the import leaves matplotlib as it found it."""
    from PIL import Image

    seen = {}
    for kind in ("light", "plain"):
        proc = subprocess.run([sys.executable, "-c", _DRAW, kind, str(tmp_path / f"{kind}.png")], cwd=ROOT,
                              capture_output=True, text=True, timeout=120)
        assert proc.returncode == 0, proc.stderr[-2000:]
        assert "Warning" not in proc.stderr, proc.stderr[-2000:]
        seen[kind] = json.loads(proc.stdout.splitlines()[-1])
    assert seen["light"] == {"mplot3d": False, "set_doc": False, "restored": True}  # both parts were left out ...
    assert seen["plain"] == {"mplot3d": True, "set_doc": True, "restored": True}  # ... which a plain import loads
    light, plain = (np.asarray(Image.open(tmp_path / f"{kind}.png")) for kind in ("light", "plain"))
    assert light.shape == plain.shape == (936, 832, 4)
    assert np.array_equal(light, plain)


@pytest.mark.slow
def test_a_figure_that_cannot_be_written_fails_the_fit(tmp_path):
    out = tmp_path / "fit"
    (out / "fit.png").mkdir(parents=True)  # savefig in the plotting process fails
    with pytest.raises(IsADirectoryError):
        fit.run_fit(4, 1e-4, out, workers=1, progress=False)
    assert (out / "fit.json").exists()  # the numbers are written before the figure is waited for


def test_log_axis_labels_are_decades_in_superscript():
    labels = [fit._decade_label(v) for v in (1e-3, 2e-3, 0.01, 0.5, 1.0, 10.0, 0.0)]
    assert labels == ["10\u207b\u00b3", "", "10\u207b\u00b2", "", "10\u2070", "10\u00b9", ""]
