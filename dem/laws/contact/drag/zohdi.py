r"""The drag of Zohdi 2014 on every particle (eq. 20 with Sec. 7's drag on a sphere): :math:`-c_{env} v` with
:math:`c_{env} = c_{env}^o\, 6 \pi R`. A drag sub-model of the contact laws (:mod:`dem.laws.contact.composition`).
Parameters: the block of :func:`dem.laws.contact.zohdi.params_of`.
"""

from __future__ import annotations

import math

from numba import njit

from dem.laws.contact import zohdi
from dem.laws.contact.kernel_options import IN_LOOP
from dem.laws.contact.zohdi import Z_C_ENV

PARAMS = (zohdi.params_of, zohdi.N_PARAMS)
FIELDS = {"c_env": ("nonnegative", "kg/(m s)")}
SCHEMA_ROWS = tuple(row for row in zohdi.SCHEMA_ROWS if set(row[0]) & set(FIELDS))


@njit(**IN_LOOP)
def drag(k, radius, params):
    r""":math:`c_{env} = c_{env}^o\, 6 \pi R` (eq. 20 with Sec. 7's drag on a sphere) of particle k, kg/s."""
    return params[Z_C_ENV] * 6.0 * math.pi * radius[k]
