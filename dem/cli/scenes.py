"""``python -m dem scenes [--json]``: list the built-in scenes with their descriptions."""


def register(sub):
    parser = sub.add_parser("scenes", help="list the built-in scenes", description=__doc__)
    parser.add_argument("--json", action="store_true", help="print one JSON object on stdout, nothing else")
    parser.set_defaults(run=run)


def run(args) -> dict:
    from dem.scene import builtin_scenes

    return builtin_scenes()
