"""``python -m fem_neck lattice``: effective conductivity of a simple, body- or face-centred cubic lattice of sintered
spheres from 3D FE of its mirror cell, with two-sided bounds (:mod:`fem_neck.lattice`)."""

import math

from sinterheat.cli import add_output_options


def register(subparsers) -> None:
    """Add the ``lattice`` sub-command's parser (its options and ``run``) to ``subparsers``.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The sub-commands of the ``python -m fem_neck`` parser.
    """
    p = subparsers.add_parser(
        "lattice", help="k_eff of an SC, BCC or FCC lattice of sintered spheres (3D FE, two-sided bounds)",
        description="Steady conduction through an infinite cubic lattice of equal spheres joined by the "
        "volume-conserving pair necks of every nearest-neighbour bond (Rojek 2022, eqs. 21-33), under a uniform "
        "gradient along z. The FE solves a sixteenth of the cubic cell bounded by mirror planes (the planes normal "
        "to z isothermal, the others insulated) on tetrahedra that fill the exact solid: conforming P_p elements give "
        "an upper bound, a divergence-free Raviart-Thomas flux of degree p - 1 a lower bound; the mesh is refined "
        "toward the neck circles until they are --rtol apart. The tetrahedra of each mesh are predicted from the "
        "cell's neck circles and the memory of its solve estimated before the mesh is made, and a run that would not "
        "fit is refused up front with the estimate and the rtol that would. "
        "Prints k_eff/kappa (the upper bound, the more accurate), its bounds, error_estimate = (upper - lower) / "
        "upper, the solid fraction phi (phi kappa is the Wiener upper bound of k_eff) and the pipe network's k_eff "
        "with the full-range fit law beside it.")
    p.add_argument("--kind", choices=("sc", "bcc", "fcc"), required=True, help="lattice")
    p.add_argument("--neck", choices=("newton", "union"), default="newton",
                   help="the solid: 'newton' (default), the spheres joined by the volume-conserving pair necks; "
                   "'union', the union of the spheres (Arzt's truncated spheres, each cut by its radical planes: "
                   "defined also where the necks of a particle meet, up to the overlap at which the spheres fill "
                   "space; second neighbours that overlap are necks too)")
    size = p.add_mutually_exclusive_group(required=True)
    size.add_argument("--h-over-r", type=float, metavar="X", help="overlap of neighbours over the radius (the "
                      "neighbour distance is 2r - h)")
    size.add_argument("--a-over-r", type=float, metavar="X", help="neck radius over the particle radius (with "
                      "--neck union: the radius of the circle where neighbours meet)")
    p.add_argument("--rtol", type=float, default=1e-4,
                   help="relative gap of the bounds to reach (default 1e-4: 10-60 s of CPU and 1-3 GB for the cubic "
                   "lattices; 1e-3 a few seconds)")
    p.add_argument("--flows", action="store_true",
                   help="with --neck union: also every neck's heat flow through its face (the flat disc between two "
                   "spheres, periodic images included) and the face's mean temperature, and every particle's mean "
                   "temperature, per unit conductivity and mean gradient along -z (flows in m^2, temperatures in m; "
                   "in full in --json and in --out's lattice.json)")
    p.add_argument("--max-memory", type=float, metavar="GB",
                   help="memory the solve may use (default: what the machine has available)")
    add_output_options(p)
    p.set_defaults(run=run)


def run(args) -> dict:
    """Solve the lattice cell (:func:`fem_neck.lattice.driver.effective_conductivity`); the result as a JSON-ready dict.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``python -m fem_neck lattice`` (its ``--help`` lists them, with their units: lengths in m,
        temperatures in K, conductivities in W/(m K)).
    """
    import json
    import pathlib

    from tqdm import tqdm

    from fem_neck import lattice
    from fem_neck.geometry import neck_radius, overlap_for_neck
    from fem_neck.law import pair_conductance

    if not (1e-6 <= args.rtol < 0.1):  # False for NaN
        raise ValueError(f"rtol = {args.rtol!r}: valid range 1e-6 <= rtol < 0.1")
    if args.max_memory is not None and not (0.1 <= args.max_memory < 1e6):
        raise ValueError(f"max_memory = {args.max_memory!r}: valid range 0.1 <= max_memory < 1e6 (GB)")
    union = args.neck == "union"
    if args.flows and not union:
        raise ValueError("flows: per-neck flows are read on the union of spheres: add --neck union")
    if args.a_over_r is not None:
        x = args.a_over_r
        if union:
            low, limit = (lattice.union_neck_ratio(h) for h in (lattice.UNION_MIN_H_OVER_R,
                                                                 lattice.union_max_h_over_r(args.kind)))
            if not (low <= x < limit):
                raise ValueError(f"a_over_r = {x!r}: valid range {low:.6g} <= a/r < {limit:.6g} for the union of "
                                 f"the {args.kind} lattice's spheres (there they fill space)")
            h = 2.0 - 2.0 * math.sqrt(1.0 - x * x)  # the circle of two unit spheres 2 - h apart: a^2 = h - h^2 / 4
        else:
            limit = lattice.max_neck_ratio(args.kind)
            if not (lattice.MIN_NECK_RATIO <= x < limit):
                raise ValueError(f"a_over_r = {x!r}: valid range {lattice.MIN_NECK_RATIO} <= a/r < {limit:.6g} for "
                                 f"{args.kind} (there the necks of one particle touch)")
            h = overlap_for_neck(1.0, 1.0, x)
    else:
        h = args.h_over_r
        if not math.isfinite(h):
            raise ValueError(f"h_over_r = {h!r}: must be finite")
    cell = lattice.lattice_cell(args.kind, h, neck=args.neck)
    with tqdm(desc=f"lattice {args.kind}", unit="mesh", leave=False, delay=2.0) as bar:
        res = lattice.effective_conductivity(cell, rtol=args.rtol,
                                             max_memory=None if args.max_memory is None else args.max_memory * 1e9,
                                             progress=lambda text: (bar.set_postfix_str(text, refresh=False), bar.update(1)),
                                             flows=args.flows)
    out = {"kind": args.kind, **({"neck": "union"} if union else {}), "h_over_r": h,
           "a_over_r": lattice.union_neck_ratio(h) if union else neck_radius(1.0, 1.0, h),
           "coordination": lattice.COORDINATION[args.kind], "k_eff_over_kappa": res.k_eff_over_kappa,
           "k_lower_over_kappa": res.k_lower_over_kappa, "k_upper_over_kappa": res.k_upper_over_kappa,
           "error_estimate": res.error_estimate, "converged": res.converged, "phi": res.phi}
    if not union:  # (the network laws read pair necks)
        network = lattice.network_conductivity(cell, lambda r_i, r_j, a: pair_conductance(1.0, r_i, r_j, a))
        out.update({"k_network_fit_over_kappa": network, "network_rel_error": network / res.k_eff_over_kappa - 1.0})
    out.update({"order": res.order, "dofs": res.dofs, "elements": res.elements, "meshes": len(res.levels),
           "volume_error": res.volume_error, "memory_estimate_gb": res.memory_estimate / 1e9, "seconds": res.seconds})
    if args.flows:
        out["flows"] = res.flows.as_dict()
    if args.out:
        path = pathlib.Path(args.out)
        path.mkdir(parents=True, exist_ok=True)
        (path / "lattice.json").write_text(json.dumps({**out, "peak_memory_gb": lattice.peak_memory() / 1e9,
                                                       "levels": res.levels}, indent=2) + "\n")
        lattice.write_vtu(res, path / "cell.vtu")
        out["out"] = str(path)
    return out
