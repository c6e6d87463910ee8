"""MPI plumbing, below everything that runs on several ranks: whether this run is one and its communicator, the
reductions and halo exchanges between ranks (:mod:`~dem.parallel.comm`, mpi4py), and a network's matrix solved over
the ranks on PETSc (:mod:`~dem.parallel.petsc`, petsc4py). Neither is imported by a run without MPI."""
