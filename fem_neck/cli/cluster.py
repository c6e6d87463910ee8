"""``python -m fem_neck cluster``: steady 3D FE conduction through a small cluster of sintered spheres."""

from fem_neck.cli import add_output_options


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "cluster",
        help="3D FE conductance and particle mean temperatures of a sintered cluster",
        description="Solve steady conduction through a cluster of spheres joined by volume-conserving cylindrical "
        "necks (gmsh OCC union, curved P2 tetrahedra graded toward the necks). The cluster is a JSON file: "
        '{"centres": [[x,y,z],...], "radii": [...], "bonds": [[i,j],...], "terminals": [{"particle": k, "T": 1.0, '
        '"kind": "plane"}, {"particle": m, "T": 0.0, "kind": "core", "rho": 0.25}]} (SI units). A "plane" terminal '
        "(one-bond particles only) is cut at its centre plane normal to its bond, a \"core\" terminal holds a "
        "centre ball of radius rho*r. Output: K = Q/(T_hot - T_cold) in W/K and each particle's mean temperature; "
        "with --levels 2 also the change from a coarser mesh (an error bar).",
    )
    p.add_argument("file", help="cluster JSON file")
    p.add_argument("--kappa", type=float, default=394.0, help="thermal conductivity [W/(m K)] (default 394)")
    p.add_argument("--size-neck", type=float, default=0.12, help="element size at the neck circles / a")
    p.add_argument("--size-far", type=float, default=0.25, help="element size away from the necks / r")
    p.add_argument("--levels", type=int, choices=(1, 2), default=2, help="mesh levels (2: error bar)")
    add_output_options(p)
    p.set_defaults(run=run)


def run(args) -> dict:
    import json
    import pathlib
    import time

    from fem_neck.cluster import build_cluster_mesh, load_cluster_json, solve_cluster, write_vtu

    try:
        data = json.loads(pathlib.Path(args.file).read_text())
    except (OSError, json.JSONDecodeError) as exc:
        raise ValueError(f"file = {args.file!r}: cannot be read as JSON ({exc})") from exc
    cluster, terminals = load_cluster_json(data)
    t0 = time.perf_counter()
    sizes = [(args.size_neck, args.size_far)]
    if args.levels == 2:
        sizes.insert(0, (args.size_neck * 1.6, args.size_far * 1.4))
    results = []
    for size_neck, size_far in sizes:
        cmesh = build_cluster_mesh(cluster, terminals, size_neck=size_neck, size_far=size_far,
                                   curvature=max(12, int(round(4.0 / size_far))))
        results.append((cmesh, solve_cluster(cmesh, kappa=args.kappa, order=2)))
    cmesh, sol = results[-1]
    out = {"K": sol.K, "Q": sol.Q, "particle_T": sol.particle_T.tolist(), "necks": cmesh.neck_a.tolist(),
           "dofs": int(sol.dofs), "error_estimate": (abs(sol.K - results[0][1].K) / sol.K if len(results) > 1
                                                else None),
           "volume_exact": float(cmesh.volume_exact), "seconds": time.perf_counter() - t0}
    if args.out:
        path = pathlib.Path(args.out)
        path.mkdir(parents=True, exist_ok=True)
        (path / "cluster.json").write_text(json.dumps(out, indent=2) + "\n")
        write_vtu(cmesh, sol, path / "cluster.vtu")
    return out
