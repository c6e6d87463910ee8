"""Adhesion sub-models of the contact laws: surfaces that stick, and the contact radius and force that follow
(:mod:`dem.laws.contact`)."""
