"""The numerical schemes that advance a scene: the static pipe network (:mod:`~dem.engines.static`), velocity Verlet
for particles that move (:mod:`dem.engines.verlet`) and Zohdi 2014's staggered implicit scheme
(:mod:`dem.engines.staggered`); heat and current on the contacts of moving particles
(:mod:`~dem.engines.contact_heat`, :mod:`~dem.engines.contact_current`)."""
