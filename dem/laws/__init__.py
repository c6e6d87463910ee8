"""Constitutive laws of the DEM: the conductance of a bond (:mod:`~dem.laws.conductance`, the dense-packing
:mod:`~dem.laws.shared_body`), the exchange with an ambient (:mod:`~dem.laws.ambient`) and the contact laws of
particles that move (:mod:`dem.laws.contact`)."""
