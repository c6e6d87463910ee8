"""``python -m verification``: the paper's claims reproduced and the DEM surrogate checked against FE (:mod:`verification.cli`)."""

from sinterheat.startup import run_main

if __name__ == "__main__":
    run_main("python -m verification", "verification.cli")
