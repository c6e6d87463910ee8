"""The engines of a run launched under MPI (:func:`dem.parallel.comm.launched`), registered in
:data:`dem.engines.RANK_ENGINES`: each shares the sample of one engine of :data:`dem.engines.ENGINES` out among the
ranks and is the module named after it -- :mod:`~dem.engines.distributed.static` (a packing that does not move, its
network solved on PETSc) and :mod:`~dem.engines.distributed.verlet` (particles that move, in slabs with ghosts and
migration). The MPI plumbing they stand on is :mod:`dem.parallel`; how the sample is cut is geometry
(:mod:`dem.geometry.bisection`, :mod:`dem.geometry.slabs`)."""
