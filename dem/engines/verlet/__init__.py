"""Particles that move under velocity-Verlet steps (Luding 2005): the engine that owns the time loop and couples the
heat (:mod:`~dem.engines.verlet.engine`), the mechanical submodel with its Verlet list and contact histories
(:mod:`~dem.engines.verlet.mechanics`) and the compiled loop (:mod:`~dem.engines.verlet.loop`)."""
