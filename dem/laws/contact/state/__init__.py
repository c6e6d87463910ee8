"""State sub-models of the contact laws: what each particle carries from step to step and what its temperature
does to it (:mod:`dem.laws.contact.composition`)."""
