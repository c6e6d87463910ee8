"""Sub-commands of ``python -m dem``; each module exposes ``register(subparsers)`` (the plumbing of
:mod:`fem_neck.cli`: one JSON object with ``--json``, one line on stderr and exit 2 for bad input)."""
