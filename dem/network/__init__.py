r"""One network problem, two fields: heat (temperatures, thermal conductances) and current (potentials, electrical
conductances) between particles on the same weighted graph Laplacian with fixed nodes and planes
(:mod:`~dem.network.laplacian`), its linear solvers (:mod:`~dem.network.linsolve`), the heat balance steady and in time
(:mod:`~dem.network.heat`; the :math:`\theta` step, its linear solve a plug-in, in :mod:`~dem.network.theta`), on one
process or over MPI ranks (:mod:`~dem.network.distributed`), and the current (:mod:`~dem.network.current`, Zohdi 2014's
iteration in :mod:`~dem.network.gauss_seidel`)."""
