"""Runs that say where they stand: the particles whose necks meet, under every neck reading (dem.geometry.necks)."""

import math

import numpy as np
import pytest

from dem import make_scene, run
from dem.geometry.periodic import PeriodicBox
from dem.laws.conductance import ConductanceSpec
from fem_neck.lattice import BASIS, EDGE_OVER_SPACING, max_h_over_r


def lattice(kind: str, d: float, neck: str = "newton", law: str = "rojek"):
    """A periodic cell of the cubic lattice ``kind`` of 1 mm spheres whose neighbours are ``d`` mm apart, 1 K drop
    per period along z."""
    edge = EDGE_OVER_SPACING[kind] * d * 1e-3
    x = np.asarray(BASIS[kind]) * edge + 0.1 * edge
    box = PeriodicBox(np.full(3, edge), drop=[0.0, 0.0, 1.0])
    return make_scene(x, np.full(len(x), 1e-3), np.zeros(len(x)), box=box, mode="steady",
                      conductance=ConductanceSpec(law=law, neck=neck))


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
    assert "law 'rojek' is not verified against FE on union necks that meet" in s["warnings"][0]
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
