"""``python -m fem_neck cluster``: steady 3D FE conduction through a small cluster of sintered spheres."""

import math

from sinterheat.cli import add_output_options

# What one 3D solve can afford: the mesh sizes' range, the particle count, and a run-time budget. Measured on 2 cores
# for two spheres: defaults ~1.5 s, size_far 0.1 ~9 s, 0.06 ~39 s, size_neck 0.04 ~14 s; estimate_seconds fits that.
SIZE_NECK = (0.02, 1.0)
SIZE_FAR = (0.05, 1.0)
MAX_PARTICLES = 40
MAX_SECONDS = 300.0


def estimate_seconds(n: int, size_neck: float, size_far: float, levels: int) -> float:
    r"""Rough run time (s) of a cluster solve on 2 cores: per particle
    :math:`\approx 0.75 \, \mathrm{s} \times \left((0.25/s_f)^{2.2} + (0.12/s_n)^2\right)` (``size_far`` :math:`s_f`,
    ``size_neck`` :math:`s_n`) for the finest level; the coarser levels (sizes x1.6, x2.56) add about 35 % and 12 %.

    Parameters
    ----------
    n : int
        Number of particles.
    size_neck : float
        The finest level's element size at the neck circles over the neck radius (dimensionless).
    size_far : float
        The finest level's element size away from the necks over the radius (dimensionless).
    levels : int
        Mesh levels, 1 to 3.
    """
    per_level = 0.75 * n * ((0.25 / size_far) ** 2.2 + (0.12 / size_neck) ** 2)
    return per_level * (1.0, 1.35, 1.5)[levels - 1]


TERMINAL_KEYS = {"particle", "T", "kind", "rho"}


def register(subparsers) -> None:
    """Add the ``cluster`` sub-command's parser (its options and ``run``) to ``subparsers``.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The sub-commands of the ``python -m fem_neck`` parser.
    """
    p = subparsers.add_parser(
        "cluster",
        help="3D FE conductance and particle mean temperatures of a sintered cluster",
        description="Solve steady conduction through a cluster of spheres joined by volume-conserving cylindrical "
        "necks (gmsh OCC union, curved P2 tetrahedra graded toward the necks). The cluster is a JSON file: "
        '{"centres": [[x,y,z],...], "radii": [...], "bonds": [[i,j],...], "terminals": [{"particle": k, "T": 1.0, '
        '"kind": "plane"}, {"particle": m, "T": 0.0, "kind": "core", "rho": 0.25}]} (SI units). A "plane" terminal '
        "(one-bond particles only) is cut at its centre plane normal to its bond, a \"core\" terminal holds a "
        "centre ball of radius rho*r. Output: K = Q/(T_hot - T_cold) in W/K and each particle's mean temperature; "
        "with --levels 2 or 3 their error estimates: every mesh size is also taken 1.6x (and 2.56x) coarser, and "
        "the change of K between the two finest levels, over the convergence rate (the slower of the observed one "
        "and the neck edges' corner rate) and times 1.25, is the error bar of K (fem_neck.accuracy).",
    )
    p.add_argument("file", help=f"cluster JSON file (at most {MAX_PARTICLES} particles)")
    p.add_argument("--kappa", type=float, default=394.0, help="thermal conductivity [W/(m K)] (default 394)")
    p.add_argument("--size-neck", type=float, default=0.12,
                   help=f"element size at the neck circles / a, in [{SIZE_NECK[0]:g}, {SIZE_NECK[1]:g}]")
    p.add_argument("--size-far", type=float, default=0.25,
                   help=f"element size away from the necks / r, in [{SIZE_FAR[0]:g}, {SIZE_FAR[1]:g}]")
    p.add_argument("--levels", type=int, choices=(1, 2, 3), default=3,
                   help="mesh levels (default 3: error bar with the observed convergence rate; 2: with the corner "
                        "rate alone; 1: none)")
    add_output_options(p)
    p.set_defaults(run=run)


def run(args) -> dict:
    """Solve the cluster of the JSON file ``args.file`` (:func:`fem_neck.cluster.cluster_conductance`); the result as a
    JSON-ready dict (VTU and JSON files into ``--out`` if given).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``python -m fem_neck cluster`` (its ``--help`` lists them, with their units: lengths in m,
        temperatures in K, conductivities in W/(m K)).
    """
    import json
    import pathlib
    import time

    from fem_neck.accuracy import MESH_RATIO
    from fem_neck.cluster import cluster_conductance, load_cluster_json, write_vtu

    try:
        data = json.loads(pathlib.Path(args.file).read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"file = {args.file!r}: cannot be read as JSON ({exc})") from exc
    coarsest = MESH_RATIO ** (args.levels - 1)
    for name, (low, high) in (("size_neck", SIZE_NECK), ("size_far", SIZE_FAR)):
        value = getattr(args, name)
        if not low <= value <= high:  # False for NaN
            raise ValueError(f"{name} = {value!r}: valid range {low:g} <= {name} <= {high:g}")
        if value * coarsest > high:
            raise ValueError(f"{name} = {value!r} with --levels {args.levels}: the coarsest level would use "
                             f"{value * coarsest:.3g} > {high:g}; valid range {low:g} <= {name} <= "
                             f"{high / coarsest:.3g} with {args.levels} levels (or use fewer levels)")
    if not (0.0 < args.kappa < math.inf):
        raise ValueError(f"kappa = {args.kappa!r}: must be finite and > 0")
    data = checked_cluster_data(data)
    seconds = estimate_seconds(len(data["radii"]), args.size_neck, args.size_far, args.levels)
    if seconds > MAX_SECONDS:
        raise ValueError(f"size_neck = {args.size_neck:g}, size_far = {args.size_far:g} with {len(data['radii'])} "
                         f"particles and --levels {args.levels}: an estimated {seconds:.0f} s exceeds the budget of "
                         f"{MAX_SECONDS:.0f} s for one run; use coarser sizes, --levels 1 or fewer particles")
    cluster, terminals = load_cluster_json(data)
    t0 = time.perf_counter()
    # K is linear in kappa: solve with kappa = 1 and scale, so any kappa a float holds keeps full precision
    res = cluster_conductance(cluster, terminals, kappa=1.0, size_neck=args.size_neck, size_far=args.size_far,
                              levels=args.levels)
    seq = res.sequence
    out = {"K": args.kappa * res.K, "Q": args.kappa * res.solution.Q, "particle_T": res.particle_T.tolist(),
           "necks": res.cmesh.neck_a.tolist(), "dofs": int(res.solution.dofs), "error_estimate": res.error_estimate,
           "T_error_estimate": res.T_error_estimate,
           "observed_order": seq.observed_order if seq is not None else None,
           "corner_order": seq.corner_order if seq is not None else None,
           "levels": [{"size_factor": lv["size_factor"], "dofs": lv["dofs"], "K": args.kappa * lv["K"]}
                      for lv in res.levels],
           "volume_exact": float(res.cmesh.volume_exact), "seconds": time.perf_counter() - t0}
    if args.out:
        path = pathlib.Path(args.out)
        path.mkdir(parents=True, exist_ok=True)
        (path / "cluster.json").write_text(json.dumps(out, indent=2) + "\n")
        write_vtu(res.cmesh, res.solution, path / "cluster.vtu")
    return out


def _numbers(name: str, value, shape_tail: tuple = ()) -> list:
    """``value`` as a (nested) list of finite JSON numbers of rank ``1 + len(shape_tail)``, else ValueError."""
    if not isinstance(value, list):
        raise ValueError(f"cluster file: {name} = {value!r:.60}: must be a list")
    for k, item in enumerate(value):
        if shape_tail:
            if not isinstance(item, list) or len(item) != shape_tail[0]:
                raise ValueError(f"cluster file: {name}[{k}] = {item!r:.60}: must be a list of {shape_tail[0]} numbers")
            _numbers(f"{name}[{k}]", item, shape_tail[1:])
        elif not isinstance(item, (int, float)) or isinstance(item, bool) or not math.isfinite(item):
            raise ValueError(f"cluster file: {name}[{k}] = {item!r}: must be a finite number")
    return value


def _index(name: str, value, n: int) -> int:
    if not isinstance(value, int) or isinstance(value, bool) or not 0 <= value < n:
        raise ValueError(f"cluster file: {name} = {value!r}: must be an integer particle index in 0..{n - 1}")
    return value


def checked_cluster_data(data) -> dict:
    """The cluster JSON with every entry's type, shape and range checked, naming the first bad entry.

    Parameters
    ----------
    data : object
        The parsed JSON document (:func:`fem_neck.cluster.load_cluster_json` gives its layout).
    """
    if not isinstance(data, dict):
        raise ValueError(f"cluster file: must be a JSON object with centres, radii, bonds, terminals; got "
                         f"{type(data).__name__}")
    keys = {"centres", "radii", "bonds", "terminals"}
    for key in sorted(keys - set(data)):
        raise ValueError(f"cluster file: {key}: required (keys: {', '.join(sorted(keys))})")
    for key in sorted(set(data) - keys):
        raise ValueError(f"cluster file: {key}: unknown key (keys: {', '.join(sorted(keys))})")
    centres = _numbers("centres", data["centres"], (3,))
    radii = _numbers("radii", data["radii"])
    n = len(radii)
    if len(centres) != n:
        raise ValueError(f"cluster file: radii has {n} entries but centres has {len(centres)}")
    if not 1 <= n <= MAX_PARTICLES:
        raise ValueError(f"cluster file: {n} particles: valid range 1 to {MAX_PARTICLES} for one 3D FE solve (use the "
                         f"DEM, python -m dem, for larger packings)")
    if not isinstance(data["bonds"], list):
        raise ValueError(f"cluster file: bonds = {data['bonds']!r:.60}: must be a list of [i, j] pairs")
    for k, bond in enumerate(data["bonds"]):
        if not isinstance(bond, list) or len(bond) != 2:
            raise ValueError(f"cluster file: bonds[{k}] = {bond!r:.60}: must be a pair [i, j] of particle indices")
        for m in (0, 1):
            _index(f"bonds[{k}][{m}]", bond[m], n)
    if not isinstance(data["terminals"], list):
        raise ValueError(f"cluster file: terminals = {data['terminals']!r:.60}: must be a list of objects")
    for k, t in enumerate(data["terminals"]):
        if not isinstance(t, dict):
            raise ValueError(f"cluster file: terminals[{k}] = {t!r:.60}: must be an object {{\"particle\": k, "
                             f"\"T\": ..., \"kind\": \"plane\"|\"core\", \"rho\": 0.25}}")
        for key in sorted(set(t) - TERMINAL_KEYS):
            raise ValueError(f"cluster file: terminals[{k}].{key}: unknown key (keys: {', '.join(sorted(TERMINAL_KEYS))})")
        for key in ("particle", "T"):
            if key not in t:
                raise ValueError(f"cluster file: terminals[{k}].{key}: required")
        _index(f"terminals[{k}].particle", t["particle"], n)
        _numbers(f"terminals[{k}].T", [t["T"]])
        if "rho" in t:
            _numbers(f"terminals[{k}].rho", [t["rho"]])
        if not isinstance(t.get("kind", "plane"), str):
            raise ValueError(f"cluster file: terminals[{k}].kind = {t['kind']!r}: must be \"plane\" or \"core\"")
    return data
