r"""``python -m dem contact SCENE --history FILE.csv [--no-damping] [--json] [--out DIR]``: one Luding 2005 contact
driven through a prescribed history.

The pair: two equal particles of the scene's mean radius :math:`a` (so :math:`\delta_\mathrm{fluid}` is
``fluid_overlap`` times :math:`a`), made of the scene's ``[contact]`` material. The history CSV has the columns ``t``
(s, strictly increasing), ``overlap`` (m; :math:`\le 0` opens the contact: no force, and a later overlap starts a
fresh contact; below the pair's size :math:`2 a`, where the centres meet) and ``T`` (the scene's temperature unit);
other columns are ignored. Per row the tool reports the normal force on a particle (N, > 0 repulsive),
``delta_max`` (:math:`\delta_\mathrm{max}`), ``delta_0`` (:math:`\delta_0`), ``k1`` = :math:`k_1(T, t)`, ``k2`` =
:math:`k_2(\delta_\mathrm{max})`, ``kc`` = :math:`k_c(T, t, \delta_\mathrm{max})` (all in N/m) and ``f_min`` (eq. 15).

:math:`k_1(T, t)` starts at its equilibrium :math:`k_1(T)` of the first row's temperature and relaxes row by row
towards :math:`k_1(T)` of each row's temperature (eq. 12, :func:`dem.laws.contact.state.sintering.relax_k1`;
cooling freezes at once). The viscous force :math:`\gamma_0 \dot\delta` (eq. 5) uses the backward difference of the
overlap between rows (0 on the first row); ``--no-damping`` leaves it out, giving the elastic-plastic force of Figs.
2, 3 and 5 alone.

Without ``--json`` the rows are printed as a table; ``--out DIR`` writes ``contact.csv`` and ``contact.png`` (force
against overlap with the cold :math:`k_1` line, the :math:`k_1(T, t)` and :math:`-k_c(T, t, \delta_\mathrm{max})` lines
of the last row and the path taken; beside it the temperature history and :math:`k_1(T, t)/k_1`).
"""

from __future__ import annotations

import csv
import math
import pathlib

import numpy as np

from sinterheat.cli import add_output_options

COLUMNS = ("t", "overlap", "T")
OUTPUTS = ("force", "delta_max", "delta_0", "k1", "k2", "kc", "f_min")


def register(sub):
    """Add the ``contact`` command (module docstring) to the subcommands of ``python -m dem``.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subparsers of the ``python -m dem`` parser.
    """
    parser = sub.add_parser("contact", help="drive one Luding 2005 contact through an overlap/temperature history",
                            description=__doc__)
    parser.add_argument("scene", help="a scene with a [contact] table (TOML file or built-in name, e.g. luding-table1)")
    parser.add_argument("--history", required=True, metavar="FILE.csv", help="CSV with columns t, overlap, T")
    parser.add_argument("--no-damping", action="store_true",
                        help=r"leave out the viscous force :math:`\gamma_0 \dot\delta` (eq. 5)")
    add_output_options(parser)
    parser.set_defaults(run=run)


def read_history(path) -> dict:
    """Columns ``t``, ``overlap``, ``T`` of a CSV as float arrays; ``ValueError`` naming the file, row and column
    of anything missing, non-numeric, non-finite, or a ``t`` that does not increase.

    Parameters
    ----------
    path : str or pathlib.Path
        The history CSV.

    Returns
    -------
    dict
        ``{"t": s, "overlap": m, "T": the scene's temperature unit}``, float arrays.

    Raises
    ------
    ValueError
        The file cannot be read, or a value is missing, not a finite number, or a time does not increase.
    """
    name = pathlib.Path(path).name
    if not pathlib.Path(path).is_file():
        raise ValueError(f"history = {str(path)!r}: no such file")
    try:
        with open(path, newline="") as fh:
            reader = csv.DictReader(fh)
            header = [h.strip() for h in (reader.fieldnames or [])]
            missing = [c for c in COLUMNS if c not in header]
            if missing:
                raise ValueError(f"history {name}: column {missing[0]!r} missing (needs {', '.join(COLUMNS)}; "
                                 f"found {', '.join(header) or 'no header'})")
            reader.fieldnames = header
            rows = list(reader)
    except UnicodeDecodeError as exc:
        raise ValueError(f"history {name}: cannot be read as text ({exc})") from None
    if not rows:
        raise ValueError(f"history {name}: no data rows")
    out = {c: np.empty(len(rows)) for c in COLUMNS}
    for k, row in enumerate(rows):
        for c in COLUMNS:
            text = (row.get(c) or "").strip()
            try:
                value = float(text)
            except ValueError:
                raise ValueError(f"history {name}: row {k + 1}: {c} = {text!r}: must be a number") from None
            if not math.isfinite(value):
                raise ValueError(f"history {name}: row {k + 1}: {c} = {text!r}: must be finite")
            out[c][k] = value
    steps = np.diff(out["t"])
    if np.any(steps <= 0):
        k = int(np.flatnonzero(steps <= 0)[0]) + 1
        raise ValueError(f"history {name}: row {k + 1}: t = {float(out['t'][k])!r}: must be > t of the row "
                         f"before ({float(out['t'][k - 1])!r}); t must increase strictly")
    return out


def check_overlaps(path, overlap, radius: float) -> None:
    """Refuse an overlap of the pair of radius ``radius`` at or beyond the pair's size ``2 radius`` (the centres meet
    there), naming the file and the row.

    Parameters
    ----------
    path : str or pathlib.Path
        The history CSV (named in the message).
    overlap : array_like
        The overlaps of its rows (m).
    radius : float
        The pair's particle radius a (m).

    Raises
    ------
    ValueError
        An overlap is ``>= 2 a``.
    """
    beyond = np.flatnonzero(np.asarray(overlap) >= 2.0 * radius)
    if beyond.size:
        k = int(beyond[0])
        raise ValueError(f"history {pathlib.Path(path).name}: row {k + 1}: overlap = {float(overlap[k])!r} m: valid "
                         f"range overlap < 2 a = {2.0 * radius:.6g} m (the pair's size: two particles of the scene's "
                         f"mean radius a = {radius:.6g} m, whose centres meet at 2 a)")


def drive_pair(material, radius: float, t, overlap, T, damping: bool = True) -> dict:
    r"""One pair contact of two equal particles of radius ``radius`` through the history (see the module
    docstring); returns the per-row arrays named in ``OUTPUTS``.

    Parameters
    ----------
    material : dem.laws.contact.luding.LudingMaterial
        The contact material.
    radius : float
        The particles' radius a (m).
    t : numpy.ndarray
        The rows' times (s), increasing.
    overlap : numpy.ndarray
        The rows' overlaps (m); <= 0 opens the contact.
    T : numpy.ndarray
        The rows' temperatures (the unit of ``T_melt``).
    damping : bool
        Whether the viscous force :math:`\gamma_0 \dot\delta` (eq. 5) is included.

    Returns
    -------
    dict
        ``{name: (rows,) array}`` for the names of ``OUTPUTS``: force (N), ``delta_max``, ``delta_0`` (m), ``k1``,
        ``k2``, ``kc`` (N/m), ``f_min`` (N).
    """
    from dem.laws.contact.normal import luding as luding_normal
    from dem.laws.contact.state import sintering

    params = material.params()
    delta_fluid = luding_normal.pair_delta_fluid(radius, radius, material.fluid_overlap)
    n = len(t)
    out = {key: np.empty(n) for key in OUTPUTS}
    s = sintering.k1_factor(T[0], material.T_melt, material.T_var)
    s_last, delta_max = s, 0.0
    for k in range(n):
        if k:
            target = sintering.k1_factor(T[k], material.T_melt, material.T_var)
            s = sintering.relax_k1(s, target, t[k] - t[k - 1], material.t0, T[k] < T[k - 1])
        rate = (overlap[k] - overlap[k - 1]) / (t[k] - t[k - 1]) if k and damping else 0.0
        if overlap[k] <= 0.0:
            delta_max = 0.0  # the contact is open: its history is gone
        f, delta_max, fmin, k2, kc, d0 = luding_normal.normal_force(overlap[k], rate, s, delta_max, s_last,
                                                                    delta_fluid, params)
        s_last = s
        for key, value in zip(OUTPUTS, (f, delta_max, d0, s * material.k1, k2, kc, fmin)):
            out[key][k] = value
    return out


def run(args) -> dict:
    """Drive the pair through the history (module docstring); print the table unless ``--json``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line: ``scene``, ``history``, ``no_damping``, ``json`` and ``out``.

    Returns
    -------
    dict
        The pair, and with ``--json`` every row's inputs and outputs; with ``--out`` the files written.

    Raises
    ------
    ValueError
        A bad scene, history or overlap.
    """
    from dem.laws.contact.normal.luding import pair_delta_fluid
    from dem.scene.parse import load_scene, luding_material_from_scene

    scene = load_scene(args.scene)
    material = luding_material_from_scene(scene)
    history = read_history(args.history)
    material.check_temperatures(history["T"], name="history T")
    radius = float(np.mean(scene.particles.radius))
    check_overlaps(args.history, history["overlap"], radius)
    rows = drive_pair(material, radius, history["t"], history["overlap"], history["T"], not args.no_damping)
    result = {
        "pair": f"two equal particles of the scene's mean radius a = {radius:.6g} m",
        "radius": radius,
        "delta_fluid": pair_delta_fluid(radius, radius, material.fluid_overlap),
        "damping": not args.no_damping,
        **{c: history[c].tolist() for c in COLUMNS},
        **{key: rows[key].tolist() for key in OUTPUTS},
    }
    if args.out:
        out = pathlib.Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        write_csv(out / "contact.csv", history, rows)
        plot(out / "contact.png", material, radius, history, rows, scene.temperature_unit)
        result["files"] = [str(out / "contact.csv"), str(out / "contact.png")]
    if not args.json:
        print_table(history, rows)
        return {key: result[key] for key in ("pair", "radius", "delta_fluid", "damping", "files") if key in result}
    return result


def write_csv(path: pathlib.Path, history: dict, rows: dict) -> None:
    """Write the rows' inputs and outputs as ``contact.csv``, numbers that read back to the same doubles.

    Parameters
    ----------
    path : pathlib.Path
        The file to write.
    history : dict
        The history's columns ``t`` (s), ``overlap`` (m), ``T`` (:func:`read_history`).
    rows : dict
        The per-row outputs of :func:`drive_pair`.
    """
    with open(path, "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(COLUMNS + OUTPUTS)
        for k in range(len(history["t"])):
            writer.writerow([repr(float(history[c][k])) for c in COLUMNS] + [repr(float(rows[o][k])) for o in OUTPUTS])


def print_table(history: dict, rows: dict) -> None:
    """Print the rows' inputs and outputs as a table on stdout.

    Parameters
    ----------
    history : dict
        The history's columns ``t`` (s), ``overlap`` (m), ``T`` (:func:`read_history`).
    rows : dict
        The per-row outputs of :func:`drive_pair`.
    """
    names = COLUMNS + OUTPUTS
    print("  ".join(f"{name:>12}" for name in names))
    for k in range(len(history["t"])):
        values = [history[c][k] for c in COLUMNS] + [rows[o][k] for o in OUTPUTS]
        print("  ".join(f"{v:>12.6g}" for v in values))


def plot(path: pathlib.Path, material, radius: float, history: dict, rows: dict, temperature_unit: str) -> None:
    r"""Left: force against overlap in the style of Luding 2005, Figs. 2, 3 and 5 -- the cold :math:`k_1` line, the
    :math:`k_1(T, t)` and :math:`-k_c(T, t, \delta_{max})` lines of the last row and the path through the rows. Right:
    the temperature history (in the scene's ``temperature_unit``) and the stiffness factor :math:`k_1(T, t)/k_1` it
    drives (eqs. 10, 12).

    Parameters
    ----------
    path : pathlib.Path
        The PNG file to write.
    material : dem.laws.contact.luding.LudingMaterial
        The contact material.
    radius : float
        The particles' radius a (m).
    history : dict
        The history's columns ``t`` (s), ``overlap`` (m), ``T`` (:func:`read_history`).
    rows : dict
        The per-row outputs of :func:`drive_pair`.
    temperature_unit : str
        The scene's temperature unit, ``"C"`` or ``"K"``, for the axis label.
    """
    from matplotlib.figure import Figure

    from dem.laws.contact.normal import luding as luding_normal
    from dem.output.plots import temperature_label

    delta_fluid = luding_normal.pair_delta_fluid(radius, radius, material.fluid_overlap)
    x = history["overlap"]
    top = max(float(np.max(x)), float(np.max(rows["delta_max"])), 1e-300)
    line = np.array([0.0, 1.1 * top])
    fig = Figure(figsize=(11.0, 4.8))
    ax, heat = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.3, 1.0]})
    ax.plot(line, material.k1 * line, "k--", lw=1, label="$k_1\\delta$ (cold)")
    if abs(rows["k1"][-1] / material.k1 - 1.0) > 1e-3:
        ax.plot(line, rows["k1"][-1] * line, "C1--", lw=1, label="$k_1(T,t)\\delta$ (last row)")
    ax.plot(line, -rows["kc"][-1] * line, "k:", lw=1, label="$-k_c(T,t,\\delta_{max})\\delta$ (last row)")
    ax.plot(x, rows["force"], "C0.-", lw=1.2, ms=3, label="path")
    ax.axhline(0.0, color="0.7", lw=0.5)
    if delta_fluid <= line[1]:
        ax.axvline(delta_fluid, color="0.7", lw=0.8, ls="-.", label="$\\delta^{fluid}$")
    ax.set_xlabel("overlap $\\delta$ (m)")
    ax.set_ylabel("normal force $f$ (N)")
    ax.set_title(f"Luding 2005 contact, equal pair a = {radius:.3g} m")
    ax.legend(fontsize=8)
    heat.plot(history["t"], history["T"], "C3.-", lw=1.2, ms=3)
    heat.set_xlabel("t (s)")
    heat.set_ylabel(temperature_label(temperature_unit), color="C3")
    heat.set_title("temperature history")
    factor = heat.twinx()
    factor.plot(history["t"], rows["k1"] / material.k1, "C0--", lw=1)
    factor.set_ylabel("$k_1(T,t)/k_1$", color="C0")
    factor.set_ylim(-0.05, 1.05)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
