"""``python -m dem``: see :mod:`dem.cli`."""

from sinterheat.startup import run_main

if __name__ == "__main__":
    run_main("python -m dem", "dem.cli")
