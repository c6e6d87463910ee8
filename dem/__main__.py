"""``python -m dem``: see :mod:`dem.cli`."""

from dem.cli import main
from sinterheat.interrupt import exit_process

if __name__ == "__main__":
    exit_process(main())
