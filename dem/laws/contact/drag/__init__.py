"""Drag sub-models of the contact laws: a force against every particle's velocity
(:mod:`dem.laws.contact.composition`)."""
