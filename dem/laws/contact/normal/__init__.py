"""Normal sub-models of the contact laws: the elastic force of two touching particles at an overlap
(:mod:`dem.laws.contact`)."""
