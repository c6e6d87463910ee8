"""``python -m dem``: run a pipe-network thermal DEM scene, or list the built-in scenes.

    python -m dem run SCENE [--out DIR] [--json]     SCENE: a TOML file or a built-in name
    python -m dem scenes [--json]
"""

import sys

from fem_neck.cli import main

if __name__ == "__main__":
    sys.exit(main(prog="python -m dem", description=__doc__.splitlines()[0], modules=("run", "scenes"),
                  package="dem.cli"))
