"""Tangential sub-models of the contact laws: the spring, damping and sliding of a contact's tangential motion
(:mod:`dem.laws.contact`)."""
