r"""``python -m fem_neck semisphere | pair | chain``: FE conductances solved to a tolerance (Rojek 2022, Secs. 5-6).

The model conductance compared with the FE is Rojek 2022, eq. (43): each particle's half conducts
:math:`K_i = 1.064 \kappa \pi a`; a bond is the two halves in series, :math:`K_{ij} = K_i / 2` (eqs. 44-45), and a chain
is its bonds in series. ``rel_diff = (K_model - K_fe) / K_fe``.
"""

from __future__ import annotations

import math

import numpy as np

from sinterheat.cli import add_output_options

PAPER_SLOPE = 1.064  # Rojek 2022, eq. (40)
MAX_CHAIN = 50  # spheres in one chain solve (40 take ~28 s and 1.4 GB on 2 cores)


def model_bond_conductance(kappa: float, a):
    r""":math:`K_{ij} = K_i K_j / (K_i + K_j) = 1.064 \kappa \pi a / 2` (Rojek 2022, eqs. 43-45).

    Parameters
    ----------
    kappa : float
        Thermal conductivity, W/(m K).
    a : float or array_like
        Neck radius, m.
    """
    return PAPER_SLOPE * kappa * math.pi * np.asarray(a, dtype=float) / 2.0


def _floats(name: str, text: str) -> list:
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise ValueError(f"{name} = {text!r}: must be comma-separated numbers") from None
    if not values:
        raise ValueError(f"{name} = {text!r}: must list at least one number")
    return values


def _add_accuracy(p, methods: tuple = ()) -> None:
    p.add_argument("--rtol", type=float, default=1e-4, help="relative tolerance of K (default 1e-4)")
    if methods:
        p.add_argument("--method", choices=methods, default=methods[0],
                       help="hp: spectral elements on a geometric mesh with the exact sphere, order raised until two "
                       "orders agree (milliseconds); gmsh: the graded triangle mesh "
                       "of chains" + ("; auto: hp where it applies, else gmsh" if "auto" in methods else "")
                       + f" (default {methods[0]})")
        p.add_argument("--order", type=int, default=None,
                       help="first order tried (hp: 2-11) or order of the reported solve (gmsh: 2-4); default: "
                       "from --rtol")
    else:
        p.add_argument("--order", type=int, default=None, choices=(2, 3, 4),
                       help="element order of the reported solve (default: fastest for --rtol)")
    add_output_options(p)


def register(subparsers) -> None:
    """Add the ``semisphere``, ``pair`` and ``chain`` sub-commands' parsers to ``subparsers``.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The sub-commands of the ``python -m fem_neck`` parser.
    """
    p = subparsers.add_parser(
        "semisphere", help="conductance of the semisphere with a neck (FE, Rojek 2022 Sec. 5)",
        description="Semisphere of radius r = 1 with the volume-conserving cylindrical half neck (Rojek 2022, Fig. 12; "
        "eqs. 19-20), T fixed on the equatorial and neck-end disks. Prints K/K_cyl (K_cyl = kappa pi r, eqs. 38-39).")
    size = p.add_mutually_exclusive_group(required=True)
    size.add_argument("--h-over-r", type=float, metavar="X", help="overlap of the two spheres over r, 0 < X < 2/3")
    size.add_argument("--a-over-r", type=float, metavar="X", help="neck radius over r, 0 < X < 1")
    _add_accuracy(p, ("hp", "gmsh"))
    p.set_defaults(run=run_semisphere)

    p = subparsers.add_parser(
        "pair", help="conductance of two sintered spheres (FE vs Rojek 2022 eqs. 43-45)",
        description="Two spheres RI, RJ (m) overlapping by H (m), volume-conserving neck, T fixed on both outer "
        "equatorial disks (Rojek 2022, Sec. 6, Figs. 8 and 17). K in W/K.")
    p.add_argument("--ri", type=float, required=True, metavar="R_I", help="radius of particle i [m]")
    p.add_argument("--rj", type=float, required=True, metavar="R_J", help="radius of particle j [m]")
    p.add_argument("--h", type=float, required=True, metavar="H", help="overlap r_i + r_j - d [m]")
    p.add_argument("--kappa", type=float, required=True, help="thermal conductivity [W/(m K)]")
    _add_accuracy(p, ("auto", "hp", "gmsh"))
    p.set_defaults(run=run_pair)

    p = subparsers.add_parser(
        "chain", help="conductance of a collinear chain of sintered spheres (FE vs the pipe model)",
        description="Chain of spheres on one axis, end particles cut at their outer equatorial planes, T fixed "
        "there. The model: eq. (43) halves in series over all bonds.")
    p.add_argument("--radii", required=True, metavar="R1,R2,...", help=f"sphere radii [m] (2 to {MAX_CHAIN} spheres)")
    p.add_argument("--overlaps", required=True, metavar="H1,...", help="overlap of each bond [m] (one fewer)")
    p.add_argument("--kappa", type=float, required=True, help="thermal conductivity [W/(m K)]")
    _add_accuracy(p)
    p.set_defaults(run=run_chain)


def _mesh_errors_as_value_errors(call):
    """A mesh that gmsh cannot make is reported like bad input: one line, exit code 2, saying what to change."""
    try:
        return call()
    except RuntimeError as exc:
        raise ValueError(f"{exc} (the geometry is degenerate for the mesher, typically a neck at the model's limit "
                         f"a = min(r_i, r_j); an overlap a little below max_overlap meshes)") from exc


def _output_dir(args):
    if not args.out:
        return None
    import pathlib

    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    return out


def _write(out, name: str, summary: dict, result, title: str, delta_t: float) -> None:
    import json

    from fem_neck import render

    render.write_vtu(result, out / f"{name}.vtu", delta_t=delta_t)
    render.write_png(result, out / f"{name}.png", title=title, delta_t=delta_t)
    (out / f"{name}.json").write_text(json.dumps(summary, indent=2) + "\n")


def _accuracy_fields(result) -> dict:
    return {"dofs": result.dofs, "error_estimate": result.error_estimate, "converged": result.converged,
            "order": result.order, "grading": result.grading, "h_min": result.h_min, "seconds": result.seconds}


def semisphere_case(args) -> tuple[float, float]:
    """``(h/r, a/r)`` of the semisphere from ``--h-over-r`` or ``--a-over-r`` (eqs. 19-20 and their inverse).

    Parameters
    ----------
    args : argparse.Namespace
        Parsed options with ``h_over_r`` (``h/r`` in ``(0, 2/3]``) or ``a_over_r`` (``a/r``), dimensionless.
    """
    from fem_neck.geometry import check_positive, equal_neck_radius, overlap_for_neck

    if args.h_over_r is not None:
        h = float(check_positive("h_over_r", args.h_over_r, upper=2.0 / 3.0, upper_name="the neck reaches r"))
        return h, float(equal_neck_radius(1.0, h))
    a = float(check_positive("a_over_r", args.a_over_r, upper=1.0, upper_name="the neck reaches r"))
    return float(overlap_for_neck(1.0, 1.0, a)), a


def run_semisphere(args) -> dict:
    """The semisphere's ``K/K_cyl`` (:func:`fem_neck.conduction.semisphere_conductance`) as a JSON-ready dict; files
    into ``--out`` if given.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``python -m fem_neck semisphere`` (its ``--help`` lists them).
    """
    from fem_neck import conduction

    h, a = semisphere_case(args)
    result = _mesh_errors_as_value_errors(
        lambda: conduction.semisphere_conductance(a, rtol=args.rtol, order=args.order, method=args.method))
    summary = {"h_over_r": h, "a_over_r": a, "K_over_Kcyl": result.K_over_Kcyl, **_accuracy_fields(result)}
    out = _output_dir(args)
    if out is not None:
        _write(out, "semisphere", summary, result, f"h/r={h:.4g}, a/r={a:.4g}", delta_t=10.0)
    return summary


def _compare(result, kappa: float, necks) -> dict:
    resistances = 1.0 / model_bond_conductance(kappa, necks)
    k_model = float(1.0 / np.sum(resistances))
    return {"K_fe": result.K, "K_model": k_model, "rel_diff": (k_model - result.K) / result.K}


def run_pair(args) -> dict:
    """The pair's conductance (:func:`fem_neck.conduction.pair_conductance`) against the paper's model, as a JSON-ready
    dict; files into ``--out`` if given.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``python -m fem_neck pair``: radii and overlap in m, ``kappa`` in W/(m K).
    """
    from fem_neck import conduction

    result = _mesh_errors_as_value_errors(
        lambda: conduction.pair_conductance(args.ri, args.rj, args.h, args.kappa, rtol=args.rtol, order=args.order,
                                            method=args.method))
    summary = {"a": result.necks[0], **_compare(result, args.kappa, result.necks), **_accuracy_fields(result)}
    out = _output_dir(args)
    if out is not None:
        _write(out, "pair", summary, result, f"r_j/r_i={args.rj / args.ri:.3g}, a={result.necks[0]:.4g} m",
               delta_t=10.0)
    return summary


def run_chain(args) -> dict:
    """The chain's conductance (:func:`fem_neck.conduction.chain_conductance`) against the pipe model in series, as a
    JSON-ready dict; files into ``--out`` if given.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``python -m fem_neck chain``: radii and overlaps in m, ``kappa`` in W/(m K).
    """
    from fem_neck import conduction

    radii = _floats("radii", args.radii)
    if len(radii) > MAX_CHAIN:
        raise ValueError(f"radii: {len(radii)} spheres exceeds the limit of {MAX_CHAIN} for one FE solve (about "
                         f"0.7 s and 35 MB per sphere at 40, growing faster than linearly); the bonds are in series, so "
                         f"solve shorter pieces")
    overlaps = _floats("overlaps", args.overlaps)
    result = _mesh_errors_as_value_errors(
        lambda: conduction.chain_conductance(radii, overlaps, args.kappa, rtol=args.rtol, order=args.order))
    summary = {"necks": result.necks, **_compare(result, args.kappa, result.necks), **_accuracy_fields(result)}
    out = _output_dir(args)
    if out is not None:
        _write(out, "chain", summary, result, f"chain of {len(radii)}", delta_t=10.0)
    return summary
