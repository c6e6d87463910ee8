"""Constitutive laws of the DEM as pure functions over bond arrays (conductance now; contact mechanics and
electrical conduction plug in beside it)."""
