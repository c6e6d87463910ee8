"""Runs that say where they stand: the particles whose necks meet, under every neck reading (dem.geometry.necks), and
the FE evidence of the law there (dem.laws.verified_range)."""

import math

import numpy as np
import pytest

from dem import make_scene, run
from dem.geometry.periodic import PeriodicBox
from dem.laws.conductance import ConductanceSpec
from fem_neck.lattice import BASIS, EDGE_OVER_SPACING, max_h_over_r


def lattice(kind: str, d: float, neck: str = "newton", law: str = "rojek", nodes: str = "particles"):
    """A periodic cell of the cubic lattice ``kind`` of 1 mm spheres whose neighbours are ``d`` mm apart, 1 K drop
    per period along z, on the network's ``nodes``."""
    edge = EDGE_OVER_SPACING[kind] * d * 1e-3
    x = np.asarray(BASIS[kind]) * edge + 0.1 * edge
    box = PeriodicBox(np.full(3, edge), drop=[0.0, 0.0, 1.0])
    return make_scene(x, np.full(len(x), 1e-3), np.zeros(len(x)), box=box, mode="steady",
                      conductance=ConductanceSpec(law=law, neck=neck, nodes=nodes))


@pytest.mark.parametrize("kind", ["sc", "fcc"])
def test_pair_necks_meet_beyond_the_lattice_limit_and_the_run_says_so(kind):
    limit = max_h_over_r(kind)
    apart = run(lattice(kind, 2.0 - 0.98 * limit)).summary
    assert apart["particles_necks_meeting"] == 0 and apart["law_in_verified_range"] is True
    assert "warnings" not in apart and apart["neck_readings"] == {"newton": apart["bonds"]}
    met = run(lattice(kind, 2.0 - 1.02 * limit)).summary
    assert met["particles_necks_meeting"] == met["particles"] and met["law_in_verified_range"] is False
    assert len(met["warnings"]) == 1 and "pair-neck reading 'newton' has no answer" in met["warnings"][0]


def test_union_reading_runs_where_the_pair_necks_have_no_answer():
    """FCC at h/r = 0.4: the volume-conserving neck is past its range for equal spheres (2r/3 is, but the necks met
    long before); the union reads it, with its circles a^2 = r^2 - (d/2)^2, and says its necks meet."""
    scene = lattice("fcc", 1.6, neck="union")
    result = run(scene)
    s = result.summary
    assert s["neck_readings"] == {"union": s["bonds"]} and s["particles_necks_meeting"] == s["particles"]
    assert s["warnings"] == ["law 'rojek' was not compared with FE on union necks (python -m verification "
                             "densification compares shared-body, shared-body (neck nodes), fit, "
                             "argento-bouvard, shared-body (neck nodes, trefftz element)): no error bound"]
    assert s["law_in_verified_range"] is False
    a = result.engine.bonds.a
    assert np.allclose(a, math.sqrt(1.0 - 0.8**2) * 1e-3, rtol=1e-12)
    assert result.engine.particle_fields()["necks_meeting"].tolist() == [1] * s["particles"]


def test_the_plain_lens_law_reports_the_count_without_a_verdict():
    s = run(lattice("fcc", 1.6, law="zohdi")).summary
    assert s["particles_necks_meeting"] == s["particles"]
    assert "law_in_verified_range" not in s and "warnings" not in s


def test_union_necks_take_the_union_half_body_law_and_refuse_the_cylinders():
    """With neck = "union" the fit laws read the union's half body (fem_neck/data/fit_union.json): a pair's bond is
    its two halves in series, each kappa pi r f_u(a/r); a fit file of the neck cylinder is refused, naming it."""
    from fem_neck import law as fem_law
    from fem_neck.geometry.union import lens

    r_i, r_j, d, kappa = 1e-3, 0.8e-3, 1.6e-3, 394.0
    x = np.array([[0.0, 0.0, 0.0], [d, 0.0, 0.0]])
    for name in ("fit", "shared-body"):
        scene = make_scene(x, [r_i, r_j], [1.0, 0.0], fixed=[True, True], mode="steady",
                           conductance=ConductanceSpec(law=name, neck="union"))
        K = run(scene).engine.K_pairs
        a = float(lens(r_i, r_j, d).a)
        union = fem_law.ConductanceLaw.default(neck="union")
        halves = [kappa * np.pi * r * union.k_over_kcyl(a / r) for r in (r_i, r_j)]
        assert K[0] == pytest.approx(1.0 / (1.0 / halves[0] + 1.0 / halves[1]), rel=1e-13), name
    with pytest.raises(ValueError, match=r"fit file = .*fit\.json'?: fitted for neck = 'cylinder', cannot be used "
                                         r"for neck = 'union'"):
        ConductanceSpec(law="fit", neck="union", fit_file=str(fem_law.DEFAULT_FIT))


@pytest.mark.parametrize("h, stands", [(0.05, "verified"), (0.3, "wide"), (0.6, "meeting")])
def test_a_union_run_reports_the_fe_evidence_of_its_range(h, stands):
    """SC on union necks with the shared-body law: necks of a/r 0.22 are verified (within 1 %, no warning), of 0.53
    are wide (apart), and at h/r = 0.6 the six necks of every sphere meet (cones of 45.6 degrees, 90 degrees apart):
    each range names its interval of EVIDENCE."""
    s = run(lattice("sc", 2.0 - h, neck="union", law="shared-body")).summary
    assert_stands(s, stands, "shared-body")


def assert_stands(s: dict, stands: str, name: str) -> None:
    """The summary ``s`` of a union SC run whose every particle ``stands`` verified, wide or meeting reports so, with
    the interval of ``EVIDENCE[name]`` for that range and one warning naming it outside the verified range."""
    from dem.laws.verified_range import EVIDENCE, percent_range

    evidence = EVIDENCE[name]
    n = s["particles"]
    assert (s["particles_necks_wide"], s["particles_necks_meeting"]) == {"verified": (0, 0), "wide": (n, 0),
                                                                         "meeting": (0, n)}[stands]
    assert s["law_in_verified_range"] is (stands == "verified")
    interval = {"verified": (-0.01, 0.01), "wide": evidence.apart, "meeting": evidence.meeting}[stands]
    assert s["law_error_range"] == list(interval)
    if stands == "verified":
        assert "warnings" not in s
    else:
        assert len(s["warnings"]) == 1 and f"law '{name}' at {percent_range(interval)} of k_eff" in s["warnings"][0]


@pytest.mark.parametrize("h, stands", [(0.2, "verified"), (0.3, "wide"), (0.6, "meeting")])
def test_a_neck_node_run_reports_the_evidence_of_the_neck_node_solve(h, stands):
    """The same SC cells with a node per neck: the summary's range, interval and warning are the neck-node solve's
    (EVIDENCE["shared-body (neck nodes)"]), not the one-node law's -- at h/r = 0.2 (a/r 0.436) the neck nodes are
    verified where the one-node law's necks are wide."""
    from dem.laws.verified_range import evidence_name

    s = run(lattice("sc", 2.0 - h, neck="union", law="shared-body", nodes="necks")).summary
    one = run(lattice("sc", 2.0 - h, neck="union", law="shared-body")).summary
    assert s["nodes"] == "necks" and s["effective_conductivity"] == pytest.approx(one["effective_conductivity"],
                                                                                  rel=1e-9)  # SC: the same k_eff
    assert_stands(s, stands, evidence_name("shared-body", "necks"))
    if stands == "verified":
        assert one["particles_necks_wide"] == s["particles"] and one["law_in_verified_range"] is False
    else:
        assert s["law_error_range"] != one["law_error_range"]


def test_every_network_of_the_densification_study_has_its_evidence():
    from dem.laws.verified_range import EVIDENCE, evidence_name
    from verification.densification import COLUMNS

    assert set(COLUMNS) == set(EVIDENCE)
    assert [evidence_name(*c) for c in COLUMNS.values()] == list(COLUMNS)
    assert evidence_name("shared-body") == "shared-body"


def test_the_account_joins_the_ranges_a_run_reached():
    from dem.laws.verified_range import EVIDENCE, neck_account

    fit = EVIDENCE["fit"]
    s = neck_account(3, 10, "union", 40, "fit", wide=5)
    assert (s["particles_necks_meeting"], s["particles_necks_wide"]) == (3, 5)
    assert s["law_error_range"] == [min(fit.apart[0], fit.meeting[0]), max(fit.apart[1], fit.meeting[1])]
    assert [w.split(":")[0] for w in s["warnings"]] == ["5 of 10 particles (50.0 %) carry a neck wider than a/r = 0 "
                                                        "(none meeting)", "3 of 10 particles (30.0 %) carry necks that meet"]
    pair = neck_account(3, 10, "newton", 40, "shared-body", wide=5)  # wide necks count only under the union reading
    assert "particles_necks_wide" not in pair and "law_error_range" not in pair and len(pair["warnings"]) == 1


def test_the_densification_study_holds_each_case_to_the_declared_evidence():
    """verification.densification fails a case whose error lies outside the interval of the range it reached."""
    from dem.laws.verified_range import EVIDENCE
    from verification.densification import outside_evidence

    ev = EVIDENCE["shared-body"]
    row = {"rel": {"shared-body": 0.009}, "widest_neck": ev.verified_width, "meeting": 0}
    assert outside_evidence(row, "shared-body") == 0.0
    row["rel"]["shared-body"] = 0.012  # verified range: +-1 %
    assert outside_evidence(row, "shared-body") == pytest.approx(0.002, abs=1e-15)
    row["widest_neck"] = ev.verified_width + 0.01  # wide: the apart interval
    row["rel"]["shared-body"] = ev.apart[1]
    assert outside_evidence(row, "shared-body") == 0.0
    row["rel"]["shared-body"] = ev.meeting[0]
    assert outside_evidence(row, "shared-body") == pytest.approx(ev.apart[0] - ev.meeting[0], abs=1e-15)
    row["meeting"] = 2
    assert outside_evidence(row, "shared-body") == 0.0


def test_one_node_evidence_takes_in_the_calibration_cells():
    """The shipped calibration of the closing pores (python -m verification closing-pores) compared the one-node
    ``shared-body`` law with the FE on lattice cells the densification study does not check: each lies inside the
    interval the evidence declares for its necks (BCC at h/r 0.27, necks apart and a/r 0.50, is +2.7 %)."""
    import json

    from dem.laws.closing_pores import CALIBRATION
    from dem.laws.verified_range import EVIDENCE
    from fem_neck.lattice import lattice_cell
    from verification.densification import standing

    evidence = EVIDENCE["shared-body"]
    for case, row in json.loads(CALIBRATION.read_text())["cells"].items():
        if "packing" in case:
            continue
        where = standing(lattice_cell(row["kind"], float(case.split("h/r=")[1]), neck="union"))
        low, high = (evidence.meeting if where["meeting"] else evidence.apart
                     if where["widest_neck"] > evidence.verified_width else (-0.01, 0.01))
        assert low <= row["rel_err"] <= high, case
