"""The contact law put together from its sub-models at compile time (dem.laws.contact.binding): each composition is a
numba type of its own, so a loop compiled for one is never the loop of another (the composition is in the signature,
the key of numba's cache, also where a law's line changes and its name does not); the sub-models' kernels are inlined
(no call is left in the compiled code); a combination that is only a registry line (hertz_luding: Hertz's normal
force, Tsuji's damping, Luding's tangential spring) gives the force its sub-models' formulas give, written out here."""

import math

import numba
import numpy as np
import pytest
from numba import njit

from dem.laws.contact import CONTACT_LAWS, Composition, law_module
from dem.laws.contact.binding import ContactLaw, spins
from test_hertz_mindlin import law_pair

HERTZ_LUDING = dict(youngs_modulus=1e9, poisson_ratio=0.3, restitution=0.6, kt_ratio=0.4, gamma_t=0.002, mu=0.4,
                    mu_wall=0.3, brittle_sliding=False, density=2500.0)


@njit(cache=True)
def _spins(law):
    return spins(law)


def test_each_law_is_a_type_of_its_own():
    types = {name: numba.typeof(ContactLaw(name)) for name in CONTACT_LAWS}
    assert len(set(types.values())) == len(CONTACT_LAWS)
    assert numba.typeof(ContactLaw("luding")) == types["luding"]


def test_an_unknown_law_is_named_in_one_line():
    with pytest.raises(ValueError, match="must be one of luding, zohdi"):
        ContactLaw("hooke")


def test_a_function_compiled_for_two_laws_has_two_signatures_and_each_law_its_constants():
    assert _spins(ContactLaw("luding")) is True
    assert _spins(ContactLaw("zohdi")) is law_module("zohdi").SPINS is False
    assert len(_spins.signatures) == 2


def test_a_changed_composition_under_the_same_name_is_another_type_and_compiles_its_own_loop(monkeypatch):
    before = ContactLaw("hertz_luding")
    assert _spins(before) is True
    monkeypatch.setitem(CONTACT_LAWS, "hertz_luding", Composition(normal="zohdi", tangential="zohdi",
                                                                  state="temperature"))
    after = ContactLaw("hertz_luding")
    assert numba.typeof(after) != numba.typeof(before)  # the cache's key differs: it cannot hand over the old loop
    assert _spins(after) is False and _spins(before) is True


def test_a_sub_model_that_does_not_fit_is_refused_naming_both():
    from dem.laws.contact.composition import Law

    with pytest.raises(ValueError, match="adhesion 'jkr' applies to the normal sub-models hertz, not 'luding'"):
        Law("x", Composition(normal="luding", tangential="luding", state="sintering", adhesion="jkr"))
    with pytest.raises(ValueError, match="damping 'tsuji' reads the particle state 'mass'"):
        Law("x", Composition(normal="zohdi", tangential="zohdi", state="temperature", damping="tsuji"))


@pytest.mark.slow
def test_the_composed_kernels_are_inlined_no_call_is_dispatched_at_run_time():
    material = law_module("hertz_luding").Material(**HERTZ_LUDING)
    state = np.array([[1e-5], [2e-5]])
    law_pair("hertz_luding", material.params(), np.zeros((1, 3)), np.zeros((1, 3)), state, 1e-7, (1.0, 0.0, 0.0),
             (0.0, 0.1, 0.0), 0.0, 1e-3, 1e-3, 1e-7)
    from test_hertz_mindlin import _bound_pair

    # hertz_luding's compilation (other tests compile other laws first; their types name their material modules)
    llvm = next(text for signature, text in _bound_pair.inspect_llvm().items() if signature[0].law == "hertz_luding")
    body = llvm[llvm.index("define"):]
    calls = [line for line in body.splitlines() if " call " in line and "@llvm." not in line and "NRT_" not in line]
    assert not any("dem" in line for line in calls), calls


def _hertz_luding_by_hand(m, r1, r2, m1, m2, delta, vn, vr, n, xi, dt):
    """Hertz (Johnson 1985, Sec. 4.2), Tsuji's damping (Antypov & Elliott 2011) and Luding 2005's tangential spring
    (eqs. 14-23), written out: ``(f_n, f_t, xi_new)``."""
    r_eff, m_eff = r1 * r2 / (r1 + r2), m1 * m2 / (m1 + m2)
    e_star = m["youngs_modulus"] / (2 * (1 - m["poisson_ratio"] ** 2))
    a = math.sqrt(r_eff * delta)
    k_n = 4 / 3 * e_star * a
    log_e = math.log(m["restitution"])
    alpha = math.sqrt(5) * -log_e / math.sqrt(math.pi**2 + log_e**2)
    f_n = k_n * delta + alpha * math.sqrt(m_eff * k_n) * -vn
    n, vr, xi = np.array(n), np.array(vr), np.array(xi)
    vt = vr - vn * n
    xi = xi - xi.dot(n) * n
    k_t = m["kt_ratio"] * k_n
    f_t = -k_t * xi - m["gamma_t"] * vt
    limit = m["mu"] * f_n
    if np.linalg.norm(f_t) <= limit:
        return f_n, f_t, xi + vt * dt
    f_t = limit * f_t / np.linalg.norm(f_t)
    return f_n, f_t, -(f_t + m["gamma_t"] * vt) / k_t


@pytest.mark.slow  # compiles a composed law's kernels (7 s in a fresh clone)
@pytest.mark.parametrize("xi0", [(0.0, 1e-9, -2e-9), (0.0, 1e-6, 0.0)], ids=["sticking", "sliding"])
def test_hertz_luding_a_registry_line_gives_its_sub_models_formulas(xi0):
    law = law_module("hertz_luding")
    assert law.PAIR_HISTORY == ("xi_x", "xi_y", "xi_z") and law.PARTICLE_STATE == ("mass",)
    material = law.Material(**HERTZ_LUDING)
    r1, r2, m1, m2, delta, dt = 1e-3, 2e-3, 1e-5, 3e-5, 2e-7, 1e-7
    n = (0.6, 0.0, 0.8)
    vr = (0.01, 0.05, -0.02)
    vn = float(np.dot(vr, n))
    hist_in, hist = np.array([xi0]), np.zeros((1, 3))
    got = law_pair("hertz_luding", material.params(), hist_in, hist, np.array([[m1], [m2]]), delta, n, vr, vn, r1, r2,
                   dt)
    f_n, f_t, xi = _hertz_luding_by_hand(HERTZ_LUDING, r1, r2, m1, m2, delta, vn, vr, n, xi0, dt)
    assert got[0] == pytest.approx(f_n, rel=1e-13)
    assert np.allclose(got[1:], f_t, rtol=1e-12, atol=0) and np.allclose(hist[0], xi, rtol=1e-12, atol=1e-25)
    sliding = np.linalg.norm(f_t) == pytest.approx(HERTZ_LUDING["mu"] * f_n, rel=1e-12)
    assert sliding == (xi0[1] == 1e-6)  # each case is the branch it names


def test_a_generated_material_checks_its_fields_naming_them():
    cls = law_module("hertz_luding").Material
    with pytest.raises(ValueError, match="contact.kt_ratio"):
        cls(**{**HERTZ_LUDING, "kt_ratio": -1.0})
    with pytest.raises(ValueError, match=r"contact.poisson_ratio = 0.5: must be in \(-1, 0.5\)"):
        cls(**{**HERTZ_LUDING, "poisson_ratio": 0.5})
    with pytest.raises(ValueError, match=r"contact.restitution = 1.5: must be in \(0, 1\]"):
        cls(**{**HERTZ_LUDING, "restitution": 1.5})
