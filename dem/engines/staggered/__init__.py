"""Electrically aided sintering (Zohdi 2014): the staggered, adaptive, implicit scheme of Algorithm 1 over the
mechanics (:mod:`~dem.engines.staggered.mechanics`, compiled :mod:`~dem.engines.staggered.kernels`), the lumped heat
balance (:mod:`~dem.engines.staggered.heat`) and the current (:mod:`dem.engines.contact_current`), run by
:mod:`~dem.engines.staggered.engine`."""
