"""``python -m fem_neck``: neck geometry, FE conductance solves, convergence studies and the conductance fit."""

from fem_neck.cli import main
from sinterheat.interrupt import exit_process

if __name__ == "__main__":
    exit_process(main(description=__doc__))
