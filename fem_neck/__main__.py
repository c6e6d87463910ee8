"""``python -m fem_neck``: neck geometry, FE conductance solves, convergence studies and the conductance fit."""

from sinterheat.startup import run_main

if __name__ == "__main__":
    run_main("python -m fem_neck", "fem_neck.cli", one_blas_thread=("fit", "lattice"), description=__doc__)
