"""Where the particles are and what bounds them: the particles and their materials (:mod:`~dem.geometry.particles`),
the mass and inertia of a sphere or disk (:mod:`~dem.geometry.inertia`), plane walls (:mod:`~dem.geometry.walls`), the
periodic box (:mod:`~dem.geometry.periodic`), neighbour lists (:mod:`~dem.geometry.neighbours`), bonds and their
necks (:mod:`~dem.geometry.bonds`), packing generators (:mod:`~dem.geometry.generators`) and the exposed surface
(:mod:`~dem.geometry.exposure`)."""
