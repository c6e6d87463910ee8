"""The static engine over several MPI ranks (:mod:`dem.engines.distributed.engine`): the network of a packing that
does not move, shared out in space among the ranks and solved on PETSc; the driver runs it in place of ``static``
when launched under MPI (:func:`dem.parallel.comm.launched`)."""
