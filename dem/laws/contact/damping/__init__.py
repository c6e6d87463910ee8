"""Damping sub-models of the contact laws: the viscous coefficient of a contact's normal motion
(:mod:`dem.laws.contact`)."""
