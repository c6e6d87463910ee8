"""``python -m benchmarks [SUBJECT ...]``: run time against error, with the targets each subject must meet (:mod:`benchmarks.cli`)."""

from sinterheat.startup import run_main

if __name__ == "__main__":
    run_main("python -m benchmarks", "benchmarks.cli")
