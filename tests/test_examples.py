"""Every script of ``examples/`` runs, and the number it leaves behind is right (each is copied by researchers, so
each must work as printed)."""

import math
import pathlib
import runpy

import numpy as np
import pytest

from verification.cases import SEC6, SEC43, SEMISPHERE_BY_H

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"


def run_example(name: str) -> dict:
    """The example's module namespace after running it as a script."""
    return runpy.run_path(str(EXAMPLES / f"{name}.py"), run_name="__main__")


def test_every_example_is_tested():
    tested = {name[len("test_"):] for name in globals() if name.startswith("test_") and name != "test_every_example_is_tested"}
    assert {p.stem for p in EXAMPLES.glob("*.py")} <= tested


def test_semisphere():
    ns = run_example("semisphere")
    assert ns["K_over_Kcyl"] == pytest.approx(SEMISPHERE_BY_H[0.08].K_over_Kcyl, rel=1e-6)  # rtol 1e-6 asked


def test_neck_models():
    ns = run_example("neck_models")
    assert ns["a"] == pytest.approx(SEC43["newton"].value, rel=1e-6)  # the paper's 6 digits: 0.741466 mm
    assert ns["a_coble"] == pytest.approx(SEC43["coble"].value, rel=1e-6)
    assert ns["a_first"] == pytest.approx(SEC43["first"].value, rel=1e-6)


def test_fit_law():
    ns = run_example("fit_law")
    assert ns["slope"] == pytest.approx(1.069802648, rel=1e-6)  # python -m fem_neck fit (the same 40 points)
    assert ns["law"].max_rel_residual < 5e-3  # the law's target: 0.5 % of the FE over its range
    shipped = ns["law"].default()  # fem_neck/data/fit.json, from the same sweep
    assert (ns["law"].B, ns["law"].C, ns["law"].E) == pytest.approx((shipped.B, shipped.C, shipped.E), rel=1e-6)


def test_unequal_pair():
    ns = run_example("unequal_pair")
    assert ns["K_model"] == pytest.approx(SEC6["K_model"].value, rel=2e-6)  # eq. 45 as printed in the paper
    assert ns["K_fe"] == pytest.approx(0.27916769625, rel=1e-6)  # our converged FE (hp at rtol 1e-8, README)


@pytest.mark.slow
def test_chain():
    ns = run_example("chain")
    assert ns["K_pipes"] == pytest.approx(ns["K_fe"], rel=1e-3)  # the fit law's pipes in series vs the chain's FE


def test_fit_law_in_dem():
    ns = run_example("fit_law_in_dem")
    K = ns["result"].thermal.K_pairs
    assert ns["K_chain"] == pytest.approx(1.0 / np.sum(1.0 / K), rel=1e-10)  # steady chain = pipes in series


def test_packing_conductivity():
    ns = run_example("packing_conductivity")
    assert 0.0 < ns["k_eff"] < 394.0  # below solid copper, and the seeded run's value:
    assert ns["k_eff"] == pytest.approx(219.720135, rel=1e-6)


def test_transient_pair():
    ns = run_example("transient_pair")
    assert ns["difference_error"] < 1e-3  # rtol 1e-4 of the temperature range, global error within 10 x
    assert ns["T_i"] + 3**3 * ns["T_j"] == pytest.approx(100.0, rel=1e-12)  # energy: C ~ r^3, r_j = 3 r_i


@pytest.mark.slow
def test_cluster():
    ns = run_example("cluster")
    assert ns["middle_T"] == pytest.approx(0.5, abs=1e-3)  # symmetry of the L
    assert math.isfinite(ns["K_cluster"]) and abs(ns["K_dem"] / ns["K_cluster"] - 1) < 0.1


def test_kirchhoff_current():
    ns = run_example("kirchhoff_current")
    flow = ns["flow"]
    assert flow.electrode_current[0] == pytest.approx(-flow.electrode_current[1], rel=1e-12)  # charge conserved
    assert flow.joule_heat == pytest.approx(flow.electrode_power, rel=1e-9)  # energy conserved
    assert flow.electrode_current[0] == pytest.approx(133.8, abs=0.05)  # the numbers of the guide's electrical page
    # the figure: every horizontal plane between the electrodes' particles carries the whole current down
    assert len(ns["planes"]) == 39 and ns["plane_current"] == pytest.approx(flow.electrode_current[0], rel=1e-9)


def test_the_guide_current_snippet_runs_as_printed():
    page = (EXAMPLES.parent / "docs" / "guide" / "dem" / "electrical.md").read_text()
    block = page.split("`examples/kirchhoff_current.py`):\n\n```python\n", 1)[1].split("```", 1)[0]
    *code, shown = block.strip().split("\n")
    ns: dict = {}
    exec("\n".join(code), ns)  # noqa: S102 -- the guide's snippet, pasted as a user would
    current, heat, power = eval(shown.split("#")[0], ns)  # noqa: S307
    assert "[133.8, -133.8] A, 0.1338 W, 0.1338 W" in shown
    assert (round(current[0], 1), round(current[1], 1), round(heat, 4), round(power, 4)) == (133.8, -133.8, 0.1338,
                                                                                             0.1338)


@pytest.mark.slow
def test_moving_particles():
    ns = run_example("moving_particles")
    radius = 0.5e-3  # m, the spheres' mean radius
    # at rest: the kinetic energy below 1e-6 of the weight lifted by a radius (one 0.5 mg sphere at 1 mm/s would
    # carry twice that); it started near the weight times the 2-12 mm drop, 1e-6 J
    assert ns["kinetic"] < 1e-6 * ns["weight"] * radius
    assert ns["floor"] == pytest.approx(ns["weight"], rel=1e-6)  # frictionless side walls: the floor carries it all


@pytest.mark.slow  # pressing and sintering 60 spheres (~12 s; the docs build runs the script too)
def test_pack_sinter_measure():
    ns = run_example("pack_sinter_measure")
    assert ns["sinter"].summary["volume_fraction"] > ns["press"].summary["volume_fraction"] + 0.05  # it densified
    assert 0.0 < ns["k_pressed"] < ns["k_sintered"] < 20.0  # necks grew; below the solid's 20 W/(m K)
    assert ns["sinter"].summary["started_from"]["t"] == ns["t_pressed"]  # each stage from the one before


@pytest.mark.slow  # every contact law's study (~1 min)
def test_contact_laws():
    ns = run_example("contact_laws")
    assert all(abs(e - 0.8) < 2e-3 for e in ns["e_hertz_mindlin"])  # the material's e at every speed (dt = auto)
    assert ns["stuck"] == (True, True, False, False, False)  # JKR: the slow ones stick
    rebounds = ns["e_jkr"][2:]
    assert list(rebounds) == sorted(rebounds) and rebounds[-1] == pytest.approx(0.8, abs=0.03)  # towards e
