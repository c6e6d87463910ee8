"""The tests of the distributed network run only under ``mpiexec -n N python -m pytest tests/mpi`` (N > 1, the
README block after ``mpi-command``): in the default run, without MPI, they are not collected."""

from dem.parallel.comm import launched

collect_ignore_glob = [] if launched() else ["test_*.py"]
