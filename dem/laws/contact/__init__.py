"""Contact laws of particles that move, each a named choice of sub-models: one line of :data:`CONTACT_LAWS` (a
:class:`~dem.laws.contact.composition.Composition` of a normal force, a damping, a tangential force, an adhesion, what
particles carry from step to step and a drag), put together by :class:`~dem.laws.contact.composition.Law` for the
engines and at compile time by :mod:`dem.laws.contact.binding` for their compiled loops.

The sub-models live one per module in the slots' folders (``normal/``, ``damping/``, ``tangential/``,
``adhesion/``, ``state/``, ``drag/``; their interface: :mod:`dem.laws.contact.composition`); a paper's material (its
dataclass, parameter block and schema rows) in a module of its own (``luding``, ``zohdi``, ``hertz_mindlin``,
``jkr``). A new combination of existing sub-models is one more line of :data:`CONTACT_LAWS`.
"""

from __future__ import annotations

from dem.laws.contact.composition import Composition, Law

#: The contact laws by the name ``[contact] law`` gives, each a choice of sub-models.
CONTACT_LAWS = {
    # Luding, Manetsberger & Mueller 2005: sintering, hysteretic normal law
    "luding": Composition(normal="luding", damping="luding", tangential="luding", state="sintering",
                          material="dem.laws.contact.luding"),
    # Zohdi 2014: power law on the contact area, bonds, thermal softening
    "zohdi": Composition(normal="zohdi", adhesion="zohdi", tangential="zohdi", state="temperature", drag="zohdi",
                         material="dem.laws.contact.zohdi"),
    # Hertz, Tsuji's damping (restitution e), Mindlin, Coulomb
    "hertz_mindlin": Composition(normal="hertz", damping="tsuji", tangential="mindlin", state="mass",
                                 material="dem.laws.contact.hertz_mindlin"),
    # Johnson-Kendall-Roberts 1971 adhesion on Hertz, with Tsuji's damping and Mindlin's friction
    "jkr": Composition(normal="hertz", damping="tsuji", tangential="mindlin", adhesion="jkr", state="mass",
                       material="dem.laws.contact.jkr"),
    # Hertz's normal force and Tsuji's damping with Luding's tangential spring and friction (eqs. 14-24)
    "hertz_luding": Composition(normal="hertz", damping="tsuji", tangential="luding", state="mass"),
}


#: One line on each contact law, for ``python -m dem laws``.
DESCRIPTIONS = {
    "luding": "sintering: hysteretic normal law with cohesion, temperature-dependent stiffness, friction "
              "(Luding, Manetsberger & Mueller 2005)",
    "zohdi": "power law on the contact area, bonds, thermal softening; staggered engine (Zohdi 2014)",
    "hertz_mindlin": "elastic spheres: Hertz normal force with Tsuji's damping (restitution e), Mindlin tangential "
                     "stiffness, Coulomb friction",
    "jkr": "Johnson-Kendall-Roberts 1971 adhesion, with Hertz-Mindlin's damping and friction",
    "hertz_luding": "Hertz normal force with Tsuji's damping (restitution e), Luding's tangential spring and "
                    "friction (Luding 2005, eqs. 14-24)",
}


def composition_of(name) -> Composition:
    """The sub-models of the contact law ``name``; ``ValueError`` naming the laws for an unknown one.

    Parameters
    ----------
    name : str
        A law of :data:`CONTACT_LAWS` (``"luding"``, say).

    Returns
    -------
    Composition
        Its sub-models.

    Raises
    ------
    ValueError
        ``name`` is not a known law.
    """
    if not isinstance(name, str) or name not in CONTACT_LAWS:
        raise ValueError(f"[contact] law = {name!r}: must be one of {', '.join(CONTACT_LAWS)}")
    return CONTACT_LAWS[name]


_LAWS = {}  # the laws put together, by name and composition


def law_module(name) -> Law:
    """The contact law ``name`` (:data:`CONTACT_LAWS`), put together from its sub-models (once per composition).

    Parameters
    ----------
    name : str
        A law of :data:`CONTACT_LAWS`.

    Returns
    -------
    Law
        The law.

    Raises
    ------
    ValueError
        ``name`` is not a known law, or its sub-models do not fit together.
    """
    key = (name, composition_of(name))
    if key not in _LAWS:
        _LAWS[key] = Law(*key)
    return _LAWS[key]
