"""``python -m fem_neck``: neck geometry, FE conductance solves, convergence studies and the conductance fit."""

import sys

from fem_neck.cli import main

if __name__ == "__main__":
    sys.exit(main(description=__doc__))
