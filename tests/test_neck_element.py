"""The exact flux element of a cut sphere (verification.neck_element) against the closed form: the uncut ball whose
two polar caps are uniform-flux faces, its resistance between them from the Legendre series."""

import numpy as np
import pytest

from verification import neck_element as E

pytest.importorskip("ngsolve")


@pytest.mark.parametrize("alpha, tolerance", [(0.3, 1e-3), (0.7, 2e-4)])
def test_two_caps_against_the_legendre_series(alpha, tolerance):
    res = E.cap_ball(alpha)
    R = res["R"][0.0]
    assert R[0, 1] == pytest.approx(R[1, 0], rel=1e-12)
    between = R[0, 0] + R[1, 1] - 2 * R[0, 1]
    exact = E.cap_ball_exact(alpha)
    # Galerkin's discrete energy is above the exact minimum: the FE's resistance is below the series', and close
    assert 0.0 < 1.0 - between / exact < tolerance
    assert res["volume"] == pytest.approx(4.0 / 3.0 * np.pi, rel=1e-4)


@pytest.mark.parametrize("kwargs, word", [({"arms": [1.2]}, "arms"), ({"betas": (0.5,)}, "beta"),
                                          ({"maxh": 0.0}, "maxh"), ({"order": 0}, "order"),
                                          ({"normals": [[0.0, 0.0, 2.0]]}, "normals")])
def test_bad_input_is_one_line_naming_the_parameter(kwargs, word):
    args = {"normals": [[0.0, 0.0, 1.0]], "arms": [0.9], **kwargs}
    with pytest.raises(ValueError, match=word) as err:
        E.cut_element(**args)
    assert "\n" not in str(err.value)
