"""The contact law bound at compile time (dem.laws.contact.binding): each law is a numba type of its own, so a loop
compiled for one law is never the loop of another (the law is in the signature, the key of numba's cache), and the
kernels reached through the binding are the law's own, to the bit."""

import math

import numba
import numpy as np
import pytest
from numba import njit

from dem.laws.contact import CONTACT_LAWS, hertz_mindlin, zohdi
from dem.laws.contact.binding import ContactLaw, pair_force, spins

MATERIAL = hertz_mindlin.HertzMindlinMaterial(youngs_modulus=1e9, poisson_ratio=0.3, restitution=0.6,
                                              tangential_damping=0.5, mu=0.4, mu_wall=0.3, density=2500.0)


@njit
def _spins(law):
    return spins(law)


@njit
def _pair_force(law, hist_in, hist, state, delta, n, vr, vn, ri, rj, dt, params):
    return pair_force(law, 0, 0, 1, hist_in, hist, state, np.zeros(2), delta, ri + rj - delta, n, vr, vn, ri, rj,
                      False, dt, params, (0.0, 0.0))


def test_each_law_is_a_type_of_its_own():
    types = {name: numba.typeof(ContactLaw(name)) for name in CONTACT_LAWS}
    assert len(set(types.values())) == len(CONTACT_LAWS)
    assert numba.typeof(ContactLaw("luding")) == types["luding"]


def test_an_unknown_law_is_named_in_one_line():
    with pytest.raises(ValueError, match="must be one of luding, zohdi"):
        ContactLaw("hooke")


def test_a_function_compiled_for_two_laws_has_two_signatures_and_each_law_its_constants():
    assert _spins(ContactLaw("luding")) is True
    assert _spins(ContactLaw("zohdi")) is zohdi.SPINS is False
    assert len(_spins.signatures) == 2


def test_the_bound_pair_force_is_the_laws_own_to_the_bit():
    rng = np.random.default_rng(1)
    params = MATERIAL.params()
    for _ in range(20):
        delta = rng.uniform(1e-9, 1e-6)
        n = tuple(v / math.sqrt(3.0) for v in (1.0, -1.0, 1.0))
        vr = tuple(rng.normal(size=3) * 0.1)
        vn = sum(a * b for a, b in zip(vr, n))
        state = rng.uniform(1e-6, 1e-5, (2, 1))
        hist_in = rng.normal(size=(1, 3)) * 1e-7
        bound, own = np.zeros((1, 3)), np.zeros((1, 3))
        got = _pair_force(ContactLaw("hertz_mindlin"), hist_in, bound, state, delta, n, vr, vn, 1e-4, 2e-4, 1e-7,
                          params)
        want = hertz_mindlin.pair_force(0, 0, 1, hist_in, own, state, np.zeros(2), delta, 3e-4 - delta, n, vr, vn,
                                        1e-4, 2e-4, False, 1e-7, params, (0.0, 0.0))
        assert np.array(got).tobytes() == np.array(want).tobytes()
        assert bound.tobytes() == own.tobytes()
        assert got[0] != 0.0 and any(bound[0])  # a normal force and a spring that moved: something compared
