"""``python -m dem run SCENE [--out DIR] [--json]``: run a scene (TOML path or built-in name), print its summary."""

from fem_neck.cli import add_output_options


def register(sub):
    parser = sub.add_parser("run", help="run a scene (TOML file or built-in name)", description=__doc__)
    parser.add_argument("scene", help="path to a scene TOML file, or a built-in name (see `python -m dem scenes`)")
    add_output_options(parser)
    parser.set_defaults(run=run)


def run(args) -> dict:
    from dem.scene import load_scene
    from dem.simulation import run as run_scene

    try:
        scene = load_scene(args.scene)
        return run_scene(scene, args.out, progress=True).summary
    except MemoryError:
        raise ValueError(f"scene = {args.scene!r}: out of memory (about 1.7 GiB per 10^6 particles for a steady "
                         f"solve); use a smaller scene") from None
