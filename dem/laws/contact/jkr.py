r"""The adhesive contact of Johnson, Kendall & Roberts 1971 (Proc. R. Soc. Lond. A 324, 301): elastic spheres whose
surfaces stick with the work of adhesion w, with the damping and the Mindlin tangential contact of
:mod:`dem.laws.contact.hertz_mindlin`: its material and scene keys. The law is the composition
(:data:`dem.laws.contact.CONTACT_LAWS`) of Hertz's normal sub-model with the JKR adhesion
(:mod:`dem.laws.contact.adhesion.jkr`), Tsuji's damping and Mindlin's tangential contact.

Conventions, :math:`R^*`, :math:`m^*`, :math:`E^*` and :math:`G^*` (a wall: a partner of infinite radius and mass of
the same material) as in :mod:`dem.laws.contact.hertz_mindlin`. ``w`` is the work of adhesion (J/m^2): the energy per
unit area it takes to part the two surfaces, :math:`w = \gamma_1 + \gamma_2 - \gamma_{12}` (Johnson 1985's
:math:`\Delta\gamma`; twice the surface energy :math:`\gamma` of identical surfaces -- LAMMPS's ``jkr`` takes that
:math:`\gamma`).

* **Normal** (Johnson, Contact Mechanics, 1985, Sec. 5.5, with :math:`P_1 = 4 E^* a^3/(3 R^*)`): at contact radius
  a, the overlap :math:`\delta = a^2/R^* - \sqrt{2 \pi w a/E^*}` and the force :math:`F_{el} = 4 E^* a^3/(3 R^*) -
  \sqrt{8 \pi w E^* a^3}`. At :math:`F_{el} = 0`, :math:`a_0^3 = 9 \pi w {R^*}^2/(2 E^*)`. The largest pull,
  :math:`-\frac{3}{2} \pi w R^*` (the pull-off force of a load-controlled test), is reached at :math:`\delta =
  -a^2/(3 R^*)`, :math:`a^3 = 9 \pi w {R^*}^2/(8 E^*)`. :func:`dem.laws.contact.adhesion.jkr.contact_radius` inverts
  the overlap in closed form: with :math:`s = \sqrt{a}` and :math:`c = \sqrt{2 \pi w/E^*}` it is the quartic
  :math:`s^4 - c R^* s - \delta R^* = 0`, solved by Ferrari's method through its resolvent cubic :math:`y^3 + \delta
  R^* y - c^2 {R^*}^2/8 = 0` (one real root for every :math:`\delta` above the break, written without cancellation).
* **Contact and break**: two surfaces that touch (:math:`\delta` reaches 0) jump into contact (:math:`F_{el} =
  -\frac{4}{3} \pi w R^*` at :math:`\delta = 0`) and then stay in contact when pulled apart, beyond touching, down
  to :math:`\delta_c = -3 a_c^2/R^* = -\frac{3}{4} (\pi^2 w^2 R^*/{E^*}^2)^{1/3}`, :math:`a_c = a_0/6^{2/3}`, where
  :math:`d\delta/da = 0`: the end of the stable branch under displacement control (Johnson 1985, Sec. 5.5; Thornton
  & Ning 1998, Powder Technol. 99, 154), with :math:`F_{el} = -\frac{5}{6} \pi w R^*`; there the contact breaks and
  the force drops to zero. The pair's history keeps the pull-off distance :math:`-\delta_c` (0 until the pair first
  touches), the engines' ``reach``: the contact acts while the surfaces are closer than that.
* **Damping**: :math:`\eta_n = \alpha \sqrt{m^* k_n}` with :math:`k_n = \frac{4}{3} E^* a` at the JKR contact
  radius a, :math:`\alpha` from the restitution coefficient as in Hertz-Mindlin
  (:func:`dem.laws.contact.damping.tsuji.damping_coefficient`): where adhesion is weak against the impact
  (:math:`w \to 0`) a head-on collision rebounds with that e; slow impacts stick.
* **Tangential**: Mindlin's spring :math:`k_t = 8 G^* a` on the JKR contact radius, damping :math:`\eta_t`, Coulomb
  sliding at :math:`\mu (F_{el} + 2 P_c)`, :math:`P_c = \frac{3}{2} \pi w R^*` (Thornton & Yin 1991, Powder
  Technol. 65, 153: adhesion adds to the load that friction resists; LAMMPS's critical force for ``jkr``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from dem.laws.contact import hertz_mindlin as hm
from dem.laws.contact.hertz_mindlin import HertzMindlinMaterial


@dataclass(frozen=True)
class JKRMaterial(HertzMindlinMaterial):
    r"""Material of the JKR contact: that of Hertz-Mindlin
    (:class:`~dem.laws.contact.hertz_mindlin.HertzMindlinMaterial`) and ``work_of_adhesion`` w > 0 (J/m^2; twice the
    surface energy of identical surfaces). ``restitution`` is that of a collision whose adhesion is negligible.

    Parameters
    ----------
    youngs_modulus : float
        Young's modulus E of the particles and walls (Pa), > 0.
    poisson_ratio : float
        Poisson's ratio :math:`\nu`, in ``(-1, 0.5)``.
    restitution : float
        Coefficient of restitution e of a head-on collision with negligible adhesion, in ``(0, 1]``.
    tangential_damping : float
        :math:`\eta_t/\eta_n`, the tangential over the normal damping coefficient, >= 0.
    mu : float
        Particle-particle friction coefficient, >= 0.
    mu_wall : float
        Particle-wall friction coefficient, >= 0.
    density : float
        Particle density (kg/m^3), > 0.
    work_of_adhesion : float
        The work of adhesion w (J/m^2), > 0.

    Raises
    ------
    ValueError
        A field is out of its range; the message names it (``contact.<field>``).
    """

    work_of_adhesion: float

    law = "jkr"

    def __post_init__(self):
        super().__post_init__()
        if not self.work_of_adhesion > 0:
            raise ValueError(f"contact.work_of_adhesion = {self.work_of_adhesion!r}: must be > 0 (J/m^2; without "
                             f"adhesion use law = \"hertz_mindlin\")")

    def pulloff_distance(self, r_eff):
        r"""How far beyond touching a contact of effective radius ``R*`` breaks, :math:`\frac{3}{4} (\pi^2 w^2
        R^*/{E^*}^2)^{1/3}` (m).

        Parameters
        ----------
        r_eff : float or array_like
            The effective radius ``R* = a_i a_j/(a_i + a_j)`` (m; a particle's radius on a wall).

        Returns
        -------
        float or numpy.ndarray
            ``-delta_c``, the pull-off distance (m).
        """
        return 0.75 * np.cbrt(math.pi**2 * self.work_of_adhesion**2 * r_eff / self.effective_modulus**2)


Material = JKRMaterial
_JKR_ROWS = {  # where the meaning of a Hertz-Mindlin key differs with adhesion
    ("restitution",): ("0 < e ≤ 1, required", "the coefficient of restitution of a head-on collision whose adhesion "
                       "is negligible (slow ones stick)"),
    ("mu", "mu_wall"): ("≥ 0, required", "particle-particle and particle-wall Coulomb friction, ‖F_t‖ ≤ μ (F_n + "
                        "3πwR*) (Thornton & Yin 1991)"),
}
SCHEMA_ROWS = tuple((keys, *_JKR_ROWS.get(keys, (unit, meaning))) for keys, unit, meaning in hm.SCHEMA_ROWS) + (
    (("work_of_adhesion",), "J/m², > 0, required", "w, the energy per area that parts the surfaces (twice the surface "
     "energy of identical ones; LAMMPS's `jkr` takes the surface energy): pull-off force 3/2 πwR*, the contact "
     "breaks 3/4 (π²w²R*/E*²)^(1/3) beyond touching (Johnson, Kendall & Roberts 1971)"),
)
