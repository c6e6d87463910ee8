"""The static engine over several MPI ranks (:mod:`dem.engines.distributed.engine`): the network of a packing that
does not move, shared out in space among the ranks and solved on PETSc; registered as ``static`` in
:data:`dem.engines.RANK_ENGINES`, the engine of a static scene launched under MPI
(:func:`dem.parallel.comm.launched`)."""
