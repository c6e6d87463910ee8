"""Electrically aided sintering (Zohdi 2014) on the engine for moving particles.

* :mod:`dem.laws.contact.zohdi` -- the contact material (eqs. 2-21, Sec. 7) and the implicit stepping (eqs. 22-30);
* :mod:`dem.zohdi.kernels` -- compiled forces, one fixed-point iteration of the trapezoidal step, the paper's
  conduction law on the Verlet list;
* :mod:`dem.zohdi.mechanics` -- the mechanical submodel (state, Verlet list, walls, iterate/accept/restart);
* :mod:`dem.zohdi.heat` -- the thermal submodel (the lumped heat balance, eqs. 31-37);
* :mod:`dem.zohdi.current` -- the electrical submodel (Kirchhoff or eq. 43, :mod:`dem.network.current`);
* :mod:`dem.network.gauss_seidel` -- the compiled Gauss-Seidel sweep of eq. (43);
* :mod:`dem.zohdi.simulation` -- the staggered adaptive scheme of Algorithm 1 and the run's observables;
* :mod:`dem.scene.zohdi` -- the scene keys that select and parametrise it.
"""
