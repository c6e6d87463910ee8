"""``python -m dem laws [--json]``: list the selectable conductance laws (``[conductance] law``), one line each."""


def register(sub):
    parser = sub.add_parser("laws", help="list the conductance laws", description=__doc__)
    parser.add_argument("--json", action="store_true", help="print one JSON object on stdout, nothing else")
    parser.set_defaults(run=run)


def run(args) -> dict:
    from dem.laws.conductance import DESCRIPTIONS, LAWS

    return {name: DESCRIPTIONS[name] for name in LAWS}
