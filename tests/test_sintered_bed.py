"""A bed of a few hundred spheres poured by LAMMPS and sintered by the Luding law until its necks meet
(verification.sintered_bed): particles are handed over to the union of spheres, k_eff stays continuous through the
hand-over and below the Wiener bound (runs only where LAMMPS is installed)."""

import numpy as np
import pytest

pytestmark = pytest.mark.slow


def test_a_small_lammps_bed_sintered_past_the_meeting_of_its_necks(tmp_path):
    """About 300 spheres in a 0.8 mm box, sintered for 10 ms at 160 degC: necks meet and particles are handed over;
    across every thermal step that hands particles over k_eff changes by at most 0.5 % on the same contacts; k_eff
    stays at or below the Wiener bound phi kappa at every output; the summary says where the law stands, and the
    run's k_eff lies within its law_error_range of the verified one (the Trefftz element on the grown spheres)."""
    from verification import sintered_bed

    if sintered_bed.lammps() is None:
        pytest.skip("LAMMPS is not installed (neither the lammps module's lmp nor lmp on the path)")
    rec = sintered_bed.measure(tmp_path, sintered_bed.QUICK_SPHERES, sintered_bed.QUICK_SIDE, t_end=0.01)
    summary = rec["summary"]
    assert rec["particles"] == 300
    assert summary["particles_necks_meeting"] > 0
    assert summary["particles_handed_over"] + summary["particles_handing_over"] > 0
    jumps = [s["jump"] for s in rec["steps"] if s["jump"] is not None]
    assert len(jumps) > 10 and np.all(np.isfinite(jumps))
    assert rec["largest_jump"] <= 5e-3
    for row in rec["rows"][1:]:
        assert 0.0 < row["k_eff"] <= row["phi"] * rec["kappa"]
    assert rec["k_eff"] <= rec["wiener"]
    assert summary["law_error_range"] == [-0.037, 0.048]  # shared-body where necks meet (dem.laws.verified_range)
    assert all(np.isfinite(v) and v > 0 for v in rec["readings"].values())
    # the verified k_eff (union of the grown spheres, neck nodes, Trefftz element): the run within its law_error_range
    v = rec["verified"]
    assert v["own"] == rec["k_eff"] and 0.0 < v["k_eff"] <= rec["wiener"]
    assert v["gap"] == v["own"] / v["k_eff"] - 1.0 and v["within"] is True
    assert 0 < v["element_particles"] <= 300
