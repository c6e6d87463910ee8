"""``python -m dem``: see :mod:`dem.cli`."""

import sys

from dem.cli import main

if __name__ == "__main__":
    sys.exit(main())
