"""``python -m dem laws [--json]``: list the laws a scene can name, one line each with the keys it reads: the
conductance laws (``[conductance] law``: every static and moving run's bonds) and the contact laws of particles that
move (``[contact] law``, :data:`dem.laws.contact.CONTACT_LAWS`: their material's keys, SI units)."""


def register(sub):
    """Add the ``laws`` command (module docstring) to the subcommands of ``python -m dem``.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subparsers of the ``python -m dem`` parser.
    """
    parser = sub.add_parser("laws", help="list the conductance and contact laws with their keys",
                            description=__doc__)
    parser.add_argument("--json", action="store_true", help="print one JSON object on stdout, nothing else")
    parser.set_defaults(run=run)


def run(args) -> dict:
    """The laws, one line each (module docstring).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line.

    Returns
    -------
    dict
        ``{law: "[table] description; keys: ..."}``.
    """
    from dataclasses import fields

    from dem.laws import contact
    from dem.laws.conductance import DESCRIPTIONS, LAWS, law_keys

    out = {name: f"[conductance] {DESCRIPTIONS[name]}; keys: {', '.join(law_keys(name))}" for name in LAWS}
    for name in contact.CONTACT_LAWS:
        keys = ", ".join(f.name for f in fields(contact.law_module(name).Material))
        out[name if name not in out else f"{name} (contact)"] = f"[contact] {contact.DESCRIPTIONS[name]}; keys: {keys}"
    return out
